"""The describing function of one link element over amplitudes (and frequencies).

Paper eq. (7), for the Jenkins element eq. (10); with ``harmonics`` also the
higher-order sinusoidal-input describing functions ``H_n = Y_n / A``.  This is
what ``motionhyst df`` prints: :func:`describing_function` computes a
:class:`DescribingFunctionResult`, which prints itself as the command's table,
gives the ``--json`` schema through :meth:`~DescribingFunctionResult.to_dict`
and draws ``|D| / k_init`` and the angle of ``D`` against the amplitude.

Examples
--------
>>> from motionhyst import Jenkins
>>> res = describing_function(Jenkins(k=20.0, fc=0.05), [0.005, 0.01])
>>> [round(p.zeta, 2) for p in res.points]                # eq. (4)
[0.5, 0.25]
>>> [round(abs(p.value), 3) for p in res.points]          # |D| [N/m], eq. (10)
[11.854, 6.171]
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis import Hysteresis

__all__ = ["DescribingFunctionPoint", "DescribingFunctionResult", "describing_function"]


@dataclass
class DescribingFunctionPoint:
    """The describing function at one amplitude (and frequency).

    Attributes
    ----------
    amplitude : float
        Input amplitude ``A`` [m] of ``x = A sin(omega t)``.
    frequency_hz : float or None
        Frequency [Hz]; None for a rate-independent element.
    zeta : float
        ``fc / (k A)`` (eq. 4); nan for a model that does not define it.
    value : complex
        ``D`` (eq. 7) [N/m].
    harmonics : ndarray of complex or None
        ``H_1 .. H_N`` [N/m], relative to ``sin(n omega t)``; None if not asked.

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> p = describing_function(Jenkins(k=20.0, fc=0.05), [0.01]).points[0]
    >>> sorted(p.to_dict())
    ['abs', 'amplitude', 'im', 'phase_deg', 're', 'zeta']
    """

    amplitude: float
    frequency_hz: float | None
    zeta: float
    value: complex
    harmonics: NDArray[np.complex128] | None = None

    def to_dict(self) -> dict:
        """JSON-ready dictionary: one point of the ``df --json`` schema."""
        D = self.value
        d: dict = {"amplitude": float(self.amplitude)}
        if self.frequency_hz is not None:
            d["frequency_hz"] = float(self.frequency_hz)
        d.update({"zeta": float(self.zeta), "re": float(D.real), "im": float(D.imag),
                  "abs": float(abs(D)), "phase_deg": float(np.degrees(np.angle(D)))})
        if self.harmonics is not None:
            d["harmonics"] = [{"n": n, "re": float(c.real), "im": float(c.imag),
                               "abs_over_amplitude": float(abs(c)),
                               "phase_deg": float(np.degrees(np.angle(c)))}
                              for n, c in enumerate(self.harmonics, start=1)]
        return d


@dataclass
class DescribingFunctionResult:
    """Result of :func:`describing_function`: ``D`` (eq. 7) of a link at its amplitudes.

    Attributes
    ----------
    link : Hysteresis
        The element described.
    points : list of DescribingFunctionPoint
        One per amplitude, frequency by frequency (all amplitudes at the first
        frequency, then at the next).
    harmonics : int
        Highest higher-order describing function computed (0: none).

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> res = describing_function(Jenkins(k=20.0, fc=0.05), [0.01], harmonics=3)
    >>> print(res)                                        # what ``motionhyst df`` prints
    Describing function of the jenkins element, k = 20 N/m, fc = 0.05 N (SI units; paper eq. 7)
    A [m]  zeta [-]  Re D [N/m]  Im D [N/m]  |D| [N/m]  |D|/k_init [-]  angle D [deg]
    -----  --------  ----------  ----------  ---------  --------------  -------------
     0.01      0.25        3.91       4.775      6.171          0.3086          50.69
    k_init = 20 N/m, the initial stiffness (|D| -> k_init as A -> 0)
    <BLANKLINE>
    Higher-order describing functions H_n = Y_n / A [N/m], relative to sin(n w t)
    A [m]  n  |H_n| [N/m]  angle H_n [deg]
    -----  -  -----------  ---------------
     0.01  1        6.171            50.69
     0.01  2            0             0.00
     0.01  3        1.592           150.00
    >>> res.to_dict()["points"][0]["harmonics"][2]["n"]
    3
    """

    link: Hysteresis
    points: list[DescribingFunctionPoint] = field(default_factory=list)
    harmonics: int = 0

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``df --json`` schema): the link's parameters and
        ``points``."""
        return {**self.link.to_dict(), "points": [p.to_dict() for p in self.points]}

    def __str__(self) -> str:
        el = self.link
        k_init = el.initial_stiffness  # not "k0": a model may have a parameter of that name

        def show(v, unit):
            if isinstance(v, list):
                return f"{', '.join(f'{x:g}' for x in v)} {unit}".rstrip() if v else "none"
            return f"{v:g} {unit}".rstrip()

        units = {p.name: p.unit for p in el.parameters}
        params = ", ".join(f"{k} = {show(v, units.get(k, ''))}"
                           for k, v in el.to_dict().items() if k != "model")
        lines = [f"Describing function of the {el.name} element, {params} "
                 "(SI units; paper eq. 7)"]
        rate = el.rate_independent
        head = ["A [m]"] if rate else ["A [m]", "f [Hz]"]

        def lead(p):
            return [g(p.amplitude)] + ([] if rate else [g(p.frequency_hz)])

        has_zeta = any(not math.isnan(p.zeta) for p in self.points)
        elastic = 0.0 < k_init < math.inf  # Coulomb friction has no elastic range: no ratio
        rows = [[*lead(p), *([g(p.zeta)] if has_zeta else []), g(p.value.real),
                 g(p.value.imag), g(abs(p.value)),
                 *([g(abs(p.value) / k_init)] if elastic else []),
                 f"{np.degrees(np.angle(p.value)):.2f}"] for p in self.points]
        lines.append(table([*head, *(["zeta [-]"] if has_zeta else []), "Re D [N/m]",
                            "Im D [N/m]", "|D| [N/m]", *(["|D|/k_init [-]"] if elastic else []),
                            "angle D [deg]"], rows))
        lines.append(f"k_init = {k_init:g} N/m, the initial stiffness"
                     + (" (|D| -> k_init as A -> 0)" if rate and elastic else "")
                     + ("" if elastic else " (no elastic range: rigid while it sticks)"))
        if self.harmonics:
            lines += ["", "Higher-order describing functions H_n = Y_n / A [N/m], relative "
                      "to sin(n w t)"]
            rows = [[*lead(p), str(n), g(abs(c)), f"{np.degrees(np.angle(c)):.2f}"]
                    for p in self.points for n, c in enumerate(p.harmonics, start=1)]
            lines.append(table([*head, "n", "|H_n| [N/m]", "angle H_n [deg]"], rows))
        return "\n".join(lines)

    def plot(self, ax=None):
        """``|D| / k_init`` and the angle of ``D`` against the amplitude, one curve per
        frequency (:func:`motionhyst.analysis.figures.plot_describing_function`).

        Parameters
        ----------
        ax : sequence of two matplotlib.axes.Axes, optional
            Axes to draw the magnitude and the angle into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
            With the plotted data as ``fig.motionhyst_data``.
        """
        from motionhyst.analysis.figures import plot_describing_function

        return plot_describing_function(self, ax=ax)


