"""The state-space realisation of a plant with lumped masses, which the time engine runs.

``M q'' + C q' + K q = e (u + f0 - w)``: the masses ``M`` (diagonal), the
damping ``C`` and stiffness ``K`` between the coordinates ``q`` and to the
ground, the force ``u`` with a constant offset ``f0`` and the link force ``w``
acting on the coordinate ``e`` (the link's displacement), one coordinate the
output.  Every plant with inertia gives its own (:meth:`Plant.mechanics
<motionhyst.plants.registry.Plant.mechanics>`), with the derivatives of the
matrices in its parameters that the forward sensitivities need.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Mechanics"]


class Mechanics:
    """A linear mechanical plant with lumped masses: ``M q'' + C q' + K q = e_l (u + f0 - w)``.

    The state-space form of an open-loop plant, ``x = (q, q')``,
    ``x' = A x + B (u + f0 - w)`` with ``A = [[0, I], [-M^-1 K, -M^-1 C]]`` and
    ``B = [0; M^-1 e_l]``: the force ``u`` and the link force ``w`` act on the
    coordinate ``q[link]`` (the link's displacement), the output is
    ``q[output]``; ``f0`` is a constant force offset, which the matrices
    leave out (the time engine adds it to the force).  The plant's parameters
    enter ``M``, ``C`` and ``K`` linearly; their derivatives are what the
    forward sensitivities need.

    Parameters
    ----------
    mass : array_like, shape (n,)
        Diagonal of ``M`` [kg].
    C, K : array_like, shape (n, n)
        Damping [N s/m] and stiffness [N/m] matrices.
    dmass, dC, dK : array_like, shapes (p, n), (p, n, n), (p, n, n)
        Their derivatives in the plant's `p` parameters.
    link, output : int
        Coordinate of the force and link, and of the output.
    force_offset : float
        The constant force ``f0`` added to the force on ``q[link]`` [N].
    c_skew : float
        Viscous friction by direction on ``q[link]`` [N s/m]: the force ``c_skew |q'[link]|``
        against the motion beside ``C``'s, so that a damper ``c`` of ``C`` on that
        coordinate acts as ``c + c_skew`` moving forward and ``c - c_skew`` backward (not in
        the matrices: the time engine adds it to the link's elements,
        :meth:`~motionhyst.hysteresis.stepping.Stepping.with_viscous`).

    Examples
    --------
    >>> from motionhyst.time.openloop import TwoMass
    >>> mech = TwoMass(m1=2.0, m2=3.0, b=20.0, k=2e5).mechanics()
    >>> A, B = mech.state_space()
    >>> A.shape, B.tolist(), mech.link, mech.output
    ((4, 4), [0.0, 0.0, 0.5, 0.0], 0, 1)
    """

    def __init__(self, mass, C, K, dmass, dC, dK, link: int, output: int,
                 force_offset: float = 0.0, c_skew: float = 0.0) -> None:
        self.mass = np.ascontiguousarray(mass, dtype=float)
        self.C = np.ascontiguousarray(C, dtype=float)
        self.K = np.ascontiguousarray(K, dtype=float)
        self.dmass = np.ascontiguousarray(dmass, dtype=float)
        self.dC = np.ascontiguousarray(dC, dtype=float)
        self.dK = np.ascontiguousarray(dK, dtype=float)
        self.link = int(link)
        self.output = int(output)
        self.force_offset = float(force_offset)
        self.c_skew = float(c_skew)

    @property
    def n(self) -> int:
        """Number of coordinates ``q``."""
        return self.mass.size

    @property
    def floating(self) -> bool:
        """True if no spring holds the plant to the ground (``K`` times ones is zero)."""
        return bool(np.all(self.K.sum(axis=1) == 0.0))

    def state_space(self, k_link: float = 0.0, c_link: float = 0.0
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``A`` and ``B`` (``x = (q, q')``), the link taken as a spring `k_link` and
        damper `c_link` to the ground (0: the link left out).

        Parameters
        ----------
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m] to the ground (0: left out).

        Returns
        -------
        tuple of ndarray
            ``A`` of shape (2n, 2n) and ``B`` of shape (2n,) (the force ``u - w`` enters on
            ``q[link]``).
        """
        n = self.n
        K = self.K.copy()
        C = self.C.copy()
        K[self.link, self.link] += k_link
        C[self.link, self.link] += c_link
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -K / self.mass[:, None]
        A[n:, n:] = -C / self.mass[:, None]
        B = np.zeros(2 * n)
        B[n + self.link] = 1.0 / self.mass[self.link]
        return A, B

    def foh(self, h: float, derivatives: bool = False) -> tuple[NDArray[np.float64], ...]:
        """The plant over a step `h` for a force linear over the step (first-order hold).

        ``x(t + h) = Ad x(t) + B0 f(t) + B1 f(t + h)`` exactly for ``f = u - w``
        linear over the step, from the exponential of ``[[A h, B h, 0], [0, 0, 1],
        [0, 0, 0]]`` (:func:`~motionhyst.core.lti.expm_small`; the link left out).

        Parameters
        ----------
        h : float
            Step [s].
        derivatives : bool
            Also the derivatives of ``Ad, B0, B1`` in the plant's `p` parameters
            (the rows of ``dmass, dC, dK``): Frechet derivatives of the
            exponential, each the corner of the exponential of a block matrix
            ``[[M, dM], [0, M]]``.

        Returns
        -------
        Ad, B0, B1 : ndarray, shapes (2n, 2n), (2n,), (2n,)
            The step's matrices.
        dAd, dB0, dB1 : ndarray, shapes (p, 2n, 2n), (p, 2n), (p, 2n)
            Their derivatives (``p = 0``, empty, without `derivatives`).

        Examples
        --------
        >>> from motionhyst.time.openloop import MassSpringDamper
        >>> mech = MassSpringDamper(2.0, 10.0, 5e4).mechanics()
        >>> Ad, B0, B1, dAd, dB0, dB1 = mech.foh(1e-4, derivatives=True)
        >>> eps = 1e-6   # d Ad / d k against a central difference
        >>> hi = MassSpringDamper(2.0, 10.0, 5e4 * (1 + eps)).mechanics().foh(1e-4)[0]
        >>> lo = MassSpringDamper(2.0, 10.0, 5e4 * (1 - eps)).mechanics().foh(1e-4)[0]
        >>> fd = (hi - lo) / (2 * 5e4 * eps)
        >>> bool(np.allclose(dAd[2], fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(fd))))
        True
        >>> mech.foh(1e-4)[3].shape
        (0, 2, 2)
        """
        from motionhyst.core.lti import expm_small  # scipy: imported when a run needs it

        A, B = self.state_space()
        ns = A.shape[0]
        n = self.n
        M = np.zeros((ns + 2, ns + 2))
        M[:ns, :ns] = A * h
        M[:ns, ns] = B * h
        M[ns, ns + 1] = 1.0
        E = expm_small(M)
        B1 = np.ascontiguousarray(E[:ns, ns + 1])
        B0 = np.ascontiguousarray(E[:ns, ns] - B1)
        Ad = np.ascontiguousarray(E[:ns, :ns])
        p = self.dmass.shape[0] if derivatives else 0
        dAd = np.zeros((p, ns, ns))
        dB0 = np.zeros((p, ns))
        dB1 = np.zeros((p, ns))
        big = np.zeros((2 * ns + 4, 2 * ns + 4))
        big[:ns + 2, :ns + 2] = M
        big[ns + 2:, ns + 2:] = M
        for a in range(p):
            # d(-M^-1 K) = -M^-1 (dK - dM M^-1 K), likewise C; d(M^-1 e_l) = -M^-2 dM e_l
            rel = (self.dmass[a] / self.mass)[:, None]
            dM = np.zeros((ns + 2, ns + 2))
            dM[n:ns, :n] = -(self.dK[a] - rel * self.K) / self.mass[:, None] * h
            dM[n:ns, n:ns] = -(self.dC[a] - rel * self.C) / self.mass[:, None] * h
            dM[n + self.link, ns] = -self.dmass[a, self.link] / self.mass[self.link] ** 2 * h
            big[:ns + 2, ns + 2:] = dM
            dE = expm_small(big)[:ns + 2, ns + 2:]
            dAd[a] = dE[:ns, :ns]
            dB1[a] = dE[:ns, ns + 1]
            dB0[a] = dE[:ns, ns] - dE[:ns, ns + 1]
        return Ad, B0, B1, dAd, dB0, dB1

    def frequency_response(self, f_hz: ArrayLike, k_link: float = 0.0, c_link: float = 0.0
                           ) -> NDArray[np.complex128]:
        """``q[output] / u`` at `f_hz`, the link a spring `k_link` and damper `c_link`.

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz].
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m] to the ground (0: left out).

        Returns
        -------
        ndarray of complex
            [m/N], one per frequency.
        """
        s = 2j * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
        K = self.K.astype(complex)
        C = self.C.astype(complex)
        K[self.link, self.link] += k_link
        C[self.link, self.link] += c_link
        Z = (np.diag(self.mass)[None] * s[:, None, None] ** 2 + C[None] * s[:, None, None]
             + K[None])
        e = np.zeros(self.n, dtype=complex)
        e[self.link] = 1.0
        x = np.linalg.solve(Z, np.broadcast_to(e, (s.size, self.n))[..., None])[..., 0]
        return x[:, self.output]

    def linear_periodic_state(self, u: NDArray[np.float64], fs: float, k_link: float
                              ) -> NDArray[np.float64]:
        """``x = (q, q')`` at the start of the periodic steady state for the period `u`, the
        link a spring `k_link` to the ground (from the spectrum of `u`).

        Parameters
        ----------
        u : ndarray
            One period of the force [N], sampled at `fs`.
        fs : float
            Sampling rate [Hz].
        k_link : float
            The link taken as a spring to the ground [N/m].

        Returns
        -------
        ndarray, shape (2n,)
        """
        U = np.fft.rfft(u)
        f = np.fft.rfftfreq(u.size, 1.0 / fs)
        x = np.zeros(2 * self.n)
        K = self.K.copy()
        K[self.link, self.link] += k_link
        s = 2j * np.pi * f
        Z = np.diag(self.mass)[None] * s[:, None, None] ** 2 + self.C[None] * s[:, None, None] + K
        if np.linalg.cond(Z[0]) > 1e12:  # no spring to the ground: the mean left out
            Z[0] = np.eye(self.n)
            U = U.copy()
            U[0] = 0.0
        e = np.zeros(self.n)
        e[self.link] = 1.0
        H = np.linalg.solve(Z, np.broadcast_to(e, (f.size, self.n))[..., None].astype(complex))
        for i in range(self.n):
            Q = H[:, i, 0] * U
            x[i] = np.fft.irfft(Q, u.size)[0]
            x[self.n + i] = np.fft.irfft(s * Q, u.size)[0]
        return x

    def natural_frequency_hz(self, k_link: float = 0.0) -> float:
        """Highest undamped natural frequency, the link a spring `k_link` to the ground [Hz].

        Parameters
        ----------
        k_link : float
            The link taken as a spring to the ground [N/m].
        """
        K = self.K.copy()
        K[self.link, self.link] += k_link
        w2 = np.linalg.eigvals(K / self.mass[:, None]).real
        return math.sqrt(max(float(np.max(w2)), 0.0)) / (2 * math.pi)

    def decay_time(self, k_link: float = 0.0) -> float:
        """Slowest decay time of the modes, the link a spring `k_link` [s] (inf: undamped).

        Parameters
        ----------
        k_link : float
            The link taken as a spring to the ground [N/m] (negative values count as 0).
        """
        A, _ = self.state_space(max(k_link, 0.0))
        lam = np.linalg.eigvals(A)
        rate = -lam.real
        if not np.all(np.isfinite(lam)) or np.min(rate) <= 1e-12 * max(np.max(np.abs(lam)),
                                                                        1e-300):
            return math.inf
        return float(1.0 / np.min(rate))
