"""Tests of the loop of Fig. 3 and its closed-loop transfers."""

from __future__ import annotations

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.controllers.loop import TRANSFERS, Loop
from motionhyst.core.lti import freqresp
from motionhyst.hysteresis.jenkins import Jenkins
from motionhyst.plants.measured import MeasuredPlant
from motionhyst.plants.two_mass import TwoMassStage

FREQS_HZ = np.array([1.0, 5.0, 10.0, 50.0, 120.0, 500.0, 694.0, 2000.0])


def docstring_transfers(P1, P2, C, M, omega):
    """The transfers of loop.py's module docstring from the parts' frequency responses."""
    p1, p2, c = freqresp(P1, omega), freqresp(P2, omega), freqresp(C, omega)
    cff = M * (1j * omega) ** 2
    return {
        "r->e": (1 - p2 * cff) / (1 + c * p2),
        "r->y1": p1 * (c + cff) / (1 + c * p2),
        "w->e": p2 / (1 + c * p2),
        "w->y1": -p1 / (1 + c * p2),
        "f->e": -p2 / (1 + c * p2),
        "f->y1": p1 / (1 + c * p2),
    }


def measured(stage, freqs_hz):
    omega = 2 * np.pi * freqs_hz
    P1 = control.frd(freqresp(stage.P1, omega), omega, smooth=True)
    P2 = control.frd(freqresp(stage.P2, omega), omega, smooth=True)
    return MeasuredPlant(P1=P1, P2=P2, M=stage.M, source="test")


@pytest.mark.parametrize("name", TRANSFERS)
def test_transfers_match_formulas(loop, stage, controller, name):
    omega = 2 * np.pi * FREQS_HZ
    ref = docstring_transfers(stage.P1, stage.P2, controller, stage.M, omega)[name]
    assert_allclose(loop.transfer(name, omega), ref, rtol=1e-9)
    # the python-control form agrees too
    tf = loop.transfer_tf(name)
    assert_allclose([complex(tf(1j * w)) for w in omega], ref, rtol=1e-9)


def test_r_to_e_at_low_frequency_is_the_flexible_residual(loop, stage, controller):
    """1 - P2 M s^2 = M s^2 Pf2 exactly: the loop keeps the digits that subtraction loses."""
    omega = 2 * np.pi * np.array([1e-3, 0.01, 0.1])
    s = 1j * omega
    ref = stage.M * s**2 * freqresp(stage.Pf2, omega) / (
        1 + freqresp(controller, omega) * freqresp(stage.P2, omega))
    assert_allclose(loop.transfer("r->e", omega), ref, rtol=1e-9)


def test_dc_values(loop, controller):
    C0 = complex(controller(0)).real
    zero = np.array([0.0])
    we = loop.transfer("w->e", zero)[0]
    wy = loop.transfer("w->y1", zero)[0]
    assert we == pytest.approx(1.0 / C0, rel=1e-12)
    assert -wy == pytest.approx(1.0 / C0, rel=1e-12)
    assert loop.transfer("r->e", zero)[0] == 0.0
    assert loop.transfer("r->y1", zero)[0] == pytest.approx(1.0, rel=1e-12)
    # and continuously so: close to DC the values tend there
    tiny = np.array([2 * np.pi * 1e-4])
    assert loop.transfer("w->e", tiny)[0] == pytest.approx(1.0 / C0, rel=1e-6)


def test_no_feedforward(stage, controller):
    loop = Loop(stage, controller, feedforward=None)
    omega = 2 * np.pi * FREQS_HZ
    p2, c = freqresp(stage.P2, omega), freqresp(controller, omega)
    assert_allclose(loop.transfer("r->e", omega), 1 / (1 + c * p2), rtol=1e-9)
    assert_allclose(loop.transfer("r->y1", omega),
                    freqresp(stage.P1, omega) * c / (1 + c * p2), rtol=1e-9)
    # without feedforward a unit DC reference leaves no error either (double integrator)
    assert loop.transfer("r->e", np.array([0.0]))[0] == 0.0


@pytest.mark.parametrize("name", TRANSFERS)
def test_tuple_plant_agrees_with_stage(loop, stage, controller, link, name):
    other = Loop((stage.P1, stage.P2), controller, link, mass=stage.M)
    omega = 2 * np.pi * np.concatenate([[0.0], FREQS_HZ])
    assert_allclose(other.transfer(name, omega), loop.transfer(name, omega), rtol=1e-12)


@pytest.mark.parametrize("name", TRANSFERS)
def test_measured_plant_agrees_with_stage(loop, stage, controller, link, name):
    other = Loop(measured(stage, FREQS_HZ), controller, link)
    assert not other.is_lti
    omega = 2 * np.pi * FREQS_HZ
    # r->e subtracts 1 - P2 M s^2 from data, losing ~1e-16 / (M w^2 |Pf2|) ~ 1e-11 at 1 Hz
    assert_allclose(other.transfer(name, omega), loop.transfer(name, omega), rtol=1e-9)


