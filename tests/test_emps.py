"""The EMPS benchmark: splits by periods, the metric, a generated axis identified and scored,
the command's JSON and its refusals."""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

from motionhyst.cli import main
from motionhyst.hysteresis import Coulomb
from motionhyst.identify.emps import (
    DRIVE_GAIN,
    INIT_WINDOW,
    run_emps,
    score,
    split_by_periods,
)
from motionhyst.identify.emps_reference import (
    REFERENCE_ASYMMETRIC,
    REFERENCE_MODEL,
    asymmetric_inverse_dynamics,
    reference_system,
)
from motionhyst.identify.input_output import IORecord
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

SHARED = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps"
TRUE = {"m": 95.0, "c": 200.0, "fc": 20.0, "offset": -3.2}  # offset: the benchmark's OF
PERIOD = 1000


def axis_record(n_periods: int = 4, period: int = PERIOD, noise: float = 1e-6) -> IORecord:
    """A positioning axis with Coulomb friction and a force offset, 1 kHz, as a loop moves it:
    the force of the true model's inverse dynamics along a periodic path, the position the
    true model's simulation from that force, the state set from its first samples."""
    t = np.arange(n_periods * period) / 1000.0
    w = 2 * np.pi * 1000.0 / period
    path = (0.02 * np.sin(w * t), 0.006 * np.sin(3 * w * t + 1.0))
    v = 0.02 * w * np.cos(w * t) + 0.018 * w * np.cos(3 * w * t + 1.0)
    acc = -w ** 2 * (path[0] + 9 * path[1])
    u = TRUE["m"] * acc + TRUE["c"] * v + TRUE["fc"] * np.sign(v) + TRUE["offset"]
    y = score(true_system(), IORecord(t, u, path[0] + path[1], "path"))[1]
    return IORecord(t, u, y + noise * np.random.default_rng(7).standard_normal(t.size), "axis")


def true_system(p: dict = TRUE) -> OpenLoop:
    """The mass-damper with Coulomb friction of the benchmark's parameters (offset = OF)."""
    return OpenLoop(MassDamper(p["m"], p["c"], force_offset=-p["offset"]), Coulomb(fc=p["fc"]))


def test_split_by_periods_names_and_sizes():
    rec = IORecord(np.arange(24841) * 1e-3, np.zeros(24841), np.zeros(24841), "DATA_EMPS")
    est, val = split_by_periods(rec)
    assert (est.name, val.name) == ("DATA_EMPS periods 1-2", "DATA_EMPS periods 3-4")
    assert est.t.size == 12480 and val.t[0] == pytest.approx(12.48)
    est, val = split_by_periods(rec, (3, 4))
    assert (est.name, val.name, est.t.size) == ("DATA_EMPS periods 3-4",
                                                "DATA_EMPS periods 1-2", 12361)
    assert split_by_periods(rec, (1, 1))[1].name == "DATA_EMPS periods 2-4"
    for periods, fragment in (((2, 3), "both sides"), ((1, 4), "no period is left"),
                              ((0, 1), "periods 1-4"), ((4, 5), "periods 1-4")):
        with pytest.raises(ValueError, match=fragment):
            split_by_periods(rec, periods)


def test_generated_axis_identified_and_scored():
    rec = axis_record()
    res = run_emps(rec, models=("coulomb",), period=PERIOD)
    (model,) = res.models
    p = model.parameters
    assert p["m"] == pytest.approx(TRUE["m"], rel=0.05)
    assert p["offset"] == pytest.approx(TRUE["offset"], abs=0.5)  # OF's sign: u - OF drives
    assert model.estimation["record"] == "axis periods 1-2"
    assert model.validation["record"] == "axis periods 3-4"
    # the scores are those of the model the reported parameters describe
    val = IORecord(rec.t[2 * PERIOD:], rec.u[2 * PERIOD:], rec.y[2 * PERIOD:], "v")
    again, yhat = score(true_system(p), val)
    assert model.validation["rmse_mm"] == pytest.approx(again["rmse_mm"], rel=1e-6)
    np.testing.assert_allclose(model.prediction, yhat, rtol=0, atol=1e-9)
    y_val = val.y[INIT_WINDOW:]
    assert model.validation["rmse_mm"] < 0.05 * 1e3 * np.std(y_val)
    assert model.validation["fit_percent"] > 90.0
    assert set(res.to_dict()) == {"models"}
    assert set(res.to_dict()["models"][0]) - {"warnings"} == {
        "name", "parameters", "std", "estimation", "validation", "seconds", "equivalent_offset",
        "model_parameters", "model_std"}
    # 1 um of noise on a floating axis: what the 20-sample window costs is said, nothing else
    assert all(w.startswith("the initialisation window's 20 samples") for w in model.warnings)
    assert set(model.std) == set(p)
    text = str(res)
    assert "validated on axis periods 3-4 (the test record DATA_EMPS_PULSES.mat was not" in text
    assert "dynoNet" in text and "IDIM-LS reference (published parameters)" in text
    fig = res.plot()
    assert len(fig.axes) == 2 and fig.axes[0].get_lines()[0].get_label() == "measured qm"


