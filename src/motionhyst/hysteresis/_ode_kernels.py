"""Compiled kernels and periodic-input helpers of the smooth hysteresis models.

Shared by :mod:`~motionhyst.hysteresis.dahl`, :mod:`~motionhyst.hysteresis.bouc_wen`
and :mod:`~motionhyst.hysteresis.lugre`.

Rate-independent models (Dahl, Bouc-Wen) are integrated in the displacement:
on a monotone piece the state follows an autonomous scalar ODE in the
normalised displacement ``v = (k / fc) |dx|``, solved in closed form (Dahl,
Bouc-Wen with ``n = 1``) or by RK4 sub-steps (Bouc-Wen, other ``n``).  A
periodic input is sampled on a uniform grid of the period with its reversal
points (found by root finding on the trigonometric polynomial) inserted, so
no excursion between samples is missed; the periodic state is the fixed
point of the scalar period map.

The LuGre model is linear in its state for a given motion, so one pass of an
exponential integrator over the period gives the periodic state exactly (the
period map is affine).
"""

from __future__ import annotations

import math

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._kernels import _trig2, reversal_roots, trig_root

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
    d1, d2 = _trig2(C1, C2, th)
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
            d2, d3 = _trig2(C2, C3, thn)
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
        xr[q] = X[0].real + _trig2(X, C1, roots[q])[0]
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
# LuGre: dz/dtheta = x' - sigma0 |x'| z / g(omega x')  (linear in z)
# ---------------------------------------------------------------------------


@njit(cache=True)
def lugre_g(v, fc, fs, vs):  # pragma: no cover - compiled
    """Stribeck curve ``g(v) = fc + (fs - fc) exp(-(v / vs)^2)`` [N]."""
    r = v / vs
    return fc + (fs - fc) * math.exp(-r * r)


_RECIPROCALS = 1.0 / np.arange(1.0, 44.0)  # 1 / (j + 1) for the series of _exp_moments


@njit(cache=True)
def _exp_moments(L):  # pragma: no cover - compiled
    """``mu_k = int_0^1 t^k exp(-L t) dt`` for k = 0, 1, 2 (L >= 0).

    For ``L < 0.5`` by the series ``sum_j (-L)^j / (j! (j + k + 1))`` (with the
    reciprocals tabulated: a multiplication per term instead of a division)
    until the terms fall below 1e-18, else in closed form.
    """
    if L < 0.5:
        m0 = m1 = m2 = 0.0
        term = 1.0  # (-L)^j / j!
        inv = _RECIPROCALS
        for j in range(40):
            m0 += term * inv[j]
            m1 += term * inv[j + 1]
            m2 += term * inv[j + 2]
            term *= -L * inv[j]
            if abs(term) < 1e-18:
                break
        return m0, m1, m2
    E = math.exp(-L)
    m0 = -math.expm1(-L) / L
    m1 = (m0 - E) / L
    m2 = (2.0 * m1 - E) / L
    return m0, m1, m2


# Stribeck window: beyond |v| = STRIBECK_WINDOW vs the term (fs - fc) exp(-(v / vs)^2) is below
# 2.3e-16 (fs - fc), so g is flat there to round-off.  Inside the window a step is cut into
# substeps over which v changes by at most STRIBECK_DV vs: the state's error there falls
# about as STRIBECK_DV^3 (measured: 5e-11 of |z| at 1/12, the step of the former grid
# criterion, and 5e-13 at 1/48).  A reversal costs at most about 4 STRIBECK_WINDOW /
# STRIBECK_DV ~ 1200 substeps (the window on both sides, up to twice the count of equal
# velocity steps where the slope of x' is uneven; about half that with the factors below),
# whatever omega A / vs.  The error comes
# from the third derivative of g, (fs - fc) / vs^3 G3(v / vs) with G3(u) = (12 u - 8 u^3)
# exp(-u^2), at most 3.9 (near u = 0.52) but 0.73 for |u| >= 2, 0.022 for |u| >= 3 and 5e-5
# for |u| >= 4: away from the reversal the velocity may change by STRIBECK_DV times
# STRIBECK_DV_FACTORS per substep (1.5, 4 and 12 for |v| beyond 2, 3 and 4 vs; below the
# (3.9 / max |G3|)^(1/3) = 1.8, 5.6 and 42 that would keep the error of the third order at
# its level near the reversal), which halves the substeps of a reversal for the same error.
STRIBECK_WINDOW = 6.0
STRIBECK_DV = 1.0 / 48.0
STRIBECK_DV_FACTORS = (1.0, 1.0, 1.5, 4.0, 12.0, 12.0)  # for |v| / vs in [k, k + 1)


