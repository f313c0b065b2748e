"""The bad-input corpus (issue 10): scenarios, CSV files, arguments and output paths.

Every case runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2,
one line on stderr without a traceback, nothing on stdout, and that every file that was
there before is byte-identical afterwards, with no file added (no temporary file, no
half-written output).
"""

from __future__ import annotations

from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()


def _record() -> str:
    """A valid force-displacement record (time,displacement,force)."""
    t = np.linspace(0.0, 1.0, 400)
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    w = np.clip(20.0 * (x - x[0]), -0.01, 0.01)
    return "time,displacement,force\n" + "".join(f"{a!r},{b!r},{c!r}\n"
                                                 for a, b, c in zip(t.tolist(), x.tolist(),
                                                                    w.tolist(), strict=True))


def _reference() -> str:
    t = np.linspace(0.0, 0.05, 51)
    r = 1e-4 * np.sin(20 * t)
    return "time,position\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), r.tolist(),
                                                                          strict=True))


def _frd(use: str = "data") -> str:
    """The Table I scenario with a measured [plant] in place of the [stage] model."""
    return (PAPER[:PAPER.index("[stage]")] + f'[plant]\nfile = "plant.csv"\nuse = "{use}"\n'
            f"mass = 22.5\n\n" + PAPER[PAPER.index("[hysteresis]"):])


def _plant_csv() -> str:
    f = np.geomspace(1.0, 1000.0, 40)
    p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    return "frequency_hz,p1_re,p1_im,p2_re,p2_im\n" + "".join(
        f"{a!r},{b!r},0,{b!r},0\n" for a, b in zip(f.tolist(), p.tolist(), strict=True))


BASE = {  # the user's folder: every case starts from these files
    "s.toml": PAPER,
    "rec.csv": _record(),
    "ref.csv": _reference(),
    "notes.txt": "my notes",
    "old.csv": "time,error\n0,0\n",
}


def _scenario(old: str, new: str) -> dict:
    assert old in PAPER, old
    return {"bad.toml": PAPER.replace(old, new)}


def _csv(name: str, text: str | bytes) -> dict:
    return {name: text}


REF_ROWS = _reference().splitlines()
REC_ROWS = _record().splitlines()

SCAN = ["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
        "--s-max", "1e6"]

