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

__all__ = ["EXTRAPOLATION_PERIODS", "MAX_PERIODIC_DECAYS", "MIN_PERIOD_SAMPLES", "PERIODIC_RTOL",
           "ROUNDING_RTOL", "STALL_PERIODS", "PeriodExtrapolation", "periodic_output", "settled",
           "whole_periods"]

#: A period's output repeats the previous one to this fraction of its amplitude.
PERIODIC_RTOL = 1e-12
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


def _relative_changes(y: NDArray[np.float64], prev: NDArray[np.float64],
                      sy: NDArray[np.float64], sprev: NDArray[np.float64], floating: bool
                      ) -> NDArray[np.float64]:
    """The output's change from the previous period relative to its amplitude (a floating
    stage's spread), and the largest of the sensitivities' relative to their largest values."""
    amp = float(np.ptp(y) if floating else np.max(np.abs(y)))
    dy = float(np.max(np.abs(y - prev))) / amp if amp > 0 else math.inf
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
