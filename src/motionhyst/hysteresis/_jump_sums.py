"""Fourier coefficients of piecewise-constant periodic functions from their jumps (numba).

The exact periodic output of stop operators (:mod:`motionhyst.hysteresis.periodic`) is
``w = g + s x`` with ``g`` and ``s`` piecewise constant; their coefficients are sums over
their jumps, ``sum_b J_b exp(-j q t_b) / (2 pi j q)``: directly (:func:`jump_series`,
``O(jumps Q)``) or, for many jumps, binned on a grid with Chebyshev moments and FFTs
(:func:`jump_series_binned`, ``O(jumps + Q log Q)``); :func:`binned_is_cheaper` chooses.
"""

from __future__ import annotations

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._fft import bit_reversed_indices, fft_unscrambling

_TWO_PI = 2.0 * np.pi
_ANCHOR = 16  # phasor powers are recomputed directly every _ANCHOR steps


@njit(cache=True)
def jump_series(t_b, jg, js, n_g, n_s):  # pragma: no cover - compiled
    """Fourier coefficients of two piecewise-constant periodic functions from their jumps.

    Functions with jumps `jg` (`js`) at the angles `t_b` have the coefficients
    ``int_0^{2 pi} f exp(-j q theta) d theta / 2 pi = sum_b J_b exp(-j q t_b) /
    (2 pi j q)`` for ``q != 0``.  Returns them for ``q = 0 .. n_g`` (`jg`) and
    ``q = 0 .. n_s`` (`js`); ``q = 0`` (the means) is left 0.  The phasors
    ``exp(-j q t_b)`` are computed directly every ``8 _ANCHOR`` steps, multiplied up by
    ``exp(-j _ANCHOR t_b)`` every ``_ANCHOR`` steps and by powers of ``exp(-j t_b)`` in
    between (their error grows by a round-off a multiplication, 24 at most).
    """
    nq = max(n_g, n_s) + 1
    G = np.zeros(n_g + 1, dtype=np.complex128)
    S = np.zeros(n_s + 1, dtype=np.complex128)
    powers = np.empty(_ANCHOR, dtype=np.complex128)
    z = np.empty(_ANCHOR, dtype=np.complex128)
    for b in range(t_b.shape[0]):
        cg = jg[b]
        cs = js[b]
        if cg == 0.0 and cs == 0.0:
            continue
        t = t_b[b]
        u = complex(np.cos(t), -np.sin(t))
        powers[0] = 1.0
        for r in range(1, _ANCHOR):
            powers[r] = powers[r - 1] * u
        step = complex(np.cos(_ANCHOR * t), -np.sin(_ANCHOR * t))
        anchor = 1.0 + 0j
        for q0 in range(0, nq, _ANCHOR):
            if q0 % (8 * _ANCHOR) == 0:
                anchor = complex(np.cos(q0 * t), -np.sin(q0 * t))
            else:
                anchor *= step
            for r in range(_ANCHOR):
                z[r] = anchor * powers[r]
            for r in range(min(_ANCHOR, n_g + 1 - q0)):
                G[q0 + r] += cg * z[r]
            for r in range(min(_ANCHOR, n_s + 1 - q0)):
                S[q0 + r] += cs * z[r]
    G[0] = 0.0
    S[0] = 0.0
    for q in range(1, n_g + 1):
        G[q] *= -1j / (_TWO_PI * q)
    for q in range(1, n_s + 1):
        S[q] *= -1j / (_TWO_PI * q)
    return G, S


@njit(cache=True)
def chebyshev_terms(a_max):  # pragma: no cover - compiled
    """Terms ``P`` of the Chebyshev series of ``exp(-j a v)``, ``|a| <= a_max``, ``|v| <= 1``,
    that reach 1e-17: its coefficients are ``2 J_p(a)``, ``|J_p(a)| <= (a / 2)^p / p!``."""
    P = 1
    term = 1.0
    while term >= 1e-17:
        term *= 0.5 * a_max / P
        P += 1
    return P


