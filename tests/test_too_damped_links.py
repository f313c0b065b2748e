"""A link too strongly damped for a run's step, in sampled loops and open-loop systems (issue 26).

A run's implicit step settles the link force by a fixed-point iteration that a damping ``c``
on the link's mass ``m`` amplifies by ``c h / (4 m)`` a pass (step ``h``).  Continuous loops
(``simulate``, ``scan``) were refused before their loop was built; a sampled controller's
loop ran its fine steps (the controller's period split for the stage's fastest mode) and
stopped at the first motion after python-control and the kernels loaded, or, with a larger
damping, ended with a link force of 3e10 N; ``predict`` on an open-loop axis returned a
displacement of 10-1000 m for 30 N (exit 0).  The step of each is known before the run:
the same check refuses them, naming the scenario's ``[hysteresis]`` (and ``--substeps`` where
the command has it).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_probe import probe

from motionhyst.hysteresis import LuGre

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCENARIOS = [p for p in sorted(EXAMPLES.glob("*.toml"))
             if "scenario" not in tomllib.loads(p.read_text())]  # not a study's file
SAMPLED = (EXAMPLES / "paper_10khz.toml").read_text()
JENKINS = 'model = "jenkins"\nk = 20.0\nfc = 0.05'
AXIS = ('[stage]\ntype = "mass-damper"\nm = 2.0\nc = 10.0\n\n[hysteresis]\nmodel = "lugre"\n'
        'sigma0 = 2e4\nsigma1 = {sigma1}\nfc = 4.0\nfs = 5.0\nvs = 0.01\n')


def _sampled_with(sigma1: float = 0.0, sigma2: float = 0.0, delay: float = 1.5) -> str:
    """The paper's loop sampled at 10 kHz with a LuGre link of damping `sigma1`, `sigma2`."""
    assert JENKINS in SAMPLED and "delay_samples = 1.5" in SAMPLED
    return SAMPLED.replace(JENKINS, f'model = "lugre"\nsigma0 = 20.0\nsigma1 = {sigma1!r}\n'
                                    f'sigma2 = {sigma2!r}\nfc = 0.05\nfs = 0.07\nvs = 0.1'
                           ).replace("delay_samples = 1.5", f"delay_samples = {delay!r}")


def _force_csv() -> str:
    t = np.arange(3000) / 1000.0
    u = 30 * np.sin(2 * np.pi * t) + 12 * np.sin(2 * np.pi * 3.7 * t + 0.4)
    return "time,force\n" + "".join(f"{float(a)!r},{float(b)!r}\n"
                                     for a, b in zip(t, u, strict=True))


@pytest.mark.parametrize("argv", [
    ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration", "0.2"],
    ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
     "--s-max", "1e6", "--compensation", "none"],
])
@pytest.mark.parametrize(("sigma1", "sigma2", "factor"), [(1e6, 0.0, "2.78"), (0.0, 1e6, "2.78"),
                                                          (1e8, 0.0, "278")])
