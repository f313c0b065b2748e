"""Inputs that ran to an answer without a word, or refused only after the work (issue 26:
every refusal within 2 s of start, 0 exit-0 answers from undetermined inputs): an exposure
window that holds one sample, a controller rate that cannot resolve the setpoint, a time
series larger than the disk holds (a file size limit, ``ulimit -f``, stands for a full disk),
a stage's record and a link's given together (over 120 s of search), a time column in ms
(its 2e6 kg said only after the fit).

The corpus cases run the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and assert exit code 2, one
line on stderr naming the option and the cause (no traceback), nothing on stdout, and every
file there before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst import Jenkins
from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
SCAN = ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
        "1000", "--s-max", "1e6", "--compensation", "none"]
SIMULATE = ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5"]
QUASI_STATIC = ('[stage]\ntype = "quasi-static"\nk = 10.0\n\n'
                '[hysteresis]\nmodel = "jenkins"\nk = 20.0\nfc = 0.05\n')
FILE_LIMIT = 10 << 20
"""A file size limit [bytes] for the cases that write a time series: 10 MiB."""


def _displacement_record(n: int) -> str:
    """time,displacement: `n` samples of a 1 mm sine at 2 Hz, sampled at 1 kHz."""
    t = np.arange(n) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    return "time,displacement\n" + "".join(f"{a:.17g},{b:.17g}\n"
                                            for a, b in zip(t, x, strict=True))


def _csv(columns: dict[str, np.ndarray]) -> str:
    rows = np.column_stack(list(columns.values()))
    return ",".join(columns) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                              for row in rows)


def _stage(n: int = 3000, seed: int = 0, time_unit: float = 1.0) -> str:
    """A positioning axis's record at 1 kHz: a 2 kg mass on viscous friction (10 N s/m) and a
    Jenkins link (2000 N/m, 1 N) driven by two sines, its position with 0.1 um of noise;
    its time column in seconds times `time_unit`."""
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    t = np.arange(n) / 1000.0
    u = 5 * np.sin(2 * np.pi * 1.3 * t) + 3 * np.sin(2 * np.pi * 4.1 * t + 0.4)
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2000.0, fc=1.0)).simulate(t, u).displacement
    y = y + 1e-7 * np.random.default_rng(seed).standard_normal(n)
    return _csv({"time": t * time_unit, "force": u, "displacement": y})


def _link(n: int = 3000) -> str:
    """A link's force-displacement record at 1 kHz: a Jenkins element with a spring and a
    damper in parallel, driven by a 1 mm sine at 2 Hz (no mass)."""
    t = np.arange(n) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * 2 * t) * (0.8 + 0.2 * np.cos(2 * np.pi * 0.05 * t))
    w = (Jenkins(k=40.0, fc=0.01).response(x) + 10 * x + 1.6 * np.gradient(x, t)
         + 1e-4 * np.random.default_rng(1).standard_normal(n))
    return _csv({"time": t, "displacement": x, "force": w})


BASE = {"s.toml": PAPER, "notes.txt": "my notes", "ts.csv": "an old time series\n"}

# (id, extra files, argv, words of the one line on stderr)
CASES = [
    # Table I's loop steps at 3.62e-5 s: a window of 1 ns holds one sample, MSD 0 everywhere
    ("scan-window-shorter-than-a-step", {}, [*SCAN, "--window", "1e-9"],
     ["scan: --window: the exposure window 1e-09 s is shorter than two time steps of the run "
      "(3.62e-05 s): it holds one sample, whose moving standard deviation is 0",
      "give a longer --window (at least 7.24e-05 s)"]),
    ("scan-window-of-one-sample", {}, [*SCAN, "--window", "7e-5"],
     ["--window: the exposure window 7e-05 s is shorter than two time steps"]),
    # on 1 s samples the move of 0.142 s takes 9 s
    ("scan-rate-slower-than-the-move", {}, [*SCAN, "--rate", "1"],
     ["scan: --rate 1 Hz cannot resolve the setpoint: its switching instants on the samples "
      "make another move (0.142 s -> 9 s, peak acceleration 0.05 m/s^2 for --a-max 10); give "
      "the controller's rate"]),
    # 100 Hz stretches the setpoint 1.27 times (a warning) and the carry-over setpoint of
    # 0.1 mm at 10 mm/s 3.6 times: the refusal alone, one line
    ("scan-rate-of-the-carry-over", {},
     [*SCAN[:-1], "ilc", "--other-length", "1e-4", "--other-speed", "1e-2", "--rate", "100"],
     ["--rate 100 Hz cannot resolve the carry-over setpoint (--other-length, --other-speed): "
      "its switching instants on the samples make another move (0.0248 s -> 0.09 s"]),
    # the link's record shows -0.115 +- 0.002 kg, the stage's 1.94 +- 0.02 kg
    ("identify-a-stage-s-record-and-a-link-s", {"stage.csv": _stage(), "link.csv": _link()},
     ["identify", "stage.csv", "link.csv", "--record", "input-output"],
     ["link.csv: no inertia in the force (its inverse-dynamics mass -0.11", "while stage.csv "
      "shows 1.9", "the records cannot describe one stage; a link's force against an imposed "
      "displacement is identified on its own, without --record input-output"]),
]


# (id, extra files, argv, words of the one line on stderr): run under FILE_LIMIT
WRITERS = [
    # 5e7 rows of 8 numbers: 8.4 GB (main wrote 10 MiB, then failed with "File too large")
    ("simulate-a-time-series-larger-than-the-disk-holds", {},
     [*SIMULATE, "--force", "--output-rate", "1e9", "--duration", "0.05"],
     ["--time-series ts.csv: 5e+07 rows of 8 numbers needs 8.4 GB, above the 10.5 MB a file "
      "may take (the file size limit, ulimit -f); lower --output-rate (1e+09 Hz) or shorten "
      "--duration (0.05 s), or write --time-series where there is room"]),
    ("scan-a-time-series-larger-than-the-disk-holds", {},
     [*SCAN, "--tail", "10", "--time-series", "new.csv"],
     ["--time-series new.csv: 2.81e+05 rows of 6 numbers needs 35.4 MB, above the 10.5 MB",
      "or --tail", "or write --time-series where there is room"]),
    ("predict-a-force-larger-than-the-disk-holds",
     {"m.toml": QUASI_STATIC, "d.csv": _displacement_record(300_000)},
     ["predict", "m.toml", "d.csv", "--out", "p.csv"],
     ["--out p.csv: 3e+05 rows of 2 numbers needs 15 MB, above the 10.5 MB a file may take",
      "give a shorter record, or write --out where there is room"]),
]


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv, words):
    populate(tmp_path, {**BASE, **files})
    before = snapshot(tmp_path)
    line = limited_process.refusal(argv, tmp_path)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in WRITERS],
                         ids=[c[0] for c in WRITERS])
def test_an_output_that_does_not_fit_is_refused_before_the_work(tmp_path, files, argv, words):
    populate(tmp_path, {**BASE, **files})
    before = snapshot(tmp_path)
    line = limited_process.refusal(argv, tmp_path, file_limit=FILE_LIMIT, timeout=120)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(tmp_path) == before


def test_a_time_series_s_rows_count_in_its_work(tmp_path):
    """5e7 rows of a step each: 3.4 min of work at 1.5 us a step and 2.5 us a row (1e6 such
    rows measured at 4 s), above a budget of one minute; the remedy names --output-rate."""
    populate(tmp_path, BASE)
    before = snapshot(tmp_path)
    line = limited_process.refusal([*SIMULATE, "--force", "--output-rate", "1e9", "--duration",
                                    "0.05", "--max-seconds", "60"], tmp_path, timeout=120)
    assert line.endswith("a run of 5e+07 time steps, 5e+07 rows written would take about "
                         "3.4 min, above the work budget of 1 min (--max-seconds); shorten "
                         "--duration, or lower --output-rate"), line
    assert snapshot(tmp_path) == before


def test_the_disk_s_free_space_bounds_a_file(tmp_path, monkeypatch):
    """Without a file size limit the free space of the output's folder is the budget."""
    import resource
    import shutil
    from collections import namedtuple

    from motionhyst.core.budget import BudgetError, check_disk

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(
        10 ** 9, 10 ** 9 - 2 * 10 ** 6, 2 * 10 ** 6))
    monkeypatch.setattr(resource, "getrlimit", lambda which: (resource.RLIM_INFINITY,) * 2)
    check_disk(1.9e6, tmp_path / "new-folder", "a file")
    with pytest.raises(BudgetError) as err:
        check_disk(8.4e9, tmp_path / "new-folder", "--time-series ts.csv: 5e+07 rows",
                   "lower --output-rate")
    assert str(err.value) == (f"--time-series ts.csv: 5e+07 rows needs 8.4 GB, above the 2 MB "
                              f"free in {tmp_path}; lower --output-rate")