# (id, extra files, argv, words the message must contain)
CASES = [
    # ---------------------------------------------------------------- scenario files
    ("toml-syntax", {"bad.toml": "[stage\nm1 = 5"}, ["analyze", "bad.toml"], ["TOML"]),
    ("toml-missing-file", {}, ["analyze", "nowhere.toml"], ["nowhere.toml", "cannot read"]),
    ("toml-is-folder", {"dir/x": "x"}, ["analyze", "dir"], ["dir"]),
    ("toml-binary", {"bad.toml": b"\x00\xff\xfe garbage"}, ["analyze", "bad.toml"],
     ["bad.toml"]),
    ("toml-negative-mass", _scenario("m1 = 5.0", "m1 = -5.0"), ["analyze", "bad.toml"],
     ["m1"]),
    ("toml-string-mass", _scenario("m1 = 5.0", 'm1 = "five"'), ["analyze", "bad.toml"],
     ["m1"]),
    ("toml-unknown-key", _scenario("m1 = 5.0", "m1 = 5.0\nmass1 = 3.0"),
     ["analyze", "bad.toml"], ["mass1"]),
    ("toml-unknown-model", _scenario('model = "jenkins"', 'model = "preisach"'),
     ["analyze", "bad.toml"], ["preisach"]),
    ("toml-missing-section", {"bad.toml": PAPER.replace("[controller]", "[ctrl]")},
     ["analyze", "bad.toml"], ["bad.toml"]),
    ("toml-zero-frequency", _scenario("frequencies = [5.0, 10.0, 15.0]",
                                      "frequencies = [0.0]"), ["steady", "bad.toml"],
     ["frequencies"]),
    ("toml-negative-amplitude", _scenario("amplitude = 0.01", "amplitude = -0.01"),
     ["steady", "bad.toml"], ["amplitude"]),
    ("toml-plant-file-missing", {"bad.toml": _frd()}, ["analyze", "bad.toml"],
     ["plant.csv"]),
    ("toml-plant-csv-bad-cell", {"bad.toml": _frd(), "plant.csv":
                                 _plant_csv().replace("0,", "x,", 1)},
     ["analyze", "bad.toml"], ["plant.csv", "non-numeric"]),
    ("toml-plant-csv-header", {"bad.toml": _frd(), "plant.csv": "f,a,b\n1,2,3\n"},
     ["analyze", "bad.toml"], ["plant.csv", "frequency_hz"]),
    ("raw-measured-plant-time-series", {"bad.toml": _frd(), "plant.csv": _plant_csv()},
     ["simulate", "bad.toml", "--time-series", "out.csv", "--frequency", "5"],
     ["--time-series", "use = \"fit\""]),
    # ---------------------------------------------------------------- CSV records
    ("record-missing", {}, ["identify", "nope.csv"], ["nope.csv", "cannot read"]),
    ("record-empty", _csv("r.csv", ""), ["identify", "r.csv"], ["r.csv", "empty"]),
    ("record-header-only", _csv("r.csv", "time,displacement,force\n"), ["identify", "r.csv"],
     ["r.csv", "no data rows"]),
    ("record-unknown-header", _csv("r.csv", "t,x,f\n0,0,0\n"), ["identify", "r.csv"],
     ["time,displacement,force", "time,y1,u"]),
    ("record-bad-cell", _csv("r.csv", "\n".join([*REC_ROWS[:5], "0.01,abc,0", *REC_ROWS[6:]])),
     ["identify", "r.csv"], ["'abc'", "line 6", "displacement"]),
    ("record-empty-cell", _csv("r.csv", "\n".join([*REC_ROWS[:5], "0.01,,0", *REC_ROWS[6:]])),
     ["identify", "r.csv"], ["empty cell", "line 6"]),
    ("record-short-row", _csv("r.csv", "\n".join([*REC_ROWS[:5], "0.01,0", *REC_ROWS[6:]])),
     ["identify", "r.csv"], ["inconsistent lengths", "line 6"]),
    ("record-long-row", _csv("r.csv", "\n".join([*REC_ROWS[:5], "0.01,0,0,9",
                                                 *REC_ROWS[6:]])),
     ["identify", "r.csv"], ["inconsistent lengths", "line 6"]),
    ("record-nan", _csv("r.csv", "\n".join([*REC_ROWS[:5], "0.01,nan,0", *REC_ROWS[6:]])),
     ["identify", "r.csv"], ["non-finite"]),
    ("record-time-backwards", _csv("r.csv", "\n".join([REC_ROWS[0], REC_ROWS[2], REC_ROWS[1],
                                                       *REC_ROWS[3:]])),
     ["identify", "r.csv"], ["increasing"]),
    ("record-duplicate-column", _csv("r.csv", "time,Time,displacement,force\n0,0,0,0\n"),
     ["identify", "r.csv"], ["appears twice"]),
    ("record-binary", _csv("r.csv", bytes(range(256)) * 4), ["identify", "r.csv"],
     ["r.csv"]),
    ("record-is-folder", {"r.csv/x": "x"}, ["identify", "r.csv"], ["r.csv"]),
    ("record-too-short", _csv("r.csv", "\n".join(REC_ROWS[:15])), ["identify", "r.csv"],
     ["too short"]),
    ("record-cutoff-force-displacement", {}, ["identify", "rec.csv", "--cutoff", "10"],
     ["--cutoff", "closed-loop"]),
    # ---------------------------------------------------------------- reference CSVs
    ("reference-missing", {}, ["simulate", "--time-series", "o.csv", "--reference-csv",
                               "nope.csv"], ["nope.csv"]),
    ("reference-header", _csv("r.csv", "t,pos\n0,0\n1,1\n"),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"],
     ["need a header with time,position"]),
    ("reference-bad-cell", _csv("r.csv", "\n".join([*REF_ROWS[:4], "0.003;x",
                                                    *REF_ROWS[5:]])),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"], ["line 5"]),
    ("reference-semicolon-bad-cell", _csv("r.csv", "time;position\n0;0\n0,1;abc\n0,2;1\n"),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"],
     ["'abc'", "line 3", "position"]),
    ("reference-too-few", _csv("r.csv", "\n".join(REF_ROWS[:4])),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"], ["6 samples"]),
    ("reference-time-repeats", _csv("r.csv", "\n".join([*REF_ROWS[:3], REF_ROWS[2],
                                                        *REF_ROWS[3:]])),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"], ["increasing"]),
    ("reference-inf", _csv("r.csv", "\n".join([*REF_ROWS[:3], "0.002,inf", *REF_ROWS[4:]])),
     ["simulate", "--time-series", "o.csv", "--reference-csv", "r.csv"],
     ["r.csv: the reference's position must be finite: sample 3 is inf"]),
    # ---------------------------------------------------------------- arguments
    ("unknown-command", {}, ["fly"], ["invalid choice"]),
    ("unknown-option", {}, ["analyze", "--colour"], ["--colour"]),
    ("amplitude-text", {}, ["analyze", "--amplitude", "ten"], ["--amplitude", "'ten'"]),
    ("amplitude-negative", {}, ["analyze", "--amplitude", "-1"], ["--amplitude"]),
    ("amplitude-nan", {}, ["analyze", "--amplitude", "nan"], ["finite"]),
    ("frequency-zero", {}, ["steady", "--frequency", "0"], ["--frequency", "> 0"]),
    ("frequency-repeated-analyze", {}, ["analyze", "--frequency", "5", "5"],
     ["--frequency 5 is given twice"]),
    ("frequency-repeated-simulate", {}, ["simulate", "--frequency", "5", "10", "5"],
     ["--frequency 5 is given twice"]),
    # an option given twice: argparse kept the last (5 Hz silently dropped), now refused
    ("frequency-option-twice", {}, ["steady", "--frequency", "5", "--frequency", "10"],
     ["--frequency is given twice; give it once, all its values after it"]),
    ("amplitude-option-twice", {}, ["analyze", "--amplitude", "1e-3", "--amplitude", "1e-2"],
     ["--amplitude is given twice; give it once"]),
    ("df-no-amplitude", {}, ["df", "--k", "20", "--fc", "0.05"], ["--amplitude"]),
    ("df-harmonics-zero", {}, ["df", "--k", "20", "--fc", "0.05", "--amplitude", "1e-3",
                               "--harmonics", "0"], ["--harmonics"]),
    ("df-frequency-rate-independent", {}, ["df", "--k", "20", "--fc", "0.05", "--amplitude",
                                           "1e-3", "--frequency", "5"], ["rate-independent"]),
    ("profile-without-time-series", {}, ["simulate", "--profile", "point-to-point"],
     ["--profile has no effect without --time-series"]),
    ("reference-without-time-series", {}, ["simulate", "--reference-csv", "ref.csv"],
     ["--reference-csv has no effect without --time-series"]),
    ("duration-without-time-series", {}, ["simulate", "--duration", "2"],
     ["--duration has no effect"]),
    ("output-rate-without-time-series", {}, ["simulate", "--output-rate", "1000"],
     ["--output-rate has no effect"]),
    ("force-without-output", {}, ["simulate", "--force"], ["--force has no effect"]),
    ("limits-without-profile", {}, ["simulate", "--time-series", "o.csv", "--v-max", "1"],
     ["--v-max has no effect without --profile"]),
    ("settle-band-without-profile", {}, ["simulate", "--time-series", "o.csv",
                                         "--settle-band", "1e-9"], ["--settle-band"]),
    ("several-frequencies-time-series", {}, ["simulate", "--time-series", "o.csv",
                                             "--frequency", "5", "10"], ["one sine"]),
    ("scenario-frequencies-time-series", {}, ["simulate", "s.toml", "--time-series",
                                              "o.csv"], ["3 frequencies"]),
    ("amplitude-with-profile", {}, ["simulate", "--time-series", "o.csv", "--profile",
                                    "point-to-point", "--amplitude", "0.01"],
     ["--amplitude has no effect with --profile"]),
    ("frequency-with-reference", {}, ["simulate", "--time-series", "o.csv", "--reference-csv",
                                      "ref.csv", "--frequency", "5"], ["--frequency"]),
    ("reference-and-profile", {}, ["simulate", "--time-series", "o.csv", "--reference-csv",
                                   "ref.csv", "--profile", "point-to-point"], ["not both"]),
    ("zero-distance", {}, ["simulate", "--time-series", "o.csv", "--profile",
                           "point-to-point", "--distance", "0"], ["--distance"]),
    ("output-rate-negative", {}, ["simulate", "--time-series", "o.csv", "--frequency", "5",
                                  "--output-rate", "-5"], ["--output-rate"]),
    ("elements-zero", {}, ["identify", "rec.csv", "--elements", "0"], ["--elements"]),
    ("scan-dwell-without-back-and-forth", {}, [*SCAN, "--dwell", "0.1"],
     ["--dwell has no effect without --back-and-forth"]),
    ("scan-force-without-time-series", {}, [*SCAN, "--force"], ["--force has no effect"]),
    ("stability-force-without-figure", {}, ["stability", "--no-exact", "--force"],
     ["--force has no effect without --figure"]),
    ("identify-force-without-save", {}, ["identify", "rec.csv", "--force"],
     ["--force has no effect without --save"]),
    # ---------------------------------------------------------------- output paths
    ("time-series-exists", {}, ["simulate", "--time-series", "old.csv", "--frequency", "5"],
     ["old.csv exists", "--force"]),
    ("time-series-is-scenario", {}, ["simulate", "s.toml", "--time-series", "s.toml",
                                     "--frequency", "5", "--force"], ["input"]),
    ("time-series-is-reference", {}, ["simulate", "--time-series", "./ref.csv",
                                      "--reference-csv", "ref.csv", "--force"], ["input"]),
    ("time-series-hardlink-to-scenario", {"@hard:link.csv": "s.toml"},
     ["simulate", "s.toml", "--time-series", "link.csv", "--frequency", "5", "--force"],
     ["input"]),
    ("time-series-symlink-to-scenario", {"@symlink:link.csv": "s.toml"},
     ["simulate", "s.toml", "--time-series", "link.csv", "--frequency", "5", "--force"],
     ["input"]),
    ("time-series-is-folder", {"sub/keep.txt": "x"},
     ["simulate", "--time-series", "sub", "--frequency", "5", "--force"], ["folder"]),
    ("time-series-parent-is-file", {}, ["simulate", "--time-series", "notes.txt/o.csv",
                                        "--frequency", "5"], ["not a folder"]),
    ("time-series-dangling-symlink", {"@symlink:dangling.csv": "nowhere.csv"},
     ["simulate", "--time-series", "dangling.csv", "--frequency", "5"],
     ["symbolic link to a missing file"]),
    ("reproduce-out-is-file", {}, ["reproduce", "--out", "notes.txt"], ["is a file"]),
    ("reproduce-out-symlink-to-folder", {"keep/x.txt": "x", "@symlink:out": "keep"},
     ["reproduce", "--out", "out"], ["symbolic link"]),
    ("reproduce-out-symlink-to-file", {"@symlink:out": "notes.txt"},
     ["reproduce", "--out", "out"], ["symbolic link"]),
    ("reproduce-out-dangling-symlink", {"@symlink:out": "nowhere"},
     ["reproduce", "--out", "out"], ["symbolic link"]),
    ("reproduce-foreign-report", {"out/report.md": "my own report", "out/data.csv": "1"},
     ["reproduce", "--out", "out"], ["report.md", "not written by motionhyst", "--force"]),
    ("reproduce-foreign-figure-here", {"fig9.png": b"\x89PNG mine"},
     ["reproduce", "--out", "."], ["fig9.png", "--force"]),
    ("reproduce-out-below-file", {}, ["reproduce", "--out", "notes.txt/out"],
     ["not a folder"]),
    ("reproduce-name-is-folder", {"out/summary.json/keep.txt": "x"},
     ["reproduce", "--out", "out", "--force"], ["summary.json", "folder"]),
]


def _populate(root: Path, files: dict) -> None:
    populate(root, {**BASE, **files})


def test_the_corpus_is_large_enough():
    assert len(CASES) >= 60
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_bad_input_is_exit_2_one_line_and_touches_nothing(tmp_path, files, argv, words):
    root = tmp_path / "user"
    root.mkdir()
    _populate(root, files)
    before = snapshot(root)
    code, out, err = limited_process.run(list(argv), root)  # under a memory limit
    assert code == 2, (code, out, err)
    assert out == ""
    line = err.strip()
    assert line and "\n" not in line and "Traceback" not in line, err
    assert line.startswith("motionhyst: error: "), line
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before  # nothing changed, nothing added
    assert [p.name for p in tmp_path.iterdir()] == ["user"]
