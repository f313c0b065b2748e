"""Linear time-invariant helpers shared by the loop, the simulation and identification.

Transfer functions as polynomial coefficient arrays (highest power first)
with exact cancellation of common factors ``s`` (so ``s = 0`` is exact), the
exact first-order-hold discretisation (the input taken as linear between
samples, as :func:`control.forced_response` does), one compiled
discrete state-space filter and the exponential of a small matrix without
BLAS (:func:`expm_small`, for the first-order hold of a stage).

Examples
--------
>>> import numpy as np
>>> num, den = cancel_s([1.0, 0.0], [1.0, 2.0, 0.0])        # s / (s^2 + 2 s)
>>> num.tolist(), den.tolist()
([1.0], [1.0, 2.0])
>>> f = HoldFilter([], [-1.0], 1.0, dt=0.01, omega0=1.0)     # 1 / (s + 1)
>>> round(float(f(np.ones(1001))[-1]), 12)                   # starts in steady state
1.0
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import expm, solve
from scipy.signal import cont2discrete, zpk2ss

from motionhyst.core.compiled import njit
from motionhyst.core.polynomials import cancel_s, trim

__all__ = ["HoldFilter", "PolyTF", "cancel_s", "discretize_foh", "divide_s2", "dss_filter",
           "expm_small", "forced_response_foh", "polyratio", "polysub_exact", "realize_scaled",
           "stack", "tf_poly", "trim"]


# ------------------------------------------------------------------ polynomials
def tf_poly(sys, what: str = "plant and controller"
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Numerator and denominator coefficients of a SISO LTI system.

    Parameters
    ----------
    sys : control.LTI
        A SISO python-control system.
    what : str
        Its name, for the message.

    Raises
    ------
    TypeError
        If `sys` is not a python-control LTI system.
    ValueError
        If it is not single-input single-output (`what` names it).

    Examples
    --------
    >>> import control
    >>> from motionhyst.core.lti import tf_poly
    >>> tf_poly(control.tf([1.0], [1.0, 2.0]))
    (array([1.]), array([1., 2.]))
    """
    if isinstance(sys, control.StateSpace):
        sys = control.ss2tf(sys)
    if not isinstance(sys, control.TransferFunction):
        raise TypeError(f"expected an LTI system, got {type(sys).__name__}")
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"{what} must be single-input single-output")
    return np.atleast_1d(np.asarray(sys.num[0][0], float)), np.atleast_1d(
        np.asarray(sys.den[0][0], float))

TWO_PI = 2.0 * np.pi


def freqresp(sys, omega: ArrayLike) -> NDArray[np.complex128]:
    """Complex frequency response of a SISO python-control system at `omega` [rad/s].

    Works for transfer functions, state-space systems and frequency-response
    data (interpolated between measured points).
    """
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    if isinstance(sys, control.FrequencyResponseData):
        return np.asarray(sys.eval(w, squeeze=True), dtype=complex).reshape(w.shape)
    if isinstance(sys, control.StateSpace):
        sys = control.ss2tf(sys)
    if isinstance(sys, control.TransferFunction):
        num = np.asarray(sys.num_array[0, 0], dtype=float) if hasattr(sys, "num_array") else \
            np.asarray(sys.num[0][0], dtype=float)
        den = np.asarray(sys.den_array[0, 0], dtype=float) if hasattr(sys, "den_array") else \
            np.asarray(sys.den[0][0], dtype=float)
        s = 1j * w
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.polyval(num, s) / np.polyval(den, s)
    raise TypeError(f"unsupported system type {type(sys).__name__}")



