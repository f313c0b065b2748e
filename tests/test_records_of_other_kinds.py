"""Records of machines without visible inertia: identified, saved, predicted on held-out parts.

A friction damper (displacement imposed, force measured) and a piezo stack (force in,
displacement out), generated with known parameters, offsets and noise
(:mod:`records_of_other_kinds`): the model identified on one history must predict another
(fit >= 95 %), through the commands a user runs; what cannot be predicted is a one-line
refusal.
"""

from __future__ import annotations

import numpy as np
import pytest
from records_of_other_kinds import (
    DAMPER_FORCE_OFFSET,
    DAMPER_LINK,
    damper_record,
    fit_percent,
)

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
