"""Records of machines without visible inertia: identified, saved, predicted on held-out parts.

A friction damper (displacement imposed, force measured) and a piezo stack (force in,
displacement out), generated with known parameters, offsets and noise
(:mod:`records_of_other_kinds`): the model identified on one history must predict another
(fit >= 95 %), through the commands a user runs; what cannot be predicted is a one-line
refusal.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from records_of_other_kinds import (
    DAMPER_FORCE_OFFSET,
    DAMPER_LINK,
    DAMPER_LINKS,
    DAMPER_NOISE,
    DAMPER_PLANT,
    LOGGED,
    PIEZO_NOISE,
    PIEZO_OUTPUT_OFFSET,
    PIEZO_PLANT,
    damper_record,
    fit_percent,
    piezo_record,
)
from scipy import signal

from motionhyst.cli import main
from motionhyst.scenario import Scenario


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def damper_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("damper")
    train = damper_record("sines", seed=1).write(folder / "sines.csv",
                                                  ("time", "displacement", "force"))
    held_out = damper_record("earthquake", seed=2)
    held_out.write(folder / "earthquake.csv", ("time", "displacement"))
    return folder, train, held_out


def test_a_friction_damper_saved_from_sines_predicts_the_force_of_an_earthquake(capsys,
                                                                                damper_files):
    folder, train, held_out = damper_files
    model = folder / "damper.toml"
    rc, out, err = run(capsys, "identify", str(train), "--elements", "4", "--save", str(model))
    assert rc == 0 and err == "" and f"wrote {model}" in out
    system = Scenario.from_file(model).open_loop()
    assert system.plant.name == "quasi-static" and not system.plant.has_inertia
    # the load cell's offset, as the force the model holds at rest
    assert system.plant.force_offset == pytest.approx(-DAMPER_FORCE_OFFSET, abs=5.0)
    # the three friction elements (and the spring, as an element that never slipped)
    fc = sorted(system.hysteresis.fc)[-3:]
    assert fc == pytest.approx(sorted(DAMPER_LINK.fc), rel=0.02)
    force = folder / "force.csv"
    rc, out, err = run(capsys, "predict", str(model), str(folder / "earthquake.csv"),
                       "--out", str(force))
    assert rc == 0 and err == "" and "force RMS" in out
    predicted = np.loadtxt(force, delimiter=",", skiprows=1)
    assert open(force).readline().strip() == "time,force"
    np.testing.assert_array_equal(predicted[:, 0], held_out.t)
    assert fit_percent(held_out.force, predicted[:, 1]) > 98.0


def test_a_model_with_inertia_needs_a_force_record(capsys, tmp_path, damper_files):
    folder, _, _ = damper_files
    model = tmp_path / "stage.toml"
    model.write_text('[stage]\ntype = "mass-spring-damper"\nm = 1.0\nc = 10.0\nk = 1e4\n'
                     '[hysteresis]\nmodel = "jenkins"\nk = 1e4\nfc = 1.0\n')
    out_csv = tmp_path / "out.csv"
    rc, out, err = run(capsys, "predict", str(model), str(folder / "earthquake.csv"),
                       "--out", str(out_csv))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "missing column(s) force" in err
    assert not out_csv.exists()


def test_a_force_the_saved_link_does_not_hold_is_one_line_and_no_file(capsys, tmp_path):
    model = tmp_path / "link.toml"
    model.write_text('[stage]\ntype = "quasi-static"\n[hysteresis]\nmodel = "jenkins"\n'
                     'k = 1e4\nfc = 10.0\n')
    t = np.arange(200) / 100.0
    record = tmp_path / "force.csv"
    np.savetxt(record, np.column_stack([t, 15.0 * np.sin(np.pi * t)]), delimiter=",",
               header="time,force", comments="")
    out_csv = tmp_path / "out.csv"
    rc, out, err = run(capsys, "predict", str(model), str(record), "--out", str(out_csv))
    assert rc != 0 and out == "" and len(err.strip().splitlines()) == 1
    assert "is not held" in err and "Traceback" not in err
    assert not out_csv.exists()


def test_save_is_refused_for_a_closed_loop_record_before_any_work(capsys, tmp_path):
    record = tmp_path / "loop.csv"
    record.write_text("time,y1,u\n0.0,0.0,0.0\n0.001,0.0,0.0\n")
    rc, _, err = run(capsys, "identify", str(record), "--save", str(tmp_path / "m.toml"))
    assert rc == 2 and "--save applies to input-output and force-displacement" in err


@pytest.fixture(scope="module")
def piezo_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("piezo")
    piezo_record("sines", seed=1).write(folder / "sines.csv")
    held_out = piezo_record("earthquake", seed=2)
    held_out.write(folder / "earthquake.csv")
    held_out.write(folder / "earthquake_force.csv", ("time", "force"))
    return folder


def test_a_piezo_identified_without_inertia_predicts_a_held_out_history(capsys, piezo_files):
    folder = piezo_files
    model = folder / "piezo.toml"
    rc, out, err = run(capsys, "identify", str(folder / "sines.csv"), "--record",
                       "input-output", "--plant", "quasi-static", "--model", "bouc-wen",
                       "--save", str(model), "--json")
    assert rc == 0 and err == ""
    fit = json.loads(out)
    est = fit["estimates"]
    # the stack's spring and damper, the drive's force offset and the sensor's zero
    assert est["k"] == pytest.approx(PIEZO_PLANT.k, rel=0.01)
    assert est["c"] == pytest.approx(PIEZO_PLANT.c, rel=0.03)
    assert est["input_offset"] == pytest.approx(-PIEZO_PLANT.force_offset, abs=0.5)
    assert est["output_offset"] == pytest.approx(PIEZO_OUTPUT_OFFSET, abs=2e-8)
    assert fit["fit_rms"] < 1.5 * PIEZO_NOISE  # down to the noise
    rc, out, err = run(capsys, "predict", str(model), str(folder / "earthquake_force.csv"),
                       "--init-from", str(folder / "earthquake.csv"), "--out",
                       str(folder / "x.csv"), "--json")
    assert rc == 0 and err == ""
    assert json.loads(out)["fit_percent"] > 99.0


@pytest.fixture(scope="module")
def saved_piezo(piezo_files):
    """The piezo's model, identified on its sines and saved (without inertia)."""
    model = piezo_files / "saved.toml"
    assert main(["identify", str(piezo_files / "sines.csv"), "--record", "input-output",
                 "--plant", "quasi-static", "--model", "bouc-wen", "--save", str(model)]) == 0
    return model


