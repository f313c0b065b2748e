"""Compiled kernels and periodic-input helpers of the smooth hysteresis models.

Shared by :mod:`~motionhyst.hysteresis.dahl` and :mod:`~motionhyst.hysteresis.bouc_wen`,
and the periodic-input helpers also by :mod:`~motionhyst.hysteresis.lugre` (whose own
kernels are in :mod:`~motionhyst.hysteresis._lugre_kernels`).

Rate-independent models (Dahl, Bouc-Wen) are integrated in the displacement:
on a monotone piece the state follows an autonomous scalar ODE in the
normalised displacement ``v = (k / fc) |dx|``, solved in closed form (Dahl,
Bouc-Wen with ``n = 1``) or by RK4 sub-steps (Bouc-Wen, other ``n``).  A
periodic input is sampled on a uniform grid of the period with its reversal
points (found by root finding on the trigonometric polynomial) inserted, so
no excursion between samples is missed; the periodic state is the fixed
point of the scalar period map.
"""

from __future__ import annotations

import math

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._kernels import reversal_roots, trig2, trig_root

TWO_PI = 2.0 * np.pi
MIN_SAMPLES = 4096
MAX_SAMPLES = 2**22

# ---------------------------------------------------------------------------
# Dahl: dzeta/dv = (1 - zeta)^alpha on a monotone piece (zeta = sign(dx) w / fc)
# ---------------------------------------------------------------------------


@njit(cache=True)
def dahl_advance(zeta, v, alpha):  # pragma: no cover - compiled
    """Exact solution of ``dzeta/dv = (1 - zeta)^alpha`` after a distance ``v >= 0``.

    ``1 - zeta`` shrinks by the factor ``exp(-v)`` (``alpha = 1``) or
    ``(1 + (alpha - 1) v (1 - zeta)^(alpha - 1))^(-1 / (alpha - 1))``; the step is
    formed as ``zeta - (1 - zeta) expm1(...)`` so that it keeps its relative
    accuracy for tiny ``v`` (nanometre motions).
    """
    y = 1.0 - zeta
    if y <= 0.0 or v == 0.0:
        return zeta
    eps = alpha - 1.0
    if eps == 0.0:
        return zeta - y * math.expm1(-v)
    arg = eps * v * y**eps
    if arg <= -1.0:
        return 1.0  # alpha < 1: saturates at a finite distance
    return zeta - y * math.expm1(-math.log1p(arg) / eps)


@njit(cache=True)
def dahl_path(u, s0, alpha):  # pragma: no cover - compiled
    """Normalised Dahl force ``w / fc`` along the normalised path ``u = (k / fc) x``."""
    n = u.shape[0]
    out = np.empty(n)
    if n == 0:
        return out
    s = s0
    out[0] = s
    for i in range(1, n):
        du = u[i] - u[i - 1]
        if du > 0.0:
            s = dahl_advance(s, du, alpha)
        elif du < 0.0:
            s = -dahl_advance(-s, -du, alpha)
        out[i] = s
    return out


# ---------------------------------------------------------------------------
# Bouc-Wen: dzeta/dv = 1 - (beta sign(zeta) + gamma) |zeta|^n  (zeta = sign(dx) z)
# ---------------------------------------------------------------------------

# Gauss-Legendre nodes and weights on [0, 1] for the crossing integrals
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
GL_T = 0.5 * (_GL_X + 1.0)
GL_W = 0.5 * _GL_W


@njit(cache=True)
def _bw_pow(a, n):  # pragma: no cover - compiled
    """``a^n`` for ``a >= 0``, without a call to pow for n = 1, 2."""
    return a if n == 1.0 else (a * a if n == 2.0 else a**n)


@njit(cache=True)
def _bw_rhs(zeta, n, ap, am):  # pragma: no cover - compiled
    p = _bw_pow(abs(zeta), n)
    if zeta >= 0.0:
        return 1.0 - ap * p
    return 1.0 + am * p


@njit(cache=True)
def _bw_quad(za, zb, n, ap, am, t, wq):  # pragma: no cover - compiled
    """``int_za^zb dzeta / f(zeta)`` by Gauss-Legendre, for ``za, zb`` on one side of 0."""
    s = 0.0
    for i in range(t.shape[0]):
        s += wq[i] / _bw_rhs(za + (zb - za) * t[i], n, ap, am)
    return s * (zb - za)


