"""A loop that hunts: its own stable limit cycle, which leaves it no steady state.

A loop with integral action around friction with a Stribeck dip (Olsson and Astrom 2001,
``examples/hunting.toml``) sticks, winds its integrator up until the friction breaks away,
slips past the setpoint and sticks again: a stable self-excited cycle of its own period.
Driven by a reference slow enough for the integrator to wind up, it keeps slipping at that
rhythm: it has no periodic steady state of the reference's period, and the fixed point of
:func:`~motionhyst.analysis.steady.periodic_steady_state` does not converge
(:class:`~motionhyst.analysis._fixed_point.NoFixedPoint`), as it may not for a link too
stiff for the loop.  Driven faster or with a smaller amplitude, the same loop may stick and
follow the reference (at 0.1 Hz, 10 mm its PID's force stays below the friction's): whether
it hunts is a question about the driven loop.  :func:`steady_state_unless_hunting` asks it.

First the loop's own cycle: the loop with its setpoint held at 0 (the state equation seen by
the link, :class:`~motionhyst.analysis.floquet.LoopStateEquation`, as for
:func:`~motionhyst.analysis.stability.stability`) is released at rest, its link's
displacement the reference's amplitude away from the setpoint, and run in time by a stiff
solver (LSODA) until its upward crossings of ``y1 = 0`` repeat: a run that settles on a
cycle has found a stable one, and its period (:func:`hunting_period`).  A loop without one
does not hunt.  Then the driven loop, run in time from rest (:func:`driven_run`): it hunts
where its error keeps crossing zero at the cycle's rhythm and its periods do not repeat; it
follows the reference where they do.  For a loop that cannot be run so (a sampled loop, a
link without a smooth state equation) the describing function's prediction is said, as a
possibility.  The runs cost a fraction of a second where the whole analysis (loci, the cut
at the integrator, the exact orbit) costs seconds; ``motionhyst stability`` refines the
cycle to its exact orbit.

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
import time
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from motionhyst.analysis._fixed_point import LARGE_CHANGE, NoFixedPoint
from motionhyst.analysis.floquet import LoopStateEquation
from motionhyst.analysis.steady import SteadyState, periodic_steady_state
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI, tf_poly

__all__ = ["DrivenRun", "driven_run", "hunting_period", "hunting_refusal",
           "steady_state_unless_hunting"]

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
#: Evaluations of its right-hand side a run may take at most: each run is bounded by the
#: simulated time it covers (here :data:`RUN_SLOW_PERIODS`; :func:`driven_run`'s cycles and
#: periods), and by this where a stiff loop with fast dynamics would need more (its cycle not
#: found: the fixed point's refusal stands, no claim of hunting).  A count, so that what is
#: found does not depend on the machine's speed.  The largest run the tests make, the held
#: loop with ki = 16 (its cycle of 6.657 s), needs 47 600 (0.43 s of processor time here);
#: the same run with the right-hand side rounded otherwise needed 60 600 and 73 200 (a
#: stiff run's steps follow its rounding), the others 2 700 to 17 100: twice the largest.
#: A run that spends it all takes 1.3 to 1.7 s here (Table I with a LuGre link: 11 us an
#: evaluation, LSODA's own work included).
RUN_EVALUATIONS = 150_000
#: Processor time [s] of its thread past which a run stops all the same (a study's threads do
#: not share it): a safety net 18 times what :data:`RUN_EVALUATIONS` takes here, never
#: reached but by a machine or a tracer (coverage) that many times slower.
GUARD_SECONDS = 30.0


class _Exhausted(Exception):
    """The run took :data:`RUN_EVALUATIONS` evaluations (or :data:`GUARD_SECONDS`)."""


def _budgeted(rhs: Callable[[float, NDArray], NDArray]) -> Callable[[float, NDArray], NDArray]:
    """`rhs` that raises :class:`_Exhausted` at its evaluation past :data:`RUN_EVALUATIONS`,
    or once the run has taken :data:`GUARD_SECONDS` of its thread's processor time (looked
    at every 4096 evaluations)."""
    calls, limit, end = [0], RUN_EVALUATIONS, time.thread_time() + GUARD_SECONDS

    def budgeted(t: float, X: NDArray) -> NDArray:
        calls[0] += 1
        if calls[0] > limit or (calls[0] % 4096 == 0 and time.thread_time() > end):
            raise _Exhausted
        return rhs(t, X)

    return budgeted


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


def _held_field(sys: LoopStateEquation) -> Callable[[float, NDArray], NDArray]:
    """``X'`` of the loop with its setpoint held (:meth:`LoopStateEquation.rhs`), the link's
    ``z'`` and ``w`` from its :meth:`~motionhyst.hysteresis.base.Hysteresis.rates`: a held
    run evaluates it tens of thousands of times (LuGre's scalar rates take 1.2 us, the
    arrays of its state equation 11 us)."""
    A, B, CA, n, rates = sys.A, sys.B, sys.CA, sys.n, sys.link.rates

    def field(t: float, X: NDArray) -> NDArray:
        x = X[:n]
        zdot, w = rates(X[n:], float(CA @ x))
        out = np.empty(X.size)
        out[:n] = A @ x - B * w
        out[n:] = zdot
        return out

    return field


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
    :data:`RUN_EVALUATIONS` evaluations of its right-hand side).

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
    rhs = _budgeted(_held_field(sys))

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


class DrivenRun(NamedTuple):
    """What a run in time of the driven loop from rest shows (:func:`driven_run`).

    Parameters
    ----------
    verdict : {"follows", "hunts", "unsettled"}
        It follows the reference's period (its error over the last period within
        :data:`FOLLOWS` of the reference's amplitude of the one before's); it hunts (it does not
        follow, and its error crosses zero upward at the loop's own cycle's rhythm,
        :data:`RHYTHM_CROSSINGS` intervals in a row within :data:`RHYTHM` of that cycle's
        period); or neither, within the run's length.
    seconds : float
        The run's length [s].
    change : float
        The largest change of the error from the last whole period to the one before [m]
        (nan before two periods).
    e1 : float
        The amplitude of the error's first harmonic over the last whole period [m] (nan
        before one).
    rhythm : float
        The mean interval of the error's last upward crossings [s] (nan without them).

    Examples
    --------
    What :func:`driven_run` says of the hunting loop at 0.1 Hz, 10 mm (it sticks):

    >>> run = DrivenRun("follows", 50.0, 1.4e-7, 9.99974e-3, 10.0)
    >>> print(run.verdict, f"after {run.seconds:g} s, e1 = {run.e1:.6g} m")
    follows after 50 s, e1 = 0.00999974 m
    """

    verdict: str
    seconds: float
    change: float
    e1: float
    rhythm: float


#: The driven run follows the reference's period when its error over a period differs from
#: the period before's by at most this fraction of the reference's amplitude (the hunting
#: loop at 0.1 Hz, 10 mm, stuck: 1.4e-5 after 5 periods, its creep and the run's accuracy;
#: driven at 0.005 Hz, where it hunts, its two periods differ by 13 times it) ...
FOLLOWS = 1e-3
#: ... judged once it has run at least this many of the reference's periods and of the
#: loop's own cycle's (a hunting loop sticks for up to a cycle before its first slip).
MIN_PERIODS = 3
MIN_CYCLES = 2.0
#: It hunts when its error's last upward crossings come this many intervals in a row within
#: this fraction of the loop's own cycle's period (the hunting loop driven at 0.005 Hz,
#: 10 mm: 24.31 to 24.53 s for its cycle's 24.44 s; at 0.01 Hz, 30 mm: 23.8 to 25.8 s).
RHYTHM_CROSSINGS = 4
RHYTHM = 0.1
#: The run's length at most: this many of the loop's own cycles, and at least
#: :data:`MIN_PERIODS` reference periods where that is longer, but never more than
#: :data:`MAX_CYCLES` cycles (a reference far slower than the cycle is judged by its rhythm).
RUN_CYCLES = 8.0
MAX_CYCLES = 24.0
#: Samples of a period at which the run's periods are compared.
PHASES = 256


def _series_derivatives(num: NDArray, den: NDArray, count: int) -> NDArray:
    """``y(0+), y'(0+), ...`` (`count` of them) of the inverse Laplace transform of the
    strictly proper ``num(s) / den(s)``: the coefficients of its expansion in ``1 / s``."""
    num = np.trim_zeros(np.asarray(num, dtype=float), "f")
    den = np.trim_zeros(np.asarray(den, dtype=float), "f")
    lag = len(den) - len(num)                         # the relative degree, >= 1
    q = np.zeros(max(count - lag + 1, 0))
    padded = np.concatenate([num, np.zeros(q.size)])
    for k in range(q.size):
        acc = padded[k] - sum(den[i] * q[k - i] for i in range(1, min(k, len(den) - 1) + 1))
        q[k] = acc / den[0]
    out = np.zeros(count)
    for j in range(count):
        if 0 <= j + 1 - lag < q.size:
            out[j] = q[j + 1 - lag]
    return out


def driven_run(loop: Loop, amplitude: float, frequency_hz: float, cycle: float, *,
               rtol: float = RUN_RTOL) -> DrivenRun:
    """Run the loop driven by ``r = amplitude sin(2 pi frequency_hz t)`` in time from rest and
    say whether it follows the reference's period or hunts at the rhythm of its own cycle
    of period `cycle` [s] (:func:`hunting_period`): :class:`DrivenRun`.

    The loop's response to the reference alone, ``y1 = p(t)`` in its steady state, is known
    in closed form (``T_{r->y1}(j w)``); the run integrates the rest, the link's force through
    ``T_{w->y1}`` (:class:`~motionhyst.analysis.floquet.LoopStateEquation`) and the linear
    loop's transient, started where ``y1`` and its derivatives are those of the loop started
    at rest (their values at ``0+`` from ``T_{r->y1}(s) R(s)``), the link unloaded.  The
    error is its linear response ``T_{r->e}(j w)`` plus the link's part, read from the same
    states (an output matrix matching ``T_{w->e}``'s Markov parameters): on Table I with a
    LuGre link its first harmonic agrees with the exact steady state's to 6e-7.  It runs
    in pieces, at most :data:`RUN_CYCLES` cycles (:data:`MIN_PERIODS` reference periods where
    longer, at most :data:`MAX_CYCLES` cycles) and :data:`RUN_EVALUATIONS` evaluations of its
    right-hand side, and stops once it follows or hunts.

    Parameters
    ----------
    loop : Loop
        A continuous LTI loop with a link that has a smooth state equation, no hysteresis or
        Coulomb feedforward (their force is no linear transfer of the reference).
    amplitude : float
        Reference amplitude [m], > 0.
    frequency_hz : float
        Reference frequency [Hz], > 0.
    cycle : float
        The period of the loop's own cycle [s], > 0.
    rtol : float
        The run's relative tolerance (:data:`RUN_RTOL`; a tighter one for a reference).

    Returns
    -------
    DrivenRun

    Raises
    ------
    ValueError
        For a loop that cannot be run so, or a non-positive argument.

    Examples
    --------
    The hunting loop (``examples/hunting.toml``) at 10 mm: at 0.1 Hz its PID's force stays
    below the friction and the stage sticks; at 0.005 Hz the integrator winds up, the stage
    slips, sticks and slips again at its own cycle's rhythm.

    >>> import control
    >>> from motionhyst import Loop, LuGre
    >>> from motionhyst.plants import MassDamper
    >>> link = LuGre(sigma0=1e5, sigma1=1e5 ** 0.5, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
    >>> loop = Loop(MassDamper(m=1.0, c=0.0), control.tf([6.0, 3.0, 4.0], [1.0, 0.0]), link,
    ...             feedforward=None)
    >>> run = driven_run(loop, 0.01, 0.1, 24.437)
    >>> print(run.verdict, f"{run.e1 * 1e3:.4f} mm")
    follows 9.9997 mm
    >>> run = driven_run(loop, 0.01, 0.005, 24.437)
    >>> print(run.verdict, f"{run.rhythm:.3g} s")
    hunts 24.5 s
    """
    from scipy.integrate import solve_ivp

    link = loop.hysteresis
    if (link is None or link.n_states == 0 or loop.sampled is not None or not loop.is_lti
            or loop.hysteresis_feedforward is not None
            or (loop.ff is not None and loop.ff.coulomb)):
        raise ValueError("a run of the driven loop needs a continuous LTI loop, a link with a "
                         "smooth state equation and no hysteresis or Coulomb feedforward")
    for name, value in (("amplitude", amplitude), ("frequency", frequency_hz),
                        ("cycle", cycle), ("rtol", rtol)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    A, f = float(amplitude), float(frequency_hz)
    sys = LoopStateEquation(loop)
    omega, period = TWO_PI * f, 1.0 / f
    num, den = tf_poly(loop.transfer_tf("r->y1"), "r->y1")
    T = complex(np.polyval(num, 1j * omega) / np.polyval(den, 1j * omega))  # T_{r->y1}(j w)
    rest = _series_derivatives(A * omega * np.asarray(num, dtype=float),
                               np.polymul(den, [1.0, 0.0, omega ** 2]), sys.n)
    steady = A * (T * (1j * omega) ** np.arange(sys.n)).imag      # p(0), p'(0), ...
    obs = np.array([sys.C @ np.linalg.matrix_power(sys.A, k) for k in range(sys.n)])
    X = np.zeros(sys.N)
    X[:sys.n] = np.linalg.solve(obs, rest - steady)
    _, scale = _start(sys, A)
    atol = rtol * 1e-2 * np.maximum(scale, 1e-300)
    TV = A * T * 1j * omega
    # the error: its linear response to the reference, and C_e x with C_e matching the Markov
    # parameters of T_{w->e} (the input of the realisation is -w): C_e A^k B = -h_k
    num_e, den_e = tf_poly(loop.transfer_tf("w->e"), "w->e")
    ctrb = np.column_stack([np.linalg.matrix_power(sys.A, k) @ sys.B for k in range(sys.n)])
    C_e = np.linalg.solve(ctrb.T, -_series_derivatives(num_e, den_e, sys.n))
    num_e, den_e = tf_poly(loop.transfer_tf("r->e"), "r->e")
    TE = A * complex(np.polyval(num_e, 1j * omega) / np.polyval(den_e, 1j * omega))

    def field(t: float, X: NDArray) -> NDArray:
        x, z = X[:sys.n], X[sys.n:]
        v = float((TV * np.exp(1j * omega * t)).imag + sys.CA @ x)
        zdot, w, *_ = link.state_equation(z, v)
        return np.concatenate([sys.A @ x - sys.B * w, zdot])

    def jac(t: float, X: NDArray) -> NDArray:
        v = float((TV * np.exp(1j * omega * t)).imag + sys.CA @ X[:sys.n])
        return sys.linearised(X[sys.n:], v)

    def error(t: NDArray, x: NDArray) -> NDArray:
        return (TE * np.exp(1j * omega * t)).imag + C_e @ x

    rhs = _budgeted(field)
    length = min(max(RUN_CYCLES * cycle, MIN_PERIODS * period), MAX_CYCLES * cycle)
    split = max(1, math.ceil(period / cycle))       # pieces a period: judged after each
    phases = np.array_split(np.arange(PHASES) / PHASES * period, split)
    ups: list[float] = []
    periods: list[NDArray] = []         # the error at the phases, period by period
    pieces: list[NDArray] = []
    change = e1 = rhythm = math.nan
    k = 0
    while k * period / split < length * (1.0 - 1e-12):
        t0, t1 = k * period / split, (k + 1) * period / split
        try:
            sol = solve_ivp(rhs, (t0, t1), X, method="LSODA", jac=jac, rtol=rtol,
                            atol=atol, dense_output=True)
        except _Exhausted:
            break
        if not sol.success:
            break
        X = sol.y[:, -1]
        e = error(sol.t, sol.y[:sys.n])
        for i in np.nonzero((e[:-1] < 0.0) & (e[1:] >= 0.0))[0]:
            ups.append(float(sol.t[i] - e[i] * (sol.t[i + 1] - sol.t[i]) / (e[i + 1] - e[i])))
        at = (k // split) * period + phases[k % split]
        pieces.append(error(at, sol.sol(at)[:sys.n]))
        k += 1
        if k % split == 0:
            periods.append(np.concatenate(pieces))
            pieces = []
            e1 = float(2.0 * abs(np.fft.rfft(periods[-1])[1]) / PHASES)
            if len(periods) >= 2:
                change = float(np.max(np.abs(periods[-1] - periods[-2])))
        gaps = np.diff([u for u in ups if u > cycle][-RHYTHM_CROSSINGS - 1:])
        if gaps.size:
            rhythm = float(np.mean(gaps))
        if (len(periods) >= MIN_PERIODS and t1 >= MIN_CYCLES * cycle
                and change <= FOLLOWS * A):
            return DrivenRun("follows", t1, change, e1, rhythm)
        own = (gaps.size == RHYTHM_CROSSINGS
               and bool(np.all(np.abs(gaps / cycle - 1.0) <= RHYTHM)))
        # a rhythm the reference's period may lock: a whole fraction of it, told from the next
        # only below 1 / RHYTHM cycles a period (the hunting loop at 0.001 Hz: 40.92 a period)
        whole = period / rhythm if own else 0.0
        locked = whole < 1.0 / RHYTHM and abs(whole - round(whole)) <= RHYTHM
        if own and (change > FOLLOWS * A or not locked):
            return DrivenRun("hunts", t1, change, e1, rhythm)
    return DrivenRun("unsettled", k * period / split, change, e1, rhythm)


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
    reference's `amplitude` [m]), true of the driven loop.

    Where the fixed point made progress (its last change below
    :data:`~motionhyst.analysis._fixed_point.LARGE_CHANGE` of the answer), or the loop has no
    cycle of its own (:func:`hunting_period`, its setpoint held), `exc` stands.  Else the loop
    driven by the reference is run in time from rest (:func:`driven_run`): where it hunts,
    the refusal says so, with its own cycle's period; where it follows the reference's
    period, `exc` with what the run shows (the loop does not hunt); where it does neither in
    its run, or cannot be run so, `exc` with the cycle the loop has with its setpoint held
    (the describing function's prediction for a loop without a run): it may hunt.

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
    >>> print(hunting_refusal(loop, not_converged(0.005, 50, 0.86), 0.01))
    steady state at 0.005 Hz: the loop hunts: ... of period 24.44 s ...
    >>> print(hunting_refusal(loop, not_converged(0.1, 50, 0.86), 0.01))
    steady state at 0.1 Hz did not converge ...; a run in time from rest follows the ...
    """
    link = loop.hysteresis
    if link is None or not loop.is_lti or not exc.change >= LARGE_CHANGE:
        return exc  # a fixed point that came near an answer: no cycle of its own took over
    f = exc.frequency_hz
    remedy = ("run it in time (motionhyst simulate --time-series)" if _runs_in_time(loop) else
              "run it in time (motionhyst simulate --time-series, with [controller] "
              "derivative_filter_hz: a pure derivative has no run)")
    try:
        cycle = hunting_period(loop, amplitude)
    except ValueError:  # no run of this loop: the describing function's prediction
        predicted = _predicted_period(loop)
        if predicted is None:
            return exc
        return NoFixedPoint(
            f"{exc}; the describing function predicts a stable self-excited limit cycle of "
            f"period {predicted:.4g} s with the setpoint held (motionhyst stability): the "
            f"loop may hunt; {remedy}", f, exc.change)
    except (RuntimeError, ArithmeticError, np.linalg.LinAlgError):
        return exc  # a run that failed finds no cycle: the fixed point's own refusal
    if cycle is None:
        return exc
    held = (f"with its setpoint held the loop has a stable self-excited limit cycle of period "
            f"{cycle:.4g} s (motionhyst stability shows its exact orbit)")
    try:
        run = driven_run(loop, amplitude, f, cycle)
    except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError):
        return NoFixedPoint(f"{exc}; {held}: driven, it may hunt; {remedy}", f, exc.change)
    if run.verdict == "hunts":
        # two whole periods compared, or the rhythm alone within the first: then whether the
        # slips repeat each period (a train the period entrains) was not seen
        seen = (f"its periods differ by {run.change:.2g} m); {held}, so no periodic steady "
                f"state of the reference's period" if np.isfinite(run.change) else
                f"{1 / (f * run.rhythm):.3g} times in the reference's {1 / f:.4g} s period; "
                f"the run covered {run.seconds * f:.2g} of it: whether its slips repeat each "
                f"period was not checked); {held}, and the fixed point found no periodic "
                f"steady state of the reference's period")
        return RuntimeError(
            f"steady state at {f:g} Hz: the loop hunts: driven from rest, a run in time slips "
            f"at its own rhythm (its error crosses zero upward every {run.rhythm:.3g} s, "
            f"{seen}; {remedy}")
    if run.verdict == "follows":
        return NoFixedPoint(
            f"{exc}; a run in time from rest follows the reference's {1 / f:.4g} s period "
            f"(after {run.seconds * f:.3g} periods its error changes by {run.change:.2g} m a "
            f"period, its first harmonic {run.e1:.6g} m): the loop does not hunt"
            + ("" if _runs_in_time(loop) else "; motionhyst simulate --time-series needs "
               "[controller] derivative_filter_hz (a pure derivative has no run)"), f,
            exc.change)
    return NoFixedPoint(
        f"{exc}; a run in time from rest has not settled on the reference's {1 / f:.4g} s "
        f"period in {run.seconds:.4g} s and {held}: it may hunt; {remedy}", f, exc.change)


def steady_state_unless_hunting(loop: Loop, amplitude: float, frequency_hz: float
                                ) -> SteadyState:
    """:func:`~motionhyst.analysis.steady.periodic_steady_state`; a fixed point that does not
    converge because the driven loop hunts (a run in time from rest) is refused saying so,
    with the cycle's period, and one whose driven loop follows the reference says what the
    run shows (:func:`hunting_refusal`).

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
