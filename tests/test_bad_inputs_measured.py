"""The hostile corpus over the measured-record commands (issue 26, the sweep of identify,
predict and their records): options a model or record kind has no use for, a record of one
kind read as another, and checks that the record alone decides, made before the plant's
engines load.

Each refusal runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2, one
line on stderr naming the cause (no traceback), nothing on stdout, and every file there
before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import subprocess
import sys

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

FS = 1000.0
QUASI_STATIC = ('[stage]\ntype = "quasi-static"\nk = 1e4\nc = 5.0\n\n'
                '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 4.0\n')
PAPER = default_scenario_path().read_text()


def _table(columns: dict[str, np.ndarray]) -> str:
    return ",".join(columns) + "\n" + "".join(
        ",".join(repr(float(v)) for v in row) + "\n" for row in zip(*columns.values(),
                                                                    strict=True))


def _stage(n: int = 3000, m: float = 2.0, c: float = 10.0, fc: float = 1.0
           ) -> dict[str, np.ndarray]:
    """A positioning axis's record, force in and position out: the force that moves a mass
    `m` [kg] along two sines against viscous (`c`) and smoothed Coulomb (`fc`) friction."""
    t = np.arange(n) / FS
    w1, w2 = 2 * np.pi * 1.0, 2 * np.pi * 3.7
    y = 2e-2 * np.sin(w1 * t) + 3e-3 * np.sin(w2 * t + 0.4)
    v = 2e-2 * w1 * np.cos(w1 * t) + 3e-3 * w2 * np.cos(w2 * t + 0.4)
    a = -2e-2 * w1 ** 2 * np.sin(w1 * t) - 3e-3 * w2 ** 2 * np.sin(w2 * t + 0.4)
    return {"time": t, "force": m * a + c * v + fc * np.tanh(v / 1e-3), "displacement": y}


def _closed_loop(n: int = 4000, rate: float = 10_000.0) -> str:
    """A closed-loop record's columns (time,y1,u; made-up values: the cases are refused
    before any plant is loaded), `rate` [Hz]."""
    t = np.arange(n) / rate
    return _table({"time": t, "y1": 0.01 * np.sin(2 * np.pi * 2.0 * t),
                   "u": 50.0 * np.sin(2 * np.pi * 2.0 * t + 0.2)})


def _reversed_damper(path) -> None:
    """A friction damper logged 300 s at 200 Hz (60000 samples) with its load cell reversed."""
    import records_of_other_kinds as kinds

    r = kinds.damper_record("sines", seconds=300.0)
    path.write_text(_table({"time": r.t, "displacement": r.displacement, "force": -r.force}))


BASE = {"qs.toml": QUASI_STATIC, "paper.toml": PAPER,
        "f.csv": _table({k: v for k, v in _stage().items() if k != "displacement"}),
        "stage.csv": _table(_stage()), "cl.csv": _closed_loop(), "notes.txt": "my notes"}
CLOSED_LOOP = ["identify", "cl.csv", "--scenario", "paper.toml"]

# (id, extra files, argv, words of the one line on stderr)
CASES = [
    # ----------------------------------------- an option the model has no use for (was exit 0)
    ("predict-substeps-on-a-quasi-static-model", {},
     ["predict", "qs.toml", "f.csv", "--out", "p.csv", "--substeps", "7"],
     ["--substeps sets the integration steps of a model with inertia; qs.toml is "
      "quasi-static"]),
    ("from-rest-on-a-quasi-static-plant", {},
     ["identify", "stage.csv", "--record", "input-output", "--plant", "quasi-static",
      "--from-rest"], ["--from-rest sets a stage's state; a quasi-static plant has none"]),
    # ---------- a long record (above the fit's 50000 rows) whose load cell is reversed: numpy's
    # "shapes (60000,) and (30000,) not aligned" was the message
    ("long-record-with-the-load-cell-reversed", {"rev.csv": _reversed_damper},
     ["identify", "rev.csv"],
     ["rev.csv: no hysteresis found: the force falls as the displacement rises (is one "
      "sensor's sign reversed? --scale force=-1)"]),
    # -------------------------- a prefilter cut-off the record cannot have (was after the plant)
    ("closed-loop-cutoff-above-nyquist", {}, [*CLOSED_LOOP, "--cutoff", "1e9"],
     ["cl.csv: cutoff_hz must be in (0, 5000) Hz"]),
    ("closed-loop-cutoff-longer-than-the-record", {}, [*CLOSED_LOOP, "--cutoff", "1e-3"],
     ["cl.csv: too short: the prefilter settles in 1e+04 s"]),
    # ------------- a made-up closed-loop record whose inferred link force is an ellipse, a
    # spring's and a damper's (was 6 Maxwell-slip elements, R^2 0.99999, exit 0)
    ("closed-loop-record-of-a-spring-and-a-damper", {}, CLOSED_LOOP,
     ["cl.csv: no hysteresis in the record: the link force inferred through the plant is a "
      "spring's and a damper's (they leave 0 % of its RMS, a straight line 5.6 %)",
      "nothing identified"]),
]


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_measured_record_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv,
                                                                       words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**BASE, **files})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before
    assert [p.name for p in tmp_path.iterdir()] == ["user"]


@pytest.mark.parametrize(("argv", "words"), [
    ([*CLOSED_LOOP, "--cutoff", "1e9"], "cl.csv: cutoff_hz must be in (0, 5000) Hz"),
    ([*CLOSED_LOOP, "--cutoff", "1e-3"], "cl.csv: too short: the prefilter settles"),
    (["identify", "cl_1k.csv", "--scenario", "sampled.toml"],
     "cl_1k.csv: the record's sampling interval 0.001 s is not the controller's period "
     "0.0001 s"),
], ids=["cutoff-above-nyquist", "cutoff-too-low", "sampled-at-another-rate"])
def test_a_closed_loop_record_is_judged_before_the_plant_loads(tmp_path, argv, words):
    """The cut-off, and the rate of a sampled controller, are judged from the record (and
    the scenario's [controller] section) alone, before the plant and its loop load
    python-control and scipy.signal: seconds on a busy machine (the refusals came 3.9-4.1 s
    after the start; a 1 kHz record for a 10 kHz sampled loop 9.0 s, 2.3 s of CPU)."""
    sampled = PAPER.replace("beta = 0.6 ", "sample_rate_hz = 10000.0\nbeta = 0.6 ")
    assert "sample_rate_hz" in sampled
    populate(tmp_path, {**BASE, "sampled.toml": sampled, "cl_1k.csv": _closed_loop(rate=1e3)})
    code = ("import sys\nfrom motionhyst.cli import main\n"
            f"code = main({argv!r})\n"
            "print(code, sorted({'control', 'scipy.signal'} & set(sys.modules)))\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, env=limited_process.environment())
    assert proc.stdout.splitlines()[-1] == "2 []", proc.stdout + proc.stderr
    assert words in proc.stderr and "Traceback" not in proc.stderr, proc.stderr


def test_a_closed_loop_record_through_another_plant_names_the_plant():
    """The paper's loop recorded, inferred through a 1 kg axis (another plant): the force
    falls as y1 rises, and the message names the plant and the closed-loop columns (it was
    numpy's "shapes (3751,) and (3215,) not aligned": the sign check compared every sample
    with the rows after the prefilter settles)."""
    from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate
    from motionhyst.identify import identify_closed_loop
    from motionhyst.plants.mass_damper import MassDamper

    sc = default_scenario()
    loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    sim = simulate(loop, SineReference(0.01, 2.0), 1.5, dt=2e-4)
    with pytest.raises(ValueError, match=r"the force falls as the displacement rises \(the "
                       r"force inferred through the plant: is the sign of u or y1 reversed "
                       r"\(--scale u=-1\), or the plant not the record's\?\)"):
        identify_closed_loop(sim.t, sim.y1, sim.u, MassDamper(1.0, 0.0))
