"""The least-squares problem of a measured plant's fit (:mod:`motionhyst.plants.frf_fit`).

The relative complex residuals of ``P1`` and ``P2`` for a rigid body plus modes and a
delay, their Jacobian, and the separable scan of candidate poles that starts each
mode; :func:`~motionhyst.plants.frf_fit.fit_frf` drives them."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.budget import check_memory
from motionhyst.plants.modal import TWO_PI

__all__ = ["DAMPING_BOUNDS", "FREQ_BOUNDS", "FrfProblem", "candidates"]

#: Damping ratios and frequency density of the start's scan.
_SCAN_DAMPING = (0.001, 0.003, 0.01, 0.03, 0.1, 0.2)
_SCAN_PER_DECADE = 50
#: Bytes the start's scan holds per line and candidate mode (its complex and real arrays).
_SCAN_BYTES = 136
#: Bounds of a fitted mode: damping ratio, and frequency relative to the measured range.
DAMPING_BOUNDS = (1e-5, 1.0)
FREQ_BOUNDS = (0.5, 10.0)


class FrfProblem:
    """Relative complex residuals of P1 and P2 and their Jacobian (real and imaginary parts).

    The parameters are ``ln M`` (unless the mass is given), the delay ``tau``
    [s] (when it is fitted) and ``ln w, ln z, r1, r2`` of each mode.  The
    delay is divided out of the data, ``(P_model - P_data e^{s tau}) /
    |P_data|``, which has the modulus of ``(P_model e^{-s tau} - P_data) /
    |P_data|``: the model itself stays the mechanics.
    """

    def __init__(self, f, p1, p2, mass, fit_delay: bool = False):
        self.f = f
        self.s = 1j * TWO_PI * f
        self.p1, self.p2 = p1, p2
        self.w1, self.w2 = 1.0 / np.abs(p1), 1.0 / np.abs(p2)
        self.mass = mass
        self.fit_delay = fit_delay
        self.n_head = int(mass is None) + int(fit_delay)

    def unpack(self, x: NDArray[np.float64], n: int):
        """``M, tau, w, z, r1, r2`` from the parameter vector `x` of `n` modes."""
        k = 0
        if self.mass is None:
            M, k = float(np.exp(x[0])), 1
        else:
            M = self.mass
        tau = 0.0
        if self.fit_delay:
            tau, k = float(x[k]), k + 1
        p = x[k:].reshape(n, 4) if n else np.zeros((0, 4))
        return M, tau, np.exp(p[:, 0]), np.exp(p[:, 1]), p[:, 2], p[:, 3]

    def pack(self, M, tau, wn, z, r1, r2) -> NDArray[np.float64]:
        """The parameter vector of :meth:`unpack`."""
        head = [np.log(M)] if self.mass is None else []
        head += [tau] if self.fit_delay else []
        body = np.column_stack([np.log(wn), np.log(z), r1, r2]).ravel() if len(wn) else []
        return np.concatenate([head, body])

    def data(self, tau: float):
        """The measured ``P1``, ``P2`` with the delay `tau` divided out, ``P e^{s tau}``."""
        if tau == 0.0:
            return self.p1, self.p2
        rot = np.exp(self.s * tau)
        return self.p1 * rot, self.p2 * rot

    def model(self, x, n):
        M, tau, wn, z, r1, r2 = self.unpack(x, n)
        s = self.s[:, None]
        g = 1.0 / (s**2 + 2 * z * wn * s + wn**2)
        pr = 1.0 / (M * self.s**2)
        return pr + g @ r1, pr - g @ r2, g, M, tau, wn, z, r1, r2

    def residuals(self, x, n):
        m1, m2, _, _, tau, *_ = self.model(x, n)
        d1, d2 = self.data(tau)
        c = np.concatenate([(m1 - d1) * self.w1, (m2 - d2) * self.w2])
        return np.concatenate([c.real, c.imag])

    def jacobian(self, x, n):
        _, _, g, M, tau, wn, z, r1, r2 = self.model(x, n)
        s = self.s[:, None]
        nf = self.f.size
        cols = []
        zero = np.zeros(nf, complex)
        if self.mass is None:
            dpr = -1.0 / (M * self.s**2)  # d/d ln M
            cols.append(np.concatenate([dpr * self.w1, dpr * self.w2]))
        if self.fit_delay:
            d1, d2 = self.data(tau)  # d/d tau of -P_data e^{s tau}
            cols.append(np.concatenate([-self.s * d1 * self.w1, -self.s * d2 * self.w2]))
        dg_dlnw = -(2 * z * wn * s + 2 * wn**2) * g**2
        dg_dlnz = -(2 * z * wn * s) * g**2
        for i in range(n):
            cols.append(np.concatenate([r1[i] * dg_dlnw[:, i] * self.w1,
                                        -r2[i] * dg_dlnw[:, i] * self.w2]))
            cols.append(np.concatenate([r1[i] * dg_dlnz[:, i] * self.w1,
                                        -r2[i] * dg_dlnz[:, i] * self.w2]))
            cols.append(np.concatenate([g[:, i] * self.w1, zero]))
            cols.append(np.concatenate([zero, -g[:, i] * self.w2]))
        J = np.array(cols).T
        return np.vstack([J.real, J.imag])

    def _fixed(self, wn, z, taus):
        """Columns of the linear parameters for fixed poles, and the data (one column per delay)."""
        s = self.s[:, None]
        nf = self.f.size
        fixed = []
        if self.mass is None:
            fixed.append(np.concatenate([self.w1 / self.s**2, self.w2 / self.s**2]))
        g = 1.0 / (s**2 + 2 * z * wn * s + wn**2)
        zero = np.zeros(nf, complex)
        for i in range(wn.size):
            fixed.append(np.concatenate([g[:, i] * self.w1, zero]))
            fixed.append(np.concatenate([zero, -g[:, i] * self.w2]))
        ys = []
        for tau in taus:
            d1, d2 = self.data(tau)
            y = np.concatenate([d1 * self.w1, d2 * self.w2])
            if self.mass is not None:
                pr = 1.0 / (self.mass * self.s**2)
                y = y - np.concatenate([self.w1 * pr, self.w2 * pr])
            ys.append(np.concatenate([y.real, y.imag]))
        F = np.array(fixed).T if fixed else np.zeros((2 * nf, 0), complex)
        return np.vstack([F.real, F.imag]), np.array(ys).T

    def linear_start(self, wn, z, extra=None, tau: float = 0.0):
        """Solve ``1/M`` and the residues for fixed poles; with `extra` candidate poles scanned.

        Returns ``(rss, a, r1, r2)`` for the fixed poles alone, or the index of the
        best candidate and its solution when `extra = (wn_c, z_c)` arrays are given.
        The data are taken with the delay `tau` divided out.
        """
        best, rss, coef = self._scan(wn, z, extra, (tau,))
        return (float(rss[0]), coef) if extra is None else (int(best[0]), float(rss[0]))

    def _scan(self, wn, z, extra, taus):
        """:meth:`linear_start` for every delay in `taus` at once: best candidates and RSS."""
        Fr, Y = self._fixed(wn, z, taus)
        if Fr.shape[1]:
            Q, _ = np.linalg.qr(Fr)
        else:
            Q = np.zeros((Y.shape[0], 0))
        if Y.shape[1] == 1:
            y = Y[:, 0]
            y_perp = (y - Q @ (Q.T @ y))[:, None]
        else:
            y_perp = Y - Q @ (Q.T @ Y)
        rss0 = np.einsum("rt,rt->t", y_perp, y_perp)
        if extra is None:
            coef = np.linalg.lstsq(Fr, Y[:, 0], rcond=None)[0] if Fr.shape[1] else np.zeros(0)
            return None, rss0, coef
        s = self.s[:, None]
        wc, zc = extra
        check_memory(_SCAN_BYTES * s.size * np.size(wc), f"the scan of {np.size(wc)} candidate "
                     f"modes over {s.size} lines", "thin the measured lines")
        gc = 1.0 / (s**2 + 2 * zc * wc * s + wc**2)  # (nf, ncand)
        g1, g2 = gc * self.w1[:, None], -gc * self.w2[:, None]
        zr = np.zeros_like(g1.real)
        G1 = np.concatenate([g1.real, zr, g1.imag, zr])  # rows ordered as the data
        G2 = np.concatenate([zr, g2.real, zr, g2.imag])
        if Q.shape[1]:
            # einsum, not BLAS: thin products, where BLAS threads only add overhead
            G1 -= np.einsum("rk,kc->rc", Q, np.einsum("rk,rc->kc", Q, G1))
            G2 -= np.einsum("rk,kc->rc", Q, np.einsum("rk,rc->kc", Q, G2))
        a11 = np.einsum("rc,rc->c", G1, G1)
        a22 = np.einsum("rc,rc->c", G2, G2)
        a12 = np.einsum("rc,rc->c", G1, G2)
        if Y.shape[1] == 1:
            b1, b2 = (y_perp[:, 0] @ G1)[None, :], (y_perp[:, 0] @ G2)[None, :]
        else:
            b1, b2 = y_perp.T @ G1, y_perp.T @ G2  # (ntau, ncand)
        det = a11 * a22 - a12**2
        with np.errstate(divide="ignore", invalid="ignore"):
            gain = (a22 * b1**2 - 2 * a12 * b1 * b2 + a11 * b2**2) / det
        gain[~np.isfinite(gain)] = -np.inf
        best = np.argmax(gain, axis=1)
        return best, rss0 - gain[np.arange(best.size), best], None


def candidates(f: NDArray[np.float64]):
    """Poles of the start's scan: frequencies and damping ratios (flattened grid)."""
    lo, hi = f.min() * FREQ_BOUNDS[0], f.max() * 3.0
    n_grid = int(np.ceil(_SCAN_PER_DECADE * np.log10(hi / lo))) + 1
    wc = TWO_PI * np.geomspace(lo, hi, n_grid)
    zc = np.asarray(_SCAN_DAMPING)
    W, Z = (a.ravel() for a in np.meshgrid(wc, zc))
    return W, Z
