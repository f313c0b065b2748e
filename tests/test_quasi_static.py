"""The quasi-static plant in time: displacement from force and force from displacement."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import BoucWen, Coulomb, Dahl, Jenkins, LuGre, MaxwellSlip
from motionhyst.plants import MassSpringDamper, QuasiStatic
from motionhyst.time.openloop import OpenLoop
from motionhyst.time.quasi_static import displacement_from_force, force_from_displacement

T = np.arange(2000) / 2000.0
X = 2e-3 * np.sin(2 * np.pi * 3 * T) + 5e-4 * np.sin(2 * np.pi * 17 * T + 0.3)

LINKS = {
    "jenkins": Jenkins(k=4e5, fc=200.0),
    "maxwell-slip": MaxwellSlip(k=[4e5, 1e5], fc=[150.0, 100.0]),
    "dahl": Dahl(k=4e5, fc=200.0, alpha=1.5),
    "bouc-wen": BoucWen(k=4e5, fc=200.0, n=1.5, beta=0.6, gamma=0.3),
    "lugre": LuGre(sigma0=4e5, sigma1=300.0, sigma2=20.0, fc=150.0, fs=200.0, vs=0.01),
}


@pytest.mark.parametrize("name", list(LINKS))
def test_displacement_from_force_undoes_force_from_displacement(name):
    plant = QuasiStatic(k=2e4, c=50.0, force_offset=7.0)
    u = force_from_displacement(plant, LINKS[name], T, X)
    x = displacement_from_force(plant, LINKS[name], T, u)
    assert np.max(np.abs(x - X)) < 1e-12 * np.max(np.abs(X))


def test_a_small_mass_tends_to_the_quasi_static_balance():
    # the same link, spring and damper (time constant 1 ms) on a mass whose modes (1.6 and
    # 7.3 kHz) are far above the force (5 Hz): the inertial force is below 0.1 % of the force
    link, t = Jenkins(k=4e5, fc=200.0), np.arange(4000) / 4000.0
    u = 400.0 * np.sin(2 * np.pi * 5 * t) ** 3
    with_mass = OpenLoop(MassSpringDamper(2e-4, 20.0, 2e4), link).simulate(t, u).displacement
    without = displacement_from_force(QuasiStatic(k=2e4, c=20.0), link, t, u)
    assert np.max(np.abs(with_mass - without)) < 2e-3 * np.max(np.abs(without))


def test_a_rigid_slider_sticks_exactly_while_it_holds_the_force():
    t = np.arange(6) * 1e-3
    u = np.array([0.0, 10.0, 30.0, 30.0, 10.0, -10.0])
    x = displacement_from_force(QuasiStatic(k=1e3), Coulomb(fc=20.0), t, u)
    # held up to 20 N (no motion), then the spring takes the excess; back within +-20 N: stuck
    assert x.tolist() == [0.0, 0.0, 0.01, 0.01, 0.01, 0.01]


def test_a_force_nothing_holds_is_an_error_naming_the_instant():
    t = np.arange(100) / 100.0
    with pytest.raises(ValueError, match=r"at t = 0\.36 s the force 10\.6667 N is not held"):
        displacement_from_force(QuasiStatic(), Jenkins(k=1e4, fc=10.0), t,
                                20.0 * np.clip(t - 0.2, 0.0, None) / 0.3)


def test_open_loop_simulates_a_plant_without_inertia_at_the_record_samples():
    plant, link = QuasiStatic(k=2e4, c=50.0), LINKS["bouc-wen"]
    system = OpenLoop(plant, link)
    assert system.default_substeps(2000.0) == 1
    u = force_from_displacement(plant, link, T, X)
    out = system.simulate(T, u)
    np.testing.assert_allclose(out.displacement, X, rtol=0, atol=1e-12 * np.max(np.abs(X)))


def test_the_periodic_steady_state_repeats_and_forgets_the_start():
    plant, link = QuasiStatic(k=2e4), LINKS["jenkins"]
    t = T[:400]
    u = 600.0 * np.sin(2 * np.pi * 5 * t)          # two whole periods, the link slipping
    y = displacement_from_force(plant, link, t, u, periodic=True)
    again = displacement_from_force(plant, link, np.arange(800) / 2000.0, np.tile(u, 2))
    np.testing.assert_allclose(y, again[400:], rtol=0, atol=1e-12 * np.max(np.abs(y)))
    assert abs(y[0]) > 1e-4                      # not the start's (0): the loop's branch
    w = force_from_displacement(plant, link, t, y, periodic=True)
    np.testing.assert_allclose(w, u, rtol=0, atol=1e-9 * 600.0)


def test_a_plant_with_inertia_is_refused():
    with pytest.raises(ValueError, match="has inertia"):
        displacement_from_force(MassSpringDamper(1.0, 1.0, 1.0), None, T, X)
