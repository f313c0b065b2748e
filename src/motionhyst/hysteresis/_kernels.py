"""Compiled inner loops of the rate-independent elements (numba).

The sampled response of the stop operator (Jenkins) and of parallel stop
operators (Maxwell-slip), and the steps of their exact periodic output
(:mod:`motionhyst.hysteresis.periodic`): roots of trigonometric polynomials,
the elements' pieces between reversals (their Fourier sums over jumps are in
:mod:`motionhyst.hysteresis._jump_sums`).  The reversal points of a periodic input
(:func:`reversal_roots`) also serve the smooth models
(:func:`motionhyst.hysteresis._ode_periodic.reversal_angles`).
"""

from __future__ import annotations

import numpy as np

from motionhyst.core.compiled import njit


@njit(cache=True)
def stop_response(x, k, fc, w0):  # pragma: no cover - compiled
    """Exact stop-operator (Jenkins) output for samples `x`, first output `w0`."""
    n = x.shape[0]
    w = np.empty(n)
    if n == 0:
        return w
    wi = w0
    w[0] = wi
    for i in range(1, n):
        wi = wi + k * (x[i] - x[i - 1])
        if wi > fc:
            wi = fc
        elif wi < -fc:
            wi = -fc
        w[i] = wi
    return w


@njit(cache=True)
def maxwell_response(x, k, fc, w0):  # pragma: no cover - compiled
    """Output of parallel stop operators; returns the per-element forces (n, m)."""
    n = x.shape[0]
    m = k.shape[0]
    w = np.empty((n, m))
    if n == 0:
        return w
    for j in range(m):
        w[0, j] = w0[j]
    for i in range(1, n):
        dx = x[i] - x[i - 1]
        for j in range(m):
            wi = w[i - 1, j] + k[j] * dx
            if wi > fc[j]:
                wi = fc[j]
            elif wi < -fc[j]:
                wi = -fc[j]
            w[i, j] = wi
    return w


# ---------------------------------------------------------------------------
# Exact periodic output of parallel stop operators (see periodic.py)
# ---------------------------------------------------------------------------

_TWO_PI = 2.0 * np.pi
CUBIC_ELEMENTS = 16  # from this many elements on, slip onsets may come from the grid's cubic
_THIRD = 1.0 / 3.0
_SIXTH = 1.0 / 6.0


@njit(cache=True)
def trig2(A, B, theta):  # pragma: no cover - compiled
    """``2 Re sum_m A_m z^m`` and ``2 Re sum_m B_m z^m`` (m >= 1, ``z = exp(j theta)``): Horner
    in ``z^2`` over the odd and the even ``m`` apart (four chains side by side)."""
    z = complex(np.cos(theta), np.sin(theta))
    w = z * z
    top = A.shape[0] - 1
    m_odd = top if top % 2 == 1 else top - 1
    m_even = top - 1 if top % 2 == 1 else top
    a_odd = 0j
    b_odd = 0j
    a_even = 0j
    b_even = 0j
    while m_even >= 2:  # as many odd terms as even ones, or one more
        a_odd = a_odd * w + A[m_odd]
        b_odd = b_odd * w + B[m_odd]
        a_even = a_even * w + A[m_even]
        b_even = b_even * w + B[m_even]
        m_odd -= 2
        m_even -= 2
    while m_odd >= 1:
        a_odd = a_odd * w + A[m_odd]
        b_odd = b_odd * w + B[m_odd]
        m_odd -= 2
    pa = z * a_odd + w * a_even
    pb = z * b_odd + w * b_even
    return 2.0 * pa.real, 2.0 * pb.real


@njit("float64(complex128[::1], complex128[::1], float64, float64, float64, boolean, float64, "
      "boolean)", cache=True)