def test_a_saved_piezo_predicts_with_its_sensor_zero_both_ways(capsys, tmp_path, piezo_files,
                                                             saved_piezo):
    """The position offset identify estimates (the sensor's 3 um zero) is saved and used by
    predict without --init-from: position from force, and force from the displacement less
    that zero (without it: 0.4 % and 16 %; with it 99.9 % both)."""
    folder, model = piezo_files, saved_piezo
    saved = Scenario.from_file(model, check=False).model.identification.position_offset
    assert saved == pytest.approx(PIEZO_OUTPUT_OFFSET, abs=2e-8)
    held_out = piezo_record("earthquake", seed=2)
    rc, out, err = run(capsys, "predict", str(model), str(folder / "earthquake_force.csv"),
                       "--out", str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == ""
    assert json.loads(out)["position_offset"] == saved
    x = np.loadtxt(tmp_path / "x.csv", delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.displacement, x) >= 99.0
    rc, out, err = run(capsys, "predict", str(model), str(folder / "earthquake.csv"),
                       "--predict", "force", "--out", str(tmp_path / "f.csv"))
    assert rc == 0 and err == ""
    assert "position offset 2.99" in out  # the output says which zero it took
    f = np.loadtxt(tmp_path / "f.csv", delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.force, f) >= 99.0


def test_a_piezo_record_cut_from_a_run_gets_its_link_state_from_the_window(capsys, tmp_path,
                                                                           saved_piezo):
    """The later half of the held-out earthquake starts loaded: --init-from sets the Bouc-Wen
    link's state (and the first velocity) from the first 20 samples, not the sensor zero
    alone (that gave 83 % with a warning; now 98.2 %, no warning)."""
    model = saved_piezo
    _, later = piezo_record("earthquake", seed=2).split(0.5)
    later.write(tmp_path / "later.csv")
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "later.csv"),
                       "--init-from", str(tmp_path / "later.csv"), "--out",
                       str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == ""
    got = json.loads(out)
    assert got["initial_state"]["position"] == pytest.approx(PIEZO_OUTPUT_OFFSET, abs=1e-7)
    assert len(got["initial_state"]["link_state"]) == 1
    x = np.loadtxt(tmp_path / "x.csv", delimiter=",", skiprows=1)[20:, 1]
    assert fit_percent(later.displacement[20:], x) >= 95.0
    assert got["fit_percent"] == pytest.approx(fit_percent(later.displacement[20:], x))