@njit(cache=True)
def _bw_invert(za, h, n, ap, am, t, wq):  # pragma: no cover - compiled
    """State after a short distance ``h`` from ``za`` on the side of ``za`` (Newton)."""
    side = -1.0 if za < 0.0 else 1.0
    zb = za + h * _bw_rhs(za, n, ap, am)
    if side * zb < 0.0:
        zb = 0.0
    for _ in range(30):
        g = _bw_quad(za, zb, n, ap, am, t, wq) - h
        step = g * _bw_rhs(zb, n, ap, am)
        zb -= step
        if side * zb < 0.0:
            zb = 0.0
        if abs(step) <= 1e-16 * max(abs(zb), 1e-300):
            break
    return zb


@njit(cache=True)
def _bw_exact(zeta, v, n, ap, am):  # pragma: no cover - compiled
    """Exact state of the normalised ODE after a distance ``v > 0``, for ``n = 1`` or 2."""
    if n == 2.0:
        if zeta < 0.0:  # dzeta/dv = 1 + am zeta^2 up to zeta = 0
            if am > 0.0:
                sq = math.sqrt(am)
                vstar = math.atan(-sq * zeta) / sq
                if v < vstar:
                    tv = math.tan(sq * v)
                    return zeta + (tv / sq) * (1.0 + am * zeta * zeta) / (1.0 - sq * zeta * tv)
            else:
                vstar = -zeta
                if v < vstar:
                    return zeta + v
            v -= vstar
            zeta = 0.0
        if ap == 0.0:
            return zeta + v
        c = math.sqrt(ap)  # dzeta/dv = 1 - ap zeta^2 (ap > 0 for n = 2)
        tv = math.tanh(c * v)
        return zeta + (tv / c) * ((1.0 - c * zeta) * (1.0 + c * zeta)) / (1.0 + c * zeta * tv)
    # n = 1
    if zeta < 0.0:
        if am > 0.0:
            vstar = math.log1p(-am * zeta) / am
            if v < vstar:
                return zeta * math.exp(-am * v) - math.expm1(-am * v) / am
        else:
            vstar = -zeta
            if v < vstar:
                return zeta + v
        v -= vstar
        zeta = 0.0
    if ap == 0.0:
        return zeta + v
    return zeta * math.exp(-ap * v) - math.expm1(-ap * v) / ap


@njit(cache=True)
def bouc_wen_advance(zeta, v, n, ap, am, hmax, t, wq):  # pragma: no cover - compiled
    """Solution of the normalised Bouc-Wen ODE after a distance ``v >= 0``.

    ``ap = beta + gamma`` applies for ``zeta > 0`` (loading), ``am = beta - gamma``
    for ``zeta < 0`` (unloading).  Exact for ``n = 1`` (piecewise exponentials)
    and ``n = 2`` (``tan`` while ``zeta < 0``, ``tanh`` after, each as an addition
    formula that keeps the increment's relative accuracy for small `v`); RK4
    sub-steps of at most `hmax` otherwise, with the crossing of ``zeta = 0``
    (where the right-hand side has a kink) located by quadrature.
    """
    if v <= 0.0:
        return zeta
    if n == 1.0 or n == 2.0:
        return _bw_exact(zeta, v, n, ap, am)
    smooth = n == math.floor(n)  # |zeta|^n is then smooth on each side of 0
    near0 = 0.0 if smooth else 0.1  # otherwise step by quadrature while |zeta| < near0
    while v > 0.0:
        h = min(v, hmax)
        if zeta < 0.0:
            f = _bw_rhs(zeta, n, ap, am)
            if -zeta <= h * f:  # may reach zeta = 0 within this sub-step
                vstar = _bw_quad(zeta, 0.0, n, ap, am, t, wq)
                if vstar <= h:
                    zeta = 0.0
                    v -= vstar
                else:
                    zeta = min(_bw_invert(zeta, h, n, ap, am, t, wq), 0.0)
                    v -= h
                continue
            if -zeta < near0:
                zeta = min(_bw_invert(zeta, h, n, ap, am, t, wq), 0.0)
                v -= h
                continue
        else:
            if abs(1.0 - ap * zeta**n) <= 1e-14:
                break  # saturated: zeta is within ~1e-14 / n of its limit and stays
            if zeta < near0:
                zeta = _bw_invert(zeta, h, n, ap, am, t, wq)
                v -= h
                continue
        k1 = _bw_rhs(zeta, n, ap, am)
        k2 = _bw_rhs(zeta + 0.5 * h * k1, n, ap, am)
        k3 = _bw_rhs(zeta + 0.5 * h * k2, n, ap, am)
        k4 = _bw_rhs(zeta + h * k3, n, ap, am)
        z_new = zeta + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if z_new == zeta and zeta > 0.0:
            break  # at its limit to round-off: no later sub-step changes the state
        zeta = z_new
        v -= h
    return zeta