def test_a_maxwell_slip_model_is_fitted_as_identify_fits_it():
    """``benchmark emps --models maxwell-slip...`` fits the link as ``identify`` does: three
    elements at most, fewer where the records do not determine them.  main fitted four
    (identify_io's own default) and failed, and the whole command with it (periods 1-2 of
    DATA_EMPS: 'the records determine 3 of the model's 10 parameters'; here 2 of 10), though
    ``identify --model maxwell-slip`` fits the record with one element."""
    t = np.arange(2000) / 1000.0
    u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    y = reference_system().simulate(t, u).displacement
    res = run_emps(IORecord(t, u, y, "axis"), models=("maxwell-slip",), periods=(1, 1),
                   period=1000)
    (model,) = res.models
    own = model.model_parameters
    assert sorted(k for k in own if k.startswith(("k[", "fc["))) == ["fc[0]", "k[0]"]
    assert own["m"] == pytest.approx(REFERENCE_MODEL["m"], rel=1e-3)
    assert own["fc[0]"] == pytest.approx(REFERENCE_MODEL["fc"], rel=1e-3)
    assert model.parameters["offset"] == pytest.approx(REFERENCE_MODEL["offset"], abs=0.05)
    assert model.validation["rmse_mm"] < 0.05  # the same axis, period 2 from period 1
    assert any("fitted with 1 (the most they determine" in w for w in model.warnings)


def test_metric_is_the_benchmarks():
    """RMSE in mm over n >= 20 and fit %, from the state set on the first 20 samples: the
    reference model scored on a record it made itself (noise only) and with a 1 mm shift."""
    rec = axis_record(n_periods=2, noise=0.0)
    sys = reference_system()
    y = sys.simulate(rec.t, rec.u).displacement
    res, yhat = score(sys, IORecord(rec.t, rec.u, y + 1e-3, "self"))
    assert res["record"] == "self"
    # the 1 mm shift is taken up by the state set from the window (to 1 % of it)
    assert res["rmse_mm"] < 1e-2 and res["fit_percent"] > 99.9
    np.testing.assert_allclose(yhat[INIT_WINDOW:], y[INIT_WINDOW:] + 1e-3, atol=1e-5)
    shifted, _ = score(sys, IORecord(rec.t, rec.u, y + 1e-3 * (rec.t > 0.5), "step"))
    late = rec.t[INIT_WINDOW:] > 0.5  # 1 mm off on these samples only
    assert shifted["rmse_mm"] == pytest.approx(np.sqrt(late.mean()), rel=0.02)
    assert sys.plant.m == REFERENCE_MODEL["m"]
    assert sys.plant.force_offset == -REFERENCE_MODEL["offset"]


def test_benchmark_emps_command_refusals(tmp_path, capsys):
    def err(*args):
        assert main(["benchmark", *args]) == 2
        text = capsys.readouterr().err
        assert text.count("\n") == 1
        return text

    assert "no such folder" in err("emps", "--data", str(tmp_path / "none"))
    assert "has no DATA_EMPS.mat" in err("emps", "--data", str(tmp_path))
    (tmp_path / "DATA_EMPS.mat").write_text("t,vir,qm\n0,0,0\n")
    assert "not a MATLAB .mat file (a text file)" in err("emps", "--data", str(tmp_path))
    savemat(tmp_path / "DATA_EMPS.mat", {"t": np.arange(10.0), "qm": np.zeros(10)})
    assert "no variable 'vir'" in err("emps", "--data", str(tmp_path))
    assert "--seed applies to bouc-wen only" in err("emps", "--data", str(tmp_path),
                                                     "--seed", "1")
    assert "--periods applies to emps only" in err("bouc-wen", "--periods", "1-2")
    assert "--periods: must be A-B" in err("emps", "--periods", "x")
    assert "--models applies to emps only" in err("bouc-wen", "--models", "coulomb")
    for bad in ("bouc-wen", "jenkins-fast", "coulomb,,jenkins", "coulomb,coulomb"):
        text = err("emps", "--data", str(tmp_path / "none"), "--models", bad)
        assert "--models" in text and "no such folder" not in text  # before the data


