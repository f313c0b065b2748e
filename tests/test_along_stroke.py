"""Tests of links whose parameters vary along the stroke (hysteresis/along_stroke.py), in the
time simulation, the scenario, the scan and its model feedforward."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import FC_LINK, K_LINK
from numpy.testing import assert_allclose, assert_array_equal

from motionhyst import Jenkins, Loop, MaxwellSlip, simulate
from motionhyst.cli import main as cli_main
from motionhyst.core.textfiles import toml_table
from motionhyst.hysteresis.along_stroke import STEPS_PER_INTERVAL, AlongStroke
from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import run_scan
from motionhyst.scenario import Scenario, ScenarioError, default_scenario
from motionhyst.time.simulation import simulate_chunks

FAST = dict(speed=0.5, a_max=20.0, j_max=2000.0, s_max=4e5, start=0.01)
TABLE = ([0.0, 0.05, 0.1], {"fc": [1.2, 0.7, 1.1], "k": [1.0, 0.8, 1.3]})


def test_unit_scales_are_the_base_link_in_time(stage, controller):
    p = scan(0.02, **FAST)
    base = simulate(Loop(stage, controller, Jenkins(K_LINK, FC_LINK)), p, p.end + 0.01)
    along = AlongStroke(Jenkins(K_LINK, FC_LINK), [0.0, 0.1], {"fc": [1.0, 1.0]})
    run = simulate(Loop(stage, controller, along), p, p.end + 0.01,
                   force=lambda t: 0.01 * np.sin(50 * t))
    ref = simulate(Loop(stage, controller, Jenkins(K_LINK, FC_LINK)), p, p.end + 0.01,
                   force=lambda t: 0.01 * np.sin(50 * t))
    assert_array_equal(run.e, ref.e)  # the run in pieces is the run in one
    assert np.max(np.abs(run.e - base.e)) > 0


def test_slipping_link_follows_its_slip_force_along_the_stroke(stage, controller):
    # paper eq. (3) with fc(x): slipping at constant velocity the link force is fc(r), and
    # the loop without integrator holds e = fc(r) / C(0)
    link = AlongStroke(Jenkins(K_LINK, FC_LINK), *TABLE)
    p = scan(0.1, **FAST)
    sim = simulate(Loop(stage, controller, link), p, p.end)
    cv = p.constant_velocity_phases()[0]
    sel = (sim.t > cv.start + 0.01) & (sim.t < cv.end)
    fc = np.array([link.at(x).fc for x in sim.r[sel]])
    assert np.ptp(fc) > 0.35 * FC_LINK
    # the parameters are held over 1/STEPS_PER_INTERVAL of the table's spacing
    held = 0.5 * np.max(np.abs(np.diff(TABLE[1]["fc"]))) * FC_LINK / STEPS_PER_INTERVAL
    assert np.max(np.abs(sim.w[sel] - fc)) < 1.5 * held
    # the error the link causes (the run's less the linear loop's): w / C(0), within the
    # pieces' holding (1 %) and the loop's lag behind a changing force
    assert_allclose((sim.e - sim.e_linear)[sel], fc / 6.2e6, rtol=0.02)


def test_response_sticks_with_the_local_stiffness_and_slips_at_the_local_force():
    link = AlongStroke(Jenkins(K_LINK, FC_LINK), *TABLE)
    x = np.linspace(0.0, 0.1, 20001)
    w = link.response(x)
    fc = np.array([link.at(v).fc for v in x])
    slipping = x > 0.01
    held = 0.5 * 0.5 * FC_LINK / STEPS_PER_INTERVAL  # half the change over a held piece
    assert np.max(np.abs(w[slipping] - fc[slipping])) < 1.01 * held
    back = np.concatenate([x, x[-1] - np.linspace(0.0, 1e-3, 101)[1:]])
    wb = link.response(back)
    k_mid = link.at(0.1 - 0.5e-3).k  # k(x) over the millimetre back, linear in x
    assert wb[-1] == pytest.approx(w[-1] - k_mid * 1e-3, rel=1e-3)  # stuck: dw = k(x) dx
    parallel = AlongStroke(MaxwellSlip([10.0, 5.0], [0.02, 0.03]), [0.0, 0.1], {"fc": [1.0, 2.0]})
    # both elements slip: 0.05 N scaled by 2 at the end, within half a held piece's change
    assert parallel.response(x)[-1] == pytest.approx(0.1, abs=0.5 * 0.05 / STEPS_PER_INTERVAL)


@pytest.mark.parametrize(("args", "message"), [
    (([0.0], {"fc": [1.0]}), "at least two"),
    (([0.0, 0.1], {"c": [1.0, 1.0]}), "not a parameter"),
    (([0.0, 0.1], {"fc": [1.0, -1.0]}), "positive"),
    (([0.1, 0.0], {"fc": [1.0, 1.0]}), "increasing"),
])
def test_invalid_tables(args, message):
    with pytest.raises(ValueError, match=message):
        AlongStroke(Jenkins(K_LINK, FC_LINK), *args)


def _scenario(along_model: bool):
    d = default_scenario().to_dict()
    table = {"position": TABLE[0], **TABLE[1]}
    d["hysteresis"]["along"] = table
    model = {"model": "jenkins", "k": 1.04 * K_LINK, "fc": 1.04 * FC_LINK}
    d["feedforward"] = {"type": "rigid-body", "snap": "plant",
                        "hysteresis": {**model, **({"along": table} if along_model else {})}}
    return Scenario.from_dict(d, "s.toml")


def test_scenario_along_round_trips_and_errors_are_one_line():
    sc = _scenario(True)
    assert isinstance(sc.loop().hysteresis, AlongStroke)
    again = Scenario.from_dict(sc.to_dict(), "again.toml")
    assert again.loop().hysteresis.scales["fc"].tolist() == TABLE[1]["fc"]
    d = default_scenario().to_dict()
    d["hysteresis"]["along"] = {"fc": [1.0, 1.0]}
    with pytest.raises(ScenarioError, match="position"):
        Scenario.from_dict(d, "s.toml")
    d["hysteresis"]["along"] = {"position": [0.0, 0.1], "fc": [1.0]}
    with pytest.raises(ScenarioError, match="scales of fc"):
        Scenario.from_dict(d, "s.toml")


def test_a_single_parameter_model_misses_what_the_table_gives():
    # over a scan where fc varies +-25 %, the model 4 % off but without the table leaves
    # the variation; with the table it leaves its 4 %; basis learns one scale per
    # parameter without the table, the table's shape with it
    p = scan(0.1, **FAST)
    single = run_scan(_scenario(False).loop(), p, 0.01, ("none", "model"))
    table = run_scan(_scenario(True).loop(), p, 0.01, ("none", "model", "basis"),
                     basis_trials=3)
    none = single.run("none").ma_max
    assert none / single.run("model").ma_max < 15
    assert none / table.run("model").ma_max > 40
    assert table.run("basis").ma_max < table.run("model").ma_max / 10


def test_cli_scan_at_a_stroke_position(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text("".join(toml_table(name, sec) for name, sec in
                            _scenario(True).to_dict().items()))
    # a gentle scan: the slipping link's e = fc(r) / C(0) dominates MA, largest where the
    # scan starts on the table (1.2 falling) and where it ends from 0.06 on (0.7 rising)
    short = ["--length", "0.03", "--speed", "0.05", "--a-max", "2", "--j-max", "50",
             "--s-max", "1000", "--window", "0.02", "--tail", "0.0", "--compensation", "none"]
    link = _scenario(True).loop().hysteresis
    for at in (0.0, 0.06):
        assert cli_main(["scan", str(path), *short, "--at", str(at), "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        ma = d["results"][0]["ma_max"]
        xs = at + np.linspace(0.001, 0.033, 200)  # the scan's positions, ramps included
        assert ma == pytest.approx(max(link.at(x).fc for x in xs) / 6.2e6, rel=0.03)
    assert cli_main(["scan", *short, "--at", "0.1"]) == 2
    assert "along" in capsys.readouterr().err


def test_sampled_loop_in_pieces_with_unit_scales_is_the_base_link_run():
    # the sampled run of a link along the stroke is run in its pieces (the parameters set
    # between them): with unit scales, the run of the base link in one, sample for sample
    # (tests/test_along_stroke_routes.py: a varying table against the continuous run)
    d = Scenario.from_file("examples/paper_10khz.toml").to_dict()
    base = simulate(Scenario.from_dict(d, "s.toml").loop(), scan(0.05, **FAST), 0.2)
    d["hysteresis"]["along"] = {"position": TABLE[0], "fc": [1.0, 1.0, 1.0]}
    along = simulate(Scenario.from_dict(d, "s.toml").loop(), scan(0.05, **FAST), 0.2)
    assert len(AlongStroke(Jenkins(K_LINK, FC_LINK), TABLE[0], {}).pieces(along.r)) > 50
    for c in ("e", "u", "w", "y1"):
        assert_array_equal(getattr(along, c), getattr(base, c))


def test_chunks_of_a_run_along_the_stroke_are_the_run(stage, controller):
    # simulate_chunks (the CLI's time series) splits the link's pieces at its chunks' ends:
    # the parameters are held over shorter stretches, the run is the same to the holding
    link = AlongStroke(Jenkins(K_LINK, FC_LINK), *TABLE)
    loop = Loop(stage, controller, link)
    p = scan(0.05, **FAST)
    whole = simulate(loop, p, p.end)
    pieces = list(simulate_chunks(loop, p, p.end, chunk=1000))
    e = np.concatenate([c.e for c in pieces])
    assert len(pieces) > 5 and e.shape == whole.e.shape
    assert np.max(np.abs(e - whole.e)) < 2e-3 * np.max(np.abs(whole.e))
    hff = Loop(stage, controller, link, hysteresis_feedforward=link)
    with pytest.raises(ValueError, match="by scan"):
        next(simulate_chunks(hff, p, p.end))