def bracketed_root(A, B, level, lo, hi, rising, t, predict):  # pragma: no cover - compiled
    """Root of ``2 Re sum_m A_m exp(j m theta) = level`` in [lo, hi], where the function
    rises (`rising`) or falls through `level` once, by Newton from `t` (in the bracket).

    The bracket is narrowed at each iterate, and a Newton step that would leave it
    becomes a bisection step.  With `predict` (a simple root, Newton converging
    quadratically from `t`) the steps stop when the next one, ``s_k^3 / s_{k-1}^2``,
    would be below round-off.
    """
    last = np.inf
    for _ in range(100):
        f, fp = trig2(A, B, t)
        f -= level
        if f == 0.0:
            return t
        if (f > 0.0) == rising:
            hi = t
        else:
            lo = t
        t_new = t - f / fp if fp != 0.0 else 0.5 * (lo + hi)
        step = abs(t_new - t)
        tiny = 4e-16 * max(1.0, abs(t))
        if step <= tiny:
            return t_new
        if not (lo <= t_new <= hi):
            t_new = 0.5 * (lo + hi)
            step = np.inf
        elif (predict and last < np.inf and step < 1e-3 * last
              and step * step * step <= tiny * last * last):
            return t_new
        if hi - lo <= 4e-16 * max(1.0, abs(t_new)):
            return t_new
        last = step
        t = t_new
    return t


@njit(cache=True)
def trig_root(A, B, level, a, b, fa, fb):  # pragma: no cover - compiled
    """Root of ``2 Re sum_m A_m exp(j m theta) = level`` in the grid cell [a, b].

    `B` holds the derivative's coefficients (``j m A_m``) and `fa`, `fb` the
    function minus `level` at the cell's ends (from the grid samples).
    Newton from the linear interpolant; two or three steps reach round-off.

    Where `fa` and `fb` bracket a root (opposite signs, or one of them zero)
    the bracket is narrowed at each iterate, and a Newton step that would
    leave it becomes a bisection step: the root found is the one in the cell,
    also when a second root lies just beyond its end (two reversals close
    together).  A root on a grid point, where the samples and the polynomial
    may disagree by round-off about its side, comes out within round-off of
    the grid point.  Without a bracket (`_crossing` with a level a round-off
    beyond the values in the cell) Newton may go half a cell either side,
    with bisection on the widest bracket with a sign change if it leaves
    that range.
    """
    h = b - a
    t = a + h * fa / (fa - fb) if fa != fb else 0.5 * (a + b)
    if fa != fb and (fa <= 0.0 <= fb or fb <= 0.0 <= fa):
        return bracketed_root(A, B, level, a, b, fb > fa, t, False)
    lo = a - 0.5 * h
    hi = b + 0.5 * h
    converged = True
    for _ in range(8):
        f, fp = trig2(A, B, t)
        if fp == 0.0:
            converged = False
            break
        t_new = t - (f - level) / fp
        if not (lo <= t_new <= hi):
            converged = False
            break
        if abs(t_new - t) <= 4e-16 * max(1.0, abs(t)):
            return t_new
        t = t_new
    if converged:
        return t
    # bisection on the widest bracket with a sign change
    flo = trig2(A, B, lo)[0] - level
    fhi = trig2(A, B, hi)[0] - level
    if flo * fhi > 0.0:
        lo, hi = a, b
        flo = trig2(A, B, lo)[0] - level
        fhi = trig2(A, B, hi)[0] - level
        if flo * fhi > 0.0:
            return a + h * fa / (fa - fb) if fa != fb else 0.5 * (a + b)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if hi - lo <= 1e-15 + 1e-15 * abs(mid) or mid == lo or mid == hi:
            break
        fm = trig2(A, B, mid)[0] - level
        if fm == 0.0:
            return mid
        if (fm > 0.0) == (flo > 0.0):
            lo, flo = mid, fm
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def reversal_roots(C1, C2, d):  # pragma: no cover - compiled
    """Roots of ``x'`` bracketed by the grid ``theta_i = 2 pi i / n``, one per grid cell.

    `C1` are the harmonics of ``x'`` (``j m X_m``), `C2` those of ``x''``
    (``-m^2 X_m``) and `d` holds ``x'`` on the grid.  A cell ``i`` (from
    ``theta_i`` to ``theta_{i+1}``, cyclically) brackets a root where ``d > 0``
    holds at one of its ends and not at the other; the root is refined by
    :func:`trig_root`.  A double root (tangency) or two roots inside one cell
    give no sign change and are not reported; a constant ``x`` has none.

    Returns
    -------
    cells : ndarray of int64
        The cells ``i`` with a sign change, ascending.
    roots : ndarray
        The root in each cell: in ``[theta_i, theta_{i+1}]`` up to round-off
        (a root on a grid point may lie a round-off outside), not wrapped
        into ``[0, 2 pi)`` (the last cell ends at ``2 pi``).
    """
    n = d.shape[0]
    h = _TWO_PI / n
    count = 0
    for i in range(n):
        if (d[i] > 0.0) != (d[i + 1 if i + 1 < n else 0] > 0.0):
            count += 1
    cells = np.empty(count, dtype=np.int64)
    roots = np.empty(count)
    q = 0
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        if (d[i] > 0.0) != (d[j] > 0.0):
            a = i * h
            cells[q] = i
            roots[q] = trig_root(C1, C2, 0.0, a, a + h, d[i], d[j])
            q += 1
    return cells, roots


