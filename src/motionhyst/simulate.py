"""Time simulation of the nonlinear loop from rest, for any reference.

The loop is split as in :mod:`motionhyst.loop`: the tracking error and the
deviation ``y1 - r`` are computed directly from the reference's acceleration
``r''`` and the hysteresis force ``w``::

    e      = [T_{r->e} / s^2] r''            + T_{w->e} w
    y1 - r = [(T_{r->y1} - 1) / s^2] r''     + T_{w->y1} w

so no position of size ``r`` is ever subtracted from another.  The linear
part is discretised exactly for inputs that are linear between samples
(first-order hold); the element is advanced with its exact update.  The step
is chosen from the loop's fastest pole and the reference; the user does not
tune it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst._jit import njit
from motionhyst.hysteresis import Hysteresis
from motionhyst.hysteresis._ode_kernels import GL_T, GL_W
from motionhyst.hysteresis.stepping import Stepping, advance, open_loop
from motionhyst.loop import Loop
from motionhyst.lti import (
    discretize_foh,
    divide_s2,
    dss_filter,
    forced_response_foh,
    polysub_exact,
    realize_scaled,
    stack,
)
from motionhyst.systems import TWO_PI

STEPS_PER_POLE_PERIOD = 40
STEPS_PER_REFERENCE_PERIOD = 400


@dataclass
class Simulation:
    """Result of :func:`simulate`: signals on the time grid ``t`` [s].

    Attributes
    ----------
    t : ndarray
        Time [s].
    r, e, y1, y2 : ndarray
        Reference, tracking error ``r - y2``, and the two positions [m].
    u : ndarray
        Actuator force [N] (feedback plus feedforward).
    w : ndarray
        Hysteresis force [N].
    e_linear : ndarray
        Error of the same loop without hysteresis and without hysteresis
        feedforward [m].

    Examples
    --------
    >>> from motionhyst import SineReference, default_scenario, simulate
    >>> sim = simulate(default_scenario().loop(), SineReference(0.01, 5.0), 0.2)
    >>> list(sim.columns())                                # the CSV of ``simulate --time-series``
    ['time', 'reference', 'error', 'y1', 'y2', 'u', 'w', 'error_linear']
    >>> bool(abs(sim.w).max() <= 0.05)                      # the Jenkins link's force, |w| <= fc
    True
    """

    t: NDArray[np.float64]
    r: NDArray[np.float64]
    e: NDArray[np.float64]
    y1: NDArray[np.float64]
    y2: NDArray[np.float64]
    u: NDArray[np.float64]
    w: NDArray[np.float64]
    e_linear: NDArray[np.float64]

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """The signals by name, in CSV column order."""
        return {"time": self.t, "reference": self.r, "error": self.e, "y1": self.y1,
                "y2": self.y2, "u": self.u, "w": self.w, "error_linear": self.e_linear}


def _block_systems(loop: Loop, omega0: float):
    """Realisations in scaled time of ``r'' -> (e, y1 - r)`` and ``w -> (e, y1 - r)``."""
    P = loop._poly
    if P is None:
        raise ValueError("time simulation needs LTI plant and controller")
    ry1 = P["r->y1"]
    n_ae = divide_s2(P["r->e"].num, P["r->e"].den, "the error response to the reference")
    n_ay = divide_s2(polysub_exact(ry1.num, ry1.den), ry1.den,
                      "the response of y1 - r to the reference")
    sys_a = stack([realize_scaled(num, den, omega0) for num, den in (n_ae, n_ay)])
    sys_w = stack([realize_scaled(P[name].num, P[name].den, omega0) for name in ("w->e", "w->y1")])
    return sys_a, sys_w


MAX_FIXED_POINT_ITERATIONS = 50


@njit(cache=True)
def _run(Ad, Bd, Cd, Dd, r, e_lin, dev_lin, uh, h, codes, params, s0, glt, glw, ftol,
         max_iter):  # pragma: no cover - compiled
    """The loop driven by the hysteresis force, around the linear response to ``r''``.

    ``Ad .. Dd`` realise ``w - u_h -> (e, y1 - r)`` (first-order hold);
    ``e_lin``, ``dev_lin`` are the responses to ``r''``.  Each step is implicit
    in ``w`` through the feedthrough ``Dd``: a fixed-point iteration, stopped
    when ``w`` changes by at most `ftol`.  Returns ``e``, ``y1 - r``, ``w`` and
    the largest number of iterations used (``max_iter + 1`` if one step failed
    to converge; the run stops there).
    """
    n_t = r.shape[0]
    n_x = Ad.shape[0]
    m = codes.shape[0]
    x = np.zeros(n_x)
    xn = np.zeros(n_x)
    s = s0.copy()
    s_new = s0.copy()
    s_prev = s0.copy()
    e = np.zeros(n_t)
    dev = np.zeros(n_t)
    w = np.zeros(n_t)
    worst = 0
    r_prev = r[0]
    dev_prev = 0.0  # the element starts at rest at y1 = r(0)
    w_prev = 0.0
    dx_prev = 0.0
    for j in range(m):
        w_prev += advance(codes[j], params[j], s[j], s[j], 0.0, 0.0, 0.0, True, glt, glw)[1]
    for i in range(n_t):
        base_e = e_lin[i]
        base_y = dev_lin[i]
        for j in range(n_x):
            base_e += Cd[0, j] * x[j]
            base_y += Cd[1, j] * x[j]
        hi = h if i > 0 else 0.0
        dr = r[i] - r_prev
        wt = w_prev
        d = base_y + Dd[1, 0] * (wt - uh[i])
        it = 0
        step_prev = np.inf
        while True:
            it += 1
            dx = dr + (d - dev_prev)
            wn = 0.0
            for j in range(m):
                s_new[j], f = advance(codes[j], params[j], s[j], s_prev[j], dx, dx_prev, hi,
                                       i == 1, glt, glw)
                wn += f
            d_next = base_y + Dd[1, 0] * (wn - uh[i])
            # converged when w settles or y1 - r changes by a few ulps only; or at the
            # round-off floor: no longer contracting while y1 - r moves by < 1e-12 of itself
            # (a steep element, e.g. LuGre's sigma1 z' / dt, amplifies the round-off of z)
            step_w = abs(wn - wt)
            step_d = abs(d_next - d)
            scale_d = abs(d) + abs(dx)
            done = (step_w <= ftol or step_d <= 1e-15 * scale_d
                    or (it >= 3 and step_w >= 0.5 * step_prev and step_d <= 1e-12 * scale_d))
            step_prev = step_w
            wt = wn
            if done or m == 0:
                break  # d: the y1 - r the element was advanced with
            d = d_next
            if it > max_iter:
                return e[:i], dev[:i], w[:i], it
        if it > worst:
            worst = it
        s_prev, s, s_new = s, s_new, s_prev
        e[i] = base_e + Dd[0, 0] * (wt - uh[i])
        dev[i] = d
        w[i] = wt
        dx_prev = dr + (d - dev_prev)
        r_prev = r[i]
        dev_prev = d
        w_prev = wt
        for j in range(n_x):
            acc = Bd[j, 0] * (wt - uh[i])
            for q in range(n_x):
                acc += Ad[j, q] * x[q]
            xn[j] = acc
        x, xn = xn, x
    return e, dev, w, worst


def _elements(h: Hysteresis | None) -> tuple[NDArray[np.int64], NDArray[np.float64],
                                             NDArray[np.float64], float]:
    """Kinds, parameters, initial states (at rest) and a force scale [N] of the link's elements.

    Raises
    ------
    ValueError
        For a model the compiled loop has no exact update for.
    """
    st = Stepping.empty() if h is None else h.time_stepping()
    return st.codes, st.params, st.state0, st.scale


def default_step(loop: Loop, max_frequency_hz: float) -> float:
    """Time step [s] resolving the loop's fastest pole and the reference."""
    p = float(np.max(np.abs(loop.closed_loop_poles())))
    return float(min(TWO_PI / (STEPS_PER_POLE_PERIOD * p),
                     1.0 / (STEPS_PER_REFERENCE_PERIOD * max_frequency_hz)))


