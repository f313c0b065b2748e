"""Sampled-data controllers: the loop as a real-time computer runs it.

The measured output is sampled at ``t_k = k T`` (``T = 1 / sample_rate_hz``),
the controller computes ``u_k`` from the samples up to ``t_k``::

    u_k = R(z) r_k - Y(z) y_k          (one degree of freedom: R = Y = C_d)

and the force is applied from ``t_k + d T`` on and held until the next update
(zero-order hold, ``d = delay_samples``, fractional allowed).  ``R`` and ``Y``
are ratios of polynomials in ``z^-1``, coefficients in ascending powers
(``num = [b0, b1, ...]`` is ``b0 + b1 z^-1 + ...``), as a real-time program
writes its difference equation ``a0 u_k + a1 u_{k-1} + ... = b0 e_k + b1 e_{k-1} + ...``.

A continuous controller ``C(s)`` becomes a sampled one by one of four
discretisations (:func:`discretize`):

- ``"tustin"`` (the default): ``s = (2 / T) (z - 1) / (z + 1)``.  It maps the
  stable half plane onto the unit disc, adds no phase lag of its own (the
  hold and the delay are the lag of the digital loop, and they are accounted
  for separately), and its frequency error is second order in ``w T``
  (``C_d(e^{j w T}) = C(j (2 / T) tan(w T / 2))``), so the controller keeps its
  response up to the bandwidth at usual rates.  It is what the paper's loop
  discretised at 10 kHz loses 6.5 deg of phase margin with for one sample of delay.
- ``"tustin-prewarp"``: Tustin with the frequency ``prewarp_hz`` mapped exactly
  (a notch or a low-pass corner near the Nyquist frequency).
- ``"zoh"``: the step-invariant equivalent (the controller's own step response
  at the samples); it delays the controller by about half a sample more.
- ``"matched"``: poles and zeros mapped by ``z = e^{s T}``, the DC gain kept.

Examples
--------
>>> import numpy as np
>>> from motionhyst import LeadLagLowpass
>>> from motionhyst.controllers.sampled import SampledController
>>> C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)   # Table I
>>> Cd = SampledController.discretize(C, 10e3, delay_samples=1.5)
>>> print(Cd)
sampled controller at 10000 Hz (T = 0.0001 s), 1.5 samples of delay, tustin of C(s)
>>> f = np.array([10.0, 120.0])
>>> np.round(np.abs(Cd.feedback_response(2 * np.pi * f) / C(2j * np.pi * f)), 5)
array([1.     , 1.00029])
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.zoh import canonical_state_space

if TYPE_CHECKING:  # imported where used: a sampled controller is built and checked without it
    import control

__all__ = ["DISCRETIZATIONS", "MAX_DELAY_SAMPLES", "SampledController", "ascending", "discretize",
           "discretize_coefficients", "polyval_zinv"]

MAX_DELAY_SAMPLES = 1000
"""Longest delay of a sampled controller [samples]: its ``z^-d`` is a polynomial of degree
``d`` in every analysis of the loop (a motion stage's loop takes a few samples; a loop slow
enough for 1000 has no use for its sampling rate)."""

#: The discretisations of a continuous controller, the first the default.
DISCRETIZATIONS = ("tustin", "tustin-prewarp", "zoh", "matched")


def polyval_zinv(coef: ArrayLike, zinv: ArrayLike) -> NDArray[np.complex128]:
    """``c0 + c1 z^-1 + c2 z^-2 + ...`` at the given values of ``z^-1`` (Horner).

    Parameters
    ----------
    coef : array_like
        Coefficients in ascending powers of ``z^-1``.
    zinv : array_like
        Values of ``z^-1``.

    Examples
    --------
    >>> from motionhyst.controllers.sampled import polyval_zinv
    >>> complex(polyval_zinv([1.0, -1.0], 1.0))            # 1 - z^-1 at z = 1
    0j
    """
    return np.polyval(np.asarray(coef, dtype=float)[::-1], np.asarray(zinv, dtype=complex))


def ascending(sys: control.TransferFunction) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Numerator and denominator of a proper discrete SISO transfer function in ``z^-1``.

    Ascending powers of ``z^-1``, the denominator's first coefficient 1.

    Parameters
    ----------
    sys : control.TransferFunction
        A proper discrete SISO transfer function.

    Examples
    --------
    >>> import control
    >>> from motionhyst.controllers.sampled import ascending
    >>> ascending(control.tf([2.0, 0.0], [2.0, -1.0], 0.1))   # 2 z / (2 z - 1)
    (array([1., 0.]), array([ 1. , -0.5]))
    """
    return _ascending(sys.num[0][0], sys.den[0][0])


