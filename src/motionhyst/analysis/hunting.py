"""A loop that hunts: its own stable limit cycle, which leaves it no steady state.

A loop with integral action around friction with a Stribeck dip (Olsson and Astrom 2001,
``examples/hunting.toml``) sticks, winds its integrator up until the friction breaks away,
slips past the setpoint and sticks again: a stable self-excited cycle of its own period.
Driven by a reference, it has no periodic steady state of the reference's period, and the
fixed point of :func:`~motionhyst.analysis.steady.periodic_steady_state` does not converge
(:class:`~motionhyst.analysis._fixed_point.NoFixedPoint`), as it does not for a link too
stiff for the loop.  :func:`steady_state_unless_hunting` tells the two apart.

The loop with its setpoint held at 0 (the state equation seen by the link,
:class:`~motionhyst.analysis.floquet.LoopStateEquation`, as for
:func:`~motionhyst.analysis.stability.stability`) is released at rest, its link's
displacement the reference's amplitude away from the setpoint, and run in time by a stiff
solver (LSODA) until its upward crossings of ``y1 = 0`` repeat: a run that settles on a
cycle has found a stable one, and its period (:func:`hunting_period`).  For a loop that
cannot be run so (a sampled loop, a link without a smooth state equation) the describing
function's prediction decides, as ``motionhyst stability`` would.  A run costs a fraction
of a second where the whole analysis (loci, the cut at the integrator, the exact orbit)
costs seconds; ``motionhyst stability`` refines the cycle to its exact orbit.

Examples
--------
The loop of ``examples/hunting.toml``: a PID (a pure derivative) around a 1 kg mass on LuGre
friction with a Stribeck dip.

>>> import control
>>> from motionhyst import Loop, LuGre
>>> from motionhyst.plants import MassDamper
>>> link = LuGre(sigma0=1e5, sigma1=1e5 ** 0.5, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
>>> pid = control.tf([6.0, 3.0, 4.0], [1.0, 0.0])
>>> loop = Loop(MassDamper(m=1.0, c=0.0), pid, link, feedforward=None)
>>> print(f"{hunting_period(loop, 0.01):.4g} s")           # the exact orbit: 24.437 s
24.44 s
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst.analysis._fixed_point import LARGE_CHANGE, NoFixedPoint
from motionhyst.analysis.floquet import LoopStateEquation
from motionhyst.analysis.steady import SteadyState, periodic_steady_state
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI, tf_poly

__all__ = ["hunting_period", "hunting_refusal", "steady_state_unless_hunting"]

#: Relative tolerance of the run (the period it gives is good to about this, far finer
#: than the message's four digits: 24.43681 s for the exact orbit's 24.43679 s).
RUN_RTOL = 1e-6
#: The run has settled on a cycle when its last two periods, and the states at its last
#: three upward crossings, agree to this fraction ...
SETTLED = 1e-4
#: ... and the change of the state from crossing to crossing has shrunk to this fraction of
#: its first (an attracting cycle; a lightly damped oscillation dying out keeps its ratio).
SHRUNK = 0.5
#: The run's length at most, and the length of each of its pieces (after each the crossings
#: are judged), in periods of the loop's slowest closed-loop pole.
RUN_SLOW_PERIODS = 60.0
PIECE_SLOW_PERIODS = 10.0
#: The run has come to rest when every state of the loop is below this fraction of its
#: start's.
AT_REST = 1e-8
#: Evaluations of the loop's state equation the run may take at most (about 12 us each):
#: a stiff loop with fast dynamics stops there, its cycle not found, in well under a second
#: (the hunting loop settles in 13 300).
MAX_EVALUATIONS = 50_000


class _Exhausted(Exception):
    """The run took :data:`MAX_EVALUATIONS` evaluations."""


def _start(sys: LoopStateEquation, offset: float) -> tuple[NDArray, NDArray]:
    """The loop at rest with the link's displacement ``y1 = -offset`` and the link
    unloaded, and a magnitude per state for the run's tolerances."""
    obs = np.array([sys.C @ np.linalg.matrix_power(sys.A, k) for k in range(sys.n)])
    X0 = np.zeros(sys.N)
    X0[:sys.n] = np.linalg.solve(obs, np.eye(sys.n)[0] * (-offset))
    scale = np.empty(sys.N)
    scale[:sys.n] = np.abs(X0[:sys.n]) + 1e-3 * np.max(np.abs(X0[:sys.n]))
    scale[sys.n:] = offset * 1e-3
    return X0, scale


