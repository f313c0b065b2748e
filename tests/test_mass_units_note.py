"""The unit a mass outside a motion stage's points to is named only where the records read in
SI are unlike a stage's as a whole (review C12 L3: a genuine 0.5 g stage, sampled at 1 kHz,
moving 5 mm under 8 mN, was asked whether its position was in mm or its force in kN)."""

from __future__ import annotations

import limited_process
import numpy as np
from file_trees import populate, snapshot
from test_bad_inputs_one_stage import _axis, _csv

from motionhyst import Jenkins
from motionhyst.identify.io_checks import check_inertia
from motionhyst.identify.io_consistency import mass_units_note
from motionhyst.identify.io_records import IORecord

GENERIC = ("if the records' units are not SI, scale them (--scale; time in ms makes the mass "
           "1e6 times too large, a position in mm or a force in kN 1e3 times too small)")


def _light():
    """A 0.5 g stage (0.01 N s/m, its link 2 N/m, 1 mN) under 5 and 3 mN at 13 and 41 Hz."""
    return _axis(5e-4, 0.01, Jenkins(k=2.0, fc=1e-3), noise=1e-9, name="light.csv",
                 force=lambda t: 5e-3 * np.sin(2 * np.pi * 13 * t)
                 + 3e-3 * np.sin(2 * np.pi * 41 * t + 0.4))


def test_a_light_stage_is_told_no_unit():
    light = _light()
    mass = check_inertia([light])
    assert abs(mass - 5e-4) < 0.1 * 5e-4
    assert mass_units_note([light], mass) == (
        f"light.csv: the records' inverse-dynamics mass is {mass:.3g} kg, outside the usual "
        f"0.001-10000 kg of motion stages: {GENERIC}")


def test_a_position_in_um_is_named_by_its_range():
    """A 2 kg axis moving 7.6 cm, its position in um: 1.99e-6 kg and a range of 76 km; mm
    would make the mass usual (2 g) but not the range (76 m): um is named."""
    stage = _axis()
    um = IORecord(stage.t, stage.u, 1e6 * stage.y, "um.csv")
    assert mass_units_note([um], check_inertia([um])) == (
        "um.csv: the records' inverse-dynamics mass is 1.99e-06 kg, outside the usual "
        "0.001-10000 kg of motion stages: is the position in um (a range of 7.63e+04 m)? "
        "--scale displacement=1e-6 makes it 1.99 kg")


def test_a_heavy_stage_s_force_in_mn_is_named_by_its_peak():
    stage = _axis(95.0, 200.0, force=lambda t: 400 * np.sin(2 * np.pi * 1.3 * t))
    mn = IORecord(stage.t, 1e3 * stage.u, stage.y, "mN.csv")
    note = mass_units_note([mn], 1e3 * check_inertia([stage]))
    assert note.endswith("is the force in mN (a peak of 4.03e+05 N)? --scale force=0.001 makes "
                         "it 95 kg"), note


def test_the_command_warns_a_light_stage_without_naming_a_unit(tmp_path):
    """Main: "is the position in mm or the force in kN? --scale displacement=0.001 or
    force=1000 makes it 0.549 kg"; the search then runs (here to its budget of a second, or
    to its end on a fast machine: only the warning is asserted)."""
    populate(tmp_path, {"light.csv": _csv(_light())})
    before = snapshot(tmp_path)
    code, _, err = limited_process.run(["identify", "light.csv", "--record", "input-output",
                                        "--plant", "mass-damper", "--max-seconds", "1"],
                                       tmp_path)
    lines = err.strip().splitlines()
    assert code in (0, 2) and snapshot(tmp_path) == before, err
    assert lines[0] == ("motionhyst: warning: identify: light.csv: the records' inverse-"
                        "dynamics mass is 0.000549 kg, outside the usual 0.001-10000 kg of "
                        f"motion stages: {GENERIC}"), err