def test_records_without_a_relation_between_force_and_position_are_refused(capsys, tmp_path):
    # force and position independent noise: no quasi-static model predicts the position
    rng = np.random.default_rng(3)
    t = np.arange(400) / 100.0
    record = tmp_path / "noise.csv"
    np.savetxt(record, np.column_stack([t, rng.standard_normal(400),
                                        1e-3 * rng.standard_normal(400)]),
               delimiter=",", header="time,force,displacement", comments="")
    model = tmp_path / "m.toml"
    rc, out, err = run(capsys, "identify", str(record), "--record", "input-output", "--plant",
                       "quasi-static", "--model", "jenkins", "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert ("the fit failed" in err or "no stiffness" in err) and not model.exists()


@pytest.fixture(scope="module", params=["dahl", "lugre"])
def logged_damper(request, tmp_path_factory):
    """A damper of another link, as its test machine logs it: sines to identify from, an
    earthquake history held out (its displacement only for predict)."""
    name = request.param
    folder = tmp_path_factory.mktemp(name)
    train = damper_record("sines", seed=3, fs=100.0, seconds=30.0, link=name)
    held_out = damper_record("earthquake", seed=4, fs=100.0, seconds=30.0, link=name)
    return (name, train.write_as_logged(folder / "sines.csv", seed=5),
            held_out.write_as_logged(folder / "earthquake.csv", seed=6, force=False), held_out)


def test_a_damper_elements_do_not_describe_is_refused_and_its_link_model_predicts(
        capsys, tmp_path, logged_damper):
    name, train, displacement, held_out = logged_damper
    model = tmp_path / "damper.toml"
    # Maxwell-slip elements alone: Dahl's loops have no elastic range, LuGre's force rises
    # with the rate; on the earthquake they explain 83 % and 47 % of the force (measured):
    # a refusal, not a model
    rc, out, err = run(capsys, "identify", str(train), *LOGGED, "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "systematic error" in err and not model.exists()
    assert "--model dahl, bouc-wen or lugre" in err
    # the link's own model, with a spring and damper in parallel, by the force's error
    rc, out, err = run(capsys, "identify", str(train), *LOGGED, "--model", name, "--save",
                       str(model), "--json")
    assert rc == 0 and err == ""
    fit = json.loads(out)
    assert fit["output"] == "force" and fit["record"] == "force-displacement"
    assert fit["estimates"]["k"] == pytest.approx(DAMPER_PLANT.k, rel=0.02)
    assert fit["estimates"]["link.fc"] == pytest.approx(DAMPER_LINKS[name].fc, rel=0.01)
    assert fit["fit_rms"] < 1.5 * DAMPER_NOISE
    # the load cell's zero, less the spring's force at the displacement sensor's zero
    assert fit["estimates"]["input_offset"] == pytest.approx(
        DAMPER_FORCE_OFFSET - DAMPER_PLANT.k * 1e-4, abs=3.0)
    force = tmp_path / "force.csv"
    rc, out, err = run(capsys, "predict", str(model), str(displacement), "--columns",
                       "time=Time (s),displacement=LVDT_mm", "--scale", "displacement=1e-3",
                       "--out", str(force))
    assert rc == 0 and err == ""
    predicted = np.loadtxt(force, delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.force, predicted) > 97.0


def test_a_lugre_damper_s_stribeck_curve_is_found():
    """The force fit of a LuGre link finds the Stribeck drop from static to Coulomb force
    (3.5 to 2.5 kN over 10 mm/s), not the local minimum that loses it (``fs`` or ``vs`` run
    to 0, a constant Coulomb force: a systematic error of 3.1 % of the force's RMS, refused,
    from the starts whose Stribeck velocity was a tenth of the record's velocity RMS)."""
    from motionhyst.hysteresis import LuGre
    from motionhyst.identify.io_link_force import identify_link_force
    from motionhyst.identify.io_records import IORecord

    true = DAMPER_LINKS["lugre"]
    record = damper_record("sines", seed=1, fs=100.0, seconds=30.0, link="lugre")
    fit = identify_link_force([IORecord(record.t, record.force, record.displacement)], LuGre)
    est = fit.estimates
    assert est["link.fs"] == pytest.approx(true.fs, rel=0.02)
    assert est["link.vs"] == pytest.approx(true.vs, rel=0.05)
    assert est["link.fc"] == pytest.approx(true.fc, rel=0.01)
    assert est["link.sigma0"] == pytest.approx(true.sigma0, rel=0.03)
    assert est["k"] == pytest.approx(DAMPER_PLANT.k, rel=0.02)
    # the damper in parallel holds the link's viscous friction sigma2
    assert est["c"] == pytest.approx(true.sigma2, rel=0.02)
    assert fit.fit_rms < 1.1 * DAMPER_NOISE
    assert not any("Stribeck" in line for line in fit.warnings)  # one it holds: no warning


def _neighbour(name: str, i: int):
    """The damper of ``DAMPER_LINKS[name]`` and its spring with each true parameter (a Dahl
    link's exponent aside) times a draw from U(0.9, 1.1): a neighbour record's truth."""
    from motionhyst.plants import QuasiStatic

    rng = np.random.default_rng(1000 + i)
    true = DAMPER_LINKS[name]
    varied = {p.name: getattr(true, p.name) * rng.uniform(0.9, 1.1)
              for p in type(true).parameters if p.name != "alpha"}
    return QuasiStatic(k=DAMPER_PLANT.k * rng.uniform(0.9, 1.1)), type(true)(**varied)


@pytest.mark.parametrize(("name", "i"), [("dahl", 1), ("dahl", 2), ("lugre", 1), ("lugre", 2)])
def test_the_link_force_searches_find_neighbour_records(name, i):
    """The searches of the Dahl and LuGre dampers' force fits find the truth on neighbour
    records too (another noise, every true parameter within 10 %), not only on the records
    the tests above were written on (the LuGre search had ended in a local minimum on one
    machine).  Measured on ten neighbours of each (sines, by the force's error; the CLI's
    logged files for Dahl and LuGre, the plain record for LuGre's Stribeck curve): 10/10
    each, spring within 0.6 %, fc within 0.2 %, LuGre's fs within 0.6 %, vs within 1 %."""
    from motionhyst.identify.io_link_force import identify_link_force
    from motionhyst.identify.io_records import IORecord

    plant, true = _neighbour(name, i)
    record = damper_record("sines", seed=1 + 10 * i, fs=100.0, seconds=30.0, link=true,
                           plant=plant)
    fit = identify_link_force([IORecord(record.t, record.force, record.displacement)],
                              type(true))
    est = fit.estimates
    assert est["k"] == pytest.approx(plant.k, rel=0.02)
    assert est["link.fc"] == pytest.approx(true.fc, rel=0.01)
    if name == "lugre":
        assert est["link.fs"] == pytest.approx(true.fs, rel=0.02)
        assert est["link.vs"] == pytest.approx(true.vs, rel=0.05)
        assert est["link.sigma0"] == pytest.approx(true.sigma0, rel=0.03)
        assert est["c"] == pytest.approx(true.sigma2, rel=0.02)
    else:
        assert est["link.k"] == pytest.approx(true.k, rel=0.03)
    assert fit.fit_rms < 1.1 * DAMPER_NOISE


def test_a_piezo_that_creeps_beyond_the_model_is_refused(capsys, tmp_path):
    # creep of 20 % of the spring's displacement: the model fitted to the sines explained 90 %
    # of a held-out history (measured); its systematic error on the sines is 3.4 % (measured)
    record = piezo_record("sines", seed=1, creep=0.2).write(tmp_path / "creep.csv")
    model = tmp_path / "piezo.toml"
    rc, out, err = run(capsys, "identify", str(record), "--record", "input-output", "--plant",
                       "quasi-static", "--model", "bouc-wen", "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "systematic error" in err and "creep" in err and not model.exists()
    assert err.startswith(f"motionhyst: error: {record}: the fit failed")  # the record named


def test_a_sensor_whose_sign_is_reversed_is_named(capsys, tmp_path):
    """A displacement sensor mounted the other way round (piezo: position falls as the force
    rises), a load cell wired reversed (damper): one line that says so, nothing saved; the
    gain -1 it suggests gives the model back."""
    piezo = piezo_record("sines", seed=1)
    flipped = tmp_path / "piezo.csv"
    np.savetxt(flipped, np.column_stack([piezo.t, piezo.force, -piezo.displacement]),
               delimiter=",", header="time,force,displacement", comments="")
    model = tmp_path / "m.toml"
    rc, out, err = run(capsys, "identify", str(flipped), "--record", "input-output",
                       "--plant", "quasi-static", "--model", "bouc-wen", "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "sign reversed" in err and "--scale displacement=-1" in err and not model.exists()
    damper = damper_record("sines", seed=1)
    reversed_cell = tmp_path / "damper.csv"
    np.savetxt(reversed_cell, np.column_stack([damper.t, damper.displacement, -damper.force]),
               delimiter=",", header="time,displacement,force", comments="")
    rc, out, err = run(capsys, "identify", str(reversed_cell), "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "sign reversed" in err and "--scale force=-1" in err and not model.exists()
    rc, out, err = run(capsys, "identify", str(reversed_cell), "--scale", "force=-1",
                       "--elements", "4", "--json")
    assert rc == 0 and err == ""
    assert json.loads(out)["offset"] == pytest.approx(DAMPER_FORCE_OFFSET, abs=5.0)


def test_a_damper_whose_spring_stiffens_still_predicts(capsys, tmp_path):
    """Its spring 20 % stiffer at the end of each record than at the start (no model here
    has that): the model saved from the sines, accepted, predicts the earthquake's force to
    >= 95 % (measured 99.2 %)."""
    train = damper_record("sines", seed=1, stiffening=0.2).write(
        tmp_path / "sines.csv", ("time", "displacement", "force"))
    held_out = damper_record("earthquake", seed=2, stiffening=0.2)
    held_out.write(tmp_path / "quake.csv", ("time", "displacement"))
    model = tmp_path / "m.toml"
    rc, _, err = run(capsys, "identify", str(train), "--save", str(model))
    assert rc == 0 and err == ""
    force = tmp_path / "f.csv"
    rc, _, err = run(capsys, "predict", str(model), str(tmp_path / "quake.csv"), "--out",
                       str(force))
    assert rc == 0 and err == ""
    predicted = np.loadtxt(force, delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.force, predicted) >= 95.0


def test_a_piezo_whose_bouc_wen_exponent_is_not_one_still_predicts(capsys, tmp_path):
    """Its link's exponent 1.5 where the quasi-static plant's fit keeps 1: accepted, the
    model predicts the held-out earthquake history to >= 95 % (measured 97.3 %)."""
    piezo_record("sines", seed=1, exponent=1.5).write(tmp_path / "sines.csv")
    held_out = piezo_record("earthquake", seed=2, exponent=1.5)
    held_out.write(tmp_path / "quake.csv")
    held_out.write(tmp_path / "quake_force.csv", ("time", "force"))
    model = tmp_path / "piezo.toml"
    rc, _, err = run(capsys, "identify", str(tmp_path / "sines.csv"), "--record",
                     "input-output", "--plant", "quasi-static", "--model", "bouc-wen",
                     "--save", str(model))
    assert rc == 0 and err == ""
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "quake_force.csv"),
                       "--init-from", str(tmp_path / "quake.csv"), "--out",
                       str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == ""
    assert json.loads(out)["fit_percent"] >= 95.0


def test_a_model_the_record_does_not_determine_is_refused_and_not_saved(capsys, tmp_path):
    """64 samples of a linear mass-spring-damper (no hysteresis) and five Maxwell-slip
    elements: the record determines 2 of the model's 13 parameters; a model of search values
    that predicts nothing else is a one-line refusal, nothing saved (it was exit 0).  The
    linear stage explains the record within its noise (1e-8 m), so the link never slips in it:
    refused before the search."""
    rng = np.random.default_rng(1)
    t = np.arange(64) * 1e-2
    u = 100.0 * rng.standard_normal(t.size)
    _, y, _ = signal.lsim(signal.lti([1.0], [2.0, 20.0, 2e4]), u, t)  # m, c, k
    record = tmp_path / "short.csv"
    np.savetxt(record, np.column_stack([t, u, y + 1e-8 * rng.standard_normal(t.size)]),
               delimiter=",", header="time,force,displacement", comments="")
    model = tmp_path / "m.toml"
    rc, out, err = run(capsys, "identify", str(record), "--record", "input-output",
                       "--model", "maxwell-slip", "--elements", "5", "--save", str(model))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert "the link never slips in these records" in err and "noise 1e-08 m" in err
    assert "k 2e+04 N/m" in err and err.rstrip().endswith("nothing identified")
    assert not model.exists()


def test_force_displacement_records_of_one_damper_are_fitted_together(capsys, tmp_path):
    """Two histories of one damper: one link from both (it was refused), which predicts a
    third history's force."""
    files = []
    for i, history in enumerate(("sines", "earthquake")):
        rec = damper_record(history, seed=10 + i, fs=100.0, seconds=20.0)
        files.append(str(rec.write(tmp_path / f"{history}.csv",
                                   ("time", "displacement", "force"))))
    held_out = damper_record("earthquake", seed=12, fs=100.0, seconds=20.0)
    held_out.write(tmp_path / "quake.csv", ("time", "displacement"))
    model = tmp_path / "damper.toml"
    rc, out, err = run(capsys, *["identify", *files], "--save", str(model))
    assert rc == 2 and "give their link with --model" in err and not model.exists()
    rc, out, err = run(capsys, *["identify", *files], "--model", "maxwell-slip", "--elements",
                       "3", "--save", str(model), "--json")
    assert rc == 0 and err == "", err
    fit = json.loads(out)
    assert fit["data"] == files and len(fit["records"]) == 2
    assert sorted(fit["estimates"][f"link.fc[{i}]"] for i in range(3)) == pytest.approx(
        sorted(DAMPER_LINK.fc), rel=0.03)
    assert fit["estimates"]["k"] == pytest.approx(DAMPER_PLANT.k, rel=0.03)
    force = tmp_path / "force.csv"
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "quake.csv"), "--out",
                       str(force))
    assert rc == 0 and err == ""
    predicted = np.loadtxt(force, delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.force, predicted) >= 95.0


def test_a_piezo_logged_in_micrometres_and_millinewtons_predicts(capsys, tmp_path):
    """A logger's file: its own column names, force in mN, displacement in um; read with
    --columns and --scale, the model predicts a held-out history (measured 99.93 %)."""
    piezo_record("sines", seed=1).write_in_units(tmp_path / "sines.csv")
    piezo_record("earthquake", seed=2).write_in_units(tmp_path / "quake.csv")
    units = ["--columns", "time=t_s,force=F_mN,displacement=x_um", "--scale",
             "force=1e-3,displacement=1e-6"]
    model = tmp_path / "piezo.toml"
    rc, _, err = run(capsys, "identify", str(tmp_path / "sines.csv"), *units, "--record",
                     "input-output", "--plant", "quasi-static", "--model", "bouc-wen",
                     "--save", str(model))
    assert rc == 0 and err == "", err
    # the force in from the logged file, its measured position compared (the same units)
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "quake.csv"),
                       "--init-from", str(tmp_path / "quake.csv"), *units, "--out",
                       str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == "", err
    assert json.loads(out)["fit_percent"] >= 99.0


def test_a_damper_earthquake_with_a_drifting_actuator_is_predicted(capsys, tmp_path):
    """An earthquake history whose actuator drifts 4 mm over the record (a residual
    displacement at its end): the model saved from sines predicts its force (measured
    99.35 %)."""
    train = damper_record("sines", seed=1).write(tmp_path / "sines.csv",
                                                 ("time", "displacement", "force"))
    held_out = damper_record("earthquake", seed=2, drift=0.004)
    held_out.write(tmp_path / "quake.csv", ("time", "displacement"))
    model = tmp_path / "damper.toml"
    rc, _, err = run(capsys, "identify", str(train), "--elements", "4", "--save", str(model))
    assert rc == 0 and err == "", err
    force = tmp_path / "force.csv"
    rc, _, err = run(capsys, "predict", str(model), str(tmp_path / "quake.csv"), "--out",
                     str(force))
    assert rc == 0 and err == "", err
    predicted = np.loadtxt(force, delimiter=",", skiprows=1)[:, 1]
    assert fit_percent(held_out.force, predicted) >= 98.0


def test_a_piezo_with_a_little_creep_is_accepted_and_predicts(capsys, tmp_path):
    """Creep of 3 % of the spring's displacement (the quasi-static plant has none): within
    what the model describes; held out, predicted to >= 95 % (measured 98.45 %). At 20 % it
    is a refusal (above)."""
    piezo_record("sines", seed=1, creep=0.03).write(tmp_path / "sines.csv")
    held_out = piezo_record("earthquake", seed=2, creep=0.03)
    held_out.write(tmp_path / "quake.csv")
    held_out.write(tmp_path / "quake_force.csv", ("time", "force"))
    model = tmp_path / "piezo.toml"
    rc, _, err = run(capsys, "identify", str(tmp_path / "sines.csv"), "--record",
                     "input-output", "--plant", "quasi-static", "--model", "bouc-wen",
                     "--save", str(model))
    assert rc == 0 and err == "", err
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "quake_force.csv"),
                       "--init-from", str(tmp_path / "quake.csv"), "--out",
                       str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == "", err
    assert json.loads(out)["fit_percent"] >= 95.0


