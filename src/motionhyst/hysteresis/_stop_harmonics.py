"""The exact periodic output of parallel stop operators, compiled whole (numba).

:func:`stop_harmonics` is :func:`motionhyst.hysteresis.periodic.stop_periodic_harmonics`
in one kernel: the input's reversal points and the elements' pieces between them
(:mod:`motionhyst.hysteresis._kernels`), the sums over the pieces' jumps
(:mod:`motionhyst.hysteresis._jump_sums`) and the product ``s x`` by compiled FFTs
(:mod:`motionhyst.hysteresis._fft`).  :func:`stop_harmonics_kept` keeps the binned sums'
weights from one call to the next (a fixed point's iterations, a sweep's points).
"""

from __future__ import annotations

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._fft import (
    analyze_packed,
    analyze_packed_odd,
    packed_product,
    synthesize,
    synthesize_odd,
    synthesize_packed,
    synthesize_packed_odd,
)
from motionhyst.hysteresis._jump_sums import (
    binned_grid_to,
    binned_is_cheaper,
    binned_table,
    chebyshev_moments,
    chebyshev_terms_to,
    half_grid_sums,
    jump_series,
    jump_series_half,
    jump_sums_binned,
)
from motionhyst.hysteresis._kernels import (
    BETWEEN_REVERSALS,
    CUBIC_ELEMENTS,
    GRID_BRACKET,
    GRID_CUBIC,
    cubic_error_bound,
    dominant_reversals,
    first_harmonic_dominates,
    half_cubic_pieces,
    half_sine_pieces,
    reversal_points,
    stop_pieces,
    trig2,
)

_TWO_PI = 2.0 * np.pi
#: Largest change of the input, relative to its size (the sums of the harmonics' moduli),
#: that :func:`stop_harmonics_update` follows to first order.  The output's error is of
#: the order of the change squared (1e-20 of it); an element that begins to slip right at
#: the reversal adds at most the change to the power 1.5 times its share of the stiffness.
LINEAR_CHANGE = 1e-10
#: Smallest accuracy asked of a sine's output (relative to the sums of the jumps' moduli) for
#: which the sums of the jumps of ``g`` come from those of ``s`` (:func:`_binned_series`):
#: their round-off, up to 1e-14 where ``g``'s sums cancel (every element slips), is then
#: far below what is asked (the fixed point's first iteration asks 1e-10).
SINE_TOL = 1e-12


@njit(cache=True)
def grid_size(M, H):  # pragma: no cover - compiled
    """Samples of the grid of :func:`stop_harmonics`: a power of two that brackets the roots
    (at least 1024 cells, 4 per harmonic) and carries ``s x`` without aliasing."""
    need = max(1024, 4 * M, 2 * (H + M) + 1)
    n = 1024
    while n < need:
        n *= 2
    return n


@njit(cache=True)
def significant_count(X, rtol):  # pragma: no cover - compiled
    """Number of leading harmonics of `X` (DC aside) whose tail is below `rtol` of the total
    (:func:`motionhyst.hysteresis.periodic.significant_harmonics`)."""
    total = 0.0
    for m in range(1, X.shape[0]):
        total += abs(X[m])
    if total == 0.0:
        return 0
    tail = 0.0
    for m in range(X.shape[0] - 1, 0, -1):
        tail += abs(X[m])
        if tail > rtol * total:
            return m
    return 0


@njit(cache=True)
def _without_dc(X, M):  # pragma: no cover - compiled
    """Harmonics ``0 .. M`` of `X` with ``X_0 = 0``; whether the even ones are below 1e-15 of
    the total (then set to zero: a half-wave symmetric input); the total of the moduli."""
    Xs = X[: M + 1].copy()
    Xs[0] = 0.0
    total = 0.0
    even = 0.0
    for m in range(1, M + 1):
        total += abs(Xs[m])
        if m % 2 == 0:
            even += abs(Xs[m])
    symmetric = even <= 1e-15 * total
    if symmetric:
        for m in range(2, M + 1, 2):
            Xs[m] = 0.0
    return Xs, symmetric, total


