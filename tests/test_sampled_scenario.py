"""Scenario keys of sampled-data controllers and the setpoint feedforward (issue 22)."""

import copy
import subprocess
import sys

import numpy as np
import pytest

from motionhyst import Scenario, ScenarioError
from motionhyst.controllers.sampled import SampledController

BASE = {
    "stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7},
    "hysteresis": {"model": "jenkins", "k": 20.0, "fc": 0.05},
    "controller": {"type": "leadlag-lowpass", "K": 6.2e6, "f1": 60.0, "f2": 240.0,
                   "flp": 700.0, "beta": 0.6},
    "reference": {"amplitude": 0.01, "frequencies": [5.0]},
}


def scenario(controller=None, feedforward=None, **extra):
    data = copy.deepcopy(BASE)
    if controller is not None:
        data["controller"] = controller
    data["controller"].update(extra)
    if feedforward is not None:
        data["feedforward"] = feedforward
    return Scenario.from_dict(data)


def test_sample_rate_makes_any_controller_sampled():
    sc = scenario(sample_rate_hz=10e3, delay_samples=1.5, u_max=500.0)
    c = sc.controller()
    assert isinstance(c, SampledController)
    assert (c.sample_rate_hz, c.delay_samples, c.u_max, c.discretization) == (
        10e3, 1.5, 500.0, "tustin")
    assert sc.loop().sampled.delay_samples == 1.5
    pre = scenario(sample_rate_hz=10e3, discretization="tustin-prewarp", prewarp_hz=700.0)
    assert pre.controller().discretization == "tustin-prewarp"
    # the continuous controller stays what it was
    assert not isinstance(scenario().controller(), SampledController)


def test_discrete_controllers_given_in_z():
    tfz = scenario({"type": "tf-z", "num": [2.0, -1.9], "den": [1.0, -0.5],
                    "sample_rate_hz": 10e3}, {"type": "rigid-body"}).controller()
    assert tfz.one_dof and tfz.r_num.tolist() == [2.0, -1.9]
    F, g, kp = 1e3, 35.15065 * 243.45, 160.18
    two = scenario({"type": "two-dof-z", "r_num": [g * kp], "r_den": [1.0],
                    "y_num": [g * (kp + F), -g * F], "y_den": [1.0], "sample_rate_hz": F},
                   {"type": "none"}, )
    c = two.controller()
    assert not c.one_dof and c.period == 1e-3


def test_pid_continuous_and_sampled():
    notch = [{"frequency_hz": 694.0, "zeta_zero": 0.005, "zeta_pole": 0.7}]
    pid = {"type": "pid", "kp": 6e6, "ki": 1e7, "kd": 2e4, "derivative_filter_hz": 1500.0,
           "notches": notch}
    cont = scenario(pid).controller()
    s = 2j * np.pi * 694.0
    assert abs(cont(s)) == pytest.approx(
        abs(6e6 + 1e7 / s + 2e4 * s / (1 + s / (2 * np.pi * 1500.0))) * 0.005 / 0.7, rel=1e-9)
    pure = {"type": "pid", "kp": 6e6, "ki": 1e7, "kd": 2e4, "notches": notch,
            "sample_rate_hz": 10e3}
    assert isinstance(scenario(pure).controller(), SampledController)


def test_feedforward_terms():
    loop = scenario(None, {"acceleration": 20.0, "viscous": 3.0, "coulomb": 0.1,
                           "advance_samples": 2.0}, sample_rate_hz=10e3,
                    delay_samples=1.5).loop()
    ff = loop.ff
    assert (ff.mass, ff.viscous, ff.coulomb, ff.advance_samples) == (20.0, 3.0, 0.1, 2.0)
    assert scenario().loop().ff.mass == 22.5     # the plant's mass by default


