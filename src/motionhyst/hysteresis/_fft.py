"""Compiled real FFTs of power-of-two length, for kernels that transform inside a loop.

numpy's FFTs cannot be called from compiled code, and from Python each call costs more
than the transform of a thousand samples itself.  These are the textbook radix-2
transforms (a real transform of ``n`` samples as a complex one of ``n / 2``), with the
twiddle factors of the largest length in use computed once by numpy
(:func:`twiddle_table`) and passed in; their results agree with numpy's to round-off.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from motionhyst.core.compiled import njit


@lru_cache(maxsize=8)
def twiddle_table(n: int) -> np.ndarray:
    """``exp(-2 pi j k / n)`` for ``k < n / 2`` (`n` a power of two): the table of every
    transform of length up to `n`."""
    if n < 2 or n & (n - 1):
        raise ValueError(f"the FFT length must be a power of two >= 2, got {n}")
    table = np.exp(-2j * np.pi * np.arange(n // 2) / n)
    table.flags.writeable = False
    return table


@njit(cache=True, inline="always")
def _powers(tw, m):  # pragma: no cover - compiled
    """``w^m``, ``w^2m``, ``w^3m`` of the table's ``w = exp(-2 pi j / (2 len(tw)))``."""
    top = tw.shape[0]
    m3 = 3 * m
    return tw[m], tw[2 * m], tw[m3] if m3 < top else -tw[m3 - top]


@njit(cache=True, inline="always")
def _butterfly(a0, a1, a2, a3):  # pragma: no cover - compiled
    """The four-point DFT of ``(a0, a2, a1, a3)`` (two radix-2 stages without twiddles):
    ``s02 + s13``, ``s02 - s13``, ``d02 - j d13``, ``d02 + j d13``."""
    s02 = a0 + a2
    d02 = a0 - a2
    s13 = a1 + a3
    d13 = a1 - a3
    jd13 = complex(-d13.imag, d13.real)
    return s02 + s13, s02 - s13, d02 - jd13, d02 + jd13


@njit(cache=True)
def _fft_scrambling(a, tw):  # pragma: no cover - compiled
    """In-place forward DFT of `a` (length a power of two, at most ``2 len(tw)``), input in
    natural order, output in bit-reversed order (decimation in frequency, two radix-2
    stages at a time: three twiddle products for four points)."""
    n = a.shape[0]
    full = 2 * tw.shape[0]
    half = n // 2
    while half >= 2:
        q = half // 2
        stride = full // (4 * q)
        for k in range(q):
            w1, w2, w3 = _powers(tw, k * stride)
            for p in range(k, n, 4 * q):
                y0, y1, y2, y3 = _butterfly(a[p], a[p + q], a[p + 2 * q], a[p + 3 * q])
                a[p] = y0
                a[p + q] = y1 * w2
                a[p + 2 * q] = y2 * w1
                a[p + 3 * q] = y3 * w3
        half //= 4
    if half == 1:
        for p in range(0, n - 1, 2):
            u = a[p]
            v = a[p + 1]
            a[p] = u + v
            a[p + 1] = u - v


@njit(cache=True)
def fft_unscrambling(a, tw):  # pragma: no cover - compiled
    """In-place forward DFT of `a`, input in bit-reversed order, output in natural order
    (decimation in time, two radix-2 stages at a time)."""
    n = a.shape[0]
    full = 2 * tw.shape[0]
    stages = 0
    while (1 << stages) < n:
        stages += 1
    half = 1
    if stages % 2 == 1:
        for p in range(0, n - 1, 2):
            u = a[p]
            t = a[p + 1]
            a[p] = u + t
            a[p + 1] = u - t
        half = 2
    while half < n:
        q = half
        stride = full // (4 * q)
        for k in range(q):
            w1, w2, w3 = _powers(tw, k * stride)
            for p in range(k, n, 4 * q):
                y0, y1, y2, y3 = _butterfly(a[p], a[p + 2 * q] * w1, a[p + q] * w2,
                                            a[p + 3 * q] * w3)
                a[p] = y0
                a[p + q] = y2
                a[p + 2 * q] = y1
                a[p + 3 * q] = y3
        half *= 4