@njit(cache=True)
def reversal_points(X, C1, C2, d):  # pragma: no cover - compiled
    """Angles in [0, 2 pi) where ``x`` changes direction, sorted, and ``x`` there.

    `X` are the harmonics of ``x``, ``C1 = j m X`` and ``C2 = -m^2 X`` those of
    its first two derivatives, `d` holds ``x'`` on the grid ``2 pi i / n``.
    The roots are those of :func:`reversal_roots`, wrapped into [0, 2 pi).
    """
    rev = reversal_roots(C1, C2, d)[1]
    # the roots ascend with their cells, so wrapping leaves them sorted but for the first
    # and last few, which an insertion sort moves in a few steps (and compiles in a
    # fraction of the time of numpy's sort)
    for i in range(rev.shape[0]):
        r = rev[i] % _TWO_PI
        j = i
        while j > 0 and rev[j - 1] > r:
            rev[j] = rev[j - 1]
            j -= 1
        rev[j] = r
    xr = np.empty(rev.shape[0])
    for q in range(rev.shape[0]):
        xr[q] = X[0].real + trig2(X, C1, rev[q])[0]
    return rev, xr


@njit(cache=True)
def _crossing(X, C1, x, level, a, b):  # pragma: no cover - compiled
    """Angle in [a, b] (b may exceed 2 pi) where the monotone ``x`` passes `level`.

    The first grid cell with a sign change of ``x - level`` brackets the root.
    """
    n = x.shape[0]
    h = _TWO_PI / n
    i0 = int(np.floor(a / h))
    i1 = int(np.ceil(b / h))
    t_prev = a
    g_prev = X[0].real + trig2(X, C1, a)[0] - level
    t_first, g_first = a, g_prev
    for i in range(i0 + 1, i1 + 1):
        if i == i1:
            t = b
            g = X[0].real + trig2(X, C1, b)[0] - level
        else:
            t = i * h
            g = x[i % n] - level
        if i == i0 + 1:
            t_first, g_first = t, g
        if np.sign(g_prev) * np.sign(g) <= 0.0:
            return trig_root(X, C1, level - X[0].real, t_prev, t, g_prev, g)
        t_prev, g_prev = t, g
    # no sign change (the level is a round-off outside [x(a), x(b)]): the first cell
    return trig_root(X, C1, level - X[0].real, a, t_first,
                     X[0].real + trig2(X, C1, a)[0] - level, g_first)


@njit(cache=True)
def _monotone_crossing(X, C1, level, a, b, fa, fb):  # pragma: no cover - compiled
    """Angle in [a, b] where ``x``, monotone there, passes `level` (``fa``, ``fb``: ``x``
    minus `level` at the ends); Newton from where a half sine would pass it."""
    if fa == 0.0 or fb == 0.0 or (fa > 0.0) == (fb > 0.0):
        return a if abs(fa) <= abs(fb) else b
    u = fa / (fa - fb)
    t = a + (b - a) * np.arccos(min(max(1.0 - 2.0 * u, -1.0), 1.0)) / np.pi
    return bracketed_root(X, C1, level, a, b, fb > fa, t, True)


#: How :func:`stop_pieces` finds a slip onset: bracketed on the grid samples (some
#: reversals may be missed), by Newton between two reversals (all of them known), or
#: on the cubic through the grid samples (all known; where it is accurate enough).
GRID_BRACKET, BETWEEN_REVERSALS, GRID_CUBIC = 0, 1, 2