@njit(cache=True)
def stop_harmonics(X, k, fc, H, tw):  # pragma: no cover - compiled
    """Harmonics ``0 .. H`` of the periodic output of parallel stop operators, compiled whole
    (:func:`motionhyst.hysteresis.periodic.stop_periodic_harmonics`).

    `tw` is the twiddle table (:func:`motionhyst.hysteresis._fft.twiddle_table`) of at
    least ``grid_size(len(X) - 1, H)`` samples.  See :func:`stop_harmonics_kept`, which
    this calls with nothing kept.
    """
    # q_grid = H: the grid for the sums' own H + M harmonics
    return stop_harmonics_kept(X, k, fc, H, tw, np.empty((0, 0)), np.zeros(2, dtype=np.int64),
                               H)[0]


@njit(cache=True)
def stop_harmonics_kept(X, k, fc, H, tw, table, grid, q_grid):  # pragma: no cover - compiled
    """:func:`stop_harmonics`, with the weights of the binned jump sums kept from one call to
    the next (a fixed point's iterations, the points of a sweep): `table` is
    :func:`binned_table` of the grid ``grid = [N, P]`` (updated in place); returns the
    harmonics and the table (the one given when it serves, else a new one).  The grid is
    chosen for harmonics up to `q_grid` where that exceeds the sums' own ``H + M`` (one
    grid for inputs of any ``M <= q_grid - H``).  See :func:`stop_harmonics_base`.
    """
    out = stop_harmonics_base(X, k, fc, H, tw, table, grid, q_grid, 1e-17)
    return out[0], out[1]


@njit(cache=True)
def stop_harmonics_base(X, k, fc, H, tw, table, grid, q_grid, tol):  # pragma: no cover
    """:func:`stop_harmonics_kept` with the binned sums to `tol` of the sums of their weights'
    moduli (1e-17: to round-off), returning also what :func:`stop_harmonics_update` needs
    to follow a small change of the input: ``(W, table, base, Xs, S, zs, t_b, js, x_top,
    moments)``.

    ``base`` is True where the output came from many jumps binned (the costly case) over a
    half-wave symmetric, monotone branch: ``Xs`` is then the input as used (no DC, no even
    harmonics), ``S`` the harmonics ``0 .. H + M`` of the stiffness ``s`` (``zs`` its
    samples as transformed for the product ``s x``, where it was transformed), ``t_b`` and
    ``js`` the jumps of ``s`` over the first half period (the slip onsets, then the
    reversal at the maximum ``x_top``), ``moments`` the jumps' Chebyshev moments on the
    binned sums' grid (:func:`chebyshev_moments` with ``shift = N``: those of ``js`` in the
    first ``N`` rows).

    The reversals come from :func:`dominant_reversals` where it applies, else from the
    grid.  An input whose even harmonics are below 1e-15 of the total is taken as half-wave
    symmetric (they are set to zero): with two reversals the output is then found for half
    a period and mirrored (:func:`stop_pieces`).  The output is ``w = g + s x``: the
    coefficients of ``g`` and ``s`` are sums over their jumps, binned where that is cheaper
    (:func:`_binned_series`), and those of ``s x`` a direct convolution where that takes
    fewer operations than the transforms.
    """
    W = np.zeros(H + 1, dtype=np.complex128)
    none = np.empty(0, dtype=np.complex128)
    no_jumps = np.empty(0)
    no_moments = np.empty((0, 0))
    M = significant_count(X, 1e-15)
    if M == 0:
        return W, table, False, none, none, none, no_jumps, no_jumps, 0.0, no_moments
    # half-wave symmetric x (even harmonics a round-off of the odd ones, as a symmetric
    # loop's y1): made exact, its output's second half period mirrors the first
    Xs, symmetric, total = _without_dc(X, M)
    C1 = np.empty(M + 1, dtype=np.complex128)
    C2 = np.empty(M + 1, dtype=np.complex128)
    for m in range(M + 1):
        C1[m] = 1j * m * Xs[m]
        C2[m] = -(m * m) * Xs[m]
    n = grid_size(M, H)
    direct = 2 * M * (H + 1) <= 4 * n
    monotone, rev, xr = dominant_reversals(Xs, C1, C2, symmetric)
    x = np.empty(0)
    if not monotone:
        x = synthesize(Xs, n, tw)
        rev, xr = reversal_points(Xs, C1, C2, synthesize(C1, n, tw))
    if rev.shape[0] < 2:
        return W, table, False, none, none, none, no_jumps, no_jumps, 0.0, no_moments
    mode = GRID_BRACKET
    if monotone:
        mode = BETWEEN_REVERSALS
        # many elements: slip onsets on the grid's cubic where its error is far below x's
        # range (the output changes with the square of an onset's error: w is continuous)
        if (k.shape[0] >= CUBIC_ELEMENTS
                and cubic_error_bound(Xs, n) <= 1e-9 * abs(xr[0] - xr[1])):
            mode = GRID_CUBIC
            if M > 1:  # (without even harmonics: half the transform)
                x = synthesize_odd(Xs, n, tw) if symmetric else synthesize(Xs, n, tw)
    half = symmetric and monotone
    top = 1 if xr[1] > xr[0] else 0
    sine = half and mode == GRID_CUBIC and M == 1
    if sine:  # the onsets in closed form
        t_b, jg, js, g_mean, s_mean = half_sine_pieces(rev[top], xr[top], k, fc)
    elif half and mode == GRID_CUBIC:
        t_b, jg, js, g_mean, s_mean = half_cubic_pieces(x, rev[top], xr[top], k, fc)
    else:
        t_b, jg, js, g_mean, s_mean = stop_pieces(Xs, C1, x, rev, xr, k, fc, mode, half)
    Q = H + M
    nb = t_b.shape[0]
    binned = binned_is_cheaper(2 * nb if half else nb, Q, 2 * tw.shape[0])
    if binned:
        # the harmonics of s above H + 1 meet those of x above the first only: to the
        # accuracy their small size needs
        tail = 0.0
        for m in range(2, M + 1):
            tail += abs(Xs[m])
        tol_rest = min(tol * total / tail, 1e-3) if tail > 0.0 else 1e-3
        G, S, table, moments = _binned_series(t_b, jg, js, H, Q, max(Q, q_grid), half, tw,
                                              table, grid, max(tol, tol_rest), tol,
                                              xr[top] if sine and tol >= SINE_TOL else 0.0)
    elif half:
        G, S = jump_series_half(t_b, jg, js, H, Q)
    else:
        G, S = jump_series(t_b, jg, js, H, Q)
    G[0] = g_mean
    S[0] = s_mean
    if direct:
        _add_convolution(G, S, Xs, 1, W)
        zs = none
    else:
        P_x, zs = _product(S, Xs, n, H, half, tw)
        for q in range(H + 1):
            W[q] = G[q] + P_x[q]
    if half and binned:
        return W, table, True, Xs, S, zs, t_b, js, xr[top], moments
    return W, table, False, none, none, none, no_jumps, no_jumps, 0.0, no_moments