def polysub_exact(a: ArrayLike, b: ArrayLike, rtol: float = 1e-12) -> NDArray[np.float64]:
    """``a - b`` with coefficients that cancel to round-off set to exactly zero.

    Parameters
    ----------
    a : array_like
        Coefficients, highest power first.
    b : array_like
        Coefficients, highest power first.
    rtol : float
        Relative size below which a difference counts as round-off.

    Examples
    --------
    >>> from motionhyst.core.lti import polysub_exact
    >>> polysub_exact([1.0, 0.1 + 0.2, 1.0], [1.0, 0.3, 0.0])   # 0.1 + 0.2 - 0.3 is 5.6e-17
    array([0., 0., 1.])
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    n = max(len(a), len(b))
    a = np.pad(a, (n - len(a), 0))
    b = np.pad(b, (n - len(b), 0))
    d = a - b
    d[np.abs(d) <= rtol * np.maximum(np.abs(a), np.abs(b))] = 0.0
    return d


def divide_s2(num: ArrayLike, den: ArrayLike, what: str
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``num / (den s^2)`` with common factors ``s`` cancelled.

    Parameters
    ----------
    num : array_like
        Numerator coefficients, highest power first.
    den : array_like
        Denominator coefficients, highest power first.
    what : str
        The transfer's name, for the message.

    Raises
    ------
    ValueError
        If the result keeps a double pole at ``s = 0`` (`what` names the transfer).

    Examples
    --------
    >>> from motionhyst.core.lti import divide_s2
    >>> divide_s2([1.0, 0.0, 0.0], [1.0, 1.0], "r->e")      # s^2 / ((s + 1) s^2)
    (array([1.]), array([1., 1.]))
    """
    num, den = cancel_s(num, np.polymul(den, [1.0, 0.0, 0.0]))
    if den[-1] == 0.0 and len(den) > 1 and den[-2] == 0.0:
        raise ValueError(f"time simulation needs {what} to vanish like s^2 at DC "
                         "(a plant with a rigid-body double integrator)")
    return num, den


@njit(cache=True)
def polyratio(num, den, omega):  # pragma: no cover - compiled
    """``num(j omega) / den(j omega)`` at each of `omega`, both by Horner's rule."""
    out = np.empty(omega.shape[0], dtype=np.complex128)
    for i in range(omega.shape[0]):
        s = 1j * omega[i]
        p = 0j
        for c in num:
            p = p * s + c
        q = 0j
        for c in den:
            q = q * s + c
        out[i] = p / q
    return out


