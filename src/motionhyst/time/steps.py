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

import contextlib
import math
from collections.abc import Iterator, Sequence

from motionhyst.core.budget import BudgetError, check_memory, check_work

__all__ = [
    "BYTES_PER_SAMPLE",
    "IMPLICIT_STEP_MARGIN",
    "MAX_ROWS",
    "MAX_SAMPLES",
    "MAX_SCAN_STEPS",
    "MAX_STEPS",
    "RUN_REMEDY",
    "SAMPLED_MIN_SUBSTEPS",
    "SAMPLED_SAMPLE_BYTES",
    "SAMPLED_STEPS_PER_MODE_PERIOD",
    "SCAN_REMEDY",
    "SECONDS_PER_ELEMENT_STEP",
    "SECONDS_PER_ROW",
    "SECONDS_PER_STEP",
    "STEPS_PER_POLE_PERIOD",
    "STEPS_PER_REFERENCE_PERIOD",
    "WHOLE_DELAY_TOLERANCE",
    "RunTooLarge",
    "a_run",
    "check_link_damping",
    "check_scan_steps",
    "check_steps_work",
    "damping_factor",
    "longest_step",
    "pole_step",
    "run_delay",
    "sampled_step",
    "sampled_steps",
    "sampled_substeps",
    "step_set_by",
    "time_series_grid",
]

STEPS_PER_POLE_PERIOD = 40
"""Time steps per period of the loop's fastest closed-loop pole."""

STEPS_PER_REFERENCE_PERIOD = 400
"""Time steps per period of the reference's highest frequency."""

BYTES_PER_SAMPLE = 160
"""Memory of one time sample of a run: its signals and the loop's intermediate arrays [bytes]."""

SAMPLED_SAMPLE_BYTES = 200
"""Memory of one controller sample of a run of a loop with a sampled controller, which is held
whole: the reference and the feedforward at the samples, the signals of the run and of the
run without the link, the kernel's arrays [bytes] (measured, Table I at 10 kHz with a file's
or a sine reference, 1e4-3e5 samples: 164-176 traced and of address space; 20 % above).
"""

MAX_SCAN_STEPS = 50_000_000
"""Most time steps of one run of a scan (each run keeps its signals)."""

MAX_SAMPLES = 50_000_000
"""Most controller samples of one run of a loop with a sampled controller."""

MAX_ROWS = 100_000_000
"""Most rows a time series writes (about 10 GB of CSV)."""

MAX_STEPS = 200_000_000
"""Most integration steps of a time series (the work budget: some minutes at about 1.5 us a
step)."""

SECONDS_PER_STEP = 1.5e-6
"""Nominal cost of one time step of a run [s] (one core of a quiet machine)."""

SECONDS_PER_ROW = 2.5e-6
"""Nominal cost of one CSV row of a time series written [s] (its samples taken and eight
numbers formatted: 1e6 rows of 1e6 steps took 4 s against 1.5 s for the steps alone)."""

SECONDS_PER_ELEMENT_STEP = 100e-9
"""Nominal cost of one element of the link (a Maxwell-slip link's stop operators) in one
time step [s]: a link of 1e5 elements makes a step 7000 times dearer."""

RUN_REMEDY = "shorten the duration or lower the reference's frequencies"
"""What the caller of :func:`~motionhyst.time.simulation.simulate` can change to make a run
smaller (its arguments); a command says its own options instead."""

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


IMPLICIT_STEP_MARGIN = 1.0
"""A link's damping is refused before a run when it would amplify a change of the link's
force over one step by more than this (:func:`check_link_damping`): above 1 the step's
fixed-point iteration diverges.  Measured on Table I's stage (m1 of 2, 5 and 20 kg, a LuGre
link): runs fail from a factor of 0.6 on (their 50 passes do not reach the tolerance) and
converge at 0.5, so the coupling of the link's mass to the rest of the stage within a step,
which the factor leaves out, refuses no run that would converge.  The runs of a sampled
loop's fine steps and of an open-loop system (``predict``) fail from 0.34-0.6 on (sigma1 or
sigma2 of a LuGre link; 0.5-20 kg, 1-20 kHz, delays of 0-1.5 samples); above the margin
some of them end, their answer meaningless (a 30 N force moving a damped 2 kg axis by
100-1000 m, a loop's link force of 3e10 N)."""

