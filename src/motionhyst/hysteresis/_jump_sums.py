"""Fourier coefficients of piecewise-constant periodic functions from their jumps (numba).

The exact periodic output of stop operators (:mod:`motionhyst.hysteresis.periodic`) is
``w = g + s x`` with ``g`` and ``s`` piecewise constant; their coefficients are sums over
their jumps, ``sum_b J_b exp(-j q t_b) / (2 pi j q)``: directly (:func:`jump_series`,
``O(jumps Q)``) or, for many jumps, binned on a grid with Chebyshev moments and FFTs
(:func:`jump_sums_binned`, ``O(jumps + Q log Q)``, real weights); :func:`binned_is_cheaper`
chooses.
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
def jump_series_half(t_b, jg, js, n_g, n_s):  # pragma: no cover - compiled
    """:func:`jump_series` of a period whose second half mirrors the first: `t_b`, `jg`, `js`
    are the jumps of the first half, those of the second ``-jg`` and ``js`` at ``t_b + pi``.
    The coefficients of ``g`` are then zero at even ``q``, ``2 sum_b jg_b exp(-j q t_b) /
    (2 pi j q)`` at odd ``q``, and those of ``s`` the other way round: the phasors step by
    ``exp(-2 j t_b)``, half the steps of :func:`jump_series`."""
    G = np.zeros(n_g + 1, dtype=np.complex128)
    S = np.zeros(n_s + 1, dtype=np.complex128)
    ng = (n_g + 1) // 2  # odd q = 2 i + 1, i < ng
    ns = n_s // 2  # even q = 2 i, 1 <= i <= ns
    nq = max(ng, ns + 1)
    powers = np.empty(_ANCHOR, dtype=np.complex128)
    z = np.empty(_ANCHOR, dtype=np.complex128)
    for b in range(t_b.shape[0]):
        cg = jg[b]
        cs = js[b]
        if cg == 0.0 and cs == 0.0:
            continue
        t = t_b[b]
        u2 = complex(np.cos(2.0 * t), -np.sin(2.0 * t))  # exp(-2 j t)
        u1 = complex(np.cos(t), -np.sin(t))
        powers[0] = 1.0
        for r in range(1, _ANCHOR):
            powers[r] = powers[r - 1] * u2
        step = complex(np.cos(2.0 * _ANCHOR * t), -np.sin(2.0 * _ANCHOR * t))
        anchor = 1.0 + 0j
        for i0 in range(0, nq, _ANCHOR):
            if i0 % (8 * _ANCHOR) == 0:
                anchor = complex(np.cos(2.0 * i0 * t), -np.sin(2.0 * i0 * t))
            else:
                anchor *= step
            for r in range(_ANCHOR):
                z[r] = anchor * powers[r]  # exp(-2 j (i0 + r) t)
            for r in range(min(_ANCHOR, ns + 1 - i0)):
                S[2 * (i0 + r)] += cs * z[r]
            for r in range(min(_ANCHOR, ng - i0)):
                G[2 * (i0 + r) + 1] += cg * (z[r] * u1)
    G[0] = 0.0
    S[0] = 0.0
    for q in range(1, n_g + 1, 2):
        G[q] *= -2j / (_TWO_PI * q)
    for q in range(2, n_s + 1, 2):
        S[q] *= -2j / (_TWO_PI * q)
    return G, S


@njit(cache=True)
def chebyshev_terms(a_max):  # pragma: no cover - compiled
    """Terms ``P`` of the Chebyshev series of ``exp(-j a v)``, ``|a| <= a_max``, ``|v| <= 1``,
    that reach 1e-17 (:func:`chebyshev_terms_to`)."""
    return chebyshev_terms_to(a_max, 1e-17)


@njit(cache=True)
def chebyshev_terms_to(a_max, tol):  # pragma: no cover - compiled
    """Terms ``P`` of the Chebyshev series of ``exp(-j a v)``, ``|a| <= a_max``, ``|v| <= 1``,
    that reach `tol`: its coefficients are ``2 J_p(a)``, ``|J_p(a)| <= (a / 2)^p / p!``
    (for ``tol <= 0``, those until the bound underflows; `a_max` finite)."""
    P = 1
    term = 1.0
    while term >= tol and 0.0 < term < np.inf:
        term *= 0.5 * a_max / P
        P += 1
    return P


@njit(cache=True)
def binned_grid(n_jumps, Q, N_max):  # pragma: no cover - compiled
    """The grid ``N`` (a power of two up to `N_max`) and the number of terms ``P`` of
    :func:`jump_sums_binned` for `n_jumps` jumps and harmonics up to `Q`, to 1e-17 of the
    sum of the weights (:func:`binned_grid_to`)."""
    return binned_grid_to(n_jumps, Q, N_max, 1e-17, Q, 1e-17)


@njit(cache=True)
def binned_grid_to(n_jumps, Q, N_max, tol, Q_full, tol_full):  # pragma: no cover - compiled
    """The grid ``N`` (a power of two up to `N_max`) and the number of terms ``P`` of
    :func:`jump_sums_binned` for `n_jumps` jumps and harmonics up to `Q` to `tol` of the sum
    of the weights, those up to ``Q_full <= Q`` to ``tol_full <= tol``: the fewest
    operations, weighted roughly as the compiled code spends its time (binning, FFTs, the
    sums over the terms, the Bessel table), ``N >= Q_full / 2``."""
    best_N, best_P, best_cost = 0, 0, np.inf
    N = 2
    while N <= N_max:
        if 2 * N >= Q_full:
            P = max(chebyshev_terms_to(np.pi * Q / N, tol),
                    chebyshev_terms_to(np.pi * Q_full / N, tol_full))
            cost = P * (n_jumps * 2.0 + N * np.log2(N) * 1.5 + Q * 2.0) + Q * (P + 24.0) * 1.5
            if cost < best_cost:
                best_N, best_P, best_cost = N, P, cost
        N *= 2
    return best_N, best_P


@njit(cache=True)
def binned_is_cheaper(n_jumps, Q, N_max):  # pragma: no cover - compiled
    """Whether :func:`jump_sums_binned` takes fewer operations than :func:`jump_series`
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
def binned_table(N, P, L):  # pragma: no cover - compiled
    """The weights of :func:`jump_sums_binned` for the grid of `N` points, `P` terms and the
    harmonics ``l = 0 .. L``: row ``l`` holds, for each pair of terms ``p, p + 1`` (``p``
    even), the weights of the pair's transform at ``l`` and of its conjugate at ``-l``.

    The terms are ``eps_p (-j)^p J_p(l h / 2) F_p`` (:func:`jump_sums_binned`); a pair's
    transform ``y`` of ``m_p + j m_p+1`` (real moments) gives ``F_p = (y + conj y_-) / 2``
    and ``(-j) F_p+1 = -(y - conj y_-) / 2`` (``y_-`` at ``-l``), and ``(-j)^p = (-1)^(p / 2)``.
    """
    bessel = bessel_table(np.pi / N, L, P)
    n_pairs = (P + 1) // 2
    table = np.empty((L + 1, 2 * n_pairs))
    for q in range(L + 1):
        jp = bessel[q]
        for pp in range(n_pairs):
            p = 2 * pp
            c_even = jp[p] if p == 0 else 2.0 * jp[p]
            c_odd = 2.0 * jp[p + 1] if p + 1 < P else 0.0
            sign = 0.5 if pp % 2 == 0 else -0.5
            table[q, 2 * pp] = sign * (c_even - c_odd)
            table[q, 2 * pp + 1] = sign * (c_even + c_odd)
    return table


