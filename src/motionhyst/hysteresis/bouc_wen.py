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

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.validation import check_finite
from motionhyst.hysteresis._ode_kernels import (
    GL_T,
    GL_W,
    MAX_SAMPLES,
    alias_of_jumps,
    bouc_wen_path,
    bouc_wen_periodic,
)
from motionhyst.hysteresis._ode_periodic import NormalisedRateIndependent, truncate_harmonics
from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.periodic import sample_period
from motionhyst.hysteresis.registry import Form, Parameter, register
from motionhyst.hysteresis.stepping import BOUC_WEN, Stepping

__all__ = ["BoucWen"]

#: least samples per period of the corrected periodic output (:meth:`BoucWen.default_samples`)
MIN_SAMPLES_CORRECTED = 1024


def _check_shape(n: float, beta: float, gamma: float, names: tuple[str, str, str]) -> None:
    """The accepted set of the normalised ``(n, beta, gamma)`` (see :class:`BoucWen`).

    `names` are the parameters' names in the caller's spelling (normalised
    ``n, beta, gamma`` or general ``nu, gamma, delta``).
    """
    nn, bn, gn = names
    got = f"got {bn}={beta!r}, {gn}={gamma!r}"
    if not beta - gamma >= 0:
        raise ValueError(f"{bn} must be >= {gn} (dissipative loops), {got}")
    if beta + gamma > 0:
        return
    if n != 1.0:
        raise ValueError(f"{bn} + {gn} must be > 0 unless {nn} = 1 (without an ultimate force "
                         f"the force escapes to infinity within a finite displacement), {got}, "
                         f"{nn}={n!r}")
    if beta < 0:
        raise ValueError(f"{bn} must be >= 0 when {bn} + {gn} <= 0 (small cycles would raise "
                         f"the force without bound), {got}")


