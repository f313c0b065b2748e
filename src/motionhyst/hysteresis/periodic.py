"""Exact Fourier coefficients of the stop operator (Jenkins element) under a periodic input.

The input is a real trigonometric polynomial over one period,
``x(theta) = X_0 + 2 Re sum_m X_m exp(j m theta)`` (numpy ``rfft`` scaling,
``theta = omega t``).  The element's periodic output is piecewise: a spring
``w = w_i + k (x - x_i)`` while it sticks, ``+-fc`` while it slips.  The
reversal points of ``x`` and the slip onsets are located by root finding on
the trigonometric polynomial, and the output's harmonics follow in closed
form from the pieces: ``w = g + s x`` with ``g`` and ``s`` piecewise constant,
whose coefficients are sums over their jumps, and ``s x`` a product of two
band-limited functions.  Unlike a sampled FFT of ``w`` this has no error from
the corners of ``w`` or from samples that miss a reversal, so the describing
function and the periodic steady state reach round-off accuracy.  The whole
computation (roots, the element's pass over its pieces, the jump sums, the
transforms of the product) is one compiled kernel,
:func:`stop_harmonics` (:mod:`motionhyst.hysteresis._stop_harmonics`); where the first
harmonic of ``x`` dominates, its reversals are bracketed by bounds on the other
harmonics rather than on a grid, and the slip onsets between them directly.  An input
without even harmonics (a symmetric loop driven by a sine) makes the second half period
of the output the mirror of the first, which alone is computed.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis._fft import twiddle_table
from motionhyst.hysteresis._stop_harmonics import stop_harmonics
from motionhyst.hysteresis._stop_harmonics import stop_harmonics_base as stop_harmonics_base
from motionhyst.hysteresis._stop_harmonics import stop_harmonics_kept as stop_harmonics_kept
from motionhyst.hysteresis._stop_harmonics import stop_harmonics_update as stop_harmonics_update

__all__ = ["TWO_PI", "sample_period", "significant_harmonics", "stop_periodic_harmonics",
           "trig_eval"]

TWO_PI = 2.0 * np.pi


def significant_harmonics(X: NDArray[np.complex128], rtol: float = 1e-15) -> int:
    """Number of leading harmonics of `X` (excluding DC) whose tail is below `rtol` of the total.

    Examples
    --------
    >>> import numpy as np
    >>> significant_harmonics(np.array([0.0, 1.0, 1e-3, 1e-20]))      # the last is round-off
    2

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M``.
    rtol : float
        Relative size of the tail that may be dropped.
    """
    mags = np.abs(X[1:])
    total = mags.sum()
    if total == 0.0:
        return 0
    tail = np.cumsum(mags[::-1])[::-1]  # tail[i] = sum of |X_{i+1}|, ...
    keep = np.nonzero(tail > rtol * total)[0]
    return int(keep[-1] + 1) if keep.size else 0


def trig_eval(X: NDArray[np.complex128], theta, deriv: int = 0):
    """Value (or derivative of order `deriv`) of the trigonometric polynomial `X` at `theta`.

    Examples
    --------
    >>> import numpy as np
    >>> X = np.array([0.0, 0.01 / 2j])                     # x = 0.01 sin(theta)
    >>> float(trig_eval(X, np.pi / 2)), float(trig_eval(X, 0.0, deriv=1))
    (0.01, 0.01)

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M`` of ``X_0 + 2 Re sum X_m exp(j m theta)``.
    theta : array_like
        Angle(s) [rad].
    deriv : int
        Order of the derivative in ``theta`` (0: the value).
    """
    m = np.arange(len(X))
    coef = X * (1j * m) ** deriv
    th = np.asarray(theta, dtype=float)
    val = 2.0 * np.real(np.exp(1j * np.multiply.outer(th, m[1:])) @ coef[1:])
    if deriv == 0:
        val = val + X[0].real
    return val


def sample_period(X: NDArray[np.complex128], N: int, deriv: int = 0) -> NDArray[np.float64]:
    """Samples of a trigonometric polynomial or its derivative on the uniform grid of a period.

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M`` (``rfft / N`` scaling) of
        ``x(theta) = X_0 + 2 Re sum_m X_m exp(j m theta)``.
    N : int
        Number of samples; ``N > 2 M`` (the highest harmonic lies below the
        Nyquist frequency).
    deriv : int, optional
        Order of the derivative in ``theta`` (0: ``x`` itself).

    Returns
    -------
    ndarray, shape (N,)
        ``x^(deriv)(theta_i)`` at ``theta_i = 2 pi i / N``, ``i = 0 .. N - 1``,
        by an inverse real FFT.

    Raises
    ------
    ValueError
        If `N` samples cannot represent `M` harmonics.

    Examples
    --------
    >>> import numpy as np
    >>> sample_period(np.array([0.0, 0.01 / 2j]), 4).round(12).tolist()   # 0.01 sin(theta)
    [0.0, 0.01, 0.0, -0.01]
    """
    X = np.asarray(X, dtype=complex)
    M = X.size - 1
    if 2 * M >= N:
        raise ValueError(f"{N} samples cannot represent {M} harmonics")
    if M < 0:
        return np.zeros(N)
    if deriv:
        jm = 1j * np.arange(M + 1)
        spec = X * (jm if deriv == 1 else jm**deriv) * N
        spec[0] = 0.0
    else:
        spec = X * N
    return np.fft.irfft(spec, n=N)  # zero-padded to N // 2 + 1 bins


def stop_periodic_harmonics(X: NDArray[np.complex128], k: ArrayLike, fc: ArrayLike,
                            n_harmonics: int) -> NDArray[np.complex128]:
    """Harmonics ``W_0`` to ``W_H`` (``rfft`` scaling) of a Jenkins element's periodic output.

    Parameters
    ----------
    X : ndarray of complex
        Harmonics ``X_0 .. X_M`` of the periodic displacement (``rfft / N`` scaling).
    k, fc : float or array_like
        Stiffness [N/m] and slip force [N]; arrays of equal length for
        Jenkins elements in parallel (Maxwell-slip), whose outputs are summed.
    n_harmonics : int
        Highest harmonic ``H`` of the output.

    Returns
    -------
    ndarray of complex, shape (H + 1,)
        Output harmonics.  Where the motion never makes the element slip the
        periodic output is defined up to a constant; the symmetric one
        (``w = k (x - mid-range)``) is returned.

    Notes
    -----
    Between the reversal points of ``x`` (roots of ``x'``) each element first
    sticks and then, from the angle where its spring reaches ``+-fc``, slips.
    So ``w = g + s x`` with ``g`` and ``s`` piecewise constant; their
    coefficients follow from their jumps, and those of ``s x`` from the
    product of ``s`` and ``x`` sampled on the grid that brackets the roots:
    with at least ``2 (H + M) + 1`` samples and ``s`` band-limited to
    ``H + M`` this is the exact (non-aliased) convolution for ``n <= H``.

    Examples
    --------
    The first harmonic gives the describing function of eq. (10), ``D = 2 j W_1 / A``:

    >>> import numpy as np
    >>> W = stop_periodic_harmonics(np.array([0.0, 0.01 / 2j]), 20.0, 0.05, 3)
    >>> D = complex(2j * W[1] / 0.01)
    >>> round(D.real, 4), round(D.imag, 4)
    (3.91, 4.7746)
    """
    H = int(n_harmonics)
    if H < 0:
        raise ValueError("n_harmonics must be >= 0")
    # copies: a read-only array (MaxwellSlip.k) would make the kernels compile once more
    k_arr = np.array(k, dtype=float, ndmin=1)
    fc_arr = np.array(fc, dtype=float, ndmin=1)
    if k_arr.ndim != 1 or k_arr.shape != fc_arr.shape:
        raise ValueError("k and fc must be scalars or one-dimensional arrays of equal length")
    X = np.ascontiguousarray(X, dtype=complex)
    if X.ndim != 1 or X.size == 0:
        return np.zeros(H + 1, dtype=complex)
    return stop_harmonics(X, np.ascontiguousarray(k_arr), np.ascontiguousarray(fc_arr), H,
                          stop_twiddles(X.size - 1, H))


def stop_twiddles(max_harmonic: int, n_harmonics: int) -> NDArray[np.complex128]:
    """The FFT's twiddle table :func:`stop_harmonics` needs for inputs of up to `max_harmonic`
    harmonics and `n_harmonics` output harmonics (computed once per size).

    Parameters
    ----------
    max_harmonic : int
        Highest harmonic ``M`` of the input.
    n_harmonics : int
        Highest output harmonic ``H``.

    Returns
    -------
    ndarray of complex
        ``exp(-2 pi j k / n)``, ``k < n / 2``, for the largest grid ``n`` of such inputs
        (read-only).

    Examples
    --------
    >>> import numpy as np
    >>> X = np.array([0.0, 0.01 / 2j])
    >>> W = stop_harmonics(X, np.array([20.0]), np.array([0.05]), 3, stop_twiddles(1, 3))
    >>> round(complex(2j * W[1] / 0.01).imag, 4)                 # Im D of eq. (10)
    4.7746
    """
    need = max(1024, 4 * int(max_harmonic), 2 * (int(n_harmonics) + int(max_harmonic)) + 1)
    return twiddle_table(1 << (need - 1).bit_length())