@njit(cache=True)
def chebyshev_moments(t_b, w_plus, w_minus, shift, N, P):  # pragma: no cover - compiled
    """The moments ``sum_b w_b T_p(v_b)`` of the points `t_b` (angles in ``[-2 pi, 4 pi)``)
    binned to the nearest of ``N`` grid points ``c_j`` (``t_b = c_j + v_b h / 2``, ``|v_b|
    <= 1``): rows ``j``, columns ``p < P`` (then zeros to a multiple of 8 columns).

    The weights are `w_plus`; `shift` places a second set, `w_minus`, at the same
    points: ``0``, none; ``N / 2``, the mirrors of the points half a period on (``N / 2``
    grid points on, the same ``v_b``); ``N``, the points' own moments of `w_minus` in rows
    ``N + j`` (``2 N`` rows).  The polynomials of four points at a time come from four
    interleaved Chebyshev recurrences (a multiplication and an addition each step, not
    fused: the same numbers on every machine, whatever its FMA).
    """
    nb = t_b.shape[0]
    width = (P + 7) // 8 * 8
    h = _TWO_PI / N
    inv_h = N / _TWO_PI
    rows = 2 * N if shift == N else N
    bins = np.zeros((rows, width))
    T = np.zeros((4, width))
    cells = np.zeros(4, dtype=np.int64)
    v = np.zeros(4)
    for b0 in range(0, nb, 4):
        count = min(4, nb - b0)
        for i in range(4):
            t = t_b[b0 + i] if i < count else 0.0
            if t >= _TWO_PI:
                t -= _TWO_PI
            elif t < 0.0:
                t += _TWO_PI
            j = int(t * inv_h + 0.5)
            v[i] = (t - j * h) * (2.0 * inv_h)
            cells[i] = j - N if j >= N else j
            T[i, 0] = 1.0
            T[i, 1] = v[i]
        x0, x1, x2, x3 = 2.0 * v[0], 2.0 * v[1], 2.0 * v[2], 2.0 * v[3]
        a0, b0_ = 1.0, v[0]
        a1, b1 = 1.0, v[1]
        a2, b2 = 1.0, v[2]
        a3, b3 = 1.0, v[3]
        for p in range(2, P):
            n0 = x0 * b0_ - a0
            n1 = x1 * b1 - a1
            n2 = x2 * b2 - a2
            n3 = x3 * b3 - a3
            T[0, p] = n0
            T[1, p] = n1
            T[2, p] = n2
            T[3, p] = n3
            a0, b0_ = b0_, n0
            a1, b1 = b1, n1
            a2, b2 = b2, n2
            a3, b3 = b3, n3
        for i in range(count):
            j = cells[i]
            row = bins[j]
            Ti = T[i]
            wp = w_plus[b0 + i]
            if shift > 0:
                o = j + shift
                other = bins[o - N if o >= rows else o]
                wm = w_minus[b0 + i]
                for p in range(width):
                    row[p] += wp * Ti[p]
                    other[p] += wm * Ti[p]
            else:
                for p in range(width):
                    row[p] += wp * Ti[p]
    return bins