@njit(cache=True)
def stop_harmonics_update(X, H, tw, Wb, Xb, S, zs, t_b, js, x_top, moments, table,
                          grid):  # pragma: no cover - compiled
    """The output of :func:`stop_harmonics_base` for the input `X`, from its output ``Wb`` for
    an input ``Xb`` near it (``Xb``, ``S``, ``zs``, ``t_b``, ``js``, ``x_top``, ``moments`` as it
    returned them, `table` and `grid` the weights and grid of its binned sums), to first
    order in their difference.  Returns ``(ok, W)``; ``ok`` is False (``W`` unset) where `X` is not
    half-wave symmetric, not monotone between two reversals, has more harmonics than
    ``Xb``, differs from it by more than :data:`LINEAR_CHANGE`, or would need more terms
    of the binned sums than `table` and ``moments`` hold.

    From the maximum ``x_top`` to the minimum an element that slips sticks, ``w = fc - k
    (x_top - x)``, until its slip onset, then slips, ``w = -fc``; one that never slips
    follows ``w = k x``.  With ``x`` moved by ``dx`` and its maximum by ``dx_top``, the
    output moves by ``(s dx)^ - dx_top (s_slip sigma)^``: ``s`` the stiffness of the
    sticking elements (its harmonics ``S``), ``s_slip`` that of those among them that slip
    later (its jumps ``js`` at ``t_b``), ``sigma`` +1 from the maximum to the minimum and
    -1 back.  The onsets move as well, but ``w`` is continuous there: they change it to
    the second order only.  The new maximum is that of the parabola through ``x``, ``x'``
    and ``x''`` at the old one's angle (its error of the third order in the small move of
    the angle).  The sums of
    ``js`` are binned on the grid of ``S``'s, from their moments computed there, to the
    accuracy the small ``dx_top`` needs (:func:`half_grid_sums`).
    """
    W = np.zeros(H + 1, dtype=np.complex128)
    Mb = Xb.shape[0] - 1
    M = significant_count(X, 1e-15)
    if M == 0 or M > Mb:
        return False, W
    Xs, symmetric, total = _without_dc(X, M)
    if not symmetric:
        return False, W
    D = np.zeros(Mb + 1, dtype=np.complex128)
    change = 0.0
    for m in range(1, Mb + 1, 2):
        D[m] = (Xs[m] if m <= M else 0.0) - Xb[m]
        change += abs(D[m])
    if not change <= LINEAR_CHANGE * total:
        return False, W
    if not first_harmonic_dominates(Xs)[0]:
        return False, W
    C1 = np.empty(M + 1, dtype=np.complex128)
    C2 = np.empty(M + 1, dtype=np.complex128)
    C1_d = np.empty(Mb + 1, dtype=np.complex128)
    for m in range(M + 1):
        C1[m] = 1j * m * Xs[m]
        C2[m] = -(m * m) * Xs[m]
    for m in range(Mb + 1):
        C1_d[m] = 1j * m * D[m]
    a = t_b[t_b.shape[0] - 1]  # the maximum's angle: the reversal's jump comes last
    slope, curvature = trig2(C1, C2, a)
    d_top = trig2(D, C1_d, a)[0] - 0.5 * slope * slope / curvature
    n = grid_size(Mb, H)
    if zs.shape[0] == 0:  # the full evaluation's product was a direct convolution
        _add_convolution(Wb, S, D, 2, W)
    else:
        P_x = _product_with(zs, D, n, H, symmetric, tw)
        for q in range(H + 1):
            W[q] = Wb[q] + P_x[q]
    if d_top == 0.0:
        return True, W
    nb = t_b.shape[0]
    size = 0.0
    for b in range(nb):
        size += abs(js[b])
    w_max = 0.0
    for q in range(H + 1):
        w_max = max(w_max, abs(Wb[q]))
    # the sums of js with an error below 1e-17 of the output's largest harmonic: the terms
    # from P on are below tol of the weights' 2 size, and 1 / (2 pi q) <= 1 / (2 pi)
    N = grid[0]
    tol = np.pi * 1e-17 * w_max / (abs(d_top) * size)
    if N <= 0 or not tol > 0.0:  # no grid kept with the table, or no output to measure by
        return False, W
    P = chebyshev_terms_to(np.pi * H / N, tol)
    # the table's weights of a term do not depend on the terms after it, nor the moments
    if P > grid[1] or moments.shape[0] != 2 * N or moments.shape[1] < P:
        return False, W
    # js at t_b and -js half a period on: twice the sums of js at odd q
    Z = half_grid_sums(moments, N - N, N > 0, H, N, P, table, tw)
    for q in range(1, H + 1, 2):
        W[q] -= d_top * Z[q] * (-1j / (_TWO_PI * q))
    return True, W