def _settled(te: list[float], ye: list[NDArray]) -> float | None:
    """The period [s] of the cycle the upward crossings at times `te` with states `ye`
    have settled on, or None."""
    if len(te) < 4:
        return None
    periods = np.diff(te[-3:])
    mag = np.maximum(np.max(np.abs(np.array(ye[-3:])), axis=0), 1e-300)
    steps = np.max(np.abs(np.diff(np.array(ye), axis=0)), axis=1) / np.max(mag)
    if (abs(periods[1] / periods[0] - 1.0) < SETTLED and max(steps[-2:]) < SETTLED
            and steps[-1] < SHRUNK * steps[0]):
        return float(periods[1])
    return None


def hunting_period(loop: Loop, offset: float) -> float | None:
    """The period [s] of the stable self-excited cycle the loop settles on, its setpoint held
    at 0, released at rest with its link's displacement `offset` [m] away (module
    docstring); None where the run comes to rest or does not settle (in
    :data:`RUN_SLOW_PERIODS` periods of the slowest closed-loop pole, or
    :data:`MAX_EVALUATIONS` evaluations of the state equation).

    Parameters
    ----------
    loop : Loop
        A continuous LTI loop with a link that has a smooth state equation (LuGre, Dahl,
        Bouc-Wen).
    offset : float
        The link's displacement at the start [m], > 0.

    Returns
    -------
    float or None

    Raises
    ------
    ValueError
        For a loop that cannot be run so (no link, a link without a smooth state equation,
        a sampled controller, a measured plant, a loop gain of relative degree < 2).

    Examples
    --------
    >>> import control
    >>> from motionhyst import Loop, LuGre
    >>> from motionhyst.plants import MassDamper
    >>> pid = control.tf([6.0, 3.0, 4.0], [1.0, 0.0])   # kd s + kp + ki / s
    >>> def loop(fs):                                      # examples/hunting.toml's loop
    ...     link = LuGre(sigma0=1e5, sigma1=1e5 ** 0.5, sigma2=0.4, fc=1.0, fs=fs, vs=1e-3)
    ...     return Loop(MassDamper(m=1.0, c=0.0), pid, link, feedforward=None)
    >>> print(f"{hunting_period(loop(1.5), 0.01):.5g} s")
    24.437 s
    >>> print(hunting_period(loop(1.0), 0.01))             # no Stribeck dip: no hunting
    None
    """
    from scipy.integrate import solve_ivp

    link = loop.hysteresis
    if link is None or link.n_states == 0 or loop.sampled is not None or not loop.is_lti:
        raise ValueError("a run of the loop needs a continuous LTI loop and a link with a "
                         "smooth state equation")
    if not (np.isfinite(offset) and offset > 0):
        raise ValueError(f"offset must be finite and > 0, got {offset!r}")
    sys = LoopStateEquation(loop)
    X, scale = _start(sys, float(offset))
    p = np.abs(loop.closed_loop_poles())
    t_slow = TWO_PI / float(np.min(p[p > 0])) if np.any(p > 0) else 1.0
    piece = PIECE_SLOW_PERIODS * t_slow
    atol = RUN_RTOL * 1e-2 * np.maximum(scale, 1e-300)
    start = float(np.max(np.abs(X[:sys.n]) / scale[:sys.n]))
    evaluations = [0]

    def rhs(t: float, X: NDArray) -> NDArray:
        evaluations[0] += 1
        if evaluations[0] > MAX_EVALUATIONS:
            raise _Exhausted
        return sys.rhs(t, X)

    te: list[float] = []
    ye: list[NDArray] = []
    for k in range(math.ceil(RUN_SLOW_PERIODS / PIECE_SLOW_PERIODS)):
        try:
            sol = solve_ivp(rhs, (0.0, piece), X, method="LSODA", jac=sys.jac, rtol=RUN_RTOL,
                            atol=atol)
        except _Exhausted:
            return None
        if not sol.success:
            return None
        y = sys.C @ sol.y[:sys.n]
        for i in np.nonzero((y[:-1] < 0.0) & (y[1:] >= 0.0))[0]:
            s = float(-y[i] / (y[i + 1] - y[i]))          # between the solver's steps
            te.append(k * piece + float(sol.t[i] + s * (sol.t[i + 1] - sol.t[i])))
            ye.append(sol.y[:, i] + s * (sol.y[:, i + 1] - sol.y[:, i]))
        period = _settled(te, ye)
        if period is not None:
            return period
        X = sol.y[:, -1]
        if np.max(np.abs(X[:sys.n]) / scale[:sys.n]) < AT_REST * start:
            return None
    return None


