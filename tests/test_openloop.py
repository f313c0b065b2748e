"""Open-loop systems (motionhyst.time.openloop) and their scenarios."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import BoucWen, Jenkins, MaxwellSlip
from motionhyst.identify.benchmark import TRUE_PARAMETERS, newmark_bouc_wen
from motionhyst.scenario import Scenario, ScenarioError
from motionhyst.time.openloop import (
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    is_periodic_record,
    simulate_bouc_wen,
    upsample,
)

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
    # with a [controller] a stage of one position is the plant of a closed loop (issue 25's
    # hunting loop), which needs its [reference]
    with pytest.raises(ScenarioError, match=r"\[reference\]: missing"):
        Scenario.from_dict({**OPEN, "controller": {"type": "tf", "num": [1.0], "den": [1.0]}})
    closed = Scenario.from_dict({**OPEN, "controller": {"type": "tf", "num": [1e5], "den": [1.0]},
                                 "reference": {"amplitude": 0.01, "frequencies": [5.0]}})
    assert not closed.is_open_loop and closed.loop().P1 is not None
    with pytest.raises(ScenarioError, match=r"\[stage\] m: .*greater than 0"):
        Scenario.from_dict({**OPEN, "stage": {**OPEN["stage"], "m": 0.0}})
    with pytest.raises(ScenarioError, match=r"\[stage\]: unknown type 'three-mass'"):
        Scenario.from_dict({**OPEN, "stage": {"type": "three-mass"}})
    with pytest.raises(ScenarioError, match=r"\[controller\]: missing"):
        Scenario.from_dict({**OPEN, "stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}})


# ----------------------------------------------------------------- the two-mass stage, open loop
TWO = TwoMass(2.0, 3.0, 20.0, 2e5)  # internal mode 65 Hz, inside the records' band


def _odd_multisine(n: int, seed: int, rms: float = 50.0) -> np.ndarray:
    """Odd harmonics only: u(t + T/2) = -u(t), so that no link ratchets the floating stage."""
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (FS / n)), int(150 / (FS / n)) + 1)
    lines = lines[lines % 2 == 1]
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


@pytest.mark.parametrize("output", ["y2", "y1"])
def test_two_mass_with_a_spring_link_matches_its_frequency_response(output):
    # a Bouc-Wen link with beta = 0 is a spring alpha: against eqs. (1)-(2) with the spring
    plant = TwoMass(2.0, 3.0, 20.0, 2e5, output)
    n = 512
    t = np.arange(n) / FS
    f = np.array([20.0, 67.0]) * FS / n
    u = 10 * np.sin(2 * np.pi * f[0] * t) + 5 * np.cos(2 * np.pi * f[1] * t)
    G = plant.frequency_response(f, k_link=5e4)
    exact = (10 * np.imag(G[0] * np.exp(2j * np.pi * f[0] * t))
             + 5 * np.real(G[1] * np.exp(2j * np.pi * f[1] * t)))
    link = BoucWen.from_general(5e4, 1.0, 0.0, 0.0, 1.0)
    y = OpenLoop(plant, link).simulate(t, u, periodic=True).displacement
    assert np.max(np.abs(y - exact)) < 1e-7 * np.max(np.abs(exact))
    # y1 and y2 differ by the spring's deflection, visible near the internal mode
    assert np.max(np.abs(plant.frequency_response([65.0], 5e4)
                         - TwoMass(2.0, 3.0, 20.0, 2e5, "y1" if output == "y2" else "y2")
                         .frequency_response([65.0], 5e4))) > 1e-6


@pytest.mark.parametrize("link", [BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0),
                                  Jenkins(k=5e4, fc=20.0),
                                  MaxwellSlip(k=[2e4, 3e4], fc=[10.0, 80.0])])
def test_two_mass_periodic_equals_the_end_of_a_long_run_from_rest(link):
    n = 512
    u = _odd_multisine(n, 2)
    t = np.arange(n) / FS
    sys = OpenLoop(TWO, link)
    y_per = sys.simulate(t, u, periodic=True).displacement
    assert abs(np.mean(y_per)) < 1e-12 * np.ptp(y_per)  # floating: returned with zero mean
    reps = 30
    y_long = sys.simulate(np.arange(reps * n) / FS, np.tile(u, reps)).displacement
    last = y_long[-n:] - np.mean(y_long[-n:])
    assert np.max(np.abs(last - y_per)) < 1e-7 * np.ptp(y_per)
    assert np.max(np.abs(y_long[:n] - np.mean(y_long[:n]) - y_per)) > 1e-3 * np.ptp(y_per)


def test_a_record_of_whole_periods_is_the_steady_state_of_one_period_repeated():
    n = 512
    u = _odd_multisine(n, 2)
    sys = OpenLoop(TWO, MaxwellSlip(k=[2e4, 3e4], fc=[10.0, 80.0]))
    one = sys.simulate(np.arange(n) / FS, u, periodic=True).displacement
    four = sys.simulate(np.arange(4 * n) / FS, np.tile(u, 4), periodic=True).displacement
    assert np.array_equal(four, np.tile(one, 4))


def test_two_mass_that_drifts_has_no_periodic_steady_state():
    # an unsymmetric force ratchets the floating stage through a Bouc-Wen link: the motion
    # repeats, the position moves on by the same distance every period
    n = 512
    u = _multisine(n, 2)
    sys = OpenLoop(TWO, BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0))
    with pytest.raises(ValueError, match=r"no periodic steady state: the stage floats.*drifts "
                                         r"-?\d\.\d+(e-\d+)? m per period"):
        sys.simulate(np.arange(n) / FS, u, periodic=True)
    # without a link, a force with a mean runs away; without one, the spectrum gives the state
    lin = OpenLoop(TWO)
    with pytest.raises(ValueError, match="nonzero mean"):
        lin.simulate(np.arange(n) / FS, u + 1.0, periodic=True)
    y = lin.simulate(np.arange(n) / FS, u, periodic=True).displacement
    y_long = lin.simulate(np.arange(3 * n) / FS, np.tile(u, 3)).displacement
    # from rest the stage keeps the mean velocity of its start: the same shape plus a ramp
    ramp = np.polyfit(np.arange(n), y_long[-n:] - y, 1)
    resid = y_long[-n:] - y - np.polyval(ramp, np.arange(n))
    assert np.max(np.abs(resid)) < 1e-6 * np.ptp(y)


def test_two_mass_sensitivities_agree_with_finite_differences():
    n = 300
    u = _multisine(n, 5)
    p = np.array([2.0, 3.0, 20.0, 2e5, 5e4, 800.0, -1100.0, 1.3])
    for output in ("y2", "y1"):
        plant = TwoMass(1.0, 1.0, 1.0, 1.0, output)
        _, sy = simulate_bouc_wen(p, u, FS, 20, periodic=False, sensitivities=True, plant=plant)
        for j in range(p.size):
            e = 1e-6 * abs(p[j])
            hi, lo = p.copy(), p.copy()
            hi[j] += e
            lo[j] -= e
            fd = (simulate_bouc_wen(hi, u, FS, 20, periodic=False, sensitivities=False,
                                    plant=plant)[0]
                  - simulate_bouc_wen(lo, u, FS, 20, periodic=False, sensitivities=False,
                                      plant=plant)[0]) / (2 * e)
            # |z|^(nu - 1) has no derivative at z = 0: differences across the crossings are
            # good to about 1e-5 (1e-7 with nu = 1)
            assert np.max(np.abs(fd - sy[:, j])) < 1e-4 * np.max(np.abs(sy[:, j])), (output, j)


def test_two_mass_bouc_wen_through_both_integrators():
    n = 512
    u = _multisine(n, 4)
    t = np.arange(n) / FS
    sys = OpenLoop(TWO, BoucWen(k=3e4, fc=15.0, n=1.0, beta=0.6, gamma=0.2))
    y_rk4 = sys.simulate(t, u).displacement
    y_exact_link = sys._simulate_elements(u, FS, 80, False)
    assert np.max(np.abs(y_rk4 - y_exact_link)) < 1e-4 * np.max(np.abs(y_rk4))


OPEN_TWO = {"stage": {"m1": 2.0, "m2": 3.0, "b": 20.0, "k": 2e5, "output": "y1"},
            "hysteresis": {"model": "jenkins", "k": 5e4, "fc": 20.0}}


def test_open_loop_two_mass_scenario():
    sc = Scenario.from_dict(OPEN_TWO)
    assert sc.is_open_loop
    sys = sc.open_loop()
    assert isinstance(sys.plant, TwoMass)
    assert (sys.plant.m1, sys.plant.m2, sys.plant.b, sys.plant.k, sys.plant.output) == (
        2.0, 3.0, 20.0, 2e5, "y1")
    assert sc.to_dict()["stage"]["output"] == "y1"
    with pytest.raises(ScenarioError, match=r'two-mass stage with output = "y1".*needs a '
                                            r"closed loop"):
        sc.loop()
    with pytest.raises(ScenarioError, match=r'\[controller\] does not apply to a \[stage\] '
                                            r'with output = "y1"'):
        Scenario.from_dict({**OPEN_TWO, "controller": {"type": "tf", "num": [1.0],
                                                       "den": [1.0]}})
    with pytest.raises(ScenarioError, match=r"\[stage\] output: .*'y2' or 'y1'"):
        Scenario.from_dict({**OPEN_TWO, "stage": {**OPEN_TWO["stage"], "output": "y3"}})
    with pytest.raises(ScenarioError, match=r'\[controller\]: missing \(or give \[stage\] '
                                            r'output = "y2" or "y1"'):
        Scenario.from_dict({**OPEN_TWO, "stage": {"m1": 2.0, "m2": 3.0, "b": 20.0, "k": 2e5}})
    with pytest.raises(ScenarioError, match=r"\[stage\]: unknown key 'output'|output"):
        Scenario.from_dict({**OPEN, "stage": {**OPEN["stage"], "output": "y2"}})
    with pytest.raises(ValueError, match="output must be 'y2' or 'y1'"):
        TwoMass(1.0, 1.0, 1.0, 1.0, "y3")


def test_predict_two_mass_periodic_and_from_rest(tmp_path, capsys):
    from motionhyst.cli import main

    n = 512
    t = np.arange(n) / FS
    u = _odd_multisine(n, 7)
    scenario = tmp_path / "two.toml"
    scenario.write_text('[stage]\nm1 = 2.0\nm2 = 3.0\nb = 20.0\nk = 2e5\noutput = "y1"\n'
                        '[hysteresis]\nmodel = "maxwell-slip"\nk = [2e4, 3e4]\n'
                        'fc = [10.0, 80.0]\n')
    inp = tmp_path / "force.csv"
    np.savetxt(inp, np.column_stack([t, u]), delimiter=",", header="time,force", comments="",
               fmt="%.17g")
    sys = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5, "y1"), MaxwellSlip(k=[2e4, 3e4],
                                                                   fc=[10.0, 80.0]))
    for periodic in (True, False):
        out = tmp_path / f"y{periodic}.csv"
        assert main(["predict", str(scenario), str(inp), "--out", str(out)]
                    + (["--periodic"] if periodic else [])) == 0
        got = np.loadtxt(out, delimiter=",", skiprows=1)
        ref = sys.simulate(t, u, periodic=periodic).displacement
        np.testing.assert_allclose(got[:, 1], ref, rtol=0, atol=1e-15 * np.ptp(ref))
    assert "two.toml (periodic steady state)" in capsys.readouterr().out
    # a force the link lets ratchet: one line, exit 2
    np.savetxt(inp, np.column_stack([t, _multisine(n, 2)]), delimiter=",",
               header="time,force", comments="", fmt="%.17g")
    scenario.write_text('[stage]\nm1 = 2.0\nm2 = 3.0\nb = 20.0\nk = 2e5\noutput = "y2"\n'
                        '[hysteresis]\nmodel = "bouc-wen"\nalpha = 5e4\nbeta = 1e3\n'
                        'gamma = 0.8\ndelta = -1.1\nnu = 1.0\n')
    assert main(["predict", str(scenario), str(inp), "--periodic", "--out",
                 str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err
    assert "force.csv: no periodic steady state" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o.csv").exists()
    # commands of the closed loop say that they need one
    for argv in (["analyze", str(scenario)], ["steady", str(scenario)],
                 ["simulate", str(scenario), "--time-series", str(tmp_path / "ts.csv")]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert 'two-mass stage with output = "y2"' in err and "needs a closed loop" in err
        assert len(err.strip().splitlines()) == 1
    closed = tmp_path / "cl.csv"
    np.savetxt(closed, np.column_stack([t, 1e-4 * u, u]), delimiter=",", header="time,y1,u",
               comments="", fmt="%.17g")
    assert main(["identify", str(closed), "--scenario", str(scenario)]) == 2
    assert "is an open-loop system" in capsys.readouterr().err


def test_stamps_rounded_when_written_are_the_same_record():
    sys = OpenLoop(PLANT, LINK)
    t = np.arange(3000) / 750
    u = 20 * np.sin(2 * np.pi * 3 * t) + 5 * np.sin(2 * np.pi * 41 * t)
    exact = sys.simulate(t, u).displacement
    rounded = sys.simulate(np.round(t, 4), u).displacement   # 4 decimals: 3.75 % of a step
    assert np.max(np.abs(rounded - exact)) < 1e-6 * np.max(np.abs(exact))
    jittered = t.copy()
    jittered[1234] += 0.1 / 750
    with pytest.raises(ValueError, match=r"stamp 1\.64\d* s is 0\.1 sampling intervals off"):
        sys.simulate(jittered, u)


def test_a_periodic_run_takes_at_most_the_periods_it_is_given():
    """A search caps its trial points' periodic runs (identify's input-output search): a
    lightly damped stage on a holding link that has not settled by then is refused."""
    from motionhyst.time.openloop import simulate_elements

    plant, link = MassSpringDamper(1.0, 2.0, 4e4), Jenkins(k=1e4, fc=100.0)  # zeta 4e-3
    t = np.arange(256) / 512.0
    u = 5.0 * np.sin(2 * np.pi * 4 * t) + 2.0 * np.sin(2 * np.pi * 12 * t)
    args = (plant.mechanics(), link.time_stepping(), u, 512.0, 20)
    with pytest.raises(ValueError, match="steady state was not reached"):
        simulate_elements(*args, periodic=True, k_link=1e4, periods=2, shooting=False)
    # Newton's steps on the period map need two: one to jump, one to confirm
    with pytest.raises(ValueError, match="steady state was not reached"):
        simulate_elements(*args, periodic=True, k_link=1e4, periods=1)
    y, _ = simulate_elements(*args, periodic=True, k_link=1e4)
    ref = OpenLoop(plant, link).simulate(t, u, periodic=True, substeps=20).displacement
    np.testing.assert_allclose(y, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))
