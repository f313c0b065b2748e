"""Studies: the study file, the points, the store, resume after SIGKILL, the local pool."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
import zarr

from motionhyst.analysis.quasilinear import loop_mismatch
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.cli import main
from motionhyst.scenario import Scenario, default_scenario_path
from motionhyst.study import Study, StudyError, open_results, run_study, summarize
from motionhyst.study import store as store_module
from motionhyst.study.engine import Evaluator, split
from motionhyst.study.export import to_netcdf_bytes, to_table
from motionhyst.study.runner import run_lock
from motionhyst.study.store import FAILED, OK, REASONS, StudyStore

BASE = tomllib.loads(default_scenario_path().read_text())

STUDY_TOML = """\
scenario = "paper.toml"
outputs = ["e1", "mismatch", "error_rms", "E"]
[axes]
amplitude = [0.001, 0.01]
frequency_hz = { geomspace = [2.0, 50.0, 4] }
"hysteresis.fc" = [0.03, 0.05]
[samples]
n = 2
seed = 7
"hysteresis.k" = { lognormal = [20.0, 0.1] }
"""


@pytest.fixture
def study_file(tmp_path: Path) -> Path:
    shutil.copy(default_scenario_path(), tmp_path / "paper.toml")
    path = tmp_path / "study.toml"
    path.write_text(STUDY_TOML)
    return path


def _values(ds) -> dict[str, np.ndarray]:
    return {name: ds[name].values for name in ds.data_vars}


def test_study_file_points_and_samples(study_file):
    st = Study.from_file(study_file)
    assert st.dims == ("amplitude", "frequency_hz", "hysteresis.fc", "sample")
    assert st.shape == (2, 4, 2, 2) and st.n_points == 32
    np.testing.assert_allclose(st.axes["frequency_hz"], [2.0, 2.0 * 25 ** (1 / 3),
                                                         2.0 * 25 ** (2 / 3), 50.0])
    # the samples come from the seed, the same every time, and change with it
    again = Study.from_file(study_file)
    np.testing.assert_array_equal(st.sample_values, again.sample_values)
    other = Study.from_dict({**tomllib.loads(STUDY_TOML),
                             "samples": {"n": 2, "seed": 8,
                                         "hysteresis.k": {"lognormal": [20.0, 0.1]}}},
                            base_dir=study_file.parent)
    assert not np.array_equal(st.sample_values, other.sample_values)
    p = st.point(31)
    assert p["amplitude"] == 0.01 and p["frequency_hz"] == 50.0 and p["hysteresis.fc"] == 0.05
    assert p["hysteresis.k"] == st.sample_values[1, 0]
    # computed with the reference axes fastest, every point once
    order = st.order()
    assert sorted(order.tolist()) == list(range(32))
    assert [st.point(i)["hysteresis.fc"] for i in order[:8]] == [0.03] * 8


def test_distributions_have_their_stated_parameters():
    data = {"outputs": ["E"], "axes": {"frequency_hz": [5.0]},
            "samples": {"n": 4000, "seed": 0, "hysteresis.k": {"lognormal": [20.0, 0.1]},
                        "hysteresis.fc": {"uniform": [0.03, 0.05]},
                        "stage.m2": {"normal": [17.5, 0.2]}}}
    s = Study.from_dict(data, scenario=BASE).sample_values
    # 4000 draws: the median within 4 standard errors (0.1 * 1.25 / sqrt(4000) relative)
    assert abs(np.median(s[:, 0]) / 20.0 - 1) < 4 * 0.1 * 1.25 / np.sqrt(4000)
    assert abs(np.std(np.log(s[:, 0])) - 0.1) < 0.005
    assert s[:, 1].min() >= 0.03 and s[:, 1].max() <= 0.05
    assert abs(np.mean(s[:, 2]) - 17.5) < 4 * 0.2 / np.sqrt(4000)


def test_points_are_the_library_functions(tmp_path):
    """A study's point is periodic_steady_state and loop_mismatch of the scenario with the
    point's keys set."""
    st = Study.from_dict({"outputs": ["e1", "mismatch", "error_rms", "harmonics", "E"],
                          "axes": {"frequency_hz": [3.0, 12.0], "stage.m2": [17.5, 30.0]}},
                         scenario=BASE)
    run_study(st, tmp_path / "s.zarr", workers=0)
    ds = open_results(tmp_path / "s.zarr")
    assert ds["e1"].dtype == complex and ds["status"].values.tolist() == [[[OK]] * 2] * 2
    assert ds.attrs["seed"] == 0 and ds.attrs["version"]
    for m2 in (17.5, 30.0):
        data = json.loads(json.dumps(BASE))
        data["stage"]["m2"] = m2
        loop = Scenario.from_dict(data).loop()
        for f in (3.0, 12.0):
            ss = periodic_steady_state(loop, 0.01, f)
            at = ds.sel(frequency_hz=f, **{"stage.m2": m2}, amplitude=0.01)
            assert complex(at["e1"]) == complex(ss.e[1])
            assert complex(at["e3"]) == complex(ss.e[3])
            assert complex(at["mismatch"]) == ss.mismatch
            assert float(at["error_rms"]) == ss.error_rms
            assert complex(at["E"]) == complex(loop_mismatch(loop, f, 0.01)[0])