def describing_function(link: Hysteresis, amplitudes: ArrayLike,
                        frequencies_hz: Sequence[float] | None = None,
                        harmonics: int = 0) -> DescribingFunctionResult:
    """The describing function ``D(A)`` (eq. 7) of `link` at `amplitudes`.

    Parameters
    ----------
    link : Hysteresis
        The link element.
    amplitudes : array_like
        Input amplitudes ``A`` [m], >= 0 (``D(0)`` is the initial stiffness).
    frequencies_hz : sequence of float, optional
        Frequencies [Hz]: required for a rate-dependent element (its ``D``
        depends on amplitude and frequency), refused for a rate-independent one.
    harmonics : int
        Also the higher-order describing functions ``H_1 .. H_harmonics``
        (0: none).

    Returns
    -------
    DescribingFunctionResult

    Raises
    ------
    ValueError
        Frequencies given for a rate-independent element or missing for a
        rate-dependent one; a negative harmonics count.

    Examples
    --------
    >>> from motionhyst import Dahl
    >>> res = describing_function(Dahl(k=20.0, fc=0.05), [0.01])
    >>> round(abs(res.points[0].value), 3)
    5.965
    """
    if link.rate_independent:
        if frequencies_hz is not None:
            raise ValueError(f"the {link.name} element is rate-independent: its describing "
                             f"function depends on the amplitude only, not on a frequency")
        freqs: list[float | None] = [None]
    else:
        if frequencies_hz is None:
            raise ValueError(f"the {link.name} element is rate-dependent: its describing "
                             f"function needs frequencies")
        freqs = [float(f) for f in frequencies_hz]
    harmonics = int(harmonics)
    if harmonics < 0:
        raise ValueError(f"harmonics must be >= 0, got {harmonics}")
    A = np.asarray(amplitudes, dtype=float).ravel()
    zeta = np.atleast_1d(link.zeta(A)) if link.defines_zeta else np.full(A.shape, np.nan)
    points: list[DescribingFunctionPoint] = []
    for f in freqs:
        omega = None if f is None else 2.0 * math.pi * f
        D = np.atleast_1d(link.describing_function(A, omega))
        H = link.hosidf(A, harmonics, omega) if harmonics else [None] * A.size
        points += [DescribingFunctionPoint(float(a), f, float(z), complex(d), h)
                   for a, z, d, h in zip(A, zeta, D, H, strict=True)]
    return DescribingFunctionResult(link, points, harmonics)
