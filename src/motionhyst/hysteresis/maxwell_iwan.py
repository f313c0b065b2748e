"""The Maxwell-Iwan link: a spring, viscoelastic Maxwell branches and an Iwan element in parallel.

A cable slab is stiff and damped at once: its force depends on the frequency
of the motion (the polymer's viscoelasticity) and on its amplitude (the
cables slipping against each other at many places).  This model separates the
two, acting in parallel on the displacement ``x``:

* a linear spring ``k0``;
* Maxwell branches, each a spring ``kv[i]`` in series with a damper ``cv[i]``
  (linear, rate-dependent: relaxation time ``cv[i] / kv[i]``);
* an Iwan element: a continuum of Jenkins elements (paper eq. 3) of total
  stiffness ``ki`` whose slip displacements ``d = fc / k`` are spread uniformly
  over ``[d_min, d_max]`` (rate-independent, amplitude-dependent).

Its describing function (paper eq. 7) is, in closed form,

.. math::

    D(A, \\omega) = k_0 + \\sum_i \\frac{k_{v,i}\\, j\\omega c_{v,i}}{k_{v,i} + j\\omega c_{v,i}}
    + D_\\mathrm{Iwan}(A), \\qquad
    D_\\mathrm{Iwan}(A) = \\frac{k_i}{d_{max} - d_{min}} \\int_{d_{min}}^{d_{max}}
    N\\!\\left(\\frac{d}{A}\\right) \\mathrm{d}d,

with ``N(zeta) = D_J(k=1, zeta)`` the normalised Jenkins describing function of
eq. (10) (``zeta = d / A``, eq. 4, ``N = 1`` for ``zeta >= 1``), whose
antiderivative is elementary (:func:`iwan_describing_function`).

Iwan, W. D. (1966), "A distributed-element model for hysteresis and its
steady-state dynamic response", J. Applied Mechanics 33(4), 893-900.
"""

from __future__ import annotations

from fractions import Fraction
from math import comb

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.compiled import njit
from motionhyst.core.validation import check_omega
from motionhyst.hysteresis._kernels import reversal_points
from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.jenkins import jenkins_describing_function
from motionhyst.hysteresis.periodic import (
    sample_period,
    significant_harmonics,
    stop_periodic_harmonics,
    trig_eval,
)
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import GL_T, GL_W, MAXWELL, STOP, Stepping, advance

__all__ = ["MaxwellIwan", "iwan_describing_function"]

TWO_PI = 2.0 * np.pi


def _bracket_series(n_terms: int) -> NDArray[np.float64]:
    """Series of ``P``, the integral of eq. (10)'s bracket: ``P(z) = sum_(n>=1) p_n z^(n + 3/2)``.

    The bracket of eq. (10), ``B(z) = asin(sqrt z) - (1 - 2 z) sqrt(z (1 - z))``,
    is ``sum_n b_n z^(n + 1/2)`` with ``b_n = a_n - (q_n - 2 q_(n-1))`` from the
    series ``asin(s) = sum a_n s^(2n+1)`` and ``sqrt(1 - s^2) = sum q_n s^(2n)``;
    ``b_0 = 0``, ``b_1 = 8/3``.  Integrated term by term from 0.
    """
    q = [Fraction(1)]
    for n in range(1, n_terms + 2):
        q.append(q[-1] * Fraction(2 * n - 3, 2 * n))
    out = []
    for n in range(1, n_terms + 1):
        a = Fraction(comb(2 * n, n), 4**n * (2 * n + 1))
        b = a - (q[n] - 2 * q[n - 1])
        out.append(float(b / Fraction(2 * n + 3, 2)))
    return np.array(out)


# below _SMALL_Z the closed form of P cancels (its terms are O(sqrt z), P is O(z^2.5)):
# there its series, whose 16th term is below 1e-16 relative
_SMALL_Z = 0.05
_P_SERIES = _bracket_series(16)