SAMPLED_MIN_SUBSTEPS = 2
"""Fine steps per controller period of a sampled loop's run at least (room for a fractional
delay's split)."""

SAMPLED_STEPS_PER_MODE_PERIOD = 40
"""Fine steps of a sampled loop's run per period of the plant's fastest mode (the link taken
as its initial stiffness), as :data:`STEPS_PER_POLE_PERIOD` per period of a continuous
loop's fastest pole."""

WHOLE_DELAY_TOLERANCE = 1e-6
"""A sampled run takes a delay within this many samples of a whole number as that number
(:func:`run_delay`)."""


def run_delay(delay_samples: float) -> float:
    """The delay a sampled loop's run takes [samples]: `delay_samples`, or the whole number
    within :data:`WHOLE_DELAY_TOLERANCE` of it.

    A delay a hair off a whole number (``3 * 0.1 / 0.1 = 3.0000000000000004``, a latency
    times a rate) would split each period at a fine step of 4e-20 s, over which the motion's
    change is rounding: a damped link's rates from it (LuGre's ``sigma2 v``) are noise (the
    paper's loop at 10 kHz, LuGre sigma2 = 1e3 N s/m: e1 24 % off).  Shifting the force by
    at most 1e-6 of a sample (0.1 ns at 10 kHz) changes the run by less than its steps'
    error.

    Parameters
    ----------
    delay_samples : float
        The controller's delay [samples], >= 0.

    Returns
    -------
    float
        The delay run.

    Examples
    --------
    >>> run_delay(3.0000000000000004), run_delay(2.9999999999999996), run_delay(1.05)
    (3.0, 3.0, 1.05)
    """
    d = float(delay_samples)
    whole = round(d)
    return float(whole) if abs(d - whole) <= WHOLE_DELAY_TOLERANCE else d


def sampled_substeps(period: float, delay_samples: float = 0.0, substeps: int | None = None,
                     natural_frequency_hz: float = 0.0) -> tuple[int, int, float, float]:
    """The fine steps of a sampled loop's run (:func:`motionhyst.time.engine.run_sampled`):
    how many a controller period, and their lengths.

    A fractional delay ``frac(d)`` splits the period at ``(1 - frac(d)) T``: ``r1`` steps of
    ``frac(d) T / r1`` after the split (the delayed force applied), the others before it; a
    delay within :data:`WHOLE_DELAY_TOLERANCE` of a whole number splits none
    (:func:`run_delay`).

    Parameters
    ----------
    period : float
        The controller's period ``T`` [s].
    delay_samples : float
        Its delay ``d`` [samples], >= 0.
    substeps : int, optional
        Fine steps a period asked for (>= 1); default: at least
        :data:`SAMPLED_MIN_SUBSTEPS` and :data:`SAMPLED_STEPS_PER_MODE_PERIOD` a period of
        `natural_frequency_hz`.
    natural_frequency_hz : float
        The plant's fastest mode with the link [Hz] (for the default).

    Returns
    -------
    R : int
        Fine steps a period.
    r1 : int
        Of them, the steps after a fractional delay's split (0 without one).
    h : float
        Length of the other ``R - r1`` steps [s].
    h1 : float
        Length of the `r1` steps [s] (0 without them).

    Raises
    ------
    ValueError
        For `substeps` below 1.

    Examples
    --------
    >>> sampled_substeps(1e-4, 1.5, natural_frequency_hz=694.3)   # the paper's loop at 10 kHz
    (3, 2, 5e-05, 2.5e-05)
    >>> sampled_substeps(1e-3, 1.0, natural_frequency_hz=694.3)   # at 1 kHz
    (28, 0, 3.5714285714285716e-05, 0.0)
    >>> sampled_substeps(1e-4, 3 * 0.1 / 0.1, natural_frequency_hz=694.3)   # 3.0000000000000004
    (3, 0, 3.3333333333333335e-05, 0.0)
    """
    if substeps is None:
        substeps = max(SAMPLED_MIN_SUBSTEPS,
                       math.ceil(SAMPLED_STEPS_PER_MODE_PERIOD * natural_frequency_hz * period))
    R = int(substeps)
    if R < 1:
        raise ValueError("substeps must be >= 1")
    d = run_delay(delay_samples)
    frac = d - math.floor(d)
    if frac > 0.0:
        r1 = min(max(1, round(frac * R)), R - 1) if R > 1 else 1
        r2 = max(R - r1, 1)
        return r1 + r2, r1, (1.0 - frac) * period / r2, frac * period / r1
    return R, 0, period / R, 0.0


