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

import control
import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy.signal import cont2discrete

from motionhyst.hysteresis import Jenkins
from motionhyst.loop import Loop, _cancel_s, _polysub_exact
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


def _divide_s2(num, den, what: str):
    num, den = _cancel_s(num, np.polymul(den, [1.0, 0.0, 0.0]))
    if den[-1] == 0.0 and len(den) > 1 and den[-2] == 0.0:
        raise ValueError(f"time simulation needs {what} to vanish like s^2 at DC "
                         "(a plant with a rigid-body double integrator)")
    return num, den


def _realize(num, den, omega0: float):
    """Balanced state-space realisation in scaled time ``omega0 t``."""
    n = len(den) - 1
    # substitute s = omega0 * s_hat, then divide numerator and denominator by omega0^n
    num_h = np.asarray(num) * omega0 ** (np.arange(len(num) - 1, -1, -1.0) - n)
    den_h = np.asarray(den) * omega0 ** (np.arange(n, -1, -1.0) - n)
    sys = control.tf2ss(control.tf(num_h / den_h[0], den_h / den_h[0]))
    return sys.A, sys.B, sys.C, sys.D


def _block_system(loop: Loop, omega0: float):
    """Stacked realisation, inputs (r'', w), outputs (e, y1 - r)."""
    P = loop._poly
    if P is None:
        raise ValueError("time simulation needs LTI plant and controller")
    ry1 = P["r->y1"]
    n_ae = _divide_s2(P["r->e"].num, P["r->e"].den, "the error response to the reference")
    n_ay = _divide_s2(_polysub_exact(ry1.num, ry1.den), ry1.den,
                      "the response of y1 - r to the reference")
    blocks = [(n_ae, 0, 0), ((P["w->e"].num, P["w->e"].den), 1, 0),
              (n_ay, 0, 1), ((P["w->y1"].num, P["w->y1"].den), 1, 1)]
    mats = [(_realize(num, den, omega0), i, o) for (num, den), i, o in blocks]
    n = sum(m[0][0].shape[0] for m in mats)
    A = np.zeros((n, n))
    B = np.zeros((n, 2))
    C = np.zeros((2, n))
    D = np.zeros((2, 2))
    k = 0
    for (a, b, c, d), i, o in mats:
        m = a.shape[0]
        A[k:k + m, k:k + m] = a
        B[k:k + m, i] = b[:, 0]
        C[o, k:k + m] = c[0]
        D[o, i] += d[0, 0]
        k += m
    return A, B, C, D


@njit(cache=True)
def _run(Ad, Bd, Cd, Dd, r, a, k, fc, x0, uh):  # pragma: no cover - compiled
    n_t = r.shape[0]
    n_x = Ad.shape[0]
    m = k.shape[0]
    x = x0.copy()
    e = np.empty(n_t)
    y1 = np.empty(n_t)
    w = np.empty(n_t)
    we = np.zeros(m)
    y1_prev = r[0]
    for i in range(n_t):
        base_e = Dd[0, 0] * a[i]
        base_y = Dd[1, 0] * a[i]
        for j in range(n_x):
            base_e += Cd[0, j] * x[j]
            base_y += Cd[1, j] * x[j]
        # implicit in w through the hold's feedthrough (|k Dd| << 1): fixed point
        wt = 0.0
        for j in range(m):
            wt += we[j]
        w_new = we.copy()
        for _ in range(4):
            yi = r[i] + base_y + Dd[1, 1] * (wt - uh[i])
            dx = yi - y1_prev
            wt = 0.0
            for j in range(m):
                v = we[j] + k[j] * dx
                if v > fc[j]:
                    v = fc[j]
                elif v < -fc[j]:
                    v = -fc[j]
                w_new[j] = v
                wt += v
        yi = r[i] + base_y + Dd[1, 1] * (wt - uh[i])
        for j in range(m):
            we[j] = w_new[j]
        y1_prev = yi
        e[i] = base_e + Dd[0, 1] * (wt - uh[i])
        y1[i] = yi
        w[i] = wt
        xn = np.zeros(n_x)
        for j in range(n_x):
            s = Bd[j, 0] * a[i] + Bd[j, 1] * (wt - uh[i])
            for q in range(n_x):
                s += Ad[j, q] * x[q]
            xn[j] = s
        x = xn
    return e, y1, w


def _stop_parameters(loop: Loop) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    h = loop.hysteresis
    if h is None:
        return np.zeros(1), np.ones(1)
    if isinstance(h, Jenkins):
        return np.array([h.k]), np.array([h.fc])
    if hasattr(h, "stop_parameters"):
        return h.stop_parameters()
    raise ValueError(f"time simulation does not support the {h.name} model yet")


def default_step(loop: Loop, max_frequency_hz: float) -> float:
    """Time step [s] resolving the loop's fastest pole and the reference."""
    p = float(np.max(np.abs(loop.closed_loop_poles())))
    return float(min(TWO_PI / (STEPS_PER_POLE_PERIOD * p),
                     1.0 / (STEPS_PER_REFERENCE_PERIOD * max_frequency_hz)))


def simulate(loop: Loop, reference, duration: float, dt: float | None = None) -> Simulation:
    """Simulate the nonlinear loop from rest.

    Parameters
    ----------
    loop : Loop
        An LTI loop whose plant has a rigid-body double integrator.
    reference : callable
        ``reference(t) -> (r, r'')``, e.g. the classes of :mod:`motionhyst.references`.
    duration : float
        Simulated time [s], > 0.
    dt : float, optional
        Output and integration step [s]; by default from :func:`default_step`.

    Returns
    -------
    Simulation
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if loop.feedforward != "rigid-body" and loop.feedforward is not None:
        raise ValueError("unknown feedforward")
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
    omega0 = float(np.max(np.abs(loop.closed_loop_poles())))
    A, B, C, D = _block_system(loop, omega0)
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), omega0 * step, method="foh")
    # a reference that starts with a velocity v0 has r'' = v0 delta(t) + ...: the impulse
    # sets the initial state (delta(t) = omega0 delta(tau) in scaled time)
    v0 = float(getattr(reference, "initial_velocity", 0.0))
    x0 = B[:, 0] * v0 * omega0
    k, fc = _stop_parameters(loop)
    if loop.hysteresis is None:
        k = np.zeros(1)
    # hysteresis feedforward u_h = phi_hat(r) acts like -w on the loop
    hff = loop.hysteresis_feedforward
    uh = hff.response(r) if hff is not None else np.zeros_like(r)
    e, y1, w = _run(Ad, Bd, Cd, Dd, r, a, k, fc, x0, uh)
    e_lin, _, _ = _run(Ad, Bd, Cd, Dd, r, a, np.zeros(1), np.ones(1), x0, np.zeros_like(r))
    y2 = r - e
    u = control.forced_response(loop.controller, t, e).outputs
    if loop.feedforward == "rigid-body":
        u = u + loop.M * a  # the impulse M v0 delta(t) at t = 0 is not representable
    u = u + uh
    return Simulation(t=t, r=r, e=e, y1=y1, y2=y2, u=np.asarray(u), w=w, e_linear=e_lin)
