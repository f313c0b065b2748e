"""Viscous friction by direction on a positioning axis (MassDamper.c_skew): simulated with
every link, refused where it has no meaning, identified with every element link
(identify_io(asymmetric=True), identify --asymmetric) and saved for predict."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb, Dahl, Jenkins
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_predict import predict_from_window
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop, simulate_elements

FS = 1000.0
#: An EMPS-like axis: 163 N s/m moving forward, 240 backward (c 201.5, c_skew -38.5)
AXIS = {"m": 95.0, "c_pos": 163.0, "c_neg": 240.0, "force_offset": 3.0}


def _force(n: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / FS
    return t, 30 + 90 * np.sin(2 * np.pi * 0.6 * t) + 40 * np.sin(2 * np.pi * 1.7 * t + 0.3)


def test_the_damper_by_direction_is_the_coulomb_links_own_viscous_friction():
    """c + c_skew forward and c - c_skew backward on the stage are the same axis as the
    Coulomb link's c_pos, c_neg on top of the smaller stage damper (closed form, both)."""
    t, u = _force(3000)
    stage = OpenLoop(MassDamper.by_direction(**AXIS), Coulomb(fc=20.0))
    link = OpenLoop(MassDamper(95.0, 163.0, force_offset=3.0), Coulomb(fc=20.0, c_neg=77.0))
    a = stage.simulate(t, u, substeps=20).displacement
    b = link.simulate(t, u, substeps=20).displacement
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * np.ptp(b))  # O(h) apart
    symmetric = OpenLoop(MassDamper(95.0, 201.5, force_offset=3.0), Coulomb(fc=20.0))
    assert np.max(np.abs(symmetric.simulate(t, u, substeps=20).displacement - b)) > 1e-2


@pytest.mark.parametrize("link", [Jenkins(k=2e5, fc=20.0), Dahl(k=2e5, fc=20.0)])
def test_an_element_link_moves_backward_with_the_backward_damper(link):
    """Moving at a constant speed (the link slipping at its force) the stage's viscous force
    is c_pos v forward and c_neg |v| backward: the steady speed under a force F is
    (F - f0 - fc) / c_pos or (F + f0 - fc) / c_neg (within the link's approach to fc)."""
    t = np.arange(40000) / FS
    for sign, c in ((1.0, AXIS["c_pos"]), (-1.0, AXIS["c_neg"])):
        u = sign * 120.0 * np.ones_like(t)
        axis = MassDamper.by_direction(95.0, AXIS["c_pos"], AXIS["c_neg"])
        y = OpenLoop(axis, link).simulate(t, u, substeps=4).displacement
        v = (y[-1] - y[-1001]) * FS / 1000
        assert v == pytest.approx(sign * (120.0 - 20.0) / c, rel=2e-3)


def test_the_skew_sensitivity_is_the_derivative_of_the_run():
    """simulate_elements' column for c_skew (exact forward sensitivities through the
    damper's row) matches central differences of the run."""
    from motionhyst.identify._element_sensitivities import row_derivatives

    _, u = _force(1500)
    values = np.array([2e5, 20.0, 0.0])  # Jenkins k, fc and a column for c_skew

    def build(v):
        return Jenkins(k=v[0], fc=v[1])

    def run(skew, dparams=None):
        mech = MassDamper(95.0, 201.5, skew, force_offset=3.0).mechanics()
        return simulate_elements(mech, build(values).time_stepping(), u, FS, 10,
                                 periodic=False, dparams=dparams, skew_column=2)

    y, dy = run(-38.5, row_derivatives(build, values))
    fd = (run(-38.5 + 1e-3)[0] - run(-38.5 - 1e-3)[0]) / 2e-3
    np.testing.assert_allclose(dy[:, -1], fd, rtol=0, atol=1e-6 * np.max(np.abs(fd)))
    np.testing.assert_array_equal(y, run(-38.5)[0])  # the same run with or without them


def test_refused_where_it_means_nothing():
    with pytest.raises(ValueError, match="c_skew must be within"):
        MassDamper(95.0, 100.0, c_skew=-120.0)
    axis = OpenLoop(MassDamper.by_direction(**AXIS), Jenkins(k=2e5, fc=20.0))
    t, u = _force(200)
    with pytest.raises(ValueError, match="run from a start"):
        axis.simulate(t, u - np.mean(u), periodic=True)
    from motionhyst import Loop
    from motionhyst.controllers.pid import Pid

    with pytest.raises(ValueError, match="no viscous friction by direction"):
        Loop(MassDamper.by_direction(95.0, 163.0, 240.0), Pid(1e5, 1e6, 1e3).tf())
    rec = IORecord(t, u, axis.simulate(t, u).displacement, "axis")
    with pytest.raises(ValueError, match="viscous friction is identified on a mass-damper"):
        identify_io([rec], "jenkins", plant="mass-spring-damper", asymmetric=True)
    with pytest.raises(ValueError, match="from a start, not periodic"):
        identify_io([rec], "jenkins", plant="mass-damper", asymmetric=True, periodic=True)


def _record(link, n: int = 2000) -> IORecord:
    t, u = _force(n)
    y = OpenLoop(MassDamper.by_direction(**AXIS), link).simulate(t, u, substeps=10).displacement
    return IORecord(t, u, y, f"axis with {link.name}")