def sampled_steps(plant, link, sample_rate_hz: float, delay_samples: float = 0.0
                  ) -> tuple[float, float]:
    """The fine steps of a sampled loop's run [s] (:func:`sampled_substeps`, by default),
    known before its loop is built: the longest, and the other where the delay splits a
    controller period into steps of two lengths.

    Parameters
    ----------
    plant : Plant
        The stage (its :meth:`mechanics` gives its fastest mode).
    link : Hysteresis or None
        The link (its initial stiffness stiffens that mode).
    sample_rate_hz : float
        The controller's rate [Hz].
    delay_samples : float
        Its delay [samples].

    Returns
    -------
    tuple of float
        The longest step and the shorter (0 where all are of one length); the controller's
        period and 0 for a plant without lumped masses.

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> sampled_steps(stage, Jenkins(k=20.0, fc=0.05), 10_000.0, 1.5)
    (5e-05, 2.5e-05)
    >>> sampled_steps(stage, Jenkins(k=20.0, fc=0.05), 10_000.0, 1.0)
    (3.3333333333333335e-05, 0.0)
    """
    period = 1.0 / sample_rate_hz
    try:
        mech = plant.mechanics()
        k = 0.0 if link is None else float(getattr(link, "initial_stiffness", 0.0))
        f_n = float(mech.natural_frequency_hz(k))
    except (AttributeError, TypeError, ValueError, NotImplementedError):
        return period, 0.0
    _, r1, h, h1 = sampled_substeps(period, delay_samples, natural_frequency_hz=f_n)
    return max(h, h1), (min(h, h1) if r1 and h != h1 else 0.0)


def sampled_step(plant, link, sample_rate_hz: float, delay_samples: float = 0.0) -> float:
    """The longest fine step of a sampled loop's run [s] (:func:`sampled_steps`' first).

    Parameters
    ----------
    plant : Plant
        The stage (its :meth:`mechanics` gives its fastest mode).
    link : Hysteresis or None
        The link (its initial stiffness stiffens that mode).
    sample_rate_hz : float
        The controller's rate [Hz].
    delay_samples : float
        Its delay [samples].

    Returns
    -------
    float
        The step; the controller's period for a plant without lumped masses.

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> sampled_step(stage, Jenkins(k=20.0, fc=0.05), 10_000.0, 1.5)
    5e-05
    """
    return sampled_steps(plant, link, sample_rate_hz, delay_samples)[0]


def damping_factor(link, plant, step: float, shorter: float = 0.0) -> float:
    """The factor by which a link's damping amplifies each pass of a run's implicit step
    (:func:`check_link_damping`); 0 for a link without damping or a plant without lumped
    masses.

    Parameters
    ----------
    link : Hysteresis
        The link (its ``small_amplitude_limit`` gives its damping, where it has one).
    plant : Plant or Mechanics
        The stage (its :meth:`mechanics` gives the mass the link moves), or its lumped
        masses.
    step : float
        The run's (longest) time step [s].
    shorter : float
        A sampled run's other fine step [s], which `step` follows once a controller period
        (:func:`sampled_steps`); 0: all steps of length `step`.

    Returns
    -------
    float
        ``c step a / (6 m)`` with ``a`` the weight of the step's change in its rate by the
        backward difference (:func:`~motionhyst.hysteresis.stepping.backward_weights`):
        ``1 + step / (step + shorter)`` after a shorter step, 1.5 (``c step / (4 m)``)
        after one as long.

    Examples
    --------
    >>> from motionhyst.hysteresis import LuGre
    >>> from motionhyst.plants import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> link = LuGre(20.0, 1e7, 0.0, 0.05, 0.07, 0.1)
    >>> print(f"{damping_factor(link, stage, 3.62e-5):.3g}")
    18.1
    >>> print(f"{damping_factor(link, stage, 4.75e-5, 5e-6):.3g}")   # 1.05 samples at 10 kHz
    30.2
    """
    small = getattr(link, "small_amplitude_limit", None)
    mass = _link_mass(plant)
    if small is None or mass is None or not step > 0:
        return 0.0
    c = float(complex(small(1.0)).imag)
    if 0.0 < shorter < step:
        return c * step * (1.0 + step / (step + shorter)) / (6.0 * mass)
    return c * step / (4.0 * mass)