@njit(cache=True)
def bouc_wen_step(z, du, n, ap, am, hmax, t, wq):  # pragma: no cover - compiled
    """Normalised Bouc-Wen state after a normalised displacement increment `du` of either sign.

    The time-stepping kernel of the element (used by :func:`bouc_wen_path` and
    by the time simulations): with ``z = w / fc`` the normalised force,
    ``du = (k / fc) dx`` the increment of the normalised displacement over a
    step in which ``x`` is monotone, ``n``, ``ap = beta + gamma`` and
    ``am = beta - gamma`` from the normalised parameters (for the benchmark's
    general form ``k = alpha``, ``fc = (alpha / beta)^(1/nu)``, ``n = nu``,
    ``ap = gamma + delta``, ``am = gamma - delta``; see
    :class:`~motionhyst.hysteresis.BoucWen`), `hmax` the RK4 sub-step
    (``BoucWen._step()``, unused for ``n = 1``) and ``t, wq`` the
    Gauss-Legendre rule :data:`GL_T`, :data:`GL_W`.  Exact for ``n = 1``
    (``ap`` of any sign) and ``n = 2``, RK4 to about 1e-10 otherwise.  The derivative of
    the new state with respect to `du` is the right-hand side at the new state,
    ``1 - (beta sign(du z) + gamma) |z|^n``.
    """
    if du > 0.0:
        return bouc_wen_advance(z, du, n, ap, am, hmax, t, wq)
    if du < 0.0:
        return -bouc_wen_advance(-z, -du, n, ap, am, hmax, t, wq)
    return z


@njit(cache=True)
def _bw_crossing(z, sg, xa, xb, tha, thb, X, C1, C2, kf, n, am):  # pragma: no cover - compiled
    """Angle, ``x'`` and ``x''`` where the state crosses 0 in a step from ``(tha, xa)`` to
    ``(thb, xb)`` (``n`` = 1 or 2, direction `sg`, state `z` at its start)."""
    zeta = -sg * z  # distance in u to zeta = 0
    if am <= 0.0:
        vstar = zeta
    elif n == 1.0:
        vstar = math.log1p(am * zeta) / am
    else:
        sq = math.sqrt(am)
        vstar = math.atan(sq * zeta) / sq
    level = xa + sg * vstar / kf
    th = trig_root(X, C1, level - X[0].real, tha, thb, xa - level, xb - level)
    d1, d2 = trig2(C1, C2, th)
    return th, d1, d2


