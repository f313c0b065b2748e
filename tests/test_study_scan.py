"""Scans in studies: the output ``scan`` over scan settings as axes, the numbers of
``motionhyst scan --json`` for the same point (study/scans.py)."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.study import Study, StudyError, open_results, run_study, summarize
from motionhyst.study.export import to_table

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

STUDY = """\
scenario = "scan.toml"
outputs = ["scan", "error_rms"]
[scan]
length = 0.005
a_max = 2.0
j_max = 50.0
s_max = 1000.0
window = 0.02
[axes]
"scan.speed" = [0.05, 0.1]
"scan.compensation" = ["none", "model"]
frequency_hz = [5.0]
"""


@pytest.fixture
def study_file(tmp_path: Path) -> Path:
    shutil.copy(EXAMPLES / "scan.toml", tmp_path / "scan.toml")
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    return path


def _scan_json(*args: str) -> dict:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["scan", *args, "--json"]) == 0
    return json.loads(buf.getvalue())


def test_scan_outputs_are_those_of_the_scan_command(study_file, tmp_path):
    """Each point's MA, MSD, peak error and settling time are the numbers `motionhyst scan
    --json` prints for the same setpoint, window and compensation (identical)."""
    st = Study.from_file(study_file)
    assert st.dims == ("scan.speed", "scan.compensation", "frequency_hz", "amplitude")
    run_study(st, tmp_path / "s.zarr", workers=0)
    ds = open_results(tmp_path / "s.zarr")
    assert list(ds["scan.compensation"].values) == ["none", "model"]
    for speed in (0.05, 0.1):
        cli = _scan_json(str(study_file.parent / "scan.toml"), "--length", "0.005",
                         "--speed", str(speed), "--a-max", "2", "--j-max", "50",
                         "--s-max", "1000", "--window", "0.02", "--compensation", "none",
                         "model")
        for run in cli["results"]:
            at = ds.sel({"scan.speed": speed, "scan.compensation": run["compensation"]})
            for name in ("ma_max", "msd_max", "peak_error", "settling_time_s"):
                got = float(at[name].values.item())
                want = run[name]
                assert (np.isnan(got) if want is None else got == want), (speed, name)
    # the model feedforward (4 % off) cuts the moving average 25-fold here
    none = ds["ma_max"].sel({"scan.compensation": "none"}).values
    model = ds["ma_max"].sel({"scan.compensation": "model"}).values
    assert np.all(model < none / 10)
    # the sine's outputs beside the scan's: one loop per point serves both
    assert np.all(ds["error_rms"].values > 0)


def test_table_and_summary_name_the_compensation(study_file, tmp_path):
    study_file.write_text(STUDY.replace('"scan.speed" = [0.05, 0.1]', '"scan.speed" = [0.05]')
                          .replace('outputs = ["scan", "error_rms"]', 'outputs = ["scan"]'))
    run_study(Study.from_file(study_file), tmp_path / "s.zarr", workers=0)
    ds = open_results(tmp_path / "s.zarr")
    lines = to_table(ds).splitlines()
    # frequency_hz is the file's axis; no amplitude (the scenario's [reference]) is carried
    assert lines[0].startswith("scan.speed,scan.compensation,frequency_hz,ma_max,")
    assert [ln.split(",")[1] for ln in lines[1:]] == ["none", "model"]
    s = summarize(ds)
    assert s.worst["ma_max"]["at"]["scan.compensation"] == "none"
    assert "scan.compensation = none" in str(s)


@pytest.mark.parametrize(("change", "message"), [
    (("length = 0.005\n", ""), r"\[scan\] 'length': missing"),
    (('outputs = ["scan", "error_rms"]', 'outputs = ["error_rms"]'),
     "add it to 'outputs'"),
    (('"scan.speed" = [0.05, 0.1]', '"scan.rate" = [1e3]'), "'scan.rate': not a scan axis"),
    (('["none", "model"]', '["none", "learned"]'), "distinct compensations among"),
    (('"scan.speed" = [0.05, 0.1]', '"scan.speed" = [-0.05]'),
     r"'scan.speed': give a number > 0"),
    (("window = 0.02", "window = 0.02\nwindows = 3"), r"\[scan\] 'windows': unknown setting"),
    (("window = 0.02", 'window = 0.02\nspeed = 0.1'),
     "also the axis \"scan.speed\""),
])
def test_bad_scan_settings_are_one_line_naming_the_key(study_file, change, message):
    study_file.write_text(STUDY.replace(*change))
    with pytest.raises(StudyError, match=message):
        Study.from_file(study_file)


def test_the_example_scan_study_reads():
    st = Study.from_file(EXAMPLES / "scan_study.toml")
    assert st.outputs == ["scan"] and st.n_points == 24
    assert st.scan_at(st.point(0))["speed"] == pytest.approx(0.02)
    assert st.scan_at(st.point(0))["compensation"] == "none"


def test_summary_says_where_the_link_dominates(tmp_path):
    """|E - 1| > 1: the error the link adds exceeds the linear loop's. For Table I at 10 mm
    the link dominates up to 7 Hz of these frequencies and not from 10 Hz on (the paper's
    low-frequency crossover, eq. 21: 7.6 Hz); the summary counts the points and gives the
    highest frequency per amplitude."""
    import tomllib

    from motionhyst.scenario import default_scenario_path

    base = tomllib.loads(default_scenario_path().read_text())
    st = Study.from_dict({"outputs": ["mismatch"],
                          "axes": {"amplitude": [0.01, 0.001],
                                   "frequency_hz": [2.0, 5.0, 7.0, 10.0, 15.0, 30.0]}},
                         scenario=base)
    run_study(st, tmp_path / "s.zarr", workers=0)
    ds = open_results(tmp_path / "s.zarr")
    d = summarize(ds).dominates["mismatch"]
    over = np.abs(ds["mismatch"].values - 1) > 1
    assert d["points"] == int(over.sum()) and d["of"] == 12 and d["never"] == 0
    per_amplitude = sorted(ds["frequency_hz"].values[row].max() for row in over)
    assert ds["frequency_hz"].values[over[0]].max() == 7.0  # 10 mm
    assert [d["crossover_hz"]["min"], d["crossover_hz"]["max"]] == per_amplitude
    assert d["top"] == 30.0
    assert "the link dominates (|mismatch - 1| > 1" in str(summarize(ds))


def test_figure_of_a_study_of_scans_is_over_its_scan_axis():
    """A study of scans (one frequency) is drawn over its first scan axis, a line per
    compensation, each the worst case over the other axes."""
    import xarray as xr

    from motionhyst.study.summary import plot_band

    ma = np.array([[[1e-8], [1e-9]], [[2e-8], [3e-9]], [[4e-8], [2e-9]]])  # speed x comp x f
    ds = xr.Dataset({"ma_max": (("scan.speed", "scan.compensation", "frequency_hz"), ma),
                     "status": (("scan.speed", "scan.compensation", "frequency_hz"),
                                np.ones(ma.shape, np.int8))},
                    coords={"scan.speed": [0.05, 0.1, 0.2],
                            "scan.compensation": ["none", "model"], "frequency_hz": [5.0]},
                    attrs={"fields": json.dumps({"ma_max": "real"})})
    ax = plot_band(ds).axes[0]
    assert ax.get_xlabel() == "scan.speed [m/s]"
    assert [ln.get_label() for ln in ax.lines] == ["none", "model"]
    np.testing.assert_array_equal(ax.lines[1].get_ydata(), ma[:, 1, 0])


def test_the_local_pool_computes_scans_as_this_process(study_file, tmp_path):
    study_file.write_text(STUDY.replace('"scan.speed" = [0.05, 0.1]', '"scan.speed" = [0.05]')
                          .replace('outputs = ["scan", "error_rms"]', 'outputs = ["scan"]'))
    run_study(Study.from_file(study_file), tmp_path / "here.zarr", workers=0)
    run_study(Study.from_file(study_file), tmp_path / "pool.zarr", workers=2)
    here, pool = open_results(tmp_path / "here.zarr"), open_results(tmp_path / "pool.zarr")
    for name in ("ma_max", "msd_max", "peak_error", "status"):
        np.testing.assert_array_equal(here[name].values, pool[name].values, err_msg=name)
    assert list(pool["scan.compensation"].values) == ["none", "model"]


def test_a_study_of_scans_alone_has_no_reference_dimensions(study_file):
    """The scan follows its setpoint, not the reference's sine: a study whose only output is
    ``scan`` carries no amplitude or frequency of the scenario's [reference] (dimensions of
    one value); one that also asks a sine's output keeps them."""
    study_file.write_text(STUDY.replace('outputs = ["scan", "error_rms"]', 'outputs = ["scan"]')
                          .replace("frequency_hz = [5.0]\n", ""))
    st = Study.from_file(study_file)
    assert st.dims == ("scan.speed", "scan.compensation") and st.n_points == 4
    study_file.write_text(STUDY.replace("frequency_hz = [5.0]\n", ""))
    assert Study.from_file(study_file).dims == ("scan.speed", "scan.compensation",
                                                "amplitude", "frequency_hz")


def test_a_point_with_the_model_alone_simulates_one_run(study_file, monkeypatch):
    """A point graded with the model feedforward alone runs the loop once (the uncompensated
    run and the loop without its link are not simulated), with the numbers of the scan that
    also runs them."""
    from motionhyst.scan import scanning
    from motionhyst.study.engine import Evaluator

    study_file.write_text(STUDY.replace('outputs = ["scan", "error_rms"]', 'outputs = ["scan"]')
                          .replace('["none", "model"]', '["model"]'))
    st = Study.from_file(study_file)
    calls = []
    simulate = scanning.simulate
    monkeypatch.setattr(scanning, "simulate", lambda *a, **k: calls.append(1) or simulate(*a, **k))
    got = Evaluator(st).batch([0])
    assert st.point(0)["scan.speed"] == 0.05 and got.status[0] == 1
    assert len(calls) == 1
    cli = _scan_json(str(study_file.parent / "scan.toml"), "--length", "0.005", "--speed",
                     "0.05", "--a-max", "2", "--j-max", "50", "--s-max", "1000", "--window",
                     "0.02", "--compensation", "none", "model")
    assert len(calls) == 3            # the command: without compensation, with the model
    model = next(r for r in cli["results"] if r["compensation"] == "model")
    for name in ("ma_max", "msd_max", "peak_error"):
        assert got.values[name][0] == model[name], name


def test_a_dear_point_is_timed_on_two_points_before_a_run(study_file, monkeypatch):
    """The time a point takes sets a run's batches and its work budget: a dear point (a long
    scan's) is timed on its loop's first point and the next after the warm-up, not on six
    (seconds of work thrown away), a cheap one on six (each run's points past its first timed
    twice, the smaller time kept: four more); the loop's construction, paid by its first
    point, counts once a loop either way (a fake clock: each point costs a stated time, its
    loop's first point 10 ms more)."""
    from types import SimpleNamespace

    from motionhyst.study import engine

    clock = SimpleNamespace(now=0.0)
    computed = []

    def fake_outputs(self, loop, values):
        clock.now += cost
        computed.append(values)
        return {name: 0.0 for name in self.fields}

    loop_at = engine.Evaluator._loop_at

    def fake_loop_at(self, values):
        before = self._key
        loop = loop_at(self, values)
        clock.now += 0.01 if self._key != before else 0.0      # the loop built anew
        return loop

    monkeypatch.setattr(engine.Evaluator, "_outputs", fake_outputs)
    monkeypatch.setattr(engine.Evaluator, "_loop_at", fake_loop_at)
    monkeypatch.setattr(engine, "time", SimpleNamespace(thread_time=lambda: clock.now,
                                                        perf_counter=lambda: clock.now))
    st = Study.from_file(study_file)              # 2 speeds x 2 compensations x 1 frequency
    assert st.n_points == 4
    loops = 1                                      # no scenario key varies: one loop
    for cost, points in ((0.2, 3), (2e-4, 11)):
        computed.clear()
        per = engine.seconds_per_point(st, 6, cpu=True)
        assert len(computed) == points              # the warm-up's, then the timed ones
        assert per == pytest.approx(cost + 0.01 * loops / st.n_points, rel=1e-9)


def test_a_scan_that_never_settles_is_the_worst_settling_time():
    """No settling time at a computed point is a scan whose error never settles: the summary
    counts those points as the worst case and names the first, rather than giving the
    longest of the others as the worst; a failed point is not counted."""
    import xarray as xr

    settle = np.array([[np.nan, 0.01], [0.02, np.nan], [np.nan, 0.0]])        # speed x comp
    status = np.array([[1, 1], [1, 1], [2, 1]], np.int8)                       # one failed
    ds = xr.Dataset({"settling_time_s": (("scan.speed", "scan.compensation"), settle),
                     "status": (("scan.speed", "scan.compensation"), status)},
                    coords={"scan.speed": [0.05, 0.1, 0.2], "scan.compensation": ["none", "model"]},
                    attrs={"fields": json.dumps({"settling_time_s": "real"})})
    s = summarize(ds)
    assert s.never["settling_time_s"] == {
        "points": 2, "of": 5, "at": {"scan.speed": 0.05, "scan.compensation": "none"}}
    assert s.worst["settling_time_s"]["value"] == 0.02
    text = str(s)
    assert ("settling_time_s: 2 of 5 computed points never settle within the band (the worst "
            "case; the first at scan.speed = 0.05, scan.compensation = none)") in text
    assert "worst |settling_time_s| of the others = 0.02" in text
    assert s.to_dict()["never"] == s.never