@njit(cache=True, inline="always")
def _cubic_crossing(x, level, a, b, fa, fb, cursor):  # pragma: no cover - compiled
    """Angle in [a, b] where ``x``, monotone there, passes `level`, on the cubic through the
    grid samples `x` (``2 pi i / n``) around it (``fa``, ``fb``: ``x`` minus `level` at
    the ends).

    The grid points inside [a, b] are searched from the grid point `cursor` on, or by
    bisection when ``cursor < 0``.  Returns the angle and the first grid point past the
    level, where the search for a level further along the branch may start (the
    elements' levels taken in order along the branch cost one pass over the grid).
    """
    if fa == 0.0 or fb == 0.0 or (fa > 0.0) == (fb > 0.0):
        return (a if abs(fa) <= abs(fb) else b), cursor
    n = x.shape[0]
    h = _TWO_PI / n
    inv_h = n / _TWO_PI
    lo, flo, hi, fhi = a * inv_h, fa, b * inv_h, fb  # in grid cells from here
    j_lo = int(np.floor(lo)) + 1
    j_hi = int(np.ceil(hi)) - 1
    if cursor >= 0:  # walk on from the cursor: the grid points before it are on fa's side
        j = max(cursor, j_lo)
        while j <= j_hi:
            f = x[j if j < n else j - n] - level
            if f == 0.0:
                return j * h, j
            if (f > 0.0) != (fa > 0.0):
                hi, fhi = float(j), f
                break
            j += 1
        cursor = j
        if j - 1 >= j_lo:
            lo = float(j - 1)
            flo = x[j - 1 if j - 1 < n else j - 1 - n] - level
    else:
        while j_lo <= j_hi:  # the grid points inside, by bisection: x is monotone
            j = (j_lo + j_hi) // 2
            f = x[j if j < n else j - n] - level  # 0 <= j < 2 n: b < 4 pi
            if f == 0.0:
                return j * h, j
            if (f > 0.0) == (fa > 0.0):
                lo, flo, j_lo = float(j), f, j + 1
            else:
                hi, fhi, j_hi = float(j), f, j - 1
        cursor = j_lo
    c = int(np.floor(0.5 * (lo + hi)))
    x0, c1, c2, c3 = _cubic_coefficients(x, c)
    u = _cubic_root(x0 - level, c1, c2, c3, lo - c, hi - c, flo, fhi, fa < 0.0)
    return (u + c) * h, cursor


@njit(cache=True, inline="always")
def _cubic_coefficients(x, c):  # pragma: no cover - compiled
    """``x_c`` and the coefficients ``c1``, ``c2``, ``c3`` of the cubic in ``u = theta / h -
    c`` through the grid samples ``c - 1 .. c + 2`` of `x` (``0 <= c < 2 n``, cyclically)."""
    n = x.shape[0]
    i0 = c - n if c >= n else c
    im = i0 - 1 if i0 >= 1 else n - 1
    i1 = i0 + 1 if i0 + 1 < n else 0
    i2 = i1 + 1 if i1 + 1 < n else 0
    xm, x0, x1, x2 = x[im], x[i0], x[i1], x[i2]
    c1 = x1 - xm * _THIRD - 0.5 * x0 - x2 * _SIXTH
    c2 = 0.5 * (xm + x1) - x0
    c3 = (x2 - xm) * _SIXTH + 0.5 * (x0 - x1)
    return x0, c1, c2, c3


@njit(cache=True, inline="always")
def _cubic_root(c0, c1, c2, c3, u_lo, u_hi, flo, fhi, rising):  # pragma: no cover - compiled
    """Root ``u`` in [`u_lo`, `u_hi`] of the cubic ``c0 + c1 u + c2 u^2 + c3 u^3`` (`flo`,
    `fhi` its values at the ends, `rising` if it rises there): Newton from the linear
    interpolant, kept in the bracket, until the next step would be below 1e-10 cells (far
    below the cubic's own error; the steps shrink quadratically)."""
    u = u_lo + (u_hi - u_lo) * flo / (flo - fhi)
    last = np.inf
    for _ in range(30):
        f = c0 + u * (c1 + u * (c2 + u * c3))
        fp = c1 + u * (2.0 * c2 + 3.0 * u * c3)
        if (f > 0.0) == rising:
            u_hi = u
        else:
            u_lo = u
        u_new = u - f / fp if fp != 0.0 else 0.5 * (u_lo + u_hi)
        step = abs(u_new - u)
        if not (u_lo <= u_new <= u_hi):
            u_new = 0.5 * (u_lo + u_hi)
            step = np.inf
        elif step <= 1e-13 or (step < 1e-3 * last and step * step * step <= 1e-10 * last * last):
            return u_new
        last = step
        u = u_new
    return u