@njit(cache=True)
def _stribeck_dv_factor(u):  # pragma: no cover - compiled
    """The factor of :data:`STRIBECK_DV` for substeps where ``|v| / vs >= u`` (u >= 0)."""
    k = int(u) if u < 5.0 else 5
    return STRIBECK_DV_FACTORS[k]


@njit(cache=True)
def _lugre_substep_g(zi, pa, pm, pb, ga, gm, gb, hh, sg, sigma0):  # pragma: no cover
    """Exponential step over an angle `hh` with ``x'`` equal to `pa`, `pm`, `pb` and ``g``
    equal to `ga`, `gm`, `gb` at its start, middle and end; returns ``z`` at its end and
    the step's ``L = int lambda``."""
    la = sigma0 * abs(pa) / ga
    lm = sigma0 * abs(pm) / gm
    lb = sigma0 * abs(pb) / gb
    L = hh * (la + 4.0 * lm + lb) / 6.0
    if not L > 0.0:
        return zi, 0.0
    Lm = hh * (-la + 8.0 * lm + 5.0 * lb) / 24.0  # Lambda(end) - Lambda(mid)
    qa = sg * ga / sigma0
    qm = sg * gm / sigma0
    qb = sg * gb / sigma0
    m0, m1, m2 = _exp_moments(L)
    tau = Lm / L
    if 0.05 < tau < 0.95:  # quadratic through t = 0 (end), tau (middle), 1 (start)
        c2 = ((qm - qb) - tau * (qa - qb)) / (tau * (tau - 1.0))
        c1 = (qa - qb) - c2
        integral = L * (qb * m0 + c1 * m1 + c2 * m2)
    else:
        integral = L * (qb * m0 + (qa - qb) * m1)
    return math.exp(-L) * zi + integral, L


@njit(cache=True)
def _lugre_substep(zi, pa, pm, pb, hh, sg, omega, sigma0, fc, fs, vs):  # pragma: no cover
    """Exponential step over an angle `hh` with ``x'`` equal to `pa`, `pm`, `pb` at its
    start, middle and end; returns ``z`` at its end and the step's ``L = int lambda``.

    ``lambda = sigma0 |x'| / g`` is integrated by Simpson's rule and the
    quasi-static state ``q = sign(x') g / sigma0`` interpolated by a quadratic in
    ``Lambda`` (:func:`_lugre_substep_g`).
    """
    return _lugre_substep_g(zi, pa, pm, pb, lugre_g(omega * pa, fc, fs, vs),
                            lugre_g(omega * pm, fc, fs, vs), lugre_g(omega * pb, fc, fs, vs),
                            hh, sg, sigma0)


@njit(cache=True)
def _quad_level(b0, b1, b2, t0, t1, level):  # pragma: no cover - compiled
    """``t`` in ``[t0, t1]`` where the monotone ``p(t) = b0 + b1 t + b2 t^2`` equals `level`
    (`t0` or `t1` if `level` is outside ``p``'s range there); bisection."""
    p0 = b0 + t0 * (b1 + t0 * b2)
    p1 = b0 + t1 * (b1 + t1 * b2)
    up = p1 >= p0
    if (level <= p0) == up:
        return t0
    if (level >= p1) == up:
        return t1
    lo, hi = t0, t1
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        pm = b0 + mid * (b1 + mid * b2)
        if (pm < level) == up:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit("(float64, float64, float64, float64, float64, float64, float64, float64, float64, "
      "float64, float64, float64, float64, int64)")