def test_records_of_one_stage_are_not_refused_as_two(tmp_path):
    """Two records of the same stage (noise of two seeds) pass the check: the search starts
    (and here meets its work budget of one second, exit 2, after it)."""
    populate(tmp_path, {"a.csv": _stage(seed=0), "b.csv": _stage(seed=2)})
    code, out, err = limited_process.run(["identify", "a.csv", "b.csv", "--record",
                                          "input-output", "--max-seconds", "1"], tmp_path)
    assert out == "" and code == 2 and "cannot describe one stage" not in err, err
    assert err.strip().splitlines()[-1].startswith(
        "motionhyst: error: identify did not finish within the work budget of 1 s"), err


def test_a_time_column_in_ms_is_said_before_the_search(tmp_path):
    """A time column in ms makes the records' inverse-dynamics mass 1e6 times too large
    (1.98e6 kg for 2 kg): said before the search, naming the time column and the scale
    that makes it 1.98 kg (the search then meets its budget of one second)."""
    populate(tmp_path, {"ms.csv": _stage(time_unit=1000.0)})
    code, out, err = limited_process.run(["identify", "ms.csv", "--record", "input-output",
                                          "--max-seconds", "1"], tmp_path)
    lines = err.strip().splitlines()
    assert out == "" and code == 2 and len(lines) == 3, err
    assert lines[0] == ("motionhyst: warning: identify: ms.csv: the records' inverse-dynamics "
                        "mass is 1.98e+06 kg, outside the usual 0.001-10000 kg of motion "
                        "stages: is the time column in ms (sampled at 1 Hz)? --scale "
                        "time=0.001 makes it 1.98 kg"), err
    assert lines[2].startswith("motionhyst: error: identify did not finish within"), err


