"""The time step of a simulated run, and the run's size checked before its loop is built.

A run's step (:func:`motionhyst.time.simulation.default_step`) resolves the
loop's fastest closed-loop pole in :data:`STEPS_PER_POLE_PERIOD` steps and the
reference's highest frequency in :data:`STEPS_PER_REFERENCE_PERIOD`; a loop with
a sampled controller runs at the controller's period.  The reference's part and
the controller's period are known before the loop is built (python-control):
:func:`longest_step` bounds the step from above with them alone, so a run of far
too many steps is refused at once (:func:`check_scan_steps`,
:func:`time_series_grid` with ``at_least``), and again with the loop's own step
once the loop is built.  Where a scenario's coefficients give its poles before the
loop is built (:meth:`motionhyst.scenario.Scenario.fastest_pole`), :func:`pole_step` is
the run's own step, and the checks are exact.
"""

from __future__ import annotations

import math

from motionhyst.core.budget import check_memory

__all__ = ["BYTES_PER_SAMPLE", "MAX_ROWS", "MAX_SCAN_STEPS", "MAX_STEPS", "SCAN_REMEDY",
           "STEPS_PER_POLE_PERIOD", "STEPS_PER_REFERENCE_PERIOD", "check_scan_steps",
           "longest_step", "pole_step", "time_series_grid"]

STEPS_PER_POLE_PERIOD = 40
"""Time steps per period of the loop's fastest closed-loop pole."""

STEPS_PER_REFERENCE_PERIOD = 400
"""Time steps per period of the reference's highest frequency."""

BYTES_PER_SAMPLE = 160
"""Memory of one time sample of a run: its signals and the loop's intermediate arrays [bytes]."""

MAX_SCAN_STEPS = 50_000_000
"""Most time steps of one run of a scan (each run keeps its signals)."""

MAX_ROWS = 100_000_000
"""Most rows a time series writes (about 10 GB of CSV)."""

MAX_STEPS = 200_000_000
"""Most integration steps of a time series (the work budget: some minutes at about 1.5 us a
step)."""

SCAN_REMEDY = "shorten the setpoint (its length, dwell) or the tail after it, or raise the speed"
"""What a scan refused for its size can change."""


def pole_step(fastest_pole: float, max_frequency_hz: float = 0.0) -> float:
    """A continuous loop's step [s]: its fastest closed-loop pole resolved in
    :data:`STEPS_PER_POLE_PERIOD` steps, the reference's highest frequency (if any) in
    :data:`STEPS_PER_REFERENCE_PERIOD`.

    Parameters
    ----------
    fastest_pole : float
        The largest magnitude of the loop's closed-loop poles [rad/s], > 0
        (:meth:`motionhyst.scenario.Scenario.fastest_pole`, known before the loop is built).
    max_frequency_hz : float
        The reference's highest frequency [Hz]; 0: none sets the step.

    Examples
    --------
    >>> print(f"{pole_step(4344.0, 5.0):.3g} s")             # Table I's loop: the pole sets it
    3.62e-05 s
    >>> pole_step(1.0, 25.0)                                  # a slow loop: the reference does
    0.0001
    """
    h = math.tau / (STEPS_PER_POLE_PERIOD * fastest_pole)
    return min(h, 1.0 / (STEPS_PER_REFERENCE_PERIOD * max_frequency_hz)) if max_frequency_hz > 0 \
        else h


def longest_step(max_frequency_hz: float, sample_period: float | None = None) -> float:
    """The longest step a run can take [s], known without its loop.

    Parameters
    ----------
    max_frequency_hz : float
        The reference's highest frequency [Hz], > 0.
    sample_period : float, optional
        A sampled controller's period [s]: the run's step itself.

    Returns
    -------
    float
        `sample_period` if given, else ``1 / (STEPS_PER_REFERENCE_PERIOD *
        max_frequency_hz)``: the loop's poles can only shorten it.

    Examples
    --------
    >>> longest_step(25.0)
    0.0001
    >>> longest_step(25.0, sample_period=1e-4 / 3)   # a controller at 30 kHz
    3.3333333333333335e-05
    """
    if sample_period is not None:
        return sample_period
    return 1.0 / (STEPS_PER_REFERENCE_PERIOD * max_frequency_hz)