def _lugre_piece(zi, b0, b1, b2, t0, t1, h, sg, omega, sigma0, fc, fs, vs,
                 m):  # pragma: no cover - compiled
    """`m` equal substeps of ``[t0, t1]`` (fractions of a step of angle `h`) with ``x'``
    from the quadratic ``b0 + b1 t + b2 t^2``; returns ``z`` and ``L`` of the piece.

    ``g`` at the end of a substep is that at the start of the next (evaluated once).
    """
    L = 0.0
    dt = (t1 - t0) / m
    pa = b0 + t0 * (b1 + t0 * b2)
    ga = lugre_g(omega * pa, fc, fs, vs)
    for k in range(m):
        ta = t0 + k * dt
        tb = t1 if k == m - 1 else t0 + (k + 1) * dt
        tm = 0.5 * (ta + tb)
        pm = b0 + tm * (b1 + tm * b2)
        pb = b0 + tb * (b1 + tb * b2)
        gm = lugre_g(omega * pm, fc, fs, vs)
        gb = lugre_g(omega * pb, fc, fs, vs)
        zi, dL = _lugre_substep_g(zi, pa, pm, pb, ga, gm, gb, (tb - ta) * h, sg, sigma0)
        L += dL
        pa = pb
        ga = gb
    return zi, L


@njit(cache=True)
def _lugre_window_step(zi, xa, xm, xb, h, sg, omega, sigma0, fc, fs, vs):  # pragma: no cover
    """Step of angle `h` whose velocity range meets the Stribeck window.

    ``x'`` is the quadratic through `xa`, `xm`, `xb`.  The step is cut at an
    interior extremum of ``x'`` into monotone pieces; each piece is cut at
    ``|omega x'| = STRIBECK_WINDOW vs`` and its part inside the window into
    equal substeps over which ``omega x'`` changes by at most ``STRIBECK_DV vs``
    (bounded by the larger end slope, ``x'`` being monotone there), times
    :func:`_stribeck_dv_factor` of the smallest ``|omega x'| / vs`` in the part.
    """
    b0 = xa
    b1 = -3.0 * xa + 4.0 * xm - xb
    b2 = 2.0 * (xa - 2.0 * xm + xb)
    P = STRIBECK_WINDOW * vs / omega
    dp = STRIBECK_DV * vs / omega
    ts = -b1 / (2.0 * b2) if b2 != 0.0 else 1.0
    nc = 2 if 0.0 < ts < 1.0 else 1  # monotone pieces [0, ts], [ts, 1] or [0, 1]
    L = 0.0
    t0 = 0.0
    for i in range(nc):
        t1 = ts if i + 1 < nc else 1.0
        ua = _quad_level(b0, b1, b2, t0, t1, -P)
        ub = _quad_level(b0, b1, b2, t0, t1, P)
        wa = min(ua, ub)
        wb = max(ua, ub)
        slope = max(abs(b1 + 2.0 * b2 * wa), abs(b1 + 2.0 * b2 * wb))
        pwa = b0 + wa * (b1 + wa * b2)
        pwb = b0 + wb * (b1 + wb * b2)
        umin = 0.0 if pwa * pwb <= 0.0 else min(abs(pwa), abs(pwb)) * (omega / vs)
        m = (max(math.ceil(slope * (wb - wa) / (dp * _stribeck_dv_factor(umin))), 1)
             if wb > wa else 0)
        if nc == 1 and m <= 1 and wa == t0 and wb == t1:  # inside, and slow enough
            return _lugre_substep(zi, xa, xm, xb, h, sg, omega, sigma0, fc, fs, vs)
        if wa > t0:
            zi, dL = _lugre_piece(zi, b0, b1, b2, t0, wa, h, sg, omega, sigma0, fc, fs, vs, 1)
            L += dL
        if m > 0:
            zi, dL = _lugre_piece(zi, b0, b1, b2, wa, wb, h, sg, omega, sigma0, fc, fs, vs, m)
            L += dL
        if wb < t1:
            zi, dL = _lugre_piece(zi, b0, b1, b2, wb, t1, h, sg, omega, sigma0, fc, fs, vs, 1)
            L += dL
        t0 = t1
    return zi, L


