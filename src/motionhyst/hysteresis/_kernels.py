"""Compiled inner loops of the rate-independent elements (numba)."""

from __future__ import annotations

import numpy as np
from numba import njit


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
