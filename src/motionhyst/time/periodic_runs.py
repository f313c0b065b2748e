"""The open loop's periodic steady state: periods run until the output repeats.

A periodic force record is run period after period from the state the
previous one left, until the output (and its sensitivities, when asked)
repeats (:func:`periodic_output`).  Only the link holds a floating stage (the
two-mass stage, or ``k = 0``) in place: its steady state is defined up to a
constant and returned with zero mean, and a stage that moves on by the same
distance every period (a slipping element, a Bouc-Wen link ratcheting under
an unsymmetric force) is reported as having none (:func:`settled`).  A
floating stage without a link has its steady state from the record's
spectrum (:func:`floating_linear_periodic`).

Examples
--------
>>> import numpy as np
>>> y = np.sin(np.linspace(0.0, 2 * np.pi, 100))
>>> settled(y, y + 1e-15, floating=False, last_step=[])
True
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from motionhyst.plants.mechanics import Mechanics

__all__ = ["EXTRAPOLATION_PERIODS", "MAX_PERIODIC_DECAYS", "MIN_PERIOD_SAMPLES", "NEUTRAL_RTOL",
           "PERIODIC_RTOL",
           "ROUNDING_RTOL", "STALL_PERIODS", "PeriodExtrapolation",
           "newton_periodic", "periodic_output", "settled", "whole_periods"]

#: A period's output repeats the previous one to this fraction of its amplitude.
PERIODIC_RTOL = 1e-12
#: Singular values of ``I - M`` (the period map's, equilibrated) below this fraction of the
#: largest are directions the period does not forget (:func:`newton_periodic`)
NEUTRAL_RTOL = 1e-9
#: Periodic runs stop after this many time constants of the slowest mode.
MAX_PERIODIC_DECAYS = 60.0
#: A record is run as one period repeated only if its period has this many samples
MIN_PERIOD_SAMPLES = 16
#: Period-start states that one extrapolation of the period map's fixed point takes
EXTRAPOLATION_PERIODS = 6
#: A run whose change from period to period has not shrunk below its smallest for this many
#: periods has reached the rounding of its arithmetic (two extrapolations)
STALL_PERIODS = 2 * EXTRAPOLATION_PERIODS
#: ... and is taken as settled if that change is below this fraction of the output's amplitude
ROUNDING_RTOL = 1e-6


_NO_STEADY_STATE = ("the periodic steady state was not reached (the response does not settle "
                    "from one period to the next)")
_FLOATING_HINT = ("; the stage floats and the link does not hold it in place: it drifts")


def settled(y: NDArray[np.float64], prev: NDArray[np.float64], floating: bool,
             last_step: list[float]) -> bool:
    """True if a period's output `y` repeats the previous one to :data:`PERIODIC_RTOL`.

    A floating stage whose link lets it move on by the same distance every
    period (a Bouc-Wen link ratchets under an unsymmetric force; a slipping
    element does not hold the stage) has no periodic steady state: raised as
    such, with the drift, once the motion repeats and its position moves on by
    the same step twice (`last_step` keeps the previous step).

    Parameters
    ----------
    y, prev : ndarray
        This period's output and the previous period's.
    floating : bool
        True for a floating stage (defined up to a constant).
    last_step : list of float
        The drift of the previous period (empty at first), updated.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.sin(np.linspace(0.0, 2 * np.pi, 100))
    >>> settled(y, y + 1e-15, floating=False, last_step=[]), settled(y, 1.01 * y, False, [])
    (True, False)
    """
    if not floating:
        return bool(np.max(np.abs(y - prev)) <= PERIODIC_RTOL * np.max(np.abs(y)))
    tol = PERIODIC_RTOL * np.ptp(y)
    if np.max(np.abs(y - prev)) <= tol:
        return True
    step = float(np.mean(y) - np.mean(prev))
    if (np.max(np.abs(y - prev - step)) <= tol and abs(step) > 10 * tol and last_step
            and abs(step - last_step[0]) <= 1e-6 * abs(step)):
        raise ValueError(f"no periodic steady state: the stage floats and the link does not "
                         f"hold it in place; it drifts {step:.3g} m per period (only a run "
                         f"from rest describes this force)")
    last_step[:] = [step]
    return False


def whole_periods(u: NDArray[np.float64]) -> int:
    """How many whole periods of one signal the force record `u` holds (1: not periodic).

    A periodic steady state repeats with the force's period, so a record of
    ``n`` periods needs the steady state of one, repeated ``n`` times.

    Parameters
    ----------
    u : ndarray
        The record's samples.

    Examples
    --------
    >>> import numpy as np
    >>> whole_periods(np.tile(np.sin(np.linspace(0, 6, 50)), 4)), whole_periods(np.arange(7.0))
    (4, 1)
    """
    from motionhyst.time.resample import is_periodic_record

    p = is_periodic_record(np.asarray(u, dtype=float))
    # a period of a few samples (a constant force) is left whole: too short to upsample
    return 1 if p is None or p < MIN_PERIOD_SAMPLES else u.size // p


def max_periods(mech: Mechanics, k_link: float, period_s: float) -> int:
    """Periods a periodic run may take: until the slowest mode has decayed
    :data:`MAX_PERIODIC_DECAYS` times (at most 1000, at least 4)."""
    tau = mech.decay_time(k_link)
    if not math.isfinite(tau):
        return 1000
    return int(min(1000, max(4, math.ceil(MAX_PERIODIC_DECAYS * tau / period_s) + 2)))


def periodic_output(next_period, periods: int, floating: bool, sensitivities: bool
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Run periods until the output (and its sensitivities) repeat: the last period's.

    `next_period()` runs one more period from the state the previous one left
    and returns its output and sensitivities, one sample longer than the
    period, and whether the state is still finite.  The output repeats as
    :func:`settled` judges, the sensitivities to 1e-8 of their largest
    values; a floating stage's output is returned with zero mean (it is
    defined up to a constant).

    Some runs never repeat to those tolerances: an output (or a sensitivity) far
    smaller than the states it is computed from, such as a stage clamped by a
    stiff link, changes by the rounding of those states from period to period.
    A run whose output changes by less than :data:`ROUNDING_RTOL` of its
    amplitude, and whose changes (the output's, and the largest of the
    sensitivities', relative to their amplitudes) have not fallen below half
    their smallest so far for
    :data:`STALL_PERIODS` periods, has settled as far as its arithmetic allows: a
    decaying start shrinks the change every period, rounding does not.  Raises if
    `periods` do not settle.

    Parameters
    ----------
    next_period : callable
        ``next_period() -> (y, sy, finite)``: the next period's output and
        sensitivities (one sample longer than the period) and whether the state
        is still finite.
    periods : int
        Periods to run at most.
    floating : bool
        True for a floating stage.
    sensitivities : bool
        True if the sensitivities must settle too.

    Examples
    --------
    A response that forgets its start by a factor 1e-3 per period:

    >>> import numpy as np
    >>> shape = np.sin(2 * np.pi * np.arange(65) / 64)
    >>> runs = iter(shape * (1 + 1e-3 ** k) for k in range(1, 20))
    >>> y, _ = periodic_output(lambda: (next(runs), np.zeros((65, 0)), True), 19,
    ...                        floating=False, sensitivities=False)
    >>> bool(np.allclose(y, shape[:-1], rtol=0, atol=1e-12))
    True

    One whose output changes by rounding noise of 1e-9 of its amplitude, period after
    period, settles after :data:`STALL_PERIODS` periods without a smaller change:

    >>> rng = np.random.default_rng(0)
    >>> noisy = lambda: (shape * (1 + 1e-9 * rng.standard_normal()), np.zeros((65, 0)), True)
    >>> y, _ = periodic_output(noisy, 100, floating=False, sensitivities=False)
    >>> bool(np.allclose(y, shape[:-1], rtol=0, atol=1e-8))
    True
    """
    prev = None
    step: list[float] = []
    smallest = None  # the smallest relative changes so far (output, sensitivities)
    since = 0  # periods since one of them last fell
    for _ in range(periods):
        y, sy, finite = next_period()
        y, sy = y[:-1], sy[:-1]
        if prev is not None:
            ok = settled(y, prev[0], floating, step)
            if sensitivities:
                ok &= bool(np.all(np.max(np.abs(sy - prev[1]), axis=0)
                                  <= 1e-8 * (np.max(np.abs(sy), axis=0) + 1e-300)))
            if not ok:  # rounding reached? (a change that no longer shrinks)
                change = _relative_changes(y, prev[0], sy, prev[1], floating)
                if smallest is None or np.any(change < 0.5 * smallest):
                    since = 0
                    smallest = change if smallest is None else np.minimum(smallest, change)
                else:
                    since += 1
                ok = since >= STALL_PERIODS and bool(change[0] <= ROUNDING_RTOL)
            if ok:
                if floating:  # defined up to a constant: zero mean
                    return y - np.mean(y), sy - np.mean(sy, axis=0)
                return y, sy
        if not finite:
            break
        prev = (y, sy)
    raise ValueError(_NO_STEADY_STATE + (_FLOATING_HINT if floating else ""))