def _link_mass(plant) -> float | None:
    """The mass the link moves [kg] of a plant (or of its lumped masses themselves); None
    without them."""
    try:
        mech = plant.mechanics() if callable(getattr(plant, "mechanics", None)) else plant
        return float(mech.mass[mech.link])
    except (AttributeError, IndexError, TypeError, ValueError, NotImplementedError):
        return None


def check_link_damping(link, plant, step: float, where: str = "", shorter: float = 0.0
                       ) -> None:
    """Refuse a link whose damping is too strong for a run's time step, before the run.

    The run's implicit step settles the link force by a fixed-point iteration: a change of
    the force (ramped over the step, as the run holds it) moves the link's mass ``m`` by
    ``step^2 / (6 m)`` per newton, and a damping ``c`` (the link's for small motions,
    ``Im D / omega``: LuGre's ``sigma1 + sigma2`` from rest) turns that back into a force
    through the velocity at the step's end, ``1.5 / step`` per metre (the second-order
    backward difference; up to ``2 / step`` after a shorter step, as a sampled run's longer
    fine step follows its shorter once a period: `shorter`).  Their product ``c step / (4 m)``
    (:func:`damping_factor`) is the factor by which each pass amplifies the error: above 1
    the iteration diverges at the stage's first motion and the run stops there, after its
    loop is built and its kernels loaded, or, where a pass happens to settle, ends with a
    motion that is no solution (:data:`IMPLICIT_STEP_MARGIN`).  The same holds for the fine
    steps of a sampled loop's run (:func:`sampled_steps`) and for an open-loop system's.  A
    link without damping (a rate-independent one), a plant without lumped masses, or a
    factor within :data:`IMPLICIT_STEP_MARGIN` passes: the run judges it (one whose
    iteration converges too slowly still stops it).

    Parameters
    ----------
    link : Hysteresis
        The link (its ``small_amplitude_limit`` gives its damping, where it has one).
    plant : Plant or Mechanics
        The stage (its :meth:`mechanics` gives the mass the link moves), or its lumped
        masses.
    step : float
        The run's time step [s].
    where : str
        What to name in the message (the scenario's section).
    shorter : float
        A sampled run's other fine step [s] (:func:`damping_factor`); 0: none.

    Raises
    ------
    ValueError
        One line naming the damping, the mass, the step and the factor.

    Examples
    --------
    >>> from motionhyst.hysteresis import LuGre
    >>> from motionhyst.plants import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> link = LuGre(sigma0=20.0, sigma1=0.0, sigma2=1e3, fc=0.05, fs=0.07, vs=0.1)
    >>> check_link_damping(link, stage, 3.62e-5)                 # factor 0.0018: runs
    >>> try:
    ...     check_link_damping(LuGre(20.0, 1e7, 0.0, 0.05, 0.07, 0.1), stage, 3.62e-5)
    ... except ValueError as exc:
    ...     print(exc)
    the link's damping for small motions, 1e+07 N s/m on the 5 kg it moves, is too strong \
for the time step of 3.62e-05 s: it would amplify each pass of the step's implicit \
iteration 18.1 times (it settles below 1): the run would stop at the stage's first motion \
or end in a motion that is no solution
    """
    factor = damping_factor(link, plant, step, shorter)
    if factor > IMPLICIT_STEP_MARGIN:
        mass = float(_link_mass(plant))
        damping = float(complex(link.small_amplitude_limit(1.0)).imag)
        raise ValueError(f"{where}the link's damping for small motions, {damping:.4g} N s/m on "
                         f"the {mass:.4g} kg it moves, is too strong for the time step of "
                         f"{step:.3g} s: it would amplify each pass of the step's implicit "
                         f"iteration {factor:.3g} times (it settles below 1): the run would "
                         f"stop at the stage's first motion or end in a motion that is no "
                         f"solution")