def test_margins_are_those_of_the_points_loop():
    """The margins output is loop_margins of the loop at the point's keys, the same at every
    amplitude and frequency of that loop."""
    from motionhyst.analysis.margins import loop_margins

    st = Study.from_dict({"outputs": ["margins"],
                          "axes": {"frequency_hz": [3.0, 12.0], "controller.K": [4e6, 6.2e6]}},
                         scenario=BASE)
    b = Evaluator(st).batch(st.order())
    assert np.all(b.status == OK)
    for j, i in enumerate(b.indices):
        values = st.point(int(i))
        data = json.loads(json.dumps(BASE))
        data["controller"]["K"] = values["controller.K"]
        loop = Scenario.from_dict(data).loop()
        m = loop_margins(loop.controller, loop.P2)
        assert b.values["gain_margin_db"][j] == m.gain_margin_db
        assert b.values["phase_margin_deg"][j] == m.phase_margin_deg
        assert b.values["modulus_margin"][j] == m.modulus_margin
        assert b.values["bandwidth_hz"][j] == m.bandwidth_hz
    # Table I's loop: the paper's margins (eq. 23's controller)
    k = list(st.axes["controller.K"]).index(6.2e6)
    at = [j for j, i in enumerate(b.indices) if st.point(int(i))["controller.K"] == 6.2e6]
    assert k == 1 and b.values["phase_margin_deg"][at[0]] == pytest.approx(24.83, abs=0.01)


def test_samples_from_an_identification(tmp_path, study_file):
    """[samples] from_identification (identify --json) draws the link's k and fc lognormal
    around the estimates with the relative standard errors; the command's option does the
    same for a study without [samples] (100 samples, seed 0); a file's own key wins."""
    fit = {"model": "maxwell-slip", "elements": [{"k": 21.0, "k_std": 0.42, "fc": 0.04,
                                                  "fc_std": 0.002}]}
    (tmp_path / "fit.json").write_text(json.dumps(fit))
    study_file.write_text(STUDY_TOML.replace('"hysteresis.k" = { lognormal = [20.0, 0.1] }',
                                             'from_identification = "fit.json"')
                          .replace('"hysteresis.fc" = [0.03, 0.05]', "")
                          .replace("n = 2", "n = 4000"))
    st = Study.from_file(study_file)
    assert st.samples == {"hysteresis.k": ("lognormal", 21.0, 0.02),
                          "hysteresis.fc": ("lognormal", 0.04, 0.05)}
    k, fc = st.sample_values.T
    assert np.median(k) == pytest.approx(21.0, rel=3 * 1.25 * 0.02 / np.sqrt(4000))
    assert np.std(np.log(fc)) == pytest.approx(0.05, rel=0.05)
    bare = tmp_path / "bare.toml"
    bare.write_text('scenario = "paper.toml"\noutputs = ["e1"]\n')
    st = Study.from_file(bare, from_identification=tmp_path / "fit.json")
    assert (st.n_samples, st.seed) == (100, 0) and st.samples["hysteresis.fc"][1] == 0.04
    fit["elements"].append(fit["elements"][0])
    (tmp_path / "two.json").write_text(json.dumps(fit))
    with pytest.raises(StudyError, match="2 Jenkins elements"):
        Study.from_file(bare, from_identification=tmp_path / "two.json")