def check_scan_steps(duration: float, step: float, runs: int, remedy: str = SCAN_REMEDY,
                     at_least: bool = False) -> int:
    """The time steps of each run of a scan, refused above :data:`MAX_SCAN_STEPS` or
    above the memory budget (:func:`motionhyst.core.budget.check_memory`).

    Parameters
    ----------
    duration : float
        Simulated time of a run [s].
    step : float
        Its time step [s]; with `at_least`, an upper bound of it (:func:`longest_step`).
    runs : int
        Runs kept at once (the compensations compared).
    remedy : str
        What the user can change, for the message (:data:`SCAN_REMEDY`).
    at_least : bool
        The count is a lower bound (the loop's step is not known yet); the message
        says so.

    Returns
    -------
    int
        The time steps of a run (with `at_least`, a lower bound).

    Raises
    ------
    ValueError
        One line: the count, the step and `remedy`.

    Examples
    --------
    >>> check_scan_steps(0.5, 1e-4, runs=3, remedy="shorten the setpoint")
    5001
    >>> try:
    ...     check_scan_steps(1e7, 1e-4, runs=3, remedy="shorten the setpoint", at_least=True)
    ... except ValueError as exc:
    ...     print(exc)
    at least 100000000001 time steps of 0.0001 s: too many; shorten the setpoint
    """
    n = math.ceil(duration / step) + 1
    if n > MAX_SCAN_STEPS:
        raise ValueError(f"{'at least ' if at_least else ''}{n} time steps of {step:.3g} s: "
                         f"too many; {remedy}")
    check_memory(n * BYTES_PER_SAMPLE * (runs + 2),
                 f"a scan of {runs} runs of {'at least ' if at_least else ''}{n:.3g} time "
                 f"steps each", remedy)
    return n


def time_series_grid(duration: float, output_rate_hz: float, step: float,
                     sample_rate_hz: float | None = None, at_least: bool = False
                     ) -> tuple[int, int, float]:
    """The rows, the steps a row and the step of a time series written at `output_rate_hz`,
    refused above :data:`MAX_ROWS` rows or :data:`MAX_STEPS` steps.

    The step divides the output period, so that every row is an integration sample; a
    sampled controller's loop steps at its period, which the output period must be a
    whole number of.

    Parameters
    ----------
    duration : float
        Simulated time [s], > 0.
    output_rate_hz : float
        Rows per second, > 0.
    step : float
        The longest step the loop's dynamics allow [s] (``inf``: any); with `at_least`,
        an upper bound of it (:func:`longest_step`).
    sample_rate_hz : float, optional
        A sampled controller's rate [Hz]: the loop steps at its period.
    at_least : bool
        The steps a row are a lower bound (the loop's step is not known yet); the
        message says so.

    Returns
    -------
    rows : int
        Rows written, the first at ``t = 0``.
    per_row : int
        Integration steps a row.
    step : float
        The integration step [s].

    Raises
    ------
    ValueError
        One line: an output period longer than the run, an output rate a sampled
        controller's rate is no multiple of, or too many rows or steps (and the remedy).

    Examples
    --------
    >>> time_series_grid(1.0, 1000.0, 2.5e-4)
    (1001, 4, 0.00025)
    >>> try:
    ...     time_series_grid(1e6, 10_000.0, 1e-4, at_least=True)
    ... except ValueError as exc:
    ...     print(str(exc)[:60])
    10000000001 rows of at least 1 steps each: too many time ste
    """
    period_out = 1.0 / output_rate_hz
    if period_out > duration:
        raise ValueError(f"the output period 1/{output_rate_hz:g} Hz is longer than the "
                         f"duration {duration:g} s")
    per_row = max(1, math.ceil(period_out / step * (1 - 1e-12)))
    step = period_out / per_row
    if sample_rate_hz is not None:   # rows at every per_row-th of the controller's samples
        step = 1.0 / sample_rate_hz
        per_row = round(period_out / step)
        if per_row < 1 or abs(per_row * step - period_out) > 1e-9 * period_out:
            raise ValueError(f"the output rate {output_rate_hz:g} Hz must divide the sampled "
                             f"controller's rate {sample_rate_hz:g} Hz")
    n_rows = math.floor(duration / period_out * (1 + 1e-12)) + 1
    if n_rows > MAX_ROWS or n_rows * per_row > MAX_STEPS:
        fast = "" if per_row < 1000 else (f" (a step of {step:.3g} s follows the "
                                          f"reference's frequency)")
        raise ValueError(f"{n_rows} rows of {'at least ' if at_least else ''}{per_row} steps "
                         f"each: too many time steps{fast}; lower the frequency, the output "
                         f"rate or the duration (at most {MAX_ROWS:.0e} rows, "
                         f"{MAX_STEPS:.0e} steps)")
    return n_rows, per_row, step
