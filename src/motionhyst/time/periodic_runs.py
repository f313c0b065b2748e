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

__all__ = ["MAX_PERIODIC_DECAYS", "PERIODIC_RTOL", "periodic_output", "settled"]

#: A period's output repeats the previous one to this fraction of its amplitude.
PERIODIC_RTOL = 1e-12
#: Periodic runs stop after this many time constants of the slowest mode.
MAX_PERIODIC_DECAYS = 60.0


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
    defined up to a constant).  Raises if `periods` do not settle.

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
    """
    prev = None
    step: list[float] = []
    for _ in range(periods):
        y, sy, finite = next_period()
        y, sy = y[:-1], sy[:-1]
        if prev is not None:
            ok = settled(y, prev[0], floating, step)
            if sensitivities:
                ok &= bool(np.all(np.max(np.abs(sy - prev[1]), axis=0)
                                  <= 1e-8 * (np.max(np.abs(sy), axis=0) + 1e-300)))
            if ok:
                if floating:  # defined up to a constant: zero mean
                    return y - np.mean(y), sy - np.mean(sy, axis=0)
                return y, sy
        if not finite:
            break
        prev = (y, sy)
    raise ValueError(_NO_STEADY_STATE + (_FLOATING_HINT if floating else ""))


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