def test_a_study_whose_every_point_fails_is_a_failure(tmp_path, capsys):
    """Every point failed (the loop unstable at each): the store records why, but the command
    exits non-zero with one line and exports no table made of failures."""
    study = tmp_path / "st.toml"
    study.write_text(f'scenario = "{default_scenario_path().as_posix()}"\n'
                     f'outputs = ["e1"]\n[axes]\nfrequency_hz = [5.0, 10.0]\n'
                     f'"controller.K" = [1e12]\n')
    table = tmp_path / "t.csv"
    code = main(["study", str(study), "--out", str(tmp_path / "s.zarr"), "--workers", "0",
                 "--table", str(table)])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "every one of its 2 points failed" in err and "the first: " in err
    assert not table.exists()
    assert np.all(open_results(tmp_path / "s.zarr")["status"].values == FAILED)


def test_a_point_that_fails_is_counted_and_the_study_goes_on(tmp_path):
    st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0],
                                                      "controller.K": [6.2e6, 1e12]}},
                         scenario=BASE)
    rep = run_study(st, tmp_path / "s.zarr", workers=0)
    assert (rep.points, rep.computed, rep.failed) == (4, 4, 2)
    ds = open_results(tmp_path / "s.zarr")
    status = ds["status"].sel({"controller.K": 1e12}).values
    assert np.all(status == FAILED)
    assert np.all(np.isnan(ds["e1"].sel({"controller.K": 1e12}).values))
    assert np.all(ds["status"].sel({"controller.K": 6.2e6}).values == OK)
    assert summarize(ds).failed == 2
    # the reason is recorded per point, with the message of the first
    assert np.all(ds["reason"].sel({"controller.K": 1e12}).values == 1)
    assert np.all(ds["reason"].sel({"controller.K": 6.2e6}).values == 0)
    [(why, f)] = summarize(ds).failures.items()
    assert why == REASONS[1] and f["points"] == 2
    assert "controller.K = 1e+12" in f["example"] and "does not stabilise" in f["example"]


def test_a_point_that_does_not_converge_says_so():
    """A link as stiff as the stage's spring: the fixed point does not converge (reason 2)."""
    st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0],
                                                      "hysteresis.k": [20.0, 1e8],
                                                      "hysteresis.fc": [100.0]}},
                         scenario=BASE)
    b = Evaluator(st).batch([0, 1])
    assert b.status.tolist() == [OK, FAILED] and b.reason.tolist() == [0, 2]
    assert "hysteresis.k = 1e+08" in b.failures[2] and "did not converge" in b.failures[2]