@njit(cache=True)
def binned_grid(n_jumps, Q, N_max):  # pragma: no cover - compiled
    """The grid ``N`` (a power of two up to `N_max`) and the number of terms ``P`` of
    :func:`jump_series_binned` for `n_jumps` jumps and harmonics up to `Q`: the fewest
    operations, weighted roughly as the compiled code spends its time (binning, FFTs, the
    sums over the terms, the Bessel table), ``N >= Q / 2``."""
    best_N, best_P, best_cost = 0, 0, np.inf
    N = 2
    while N <= N_max:
        if 2 * N >= Q:
            P = chebyshev_terms(np.pi * Q / N)
            cost = P * (n_jumps * 2.0 + N * np.log2(N) * 1.5 + Q * 2.0) + Q * (P + 24.0) * 1.5
            if cost < best_cost:
                best_N, best_P, best_cost = N, P, cost
        N *= 2
    return best_N, best_P


@njit(cache=True)
def binned_is_cheaper(n_jumps, Q, N_max):  # pragma: no cover - compiled
    """Whether :func:`jump_series_binned` takes fewer operations than :func:`jump_series`
    for `n_jumps` jumps and harmonics up to `Q` (weighted as in :func:`binned_grid`)."""
    N, P = binned_grid(n_jumps, Q, N_max)
    cost = P * (n_jumps * 2.0 + N * np.log2(N) * 1.5 + Q * 2.0) + Q * (P + 24.0) * 1.5
    return cost < 2.5 * n_jumps * (Q + 1)


@njit(cache=True)
def bessel_table(alpha, Q, P):  # pragma: no cover - compiled
    """``J_p(q alpha)`` for ``q = 0 .. Q``, ``p = 0 .. P - 1`` (rows ``q``), for
    ``P >= chebyshev_terms(Q alpha)`` (the orders from ``P`` on below 1e-17).

    ``J_P`` and ``J_{P-1}`` come from their power series ``J_p(a) = (a / 2)^p / p! sum_k
    (-a^2 / 4)^k / (k! (p + 1)_k)``, the lower orders from the (stable) downward
    recurrence ``J_{p-1} = (2 p / a) J_p - J_{p+1}``, and the series' round-off, common
    to all orders, is removed by ``J_0 + 2 sum_k J_2k = 1``.

    Examples
    --------
    >>> import numpy as np
    >>> J = bessel_table(0.5, 4, 20)
    >>> float(np.round(J[2, 0], 12)), float(np.round(J[4, 1], 12))   # J_0(1), J_1(2)
    (0.765197686558, 0.576724807757)
    """
    out = np.zeros((Q + 1, P))
    out[0, 0] = 1.0
    kmax = 40
    inv_up = np.empty(kmax)  # 1 / (k (P + k)) and 1 / (k (P - 1 + k))
    inv_down = np.empty(kmax)
    for k in range(1, kmax):
        inv_up[k] = 1.0 / (k * (P + k))
        inv_down[k] = 1.0 / (k * (P - 1 + k))
    inv_factorial = 1.0  # 1 / (P - 1)!
    for i in range(1, P):
        inv_factorial /= i
    for q in range(1, Q + 1):
        a = q * alpha
        half = 0.5 * a
        lead = inv_factorial  # (a / 2)^(P - 1) / (P - 1)!, by squaring
        power = half
        e = P - 1
        while e > 0:
            if e & 1:
                lead *= power
            power *= power
            e >>= 1
        x = -half * half
        term_up = 1.0
        sum_up = 1.0
        term_down = 1.0
        sum_down = 1.0
        for k in range(1, kmax):
            term_up *= x * inv_up[k]
            term_down *= x * inv_down[k]
            sum_up += term_up
            sum_down += term_down
            if abs(term_up) <= 1e-18 * abs(sum_up) and abs(term_down) <= 1e-18 * abs(sum_down):
                break
        row = out[q]
        j_up = lead * (half / P) * sum_up
        j_p = lead * sum_down
        row[P - 1] = j_p
        two_a = 2.0 / a
        for p in range(P - 1, 0, -1):
            j_down = p * two_a * j_p - j_up
            row[p - 1] = j_down
            j_up = j_p
            j_p = j_down
        norm = row[0]
        for p in range(2, P, 2):
            norm += 2.0 * row[p]
        scale = 1.0 / norm
        for p in range(P):
            row[p] *= scale
    return out


@njit(cache=True)
def balance(jg, js):  # pragma: no cover - compiled
    """The power of two ``r`` that makes ``sum |jg|`` and ``r sum |js|`` alike, so that the
    two sets of jumps, transformed together, each keep their accuracy."""
    sum_g = 0.0
    sum_s = 0.0
    for b in range(jg.shape[0]):
        sum_g += abs(jg[b])
        sum_s += abs(js[b])
    if sum_g > 0.0 and sum_s > 0.0:
        return 2.0 ** np.round(np.log2(sum_g / sum_s))
    return 1.0