def test_a_sampled_loop_s_link_too_damped_for_its_fine_steps_is_refused_first(
        tmp_path, argv, sigma1, sigma2, factor):
    """The paper's loop at 10 kHz, 1.5 samples late (fine steps of 5e-5 s on the 5 kg m1):
    was refused after the loop was built and the run started (1.5 s of CPU), its message
    naming "the loop's poles and the reference"; now before either, naming the sampled
    controller.  The factor is the step of 5e-5 s after one of 2.5e-5 s: its rates weigh
    its change 1 + 5 / 7.5 times (c h (1 + 5 / 7.5) / (6 m)), not 1.5."""
    (tmp_path / "s.toml").write_text(_sampled_with(sigma1, sigma2))
    out = probe(argv, tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert out["err"].startswith("motionhyst: error: s.toml: [hysteresis]: the link's damping "
                                 f"for small motions, {sigma1 + sigma2:.4g} N s/m on the 5 kg it "
                                 "moves, is too strong for the time step of 5e-05 s: it would "
                                 f"amplify each pass of the step's implicit iteration {factor} "
                                 "times"), out["err"]
    assert out["err"].rstrip().endswith(
        "the step is the command's, the sampled controller's period (10000 Hz, 1.5 samples "
        "late) split for the stage's fastest mode: is the link's damping meant (in SI "
        "units)?"), out["err"]
    assert "control" not in out["packages"] and "numba" not in out["packages"], out["packages"]
    assert not (tmp_path / "ts.csv").exists()


def test_a_sampled_run_does_not_end_in_no_solution():
    """sigma1 = 1e8 N s/m with a whole sample of delay: the run ended, its link force 3e10 N
    and its error 0.26 mm on a 10 mm sine (exit 0); now refused by the library's run."""
    from motionhyst import Loop, SineReference
    from motionhyst.scenario import Scenario
    from motionhyst.time.sampled import simulate_sampled

    sc = Scenario.from_dict(tomllib.loads(_sampled_with(1e8, delay=1.0)), "s")
    loop = Loop(sc.plant(), sc.controller(), sc.hysteresis())
    with pytest.raises(ValueError, match=r"too strong for the time step of 3\.33e-05 s"):
        simulate_sampled(loop, SineReference(0.01, 5.0), 0.1)


@pytest.mark.parametrize("delay", [1.0, 1.5])
def test_the_sampled_margin_refuses_only_runs_that_fail(monkeypatch, delay):
    """Just below the margin the check passes; just above it refuses, and there the run
    itself, the check taken out, does fail (measured: from a factor of 0.47 on for sigma2 at
    both delays): the check refuses no run that would converge."""
    from motionhyst import Loop, SineReference
    from motionhyst.scenario import Scenario
    from motionhyst.time import engine
    from motionhyst.time.kernel import StepNotConverged
    from motionhyst.time.sampled import simulate_sampled
    from motionhyst.time.steps import IMPLICIT_STEP_MARGIN, check_link_damping, sampled_steps

    sc = Scenario.from_dict(tomllib.loads(_sampled_with(delay=delay)), "s")
    step, shorter = sampled_steps(sc.plant(), sc.hysteresis(), 10_000.0, delay)
    assert (step, shorter) == pytest.approx((5e-5, 2.5e-5) if delay == 1.5 else (1e-4 / 3, 0.0),
                                            rel=1e-12)
    weight = 1.0 + 5.0 / 7.5 if delay == 1.5 else 1.5  # of the step's change in its rates
    at_margin = IMPLICIT_STEP_MARGIN * 6 * 5.0 / (step * weight)

    def lugre(c: float) -> LuGre:
        return LuGre(sigma0=20.0, sigma1=0.0, sigma2=c, fc=0.05, fs=0.07, vs=0.1)

    check_link_damping(lugre(0.95 * at_margin), sc.plant(), step, shorter=shorter)
    with pytest.raises(ValueError, match="is too strong for the time step"):
        check_link_damping(lugre(1.05 * at_margin), sc.plant(), step, shorter=shorter)
    monkeypatch.setattr(engine, "check_link_damping", lambda *args, **kwargs: None)
    with pytest.raises(StepNotConverged):
        simulate_sampled(Loop(sc.plant(), sc.controller(), lugre(1.05 * at_margin)),
                         SineReference(0.01, 5.0), 0.02, linear=False)


def test_predict_refuses_a_link_too_damped_for_its_steps_and_names_the_substeps(tmp_path):
    """A damped axis (2 kg, LuGre sigma1 1e6 N s/m) under 30 N: predicted 9.8 m RMS, exit 0
    (its steps of 5e-5 s amplify each pass 6.25 times); now refused before the run with the
    --substeps that settle it, and with them predicted: the damper's few micrometres."""
    import json

    from file_trees import populate, snapshot

    populate(tmp_path, {"axis.toml": AXIS.format(sigma1=1e6), "force.csv": _force_csv(),
                        "silly.toml": AXIS.format(sigma1=1e8)})
    before = snapshot(tmp_path)
    out = probe(["predict", "axis.toml", "force.csv", "--out", "p.csv"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert out["err"].startswith("motionhyst: error: axis.toml: [hysteresis]: the link's "
                                 "damping for small motions, 1e+06 N s/m on the 2 kg it moves, "
                                 "is too strong for the time step of 5e-05 s"), out["err"]
    assert out["err"].rstrip().endswith("(a step is 1/20 of a sample of force.csv): "
                                        "--substeps 500 (20 now) would settle it"), out["err"]
    assert "numba" not in out["packages"], out["packages"]
    silly = probe(["predict", "silly.toml", "force.csv", "--out", "p.csv"], tmp_path)
    assert silly["rc"] == 2 and silly["err"].rstrip().endswith(
        "is the link's damping meant (in SI units)?"), silly["err"]
    assert snapshot(tmp_path) == before
    import limited_process

    code, stdout, err = limited_process.run(["predict", "axis.toml", "force.csv", "--out",
                                             "p.csv", "--substeps", "500", "--json"], tmp_path)
    assert code == 0, err
    y = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)[:, 1]
    # 30 N on 1e6 N s/m: 30 um/s; the bristles' 2e4 N/m spring holds it near 1.5 mm / 1e3
    assert 1e-6 < np.max(np.abs(y)) < 3e-5, np.max(np.abs(y))
    assert json.loads(stdout)["samples"] == 3000


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.name)
def test_no_example_s_link_is_refused_for_its_damping(path):
    """Every example scenario's link passes the check at the step its runs take (a
    continuous loop's from its poles and its reference's highest frequency, a sampled
    loop's fine steps, an open-loop axis at 1 kHz), by a factor of ten: no false refusal."""
    from motionhyst.scenario import load_scenario
    from motionhyst.time.steps import IMPLICIT_STEP_MARGIN, damping_factor, pole_step, sampled_steps

    sc = load_scenario(path, check=False)
    link = sc.hysteresis()
    if link is None:
        return
    c = sc.model.controller
    shorter = 0.0
    if c is None:
        system = sc.open_loop()
        if not system.plant.has_inertia:
            return
        step = 1.0 / (1000.0 * system.default_substeps(1000.0))
    elif getattr(c, "sample_rate_hz", None) is not None:
        step, shorter = sampled_steps(sc.plant(), link, c.sample_rate_hz,
                                      c.delay_samples or 0.0)
    else:  # the step the commands check (hunting.toml's pure derivative is no time run's)
        pole = sc.fastest_pole()
        if pole is None:
            return
        step = pole_step(pole, max(sc.model.reference.frequencies))
    assert damping_factor(link, sc.plant(), step, shorter) < 0.1 * IMPLICIT_STEP_MARGIN