@pytest.mark.parametrize(("link", "name"), [
    (Jenkins(k=2e5, fc=20.0), "jenkins"),
    (Dahl(k=2e5, fc=20.0), "dahl"),
])
def test_identified_for_every_element_link(link, name):
    """From exact data of an axis with known c+ and c-, each link's fit finds the stage's
    mass, mean damper and skew with the force offset (a symmetric damper would put the
    difference into the mass and the offset), with standard errors."""
    fit = identify_io([_record(link)], name, plant="mass-damper", substeps=10, from_rest=True,
                      asymmetric=True, n_elements=2)
    est = fit.estimates
    assert est["m"] == pytest.approx(AXIS["m"], rel=1e-3)
    assert est["c"] == pytest.approx(201.5, rel=1e-3)
    assert est["c_skew"] == pytest.approx(-38.5, rel=1e-3)
    assert est["input_offset"] == pytest.approx(-AXIS["force_offset"], rel=1e-3)
    assert fit.std["c_skew"] is not None and fit.std["c_skew"] < 1.0
    assert fit.plant.c_pos == pytest.approx(163.0, rel=1e-3)
    assert fit.plant.c_neg == pytest.approx(240.0, rel=1e-3)


def test_identify_asymmetric_on_the_command_line_saves_it_for_predict(tmp_path, capsys):
    """identify --asymmetric --model jenkins saves the stage's c_skew; predict --init-from
    runs the saved model with it; on a stage held by a spring it is refused in one line."""
    from motionhyst.cli import main

    rec = _record(Jenkins(k=2e5, fc=20.0), n=3000)  # both directions' motion, long enough
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")
    model = tmp_path / "axis.toml"
    assert main(["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
                 "--model", "jenkins", "--init-window", "20", "--asymmetric", "--save",
                 str(model), "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["estimates"]["c_skew"] == pytest.approx(-38.5, rel=1e-3)
    assert "c_skew = -38.4" in model.read_text() or "c_skew = -38.5" in model.read_text()
    out = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(path), "--init-from", str(path), "--out", str(out),
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rmse"] < 1e-5 * np.ptp(rec.y)
    assert main(["identify", str(path), "--record", "input-output", "--plant",
                 "mass-spring-damper", "--model", "bouc-wen", "--asymmetric"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--asymmetric applies to --plant mass-damper" in err


def test_predicted_from_the_window_with_its_damper():
    """The benchmark's route: the state from the first 20 samples, the axis run on."""
    link = Jenkins(k=2e5, fc=20.0)
    rec = _record(link, n=1500)
    pred = predict_from_window(OpenLoop(MassDamper.by_direction(**AXIS), link), rec.t, rec.u,
                               rec.y, 20, substeps=10)
    assert pred.rmse < 1e-8 * np.ptp(rec.y)
    mean = OpenLoop(MassDamper(95.0, 201.5, force_offset=3.0), link)  # the mean damper
    assert predict_from_window(mean, rec.t, rec.u, rec.y, 20, substeps=10).rmse > 1e-3


EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"


@pytest.mark.skipif(not EMPS.is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_a_stiff_link_on_the_measured_record_is_simulated():
    """A nearly rigid Jenkins link (k 2.8e8 N/m, fitted on EMPS periods 3-4) turns the last
    bit of a step's displacement into more force than the fixed point's rounding floor: the
    passes repeat in a two-cycle, which is the step's end (it ended the run before)."""
    from motionhyst.cli.benchmark import _emps_record
    from motionhyst.identify.emps import split_by_periods

    rec, _ = split_by_periods(_emps_record(EMPS, "DATA_EMPS"), (3, 4))
    axis = OpenLoop(MassDamper(92.40918701923592, 190.0506702169536, -39.67811826643633),
                    Jenkins(k=275714121.3158981, fc=21.943279798965058))
    y = axis.simulate(rec.t, rec.u, substeps=110).displacement
    assert np.all(np.isfinite(y)) and np.ptp(y) > 0.1


def test_identify_reports_the_fit_as_one_viscous_coefficient_and_an_offset(tmp_path, capsys):
    """With viscous friction by direction the fit's own force offset is the drive's (3 N); on
    the record's motion its even part (c_pos - c_neg)/2 |q'| is a further constant offset, and
    identify reports the fit in that form too (c, fc and the offset a model with one viscous
    coefficient would carry, with standard errors); a symmetric fit has nothing to add."""
    from motionhyst.cli import main

    rec = _record(Coulomb(fc=20.0), n=3000)
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")
    args = ["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
            "--model", "coulomb", "--from-rest"]
    assert main([*args, "--asymmetric", "--json"]) == 0
    (form,) = json.loads(capsys.readouterr().out)["reference_form"]
    mean_speed = float(np.mean(np.abs(np.gradient(rec.y, rec.t))))
    expected = {"c": 201.5, "fc": 20.0, "offset": -AXIS["force_offset"] - 38.5 * mean_speed}
    # the offset: -9.81 N true, -9.685 +- 0.034 fitted with numpy 2.4.6 / scipy 1.17.1, whose
    # search ends with c_neg 1.5 N s/m (3.7 of its std) from the truth: within 2 %
    for name, value in expected.items():
        rel = 2e-2 if name == "offset" else 1e-2
        assert form["parameters"][name] == pytest.approx(value, rel=rel), name
        assert 0 < form["std"][name] < 1e-2 * abs(value)
    assert form["record"] == str(path)
    assert main([*args, "--asymmetric"]) == 0
    out = capsys.readouterr().out
    assert f"constant force offset on the motion of {path}:\n" in out
    assert f"input_offset {form['parameters']['offset']:.4g} +- " in out
    assert main([*args, "--symmetric", "--json"]) == 0
    assert "reference_form" not in json.loads(capsys.readouterr().out)
