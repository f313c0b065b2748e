"""identify on a positioning axis whose viscous friction differs by direction (EMPS: c+ 163,
c- 240 N s/m): the records' inverse dynamics says so in one warning line naming c+ and c- (a
symmetric fit's mass is biased), and by default the fit then has a coefficient per direction
(--symmetric: one); a symmetric axis gets no such line and one coefficient."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.hysteresis import Coulomb
from motionhyst.identify.input_output import IORecord
from motionhyst.identify.io_checks import viscous_direction_note
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

FS = 1000.0


def _axis_record(c_pos: float, c_neg: float, n: int = 4000, bias: float = 0.0) -> IORecord:
    """A mass-damper with Coulomb friction driven by a force, position measured (noise 1 um);
    with a `bias` of the force it moves mostly forward, turning and sticking briefly."""
    t = np.arange(n) / FS
    u = bias + 200 * np.sin(2 * np.pi * 0.6 * t) + 80 * np.sin(2 * np.pi * 1.7 * t + 0.3)
    if bias:
        u = bias + 90 * np.sin(2 * np.pi * 0.6 * t) + 40 * np.sin(2 * np.pi * 1.7 * t + 0.3)
    axis = OpenLoop(MassDamper.by_direction(95.0, c_pos, c_neg, force_offset=3.0),
                    Coulomb(fc=20.0))
    y = axis.simulate(t, u, substeps=20).displacement
    return IORecord(t, u, y + 1e-6 * np.random.default_rng(3).standard_normal(n), "axis")


def test_the_note_names_both_directions_of_an_asymmetric_axis():
    note = viscous_direction_note([_axis_record(163.0, 240.0)])
    assert note is not None and "--asymmetric" in note
    c_pos = float(note.split("c+ ")[1].split()[0])
    c_neg = float(note.split("c- ")[1].split()[0])
    assert c_pos == pytest.approx(163.0, rel=0.05) and c_neg == pytest.approx(240.0, rel=0.05)
    assert viscous_direction_note([_axis_record(200.0, 200.0)]) is None
    # a difference within the stated share of the mean is no finding, however well determined
    assert viscous_direction_note([_axis_record(195.0, 205.0)]) is None
    # moving mostly forward: the brief backward motion, where the axis turns and sticks, says
    # nothing of a backward viscous friction (all samples taken: c- 300-500 N s/m)
    assert viscous_direction_note([_axis_record(200.0, 200.0, bias=30.0)]) is None


@pytest.mark.parametrize(("c_neg", "asymmetric", "warned"), [
    (240.0, False, True), (240.0, True, False), (163.0, False, False)])
def test_identify_warns_without_asymmetric(tmp_path, capsys, c_neg, asymmetric, warned):
    rec = _axis_record(163.0, c_neg)
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="")
    args = ["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
            "--model", "coulomb", "--init-window", "20"] + (["--asymmetric"] * asymmetric)
    assert main(args) == 0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "by direction" in line]
    assert len(lines) == int(warned)
    if warned:
        assert "c+ " in lines[0] and "c- " in lines[0] and "--asymmetric" in lines[0]


def _identify(tmp_path, capsys, rec, *options):
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="")
    code = main(["identify", str(path), "--record", "input-output", "--plant", "mass-damper",
                 "--model", "coulomb", "--json", *options])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if code == 0 else None), err


def test_identify_fits_viscous_friction_by_direction_where_the_records_show_it(tmp_path, capsys):
    """The default on a mass-damper: the records' inverse dynamics shows two viscous
    coefficients, so the fit has them (as --asymmetric) and says so in one line; --symmetric
    fits one, with the warning that its mass is biased; a symmetric axis is fitted with one."""
    code, fit, err = _identify(tmp_path, capsys, _axis_record(163.0, 240.0))
    assert code == 0
    lines = [line for line in err.splitlines() if "by direction" in line]
    assert len(lines) == 1 and "fitted with one viscous coefficient per direction" in lines[0]
    assert "--symmetric" in lines[0]
    est = fit["estimates"]
    assert est["c"] == pytest.approx(163.0, rel=0.01)
    assert est["c"] + est["link.c_neg"] == pytest.approx(240.0, rel=0.01)
    assert est["m"] == pytest.approx(95.0, rel=0.01)
    code, fit, err = _identify(tmp_path, capsys, _axis_record(163.0, 240.0), "--symmetric")
    assert code == 0 and "link.c_neg" not in fit["estimates"]
    lines = [line for line in err.splitlines() if "by direction" in line]
    assert len(lines) == 1 and "a fit with one viscous coefficient biases the mass" in lines[0]
    code, fit, err = _identify(tmp_path, capsys, _axis_record(200.0, 200.0))
    assert code == 0 and "by direction" not in err
    assert not {"link.c_pos", "link.c_neg", "c_skew"} & set(fit["estimates"])


@pytest.mark.parametrize(("options", "message"), [
    (["--asymmetric", "--symmetric"], "--asymmetric and --symmetric exclude each other"),
    (["--symmetric", "--plant", "mass-spring-damper"], "--symmetric applies to --plant "
                                                        "mass-damper"),
])
def test_symmetric_refusals(tmp_path, capsys, options, message):
    rec = _axis_record(163.0, 240.0, n=500)
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="")
    args = ["identify", str(path), "--record", "input-output", "--model", "coulomb", *options]
    if "--plant" not in options:
        args += ["--plant", "mass-damper"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
