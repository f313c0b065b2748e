"""A force offset that drifts in time (MassDamper.force_drift): simulated, refused where it
has no meaning, identified (identify_io(drift=True), identify --drift) and predicted."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_predict import predict_from_window
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

FS = 1000.0
AXIS = {"m": 95.0, "c": 170.0, "force_offset": 3.0, "force_drift": 0.05}


def _record(t0: float = 0.0, n: int = 3000) -> IORecord:
    """The drifting axis from rest at time `t0` (its force offset ``3 + 0.05 t`` N)."""
    t = t0 + np.arange(n) / FS
    u = 30 + 90 * np.sin(2 * np.pi * 0.6 * t) + 40 * np.sin(2 * np.pi * 1.7 * t + 0.3)
    y = OpenLoop(MassDamper(**AXIS), Coulomb(fc=20.0)).simulate(t, u, substeps=20).displacement
    return IORecord(t, u, y, f"axis from {t0:g} s")


def test_the_drift_is_a_force_growing_with_the_records_time():
    """The force at time t is u + f0 + f1 t: the same as a constant offset's run with that
    force added, wherever the record's time starts."""
    t = 5.0 + np.arange(2000) / FS
    u = 60 * np.sin(2 * np.pi * t)
    drifting = OpenLoop(MassDamper(**AXIS), Coulomb(fc=20.0)).simulate(t, u, substeps=20)
    same = OpenLoop(MassDamper(95.0, 170.0, force_offset=3.0), Coulomb(fc=20.0)).simulate(
        t, u + 0.05 * t, substeps=20)
    np.testing.assert_allclose(drifting.displacement, same.displacement, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(drifting.force, u)  # the record's force, as given
    axis = MassDamper(**AXIS)
    assert axis.to_dict() == {"type": "mass-damper", **AXIS}
    assert repr(axis.with_parameters([90.0, 150.0])) == (
        "MassDamper(m=90.0, c=150.0, force_offset=3.0, force_drift=0.05)")
    assert MassDamper(95.0, 170.0).to_dict() == {"type": "mass-damper", "m": 95.0, "c": 170.0}


def test_refused_where_a_drift_means_nothing():
    axis = OpenLoop(MassDamper(**AXIS), Coulomb(fc=20.0))
    t = np.arange(100) / FS
    with pytest.raises(ValueError, match="no periodic steady state"):
        axis.simulate(t, np.sin(2 * np.pi * 10 * t), periodic=True)
    with pytest.raises(ValueError, match="finite"):
        MassDamper(95.0, 170.0, force_drift=float("nan"))
    rec = _record(n=300)
    with pytest.raises(ValueError, match="on a mass-damper"):
        identify_io([rec], "coulomb", plant="mass-spring-damper", drift=True)
    with pytest.raises(ValueError, match="with the force offset"):
        identify_io([rec], "coulomb", plant="mass-damper", offset="output", drift=True)


def test_identified_with_the_state_set_from_the_window_and_predicted():
    """From exact data, the drift's rate is found with the stage, the link and the offset;
    the fitted model predicts a later record of the same axis (its own time) to rounding,
    the model without the drift does not."""
    fit = identify_io([_record()], "coulomb", plant="mass-damper", substeps=20,
                      init_window=20, drift=True)
    est = fit.estimates
    assert est["input_drift"] == pytest.approx(-AXIS["force_drift"], rel=1e-4)
    assert est["input_offset"] == pytest.approx(-AXIS["force_offset"], rel=1e-4)
    assert est["m"] == pytest.approx(AXIS["m"], rel=1e-4)
    assert fit.std["input_drift"] is not None and fit.std["input_drift"] < 1e-3
    assert fit.plant.force_drift == pytest.approx(AXIS["force_drift"], rel=1e-4)
    assert fit.extra["offsets"]["input_drift"] == est["input_drift"]
    later = _record(t0=20.0)
    pred = predict_from_window(fit.system(), later.t, later.u, later.y, 20, substeps=20)
    assert pred.rmse < 1e-6 * np.ptp(later.y)
    fit.plant.force_drift = 0.0
    pred = predict_from_window(fit.system(), later.t, later.u, later.y, 20, substeps=20)
    assert pred.rmse > 1e-2 * np.ptp(later.y)  # one N of offset missed, integrated


def test_identify_drift_on_the_command_line(tmp_path, capsys):
    """identify --drift saves the stage's force_drift; predict --init-from uses it."""
    from motionhyst.cli import main

    rec = _record()
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")
    model = tmp_path / "axis.toml"
    assert main(["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
                 "--model", "coulomb", "--init-window", "20", "--drift", "--save", str(model),
                 "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["estimates"]["input_drift"] == pytest.approx(-AXIS["force_drift"], rel=1e-3)
    assert "force_drift = 0.0499" in model.read_text()
    out = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(path), "--init-from", str(path), "--out", str(out),
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rmse"] < 1e-5 * np.ptp(rec.y)
    assert main(["identify", str(path), "--record", "input-output", "--plant", "two-mass",
                 "--model", "coulomb", "--drift"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--drift applies to records from a start" in err
