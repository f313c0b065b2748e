"""The judgement of the steady state's fixed point: an answer only where it has converged.

The exact steady state (:mod:`motionhyst.analysis.steady`) iterates
``y1 = y1_lin + T_{w->y1} w(y1)``.  A change of the link's force comes back through the loop
multiplied, at the ``n``-th harmonic, by the link's local stiffness times ``T_{w->y1}(j n w)``;
a link's damping ``c`` gives it ``|T_{w->y1}(j n w) j n w c|``, on Table I at most 7.0e-4 c at
690 Hz (the stage's resonance).  Above 1 that harmonic of the iteration grows each pass from
round-off; its first harmonic, which the stopping rule watches, may still settle: a LuGre
link of sigma2 = 1e4 N s/m once "converged" with an error of 7e19 m at 695 Hz.  A damping that
acts at every amplitude (LuGre's ``sigma2``) is solved with the linear loop
(:func:`viscous_damping`); what remains is watched pass by pass (:class:`Passes`): the change
of every harmonic of the error, refused as soon as it grows pass after pass above the
answer's accuracy, and judged once the first harmonic has settled.

A damping that acts only part of the period (LuGre's ``sigma1``, while the link sticks)
cannot be solved with the loop that way; where it makes the plain pass ``x <- g(x)``
contract slowly or grow at a few harmonics (the stage's resonance), the passes are mixed
(:class:`Mixing`, Anderson acceleration): each takes the combination of the last passes'
``g(x)`` whose residual ``g(x) - x`` is least, which converges where those few harmonics of
the plain pass grow, and the iteration stops at the same fixed point.  Mixed passes that still
make progress after the pass limit go on, up to :data:`EXTRA_PASSES` times it
(:class:`Progress`); an iteration left unfinished is refused as slow, not as a stiff link.

A link that sticks (LuGre's bristles, ``sigma0`` far above the loop's stiffness: a PID on a
1 kg stage against 1e5 N/m) returns a change of its force multiplied by its stiffness times
``|T_{w->y1}|``, thousands of times a pass.  Where the passes above are refused, the link's
stiffness and damping while it sticks (:func:`sticking`) are solved with the loop as the
damping at every amplitude is (:func:`chord`, ``L = k + j n w c``), starting from the loop
with the link stuck; only the link's departure from that spring is iterated, which vanishes
while it sticks and is bounded by ``k`` while it slips (a sampled loop: only where the refusal
is not the link's damping's, which no Floquet multipliers check there).  A loop that converges
without it keeps its passes and its numbers; where it does not converge either, the first
refusal stands.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.lti import TWO_PI

__all__: list[str] = []

#: The last pass may change no harmonic of the error by more than this fraction of the
#: error's RMS (the stopping rule watches the first harmonic of the link's force only) ...
FULL_RESIDUAL = 1e-6
#: ... or by more than this fraction where that change is shrinking pass by pass (a transient
#: at a lightly damped harmonic settling: the 10 kHz loop with LuGre sigma1 = 700 at 1 mm
#: ends with 1.7e-6 of its RMS at 705 Hz, and its answer agrees with a run in time to 3e-8).
SETTLING_RESIDUAL = 1e-4
#: Passes in a row whose change of the error grows (by more than :data:`GROWTH`) before the
#: iteration is refused as diverging, once that change exceeds :data:`FULL_RESIDUAL` of the
#: error's RMS; or :data:`GROWING_PASSES_LARGE` passes once it exceeds :data:`LARGE_CHANGE`.
#: A converging iteration can grow for several passes at the stage's resonance before it
#: decays (Table I, LuGre sigma1 = 1500 at 3.16 mm: 5 passes, to 3e-3 of the error's RMS).
GROWING_PASSES = 10
GROWING_PASSES_LARGE = 3
LARGE_CHANGE = 0.1
GROWTH = 1.05
#: Passes in a row that bring the change of the error no lower than its smallest so far,
#: while it exceeds :data:`LARGE_CHANGE` of the error's RMS, before the iteration is refused:
#: mixed passes (:class:`Mixing`) do not shrink pass by pass, a stalled mixture does not
#: shrink at all.
STALLED_PASSES = 5
#: The passes whose pairs ``(x, g(x))`` a mixed pass combines (:class:`Mixing`): Table I's
#: LuGre with sigma1 = 1e4 at 10 mm converges in 41 passes with 10 (37 with 20, 34 with 30),
#: not in 50 with 5.
MEMORY = 10
#: The plain passes run while each shrinks the residual ``max |g(x) - x|`` to at most this
#: fraction of the pass before's (a fixed point that contracts fast is computed as it always
#: was, to the bit); the first pass that does not starts the mixing.
SLOW = 0.5
#: Passes beyond the limit, as a multiple of it, that an iteration still making progress
#: (:class:`Progress`) may run before it is refused as slow: Table I's LuGre with sigma1 =
#: 1e4 at 1 mm, 5 Hz ended its 50 mixed passes at a relative change of 6.3e-7.
EXTRA_PASSES = 3
#: The passes over which :class:`Progress` compares the smallest residual with that of as
#: many passes before.
PROGRESS_WINDOW = 10


class FixedPointError(RuntimeError):
    """The fixed point of the steady state refused: it diverged, stalled or did not finish in
    its passes (:class:`Passes`, :func:`not_converged`)."""


class NoFixedPoint(FixedPointError):
    """The fixed point did not converge in its passes at `frequency_hz` [Hz] (a link too
    stiff for the loop, or a loop with no steady state of the reference's period: one that
    hunts); a caller that can tell which says so.  `change` is the last pass's relative
    change of the link force's first harmonic after all passes (:func:`not_converged`; a loop
    that hunts leaves it large, above :data:`LARGE_CHANGE`), unknown (inf) for passes refused
    as they grow or stall (:meth:`Passes.refuse`)."""

    def __init__(self, message: str, frequency_hz: float, change: float = np.inf) -> None:
        super().__init__(message)
        self.frequency_hz = float(frequency_hz)
        self.change = float(change)


def not_converged(frequency_hz: float, max_iter: int, residual: float) -> NoFixedPoint:
    """The refusal of a fixed point that did not converge in `max_iter` passes: one that
    still changes its answer by a tenth (:data:`LARGE_CHANGE`) made no progress (a link too
    stiff for the loop, or a loop that hunts); one below that is slow.

    Examples
    --------
    >>> from motionhyst.analysis._fixed_point import not_converged
    >>> print(not_converged(5.0, 200, 6.3e-7))
    steady state at 5 Hz did not converge in 200 iterations (relative change 6.3e-07): its \