def test_measured_plant_loop_limits(stage, controller):
    other = Loop(measured(stage, np.geomspace(0.5, 3000.0, 60)), controller)
    with pytest.raises(ValueError, match="LTI"):
        other.transfer_tf("w->e")
    other.check_stable()  # cannot be checked from data: no error
    assert other.bandwidth_hz() == pytest.approx(120.65, abs=1.0)


def test_loop_attributes(loop, stage):
    assert loop.M == stage.M
    assert loop.is_lti
    assert_allclose(freqresp(loop.Pr, [1.0]), freqresp(stage.Pr, [1.0]), rtol=1e-15)
    assert loop.bandwidth_hz() == pytest.approx(120.65, abs=1.0)


def test_closed_loop_poles(loop, stage, controller):
    ref = control.poles(control.feedback(controller * stage.P2))
    got = loop.closed_loop_poles()
    assert_allclose(np.sort_complex(got), np.sort_complex(ref), rtol=1e-6)
    assert np.all(got.real < 0)


def test_closed_loop_poles_are_computed_once_and_returned_as_a_copy(loop):
    p = loop.closed_loop_poles()
    p[:] = 0.0
    assert np.all(loop.closed_loop_poles() != 0.0)


def test_check_stable_table1(loop):
    loop.check_stable()


def closed_loop_max_real(P2, C):
    return float(np.max(control.poles(control.feedback(C * P2)).real))


def test_check_stable_negative_gain(stage, controller, link):
    C = -1.0 * control.tf(controller.num, controller.den)
    assert closed_loop_max_real(stage.P2, C) > 0  # really unstable
    with pytest.raises(ValueError, match="does not stabilise"):
        Loop(stage, C, link).check_stable()


def test_check_stable_excessive_gain(stage, link):
    C = LeadLagLowpass(K=6.2e9, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
    assert closed_loop_max_real(stage.P2, C) > 0  # crossover far above the low-pass
    with pytest.raises(ValueError, match="does not stabilise"):
        Loop(stage, C, link).check_stable()


def stuck_stage(stage, kj):
    """State-space u -> y2 of the stage with the link stuck: a spring kj from y1 to ground."""
    m1, m2, b, k = stage.m1, stage.m2, stage.b, stage.k
    A = [[0, 0, 1, 0], [0, 0, 0, 1], [-(k + kj) / m1, k / m1, -b / m1, b / m1],
         [k / m2, -k / m2, b / m2, -b / m2]]
    return control.ss(A, [[0], [0], [1 / m1], [0]], [[0, 1, 0, 0]], [[0]])


def test_check_stable_with_stuck_link(stage, controller):
    """A link so stiff (resonance with M at 500 Hz) that the stuck loop is unstable."""
    kj = stage.M * (2 * np.pi * 500.0) ** 2
    assert closed_loop_max_real(stage.P2, controller) < 0
    worst = closed_loop_max_real(stuck_stage(stage, kj), controller)
    assert worst > 0  # really unstable, independently of loop.py
    with pytest.raises(ValueError, match="with the dynamic link stuck") as info:
        Loop(stage, controller, Jenkins(k=kj, fc=1.0)).check_stable()
    assert f"{worst:.4g}" in str(info.value)
    # the same controller and stage without the link pass
    Loop(stage, controller).check_stable()
    # and a softer link at 300 Hz is still stable, as the state-space model confirms
    soft = stage.M * (2 * np.pi * 300.0) ** 2
    assert closed_loop_max_real(stuck_stage(stage, soft), controller) < 0
    Loop(stage, controller, Jenkins(k=soft, fc=1.0)).check_stable()


def test_check_stable_undamped_stage_with_link(controller, link):
    stage = TwoMassStage(m1=5.0, m2=17.5, b=0.0, k=7.4e7)
    # independent check: stage with the link stuck (spring kJ from y1 to ground) in the loop
    assert closed_loop_max_real(stuck_stage(stage, link.k), controller) < -100
    assert closed_loop_max_real(stage.P2, controller) < -100
    Loop(stage, controller, link).check_stable()


def test_single_transfer_function_plant_rejected(stage, controller):
    with pytest.raises(TypeError, match="plant must be"):
        Loop(stage.P2, controller)


def test_loop_argument_errors(stage, controller):
    with pytest.raises(TypeError, match="plant must be"):
        Loop(42.0, controller)
    with pytest.raises(TypeError, match="plant must be"):
        Loop((stage.P1, stage.P2, stage.P2), controller, mass=1.0)
    with pytest.raises(ValueError, match="mass"):
        Loop((stage.P1, stage.P2), controller)
    with pytest.raises(ValueError, match="unknown feedforward"):
        Loop(stage, controller, feedforward="inverse")
    loop = Loop(stage, controller)
    with pytest.raises(ValueError, match="unknown transfer"):
        loop.transfer("u->y", [1.0])
    with pytest.raises(ValueError, match="no rigid-body mass"):
        _ = Loop((stage.P1, stage.P2), controller, feedforward=None).Pr
