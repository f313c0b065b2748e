"""Tests of the time engine's sampled loop (a discrete controller around a plant with a link).

The linear loop is checked against independent discrete-time loops: python-control's
``c2d(P, T, "zoh")`` with the controller in z and ``z^-d`` (integer delays), the
modified z-transform of the plant for a fractional delay, and a loop written out
sample by sample for the output limit and the feedforward; the loop with a
slipping link against the continuous loop of :func:`simulate` at a fast rate.
"""

from __future__ import annotations

import control
import numpy as np
import pytest
from scipy.linalg import expm

from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis import Jenkins
from motionhyst.scenario import default_scenario
from motionhyst.time.engine import DiscreteController, run_sampled
from motionhyst.time.openloop import TwoMass
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

T = 1e-4  # 10 kHz
PLANT = TwoMass(m1=5.0, m2=17.5, b=90.0, k=7.4e7)  # Table I
C_CONT = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)


def feedback_controller(Cz: control.StateSpace) -> DiscreteController:
    """``u = C(z) (r - y)`` as a controller of the two inputs ``(r, y)``."""
    return DiscreteController(Cz.A, np.hstack([Cz.B, -Cz.B]), Cz.C,
                              [Cz.D[0, 0], -Cz.D[0, 0]], Cz.dt)


@pytest.fixture(scope="module")
def Cz() -> control.StateSpace:
    return control.ss(control.c2d(control.ss(C_CONT), T, "tustin"))


@pytest.fixture(scope="module")
def reference() -> np.ndarray:
    return 0.01 * np.sin(2 * np.pi * 10.0 * np.arange(3000) * T)


def plant_ss() -> control.StateSpace:
    A, B = PLANT.mechanics().state_space()
    C = np.zeros((1, 4))
    C[0, 1] = 1.0  # y2
    return control.ss(A, B[:, None], C, 0.0)


@pytest.mark.parametrize("d", [0, 1, 2])
def test_linear_loop_equals_python_control_at_the_samples(Cz, reference, d):
    run = run_sampled(PLANT, None, feedback_controller(Cz), reference, delay_samples=d)
    Pz = control.c2d(plant_ss(), T, "zoh")
    delay = control.ss(control.tf([1.0], [1.0] + [0.0] * d, T))
    closed = control.feedback(Pz * delay * Cz, 1)
    y = control.forced_response(closed, run.t, reference).outputs
    assert np.max(np.abs(run.y - y)) <= 1e-12 * np.max(np.abs(reference))
    assert np.max(np.abs(run.e - (reference - y))) <= 1e-12 * np.max(np.abs(reference))


def modified_z_loop(Cz, r, d, u_max=np.inf, ff=None, x0=None):
    """The linear loop sample by sample; the plant over a period by its modified z-transform.

    With ``d = n + phi``, ``u_{k-n-1}`` acts over the first ``phi T`` of period k and
    ``u_{k-n}`` over the rest: ``x+ = Phi x + Gamma1 u_{k-n-1} + Gamma0 u_{k-n}``.
    """
    sys = plant_ss()
    A, B = sys.A, sys.B[:, 0]
    n_int = int(np.floor(d))
    phi = d - n_int

    def hold(h):  # the state change over h for a constant unit force, and e^{A h}
        M = np.zeros((5, 5))
        M[:4, :4] = A * h
        M[:4, 4] = B * h
        E = expm(M)
        return E[:4, :4], E[:4, 4]

    E1, g1 = hold(phi * T)
    E0, g0 = hold((1 - phi) * T)
    Phi = E0 @ E1
    gamma1 = E0 @ g1
    ff = np.zeros_like(r) if ff is None else ff
    x = np.zeros(4) if x0 is None else np.array(x0, dtype=float)
    xc = np.zeros(Cz.A.shape[0])
    u = np.zeros(r.size + n_int + 2)  # u[k + n_int + 1] = u_k; the first entries 0
    y = np.zeros(r.size)
    for k in range(r.size):
        y[k] = x[1]
        e = r[k] - y[k]
        uk = float((Cz.C @ xc)[0] + Cz.D[0, 0] * e) + ff[k]
        u[k + n_int + 1] = np.clip(uk, -u_max, u_max)
        xc = Cz.A @ xc + Cz.B[:, 0] * e
        x = Phi @ x + gamma1 * u[k] + g0 * u[k + 1]  # u_{k-n-1}, u_{k-n}
    return y, u[n_int + 1:n_int + 1 + r.size]