passes are too slow for this loop; no answer is given: run the loop in time (motionhyst \
simulate --time-series)
    """
    why = ("the dynamic link is too stiff for this loop" if not residual < LARGE_CHANGE else
           "its passes are too slow for this loop; no answer is given: run the loop in time "
           "(motionhyst simulate --time-series)")
    return NoFixedPoint(
        f"steady state at {frequency_hz:g} Hz did not converge in {max_iter} iterations "
        f"(relative change {residual:.2g}): {why}", frequency_hz, residual)


class Progress:
    """The pass limit of a fixed point: `max_iter` passes, and up to :data:`EXTRA_PASSES`
    times as many more while the smallest relative change of the last :data:`PROGRESS_WINDOW`
    passes is below half that of the window before (mixed passes do not shrink pass by
    pass).

    Examples
    --------
    >>> from motionhyst.analysis._fixed_point import Progress
    >>> shrinking, stalled = Progress(20), Progress(20)
    >>> all(shrinking.more(it, 0.9 ** it) for it in range(1, 20))
    True
    >>> shrinking.more(20, 0.9 ** 20)            # still shrinking after 20 passes: on
    True
    >>> [stalled.more(it, 1e-6) for it in range(1, 21)][-1]   # no progress: refused
    False
    """

    def __init__(self, max_iter: int) -> None:
        self.max_iter = int(max_iter)
        self.residuals: list[float] = []

    def more(self, it: int, residual: float) -> bool:
        """Whether a pass may follow pass `it`, whose relative change was `residual`."""
        self.residuals.append(float(residual))
        if it < self.max_iter:
            return True
        if it >= (1 + EXTRA_PASSES) * self.max_iter or len(self.residuals) < 2 * PROGRESS_WINDOW:
            return False
        last = min(self.residuals[-PROGRESS_WINDOW:])
        before = min(self.residuals[-2 * PROGRESS_WINDOW:-PROGRESS_WINDOW])
        return last < 0.5 * before


def sticking(link) -> tuple[float, float]:
    """The link's stiffness [N/m] and damping [N s/m] while it sticks: its
    :meth:`~motionhyst.hysteresis.base.Hysteresis.initial_stiffness` (0 where it is not finite
    and positive) and its :func:`viscous_damping`, with its
    :attr:`~motionhyst.hysteresis.base.Hysteresis.bristle_damping` (LuGre's ``sigma1``: its
    force ``sigma0 z + sigma1 dz/dt + sigma2 v``, Canudas de Wit et al. 1995, is that of a
    spring and dampers for ``z = y1`` while it sticks).

    Examples
    --------
    >>> from motionhyst.analysis._fixed_point import sticking
    >>> from motionhyst.hysteresis import LuGre
    >>> sticking(LuGre(sigma0=1e5, sigma1=316.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3))
    (100000.0, 316.4)
    """
    k = float(link.initial_stiffness) if link is not None else 0.0
    c = viscous_damping(link) + (link.bristle_damping if link is not None else 0.0)
    return (k if np.isfinite(k) and k > 0 else 0.0), c


def viscous_damping(link) -> float:
    """The part of a link's force linear in its velocity at every amplitude [N s/m]: its
    :attr:`~motionhyst.hysteresis.base.Hysteresis.viscous_damping` (LuGre's ``sigma2``, the
    mean of an asymmetric Coulomb link's ``c_pos`` and ``c_neg``; along the stroke, the
    largest along the table); 0 without a link."""
    return 0.0 if link is None else float(link.viscous_damping)


def _damping_words(link, solved: bool, omega: float = np.inf) -> str:
    """The link's damping keys and values that the iteration feeds back at the angular
    frequency `omega` [rad/s], for a refusal (empty for a link without any; its
    :func:`viscous_damping` left out where it is `solved` with the loop; LuGre's bristle
    damping only where ``omega sigma1`` exceeds the bristles' stiffness ``sigma0``: below, the
    stiffness is what the loop amplifies).  Read from the model's attributes (a link along
    the stroke's largest along its table), its keys from its base model's."""
    model = getattr(link, "base", link)
    words = []
    if hasattr(model, "c_pos"):
        if (model.c_pos or model.c_neg) and not solved:
            words.append(f"viscous friction c_pos = {model.c_pos:.4g}, c_neg = "
                         f"{model.c_neg:.4g} N s/m")
    elif link.viscous_damping and not solved:
        words.append(f"viscous friction sigma2 = {link.viscous_damping:.4g} N s/m")
    sigma1 = link.bristle_damping
    if sigma1 and omega * sigma1 >= link.initial_stiffness:
        words.append(f"bristle damping sigma1 = {sigma1:.4g} N s/m (while it sticks)")
    return " and ".join(words)


class Passes:
    """The changes of the error's harmonics pass by pass, judged (module docstring).

    Parameters
    ----------
    frequency_hz : float
        The steady state's frequency [Hz].
    link : Hysteresis
        The loop's link, named in a refusal.
    solved : bool
        Whether the link's :func:`viscous_damping` is solved with the loop (not named).
    """

    def __init__(self, frequency_hz: float, link, solved: bool = False) -> None:
        self.frequency_hz = float(frequency_hz)
        self.link = link
        self.solved = bool(solved)
        self.sizes: list[float] = []
        self.growing = 0
        self.stalled = 0
        self.last: NDArray[np.complex128] | None = None

    def step(self, dE: NDArray[np.complex128], E: NDArray[np.complex128]) -> None:
        """Record a pass's change `dE` of the error's harmonics ``0 .. H`` (`E` after it);
        raise RuntimeError (:meth:`refuse`) once it has grown :data:`GROWING_PASSES` passes in a row
        above :data:`FULL_RESIDUAL` of the error's RMS, or :data:`GROWING_PASSES_LARGE` passes
        above :data:`LARGE_CHANGE` of it, or stalled :data:`STALLED_PASSES` passes above
        :data:`LARGE_CHANGE` of it."""
        size = float(np.max(np.abs(dE)))
        if self.sizes and size > GROWTH * self.sizes[-1]:
            self.growing += 1
        else:
            self.growing = 0
        growth = size / self.sizes[-1] if self.sizes and self.sizes[-1] > 0 else np.inf
        smallest = min(self.sizes, default=np.inf)
        self.stalled = self.stalled + 1 if self.sizes and not size < smallest else 0
        self.sizes.append(size)
        self.last = dE
        rms = _rms(E)
        stalled = self.stalled >= STALLED_PASSES and size > LARGE_CHANGE * rms
        if stalled:  # the growth a pass, on average, since the smallest change
            growth = (size / smallest) ** (1.0 / self.stalled) if smallest > 0 else np.inf
        if ((self.growing >= GROWING_PASSES and size > FULL_RESIDUAL * rms)
                or (self.growing >= GROWING_PASSES_LARGE and size > LARGE_CHANGE * rms)
                or stalled):
            self.refuse(f"diverges: a change of the error grows {growth:.3g} times a pass",
                        dE, len(self.sizes))

    def judge(self, E: NDArray[np.complex128], last: NDArray[np.complex128] | None = None,
              passes: int | None = None) -> None:
        """Raise RuntimeError unless the last pass (`last` given: its change of the error,
        after `passes` passes) changed every harmonic of the error `E` by at most
        :data:`FULL_RESIDUAL` of its RMS, or :data:`SETTLING_RESIDUAL` where the passes
        recorded show that change shrinking."""
        settling = last is None and len(self.sizes) >= 2 and self.sizes[-1] < self.sizes[-2]
        last = self.last if last is None else last
        if last is None:
            return
        size = float(np.max(np.abs(last)))
        limit = SETTLING_RESIDUAL if settling else FULL_RESIDUAL
        if not (size <= limit * _rms(E)):  # a NaN is refused too
            self.refuse(f"has not converged at every harmonic (its first harmonic has): the "
                        f"last pass changed the error by {size:.3g} m", last,
                        len(self.sizes) if passes is None else passes)

    def refuse(self, what: str, dE: NDArray[np.complex128], passes: int) -> None:
        """Raise the refusal: `what` the iteration did, at the harmonic where `dE` is largest;
        where no damping of the link explains it there, a :class:`NoFixedPoint`, whose caller
        can tell whether the loop hunts (mixed passes of such a loop grow or stall too)."""
        n = int(np.nanargmax(np.abs(dE))) if np.any(np.isfinite(dE)) else 0
        words = _damping_words(self.link, self.solved, TWO_PI * n * self.frequency_hz)
        which = "damping" if words else "stiffness"
        message = (
            f"steady state at {self.frequency_hz:g} Hz: the fixed point {what} at harmonic "
            f"{n} ({n * self.frequency_hz:.4g} Hz) after {passes} passes: the link's "
            f"{words or 'stiffness'}, fed back through the loop, amplifies each pass there; "
            f"no answer is given: run the loop in time (motionhyst simulate --time-series) or "
            f"lower the link's {which}")
        if words:
            raise FixedPointError(message)
        raise NoFixedPoint(message, self.frequency_hz)


def _rms(E: NDArray[np.complex128]) -> float:
    """RMS over a period of the signal of one-sided harmonics `E` (``rfft / N`` scaling)."""
    E = np.asarray(E)
    return float(np.sqrt(abs(E[0]) ** 2 + 2.0 * np.sum(np.abs(E[1:]) ** 2)))


def chord(G_1: NDArray[np.complex128], frequency_hz: float, c: float, k: float = 0.0):
    """The linear spring's and damping's force per harmonic ``L = k + j n w c`` and the
    loop's ``1 / (1 - T_{w->y1} L)`` with it, or None for ``c = k = 0`` (or a loop that they
    make singular at a harmonic)."""
    if not (c > 0 or k > 0):
        return None
    L = k + 1j * TWO_PI * float(frequency_hz) * np.arange(G_1.size) * c
    den = 1.0 - G_1 * L
    if not np.all(np.abs(den) > 1e-6):
        return None
    return L, 1.0 / den


class Mixing:
    """Anderson acceleration of the fixed point ``x = g(x)`` (Walker and Ni, SIAM J. Numer.
    Anal. 49, 2011, "type II"), started once a plain pass is slow (:data:`SLOW`).

    A mixed pass goes to ``g(x_k) - dG gamma``, with ``dG`` the differences of the last
    :data:`MEMORY` passes' ``g(x)`` and ``gamma`` the real coefficients that minimise
    ``|f_k - dF gamma|`` (``f = g(x) - x``, ``dF`` its differences) in least squares: for a
    linear ``g`` the Krylov iterate of GMRES, which converges where a few harmonics of the
    plain pass grow.  Real coefficients keep a real signal's mean real.  The fixed point is
    that of the plain pass: only the way to it changes.

    Examples
    --------
    The fixed point of ``x = 2 x - 1`` (plain passes diverge from any ``x`` but 1):

    >>> import numpy as np
    >>> from motionhyst.analysis._fixed_point import Mixing
    >>> mixing, x = Mixing(), np.array([0.0 + 0.0j])
    >>> for _ in range(4):
    ...     x = mixing.next(x, 2.0 * x - 1.0)
    >>> complex(x[0]), mixing.engaged
    ((1+0j), True)
    """

    def __init__(self, memory: int = MEMORY) -> None:
        self.memory = int(memory)
        self.engaged = False
        self.xs: list[NDArray[np.complex128]] = []
        self.gs: list[NDArray[np.complex128]] = []
        self.size = np.inf

    def next(self, x: NDArray[np.complex128], gx: NDArray[np.complex128]
             ) -> NDArray[np.complex128]:
        """The next pass's ``x`` after the pass that mapped `x` to `gx`: `gx` itself while the
        passes are plain, their mixture once one was slow (:data:`SLOW`)."""
        size = float(np.max(np.abs(gx - x)))
        if not self.engaged and self.xs and not size <= SLOW * self.size:
            self.engaged = True
        self.size = size
        self.xs = [*self.xs[-self.memory:], np.array(x, dtype=complex)]
        self.gs = [*self.gs[-self.memory:], np.array(gx, dtype=complex)]
        if not self.engaged or len(self.xs) < 2:
            return gx
        G = np.stack(self.gs, axis=1)
        F = G - np.stack(self.xs, axis=1)
        dF, dG = np.diff(F, axis=1), np.diff(G, axis=1)
        gamma = np.linalg.lstsq(np.concatenate([dF.real, dF.imag]),
                                np.concatenate([F[:, -1].real, F[:, -1].imag]), rcond=None)[0]
        mixed = gx - dG @ gamma
        return mixed if np.all(np.isfinite(mixed)) else gx


class ContinuousPasses:
    """The passes of the continuous loop's fixed point ``y1 = y1_lin + T_{w->y1} (w(y1) -
    U_h)`` (:mod:`motionhyst.analysis.steady`) for one link, frequency and reference.

    Parameters
    ----------
    hyst : Hysteresis
        The link.
    frequency_hz : float
        The reference's frequency [Hz].
    H : int
        The highest harmonic kept.
    y1_lin, e_lin, U_h : ndarray of complex
        Harmonics ``0 .. H`` (``rfft / N`` scaling) of the linear loop's ``y1`` and ``e`` and
        of the feedforward's force on the link's side.
    T : tuple
        The loop's transfers at the harmonics (``w_y1``, ``w_e``).
    tol, max_iter : float, int
        The stopping rule's tolerance and the pass limit (:class:`Progress`).
    """

    def __init__(self, hyst, frequency_hz: float, H: int, y1_lin, e_lin, U_h, T, tol: float,
                 max_iter: int) -> None:
        self.hyst, self.frequency_hz, self.H = hyst, float(frequency_hz), H
        self.y1_lin, self.e_lin, self.U_h, self.T = y1_lin, e_lin, U_h, T
        self.tol, self.max_iter = float(tol), int(max_iter)

    def passes(self, linear, X: NDArray[np.complex128], W: NDArray[np.complex128]
               ) -> tuple[NDArray[np.complex128], NDArray[np.complex128], int, float]:
        """The link's force ``W`` and displacement ``X`` at the fixed point, the passes and
        the last relative change, from `X` (`W` the force the first pass is compared with);
        `linear` the link's part solved with the loop (:func:`chord`) or None.  Raises
        :class:`FixedPointError` where it does not converge."""
        hyst, T, G_1, y1_lin, U_h = self.hyst, self.T, self.T.w_y1, self.y1_lin, self.U_h
        omega = TWO_PI * self.frequency_hz
        previous, residual, it = np.inf, np.inf, 0
        passes = Passes(self.frequency_hz, hyst, solved=linear is not None)
        mixing, limit = Mixing(), Progress(self.max_iter)
        while True:
            it += 1
            W_new = hyst.periodic_harmonics(X, self.H, omega)
            if linear is None:
                X_new = y1_lin + G_1 * (W_new - U_h)
            else:  # W_new + L (X_new - X): the force with its linear part at X_new
                L, inverse = linear
                X_new = (y1_lin + G_1 * (W_new - L * X - U_h)) * inverse
                W_new = W_new + L * (X_new - X)
            change = float(np.max(np.abs(W_new - W)))
            residual = float(abs(W_new[1] - W[1]) / max(abs(W_new[1]), 1e-300))
            passes.step(T.w_e * (W_new - W), self.e_lin + T.w_e * (W_new - U_h))
            W, X, X_in = W_new, X_new, X
            # error of a contraction with observed rate rho is about residual * rho / (1 - rho)
            rho = residual / previous if it > 2 and previous > 0 else 1.0
            previous = residual
            if it > 1 and (change == 0.0
                           or (rho < 0.5 and residual * rho / (1 - rho) <= self.tol)):
                break
            if not limit.more(it, residual):
                raise not_converged(self.frequency_hz, it, residual)
            X = mixing.next(X_in, X_new)
        passes.judge(self.e_lin + T.w_e * (W - U_h))
        return W, X, it, residual