@njit(cache=True)
def _bw_period(s0, X, C1, C2, C3, x, cells, roots, xr, kf, n, ap, am, hmax, t, wq, out,
               dout, jt, jv, jo):  # pragma: no cover - compiled
    """One period of the normalised state from `s0` at ``x[0]``, written to `out` at the grid
    (and its derivative with respect to `s0` to `dout`).

    The path visits the grid samples `x` in order with the reversals (angles
    `roots`, values `xr`) inserted after the samples ``cells`` and ends at
    ``x[0]``.  Returns the final state, its derivative with respect to `s0`
    (for an autonomous scalar ODE a monotone step maps ``z`` to ``z'`` with
    slope ``f(z') / f(z)``, so the period's slope is the product over its
    steps) and the number of jumps recorded in `jt` (angle), `jv` (size) and
    `jo` (order ``p`` of the derivative ``z^(p) = d^p z / d theta^p`` that jumps).
    With ``z' = kf x' g(z, s)``, ``g = 1 - (beta sign(s z) + gamma) |z|^n`` (``s``
    the direction of motion; ``beta``, ``gamma`` the normalised parameters):

    * at a reversal ``g`` jumps by ``Dg = -2 beta sign(x'' z) |z|^n``, so ``z^(2)``
      by ``kf x^(2) Dg`` and ``z^(3)`` by ``kf x^(3) Dg``;
    * where ``z`` crosses 0, for ``n = 1`` ``g_z`` jumps by ``-2 gamma s`` and
      ``g_z^2`` by ``ap^2 - am^2``: ``z^(2)`` by ``-2 gamma s kf^2 x'^2`` and ``z^(3)``
      by ``3 kf^2 x' x'' (-2 gamma s) + kf^3 x'^3 (ap^2 - am^2)``; for ``n = 2``
      ``g_zz`` jumps by ``-4 beta``: ``z^(3)`` by ``-4 beta kf^3 x'^3``.
    """
    m = x.shape[0]
    h = 2.0 * np.pi / m
    exact = n == 1.0 or n == 2.0
    z = s0
    slope = 1.0
    q = 0
    nq = cells.shape[0]
    nj = 0
    xp = x[0]
    thp = 0.0
    i = 0  # the next grid sample to record is i; the step ends at a reversal or at i + 1
    out[0] = z
    dout[0] = 1.0
    while i < m:
        rev = q < nq and cells[q] == i
        if rev:
            xn = xr[q]
            thn = roots[q]
        else:
            xn = x[i + 1] if i + 1 < m else x[0]
            thn = (i + 1) * h
        du = kf * (xn - xp)
        if du != 0.0:
            sg = 1.0 if du > 0.0 else -1.0
            if exact:
                zn = sg * _bw_exact(sg * z, sg * du, n, ap, am)
            else:
                zn = bouc_wen_step(z, du, n, ap, am, hmax, t, wq)
            fa = _bw_rhs(sg * z, n, ap, am)
            slope = slope * (_bw_rhs(sg * zn, n, ap, am) / fa) if fa > 0.0 else 0.0
            if exact and sg * z < 0.0 < sg * zn:
                th, d1, d2 = _bw_crossing(z, sg, xp, xn, thp, thn, X, C1, C2, kf, n, am)
                if n == 1.0:
                    dgz = -(ap - am) * sg  # -2 gamma s
                    jt[nj] = th
                    jv[nj] = dgz * kf * kf * d1 * d1
                    jo[nj] = 2
                    jt[nj + 1] = th
                    jv[nj + 1] = (3.0 * kf * kf * d1 * d2 * dgz
                                  + kf**3 * d1**3 * (ap * ap - am * am))
                    jo[nj + 1] = 3
                    nj += 2
                else:
                    jt[nj] = th
                    jv[nj] = -2.0 * (ap + am) * kf**3 * d1**3  # -4 beta kf^3 x'^3
                    jo[nj] = 3
                    nj += 1
            z = zn
        xp = xn
        thp = thn
        if rev:
            d2, d3 = trig2(C2, C3, thn)
            sz = 1.0 if z > 0.0 else (-1.0 if z < 0.0 else 0.0)
            s2 = 1.0 if d2 > 0.0 else -1.0
            dg = -(ap + am) * s2 * sz * _bw_pow(abs(z), n)  # -2 beta sign(x'' z) |z|^n
            jt[nj] = thn
            jv[nj] = kf * d2 * dg
            jo[nj] = 2
            jt[nj + 1] = thn
            jv[nj + 1] = kf * d3 * dg
            jo[nj + 1] = 3
            nj += 2
            q += 1
        else:
            i += 1
            if i < m:
                out[i] = z
                dout[i] = slope
    return z, slope, nj