@njit(cache=True, inline="always")
def _add_convolution(A, S, Y, step, W):  # pragma: no cover - compiled
    """``W_q = A_q + (s y)_q``, ``q <= len(W) - 1``, by the direct convolution of the harmonics
    ``S`` and ``Y`` (every `step`-th harmonic of ``Y`` from the first, the others zero)."""
    for q in range(W.shape[0]):
        acc = A[q]
        for m in range(1, Y.shape[0], step):
            lo = q - m
            acc += (S[lo] if lo >= 0 else S[-lo].conjugate()) * Y[m]
            acc += S[q + m] * Y[m].conjugate()
        W[q] = acc


@njit(cache=True)
def _binned_series(t_b, jg, js, H, Q, q_grid, half, tw, table, grid, tol, tol_full,
                   x_sine):  # pragma: no cover - compiled
    """:func:`jump_series` of many jumps, binned (:func:`jump_sums_binned`) on the grid for
    harmonics up to `q_grid` (>= `Q`), to `tol` of the sums of the weights' moduli (those up
    to ``H + 1`` to ``tol_full``), with the weights' `table` of the grid ``grid = [N, P]``
    kept (a new one where it does not serve).

    With `half` (the jumps of the first half period; the second's are ``-jg`` and ``js``
    half a period on) ``s`` has only even harmonics, twice the sums of `js` there, and
    ``g`` only odd ones, the sums of `jg` and their opposites: each from the moments of the
    jumps alone on half the grid (:func:`half_grid_sums`; the moments of `js` and `jg`
    together, :func:`chebyshev_moments` with ``shift = N``, returned as well).  Returns
    ``G``, ``S``, the table and those moments (none without `half`).

    With `x_sine` > 0 the input is the sine ``x = x_sine cos(theta - a)``, ``a`` the angle
    of the last jump (the reversal, :func:`half_sine_pieces`): at each slip onset before it
    ``g`` jumps by ``-js x`` (``w = g + s x`` is continuous there), so that the sums of `jg`
    at odd ``q`` are ``-x_sine / 2`` times those of `js` at ``q - 1`` and ``q + 1``, turned
    by ``exp(-+j a)``, plus the reversal's own: only the moments of `js` are binned (those
    returned).
    """
    nb = t_b.shape[0]
    n_points = 2 * nb if half else nb
    N, P = binned_grid_to(n_points, q_grid, 2 * tw.shape[0], tol, H + 1, tol_full)
    if N != grid[0] or P != grid[1] or table.shape[0] <= Q:
        table = binned_table(N, P, q_grid)
        grid[0] = N
        grid[1] = P
    G = np.zeros(H + 1, dtype=np.complex128)
    S = np.zeros(Q + 1, dtype=np.complex128)
    if half and x_sine > 0.0:
        alone = chebyshev_moments(t_b, js, js, N - N, N, P)
        Zs = half_grid_sums(alone, N - N, N < 0, Q, N, P, table, tw)  # q <= H + 1 = Q
        for q in range(2, Q + 1, 2):
            S[q] = Zs[q] * (-2j / (_TWO_PI * q))
        last = nb - 1
        a = t_b[last]
        turn = complex(np.cos(a), -np.sin(a))  # exp(-j a)
        # the reversal's jump of g less what the onsets' rule gives it
        extra = jg[last] + x_sine * js[last]
        for q in range(1, H + 1, 2):
            sums = extra * complex(np.cos(q * a), -np.sin(q * a)) - 0.5 * x_sine * (
                turn * Zs[q - 1] + turn.conjugate() * Zs[q + 1])
            G[q] = sums * (-2j / (_TWO_PI * q))
        return G, S, table, alone
    if half:
        pair = chebyshev_moments(t_b, js, jg, N, N, P)
        # (the row and the flag as values, not literals: one compiled version serves all)
        Zs = half_grid_sums(pair, N - N, N < 0, Q, N, P, table, tw)
        Zg = half_grid_sums(pair, N, N > 0, H, N, P, table, tw)  # twice the sums
        for q in range(2, Q + 1, 2):
            S[q] = Zs[q] * (-2j / (_TWO_PI * q))
        for q in range(1, H + 1, 2):
            G[q] = Zg[q] * (-1j / (_TWO_PI * q))
        return G, S, table, pair
    Zg = jump_sums_binned(t_b, jg, jg, half, H, N, P, table, tw)  # half is False here
    Zs = jump_sums_binned(t_b, js, js, half, Q, N, P, table, tw)
    for q in range(1, Q + 1):
        scale = -1j / (_TWO_PI * q)
        if q <= H:
            G[q] = Zg[q] * scale
        S[q] = Zs[q] * scale
    return G, S, table, np.empty((0, 0))


