"""The Bouc-Wen model in a normalised, rate-independent form.

Bouc, R. (1967), "Forced vibrations of mechanical systems with hysteresis",
Proc. 4th Conference on Nonlinear Oscillations, Prague.
Wen, Y.-K. (1976), "Method for random vibration of hysteretic systems",
J. Eng. Mech. Div. ASCE 102(2), 249-263.
Ismail, M., Ikhouane, F. and Rodellar, J. (2009), "The hysteresis Bouc-Wen
model, a survey", Arch. Comput. Methods Eng. 16, 161-188.
Ikhouane, F. and Rodellar, J. (2007), "Systems with Hysteresis", Wiley (ch. 2:
bounded, thermodynamically admissible parameter classes).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis._ode_kernels import (
    GL_T,
    GL_W,
    NormalisedRateIndependent,
    bouc_wen_path,
)
from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import BOUC_WEN, Stepping


def _check_finite(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


@register
class BoucWen(NormalisedRateIndependent, Hysteresis):
    """Bouc-Wen hysteresis (Bouc 1967, Wen 1976), normalised, rate-independent.

    .. math::

        w = f_c z, \\qquad
        \\frac{dz}{dx} = \\frac{k}{f_c}\\left[1 - \\left(\\beta\\,
        \\mathrm{sign}(\\dot x z) + \\gamma\\right) |z|^n\\right].

    This is the classical ``z' = A x' - beta |x'| |z|^(n-1) z - gamma x' |z|^n``
    (Ismail et al. 2009, eq. 1, without the parallel linear spring) with
    ``A = k / fc``, ``beta_c = beta k / fc``, ``gamma_c = gamma k / fc`` and the
    force ``fc z``, so that

    * the stiffness at ``w = 0`` (the initial stiffness) is ``k``;
    * in a long monotone motion ``|z|`` tends to ``z_u = (beta + gamma)^(-1/n)``,
      i.e. the force saturates at ``fc`` when ``beta + gamma = 1``;
    * ``n`` sets the sharpness of the transition (``n -> inf`` with
      ``beta = gamma = 1/2`` gives the Jenkins element of paper eq. 3);
    * the loading stiffness is ``k (1 - (beta + gamma) |z|^n)``, the unloading
      stiffness ``k (1 + (beta - gamma) |z|^n)`` (``= k`` for ``beta = gamma``).

    The parameters must satisfy ``beta + gamma > 0`` and ``beta - gamma >= 0``
    (class I of Ikhouane and Rodellar 2007: bounded and dissipative); then
    ``D`` has ``Im D >= 0``.  The element is rate-independent, integrated in
    ``x``: exactly (piecewise exponentials) for ``n = 1``, by RK4 sub-steps of
    at most ``0.02 / max(1, n (beta + gamma)^(1/n))`` in ``k x / fc`` otherwise,
    with the crossing of ``z = 0`` (a kink of the right-hand side) located by
    Gauss-Legendre quadrature.

    Parameters
    ----------
    k : float
        Initial stiffness [N/m], > 0.
    fc : float
        Force scale [N], > 0: the saturation force when ``beta + gamma = 1``.
    n : float
        Smoothness exponent [-], >= 1.
    beta, gamma : float
        Shape parameters [-]; ``beta + gamma > 0`` and ``beta >= gamma``.

    Examples
    --------
    >>> from motionhyst.hysteresis.bouc_wen import BoucWen
    >>> el = BoucWen(k=20.0, fc=0.05)
    >>> el.saturation_force
    0.05
    >>> round(abs(el.describing_function(1e-7)) / el.k, 6)
    1.0
    """

    name = "bouc-wen"
    rate_independent = True
    parameters = (Parameter("k", "N/m", "spring stiffness k"),
                  Parameter("fc", "N", "slip (Coulomb) force f_c"),
                  Parameter("n", "", "sharpness n >= 1", 1.0, "finite"),
                  Parameter("beta", "", "beta", 0.5, "finite"),
                  Parameter("gamma", "", "gamma, <= beta", 0.5, "finite"))
    #: RK4 step in ``k x / fc`` for ``n != 1``, divided by ``max(1, n (beta + gamma)^(1/n))``
    rk4_step = 0.02

    def __init__(self, k: float, fc: float, n: float = 1.0, beta: float = 0.5,
                 gamma: float = 0.5) -> None:
        super().__init__()
        self.k = check_positive("k", k)
        self.fc = check_positive("fc", fc)
        self.n = _check_finite("n", n)
        if self.n < 1.0:
            raise ValueError(f"n must be >= 1, got {n!r}")
        self.beta = _check_finite("beta", beta)
        self.gamma = _check_finite("gamma", gamma)
        if not self.beta + self.gamma > 0:
            raise ValueError(f"beta + gamma must be > 0 (bounded hysteresis), got "
                             f"beta={beta!r}, gamma={gamma!r}")
        if not self.beta - self.gamma >= 0:
            raise ValueError(f"beta must be >= gamma (dissipative loops), got "
                             f"beta={beta!r}, gamma={gamma!r}")
        self.reset()

    def __repr__(self) -> str:
        return (f"BoucWen(k={self.k!r}, fc={self.fc!r}, n={self.n!r}, beta={self.beta!r}, "
                f"gamma={self.gamma!r})")

    @property
    def initial_stiffness(self) -> float:
        """Stiffness ``k`` at ``z = 0`` [N/m]: the small-motion limit of ``D``."""
        return self.k

    @property
    def z_max(self) -> float:
        """Bound ``z_u = (beta + gamma)^(-1/n)`` of the normalised state [-]."""
        return float((self.beta + self.gamma) ** (-1.0 / self.n))

    @property
    def saturation_force(self) -> float:
        """Force approached in a long monotone motion, ``fc z_u`` [N]."""
        return self.fc * self.z_max

    def _step(self) -> float:
        lam = self.n * (self.beta + self.gamma) ** (1.0 / self.n)
        return self.rk4_step / max(1.0, lam)

    def _path(self, u: NDArray[np.float64], s0: float) -> NDArray[np.float64]:
        return bouc_wen_path(u, float(s0), self.n, self.beta + self.gamma,
                             self.beta - self.gamma, self._step(), GL_T, GL_W)

    def _state_bounds(self) -> tuple[float, float]:
        z = self.z_max
        return -z, z

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Describing function ``D = (b1 + j a1) / A`` (paper eq. 7) at amplitude(s) `A` [N/m].

        From the periodic output (:meth:`periodic_harmonics`); about 1e-10
        relative for ``n = 1``, cached per amplitude.  `omega` is ignored
        (rate-independent); the result is broadcast against it.  ``A = 0``
        gives ``k``.
        """
        return self._describing_function(check_amplitudes(A), omega)

    def response(self, x: ArrayLike, w0: float = 0.0) -> NDArray[np.float64]:
        """Force for a sampled displacement (motion taken as monotone between samples).

        Independent of the sampling instants (rate-independent); exact for
        ``n = 1`` and converged to RK4 accuracy (about 1e-10) otherwise.

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Force at the first sample [N], ``|w0| <= fc z_u`` (:attr:`saturation_force`).

        Returns
        -------
        ndarray
            Force at each sample [N].
        """
        xs = self._validated_path(x)
        w_max = self.saturation_force
        if not abs(w0) <= w_max * (1.0 + 1e-12):
            raise ValueError(f"|w0| must be <= the saturation force {w_max}, got {w0}")
        if xs.size == 0:
            return np.empty(0)
        u = (self.k / self.fc) * (xs - xs[0])
        return self.fc * self._path(u, float(w0) / self.fc)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None, *, n_samples: int | None = None
                           ) -> NDArray[np.complex128]:
        """Harmonics ``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic output.

        The period is sampled uniformly (`n_samples`, default
        :meth:`default_samples`) with the input's reversal points inserted; the
        model is integrated along the path from the state that repeats after
        one period (a scalar fixed point, secant steps to 1e-14 of the loop's
        range) and the samples are transformed by an FFT.  `omega` is ignored.
        """
        return self._harmonics(X, n_harmonics, n_samples)

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        p = (self.k / self.fc, self.fc, self.n, self.beta + self.gamma, self.beta - self.gamma,
             self._step())
        return Stepping.from_rows([(BOUC_WEN, p)], self.saturation_force)

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "k": self.k, "fc": self.fc, "n": self.n,
                "beta": self.beta, "gamma": self.gamma}