class RunTooLarge(BudgetError):
    """A time run refused for its size (steps, rows, memory or work) before it starts.

    Its :attr:`remedy` names the library function's arguments (a duration, a
    reference); a command names its own options instead
    (:meth:`~motionhyst.core.budget.BudgetError.with_remedy`), and only for these
    refusals, not for others of the same command (a measured plant's fit).

    Parameters
    ----------
    cause : str
        What is too large (the steps, the rows), and the limit.
    remedy : str
        What the caller can change.

    Examples
    --------
    >>> err = RunTooLarge("6e+07 time steps of 1e-06 s: too many", "shorten the duration")
    >>> print(err.with_remedy("shorten --tail"))
    6e+07 time steps of 1e-06 s: too many; shorten --tail
    >>> isinstance(err, ValueError), type(err.with_remedy("")).__name__
    (True, 'RunTooLarge')
    """


@contextlib.contextmanager
def a_run() -> Iterator[None]:
    """A budget refusal inside (:func:`~motionhyst.core.budget.check_memory`,
    :func:`~motionhyst.core.budget.check_work`) raised as the :class:`RunTooLarge` it is.

    Examples
    --------
    >>> from motionhyst.core.budget import set_max_memory
    >>> set_max_memory(1 << 20)
    >>> try:
    ...     with a_run():
    ...         check_memory(1e9, "a run of 6e6 time steps", "shorten the duration")
    ... except RunTooLarge as exc:
    ...     print(exc.remedy)
    shorten the duration
    >>> set_max_memory(None)
    """
    try:
        yield
    except RunTooLarge:
        raise
    except BudgetError as exc:
        raise RunTooLarge(exc.cause, exc.remedy) from None


def step_set_by(fastest_pole: float, max_frequency_hz: float = 0.0) -> str:
    """What sets :func:`pole_step` of a loop and a reference, for messages.

    Parameters
    ----------
    fastest_pole : float
        The largest magnitude of the loop's closed-loop poles [rad/s], > 0.
    max_frequency_hz : float
        The reference's highest frequency [Hz]; 0: none sets the step.

    Returns
    -------
    str
        The loop's fastest pole or the reference's frequency, with its frequency.

    Examples
    --------
    >>> step_set_by(4344.0, 5.0)
    "the loop's fastest closed-loop pole, 691.4 Hz, resolved in 40 steps"
    >>> step_set_by(1.0, 25.0)
    "the reference's 25 Hz, resolved in 400 steps a period"
    """
    if max_frequency_hz > 0 and pole_step(fastest_pole, max_frequency_hz) < pole_step(
            fastest_pole):
        return (f"the reference's {max_frequency_hz:.4g} Hz, resolved in "
                f"{STEPS_PER_REFERENCE_PERIOD} steps a period")
    return (f"the loop's fastest closed-loop pole, {fastest_pole / math.tau:.4g} Hz, resolved "
            f"in {STEPS_PER_POLE_PERIOD} steps")


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
    RunTooLarge
        One line: the count, the step and `remedy` (a ``ValueError``).

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
        raise RunTooLarge(f"{'at least ' if at_least else ''}{n} time steps of {step:.3g} s: "
                          f"too many", remedy)
    with a_run():
        check_memory(n * BYTES_PER_SAMPLE * (runs + 2),
                     f"a scan of {runs} runs of {'at least ' if at_least else ''}{n:.3g} time "
                     f"steps each", remedy)
    return n


def _element_count(link) -> int:
    """The elements the time step advances for `link` (0 without a link)."""
    if link is None:
        return 0
    try:
        return int(link.time_stepping().codes.size)
    except (ValueError, AttributeError):  # advanced otherwise (along the stroke): one
        return 1