@njit(cache=True)
def _product(S, Y, n, H, half, tw):  # pragma: no cover - compiled
    """Harmonics ``0 .. H`` of ``s y`` from those of ``s`` (`S`) and ``y`` (`Y`), by transforms
    of `n` samples, and the samples of ``s`` as transformed (:func:`_product_with`)."""
    if half:  # s's packed samples from half the transform
        zs = synthesize_packed(S[0::2].copy(), n // 2, tw)
    else:
        zs = synthesize_packed(S, n, tw)
    return _product_with(zs, Y, n, H, half, tw), zs


@njit(cache=True)
def _product_with(zs, Y, n, H, half, tw):  # pragma: no cover - compiled
    """:func:`_product` from the samples `zs` of ``s`` it gave.  With `half` ``s`` repeats
    after half a period (even harmonics only) and ``y`` changes sign (odd harmonics only),
    and so does ``s y``: each transform is of half the samples
    (:func:`synthesize_packed_odd`, :func:`analyze_packed_odd`)."""
    if half:
        # t and t + n / 4 are neighbours in bit-reversed order, where y's are y_u and -y_u
        zy = synthesize_packed_odd(Y, n, tw)
        return analyze_packed_odd(packed_product(zy, zs), n, H, tw)
    return analyze_packed(packed_product(synthesize_packed(Y, n, tw), zs), n, H, tw)
