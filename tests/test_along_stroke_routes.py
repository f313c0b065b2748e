"""Every route of a link along the stroke (hysteresis/along_stroke.py) for every link model:
the exact periodic steady state (continuous and sampled loop) against runs in time, the
sampled loop's run following the table against the continuous run, and the routes that need
the describing function refused in one line naming ``[hysteresis] along``."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from conftest import FC_LINK, K_LINK

from motionhyst import Loop, periodic_steady_state, simulate
from motionhyst.analysis.comparison import compare_with_describing_function
from motionhyst.analysis.floquet import steady_state_floquet
from motionhyst.analysis.quasilinear import loop_mismatch
from motionhyst.cli import main as cli_main
from motionhyst.core.textfiles import toml_table
from motionhyst.hysteresis import BoucWen, Coulomb, Dahl, Jenkins, LuGre, MaxwellIwan, MaxwellSlip
from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.scan.profiles import scan
from motionhyst.scenario import Scenario, default_scenario
from motionhyst.time.references import SineReference

A, F = 0.01, 5.0  # the stage spans the whole table below
POSITION = [-A, A]
#: each model with the scales that change its force over the table (4x from end to end)
LINKS = {
    "jenkins": (Jenkins(K_LINK, FC_LINK), {"fc": [0.5, 2.0]}),
    "maxwell-slip": (MaxwellSlip([10.0, 10.0], [0.02, 0.03]), {"fc": [0.5, 2.0]}),
    "dahl": (Dahl(K_LINK, FC_LINK), {"fc": [0.5, 2.0]}),
    "bouc-wen": (BoucWen(k=K_LINK, fc=FC_LINK), {"fc": [0.5, 2.0]}),
    "lugre": (LuGre(sigma0=1e3, sigma1=100.0, sigma2=0.0, fc=FC_LINK, fs=0.06, vs=0.01),
              {"fc": [0.5, 2.0], "fs": [0.5, 2.0]}),
    "coulomb": (Coulomb(FC_LINK), {"fc": [0.5, 2.0]}),
    "maxwell-iwan": (MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3, kv=[8.0],
                                 cv=[0.4], n_stops=16), {"ki": [0.25, 4.0]}),
}


def _along(name: str) -> AlongStroke:
    base, scales = LINKS[name]
    return AlongStroke(base, POSITION, scales)


def _harmonics_in_time(loop: Loop, periods: int = 6, n: int = 8000) -> np.ndarray:
    """The error's harmonics (complex amplitudes of sin(n theta), as SteadyState.e) over the
    last of `periods` periods of a run from rest with `n` steps a period."""
    sim = simulate(loop, SineReference(A, F), periods / F, dt=1.0 / (F * n))
    e = sim.e[-n - 1:-1]
    return 2j * np.fft.rfft(e)[:8] / n


def steady_is_run(loop: Loop) -> tuple[np.ndarray, complex]:
    """Assert that the loop's exact steady state at ``A sin(2 pi F t)`` is the last of 6
    periods of its run from rest: the link's part of the error, ``e - e_linear``, at
    harmonics 1 and 3 to 2e-3 of it; the run's harmonics and that part returned."""
    ss = periodic_steady_state(loop, A, F)
    run = _harmonics_in_time(loop)
    link_part = ss.e[1] - ss.e_linear[1]
    assert abs(link_part) > 1e-9
    assert abs(ss.e[1] - run[1]) < 2e-3 * abs(link_part)
    assert abs(ss.e[3] - run[3]) < 2e-3 * abs(link_part)
    return run, link_part


@pytest.mark.parametrize("name", list(LINKS))
def test_steady_state_along_the_stroke_is_the_run_in_time(stage, controller, name):
    # the link's part of the error, e - e_linear, at harmonics 1 and 3: the steady state
    # (the table followed at the stage's position) against the last of 6 periods of a run
    # from rest (the table followed at the setpoint, within the tracking error); main gave
    # LuGre's the linear loop's (the link's part 0, where the run has 3.9e-8 m)
    run, link_part = steady_is_run(Loop(stage, controller, _along(name)))
    # the table matters: the base link alone is 10 % or more off
    base = periodic_steady_state(Loop(stage, controller, LINKS[name][0]), A, F)
    assert abs(base.e[1] - run[1]) > 0.1 * abs(link_part)


