"""Stop operators at chosen samples, compiled: the columns of the Maxwell-slip fit.

The recursions of :mod:`motionhyst.hysteresis._kernels` (eqs. 1-3), run over every sample of
a record and kept only at the rows of a residual, so that a fit's memory grows with its rows,
not with the record times its parameters (:mod:`motionhyst.identify.fit`,
:mod:`motionhyst.identify.fd_bound`)."""

from __future__ import annotations

import numpy as np

from motionhyst.core.compiled import njit


@njit(cache=True)
def maxwell_at(x, k, fc, w0, rows):  # pragma: no cover - compiled
    """Parallel stop operators run over every sample of `x`, kept only at `rows` (ascending).

    Returns the element forces ``W``, the sign of each element's force at its
    latest saturation (``|w_i| >= fc_i``) and whether it has not saturated
    yet, all of shape ``(rows.size, k.size)``; the recursion is that of
    :func:`~motionhyst.hysteresis._kernels.maxwell_response`.
    """
    n = x.shape[0]
    m = k.shape[0]
    r = rows.shape[0]
    W = np.empty((r, m))
    sign = np.zeros((r, m))
    before = np.ones((r, m), dtype=np.bool_)
    w = w0.copy()
    last = np.zeros(m)
    seen = np.zeros(m, dtype=np.bool_)
    q = 0
    for i in range(n):
        if i > 0:
            dx = x[i] - x[i - 1]
            for j in range(m):
                wi = w[j] + k[j] * dx
                if wi > fc[j]:
                    wi = fc[j]
                elif wi < -fc[j]:
                    wi = -fc[j]
                w[j] = wi
        for j in range(m):
            if abs(w[j]) >= fc[j]:
                seen[j] = True
                last[j] = 1.0 if w[j] > 0 else (-1.0 if w[j] < 0 else 0.0)
        while q < r and rows[q] == i:
            for j in range(m):
                W[q, j] = w[j]
                sign[q, j] = last[j]
                before[q, j] = not seen[j]
            q += 1
    return W, sign, before


@njit(cache=True)
def stops_at(x, d, w0, rows, per_slip_force):  # pragma: no cover - compiled
    """Unit-stiffness stop operators of thresholds `d` from `w0`, kept only at `rows`.

    The recursion of :func:`~motionhyst.hysteresis._kernels.stop_response`
    with ``k = 1``; with `per_slip_force` each column is divided by its ``d``.
    """
    n = x.shape[0]
    m = d.shape[0]
    r = rows.shape[0]
    S = np.empty((r, m))
    for j in range(m):
        fc = d[j]
        wi = w0[j]
        q = 0
        for i in range(n):
            if i > 0:
                wi = wi + 1.0 * (x[i] - x[i - 1])
                if wi > fc:
                    wi = fc
                elif wi < -fc:
                    wi = -fc
            while q < r and rows[q] == i:
                S[q, j] = wi / fc if per_slip_force else wi
                q += 1
    return S
