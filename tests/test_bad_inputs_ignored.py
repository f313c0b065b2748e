"""Options and files that were silently dropped, and refusals that said more than one line
(issue 26: "0 silently ignored options"; every refusal one line, exit 2, within 2 s).

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2, one
line on stderr without a traceback, nothing on stdout, the line's words, and every file that
was there before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import math

import limited_process
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()

MASS_DAMPER = ('[stage]\ntype = "mass-damper"\nm = 10.0\nc = 20.0\n\n'
               '[hysteresis]\nmodel = "jenkins"\nk = 2000.0\nfc = 2.0\n')
"""An identified axis (as ``identify --record input-output --plant mass-damper --save``
writes it): an open-loop system, force in, position out."""


def _series(header: str, *columns) -> str:
    """A CSV of 2 s at 1 kHz: time and the `columns`, functions of the time [SI]."""
    rows = []
    for i in range(2000):
        t = i / 1000.0
        rows.append(",".join([repr(t), *(repr(f(t)) for f in columns)]) + "\n")
    return header + "\n" + "".join(rows)


def _force(t: float) -> float:
    return 3.0 * math.sin(2 * math.pi * 2.0 * t)


def _position(t: float) -> float:
    return 1e-3 * math.sin(2 * math.pi * 2.0 * t)


QUASI_STATIC = ('[stage]\ntype = "quasi-static"\nk = 100.0\nc = 0.5\n\n'
                '[hysteresis]\nmodel = "jenkins"\nk = 2000.0\nfc = 2.0\n')
"""A link without inertia (as identify saves a force-displacement record's fit)."""

BASE = {  # the user's folder: every case starts from these files
    "s.toml": PAPER,
    "axis.toml": MASS_DAMPER,
    "qs.toml": QUASI_STATIC,
    "force.csv": _series("time,force", _force),
    "position.csv": _series("time,displacement", _position),
    "notes.txt": "my notes",
}

SCAN = ["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
        "--s-max", "1e6"]

# (id, extra files, argv, words the line must contain)
CASES = [
    # ------------------------------------------- an option given twice (argparse kept the last)
    ("df-amplitude-twice", {}, ["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01",
                                "--amplitude", "0.02"],
     ["df: --amplitude is given twice; give it once, all its values after it"]),
    ("steady-abbreviated-and-whole", {}, ["steady", "s.toml", "--freq", "5", "--frequency",
                                          "10"], ["--frequency is given twice"]),
    ("predict-out-twice", {}, ["predict", "axis.toml", "force.csv", "--out", "a.csv", "--out",
                               "b.csv"], ["predict: --out is given twice; give it once"]),
    ("scan-speed-twice", {}, [*SCAN, "--speed", "0.2"], ["scan: --speed is given twice"]),
    ("budget-twice-before-the-command", {}, ["--max-seconds", "1", "--max-seconds", "2",
                                             "steady", "s.toml"],
     ["--max-seconds is given twice"]),
    # the one before the command has another destination: it was dropped for the command's
    ("max-memory-before-and-after", {}, ["--max-memory", "1G", "steady", "s.toml",
                                         "--max-memory", "2G"],
     ["steady: --max-memory is given twice (before the command and after it); give it once"]),
    ("max-seconds-before-and-after", {}, ["--max-seconds", "1e-9", "steady", "s.toml",
                                          "--max-seconds", "100"],
     ["steady: --max-seconds is given twice (before the command and after it)"]),
    # ------------------------------------ predict: a map's entry for what the run predicts
    # the displacement of a force record is the output, not read: the entry was dropped
    ("predict-columns-displacement-unread", {}, ["predict", "axis.toml", "force.csv", "--out",
                                                 "p.csv", "--columns", "displacement=foo"],
     ["predict: --columns names 'displacement', which is not read here: the run predicts the "
      "displacement from the force of force.csv, which holds no column 'foo' (a measured one "
      "is read with --init-from REC)"]),
    ("predict-scale-displacement-unread", {}, ["predict", "axis.toml", "force.csv", "--out",
                                               "p.csv", "--scale", "displacement=1e-3"],
     ["predict: --scale names 'displacement', which is not read here", "holds no "
      "displacement"]),
    ("predict-columns-force-unread", {}, ["predict", "qs.toml", "position.csv", "--out",
                                          "f.csv", "--columns", "force=foo"],
     ["predict: --columns names 'force', which is not read here: the run predicts the force "
      "from the displacement of position.csv, which holds no column 'foo'"]),
    ("predict-scale-force-unread", {}, ["predict", "qs.toml", "position.csv", "--out", "f.csv",
                                        "--scale", "force=1e-3"],
     ["predict: --scale names 'force', which is not read here"]),
]


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_refused_in_one_line_touching_nothing(tmp_path, files, argv, words):
    populate(root := tmp_path / "user", {**BASE, **files})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)  # exit 2, one line, nothing on stdout
    missing = [word for word in words if word not in line]
    assert line.startswith("motionhyst: error: ") and not missing, (missing, line)
    # nothing changed, nothing added (beside the folder either)
    assert (snapshot(root), list(tmp_path.iterdir())) == (before, [root])


def test_the_map_given_identify_still_reads_the_record_that_holds_the_position(tmp_path):
    """A force record that holds the measured position too (the record identify was given),
    read with identify's map: the entry for the position describes the file, and is kept
    (only time and force are read); the run predicts as without it."""
    rec = _series("time,force,pos", _force, _position)
    populate(tmp_path, {"axis.toml": MASS_DAMPER, "rec.csv": rec,
                        "force.csv": _series("time,force", _force)})
    outputs = []
    for name, maps in (("a.csv", ["--columns", "displacement=pos", "--scale",
                                  "displacement=1"]), ("b.csv", [])):
        record = "rec.csv" if maps else "force.csv"
        code, _, err = limited_process.run(["predict", "axis.toml", record, "--out", name,
                                            *maps], tmp_path)
        assert code == 0 and err == "", err
        outputs.append((tmp_path / name).read_text())
    assert outputs[0] == outputs[1]