@njit(cache=True, inline="always")
def chebyshev_values(t_b, b0, N, P, cell, v, T):  # pragma: no cover - compiled
    """For the jumps ``b0 .. b0 + 3`` (those that exist): the grid point ``cell[i]`` nearest
    to each angle (``N`` points) and the Chebyshev polynomials ``T[i, p] = T_p(v)`` of its
    offset ``v`` in half cells (0 past the last jump), ``p < P``; the four recurrences
    interleaved."""
    h = _TWO_PI / N
    v[:] = 0.0
    for i in range(min(4, t_b.shape[0] - b0)):
        t = t_b[b0 + i] % _TWO_PI
        j = int(np.floor(t / h + 0.5))
        v[i] = (t - j * h) / (0.5 * h)
        cell[i] = j - N if j >= N else j
    for i in range(4):
        T[i, 0] = 1.0
    if P > 1:
        for i in range(4):
            T[i, 1] = v[i]
    for p in range(2, P):
        for i in range(4):
            T[i, p] = 2.0 * v[i] * T[i, p - 1] - T[i, p - 2]


@njit(cache=True)
def jump_series_binned(t_b, jg, js, n_g, n_s, tw):  # pragma: no cover - compiled
    """:func:`jump_series` for many jumps, in ``O(jumps + Q log Q)`` (``Q = max(n_g, n_s)``).

    The jumps are binned to the nearest point ``c_j`` of a grid of ``N`` points
    (``h = 2 pi / N``, :func:`binned_grid`), with ``t_b = c_j + v h / 2``, ``|v| <= 1``;
    then ``exp(-j q t_b) = exp(-j q c_j) sum_p eps_p (-j)^p J_p(q h / 2) T_p(v)``
    (Jacobi-Anger: Chebyshev polynomials ``T_p``, Bessel functions ``J_p``, ``eps_0 = 1``,
    else 2), summed until its terms are below 1e-17: one FFT of the bins' moments ``sum
    T_p(v) J`` for each term, read at ``q`` modulo ``N``.  `jg` and `js` are transformed
    together as ``jg + j r js`` (``r`` a power of two that makes the two sums of
    magnitudes alike).  `tw` is the twiddle table of at least ``N`` points.
    """
    Q = max(n_g, n_s)
    N, P = binned_grid(t_b.shape[0], Q, 2 * tw.shape[0])
    h = _TWO_PI / N
    r = balance(jg, js)  # jg + j r js
    bins = np.zeros((N, P), dtype=np.complex128)  # a jump's moments side by side
    cell = np.empty(4, dtype=np.int64)
    v = np.empty(4)
    T = np.empty((4, P))
    for b0 in range(0, t_b.shape[0], 4):
        chebyshev_values(t_b, b0, N, P, cell, v, T)
        for i in range(min(4, t_b.shape[0] - b0)):
            c = complex(jg[b0 + i], js[b0 + i] * r)
            row = bins[cell[i]]
            Ti = T[i]
            for p in range(P):
                row[p] += c * Ti[p]
    reversed_index = bit_reversed_indices(N)
    mu = np.empty((P, N), dtype=np.complex128)
    for p in range(P):
        row = mu[p]
        for j in range(N):
            row[j] = bins[reversed_index[j], p]
        fft_unscrambling(row, tw)
    G = np.zeros(n_g + 1, dtype=np.complex128)
    S = np.zeros(n_s + 1, dtype=np.complex128)
    bessel = bessel_table(0.5 * h, Q, P)
    for q in range(1, Q + 1):
        jp = bessel[q]
        iq = q % N
        im = (N - iq) % N
        # sum_p eps_p (-+j)^p J_p mu_p: the powers of -+j cycle with p
        up = mu[0, iq] * jp[0]
        um = mu[0, im] * jp[0]
        for p in range(1, P):
            fu = 2.0 * jp[p] * mu[p, iq]
            fm = 2.0 * jp[p] * mu[p, im]
            ph = p % 4
            if ph == 0:
                up += fu
                um += fm
            elif ph == 1:
                up += complex(fu.imag, -fu.real)
                um += complex(-fm.imag, fm.real)
            elif ph == 2:
                up -= fu
                um -= fm
            else:
                up += complex(-fu.imag, fu.real)
                um += complex(fm.imag, -fm.real)
        umc = um.conjugate()
        scale = -1j / (_TWO_PI * q)
        if q <= n_g:
            G[q] = 0.5 * (up + umc) * scale
        if q <= n_s:
            S[q] = -0.5j * (up - umc) * (scale / r)
    return G, S


