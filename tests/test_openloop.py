"""Open-loop systems (motionhyst.openloop) and their scenarios."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.benchmark import TRUE_PARAMETERS, newmark_bouc_wen
from motionhyst.hysteresis import BoucWen, Jenkins, MaxwellSlip
from motionhyst.openloop import MassSpringDamper, OpenLoop, is_periodic_record, upsample
from motionhyst.scenario import Scenario, ScenarioError

P = TRUE_PARAMETERS
PLANT = MassSpringDamper(P["m"], P["c"], P["k"])
LINK = BoucWen.from_general(P["alpha"], P["beta"], P["gamma"], P["delta"], P["nu"])
FS = 750.0


def _multisine(n: int, seed: int, rms: float = 50.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(1, int(150 / (FS / n)) + 1)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


def test_linear_stage_periodic_matches_frequency_response():
    n = 750
    t = np.arange(n) / FS
    u = 10 * np.sin(2 * np.pi * 30 * t) + 5 * np.cos(2 * np.pi * 37 * t)
    y = OpenLoop(PLANT).simulate(t, u, periodic=True).displacement
    G30, G37 = PLANT.frequency_response([30.0, 37.0])
    exact = (10 * np.imag(G30 * np.exp(2j * np.pi * 30 * t))
             + 5 * np.real(G37 * np.exp(2j * np.pi * 37 * t)))
    assert np.max(np.abs(y - exact)) < 1e-8 * np.max(np.abs(exact))


def test_bouc_wen_agrees_with_a_fine_newmark_reference():
    # the benchmark's own (second-order) scheme at 32x its step converges to the RK4
    # integration (measured 8.6e-9, 2.2e-9, 6.7e-10 m at 4x, 8x, 16x), on the same
    # band-limited input, from rest
    n = 600
    u = _multisine(n, 1)
    t = np.arange(n) / FS
    sys = OpenLoop(PLANT, LINK)
    y80 = sys.simulate(t, u, substeps=80).displacement
    fine = upsample(u, 640, periodic=False)
    y_ref = newmark_bouc_wen(fine, 1 / (FS * 640))[::640]
    rms = np.sqrt(np.mean(y_ref ** 2))
    assert np.sqrt(np.mean((y80 - y_ref) ** 2)) < 2e-6 * rms
    # the default step (20 per sample here) is within 3e-5 of it; the benchmark's Newmark
    # at its own 15 kHz is 2e-4 off
    y = sys.simulate(t, u).displacement
    assert np.sqrt(np.mean((y - y80) ** 2)) < 3e-5 * rms


def test_periodic_equals_the_end_of_a_long_run_from_rest():
    n = 512  # 0.68 s per period; the mode decays with 0.4 s: 16 periods forget the start
    u = _multisine(n, 2)
    t = np.arange(n) / FS
    sys = OpenLoop(PLANT, LINK)
    y_per = sys.simulate(t, u, periodic=True).displacement
    reps = 16
    y_long = sys.simulate(np.arange(reps * n) / FS, np.tile(u, reps)).displacement
    assert np.max(np.abs(y_long[-n:] - y_per)) < 1e-7 * np.max(np.abs(y_per))
    # and the first period from rest is visibly different
    assert np.max(np.abs(y_long[:n] - y_per)) > 1e-2 * np.max(np.abs(y_per))


@pytest.mark.parametrize("link", [Jenkins(k=2e4, fc=8.0),
                                  MaxwellSlip(k=[1e4, 2e4], fc=[3.0, 10.0])])
def test_other_links_periodic_and_second_order(link):
    n = 512
    u = _multisine(n, 3)
    t = np.arange(n) / FS
    sys = OpenLoop(PLANT, link)
    ys = [sys.simulate(t, u, periodic=True, substeps=r).displacement for r in (10, 20, 40)]
    e1 = np.max(np.abs(ys[0] - ys[2]))
    e2 = np.max(np.abs(ys[1] - ys[2]))
    assert e1 / e2 == pytest.approx(5.0, rel=0.3)  # second order: (1/1 - 1/16) / (1/4 - 1/16)
    assert e2 < 1e-4 * np.max(np.abs(ys[2]))
    reps = 16
    y_long = sys.simulate(np.arange(reps * n) / FS, np.tile(u, reps), substeps=20).displacement
    assert np.max(np.abs(y_long[-n:] - ys[1])) < 1e-7 * np.max(np.abs(ys[1]))


def test_bouc_wen_normalised_form_through_both_integrators():
    link = BoucWen(k=3e4, fc=15.0, n=1.0, beta=0.6, gamma=0.2)
    n = 512
    u = _multisine(n, 4)
    t = np.arange(n) / FS
    sys = OpenLoop(PLANT, link)
    y_rk4 = sys.simulate(t, u, periodic=True).displacement
    y_exact_link = sys._simulate_elements(u, FS, 80, True)  # exact element update, FOH stage
    assert np.max(np.abs(y_rk4 - y_exact_link)) < 1e-5 * np.max(np.abs(y_rk4))


def test_upsample_and_periodicity():
    t = np.arange(200) / 200
    x = np.sin(2 * np.pi * 7 * t) + 0.2 * np.cos(2 * np.pi * 31 * t)
    fine = upsample(x, 5, periodic=True)
    tf = np.arange(1000) / 1000
    np.testing.assert_allclose(fine, np.sin(2 * np.pi * 7 * tf) + 0.2 * np.cos(2 * np.pi * 31 * tf),
                               atol=1e-12)
    np.testing.assert_allclose(upsample(x, 5, periodic=False)[::5], x, atol=1e-6)
    assert is_periodic_record(np.tile(x, 3)) == 200
    assert is_periodic_record(x) is None


def test_record_errors():
    sys = OpenLoop(PLANT, LINK)
    with pytest.raises(ValueError, match="uniform"):
        sys.simulate([0.0, 0.1, 0.3], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="finite"):
        sys.simulate([0.0, 0.1, 0.2], [1.0, np.nan, 3.0])
    with pytest.raises(ValueError, match="equal length"):
        sys.simulate([0.0, 0.1, 0.2], [1.0, 2.0])
    with pytest.raises(ValueError, match="m must be finite and > 0"):
        MassSpringDamper(0.0, 1.0, 1.0)


OPEN = {"stage": {"type": "mass-spring-damper", "m": 2.0, "c": 10.0, "k": 5e4},
        "hysteresis": {"model": "bouc-wen", "alpha": 5e4, "beta": 1e3, "gamma": 0.8,
                       "delta": -1.1, "nu": 1.0}}


def test_open_loop_scenario():
    sc = Scenario.from_dict(OPEN)
    assert sc.is_open_loop
    sys = sc.open_loop()
    assert (sys.plant.m, sys.plant.c, sys.plant.k) == (2.0, 10.0, 5e4)
    assert sys.hysteresis.general == {"alpha": 5e4, "beta": 1e3, "gamma": 0.8, "delta": -1.1,
                                      "nu": 1.0}
    with pytest.raises(ScenarioError, match=r"mass-spring-damper.*needs a closed loop"):
        sc.loop()
    with pytest.raises(ScenarioError, match=r"\[controller\] does not apply"):
        Scenario.from_dict({**OPEN, "controller": {"type": "tf", "num": [1.0], "den": [1.0]}})
    with pytest.raises(ScenarioError, match=r"\[stage\] m: .*greater than 0"):
        Scenario.from_dict({**OPEN, "stage": {**OPEN["stage"], "m": 0.0}})
    with pytest.raises(ScenarioError, match=r"\[stage\]: unknown type 'three-mass'"):
        Scenario.from_dict({**OPEN, "stage": {"type": "three-mass"}})
    with pytest.raises(ScenarioError, match=r"\[controller\]: missing"):
        Scenario.from_dict({**OPEN, "stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}})