def newton_periodic(run_period, z0: NDArray[np.float64], n_params: int, periods: int,
                    floating: bool,
                    bounds: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
                    gauge: NDArray[np.float64] | None = None
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The periodic steady state by Newton's method on the period map (shooting).

    A period run from the state ``z`` ends in ``F(z)``; the periodic state is
    the fixed point ``z* = F(z*)``.  Each period is run with the sensitivities of
    its end state and output to its start state (the monodromy matrix ``M``),
    and the next start is ``z + (I - M)^-1 (F(z) - z)``: exact at once where
    the period map is affine (a linear plant with a link that holds or slips in
    the same pattern), a few periods otherwise, however lightly damped the
    plant.  The sensitivities ``S`` of the state to the parameters follow the
    same way: ``S <- S + (I - M)^-1 (T - S)``, ``T`` the end state's.  A
    period's output is the steady state once the remaining correction of its
    start changes the output by at most :data:`PERIODIC_RTOL` of its amplitude
    (a floating stage's: of its spread, up to a constant; first order, through
    the output's sensitivities to the start state); its sensitivities, linear
    in their start along that run, are those of the start ``S + dS`` (exact: no
    further period).  The result equals that of periods repeated until they
    settle (:func:`periodic_output`) to its tolerances.

    Some states are not forgotten: a floating stage's position (defined up to
    a constant), the preload of a link that never slips.  Along them ``M`` has
    the eigenvalue 1 (a singular value of ``I - M`` below
    :data:`NEUTRAL_RTOL` of the largest, its states each in units of its
    size).  A floating stage's position (`gauge`) is kept, and what no start
    closes (the part of ``F(z) - z`` outside the range of ``I - M``) is a step
    along it every period once the rest has settled: no periodic steady state
    (raised, with the step); a stage without a link closes its period by its
    momentum.  A preload (a stage on a spring) is kept as the run from `z0`
    has it, as repeating the period does.  The sensitivities of a preload
    depend on the path the run took from `z0` to the steady state, which
    Newton's steps skip; so does a floating stage with other states left
    unchanged: None then (repeat the periods).  A
    correction that no longer shrinks for three periods, below
    :data:`ROUNDING_RTOL` of the amplitude, is the rounding of the states the
    output is computed from (a stage clamped by a stiff link): settled as far as
    the arithmetic allows, as in :func:`periodic_output`.

    Parameters
    ----------
    run_period : callable
        ``run_period(z, S) -> (y, sy, z_end, S_end)``: one period from the state
        `z`, whose sensitivities to the parameters are `S` (``(nz, n_params)``);
        its output `y` (one sample longer than the period), the output's
        sensitivities `sy` (columns: the `n_params` parameters, then the `nz`
        start states), the end state and its sensitivities (the same columns).
    z0 : ndarray
        The first period's start.
    n_params : int
        Number of parameters (0: the output alone).
    periods : int
        Periods to run at most.
    floating : bool
        True for a floating stage.
    bounds : tuple of ndarray, optional
        ``(lo, hi)`` of each state (infinite where it has none): the next start is
        clipped to them (a stop operator's force within its slip force).
    gauge : ndarray, optional
        A floating stage's position shift (the masses' positions 1, the rest 0):
        the state its period leaves unchanged (default: the first state's).

    Returns
    -------
    (y, sy) or None
        The steady state's output over one period (zero mean if floating) and its
        sensitivities to the parameters; None where those depend on the path.

    Examples
    --------
    A period map that is affine, ``F(z) = 0.999 z + 1`` (a mode that forgets its
    start by 0.1 % a period), its output the state: the fixed point 1000 after
    one Newton step, where repeating the period would take thousands.

    >>> import numpy as np
    >>> def run_period(z, S):
    ...     y = np.full(9, z[0])
    ...     sy = np.ones((9, 1))                        # d y / d z
    ...     return y, sy, 0.999 * z + 1.0, np.array([[0.999]])
    >>> y, _ = newton_periodic(run_period, np.zeros(1), 0, 5, floating=False)
    >>> round(float(y[0]), 9), y.size
    (1000.0, 8)
    """
    z = np.array(z0, dtype=float)
    nz = z.size
    S = np.zeros((nz, n_params))
    eye = np.eye(nz)
    g = np.asarray(gauge, dtype=float) if gauge is not None else eye[0]
    smallest, since = math.inf, 0  # the smallest correction so far, periods since
    for _ in range(periods):
        y, sy, z_end, S_end = run_period(z, S)
        if not (np.all(np.isfinite(z_end)) and np.all(np.isfinite(S_end))
                and np.all(np.isfinite(y))):
            break
        M, T = S_end[:, n_params:], S_end[:, :n_params]
        # equilibrated: each state in units of its size (positions, velocities, forces)
        d = np.maximum(np.abs(z), np.abs(z_end))
        d = np.where(d > 0, d, 1.0)
        A = (eye - M) * d / d[:, None]
        rhs = np.column_stack([z_end - z, T - S]) / d[:, None]
        U, sv, Vt = np.linalg.svd(A)
        null = sv <= NEUTRAL_RTOL * sv[0]
        gauge_drift = False  # the correction's border is a floating stage's step per period
        if null.any():
            V, L = Vt[null].T, U[:, null]  # right (unchanged states) and left (conserved)
            k = V.shape[1]
            if floating:  # its position: pinned; what no start closes, along L
                g_s = g / d
                g_s = g_s / np.linalg.norm(g_s)
                if k > 1 or abs(float(V[:, 0] @ g_s)) < 0.99:
                    return None  # other states left unchanged too: repeat the periods
                pin = (g * d / np.linalg.norm(g * d))[:, None]
                if abs(float(L[:, 0] @ g_s)) > 1e-6:  # a step along the gauge: mu [m]
                    border, gauge_drift = (g / d)[:, None], True
                else:  # the gauge is in the range (a free rigid body): L is what no start closes
                    border = L
            else:  # a preload: the conserved part kept, what remains a step along V
                if np.min(np.linalg.svd(L.T @ V, compute_uv=False)) < 1e-6:
                    return None
                border, pin = V, L
            A = np.block([[A, border], [pin.T, np.zeros((k, k))]])
            rhs = np.vstack([rhs, np.zeros((k, rhs.shape[1]))])
        step = np.linalg.lstsq(A, rhs, rcond=None)[0]
        delta, dS = step[:nz, 0] * d, step[:nz, 1:] * d[:, None]
        y, sy_all = y[:-1], sy[:-1]
        Y_z = sy_all[:, n_params:]
        ey = Y_z @ delta
        if floating:
            ey = ey - np.mean(ey)
        amp = float(np.ptp(y) if floating else np.max(np.abs(y)))
        change = _relative(float(np.max(np.abs(ey))), amp)
        if change < 0.5 * smallest:
            smallest, since = change, 0
        else:
            since += 1
        if change <= PERIODIC_RTOL or (since >= 3 and change <= ROUNDING_RTOL):
            if n_params and null.sum() > int(floating):
                return None  # a preload the parameters move along the path from z0
            if null.any():  # what no start removes: a step every period
                if gauge_drift:
                    step_m = float(step[nz, 0])
                    if abs(step_m) > 10 * PERIODIC_RTOL * amp:
                        raise ValueError(
                            f"no periodic steady state: the stage floats and the link does "
                            f"not hold it in place; it drifts {step_m:.3g} m per period (only "
                            f"a run from rest describes this force)")
                elif np.max(np.abs(Y_z @ ((border @ step[nz:, 0]) * d))) > 10 * PERIODIC_RTOL * amp:
                    break
            # the sensitivities are linear in their start along this (settled) run: those of
            # the periodic ones' start, S + dS, exactly
            sy_p = sy_all[:, :n_params] + Y_z @ dS
            if floating:
                return y - np.mean(y), sy_p - np.mean(sy_p, axis=0)
            return y, sy_p
        z = z + delta
        S = S + dS
        if bounds is not None:
            z = np.clip(z, *bounds)
    raise ValueError(_NO_STEADY_STATE + (_FLOATING_HINT if floating else ""))


def _relative(change: float, amp: float) -> float:
    """`change` relative to the output's amplitude `amp`; an output that stays exactly zero
    (a stage at rest under a zero force) has not changed at all."""
    if amp > 0:
        return change / amp
    return 0.0 if change == 0 else math.inf


def _relative_changes(y: NDArray[np.float64], prev: NDArray[np.float64],
                      sy: NDArray[np.float64], sprev: NDArray[np.float64], floating: bool
                      ) -> NDArray[np.float64]:
    """The output's change from the previous period relative to its amplitude (a floating
    stage's spread), and the largest of the sensitivities' relative to their largest values."""
    amp = float(np.ptp(y) if floating else np.max(np.abs(y)))
    dy = _relative(float(np.max(np.abs(y - prev))), amp)
    ds = np.max(np.abs(sy - sprev), axis=0) / (np.max(np.abs(sy), axis=0) + 1e-300)
    return np.array([dy, float(np.max(ds, initial=0.0))])


class PeriodExtrapolation:
    """The periodic state extrapolated from the states that successive periods start from.

    Repeating a period is a fixed-point iteration ``z <- F(z)`` of the state at
    the period's start; a lightly damped mode (a floating stage on its link's
    spring) forgets its start only over many periods.  Near the steady state
    ``F`` is nearly affine, and every :data:`EXTRAPOLATION_PERIODS` states
    ``z_0 .. z_k`` give its fixed point by reduced-rank extrapolation (RRE,
    Sidi 2017, ch. 1): ``z* = sum g_j z_j`` with ``sum g_j = 1`` minimising
    ``|sum g_j (z_{j+1} - z_j)|`` (each component scaled by its block's
    spread), exact for an affine map with up to ``k - 1`` modes.  Blocks
    named in `bounded` (element states with a range, such as a stop
    operator's force within its slip force) are clipped to it.  The run
    continues from ``z*``; the periodic check (:func:`periodic_output`) still
    decides when the output repeats.

    Parameters
    ----------
    bounded : dict, optional
        Block index -> ``(lo, hi)``, arrays of the block's shape (or scalars).
    periods : int
        States per extrapolation.
    weighted : tuple of int, optional
        The blocks whose differences choose the weights ``g`` (default: all); the
        others are combined with the same weights, so that a run with them follows
        the same states as one without.
    own : tuple of int
        Blocks extrapolated with weights chosen from their own differences
        (sensitivities: given the states, an affine map of their own, which the
        states' weights fit only as the states settle); the states do not depend
        on them, so the run's states are those of a run without them.

    Examples
    --------
    An affine map with a slowly decaying rotation (a lightly damped mode): its fixed point
    ``(1, 2)`` from six iterates, where iterating alone is still 0.2 away:

    >>> import numpy as np
    >>> c, s = 0.98 * np.cos(0.3), 0.98 * np.sin(0.3)
    >>> A, b = np.array([[c, -s], [s, c]]), np.array([1.0, 2.0])
    >>> step = lambda z: A @ (z - b) + b
    >>> ex, z = PeriodExtrapolation(), np.zeros(2)
    >>> for _ in range(6):
    ...     z = step(z)
    ...     jump = ex([z])
    >>> [round(float(v), 9) for v in jump[0]], round(float(np.linalg.norm(z - b)), 1)
    ([1.0, 2.0], 2.0)
    """

    def __init__(self, bounded: dict[int, tuple] | None = None,
                 periods: int = EXTRAPOLATION_PERIODS,
                 weighted: tuple[int, ...] | None = None,
                 own: tuple[int, ...] = ()) -> None:
        self.bounded = dict(bounded or {})
        self.periods = int(periods)
        self.weighted = weighted
        self.own = tuple(own)
        self.history: list[list[NDArray[np.float64]]] = []

    def __call__(self, blocks: list[NDArray[np.float64]]) -> list[NDArray[np.float64]] | None:
        """Record the state a period starts from; every `periods` states, the extrapolated
        state (same blocks, copies), else None."""
        self.history.append([np.array(b, dtype=float, copy=True) for b in blocks])
        if len(self.history) < self.periods:
            return None
        hist, self.history = self.history, []
        Z = np.array([np.concatenate([b.ravel() for b in h]) for h in hist])  # (k + 1, n)
        if not np.all(np.isfinite(Z)):
            return None
        shared = [j for j in range(len(hist[-1])) if j not in self.own
                  and (self.weighted is None or j in self.weighted)]
        g = _rre_weights(Z, hist[-1], shared)
        if g is None:
            return None
        z = g @ Z[:-1]
        if self.own:  # blocks with weights of their own (where they are not found, the shared)
            g_own = _rre_weights(Z, hist[-1], list(self.own))
            z_own = g_own @ Z[:-1] if g_own is not None else z
            i = 0
            for j, b in enumerate(hist[-1]):
                if j in self.own:
                    z[i:i + b.size] = z_own[i:i + b.size]
                i += b.size
        out, i = [], 0
        for j, b in enumerate(hist[-1]):
            block = z[i:i + b.size]
            block = block.reshape(b.shape)
            if j in self.bounded and b.size:
                block = np.clip(block, *self.bounded[j])
            out.append(block)
            i += b.size
        return out if all(np.all(np.isfinite(b)) for b in out) else None


def _rre_weights(Z: NDArray[np.float64], blocks: list[NDArray[np.float64]], which: list[int]
                 ) -> NDArray[np.float64] | None:
    """The weights ``g`` (``sum g = 1``) minimising ``|sum g_j (z_{j+1} - z_j)|`` over the
    blocks `which` of the states `Z` (rows), each block scaled by its spread; None if not
    found."""
    scale = np.zeros(Z.shape[1])
    i = 0
    for j, b in enumerate(blocks):
        if b.size and j in which:
            spread = float(np.max(np.abs(Z[:, i:i + b.size] - Z[-1, i:i + b.size])))
            scale[i:i + b.size] = 1.0 / spread if spread > 0 else 0.0
        i += b.size
    D = np.diff(Z, axis=0) * scale  # (k, n)
    G = D @ D.T
    k = G.shape[0]
    # min |D^T g| with sum g = 1: G g = lambda 1 (Lagrange), solved in the least-squares sense
    try:
        g = np.linalg.lstsq(G + 1e-14 * np.trace(G) * np.eye(k), np.ones(k), rcond=None)[0]
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(g)) or abs(np.sum(g)) < 1e-300:
        return None
    return g / np.sum(g)


def floating_linear_periodic(mech: Mechanics, u: NDArray[np.float64], fs: float
                              ) -> NDArray[np.float64]:
    """Periodic steady state of a floating plant without a link, from the record's spectrum.

    Nothing damps its rigid-body motion, so repeating the period never forgets
    the start; the steady state is ``G(f) U(f)`` line by line (exact for a
    band-limited period), with zero mean.  A force with a nonzero mean has none.
    """
    U = np.fft.rfft(u)
    if abs(U[0]) > 1e-9 * max(float(np.max(np.abs(U))), 1e-300):
        raise ValueError("the force has a nonzero mean: a floating stage without a link "
                         "runs away and has no periodic steady state")
    f = np.fft.rfftfreq(u.size, 1.0 / fs)
    Y = np.zeros_like(U)
    Y[1:] = mech.frequency_response(f[1:]) * U[1:]
    if u.size % 2 == 0:
        Y[-1] = Y[-1].real  # the Nyquist line of a real signal
    return np.fft.irfft(Y, u.size)