@njit(cache=True)
def bouc_wen_periodic(X, C1, C2, C3, x, d, kf, n, ap, am, hmax, lo, hi, t,
                      wq):  # pragma: no cover - compiled
    """Normalised periodic Bouc-Wen state on the grid ``theta_i = 2 pi i / N``, compiled end to end.

    `X`, ``C1 = j m X``, ``C2 = -m^2 X``, ``C3 = -j m^3 X`` are the harmonics of ``x``
    and its first three derivatives, `x` and `d` its samples and those of ``x'`` on the
    grid, ``kf = k / fc``.  The reversals of ``x`` are found on the
    trigonometric polynomial (:func:`~motionhyst.hysteresis._kernels.reversal_roots`)
    and inserted in the path; the state that repeats after one period is the
    root of ``g(s) = P(s) - s`` for the period map ``P``, found by Newton steps
    with the exact slope ``P'`` (:func:`_bw_period`) kept inside the bracket
    ``[lo, hi]`` (bisection otherwise).  A pass is accepted when ``g`` is below
    1e-14 of the state's range, or when the Newton correction ``delta`` moves
    no sample by more than 1e-8 of it: the samples are then corrected to first
    order, ``z_i + delta dz_i/ds`` (the neglected second order is ~1e-16), which
    saves the pass that would only confirm them.

    Returns
    -------
    z : ndarray, shape (N,)
        The state ``w / fc`` at the grid samples.
    jt, jv, jo : ndarray
        Angles, sizes and orders ``p`` of the jumps of ``d^p z / d theta^p``
        over the period (:func:`_bw_period`).
    ok : bool
        False if the fixed point was not found to 1e-10 of the range.
    """
    m = x.shape[0]
    cells, roots = reversal_roots(C1, C2, d)
    h = 2.0 * np.pi / m
    nq = cells.shape[0]
    xr = np.empty(nq)
    for q in range(nq):
        roots[q] = min(max(roots[q], cells[q] * h), (cells[q] + 1) * h)
        xr[q] = X[0].real + trig2(X, C1, roots[q])[0]
    out = np.empty(m)
    dout = np.empty(m)
    jt = np.empty(4 * nq + 4)
    jv = np.empty(4 * nq + 4)
    jo = np.empty(4 * nq + 4, dtype=np.int64)
    s = 0.0
    best = np.inf
    for _ in range(60):
        zend, slope, nj = _bw_period(s, X, C1, C2, C3, x, cells, roots, xr, kf, n, ap, am,
                                     hmax, t, wq, out, dout, jt, jv, jo)
        g = zend - s
        lo_out = hi_out = out[0]
        dmax = 1.0
        for i in range(m):
            lo_out = min(lo_out, out[i])
            hi_out = max(hi_out, out[i])
            dmax = max(dmax, abs(dout[i]))
        scale = max(hi_out - lo_out, 1e-300)
        if abs(g) <= 1e-14 * scale or g == 0.0:
            return out, jt[:nj], jv[:nj], jo[:nj], True
        if slope < 1.0:
            delta = g / (1.0 - slope)
            if abs(delta) * dmax <= 1e-8 * scale:
                for i in range(m):
                    out[i] += delta * dout[i]
                return out, jt[:nj], jv[:nj], jo[:nj], True
        best = min(best, abs(g) / scale)
        if g > 0.0:
            lo = max(lo, s)
        else:
            hi = min(hi, s)
        s_new = s - g / (slope - 1.0) if slope != 1.0 else 0.5 * (lo + hi)
        if not lo <= s_new <= hi:
            s_new = 0.5 * (lo + hi)
        if s_new == s:
            return out, jt[:nj], jv[:nj], jo[:nj], True
        s = s_new
    return out, jt[:nj], jv[:nj], jo[:nj], best <= 1e-10


#: aliases summed on each side in :func:`alias_of_jumps` (the rest: below 1e-5 of the correction)
ALIAS_TERMS = 256
#: most terms of the expansion in ``m / N`` (``<= 1/2``) in :func:`alias_of_jumps`; fewer
#: are used where ``H / N`` is small enough for the rest to fall below 1e-9 of the first
ALIAS_ORDERS = 40