def test_benchmark_emps_command_json(tmp_path, capsys, monkeypatch):
    """The command on a folder holding a generated DATA_EMPS.mat in the benchmark's variables
    (the controller's output in volts), its periods shortened for the test."""
    import motionhyst.identify.emps as emps

    rec = axis_record()
    savemat(tmp_path / "DATA_EMPS.mat", {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                                         "qm": rec.y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "MODELS", ("jenkins",))  # --models replaces the default list
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    assert main(["benchmark", "emps", "--data", str(tmp_path), "--models", "coulomb",
                 "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    models = json.loads(out)["models"]  # without the test record: both splits
    assert json.loads(out)["chosen"]["name"] == "coulomb"  # the only model: the rule's choice
    assert [m["validation"]["record"] for m in models] == ["DATA_EMPS periods 3-4",
                                                           "DATA_EMPS periods 1-2"]
    for model in models:
        assert model["name"] == "coulomb"
        assert model["parameters"]["m"] == pytest.approx(TRUE["m"], rel=0.05)
        assert model["parameters"]["offset"] == pytest.approx(TRUE["offset"], abs=0.5)


def test_a_failed_model_is_a_row_and_the_others_go_on(tmp_path, capsys, monkeypatch):
    """One model whose fit fails (here at once: identify_io refuses every Dahl link) is a row
    with its one-line reason, in the table and in the JSON as {"name", "error", ...}; the
    other models are identified and scored on both splits, the rule chooses among those
    that did not fail, and the command ends with one line on stderr and exit 2.  main ended
    the whole command at the first failure and printed no row."""
    import motionhyst.identify.emps as emps
    from motionhyst.identify.io_checks import FitFailed

    real = emps.identify_io

    def identify_io(records, link, **kwargs):
        if link == "dahl":
            raise FitFailed("the fit failed: its prediction is not finite")
        return real(records, link, **kwargs)

    rec = axis_record()
    savemat(tmp_path / "DATA_EMPS.mat", {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                                         "qm": rec.y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "identify_io", identify_io)
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    args = ["benchmark", "emps", "--data", str(tmp_path), "--models", "dahl,coulomb"]
    assert main([*args, "--json"]) == 2
    out, err = capsys.readouterr()
    assert err == ("motionhyst: error: benchmark emps: 2 of 4 fits failed (dahl on DATA_EMPS "
                   "periods 1-2, dahl on DATA_EMPS periods 3-4): their rows say why; the "
                   "others are above\n")
    result = json.loads(out)
    dahl, coulomb = result["models"][0::2], result["models"][1::2]
    for split, (est, val) in enumerate((("1-2", "3-4"), ("3-4", "1-2"))):
        assert dahl[split]["name"] == "dahl" and "parameters" not in dahl[split]
        assert dahl[split]["error"] == "the fit failed: its prediction is not finite"
        assert dahl[split]["estimation"] == {"record": f"DATA_EMPS periods {est}"}
        assert dahl[split]["validation"] == {"record": f"DATA_EMPS periods {val}"}
        assert coulomb[split]["parameters"]["m"] == pytest.approx(TRUE["m"], rel=0.05)
        assert coulomb[split]["validation"]["record"] == f"DATA_EMPS periods {val}"
        assert coulomb[split]["validation"]["rmse_mm"] < 0.05  # the true model's structure
    worst = max(m["validation"]["rmse_mm"] for m in coulomb)
    assert result["chosen"] == {"name": "coulomb", "worse_split_rmse_mm": worst}
    assert main(args) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1  # no progress off a terminal: the one line
    assert err.startswith("motionhyst: error: benchmark emps: 2 of 4 fits")
    rows = [line.strip() for line in out.splitlines()
            if line.strip().startswith("motionhyst: mass-damper")]
    assert rows[0] == ("motionhyst: mass-damper + dahl  failed: the fit failed: its "
                       "prediction is not finite")
    assert rows[1].startswith("motionhyst: mass-damper + coulomb") and "failed" not in rows[1]
    assert "dahl - (failed on 2 of 2 splits)" in out and "warning: dahl" not in out
    assert f"(the rule stated in advance): coulomb, {worst:.3g} mm" in out


def test_the_best_of_models_that_all_failed_is_a_failed_fit_naming_each():
    """EMPSBenchmark.best() when every model failed (review B17 L2): main raised min()'s
    'ValueError: min() arg is an empty sequence'; now the FitFailed (a RuntimeError, the
    command line's one line) naming each model and its reason.  With one model scored it is
    that one."""
    from motionhyst.identify.emps import EMPSBenchmark, EMPSModel
    from motionhyst.identify.io_checks import FitFailed

    failed = [EMPSModel.failed("dahl", {}, {}, "the fit failed: its prediction is not finite"),
              EMPSModel.failed("coulomb", {}, {}, "no fit")]
    with pytest.raises(FitFailed) as caught:
        EMPSBenchmark(failed, None, None, False, {}).best()
    assert str(caught.value) == ("no model to choose: every model's fit failed (dahl: the fit "
                                 "failed: its prediction is not finite; coulomb: no fit)")
    with pytest.raises(FitFailed, match=r"\(no model fitted\)$"):
        EMPSBenchmark([], None, None, False, {}).best()
    scored = EMPSModel("jenkins", {}, {}, {}, {"rmse_mm": 2.5}, 0.0)
    assert EMPSBenchmark([*failed, scored], None, None, False, {}).best() is scored


def test_benchmark_emps_every_split(tmp_path, capsys, monkeypatch):
    """--periods all: both halves, then all periods but the last and all but the first, each
    validated on what it left out; the rule takes the worst of the four."""
    import motionhyst.identify.emps as emps

    rec = axis_record()
    savemat(tmp_path / "DATA_EMPS.mat", {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                                         "qm": rec.y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "MODELS", ("coulomb",))
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    assert main(["benchmark", "emps", "--data", str(tmp_path), "--periods", "all",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [m["validation"]["record"] for m in out["models"]] == [
        "DATA_EMPS periods 3-4", "DATA_EMPS periods 1-2", "DATA_EMPS period 4",
        "DATA_EMPS period 1"]
    worst = max(m["validation"]["rmse_mm"] for m in out["models"])
    assert out["chosen"] == {"name": "coulomb", "worse_split_rmse_mm": worst}
    assert worst < 0.05  # the true model's structure: every split predicted
    assert main(["benchmark", "emps", "--data", str(tmp_path), "--periods", "all"]) == 0
    text = capsys.readouterr().out
    assert "Chosen by the worst of the 4 splits (the rule stated in advance): coulomb" in text


def test_benchmark_emps_with_the_test_record_names_the_chosen_model(tmp_path, capsys,
                                                                   monkeypatch):
    """With the test record the JSON names the model chosen before the test, in the shape
    {"name", "rule", "validation_rmse_mm"}: the rule it was chosen by on the splits, and its
    RMSE on the test record measured in this run; a list without that model has no chosen one."""
    import motionhyst.identify.emps as emps

    rec = axis_record(n_periods=2)
    for name in ("DATA_EMPS.mat", "DATA_EMPS_PULSES.mat"):
        savemat(tmp_path / name, {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                                  "qm": rec.y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    monkeypatch.setattr(emps, "CHOSEN", "coulomb")
    assert main(["benchmark", "emps", "--data", str(tmp_path), "--models", "coulomb",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["chosen"]["name"] == "coulomb"
    assert "worse of the two splits" in out["chosen"]["rule"]
    assert out["chosen"]["validation_rmse_mm"] == out["models"][0]["validation"]["rmse_mm"]
    assert [m["validation"]["record"] for m in out["models"]] == ["DATA_EMPS_PULSES"]
    monkeypatch.setattr(emps, "CHOSEN", "coulomb-drift")
    assert main(["benchmark", "emps", "--data", str(tmp_path), "--models", "coulomb",
                 "--json"]) == 0
    assert "chosen" not in json.loads(capsys.readouterr().out)


def test_a_chosen_model_that_failed_on_the_test_record_has_no_figure(tmp_path, capsys,
                                                                     monkeypatch):
    """With the test record, the model chosen before the test whose fit failed: no "chosen"
    in the JSON, no figure below the table, the other model scored, exit 2."""
    import motionhyst.identify.emps as emps
    from motionhyst.identify.io_checks import FitFailed

    real = emps.identify_io

    def identify_io(records, link, **kwargs):
        if link == "dahl":
            raise FitFailed("the fit failed: its prediction is not finite")
        return real(records, link, **kwargs)

    rec = axis_record(n_periods=2)
    for name in ("DATA_EMPS.mat", "DATA_EMPS_PULSES.mat"):
        savemat(tmp_path / name, {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                                  "qm": rec.y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "identify_io", identify_io)
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    monkeypatch.setattr(emps, "CHOSEN", "dahl")
    args = ["benchmark", "emps", "--data", str(tmp_path), "--models", "dahl,coulomb"]
    assert main([*args, "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert "chosen" not in out and out["models"][0]["error"].startswith("the fit failed")
    assert out["models"][1]["validation"]["record"] == "DATA_EMPS_PULSES"
    assert out["models"][1]["validation"]["rmse_mm"] < 0.05
    assert main(args) == 2
    assert "motionhyst's figure" not in capsys.readouterr().out


@pytest.mark.skipif(not (SHARED / "DATA_EMPS.mat").is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_emps_record_splits_into_its_reference_periods():
    from scipy.io import loadmat

    qg = loadmat(SHARED / "DATA_EMPS.mat")["qg"].ravel()
    assert qg.size == 24841
    np.testing.assert_allclose(qg[6240:12480], qg[:6240], rtol=0, atol=1e-12)  # it repeats
    np.testing.assert_allclose(qg[18720:], qg[:qg.size - 18720], rtol=0, atol=1e-12)
    assert np.max(np.abs(qg[6000:12000] - qg[:6000])) > 1e-3  # and not with another period


def test_identify_and_predict_a_mat_record_with_the_window(tmp_path, capsys):
    """The guide's path on the command line: identify a .mat record in the benchmark's names
    with --init-window, save, and predict it from its force with --init-from, the --columns
    and --scale maps naming the position too (the force record takes the keys it has), and
    without --init-from from rest with the same maps."""
    rec = axis_record(n_periods=2)
    path = tmp_path / "axis.mat"
    savemat(path, {"t": rec.t[:, None], "vir": rec.u[:, None] / DRIVE_GAIN,
                   "qm": rec.y[:, None]})
    maps = ["--columns", "time=t,force=vir,displacement=qm", "--scale", f"force={DRIVE_GAIN}"]
    model = tmp_path / "axis.toml"
    assert main(["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
                 "--model", "coulomb", "--init-window", "20", "--save", str(model), "--json",
                 *maps]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["estimates"]["m"] == pytest.approx(TRUE["m"], rel=0.02)
    assert fit["estimates"]["input_offset"] == pytest.approx(TRUE["offset"], abs=0.3)
    out = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(path), "--init-from", str(path), "--out", str(out),
                 "--json", *maps]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["init_window"] == INIT_WINDOW
    assert summary["rmse"] < 0.02 * np.std(rec.y)
    # without --init-from the map given identify is taken as it is: the model predicts what
    # its own record measured, the position from the force, from rest
    assert main(["predict", str(model), str(path), "--out", str(tmp_path / "p2.csv"),
                 *maps]) == 0
    assert capsys.readouterr().out.startswith(f"Predicted the displacement of {model} (from rest)")
    predicted = np.genfromtxt(tmp_path / "p2.csv", delimiter=",", names=True)
    assert predicted.dtype.names == ("time", "displacement")
    assert predicted["time"] == pytest.approx(rec.t, abs=1e-12)


def test_with_the_test_record_the_whole_estimation_record_is_used():
    """With the test record the models are identified on the whole estimation record and
    scored on the test record (the benchmark's protocol), and the output says so."""
    rec = axis_record(n_periods=2)
    test = IORecord(rec.t, rec.u, rec.y, "DATA_EMPS_PULSES")
    res = run_emps(IORecord(rec.t, rec.u, rec.y, "DATA_EMPS"), test, models=("coulomb",),
                   period=PERIOD)
    assert res.official_test
    assert res.estimation_record.t.size == rec.t.size
    (model,) = res.models
    assert model.estimation["record"] == "DATA_EMPS"
    assert model.validation["record"] == "DATA_EMPS_PULSES"
    assert model.parameters["m"] == pytest.approx(TRUE["m"], rel=0.02)
    assert "was not given" not in str(res)


def test_a_drifting_offset_is_diagnosed():
    """A record whose force offset drifts from period to period (as DATA_EMPS's does): the
    inverse dynamics of each period shows it, and the held-out record's own offset takes
    the error that the drift made."""
    rec = axis_record(noise=0.0)
    # the force measured drifts by 0.15 N/s while the axis moves as before (its offset OF)
    drifting = IORecord(rec.t, rec.u + 0.15 * rec.t, rec.y, "drifting")
    res = run_emps(drifting, models=("coulomb",), period=PERIOD)
    offsets = [d["offset"] for d in res.drift]
    assert len(offsets) == 4
    np.testing.assert_allclose(np.diff(offsets), 0.15, rtol=0.1)  # 0.15 N per 1 s period
    (model,) = res.models
    own = model.validation["own_offset"]
    held_out = TRUE["offset"] + 0.15 * 3.0  # the mean offset of periods 3-4
    assert own["offset"] == pytest.approx(held_out, abs=0.1)
    assert own["rmse_mm"] < 0.2 * model.validation["rmse_mm"]
    assert "own offset" in str(res) and "Inverse dynamics (IDIM-LS) of each period" in str(res)


def test_offset_with_viscous_friction_by_direction_as_the_reference_models():
    """An axis whose viscous friction is larger backward, with no force offset: the
    reference model's structure (one viscous coefficient) fits it with an offset, and the
    equivalent offset of the true parameters is that offset; in the benchmark's table too."""
    from motionhyst.identify.emps_reference import equivalent_offset
    from motionhyst.identify.io_start import inverse_dynamics

    t = np.arange(4000) / 1000.0
    y = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(6 * np.pi * t)
    v = np.gradient(y, t, edge_order=2)
    a = np.gradient(v, t, edge_order=2)
    u = 95.0 * a + 160.0 * v + 80.0 * np.minimum(v, 0.0) + 20.0 * np.sign(v) + 0.1
    rec = IORecord(t, u, y, "asymmetric")
    symmetric = inverse_dynamics([rec], floating=True)
    true = {"offset": 0.1, "c_neg": 80.0}
    assert symmetric["u0"] < -2.0  # the direction-dependent viscous force taken as an offset
    assert equivalent_offset(true, rec) == pytest.approx(symmetric["u0"], abs=0.05)
    res = run_emps(IORecord(t, u, y, "axis"), models=("coulomb-symmetric",), periods=(1, 2),
                   period=PERIOD)
    (model,) = res.models
    assert model.to_dict()["equivalent_offset"] == pytest.approx(model.parameters["offset"],
                                                                 abs=1e-9)  # symmetric: itself
    assert "as OF [N]" in str(res)


def test_a_link_at_its_rigid_limit_is_reported_as_that_limit(monkeypatch):
    """A Jenkins link whose stiffness runs to where predict cannot step it (here: the finest
    step lowered so that the fitted k of this Coulomb axis is past it) does not fail the run:
    the model is reported as its rigid limit, the Coulomb link with the same options, and
    says so; the Coulomb fit already made is reused."""
    import motionhyst.identify.io_checks as io_checks

    monkeypatch.setattr(io_checks, "MAX_PREDICT_SUBSTEPS", 60)
    rec = axis_record(n_periods=2)
    res = run_emps(rec, models=("coulomb", "jenkins"), periods=(1, 1), period=PERIOD)
    coulomb, jenkins = res.models
    assert jenkins.limit == "coulomb" and coulomb.limit is None
    assert jenkins.parameters == coulomb.parameters and "k" not in jenkins.parameters
    assert jenkins.validation["rmse_mm"] == coulomb.validation["rmse_mm"]
    assert "rigid limit" in jenkins.warnings[0] and jenkins.to_dict()["limit"] == "coulomb"
    assert "jenkins (its rigid limit, coulomb)" in str(res)
    assert "warning: jenkins: the link's stiffness ran to the rigid limit" in str(res)


def test_a_link_whose_rigid_limit_failed_is_a_failed_row(monkeypatch):
    """A Jenkins link run to its rigid limit when that limit, the Coulomb fit, failed on the
    same records: its row says both, and the Coulomb fit is not made again."""
    import motionhyst.identify.emps as emps
    import motionhyst.identify.io_checks as io_checks
    from motionhyst.identify.io_checks import FitFailed

    real, links = emps.identify_io, []

    def identify_io(records, link, **kwargs):
        links.append(link)
        if link == "coulomb":
            raise FitFailed("the fit failed: its prediction is not finite")
        return real(records, link, **kwargs)

    monkeypatch.setattr(io_checks, "MAX_PREDICT_SUBSTEPS", 60)
    monkeypatch.setattr(emps, "identify_io", identify_io)
    res = run_emps(axis_record(n_periods=2), models=("coulomb", "jenkins"), periods=(1, 1),
                   period=PERIOD)
    assert links == ["coulomb", "jenkins"]
    assert res.failed == res.models  # both rows say why
    assert res.models[1].error.startswith("a model that needs more than ")
    assert res.models[1].error.endswith("integration steps per sample; its rigid limit coulomb: "
                                        "the fit failed: its prediction is not finite")


def test_the_asymmetric_reference_model_by_one_linear_solve():
    """The benchmark's eq. (12) (viscous and Coulomb friction by direction, no offset): its
    published parameters as a system, and found again from that system's record by the one
    linear solve; the table lists it beside the symmetric reference, both ways."""
    t = np.arange(4000) / 1000.0
    u = 200 * np.sin(2 * np.pi * 0.6 * t) + 80 * np.sin(2 * np.pi * 1.7 * t + 0.3)
    y = reference_system(REFERENCE_ASYMMETRIC).simulate(t, u).displacement
    found = asymmetric_inverse_dynamics(IORecord(t, u, y))
    for name, value in REFERENCE_ASYMMETRIC.items():
        assert found[name] == pytest.approx(value, rel=0.03), name
    assert found["c_neg"] - found["c_pos"] == pytest.approx(73.7, rel=0.05)
    rec = axis_record(n_periods=2, noise=0.0)
    res = run_emps(rec, models=("coulomb",), periods=(1, 1), period=PERIOD)
    text = str(res)
    assert "IDIM-LS, asymmetric friction (eq. 12), published" in text
    assert "IDIM-LS, asymmetric friction (eq. 12), on axis period 1" in text
    assert res.reference["asymmetric"]["parameters"] == REFERENCE_ASYMMETRIC
    own = res.reference["idim_asymmetric"]["parameters"]  # a symmetric axis: c+ = c-
    assert own["c_pos"] == pytest.approx(own["c_neg"], rel=0.05)
    assert own["m"] == pytest.approx(TRUE["m"], rel=0.02)


def test_the_table_marks_what_the_record_does_not_determine():
    """A parameter without a standard error (the Jenkins link's offset on DATA_EMPS periods
    1-2, +0.0004 N) is marked in the benchmark's table, as JSON's None says; others not."""
    res = run_emps(axis_record(n_periods=2), models=("coulomb",), periods=(1, 1),
                   period=PERIOD)
    (model,) = res.models
    assert all(model.model_std[n] is not None for n in ("m", "offset"))
    assert "(not determined)" not in str(res)
    model.model_std["offset"], model.std["offset"] = None, None
    row = next(line for line in str(res).splitlines() if "mass-damper + coulomb" in line)
    assert row.count("(not determined)") == 2  # its own offset, and as OF, which it enters
    model.model_std["m"] = None
    row = next(line for line in str(res).splitlines() if "mass-damper + coulomb" in line)
    assert row.count("(not determined)") == 3


def _data_emps() -> IORecord:
    """DATA_EMPS as the command reads it (its force in N)."""
    from motionhyst.identify.emps_files import COLUMNS
    from motionhyst.io.records import read_record

    data = read_record(SHARED / "DATA_EMPS.mat", ("time", "force", "displacement"),
                       columns=COLUMNS, scale={"force": DRIVE_GAIN})
    return IORecord(data[:, 0], data[:, 1], data[:, 2], "DATA_EMPS")


@pytest.mark.skipif(not (SHARED / "DATA_EMPS.mat").is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_jenkins_with_a_drifting_offset_keeps_the_stiffness_the_record_shows():
    """The Jenkins link with viscous friction by direction and the offset drifting, on
    periods 1-2: its search refines both its starts, the short runs' best and its rigid
    limit (the Coulomb fit, which cost less at the start), and keeps the better end: a
    stiffness the record resolves (2.9e6 N/m, 28 Hz) fitting the periods to 0.234 mm, not
    the rigid limit's 0.288 mm reported as that limit (main)."""
    res = run_emps(_data_emps(), models=("jenkins-asymmetric-drift",), periods=(1, 2))
    (model,) = res.models
    assert model.limit is None
    assert model.parameters["k"] == pytest.approx(2.9e6, rel=0.3)
    assert model.model_std["k"] is not None and model.model_std["k"] < model.parameters["k"]
    assert model.estimation["rmse_mm"] < 0.25
    assert model.parameters["m"] == pytest.approx(95.1, rel=0.03)


@pytest.mark.skipif(not (SHARED / "DATA_EMPS.mat").is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_emps_periods_3_4_jenkins_leaves_its_local_minimum():
    """The Jenkins link with viscous friction by direction and the offset drifting, identified
    on EMPS periods 3-4 as the command does: its search ended at k 2.3e6 N/m fitting the
    periods to 0.2339 mm (the base, 3bf7065), a local minimum: held at 1.08e7 N/m (the grid
    about that end) and the rest refined, it fits them better; the search now ends there, k
    1.0e7 N/m, 0.2297 mm, and predicts the held-out periods 1-2 to 4.39 mm (base: 5.72; issue
    21's target for this model, at most 5.5 mm)."""
    res = run_emps(_data_emps(), models=("jenkins-asymmetric-drift",), periods=(3, 4))
    (model,) = res.models
    assert model.limit is None
    assert model.estimation["rmse_mm"] < 0.2337  # below the base's end
    assert 5e6 < model.parameters["k"] < 3e7
    assert model.parameters["m"] == pytest.approx(95.1, rel=0.03)
    assert model.validation["rmse_mm"] <= 5.5


@pytest.mark.skipif(not (SHARED / "DATA_EMPS.mat").is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_every_default_model_finds_the_axis_on_the_raw_record():
    """Issue 21's target on the raw estimation record (no preprocessing), as the command
    identifies it when it has the test record: a default model's mass within 3 % of the
    benchmark's 95.1 kg and its force offset, as the reference model's OF, within 0.6 N of
    -3.16 N, or a warning that says which misses and by how much.  Measured: Coulomb with
    viscous friction by direction 93.47 kg (92.98 kg on a machine with numpy 2.4.6 and scipy
    1.17.1: its search ends elsewhere on a flat valley), in the band; Jenkins 92.34 kg, in the
    band, its stiffness profiled (io_stiffness): the refinement ends at k 3.0e7 N/m, not
    determined (+- 3.1e8), 93.59 kg, 1.910 mm; the held fit at 1.4e6 N/m fits the record better
    and the end from it, k 1.40e6 +- 1.25e6 N/m (stuck mode 20 Hz), 92.34 kg, fits it to
    1.706 mm, chosen by that cost (the mass 3.3 % from the inverse dynamics' 95.5 kg and 1.5 of
    its standard errors, 2.0 kg, from the published 95.1 kg: no implausibility); the Coulomb link
    with the offset drifting 92.05 kg, 3.2 % low (the drift in time takes part of the inertia:
    93.3 kg costs it 0.49 against 0.43 mm), said; every OF -3.15 to -3.21 N."""
    from motionhyst.identify.emps import MODELS

    rec = _data_emps()
    res = run_emps(rec, rec, models=MODELS)
    assert [m.name for m in res.models] == list(MODELS)
    for model in res.models:
        mass_noted = any("published 95.11 kg" in w for w in model.warnings)
        in_band = model.parameters["m"] == pytest.approx(95.1089, rel=0.03)
        assert in_band != mass_noted, model.name
        assert model.parameters["offset"] == pytest.approx(-3.16, abs=0.6), model.name
        assert not any("as OF" in w for w in model.warnings), model.name
    by_name = {m.name: m for m in res.models}
    assert by_name["coulomb-asymmetric"].parameters["m"] == pytest.approx(93.5, abs=0.6)
    jenkins = by_name["jenkins-asymmetric"]
    assert jenkins.parameters["m"] == pytest.approx(92.34, abs=0.3)
    assert jenkins.model_parameters["k"] == pytest.approx(1.4e6, rel=0.3)
    assert jenkins.estimation["rmse_mm"] < 1.8  # the refinement's end without the profile: 1.91
    drifting = by_name["coulomb-asymmetric-drift"]
    assert drifting.parameters["m"] == pytest.approx(92.05, abs=0.15)
    assert drifting.warnings[-1].startswith(f"m = {drifting.parameters['m']:.2f} kg is 3.")
    assert f"warning: coulomb-asymmetric-drift: {drifting.warnings[-1]}" in str(res)
