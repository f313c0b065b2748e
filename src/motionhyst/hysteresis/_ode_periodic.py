"""The periodic output of the ODE link models, assembled around the compiled kernels of
:mod:`motionhyst.hysteresis._ode_kernels`: harmonic truncation, reversal angles, the
periodic fixed point and :class:`NormalisedRateIndependent`, the common implementation of
the rate-independent ODE models (Bouc-Wen, Dahl) in normalised form."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.validation import check_positive
from motionhyst.hysteresis._kernels import reversal_roots
from motionhyst.hysteresis._ode_kernels import (
    MAX_SAMPLES,
    MIN_SAMPLES,
    TWO_PI,
    path_with_reversals,
)
from motionhyst.hysteresis.periodic import sample_period, significant_harmonics


def truncate_harmonics(X: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """`X` without trailing harmonics that are negligible (below 1e-15 of the total)."""
    X = np.asarray(X, dtype=complex)
    if X.ndim != 1 or X.size == 0:
        raise ValueError("X must be a non-empty one-dimensional array of harmonics")
    if not np.all(np.isfinite(X)):
        raise ValueError("X must be finite")
    return X[: significant_harmonics(X) + 1]


def pow2_at_least(n: float) -> int:
    """Smallest power of two >= `n` (at least :data:`MIN_SAMPLES`, at most :data:`MAX_SAMPLES`)."""
    n = min(max(float(n), MIN_SAMPLES), MAX_SAMPLES)
    return int(2 ** math.ceil(math.log2(n)))


def reversal_angles(X: NDArray[np.complex128], d: NDArray[np.float64]
                    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Reversal points of ``x``: the grid cells that hold them and their angles.

    Each sign change of `d` between neighbouring samples (cyclically) brackets
    a root of ``x'``, refined on the trigonometric polynomial by the compiled
    root finder shared with the stop operator
    (:func:`~motionhyst.hysteresis._kernels.reversal_roots`).

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M`` of ``x`` (``rfft / N`` scaling).
    d : ndarray, shape (N,)
        ``dx/dtheta`` on the grid ``theta_i = 2 pi i / N``.

    Returns
    -------
    cells : ndarray of int64
        Cells ``i`` (between samples ``i`` and ``i + 1``, the last one ending at
        ``2 pi``), ascending, one per sign change of `d` (``d > 0`` against
        ``d <= 0``); empty for a constant ``x``.  Tangencies and two roots in
        one cell give no sign change.
    angles : ndarray
        The root in each cell [rad], clamped to ``[theta_i, theta_{i+1}]``.
    """
    X = np.asarray(X, dtype=complex)
    m = np.arange(X.size)
    cells, roots = reversal_roots(1j * m * X, -(m**2) * X, np.ascontiguousarray(d, dtype=float))
    hgrid = TWO_PI / d.size
    return cells, np.clip(roots, cells * hgrid, (cells + 1) * hgrid)