def test_rate_dependent_link_along_the_stroke_as_feedforward(stage, controller):
    # a LuGre model along the stroke as the feedforward, unit scales: the run and the steady
    # state are those of the LuGre model itself (main ran it without time: no force)
    lugre = LINKS["lugre"][0]
    unit = AlongStroke(lugre, POSITION, {"fc": [1.0, 1.0]})
    link = Jenkins(K_LINK, FC_LINK)
    ref = SineReference(A, F)
    runs = [simulate(Loop(stage, controller, link, hysteresis_feedforward=h), ref, 2 / F)
            for h in (lugre, unit)]
    assert np.max(np.abs(runs[1].e - runs[0].e)) < 1e-3 * np.max(np.abs(runs[0].e))
    states = [periodic_steady_state(Loop(stage, controller, link, hysteresis_feedforward=h),
                                    A, F) for h in (lugre, unit)]
    assert abs(states[1].e[1] - states[0].e[1]) < 1e-6 * abs(states[0].e[1])
    with pytest.raises(ValueError, match="sample times"):
        unit.response(np.linspace(0.0, 0.01, 11))


def _sampled_scenario(rate_hz: float | None, name: str = "jenkins",
                      table: dict | None = None) -> Scenario:
    d = default_scenario().to_dict()
    base, scales = LINKS[name]
    d["hysteresis"] = {**base.to_dict(), "along": table or {"position": POSITION, **scales}}
    if rate_hz is not None:
        d["controller"]["sample_rate_hz"] = rate_hz
        d["feedforward"] = {"type": "rigid-body"}
    return Scenario.from_dict(d, "s.toml")


def test_sampled_run_follows_the_table_as_the_continuous_run():
    # a scan over a table whose fc falls and rises +-25 %: at 50 kHz the sampled loop's link
    # error (e - e_linear) is the continuous loop's to 0.5 % of its peak; the table's first
    # position held (what main ran, silently) is 40 % off
    table = {"position": [0.0, 0.05, 0.1], "fc": [1.2, 0.7, 1.1], "k": [1.0, 0.8, 1.3]}
    p = scan(0.1, speed=0.5, a_max=20.0, j_max=2000.0, s_max=4e5, start=0.01)
    cont = simulate(_sampled_scenario(None, table=table).loop(), p, p.end)
    sampled = simulate(_sampled_scenario(50e3, table=table).loop(), p, p.end)
    ref = np.interp(sampled.t, cont.t, cont.e - cont.e_linear)
    peak = np.max(np.abs(ref))
    assert np.max(np.abs(sampled.e - sampled.e_linear - ref)) < 5e-3 * peak
    d = _sampled_scenario(50e3, table=table).to_dict()
    d["hysteresis"].pop("along")
    d["hysteresis"]["fc"] = 1.2 * FC_LINK
    first = simulate(Scenario.from_dict(d, "b.toml").loop(), p, p.end)
    assert np.max(np.abs(first.e - first.e_linear - ref)) > 0.3 * peak


@pytest.mark.parametrize("name, table", [("jenkins", None), ("lugre", None),
                                         ("jenkins", {"position": POSITION, "k": [0.5, 2.0]})])
def test_sampled_steady_state_along_the_stroke_is_the_sampled_run(name, table):
    # the hybrid loop's steady state against the last of 6 periods of its run in time, at
    # the controller's samples (10 kHz: 2000 a period); a stiffness along the stroke too
    # (the steady state's stops on the integral of k, the run's set at its pieces' ends)
    loop = _sampled_scenario(10e3, name, table).loop()
    ss = periodic_steady_state(loop, A, F)
    sim = simulate(loop, SineReference(A, F), 6 / F)
    n = 2000
    run = 2j * np.fft.rfft(sim.e[-n - 1:-1])[:4] / n
    link_part = ss.e[1] - ss.e_linear[1]
    assert abs(link_part) > 1e-9
    assert abs(ss.e[1] - run[1]) < 2e-3 * abs(link_part)


def _write(tmp_path, sc: Scenario):
    path = tmp_path / "along.toml"
    path.write_text("".join(toml_table(k, v) for k, v in sc.to_dict().items()))
    return path


@pytest.mark.parametrize("name", list(LINKS))
@pytest.mark.parametrize("command", ["steady", "analyze", "stability", "reproduce"])
def test_describing_function_commands_refuse_in_one_line(tmp_path, capsys, name, command):
    path = _write(tmp_path, _sampled_scenario(None, name))
    before = sorted(p.name for p in tmp_path.iterdir())
    args = [command, str(path)] + (["--out", str(tmp_path / "out")] if command == "reproduce"
                                   else [])
    assert cli_main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "[hysteresis] along" in err and "simulate" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


