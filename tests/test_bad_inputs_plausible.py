"""Implausible inputs that still run (issue 26): a warning of the product's own, one line
naming the quantity, never another library's text; and what the warning is about computed
right all the same.

The command lines run in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files; they exit 0, every warning
is one line ``motionhyst: warning: ...`` (no traceback, no source path), and the user's
files are byte-identical afterwards.
"""

from __future__ import annotations

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
SCAN = ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
        "1000", "--s-max", "1e6", "--compensation", "none"]


def _paper(old: str, new: str) -> str:
    assert old in PAPER
    return PAPER.replace(old, new)


# (id, scenario, argv, the warning's words)
CASES = [
    ("steady-actuated-mass-of-a-microgram", _paper("m1 = 5.0", "m1 = 1e-9"),
     ["steady", "s.toml", "--frequency", "5"],
     "s.toml: [stage] m1 = 1e-09 kg, a factor 1e+06 below the 0.001-10000 kg of motion "
     "stages: is it in kg?"),
    ("scan-actuated-mass-of-a-megatonne", _paper("m1 = 5.0", "m1 = 1e9"), SCAN,
     "s.toml: [stage] m1 = 1e+09 kg, a factor 1e+05 above the 0.001-10000 kg of motion "
     "stages: is it in kg?"),
    ("simulate-mass-at-the-point-of-control-in-grams", _paper("m2 = 17.5", "m2 = 17500.0"),
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration",
      "0.05"],
     "s.toml: [stage] m2 = 17500 kg, a factor 1.8 above the 0.001-10000 kg of motion "
     "stages: is it in kg?"),
]


@pytest.mark.parametrize(("scenario", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_an_implausible_mass_is_one_warning_naming_it(tmp_path, scenario, argv, words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {"s.toml": scenario, "notes.txt": "my notes"})
    before = snapshot(root)
    code, out, err = limited_process.run(list(argv), root)
    assert code == 0, err
    assert out
    lines = err.strip().splitlines()
    assert all(line.startswith("motionhyst: warning: ") for line in lines), err
    assert sum(words in line for line in lines) == 1, err
    assert "BadCoefficients" not in err and ".py" not in err and "Traceback" not in err, err
    after = snapshot(root)
    after.pop("ts.csv", None)  # simulate's own output
    assert after == before


def test_a_plausible_stage_says_nothing(tmp_path):
    (tmp_path / "s.toml").write_text(PAPER)
    code, _, err = limited_process.run(["steady", "s.toml", "--frequency", "5",
                                        "--no-floquet"], tmp_path)
    assert code == 0 and err == "", err


def test_a_refusal_stays_one_line_with_an_implausible_mass(tmp_path):
    """The warning comes once the loop is built: a scenario refused before (a scan of too
    many steps of the microgram's pole) is one line."""
    (tmp_path / "s.toml").write_text(_paper("m1 = 5.0", "m1 = 1e-9"))
    line = limited_process.refusal(["scan", "s.toml", "--length", "0.1", "--speed", "0.1",
                                    "--a-max", "10", "--j-max", "1000", "--s-max", "1e5"],
                                   tmp_path)
    assert "too many" in line and "[stage] m1 = 1e-09 kg" in line and "is it in kg?" in line


@pytest.mark.parametrize("m1", [5.0, 1e9])
def test_the_time_engine_realises_a_loop_of_a_huge_mass_exactly(m1):
    """The link's force reaches y1 through ``w -> y1``, whose coefficients in scaled time
    are all below 1e-14 for m1 = 1e9 kg: scipy dropped every one but the last (its
    BadCoefficients warning) and the realisation was a constant.  Realised at unit gain, its
    response equals the transfer function's to 1e-9 at every frequency."""
    import warnings

    from motionhyst import default_scenario
    from motionhyst.core.lti import polyratio
    from motionhyst.time.simulation import _block_systems

    sc = default_scenario(check=False)
    sc.model.stage.m1 = m1
    loop = sc.loop()
    omega0 = float(np.max(np.abs(loop.closed_loop_poles())))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, (A, B, C, D) = _block_systems(loop, omega0)
    tf = loop._poly["w->y1"]
    for w in 2 * np.pi * np.array([1.0, 10.0, 100.0, 700.0, 3000.0]):
        s = 1j * w / omega0
        realised = (C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + D)[1, 0]
        exact = polyratio(tf.num, tf.den, np.array([w]))[0]
        assert abs(realised - exact) < 1e-9 * abs(exact), (w, realised, exact)


@pytest.mark.parametrize(("values", "named"), [
    ({"c1": 5e4}, None),        # c1 / m1: a pole at 2.7 Hz (main: 1.6e5 Hz, both in series)
    ({"c2": 5e4}, "c2"),        # c2 / m2: 1.6e5 Hz
    ({"b": 5e4}, "b"),          # between the masses: both in series, 1.6e5 Hz
    ({"c1": 4e9}, "c1"),        # c1 / m1: 2.1e5 Hz
])
def test_a_ground_damper_is_judged_against_its_own_mass(values, named):
    """Review C11 LOW-1: a two-mass stage's damper from m1 (3000 kg) to the ground was
    judged against both masses in series (m2 0.05 kg): c1 = 5e4 N s/m "gives the stage a
    pole at 1.6e+05 Hz"; its pole is c1 / m1 = 2.7 Hz."""
    from motionhyst import default_scenario
    from motionhyst.scenario.schema import implausible_stage

    sc = default_scenario(check=False)
    for name, value in {"m1": 3000.0, "m2": 0.05, "k": 1e8, **values}.items():
        setattr(sc.model.stage, name, value)
    lines = implausible_stage(sc)
    if named is None:
        assert lines == []
        return
    assert len(lines) == 1 and f"[stage] {named} = " in lines[0], lines
    pole = float(lines[0].split("pole at ")[1].split(" Hz")[0])
    mass = 3000.0 if named == "c1" else 0.05 if named == "c2" else 1 / (1 / 3000 + 1 / 0.05)
    assert pole == pytest.approx(values[named] / mass / (2 * np.pi), rel=0.02)
