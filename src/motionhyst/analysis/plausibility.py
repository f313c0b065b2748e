"""Plausibility of a sine analysis: where the paper's quasi-linear reading stops holding.

Each finding is a :class:`~motionhyst.core.warnings.MotionhystWarning`; the
computation goes on (:func:`check_plausible`).  A frequency outside what the loop's
model can mean at all is refused instead (:func:`check_frequency_range`).
:func:`~motionhyst.analysis.quasilinear.analyze` and
:func:`~motionhyst.analysis.comparison.compare_with_describing_function`
check their arguments here themselves.

Examples
--------
>>> import warnings
>>> from motionhyst import default_scenario
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     check_plausible(default_scenario().loop(), 0.01, [0.05, 5.0])
>>> print(caught[0].message)                            # doctest: +ELLIPSIS
0.05 Hz below f* = 0.15 Hz (eq. 13): the link shapes the plant there, ...
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from motionhyst.core.warnings import warn

__all__ = ["DECADES_ABOVE", "PLAUSIBLE_AMPLITUDE_M", "check_frequencies", "check_frequency_range",
           "check_plausible", "check_stroke"]

DECADES_ABOVE = 2
"""How far (decades) a sine's frequency may lie above the loop's fastest closed-loop pole."""

PLAUSIBLE_AMPLITUDE_M = 2.0
"""Largest reference amplitude of a motion stage [m] (half its stroke: a wafer stage's is
some 0.2 m, a long gantry's a metre or two): beyond, a warning asks for the unit (10 for
10 mm is 10 m)."""


def check_plausible(loop, amplitude: float, frequencies_hz: Iterable[float],
                    stacklevel: int = 2) -> None:
    """Warn where a sine of `amplitude` at `frequencies_hz` leaves the model's meaning.

    - a frequency below ``f*`` (eq. 13): the quasi-linear plant no longer
      tends to the floating mass ``P2``, so eq. (20) and the crossover of
      eq. (21) do not apply;
    - an amplitude at which the element never slips (``zeta = fc / (k A) >= 1``,
      eq. 4): it is a linear spring at every frequency asked, no hysteresis to see;
    - a frequency outside a measured plant's data (the plant is extrapolated);
    - an amplitude above :data:`PLAUSIBLE_AMPLITUDE_M` (a unit slip: millimetres).

    Parameters
    ----------
    loop : Loop
        The loop analysed; without a link only the measured-data check applies.
    amplitude : float
        Reference amplitude ``A_r`` [m].
    frequencies_hz : iterable of float
        The frequencies asked [Hz].
    stacklevel : int
        As for :func:`motionhyst.core.warnings.warn`: 2 names the caller's line.

    Examples
    --------
    >>> import warnings
    >>> from motionhyst import default_scenario
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     check_plausible(default_scenario().loop(), 0.001, [5.0])   # zeta = 2.5
    >>> print(caught[0].message)                        # doctest: +ELLIPSIS
    at amplitude 0.001 m the element never slips (zeta = fc / (k A) = 2.5 >= 1): ...
    """
    from motionhyst.analysis.equations import f_star

    el = loop.hysteresis
    freqs = [float(f) for f in frequencies_hz]
    level = stacklevel + 1
    if amplitude > PLAUSIBLE_AMPLITUDE_M:
        warn(f"amplitude {amplitude:g} m, above the {PLAUSIBLE_AMPLITUDE_M:g} m of a motion "
             f"stage's half stroke: is it in m?", level)
    if el is not None:
        fs = f_star(el.initial_stiffness, loop.M)
        low = [f for f in freqs if f < fs]
        if low:
            warn(f"{', '.join(f'{f:g}' for f in low)} Hz below f* = {fs:.3g} Hz (eq. 13): the "
                 f"link shapes the plant there, the asymptote of eq. (20) and the crossover of "
                 f"eq. (21) do not apply", level)
        if el.defines_zeta and float(el.zeta(amplitude)) >= 1.0:
            warn(f"at amplitude {amplitude:g} m the element never slips (zeta = fc / (k A) = "
                 f"{float(el.zeta(amplitude)):.3g} >= 1): it is a linear spring at every "
                 f"frequency asked, there is no hysteresis to see", level)
    data = loop.plant.frequency_range_hz
    if data is not None:
        lo, hi = data
        out = [f for f in freqs if f < lo or f > hi]
        if out:
            warn(f"{', '.join(f'{f:g}' for f in out)} Hz outside the measured plant's data "
                 f"({lo:g}-{hi:g} Hz): the plant there is extrapolated", level)


def check_stroke(length: float, what: str, stacklevel: int = 2) -> None:
    """Warn of a move or a scan longer than a motion stage's stroke (twice
    :data:`PLAUSIBLE_AMPLITUDE_M`): a unit slip (millimetres) likelier than a stage of a
    kilometre, and a run as long as it.

    Parameters
    ----------
    length : float
        The move's length [m] (its sign is its direction).
    what : str
        The option or key that gives it, as the warning names it.
    stacklevel : int
        As for :func:`motionhyst.core.warnings.warn`.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     check_stroke(0.3, "--distance")
    ...     check_stroke(-1000.0, "--distance")
    >>> print(caught[0].message)
    --distance -1000 m, longer than the 4 m stroke of a motion stage: is it in m?
    """
    if abs(length) > 2 * PLAUSIBLE_AMPLITUDE_M:
        warn(f"{what} {length:g} m, longer than the {2 * PLAUSIBLE_AMPLITUDE_M:g} m stroke of a "
             f"motion stage: is it in m?", stacklevel + 1)


def check_frequencies(frequencies_hz: Iterable[float], fastest_pole_hz: float | None = None,
                      sample_rate_hz: float | None = None) -> None:
    """Refuse a frequency at which a sine analysis of a loop means nothing: more than
    :data:`DECADES_ABOVE` decades above the loop's fastest closed-loop pole (for a sampled
    loop, above its sampling rate if that is higher).  Neither the controller nor the stage
    follows the reference there, the error is the reference itself (``|E| = 1``), and an
    exact steady state only spends its time on the periods the loop's slow modes take to
    forget their start (25 s of CPU at 1e5 Hz, 17 s at 1e9 Hz for Table I).

    A frequency below ``f*`` (eq. 13) is not refused: the link shapes the plant there, which
    :func:`check_plausible` says; a stiff link's ``f*`` is tens of hertz.

    Only numbers: a command checks its scenario here before python-control loads.

    Parameters
    ----------
    frequencies_hz : iterable of float
        The frequencies asked [Hz].
    fastest_pole_hz : float, optional
        The magnitude of the loop's fastest closed-loop pole over 2 pi [Hz].
    sample_rate_hz : float, optional
        A sampled controller's rate [Hz].

    Raises
    ------
    ValueError
        Naming the first frequency outside and the range, before any work.

    Examples
    --------
    >>> check_frequencies([1e-30, 5.0, 1e4], fastest_pole_hz=691.0)
    >>> check_frequencies([1e9], fastest_pole_hz=691.0)
    Traceback (most recent call last):
    ...
    ValueError: 1e+09 Hz is more than 2 decades above the loop's fastest closed-loop pole \
(691 Hz): nothing follows a reference there (|E| = 1); give frequencies up to 6.91e+04 Hz
    """
    freqs = [float(f) for f in frequencies_hz]
    factor = 10.0 ** DECADES_ABOVE
    fastest, rate = fastest_pole_hz or 0.0, sample_rate_hz or 0.0
    top = max(fastest, rate)
    high = [f for f in freqs if top > 0 and f > top * factor]
    if high:
        what = (f"fastest closed-loop pole ({fastest:.3g} Hz)" if fastest >= rate
                else f"sampling rate ({rate:g} Hz)")
        raise ValueError(f"{high[0]:g} Hz is more than {DECADES_ABOVE} decades above the "
                         f"loop's {what}: nothing follows a reference there (|E| = 1); give "
                         f"frequencies up to {top * factor:.3g} Hz")


def check_frequency_range(loop, frequencies_hz: Iterable[float]) -> None:
    """:func:`check_frequencies` for `loop`: its fastest closed-loop pole (none for measured
    data) and a sampled controller's rate.

    Parameters
    ----------
    loop : Loop
        The loop analysed.
    frequencies_hz : iterable of float
        The frequencies asked [Hz].

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> loop = default_scenario().loop()
    >>> check_frequency_range(loop, [0.01, 5.0, 1e4])                 # Table I: fine
    >>> check_frequency_range(loop, [1e9])
    Traceback (most recent call last):
    ...
    ValueError: 1e+09 Hz is more than 2 decades above the loop's fastest closed-loop pole \
(691 Hz): nothing follows a reference there (|E| = 1); give frequencies up to 6.91e+04 Hz
    """
    try:
        poles = loop.closed_loop_poles()
    except ValueError:  # measured data: no poles (its data range is warned about)
        poles = []
    fastest = max((abs(p) for p in poles), default=0.0) / (2 * math.pi)
    check_frequencies(frequencies_hz, fastest,
                      None if loop.sampled is None else loop.sampled.sample_rate_hz)
