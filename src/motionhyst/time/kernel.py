"""The compiled step loop of the one time engine (:mod:`motionhyst.time.engine`).

:func:`step_loop` runs every time step of every time-domain run: the linear part
discretised for a first-order-hold input, the link's exact update solved with the
hold's feedthrough by a fixed-point iteration, the forward sensitivities on request,
and a sampled controller every `period` steps.  :func:`motionhyst.time.engine.run_steps`
prepares its arguments and is what the rest of the package calls.
"""

from __future__ import annotations

import math

import numpy as np

from motionhyst.core.compiled import njit
from motionhyst.hysteresis.stepping import (
    COULOMB,
    N_PARAMS,
    N_PARTIALS,
    advance,
    advance_partials,
    coulomb_implicit,
)

__all__ = ["CLOSED", "MAX_FIXED_POINT_ITERATIONS", "OPEN", "StepNotConverged", "step_loop"]

#: Fixed-point passes a step's link force may take before the run stops.
MAX_FIXED_POINT_ITERATIONS = 50


class StepNotConverged(RuntimeError):
    """A link's implicit step that did not converge: the link is too stiff, or too strongly
    damped, for the time step (its force changes more over a step than the loop's
    feedthrough lets a fixed point settle).

    The message is :attr:`what` happened and :attr:`remedy`, the caller's own way to a
    finer step (a library function's ``dt`` or ``substeps``); a command that has no such
    option says what its user can change instead, from :attr:`what`.

    Parameters
    ----------
    what : str
        What happened (where the step did not converge).
    remedy : str
        The caller's way to a finer step.

    Examples
    --------
    >>> err = StepNotConverged("the implicit step at t = 0.01 s did not converge",
    ...                        "use a smaller dt")
    >>> print(err)
    the implicit step at t = 0.01 s did not converge; use a smaller dt
    >>> isinstance(err, RuntimeError), err.what
    (True, 'the implicit step at t = 0.01 s did not converge')
    """

    def __init__(self, what: str, remedy: str):
        super().__init__(f"{what}; {remedy}")
        self.what = what
        self.remedy = remedy


#: Conventions of the implicit step (see :func:`step_loop`).
CLOSED, OPEN = 0, 1

_SIGNATURE = (
    "(float64[:, :, ::1], float64[:, ::1], float64[:, ::1], float64[:, ::1], float64[:, ::1], "
    "float64[::1], float64[:, :, ::1], float64[:, ::1], float64[:, ::1], int64, int64, "
    "float64[::1], float64[::1], float64[:, ::1], int64, boolean, "
    "int64[::1], float64[:, ::1], float64[:, :, ::1], float64[::1], float64[::1], float64, "
    "int64, int64, int64, int64, boolean, "
    "float64[:, ::1], float64[:, ::1], float64[::1], float64[::1], float64[::1], float64[::1], "
    "float64, int64, int64, int64, int64, "
    "float64[::1], float64[::1], float64[::1], float64[:, ::1], float64[:, ::1], "
    "float64[:, ::1], float64[:, ::1], float64[::1], float64[::1], float64[::1], float64[::1])")


