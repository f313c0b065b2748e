"""Open-loop systems: a mass on a spring and damper with a dynamic link, force in, position out.

The stage of the Bouc-Wen benchmark (Noel and Schoukens 2016) and of any
single-mass test rig without feedback,

.. math::

    m \\ddot y + c \\dot y + k y + w = u,

with ``w`` the force of a hysteresis model acting on the position ``y``
(any model of :mod:`motionhyst.hysteresis`).  :class:`OpenLoop` simulates the
response to a sampled force record from rest, or the periodic steady state
when the record is one period of a periodic force.

Accuracy
--------
A sampled force says nothing about the force between samples; like the
benchmark's own data, the record is taken as band-limited and upsampled by
zero-padding its spectrum (:func:`upsample`: exact for a periodic record, the
record's even extension otherwise, so that its ends do not ring).  The
system is then integrated with a fine fixed step, ``substeps`` per sample
(default: at least 20 and at least 400 per period of the undamped mode):

* Bouc-Wen links (every parameter set, :class:`~motionhyst.hysteresis.BoucWen`'s
  normalised form mapped exactly onto the general one
  ``z' = alpha y' - beta (gamma |y'| |z|^(nu-1) z + delta y' |z|^nu)``) and the
  linear stage: classical fourth-order Runge-Kutta on ``(y, y', z)``, with the
  forward sensitivities of ``y`` to ``m, c, k, alpha, beta*gamma, beta*delta, nu``
  when asked (they are what :mod:`motionhyst.identify.input_output` fits with);
* the other links: the stage discretised exactly for a force linear between
  fine steps (first-order hold) and the link advanced by its exact update
  (as :func:`motionhyst.simulate.simulate`), implicit in ``w`` and solved by a
  fixed-point iteration; second order in the step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import firwin, resample_poly

from motionhyst._jit import njit
from motionhyst.hysteresis import BoucWen, Hysteresis
from motionhyst.hysteresis.stepping import GL_T, GL_W, Stepping, advance
from motionhyst.simulate import MAX_FIXED_POINT_ITERATIONS

#: Names of the general Bouc-Wen parameters the compiled integrator carries (sensitivity order).
BW_PARAMETERS = ("m", "c", "k", "alpha", "beta_gamma", "beta_delta", "nu")
MIN_SUBSTEPS = 20
STEPS_PER_MODE_PERIOD = 400
PERIODIC_RTOL = 1e-12
SINC_HALF_WIDTH = 64
MAX_PERIODIC_DECAYS = 60.0  # periodic runs stop after this many time constants of the mode


class MassSpringDamper:
    """A single mass on a linear spring and damper: ``m y'' + c y' + k y = u - w``.

    Parameters
    ----------
    m : float
        Mass [kg], > 0.
    c : float
        Viscous damping [N s/m], >= 0.
    k : float
        Stiffness [N/m], >= 0.

    Examples
    --------
    >>> p = MassSpringDamper(m=2.0, c=10.0, k=5e4)
    >>> round(p.resonance_hz, 2), round(p.damping_ratio, 4)
    (25.16, 0.0158)
    >>> abs(p.frequency_response(0.0))   # 1 / k at DC
    2e-05
    """

    def __init__(self, m: float, c: float, k: float) -> None:
        self.m = _check(m, "m", positive=True)
        self.c = _check(c, "c", positive=False)
        self.k = _check(k, "k", positive=False)

    def __repr__(self) -> str:
        return f"MassSpringDamper(m={self.m!r}, c={self.c!r}, k={self.k!r})"

    @property
    def resonance_hz(self) -> float:
        """Undamped natural frequency ``sqrt(k/m) / (2 pi)`` [Hz]."""
        return math.sqrt(self.k / self.m) / (2 * math.pi)

    @property
    def damping_ratio(self) -> float:
        """``c / (2 sqrt(k m))`` [-] (inf for ``k = 0``)."""
        return self.c / (2 * math.sqrt(self.k * self.m)) if self.k > 0 else math.inf

    def frequency_response(self, f_hz: ArrayLike) -> NDArray[np.complex128] | complex:
        """``Y / U = 1 / (m s^2 + c s + k)`` at ``s = 2 pi j f`` [m/N]."""
        s = 2j * np.pi * np.asarray(f_hz, dtype=float)
        out = 1.0 / (self.m * s * s + self.c * s + self.k)
        return complex(out) if np.ndim(out) == 0 else out

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary (the ``[stage]`` table of a scenario)."""
        return {"type": "mass-spring-damper", "m": self.m, "c": self.c, "k": self.k}