def test_api_routes_of_the_describing_function_refuse(stage, controller):
    link = _along("lugre")
    loop = Loop(stage, controller, link)
    for route in (lambda: link.describing_function(A, 1.0), lambda: link.hosidf(A, 3, 1.0),
                  lambda: loop_mismatch(loop, [F], A),
                  lambda: compare_with_describing_function(loop, A, [F])):
        with pytest.raises(ValueError, match=r"\[hysteresis\] along"):
            route()
    ss = periodic_steady_state(Loop(stage, controller, _along("jenkins")), A, F)
    with pytest.raises(ValueError, match="along the stroke"):
        steady_state_floquet(Loop(stage, controller, _along("jenkins")), ss)


def test_study_of_a_link_along_the_stroke(tmp_path, capsys):
    # its exact steady state is the study's e1 and error_rms; E (the describing function's)
    # is refused before any point runs, nothing written
    sc = _sampled_scenario(None, "lugre")
    path = _write(tmp_path, sc)
    study = tmp_path / "study.toml"
    study.write_text(f'scenario = "{path.name}"\noutputs = ["e1", "error_rms"]\n'
                     f"[axes]\namplitude = [{A}]\nfrequency_hz = [{F}]\n")
    table = tmp_path / "t.csv"
    assert cli_main(["study", str(study), "--out", str(tmp_path / "s.zarr"), "--workers", "0",
                     "--table", str(table)]) == 0
    row = next(csv.DictReader(table.open()))
    ss = periodic_steady_state(sc.loop(), A, F)
    assert float(row["error_rms"]) == pytest.approx(ss.error_rms, rel=1e-9)
    capsys.readouterr()
    study.write_text(study.read_text().replace('"error_rms"', '"E"'))
    assert cli_main(["study", str(study), "--out", str(tmp_path / "e.zarr"), "--workers",
                     "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[hysteresis] along" in err
    assert not (tmp_path / "e.zarr").exists()


def test_a_spring_that_never_slips_scaled_along_the_stroke_is_run():
    # k0 of a Maxwell-Iwan link (a spring in parallel) 0.5x to 2x: held piece by piece its
    # force moved by 3e-4 of its peak every period, and main refused the table as the
    # scenario was read; a stiffness along the stroke is now conservative (its force the
    # integral of k0(x) dx, tests/test_along_stroke_conservative.py): the exact steady state
    # is the last of six periods of a run from rest, the link's part of e1 and e3 to 2e-3
    loop = _sampled_scenario(None, "maxwell-iwan",
                             table={"position": POSITION, "k0": [0.5, 2.0]}).loop()
    assert loop.hysteresis.at(A).k0 == pytest.approx(2.0 * LINKS["maxwell-iwan"][0].k0)
    steady_is_run(loop)


def test_sampled_loop_runs_a_rate_dependent_feedforward_over_its_samples():
    # the controller's LuGre model (plain, or along the stroke with unit scales) integrated
    # over the setpoint's sample times (their integrations converge as the samples resolve
    # the bristles' deflection): the two runs agree and differ from the run without
    # it (main refused the plain model, "response() needs the sample times", and ran the one
    # along the stroke without time: no force)
    lugre = LINKS["lugre"][0].to_dict()
    runs = []
    for ff in (None, lugre, {**lugre, "along": {"position": POSITION, "fc": [1.0, 1.0]}}):
        d = _sampled_scenario(50e3).to_dict()  # 6 um a sample, the bristles' 50 um resolved
        if ff is not None:
            d["feedforward"]["hysteresis"] = ff
        runs.append(simulate(Scenario.from_dict(d, "s.toml").loop(), SineReference(A, F),
                             1 / F))
    none, plain, along = (r.e for r in runs)
    # 0.6 % at 50 kHz, 4.6 % at 10 kHz: the two integrations' difference, shrinking with the
    # sample; a feedforward without force would be 100 % off
    assert np.max(np.abs(along - plain)) < 1e-2 * np.max(np.abs(plain - none))


OPEN_LOOP = {"mass-spring-damper": {"type": "mass-spring-damper", "m": 1.0, "c": 20.0,
                                    "k": 1000.0},
             "quasi-static": {"type": "quasi-static"}}


@pytest.mark.parametrize("stage_kind", list(OPEN_LOOP))
def test_open_loop_systems_refuse_a_link_along_the_stroke(tmp_path, capsys, stage_kind):
    # predict ran the table's first position (a quasi-static Jenkins link over fc 0.5x..2x
    # on [-10, 10] mm: a peak force 0.25 N where the table gives 1 N at 10 mm), exit 0
    link = {"model": "jenkins", "k": 200.0, "fc": 0.5,
            "along": {"position": POSITION, "fc": [0.5, 2.0]}}
    path = tmp_path / "open.toml"
    path.write_text(toml_table("stage", OPEN_LOOP[stage_kind]) + toml_table("hysteresis", link))
    t = np.arange(2001) * 1e-3
    column, values = (("displacement", A * np.sin(2 * np.pi * t)) if stage_kind == "quasi-static"
                      else ("force", 12.0 * np.sin(2 * np.pi * t)))
    record = tmp_path / "in.csv"
    record.write_text(f"time,{column}\n"
                      + "".join(f"{a!r},{b!r}\n" for a, b in zip(t, values, strict=True)))
    before = sorted(p.name for p in tmp_path.iterdir())
    assert cli_main(["predict", str(path), str(record), "--out", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[hysteresis] along" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_open_loop_api_refuses_a_link_along_the_stroke():
    from motionhyst.plants.quasi_static import QuasiStatic
    from motionhyst.time.openloop import OpenLoop
    from motionhyst.time.quasi_static import force_from_displacement

    link = _along("jenkins")
    with pytest.raises(ValueError, match=r"\[hysteresis\] along"):
        OpenLoop(QuasiStatic(), link)
    with pytest.raises(ValueError, match=r"\[hysteresis\] along"):
        force_from_displacement(QuasiStatic(), link, np.arange(11) * 1e-3, np.linspace(0.0, A, 11))


@pytest.mark.parametrize("amplitude", [1e-4, 1e-5])
@pytest.mark.parametrize("name", ["dahl", "bouc-wen"])
def test_a_small_stroke_s_periodic_force_is_the_base_link_s(name, amplitude):
    """At 0.1 mm and 10 um about 2 mm on the table (unit scales) the periodic force is the
    base link's own harmonics: a Dahl or Bouc-Wen link forgets its start from rest slowly
    there (its change shrinks by a steady ratio a period, extrapolated to its limit) and
    the change stops at the run's rounding (settled, not a drift)."""
    from motionhyst.hysteresis.bouc_wen import BoucWen
    from motionhyst.hysteresis.dahl import Dahl

    base = Dahl(20.0, 0.05) if name == "dahl" else BoucWen(20.0, 0.05)
    link = AlongStroke(base, [-0.01, 0.01], {"fc": [1.0, 1.0]})
    X = np.zeros(6, dtype=complex)
    X[0], X[1] = 0.002, amplitude / 2j
    W, ref = link.periodic_harmonics(X, 5), base.periodic_harmonics(X, 5)
    assert np.max(np.abs(W - ref)) <= 1e-9 * np.max(np.abs(ref))


def _feedforward_along(tmp_path) -> Path:
    """Table I with its link plain and the feedforward's model of it along the stroke."""
    d = default_scenario().to_dict()
    base, scales = LINKS["jenkins"]
    d["feedforward"]["hysteresis"] = {**base.to_dict(),
                                      "along": {"position": POSITION, **scales}}
    return _write(tmp_path, Scenario.from_dict(d, "s.toml"))


@pytest.mark.parametrize("command", ["steady", "analyze", "stability", "reproduce", "study",
                                     "simulate"])
def test_refusals_name_the_feedforward_s_key(tmp_path, capsys, command):
    # a feedforward model along the stroke (the link itself plain) was refused naming
    # "[hysteresis] along", a key the scenario does not have
    path = _feedforward_along(tmp_path)
    args = {"reproduce": ["--out", str(tmp_path / "out")],
            "simulate": ["--time-series", str(tmp_path / "run.csv"), "--duration", "0.01",
                         "--frequency", "5"]
            }.get(command, [])
    if command == "study":
        study = tmp_path / "study.toml"
        study.write_text(f'scenario = "{path.name}"\noutputs = ["E"]\n'
                         f"[axes]\namplitude = [{A}]\nfrequency_hz = [{F}]\n")
        path, args = study, ["--out", str(tmp_path / "s.zarr"), "--workers", "0"]
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert cli_main([command, str(path), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "[feedforward] hysteresis.along" in err and "[hysteresis] along" not in err, err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_feedforward_model_along_the_stroke_names_its_key_in_the_api(stage, controller):
    sc = Scenario.from_dict({**default_scenario().to_dict(), "feedforward": {
        "type": "rigid-body", "hysteresis": {**LINKS["jenkins"][0].to_dict(), "along": {
            "position": POSITION, "fc": [0.5, 2.0]}}}}, "s.toml")
    assert sc.along_keys == ["[feedforward] hysteresis.along"]
    assert sc.loop().hysteresis_feedforward.key == "[feedforward] hysteresis.along"
    assert sc.loop().hysteresis_feedforward.shifted(0.001).key == sc.along_keys[0]
    assert _sampled_scenario(None).along_keys == ["[hysteresis] along"]