@njit(cache=True)
def cubic_error_bound(X, n):  # pragma: no cover - compiled
    """Bound on the error of the cubic through `n` grid samples of ``x`` (harmonics `X`)
    between its middle samples: ``(9 / 16) h^4 / 4!`` times the bound on ``|x^(4)|``."""
    h = _TWO_PI / n
    r4 = 0.0
    for m in range(1, X.shape[0]):
        r4 += float(m) ** 4 * (abs(X[m].real) + abs(X[m].imag))
    return 2.0 * r4 * h**4 * 9.0 / (16.0 * 24.0)


@njit(cache=True)
def stop_pieces(X, C1, x, rev, xr, k, fc, mode, half):  # pragma: no cover - compiled
    """Pieces of the periodic output of parallel stop operators, as jumps.

    Over one period each element ``(k_i, fc_i)`` sticks (``w = w_j + k_i (x -
    x_j)``) or slips (``w = +-fc_i``) between the reversal points `rev` (values
    `xr`).  The output is ``w = g + s x`` with ``g`` piecewise constant and
    ``s`` the sum of the stiffnesses of the sticking elements.  Returns the
    angles where ``g`` or ``s`` jump, the jumps of ``g`` and ``s``, and their
    means over the period: each element's slip onsets, then the reversals (every
    element's jump there summed).  The periodic state is found by running the
    elements twice round the reversal points from the global maximum; where
    an element never slips, the symmetric solution (about mid-range) is used.
    `mode` says how a slip onset is found (:data:`GRID_BRACKET`,
    :data:`BETWEEN_REVERSALS`, :data:`GRID_CUBIC`; `x` holds the grid samples
    ``2 pi i / n`` of ``x`` the first and the last use).

    With `half` (two reversals and ``x(theta + pi) = -x(theta)``: no even harmonics) only
    the first half period is run, from the maximum to the minimum: the second mirrors it
    (``g(theta + pi) = -g(theta)``, ``s(theta + pi) = s(theta)``), so its jumps are
    those of the first half, the means ``g_mean = 0`` and ``s_mean`` twice the half's.
    """
    nr = rev.shape[0]
    m = k.shape[0]
    i0 = 0
    x_min = xr[0] if nr else 0.0
    for i in range(nr):
        if xr[i] > xr[i0]:
            i0 = i
        x_min = min(x_min, xr[i])
    th = np.empty(nr + 1)
    xs = np.empty(nr + 1)
    for i in range(nr):
        j = (i0 + i) % nr
        th[i] = rev[j] if rev[j] >= rev[i0] else rev[j] + _TWO_PI
        xs[i] = xr[j]
    th[nr] = th[0] + _TWO_PI
    xs[nr] = xs[0]
    mid = 0.5 * (xr[i0] + x_min)
    n_run = nr
    if half:  # the minimum half a period after the maximum, at minus its value
        th[1] = th[0] + np.pi
        xs[1] = -xs[0]
        mid = 0.0
        n_run = 1
    t_b = np.empty(nr * m + nr)  # at most a slip onset per element and interval
    jg = np.empty(nr * m + nr)
    js = np.empty(nr * m + nr)
    at_g = np.zeros(nr)  # jumps at the reversals, summed over the elements
    at_s = np.zeros(nr)
    nb = 0
    g_mean = 0.0
    s_mean = 0.0
    ws = np.empty(nr + 1)
    # GRID_CUBIC: each interval's search for an onset starts where the last one ended while
    # the levels come in order along it (elements sorted by fc / k), else bisects
    cursors = np.full(nr, -1, dtype=np.int64)
    last_level = np.empty(nr)
    first_g = np.empty(nr)  # the element's first and last piece in each interval
    first_s = np.empty(nr)
    last_g = np.empty(nr)
    last_s = np.empty(nr)
    for e in range(m):
        ke, fe = k[e], fc[e]
        w = min(max(ke * (xs[0] - mid), -fe), fe)
        for _ in range(2):  # the second pass starts from the periodic state
            ws[0] = w
            for i in range(nr):
                w = min(max(w + ke * (xs[i + 1] - xs[i]), -fe), fe)
                ws[i + 1] = w
        for i in range(n_run):
            a, b = th[i], th[i + 1]
            wi, xi, x_end = ws[i], xs[i], xs[i + 1]
            d = 1.0 if x_end > xi else -1.0
            slip_level = xi + (d * fe - wi) / ke  # x where the spring reaches +-fc
            s = b
            if d * (x_end - slip_level) > 0.0:
                fa = xi - slip_level
                fb = x_end - slip_level
                if mode == BETWEEN_REVERSALS:
                    s = _monotone_crossing(X, C1, slip_level - X[0].real, a, b, fa, fb)
                elif mode == GRID_CUBIC:
                    if cursors[i] >= 0 and d * (slip_level - last_level[i]) < 0.0:
                        cursors[i] = -1  # behind the last level: bisect
                    last_level[i] = slip_level
                    s, cursors[i] = _cubic_crossing(x, slip_level - X[0].real, a, b, fa, fb,
                                                    cursors[i])
                else:
                    s = min(max(_crossing(X, C1, x, slip_level, a, b), a), b)
            # pieces of non-zero length: stick (g = w_i - k x_i, s = k) on [a, s),
            # slip (g = +-fc, s = 0) on [s, b)
            g_stick = wi - ke * xi
            if s > a:
                first_g[i], first_s[i] = g_stick, ke
                g_mean += g_stick * (s - a)
                s_mean += ke * (s - a)
            else:
                first_g[i], first_s[i] = d * fe, 0.0
            if b > s:
                last_g[i], last_s[i] = d * fe, 0.0
                g_mean += d * fe * (b - s)
            else:
                last_g[i], last_s[i] = g_stick, ke
            if a < s < b:
                t_b[nb], jg[nb], js[nb] = s, d * fe - g_stick, -ke
                nb += 1
        if half:  # the second half's last piece mirrors the first's
            at_g[0] += first_g[0] + last_g[0]
            at_s[0] += first_s[0] - last_s[0]
        else:
            for i in range(nr):
                at_g[i] += first_g[i] - last_g[i - 1]  # i - 1 = -1: the last interval
                at_s[i] += first_s[i] - last_s[i - 1]
    for i in range(n_run):
        t_b[nb], jg[nb], js[nb] = th[i], at_g[i], at_s[i]
        nb += 1
    if half:
        return t_b[:nb], jg[:nb], js[:nb], 0.0, 2.0 * s_mean / _TWO_PI
    return t_b[:nb], jg[:nb], js[:nb], g_mean / _TWO_PI, s_mean / _TWO_PI