def _predicted_period(loop: Loop) -> float | None:
    """The period [s] of the first stable cycle the describing function predicts
    (:func:`~motionhyst.analysis.stability.stability` without exact orbits), or None."""
    from motionhyst.analysis.stability import stability

    try:
        res = stability(loop, exact=False, search=False)
    except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError):
        return None
    stable = [1.0 / p.frequency_hz for p in res.predicted if p.stable]
    return stable[0] if stable else None


def _runs_in_time(loop: Loop) -> bool:
    """Whether ``motionhyst simulate --time-series`` can run the loop: a sampled or a proper
    continuous controller (a PID's pure derivative is not)."""
    if loop.sampled is not None:
        return True
    num, den = tf_poly(loop.controller, "controller")
    return len(np.trim_zeros(num, "f")) <= len(np.trim_zeros(den, "f"))


def hunting_refusal(loop: Loop, exc: NoFixedPoint, amplitude: float) -> RuntimeError:
    """The refusal of a steady state whose fixed point did not converge (`exc`, at the
    reference's `amplitude` [m]): where it made no progress (its last change above
    :data:`~motionhyst.analysis._fixed_point.LARGE_CHANGE` of the answer) and the loop hunts
    (:func:`hunting_period` from rest at `amplitude`; the describing function's prediction
    for a loop that cannot be run so) it says so, with the cycle's period; else `exc`, the
    link too stiff for the loop.  A fixed point that came within that of an answer is no
    loop's own cycle.

    Parameters
    ----------
    loop : Loop
        The loop.
    exc : NoFixedPoint
        The fixed point's refusal.
    amplitude : float
        The reference's amplitude [m].

    Returns
    -------
    RuntimeError

    Examples
    --------
    >>> import control
    >>> from motionhyst import Loop, LuGre
    >>> from motionhyst.analysis._fixed_point import not_converged
    >>> from motionhyst.plants import MassDamper
    >>> link = LuGre(sigma0=1e5, sigma1=1e5 ** 0.5, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
    >>> loop = Loop(MassDamper(m=1.0, c=0.0), control.tf([6.0, 3.0, 4.0], [1.0, 0.0]), link,
    ...             feedforward=None)                    # examples/hunting.toml's loop
    >>> print(hunting_refusal(loop, not_converged(0.1, 50, 0.86), 0.01))
    steady state at 0.1 Hz: the loop hunts: ... of period 24.44 s (a run from rest ...
    """
    link = loop.hysteresis
    if link is None or not loop.is_lti or not exc.change >= LARGE_CHANGE:
        return exc  # a fixed point that came near an answer: no cycle of its own took over
    how = "a run from rest settles on it"
    try:
        period = hunting_period(loop, amplitude)
    except ValueError:  # no run of this loop: the describing function's prediction
        period, how = _predicted_period(loop), "predicted by the describing function"
    except (RuntimeError, ArithmeticError, np.linalg.LinAlgError):
        period = None  # a run that failed finds no cycle: the fixed point's own refusal
    if period is None:
        return exc
    f = exc.frequency_hz
    run = ("run it in time (motionhyst simulate --time-series)" if _runs_in_time(loop) else
           "run it in time (motionhyst simulate --time-series, with [controller] "
           "derivative_filter_hz: a pure derivative has no run)")
    return RuntimeError(
        f"steady state at {f:g} Hz: the loop hunts: it has a stable self-excited limit cycle "
        f"of period {period:.4g} s ({how}; motionhyst stability shows its exact orbit), so "
        f"no periodic steady state of the reference's {1 / f:.4g} s period; {run}")


def steady_state_unless_hunting(loop: Loop, amplitude: float, frequency_hz: float
                                ) -> SteadyState:
    """:func:`~motionhyst.analysis.steady.periodic_steady_state`; a fixed point that does not
    converge because the loop hunts is refused saying so, with the cycle's period
    (:func:`hunting_refusal`).

    Parameters
    ----------
    loop : Loop
        The loop.
    amplitude : float
        Reference amplitude ``A_r`` [m] of ``r = A_r sin(2 pi f t)``.
    frequency_hz : float
        Reference frequency [Hz].

    Returns
    -------
    SteadyState
        The exact periodic steady state.

    Raises
    ------
    ValueError
        As :func:`~motionhyst.analysis.steady.periodic_steady_state`.
    RuntimeError
        A steady state without an answer; one whose loop hunts says so.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> ss = steady_state_unless_hunting(default_scenario().loop(), 0.01, 5.0)
    >>> print(f"|E_sim| = {abs(ss.mismatch):.3f}")
    |E_sim| = 6.041
    """
    try:
        return periodic_steady_state(loop, amplitude, frequency_hz)
    except NoFixedPoint as exc:
        raise hunting_refusal(loop, exc, amplitude) from None
