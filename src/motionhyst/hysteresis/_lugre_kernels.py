"""Compiled kernels of the LuGre model (:mod:`~motionhyst.hysteresis.lugre`).

The LuGre state equation is linear in its state for a given motion, so one
pass of an exponential integrator over the period gives the periodic state
exactly (the period map is affine); in time, the state relaxes exactly over a
step of constant velocity.  The Stribeck window around a reversal is resolved
by substeps.
"""

from __future__ import annotations

import math

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._kernels import reversal_roots, trig2

TWO_PI = 2.0 * np.pi

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
            e1, b1, L1 = _lugre_step_map(pa, trig2(C1, C1, 0.5 * (lo + r))[0], 0.0, r - lo,
                                         omega, sigma0, fc, fs, vs, P, g_out)
            e2, b2, L2 = _lugre_step_map(0.0, trig2(C1, C1, 0.5 * (r + hi))[0], pb, hi - r,
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
