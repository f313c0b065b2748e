"""The Coulomb link (motionhyst.hysteresis.coulomb): the rigid limit of the Jenkins element."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb, Jenkins
from motionhyst.hysteresis.stepping import N_PARAMS
from motionhyst.scenario import ScenarioError, hysteresis_from_dict
from motionhyst.time.openloop import MassSpringDamper, OpenLoop, simulate_elements

FS = 1000.0
AXIS = MassSpringDamper(95.0, 200.0, 0.0)  # a positioning axis: a mass and a damper


def _drive(n: int = 3000) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / FS
    return t, 60.0 * np.sin(2 * np.pi * 0.7 * t) + 15.0 * np.sin(2 * np.pi * 3.1 * t)


def test_jenkins_tends_to_coulomb_as_its_spring_stiffens():
    """The Jenkins element's response approaches the rigid slider's as its slip displacement
    fc/k shrinks, so the exact stick of the Coulomb link is its limit."""
    t, u = _drive()
    y = OpenLoop(AXIS, Coulomb(fc=20.0)).simulate(t, u).displacement
    gaps = [float(np.max(np.abs(OpenLoop(AXIS, Jenkins(k=k, fc=20.0)).simulate(t, u)
                                .displacement - y))) for k in (1e5, 1e6, 1e7, 1e8)]
    assert gaps[0] > gaps[1] > gaps[2] > gaps[3]
    assert gaps[0] > 0.05 * np.ptp(y) > 0.003 * np.ptp(y) > gaps[3]


def test_a_force_below_the_slip_force_moves_nothing():
    """Sticking is exact: from rest, a force that never reaches fc leaves the stage where it is,
    to rounding (not a creep of a stiff spring: 15 N on a 1e8 N/m spring is 0.15 um), and one
    that does makes it move only then."""
    t = np.arange(2000) / FS
    u = 15.0 * np.sin(2 * np.pi * 1.0 * t)
    y = OpenLoop(AXIS, Coulomb(fc=20.0)).simulate(t, u).displacement
    assert np.max(np.abs(y)) < 1e-20
    y = OpenLoop(AXIS, Coulomb(fc=20.0)).simulate(t, 2.0 * u).displacement
    first = int(np.argmax(np.abs(y) > 1e-20))
    assert abs(2.0 * u[first - 1]) <= 20.0 + 1e-9 < abs(2.0 * u[first + 1])


def test_asymmetric_friction_sets_the_sliding_velocity_by_direction():
    """A constant force F drives the mass at v = (F - fc_pos) / (c + c_pos) forward and
    (F + fc_neg) / (c + c_neg) backward."""
    link = Coulomb(fc_pos=18.0, fc_neg=24.0, c_pos=30.0, c_neg=90.0)
    t = np.arange(10000) / FS  # 24 time constants m / (c + c_pos)
    for force, v_expected in ((60.0, (60.0 - 18.0) / (200.0 + 30.0)),
                              (-60.0, (-60.0 + 24.0) / (200.0 + 90.0))):
        y = OpenLoop(AXIS, link).simulate(t, np.full(t.size, force)).displacement
        v = (y[-1] - y[-1001]) * FS / 1000
        assert v == pytest.approx(v_expected, rel=1e-6)


def test_sensitivities_match_finite_differences():
    """The forward sensitivities through the closed-form step (sliding both ways and stuck)
    agree with central differences of the simulation in m, c and the friction parameters."""
    _, u = _drive(1500)
    p0 = np.array([95.0, 200.0, 0.0, 20.0, 26.0, 30.0, 50.0])
    mech = AXIS.mechanics

    def run(p, sens):
        link = Coulomb(fc_pos=p[3], fc_neg=p[4], c_pos=p[5], c_neg=p[6])
        dp = None
        if sens:
            dp = np.zeros((1, N_PARAMS, 4))
            dp[0, :4, :] = np.eye(4)
        return simulate_elements(mech(p[:3]), link.time_stepping(), u, FS, 10, periodic=False,
                                 dparams=dp)

    y, dy = run(p0, True)
    assert np.array_equal(y, run(p0, False)[0])
    for j in (0, 1, 3, 4, 5, 6):
        step = 1e-6 * p0[j]
        hi, lo = p0.copy(), p0.copy()
        hi[j] += step
        lo[j] -= step
        fd = (run(hi, False)[0] - run(lo, False)[0]) / (2 * step)
        assert np.max(np.abs(dy[:, j] - fd)) <= 1e-6 * np.max(np.abs(fd)), j


def test_scenario_forms_round_trip():
    for link in (Coulomb(fc=20.4), Coulomb(fc_pos=20.1, fc_neg=20.6, c_pos=1.5, c_neg=40.0)):
        back = hysteresis_from_dict(link.to_dict())
        assert back.to_dict() == link.to_dict()
    with pytest.raises(ScenarioError, match="fc"):
        hysteresis_from_dict({"model": "coulomb"})
    with pytest.raises(ValueError, match="not both"):
        Coulomb(fc=1.0, fc_pos=2.0)


def test_describing_function_is_the_slip_force_harmonic():
    link = Coulomb(fc_pos=18.0, fc_neg=22.0, c_pos=10.0, c_neg=30.0)
    A, omega = 2e-3, 2 * np.pi * 1.5
    x_period = np.array([0.0, A / 2j])
    W = link.periodic_harmonics(x_period, 1, omega)
    D_numeric = 2j * W[1] / A
    assert D_numeric == pytest.approx(link.describing_function(A, omega), rel=2e-3)
    assert W[0].real == pytest.approx((18.0 - 22.0) / 2 + omega * A * (10.0 - 30.0) / np.pi,
                                      rel=2e-3)
