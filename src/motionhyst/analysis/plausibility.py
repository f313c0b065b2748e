"""Plausibility of a sine analysis: where the paper's quasi-linear reading stops holding.

Each finding is a :class:`~motionhyst.core.warnings.MotionhystWarning`; the
computation goes on.  :func:`~motionhyst.analysis.quasilinear.analyze` and
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

from collections.abc import Iterable

from motionhyst.analysis.equations import f_star
from motionhyst.core.warnings import warn

__all__ = ["check_plausible"]


def check_plausible(loop, amplitude: float, frequencies_hz: Iterable[float],
                    stacklevel: int = 2) -> None:
    """Warn where a sine of `amplitude` at `frequencies_hz` leaves the model's meaning.

    - a frequency below ``f*`` (eq. 13): the quasi-linear plant no longer
      tends to the floating mass ``P2``, so eq. (20) and the crossover of
      eq. (21) do not apply;
    - an amplitude at which the element never slips (``zeta = fc / (k A) >= 1``,
      eq. 4): it is a linear spring at every frequency asked, no hysteresis to see;
    - a frequency outside a measured plant's data (the plant is extrapolated).

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
    el = loop.hysteresis
    freqs = [float(f) for f in frequencies_hz]
    level = stacklevel + 1
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