@njit(_SIGNATURE, nogil=True)
def step_loop(A, B0, B1, C, G, hs, dA, dB0, dB1, link_row, vel_row, a, dexo, exo, record_every,
              record_initial, codes, params, dparams, glt, glw, ftol, max_iter, convention, i0,
              i_first, fresh, Ac, Bc, Cc, Dc, ref, ff, u_max, period, r1, meas_row, n_delay,
              z, s, s_prev, sx, ss, ss_prev, dvec, out_prev, scal, xc, uq
              ):  # pragma: no cover - compiled
    """The time loop: ``len(a) - 1`` steps of the linear part, the link and the controller.

    Linear part (kinds ``q`` = 0, 1 of step: ``A[q], B0[q], B1[q]``, step ``hs[q]``; kind 1
    only for the first `r1` steps of each controller period), state `z`::

        zp = A z + B0 f_old,   z_new = zp + B1 f_new,   y = C zp + G f_new (+ exo)

    with ``G = C B1 + D``; ``f = a + u - w`` at the step's two ends.  The link's
    displacement increment is ``dexo[i] + y[link_row] - y_prev[link_row]``.  A lone
    rigid slider (``COULOMB``) with its velocity an output (`vel_row` >= 0, ``OPEN``)
    is solved at the velocity level in closed form
    (:func:`~motionhyst.hysteresis.stepping.coulomb_implicit`) instead of iterated.

    Two conventions of the implicit step, each that of the path it came from (their
    numbers unchanged): ``CLOSED`` (the closed loop's: the linear part's state before
    the update is ``zp``, ``B1 = 0``; the recorded link output is the displacement the
    elements were last advanced with; converged when ``w`` settles to `ftol` or the
    displacement to 1e-15 of itself, or stalls at round-off) and ``OPEN`` (the
    plant's: ``D = 0``, the outputs recorded from ``C z_new``; converged when ``w``
    settles to `ftol`, stalls within ``1e3 ftol`` or repeats the pass before last
    exactly (a two-cycle of rounding); sensitivities and the controller only here).

    Steps before `i_first` (global index ``i0 + i``) have length 0; step `i_first` is
    the elements' first (LuGre's rates from one step).  `fresh`: the state `z`, `s`
    (and `sx`, `ss`) is the start; ``w``, the previous outputs and the previous
    states are taken from it (else they are read from `scal`, `out_prev`, `s_prev`,
    `dvec`, as a previous call left them).  Sensitivities in ``P = sx.shape[1]``
    parameters, the linear part's first (``dA, dB0, dB1``, kind 0; ``C`` and ``D``
    constant), then the link's (``dparams``).

    Controller (``period > 0``, ``OPEN``): at the start of each period ``k`` (step
    ``i = k period``) ``y_k = y_prev[meas_row]``, ``u_k = Cc xc + Dc (r_k, y_k) +
    ff_k`` limited to `u_max`, ``xc = Ac xc + Bc (r_k, y_k)``; the queue `uq` holds
    ``u_k, u_{k-1}, ...``; the steps of kind 1 apply ``uq[n_delay + 1]``, the others
    ``uq[n_delay]``.

    Returns the outputs ``Y`` (records, p), their sensitivities ``SY`` (records, p, P),
    the link force ``W`` (records), the controller outputs ``U`` (periods), the most
    fixed-point passes a step took (``max_iter + 1``: a step failed; the run stopped
    there) and the number of steps run.
    """
    n_steps = a.shape[0] - 1
    n = z.shape[0]
    p = C.shape[0]
    m = codes.shape[0]
    P = sx.shape[1]
    npl = dA.shape[0]
    sens = P > 0
    nc = xc.shape[0]
    n_rec = n_steps // record_every + (1 if record_initial else 0)
    n_per = (n_steps + period - 1) // period if period > 0 else 0
    Y = np.zeros((n_rec, p))
    SY = np.zeros((n_rec, p, P))
    W = np.zeros(n_rec)
    U = np.zeros(n_per)
    zp = np.zeros(n)
    zn = np.zeros(n)
    xcn = np.zeros(nc)
    s_new = s.copy()
    ss_new = ss.copy()
    sxn = sx.copy()
    dw = np.zeros(P)
    ddx = np.zeros(P)
    pds = np.zeros((m, N_PARTIALS))
    pdf = np.zeros((m, N_PARTIALS))
    dw_prev = dvec[0]
    ddx_prev = dvec[1]
    dout_prev = dvec[2]
    if fresh:
        w0 = 0.0
        for j in range(m):
            s_prev[j] = s[j]
            if not sens:
                w0 += advance(codes[j], params[j], s[j], s[j], 0.0, 0.0, 0.0, 0.0, True, glt,
                              glw)[1]
            else:
                w0 += advance_partials(codes[j], params[j], s[j], s[j], 0.0, 0.0, 0.0, 0.0,
                                       True, pds[j], pdf[j])[1]
        scal[0] = w0
        scal[1] = 0.0
        scal[2] = 0.0
        for b in range(P):
            dw_prev[b] = 0.0
            ddx_prev[b] = 0.0
        if sens:
            for j in range(m):
                for b in range(P):
                    ss_prev[j, b] = ss[j, b]
                    dw_prev[b] += (pdf[j, 0] + pdf[j, 1]) * ss[j, b]
                for b in range(npl, P):
                    for lp in range(N_PARAMS):
                        dw_prev[b] += pdf[j, 4 + lp] * dparams[j, lp, b - npl]
        for o in range(p):
            acc = 0.0
            for q in range(n):
                acc += C[o, q] * z[q]
            out_prev[o] = acc
        for b in range(P):
            acc = 0.0
            for q in range(n):
                acc += C[link_row, q] * sx[q, b]
            dout_prev[b] = acc
        for q in range(nc):
            xc[q] = 0.0
        for q in range(uq.shape[0]):
            uq[q] = 0.0
    w_prev = scal[0]
    dx_prev = scal[1]
    h_prev = scal[2]
    if record_initial:
        for o in range(p):
            Y[0, o] = out_prev[o]
            for b in range(P):
                acc = 0.0
                for q in range(n):
                    acc += C[o, q] * sx[q, b]
                SY[0, o, b] = acc
        W[0] = w_prev
    worst = 0
    u_app = 0.0
    rigid = vel_row >= 0 and m == 1 and codes[0] == COULOMB  # the step in closed form
    v_end = 0.0
    for i in range(n_steps):
        gi = i0 + i
        kind = 0
        if period > 0:
            jp = i % period
            if jp == 0:  # the controller's sample: measure, compute, queue
                k = i // period
                y_k = out_prev[meas_row]
                u_k = ff[k] + Dc[0] * ref[k] + Dc[1] * y_k
                for q in range(nc):
                    u_k += Cc[q] * xc[q]
                if u_k > u_max:
                    u_k = u_max
                elif u_k < -u_max:
                    u_k = -u_max
                for q in range(nc):
                    acc = Bc[q, 0] * ref[k] + Bc[q, 1] * y_k
                    for c in range(nc):
                        acc += Ac[q, c] * xc[c]
                    xcn[q] = acc
                for q in range(nc):
                    xc[q] = xcn[q]
                for q in range(uq.shape[0] - 1, 0, -1):
                    uq[q] = uq[q - 1]
                uq[0] = u_k
                U[k] = u_k
            if jp < r1:
                kind = 1
                u_app = uq[n_delay + 1]
            else:
                u_app = uq[n_delay]
        h = hs[kind] if gi >= i_first else 0.0
        first = gi == i_first
        f_old = a[i] + u_app - w_prev if period > 0 else a[i] - w_prev
        a_new = a[i + 1] + u_app if period > 0 else a[i + 1]
        # the linear part's prediction without this step's input
        if convention == CLOSED:
            for q in range(n):
                acc = B0[kind, q] * f_old
                for c in range(n):
                    acc += A[kind, q, c] * z[c]
                zp[q] = acc
        else:
            for q in range(n):
                acc = A[kind, q, 0] * z[0]
                for c in range(1, n):
                    acc += A[kind, q, c] * z[c]
                zp[q] = acc + B0[kind, q] * f_old
        pre = 0.0 if exo.shape[0] == 0 else exo[i, link_row]
        for q in range(n):
            pre += C[link_row, q] * zp[q]
        gl = G[kind, link_row]
        dr = 0.0 if dexo.shape[0] == 0 else dexo[i]
        wt = w_prev
        it = 0
        if convention == CLOSED:
            d = pre + gl * (a_new - wt)
            step_prev = np.inf
            while True:
                it += 1
                dx = dr + (d - out_prev[link_row])
                wn = 0.0
                for j in range(m):
                    s_new[j], fj = advance(codes[j], params[j], s[j], s_prev[j], dx, dx_prev, h,
                                           h_prev, first, glt, glw)
                    wn += fj
                d_next = pre + gl * (a_new - wn)
                step_w = abs(wn - wt)
                step_d = abs(d_next - d)
                scale_d = abs(d) + abs(dx)
                done = (step_w <= ftol or step_d <= 1e-15 * scale_d
                        or (it >= 3 and step_w >= 0.5 * step_prev and step_d <= 1e-12 * scale_d))
                step_prev = step_w
                wt = wn
                if done or m == 0:
                    break  # d: the displacement the elements were advanced with
                d = d_next
                if it > max_iter:
                    break
            dx = dr + (d - out_prev[link_row])
        else:
            base = pre + gl * a_new
            change = math.inf
            w_back = math.nan  # the force two passes back
            if rigid:  # the velocity at the step's end without the link force, then with it
                a_v = 0.0
                for q in range(n):
                    a_v += C[vel_row, q] * zp[q]
                a_v = a_v + G[kind, vel_row] * a_new
                wt, v_end = coulomb_implicit(params[0], a_v, G[kind, vel_row])
                s_new[0] = wt
                it = 1
            while not rigid:
                it += 1
                dx = dr + (base - gl * wt - out_prev[link_row])
                wn = 0.0
                if not sens:
                    for j in range(m):
                        s_new[j], fj = advance(codes[j], params[j], s[j], s_prev[j], dx,
                                               dx_prev, h, h_prev, first, glt, glw)
                        wn += fj
                else:  # the same states and forces, and their partials
                    for j in range(m):
                        s_new[j], fj = advance_partials(codes[j], params[j], s[j], s_prev[j],
                                                        dx, dx_prev, h, h_prev, first, pds[j],
                                                        pdf[j])
                        wn += fj
                # converged, or stalled at the rounding floor (a contraction's changes stop
                # falling only there: rate terms such as LuGre's sigma1 z' amplify the
                # rounding of dx by ~ sigma1 / h), or caught in a two-cycle of rounding (a
                # stiff element turns the last bit of dx into more than that floor: the
                # passes repeat exactly, and would forever)
                last = change
                change = abs(wn - wt)
                done = (change <= ftol or m == 0 or (change <= 1e3 * ftol and change >= last)
                        or wn == w_back)
                w_back = wt
                wt = wn
                if done or it > max_iter:
                    break
            dx = dr + (base - gl * wt - out_prev[link_row])
            d = 0.0
        if it > worst:
            worst = it
        if it > max_iter:
            return Y, SY, W, U, worst, i
        f_new = a_new - wt
        if sens:  # the partials of the last pass (at the converged point to rounding)
            w_dx = 0.0
            for j in range(m):
                w_dx += pdf[j, 2]
            # the linear step in the sensitivities but for this step's link force:
            # A sx - B0 dw_prev, and dA z + dB0 f_old + dB1 f_new in the linear parameters
            for q in range(n):
                for b in range(P):
                    sxn[q, b] = -B0[kind, q] * dw_prev[b]
                for c in range(n):
                    aqc = A[kind, q, c]
                    for b in range(P):
                        sxn[q, b] += aqc * sx[c, b]
                for b in range(npl):
                    t = dB0[b, q] * f_old + dB1[b, q] * f_new
                    for c in range(n):
                        t += dA[b, q, c] * z[c]
                    sxn[q, b] += t
            # the link force's change: the elements' partials in their states, their
            # previous displacement and their parameters, then through dx (implicit)
            for b in range(P):
                dw[b] = 0.0
            for j in range(m):
                c0, c1, c3 = pdf[j, 0], pdf[j, 1], pdf[j, 3]
                for b in range(P):
                    dw[b] += c0 * ss[j, b] + c1 * ss_prev[j, b] + c3 * ddx_prev[b]
                for lp in range(N_PARAMS):
                    cp = pdf[j, 4 + lp]
                    if cp != 0.0:
                        for b in range(npl, P):
                            dw[b] += cp * dparams[j, lp, b - npl]
            for b in range(P):
                acc = 0.0
                for q in range(n):
                    acc += C[link_row, q] * sxn[q, b]
                dbase = acc - dout_prev[b]  # of the displacement but for this step's dw
                if rigid:  # from v_end = a - G_v w (the velocity's own step)
                    gv = G[kind, vel_row]
                    da = 0.0
                    for q in range(n):
                        da += C[vel_row, q] * sxn[q, b]
                    if v_end == 0.0:  # stuck: v_end = 0 whatever the parameters
                        dw[b] = da / gv
                    else:
                        lp, cv = (0, params[0, 2]) if v_end > 0.0 else (1, params[0, 3])
                        dpar = 0.0
                        if b >= npl:
                            dpar = (dparams[0, lp, b - npl] * (1.0 if lp == 0 else -1.0)
                                    + dparams[0, lp + 2, b - npl] * v_end)
                        dw[b] = (dpar + cv * da) / (1.0 + cv * gv)
                else:
                    dw[b] = (dw[b] + w_dx * dbase) / (1.0 + w_dx * gl)
                ddx[b] = dbase - gl * dw[b]
            for q in range(n):
                for b in range(P):
                    sxn[q, b] -= B1[kind, q] * dw[b]
            for j in range(m):
                c0, c1, c2, c3 = pds[j, 0], pds[j, 1], pds[j, 2], pds[j, 3]
                for b in range(P):
                    ss_new[j, b] = (c0 * ss[j, b] + c1 * ss_prev[j, b] + c2 * ddx[b]
                                    + c3 * ddx_prev[b])
                for lp in range(N_PARAMS):
                    cp = pds[j, 4 + lp]
                    if cp != 0.0:
                        for b in range(npl, P):
                            ss_new[j, b] += cp * dparams[j, lp, b - npl]
            for q in range(n):
                for b in range(P):
                    sx[q, b] = sxn[q, b]
            for j in range(m):
                for b in range(P):
                    ss_prev[j, b] = ss[j, b]
                    ss[j, b] = ss_new[j, b]
            for b in range(P):
                dw_prev[b] = dw[b]
                ddx_prev[b] = ddx[b]
                acc = 0.0
                for q in range(n):
                    acc += C[link_row, q] * sx[q, b]
                dout_prev[b] = acc
        # the step's outputs and the new state
        if convention == CLOSED:
            for o in range(p):
                if o == link_row:
                    out_prev[o] = d
                else:
                    acc = 0.0 if exo.shape[0] == 0 else exo[i, o]
                    for q in range(n):
                        acc += C[o, q] * zp[q]
                    out_prev[o] = acc + G[kind, o] * f_new
            for q in range(n):
                z[q] = zp[q] + B1[kind, q] * f_new
        else:
            for q in range(n):
                zn[q] = zp[q] + B1[kind, q] * f_new
            for q in range(n):
                z[q] = zn[q]
            for o in range(p):
                acc = 0.0
                for q in range(n):
                    acc += C[o, q] * z[q]
                out_prev[o] = acc
        for j in range(m):
            s_prev[j] = s[j]
            s[j] = s_new[j]
        w_prev = wt
        dx_prev = dx
        h_prev = h
        scal[0] = w_prev
        scal[1] = dx_prev
        scal[2] = h_prev
        if (i + 1) % record_every == 0:
            o_i = (i + 1) // record_every - (0 if record_initial else 1)
            for o in range(p):
                Y[o_i, o] = out_prev[o]
                for b in range(P):
                    acc = 0.0
                    for q in range(n):
                        acc += C[o, q] * sx[q, b]
                    SY[o_i, o, b] = acc
            W[o_i] = wt
    return Y, SY, W, U, worst, n_steps