def test_store_chunks_follow_the_computing_order(monkeypatch):
    """Each chunk of the store is one contiguous run of the points in the order they are
    computed, so a run holds one or two chunks open whatever the size of the study."""
    monkeypatch.setattr(store_module, "CHUNK_POINTS", 12)
    st = Study.from_dict({"outputs": ["e1"],
                          "axes": {"frequency_hz": [2.0, 5.0, 9.0], "hysteresis.fc": [0.03, 0.05],
                                   "stage.m2": [17.5, 20.0, 30.0]},
                          "samples": {"n": 5, "seed": 0,
                                      "hysteresis.k": {"lognormal": [20.0, 0.1]}}},
                         scenario=BASE)
    chunks = store_module._chunks(st)
    assert np.prod(chunks) <= 12
    idx = np.unravel_index(st.order(), st.shape)
    grid = [int(np.ceil(n / c)) for n, c in zip(st.shape, chunks, strict=True)]
    keys = np.ravel_multi_index(tuple(i // c for i, c in zip(idx, chunks, strict=True)), grid)
    runs = keys[np.r_[True, keys[1:] != keys[:-1]]]
    assert len(runs) == len(np.unique(keys)) == np.prod(grid)


def test_chunk_writer_holds_few_chunks_and_writes_what_direct_writes_write(tmp_path,
                                                                          monkeypatch):
    """Batches that straddle chunks, in the computing order: the writer holds at most two
    chunks, and the store ends as with one direct write a batch (the first batch is on disk
    at once, a completed chunk when it completes)."""
    monkeypatch.setattr(store_module, "CHUNK_POINTS", 8)
    st = Study.from_dict({"outputs": ["e1", "error_rms"],
                          "axes": {"frequency_hz": [2.0, 5.0, 9.0, 20.0],
                                   "hysteresis.fc": [0.03, 0.04, 0.05]},
                          "samples": {"n": 3, "seed": 0,
                                      "hysteresis.k": {"lognormal": [20.0, 0.1]}}},
                         scenario=BASE)
    ev = Evaluator(st)
    batches = [ev.batch(b) for b in split(st.order(), 5)]
    direct = StudyStore.create(tmp_path / "direct.zarr", st)
    for b in batches:
        direct.write(b.indices, b.status, b.values, b.reason)
    gathered = StudyStore.create(tmp_path / "gathered.zarr", st)
    with gathered.writer(flush_seconds=3600) as w:
        for j, b in enumerate(batches):
            w.add(b.indices, b.status, b.values, b.reason, b.failures)
            if j == 0:
                assert np.count_nonzero(gathered.status() == OK) == 5
        assert w.most_open <= 2
    a, b = open_results(tmp_path / "direct.zarr"), open_results(tmp_path / "gathered.zarr")
    for name in ("e1", "error_rms", "status", "reason"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert np.all(b["status"].values == OK)


def test_local_pool_gives_the_numbers_of_this_process(tmp_path, study_file):
    """Two worker processes, batches of 3 points, equal to one process bit for bit."""
    st = Study.from_file(study_file)
    t0 = time.thread_time()
    alone = run_study(st, tmp_path / "one.zarr", workers=0)
    # the points' work is part of this thread's CPU time (which times points first, makes
    # the loops and writes the store)
    assert 0 < alone.cpu_seconds < time.thread_time() - t0
    rep = run_study(st, tmp_path / "pool.zarr", workers=2, batch=3)
    assert (rep.points, rep.computed, rep.failed) == (32, 32, 0)
    assert rep.cpu_seconds > 0 and rep.to_dict()["cpu_seconds"] == rep.cpu_seconds
    one, pool = open_results(tmp_path / "one.zarr"), open_results(tmp_path / "pool.zarr")
    for name, v in _values(one).items():
        np.testing.assert_array_equal(v, pool[name].values, err_msg=name)
    # run again: nothing missing, nothing computed
    assert run_study(st, tmp_path / "pool.zarr", workers=2).computed == 0
    s = summarize(one)
    assert s.computed == 32 and set(s.band) == {"e1", "mismatch", "error_rms", "E"}
    lo, mid, hi = s.band["error_rms"].values()
    assert lo <= mid <= hi
    wide = dict(s.widest["E"])
    at = wide.pop("at")
    mags = np.abs(one["E"].sel(at).values)
    assert list(wide.values()) == pytest.approx(np.percentile(mags, [5, 50, 95]))
    worst = s.worst["error_rms"]
    assert worst["value"] == pytest.approx(float(np.nanmax(one["error_rms"].values)))


def test_exports(tmp_path, study_file):
    st = Study.from_file(study_file)
    run_study(st, tmp_path / "s.zarr", workers=0)
    ds = open_results(tmp_path / "s.zarr")
    lines = to_table(ds).splitlines()
    assert lines[0] == ("amplitude,frequency_hz,hysteresis.fc,sample,hysteresis.k,e1_abs,e1_deg,"
                        "mismatch_abs,mismatch_deg,error_rms,E_abs,E_deg,status")
    assert len(lines) == 33
    row = dict(zip(lines[0].split(","), lines[-1].split(","), strict=True))
    at = ds.isel(amplitude=-1, frequency_hz=-1, sample=-1).sel({"hysteresis.fc": 0.05})
    assert float(row["e1_abs"]) == abs(complex(at["e1"]))
    assert float(row["hysteresis.k"]) == float(at["hysteresis.k"])
    import xarray as xr

    (tmp_path / "s.nc").write_bytes(to_netcdf_bytes(ds))
    nc = xr.open_dataset(tmp_path / "s.nc", engine="scipy")
    np.testing.assert_array_equal(nc["e1_real"].values, ds["e1"].values.real)
    np.testing.assert_array_equal(nc["e1_imag"].values, ds["e1"].values.imag)


@pytest.mark.parametrize(("text", "message"), [
    ('outputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n', "'scenario'"),
    ('scenario = "paper.toml"\noutputs = ["e7"]\n', "unknown output 'e7'"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\nfrequency_hz = { geomspace = [0.0, 1.0,'
     ' 3] }\n', "'frequency_hz': geomspace needs a, b > 0"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\n"hysteresis.kk" = [1.0]\n',
     "[axes] 'hysteresis.kk': not a key of the scenario"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\n"plant.k" = [1.0]\n',
     "'plant.k': not a key of the scenario"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[samples]\nn = 5\nseed = 0\n'
     '"hysteresis.k" = { gamma = [1.0, 2.0] }\n', "[samples] 'hysteresis.k': give one of"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[samples]\nn = 5\n'
     '"hysteresis.k" = { normal = [1.0, 2.0] }\n', "[samples] 'seed'"),
    ('scenario = "missing.toml"\noutputs = ["e1"]\n', "missing.toml: cannot read"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\n"hysteresis.k" = [-1.0, 20.0]\n',
     "[axes] 'hysteresis.k' = -1: refused by the scenario: [hysteresis] k: Input should be "
     "greater than 0"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\namplitude = [0.01, 0.01]\n',
     "'amplitude': values repeat"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\nextra = 1\n', "unknown key 'extra'"),
    ('scenario = "paper.toml"\noutputs = ["e1"\n', "study.toml: TOML syntax error: "),
    ('scenario = "latin1.toml"\noutputs = ["e1"]\n',
     "'scenario': latin1.toml: not a text file (TOML must be UTF-8)"),
    ('scenario = "."\noutputs = ["e1"]\n', "cannot read (it is a folder)"),
    ('scenario = "paper.toml"\noutputs = ["e1"]\n[samples]\nfrom_identification = "fit.json"\n',
     "from_identification fit.json: not a text file (JSON must be UTF-8)"),
])
def test_bad_study_files_are_one_line_naming_the_key(tmp_path, study_file, capsys, monkeypatch,
                                                     text, message):
    (tmp_path / "latin1.toml").write_bytes(b"# r\xe9glage\n")
    (tmp_path / "fit.json").write_bytes(b"\xff\xfe{}")
    study_file.write_text(text)
    monkeypatch.chdir(tmp_path)                         # the files named relative, as given
    assert main(["study", "study.toml", "--out", str(tmp_path / "s.zarr")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "s.zarr").exists()


@pytest.mark.parametrize("address, message", [
    ("tcp://256.1.1.1:8786", "'256.1.1.1' is not an IP address"),
    ("tcp://127.0.0.1:99999", "the port must be from 1 to 65535"),
    ("tcp://", "names no host"),
])
def test_an_address_that_names_no_scheduler_is_refused_before_connecting(tmp_path, study_file,
                                                                          capsys, address,
                                                                          message):
    assert main(["study", str(study_file), "--out", str(tmp_path / "s.zarr"),
                 "--scheduler", address]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "--scheduler" in err, err
    assert not (tmp_path / "s.zarr").exists()


def test_store_of_another_study_needs_force(tmp_path, study_file, capsys):
    out = tmp_path / "s.zarr"
    assert main(["study", str(study_file), "--out", str(out), "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    study_file.write_text(STUDY_TOML.replace("seed = 7", "seed = 8"))
    assert main(["study", str(study_file), "--out", str(out), "--workers", "0"]) == 2
    assert "holds another study" in capsys.readouterr().err
    assert main(["study", str(study_file), "--out", str(out), "--workers", "0", "--json",
                 "--force"]) == 0
    assert json.loads(capsys.readouterr().out)["computed"] == 32
    with run_lock(out):                                  # another run writing this store
        assert main(["study", str(study_file), "--out", str(out), "--workers", "0"]) == 2
    assert "another run is writing to this store" in capsys.readouterr().err
    (tmp_path / "folder").mkdir()
    (tmp_path / "folder" / "keep.txt").write_text("mine")
    assert main(["study", str(study_file), "--out", str(tmp_path / "folder"), "--force"]) == 2
    assert "not a study's store" in capsys.readouterr().err
    assert (tmp_path / "folder" / "keep.txt").read_text() == "mine"


def test_resume_after_sigkill_computes_only_what_is_missing(tmp_path, study_file):
    """The command killed with SIGKILL mid-study; the same command computes the rest, and the
    results are those of one uninterrupted run."""
    study_file.write_text(STUDY_TOML.replace("n = 2", "n = 24")
                          .replace('outputs = ["e1", "mismatch", "error_rms", "E"]',
                                   'outputs = ["e1", "error_peak"]'))
    out = tmp_path / "s.zarr"
    cmd = [sys.executable, "-m", "motionhyst.cli", "study", str(study_file), "--out", str(out),
           "--workers", "0", "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    done = 0
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                done = int(np.count_nonzero(zarr.open_array(out / "status", mode="r")[...] == OK))
            except (OSError, ValueError, KeyError):
                done = 0
            if done:
                break
            time.sleep(0.005)
        assert proc.poll() is None, proc.communicate()[1].decode()
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    before = open_results(out)["status"].values
    n_done = int(np.count_nonzero(before == OK))
    assert 0 < n_done < 384
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout)
    assert report["points"] == 384 and report["failed"] == 0
    assert report["computed"] == 384 - n_done
    resumed = open_results(out)
    run_study(Study.from_file(study_file), tmp_path / "whole.zarr", workers=0)
    whole = open_results(tmp_path / "whole.zarr")
    for name, v in _values(whole).items():
        np.testing.assert_array_equal(v, resumed[name].values, err_msg=name)


def test_ctrl_c_stops_the_command_and_its_workers(tmp_path, study_file):
    """SIGINT to the process group (Ctrl-C in a terminal): exit 130 with one line, the local
    workers gone with the command, the store resumable.

    The study is long enough (7680 points, about 5 s of CPU) that it cannot finish between
    its first results and the signal, even on a loaded machine (with 384 points it once did:
    exit 0; the engine has since lost the time it spent outside the points). A Ctrl-C that
    lands inside an import or a compilation is still 130 (cli.main looks for the interrupt in
    the exception's context)."""
    study_file.write_text(STUDY_TOML.replace("n = 2", "n = 480")
                          .replace('outputs = ["e1", "mismatch", "error_rms", "E"]',
                                   'outputs = ["e1", "error_peak"]'))
    out = tmp_path / "s.zarr"
    cmd = [sys.executable, "-m", "motionhyst.cli", "study", str(study_file), "--out", str(out),
           "--workers", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                if np.any(zarr.open_array(out / "status", mode="r")[...] == OK):
                    break
            except (OSError, ValueError, KeyError):
                pass
            time.sleep(0.005)
        assert proc.poll() is None, proc.communicate()[1].decode()
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130
    assert err.decode().splitlines()[-1] == "motionhyst: interrupted"
    assert "Traceback" not in err.decode()
    # no process of the group is left (the workers were forked into it)
    with pytest.raises(ProcessLookupError):
        for _ in range(100):
            os.killpg(proc.pid, 0)
            time.sleep(0.05)
    res = subprocess.run([*cmd, "--json"], capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["failed"] == 0
    assert np.all(open_results(out)["status"].values == OK)


def test_cli_summary_table_and_estimate(tmp_path, study_file, capsys):
    out = tmp_path / "s.zarr"
    assert main(["study", str(study_file), "--estimate", "--json"]) == 0
    est = json.loads(capsys.readouterr().out)
    assert est["points"] == 32 and est["missing"] == 32 and est["seconds_per_point"] > 0
    assert est["cores"] == (os.cpu_count() or 1)
    assert est["load_average"] is None or est["load_average"] >= 0
    assert main(["study", str(study_file), "--out", str(out), "--workers", "0",
                 "--table", str(tmp_path / "t.csv")]) == 0
    assert "32 points: 32 computed" in capsys.readouterr().out
    assert len((tmp_path / "t.csv").read_text().splitlines()) == 33
    assert main(["study", "--summary", str(out), "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["computed"] == 32 and s["failed"] == 0
    assert s["worst"]["error_rms"]["at"]["amplitude"] == 0.01
    fig = tmp_path / "band.png"
    assert main(["study", "--summary", str(out), "--figure", str(fig)]) == 0
    capsys.readouterr()
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["study", "--summary", str(out), "--figure", str(tmp_path / "band.txt")]) == 2
    assert ".png, .pdf or .svg" in capsys.readouterr().err
    assert main(["study", "--summary", str(out), "--figure", str(fig)]) == 2   # exists
    assert "--force" in capsys.readouterr().err
    assert main(["study", "--summary", str(tmp_path)]) == 2
    assert "not a store of motionhyst study" in capsys.readouterr().err
    assert main(["study", str(study_file)]) == 2
    assert "--out" in capsys.readouterr().err


def test_the_fleet_example_runs_resumes_and_bands_the_nominal_machine(tmp_path):
    """examples/fleet_study.py (the guide's Python example), on 12 machines: every point
    computed once, nothing the second time, and the machines' 5-95 % band of |E| at 1 Hz and
    10 mm holds the nominal machine's (k_J and f_c at the distributions' medians)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "fleet_study", Path(__file__).parent.parent / "examples" / "fleet_study.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    out = example.main(tmp_path, samples=12, workers=0)
    assert (out["points"], out["computed"], out["again"], out["failed"]) == (1200, 1200, 0, 0)
    nominal = Study.from_dict({"outputs": ["E"], "axes": {"amplitude": [0.01],
                                                          "frequency_hz": [1.0]}}, scenario=BASE)
    run_study(nominal, tmp_path / "nominal.zarr", workers=0)
    e = float(abs(open_results(tmp_path / "nominal.zarr")["E"].values.ravel()[0]))
    lo, mid, hi = out["E_1Hz_10mm"]
    assert lo < e < hi and lo < mid < hi
    assert out["figure"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_example_study_is_the_papers_loop():
    st = Study.from_file(Path(__file__).parent.parent / "examples" / "study.toml")
    assert st.n_points == 2 * 50 * 100
    assert st.scenario == tomllib.loads(default_scenario_path().read_text())
    assert np.median(st.sample_values[:, 0]) == pytest.approx(20.0, rel=0.05)
    assert np.median(st.sample_values[:, 1]) == pytest.approx(0.05, rel=0.05)


def test_a_study_above_the_work_budget_is_refused_before_anything_is_written(tmp_path,
                                                                              study_file,
                                                                              capsys):
    """--max-seconds: the missing points' CPU time (measured on a few) shared by the workers;
    above it, one line with the remedy, exit 2, no store made and another study's store kept
    (even with --force); a finished store has nothing missing and passes any budget."""
    out = tmp_path / "s.zarr"
    for budget, fits in (("1e-6", False), ("3600", True)):    # --estimate says which it is
        assert main(["study", str(study_file), "--estimate", "--json", "--max-seconds",
                     budget]) == 0
        est = json.loads(capsys.readouterr().out)
        assert est["within_budget"] is fits and est["budget_seconds"] == float(budget)
    assert est["memory_bytes"] > 50e6                        # the libraries and kernels held
    store = ["study", str(study_file), "--out", str(out)]
    args = [*store, "--workers", "2"]
    assert main([*args, "--max-seconds", "1e-6"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a study of 32 points (" in err[0] and "on 2 workers" in err[0]
    assert "above the work budget" in err[0] and "--max-seconds" in err[0]
    assert not out.exists()
    assert main([*store, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    assert main([*args, "--max-seconds", "1e-6"]) == 0       # nothing missing: nothing to refuse
    before = sorted(p.relative_to(out) for p in out.rglob("*"))
    study_file.write_text(STUDY_TOML.replace("seed = 7", "seed = 8"))
    assert main([*args, "--max-seconds", "1e-6", "--force"]) == 2
    assert "above the work budget" in capsys.readouterr().err
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == before
    kept = open_results(out)
    assert kept.attrs["seed"] == 7 and (kept["status"].values == OK).all()


def test_estimate_and_refusal_say_the_load_they_were_measured_under(study_file, monkeypatch,
                                                                    capsys, tmp_path):
    """A point's CPU time reads 3-4 times more on a loaded machine: the estimate and the
    budget's refusal say so when the load average exceeds the cores, and not otherwise."""
    from motionhyst.study import runner

    monkeypatch.setattr(runner, "machine_load", lambda: (9.3, 2))
    assert main(["study", str(study_file), "--estimate"]) == 0
    out = capsys.readouterr().out
    assert "measured under load    load average 9.3 on 2 cores: a point's CPU time," in out
    assert main(["study", str(study_file), "--out", str(tmp_path / "s.zarr"),
                 "--max-seconds", "1e-9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "measured under load average 9.3 on 2 cores" in err, err
    assert not (tmp_path / "s.zarr").exists()
    monkeypatch.setattr(runner, "machine_load", lambda: (1.5, 2))
    assert main(["study", str(study_file), "--estimate"]) == 0
    assert "under load" not in capsys.readouterr().out


@pytest.mark.parametrize("replacing", [False, True], ids=["new-store", "force-over-another"])
def test_a_study_killed_while_it_writes_leaves_no_temporary_file(tmp_path, study_file,
                                                                 replacing):
    """A real ``motionhyst study`` killed with SIGKILL while it writes its store (new, or
    built with --force over another study's store and swapped into its place): after the next
    command in the folder no temporary file of either outlives them (no ``.part``,
    ``.partial`` or ``.motionhyst-PID-`` name anywhere, in the store either), the user's
    files are byte-identical and the store is whole (resumed to the end)."""
    from file_trees import snapshot as files

    study_file.write_text(STUDY_TOML.replace("n = 2", "n = 24")
                          .replace('outputs = ["e1", "mismatch", "error_rms", "E"]',
                                   'outputs = ["e1", "error_peak"]'))
    (tmp_path / "notes.txt").write_text("mine\n")
    out = tmp_path / "s.zarr"
    if replacing:  # another study's store, replaced with --force: built beside it first
        other = tmp_path / "other.toml"
        other.write_text(STUDY_TOML)
        run_study(Study.from_file(other), out, workers=0)
    mine = {n: (tmp_path / n).read_bytes() for n in ("paper.toml", "study.toml", "notes.txt")}
    cmd = [sys.executable, "-m", "motionhyst.cli", "study", str(study_file), "--out", str(out),
           "--workers", "0", "--json", *(["--force"] if replacing else [])]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                status = zarr.open_array(out / "status", mode="r")[...]
                if status.size == 384 and np.any(status == OK):  # this study's, half written
                    break
            except (OSError, ValueError, KeyError):
                pass
            time.sleep(0.002)
        assert proc.poll() is None, proc.communicate()[1].decode()
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["failed"] == 0
    left = [p for p in files(tmp_path) if any(
        w in Path(p).name for w in (".part", ".partial", ".motionhyst-"))]
    assert left == [], left
    assert {n: (tmp_path / n).read_bytes() for n in mine} == mine
    assert np.all(open_results(out)["status"].values == OK)