@njit(cache=True, error_model="numpy")
def half_cubic_pieces(x, a, x_top, k, fc):  # pragma: no cover - compiled
    """:func:`stop_pieces` with `half` and :data:`GRID_CUBIC`, for elements sorted by ``fc /
    k``: the same pieces (the same arithmetic), from the maximum `x_top` at angle `a` down
    to ``-x_top`` half a period on.

    In passes over the elements: their slip levels; their cells along the branch, in one
    walk over the grid samples `x` (the levels come in order; the first by bisection);
    the first Newton step on each cell's cubic (:func:`_cubic_crossing`) for all elements
    side by side, the further steps where it does not end; the pieces.  (Division by
    zero gives inf here rather than an error, so that the passes run on vectors; the
    results of such divisions are not used.)
    """
    m = k.shape[0]
    n = x.shape[0]
    h = _TWO_PI / n
    inv_h = n / _TWO_PI
    b = a + np.pi
    x_end = -x_top
    lo0 = a * inv_h
    hi0 = b * inv_h
    j_lo = int(np.floor(lo0)) + 1
    j_hi = int(np.ceil(hi0)) - 1
    level, wis = _half_levels(x_top, k, fc)
    # pass 2: each slipping element's cell along the branch (one walk), or its angle
    s_of = np.empty(m)
    c_of = np.empty(m, dtype=np.int64)  # -1: s known
    lo_of = np.zeros(m)  # the bracket in cells from c, the cubic's values at its ends
    hi_of = np.ones(m)
    flo_of = np.ones(m)
    fhi_of = -np.ones(m)
    cursor = -1
    last_level = 0.0
    for e in range(m):
        slip_level = level[e]
        c_of[e] = -1
        s_of[e] = b
        if not (-(x_end - slip_level) > 0.0):
            continue
        fa = x_top - slip_level
        fb = x_end - slip_level
        if cursor >= 0 and -(slip_level - last_level) < 0.0:
            cursor = -1
        last_level = slip_level
        if fa == 0.0 or fb == 0.0 or (fa > 0.0) == (fb > 0.0):
            s_of[e] = a if abs(fa) <= abs(fb) else b
            continue
        # the walk of _cubic_crossing (written out: through a shared inline function both ran
        # 20-50 % slower)
        lo, flo, hi, fhi = lo0, fa, hi0, fb
        found = False
        if cursor >= 0:
            j = max(cursor, j_lo)
            while j <= j_hi:
                f = x[j if j < n else j - n] - slip_level
                if f == 0.0:
                    s_of[e] = j * h
                    found = True
                    break
                if (f > 0.0) != (fa > 0.0):
                    hi, fhi = float(j), f
                    break
                j += 1
            cursor = j
            if not found and j - 1 >= j_lo:
                lo = float(j - 1)
                flo = x[j - 1 if j - 1 < n else j - 1 - n] - slip_level
        else:
            jl, jh = j_lo, j_hi
            while jl <= jh:
                j = (jl + jh) // 2
                f = x[j if j < n else j - n] - slip_level
                if f == 0.0:
                    s_of[e] = j * h
                    found = True
                    jl = j
                    break
                if (f > 0.0) == (fa > 0.0):
                    lo, flo, jl = float(j), f, j + 1
                else:
                    hi, fhi, jh = float(j), f, j - 1
            cursor = jl
        if not found:
            c = int(np.floor(0.5 * (lo + hi)))
            c_of[e] = c
            lo_of[e] = lo - c
            hi_of[e] = hi - c
            flo_of[e] = flo
            fhi_of[e] = fhi
    # pass 3: Newton on each cell's cubic, the first step for all elements side by side
    u_first = np.empty(m)
    accepted = np.empty(m, dtype=np.bool_)
    for e in range(m):
        x0, c1, c2, c3 = _cubic_coefficients(x, max(c_of[e], 0))
        c0 = x0 - level[e]
        u_lo = lo_of[e]
        u_hi = hi_of[e]
        flo = flo_of[e]
        u = u_lo + (u_hi - u_lo) * flo / (flo - fhi_of[e])
        f = c0 + u * (c1 + u * (c2 + u * c3))
        fp = c1 + u * (2.0 * c2 + 3.0 * u * c3)
        rising_side = f > 0.0  # the cubic falls: f > 0 before the root
        lo1 = u if rising_side else u_lo
        hi1 = u_hi if rising_side else u
        u_new = u - f / fp
        u_first[e] = u_new
        accepted[e] = (fp != 0.0) & (lo1 <= u_new) & (u_new <= hi1)
    for e in range(m):
        c = c_of[e]
        if c < 0:
            continue
        if accepted[e]:
            s = u_first[e] + c
        else:
            x0, c1, c2, c3 = _cubic_coefficients(x, c)
            s = _cubic_root(x0 - level[e], c1, c2, c3, lo_of[e], hi_of[e], flo_of[e],
                            fhi_of[e], False) + c
        s_of[e] = s * h
    return _half_pieces(s_of, a, x_top, wis, k, fc)


