"""Forward sensitivities of the open-loop simulation of a stage with a link of elements.

:class:`~motionhyst.openloop.OpenLoop` simulates a link other than Bouc-Wen by
discretising the stage exactly for a force linear between fine steps
(first-order hold) and advancing each element by its exact update
(:func:`motionhyst.hysteresis.stepping.advance`), the step's link force being
the fixed point ``w = W(dx(w))``.  This module runs the same steps and
differentiates each of them: the derivatives of the stage's discrete matrices
in ``m, c, k`` (Frechet derivatives of the matrix exponential, from the
exponential of a block matrix), the partial
derivatives of each element's update in its state, its displacement and its
parameters, and the implicit link force through
``dw = (dW_rest + W_dx d(base)) / (1 + W_dx B1)``.  The derivatives are exact
wherever the update is differentiable, i.e. almost everywhere: a stop
operator that starts or stops slipping inside a step, a LuGre or Dahl element
at an exact reversal, have one-sided derivatives there.

The outputs are the displacement at the record samples (bitwise the one of
:meth:`OpenLoop.simulate`) and its derivatives in ``m, c, k`` and in the
link's own parameters (through the derivatives of its
:class:`~motionhyst.hysteresis.stepping.Stepping` rows in them).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst._jit import njit
from motionhyst.hysteresis.stepping import DAHL, LUGRE, MAXWELL, N_PARAMS, STOP
from motionhyst.lti import expm_small

#: Element kinds whose update is differentiated here (the others fall back to differences)
SUPPORTED = (STOP, DAHL, LUGRE, MAXWELL)
# partials layout: 0 d/ds, 1 d/ds_prev, 2 d/ddx, 3 d/ddx_prev, 4.. d/dp[0..N_PARAMS-1]
_NP = 4 + N_PARAMS


@njit(cache=True, inline="always")
def _dahl_partials(zeta, v, alpha):  # pragma: no cover - compiled
    """``dahl_advance(zeta, v, alpha)`` and its derivatives in zeta, v and alpha."""
    y = 1.0 - zeta
    if y <= 0.0:
        return zeta, 1.0, 0.0, 0.0
    if v == 0.0:
        return zeta, 1.0, y ** alpha, 0.0
    eps = alpha - 1.0
    if abs(eps) < 1e-8:  # alpha = 1 (the alpha-derivative's limit; the general one cancels)
        e = math.exp(-v)
        yn = y * e
        if eps == 0.0:
            return zeta - y * math.expm1(-v), e, yn, -yn * (0.5 * v * v - v * math.log(y))
        zn, dz, dv, _ = _dahl_general(zeta, y, v, eps)
        return zn, dz, dv, -yn * (0.5 * v * v - v * math.log(y))
    return _dahl_general(zeta, y, v, eps)


@njit(cache=True, inline="always")
def _dahl_general(zeta, y, v, eps):  # pragma: no cover - compiled
    """:func:`_dahl_partials` for ``alpha = 1 + eps`` != 1 and ``y = 1 - zeta > 0`` (the
    state formed as :func:`~motionhyst.hysteresis._ode_kernels.dahl_advance` forms it)."""
    ye = y ** eps
    arg = eps * v * ye
    if arg <= -1.0:
        return 1.0, 0.0, 0.0, 0.0
    a = 1.0 + arg
    lg = -math.log1p(arg) / eps
    fac = math.exp(lg)  # A^(-1/eps)
    yn = y * fac
    d_zeta = fac * (1.0 - arg / a)
    d_v = y * ye * fac / a
    dlog = math.log1p(arg) / (eps * eps) - v * ye * (1.0 + eps * math.log(y)) / (eps * a)
    return zeta - y * math.expm1(lg), d_zeta, d_v, -yn * dlog


@njit("(int64, float64[::1], float64, float64, float64, float64, float64, boolean, "
      "float64[::1], float64[::1])")
def advance_partials(code, p, s, s_prev, dx, dx_prev, h, first, ds, df
                     ):  # pragma: no cover - compiled
    """:func:`~motionhyst.hysteresis.stepping.advance` with its partial derivatives.

    Returns the new state and force as ``advance`` does, and fills `ds` and
    `df` (length ``4 + N_PARAMS``) with the derivatives of the state and the
    force in ``(s, s_prev, dx, dx_prev, p[0], ..., p[N_PARAMS - 1])``.

    Examples
    --------
    A stop operator ``k = 2e4 N/m, fc = 10 N`` at 4 N moved by 0.1 mm: it
    reaches 6 N, so the force grows with ``k`` at rate ``dx``:

    >>> import numpy as np
    >>> from motionhyst.hysteresis.stepping import GL_T, GL_W, STOP, advance
    >>> p = np.array([2e4, 10.0, 0.0, 0.0, 0.0, 0.0])
    >>> ds, df = np.zeros(10), np.zeros(10)
    >>> advance_partials(STOP, p, 4.0, 4.0, 1e-4, 0.0, 1e-4, False, ds, df)
    (6.0, 6.0)
    >>> float(df[0]), float(df[2]), float(df[4])     # d/ds, d/ddx, d/dk
    (1.0, 20000.0, 0.0001)
    >>> advance(STOP, p, 4.0, 4.0, 1e-4, 0.0, 1e-4, False, GL_T, GL_W)
    (6.0, 6.0)
    """
    for i in range(_NP):
        ds[i] = 0.0
        df[i] = 0.0
    if code == STOP:
        v = s + p[0] * dx
        if v > p[1]:
            v = p[1]
            ds[5] = 1.0
        elif v < -p[1]:
            v = -p[1]
            ds[5] = -1.0
        else:
            ds[0] = 1.0
            ds[2] = p[0]
            ds[4] = dx
        for i in range(_NP):
            df[i] = ds[i]
        return v, v
    if code == DAHL:  # p = (k / fc, fc, alpha); state w / fc
        du = p[0] * dx
        if du > 0.0:
            sn, dz, dv, da = _dahl_partials(s, du, p[2])
        elif du < 0.0:
            sn, dz, dv, da = _dahl_partials(-s, -du, p[2])
            sn = -sn
            da = -da
        else:
            sn, dz, dv, da = s, 1.0, (1.0 - abs(s)) ** p[2] if abs(s) < 1.0 else 0.0, 0.0
        ds[0] = dz
        ds[2] = dv * p[0]
        ds[4] = dv * dx
        ds[6] = da
        for i in range(_NP):
            df[i] = p[1] * ds[i]
        df[5] = sn
        return sn, p[1] * sn
    if code == MAXWELL:  # p = (kv, cv); state f
        a = h * p[0] / p[1]
        if a > 0.0:
            e = math.exp(-a)
            phi = -math.expm1(-a) / a
            dphi = (a * e + math.expm1(-a)) / (a * a)
            sn = s * np.exp(-a) - p[0] * dx * np.expm1(-a) / a  # as advance forms it
            d_a = -s * e + p[0] * dx * dphi
            ds[0] = e
            ds[2] = p[0] * phi
            ds[4] = dx * phi + d_a * h / p[1]
            ds[5] = -d_a * h * p[0] / (p[1] * p[1])
        else:
            sn = s + p[0] * dx
            ds[0] = 1.0
            ds[2] = p[0]
            ds[4] = dx
        for i in range(_NP):
            df[i] = ds[i]
        return sn, sn
    # LuGre, p = (sigma0, sigma1, sigma2, fc, fs, vs); state z (see stepping.advance)
    sigma0, sigma1, sigma2, fc, fs, vs = p[0], p[1], p[2], p[3], p[4], p[5]
    if h <= 0.0:
        ds[0] = 1.0
        df[0] = sigma0
        df[4] = s
        return s, sigma0 * s
    z0 = s
    if dx == 0.0:
        sn = z0
        ds[0] = 1.0
        ds[2] = 1.0
    else:
        v = dx / h
        r = v / vs
        e = math.exp(-r * r)
        g = fc + (fs - fc) * e
        g_v = (fs - fc) * e * (-2.0 * r / vs)
        sg = 1.0 if dx > 0.0 else -1.0
        q = sg * g / sigma0
        ad = abs(dx)
        ex = math.exp(-sigma0 * ad / g)
        sn = q + (z0 - q) * ex
        d_g = sg / sigma0 * (1.0 - ex) + (z0 - q) * ex * sigma0 * ad / (g * g)
        ds[0] = ex
        ds[2] = (z0 - q) * ex * (-sigma0 * sg / g) + d_g * g_v / h
        ds[4] = -q / sigma0 * (1.0 - ex) - (z0 - q) * ex * ad / g
        ds[7] = d_g * (1.0 - e)
        ds[8] = d_g * e
        ds[9] = d_g * (fs - fc) * e * 2.0 * r * r / vs
    if first:
        vf = dx / h
        zdot = (sn - z0) / h
        c1 = sigma1 / h
        df[0] = sigma0 * ds[0] + c1 * (ds[0] - 1.0)
        df[2] = (sigma0 + c1) * ds[2] + sigma2 / h
    else:
        vf = (1.5 * dx - 0.5 * dx_prev) / h
        zdot = (1.5 * (sn - z0) - 0.5 * (z0 - s_prev)) / h
        c1 = 1.5 * sigma1 / h
        df[0] = sigma0 * ds[0] + c1 * ds[0] - 2.0 * sigma1 / h
        df[1] = 0.5 * sigma1 / h
        df[2] = (sigma0 + c1) * ds[2] + 1.5 * sigma2 / h
        df[3] = -0.5 * sigma2 / h
    df[4] = sn + (sigma0 + c1) * ds[4]
    df[5] = zdot
    df[6] = vf
    for i in range(7, 10):
        df[i] = (sigma0 + c1) * ds[i]
    return sn, sigma0 * sn + sigma1 * zdot + sigma2 * vf


@njit(cache=True, nogil=True)
def foh_link_sensitivities(Ad, B0, B1, dAd, dB0, dB1, uf, r, codes, params, dparams, glt, glw,
                           h, ftol, max_iter, x0, s0, sx0, ss0):  # pragma: no cover - compiled
    """``_foh_link_run`` of :mod:`motionhyst.openloop` with forward sensitivities.

    ``dAd[a], dB0[a], dB1[a]`` are the derivatives of the stage's matrices in
    ``m, c, k`` (``a = 0, 1, 2``); ``dparams[j, l, b]`` that of element ``j``'s
    parameter ``l`` in the link's parameter ``b``.  ``sx0`` (2, P) and ``ss0``
    (n elements, P) are the initial sensitivities, ``P = 3 + dparams.shape[2]``.

    Returns the output at every `r`-th step, its sensitivities (n_out, P), the
    final stage and element states and their sensitivities, and the largest
    number of fixed-point iterations of a step.
    """
    n_steps = uf.shape[0] - 1
    n_out = n_steps // r + 1
    m = codes.shape[0]
    P = 3 + dparams.shape[2]
    y = np.empty(n_out)
    sy = np.zeros((n_out, P))
    x = x0.copy()
    s = s0.copy()
    s_prev = s0.copy()
    s_new = s0.copy()
    sx = sx0.copy()
    ss = ss0.copy()
    ss_prev = ss0.copy()
    ss_new = np.zeros((m, P))
    dw_prev = np.zeros(P)
    ddx_prev = np.zeros(P)
    dbase = np.zeros(P)
    dw = np.zeros(P)
    ddx = np.zeros(P)
    pds = np.zeros((m, _NP))
    pdf = np.zeros((m, _NP))
    w_prev = 0.0
    for j in range(m):
        _, fj = advance_partials(codes[j], params[j], s[j], s[j], 0.0, 0.0, 0.0, True,
                                 pds[j], pdf[j])
        w_prev += fj
        for b in range(P):
            dw_prev[b] += (pdf[j, 0] + pdf[j, 1]) * ss[j, b]
        for b in range(3, P):
            for lp in range(N_PARAMS):
                dw_prev[b] += pdf[j, 4 + lp] * dparams[j, lp, b - 3]
    y[0] = x[0]
    for b in range(P):
        sy[0, b] = sx[0, b]
    dx_prev = 0.0
    worst = 0
    for i in range(n_steps):
        f0 = uf[i] - w_prev
        base_y = Ad[0, 0] * x[0] + Ad[0, 1] * x[1] + B0[0] * f0 + B1[0] * uf[i + 1]
        wt = w_prev
        it = 0
        change = math.inf
        while True:
            it += 1
            dx = base_y - B1[0] * wt - x[0]
            wn = 0.0
            for j in range(m):
                s_new[j], fj = advance_partials(codes[j], params[j], s[j], s_prev[j], dx,
                                                dx_prev, h, i == 0, pds[j], pdf[j])
                wn += fj
            last = change
            change = abs(wn - wt)
            done = change <= ftol or m == 0 or (change <= 1e3 * ftol and change >= last)
            wt = wn
            if done or it > max_iter:
                break
        if it > worst:
            worst = it
        dx = base_y - B1[0] * wt - x[0]
        # the partials of the last pass (at the converged point to the rounding floor)
        w_dx = 0.0
        for j in range(m):
            w_dx += pdf[j, 2]
        for b in range(P):
            db = Ad[0, 0] * sx[0, b] + Ad[0, 1] * sx[1, b] - B0[0] * dw_prev[b]
            if b < 3:
                db += (dAd[b, 0, 0] * x[0] + dAd[b, 0, 1] * x[1] + dB0[b, 0] * f0
                       + dB1[b, 0] * uf[i + 1] - dB1[b, 0] * wt)
            dbase[b] = db - sx[0, b]
            rr = 0.0
            for j in range(m):
                rr += (pdf[j, 0] * ss[j, b] + pdf[j, 1] * ss_prev[j, b]
                       + pdf[j, 3] * ddx_prev[b])
                if b >= 3:
                    for lp in range(N_PARAMS):
                        rr += pdf[j, 4 + lp] * dparams[j, lp, b - 3]
            dw[b] = (rr + w_dx * dbase[b]) / (1.0 + w_dx * B1[0])
            ddx[b] = dbase[b] - B1[0] * dw[b]
        for j in range(m):
            for b in range(P):
                v = (pds[j, 0] * ss[j, b] + pds[j, 1] * ss_prev[j, b] + pds[j, 2] * ddx[b]
                     + pds[j, 3] * ddx_prev[b])
                if b >= 3:
                    for lp in range(N_PARAMS):
                        v += pds[j, 4 + lp] * dparams[j, lp, b - 3]
                ss_new[j, b] = v
        f1 = uf[i + 1] - wt
        x0n = Ad[0, 0] * x[0] + Ad[0, 1] * x[1] + B0[0] * f0 + B1[0] * f1
        x1n = Ad[1, 0] * x[0] + Ad[1, 1] * x[1] + B0[1] * f0 + B1[1] * f1
        for b in range(P):
            d0 = Ad[0, 0] * sx[0, b] + Ad[0, 1] * sx[1, b] - B0[0] * dw_prev[b] - B1[0] * dw[b]
            d1 = Ad[1, 0] * sx[0, b] + Ad[1, 1] * sx[1, b] - B0[1] * dw_prev[b] - B1[1] * dw[b]
            if b < 3:
                d0 += (dAd[b, 0, 0] * x[0] + dAd[b, 0, 1] * x[1] + dB0[b, 0] * f0
                       + dB1[b, 0] * f1)
                d1 += (dAd[b, 1, 0] * x[0] + dAd[b, 1, 1] * x[1] + dB0[b, 1] * f0
                       + dB1[b, 1] * f1)
            sx[0, b] = d0
            sx[1, b] = d1
        x[0] = x0n
        x[1] = x1n
        for j in range(m):
            s_prev[j] = s[j]
            s[j] = s_new[j]
            for b in range(P):
                ss_prev[j, b] = ss[j, b]
                ss[j, b] = ss_new[j, b]
        w_prev = wt
        dx_prev = dx
        for b in range(P):
            dw_prev[b] = dw[b]
            ddx_prev[b] = ddx[b]
        if (i + 1) % r == 0:
            o = (i + 1) // r
            y[o] = x[0]
            for b in range(P):
                sy[o, b] = sx[0, b]
    return y, sy, x, s, sx, ss, worst


def stage_matrices(m: float, c: float, k: float, h: float):
    """``Ad, B0, B1`` of the stage for a first-order-hold force over a step `h`, and their
    derivatives in ``m, c, k`` (shapes (3, 2, 2), (3, 2), (3, 2)).

    Examples
    --------
    >>> Ad, B0, B1, dAd, dB0, dB1 = stage_matrices(2.0, 10.0, 5e4, 1e-4)
    >>> eps = 1e-6
    >>> Ad2 = stage_matrices(2.0, 10.0, 5e4 * (1 + eps), 1e-4)[0]
    >>> bool(abs((Ad2[1, 0] - Ad[1, 0]) / (5e4 * eps) - dAd[2, 1, 0]) < 1e-6 * abs(dAd[2, 1, 0]))
    True
    """
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    B = np.array([0.0, 1.0 / m])
    M = np.zeros((4, 4))
    M[:2, :2] = A * h
    M[:2, 2] = B * h
    M[2, 3] = 1.0
    dA = [np.array([[0.0, 0.0], [k / m ** 2, c / m ** 2]]),
          np.array([[0.0, 0.0], [0.0, -1.0 / m]]),
          np.array([[0.0, 0.0], [-1.0 / m, 0.0]])]
    dB = [np.array([0.0, -1.0 / m ** 2]), np.zeros(2), np.zeros(2)]
    dAd = np.zeros((3, 2, 2))
    dB0 = np.zeros((3, 2))
    dB1 = np.zeros((3, 2))
    E = None
    for a in range(3):
        dM = np.zeros((4, 4))
        dM[:2, :2] = dA[a] * h
        dM[:2, 2] = dB[a] * h
        # the Frechet derivative of expm at M along dM: the corner of expm([[M, dM], [0, M]])
        big = np.zeros((8, 8))
        big[:4, :4] = M
        big[:4, 4:] = dM
        big[4:, 4:] = M
        Eb = expm_small(big)
        E, dE = Eb[:4, :4], Eb[:4, 4:]
        dAd[a] = dE[:2, :2]
        dB1[a] = dE[:2, 3]
        dB0[a] = dE[:2, 2] - dE[:2, 3]
    assert E is not None
    B1 = np.ascontiguousarray(E[:2, 3])
    B0 = np.ascontiguousarray(E[:2, 2] - B1)
    Ad = np.ascontiguousarray(E[:2, :2])
    return Ad, B0, B1, dAd, dB0, dB1


def row_derivatives(build, values: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """``d params[j, l] / d values[b]`` of the link's stepping rows, by central differences.

    The rows are algebraic in the model's parameters (copies, products,
    ratios, a reordering), so central differences with a relative step of
    ``1e-5`` are exact to about ``1e-10``.  None if an element kind is not
    differentiated here (:data:`SUPPORTED`) or the rows change shape.

    Examples
    --------
    A Dahl link's row is ``(k / fc, fc, alpha)``:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Dahl
    >>> d = row_derivatives(lambda v: Dahl(k=v[0], fc=v[1], alpha=v[2]),
    ...                     np.array([2e4, 10.0, 1.0]))
    >>> np.round(d[0, :3, 1], 6).tolist()      # d(k / fc, fc, alpha) / d fc
    [-200.0, 1.0, 0.0]
    """
    st = build(values).time_stepping()
    if not np.all(np.isin(st.codes, SUPPORTED)):
        return None
    m = st.codes.size
    out = np.zeros((m, N_PARAMS, values.size))
    for b in range(values.size):
        step = 1e-5 * abs(values[b]) if values[b] != 0.0 else 1e-8
        hi, lo = values.copy(), values.copy()
        hi[b] += step
        lo[b] = max(lo[b] - step, 0.0) if values[b] >= 0 else lo[b] - step
        try:
            p_hi = build(hi).time_stepping().params
            p_lo = build(lo).time_stepping().params
        except ValueError:
            return None
        if p_hi.shape != st.params.shape or p_lo.shape != st.params.shape:
            return None
        out[:, :, b] = (p_hi - p_lo) / (hi[b] - lo[b])
    return out


def simulate_with_sensitivities(m: float, c: float, k: float, stepping, dparams, u, fs: float,
                                r: int, periodic: bool, upsampled: NDArray[np.float64],
                                k_link: float = 0.0):
    """Output of :meth:`OpenLoop.simulate` for a link of elements and its sensitivities.

    Parameters
    ----------
    m, c, k : float
        The stage.
    stepping : Stepping
        The link's rows (:meth:`Hysteresis.time_stepping`).
    dparams : ndarray, shape (n elements, N_PARAMS, P_link)
        :func:`row_derivatives` of the rows in the link's parameters.
    u : ndarray
        Force record [N] at `fs` [Hz]; `r` steps per sample.
    periodic : bool
        From rest, or the periodic steady state (periods repeated until the
        output changes by less than 1e-12 of its amplitude and the
        sensitivities by less than 1e-8 of theirs).
    upsampled : ndarray
        ``fine_input(u, r, periodic)``.
    k_link : float
        The link's initial stiffness [N/m] (bounds the number of periods a
        periodic run may take, as :meth:`OpenLoop.simulate` does).

    Returns
    -------
    y : ndarray
        Displacement at the samples [m].
    dy : ndarray, shape (len(u), 3 + P_link)
        Its derivatives in ``m, c, k`` and the link's parameters.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.openloop import MassSpringDamper, OpenLoop, fine_input
    >>> link = Jenkins(k=2e4, fc=10.0)
    >>> t = np.arange(256) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t)
    >>> build = lambda v: Jenkins(k=v[0], fc=v[1])
    >>> y, dy = simulate_with_sensitivities(
    ...     2.0, 10.0, 5e4, link.time_stepping(), row_derivatives(build, np.array([2e4, 10.0])),
    ...     u, 750.0, 10, False, fine_input(u, 10, False), link.initial_stiffness)
    >>> ref = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), link).simulate(t, u, substeps=10)
    >>> bool(np.max(np.abs(y - ref.displacement)) < 1e-15), dy.shape
    (True, (256, 5))
    """
    from motionhyst.hysteresis.stepping import GL_T, GL_W
    from motionhyst.openloop import (
        PERIODIC_RTOL,
        MassSpringDamper,
        _check_converged,
        _max_periods,
    )
    from motionhyst.simulate import MAX_FIXED_POINT_ITERATIONS

    h = 1.0 / (fs * r)
    Ad, B0, B1, dAd, dB0, dB1 = stage_matrices(m, c, k, h)
    ftol = 1e-13 * stepping.scale
    n_el = stepping.codes.size
    P = 3 + dparams.shape[2]
    x, s = np.zeros(2), stepping.state0.copy()
    sx, ss = np.zeros((2, P)), np.zeros((n_el, P))
    dparams = np.ascontiguousarray(dparams)

    def run(x, s, sx, ss):
        out = foh_link_sensitivities(Ad, B0, B1, dAd, dB0, dB1, upsampled, r, stepping.codes,
                                     stepping.params, dparams, GL_T, GL_W, h, ftol,
                                     MAX_FIXED_POINT_ITERATIONS, x, s, sx, ss)
        _check_converged(out[-1])
        return out[:-1]

    if not periodic:
        y, sy, *_ = run(x, s, sx, ss)
        return y, sy
    prev = None
    mech = MassSpringDamper(m, c, k).mechanics()
    for _ in range(_max_periods(mech, k_link, u.size / fs)):
        y, sy, x, s, sx, ss = run(x, s, sx, ss)
        y, sy = y[:-1], sy[:-1]
        if prev is not None:
            ok = np.max(np.abs(y - prev[0])) <= PERIODIC_RTOL * np.max(np.abs(y))
            ok &= bool(np.all(np.max(np.abs(sy - prev[1]), axis=0)
                              <= 1e-8 * (np.max(np.abs(sy), axis=0) + 1e-300)))
            if ok:
                return y, sy
        prev = (y, sy)
    raise ValueError("the periodic steady state was not reached (the response does not "
                     "settle from one period to the next)")