def _normalised_antiderivative(z: NDArray[np.float64]) -> NDArray[np.complex128]:
    """``G(z)``: the integral from 0 to `z` of the normalised Jenkins describing function.

    With ``m = min(z, 1)``: ``Re G = (2/pi) P(m) + max(z - 1, 0)`` where
    ``P(z) = sqrt(z (1 - z)) / 2 - (1 - 2 z) asin(sqrt z) / 2 - (2/3) (z (1 - z))^(3/2)``
    integrates the bracket of eq. (10) (``gamma / 2 + pi / 4 = asin(sqrt z)``), and
    ``Im G = (4/pi) (m^2 / 2 - m^3 / 3)``.  ``G(1) = 1/2 + 2 j / (3 pi)``.
    """
    m = np.clip(z, 0.0, 1.0)
    s = np.sqrt(m)
    c = np.sqrt(1.0 - m)
    u = s * c
    direct = 0.5 * u - 0.5 * (1.0 - 2.0 * m) * np.arctan2(s, c) - (2.0 / 3.0) * u**3
    series = m**2 * s * np.polynomial.polynomial.polyval(m, _P_SERIES)
    P = np.where(m < _SMALL_Z, series, direct)
    re = (2.0 / np.pi) * P + np.maximum(z - 1.0, 0.0)
    im = (4.0 / np.pi) * m**2 * (0.5 - m / 3.0)
    return re + 1j * im