def check_steps_work(n_steps: int, links: Sequence, remedy: str, rows: int = 0) -> None:
    """Refuse a run of `n_steps` time steps of `links` above the work budget, before it
    starts (known before the loop is built: a scenario's link gives its elements).

    Its work is the steps times :data:`SECONDS_PER_STEP` and the links' elements (a
    Maxwell-slip link's stop operators) times :data:`SECONDS_PER_ELEMENT_STEP`, and the
    rows it writes times :data:`SECONDS_PER_ROW` (:func:`motionhyst.core.budget.check_work`).

    Parameters
    ----------
    n_steps : int
        The run's time steps.
    links : sequence of Hysteresis or None
        The links the run advances (the loop's, its feedforward model's).
    remedy : str
        What the user can change, for the message.
    rows : int
        The CSV rows the run writes (a time series).

    Raises
    ------
    RunTooLarge
        One line: the run's steps and elements (and rows), its estimated time, the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_seconds
    >>> from motionhyst.hysteresis import MaxwellSlip
    >>> link = MaxwellSlip(k=[20.0] * 3000, fc=[0.05] * 3000)
    >>> check_steps_work(5_000, [link, None], "shorten the setpoint")     # about 1.5 s
    >>> set_max_seconds(1.0)
    >>> try:
    ...     check_steps_work(5_000, [link, None], "shorten the setpoint")
    ... except BudgetError as exc:
    ...     print(exc)
    a run of 5e+03 time steps of a link of 3000 elements would take about 1.5 s, above the \
work budget of 1 s (--max-seconds); shorten the setpoint, or give the link fewer elements
    >>> set_max_seconds(None)
    """
    m = sum(_element_count(link) for link in links)
    seconds = n_steps * (SECONDS_PER_STEP + m * SECONDS_PER_ELEMENT_STEP) + rows * SECONDS_PER_ROW
    of = f" of a link of {m} elements" if m > 2 else ""
    written = f", {rows:.3g} rows written" if rows else ""
    with a_run():
        check_work(seconds, f"a run of {n_steps:.3g} time steps{of}{written}",
                   remedy + (", or give the link fewer elements" if of else ""))


def time_series_grid(duration: float, output_rate_hz: float, step: float,
                     sample_rate_hz: float | None = None, at_least: bool = False,
                     set_by: str = "") -> tuple[int, int, float]:
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
    set_by : str
        What sets `step`, for the message (:func:`step_set_by`); "": the message does not say.

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
        controller's rate is no multiple of, or too many rows or steps (a
        :class:`RunTooLarge`, with the remedy).

    Examples
    --------
    >>> time_series_grid(1.0, 1000.0, 2.5e-4)
    (1001, 4, 0.00025)
    >>> try:
    ...     time_series_grid(1e6, 10_000.0, 1e-4, at_least=True)
    ... except ValueError as exc:
    ...     print(str(exc)[:60])
    10000000001 rows of at least 1 steps each: too many time ste
    >>> try:
    ...     time_series_grid(6000.0, 10_000.0, 1e-4, sample_rate_hz=10_000.0)
    ... except RunTooLarge as exc:
    ...     print(exc)
    60000001 controller samples at 10000 Hz: too many (at most 5e+07); shorten the duration
    """
    period_out = 1.0 / output_rate_hz
    if period_out > duration:
        raise ValueError(f"the output period 1/{output_rate_hz:g} Hz is longer than the "
                         f"duration {duration:g} s")
    per_row = max(1, math.ceil(period_out / step * (1 - 1e-12)))
    if per_row == 1 and period_out < step * (1 - 1e-12) and sample_rate_hz is None:
        set_by = f"a row every step, at the output rate {output_rate_hz:g} Hz"
    step = period_out / per_row
    if sample_rate_hz is not None:   # rows at every per_row-th of the controller's samples
        step = 1.0 / sample_rate_hz
        per_row = round(period_out / step)
        if per_row < 1 or abs(per_row * step - period_out) > 1e-9 * period_out:
            raise ValueError(f"the output rate {output_rate_hz:g} Hz must divide the sampled "
                             f"controller's rate {sample_rate_hz:g} Hz")
    n_rows = math.floor(duration / period_out * (1 + 1e-12)) + 1
    if sample_rate_hz is not None and math.floor(duration * sample_rate_hz + 1e-9) >= MAX_SAMPLES:
        raise RunTooLarge(f"{math.floor(duration * sample_rate_hz + 1e-9) + 1} controller "
                          f"samples at {sample_rate_hz:g} Hz: too many (at most "
                          f"{MAX_SAMPLES:.0e})", "shorten the duration")
    if n_rows > MAX_ROWS or n_rows * per_row > MAX_STEPS:
        why = f" (a step of {step:.3g} s: {set_by})" if set_by else ""
        raise RunTooLarge(f"{n_rows} rows of {'at least ' if at_least else ''}{per_row} steps "
                          f"each: too many time steps{why} (at most {MAX_ROWS:.0e} rows, "
                          f"{MAX_STEPS:.0e} steps)", "lower the frequency, the output rate "
                          "or the duration")
    return n_rows, per_row, step
