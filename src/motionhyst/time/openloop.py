"""Open-loop systems: a stage with a dynamic link, force in, a position out.

The stage is any plant of :mod:`motionhyst.plants` with inertia: its
state-space form :class:`~motionhyst.plants.mechanics.Mechanics`
(``M q'' + C q' + K q = e (u + f0 - w)``, ``x = (q, q')``), the force ``u``
(with the plant's constant offset ``f0``) and the link force ``w`` acting on
the link's coordinate, ``w`` the force of a hysteresis model (any model of
:mod:`motionhyst.hysteresis`) of that coordinate's position; for example

* :class:`~motionhyst.plants.MassSpringDamper`, the stage of the Bouc-Wen
  benchmark (Noel and Schoukens 2016) and of any single-mass test rig
  without feedback, ``m y'' + c y' + k y + w = u``, output ``y``;
* :class:`~motionhyst.plants.MassDamper`, a positioning axis (no spring);
* :class:`~motionhyst.plants.TwoMassStage`, the floating two-mass stage of
  the paper's eqs. (1)-(2) without its controller: ``m1`` actuated (position
  ``y1``, where the link acts), ``m2`` the point of control (``y2``), spring
  ``k`` and damper ``b`` between them; output ``y2`` (default) or ``y1``
  (``TwoMass``, its older name here).

:class:`OpenLoop` simulates the response to a sampled force record from rest,
or the periodic steady state when the record is one period of a periodic
force.  Only the link holds a floating stage (the two-mass stage, or
``k = 0``) in place: from rest, a force the link cannot hold makes it run
away (the simulation says so by its numbers); a periodic steady state exists
only if the position repeats too, is then defined up to a constant and
returned with zero mean, and a stage that moves on by the same distance
every period (a slipping element, a Bouc-Wen link ratcheting under an
unsymmetric force) is reported as having none.

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
  linear stage: classical fourth-order Runge-Kutta on ``(q, q', z)``, one
  compiled integrator for both plants (compiled for the plant's size), with
  the forward sensitivities of the output to the plant's parameters
  (``m, c, k`` or ``m1, m2, b, k``) and ``alpha, beta*gamma, beta*delta, nu``
  when asked (they are what :mod:`motionhyst.identify.input_output` fits with);
* the other links: the stage discretised exactly for a force linear between
  fine steps (first-order hold) and the link advanced by its exact update
  (as :func:`motionhyst.time.simulation.simulate`), implicit in ``w`` and solved by a
  fixed-point iteration; second order in the step.  One compiled run
  (:func:`simulate_elements`) for both plants, with the forward sensitivities
  of the output to the plant's and the link's parameters when asked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import firwin, resample_poly

from motionhyst.core.budget import check_memory
from motionhyst.core.compiled import njit
from motionhyst.hysteresis import BoucWen, Hysteresis
from motionhyst.hysteresis.stepping import (
    DIFFERENTIATED,
    N_PARAMS,
    Stepping,
)
from motionhyst.plants.mass_spring_damper import MassSpringDamper
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.time.engine import (
    MAX_FIXED_POINT_ITERATIONS,
    OPEN,
    FohStep,
    LoopState,
    run_steps,
)

#: Names of the general Bouc-Wen parameters the compiled integrator carries (sensitivity order).
BW_PARAMETERS = ("m", "c", "k", "alpha", "beta_gamma", "beta_delta", "nu")
MIN_SUBSTEPS = 20
STEPS_PER_MODE_PERIOD = 400
PERIODIC_RTOL = 1e-12
SINC_HALF_WIDTH = 64
MAX_PERIODIC_DECAYS = 60.0  # periodic runs stop after this many time constants of the mode


#: The two-mass stage's name as an open-loop plant before the plants had one class.
TwoMass = TwoMassStage

Plant = MassSpringDamper | TwoMassStage
"""An open-loop plant: force in, the link on its (first) mass, a position out."""


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


FINE_BYTES = 48
"""Memory of one integration step of an open-loop run: fine input, midpoints, output [bytes]."""


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
    if sens is not None and az > 0.0:
        f_nu = -(bg * g + bd * d) * math.log(az)
    return f, f_v, f_z, f_nu, g, d


@njit(cache=True, inline="always")
def _deriv(uu, x, s, mass, C, K, dmass, dC, dK, li, lp, acc, dx, ds, sens
           ):  # pragma: no cover - compiled
    """Rates of the state ``(q, q', z)`` of ``M q'' + C q' + K q = e_li (u - z)`` and of
    its sensitivities (columns: the plant's parameters, then alpha, beta*gamma,
    beta*delta, nu; ``lp`` holds those four)."""
    n = len(mass)
    z = x[2 * n]
    for i in range(n):
        f = uu if i == li else 0.0
        for j in range(n):
            f -= C[i, j] * x[n + j]
        for j in range(n):
            f -= K[i, j] * x[j]
        if i == li:
            f -= z
        acc[i] = f / mass[i]
    rf, f_v, f_z, f_nu, g, d = _rate(x[n + li], z, lp[0], lp[1], lp[2], lp[3], sens)
    for i in range(n):
        dx[i] = x[n + i]
        dx[n + i] = acc[i]
    dx[2 * n] = rf
    if sens is not None:
        n_plant = len(dmass)
        nc = len(dmass) + 4
        for i in range(n):
            for col in range(nc):
                ds[i, col] = s[n + i, col]
            for col in range(nc):
                ds[n + i, col] = 0.0
            for j in range(n):
                cij = C[i, j]
                for col in range(nc):
                    ds[n + i, col] -= cij * s[n + j, col]
            for j in range(n):
                kij = K[i, j]
                for col in range(nc):
                    ds[n + i, col] -= kij * s[j, col]
            if i == li:
                for col in range(nc):
                    ds[n + i, col] -= s[2 * n, col]
            mi = mass[i]
            for col in range(nc):
                ds[n + i, col] = ds[n + i, col] / mi
        for col in range(nc):
            ds[2 * n, col] = f_v * s[n + li, col] + f_z * s[2 * n, col]
        for col in range(n_plant):
            for i in range(n):
                t = dmass[col][i] * acc[i]
                for j in range(n):
                    t += dC[col, i, j] * x[n + j]
                for j in range(n):
                    t += dK[col, i, j] * x[j]
                ds[n + i, col] -= t / mass[i]
        ds[2 * n, n_plant] += x[n + li]
        ds[2 * n, n_plant + 1] -= g
        ds[2 * n, n_plant + 2] -= d
        ds[2 * n, n_plant + 3] += f_nu


@njit(cache=True, nogil=True)
def _rk4_run(uf, h, r, mass, C, K, dmass, dC, dK, li, lo, lp, x0, s0, sens
             ):  # pragma: no cover - compiled
    """RK4 with step `h` over ``uf`` (input at half steps); outputs every `r` steps.

    Returns the output ``q[lo]`` and its sensitivities at the record samples
    (the first at the initial state) and the final state and sensitivities
    (``sens``: True, or None for none).  ``mass`` (the diagonal of ``M``) and
    ``dmass`` are tuples, so that the run is compiled for the plant's size.
    """
    n_steps = (uf.shape[0] - 1) // 2
    n_out = n_steps // r + 1
    ns = 2 * len(mass) + 1
    nc = len(dmass) + 4
    y = np.empty(n_out)
    sy = np.zeros((n_out, nc))
    x = x0.copy()
    s = s0.copy()
    acc = np.empty(len(mass))
    k1 = np.empty(ns)
    k2 = np.empty(ns)
    k3 = np.empty(ns)
    k4 = np.empty(ns)
    q1 = np.zeros((ns, nc))
    q2 = np.zeros((ns, nc))
    q3 = np.zeros((ns, nc))
    q4 = np.zeros((ns, nc))
    xt = np.empty(ns)
    st = np.zeros((ns, nc))
    y[0] = x[lo]
    if sens is not None:
        for j in range(nc):
            sy[0, j] = s[lo, j]
    for i in range(n_steps):
        _deriv(uf[2 * i], x, s, mass, C, K, dmass, dC, dK, li, lp, acc, k1, q1, sens)
        for a in range(ns):
            xt[a] = x[a] + 0.5 * h * k1[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + 0.5 * h * q1[a, j]
        _deriv(uf[2 * i + 1], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k2, q2, sens)
        for a in range(ns):
            xt[a] = x[a] + 0.5 * h * k2[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + 0.5 * h * q2[a, j]
        _deriv(uf[2 * i + 1], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k3, q3, sens)
        for a in range(ns):
            xt[a] = x[a] + h * k3[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + h * q3[a, j]
        _deriv(uf[2 * i + 2], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k4, q4, sens)
        for a in range(ns):
            x[a] += h / 6.0 * (k1[a] + 2.0 * k2[a] + 2.0 * k3[a] + k4[a])
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    s[a, j] += h / 6.0 * (q1[a, j] + 2.0 * q2[a, j] + 2.0 * q3[a, j] + q4[a, j])
        if (i + 1) % r == 0:
            o = (i + 1) // r
            y[o] = x[lo]
            if sens is not None:
                for j in range(nc):
                    sy[o, j] = s[lo, j]
    return y, sy, x, s


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
        The plant's output position [m] (``y``; ``y2`` or ``y1`` of a two-mass stage).
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
    """An open-loop plant with a hysteresis link, force in, a position out.

    Parameters
    ----------
    plant : Plant
        The stage, a plant with inertia (:class:`~motionhyst.plants.registry.Plant`);
        the force and the link act on its link coordinate.
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

    A two-mass stage held by a Bouc-Wen link, ``y2`` measured:

    >>> from motionhyst.hysteresis import BoucWen
    >>> sys = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5), BoucWen(k=5e4, fc=20.0, beta=0.6,
    ...                                                        gamma=0.2))
    >>> out = sys.simulate(t, 20 * np.sin(2 * np.pi * 3 * t))   # from rest
    >>> round(float(np.max(np.abs(out.displacement))) * 1e4, 1)
    11.3
    """

    def __init__(self, plant: Plant, hysteresis: Hysteresis | None = None) -> None:
        self.plant = plant
        self.hysteresis = hysteresis

    def __repr__(self) -> str:
        return f"OpenLoop({self.plant!r}, {self.hysteresis!r})"

    def _k_link(self) -> float:
        return self.hysteresis.initial_stiffness if self.hysteresis is not None else 0.0

    def default_substeps(self, fs: float) -> int:
        """Integration steps per record sample: >= 20 and >= 400 per period of the fastest
        mode (the link taken as its initial stiffness)."""
        f_n = self.plant.mechanics().natural_frequency_hz(self._k_link())
        return max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n / fs))

    def _bw_parameters(self) -> NDArray[np.float64] | None:
        h = self.hysteresis
        if h is None:
            return np.array([*self.plant.values(), 0.0, 0.0, 0.0, 1.0])
        if isinstance(h, BoucWen):
            return np.array([*self.plant.values(), *bouc_wen_general(h)])
        return None

    def simulate(self, t: ArrayLike, force: ArrayLike, *, periodic: bool = False,
                 substeps: int | None = None) -> OpenLoopResponse:
        """The output position for a force record, from rest or as the periodic steady state.

        Parameters
        ----------
        t : array_like
            Uniform time grid [s], at least 2 samples.
        force : array_like
            Force at the instants `t` [N].
        periodic : bool
            False: from rest (``q = q' = 0``, link relaxed) at ``t[0]``.  True:
            `force` is one period (or whole periods) of a periodic force; the
            response is the periodic steady state, reached by repeating the
            period until the output changes by less than ``1e-12`` of its
            amplitude from one period to the next.  A floating plant (no spring
            to the ground: the two-mass stage, or ``k = 0``) has such a state
            only if the link carries the force's mean, and then at any constant
            offset: it is returned with zero mean.
        substeps : int, optional
            Integration steps per sample (default :meth:`default_substeps`).

        Returns
        -------
        OpenLoopResponse
        """
        tt, u = check_record(t, force)
        fs = sampling_rate(tt)
        r = substeps or self.default_substeps(fs)
        # the force at every integration step and midpoint, and the response at each step
        check_memory(FINE_BYTES * u.size * r, f"{u.size} samples of {r} integration steps "
                     f"each", "fewer samples or substeps")
        p = self._bw_parameters()
        if periodic and self.hysteresis is None and self.plant.mechanics().floating:
            y = _floating_linear_periodic(self.plant.mechanics(), u, fs)
        elif p is not None:
            y, _ = simulate_bouc_wen(p, u, fs, r, periodic=periodic, sensitivities=False,
                                     plant=self.plant)
        else:
            y = self._simulate_elements(u, fs, r, periodic)
        return OpenLoopResponse(tt, u, y, periodic)

    def _simulate_elements(self, u, fs, r, periodic, upsampled=None):
        """Displacement of a link of exact-update elements (`upsampled`: ``fine_input(u, r,
        periodic)`` if already computed)."""
        st = Stepping.empty() if self.hysteresis is None else self.hysteresis.time_stepping()
        y, _ = simulate_elements(self.plant.mechanics(), st, u, fs, r, periodic=periodic,
                                 k_link=self._k_link(), upsampled=upsampled)
        return y


def _floating_linear_periodic(mech: Mechanics, u: NDArray[np.float64], fs: float
                              ) -> NDArray[np.float64]:
    """Periodic steady state of a floating plant without a link, from the record's spectrum.

    Nothing damps its rigid-body motion, so repeating the period never forgets
    the start; the steady state is ``G(f) U(f)`` line by line (exact for a
    band-limited period), with zero mean.  A force with a nonzero mean has none.
    """
    U = np.fft.rfft(u)
    if abs(U[0]) > 1e-9 * max(float(np.max(np.abs(U))), 1e-300):
        raise ValueError("the force has a nonzero mean: a floating stage without a link "
                         "runs away and has no periodic steady state")
    f = np.fft.rfftfreq(u.size, 1.0 / fs)
    Y = np.zeros_like(U)
    Y[1:] = mech.frequency_response(f[1:]) * U[1:]
    if u.size % 2 == 0:
        Y[-1] = Y[-1].real  # the Nyquist line of a real signal
    return np.fft.irfft(Y, u.size)


_NO_STEADY_STATE = ("the periodic steady state was not reached (the response does not settle "
                    "from one period to the next)")
_FLOATING_HINT = ("; the stage floats and the link does not hold it in place: it drifts")


def _settled(y: NDArray[np.float64], prev: NDArray[np.float64], floating: bool,
             last_step: list[float]) -> bool:
    """True if a period's output `y` repeats the previous one to :data:`PERIODIC_RTOL`.

    A floating stage whose link lets it move on by the same distance every
    period (a Bouc-Wen link ratchets under an unsymmetric force; a slipping
    element does not hold the stage) has no periodic steady state: raised as
    such, with the drift, once the motion repeats and its position moves on by
    the same step twice (`last_step` keeps the previous step).
    """
    if not floating:
        return bool(np.max(np.abs(y - prev)) <= PERIODIC_RTOL * np.max(np.abs(y)))
    tol = PERIODIC_RTOL * np.ptp(y)
    if np.max(np.abs(y - prev)) <= tol:
        return True
    step = float(np.mean(y) - np.mean(prev))
    if (np.max(np.abs(y - prev - step)) <= tol and abs(step) > 10 * tol and last_step
            and abs(step - last_step[0]) <= 1e-6 * abs(step)):
        raise ValueError(f"no periodic steady state: the stage floats and the link does not "
                         f"hold it in place; it drifts {step:.3g} m per period (only a run "
                         f"from rest describes this force)")
    last_step[:] = [step]
    return False


def _check_converged(worst: int) -> None:
    if worst > MAX_FIXED_POINT_ITERATIONS:
        raise ValueError("the link's implicit step did not converge; use more substeps")


def _max_periods(mech: Mechanics, k_link: float, period_s: float) -> int:
    """Periods a periodic run may take: until the slowest mode has decayed
    :data:`MAX_PERIODIC_DECAYS` times (at most 1000, at least 4)."""
    tau = mech.decay_time(k_link)
    if not math.isfinite(tau):
        return 1000
    return int(min(1000, max(4, math.ceil(MAX_PERIODIC_DECAYS * tau / period_s) + 2)))


def _periodic_output(next_period, periods: int, floating: bool, sensitivities: bool
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Run periods until the output (and its sensitivities) repeat: the last period's.

    `next_period()` runs one more period from the state the previous one left
    and returns its output and sensitivities, one sample longer than the
    period, and whether the state is still finite.  The output repeats as
    :func:`_settled` judges, the sensitivities to 1e-8 of their largest
    values; a floating stage's output is returned with zero mean (it is
    defined up to a constant).  Raises if `periods` do not settle.
    """
    prev = None
    step: list[float] = []
    for _ in range(periods):
        y, sy, finite = next_period()
        y, sy = y[:-1], sy[:-1]
        if prev is not None:
            ok = _settled(y, prev[0], floating, step)
            if sensitivities:
                ok &= bool(np.all(np.max(np.abs(sy - prev[1]), axis=0)
                                  <= 1e-8 * (np.max(np.abs(sy), axis=0) + 1e-300)))
            if ok:
                if floating:  # defined up to a constant: zero mean
                    return y - np.mean(y), sy - np.mean(sy, axis=0)
                return y, sy
        if not finite:
            break
        prev = (y, sy)
    raise ValueError(_NO_STEADY_STATE + (_FLOATING_HINT if floating else ""))


#: Largest distance of a time stamp from the record's uniform grid, in sampling intervals
#: (time columns written with few digits, e.g. 12.3457 s at 750 Hz, are off by up to 4 %)
STAMP_TOLERANCE = 0.05


def check_record(t: ArrayLike, force: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A uniform time grid and a finite force of the same length, as float arrays.

    The grid is the uniform one nearest to `t` (:func:`sampling_rate`);
    stamps rounded when written are accepted within :data:`STAMP_TOLERANCE` of
    a sampling interval.  Raises ``ValueError`` (one line) otherwise.

    Examples
    --------
    >>> t = np.round(np.arange(3000) / 750, 4)   # stamps written with 4 decimals
    >>> tt, u = check_record(t, np.zeros(3000))
    >>> print(f"{sampling_rate(tt):.4f}")
    750.0000
    >>> try:
    ...     check_record([0.0, 0.1, 0.3], [1.0, 2.0, 3.0])
    ... except ValueError as exc:
    ...     print(exc)
    time must increase in uniform steps (the stamp 0.1 s is 0.22 sampling intervals off the
    uniform grid)
    """
    tt = np.asarray(t, dtype=float)
    u = np.asarray(force, dtype=float)
    if tt.ndim != 1 or u.ndim != 1 or tt.size != u.size:
        raise ValueError("time and force must be 1-D and of equal length")
    if tt.size < 2:
        raise ValueError("a record needs at least 2 samples")
    if not (np.all(np.isfinite(tt)) and np.all(np.isfinite(u))):
        raise ValueError("time and force must be finite")
    if not np.all(np.diff(tt) > 0):
        raise ValueError("time must increase")
    t0, dt = _uniform_grid(tt)
    off = np.abs(tt - (t0 + dt * np.arange(tt.size))) / dt
    worst = int(np.argmax(off))
    if off[worst] > STAMP_TOLERANCE:
        raise ValueError(f"time must increase in uniform steps (the stamp {tt[worst]:.9g} s is "
                         f"{off[worst]:.2g} sampling intervals off the uniform grid)")
    return tt, u


def _uniform_grid(t: NDArray[np.float64]) -> tuple[float, float]:
    """Start and step of the uniform grid nearest to `t` (least squares)."""
    i = np.arange(t.size, dtype=float) - 0.5 * (t.size - 1)
    tc = t - t.mean()
    dt = float(i @ tc / (i @ i))
    return float(t.mean() - 0.5 * (t.size - 1) * dt), dt


def sampling_rate(t: NDArray[np.float64]) -> float:
    """Rate of a record's uniform grid [Hz]: the step fitted to all its stamps.

    Exact for exact stamps; for stamps rounded when written, far more exact
    than the difference of two of them.
    """
    return 1.0 / _uniform_grid(np.asarray(t, dtype=float))[1]


def simulate_bouc_wen(p: NDArray[np.float64], u: NDArray[np.float64], fs: float, r: int, *,
                      periodic: bool, sensitivities: bool, upsampled: NDArray | None = None,
                      plant: Plant | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Output of a plant with a general Bouc-Wen link and its sensitivities (RK4).

    Parameters
    ----------
    p : ndarray
        The plant's parameters (:attr:`MassSpringDamper.PARAMETERS`,
        :attr:`TwoMass.PARAMETERS`), then ``alpha, beta*gamma, beta*delta, nu``
        (for the mass-spring-damper: :data:`BW_PARAMETERS`).
    u : ndarray
        Force record at `fs` [N].
    fs : float
        Record sampling frequency [Hz].
    r : int
        RK4 steps per sample.
    periodic : bool
        From rest (False) or the periodic steady state of the period `u` (True;
        with zero mean for a floating plant, as :meth:`OpenLoop.simulate`).
    sensitivities : bool
        Also return ``dy/dp`` (else an empty array).
    upsampled : ndarray, optional
        ``fine_input(u, 2 r, periodic)``, if already computed (it depends on `u` only).
    plant : MassSpringDamper or TwoMass, optional
        The kind of plant (and its output) the first entries of `p` are the
        parameters of; its own values are not used.  Default: a mass-spring-damper.

    Returns
    -------
    y : ndarray
        Output position at the record samples [m].
    dy_dp : ndarray, shape ``(len(u), len(p))``
        Its derivatives in ``p``.

    Examples
    --------
    >>> import numpy as np
    >>> u = 30 * np.sin(2 * np.pi * 5 * np.arange(300) / 750)
    >>> p = np.array([2.0, 3.0, 20.0, 2e5, 5e4, 800.0, -1100.0, 1.0])
    >>> y, dy = simulate_bouc_wen(p, u, 750.0, 20, periodic=False, sensitivities=True,
    ...                           plant=TwoMass(1.0, 1.0, 0.0, 1.0))
    >>> y.shape, dy.shape
    ((300,), (300, 8))
    """
    structure = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
    n_plant = len(structure.PARAMETERS)
    p = np.ascontiguousarray(p, dtype=float)
    if p.size != n_plant + 4:
        raise ValueError(f"expected {n_plant + 4} parameters, got {p.size}")
    mech = structure.mechanics(p[:n_plant])
    lp = np.ascontiguousarray(p[n_plant:])
    h = 1.0 / (fs * r)
    uf = upsampled if upsampled is not None else fine_input(u, 2 * r, periodic)
    if mech.force_offset:  # the plant's constant force offset adds to the force
        uf = uf + mech.force_offset
    ns = 2 * mech.n + 1
    x0 = np.zeros(ns)
    s0 = np.zeros((ns, p.size))

    def run(x0, s0):
        # the masses and parameter count as tuples: compiled for their sizes (unrolled loops);
        # no sensitivities: None, which removes their code from the compiled run
        return _rk4_run(uf, h, r, tuple(mech.mass), mech.C, mech.K,
                        tuple(tuple(row) for row in mech.dmass), mech.dC, mech.dK, mech.link,
                        mech.output, lp, x0, s0, True if sensitivities else None)

    if not periodic:
        y, sy, _, _ = run(x0, s0)
        return y, sy
    if isinstance(structure, MassSpringDamper):  # as ever: a negative c or k taken as 0
        mech_tau = structure.mechanics([p[0], max(p[1], 0.0), max(p[2], 0.0)])
    else:
        mech_tau = mech
    if mech.floating and lp[0] > 0.0:
        # the lightly damped mode of the stage on its link would take long to forget a start
        # from rest: start from the steady state with the link a spring alpha
        x0[:-1] = mech.linear_periodic_state(u, fs, lp[0])
        x0[-1] = lp[0] * x0[mech.link]
    state = [x0, s0]

    def next_period():
        y, sy, state[0], state[1] = run(*state)
        return y, sy, bool(np.all(np.isfinite(state[0])))

    return _periodic_output(next_period, _max_periods(mech_tau, lp[0], u.size / fs),
                            mech.floating, bool(sensitivities))


def simulate_elements(mech: Mechanics, stepping: Stepping, u: NDArray[np.float64], fs: float,
                      r: int, *, periodic: bool, k_link: float = 0.0,
                      upsampled: NDArray[np.float64] | None = None,
                      dparams: NDArray[np.float64] | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Output of a plant with a link of exact-update elements, and its sensitivities (FOH).

    The plant is discretised exactly for a force linear over each of the `r`
    fine steps per sample (:meth:`Mechanics.foh`), the elements advanced by
    their exact update (:func:`~motionhyst.hysteresis.stepping.advance`), the
    step's link force solved by a fixed-point iteration; with `dparams`, the
    forward sensitivities of the output are carried along in the same compiled
    run (the partials of each element's update,
    :func:`~motionhyst.hysteresis.stepping.advance_partials`, and of the
    implicit link force).  What :meth:`OpenLoop.simulate` runs for such a link,
    and the exact Jacobian of :mod:`motionhyst.identify.input_output`; the
    output is the same with or without the sensitivities, bit for bit.

    Parameters
    ----------
    mech : Mechanics
        The plant.
    stepping : Stepping
        The link's rows (:meth:`Hysteresis.time_stepping`; empty: no link).
    u : ndarray
        Force record [N] at `fs` [Hz].
    r : int
        Fine steps per sample.
    periodic : bool
        From rest (False) or the periodic steady state of the period `u`
        (True: periods repeated until the output changes by less than
        :data:`PERIODIC_RTOL` of its amplitude and, with `dparams`, the
        sensitivities by less than 1e-8 of theirs; returned with zero mean for
        a floating plant, as :meth:`OpenLoop.simulate`).
    k_link : float
        The link's initial stiffness [N/m] (bounds the periods a periodic run may take).
    upsampled : ndarray, optional
        ``fine_input(u, r, periodic)``, if already computed.
    dparams : ndarray, shape (elements, N_PARAMS, P_link), optional
        The derivatives of the rows' parameters in the link's `P_link`
        parameters (every element of a kind in
        :data:`~motionhyst.hysteresis.stepping.DIFFERENTIATED`); None: no
        sensitivities.

    Returns
    -------
    y : ndarray
        Output position at the samples [m].
    dy : ndarray, shape (len(u), p + P_link)
        Its derivatives in the plant's `p` parameters (the rows of
        ``mech.dmass``), then the link's; ``(len(u), 0)`` without `dparams`.

    Examples
    --------
    A Jenkins link ``(k, fc)``: its row ``(k, fc)`` moves one for one with them.

    >>> from motionhyst.hysteresis import Jenkins
    >>> link = Jenkins(k=2e4, fc=10.0)
    >>> t = np.arange(256) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t)
    >>> dparams = np.zeros((1, N_PARAMS, 2))
    >>> dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0
    >>> plant = MassSpringDamper(2.0, 10.0, 5e4)
    >>> y, dy = simulate_elements(plant.mechanics(), link.time_stepping(), u, 750.0, 10,
    ...                           periodic=False, dparams=dparams)
    >>> ref = OpenLoop(plant, link).simulate(t, u, substeps=10)
    >>> bool(np.array_equal(y, ref.displacement)), dy.shape    # m, c, k, link k, fc
    (True, (256, 5))
    """
    h = 1.0 / (fs * r)
    sens = dparams is not None
    Ad, B0, B1, dAd, dB0, dB1 = mech.foh(h, derivatives=sens)
    ns = Ad.shape[0]
    n_el = stepping.codes.size
    if sens:
        if not np.all(np.isin(stepping.codes, DIFFERENTIATED)):
            raise ValueError("sensitivities need elements of the kinds advance_partials "
                             "differentiates (stop, Dahl, LuGre, Maxwell)")
        dp = np.ascontiguousarray(dparams, dtype=float)
        n_sens = dAd.shape[0] + dp.shape[2]
    else:
        dp = np.zeros((n_el, N_PARAMS, 0))
        n_sens = 0
    uf = np.ascontiguousarray(upsampled if upsampled is not None
                              else fine_input(u, r, periodic), dtype=float)
    if mech.force_offset:  # the plant's constant force offset adds to the force
        uf = uf + mech.force_offset
    ftol = 1e-13 * stepping.scale

    steps = [FohStep(Ad, B0, B1, h, dAd, dB0, dB1)]
    C = np.zeros((3, ns))  # the output, then the link's displacement and velocity
    C[0, mech.output] = 1.0
    C[1, mech.link] = 1.0
    C[2, ns // 2 + mech.link] = 1.0

    def run(x, s, sx, ss):
        # each period starts afresh from the state the previous one left
        state = LoopState(x, s, sx, ss)
        Y, SY, _, _, worst, _ = run_steps(steps, C, np.zeros(3), 1, stepping, uf, state,
                                          vel_row=2, convention=OPEN, ftol=ftol,
                                          record_every=r,
                                          record_initial=True, dparams=dp if sens else None)
        _check_converged(worst)
        return Y[:, 0], SY[:, 0, :], state.z, state.s, state.sx, state.ss

    x, s = np.zeros(ns), np.array(stepping.state0, dtype=float)
    sx, ss = np.zeros((ns, n_sens)), np.zeros((n_el, n_sens))
    if not periodic:
        y, sy, *_ = run(x, s, sx, ss)
        return y, sy
    state = [x, s, sx, ss]

    def next_period():
        y, sy, *state[:] = run(*state)
        return y, sy, bool(np.all(np.isfinite(state[0])))

    return _periodic_output(next_period, _max_periods(mech, k_link, u.size / fs),
                            mech.floating, sens)