@njit(cache=True)
def bit_reversed_indices(n):  # pragma: no cover - compiled
    """``0 .. n - 1`` (`n` a power of two) in bit-reversed order."""
    out = np.empty(n, dtype=np.int64)
    j = 0
    for i in range(n):
        out[i] = j
        bit = n >> 1
        while j & bit:
            j ^= bit
            bit >>= 1
        j |= bit
    return out


@njit(cache=True)
def bit_reverse(a):  # pragma: no cover - compiled
    """Permute `a` (length a power of two) into bit-reversed order, in place."""
    n = a.shape[0]
    j = 0
    for i in range(1, n):
        bit = n >> 1
        while j & bit:
            j ^= bit
            bit >>= 1
        j |= bit
        if i < j:
            t = a[i]
            a[i] = a[j]
            a[j] = t


@njit(cache=True)
def synthesize_packed(X, n, tw):  # pragma: no cover - compiled
    """Samples ``x_t = X_0 + 2 Re sum_{k >= 1} X_k exp(2 pi j k t / n)``, ``t < n``, packed:
    ``z_u = x_{2t} - j x_{2t+1}`` at ``u`` the bit reversal of ``t < n / 2``.

    `X` holds harmonics ``0 .. L`` with ``2 L < n`` (the real part of ``X_0`` counts).
    Two signals packed alike multiply sample by sample in their packed form
    (:func:`packed_product`).
    """
    h = n // 2
    L = X.shape[0] - 1
    step = 2 * tw.shape[0] // n
    z = np.empty(h, dtype=np.complex128)
    for k in range(h):
        a = X[k] if k <= L else 0j
        b = X[h - k] if h - k <= L else 0j
        if k == 0:
            a = complex(a.real, 0.0)
            b = complex(b.real, 0.0)
        bc = b.conjugate()
        e = a + bc
        o = (a - bc) * tw[k * step].conjugate()
        z[k] = complex(e.real - o.imag, -(e.imag + o.real))  # conj(e + j o)
    _fft_scrambling(z, tw)
    return z


@njit(cache=True)
def packed_product(zx, zs):  # pragma: no cover - compiled
    """The samples ``x s`` packed as :func:`synthesize_packed` packs them, from `zx` and `zs`."""
    out = np.empty(zx.shape[0], dtype=np.complex128)
    for u in range(zx.shape[0]):
        out[u] = complex(zx[u].real * zs[u].real, -(zx[u].imag * zs[u].imag))
    return out


@njit(cache=True)
def _unpack_spectrum(z, n, n_out, tw):  # pragma: no cover - compiled
    """Harmonics ``0 .. n_out`` of ``rfft(x) / n`` from ``z = DFT(x_{2t} + j x_{2t+1})``."""
    h = n // 2
    step = 2 * tw.shape[0] // n
    out = np.empty(n_out + 1, dtype=np.complex128)
    scale = 0.5 / n
    for k in range(n_out + 1):
        a = z[k] if k < h else z[0]
        b = (z[h - k] if k > 0 else z[0]).conjugate()
        w = tw[k * step] if k < h else -1.0 + 0j
        d = (a - b) * w
        out[k] = scale * complex(a.real + b.real + d.imag, a.imag + b.imag - d.real)
    return out


@njit(cache=True)
def analyze_packed(zp, n, n_out, tw):  # pragma: no cover - compiled
    """Harmonics ``0 .. n_out`` of ``rfft(x) / n`` (``n_out <= n / 2``) of the samples packed
    as :func:`synthesize_packed` packs them (overwrites `zp`)."""
    for u in range(zp.shape[0]):
        zp[u] = zp[u].conjugate()
    fft_unscrambling(zp, tw)
    return _unpack_spectrum(zp, n, n_out, tw)


