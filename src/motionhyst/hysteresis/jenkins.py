"""The Jenkins (elasto-plastic) element: a spring in series with a Coulomb slider.

Paper section III-A (eq. 3) and III-B (eqs. 4-11).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import STOP, Stepping

__all__ = ["Jenkins", "jenkins_describing_function"]

# Taylor coefficients of asin(s) - s (1 - 2 s^2) sqrt(1 - s^2) in odd powers s^3, s^5, ...
_SMALL_ZETA_SERIES = np.array(
    [8.0 / 3.0, -4.0 / 5.0, -1.0 / 7.0, -1.0 / 18.0, -5.0 / 176.0, -7.0 / 416.0, -7.0 / 640.0]
)
_SMALL_ZETA = 1e-3


def _real_part_bracket(zeta: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(2 zeta - 1) sqrt(zeta (1 - zeta)) + gamma / 2 + pi / 4`` of eq. (10), for 0 <= zeta <= 1.

    With ``s = sqrt(zeta)`` this equals ``asin(s) - s (1 - 2 s^2) sqrt(1 - s^2)``; for small
    `zeta` its terms cancel, so a series is used there.
    """
    s = np.sqrt(zeta)
    c = np.sqrt(1.0 - zeta)
    direct = np.arctan2(s, c) - s * (1.0 - 2.0 * zeta) * c  # arctan2: well conditioned at 1
    series = s**3 * np.polynomial.polynomial.polyval(zeta, _SMALL_ZETA_SERIES)
    return np.where(zeta < _SMALL_ZETA, series, direct)


def jenkins_describing_function(k: float, zeta: ArrayLike) -> NDArray[np.complex128]:
    """Closed-form describing function of the Jenkins element, paper eq. (10).

    Parameters
    ----------
    k : float
        Spring stiffness ``k_J`` [N/m].
    zeta : array_like
        Dimensionless coefficient ``zeta = fc / (k_J A)`` of eq. (4), >= 0.

    Returns
    -------
    ndarray of complex
        ``D = k (2/pi) [(2 zeta - 1) sqrt(zeta (1 - zeta)) + gamma/2 + pi/4]
        + j k (4/pi) zeta (1 - zeta)`` for ``zeta < 1`` with
        ``gamma = arcsin(2 zeta - 1)`` (eq. 6), and ``D = k`` for ``zeta >= 1``
        (no slip).  ``D -> (4/pi) k zeta j`` as ``zeta -> 0`` (eq. 11).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import jenkins_describing_function
    >>> D = jenkins_describing_function(20.0, [0.25, 1.0, 2.0])    # k_J = 20 N/m
    >>> print(np.round(D, 4))                  # zeta = 0.25: the paper's |D| = 0.3 k_J, 50 deg
    [ 3.91+4.7746j 20.  +0.j     20.  +0.j    ]
    >>> small = complex(jenkins_describing_function(20.0, 1e-3))
    >>> print(f"{small.imag:.5f} vs eq. (11): {4 / np.pi * 20.0 * 1e-3:.5f}")
    0.02544 vs eq. (11): 0.02546
    """
    z = np.asarray(zeta, dtype=float)
    zc = np.clip(z, 0.0, 1.0)
    re = k * (2.0 / np.pi) * _real_part_bracket(zc)
    im = k * (4.0 / np.pi) * zc * (1.0 - zc)
    return np.where(z >= 1.0, k + 0j, re + 1j * im)