def test_a_rate_whose_samples_are_longer_than_a_short_snap_is_not_refused(tmp_path):
    """A snap pulse of 8 us (s-max 1e12) on a 10 kHz controller's samples: the setpoint of
    1 s lasts 1 s on them, a move the rate resolves; the run goes on (here to the work budget
    of a millisecond, refused before the loop)."""
    populate(tmp_path, BASE)
    line = limited_process.refusal(["scan", "s.toml", "--length", "1e-3", "--speed", "1e-3",
                                    "--a-max", "100", "--j-max", "1e6", "--s-max", "1e12",
                                    "--rate", "10000", "--compensation", "none",
                                    "--max-seconds", "0.001"], tmp_path)
    assert "--rate" not in line and "above the work budget of 0.001 s" in line, line


def test_a_rate_that_stretches_the_setpoint_is_said(capsys):
    """A rate of 100 Hz resolves the setpoint's 21 ms of acceleration, but its switching
    instants on 10 ms samples stretch the move from 0.142 s to 0.18 s, its peak acceleration
    from 9.5 to 5 m/s^2: an answer, with a warning naming --rate."""
    assert main([*SCAN[:1], *SCAN[2:], "--rate", "100"]) == 0
    captured = capsys.readouterr()
    warned = [line for line in captured.err.splitlines() if line.startswith("motionhyst: warn")]
    assert warned == ["motionhyst: warning: scan: --rate 100 Hz: the setpoint's switching "
                      "instants on its samples stretch the move (0.142 s -> 0.18 s, peak "
                      "acceleration 5 m/s^2 for --a-max 10)"], captured.err
    assert "scan of 0.01 m at 0.1 m/s: 0.18 s; peak acceleration 5 m/s^2" in captured.out


def test_an_infinite_standard_error_is_not_printed_as_a_figure():
    """A closed-loop record refused for an element it cannot determine: its slip force's
    infinite standard error is said as not determined, never ``+- inf``."""
    from types import SimpleNamespace

    from motionhyst.cli.identify import _check_slips

    ident = SimpleNamespace(elements=[{"k": 7.102, "fc": 71.02, "fc_std": float("inf")}],
                            judged_std={"fc[0]": float("inf")})
    with pytest.raises(ValueError) as err:
        _check_slips(Path("cl.csv"), ident, np.array([-10.0, 10.0]))
    assert "fc 71.02 N, its standard error not determined)" in str(err.value)
    assert "+- inf" not in str(err.value)


def test_predict_counts_the_first_scored_sample_from_one():
    """After a window of 20 samples the error is scored from the 21st, as the finite checks
    count samples (from 1)."""
    from motionhyst.identify.io_predict import WindowPrediction

    pred = WindowPrediction(np.arange(100) / 1e3, np.zeros(100), 20,
                            {"position": 0.0, "velocity": 0.0}, 1e-6, 99.0)
    assert "; RMS error from sample 21 on 1e-06 m" in str(pred)