@njit(cache=True)
def synthesize(X, n, tw):  # pragma: no cover - compiled
    """Samples ``x_t = X_0 + 2 Re sum_{k >= 1} X_k exp(2 pi j k t / n)``, ``t < n``:
    numpy's ``irfft(X * n, n)``."""
    zz = synthesize_packed(X, n, tw)
    bit_reverse(zz)
    x = np.empty(n)
    for t in range(n // 2):
        x[2 * t] = zz[t].real
        x[2 * t + 1] = -zz[t].imag
    return x


@njit(cache=True)
def synthesize_odd(X, n, tw):  # pragma: no cover - compiled
    """:func:`synthesize` of `X` without even harmonics (``x(t + n / 2) = -x(t)``), in half the
    work: the first half period from :func:`synthesize_packed_odd`, the second its opposite."""
    y = synthesize_packed_odd(X, n, tw)
    bit_reverse(y)  # packed samples t < n / 4: x_2t and x_2t+1
    x = np.empty(n)
    half = n // 2
    for t in range(n // 4):
        a = y[t].real
        b = -y[t].imag
        x[2 * t] = a
        x[2 * t + 1] = b
        x[2 * t + half] = -a
        x[2 * t + 1 + half] = -b
    return x


@njit(cache=True)
def analyze(x, n_out, tw):  # pragma: no cover - compiled
    """Harmonics ``0 .. n_out`` of ``rfft(x) / n`` (``n = len(x)``, ``n_out <= n / 2``)."""
    n = x.shape[0]
    z = np.empty(n // 2, dtype=np.complex128)
    for t in range(n // 2):
        z[t] = complex(x[2 * t], x[2 * t + 1])
    bit_reverse(z)
    fft_unscrambling(z, tw)
    return _unpack_spectrum(z, n, n_out, tw)


@njit(cache=True)
def synthesize_packed_odd(X, n, tw):  # pragma: no cover - compiled
    """:func:`synthesize_packed` of `X` without even harmonics (``x(t + pi) = -x(t)``), in
    half the work: returns ``y`` (``n / 4`` values) with the packed samples ``(y_0, -y_0,
    y_1, -y_1, ...)``.

    The packed samples' spectrum has odd entries only, so their DFT is ``+-w^t`` times the
    DFT of half the length of the odd entries at ``t`` and ``t + n / 4`` (neighbours in
    bit-reversed order), ``w = exp(-2 pi j / (n / 2))``.
    """
    h = n // 2
    q = h // 2
    L = X.shape[0] - 1
    step = 2 * tw.shape[0] // n
    y = np.empty(q, dtype=np.complex128)
    for r in range(q):
        k = 2 * r + 1
        a = X[k] if k <= L else 0j
        b = X[h - k] if h - k <= L else 0j
        bc = b.conjugate()
        e = a + bc
        o = (a - bc) * tw[k * step].conjugate()
        y[r] = complex(e.real - o.imag, -(e.imag + o.real))  # as synthesize_packed
    _fft_scrambling(y, tw)
    _twiddle_reversed(y, 2 * tw.shape[0] // h, tw, False)
    return y


@njit(cache=True)
def analyze_packed_odd(y, n, n_out, tw):  # pragma: no cover - compiled
    """:func:`analyze_packed` of the packed samples ``(y_0, -y_0, y_1, -y_1, ...)`` (a signal
    without even harmonics, as :func:`synthesize_packed_odd` gives them), in half the work
    (overwrites `y`): the even harmonics are zero, the odd ones the DFT of half the length
    of ``2 w^t conj(y_t)``."""
    h = n // 2
    q = h // 2
    for u in range(q):
        y[u] = 2.0 * y[u].conjugate()
    _twiddle_reversed(y, 2 * tw.shape[0] // h, tw, False)
    fft_unscrambling(y, tw)
    spectrum = np.zeros(h, dtype=np.complex128)
    for r in range(q):
        spectrum[2 * r + 1] = y[r]
    return _unpack_spectrum(spectrum, n, n_out, tw)


@njit(cache=True)
def _twiddle_reversed(y, step, tw, conjugate):  # pragma: no cover - compiled
    """Multiply ``y_u`` by ``w^t``, ``t`` the bit reversal of ``u`` (``w = tw[step]``)."""
    q = y.shape[0]
    t = 0
    for u in range(q):
        w = tw[t * step]
        y[u] *= w.conjugate() if conjugate else w
        bit = q >> 1  # the next bit-reversed index
        while t & bit:
            t ^= bit
            bit >>= 1
        t |= bit