@njit(cache=True)
def jump_sums_binned(t_b, w_plus, w_minus, mirror, L, N, P, table, tw):  # pragma: no cover
    """``Z_l = sum_b w_b exp(-j l t_b)`` for ``l = 0 .. L``, real weights `w_plus` (and with
    `mirror`, `w_minus` half a period on), in ``O(points + L log L)`` (the grid ``N`` and
    terms ``P`` of :func:`binned_grid`).

    The points are binned to the nearest grid point ``c_j`` (``h = 2 pi / N``), with
    ``t_b = c_j + v h / 2``, ``|v| <= 1``; then ``exp(-j l t_b) = exp(-j l c_j) sum_p
    eps_p (-j)^p J_p(l h / 2) T_p(v)`` (Jacobi-Anger: Chebyshev polynomials ``T_p``,
    Bessel functions ``J_p``, ``eps_0 = 1``, else 2), summed until its terms are below
    1e-17: one FFT of the bins' moments (:func:`chebyshev_moments`) for each term, read at
    ``l`` modulo ``N``; real moments go two to a complex FFT.  `table` holds the terms'
    weights (:func:`binned_table` of ``N``, ``P`` and at least ``L``), `tw` the twiddle
    table of at least ``N`` points.
    """
    bins = chebyshev_moments(t_b, w_plus, w_minus, N // 2 if mirror else 0, N, P)
    return binned_sums(bins, L, N, P, table, tw)


@njit(cache=True)
def binned_sums(bins, L, N, P, table, tw):  # pragma: no cover - compiled
    """:func:`jump_sums_binned` from the moments `bins` (:func:`chebyshev_moments`: rows
    ``j < N``, columns ``p < P`` at least)."""
    n_pairs = (P + 1) // 2
    reversed_index = bit_reversed_indices(N)
    mu = np.empty((n_pairs, N), dtype=np.complex128)
    for pp in range(n_pairs):
        row = mu[pp]
        for j in range(N):
            src = bins[reversed_index[j]]
            row[j] = complex(src[2 * pp], src[2 * pp + 1])
        fft_unscrambling(row, tw)
    Z = np.empty(L + 1, dtype=np.complex128)
    for q in range(L + 1):
        iq = q % N
        im = (N - iq) % N
        w = table[q]
        z = 0j
        for pp in range(n_pairs):
            z += w[2 * pp] * mu[pp, iq] + w[2 * pp + 1] * mu[pp, im].conjugate()
        Z[q] = z
    return Z


@njit(cache=True)
def jump_sums_binned_odd(t_b, w, L, N, P, table, tw):  # pragma: no cover - compiled
    """:func:`jump_sums_binned` with `mirror` and the weights ``w`` at ``t_b``, ``-w`` half a
    period on, whose sums vanish at even ``l``: ``Z_l = 2 sum_b w_b exp(-j l t_b)`` at odd
    ``l <= L`` (zero at even ``l``), in half the transforms (:func:`half_grid_sums`).
    """
    # the points alone (shift N - N = 0, and odd L >= 0: values, not literals, so that one
    # compiled version of each kernel serves every call)
    bins = chebyshev_moments(t_b, w, w, N - N, N, P)
    return half_grid_sums(bins, N - N, L >= 0, L, N, P, table, tw)


@njit(cache=True)
def half_grid_sums(bins, first, odd, L, N, P, table, tw):  # pragma: no cover - compiled
    """:func:`jump_sums_binned` at the odd or the even ``l <= L`` only, from the moments of the
    points alone (:func:`chebyshev_moments`: rows ``first + j``, ``j < N``, columns ``p < P``
    at least), each set of harmonics by transforms of half the grid (zero at the others).

    With ``B_j`` those moments, ``exp(-j l c_j)`` at even ``l`` repeats after ``N / 2``
    points: the sums are the transform of the ``N / 2`` points ``B_j + B_{j + N/2}`` read at
    ``l / 2``.  With `odd` the points have their opposites half a period on (weights ``w``
    and ``-w``), whose moments are ``B_j - B_{j - N/2}``: at odd ``l`` the transform of
    these is twice that of ``D_j exp(-2 pi j j l / N)``, ``D_j = B_j - B_{j + N/2}``, ``j <
    N / 2``: the transform of ``N / 2`` points of ``D_j exp(-2 pi j j / N)`` read at ``(l -
    1) / 2`` (the sums returned are those of the points and their opposites, ``2 sum_b w_b
    exp(-j l t_b)``).
    """
    n_pairs = (P + 1) // 2
    half = N // 2
    step = 2 * tw.shape[0] // N
    sign = -1.0 if odd else 1.0
    reversed_index = bit_reversed_indices(half)
    y = np.empty((n_pairs, half), dtype=np.complex128)
    for pp in range(n_pairs):
        row = y[pp]
        for j in range(half):
            jj = reversed_index[j]
            a = bins[first + jj]
            b = bins[first + jj + half]
            z = complex(a[2 * pp] + sign * b[2 * pp], a[2 * pp + 1] + sign * b[2 * pp + 1])
            row[j] = z * tw[jj * step] if odd else z
        fft_unscrambling(row, tw)
    # their real and imaginary parts with the terms side by side (rows j), for the sums
    # over the terms at each l in independent parts
    yr = np.empty((half, n_pairs))
    yi = np.empty((half, n_pairs))
    for pp in range(n_pairs):
        for j in range(half):
            yr[j, pp] = y[pp, j].real
            yi[j, pp] = y[pp, j].imag
    Z = np.zeros(L + 1, dtype=np.complex128)
    q0 = 1 if odd else 0
    scale = 2.0 if odd else 1.0
    for q in range(q0, L + 1, 2):
        iq = q % N
        a = iq // 2
        b = ((N - iq) % N) // 2
        weights = table[q]
        zr_a = 0.0
        zr_b = 0.0
        zi_a = 0.0
        zi_b = 0.0
        for pp in range(n_pairs):
            w_a = weights[2 * pp]
            w_b = weights[2 * pp + 1]  # times the conjugate of the transform at -l
            zr_a += w_a * yr[a, pp]
            zr_b += w_b * yr[b, pp]
            zi_a += w_a * yi[a, pp]
            zi_b -= w_b * yi[b, pp]
        Z[q] = scale * complex(zr_a + zr_b, zi_a + zi_b)
    return Z