def test_fractional_delay_equals_the_modified_z_transform(Cz, reference):
    run = run_sampled(PLANT, None, feedback_controller(Cz), reference, delay_samples=1.5)
    y, u = modified_z_loop(Cz, reference, 1.5)
    assert np.max(np.abs(run.y - y)) <= 1e-12 * np.max(np.abs(reference))
    assert np.max(np.abs(run.u - u)) <= 1e-9 * np.max(np.abs(u))
    # half a sample more delay than one sample is a different loop (the test can fail)
    one = run_sampled(PLANT, None, feedback_controller(Cz), reference, delay_samples=1.0)
    assert np.max(np.abs(one.y - y)) > 1e-3 * np.max(np.abs(one.e))


def test_output_limit_and_feedforward_as_the_loop_written_out(Cz, reference):
    ff = 22.5 * np.gradient(np.gradient(reference, T), T)  # M r''
    free = run_sampled(PLANT, None, feedback_controller(Cz), reference, ff=ff,
                       delay_samples=0.5)
    u_max = 0.5 * np.max(np.abs(free.u))
    run = run_sampled(PLANT, None, feedback_controller(Cz), reference, ff=ff,
                      delay_samples=0.5, u_max=u_max)
    y, u = modified_z_loop(Cz, reference, 0.5, u_max=u_max, ff=ff)
    assert np.max(np.abs(run.u)) == pytest.approx(u_max, rel=1e-15)
    assert np.max(np.abs(run.u - u)) <= 1e-9 * u_max
    assert np.max(np.abs(run.y - y)) <= 1e-12 * np.max(np.abs(reference))
    assert np.max(np.abs(run.y - free.y)) > 1e-3 * np.max(np.abs(free.e))  # the limit bites


def test_a_start_off_rest_as_the_loop_written_out(Cz, reference):
    x0 = [1e-4, 1.2e-4, -3e-3, 2e-3]  # q1, q2, q1', q2'
    run = run_sampled(PLANT, None, feedback_controller(Cz), reference, delay_samples=0.25,
                      x0=x0)
    y, _ = modified_z_loop(Cz, reference, 0.25, x0=x0)
    assert run.y[0] == 1.2e-4
    assert np.max(np.abs(run.y - y)) <= 1e-12 * np.max(np.abs(reference))
    with pytest.raises(ValueError, match="x0"):
        run_sampled(PLANT, None, feedback_controller(Cz), reference, x0=[0.0, 0.0])


def test_fast_sampled_loop_with_a_slipping_link_approaches_the_continuous_loop():
    """At 1 MHz (Tustin controller, no delay) the link acts as in the continuous loop.

    The sampled loop lags the continuous one by about half a sample (the hold): the
    link's contribution to the error, ``e - e_linear``, agrees to O(T), 2e-4 of it here.
    """
    base = default_scenario().loop()
    link = Jenkins(k=2e4, fc=5.0)  # slips at the amplitude below
    linear = Loop(base.plant, base.controller, None, feedforward=None)
    loop = Loop(base.plant, base.controller, link, feedforward=None)
    Ts = 1e-6
    ctrl = feedback_controller(control.ss(control.c2d(control.ss(base.controller), Ts,
                                                      "tustin")))
    ref = SineReference(0.01, 10.0)
    n = 20000
    r = ref(np.arange(n) * Ts)[0]
    run = run_sampled(PLANT, link, ctrl, r, substeps=1)
    run_linear = run_sampled(PLANT, None, ctrl, r, substeps=1)
    sim = simulate(loop, ref, (n - 1) * Ts, dt=Ts)
    sim_linear = simulate(linear, ref, (n - 1) * Ts, dt=Ts)
    assert np.max(np.abs(run.w)) == pytest.approx(5.0, rel=1e-12)  # the link slips
    by_link = sim.e - sim_linear.e
    assert np.max(np.abs((run.e - run_linear.e) - by_link)) <= 1e-3 * np.max(np.abs(by_link))
    assert np.max(np.abs(run.w - sim.w)) <= 2e-3 * 5.0


def test_bad_controllers_and_arguments_are_refused(Cz, reference):
    ctrl = feedback_controller(Cz)
    with pytest.raises(ValueError, match="sampling interval"):
        DiscreteController(Cz.A, np.hstack([Cz.B, -Cz.B]), Cz.C, [1.0, -1.0], 0.0)
    with pytest.raises(ValueError, match="two inputs"):
        run_sampled(PLANT, None, Cz, reference)  # one input only
    with pytest.raises(ValueError, match="delay_samples"):
        run_sampled(PLANT, None, ctrl, reference, delay_samples=-1.0)
    with pytest.raises(ValueError, match="u_max"):
        run_sampled(PLANT, None, ctrl, reference, u_max=0.0)
    with pytest.raises(ValueError, match="feedforward"):
        run_sampled(PLANT, None, ctrl, reference, ff=np.ones(3))