@njit(cache=True)
def _lugre_step_map(pa, pm, pb, h, omega, sigma0, fc, fs, vs, P, g_out):  # pragma: no cover
    """The step of angle `h` as the affine map ``z -> e z + b``; returns ``e, b, L``.

    ``x'`` is `pa`, `pm`, `pb` at the start, middle and end of the step and of
    one sign inside, ``L = int lambda`` over the step (Simpson's rule) and
    ``e = exp(-L)``.  A step whose velocity range (the quadratic through the
    three values) meets the Stribeck window ``|x'| < P`` is cut into substeps
    (:func:`_lugre_window_step`); elsewhere ``g`` is the constant `g_out` (``fc``
    beyond the window, where ``g - fc < 2.3e-16 (fs - fc)``, or ``g(0) = fs`` at
    ``omega = 0``), and the exponential step is exact:
    ``z_b = q + (z_a - q) exp(-L)`` with ``q = sign(x') g / sigma0``, one
    ``expm1`` per step.
    """
    s = pa + 4.0 * pm + pb
    if s == 0.0 or h == 0.0:
        return 1.0, 0.0, 0.0
    sg = 1.0 if s > 0.0 else -1.0
    # does the range of the quadratic x' meet (-P, P)?  It lies within |pa - 2 pm + pb| / 2
    # of the chord from pa to pb: a test without a division settles most steps
    bow = 0.5 * abs(pa - 2.0 * pm + pb)
    if P > 0.0 and min(pa, pb) - bow < P and max(pa, pb) + bow > -P:
        lo = min(pa, pb)
        hi = max(pa, pb)
        b1 = -3.0 * pa + 4.0 * pm - pb
        b2 = 2.0 * (pa - 2.0 * pm + pb)
        if b2 != 0.0:
            ts = -b1 / (2.0 * b2)
            if 0.0 < ts < 1.0:
                pe = pa + ts * (b1 + ts * b2)
                lo = min(lo, pe)
                hi = max(hi, pe)
        if lo < P and hi > -P:
            b, L = _lugre_window_step(0.0, pa, pm, pb, h, sg, omega, sigma0, fc, fs, vs)
            return math.exp(-L), b, L
    L = (abs(pa) + 4.0 * abs(pm) + abs(pb)) * (h * sigma0 / (6.0 * g_out))
    em = math.expm1(-L)
    return 1.0 + em, -(sg * g_out / sigma0) * em, L


@njit(cache=True)
def lugre_periodic_state(d2, C1, C2, omega, sigma0, fc, fs, vs):  # pragma: no cover - compiled
    """Periodic LuGre bristle state ``z`` on the grid ``theta_i = 2 pi i / N``, compiled end to end.

    With ``x' = dx/dtheta`` and ``lambda = sigma0 |x'| / g(omega x')`` the state
    equation ``dz/dtheta = x' - lambda z`` is linear in ``z``.  Its steps are
    the grid cells, split at the reversals of ``x`` (roots of ``x'``, found on
    the trigonometric polynomial by
    :func:`~motionhyst.hysteresis._kernels.reversal_roots`) so that ``x'`` has
    one sign inside each.  Each step is an affine map ``z -> e z + b``
    (:func:`_lugre_step_map`): the exact step
    ``z_b = exp(-L) z_a + int_0^L q(sigma) exp(-sigma) d sigma`` (``L = int lambda``
    by Simpson's rule, ``q = sign(x') g / sigma0``, ``sigma`` measured back from
    the step's end).  Outside the Stribeck window ``g`` is constant and the
    step costs one ``expm1``; a step whose velocity range meets the window
    ``|omega x'| < 6 vs`` (where ``g`` varies on the scale ``vs``, near the
    reversals) is cut into substeps over which ``omega x'`` changes by at most
    ``vs / 48`` (up to 12 times that beyond ``4 vs``, where ``g`` is nearly flat:
    :data:`STRIBECK_DV_FACTORS`), each with ``q`` interpolated by a quadratic in ``Lambda``
    (:func:`_lugre_window_step`), so the work per step is bounded
    independently of ``omega A / vs``.  The period map is then affine,
    ``z -> exp(-Lambda) z + z_p``, and its fixed point
    ``z_0 = z_p / (1 - exp(-Lambda))`` is the periodic state: one pass over the
    period computes the steps, two passes of one multiply-add per cell give
    ``z_p`` and the samples.

    Accuracy: outside the window the step is exact but for Simpson's rule on
    ``|x'|`` (error ``~ h^5 |x^(5)|``, below round-off on the default grids);
    inside it the substeps' error is below about 5e-13 of ``|z|`` (falling as
    the cube of the velocity change per substep), so ``D`` agrees with an
    adaptive ODE reference (DOP853 at ``rtol = 1e-13``) to about 1e-11 relative or
    better (measured: at most 1.4e-12 at the 30 points of ``tests/test_lugre_kernel.py``,
    ``omega A / vs`` from 0.06 to 6e5; see
    :meth:`~motionhyst.hysteresis.LuGre.default_samples` for the grid's share).

    Parameters
    ----------
    d2 : ndarray, shape (2 N,)
        ``x'`` on the grid ``pi j / N``: the samples ``2 i`` are the grid points,
        ``2 i + 1`` the middles of the cells.
    C1, C2 : ndarray of complex
        Harmonics of ``x'`` (``j m X_m``) and ``x''`` (``-m^2 X_m``).
    omega : float
        Angular frequency [rad/s], >= 0.
    sigma0, fc, fs, vs : float
        The element's parameters.

    Returns
    -------
    ndarray, shape (N,)
        The periodic ``z`` at ``theta_i``.
    """
    n = d2.shape[0] // 2
    hgrid = TWO_PI / n
    d = np.empty(n)
    for i in range(n):
        d[i] = d2[2 * i]
    cells, roots = reversal_roots(C1, C2, d)  # at most one reversal per cell
    nc = cells.shape[0]
    P = STRIBECK_WINDOW * vs / omega if (fs != fc and omega > 0.0) else 0.0
    g_out = fc if omega > 0.0 else fs
    e = np.empty(n)
    b = np.empty(n)
    total = 0.0
    q = 0
    for i in range(n):
        pa = d[i]
        pb = d[i + 1] if i + 1 < n else d[0]
        if q < nc and cells[q] == i:  # split at the reversal: x' = 0 there
            lo = i * hgrid
            hi = (i + 1) * hgrid
            r = min(max(roots[q], lo), hi)
            e1, b1, L1 = _lugre_step_map(pa, _trig2(C1, C1, 0.5 * (lo + r))[0], 0.0, r - lo,
                                         omega, sigma0, fc, fs, vs, P, g_out)
            e2, b2, L2 = _lugre_step_map(0.0, _trig2(C1, C1, 0.5 * (r + hi))[0], pb, hi - r,
                                         omega, sigma0, fc, fs, vs, P, g_out)
            e[i] = e1 * e2
            b[i] = e2 * b1 + b2
            total += L1 + L2
            q += 1
        else:
            ei, bi, L = _lugre_step_map(pa, d2[2 * i + 1], pb, hgrid, omega, sigma0, fc, fs,
                                        vs, P, g_out)
            e[i] = ei
            b[i] = bi
            total += L
    zp = 0.0  # particular solution: z after one period from z = 0
    for i in range(n):
        zp = e[i] * zp + b[i]
    zi = zp / -math.expm1(-total) if total > 0.0 else 0.0
    z = np.empty(n)
    for i in range(n):
        z[i] = zi
        zi = e[i] * zi + b[i]
    return z