def _cosine_nodes(breaks: NDArray[np.float64], n: int
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Gauss-Legendre nodes and weights on each interval between sorted `breaks`.

    Each interval ``[a, b]`` is mapped by ``d = a + (b - a) (1 - cos(pi u)) / 2``:
    a behaviour ``(b - d)^(1/2)`` or ``(b - d)^(3/2)`` at an end (a Jenkins
    element that only just slips at a reversal) becomes smooth in ``u``, so
    the rule converges spectrally on integrands smooth between the breaks.
    """
    u, wu = np.polynomial.legendre.leggauss(n)
    u = 0.5 * (u + 1.0)
    wu = 0.5 * wu
    a = breaks[:-1, None]
    L = np.diff(breaks)[:, None]
    d = a + L * 0.5 * (1.0 - np.cos(np.pi * u))
    w = L * (0.5 * np.pi) * np.sin(np.pi * u) * wu
    return d.ravel(), w.ravel()


def iwan_describing_function(ki: float, d_min: float, d_max: float, A: ArrayLike
                             ) -> NDArray[np.complex128]:
    """Closed-form describing function of the uniform Iwan element, eq. (10) over the density.

    Parameters
    ----------
    ki : float
        Total stiffness of the Jenkins elements [N/m].
    d_min, d_max : float
        Range of their slip displacements ``d = fc / k`` [m], ``0 <= d_min <= d_max``,
        ``d_max > 0``; uniformly distributed (equal stiffness per unit of ``d``).
    A : array_like
        Amplitude(s) [m], >= 0.

    Returns
    -------
    ndarray of complex
        ``D = ki A / (d_max - d_min) [G(d_max / A) - G(d_min / A)]`` with ``G``
        the antiderivative of the normalised eq. (10) (``zeta = d / A``,
        eq. 4), in closed form; ``D = ki`` for ``A <= d_min``.  Small ``zeta``
        uses the series of ``G`` (the closed form cancels there).  For
        ``d_max - d_min < 1e-3 d_max`` the difference of ``G`` would cancel:
        then the integral of eq. (10) is taken by a 16-point Gauss rule on each
        side of ``d = A``, exact to round-off on so short a range; ``d_min =
        d_max`` is the Jenkins element ``k = ki``, ``fc = ki d_max``.  Large
        ``A``: ``D -> (4/pi) j ki mean(d) / A`` (eq. 11).

    Examples
    --------
    >>> from motionhyst.hysteresis.maxwell_iwan import iwan_describing_function
    >>> D = iwan_describing_function(30.0, 1e-4, 4e-3, [5e-5, 1e-3, 10.0])
    >>> complex(D[0])                          # no element slips: the spring ki
    (30+0j)
    >>> round(float(D[1].real), 4), round(float(D[1].imag), 4)
    (26.9069, 1.5867)
    >>> mean_d = (1e-4 + 4e-3) / 2             # large A: eq. (11), (4/pi) j ki mean(d) / A
    >>> round(float(D[2].imag) / (4 / 3.141592653589793 * 30.0 * mean_d / 10.0), 3)
    1.0
    """
    a = np.asarray(A, dtype=float)
    width = d_max - d_min
    safe = np.where(a > 0.0, a, 1.0)
    if width <= 0.0:
        d = jenkins_describing_function(ki, d_max / safe)
    elif width < 1e-3 * d_max:
        out = np.empty(a.shape, dtype=complex)
        for idx, amp in np.ndenumerate(safe):
            cut = [d_min, d_max] if not d_min < amp < d_max else [d_min, amp, d_max]
            nodes, weights = _cosine_nodes(np.array(cut), 16)
            out[idx] = weights @ jenkins_describing_function(1.0, nodes / amp) * (ki / width)
        d = out
    else:
        G = _normalised_antiderivative
        d = (ki * safe / width) * (G(d_max / safe) - G(d_min / safe))
        d = np.where(safe <= d_min, ki + 0j, d)
    return np.where(a > 0.0, d, ki + 0j)


@njit(cache=True)
def _run_rows(codes, params, s0, x, t, glt, glw):  # pragma: no cover - compiled
    """Force of the rows for displacement samples `x` at times `t`, from rest at ``x[0]``."""
    s = s0.copy()
    w = np.zeros(x.shape[0])
    for i in range(1, x.shape[0]):
        dx = x[i] - x[i - 1]
        h = t[i] - t[i - 1]
        total = 0.0
        for j in range(codes.shape[0]):
            s[j], f = advance(codes[j], params[j], s[j], s[j], dx, 0.0, h, h, i == 1, glt,
                              glw)
            total += f
        w[i] = total
    return w


@register
class MaxwellIwan(Hysteresis):
    """A spring, Maxwell branches and a uniform Iwan element in parallel (cable-slab model).

    The force for a displacement ``x`` is ``w = k0 x + sum_i f_i + w_Iwan``:
    each Maxwell branch obeys ``f_i' = kv_i (x' - f_i / cv_i)``, and the Iwan
    element is the integral of Jenkins elements (eq. 3) of stiffness density
    ``ki / (d_max - d_min)`` per unit slip displacement ``d`` on
    ``[d_min, d_max]``.  The model is rate-dependent through the Maxwell
    branches (``rate_independent = False``); the Iwan part alone is
    rate-independent and obeys the Masing rules.  For small motions the link
    is a spring ``k0 + ki`` plus the branches; for ``A >> d_max`` the Iwan part
    slips at the force ``fc = ki mean(d)``.

    Parameters
    ----------
    k0 : float
        Stiffness of the parallel spring [N/m], >= 0.
    ki : float
        Total stiffness of the Iwan element's Jenkins elements [N/m], > 0.
    d_min, d_max : float
        Range of the slip displacements ``fc / k`` of the Jenkins elements [m],
        ``0 <= d_min <= d_max``, ``d_max > 0``; ``d_min = d_max`` is one Jenkins
        element ``k = ki``, ``fc = ki d_max``.
    kv, cv : array_like, optional
        Spring stiffness [N/m] and damping [N s/m] of each Maxwell branch, each
        > 0, lists of equal length; empty (the default): no branch.
    n_stops : int, optional
        Number of stop operators that represent the Iwan element in the time
        simulation (:meth:`time_stepping`, :meth:`response`); see there for
        the error.  The describing function and the periodic output do not
        use it.

    Examples
    --------
    >>> from motionhyst.hysteresis import MaxwellIwan
    >>> link = MaxwellIwan(k0=5.0, kv=[8.0, 3.0], cv=[0.4, 0.02], ki=30.0,
    ...                    d_min=1e-4, d_max=4e-3)
    >>> link.initial_stiffness                 # k0 + sum(kv) + ki
    46.0
    >>> D = link.describing_function(1e-3, 2 * 3.141592653589793 * 10.0)
    >>> round(D.real, 3), round(D.imag, 3)
    (39.619, 4.968)
    """

    name = "maxwell-iwan"
    rate_independent = False
    parameters = (
        Parameter("k0", "N/m", "stiffness k0 of the parallel spring", kind="nonnegative",
                  parallel="spring"),
        Parameter("kv", "N/m", "spring stiffness kv of each Maxwell branch", (), many=True),
        Parameter("cv", "N s/m", "damping cv of each Maxwell branch", (), many=True),
        Parameter("ki", "N/m", "total stiffness ki of the Iwan element"),
        Parameter("d_min", "m", "smallest slip displacement fc/k of the Iwan element",
                  kind="nonnegative"),
        Parameter("d_max", "m", "largest slip displacement fc/k of the Iwan element"))
    N_STOPS = 256
    MAX_CUTS = 1024

    def __init__(self, k0: float, ki: float, d_min: float, d_max: float,
                 kv: ArrayLike = (), cv: ArrayLike = (), *, n_stops: int = N_STOPS) -> None:
        super().__init__()
        self.k0 = _nonnegative("k0", k0)
        self.ki = check_positive("ki", ki)
        self.d_min = _nonnegative("d_min", d_min)
        self.d_max = check_positive("d_max", d_max)
        if self.d_max < self.d_min:
            raise ValueError(f"d_max must be >= d_min, got d_max = {d_max!r} < d_min = "
                             f"{d_min!r}")
        kv_arr = _branch_list("kv", kv)
        cv_arr = _branch_list("cv", cv)
        if kv_arr.shape != cv_arr.shape:
            raise ValueError(f"kv and cv must have the same length ({kv_arr.size} != "
                             f"{cv_arr.size})")
        self.kv, self.cv = kv_arr, cv_arr
        if isinstance(n_stops, bool) or not isinstance(n_stops, (int, np.integer)) \
                or n_stops < 1:
            raise ValueError(f"n_stops must be an integer >= 1, got {n_stops!r}")
        self.n_stops = int(n_stops)

    def __repr__(self) -> str:
        return (f"MaxwellIwan(k0={self.k0!r}, ki={self.ki!r}, d_min={self.d_min!r}, "
                f"d_max={self.d_max!r}, kv={self.kv.tolist()!r}, cv={self.cv.tolist()!r})")

    @property
    def initial_stiffness(self) -> float:
        """Stiffness for small, fast motions, ``k0 + sum(kv) + ki`` [N/m] (bound of ``|D|``)."""
        return float(self.k0 + self.kv.sum() + self.ki)

    @property
    def fc(self) -> float:
        """Total slip force of the Iwan element, ``ki (d_min + d_max) / 2`` [N].

        The force it carries once all its elements slip (the sum of their
        ``fc``): the scale of the loops, as the figures take it (:mod:`motionhyst.present.plots`).
        """
        return 0.5 * self.ki * (self.d_min + self.d_max)

    # ------------------------------------------------------------------ linear part

    def linear_gain(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """``k0 + sum_i kv_i j omega cv_i / (kv_i + j omega cv_i)`` at `omega` [rad/s] [N/m].

        The transfer function of the spring and the Maxwell branches, from
        ``x`` to their force: the part of ``D`` that does not depend on the amplitude.

        Parameters
        ----------
        omega : array_like
            Angular frequency(ies) [rad/s].
        """
        jw = 1j * np.asarray(omega, dtype=float)[..., None]
        return self.k0 + np.sum(self.kv * jw * self.cv / (self.kv + jw * self.cv), axis=-1)

    # ------------------------------------------------------------------ describing function

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Describing function ``D(A, omega)`` (paper eq. 7) in closed form [N/m].

        ``D = linear_gain(omega) + D_Iwan(A)`` with ``D_Iwan`` from
        :func:`iwan_describing_function` (eq. 10 integrated over the slip density).

        Parameters
        ----------
        A : array_like
            Amplitude(s) of ``x = A sin(omega t)`` [m], >= 0.
        omega : array_like
            Angular frequency(ies) [rad/s], >= 0; required; broadcast against `A`.

        Returns
        -------
        complex or ndarray of complex
            Shape of ``broadcast(A, omega)``; ``A = 0`` gives the small-motion
            limit ``linear_gain(omega) + ki``.
        """
        if omega is None:
            check_omega(None, "maxwell-iwan")
        a = check_amplitudes(A)
        om = np.asarray(omega, dtype=float)
        if not np.all(np.isfinite(om)) or np.any(om < 0):
            raise ValueError("omega must be finite and >= 0")
        d = (iwan_describing_function(self.ki, self.d_min, self.d_max, a)
             + self.linear_gain(om))
        return complex(d) if d.ndim == 0 else d

    # ------------------------------------------------------------------ periodic state

    def iwan_stops(self, breaks: ArrayLike = (), n: int = 20
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Stiffnesses and slip forces of stop operators whose sum integrates the Iwan element.

        A Gauss rule in the slip displacement ``d`` (:func:`_cosine_nodes`, `n`
        nodes per interval) on ``[d_min, d_max]`` cut at the `breaks` inside it.
        Exact for integrands smooth between the breaks (to the rule's spectral
        convergence); ``d_min = d_max`` gives the one Jenkins element.  Beyond
        ``MAX_CUTS`` breaks (an input with many reversals per period) the cuts
        are their quantiles and the convergence at the others algebraic.

        Parameters
        ----------
        breaks : array_like
            Slip displacements [m] at which the integrand has a kink (cuts of the rule); those
            outside ``(d_min, d_max)`` are ignored.
        n : int
            Gauss nodes per interval.
        """
        if self.d_max == self.d_min:
            return np.array([self.ki]), np.array([self.ki * self.d_max])
        b = np.asarray(breaks, dtype=float)
        b = np.unique(b[(b > self.d_min) & (b < self.d_max)])
        if b.size > self.MAX_CUTS:  # many reversals: cut at the quantiles of the breaks
            b = np.unique(np.quantile(b, np.linspace(0.0, 1.0, self.MAX_CUTS)))
        cuts = np.concatenate([[self.d_min], b, [self.d_max]])
        d, w = _cosine_nodes(cuts, n)
        k = w * (self.ki / (self.d_max - self.d_min))
        return k, k * d

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Harmonics ``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic output.

        The spring and the Maxwell branches are linear: ``W_m = linear_gain(m
        omega) X_m``, exact.  The Iwan element is the integral over ``d`` of
        the exact periodic output of a Jenkins element
        (:func:`~motionhyst.hysteresis.periodic.stop_periodic_harmonics`), which
        is smooth in ``d`` except where an element only just slips between two
        reversal points ``x_r``, ``x_s`` of the input, ``d = |x_r - x_s| / 2``,
        and varies fast near the values of nearly stationary inflections.  Cut
        there (:meth:`_cuts`), the integral is taken by a 20-point Gauss rule per
        interval after a cosine map that smooths the ``(d_b - d)^(3/2)``
        behaviour at the cuts: measured within 2e-14 of
        :meth:`describing_function` for sine inputs, and within 2e-11 of
        80,000 stop operators (the reference's own error) for an input with a
        minor loop and one of 20 harmonics with 12 reversals per period.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics of the displacement.
        n_harmonics : int
            Highest output harmonic ``H``, >= 0.
        omega : float
            Angular frequency of the period [rad/s]; required (rate-dependent).
        """
        om = check_omega(omega, "maxwell-iwan")
        H = int(n_harmonics)
        if H < 0:
            raise ValueError("n_harmonics must be >= 0")
        X = np.asarray(X, dtype=complex)
        W = np.zeros(H + 1, dtype=complex)
        m = min(H + 1, X.size)
        W[:m] = self.linear_gain(om * np.arange(m)) * X[:m]
        W[0] = self.k0 * X[0].real
        M = significant_harmonics(X)
        if M == 0:
            return W
        k, fc = self.iwan_stops(self._cuts(X[: M + 1]))
        return W + stop_periodic_harmonics(X, k, fc, H)

    @staticmethod
    def _cuts(X: NDArray[np.complex128]) -> NDArray[np.float64]:
        """Slip displacements where the Iwan integrand is not smooth (or nearly so).

        ``d = |x_c - x_r| / 2`` for every reversal value ``x_r`` of the input and
        every critical value ``x_c``: a reversal value (an element that only just
        slips there) or the value at an inflection (where a nearly stationary
        input makes the slip onset move fast with ``d``).
        """
        M = X.size - 1
        m = np.arange(M + 1)
        C1, C2 = 1j * m * X, -(m**2) * X
        n = max(1024, 4 * M)
        _, xr = reversal_points(X, C1, C2, sample_period(C1, n))
        th, _ = reversal_points(C1, C2, -1j * m**3 * X, sample_period(C2, n))
        xc = np.concatenate([xr, trig_eval(X, th)])
        return np.abs(np.subtract.outer(xc, xr)).ravel() / 2.0

    def hosidf(self, A: ArrayLike, n_max: int, omega: float | None = None
               ) -> NDArray[np.complex128]:
        """Higher-order describing functions ``H_1 .. H_n_max`` at `omega` (required) [N/m].

        From :meth:`periodic_harmonics`; the linear parts give ``H_1`` only.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        n_max : int
            Highest harmonic, >= 1.
        omega : float
            Angular frequency [rad/s]; required (rate-dependent).
        """
        om = check_omega(omega, "maxwell-iwan")
        out = super().hosidf(A, n_max, om)
        a = check_amplitudes(A)
        out[(a == 0), 0] = complex(self.describing_function(0.0, om))
        return out

    def virgin_force(self, u: ArrayLike) -> NDArray[np.float64]:
        """Force of the Iwan element on its initial loading curve at displacement `u` >= 0 [N].

        ``ki u`` up to ``d_min``, ``ki (u - (u - d_min)^2 / (2 (d_max - d_min)))`` up to
        ``d_max`` and ``ki mean(d)`` beyond.  By the Masing rules a branch after a
        reversal at ``(x_r, w_r)`` is ``w_r +- 2 virgin_force(|x - x_r| / 2)``.

        Parameters
        ----------
        u : array_like
            Displacement(s) from the unloaded state [m]; its magnitude is used.
        """
        v = np.abs(np.asarray(u, dtype=float))
        lo, hi = self.d_min, self.d_max
        if hi == lo:
            return self.ki * np.minimum(v, hi)
        mid = v - (np.clip(v, lo, hi) - lo) ** 2 / (2.0 * (hi - lo))
        return self.ki * np.where(v >= hi, 0.5 * (lo + hi), mid)

    def sine_loop(self, A: float, omega: float | None = None, n_samples: int | None = None
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """One closed period of the exact periodic response to ``x = A sin(omega t)``.

        In closed form: ``k0 x``, the Maxwell branches' sinusoidal steady state
        ``Im(G_v A exp(j theta))`` and the Iwan element's Masing branches
        through ``(+-A, +-virgin_force(A))`` (:meth:`virgin_force`).

        Parameters
        ----------
        A : float
            Amplitude [m], > 0.
        omega : float
            Angular frequency [rad/s], >= 0; required.
        n_samples : int, optional
            Samples per period (default 2000).

        Returns
        -------
        x, w : ndarray
            Displacement [m] and force [N] on ``theta = 2 pi i / n``; the first
            sample repeated at the end.
        """
        amp = check_positive("A", A)
        om = check_omega(omega, "maxwell-iwan")
        n = 2000 if n_samples is None else int(n_samples)
        theta = np.linspace(0.0, TWO_PI, n + 1)
        x = amp * np.sin(theta)
        g_v = complex(self.linear_gain(om)) - self.k0
        w = self.k0 * x + np.imag(g_v * amp * np.exp(1j * theta))
        fa = float(self.virgin_force(amp))
        up = (theta < 0.5 * np.pi) | (theta >= 1.5 * np.pi)
        w_iwan = np.where(up, -fa + 2.0 * self.virgin_force((x + amp) / 2.0),
                          fa - 2.0 * self.virgin_force((amp - x) / 2.0))
        return x, w + w_iwan

    # ------------------------------------------------------------------ time domain

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`).

        ``k0`` is a stop operator that never slips; each Maxwell branch a
        ``MAXWELL`` row (exact for a displacement linear in time); the Iwan
        element `n_stops` stop operators of stiffness ``ki / n_stops`` and slip
        displacements at the midpoints of ``n_stops`` equal cells of
        ``[d_min, d_max]``.  The force per unit ``d`` of an Iwan element is
        piecewise linear in ``d``, so the midpoint rule errs only in the cells of
        its kinks: on a Masing branch (two kinks) by at most
        ``ki (d_max - d_min) / (4 n_stops^2)``, 4e-6 of ``ki d_max`` at the
        default 256 (tested against :meth:`sine_loop`).
        """
        rows: list[tuple[int, tuple[float, ...]]] = []
        if self.k0 > 0.0:
            rows.append((STOP, (self.k0, np.inf)))
        rows += [(MAXWELL, (float(k), float(c))) for k, c in zip(self.kv, self.cv, strict=True)]
        n = 1 if self.d_max == self.d_min else self.n_stops
        d = self.d_min + (np.arange(n) + 0.5) * ((self.d_max - self.d_min) / n)
        kj = self.ki / n
        rows += [(STOP, (kj, kj * float(dj))) for dj in d]
        return Stepping.from_rows(rows, self.fc)

    def response(self, x: ArrayLike, w0: float = 0.0, t: ArrayLike | None = None
                 ) -> NDArray[np.float64]:
        """Force for displacement samples `x` at times `t`, linear in between, from rest.

        Every element starts unstressed at ``x[0]``; the update is that of
        :meth:`time_stepping` (exact for the spring and the Maxwell branches,
        the Iwan element as `n_stops` stop operators).

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Initial force [N]; only 0 (the state of an Iwan element is not
            determined by its force).
        t : array_like
            Sample times [s], strictly increasing, same length as `x`; required.

        Returns
        -------
        ndarray
            Force at each sample [N], ``w[0] = 0``.
        """
        if t is None:
            raise ValueError("the maxwell-iwan model is rate-dependent: response() needs the "
                             "sample times t [s]")
        if w0 != 0.0:
            raise ValueError("w0 must be 0: the maxwell-iwan response starts at rest")
        xs = np.ascontiguousarray(x, dtype=float)
        ts = np.ascontiguousarray(t, dtype=float)
        if xs.ndim != 1 or ts.shape != xs.shape:
            raise ValueError("x and t must be one-dimensional and of the same length")
        if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(ts))):
            raise ValueError("x and t must be finite")
        if np.any(np.diff(ts) <= 0):
            raise ValueError("t must be strictly increasing")
        st = self.time_stepping()
        return _run_rows(st.codes, st.params, st.state0, xs, ts, GL_T, GL_W)

    def __call__(self, x: float) -> float:
        """Not available: the element is rate-dependent and needs time (see :meth:`response`)."""
        raise TypeError("the maxwell-iwan model is rate-dependent: it cannot be advanced by a "
                        "displacement alone; use response(x, t=...) or describing_function(A, "
                        "omega)")

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "k0": self.k0, "kv": self.kv.tolist(),
                "cv": self.cv.tolist(), "ki": self.ki, "d_min": self.d_min,
                "d_max": self.d_max}


def _nonnegative(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v < 0:
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return v


def _branch_list(name: str, values: ArrayLike) -> NDArray[np.float64]:
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a list of numbers, got {values!r}") from None
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a list of numbers")
    for i, v in enumerate(arr):
        check_positive(f"{name}[{i}]", v)
    return arr
