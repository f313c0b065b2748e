"""Exact Fourier coefficients of the stop operator (Jenkins element) under a periodic input.

The input is a real trigonometric polynomial over one period,
``x(theta) = X_0 + 2 Re sum_m X_m exp(j m theta)`` (numpy ``rfft`` scaling,
``theta = omega t``).  The element's periodic output is piecewise: a spring
``w = w_i + k (x - x_i)`` while it sticks, ``+-fc`` while it slips.  The
reversal points of ``x`` and the slip onsets are located by root finding on
the trigonometric polynomial, and the output's harmonics are integrated
piece by piece in closed form.  Unlike a sampled FFT this has no error from
the corners of ``w`` or from samples that miss a reversal, so the describing
function and the periodic steady state reach round-off accuracy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.fft import next_fast_len
from scipy.optimize import brentq
from scipy.signal import fftconvolve

TWO_PI = 2.0 * np.pi


def significant_harmonics(X: NDArray[np.complex128], rtol: float = 1e-15) -> int:
    """Number of leading harmonics of `X` (excluding DC) whose tail is below `rtol` of the total."""
    mags = np.abs(X[1:])
    total = mags.sum()
    if total == 0.0:
        return 0
    tail = np.cumsum(mags[::-1])[::-1]  # tail[i] = sum of |X_{i+1}|, ...
    keep = np.nonzero(tail > rtol * total)[0]
    return int(keep[-1] + 1) if keep.size else 0


def trig_eval(X: NDArray[np.complex128], theta, deriv: int = 0):
    """Value (or derivative of order `deriv`) of the trigonometric polynomial `X` at `theta`."""
    m = np.arange(len(X))
    coef = X * (1j * m) ** deriv
    th = np.asarray(theta, dtype=float)
    val = 2.0 * np.real(np.exp(1j * np.multiply.outer(th, m[1:])) @ coef[1:])
    if deriv == 0:
        val = val + X[0].real
    return val


def _root(X: NDArray[np.complex128], deriv: int, level: float, a: float, b: float,
          fa: float, fb: float) -> float:
    """Root of ``x^(deriv)(theta) = level`` in the bracket [a, b] (values fa, fb there).

    Newton from the linear interpolant (the bracket is one grid cell, so two
    or three steps reach round-off), with a bisection safeguard.
    """
    t = a + (b - a) * fa / (fa - fb) if fa != fb else 0.5 * (a + b)
    # a root on a grid point may lie a round-off outside [a, b]: allow half a cell either side
    lo, hi = a - 0.5 * (b - a), b + 0.5 * (b - a)
    for _ in range(8):
        f = float(trig_eval(X, t, deriv)) - level
        step = f / float(trig_eval(X, t, deriv + 1))
        t_new = t - step
        if not lo <= t_new <= hi:
            break
        if abs(t_new - t) <= 4e-16 * max(1.0, abs(t)):
            return t_new
        t = t_new
    else:
        return t
    return brentq(lambda u: float(trig_eval(X, u, deriv)) - level, lo, hi,
                  xtol=1e-15, rtol=1e-15)


def _grid(X: NDArray[np.complex128]) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                              NDArray[np.float64]]:
    """Angles, x and dx/dtheta on a grid fine enough to separate the roots."""
    M = len(X) - 1
    n = next_fast_len(max(1024, 4 * M), real=True)
    th = np.arange(n) * (TWO_PI / n)
    x = np.fft.irfft(X * n, n=n)
    d = np.fft.irfft(1j * np.arange(M + 1) * X * n, n=n)
    return th, x, d


def _reversals(X: NDArray[np.complex128], th, d) -> NDArray[np.float64]:
    """Angles in [0, 2 pi) where x changes direction (sign changes of dx/dtheta)."""
    h = th[1] - th[0]
    nxt = np.roll(d, -1)
    idx = np.nonzero((d > 0) != (nxt > 0))[0]
    roots = [_root(X, 1, 0.0, th[i], th[i] + h, d[i], nxt[i]) % TWO_PI for i in idx]
    return np.sort(np.array(roots))


def _crossing(X, th, x, level: float, a: float, b: float) -> float:
    """Angle in [a, b] (b may exceed 2 pi) where the monotone x(theta) passes `level`."""
    n, h = th.size, th[1] - th[0]
    i0, i1 = int(np.floor(a / h)), int(np.ceil(b / h))
    idx = np.arange(i0, i1 + 1)
    tt, xx = idx * h, x[idx % n]
    tt[0], tt[-1] = a, b
    xx[0], xx[-1] = trig_eval(X, a), trig_eval(X, b)
    g = xx - level
    j = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) <= 0)[0]
    j = int(j[0]) if j.size else 0
    return _root(X, 0, level, tt[j], tt[j + 1], float(g[j]), float(g[j + 1]))


def _exp_integrals(a: float, b: float, q: NDArray[np.int64]) -> NDArray[np.complex128]:
    """``int_a^b exp(-j q theta) d theta`` for integer `q`."""
    out = np.empty(q.shape, dtype=complex)
    nz = q != 0
    qq = q[nz]
    out[nz] = (np.exp(-1j * qq * a) - np.exp(-1j * qq * b)) / (1j * qq)
    out[~nz] = b - a
    return out


def stop_periodic_harmonics(X: NDArray[np.complex128], k: float, fc: float,
                            n_harmonics: int) -> NDArray[np.complex128]:
    """Harmonics ``W_0 .. W_H`` (``rfft`` scaling) of a Jenkins element's periodic output.

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M`` of the periodic displacement (``rfft / N`` scaling).
    k, fc : float
        Stiffness [N/m] and slip force [N].
    n_harmonics : int
        Highest harmonic ``H`` of the output.

    Returns
    -------
    ndarray of complex, shape (H + 1,)
        Output harmonics.  Where the motion never makes the element slip the
        periodic output is defined up to a constant; the symmetric one
        (``w = k (x - mid-range)``) is returned.
    """
    M = significant_harmonics(X)
    X = np.asarray(X[: M + 1], dtype=complex)
    H = int(n_harmonics)
    W = np.zeros(H + 1, dtype=complex)
    if M == 0:
        return W
    th_grid, x_grid, d_grid = _grid(X)
    rev = _reversals(X, th_grid, d_grid)
    if rev.size < 2:
        return W
    xr = trig_eval(X, rev)
    # periodic stop operator on the reversal points, started at the global maximum
    i0 = int(np.argmax(xr))
    order = np.roll(np.arange(rev.size), -i0)
    th = rev[order]
    th = np.where(th < th[0], th + TWO_PI, th)
    th = np.append(th, th[0] + TWO_PI)
    xs = np.append(xr[order], xr[order][0])
    mid = 0.5 * (xr.max() + xr.min())
    w = float(np.clip(k * (xs[0] - mid), -fc, fc))
    for _ in range(2):  # second pass starts from the periodic state
        ws = [w]
        for i in range(len(xs) - 1):
            w = float(np.clip(w + k * (xs[i + 1] - xs[i]), -fc, fc))
            ws.append(w)
        w = ws[-1]
    n = np.arange(H + 1)
    q = np.arange(-M, H + M + 1)
    Xfull = np.concatenate([np.conj(X[:0:-1]), X])
    for i in range(len(xs) - 1):
        a, b = th[i], th[i + 1]
        wi, xi, x_end = ws[i], xs[i], xs[i + 1]
        d = 1.0 if x_end > xi else -1.0
        slip_level = xi + (d * fc - wi) / k  # x where the spring reaches +-fc
        s = b
        if d * (x_end - slip_level) > 0:
            s = _crossing(X, th_grid, x_grid, slip_level, a, b)
            W += d * fc * _exp_integrals(s, b, n)
        if s > a:
            E = _exp_integrals(a, s, q)
            W += (wi - k * xi) * E[M:M + H + 1] + k * fftconvolve(Xfull, E)[2 * M:2 * M + H + 1]
    return W / TWO_PI