@njit(cache=True)
def alias_of_jumps(jt, jv, jo, N, H):  # pragma: no cover - compiled
    """Aliasing error of the sampled FFT (``rfft / N``) from jumps of a function's derivatives.

    A jump ``J`` of the ``p``-th derivative at ``theta_j`` (`jt`, `jv`, `jo`)
    gives the function the Fourier coefficients ``c_k ~ J exp(-j k theta_j) /
    (2 pi (j k)^q)``, ``q = p + 1``; the FFT of ``N`` samples returns
    ``sum_l c_{m + l N}``, so its error at harmonic ``m`` is the sum over ``l != 0``,
    returned for ``m = 0 .. H`` (``O(N^-q)`` off the grid).  With
    ``(m + l N)^-q = (l N)^-q sum_s binom(-q, s) (m / (l N))^s`` (``|m / N| <= 1/2``)
    it is ``N^-q sum_s binom(-q, s) (m / N)^s T_{q+s}`` with the lattice sums
    ``T_n = sum_{l != 0} exp(-j l N theta_j) l^-n``, computed once per jump
    (:data:`ALIAS_TERMS` values of ``l`` each side, :data:`ALIAS_ORDERS` values of ``s``).
    The sum is taken directly here rather than by subtracting the jumps'
    Bernoulli polynomials from the samples, which would lose the precision of
    ``w`` to their size (``~ (k A / fc)^3`` at sharp crossings).
    """
    E = np.zeros(H + 1, dtype=np.complex128)
    B = np.zeros(ALIAS_ORDERS, dtype=np.complex128)  # the polynomial in m / N at one angle
    Tc = np.empty(ALIAS_ORDERS)
    Ts = np.empty(ALIAS_ORDERS)
    rmax = min(H / N, 0.5)
    nj = jt.shape[0]
    top = 0  # orders in B
    for j in range(nj):
        q = jo[j] + 1
        orders = 1
        bound = 1.0  # |binom(-q, s)| rmax^s
        while orders < ALIAS_ORDERS and bound > 1e-9:
            bound *= (q + orders - 1) / orders * rmax
            orders += 1
        phi = (N * jt[j]) % (2.0 * np.pi)
        Tc[:orders] = 0.0
        Ts[:orders] = 0.0
        for li in range(1, ALIAS_TERMS + 1):
            c = math.cos(li * phi)
            sn = math.sin(li * phi)
            w = 1.0 / float(li) ** q
            inv = 1.0 / li
            for s in range(orders):
                Tc[s] += c * w
                Ts[s] += sn * w
                w *= inv
        amp = jv[j] / (2.0 * np.pi) / (1j) ** q / float(N) ** q
        coef = 1.0  # binom(-q, s)
        for s in range(orders):
            B[s] += amp * coef * (2.0 * Tc[s] if (q + s) % 2 == 0 else -2.0j * Ts[s])
            coef *= -(q + s) / (s + 1.0)
        top = max(top, orders)
        if j + 1 < nj and jt[j + 1] == jt[j]:
            continue  # jumps of several derivatives at one angle share the sum over m
        turn = complex(math.cos(jt[j]), -math.sin(jt[j]))  # exp(-j theta_j)
        base = 1.0 + 0j
        for mm in range(H + 1):
            if mm % 64 == 0:  # exp(-j m theta_j), recomputed now and then against drift
                base = complex(math.cos(mm * jt[j]), -math.sin(mm * jt[j]))
            ratio = mm / N
            acc = B[top - 1]
            for s in range(top - 2, -1, -1):
                acc = acc * ratio + B[s]
            E[mm] += base * acc
            base *= turn
        B[:top] = 0.0
        top = 0
    return E


@njit(cache=True)
def bouc_wen_path(u, z0, n, ap, am, hmax, t, wq):  # pragma: no cover - compiled
    """Normalised Bouc-Wen state ``z = w / fc`` along the normalised path ``u = (k / fc) x``."""
    m = u.shape[0]
    out = np.empty(m)
    if m == 0:
        return out
    z = z0
    out[0] = z
    for i in range(1, m):
        z = bouc_wen_step(z, u[i] - u[i - 1], n, ap, am, hmax, t, wq)
        out[i] = z
    return out


# ---------------------------------------------------------------------------
# Periodic inputs
# ---------------------------------------------------------------------------


@njit(cache=True)
def path_with_reversals(x, d, X, C1, C2):  # pragma: no cover - compiled
    """``x`` on the grid with the reversal values inserted (see :func:`rate_independent_path`)."""
    n = x.shape[0]
    hgrid = TWO_PI / n
    cells, roots = reversal_roots(C1, C2, d)
    nc = cells.shape[0]
    path = np.empty(n + 1 + nc)
    grid_index = np.empty(n, dtype=np.int64)
    q = 0
    k = 0
    for i in range(n):
        grid_index[i] = k
        path[k] = x[i]
        k += 1
        if q < nc and cells[q] == i:
            r = min(max(roots[q], i * hgrid), (i + 1) * hgrid)
            path[k] = X[0].real + trig2(X, X, r)[0]
            k += 1
            q += 1
    path[k] = x[0]
    return path, grid_index