def rate_independent_path(X: NDArray[np.complex128], N: int
                          ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Displacement path over one period with the reversal points inserted.

    Returns
    -------
    x : ndarray, shape (N,)
        Grid samples.
    path : ndarray
        ``x_0``, the reversal values and grid samples in order, ending with ``x_0``
        after one period.
    grid_index : ndarray, shape (N,)
        Position of each grid sample in `path`.
    """
    X = np.asarray(X, dtype=complex)
    x = sample_period(X, N)
    d = sample_period(X, N, 1)
    m = np.arange(X.size)
    path, grid_index = path_with_reversals(x, d, X, 1j * m * X, -(m**2) * X)
    return x, path, grid_index


def periodic_fixed_point(period: Callable[[float], NDArray[np.float64]], s0: float,
                         lo: float, hi: float, max_iter: int = 60) -> NDArray[np.float64]:
    """Trajectory over one period that starts and ends in the same state.

    `period(s)` returns the state along the period from ``s``; its last value
    ``P(s)`` is increasing in ``s`` with slope < 1 (a scalar, order-preserving
    contraction), so ``g(s) = P(s) - s`` decreases and has one root in
    ``[lo, hi]``.  Secant steps from the fixed-point iterate, kept inside the
    bracket (bisection otherwise), converge in a few periods.
    """
    traj = period(s0)
    g = traj[-1] - s0
    best = (abs(g), traj)
    s_prev, g_prev = s0, g
    s = float(np.clip(traj[-1], lo, hi))
    for _ in range(max_iter):
        scale = float(np.max(traj) - np.min(traj))
        if abs(g) <= 1e-14 * scale or g == 0.0:
            return traj
        if g > 0:
            lo = max(lo, s_prev)
        else:
            hi = min(hi, s_prev)
        traj = period(s)
        g = traj[-1] - s
        if abs(g) < best[0]:
            best = (abs(g), traj)
        if g == 0.0 or abs(g) <= 1e-14 * float(np.max(traj) - np.min(traj)):
            return traj
        if g > 0:
            lo = max(lo, s)
        else:
            hi = min(hi, s)
        s_new = s - g * (s - s_prev) / (g - g_prev) if g != g_prev else 0.5 * (lo + hi)
        if not lo < s_new < hi:
            s_new = 0.5 * (lo + hi)
        if s_new == s:
            return traj
        s_prev, g_prev, s = s, g, s_new
    scale = float(np.max(best[1]) - np.min(best[1]))
    if best[0] <= 1e-10 * max(scale, 1e-300):
        return best[1]
    raise RuntimeError("periodic state not found (period map did not converge)")


def describing_function_from_harmonics(W1: complex, A: float) -> complex:
    """``D = (b1 + j a1) / A`` from the ``rfft / N`` first harmonic ``W_1`` for ``x = A sin``."""
    return complex(2j * W1 / A)


class NormalisedRateIndependent:
    """Mixin: periodic output and describing function of ``w = fc s(u)``, ``u = (k / fc) x``.

    Subclasses define ``k``, ``fc``, :meth:`_path` (the normalised state along a
    normalised path) and :meth:`_state_bounds` (an interval every periodic
    state lies in).
    """

    k: float
    fc: float
    _CACHE_SIZE = 4096

    def _path(self, u: NDArray[np.float64], s0: float) -> NDArray[np.float64]:
        raise NotImplementedError

    def _state_bounds(self) -> tuple[float, float]:
        raise NotImplementedError

    def default_samples(self, X: NDArray[np.complex128], n_harmonics: int = 1) -> int:
        """Samples per period used by :meth:`periodic_harmonics` for the input `X`.

        A power of two with at least 8 samples per input harmonic and 4 per
        output harmonic, and enough to keep the first output harmonic's
        aliasing error (from the corners of ``w'`` at reversals, ``~ 1/N^3``)
        near 1e-10: ``N ~ 1100 (k A / fc)^(1/3)``.
        """
        X = truncate_harmonics(X)
        amp = float(np.sum(np.abs(X[1:]))) * 2.0  # bound on the half range of x
        r = self.k * amp / self.fc
        return pow2_at_least(max(8 * (len(X) - 1), 4 * (int(n_harmonics) + 1),
                                 1100.0 * max(r, 1.0) ** (1.0 / 3.0)))

    def _grid(self, X: ArrayLike, n_samples: int | None) -> tuple[NDArray[np.complex128], int]:
        """The harmonics without negligible ones, and the checked grid size ``N``."""
        X = truncate_harmonics(np.asarray(X, dtype=complex))
        N = self.default_samples(X) if n_samples is None else int(n_samples)
        if N < 8 or N % 2:
            raise ValueError(f"n_samples must be an even number >= 8, got {n_samples!r}")
        return X, N

    def periodic_samples(self, X: ArrayLike, n_samples: int | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Displacement and force on the grid ``theta = 2 pi i / N`` of the periodic state.

        Parameters
        ----------
        X : array_like of complex
            Harmonics of the displacement (``rfft / N`` scaling).
        n_samples : int, optional
            Grid size ``N`` (even); by default :meth:`default_samples`.

        Returns
        -------
        x, w : ndarray, shape (N,)
            Displacement [m] and force [N] over one period of the periodic state.
        """
        X, N = self._grid(X, n_samples)
        if len(X) == 1:  # constant displacement: the (non-unique) periodic state w = 0
            return np.full(N, X[0].real), np.zeros(N)
        x, path, grid_index = rate_independent_path(X, N)
        u = (self.k / self.fc) * (path - path[0])
        lo, hi = self._state_bounds()
        traj = periodic_fixed_point(lambda s: self._path(u, s), 0.0, lo, hi)
        return x, self.fc * traj[grid_index]

    def _harmonics(self, X: ArrayLike, n_harmonics: int, n_samples: int | None
                   ) -> NDArray[np.complex128]:
        H = int(n_harmonics)
        if H < 0:
            raise ValueError("n_harmonics must be >= 0")
        X = truncate_harmonics(np.asarray(X, dtype=complex))
        N = self.default_samples(X, H) if n_samples is None else int(n_samples)
        _, w = self.periodic_samples(X, N)
        W = np.zeros(H + 1, dtype=complex)
        spec = np.fft.rfft(w) / N
        m = min(H + 1, spec.size)
        W[:m] = spec[:m]
        return W

    def _describing_function_scalar(self, amp: float) -> complex:
        if amp == 0.0:
            return complex(self.k)
        cache = self.__dict__.setdefault("_df_cache", {})
        d = cache.get(amp)
        if d is None:
            W = self._harmonics(np.array([0.0, amp / 2j]), 1, None)
            d = describing_function_from_harmonics(W[1], amp)
            if len(cache) >= self._CACHE_SIZE:
                cache.clear()
            cache[amp] = d
        return d

    def _describing_function(self, a: NDArray[np.float64], omega) -> complex | NDArray:
        uniq, inv = np.unique(a, return_inverse=True)
        vals = np.array([self._describing_function_scalar(float(v)) for v in uniq],
                        dtype=complex)
        d = vals[inv].reshape(a.shape)
        if omega is not None:
            d = np.broadcast_to(d, np.broadcast_shapes(d.shape, np.shape(omega))).copy()
        return complex(d) if d.ndim == 0 else d

    def sine_loop(self, A: float, omega: float | None = None, n_samples: int | None = None
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """One closed period of the exact periodic response (see :meth:`Hysteresis.sine_loop`)."""
        _, x, w = self.steady_loop(A, n_samples=n_samples)
        return np.append(x, x[0]), np.append(w, w[0])

    def steady_loop(self, A: float, n_samples: int | None = None
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """One period of the periodic response to ``x = A sin(theta)``.

        Returns
        -------
        theta, x, w : ndarray
            Angles [rad], displacement [m] and force [N] on a uniform grid.
        """
        amp = check_positive("A", A)
        x, w = self.periodic_samples(np.array([0.0, amp / 2j]), n_samples)
        return np.arange(x.size) * (TWO_PI / x.size), x, w

    def _validated_path(self, x: ArrayLike) -> NDArray[np.float64]:
        xs = np.ascontiguousarray(x, dtype=float)
        if xs.ndim != 1:
            raise ValueError("x must be one-dimensional")
        if not np.all(np.isfinite(xs)):
            raise ValueError("x must be finite")
        return xs
