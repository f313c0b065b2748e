"""The describing function's prediction next to the exact periodic steady state.

Paper section V: the quasi-linear mismatch of eq. (18) and the error
harmonics predicted by the higher-order describing functions, compared per
frequency with the exact steady state of the nonlinear loop
(:func:`~motionhyst.analysis.steady.periodic_steady_state`).  This is the one module
that needs both analyses; neither of them imports the other.

Examples
--------
>>> from motionhyst import default_scenario
>>> cmp = compare_with_describing_function(default_scenario().loop(), 0.01, [5.0])
>>> p = cmp.points[0]
>>> round(abs(p.state.mismatch), 2), round(abs(p.mismatch_df), 2)
(6.04, 6.04)
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.analysis.floquet import (
    FloquetResult,
    check_floquet_budget,
    steady_state_floquet,
    unresolved_time_scales,
)
from motionhyst.analysis.hunting import steady_state_unless_hunting
from motionhyst.analysis.plausibility import check_frequency_range, check_plausible
from motionhyst.analysis.quasilinear import error_harmonics_df, loop_mismatch
from motionhyst.analysis.steady import SteadyState
from motionhyst.controllers.loop import Loop
from motionhyst.core.budget import BudgetError
from motionhyst.core.textfmt import g, table
from motionhyst.core.warnings import warn

__all__ = ["ComparisonPoint", "DescribingFunctionComparison", "compare_with_describing_function",
           "exact_mismatch"]


@dataclass
class ComparisonPoint:
    """Exact steady state and describing-function prediction at one frequency.

    Examples
    --------
    >>> from motionhyst import compare_with_describing_function, default_scenario
    >>> p = compare_with_describing_function(default_scenario().loop(), 0.01, [5.0]).points[0]
    >>> round(abs(p.mismatch_df), 2), round(abs(p.state.mismatch), 2)
    (6.04, 6.04)

    Attributes
    ----------
    state : SteadyState
        The exact periodic steady state.
    mismatch_df : complex
        Eq. (18) at the reference amplitude.
    error_harmonics_df : ndarray of complex
        Predicted error harmonics ``1 .. n`` [m] (higher-order describing functions).
    floquet : FloquetResult, None or False
        The steady state's Floquet multipliers
        (:func:`~motionhyst.analysis.floquet.steady_state_floquet`); None where they
        cannot be computed, False when not asked.
    """

    state: SteadyState
    mismatch_df: complex
    error_harmonics_df: NDArray[np.complex128]
    floquet: FloquetResult | bool | None = False

    def to_dict(self) -> dict:
        """JSON-ready dictionary: one point of the ``steady --json`` schema (with
        ``floquet_max`` and ``stable`` when the multipliers were computed; null where
        they cannot be)."""
        out = self.state.to_dict(mismatch_df=self.mismatch_df,
                                 error_harmonics_df=self.error_harmonics_df)
        if self.floquet is not False:
            f = self.floquet
            out.update({"floquet_max": None, "stable": None} if f is None else f.to_dict())
        return out


@dataclass
class DescribingFunctionComparison:
    """Result of :func:`compare_with_describing_function`, one point per frequency.

    Parameters
    ----------
    amplitude : float
        Reference amplitude ``A_r`` [m].
    points : list of ComparisonPoint
        One per frequency.

    Examples
    --------
    >>> from motionhyst import compare_with_describing_function, default_scenario
    >>> cmp = compare_with_describing_function(default_scenario().loop(), 0.01, [5.0, 10.0])
    >>> [round(p["mismatch_simulated_abs"], 3) for p in cmp.to_dict()["points"]]
    [6.041, 1.24]
    >>> print(str(cmp).splitlines()[0].split()[:3])        # the table ``steady`` prints
    ['f', '[Hz]', '|e1|']
    """

    amplitude: float
    points: list[ComparisonPoint] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready dictionary: ``{"points": [...]}``."""
        return {"points": [p.to_dict() for p in self.points]}

    def __str__(self) -> str:
        rows = []
        for p in (q.to_dict() for q in self.points):
            h = {x["n"]: x for x in p["error_harmonics"]}
            hd = {x["n"]: x for x in p["error_harmonics_df"]}
            rows.append([g(p["frequency_hz"]), g(h[1]["abs"]), f"{h[1]['phase_deg']:.1f}",
                         g(h[3]["abs"]) if 3 in h else "-", g(hd[3]["abs"]) if 3 in hd else "-",
                         g(h[5]["abs"]) if 5 in h else "-", g(hd[5]["abs"]) if 5 in hd else "-",
                         g(p["error_linear_abs"]), g(p["mismatch_simulated_abs"]),
                         f"{p['mismatch_simulated_phase_deg']:.2f}", g(p["mismatch_df_abs"]),
                         f"{p['mismatch_df_phase_deg']:.2f}", g(p["error_peak"]),
                         g(p["error_hysteresis_rms"])])
        return table(["f [Hz]", "|e1| [m]", "angle e1 [deg]", "|e3| [m]", "|e3| HOSIDF",
                      "|e5| [m]", "|e5| HOSIDF",
                      "|e1 lin| [m]", "|E sim|", "angle E sim", "|E df| (18)", "angle E df",
                      "peak e [m]", "rms e-e_lin [m]"], rows) + self._undefined_line() + \
            self._floquet_lines()

    def _undefined_line(self) -> str:
        """Why E is nan where the loop without the link has no error (e1 linear = 0)."""
        if all(p.state.e_linear[1] != 0 for p in self.points):
            return ""
        return ("\n  E (sim and eq. 18) is not defined where |e1 lin| = 0: the plant has no "
                "flexible part (Pf2 = Pr - P2 = 0), so its rigid-body feedforward leaves no "
                "error without the link; e1 is the link's error")

    def _floquet_lines(self) -> str:
        lines = []
        for p in self.points:
            if p.floquet is False:
                continue
            head = f"\n  {g(p.state.frequency_hz)} Hz: "
            lines.append(head + ("Floquet multipliers not available for this loop"
                                 if p.floquet is None else str(p.floquet)))
        return "".join(lines)

    def plot(self, ax=None):
        """Fig. 11: the error over a period, exact, without hysteresis and predicted.

        Parameters
        ----------
        ax : sequence of N matplotlib.axes.Axes, optional
            Axes to draw into (one per frequency); default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import fig11_errors

        return fig11_errors([p.state for p in self.points],
                            [p.mismatch_df for p in self.points],
                            [p.error_harmonics_df for p in self.points], ax=ax)


def exact_mismatch(state: SteadyState) -> complex:
    """The exact mismatch ``E_sim = e1 / e1_linear`` of a steady state (compare eq. 18).

    .. deprecated:: 0.1.0
        Use :attr:`SteadyState.mismatch <motionhyst.analysis.steady.SteadyState.mismatch>`,
        which this returns (nan where the loop without the link has no error); this name
        warns with a :class:`DeprecationWarning` and will be removed in the next release.

    Parameters
    ----------
    state : SteadyState
        The exact periodic steady state.

    Examples
    --------
    >>> import warnings
    >>> from motionhyst import default_scenario, periodic_steady_state
    >>> state = periodic_steady_state(default_scenario().loop(), 0.01, 5.0)
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore", DeprecationWarning)
    ...     round(abs(exact_mismatch(state)), 2), round(abs(state.mismatch), 2)
    (6.04, 6.04)
    """
    warnings.warn("motionhyst.analysis.comparison.exact_mismatch(state) is deprecated: use "
                  "state.mismatch (SteadyState.mismatch); exact_mismatch will be removed in "
                  "the next release", DeprecationWarning, stacklevel=2)
    return state.mismatch


def _steady_states(loop: Loop, amplitude: float, f: NDArray[np.float64]) -> list[SteadyState]:
    """The steady state at each frequency; a fixed point that does not converge because the
    loop hunts is refused saying so
    (:func:`~motionhyst.analysis.hunting.steady_state_unless_hunting`)."""
    return [steady_state_unless_hunting(loop, amplitude, float(fi)) for fi in f]


def compare_with_describing_function(loop: Loop, amplitude: float, frequencies_hz: ArrayLike,
                                     floquet: bool = False) -> DescribingFunctionComparison:
    """Exact steady state next to the mismatch of eq. (18) and the HOSIDF error harmonics.

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    amplitude : float
        Reference amplitude ``A_r`` [m] of ``r = A_r sin(2 pi f t)``.
    frequencies_hz : array_like
        Frequencies [Hz].
    floquet : bool
        Also the Floquet multipliers of each steady state (is it stable?), where the
        loop allows (:func:`~motionhyst.analysis.floquet.steady_state_floquet`).

    Returns
    -------
    DescribingFunctionComparison

    Raises
    ------
    motionhyst.core.budget.BudgetError
        With `floquet`: the multipliers above the memory or work budget, before any point
        is computed (:func:`~motionhyst.analysis.floquet.check_floquet_budget`).
    RuntimeError
        A steady state that has no answer
        (:func:`~motionhyst.analysis.steady.periodic_steady_state`); one whose fixed point
        does not converge because the loop hunts says so, with its limit cycle's period.

    Warns
    -----
    MotionhystWarning
        Where the paper's quasi-linear reading stops holding (a frequency below
        ``f*``, a link that never slips, a frequency outside measured data):
        :func:`~motionhyst.analysis.plausibility.check_plausible`.

    Examples
    --------
    >>> from motionhyst import compare_with_describing_function, default_scenario
    >>> cmp = compare_with_describing_function(default_scenario().loop(), 0.01, [10.0])
    >>> p = cmp.points[0]
    >>> round(abs(p.mismatch_df), 3), round(abs(p.state.mismatch), 3)   # eq. (18) vs exact
    (1.239, 1.24)
    """
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    check_frequency_range(loop, f)  # a frequency the loop's model cannot mean: before any work
    if floquet:  # the multipliers' memory and work, before any point is computed
        check_floquet_budget(loop, f, remedy="give fewer frequencies or leave the multipliers "
                                             "out (floquet=False)")
    check_plausible(loop, amplitude, f)
    E_df = loop_mismatch(loop, f, amplitude)
    points = [ComparisonPoint(ss, complex(ed),
                              error_harmonics_df(loop, amplitude, ss.frequency_hz), False)
              for ss, ed in zip(_steady_states(loop, amplitude, f), E_df, strict=True)]
    why = (unresolved_time_scales(loop) if floquet and loop.hysteresis is not None
           and loop.is_lti and loop.sampled is None else None)
    if why:  # said once, rather than multipliers that mean nothing
        warn(f"Floquet multipliers not computed: {why}")
        floquet = False
        for p in points:
            p.floquet = None
    if floquet:
        for p in points:
            try:
                p.floquet = steady_state_floquet(loop, p.state)
            except BudgetError:
                raise
            except ValueError:
                p.floquet = None
    return DescribingFunctionComparison(float(amplitude), points)
