"""Options and files that were silently dropped, and refusals that said more than one line
(issue 26: "0 silently ignored options"; every refusal one line, exit 2, within 2 s).

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2, one
line on stderr without a traceback, nothing on stdout, the line's words, and every file that
was there before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import math
import resource
from pathlib import Path

import limited_process
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

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


def _measured(path: Path) -> None:
    """Table I's stage (eqs. 1-2) as a measured response, 61 lines from 1 Hz to 3 kHz of
    ``P1`` and ``P2`` (plant.csv), and the scenario `path` with ``[plant] file`` in place of
    its [stage]."""
    m1, m2, b, k = 5.0, 17.5, 90.0, 7.4e7
    rows = []
    for i in range(61):
        s = 2j * math.pi * 3000.0 ** (i / 60)
        den = s * s * (m1 * m2 * s * s + (m1 + m2) * (b * s + k))
        p1, p2 = (m2 * s * s + b * s + k) / den, (b * s + k) / den
        rows.append(f"{abs(s) / (2 * math.pi)!r},{p1.real!r},{p1.imag!r},{p2.real!r},"
                    f"{p2.imag!r}\n")
    path.with_name("plant.csv").write_text("frequency_hz,p1_re,p1_im,p2_re,p2_im\n"
                                           + "".join(rows))
    path.write_text(PAPER[:PAPER.index("[stage]")] + '[plant]\nfile = "plant.csv"\n\n'
                    + PAPER[PAPER.index("[hysteresis]"):])


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
    # ----------------------------------------------------- refusals said once and plainly
    # the scenario's name was said twice, and "is a quasi-static (an open-loop ...)"
    ("stability-open-loop-named-once", {}, ["stability", "axis.toml"],
     ["stability: axis.toml: [stage] is a mass-damper stage (an open-loop system"]),
    ("stability-quasi-static-stage", {}, ["stability", "qs.toml"],
     ["stability: qs.toml: [stage] is a quasi-static stage (an open-loop system"]),
    # predict of a measured plant said "[stage] is not ..." of a scenario without [stage]
    ("predict-measured-plant", {"m.toml": _measured}, ["predict", "m.toml", "force.csv",
                                                       "--out", "p.csv"],
     ["m.toml: has a measured [plant], not a [stage]; an open-loop system needs a [stage] "
      "of type"]),
    # a robustness filter's corner beyond every frequency of the trial filters nothing
    ("scan-ilc-cutoff-above-nyquist", {}, [*SCAN, "--compensation", "ilc", "--ilc-cutoff",
                                           "1e9"],
     ["scan: --ilc-cutoff 1e+09 Hz is above", "Hz, the Nyquist frequency of the run's "
      "samples (a step of", "give a corner below it (default 300 Hz)"]),
    ("scan-ilc-cutoff-above-a-sampled-loop-s-nyquist",
     {"z.toml": (EXAMPLES / "paper_10khz.toml").read_text()},
     [*SCAN, "z.toml", "--compensation", "ilc", "--ilc-cutoff", "5001"],
     ["scan: --ilc-cutoff 5001 Hz is above 5000 Hz, the Nyquist frequency of the run's "
      "samples (a step of 0.0001 s)"]),
    ("scan-ilc-cutoff-above-a-measured-loop-s-nyquist", {"m.toml": _measured},
     [*SCAN, "m.toml", "--compensation", "ilc", "--ilc-cutoff", "1e9"],
     ["scan: --ilc-cutoff 1e+09 Hz is above"]),
    # a model TOML under another name (identify --save x.csv wrote TOML into x.csv)
    ("identify-save-csv", {"rec.csv": _series("time,displacement,force", _position,
                                              lambda t: 2.0 * _position(t) / 1e-3)},
     ["identify", "rec.csv", "--save", "x.csv"],
     ["identify: --save x.csv: the identified model is written as a scenario TOML (read by "
      "predict, steady and study --from-identification); give a name ending in .toml"]),
    ("identify-input-output-save-txt", {"rec.csv": _series("time,force,displacement", _force,
                                                           _position)},
     ["identify", "rec.csv", "--record", "input-output", "--plant", "mass-damper", "--model",
      "jenkins", "--save", "model.txt"],
     ["identify: --save model.txt: the identified model is written as a scenario TOML"]),
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


def test_a_budget_beyond_the_machine_is_not_said_before_a_refusal(tmp_path):
    """A --max-memory larger than the machine is warned of when the work starts; a refusal
    before the work (here too many time steps) was that warning and the refusal, two lines:
    it is the refusal's line alone.  Without an address-space limit: under one within the
    machine's memory nothing is warned of in any case."""
    populate(tmp_path, BASE)
    before = snapshot(tmp_path)
    line = limited_process.refusal(["simulate", "s.toml", "--frequency", "5", "--time-series",
                                    "big.csv", "--duration", "1e5", "--max-memory", "1e308"],
                                   tmp_path, limit=resource.RLIM_INFINITY)
    assert line.startswith("motionhyst: error: ") and "too many time steps" in line, line
    assert snapshot(tmp_path) == before
