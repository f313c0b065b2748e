"""The PID controller, the common case of a motion controller, continuous or sampled.

Parallel form with an optional first-order filter on the derivative and
optional notch filters in series::

    C(s) = (kp + ki / s + kd s / (1 + s / w_d)) prod_i N_i(s),   w_d = 2 pi derivative_filter_hz
    N_i(s) = (s^2 + 2 zeta_zero w_i s + w_i^2) / (s^2 + 2 zeta_pole w_i s + w_i^2)

Without ``derivative_filter_hz`` the derivative is pure (``kd s``): improper as
a continuous controller (it can be analysed in the frequency domain, not run),
and sampled as the backward difference ``kd (1 - z^-1) / T``, the difference of
two measured samples a real-time program takes; every other part is
discretised by the chosen method (:func:`motionhyst.controllers.sampled.discretize`).

Examples
--------
>>> from motionhyst.controllers.pid import Notch, Pid
>>> pid = Pid(kp=1e6, ki=2e7, kd=2e3, derivative_filter_hz=2000.0,
...           notches=(Notch(694.0, zeta_zero=0.02, zeta_pole=0.3),))
>>> pid.tf().den[0][0].size - 1                        # order: integrator, filter, notch
4
>>> c = pid.sampled(10e3, delay_samples=1.0)
>>> print(c)
sampled controller at 10000 Hz (T = 0.0001 s), 1 samples of delay, tustin of C(s)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from motionhyst.controllers.sampled import SampledController, discretize_coefficients

if TYPE_CHECKING:  # imported where used: a scenario's PID is checked without it
    import control

__all__ = ["Notch", "Pid"]


@dataclass(frozen=True)
class Notch:
    """A notch ``(s^2 + 2 zeta_zero w s + w^2) / (s^2 + 2 zeta_pole w s + w^2)``, ``w = 2 pi f``.

    Parameters
    ----------
    frequency_hz : float
        Centre frequency [Hz], > 0.
    zeta_zero : float
        Damping of the zeros, >= 0 (the depth is ``zeta_zero / zeta_pole``).
    zeta_pole : float
        Damping of the poles, > 0 (the width).

    Examples
    --------
    >>> from motionhyst.controllers.pid import Notch
    >>> n = Notch(100.0, 0.01, 0.5)
    >>> round(float(abs(n.tf()(2j * 3.141592653589793 * 100.0))), 6)   # depth at the centre
    0.02
    """

    frequency_hz: float
    zeta_zero: float = 0.01
    zeta_pole: float = 0.5

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0):
            raise ValueError(f"notch frequency_hz must be finite and > 0, got "
                             f"{self.frequency_hz!r}")
        if not (math.isfinite(self.zeta_zero) and self.zeta_zero >= 0):
            raise ValueError(f"notch zeta_zero must be finite and >= 0, got {self.zeta_zero!r}")
        if not (math.isfinite(self.zeta_pole) and self.zeta_pole > 0):
            raise ValueError(f"notch zeta_pole must be finite and > 0, got {self.zeta_pole!r}")

    def coefficients(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Numerator and denominator, highest power of ``s`` first."""
        w = 2.0 * math.pi * self.frequency_hz
        return (np.array([1.0, 2.0 * self.zeta_zero * w, w * w]),
                np.array([1.0, 2.0 * self.zeta_pole * w, w * w]))

    def tf(self) -> control.TransferFunction:
        """The notch as a python-control transfer function."""
        import control

        return control.tf(*self.coefficients())

    def to_dict(self) -> dict:
        """JSON-ready dictionary (a ``notches`` entry of a scenario)."""
        return {"frequency_hz": self.frequency_hz, "zeta_zero": self.zeta_zero,
                "zeta_pole": self.zeta_pole}