def _ascending(num: ArrayLike, den: ArrayLike
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
    den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    if num.size == 0:
        num = np.zeros(1)
    if num.size > den.size:
        raise ValueError("a discrete controller must be proper (causal)")
    num = np.concatenate([np.zeros(den.size - num.size), num])
    return num / den[0], den / den[0]


def _checked_poly(name: str, coef: ArrayLike, leading: bool = False) -> NDArray[np.float64]:
    c = np.atleast_1d(np.asarray(coef, dtype=float))
    if c.ndim != 1 or c.size == 0 or not np.all(np.isfinite(c)):
        raise ValueError(f"{name} must be a non-empty list of finite numbers")
    if leading and c[0] == 0.0:
        raise ValueError(f"{name}[0] (the coefficient of u_k) must not be 0: the controller "
                         "would not be causal")
    if not np.any(c != 0.0):
        raise ValueError(f"{name} must have a non-zero coefficient")
    return c


def discretize(controller, sample_rate_hz: float, method: str = "tustin",
               prewarp_hz: float | None = None) -> tuple[NDArray[np.float64],
                                                         NDArray[np.float64]]:
    """A continuous controller's discrete equivalent, coefficients in ascending ``z^-1``.

    Parameters
    ----------
    controller : python-control LTI system
        Proper continuous SISO controller ``C(s)``.
    sample_rate_hz : float
        Sampling rate ``1 / T`` [Hz].
    method : {"tustin", "tustin-prewarp", "zoh", "matched"}
        See the module docstring; ``"tustin"`` is the default.
    prewarp_hz : float, optional
        The frequency ``"tustin-prewarp"`` maps exactly [Hz], below the Nyquist frequency.

    Returns
    -------
    num, den : ndarray
        ``C_d(z) = num(z^-1) / den(z^-1)``, ``den[0] = 1``.

    Examples
    --------
    >>> import control
    >>> from motionhyst.controllers.sampled import discretize
    >>> num, den = discretize(control.tf([1.0], [1.0, 0.0]), 1000.0)   # integrator
    >>> num.tolist(), den.tolist()                         # (T / 2) (1 + z^-1) / (1 - z^-1)
    ([0.0005, 0.0005], [1.0, -1.0])
    """
    import control

    if isinstance(controller, control.StateSpace):
        controller = control.ss2tf(controller)
    if not isinstance(controller, control.TransferFunction) or controller.isdtime(strict=True):
        raise TypeError("only a continuous python-control LTI controller can be discretised")
    return discretize_coefficients(controller.num[0][0], controller.den[0][0], sample_rate_hz,
                                   method, prewarp_hz)


def discretize_coefficients(num: ArrayLike, den: ArrayLike, sample_rate_hz: float,
                            method: str = "tustin", prewarp_hz: float | None = None
                            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`discretize` of the continuous controller ``C(s) = num(s) / den(s)``.

    numpy and scipy's linear algebra alone: a scenario's sampled controller is known, and
    its loop checked, before python-control (and scipy.signal) is imported.  The
    coefficients are those of python-control's ``c2d`` (``tests/test_sampled_controllers.py``
    compares them bit for bit): the same realisation
    (:func:`~motionhyst.core.zoh.canonical_state_space`), bilinear map or exponential, and
    the same polynomials of its eigenvalues back; ``"matched"`` maps the roots by
    ``z = e^{s T}`` and keeps the gain at ``s = 0``.

    Parameters
    ----------
    num, den : array_like
        ``C(s)``, highest power first, proper.
    sample_rate_hz : float
        Sampling rate ``1 / T`` [Hz].
    method : {"tustin", "tustin-prewarp", "zoh", "matched"}
        The discretisation.
    prewarp_hz : float, optional
        For ``"tustin-prewarp"``.

    Returns
    -------
    num, den : ndarray
        ``C_d(z) = num(z^-1) / den(z^-1)``, ``den[0] = 1``.

    Examples
    --------
    >>> from motionhyst.controllers.sampled import discretize_coefficients
    >>> num, den = discretize_coefficients([1.0], [1.0, 1.0], 10.0, "zoh")   # 1 / (s + 1)
    >>> [round(float(x), 6) for x in (*num, *den)]         # (1 - e^-T) z^-1 / (1 - e^-T z^-1)
    [0.0, 0.095163, 1.0, -0.904837]
    """
    if method not in DISCRETIZATIONS:
        raise ValueError(f"unknown discretization {method!r}; one of {', '.join(DISCRETIZATIONS)}")
    rate = _positive("sample_rate_hz", sample_rate_hz)
    T = 1.0 / rate
    if (method == "tustin-prewarp") != (prewarp_hz is not None):
        raise ValueError("prewarp_hz goes with discretization = \"tustin-prewarp\" (the "
                         "frequency it maps exactly), and only with it")
    num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
    den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    if num.size > den.size:
        raise ValueError("the continuous controller must be proper to be discretised (a pure "
                         "derivative needs a filter)")
    if den.size == 1:  # a static gain is its own equivalent
        return np.array([num[0] / den[0]]) if num.size else np.zeros(1), np.ones(1)
    dt = T
    if method == "tustin-prewarp":
        f = _positive("prewarp_hz", prewarp_hz)
        if f >= rate / 2:
            raise ValueError(f"prewarp_hz = {f:g} Hz must lie below the Nyquist frequency "
                             f"{rate / 2:g} Hz")
        w = 2.0 * math.pi * f
        dt = 2.0 * np.tan(w * T / 2.0) / w  # the step that maps w exactly
    if method == "matched":
        if den[-1] == 0.0:
            raise ValueError('discretization = "matched" keeps the gain at s = 0, which a '
                             'controller with an integrator has not: use "tustin" or "zoh"')
        return _ascending(*_matched(num, den, T))
    from scipy.linalg import expm, solve  # numpy's solve rounds otherwise (a triangular one)

    A, B, C, D = canonical_state_space(num, den)
    n = A.shape[0]
    if method == "zoh":
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n:] = A, B
        E = expm(dt * M)[:n, :]
        ad, bd, cd, dd = E[:, :n], E[:, n:], C, D
    else:  # s = (2 / dt) (z - 1) / (z + 1)
        eye = np.eye(n)
        ima = eye - 0.5 * dt * A
        ad = solve(ima, eye + 0.5 * dt * A)
        bd = solve(ima, dt * B)
        cd = solve(ima.T, C.T).T
        dd = D + 0.5 * (C @ bd)
    den_d = np.poly(ad)
    return _ascending(np.poly(ad - bd @ cd) + (dd[0] - 1.0) * den_d, den_d)


def _matched(num: NDArray[np.float64], den: NDArray[np.float64], T: float
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Zeros and poles mapped by ``z = e^{s T}``, the gain at ``s = 0`` kept (descending)."""
    n = num / den[0]
    big = np.flatnonzero(np.abs(n) > 1e-14)  # leading coefficients dropped as scipy's tf2zpk
    n = n[big[0] if big.size else n.size - 1:]
    zeros = [np.exp(s * T) for s in np.roots(n / n[0])]
    poles = [np.exp(s * T) for s in np.roots(den / den[0])]
    with np.errstate(divide="ignore", invalid="ignore"):
        zgain = np.multiply.reduce([1 - z for z in zeros]) / \
            np.multiply.reduce([1 - p for p in poles])
        s0 = np.zeros(1, complex)
        gain = (np.polyval(num, s0) / np.polyval(den, s0))[0].real / zgain.real
    return (np.atleast_1d(np.real(np.multiply(np.atleast_1d(gain), np.poly(zeros)))),
            np.atleast_1d(np.real(np.poly(poles))))


def _positive(name: str, value) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


class SampledController:
    """A controller running at ``sample_rate_hz``: ``u_k = R(z) r_k - Y(z) y_k``, held.

    Parameters
    ----------
    r_num, r_den : array_like
        Reference path ``R(z)``, ascending powers of ``z^-1``.
    y_num, y_den : array_like, optional
        Feedback path ``Y(z)``; by default ``Y = R`` (a controller of the error
        ``e_k = r_k - y_k``).
    sample_rate_hz : float
        ``1 / T`` [Hz].
    delay_samples : float
        Delay ``d >= 0`` from sampling to applying the force, in samples; the
        whole output (feedback and feedforward) is delayed.
    u_max : float, optional
        Output limit ``|u| <= u_max`` [N], honoured by the time simulation.
    continuous : python-control LTI system, optional
        The continuous controller this one discretises (kept for reports).
    discretization : str, optional
        How `continuous` was discretised.

    Attributes
    ----------
    period : float
        ``T`` [s].
    one_dof : bool
        True when ``R = Y``.

    Examples
    --------
    The EMPS benchmark's cascade, ``u = gtau kv (kp (r - y) - (y_k - y_{k-1}) / T)``:

    >>> from motionhyst.controllers.sampled import SampledController
    >>> F, g = 1000.0, 35.15065 * 243.45
    >>> c = SampledController([g * 160.18], [1.0], [g * (160.18 + F), -g * F], [1.0],
    ...                       sample_rate_hz=F)
    >>> c.one_dof, round(float(c.dc_gain()), 1)
    (False, 1370728.5)
    """

    def __init__(self, r_num: ArrayLike, r_den: ArrayLike, y_num: ArrayLike | None = None,
                 y_den: ArrayLike | None = None, *, sample_rate_hz: float,
                 delay_samples: float = 0.0, u_max: float | None = None,
                 continuous=None, discretization: str | None = None) -> None:
        self.sample_rate_hz = _positive("sample_rate_hz", sample_rate_hz)
        self.period = 1.0 / self.sample_rate_hz
        d = float(delay_samples)
        if not (math.isfinite(d) and d >= 0):
            raise ValueError(f"delay_samples must be finite and >= 0, got {delay_samples!r}")
        if d > MAX_DELAY_SAMPLES:  # its z^-d would be a polynomial of that degree
            raise ValueError(f"delay_samples = {d:g} is more than {MAX_DELAY_SAMPLES} samples "
                             f"({d * self.period:.3g} s at {self.sample_rate_hz:g} Hz): is it "
                             f"in samples?")
        self.delay_samples = d
        self.u_max = None if u_max is None else _positive("u_max", u_max)
        self.r_num = _checked_poly("num" if y_num is None else "r_num", r_num)
        self.r_den = _checked_poly("den" if y_num is None else "r_den", r_den, leading=True)
        if (y_num is None) != (y_den is None):
            raise ValueError("give both y_num and y_den, or neither")
        self.one_dof = y_num is None
        if self.one_dof:
            self.y_num, self.y_den = self.r_num, self.r_den
        else:
            self.y_num = _checked_poly("y_num", y_num)
            self.y_den = _checked_poly("y_den", y_den, leading=True)
        self.continuous = continuous
        self.discretization = discretization

    @classmethod
    def discretize(cls, controller, sample_rate_hz: float, method: str = "tustin",
                   prewarp_hz: float | None = None, delay_samples: float = 0.0,
                   u_max: float | None = None) -> SampledController:
        """A continuous controller run at `sample_rate_hz` (see :func:`discretize`).

        Parameters
        ----------
        controller : python-control LTI system
            Proper continuous controller ``C(s)``.
        sample_rate_hz : float
            ``1 / T`` [Hz].
        method : {"tustin", "tustin-prewarp", "zoh", "matched"}
            The discretisation (the module docstring says why Tustin is the default).
        prewarp_hz : float, optional
            For ``"tustin-prewarp"``.
        delay_samples : float
            Delay of the output [samples].
        u_max : float, optional
            Output limit [N].

        Examples
        --------
        >>> import control
        >>> from motionhyst.controllers.sampled import SampledController
        >>> c = SampledController.discretize(control.tf([1.0], [1.0, 0.0]), 1000.0, "zoh")
        >>> c.r_num.tolist(), c.r_den.tolist()             # T z^-1 / (1 - z^-1)
        ([0.0, 0.001], [1.0, -1.0])
        """
        num, den = discretize(controller, sample_rate_hz, method, prewarp_hz)
        return cls(num, den, sample_rate_hz=sample_rate_hz, delay_samples=delay_samples,
                   u_max=u_max, continuous=controller, discretization=method)

    @property
    def nyquist_hz(self) -> float:
        """Half the sampling rate [Hz]."""
        return 0.5 * self.sample_rate_hz

    def response(self, omega: ArrayLike) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """``R`` and ``Y`` at ``z = e^{j w T}``.

        The delay is not included (it belongs to the hold,
        :func:`motionhyst.core.sampling.hold_response`).

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].
        """
        zinv = np.exp(-1j * np.asarray(omega, dtype=float) * self.period)
        # at a pole (an integrator's z = 1) infinite, nan where a zero meets it: the periodic
        # steady state sets that point (z_0 of a free plant) from the static balance
        with np.errstate(divide="ignore", invalid="ignore"):
            Y = polyval_zinv(self.y_num, zinv) / polyval_zinv(self.y_den, zinv)
            if self.one_dof:
                return Y, Y
            return polyval_zinv(self.r_num, zinv) / polyval_zinv(self.r_den, zinv), Y

    def feedback_response(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """The feedback path ``Y(e^{j w T})`` (the controller of the stability margins).

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].
        """
        return self.response(omega)[1]

    def dc_gain(self) -> float:
        """``Y(1)``, the static gain of the feedback path (inf with an integrator)."""
        d = float(np.sum(self.y_den))
        return math.inf if d == 0.0 else float(np.sum(self.y_num)) / d

    def tf(self, path: str = "y") -> control.TransferFunction:
        """``Y`` (or ``R``) as a python-control discrete transfer function.

        Parameters
        ----------
        path : {"y", "r"}
            The feedback path ``Y`` or the reference path ``R``.

        Examples
        --------
        >>> from motionhyst.controllers.sampled import SampledController
        >>> SampledController([1.0, -0.5], [1.0], sample_rate_hz=100.0).tf().dt
        0.01
        """
        if path not in ("y", "r"):
            raise ValueError(f"path must be 'y' or 'r', got {path!r}")
        num, den = (self.y_num, self.y_den) if path == "y" else (self.r_num, self.r_den)
        n = max(num.size, den.size)
        pad = lambda c: np.concatenate([c, np.zeros(n - c.size)])  # noqa: E731
        import control

        return control.tf(pad(num), pad(den), self.period)

    def state_space(self) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                   NDArray[np.float64], NDArray[np.float64]]:
        """A discrete realisation ``x+ = A x + B [r_k, y_k]``, ``u_k = C x + D [r_k, y_k]``.

        One realisation of ``C_d`` driven by ``r_k - y_k`` for a one-degree-of-freedom
        controller; the two paths side by side otherwise.

        Examples
        --------
        >>> from motionhyst.controllers.sampled import SampledController
        >>> A, B, C, D = SampledController([1.0, 1.0], [1.0, -1.0], sample_rate_hz=10.0
        ...                                ).state_space()
        >>> A.tolist(), B.tolist(), D.tolist()           # (1 + z^-1) / (1 - z^-1)
        ([[1.0]], [[1.0, -1.0]], [[1.0, -1.0]])
        """
        paths = [(self.r_num, self.r_den, 1.0)] if self.one_dof else [
            (self.r_num, self.r_den, 0), (self.y_num, self.y_den, 1)]
        blocks = []
        for num, den, _ in paths:
            n = max(num.size, den.size)
            num = np.concatenate([num, np.zeros(n - num.size)]) / den[0]
            den = np.concatenate([den, np.zeros(n - den.size)]) / den[0]
            k = n - 1  # controllable canonical form in z^-1
            A = np.zeros((k, k))
            if k:
                A[0, :] = -den[1:]
                A[1:, :-1] = np.eye(k - 1)
            b = np.zeros(k)
            if k:
                b[0] = 1.0
            c = num[1:] - num[0] * den[1:]
            blocks.append((A, b, c, num[0]))
        if self.one_dof:
            A, b, c, d0 = blocks[0]
            return A, np.stack([b, -b], axis=1), c[None, :], np.array([[d0, -d0]])
        (Ar, br, cr, dr), (Ay, by, cy, dy) = blocks
        kr, ky = Ar.shape[0], Ay.shape[0]
        A = np.zeros((kr + ky, kr + ky))
        A[:kr, :kr], A[kr:, kr:] = Ar, Ay
        B = np.zeros((kr + ky, 2))
        B[:kr, 0], B[kr:, 1] = br, by
        C = np.concatenate([cr, -cy])[None, :]
        return A, B, C, np.array([[dr, -dy]])

    def to_dict(self) -> dict:
        """JSON-ready description (the keys of a scenario's ``[controller]``)."""
        out: dict = {"sample_rate_hz": self.sample_rate_hz, "delay_samples": self.delay_samples}
        if self.discretization is not None:
            out["discretization"] = self.discretization
            if hasattr(self.continuous, "to_dict"):
                out = {**self.continuous.to_dict(), **out}
        elif self.one_dof:
            out.update(type="tf-z", num=self.r_num.tolist(), den=self.r_den.tolist())
        else:
            out.update(type="two-dof-z", r_num=self.r_num.tolist(), r_den=self.r_den.tolist(),
                       y_num=self.y_num.tolist(), y_den=self.y_den.tolist())
        if self.u_max is not None:
            out["u_max"] = self.u_max
        return out

    def __repr__(self) -> str:
        return (f"SampledController(sample_rate_hz={self.sample_rate_hz:g}, "
                f"delay_samples={self.delay_samples:g}, one_dof={self.one_dof})")

    def __str__(self) -> str:
        what = ("" if self.discretization is None else f", {self.discretization} of C(s)")
        if self.discretization is None:
            what = ", C(z) given" if self.one_dof else ", u = R(z) r - Y(z) y given"
        lim = "" if self.u_max is None else f", |u| <= {self.u_max:g} N"
        return (f"sampled controller at {self.sample_rate_hz:g} Hz (T = {self.period:g} s), "
                f"{self.delay_samples:g} samples of delay{what}{lim}")
