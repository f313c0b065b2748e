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


class NoFixedPoint(RuntimeError):
    """The fixed point did not converge in its passes at `frequency_hz` [Hz] (a link too
    stiff for the loop, or a loop with no steady state of the reference's period: one that
    hunts); a caller that can tell which says so."""

    def __init__(self, message: str, frequency_hz: float) -> None:
        super().__init__(message)
        self.frequency_hz = float(frequency_hz)


def not_converged(frequency_hz: float, max_iter: int, residual: float) -> NoFixedPoint:
    """The refusal of a fixed point that did not converge in `max_iter` passes."""
    return NoFixedPoint(
        f"steady state at {frequency_hz:g} Hz did not converge in {max_iter} iterations "
        f"(relative change {residual:.2g}); the dynamic link is too stiff for this loop",
        frequency_hz)


def viscous_damping(link) -> float:
    """The part of a link's force linear in its velocity at every amplitude [N s/m]: LuGre's
    ``sigma2``, the mean of an asymmetric Coulomb link's ``c_pos`` and ``c_neg``; 0 else."""
    if link is None:
        return 0.0
    if type(link).__name__ == "LuGre":
        return float(link.sigma2)
    if type(link).__name__ == "Coulomb":
        return 0.5 * float(link.c_pos + link.c_neg)
    return 0.0


def _damping_words(link, solved: bool) -> str:
    """The link's damping keys and values that the iteration feeds back, for a refusal (empty
    for a link without any; its :func:`viscous_damping` left out where it is `solved` with
    the loop)."""
    name = type(link).__name__
    words = []
    if name == "LuGre":
        if link.sigma2 and not solved:
            words.append(f"viscous friction sigma2 = {link.sigma2:.4g} N s/m")
        if link.sigma1:
            words.append(f"bristle damping sigma1 = {link.sigma1:.4g} N s/m (while it sticks)")
    elif name == "Coulomb" and (link.c_pos or link.c_neg) and not solved:
        words.append(f"viscous friction c_pos = {link.c_pos:.4g}, c_neg = {link.c_neg:.4g} "
                     f"N s/m")
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
        self.last: NDArray[np.complex128] | None = None

    def step(self, dE: NDArray[np.complex128], E: NDArray[np.complex128]) -> None:
        """Record a pass's change `dE` of the error's harmonics ``0 .. H`` (`E` after it);
        raise RuntimeError once it has grown :data:`GROWING_PASSES` passes in a row above
        :data:`FULL_RESIDUAL` of the error's RMS, or :data:`GROWING_PASSES_LARGE` passes above
        :data:`LARGE_CHANGE` of it."""
        size = float(np.max(np.abs(dE)))
        if self.sizes and size > GROWTH * self.sizes[-1]:
            self.growing += 1
        else:
            self.growing = 0
        growth = size / self.sizes[-1] if self.sizes and self.sizes[-1] > 0 else np.inf
        self.sizes.append(size)
        self.last = dE
        rms = _rms(E)
        if ((self.growing >= GROWING_PASSES and size > FULL_RESIDUAL * rms)
                or (self.growing >= GROWING_PASSES_LARGE and size > LARGE_CHANGE * rms)):
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
        """Raise the refusal: `what` the iteration did, at the harmonic where `dE` is largest."""
        n = int(np.nanargmax(np.abs(dE))) if np.any(np.isfinite(dE)) else 0
        words = _damping_words(self.link, self.solved)
        which = "damping" if words else "stiffness"
        raise RuntimeError(
            f"steady state at {self.frequency_hz:g} Hz: the fixed point {what} at harmonic "
            f"{n} ({n * self.frequency_hz:.4g} Hz) after {passes} passes: the link's "
            f"{words or 'stiffness'}, fed back through the loop, amplifies each pass there; "
            f"no answer is given: run the loop in time (motionhyst simulate --time-series) or "
            f"lower the link's {which}")


def _rms(E: NDArray[np.complex128]) -> float:
    """RMS over a period of the signal of one-sided harmonics `E` (``rfft / N`` scaling)."""
    E = np.asarray(E)
    return float(np.sqrt(abs(E[0]) ** 2 + 2.0 * np.sum(np.abs(E[1:]) ** 2)))


def chord(G_1: NDArray[np.complex128], frequency_hz: float, c: float):
    """The linear damping's force per harmonic ``L = j n w c`` and the loop's
    ``1 / (1 - T_{w->y1} L)`` with it, or None for ``c = 0`` (or a loop that this damping
    makes singular at a harmonic)."""
    if not c > 0:
        return None
    L = 1j * TWO_PI * float(frequency_hz) * np.arange(G_1.size) * c
    den = 1.0 - G_1 * L
    if not np.all(np.abs(den) > 1e-6):
        return None
    return L, 1.0 / den