@njit(cache=True)
def jump_series_binned_half(t_b, jg, js, n_g, n_s, tw):  # pragma: no cover - compiled
    """:func:`jump_series_binned` of a period whose second half mirrors the first: `t_b`,
    `jg`, `js` are the jumps of the first half, those of the second are ``-jg`` and ``js``
    at ``t_b + pi`` (``g(t + pi) = -g(t)``, ``s(t + pi) = s(t)``).  Returns the whole
    period's ``G`` (odd harmonics only) and ``S`` (even harmonics only).

    Each jump and its mirror make one sum with real weights, ``(r js + jg) / 2`` at
    ``t_b`` and ``(r js - jg) / 2`` at ``t_b + pi`` (``r`` as in
    :func:`jump_series_binned`): ``r`` times the sum of `js` at even ``q``, the sum of
    `jg` at odd ``q``.  Real weights halve the transforms (two terms' moments in one
    complex FFT) and need ``q >= 0`` only.
    """
    Q = max(n_g, n_s)
    N, P = binned_grid(2 * t_b.shape[0], Q, 2 * tw.shape[0])
    h = _TWO_PI / N
    half_grid = N // 2
    r = balance(jg, js)
    P2 = (P + 1) // 2 * 2  # whole pairs of terms, the last padded with zeros
    bins = np.zeros((N, P2))  # a jump's moments side by side
    cell = np.empty(4, dtype=np.int64)
    v = np.empty(4)
    T = np.zeros((4, P2))
    for b0 in range(0, t_b.shape[0], 4):
        chebyshev_values(t_b, b0, N, P, cell, v, T)
        for i in range(min(4, t_b.shape[0] - b0)):
            w_plus = 0.5 * (r * js[b0 + i] + jg[b0 + i])
            w_minus = 0.5 * (r * js[b0 + i] - jg[b0 + i])
            j = cell[i]
            row = bins[j]
            mirror = bins[j + half_grid if j < half_grid else j - half_grid]
            Ti = T[i]
            for p in range(P2):
                row[p] += w_plus * Ti[p]
                mirror[p] += w_minus * Ti[p]
    reversed_index = bit_reversed_indices(N)
    n_pairs = P2 // 2
    mu = np.empty((n_pairs, N), dtype=np.complex128)
    for pp in range(n_pairs):
        row = mu[pp]
        for j in range(N):
            src = bins[reversed_index[j]]
            row[j] = complex(src[2 * pp], src[2 * pp + 1])
        fft_unscrambling(row, tw)
    G = np.zeros(n_g + 1, dtype=np.complex128)
    S = np.zeros(n_s + 1, dtype=np.complex128)
    bessel = bessel_table(0.5 * h, Q, P)
    weight_y = np.empty(n_pairs)
    weight_yc = np.empty(n_pairs)
    for q in range(1, Q + 1):
        jp = bessel[q]
        iq = q % N
        im = (N - iq) % N
        # sum_p eps_p (-j)^p J_p F_p with the pair's F_p = (y + conj y_-) / 2 and F_p+1 =
        # -j (y - conj y_-) / 2 (y, y_- its transform at q and -q): (-j)^p = (-1)^(p/2) for
        # p even, and (-j) F_p+1 = -(y - conj y_-) / 2
        for pp in range(n_pairs):
            p = 2 * pp
            c_even = jp[p] if p == 0 else 2.0 * jp[p]
            c_odd = 2.0 * jp[p + 1] if p + 1 < P else 0.0
            sign = 0.5 if pp % 2 == 0 else -0.5
            weight_y[pp] = sign * (c_even - c_odd)
            weight_yc[pp] = sign * (c_even + c_odd)
        z = 0j
        for pp in range(n_pairs):
            z += weight_y[pp] * mu[pp, iq] + weight_yc[pp] * mu[pp, im].conjugate()
        scale = -2j / (_TWO_PI * q)
        if q % 2 == 1:
            if q <= n_g:
                G[q] = z * scale
        elif q <= n_s:
            S[q] = z * (scale / r)
    return G, S