@register
class Jenkins(Hysteresis):
    """Elasto-plastic (Jenkins) element, paper eq. (3).

    A linear spring of stiffness `k` in series with a Coulomb slider that
    slips at force `fc`.  While ``|w| < fc`` the element is a spring; at
    ``|w| = fc`` the slider slips and the force stays at ``+-fc``.  The
    element is rate-independent.

    Parameters
    ----------
    k : float
        Spring stiffness ``k_J`` [N/m], > 0.
    fc : float
        Slip force ``f_c`` of the Coulomb element [N], > 0.

    Examples
    --------
    >>> import control
    >>> from motionhyst import Jenkins
    >>> el = Jenkins(k=20.0, fc=0.05)
    >>> el.zeta(0.01)
    0.25
    >>> D = control.describing_function(el, 0.01)
    >>> print(round(abs(D) / el.k, 3))
    0.309
    """

    name = "jenkins"
    rate_independent = True
    defines_zeta = True
    parameters = (Parameter("k", "N/m", "spring stiffness k"),
                  Parameter("fc", "N", "slip (Coulomb) force f_c"))

    def __init__(self, k: float, fc: float) -> None:
        super().__init__()
        self.k = check_positive("k", k)
        self.fc = check_positive("fc", fc)
        self.reset()

    def __repr__(self) -> str:
        return f"Jenkins(k={self.k!r}, fc={self.fc!r})"

    @property
    def initial_stiffness(self) -> float:
        """Spring stiffness ``k_J`` [N/m]."""
        return self.k

    @property
    def slip_displacement(self) -> float:
        """Spring elongation at slip, ``fc / k`` [m]; amplitudes below it never slip."""
        return self.fc / self.k

    def zeta(self, A: ArrayLike):
        """Dimensionless coefficient ``zeta = fc / (k A)``, paper eq. (4).

        ``A = 0`` gives ``inf`` (the element does not slip).

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        """
        a = check_amplitudes(A)
        with np.errstate(divide="ignore", over="ignore"):
            z = self.fc / (self.k * a)
        return float(z) if z.ndim == 0 else z

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Closed-form describing function at amplitude(s) `A`, paper eq. (10) [N/m].

        `omega` is accepted for the common interface and ignored: the element
        is rate-independent.  Returns a complex scalar for scalar `A`.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        omega : array_like, optional
            Angular frequency [rad/s]; ignored (rate-independent), the result is broadcast against
            it.
        """
        a = check_amplitudes(A)
        with np.errstate(divide="ignore", over="ignore"):
            z = self.fc / (self.k * a)
        d = jenkins_describing_function(self.k, z)
        if omega is not None:
            d = np.broadcast_to(d, np.broadcast_shapes(d.shape, np.shape(omega))).copy()
        return complex(d) if d.ndim == 0 else d

    def response(self, x: ArrayLike, w0: float = 0.0) -> NDArray[np.float64]:
        """Exact force for a sampled displacement: ``w <- clip(w + k dx, -fc, fc)``.

        Exact when the displacement is monotone between samples (the element
        is rate-independent, so the sampling instants do not matter).

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Force at the first sample [N], ``|w0| <= fc``.

        Returns
        -------
        ndarray
            Force at each sample [N].
        """
        from motionhyst.hysteresis._kernels import stop_response

        xs = np.ascontiguousarray(x, dtype=float)
        if xs.ndim != 1:
            raise ValueError("x must be one-dimensional")
        if not np.all(np.isfinite(xs)):
            raise ValueError("x must be finite")
        if not abs(w0) <= self.fc:
            raise ValueError(f"|w0| must be <= fc = {self.fc}, got {w0}")
        return stop_response(xs, self.k, self.fc, float(w0))

    def periodic_stops(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The element as one stop operator: ``([k], [fc])``."""
        return np.array([self.k]), np.array([self.fc])

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Exact harmonics of the periodic output (see :mod:`motionhyst.hysteresis.periodic`).

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency of the period [rad/s]; ignored (rate-independent).
        """
        from motionhyst.hysteresis.periodic import stop_periodic_harmonics

        return stop_periodic_harmonics(np.asarray(X, dtype=complex), self.k, self.fc, n_harmonics)

    def hosidf_closed_form(self, A: ArrayLike, n_max: int) -> NDArray[np.complex128]:
        """Higher-order describing functions ``H_n(A)``, n = 1 .. n_max, in closed form.

        For ``x = A sin(theta)`` and ``zeta < 1`` the periodic output is, from
        the maximum at ``theta = pi/2``: a spring ``fc - k A (1 - sin theta)``
        until ``theta_1 = pi - arcsin(1 - 2 zeta)`` (eq. 6), slip at ``-fc``
        until ``3 pi / 2``, a spring ``-fc + k A (1 + sin theta)`` until
        ``theta_3 = 2 pi - arcsin(1 - 2 zeta)``, and slip at ``+fc``.  Each piece
        is integrated against ``exp(-j n theta)`` exactly; ``H_1`` is eq. (10).
        Even harmonics are zero (half-wave symmetry); ``zeta >= 1`` gives
        ``H_1 = k`` only.  Terms of size ``k A`` cancel for small ``zeta``: the
        absolute accuracy is about ``1e-16 / zeta`` of ``|H_1|``.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        n_max : int
            Highest harmonic, >= 1.

        Returns
        -------
        ndarray of complex, shape ``A.shape + (n_max,)`` [N/m]
        """
        a = check_amplitudes(A)
        n = np.arange(1, int(n_max) + 1)
        if n.size == 0:
            raise ValueError("n_max must be >= 1")
        with np.errstate(divide="ignore", over="ignore"):
            zeta = self.fc / (self.k * a)
        z = np.clip(zeta, 0.0, 1.0)[..., None]
        kA = (self.k * a)[..., None]
        asn = np.arcsin(np.clip(1.0 - 2.0 * z, -1.0, 1.0))
        t0, t1, t2 = np.pi / 2, np.pi - asn, 1.5 * np.pi
        t3, t4 = 2 * np.pi - asn, 2.5 * np.pi

        def E(q, lo, hi):  # int_lo^hi exp(-j q theta) d theta, q integer
            q = np.broadcast_to(q, np.broadcast_shapes(np.shape(q), np.shape(lo)))
            safe = np.where(q == 0, 1, q)
            val = (np.exp(-1j * safe * lo) - np.exp(-1j * safe * hi)) / (1j * safe)
            return np.where(q == 0, hi - lo, val)

        def S(lo, hi):  # int sin(theta) exp(-j n theta)
            return (E(n - 1, lo, hi) - E(n + 1, lo, hi)) / 2j

        fc = self.fc
        total = ((fc - kA) * E(n, t0, t1) + kA * S(t0, t1) - fc * E(n, t1, t2)
                 + (kA - fc) * E(n, t2, t3) + kA * S(t2, t3) + fc * E(n, t3, t4))
        with np.errstate(divide="ignore", invalid="ignore"):
            H = 1j * total / (np.pi * a[..., None])
        linear = np.where(n == 1, self.k + 0j, 0j)
        return np.where((zeta >= 1.0)[..., None], linear, H)

    def ode_rhs(self, w: ArrayLike, xdot: ArrayLike):
        """Right-hand side ``dw/dt`` of the differential form, paper eq. (3).

        ``dw/dt = k xdot / 2 {1 - sign(w^2 - fc^2) - sign(xdot w) (1 + sign(w^2 - fc^2))}``.
        Discontinuous at ``|w| = fc``: general ODE solvers chatter on it, so
        motionhyst itself uses :meth:`response`.  Provided for comparison.

        Parameters
        ----------
        w : array_like
            Force of the element [N].
        xdot : array_like
            Velocity of the displacement [m/s].
        """
        w = np.asarray(w, dtype=float)
        xdot = np.asarray(xdot, dtype=float)
        s = np.sign(w**2 - self.fc**2)
        return 0.5 * self.k * xdot * (1.0 - s - np.sign(xdot * w) * (1.0 + s))

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        return Stepping.from_rows([(STOP, (self.k, self.fc))], self.fc)

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "k": self.k, "fc": self.fc}