@njit(cache=True)
def lugre_relax(z, dx, h, sigma0, fc, fs, vs):  # pragma: no cover - compiled
    """Bristle state after a displacement `dx` at constant velocity over a time `h` > 0.

    ``g(v)`` is constant for ``v = dx / h``, and ``z`` relaxes exactly to the
    quasi-static state ``q = sign(v) g / sigma0``:
    ``z <- q + (z - q) exp(-sigma0 |dx| / g)``.
    """
    if dx == 0.0:
        return z
    g = lugre_g(dx / h, fc, fs, vs)
    q = g / sigma0 if dx > 0.0 else -g / sigma0
    return q + (z - q) * math.exp(-sigma0 * abs(dx) / g)


@njit(cache=True)
def lugre_response(x, t, sigma0, sigma1, sigma2, fc, fs, vs, z0):  # pragma: no cover
    """LuGre state and force for displacement samples `x` at times `t`, linear in between.

    With constant velocity on an interval the state relaxes exactly
    (:func:`lugre_relax`).  The force at a sample uses the velocity of the
    interval ending there.
    """
    n = x.shape[0]
    w = np.empty(n)
    if n == 0:
        return w
    z = z0
    w[0] = sigma0 * z
    for i in range(1, n):
        dt = t[i] - t[i - 1]
        dx = x[i] - x[i - 1]
        v = dx / dt
        z = lugre_relax(z, dx, dt, sigma0, fc, fs, vs)
        zdot = v - sigma0 * abs(v) * z / lugre_g(v, fc, fs, vs)
        w[i] = sigma0 * z + sigma1 * zdot + sigma2 * v
    return w


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
            path[k] = X[0].real + _trig2(X, X, r)[0]
            k += 1
            q += 1
    path[k] = x[0]
    return path, grid_index