def test_a_piezo_bouc_wen_exponent_is_estimated_with_nu_free(capsys, tmp_path):
    """--nu free on the quasi-static plant (it was refused): the exponent 1.5 comes back,
    the fit reaches the noise, and the held-out history is predicted to >= 99 % (with the
    exponent kept at 1: 97.3 %)."""
    piezo_record("sines", seed=1, seconds=1.0, exponent=1.5).write(tmp_path / "sines.csv")
    held_out = piezo_record("earthquake", seed=2, seconds=1.0, exponent=1.5)
    held_out.write(tmp_path / "quake.csv")
    held_out.write(tmp_path / "quake_force.csv", ("time", "force"))
    model = tmp_path / "piezo.toml"
    rc, out, err = run(capsys, "identify", str(tmp_path / "sines.csv"), "--record",
                       "input-output", "--plant", "quasi-static", "--model", "bouc-wen",
                       "--nu", "free", "--save", str(model), "--json")
    assert rc == 0, err
    fit = json.loads(out)
    assert fit["estimates"]["link.n"] == pytest.approx(1.5, abs=0.01)
    assert fit["std"]["link.n"] < 0.01
    assert fit["fit_rms"] < 1.5 * PIEZO_NOISE
    assert Scenario.from_file(model).open_loop().hysteresis.n == pytest.approx(1.5, abs=0.01)
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "quake_force.csv"),
                       "--init-from", str(tmp_path / "quake.csv"), "--out",
                       str(tmp_path / "x.csv"), "--json")
    assert rc == 0 and err == "", err
    assert json.loads(out)["fit_percent"] >= 99.0
