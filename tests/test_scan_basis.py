"""Tests of the derivative feedforward (the stage's inverse) and of learning its coefficients
(controllers/inverse.py, scan/terms.py, scan/basis.py, the scan's ``model`` and ``basis``)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import FC_LINK, K_LINK
from numpy.testing import assert_allclose

from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage, simulate
from motionhyst.cli import main as cli_main
from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.inverse import stage_inverse
from motionhyst.plants import ModalPlant
from motionhyst.plants.mass_spring_damper import MassSpringDamper
from motionhyst.scan.basis import _through_ps, learn_basis
from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import run_scan
from motionhyst.scan.terms import FeedforwardTerms, model_terms, setpoint_samples
from motionhyst.scenario import Scenario, ScenarioError, default_scenario
from motionhyst.time.references import SineReference
from motionhyst.time.sampled import feedforward_samples

M1, M2, B, K = 5.0, 17.5, 90.0, 7.4e7
# a production-speed scan, short: the stage's flexible mode dominates the link
FAST = dict(speed=0.5, a_max=20.0, j_max=2000.0, s_max=4e5, start=0.01)


@pytest.mark.parametrize(("c1", "c2"), [(0.0, 0.0), (40.0, 60.0)])
def test_two_mass_inverse_is_the_taylor_series_of_one_over_p2(c1, c2):
    inv = stage_inverse(TwoMassStage(M1, M2, B, K, c1=c1, c2=c2))
    M = M1 + M2
    # the closed forms of the module docstring
    assert inv.viscous == pytest.approx(c1 + c2, rel=1e-12, abs=1e-15)
    assert inv.acceleration == pytest.approx(M + c1 * c2 / K, rel=1e-12)
    assert inv.jerk == pytest.approx((M1 * c2 + M2 * c1) / K - B * c1 * c2 / K**2, rel=1e-9,
                                     abs=1e-20)
    assert inv.snap == pytest.approx(M1 * M2 / K - B * (M1 * c2 + M2 * c1) / K**2
                                     + B**2 * c1 * c2 / K**3, rel=1e-9)
    if c1 == c2 == 0.0:
        assert inv.jerk == 0.0  # the internal damper enters with the fifth derivative
        assert inv.crackle == pytest.approx(-M1 * M2 * B / K**2, rel=1e-9)
    # the series is 1 / P2 at low frequency: the rest is O(s^6) relative to M s^2
    s = 2j * np.pi * 20.0
    series = sum(c * s**n for n, c in enumerate([0.0, inv.viscous, inv.acceleration,
                                                 inv.jerk, inv.snap, inv.crackle]))
    P2 = TwoMassStage(M1, M2, B, K, c1=c1, c2=c2).P2
    exact = 1.0 / complex(P2(s))
    assert abs(series - exact) < 1e-9 * abs(exact)  # the s^5 term alone is 1.3e-7 of it


def test_modal_fit_gives_the_same_terms_and_a_spring_held_plant_none():
    stage = TwoMassStage(M1, M2, B, K)
    a, b = stage_inverse(stage), stage_inverse(ModalPlant.from_two_mass(stage))
    assert b.acceleration == pytest.approx(a.acceleration, rel=1e-12)
    assert b.snap == pytest.approx(stage.M**2 * stage.pf2_static, rel=1e-9)  # M^2 Pf2(0)
    assert b.crackle == pytest.approx(a.crackle, rel=1e-6)
    with pytest.raises(ValueError, match="free rigid body"):
        stage_inverse(MassSpringDamper(1.0, 20.0, 1e4))


def test_feedforward_jerk_and_snap_in_the_loop_transfer(stage, controller):
    inv = stage_inverse(stage)
    ff = Feedforward(snap=inv.snap, jerk=1e-7)
    assert ff.force(0.0, 2.0, 3.0, 4.0) == pytest.approx(0.0 * 2 + 1e-7 * 3 + inv.snap * 4)
    w = 2 * np.pi * np.array([3.0, 30.0, 300.0])
    assert_allclose(ff.with_mass(22.5).linear_response(w),
                    22.5 * (1j * w) ** 2 + 1e-7 * (1j * w) ** 3 + inv.snap * (1j * w) ** 4)
    rigid = Loop(stage, controller)
    full = Loop(stage, controller, feedforward=Feedforward(snap=inv.snap))
    # e = PS (1/P2 - C_ff) r: the snap term takes the s^4 term out, s^5 is left
    ps = rigid.transfer("w->e", w)
    assert_allclose(full.transfer("r->e", w), ps * inv.crackle * (1j * w) ** 5, rtol=0.02)
    assert_allclose(rigid.transfer("r->e", w)[0], ps[0] * inv.snap * (1j * w[0]) ** 4,
                    rtol=1e-3)
    with pytest.raises(ValueError, match="jerk and snap"):
        simulate(full, scan(0.01, **FAST), 0.01)


def test_snap_feedforward_cuts_the_flexible_error_by_the_predicted_factor(stage, controller):
    # without link, the rigid-body feedforward leaves e = PS (cs r'''' + c5 r^(5) + ...),
    # cs = m1 m2 / k; with the snap term the fifth-derivative term is left: the error
    # falls by ||cs PS r''''|| / ||c5 PS r^(5)||, computed from PS r'''' and its derivative
    loop = Loop(stage, controller)
    inv = stage_inverse(stage)
    p = scan(0.02, **FAST)
    duration = p.end + 0.02
    rigid = simulate(loop, p, duration)
    t = rigid.t
    terms = FeedforwardTerms(loop.M, {"mass": loop.M, "snap": inv.snap})
    snap = simulate(loop, p, duration, force=terms.force_function(p, step=t[1] - t[0]))
    g = _through_ps(loop, t, setpoint_samples(p, t, t[1] - t[0])[4][:, None])[:, 0]
    assert_allclose(rigid.e, inv.snap * g, atol=2e-3 * np.max(np.abs(rigid.e)))

    def rms(x):
        return np.sqrt(np.mean(x ** 2))

    predicted = inv.snap * rms(g) / (abs(inv.crackle) * rms(np.gradient(g, t)))
    assert predicted > 1000
    assert rms(rigid.e) / rms(snap.e) == pytest.approx(predicted, rel=0.05)
    # the snap's jumps sampled, not averaged, move them by up to half a step: 8x worse here
    sampled = simulate(loop, p, duration, force=terms.force_function(p))
    assert rms(sampled.e) > 4 * rms(snap.e)


def test_setpoint_samples_keep_a_jump_impulse_and_its_centre():
    p = scan(0.01, **FAST)
    h = 3e-5
    t = np.arange(0.0, p.end + 0.01, h) + 0.37 * h  # the jumps fall between samples
    d = setpoint_samples(p, t, h)
    exact = p.derivatives(t)
    # r''' is the snap's integral: the input linear between the averaged samples has it
    # wherever no jump is within two samples (each jump's impulse whole, at its place)
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (d[4][1:] + d[4][:-1]) * h)])
    jumps = np.flatnonzero(np.diff(exact[4]))
    away = np.ones(t.size, dtype=bool)
    for j in jumps:
        away[max(j - 2, 0):j + 4] = False
    assert jumps.size >= 8 and away.sum() > 0.9 * t.size
    err = np.abs(integral + exact[3][0] - exact[3])[away]
    assert np.max(err) < 1e-9 * np.max(np.abs(exact[3]))
    # sampled, not averaged, the snap's jumps each shift r''' by up to half a step's worth
    sampled = np.concatenate([[0.0], np.cumsum(0.5 * (exact[4][1:] + exact[4][:-1]) * h)])
    assert np.max(np.abs(sampled + exact[3][0] - exact[3])[away]) > 0.05 * 4e5 * h


def test_basis_recovers_known_coefficients_of_a_generated_case():
    # a stage with dampers to the ground (viscous and jerk terms), a Jenkins link; the
    # learning starts from a mass 5 % off, no jerk, snap or viscous term, a link 20 % off
    stage = TwoMassStage(M1, M2, B, K, c1=40.0, c2=60.0)
    inv = stage_inverse(stage)
    loop = Loop(stage, LeadLagLowpass(6.2e6, 60, 240, 700, 0.6), Jenkins(K_LINK, FC_LINK))
    p = scan(0.02, **FAST)
    start = FeedforwardTerms(22.5, {"mass": 0.95 * 22.5, "jerk": 0.0, "snap": 0.0,
                                    "viscous": 0.0}, Jenkins(1.2 * K_LINK, 0.8 * FC_LINK))
    res = learn_basis(loop, start, p, p.end + 0.02, trials=4)
    got = res.terms.values()
    assert got["mass"] == pytest.approx(inv.acceleration, rel=1e-5)
    assert got["viscous"] == pytest.approx(inv.viscous, rel=1e-4)
    assert got["jerk"] == pytest.approx(inv.jerk, rel=0.02)
    assert got["snap"] == pytest.approx(inv.snap, rel=0.002)
    assert got["link fc"] == pytest.approx(FC_LINK, rel=0.01)
    assert got["link k"] == pytest.approx(K_LINK, rel=0.03)
    assert res.rms_errors[-1] < 1e-4 * res.rms_errors[0]
    d = res.to_dict()
    assert d["initial"]["mass"] == 0.95 * 22.5 and d["units"]["link fc"] == "N"
    assert "learned" in str(res) and "link k" in str(res)


def test_basis_carries_over_where_the_learned_force_does_not(stage, controller):
    # the link model 4 % off and no snap term to start: basis learns both on one speed
    # and keeps them at half the speed; the force ILC learned belongs to its setpoint
    loop = Loop(stage, controller, Jenkins(K_LINK, FC_LINK),
                hysteresis_feedforward=Jenkins(1.04 * K_LINK, 1.04 * FC_LINK))
    p = scan(0.03, **FAST)
    other = scan(0.03, **{**FAST, "speed": 0.25})
    res = run_scan(loop, p, 0.01, ("none", "model", "ilc", "basis"), ilc_trials=3,
                   other_profile=other, basis_trials=3)
    assert list(res.terms.coefficients) == ["mass"]  # the loop's feedforward: no snap term
    assert res.basis.terms.coefficients["snap"] == pytest.approx(stage_inverse(stage).snap,
                                                                 rel=0.01)
    for r in (res, res.carry_over):
        none, basis = r.run("none"), r.run("basis")
        assert none.ma_max / basis.ma_max > 10 and none.msd_max / basis.msd_max > 10
    co = res.carry_over
    assert co.run("ilc").msd_max > co.run("none").msd_max / 5
    d = res.to_dict()
    assert set(d["basis"]["learned"]) == {"mass", "jerk", "snap", "link k", "link fc"}
    assert d["feedforward"]["coefficients"] == {"mass": 22.5, "link k": 1.04 * K_LINK,
                                                "link fc": 1.04 * FC_LINK}


def test_model_terms_of_a_scenario():
    base = default_scenario().to_dict()
    base["feedforward"] = {"type": "rigid-body", "snap": "plant", "jerk": 2e-8,
                           "hysteresis": {"model": "jenkins", "k": 20.8, "fc": 0.052}}
    loop = Scenario.from_dict(base, "s.toml").loop()
    assert loop.ff.snap == pytest.approx(M1 * M2 / K) and loop.ff.jerk == 2e-8
    terms = model_terms(loop)
    assert terms.names() == ["mass", "jerk", "snap", "link k", "link fc"]
    assert model_terms(loop, ["viscous"]).coefficients == {"mass": 22.5, "viscous": 0.0}
    with pytest.raises(ValueError, match="unknown feedforward term"):
        model_terms(loop, ["crackle"])
    base["feedforward"] = {"type": "none", "snap": "plant"}
    with pytest.raises(ScenarioError, match="snap"):
        Scenario.from_dict(base, "s.toml")


SHORT = ["--length", "0.03", "--speed", "0.5", "--a-max", "20", "--j-max", "2000",
         "--s-max", "4e5", "--window", "0.01", "--tail", "0.02"]


def test_cli_scan_basis_json(capsys):
    argv = ["scan", "examples/scan_production.toml", *SHORT, "--compensation", "none",
            "model", "basis", "--basis-trials", "2", "--feedforward", "jerk", "snap",
            "hysteresis", "--json"]
    assert cli_main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert [r["compensation"] for r in d["results"]] == ["none", "model", "basis"]
    assert len(d["basis"]["trials"]) == 2
    assert d["basis"]["learned"]["snap"] == pytest.approx(M1 * M2 / K, rel=0.01)
    assert d["feedforward"]["coefficients"]["jerk"] == 0.0
    assert d["carry_over"]["profile"]["v_max"] == 0.25


@pytest.mark.parametrize(("extra", "message"), [
    (["--compensation", "none", "--basis-trials", "3"], "--basis-trials"),
    (["--compensation", "none", "--feedforward", "snap"], "--feedforward"),
    (["--feedforward", "snap", "snap"], "twice"),
    (["--compensation", "none", "--other-speed", "1"], "--other-speed"),
])
def test_cli_scan_basis_errors_are_one_line_exit_2(extra, message, capsys):
    assert cli_main(["scan", *SHORT, *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_cli_scan_hysteresis_term_needs_a_model(capsys):
    assert cli_main(["scan", *SHORT, "--feedforward", "hysteresis"]) == 2
    assert "has none" in capsys.readouterr().err


def test_sampled_controller_computes_the_jerk_and_snap_terms_ahead():
    base = Scenario.from_file("examples/paper_10khz.toml").to_dict()
    base["feedforward"].update({"snap": "plant", "jerk": 1e-6})
    loop = Scenario.from_dict(base, "s.toml").loop()
    p = scan(0.01, **FAST)
    T, a = loop.sampled.period, loop.ff.advance_samples
    t = np.arange(0.0, p.end, T)
    d = p.derivatives(t + a * T)
    expected = loop.M * d[2] + 1e-6 * d[3] + M1 * M2 / K * d[4]
    assert_allclose(feedforward_samples(loop, p, t), expected, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="derivatives"):
        feedforward_samples(loop, SineReference(0.01, 5.0), t)


def test_without_feedforward_basis_learns_the_mass_from_zero(stage, controller):
    # a loop without feedforward: the model's acceleration term starts at 0, as the loop
    # applies none; the learning finds M = m1 + m2 (the error is then the stage's own)
    loop = Loop(stage, controller, Jenkins(K_LINK, FC_LINK), feedforward=None,
                hysteresis_feedforward=Jenkins(K_LINK, FC_LINK))
    terms = model_terms(loop)
    assert terms.base_mass == 0.0 and terms.coefficients == {"mass": 0.0}
    p = scan(0.02, **FAST)
    res = run_scan(loop, p, 0.01, ("none", "basis"), basis_trials=3)
    assert res.basis.terms.coefficients["mass"] == pytest.approx(stage.M, rel=1e-4)
    assert res.run("basis").ma_max < 1e-3 * res.run("none").ma_max


def test_terms_jacobian_is_the_force_derivative():
    p = scan(0.01, **FAST)
    t = np.linspace(0.0, p.end, 3001)
    d = setpoint_samples(p, t, t[1] - t[0])
    terms = FeedforwardTerms(22.5, {"mass": 22.0, "jerk": 1e-7, "snap": 1e-6, "viscous": 3.0,
                                    "coulomb": 0.01}, Jenkins(K_LINK, FC_LINK))
    J = terms.jacobian(d)
    theta = terms.vector()
    for i in range(theta.size):
        h = 1e-4 * abs(theta[i])  # the force is linear in all but the link's: rounding small
        up = terms.with_vector(theta + h * np.eye(theta.size)[i]).force(d)
        down = terms.with_vector(theta - h * np.eye(theta.size)[i]).force(d)
        assert_allclose(J[:, i], (up - down) / (2 * h), rtol=1e-4,
                        atol=1e-6 * np.max(np.abs(J[:, i])))