@dataclass(frozen=True)
class Pid:
    """Parallel PID with optional derivative filter and notches (see the module docstring).

    Parameters
    ----------
    kp : float
        Proportional gain [N/m], >= 0.
    ki : float
        Integral gain [N/(m s)], >= 0.
    kd : float
        Derivative gain [N s/m], >= 0.
    derivative_filter_hz : float, optional
        Corner of the first-order filter on the derivative [Hz]; None for a pure derivative.
    notches : tuple of Notch
        Notch filters in series.

    Examples
    --------
    >>> from motionhyst.controllers.pid import Pid
    >>> c = Pid(kp=2.0, ki=1.0).tf()                       # (2 s + 1) / s
    >>> c.num[0][0].tolist(), c.den[0][0].tolist()
    ([2.0, 1.0], [1.0, 0.0])
    """

    kp: float
    ki: float = 0.0
    kd: float = 0.0
    derivative_filter_hz: float | None = None
    notches: tuple[Notch, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        for name in ("kp", "ki", "kd"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be finite and >= 0, got {v!r}")
        if self.kp == self.ki == self.kd == 0:
            raise ValueError("a PID needs a non-zero gain (kp, ki or kd)")
        f = self.derivative_filter_hz
        if f is not None and not (math.isfinite(f) and f > 0):
            raise ValueError(f"derivative_filter_hz must be finite and > 0, got {f!r}")
        object.__setattr__(self, "notches", tuple(self.notches))

    @property
    def proper(self) -> bool:
        """False for a pure derivative (``kd > 0`` without a filter): no continuous realisation."""
        return self.kd == 0 or self.derivative_filter_hz is not None

    def _pi(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return (np.array([self.kp, self.ki]), np.array([1.0, 0.0])) if self.ki else (
            np.array([self.kp]), np.array([1.0]))

    def _derivative(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        if self.derivative_filter_hz is None:
            return np.array([self.kd, 0.0]), np.array([1.0])
        wd = 2.0 * math.pi * self.derivative_filter_hz
        return np.array([self.kd, 0.0]), np.array([1.0 / wd, 1.0])

    def _notches(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        num, den = np.array([1.0]), np.array([1.0])
        for n in self.notches:  # a product, as python-control forms it
            nn, dn = n.coefficients()
            num, den = _sum(np.array([0.0]), np.array([1.0]), np.polymul(num, nn),
                            np.polymul(den, dn))
        return num, den

    def coefficients(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Numerator and denominator of ``C(s)``, highest power first (the polynomials of
        :meth:`tf`, formed as python-control forms the sum and products; improper for a pure
        derivative).

        Examples
        --------
        >>> from motionhyst.controllers.pid import Pid
        >>> num, den = Pid(kp=2.0, ki=1.0, kd=0.5).coefficients()   # (0.5 s^2 + 2 s + 1) / s
        >>> num.tolist(), den.tolist()
        ([0.5, 2.0, 1.0], [1.0, 0.0])
        """
        num, den = self._pi()
        if self.kd:
            num, den = _sum(num, den, *self._derivative())
        if self.notches:
            nn, dn = self._notches()
            num, den = _sum(np.array([0.0]), np.array([1.0]), np.polymul(num, nn),
                            np.polymul(den, dn))
        return np.trim_zeros(num, "f"), np.trim_zeros(den, "f")

    def tf(self) -> control.TransferFunction:
        """The continuous controller ``C(s)`` (improper for a pure derivative)."""
        import control

        return control.tf(*self.coefficients())

    def sampled(self, sample_rate_hz: float, method: str = "tustin",
                prewarp_hz: float | None = None, delay_samples: float = 0.0,
                u_max: float | None = None) -> SampledController:
        """The PID run at `sample_rate_hz` (a pure derivative as a backward difference).

        Parameters
        ----------
        sample_rate_hz : float
            ``1 / T`` [Hz].
        method : {"tustin", "tustin-prewarp", "zoh", "matched"}
            Discretisation of every part but a pure derivative.
        prewarp_hz : float, optional
            For ``"tustin-prewarp"``.
        delay_samples : float
            Delay of the output [samples].
        u_max : float, optional
            Output limit [N].

        Examples
        --------
        >>> from motionhyst.controllers.pid import Pid
        >>> c = Pid(kp=1.0, kd=0.5).sampled(100.0)      # 1 + 0.5 (1 - z^-1) / 0.01
        >>> c.r_num.tolist(), c.r_den.tolist()
        ([51.0, -50.0], [1.0, 0.0])
        """
        if self.proper:
            num, den = discretize_coefficients(*self.coefficients(), sample_rate_hz, method,
                                               prewarp_hz)
        else:
            T = 1.0 / float(sample_rate_hz)
            parts = [discretize_coefficients(*self._pi(), sample_rate_hz, method, prewarp_hz)]
            parts.append((np.array([self.kd / T, -self.kd / T]), np.array([1.0, 0.0])))
            (n1, d1), (n2, d2) = parts
            num = _add_asc(np.convolve(n1, d2), np.convolve(n2, d1))
            den = np.convolve(d1, d2)
            if self.notches:
                nn, dn = discretize_coefficients(*self._notches(), sample_rate_hz, method,
                                                 prewarp_hz)
                num, den = np.convolve(num, nn), np.convolve(den, dn)
        return SampledController(num, den, sample_rate_hz=sample_rate_hz,
                                 delay_samples=delay_samples, u_max=u_max, continuous=self,
                                 discretization=method)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the scenario's ``[controller] type = "pid"`` keys)."""
        out: dict = {"type": "pid", "kp": self.kp, "ki": self.ki, "kd": self.kd}
        if self.derivative_filter_hz is not None:
            out["derivative_filter_hz"] = self.derivative_filter_hz
        if self.notches:
            out["notches"] = [n.to_dict() for n in self.notches]
        return out


def _add_asc(a, b):
    """Sum of two polynomials in ascending powers."""
    n = max(len(a), len(b))
    return np.pad(a, (0, n - len(a))) + np.pad(b, (0, n - len(b)))


def _sum(n1, d1, n2, d2):
    """``n1 / d1 + n2 / d2`` over the product of the denominators, as python-control adds."""
    return np.polyadd(np.polymul(n1, d2), np.polymul(n2, d1)), np.polymul(d1, d2)