@register
class BoucWen(NormalisedRateIndependent, Hysteresis):
    r"""Bouc-Wen hysteresis (Bouc 1967, Wen 1976), rate-independent, in two spellings.

    The benchmark's general form (Noel and Schoukens 2016; Ismail et al. 2009,
    eq. 1, with ``beta`` factored out), force ``z`` [N] of the displacement
    ``x`` [m]:

    .. math::

        \dot z = \alpha \dot x - \beta\left(\gamma |\dot x| |z|^{\nu-1} z
                  + \delta \dot x |z|^\nu\right)                  \qquad (1)

    and the normalised form ``w = fc zeta`` with

    .. math::

        \frac{d\zeta}{dx} = \frac{k}{f_c}\left[1 - \left(\beta_n\,
        \mathrm{sign}(\dot x \zeta) + \gamma_n\right) |\zeta|^n\right]   \qquad (2)

    are one model: (1) is (2) with

    .. math::

        k = \alpha, \quad f_c = (\alpha / \beta)^{1/\nu}, \quad n = \nu, \quad
        \beta_n = \gamma, \quad \gamma_n = \delta                          \qquad (3)

    (substitute ``z = fc zeta`` in (1) and divide by ``fc``: ``beta fc^nu / alpha = 1``).
    Conversely (2) is (1) with ``alpha = k``, ``beta = k / fc^n``, ``gamma = beta_n``,
    ``delta = gamma_n``, ``nu = n``.  The constructor takes the normalised
    parameters, :meth:`from_general` the general ones; :attr:`general`
    gives (1)'s parameters of either, and :meth:`to_dict` returns the spelling
    the element was made with, so that it round-trips exactly.

    In the normalised form

    * the stiffness at ``w = 0`` (the initial stiffness) is ``k``;
    * the loading stiffness is ``k (1 - (beta_n + gamma_n) |zeta|^n)``, the
      unloading stiffness ``k (1 + (beta_n - gamma_n) |zeta|^n)`` (``= k`` for
      ``beta_n = gamma_n``);
    * with ``beta_n + gamma_n > 0`` a long monotone motion takes ``|zeta|`` to
      ``z_u = (beta_n + gamma_n)^(-1/n)``: the force saturates at
      ``fc z_u`` (``= fc`` when ``beta_n + gamma_n = 1``; ``n -> inf`` with
      ``beta_n = gamma_n = 1/2`` gives the Jenkins element of paper eq. 3);
    * with ``beta_n + gamma_n <= 0`` (the benchmark: ``gamma + delta = -0.3``)
      there is no ultimate force: the loading branch stiffens.

    Accepted parameters (the response stays bounded for every bounded
    motion; Ikhouane and Rodellar 2007, ch. 2): ``k, fc > 0``, ``n >= 1``,
    ``beta_n >= gamma_n`` (dissipative loops, ``Im D >= 0``), and either
    ``beta_n + gamma_n > 0`` or (no ultimate force) ``n = 1`` and
    ``beta_n >= 0``.  Rejected: ``beta_n + gamma_n <= 0`` with ``n > 1``, where
    the loading branch ``d zeta / du = 1 + |beta_n + gamma_n| zeta^n`` escapes
    to infinity within a finite displacement, and ``beta_n < 0``, where small
    cycles at a large force multiply it by ``exp(-2 beta_n du)`` each, without
    bound.  In the general form: ``alpha, beta > 0``, ``nu >= 1``,
    ``delta <= gamma``, and ``gamma + delta > 0`` or (``nu = 1`` and
    ``gamma >= 0``).

    The element is integrated in ``x``: exactly for ``n = 1`` (piecewise
    exponentials) and ``n = 2`` (``tan`` and ``tanh``), by RK4 sub-steps of at
    most ``0.02 / max(1, n (beta_n + gamma_n)^(1/n))`` in ``k x / fc``
    otherwise, with the crossing of ``zeta = 0`` (a kink of the right-hand
    side) located by Gauss-Legendre quadrature.  The compiled step,
    :func:`~motionhyst.hysteresis._ode_kernels.bouc_wen_step`, serves the
    time simulations.

    Parameters
    ----------
    k : float
        Initial stiffness [N/m], > 0 (``alpha``).
    fc : float
        Force scale [N], > 0: the saturation force when ``beta + gamma = 1``.
    n : float
        Smoothness exponent [-], >= 1 (``nu``).
    beta, gamma : float
        Normalised shape parameters ``beta_n``, ``gamma_n`` [-] (the general
        form's ``gamma`` and ``delta``), within the accepted set above.

    Examples
    --------
    >>> from motionhyst.hysteresis.bouc_wen import BoucWen
    >>> el = BoucWen(k=20.0, fc=0.05)
    >>> el.saturation_force
    0.05
    >>> round(abs(el.describing_function(1e-10)) / el.k, 6)
    1.0

    The benchmark's element, in its own names:

    >>> bw = BoucWen.from_general(alpha=5e4, beta=1e3, gamma=0.8, delta=-1.1, nu=1.0)
    >>> bw.k, bw.fc, bw.n, bw.beta, bw.gamma
    (50000.0, 50.0, 1.0, 0.8, -1.1)
    >>> bw.saturation_force
    inf
    >>> bw.to_dict()
    {'model': 'bouc-wen', 'alpha': 50000.0, 'beta': 1000.0, 'gamma': 0.8, 'delta': -1.1, 'nu': 1.0}
    """

    name = "bouc-wen"
    n_states = 1
    rate_independent = True
    parameters = (Parameter("k", "N/m", "spring stiffness k"),
                  Parameter("fc", "N", "slip (Coulomb) force f_c"),
                  Parameter("n", "", "sharpness n >= 1", 1.0, "finite"),
                  Parameter("beta", "", "beta", 0.5, "finite"),
                  Parameter("gamma", "", "gamma, <= beta", 0.5, "finite"))
    #: the benchmark's general form, eq. (1), read by :meth:`from_general`
    forms = (Form("general", "from_general", (
        Parameter("alpha", "N/m", "initial stiffness alpha"),
        Parameter("beta", "N^-nu", "scale beta of the nonlinear terms"),
        Parameter("gamma", "", "gamma", None, "finite"),
        Parameter("delta", "", "delta, <= gamma", None, "finite"),
        Parameter("nu", "", "smoothness nu >= 1", 1.0, "finite"))),)
    #: RK4 step in ``k x / fc`` for ``n != 1``, divided by ``max(1, n (beta + gamma)^(1/n))``
    rk4_step = 0.02
    #: names of the general form's parameters, eq. (1)
    GENERAL_KEYS = ("alpha", "beta", "gamma", "delta", "nu")

    def __init__(self, k: float, fc: float, n: float = 1.0, beta: float = 0.5,
                 gamma: float = 0.5) -> None:
        super().__init__()
        self.k = check_positive("k", k)
        self.fc = check_positive("fc", fc)
        self.n = check_finite("n", n)
        if self.n < 1.0:
            raise ValueError(f"n must be >= 1, got {n!r}")
        self.beta = check_finite("beta", beta)
        self.gamma = check_finite("gamma", gamma)
        _check_shape(self.n, self.beta, self.gamma, ("n", "beta", "gamma"))
        self._general: dict | None = None
        self.reset()

    @classmethod
    def from_general(cls, alpha: float, beta: float, gamma: float, delta: float,
                     nu: float = 1.0) -> BoucWen:
        """The element of the benchmark's general form, eq. (1), mapped by eq. (3).

        Parameters
        ----------
        alpha : float
            Initial stiffness [N/m], > 0.
        beta : float
            Scale of the nonlinear terms [N^-nu], > 0 ([1/m] for ``nu = 1``
            with ``alpha`` in N/m).
        gamma, delta : float
            Shape parameters [-]; ``delta <= gamma``, and ``gamma + delta > 0``
            or (``nu = 1`` and ``gamma >= 0``).
        nu : float
            Smoothness exponent [-], >= 1.

        Examples
        --------
        >>> from motionhyst.hysteresis import BoucWen
        >>> bw = BoucWen.from_general(alpha=20.0, beta=400.0, gamma=0.5, delta=0.5)
        >>> bw.to_dict() == BoucWen.from_dict(bw.to_dict()).to_dict()
        True
        >>> bw.describing_function(0.01) == BoucWen(20.0, 0.05).describing_function(0.01)
        True
        """
        a = check_positive("alpha", alpha)
        b = check_positive("beta", beta)
        nu_ = check_finite("nu", nu)
        if nu_ < 1.0:
            raise ValueError(f"nu must be >= 1, got {nu!r}")
        g = check_finite("gamma", gamma)
        d = check_finite("delta", delta)
        _check_shape(nu_, g, d, ("nu", "gamma", "delta"))
        fc = a / b if nu_ == 1.0 else (a / b) ** (1.0 / nu_)
        if not (np.isfinite(fc) and fc > 0.0):
            raise ValueError(f"alpha / beta must give a finite force scale (alpha / beta)^(1/nu) "
                             f"> 0, got alpha={alpha!r}, beta={beta!r}")
        el = cls(a, fc, nu_, g, d)
        el._general = {"alpha": a, "beta": b, "gamma": g, "delta": d, "nu": nu_}
        return el

    @classmethod
    def from_dict(cls, params: dict) -> BoucWen:
        """The element of either spelling of :meth:`to_dict` (the key ``model`` is ignored).

        Parameters
        ----------
        params : dict
            Parameters in either spelling (``k, fc, n, beta, gamma`` or ``alpha, beta, gamma, delta,
            nu``).

        Raises
        ------
        ValueError
            For keys of both spellings, or of neither.
        """
        keys = {key for key in params if key != "model"}
        general = bool(keys & {"alpha", "delta", "nu"})
        allowed, required = ((cls.GENERAL_KEYS, ("alpha", "beta", "gamma", "delta")) if general
                             else (("k", "fc", "n", "beta", "gamma"), ("k", "fc")))
        form = "general" if general else "normalised"
        for key in sorted(keys - set(allowed)):
            raise ValueError(f"{key}: not a parameter of the {form} form ({', '.join(allowed)})")
        for key in required:
            if key not in keys:
                raise ValueError(f"{key}: missing (a parameter of the {form} form)")
        args = {key: params[key] for key in keys}
        return cls.from_general(**args) if general else cls(**args)

    def __repr__(self) -> str:
        if self._general is not None:
            g = self._general
            return (f"BoucWen.from_general(alpha={g['alpha']!r}, beta={g['beta']!r}, "
                    f"gamma={g['gamma']!r}, delta={g['delta']!r}, nu={g['nu']!r})")
        return (f"BoucWen(k={self.k!r}, fc={self.fc!r}, n={self.n!r}, beta={self.beta!r}, "
                f"gamma={self.gamma!r})")

    @property
    def general(self) -> dict[str, float]:
        """Parameters ``alpha, beta, gamma, delta, nu`` of the general form, eq. (1).

        Those given to :meth:`from_general`, or from the normalised ones by
        ``alpha = k``, ``beta = k / fc^n``, ``gamma = beta_n``, ``delta = gamma_n``,
        ``nu = n``.
        """
        if self._general is not None:
            return dict(self._general)
        return {"alpha": self.k, "beta": self.k / self.fc**self.n, "gamma": self.beta,
                "delta": self.gamma, "nu": self.n}

    @property
    def initial_stiffness(self) -> float:
        """Stiffness ``k`` at ``z = 0`` [N/m]: the small-motion limit of ``D``."""
        return self.k

    @property
    def z_max(self) -> float:
        """Bound ``z_u = (beta + gamma)^(-1/n)`` of the normalised state [-] (inf if
        ``beta + gamma <= 0``: no ultimate force)."""
        ap = self.beta + self.gamma
        return float(ap ** (-1.0 / self.n)) if ap > 0.0 else math.inf

    @property
    def saturation_force(self) -> float:
        """Force approached in a long monotone motion, ``fc z_u`` [N] (inf: no ultimate force)."""
        return self.fc * self.z_max

    def _step(self) -> float:
        lam = self.n * (self.beta + self.gamma) ** (1.0 / self.n)
        return self.rk4_step / max(1.0, lam)

    def _path(self, u: NDArray[np.float64], s0: float) -> NDArray[np.float64]:
        return bouc_wen_path(u, float(s0), self.n, self.beta + self.gamma,
                             self.beta - self.gamma, self._step(), GL_T, GL_W)

    def _state_bounds(self, u_range: float = math.inf) -> tuple[float, float]:
        """An interval holding every periodic state for a path of range `u_range` in ``u``.

        ``[-z_u, z_u]`` with an ultimate force.  Without one (``n = 1``,
        ``beta + gamma = -b <= 0``), a monotone motion from ``zeta = 0`` over
        the path's whole range reaches ``expm1(b u_range) / b``, and smaller
        cycles never raise it (``beta >= 0``); twice that is returned.
        """
        z = self.z_max
        if math.isfinite(z):
            return -z, z
        b = -(self.beta + self.gamma)
        reach = u_range if b == 0.0 else math.expm1(b * u_range) / b
        bound = 2.0 * reach + 1.0
        if not math.isfinite(bound):
            raise ValueError(f"the motion is too large for an element without an ultimate "
                             f"force: k x / fc spans {u_range:.3g}, the force would exceed "
                             "1e300 fc")
        return -bound, bound

    def default_samples(self, X: NDArray[np.complex128], n_harmonics: int = 1) -> int:
        """Samples per period used by :meth:`periodic_harmonics` for the input `X`.

        An even FFT-friendly size (:func:`scipy.fft.next_fast_len`) with at
        least 4 samples per input harmonic (as the stop operator's exact
        harmonics), 4 per output harmonic, 1024, and ``700 (k A / fc)^(1/3)``:
        with the aliasing of the jumps of ``w''`` and ``w'''`` subtracted
        (:func:`~motionhyst.hysteresis._ode_kernels.alias_of_jumps`) the
        harmonics' remaining error is that of the jumps of higher derivatives,
        ``~ N^-5``, below 1e-10 of ``|W_1|`` there.  For a non-integer ``n`` the
        crossing of ``z = 0`` (``|z|^n``) is not corrected and the count of
        :meth:`NormalisedRateIndependent.default_samples` applies.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the input over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic wanted.

        Returns
        -------
        int
            Samples per period.
        """
        if self.n != math.floor(self.n):
            return super().default_samples(X, n_harmonics)
        from scipy.fft import next_fast_len  # here: importing scipy.fft delays every command

        X = truncate_harmonics(X)
        amp = float(np.sum(np.abs(X[1:]))) * 2.0  # bound on the half range of x
        r = self.k * amp / self.fc
        target = max(4 * (len(X) - 1), 4 * (int(n_harmonics) + 1), MIN_SAMPLES_CORRECTED,
                     700.0 * max(r, 1.0) ** (1.0 / 3.0))
        n = next_fast_len(math.ceil(min(target, MAX_SAMPLES)), real=True)
        while n % 2:
            n = next_fast_len(n + 1, real=True)
        return n

    def _periodic_state(self, X: NDArray[np.complex128], N: int):
        """Grid samples of ``x``, the periodic normalised state and its jumps (compiled)."""
        m = np.arange(X.size)
        x = sample_period(X, N)
        d = sample_period(X, N, 1)
        u_range = (self.k / self.fc) * float(np.max(x) - np.min(x)) * 1.01
        lo, hi = self._state_bounds(u_range)
        ap, am = self.beta + self.gamma, self.beta - self.gamma
        z, jt, jv, jo, ok = bouc_wen_periodic(X, 1j * m * X, -(m**2) * X, -1j * m**3 * X, x,
                                              d, self.k / self.fc, self.n, ap, am,
                                              self._step(), lo, hi, GL_T, GL_W)
        if not ok:
            raise RuntimeError("periodic state not found (period map did not converge)")
        return x, z, (jt, jv, jo)

    def periodic_samples(self, X: ArrayLike, n_samples: int | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Displacement and force on the grid ``theta = 2 pi i / N`` of the periodic state.

        Parameters
        ----------
        X : array_like of complex
            Harmonics of the displacement (``rfft / N`` scaling).
        n_samples : int, optional
            Grid size ``N`` (even); by default :meth:`default_samples`.

        Returns
        -------
        x, w : ndarray, shape (N,)
            Displacement [m] and force [N] over one period of the periodic state.
        """
        X, N = self._grid(X, n_samples)
        if len(X) == 1:  # constant displacement: the (non-unique) periodic state w = 0
            return np.full(N, X[0].real), np.zeros(N)
        x, z, _ = self._periodic_state(X, N)
        return x, self.fc * z

    def _harmonics(self, X: ArrayLike, n_harmonics: int, n_samples: int | None
                   ) -> NDArray[np.complex128]:
        H = int(n_harmonics)
        if H < 0:
            raise ValueError("n_harmonics must be >= 0")
        X = truncate_harmonics(np.asarray(X, dtype=complex))
        N = self.default_samples(X, H) if n_samples is None else int(n_samples)
        if N < 8 or N % 2:
            raise ValueError(f"n_samples must be an even number >= 8, got {n_samples!r}")
        W = np.zeros(H + 1, dtype=complex)
        if len(X) == 1:
            return W
        _, z, jumps = self._periodic_state(X, N)
        spec = np.fft.rfft(z) / N
        m = min(H + 1, spec.size)
        W[:m] = self.fc * (spec[:m] - alias_of_jumps(*jumps, N, m - 1))
        return W

    def state_equation(self, z: ArrayLike, v: float
                       ) -> tuple[NDArray[np.float64], float, NDArray[np.float64],
                                  NDArray[np.float64], NDArray[np.float64], float]:
        """The model's state equation at the force `z` and the velocity `v`.

        ``z' = k v [1 - (beta_n sign(v z) + gamma_n) |z / fc|^n]`` (form (2) with
        ``w = z = fc zeta``) with its derivatives: what an autonomous loop's orbit and its
        monodromy need (:mod:`motionhyst.analysis.stability`).  At ``v = 0`` or ``z = 0``
        the one-sided derivatives of ``v z > 0`` are taken (``z'`` is continuous there).

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
        >>> el = BoucWen(k=20.0, fc=0.05, n=1.0, beta=0.5, gamma=0.5)
        >>> zdot, w, *_ = el.state_equation([0.025], 0.01)   # loading half-way: half of k v
        >>> round(float(zdot[0]), 12), w
        (0.1, 0.025)
        """
        zz = float(np.ravel(z)[0])
        sz = 1.0 if zz >= 0.0 else -1.0
        c = self.beta * (1.0 if v * zz >= 0.0 else -1.0) + self.gamma
        a = abs(zz) / self.fc
        g = 1.0 - c * a ** self.n
        da = self.n * a ** (self.n - 1.0) if a > 0.0 else (1.0 if self.n == 1.0 else 0.0)
        dzz = -self.k * v * c * da * sz / self.fc
        return (np.array([self.k * v * g]), zz, np.array([[dzz]]), np.array([self.k * g]),
                np.array([1.0]), 0.0)

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Numerical describing function ``D = (b1 + j a1) / A`` (eq. 7) at amplitude(s) `A` [N/m].

        From the periodic output (:meth:`periodic_harmonics`); within 1e-10
        relative (measured <= 5e-13 for ``n = 1`` and 3e-12 for ``n = 2`` up to
        ``k A / fc = 3000``), cached per amplitude.  `omega` is ignored
        (rate-independent); the result is broadcast against it.  ``A = 0``
        gives ``k``.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        omega : array_like, optional
            Angular frequency [rad/s]; ignored.
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
        if not (math.isfinite(w0) and abs(w0) <= w_max * (1.0 + 1e-12)):
            raise ValueError(f"|w0| must be <= the saturation force {w_max}, got {w0}")
        if xs.size == 0:
            return np.empty(0)
        u = (self.k / self.fc) * (xs - xs[0])
        return self.fc * self._path(u, float(w0) / self.fc)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None, *, n_samples: int | None = None
                           ) -> NDArray[np.complex128]:
        """Harmonics ``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic output.

        Compiled end to end
        (:func:`~motionhyst.hysteresis._ode_kernels.bouc_wen_periodic`): the
        period is sampled uniformly (`n_samples`, default
        :meth:`default_samples`) with the input's reversal points inserted; the
        model is integrated along the path (exactly for ``n = 1, 2``) from the
        state that repeats after one period (Newton steps on the scalar period
        map with its exact slope); the samples are transformed by an FFT and
        the aliasing of the jumps of ``w''`` and ``w'''`` (at the reversals and,
        for ``n = 1, 2``, where ``w`` crosses 0) is subtracted in closed form
        (:func:`~motionhyst.hysteresis._ode_kernels.alias_of_jumps`), so that
        for ``n = 1, 2`` the error falls as ``N^-5``.  `omega` is ignored.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the input over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency [rad/s]; ignored.
        n_samples : int, optional
            Samples per period (default :meth:`default_samples`).

        Returns
        -------
        ndarray of complex, shape (H + 1,)
            ``W_0 .. W_H``.
        """
        return self._harmonics(X, n_harmonics, n_samples)

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        p = (self.k / self.fc, self.fc, self.n, self.beta + self.gamma, self.beta - self.gamma,
             self._step())
        scale = self.saturation_force if math.isfinite(self.saturation_force) else self.fc
        return Stepping.from_rows([(BOUC_WEN, p)], scale)

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary, in the spelling the element was made with."""
        if self._general is not None:
            return {"model": self.name, **self._general}
        return {"model": self.name, "k": self.k, "fc": self.fc, "n": self.n,
                "beta": self.beta, "gamma": self.gamma}