@njit(cache=True, error_model="numpy")
def _half_levels(x_top, k, fc):  # pragma: no cover - compiled
    """The first pass of :func:`half_cubic_pieces`: each element's periodic state at the
    maximum `x_top` of a half-wave symmetric input and the level of ``x`` at which it
    slips on the way down."""
    m = k.shape[0]
    down = -2.0 * x_top
    up = 2.0 * x_top
    level = np.empty(m)
    wis = np.empty(m)
    for e in range(m):
        ke = k[e]
        fe = fc[e]
        w = min(max(ke * x_top, -fe), fe)
        w = min(max(w + ke * down, -fe), fe)
        wi = min(max(w + ke * up, -fe), fe)
        wis[e] = wi
        level[e] = x_top + (-fe - wi) / ke
    return level, wis


@njit(cache=True)
def _half_pieces(s_of, a, x_top, wis, k, fc):  # pragma: no cover - compiled
    """The last pass of :func:`half_cubic_pieces`: the jumps of the pieces from the slip
    onsets `s_of` (``a + pi`` for an element that does not slip) and the states `wis`."""
    m = k.shape[0]
    b = a + np.pi
    t_b = np.empty(m + 1)
    jg = np.empty(m + 1)
    js = np.empty(m + 1)
    nb = 0
    s_mean = 0.0
    at_g = 0.0
    at_s = 0.0
    for e in range(m):
        ke = k[e]
        fe = fc[e]
        s = s_of[e]
        g_stick = wis[e] - ke * x_top
        if s > a:
            first_g, first_s = g_stick, ke
            s_mean += ke * (s - a)
        else:
            first_g, first_s = -fe, 0.0
        if b > s:
            last_g, last_s = -fe, 0.0
        else:
            last_g, last_s = g_stick, ke
        if a < s < b:
            t_b[nb], jg[nb], js[nb] = s, -fe - g_stick, -ke
            nb += 1
        at_g += first_g + last_g
        at_s += first_s - last_s
    t_b[nb], jg[nb], js[nb] = a, at_g, at_s
    nb += 1
    return t_b[:nb], jg[:nb], js[:nb], 0.0, 2.0 * s_mean / _TWO_PI


