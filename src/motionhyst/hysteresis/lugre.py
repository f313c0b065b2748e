"""The LuGre friction model: a rate-dependent hysteresis with presliding and Stribeck effect.

Canudas de Wit, C., Olsson, H., Astrom, K. J. and Lischinsky, P. (1995),
"A new model for control of systems with friction", IEEE Trans. Automatic
Control 40(3), 419-425.
Olsson, H., Astrom, K. J., Canudas de Wit, C., Gafvert, M. and Lischinsky, P.
(1998), "Friction models and friction compensation", European Journal of
Control 4(3), 176-195.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.validation import check_omega
from motionhyst.hysteresis._lugre_kernels import (
    TWO_PI,
    lugre_g,
    lugre_periodic_state,
    lugre_response,
)
from motionhyst.hysteresis._ode_periodic import (
    describing_function_from_harmonics,
    pow2_at_least,
    truncate_harmonics,
)
from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.periodic import sample_period
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import LUGRE, Stepping


def _check_nonnegative(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v < 0:
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return v


@register
class LuGre(Hysteresis):
    """LuGre friction (Canudas de Wit et al. 1995), displacement ``x`` in, force ``w`` out.

    .. math::

        \\dot z = v - \\frac{\\sigma_0 |v|}{g(v)} z, \\qquad
        g(v) = f_c + (f_s - f_c) e^{-(v / v_s)^2}, \\qquad
        w = \\sigma_0 z + \\sigma_1 \\dot z + \\sigma_2 v,

    with ``v = dx/dt``.  ``z`` is the mean bristle deflection; in steady
    sliding ``w = g(v) sign(v) + sigma2 v`` (the Stribeck curve plus viscous
    friction).  The model is rate-dependent (``rate_independent = False``):
    its describing function depends on amplitude and frequency, and
    :meth:`response` needs sample times.

    The small-motion (presliding) stiffness is ``sigma0`` (:attr:`initial_stiffness`);
    for small amplitudes ``D -> sigma0 + j omega (sigma1 + sigma2)``, so unlike
    the rate-independent models ``|D|`` is not bounded by it.  The viscous
    term adds exactly ``j omega sigma2`` to ``D`` at every amplitude.  With
    ``sigma1 = sigma2 = 0`` and ``fs = fc`` the model is the Dahl model with
    ``k = sigma0``, ``alpha = 1``.

    For a given motion the state equation is linear in ``z``:
    ``dz/dtheta = x' - lambda(theta) z`` with ``lambda = sigma0 |x'| / g``, so the
    periodic state follows from one pass over the period (the period map is
    affine), integrated by an exponential scheme exact for constant ``g``,
    with substeps where the Stribeck curve varies (``|v| < 6 vs``, near the
    reversals), so the grid does not grow with ``omega A / vs``
    (see :func:`~motionhyst.hysteresis._lugre_kernels.lugre_periodic_state`).

    Parameters
    ----------
    sigma0 : float
        Bristle (presliding) stiffness [N/m], > 0.
    sigma1 : float
        Bristle damping [N s/m], >= 0.
    sigma2 : float
        Viscous friction coefficient [N s/m], >= 0.
    fc : float
        Coulomb friction force [N], > 0.
    fs : float
        Static (stiction) force [N], > 0 (usually >= fc).
    vs : float
        Stribeck velocity [m/s], > 0.

    Notes
    -----
    The map from ``v`` to ``w`` is dissipative when ``sigma1`` is not too large
    compared with ``sigma2`` (Olsson et al. 1998, sec. 3.4; Barabanov and
    Ortega 2000); for large ``sigma1`` and ``fs > fc``, ``Im D`` can become
    negative at some amplitudes and frequencies.

    Examples
    --------
    >>> from motionhyst.hysteresis.lugre import LuGre
    >>> el = LuGre(sigma0=20.0, sigma1=0.0, sigma2=0.0, fc=0.05, fs=0.05, vs=0.01)
    >>> D = el.describing_function(1e-7, 2 * 3.141592653589793 * 10)
    >>> round(abs(D) / el.sigma0, 5)
    1.0
    """

    name = "lugre"
    n_states = 1
    rate_independent = False
    parameters = (Parameter("sigma0", "N/m", "bristle stiffness sigma0"),
                  Parameter("sigma1", "N s/m", "bristle damping sigma1", 0.0, "nonnegative"),
                  Parameter("sigma2", "N s/m", "viscous friction sigma2", 0.0, "nonnegative",
                            parallel="damper"),
                  Parameter("fc", "N", "Coulomb force f_c"),
                  Parameter("fs", "N", "static (Stribeck) force f_s"),
                  Parameter("vs", "m/s", "Stribeck velocity v_s"))
    _CACHE_SIZE = 8192

    def __init__(self, sigma0: float, sigma1: float, sigma2: float, fc: float, fs: float,
                 vs: float) -> None:
        super().__init__()
        self.sigma0 = check_positive("sigma0", sigma0)
        self.sigma1 = _check_nonnegative("sigma1", sigma1)
        self.sigma2 = _check_nonnegative("sigma2", sigma2)
        self.fc = check_positive("fc", fc)
        self.fs = check_positive("fs", fs)
        self.vs = check_positive("vs", vs)
        self._df_cache: dict[tuple[float, float], complex] = {}
        self.reset()

    def __repr__(self) -> str:
        return (f"LuGre(sigma0={self.sigma0!r}, sigma1={self.sigma1!r}, "
                f"sigma2={self.sigma2!r}, fc={self.fc!r}, fs={self.fs!r}, vs={self.vs!r})")

    @property
    def initial_stiffness(self) -> float:
        """Presliding stiffness ``sigma0`` [N/m] (``Re D`` for small amplitudes)."""
        return self.sigma0

    def stribeck(self, v: ArrayLike) -> NDArray[np.float64]:
        """Stribeck curve ``g(v)`` [N] at velocity(ies) `v` [m/s].

        Parameters
        ----------
        v : array_like
            Sliding velocity(ies) [m/s].
        """
        r = np.asarray(v, dtype=float) / self.vs
        return self.fc + (self.fs - self.fc) * np.exp(-r * r)

    def steady_sliding_force(self, v: ArrayLike) -> NDArray[np.float64]:
        """Friction in steady sliding, ``g(v) sign(v) + sigma2 v`` [N].

        Parameters
        ----------
        v : array_like
            Sliding velocity(ies) [m/s].
        """
        v = np.asarray(v, dtype=float)
        return self.stribeck(v) * np.sign(v) + self.sigma2 * v

    def small_amplitude_limit(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """``D`` for vanishing amplitude, ``sigma0 + j omega (sigma1 + sigma2)`` [N/m].

        Parameters
        ----------
        omega : array_like
            Angular frequency(ies) [rad/s].
        """
        return self.sigma0 + 1j * np.asarray(omega, dtype=float) * (self.sigma1 + self.sigma2)

    # ------------------------------------------------------------------ periodic state

    def default_samples(self, X: NDArray[np.complex128], omega: float,
                        n_harmonics: int = 1) -> int:
        """Samples per period used for the input `X` at `omega` (a power of two).

        At least 8 samples per input harmonic and 4 per output harmonic, 12
        across the width ``sqrt(2 g / (sigma0 A))`` [rad] of the transition
        after a reversal and ``1100 (sigma0 A / fc)^(1/3)`` for the aliasing of
        the corners at reversals.  The first harmonic's error falls as ``N^-4``
        and is about 1e-10 relative or less at this size.

        The size does not depend on `omega` (accepted for a uniform
        signature): the Stribeck window ``|v| < 6 vs``, only
        ``~ 6 vs / (omega A)`` rad wide around a reversal at high
        ``omega A / vs``, is resolved by substeps inside
        :func:`~motionhyst.hysteresis._lugre_kernels.lugre_periodic_state`, not by the grid.
        The window leaves a narrow change in ``z`` whose effect on ``D`` falls
        as ``(vs / (omega A))^2``; sampling it on a grid coarser than the window
        costs nothing measurable (measured: ``D`` agrees with an adaptive ODE
        reference to about 1e-11 relative or better for ``omega A / vs`` from 0.06
        to 6e5 and ``sigma0 A / fc`` from 0.4 to 1000).

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period (``rfft / N`` scaling).
        omega : float
            Angular frequency [rad/s] (does not change the size, see above).
        n_harmonics : int
            Highest output harmonic wanted.
        """
        return self._samples(truncate_harmonics(X), n_harmonics)

    def _samples(self, X: NDArray[np.complex128], n_harmonics: int = 1) -> int:
        """:meth:`default_samples` for harmonics `X` already truncated."""
        amp = 2.0 * float(np.sum(np.abs(X[1:])))
        r = self.sigma0 * amp / min(self.fc, self.fs)
        need = [8 * (len(X) - 1), 4 * (int(n_harmonics) + 1),
                1100.0 * max(r, 1.0) ** (1.0 / 3.0),
                12.0 * TWO_PI / np.sqrt(2.0 / max(r, 1e-300))]
        return pow2_at_least(max(need))

    def _periodic_state(self, X: NDArray[np.complex128], omega: float, N: int
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Periodic bristle state ``z`` on the grid of `N` samples, and ``dx/dtheta`` on the
        grid of ``2 N`` (the samples ``2 i`` are those of the grid of `N`)."""
        m = np.arange(X.size)
        d2 = sample_period(X, 2 * N, 1)
        z = lugre_periodic_state(d2, 1j * m * X, -(m**2) * X, float(omega), self.sigma0,
                                 self.fc, self.fs, self.vs)
        return z, d2

    def periodic_samples(self, X: ArrayLike, omega: float, n_samples: int | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Displacement [m] and force [N] of the periodic state on ``theta = 2 pi i / N``.

        Parameters
        ----------
        X : array_like of complex
            Harmonics of the displacement (``rfft / N`` scaling).
        omega : float
            Angular frequency of the period [rad/s], >= 0.
        n_samples : int, optional
            Grid size ``N`` (even); by default :meth:`default_samples`.
        """
        om = check_omega(omega, "LuGre")
        X = truncate_harmonics(np.asarray(X, dtype=complex))
        N = self._samples(X) if n_samples is None else int(n_samples)
        if N < 8 or N % 2:
            raise ValueError(f"n_samples must be an even number >= 8, got {n_samples!r}")
        x = sample_period(X, N)
        if len(X) == 1:
            return x, np.zeros(N)
        z, d2 = self._periodic_state(X, om, N)
        d = d2[0::2]
        g = self.stribeck(om * d)
        zdot = om * (d - self.sigma0 * np.abs(d) * z / g)
        return x, self.sigma0 * z + self.sigma1 * zdot + self.sigma2 * om * d

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None, *, n_samples: int | None = None
                           ) -> NDArray[np.complex128]:
        """Harmonics ``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic output.

        ``z`` is integrated over one period (steps split at the input's
        reversals) and made periodic exactly through the affine period map;
        then ``W_m = (sigma0 + j m omega sigma1) Z_m + j m omega sigma2 X_m``,
        with ``Z_m`` from an FFT of the samples of ``z``.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics of the displacement.
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float
            Angular frequency of the period [rad/s]; required (rate-dependent).
        n_samples : int, optional
            Samples per period; by default :meth:`default_samples`.

        Raises
        ------
        ValueError
            If `omega` is None, negative or not finite.
        """
        om = check_omega(omega, "LuGre")
        H = int(n_harmonics)
        if H < 0:
            raise ValueError("n_harmonics must be >= 0")
        X = truncate_harmonics(np.asarray(X, dtype=complex))
        W = np.zeros(H + 1, dtype=complex)
        if len(X) == 1:
            return W
        N = self._samples(X, H) if n_samples is None else int(n_samples)
        if N < 8 or N % 2:
            raise ValueError(f"n_samples must be an even number >= 8, got {n_samples!r}")
        z, _ = self._periodic_state(X, om, N)
        Z = np.fft.rfft(z) / N
        m = min(H + 1, Z.size)
        jm = 1j * np.arange(m)
        W[:m] = (self.sigma0 + jm * om * self.sigma1) * Z[:m]
        mx = min(m, len(X))
        W[:mx] += jm[:mx] * om * self.sigma2 * X[:mx]
        return W

    # ------------------------------------------------------------------ describing function

    def _df_scalar(self, amp: float, om: float) -> complex:
        if amp == 0.0:
            return complex(self.small_amplitude_limit(om))
        key = (amp, om)
        d = self._df_cache.get(key)
        if d is None:
            W = self.periodic_harmonics(np.array([0.0, amp / 2j]), 1, om)
            d = describing_function_from_harmonics(W[1], amp)
            if len(self._df_cache) >= self._CACHE_SIZE:
                self._df_cache.clear()
            self._df_cache[key] = d
        return d

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Numerical describing function ``D(A, omega) = (b1 + j a1) / A`` (paper eq. 7) [N/m].

        Parameters
        ----------
        A : array_like
            Amplitude(s) of ``x = A sin(omega t)`` [m], >= 0.
        omega : array_like
            Angular frequency(ies) [rad/s], >= 0; required; broadcast against `A`.

        Returns
        -------
        complex or ndarray of complex
            Shape of ``broadcast(A, omega)``.  Values are cached per ``(A, omega)``;
            ``A = 0`` gives :meth:`small_amplitude_limit`.
        """
        if omega is None:
            check_omega(None, "LuGre")
        a = check_amplitudes(A)
        om = np.asarray(omega, dtype=float)
        if not np.all(np.isfinite(om)) or np.any(om < 0):
            raise ValueError("omega must be finite and >= 0")
        a, om = np.broadcast_arrays(a, om)
        pairs = np.stack([a.ravel(), om.ravel()], axis=1)
        uniq, inv = np.unique(pairs, axis=0, return_inverse=True)
        vals = np.array([self._df_scalar(float(p[0]), float(p[1])) for p in uniq],
                        dtype=complex)
        d = vals[np.ravel(inv)].reshape(a.shape)
        return complex(d) if d.ndim == 0 else d

    def hosidf(self, A: ArrayLike, n_max: int, omega: float | None = None
               ) -> NDArray[np.complex128]:
        """Higher-order describing functions ``H_1 .. H_n_max`` at `omega` (required) [N/m].

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        n_max : int
            Highest harmonic, >= 1.
        omega : float
            Angular frequency [rad/s]; required (rate-dependent).
        """
        om = check_omega(omega, "LuGre")
        out = super().hosidf(A, n_max, om)
        a = check_amplitudes(A)
        out[(a == 0), 0] = complex(self.small_amplitude_limit(om))
        return out

    def sine_loop(self, A: float, omega: float | None = None, n_samples: int | None = None
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """One closed period of the exact periodic response (see :meth:`Hysteresis.sine_loop`).

        Parameters
        ----------
        A : float
            Amplitude [m], > 0.
        omega : float
            Angular frequency [rad/s]; required (rate-dependent).
        n_samples : int, optional
            Samples per period (default :meth:`default_samples`).
        """
        _, x, w = self.steady_loop(A, omega, n_samples)
        return np.append(x, x[0]), np.append(w, w[0])

    def steady_loop(self, A: float, omega: float, n_samples: int | None = None
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """One period of the periodic response to ``x = A sin(theta)``, ``theta = omega t``.

        Parameters
        ----------
        A : float
            Amplitude [m], > 0.
        omega : float
            Angular frequency [rad/s], >= 0.
        n_samples : int, optional
            Samples per period (default :meth:`default_samples`).

        Returns
        -------
        theta, x, w : ndarray
            Angles [rad], displacement [m] and force [N] on a uniform grid.
        """
        amp = check_positive("A", A)
        x, w = self.periodic_samples(np.array([0.0, amp / 2j]), omega, n_samples)
        return np.arange(x.size) * (TWO_PI / x.size), x, w

    # ------------------------------------------------------------------ time domain

    def response(self, x: ArrayLike, w0: float = 0.0, t: ArrayLike | None = None
                 ) -> NDArray[np.float64]:
        """Force for displacement samples `x` at times `t`, linear in between.

        With constant velocity on each interval the state equation is solved
        exactly (``g`` is then constant), so the bristle force ``sigma0 z``
        converges at the second-order rate of the linear interpolation of
        ``x``; the damping and viscous terms (``sigma1``, ``sigma2`` > 0) use the
        velocity of the interval ending at the sample and converge at first
        order in the step.

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Initial bristle force ``sigma0 z`` [N], ``|w0| <= max(fc, fs)``; the
            element starts at rest, so ``w[0] = w0``.
        t : array_like
            Sample times [s], strictly increasing, same length as `x`; required.

        Returns
        -------
        ndarray
            Force at each sample [N]; ``sigma1 dz/dt`` and ``sigma2 v`` use the
            velocity of the interval ending at the sample.
        """
        if t is None:
            raise ValueError("the LuGre model is rate-dependent: response() needs the sample "
                             "times t [s]")
        xs = np.ascontiguousarray(x, dtype=float)
        ts = np.ascontiguousarray(t, dtype=float)
        if xs.ndim != 1 or ts.shape != xs.shape:
            raise ValueError("x and t must be one-dimensional and of the same length")
        if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(ts))):
            raise ValueError("x and t must be finite")
        if np.any(np.diff(ts) <= 0):
            raise ValueError("t must be strictly increasing")
        w_max = max(self.fc, self.fs)
        if not abs(w0) <= w_max:
            raise ValueError(f"|w0| must be <= max(fc, fs) = {w_max}, got {w0}")
        return lugre_response(xs, ts, self.sigma0, self.sigma1, self.sigma2, self.fc,
                              self.fs, self.vs, float(w0) / self.sigma0)

    def __call__(self, x: float) -> float:
        """Not available: the element is rate-dependent and needs time (see :meth:`response`)."""
        raise TypeError("the LuGre model is rate-dependent: it cannot be advanced by a "
                        "displacement alone; use response(x, t=...) or describing_function(A, "
                        "omega)")

    def state_equation(self, z: ArrayLike, v: float
                       ) -> tuple[NDArray[np.float64], float, NDArray[np.float64],
                                  NDArray[np.float64], NDArray[np.float64], float]:
        """The model's state equation at the bristle state `z` and the velocity `v`.

        ``z' = v - sigma0 |v| z / g(v)`` and ``w = sigma0 z + sigma1 z' + sigma2 v``
        with their derivatives: what an autonomous loop's orbit and its monodromy
        need (:mod:`motionhyst.analysis.stability`).  ``|v|`` has a corner at
        ``v = 0``; its one-sided derivative is taken (the vector field is continuous
        there, so crossings of ``v = 0`` need no jump of the variations).

        Parameters
        ----------
        z : array_like, shape (1,)
            Bristle deflection [m].
        v : float
            Velocity [m/s].

        Returns
        -------
        zdot : ndarray, shape (1,)
            ``z'`` [m/s].
        w : float
            Force [N].
        dzdot_dz : ndarray, shape (1, 1)
            ``d z' / d z``.
        dzdot_dv : ndarray, shape (1,)
            ``d z' / d v``.
        dw_dz : ndarray, shape (1,)
            ``d w / d z`` [N/m].
        dw_dv : float
            ``d w / d v`` [N s/m].

        Examples
        --------
        >>> from motionhyst.hysteresis.lugre import LuGre
        >>> el = LuGre(sigma0=1e5, sigma1=0.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
        >>> zdot, w, *_ = el.state_equation([1e-5], 0.01)      # steady sliding at 1 N
        >>> round(float(zdot[0]), 12), round(w, 6)
        (0.0, 1.004)
        """
        zz = float(np.ravel(np.asarray(z, dtype=float))[0])
        v = float(v)
        r = v / self.vs
        e = np.exp(-r * r)
        g = self.fc + (self.fs - self.fc) * e
        dg = -2.0 * r / self.vs * (self.fs - self.fc) * e
        av, sv = abs(v), (1.0 if v >= 0.0 else -1.0)
        zdot = v - self.sigma0 * av * zz / g
        dzdot_dz = -self.sigma0 * av / g
        dzdot_dv = 1.0 - self.sigma0 * zz * (sv * g - av * dg) / (g * g)
        w = self.sigma0 * zz + self.sigma1 * zdot + self.sigma2 * v
        return (np.array([zdot]), float(w), np.array([[dzdot_dz]]), np.array([dzdot_dv]),
                np.array([self.sigma0 + self.sigma1 * dzdot_dz]),
                float(self.sigma1 * dzdot_dv + self.sigma2))

    @property
    def bristle_damping(self) -> float:
        """``sigma1`` [N s/m]: while the element sticks (``z = y1``) its force is that of the
        bristles' spring ``sigma0`` and this damper beside ``sigma2``
        (:func:`~motionhyst.analysis._fixed_point.sticking`).

        Examples
        --------
        >>> LuGre(sigma0=1e5, sigma1=316.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3).bristle_damping
        316.0
        """
        return float(self.sigma1)

    @property
    def viscous_damping(self) -> float:
        """``sigma2`` [N s/m]: the viscous part of the force, ``sigma2 v``, at every amplitude.

        Examples
        --------
        >>> LuGre(sigma0=1e5, sigma1=316.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3).viscous_damping
        0.4
        """
        return float(self.sigma2)

    def rates(self, z: ArrayLike, v: float) -> tuple[float, float]:
        """``z'`` and ``w`` of :meth:`state_equation` without its derivatives, in scalar
        arithmetic: a run in time evaluates them at every step
        (:func:`~motionhyst.analysis.hunting.hunting_period`); 1.2 us here against the 11 us
        of :meth:`state_equation`'s arrays.

        Parameters
        ----------
        z, v
            As :meth:`state_equation`: bristle deflection [m], velocity [m/s].

        Returns
        -------
        zdot, w : float
            ``z'`` [m/s] and the force [N].

        Examples
        --------
        >>> el = LuGre(sigma0=1e5, sigma1=0.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
        >>> zdot, w = el.rates([1e-5], 0.01)                  # steady sliding at 1 N
        >>> round(zdot, 12), round(w, 6)
        (0.0, 1.004)
        """
        zz = float(z[0])
        v = float(v)
        r = v / self.vs
        g = self.fc + (self.fs - self.fc) * math.exp(-r * r)
        zdot = v - self.sigma0 * abs(v) * zz / g
        return zdot, self.sigma0 * zz + self.sigma1 * zdot + self.sigma2 * v

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        p = (self.sigma0, self.sigma1, self.sigma2, self.fc, self.fs, self.vs)
        return Stepping.from_rows([(LUGRE, p)], max(self.fc, self.fs))

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "sigma0": self.sigma0, "sigma1": self.sigma1,
                "sigma2": self.sigma2, "fc": self.fc, "fs": self.fs, "vs": self.vs}


__all__ = ["LuGre", "lugre_g"]
