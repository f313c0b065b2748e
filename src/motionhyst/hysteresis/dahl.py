"""The Dahl solid-friction model: a smooth, rate-independent hysteresis.

Dahl, P. R. (1968), "A solid friction model", Technical Report
TOR-0158(3107-18)-1, The Aerospace Corporation, El Segundo, CA.
See also Dahl (1976), "Solid friction damping of mechanical vibrations",
AIAA Journal 14(12), 1675-1682.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis._ode_kernels import dahl_path
from motionhyst.hysteresis._ode_periodic import NormalisedRateIndependent
from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import DAHL, Stepping

__all__ = ["Dahl"]


@register
class Dahl(NormalisedRateIndependent, Hysteresis):
    """Dahl friction element (Dahl 1968), displacement ``x`` in, force ``w`` out.

    .. math::

        \\frac{dw}{dt} = k \\left(1 - \\frac{w}{f_c}\\,\\mathrm{sign}(\\dot x)\\right)^{\\alpha}
        \\dot x ,

    i.e. ``dw/dx = k (1 - sign(dx) w / fc)^alpha``.  Time enters only through
    ``dx``, so the element is rate-independent (``rate_independent = True``):
    its output depends on the path of ``x`` only and its describing function
    on the amplitude only.  The stiffness is ``k`` at ``w = 0`` and falls to
    zero as ``|w| -> fc`` (the Coulomb force); after a reversal it is
    ``k (1 + |w| / fc)^alpha``, up to ``2^alpha k``.  ``alpha -> 0`` gives the
    Jenkins element of paper eq. (3); ``alpha = 1`` is the LuGre model without
    damping and Stribeck effect.

    On a monotone piece ``zeta = sign(dx) w / fc`` obeys
    ``dzeta/dv = (1 - zeta)^alpha`` with ``v = k |dx| / fc``, solved in closed
    form: ``1 - zeta = (1 - zeta_0) exp(-v)`` for ``alpha = 1`` and
    ``1 - zeta = (1 - zeta_0) (1 + (alpha - 1) v (1 - zeta_0)^(alpha - 1))^(-1 / (alpha - 1))``
    otherwise (zero once the bracket reaches zero, ``alpha < 1``).  The sampled
    response is therefore exact for motion monotone between samples.

    Parameters
    ----------
    k : float
        Stiffness at zero force ``sigma`` (Dahl's rest stiffness) [N/m], > 0.
    fc : float
        Coulomb (saturation) force [N], > 0.
    alpha : float
        Shape exponent ``i`` of Dahl's model [-], > 0 (1 in most uses).  A scenario and
        ``motionhyst df`` take at most :attr:`ALPHA_MAX`: past ``alpha = 1`` the force needs
        a travel of ``(2^(alpha - 1) - 1) / (alpha - 1) fc / k`` to reach ``fc / 2`` (57
        ``fc / k`` at 10, 6e27 at 100), and past about 1e15 the closed form below loses every
        digit, so a larger one is a slip, not a link.

    Examples
    --------
    >>> from motionhyst.hysteresis.dahl import Dahl
    >>> el = Dahl(k=20.0, fc=0.05)
    >>> D = el.describing_function(1e-6)          # small motion: a spring k
    >>> round(D.real, 4), round(D.imag, 4)
    (20.0, 0.0)
    """

    name = "dahl"
    n_states = 1
    rate_independent = True
    ALPHA_MAX = 100.0
    """The largest shape exponent a scenario or ``motionhyst df`` takes (see `alpha`)."""
    parameters = (Parameter("k", "N/m", "spring stiffness k"),
                  Parameter("fc", "N", "slip (Coulomb) force f_c"),
                  Parameter("alpha", "", "shape exponent alpha (dahl: at most 100)", 1.0,
                            maximum=ALPHA_MAX))

    def __init__(self, k: float, fc: float, alpha: float = 1.0) -> None:
        super().__init__()
        self.k = check_positive("k", k)
        self.fc = check_positive("fc", fc)
        self.alpha = check_positive("alpha", alpha)
        self.reset()

    def __repr__(self) -> str:
        return f"Dahl(k={self.k!r}, fc={self.fc!r}, alpha={self.alpha!r})"

    @property
    def initial_stiffness(self) -> float:
        """Stiffness ``k`` at zero force [N/m]: the small-motion limit of ``D``."""
        return self.k

    @property
    def saturation_force(self) -> float:
        """Force approached in a long monotone motion, ``fc`` [N]."""
        return self.fc

    def _path(self, u: NDArray[np.float64], s0: float) -> NDArray[np.float64]:
        return dahl_path(u, float(s0), self.alpha)

    def _state_bounds(self) -> tuple[float, float]:
        return -1.0, 1.0

    def state_equation(self, z: ArrayLike, v: float
                       ) -> tuple[NDArray[np.float64], float, NDArray[np.float64],
                                  NDArray[np.float64], NDArray[np.float64], float]:
        """The model's state equation at the force `z` and the velocity `v`.

        ``z' = k (1 - sign(v) z / fc)^alpha v`` and ``w = z`` with their derivatives:
        what an autonomous loop's orbit and its monodromy need
        (:mod:`motionhyst.analysis.stability`).  At ``v = 0`` the one-sided derivatives
        of ``v > 0`` are taken (``z'`` is continuous there).

        Parameters
        ----------
        z : array_like, shape (1,)
            The force [N].
        v : float
            Velocity [m/s].

        Returns
        -------
        tuple
            ``(zdot, w, dzdot_dz, dzdot_dv, dw_dz, dw_dv)`` as
            :meth:`motionhyst.LuGre.state_equation` returns them; here ``w = z``.

        Examples
        --------
        >>> el = Dahl(k=20.0, fc=0.05)
        >>> zdot, w, *_ = el.state_equation([0.025], 0.01)   # half-way to fc: half of k v
        >>> round(float(zdot[0]), 12), w
        (0.1, 0.025)
        """
        zz = float(np.ravel(z)[0])
        s = 1.0 if v >= 0.0 else -1.0
        base = max(1.0 - s * zz / self.fc, 1e-12)
        p = base ** self.alpha
        dzz = -self.k * self.alpha * abs(v) * base ** (self.alpha - 1.0) / self.fc
        return (np.array([self.k * p * v]), zz, np.array([[dzz]]), np.array([self.k * p]),
                np.array([1.0]), 0.0)

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Numerical describing function ``D = (b1 + j a1) / A`` (eq. 7) at amplitude(s) `A` [N/m].

        Computed from the exact periodic output (:meth:`periodic_harmonics`),
        about 1e-10 relative; values are cached per amplitude.  `omega` is
        accepted for the common interface and ignored (rate-independent); the
        result is broadcast against it.  ``A = 0`` gives ``k``.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        omega : array_like, optional
            Angular frequency [rad/s]; ignored (rate-independent), the result is broadcast against
            it.
        """
        return self._describing_function(check_amplitudes(A), omega)

    def response(self, x: ArrayLike, w0: float = 0.0) -> NDArray[np.float64]:
        """Force for a sampled displacement, exact for motion monotone between samples.

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
        xs = self._validated_path(x)
        if not abs(w0) <= self.fc:
            raise ValueError(f"|w0| must be <= fc = {self.fc}, got {w0}")
        if xs.size == 0:
            return np.empty(0)
        u = (self.k / self.fc) * (xs - xs[0])
        return self.fc * dahl_path(u, float(w0) / self.fc, self.alpha)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None, *, n_samples: int | None = None
                           ) -> NDArray[np.complex128]:
        """Harmonics ``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic output.

        The period is sampled uniformly (`n_samples`, default
        :meth:`default_samples`) with the input's reversal points inserted; the
        exact segment solution is run from the state that repeats after one
        period (a scalar fixed point, found by secant steps to 1e-14 of the
        loop's range), and the samples are transformed by an FFT.  `omega` is
        ignored (rate-independent).

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency of the period [rad/s]; ignored (rate-independent).
        n_samples : int, optional
            Samples per period (default :meth:`default_samples`).
        """
        return self._harmonics(X, n_harmonics, n_samples)

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        return Stepping.from_rows([(DAHL, (self.k / self.fc, self.fc, self.alpha))], self.fc)

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "k": self.k, "fc": self.fc, "alpha": self.alpha}