@njit(cache=True)
def half_sine_pieces(a, x_top, k, fc):  # pragma: no cover - compiled
    """:func:`half_cubic_pieces` of a sine, ``x = x_top cos(theta - a)``: each slip onset in
    closed form, ``a + arccos(level / x_top)``, rather than on the grid's cubic."""
    level, wis = _half_levels(x_top, k, fc)
    m = k.shape[0]
    b = a + np.pi
    s_of = np.empty(m)
    for e in range(m):
        slip_level = level[e]
        if not slip_level > -x_top:
            s_of[e] = b  # never slips
        elif slip_level >= x_top:
            s_of[e] = a
        else:
            s_of[e] = a + np.arccos(slip_level / x_top)
    return _half_pieces(s_of, a, x_top, wis, k, fc)


@njit(cache=True)
def first_harmonic_dominates(X):  # pragma: no cover - compiled
    """Whether the bounds of :func:`dominant_reversals` hold for `X` (two reversals a period,
    one near each zero of the first harmonic's derivative), with ``a_1`` and ``R_1``."""
    M = X.shape[0] - 1
    a1 = 2.0 * abs(X[1]) if M >= 1 else 0.0
    r1 = 0.0
    r2 = 0.0
    for m in range(2, M + 1):
        r1 += m * abs(X[m])
        r2 += m * m * abs(X[m])
    r1 *= 2.0
    r2 *= 2.0
    return a1 > 0.0 and r1 < 0.25 * a1 and r2 < 0.8 * a1, a1, r1


@njit(cache=True)
def dominant_reversals(X, C1, C2, half):  # pragma: no cover - compiled
    """The reversal points of ``x`` when its first harmonic dominates, else none.

    With ``x_1' = -a_1 sin(theta + alpha)`` the first harmonic's derivative and the
    others' bounded by ``R_1 = 2 sum_{m >= 2} m |X_m|`` (``x''``'s by ``R_2``), ``x'``
    has no root where ``|x_1'| > R_1``, and where ``|x_1'| <= 2 R_1 < a_1 / 2`` around
    each zero of ``x_1'`` its derivative has one sign (``R_2 < 0.8 a_1``): one root
    each, two a period, each bracketed without a grid.  Returns ``(ok, rev, xr)`` as
    :func:`reversal_points`; ``ok`` is False where the bounds do not hold (the roots
    are then bracketed on a grid).  With `half` (no even harmonics: ``x(theta + pi) - X_0
    = -(x(theta) - X_0)``) the second reversal is the first's, half a period on.
    """
    rev = np.empty(2)
    xr = np.empty(2)
    ok, a1, r1 = first_harmonic_dominates(X)
    if not ok:
        return False, rev, xr
    delta = np.arcsin(2.0 * r1 / a1) + 1e-6
    alpha = np.arctan2(X[1].imag, X[1].real)
    for i in range(1 if half else 2):
        t0 = (i * np.pi - alpha) % _TWO_PI
        lo = t0 - delta
        hi = t0 + delta
        flo = trig2(C1, C2, lo)[0]
        fhi = trig2(C1, C2, hi)[0]
        if not (flo != 0.0 and fhi != 0.0 and (flo > 0.0) != (fhi > 0.0)):
            return False, rev, xr
        rev[i] = bracketed_root(C1, C2, 0.0, lo, hi, fhi > flo, 0.5 * (lo + hi),
                                True) % _TWO_PI
    xr[0] = X[0].real + trig2(X, C1, rev[0])[0]
    if half:  # x(theta + pi) - X_0 = -(x(theta) - X_0)
        rev[1] = (rev[0] + np.pi) % _TWO_PI
        xr[1] = 2.0 * X[0].real - xr[0]
    else:
        xr[1] = X[0].real + trig2(X, C1, rev[1])[0]
    if rev[1] < rev[0]:
        rev[0], rev[1] = rev[1], rev[0]
        xr[0], xr[1] = xr[1], xr[0]
    return True, rev, xr