def _check(value, name: str, positive: bool) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or (v <= 0 if positive else v < 0):
        raise ValueError(f"{name} must be finite and {'> 0' if positive else '>= 0'}, "
                         f"got {value!r}")
    return v


def upsample(u: ArrayLike, factor: int, periodic: bool) -> NDArray[np.float64]:
    """Band-limited upsampling of a record.

    Parameters
    ----------
    u : array_like
        Samples, 1-D, at least 2.
    factor : int
        New samples per old sample, >= 1.
    periodic : bool
        True if the record is a whole number of periods of a periodic signal:
        the spectrum is zero-padded (exact for a signal band-limited below half
        the sampling rate) when the record's length has no prime factor above
        7, else as below with the record wrapped around.  False: the record is
        extended by its mirror image at both ends (no jump) and interpolated by
        a Kaiser-windowed sinc (beta = 14) spanning 128 samples, flat to
        about 1e-7 up to 0.8 of the Nyquist frequency.

    Returns
    -------
    ndarray
        ``(len(u) - 1) * factor + 1`` samples (``len(u) * factor`` if periodic);
        every `factor`-th one is the input sample (to the interpolator's accuracy).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(64) / 64
    >>> fine = upsample(np.sin(2 * np.pi * 3 * t), 4, periodic=True)
    >>> bool(np.allclose(fine, np.sin(2 * np.pi * 3 * np.arange(256) / 256)))
    True
    >>> t = np.arange(2000) / 2000   # 40.1 cycles: not periodic in the record
    >>> fine = upsample(np.sin(2 * np.pi * 40.1 * t), 8, periodic=False)
    >>> exact = np.sin(2 * np.pi * 40.1 * np.arange(fine.size) / 16000)
    >>> bool(np.max(np.abs(fine - exact)[400:-400]) < 1e-5)   # away from the ends
    True
    """
    x = np.asarray(u, dtype=float)
    n = x.size
    if factor == 1:
        return x.copy()
    if periodic and _smooth_length(n):
        spec = np.fft.rfft(x)
        if n % 2 == 0:
            spec[-1] *= 0.5  # the Nyquist line splits between +f and -f
        padded = np.zeros(n * factor // 2 + 1, dtype=complex)
        padded[: spec.size] = spec
        return np.fft.irfft(padded, n * factor) * factor
    half = SINC_HALF_WIDTH
    pad = half + 2
    ext = np.pad(x, pad, mode="wrap" if periodic else "reflect")
    taps = firwin(2 * half * factor + 1, 1.0 / factor, window=("kaiser", 14.0))
    fine = resample_poly(ext, factor, 1, window=taps)[pad * factor:]
    return fine[: n * factor] if periodic else fine[: (n - 1) * factor + 1]


def _smooth_length(n: int) -> bool:
    for p in (2, 3, 5, 7):
        while n % p == 0:
            n //= p
    return n == 1


def fine_input(u: NDArray[np.float64], factor: int, periodic: bool) -> NDArray[np.float64]:
    """The record upsampled for integration: one period plus its first sample again if
    `periodic`, else ``(len(u) - 1) * factor + 1`` samples.

    A record from rest that holds two or more whole periods of its signal
    (:func:`is_periodic_record`) is upsampled as periodic (exact), otherwise
    through its mirror image (:func:`upsample`).
    """
    if periodic:
        fine = upsample(u, factor, periodic=True)
        return np.concatenate([fine, fine[:1]])
    if is_periodic_record(u) is not None:
        return upsample(u, factor, periodic=True)[: (u.size - 1) * factor + 1]
    return upsample(u, factor, periodic=False)


def is_periodic_record(u: NDArray[np.float64], rtol: float = 1e-9) -> int | None:
    """Samples per period if `u` is two or more whole periods of one signal, else None."""
    n = u.size
    scale = float(np.max(np.abs(u))) if n else 0.0
    for p in range(2, n // 2 + 1):
        if n % p == 0 and np.all(np.abs(u.reshape(-1, p) - u[:p]) <= rtol * scale):
            return p
    return None


# ----------------------------------------------------------------- compiled Bouc-Wen integrator
@njit(cache=True, inline="always")
def _rate(v, z, alpha, bg, bd, nu, sens):  # pragma: no cover - compiled
    """``z'`` and its partial derivatives in v, z and nu."""
    az = abs(z)
    if nu == 1.0:
        pn1 = 1.0
        pn = az
    else:
        pn1 = az ** (nu - 1.0) if az > 0.0 else 0.0
        pn = pn1 * az
    av = abs(v)
    sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
    sz = 1.0 if z > 0.0 else (-1.0 if z < 0.0 else 0.0)
    g = av * pn1 * z      # |v| |z|^(nu-1) z
    d = v * pn            # v |z|^nu
    f = alpha * v - bg * g - bd * d
    f_v = alpha - bg * sv * pn1 * z - bd * pn
    f_z = -nu * pn1 * (bg * av + bd * v * sz)
    f_nu = 0.0
    if sens and az > 0.0:
        f_nu = -(bg * g + bd * d) * math.log(az)
    return f, f_v, f_z, f_nu, g, d


@njit(cache=True, inline="always")
def _deriv(uu, x, s, p, dx, ds, sens):  # pragma: no cover - compiled
    m, c, k, alpha, bg, bd, nu = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    y, v, z = x[0], x[1], x[2]
    a = (uu - c * v - k * y - z) / m
    f, f_v, f_z, f_nu, g, d = _rate(v, z, alpha, bg, bd, nu, sens)
    dx[0] = v
    dx[1] = a
    dx[2] = f
    if sens:
        for j in range(7):
            sy, sv, sz = s[0, j], s[1, j], s[2, j]
            ds[0, j] = sv
            ds[1, j] = (-c * sv - k * sy - sz) / m
            ds[2, j] = f_v * sv + f_z * sz
        ds[1, 0] -= a / m
        ds[1, 1] -= v / m
        ds[1, 2] -= y / m
        ds[2, 3] += v
        ds[2, 4] -= g
        ds[2, 5] -= d
        ds[2, 6] += f_nu


@njit(cache=True, nogil=True)
def _rk4_run(uf, h, r, p, x0, s0, sens):  # pragma: no cover - compiled
    """RK4 with step `h` over ``uf`` (input at half steps); outputs every `r` steps.

    Returns the output ``y`` and its sensitivities at the record samples
    (the first at the initial state) and the final state and sensitivities.
    """
    n_steps = (uf.shape[0] - 1) // 2
    n_out = n_steps // r + 1
    y = np.empty(n_out)
    sy = np.zeros((n_out, 7))
    x = x0.copy()
    s = s0.copy()
    k1 = np.empty(3)
    k2 = np.empty(3)
    k3 = np.empty(3)
    k4 = np.empty(3)
    q1 = np.zeros((3, 7))
    q2 = np.zeros((3, 7))
    q3 = np.zeros((3, 7))
    q4 = np.zeros((3, 7))
    xt = np.empty(3)
    st = np.zeros((3, 7))
    y[0] = x[0]
    if sens:
        for j in range(7):
            sy[0, j] = s[0, j]
    for i in range(n_steps):
        _deriv(uf[2 * i], x, s, p, k1, q1, sens)
        for a in range(3):
            xt[a] = x[a] + 0.5 * h * k1[a]
        if sens:
            for a in range(3):
                for j in range(7):
                    st[a, j] = s[a, j] + 0.5 * h * q1[a, j]
        _deriv(uf[2 * i + 1], xt, st, p, k2, q2, sens)
        for a in range(3):
            xt[a] = x[a] + 0.5 * h * k2[a]
        if sens:
            for a in range(3):
                for j in range(7):
                    st[a, j] = s[a, j] + 0.5 * h * q2[a, j]
        _deriv(uf[2 * i + 1], xt, st, p, k3, q3, sens)
        for a in range(3):
            xt[a] = x[a] + h * k3[a]
        if sens:
            for a in range(3):
                for j in range(7):
                    st[a, j] = s[a, j] + h * q3[a, j]
        _deriv(uf[2 * i + 2], xt, st, p, k4, q4, sens)
        for a in range(3):
            x[a] += h / 6.0 * (k1[a] + 2.0 * k2[a] + 2.0 * k3[a] + k4[a])
        if sens:
            for a in range(3):
                for j in range(7):
                    s[a, j] += h / 6.0 * (q1[a, j] + 2.0 * q2[a, j] + 2.0 * q3[a, j] + q4[a, j])
        if (i + 1) % r == 0:
            o = (i + 1) // r
            y[o] = x[0]
            if sens:
                for j in range(7):
                    sy[o, j] = s[0, j]
    return y, sy, x, s


# ----------------------------------------------------------------- other links: FOH + exact update
@njit(cache=True, nogil=True)
def _foh_link_run(Ad, B0, B1, uf, r, codes, params, glt, glw, h, ftol, max_iter, x0, s0
                  ):  # pragma: no cover - compiled
    """Stage (FOH, state (y, v)), link elements advanced exactly; outputs every r steps."""
    n_steps = uf.shape[0] - 1
    n_out = n_steps // r + 1
    m = codes.shape[0]
    y = np.empty(n_out)
    x = x0.copy()
    s = s0.copy()
    s_prev = s0.copy()
    s_new = s0.copy()
    w_prev = 0.0
    for j in range(m):
        w_prev += advance(codes[j], params[j], s[j], s[j], 0.0, 0.0, 0.0, True, glt, glw)[1]
    y[0] = x[0]
    dx_prev = 0.0
    worst = 0
    for i in range(n_steps):
        # y_{i+1} = base + B1[0] * (-w_{i+1})
        f0 = uf[i] - w_prev
        base_y = Ad[0, 0] * x[0] + Ad[0, 1] * x[1] + B0[0] * f0 + B1[0] * uf[i + 1]
        wt = w_prev
        it = 0
        change = math.inf
        while True:
            it += 1
            dx = base_y - B1[0] * wt - x[0]
            wn = 0.0
            for j in range(m):
                s_new[j], fj = advance(codes[j], params[j], s[j], s_prev[j], dx, dx_prev, h,
                                        i == 0, glt, glw)
                wn += fj
            # converged, or stalled at the rounding floor (a contraction's changes stop
            # falling only there: rate terms such as LuGre's sigma1 z' amplify the rounding
            # of dx by ~ sigma1 / h)
            last = change
            change = abs(wn - wt)
            done = change <= ftol or m == 0 or (change <= 1e3 * ftol and change >= last)
            wt = wn
            if done or it > max_iter:
                break
        if it > worst:
            worst = it
        dx = base_y - B1[0] * wt - x[0]
        f1 = uf[i + 1] - wt
        x0n = Ad[0, 0] * x[0] + Ad[0, 1] * x[1] + B0[0] * f0 + B1[0] * f1
        x1n = Ad[1, 0] * x[0] + Ad[1, 1] * x[1] + B0[1] * f0 + B1[1] * f1
        x[0] = x0n
        x[1] = x1n
        for j in range(m):
            s_prev[j] = s[j]
            s[j] = s_new[j]
        w_prev = wt
        dx_prev = dx
        if (i + 1) % r == 0:
            y[(i + 1) // r] = x[0]
    return y, x, s, w_prev, worst


# ----------------------------------------------------------------- the system
def bouc_wen_general(link: BoucWen) -> tuple[float, float, float, float]:
    """``(alpha, beta*gamma, beta*delta, nu)`` of a Bouc-Wen link in the general form.

    The normalised form ``(k, fc, n, beta_n, gamma_n)`` maps exactly onto
    ``alpha = k``, ``beta*gamma = k beta_n / fc^n``, ``beta*delta = k gamma_n / fc^n``,
    ``nu = n`` (:attr:`BoucWen.general`; the force is the general form's ``z``).
    """
    g = link.general
    return (float(g["alpha"]), float(g["beta"] * g["gamma"]), float(g["beta"] * g["delta"]),
            float(g["nu"]))


@dataclass
class OpenLoopResponse:
    """Response of an :class:`OpenLoop` on the record's time grid.

    Attributes
    ----------
    t : ndarray
        Time [s].
    force : ndarray
        Input force [N].
    displacement : ndarray
        Position ``y`` [m].
    periodic : bool
        True for a periodic steady state, False for a run from rest.
    """

    t: NDArray[np.float64]
    force: NDArray[np.float64]
    displacement: NDArray[np.float64]
    periodic: bool

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """The output signals by CSV column name."""
        return {"time": self.t, "displacement": self.displacement}


class OpenLoop:
    """A :class:`MassSpringDamper` with a hysteresis link on its position, force in.

    Parameters
    ----------
    plant : MassSpringDamper
        The stage.
    hysteresis : Hysteresis or None
        The link's model (None: the linear stage alone).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> sys = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=1e4, fc=1.0))
    >>> t = np.arange(512) / 750
    >>> out = sys.simulate(t, 20 * np.sin(2 * np.pi * 3 * t), periodic=True)
    >>> round(float(np.max(out.displacement)) * 1e4, 2)   # between 20 N/(k + kJ) and 20 N/k
    4.63
    """

    def __init__(self, plant: MassSpringDamper, hysteresis: Hysteresis | None = None) -> None:
        self.plant = plant
        self.hysteresis = hysteresis

    def __repr__(self) -> str:
        return f"OpenLoop({self.plant!r}, {self.hysteresis!r})"

    def default_substeps(self, fs: float) -> int:
        """Integration steps per record sample: >= 20 and >= 400 per period of the mode."""
        k_total = self.plant.k + (self.hysteresis.initial_stiffness
                                  if self.hysteresis is not None else 0.0)
        f_n = math.sqrt(max(k_total, 0.0) / self.plant.m) / (2 * math.pi)
        return max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n / fs))

    def _bw_parameters(self) -> NDArray[np.float64] | None:
        h = self.hysteresis
        if h is None:
            return np.array([self.plant.m, self.plant.c, self.plant.k, 0.0, 0.0, 0.0, 1.0])
        if isinstance(h, BoucWen):
            return np.array([self.plant.m, self.plant.c, self.plant.k, *bouc_wen_general(h)])
        return None

    def simulate(self, t: ArrayLike, force: ArrayLike, *, periodic: bool = False,
                 substeps: int | None = None) -> OpenLoopResponse:
        """Displacement for a force record, from rest or as the periodic steady state.

        Parameters
        ----------
        t : array_like
            Uniform time grid [s], at least 2 samples.
        force : array_like
            Force at the instants `t` [N].
        periodic : bool
            False: from rest (``y = y' = 0``, link relaxed) at ``t[0]``.  True:
            `force` is one period (or whole periods) of a periodic force; the
            response is the periodic steady state, reached by repeating the
            period until the output changes by less than ``1e-12`` of its
            amplitude from one period to the next.
        substeps : int, optional
            Integration steps per sample (default :meth:`default_substeps`).

        Returns
        -------
        OpenLoopResponse
        """
        tt, u = check_record(t, force)
        fs = 1.0 / (tt[1] - tt[0])
        r = substeps or self.default_substeps(fs)
        p = self._bw_parameters()
        if p is not None:
            y, _ = simulate_bouc_wen(p, u, fs, r, periodic=periodic, sensitivities=False)
        else:
            y = self._simulate_elements(u, fs, r, periodic)
        return OpenLoopResponse(tt, u, y, periodic)

    def _simulate_elements(self, u, fs, r, periodic, upsampled=None):
        """Displacement of a link of exact-update elements (`upsampled`: ``fine_input(u, r,
        periodic)`` if already computed)."""
        st = Stepping.empty() if self.hysteresis is None else self.hysteresis.time_stepping()
        codes, params, s0, scale = st.codes, st.params, st.state0, st.scale
        h = 1.0 / (fs * r)
        pl = self.plant
        A = np.array([[0.0, 1.0], [-pl.k / pl.m, -pl.c / pl.m]])
        B = np.array([[0.0], [1.0 / pl.m]])
        # first-order hold, split into the weights of the step's two end samples
        M = np.zeros((4, 4))
        M[:2, :2] = A * h
        M[:2, 2] = B[:, 0] * h
        M[2, 3] = 1.0
        from scipy.linalg import expm

        E = expm(M)
        B1 = np.ascontiguousarray(E[:2, 3])
        B0 = np.ascontiguousarray(E[:2, 2] - B1)
        Ad = np.ascontiguousarray(E[:2, :2])
        ftol = 1e-13 * scale
        uf = upsampled if upsampled is not None else fine_input(u, r, periodic)
        if not periodic:
            y, _, _, _, worst = _foh_link_run(Ad, B0, B1, uf, r, codes, params, GL_T, GL_W, h,
                                              ftol, MAX_FIXED_POINT_ITERATIONS, np.zeros(2), s0)
            _check_converged(worst)
            return y
        x, s = np.zeros(2), s0
        prev = None
        for _ in range(_max_periods(pl, u.size / fs)):
            y, x, s, _, worst = _foh_link_run(Ad, B0, B1, uf, r, codes, params, GL_T, GL_W, h,
                                              ftol, MAX_FIXED_POINT_ITERATIONS, x, s)
            _check_converged(worst)
            y = y[:-1]
            if prev is not None and np.max(np.abs(y - prev)) <= PERIODIC_RTOL * np.max(np.abs(y)):
                return y
            prev = y
        raise ValueError("the periodic steady state was not reached (the response does not "
                         "settle from one period to the next)")


def _check_converged(worst: int) -> None:
    if worst > MAX_FIXED_POINT_ITERATIONS:
        raise ValueError("the link's implicit step did not converge; use more substeps")


def _max_periods(plant: MassSpringDamper, period_s: float) -> int:
    tau = 2.0 * plant.m / plant.c if plant.c > 0 else math.inf
    if not math.isfinite(tau):
        return 1000
    return int(min(1000, max(4, math.ceil(MAX_PERIODIC_DECAYS * tau / period_s) + 2)))


def check_record(t: ArrayLike, force: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A uniform time grid and a finite force of the same length, as float arrays.

    Raises ``ValueError`` (one line) otherwise.
    """
    tt = np.asarray(t, dtype=float)
    u = np.asarray(force, dtype=float)
    if tt.ndim != 1 or u.ndim != 1 or tt.size != u.size:
        raise ValueError("time and force must be 1-D and of equal length")
    if tt.size < 2:
        raise ValueError("a record needs at least 2 samples")
    if not (np.all(np.isfinite(tt)) and np.all(np.isfinite(u))):
        raise ValueError("time and force must be finite")
    dt = np.diff(tt)
    if not np.all(dt > 0) or np.max(np.abs(dt - dt.mean())) > 1e-6 * dt.mean():
        raise ValueError("time must increase in uniform steps")
    return tt, u


def simulate_bouc_wen(p: NDArray[np.float64], u: NDArray[np.float64], fs: float, r: int, *,
                      periodic: bool, sensitivities: bool, upsampled: NDArray | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Output of the stage with a general Bouc-Wen link and its sensitivities (RK4).

    Parameters
    ----------
    p : ndarray
        ``m, c, k, alpha, beta*gamma, beta*delta, nu`` (:data:`BW_PARAMETERS`).
    u : ndarray
        Force record at `fs` [N].
    fs : float
        Record sampling frequency [Hz].
    r : int
        RK4 steps per sample.
    periodic : bool
        From rest (False) or the periodic steady state of the period `u` (True).
    sensitivities : bool
        Also return ``dy/dp`` (else an empty array).
    upsampled : ndarray, optional
        ``fine_input(u, 2 r, periodic)``, if already computed (it depends on `u` only).

    Returns
    -------
    y : ndarray
        Displacement at the record samples [m].
    dy_dp : ndarray, shape ``(len(u), 7)``
        Its derivatives in ``p``.
    """
    h = 1.0 / (fs * r)
    uf = upsampled if upsampled is not None else fine_input(u, 2 * r, periodic)
    p = np.ascontiguousarray(p, dtype=float)
    x0 = np.zeros(3)
    s0 = np.zeros((3, 7))
    if not periodic:
        y, sy, _, _ = _rk4_run(uf, h, r, p, x0, s0, sensitivities)
        return y, sy
    plant = MassSpringDamper(p[0], max(p[1], 0.0), max(p[2], 0.0))
    prev = None
    for _ in range(_max_periods(plant, u.size / fs)):
        y, sy, x0, s0 = _rk4_run(uf, h, r, p, x0, s0, sensitivities)
        y, sy = y[:-1], sy[:-1]
        if prev is not None:
            ok = np.max(np.abs(y - prev[0])) <= PERIODIC_RTOL * np.max(np.abs(y))
            if sensitivities:
                ok &= bool(np.all(np.max(np.abs(sy - prev[1]), axis=0)
                                  <= 1e-8 * (np.max(np.abs(sy), axis=0) + 1e-300)))
            if ok:
                return y, sy
        if not np.all(np.isfinite(x0)):
            break
        prev = (y, sy)
    raise ValueError("the periodic steady state was not reached (the response does not "
                     "settle from one period to the next)")