@pytest.mark.parametrize(("controller", "feedforward", "extra", "message"), [
    (None, None, {"delay_samples": 1.0}, "delay_samples needs sample_rate_hz"),
    (None, None, {"u_max": 10.0}, "u_max needs sample_rate_hz"),
    (None, None, {"discretization": "zoh"}, "discretization needs sample_rate_hz"),
    (None, None, {"sample_rate_hz": 1e4, "discretization": "euler"}, "discretization"),
    (None, None, {"sample_rate_hz": 1e4, "prewarp_hz": 100.0}, "prewarp_hz goes with"),
    (None, None, {"sample_rate_hz": 1e4, "discretization": "tustin-prewarp",
                  "prewarp_hz": 6000.0}, "below the Nyquist"),
    (None, None, {"sample_rate_hz": 1e4, "delay_samples": -1.0}, "delay_samples"),
    (None, {"advance_samples": 1.0}, {}, "advance_samples needs a sampled controller"),
    (None, {"type": "none", "viscous": 1.0}, {}, "viscous cannot go with type"),
    ({"type": "tf-z", "num": [1.0], "den": [1.0]}, None, {}, "needs sample_rate_hz"),
    ({"type": "tf-z", "num": [1.0], "den": [0.0, 1.0], "sample_rate_hz": 1e3}, None, {},
     "not be causal"),
    ({"type": "two-dof-z", "r_num": [1.0], "r_den": [1.0], "y_num": [1.0],
      "sample_rate_hz": 1e3}, None, {}, "y_den: missing"),
    ({"type": "pid", "kp": 0.0}, None, {}, "non-zero gain"),
    (None, None, {"sample_rate_hz": 2e3, "delay_samples": 1.0}, "does not stabilise"),
])
def test_bad_sampled_scenarios(controller, feedforward, extra, message):
    with pytest.raises(ScenarioError, match=message) as info:
        scenario(controller, feedforward, **extra)
    assert "\n" not in str(info.value)


def test_cli_one_line_errors(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        "[stage]\nm1 = 5.0\nm2 = 17.5\nb = 90.0\nk = 7.4e7\n"
        "[hysteresis]\nmodel = \"jenkins\"\nk = 20.0\nfc = 0.05\n"
        "[controller]\ntype = \"leadlag-lowpass\"\nK = 6.2e6\nf1 = 60.0\nf2 = 240.0\n"
        "flp = 700.0\nbeta = 0.6\nsample_rate_hz = 10000.0\ndelay_samples = 1.0\n"
        "[reference]\namplitude = 0.01\nfrequencies = [7.0]\n")
    before = bad.read_bytes()
    out = subprocess.run([sys.executable, "-m", "motionhyst.cli", "steady", str(bad)],
                         capture_output=True, text=True)
    assert out.returncode == 2
    errors = [x for x in out.stderr.splitlines() if x.startswith("motionhyst: error:")]
    assert len(errors) == 1 and "6.997900629811 Hz (1429 samples)" in errors[0]
    assert "Traceback" not in out.stderr
    assert bad.read_bytes() == before


def test_continuous_simulation_refuses_feedforward_terms_it_cannot_run():
    from motionhyst import SineReference, simulate

    loop = scenario(None, {"viscous": 3.0}).loop()
    with pytest.raises(ValueError, match="rigid-body feedforward M r'' alone"):
        simulate(loop, SineReference(0.01, 5.0), 0.01)


def test_the_shipped_10khz_example():
    from pathlib import Path

    from motionhyst import analyze
    from motionhyst.analysis.steady import periodic_steady_state

    path = Path(__file__).resolve().parent.parent / "examples" / "paper_10khz.toml"
    sc = Scenario.from_file(path)
    loop = sc.loop()
    assert loop.sampled.sample_rate_hz == 10e3 and loop.ff.advance_samples == 2.0
    res = analyze(loop, sc.amplitude, sc.frequencies)
    for p in res.points:
        ss = periodic_steady_state(loop, sc.amplitude, p.frequency_hz)
        assert abs(ss.mismatch / p.value - 1) < 2e-3