def simulate(loop: Loop, reference, duration: float, dt: float | None = None,
             force=None) -> Simulation:
    """Simulate the nonlinear loop from rest.

    The linear part is discretised exactly for inputs linear between samples
    (first-order hold); the link is advanced between samples by its exact
    update for a displacement linear in time: the stop operator (Jenkins,
    Maxwell-slip), the closed-form Dahl and Bouc-Wen (``n = 1``) solutions or
    converged RK4 sub-steps (Bouc-Wen, other ``n``), and the exponential LuGre
    update for the step's constant velocity (force ``sigma0 z + sigma1 z' +
    sigma2 v`` with the velocity of the step ending at the sample, as in
    :meth:`~motionhyst.hysteresis.LuGre.response`).  Each step is implicit in
    ``w`` through the hold's feedthrough and solved by fixed-point iteration.

    Parameters
    ----------
    loop : Loop
        An LTI loop whose plant has a rigid-body double integrator; its link
        and hysteresis feedforward (if any) one of Jenkins, MaxwellSlip, Dahl,
        BoucWen, LuGre.
    reference : callable
        ``reference(t) -> (r, r'')``, e.g. the classes of :mod:`motionhyst.references`.
    duration : float
        Simulated time [s], > 0.
    dt : float, optional
        Output and integration step [s]; by default from :func:`default_step`.
    force : callable, optional
        An additional feedforward force [N], ``force(t) -> array`` on the time
        grid (e.g. one learned by :mod:`motionhyst.ilc`); it is added to the
        actuator force like the hysteresis feedforward, linear between samples.

    Returns
    -------
    Simulation

    Raises
    ------
    ValueError
        For invalid arguments, a loop that is not LTI or a link model without
        a time-domain update.
    RuntimeError
        If the implicit step does not converge (a link too stiff for the step).

    Examples
    --------
    The Table I loop running a 20 mm point-to-point move from rest:

    >>> import numpy as np
    >>> from motionhyst import PointToPoint, default_scenario, simulate
    >>> loop = default_scenario().loop()
    >>> move = PointToPoint(0.02, 0.5, 10.0, 1000.0)
    >>> sim = simulate(loop, move, move.duration + 0.2)
    >>> print(f"{sim.t[-1]:.1f} s in {sim.t.size} samples")
    0.3 s in 12001 samples
    >>> print(f"peak error {np.abs(sim.e_linear).max():.2e} m without the link, "
    ...       f"the link adds {np.abs(sim.e - sim.e_linear).max():.2e} m")
    peak error 8.32e-08 m without the link, the link adds 8.28e-09 m
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if loop.feedforward != "rigid-body" and loop.feedforward is not None:
        raise ValueError("unknown feedforward")
    codes, params, s0, f_scale = _elements(loop.hysteresis)
    hff = loop.hysteresis_feedforward
    if hff is not None:
        _elements(hff)  # the same models are supported as feedforward
    f_ref = getattr(reference, "max_frequency_hz", 1.0)
    step = default_step(loop, f_ref) if dt is None else float(dt)
    if not (np.isfinite(step) and step > 0):
        raise ValueError("dt must be finite and > 0")
    n = int(np.ceil(duration / step)) + 1
    if n > 50_000_000:
        raise ValueError(f"{n} time steps: too many; shorten the duration")
    t = np.arange(n) * step
    r, a = reference(t)
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(a))):
        raise ValueError("the reference has non-finite values")
    r = np.ascontiguousarray(r, dtype=float)
    a = np.ascontiguousarray(a, dtype=float)
    omega0 = float(np.max(np.abs(loop.closed_loop_poles())))
    sys_a, sys_w = _block_systems(loop, omega0)
    # a reference that starts with a velocity v0 has r'' = v0 delta(t) + ...: the impulse
    # sets the initial state (delta(t) = omega0 delta(tau) in scaled time)
    v0 = float(getattr(reference, "initial_velocity", 0.0))
    x0 = sys_a[1][:, 0] * v0 * omega0
    Ad, Bd, Cd, Dd = discretize_foh(sys_a, omega0 * step)
    lin = dss_filter(Ad, np.ascontiguousarray(Bd[:, 0]), Cd, np.ascontiguousarray(Dd[:, 0]),
                     a[:, None], x0[:, None])[:, :, 0]
    e_lin = np.ascontiguousarray(lin[:, 0])
    # hysteresis feedforward u_h = phi_hat(r) acts like -w on the loop
    if hff is None:
        uh = np.zeros_like(r)
    elif hff.rate_independent:
        uh = hff.response(r)
    else:  # as the link in the loop: force with the velocity at the sample
        uh = open_loop(*_elements(hff)[:3], r, step, GL_T, GL_W)
    if force is not None:
        uf = np.asarray(force(t), dtype=float)
        if uf.shape != t.shape or not np.all(np.isfinite(uf)):
            raise ValueError("the feedforward force must give one finite value per time")
        uh = np.ascontiguousarray(uh + uf)
    e, dev, w, iters = _run(*discretize_foh(sys_w, omega0 * step), r, e_lin,
                            np.ascontiguousarray(lin[:, 1]), uh, step, codes, params, s0,
                            GL_T, GL_W, 1e-14 * f_scale, MAX_FIXED_POINT_ITERATIONS)
    if iters > MAX_FIXED_POINT_ITERATIONS:
        raise RuntimeError(
            f"the implicit step at t = {len(e) * step:.6g} s did not converge in "
            f"{MAX_FIXED_POINT_ITERATIONS} iterations: the link is too stiff (or too "
            "strongly damped) for dt; use a smaller dt")
    y1 = r + dev
    y2 = r - e
    # feedback force C e, with the input linear between samples (as control.forced_response)
    u = forced_response_foh(loop.controller, t, e)
    if loop.feedforward == "rigid-body":
        u = u + loop.M * a  # the impulse M v0 delta(t) at t = 0 is not representable
    u = u + uh
    return Simulation(t=t, r=r, e=e, y1=y1, y2=y2, u=u, w=w, e_linear=e_lin)