@dataclass(frozen=True)
class PolyTF:
    """A SISO transfer function as coefficient arrays (highest power first).

    Parameters
    ----------
    num : array_like
        Numerator coefficients, highest power first.
    den : array_like
        Denominator coefficients, highest power first.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.core.lti import PolyTF
    >>> lowpass = PolyTF(np.array([1.0]), np.array([1.0, 1.0]))   # 1 / (s + 1)
    >>> lowpass(np.array([0.0, 1.0]))
    array([1. +0.j , 0.5-0.5j])
    """

    num: NDArray[np.float64]
    den: NDArray[np.float64]

    def __call__(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """Frequency response at the angular frequencies `omega` [rad/s]."""
        w = np.asarray(omega, dtype=float)
        return polyratio(self.num, self.den, w.ravel()).reshape(w.shape)

    def tf(self) -> control.TransferFunction:
        """As a python-control transfer function."""
        return control.tf(self.num, self.den)


# ------------------------------------------------------------------ state space
def realize_scaled(num: ArrayLike, den: ArrayLike, omega0: float):
    """State-space realisation ``(A, B, C, D)`` in scaled time ``omega0 t`` (conditioning).

    Parameters
    ----------
    num : array_like
        Numerator coefficients, highest power first.
    den : array_like
        Denominator coefficients, highest power first.
    omega0 : float
        Time scale [rad/s].

    Examples
    --------
    >>> from motionhyst.core.lti import realize_scaled
    >>> A, B, C, D = realize_scaled([1.0], [1.0, 100.0], 100.0)   # 1 / (s + 100), time 100 t
    >>> float(A[0, 0]), float(B[0, 0] * C[0, 0])
    (-1.0, 0.01)
    >>> A, B, C, D = realize_scaled([1e-20, 2e-20], [1.0, 3.0, 2.0], 1.0)  # a tiny gain: kept
    >>> float(np.real(C @ np.linalg.solve(-A, B) + D)[0, 0])                 # at s = 0
    1e-20
    """
    n = len(den) - 1
    # substitute s = omega0 * s_hat, then divide numerator and denominator by omega0^n
    num_h = np.asarray(num, dtype=float) * omega0 ** (np.arange(len(num) - 1, -1, -1.0) - n)
    den_h = np.asarray(den, dtype=float) * omega0 ** (np.arange(n, -1, -1.0) - n)
    num_h, den_h = num_h / den_h[0], den_h / den_h[0]
    # realised at unit gain: scipy drops leading numerator coefficients below 1e-14 in
    # absolute terms (BadCoefficients), which for a small gain (a mass of 1e9 kg) is every
    # one but the last; the leading ones below round-off of the largest are dropped here
    gain = float(np.max(np.abs(num_h)))
    if gain > 0:
        keep = np.flatnonzero(np.abs(num_h) > 1e-14 * gain)
        num_h = num_h[keep[0]:] / gain
    sys = control.tf2ss(control.tf(num_h, den_h))
    scale = gain if gain > 0 else 1.0
    return sys.A, sys.B, sys.C * scale, sys.D * scale


def stack(mats):
    """Block-diagonal stack of single-input realisations sharing that input, one output each.

    Parameters
    ----------
    mats : list of tuple
        ``(A, B, C, D)`` of each realisation.

    Examples
    --------
    >>> from motionhyst.core.lti import realize_scaled, stack
    >>> A, B, C, D = stack([realize_scaled([1.0], [1.0, 1.0], 1.0),
    ...                     realize_scaled([2.0], [1.0, 2.0], 1.0)])   # one input, two outputs
    >>> A.shape, B.shape, C.shape, D.shape
    ((2, 2), (2, 1), (2, 2), (2, 1))
    """
    n = sum(a.shape[0] for a, _, _, _ in mats)
    A = np.zeros((n, n))
    B = np.zeros((n, 1))
    C = np.zeros((len(mats), n))
    D = np.zeros((len(mats), 1))
    k = 0
    for o, (a, b, c, d) in enumerate(mats):
        m = a.shape[0]
        A[k:k + m, k:k + m] = a
        B[k:k + m, 0] = b[:, 0]
        C[o, k:k + m] = c[0]
        D[o, 0] = d[0, 0]
        k += m
    return A, B, C, D


@njit(cache=True, inline="always")
def _matmul(A, B, out):  # pragma: no cover - compiled
    """``out = A @ B`` for square matrices, by loops (no BLAS call)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for q in range(n):
                acc += A[i, q] * B[q, j]
            out[i, j] = acc


@njit(cache=True, inline="always")
def _norm1(A):  # pragma: no cover - compiled
    """The 1-norm (largest column sum) of a square matrix."""
    n = A.shape[0]
    norm = 0.0
    for j in range(n):
        col = 0.0
        for i in range(n):
            col += abs(A[i, j])
        norm = max(norm, col)
    return norm


@njit("(float64[:, ::1],)")
def _expm_taylor(M):  # pragma: no cover - compiled
    """:func:`expm_small` of a C-contiguous float matrix."""
    n = M.shape[0]
    # alpha = max(||M^5||^(1/5), ||M^6||^(1/6)) bounds the Taylor remainder from degree 21 on
    # (Al-Mohy and Higham 2009, thm. 4.2, p = 5: 21 >= p (p - 1)); it is far below ||M||
    # for the badly scaled state matrices of a stage (entries k h / m and h)
    P = M.copy()
    W = np.empty((n, n))
    alpha = 0.0
    for p in range(2, 7):
        _matmul(P, M, W)
        P, W = W, P
        if p >= 5:
            alpha = max(alpha, _norm1(P) ** (1.0 / p))
    alpha = min(alpha, _norm1(M))
    sq = 0
    while alpha > 0.5:
        alpha *= 0.5
        sq += 1
    A = M / 2.0 ** sq
    E = np.eye(n)
    T = np.eye(n)
    for kk in range(1, 21):
        _matmul(T, A, W)
        for i in range(n):
            for j in range(n):
                T[i, j] = W[i, j] / kk
                E[i, j] += T[i, j]
    for _ in range(sq):
        _matmul(E, E, W)
        E, W = W, E
    return E


def expm_small(M: ArrayLike) -> NDArray[np.float64]:
    """``exp(M)`` of a small square matrix: scaling and squaring of a 20-term Taylor series.

    Compiled loops without BLAS: for the matrices of a stage's first-order hold
    (4x4 to 12x12) this takes microseconds, where :func:`scipy.linalg.expm`
    goes through a threaded BLAS that can spend tens of milliseconds waking
    its threads on a busy machine.  The series is summed for ``M / 2^s``, `s`
    the least for which ``max(||M^5||^(1/5), ||M^6||^(1/6)) / 2^s <= 1/2``
    (1-norms): the remainder after degree 20 is then below ``1e-26`` (Al-Mohy
    and Higham 2009, theorem 4.2), and a state matrix with entries as far
    apart as ``k h / m`` and ``h`` is not squared more often than its modes
    need.  Meant for small matrices (the loops are ``O(n^3)``, unblocked).

    Parameters
    ----------
    M : array_like, shape (n, n)
        A real square matrix.

    Returns
    -------
    ndarray, shape (n, n)
        Its exponential.

    Examples
    --------
    >>> import numpy as np
    >>> E = expm_small([[0.0, 1.0], [-1.0, 0.0]])   # a rotation by 1 rad
    >>> bool(np.allclose(E, [[np.cos(1), np.sin(1)], [-np.sin(1), np.cos(1)]], atol=1e-15))
    True
    """
    A = np.ascontiguousarray(M, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"expm_small needs a square matrix, got shape {A.shape}")
    return _expm_taylor(A)


def discretize_foh(sys, h: float):
    """First-order-hold discretisation (input linear between samples) with step `h`.

    Returns contiguous ``Ad, Bd, Cd, Dd`` (2-D, as :func:`scipy.signal.cont2discrete`).

    Parameters
    ----------
    sys : control.LTI
        A SISO python-control system.
    h : float
        Step [s].

    Examples
    --------
    >>> import control
    >>> from motionhyst.core.lti import discretize_foh
    >>> sys = control.ss(control.tf([1.0], [1.0, 1.0]))
    >>> Ad, Bd, Cd, Dd = discretize_foh((sys.A, sys.B, sys.C, sys.D), 0.1)
    >>> round(float(Ad[0, 0]), 6)                          # exp(-0.1)
    0.904837
    """
    Ad, Bd, Cd, Dd, _ = cont2discrete(sys, h, method="foh")
    return (np.ascontiguousarray(Ad), np.ascontiguousarray(Bd), np.ascontiguousarray(Cd),
            np.ascontiguousarray(Dd))


@njit(cache=True)
def dss_filter(Ad, Bd, Cd, Dd, U, X0):  # pragma: no cover - compiled
    """The discrete system ``x+ = Ad x + Bd u``, ``y = Cd x + Dd u`` over each column of `U`.

    Parameters
    ----------
    Ad : ndarray, shape (n, n)
    Bd : ndarray, shape (n,)
    Cd : ndarray, shape (p, n)
    Dd : ndarray, shape (p,)
    U : ndarray, shape (n_t, m)
        Inputs, one signal per column, filtered independently.
    X0 : ndarray, shape (n, m)
        Initial state of each column; overwritten with the final state, so
        that a signal filtered in pieces continues where the last piece ended.

    Returns
    -------
    ndarray, shape (n_t, p, m)
    """
    n_t, m = U.shape
    nx = Ad.shape[0]
    p = Cd.shape[0]
    Y = np.empty((n_t, p, m))
    x = np.empty(nx)
    xn = np.empty(nx)
    for j in range(m):
        for a in range(nx):
            x[a] = X0[a, j]
        for i in range(n_t):
            u = U[i, j]
            for o in range(p):
                y = Dd[o] * u
                for a in range(nx):
                    y += Cd[o, a] * x[a]
                Y[i, o, j] = y
            for a in range(nx):
                s = Bd[a] * u
                for b in range(nx):
                    s += Ad[a, b] * x[b]
                xn[a] = s
            for a in range(nx):
                x[a] = xn[a]
        for a in range(nx):
            X0[a, j] = x[a]
    return Y


@njit(cache=True)
def _foh_states(Ad, Bd0, Bd1, C, D, u, state, u_prev, first):  # pragma: no cover - compiled
    """Output of ``x_i = Ad x_{i-1} + Bd0 u_{i-1} + Bd1 u_i``, ``y = C x + D u``.

    From rest if `first`, else from `state` after the input `u_prev`; the
    final state is left in `state` (a signal filtered in pieces).
    """
    n_t = u.shape[0]
    n_x = Ad.shape[0]
    x = np.zeros(n_x) if first else state.copy()
    xn = np.zeros(n_x)
    y = np.empty(n_t)
    for i in range(n_t):
        if i > 0 or not first:
            up = u[i - 1] if i > 0 else u_prev
            for j in range(n_x):
                acc = 0.0
                for q in range(n_x):
                    acc += Ad[j, q] * x[q]
                xn[j] = acc + Bd0[j] * up + Bd1[j] * u[i]
            x, xn = xn, x
        acc = 0.0
        for j in range(n_x):
            acc += C[j] * x[j]
        y[i] = acc + D * u[i]
    for j in range(n_x):  # element-wise: a slice assigned an array compiles an error message
        state[j] = x[j]
    return y


class FohResponse:
    """The SISO LTI `sys` from rest, driven by an input linear between samples `h` apart.

    The algorithm and realisation of :func:`control.forced_response` (exact for
    an input linear between samples), with the time loop compiled; called on
    consecutive pieces of a signal, it carries its state from one to the next.
    """

    def __init__(self, sys, h: float):
        ss = control.ss(sys)
        A, B = np.asarray(ss.A, float), np.asarray(ss.B, float)
        C, D = np.asarray(ss.C, float), np.asarray(ss.D, float)
        n = A.shape[0]
        self.D = float(D[0, 0])
        self.n = n
        if n == 0:
            return
        M = np.zeros((n + 2, n + 2))
        M[:n, :n] = A * h
        M[:n, n] = B[:, 0] * h
        M[n, n + 1] = 1.0
        E = expm(M)
        self.Ad = np.ascontiguousarray(E[:n, :n])
        self.Bd1 = np.ascontiguousarray(E[:n, n + 1])
        self.Bd0 = np.ascontiguousarray(E[:n, n] - self.Bd1)
        self.C = np.ascontiguousarray(C[0])
        self.state = np.zeros(n)
        self.u_prev = 0.0
        self.first = True

    def __call__(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """The output for the next piece `u` of the input."""
        u = np.ascontiguousarray(u, dtype=float)
        if self.n == 0:
            return self.D * u
        y = _foh_states(self.Ad, self.Bd0, self.Bd1, self.C, self.D, u, self.state,
                        self.u_prev, self.first)
        if len(u):
            self.first = False
            self.u_prev = float(u[-1])
        return y


def forced_response_foh(sys, t: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Response from rest of the SISO LTI `sys` to `u`, linear between the uniform samples `t`.

    The algorithm and realisation of :func:`control.forced_response` (exact for
    an input linear between samples), with the time loop compiled, so that it
    agrees with python-control to round-off; :class:`HoldFilter` is the
    filter for records (conditioned by a time scale, started in steady state).

    Parameters
    ----------
    sys : control.LTI
        A SISO python-control system.
    t : ndarray
        Uniform sample times [s].
    u : ndarray
        Input samples.

    Examples
    --------
    >>> import control
    >>> import numpy as np
    >>> from motionhyst.core.lti import forced_response_foh
    >>> sys = control.tf([1.0], [1.0, 1.0])
    >>> t = np.linspace(0.0, 5.0, 501)
    >>> y = forced_response_foh(sys, t, np.ones_like(t))   # step response from rest
    >>> bool(np.allclose(y, 1.0 - np.exp(-t), rtol=0, atol=1e-12))
    True
    >>> bool(np.allclose(y, control.forced_response(sys, t, np.ones_like(t)).outputs, atol=1e-14))
    True
    """
    h = (t[-1] - t[0]) / (len(t) - 1) if len(t) > 1 else 0.0
    return FohResponse(sys, h)(u)


class HoldFilter:
    """A proper SISO LTI filter applied to sampled signals, exact for piecewise-linear inputs.

    The filter is discretised with a first-order hold (``cont2discrete(...,
    method="foh")``) in time scaled by `omega0`, so the discrete filter is the
    continuous one applied to the samples' linear interpolation.  By default
    every signal is taken as constant at its first value before the record
    (the filter state starts in steady state), which removes start-up
    transients from position offsets.

    Parameters
    ----------
    zeros, poles : array_like
        Zeros and poles [rad/s] (conjugate pairs complete); ``len(zeros) <= len(poles)``.
    gain : float
        Gain of the zero-pole-gain form.
    dt : float
        Sampling interval [s].
    omega0 : float
        Time scale [rad/s] used for conditioning (e.g. the cut-off).

    Examples
    --------
    A 10 Hz first-order low-pass sampled at 1 kHz:

    >>> import numpy as np
    >>> from motionhyst.core.lti import HoldFilter
    >>> wc = 2 * np.pi * 10.0
    >>> lowpass = HoldFilter(zeros=[], poles=[-wc], gain=wc, dt=1e-3, omega0=wc)
    >>> round(lowpass.dc_gain, 12)
    1.0
    >>> lowpass(np.full(5, 2.0))                           # starts in steady state: no transient
    array([2., 2., 2., 2., 2.])
    """

    def __init__(self, zeros: ArrayLike, poles: ArrayLike, gain: float, dt: float,
                 omega0: float) -> None:
        self.zeros = np.asarray(zeros, dtype=complex)
        self.poles = np.asarray(poles, dtype=complex)
        self.gain = float(gain)
        self.dt = float(dt)
        self.omega0 = float(omega0)
        z = self.zeros / omega0
        p = self.poles / omega0
        if z.size > p.size:
            raise ValueError("the filter must be proper")
        g = float(gain) * omega0 ** (z.size - p.size)
        A, B, C, D = zpk2ss(z, p, g)
        Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), omega0 * dt, method="foh")
        self.Ad = np.ascontiguousarray(Ad, dtype=float)
        self.Bd = np.ascontiguousarray(np.ravel(Bd), dtype=float)
        self.Cd = np.ascontiguousarray(np.ravel(Cd), dtype=float)
        self.Dd = float(np.ravel(Dd)[0])
        # steady state for a unit constant input: x = Ad x + Bd
        self._x_unit = solve(np.eye(self.Ad.shape[0]) - self.Ad, self.Bd)
        self.dc_gain = float(self.Dd + self.Cd @ self._x_unit)

    def with_step(self, dt: float) -> HoldFilter:
        """The same continuous filter discretised for sampling interval `dt` [s].

        Parameters
        ----------
        dt : float
            Sampling interval [s].
        """
        return HoldFilter(self.zeros, self.poles, self.gain, dt, self.omega0)

    def __call__(self, u: ArrayLike) -> NDArray[np.float64]:
        """Filter a signal (1-D) or each column of a 2-D array (time along axis 0)."""
        U = np.asarray(u, dtype=float)
        one = U.ndim == 1
        U2 = np.ascontiguousarray(U[:, None] if one else U)
        X0 = np.ascontiguousarray(np.outer(self._x_unit, U2[0]))
        Y = dss_filter(self.Ad, self.Bd, self.Cd[None, :], np.array([self.Dd]), U2, X0)[:, 0, :]
        return Y[:, 0] if one else Y
