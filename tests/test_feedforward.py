"""Hysteresis feedforward ``u_ff = M r'' + phi_hat(r)``: steady state, quasi-linear mismatch,
time simulation and the ``[feedforward] hysteresis`` table of scenario files."""

from __future__ import annotations

import copy
import tomllib

import control
import numpy as np
import pytest

from motionhyst.analysis.quasilinear import (
    analyze,
    error_harmonics_df,
    loop_mismatch,
    mismatch,
    residual_mismatch,
)
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI, freqresp
from motionhyst.hysteresis import Jenkins, MaxwellSlip
from motionhyst.scenario import Scenario, ScenarioError, default_scenario_path
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

K3, FC3 = [8.0, 6.0, 4.0], [0.01, 0.03, 0.06]
# the same link with every parameter off by 2 %, alternately up and down
K3_OFF = [8.0 * 1.02, 6.0 * 0.98, 4.0 * 1.02]
FC3_OFF = [0.01 * 0.98, 0.03 * 1.02, 0.06 * 0.98]
A_REF, F_REF = 0.01, 5.0

# Table I (paper section V)
M1, M2, B, K_STAGE = 5.0, 17.5, 90.0, 7.4e7
K_GAIN, F1, F2, FLP, BETA = 6.2e6, 60.0, 240.0, 700.0, 0.6


def link() -> MaxwellSlip:
    return MaxwellSlip(k=K3, fc=FC3)


@pytest.fixture(scope="module")
def table1():
    loop = Scenario.from_file(default_scenario_path()).loop()
    return loop.plant, loop.controller


@pytest.fixture(scope="module")
def loops(table1) -> dict[str, Loop]:
    stage, C = table1
    return {
        "none": Loop(stage, C, link()),
        "perfect": Loop(stage, C, link(), hysteresis_feedforward=link()),
        "off": Loop(stage, C, link(), hysteresis_feedforward=MaxwellSlip(K3_OFF, FC3_OFF)),
    }


@pytest.fixture(scope="module")
def steady(loops):
    return {name: periodic_steady_state(lp, A_REF, F_REF) for name, lp in loops.items()}


# ------------------------------------------------------------------ steady state
def test_perfect_feedforward_removes_hysteresis_error(steady):
    none, perfect = steady["none"], steady["perfect"]
    assert none.error_hysteresis_rms > 1e-9  # the link matters without feedforward
    assert none.error_hysteresis_rms / perfect.error_hysteresis_rms > 1000
    # the linear error is the same reference: feedforward does not change it
    np.testing.assert_allclose(perfect.e_linear, none.e_linear, rtol=1e-14)
    assert abs(perfect.mismatch - 1) < 2e-3


def test_two_percent_model_error_still_helps(steady):
    ratio = steady["none"].error_hysteresis_rms / steady["off"].error_hysteresis_rms
    assert ratio > 20
    assert steady["off"].error_hysteresis_rms > 10 * steady["perfect"].error_hysteresis_rms


def test_feedforward_with_the_same_instance(table1, steady):
    stage, C = table1
    el = link()
    ss = periodic_steady_state(Loop(stage, C, el, hysteresis_feedforward=el), A_REF, F_REF)
    np.testing.assert_allclose(ss.e, steady["perfect"].e, rtol=0, atol=1e-22)


def test_feedforward_without_link_adds_the_model_force(table1, steady):
    """phi_hat alone acts like -w: its error is the negative of the link's first-order error."""
    stage, C = table1
    only_ff = periodic_steady_state(Loop(stage, C, None, hysteresis_feedforward=link()),
                                    A_REF, F_REF)
    # with y1 ~ r the link's force is ~ phi(r), so the errors added are nearly opposite
    d_ff = only_ff.e[1] - only_ff.e_linear[1]
    d_link = steady["none"].e[1] - steady["none"].e_linear[1]
    assert abs(d_ff + d_link) < 1e-3 * abs(d_link)


# ------------------------------------------------------------- quasi-linear mismatch
def eq18(f_hz: np.ndarray, D) -> np.ndarray:
    """Paper eq. (18) from eqs. (1), (2), (15) and (23), written out independently."""
    s = 1j * TWO_PI * np.asarray(f_hz)
    M = M1 + M2
    Pr = 1 / (M * s**2)
    den = M * (M1 * M2 * s**2 + B * M * s + K_STAGE * M)
    Pf1, Pf2 = M2**2 / den, M1 * M2 / den
    P1, P2 = Pr + Pf1, Pr - Pf2
    w1, w2, wlp = TWO_PI * F1, TWO_PI * F2, TWO_PI * FLP
    C = K_GAIN * (F2 / F1) * (s + w1) / (s + w2) * wlp**2 / (s**2 + 2 * BETA * wlp * s + wlp**2)
    S1 = 1 / (1 + D * P1)
    return (C * P2 + 1) * (Pr - P2 * S1) / (Pf2 * (C * P2 * S1 + 1))


FREQS = np.array([1.0, 2.0, 5.0, 10.0, 20.0, 50.0])


@pytest.mark.parametrize("el", [link(), Jenkins(20.0, 0.05)], ids=["maxwell", "jenkins"])
def test_residual_mismatch_without_feedforward_is_eq18(loops, el):
    stage, C = loops["none"].plant, loops["none"].controller
    lp = Loop(stage, C, el)
    D = np.full(FREQS.shape, el.describing_function(A_REF))
    E = residual_mismatch(lp, TWO_PI * FREQS, D, 0.0)
    omega = TWO_PI * FREQS
    parts = [freqresp(sys, omega) for sys in (C, stage.P1, stage.P2, stage.Pr, stage.Pf2)]
    np.testing.assert_allclose(E, mismatch(*parts, D), rtol=1e-9)
    np.testing.assert_allclose(E, eq18(FREQS, D), rtol=1e-7)  # eq. (18) cancels Pr - P2 S1
    np.testing.assert_allclose(loop_mismatch(lp, FREQS, A_REF), E, rtol=1e-12)
    assert abs(E[2]) > 2  # a real mismatch at 5 Hz


def test_loop_mismatch_with_perfect_feedforward_is_one(loops):
    f = np.array([5.0, 10.0, 20.0, 50.0])
    E = loop_mismatch(loops["perfect"], f, A_REF)
    E0 = loop_mismatch(loops["none"], f, A_REF)
    assert np.all(np.abs(E - 1) < 5e-3)
    assert np.all(np.abs(E - 1) < 0.05 * np.abs(E0 - 1))
    # analyze() reports the same residual mismatch
    res = analyze(loops["perfect"], A_REF, f)
    np.testing.assert_allclose([p.value for p in res.points], E, rtol=1e-12)


@pytest.mark.parametrize("name", ["perfect", "off"])
def test_quasi_linear_residual_mismatch_matches_steady_state(loops, steady, name):
    E_df = complex(loop_mismatch(loops[name], [F_REF], A_REF)[0])
    E_exact = steady[name].mismatch
    assert abs(E_df - E_exact) <= 0.01 * abs(E_exact)
    if name == "off":  # the residual itself is resolved, not only E ~ 1
        assert abs(E_df - 1) == pytest.approx(abs(E_exact - 1), rel=0.02)


def test_first_error_harmonic_df_with_feedforward(loops, steady):
    e = error_harmonics_df(loops["off"], A_REF, F_REF)
    assert abs(e[0]) == pytest.approx(abs(steady["off"].e[1]), rel=0.01)


def test_higher_error_harmonics_df_account_for_feedforward(loops, steady):
    e = error_harmonics_df(loops["off"], A_REF, F_REF)
    ss = steady["off"]
    for n in (3, 5):
        assert abs(e[n - 1]) == pytest.approx(abs(ss.e[n]), rel=0.02)
    e_perfect = error_harmonics_df(loops["perfect"], A_REF, F_REF)
    e_none = error_harmonics_df(loops["none"], A_REF, F_REF)
    assert abs(e_perfect[2]) < 0.01 * abs(e_none[2])


def test_self_consistent_error_harmonic_matches_analyze_with_feedforward(loops):
    lp = loops["off"]
    e1 = error_harmonics_df(lp, A_REF, F_REF, amplitude_mode="self-consistent")[0]
    e_hat = complex(lp.transfer("r->e", np.array([TWO_PI * F_REF]))[0]) * A_REF
    E = analyze(lp, A_REF, [F_REF], amplitude_mode="self-consistent").points[0].value
    assert abs(e1 / e_hat - E) <= 1e-6 * abs(E)


# ------------------------------------------------------------------ time simulation
@pytest.fixture(scope="module")
def sims(loops):
    ref = SineReference(A_REF, F_REF)
    return {name: simulate(loops[name], ref, 2.0) for name in ("none", "perfect")}


def last_period(sim):
    return sim.t >= sim.t[-1] - 1.0 / F_REF


def test_simulation_with_perfect_feedforward(sims):
    dev = {}
    for name, sim in sims.items():
        m = last_period(sim)
        dev[name] = np.max(np.abs(sim.e[m] - sim.e_linear[m]))
    assert dev["none"] > 1e-9
    assert dev["none"] / dev["perfect"] > 1000


def test_simulation_feedforward_force_is_in_u(loops, sims):
    """u = C e + M r'' + phi_hat(r); with perfect feedforward, phi_hat(r) takes over the
    force the feedback spends on the link without it."""
    t = sims["perfect"].t
    _, acc = SineReference(A_REF, F_REF)(t)
    C = loops["none"].controller
    M = loops["none"].M
    m = last_period(sims["perfect"])
    fb_lin = control.forced_response(C, t, sims["none"].e_linear).outputs
    fb = {}
    for name, sim in sims.items():
        u_fb = control.forced_response(C, t, sim.e).outputs
        uh = link().response(sim.r) if name == "perfect" else 0.0
        np.testing.assert_allclose(sim.u, u_fb + M * acc + uh, rtol=0, atol=1e-12)
        fb[name] = np.max(np.abs((u_fb - fb_lin)[m]))  # feedback force spent on the link
    w_peak = np.max(np.abs(sims["none"].w[m]))
    assert fb["none"] == pytest.approx(w_peak, rel=0.01)
    assert fb["perfect"] < 1e-3 * w_peak


def test_simulation_agrees_with_steady_state(sims, steady):
    sim = sims["perfect"]
    m = last_period(sim)
    ts = steady["perfect"].time_series()
    peak_steady = np.max(np.abs(ts["e"] - ts["e_linear"]))
    peak_sim = np.max(np.abs(sim.e[m] - sim.e_linear[m]))
    assert peak_sim == pytest.approx(peak_steady, rel=0.05)


# ------------------------------------------------------------------- scenario files
def paper_dict() -> dict:
    return tomllib.loads(default_scenario_path().read_text())


def with_feedforward(table) -> dict:
    d = copy.deepcopy(paper_dict())
    d["feedforward"]["hysteresis"] = table
    return d


def test_scenario_toml_maxwell_feedforward(tmp_path):
    text = default_scenario_path().read_text().replace(
        "[reference]",
        'hysteresis = { model = "maxwell-slip", k = [8, 6, 4], fc = [0.01, 0.03, 0.06] }\n\n'
        "[reference]")
    path = tmp_path / "ff.toml"
    path.write_text(text)
    sc = Scenario.from_file(path)
    hff = sc.loop().hysteresis_feedforward
    assert isinstance(hff, MaxwellSlip)
    assert hff.to_dict() == {"model": "maxwell-slip", "k": K3, "fc": FC3}
    assert isinstance(sc.loop().hysteresis, Jenkins)  # [hysteresis] is unchanged
    assert sc.to_dict()["feedforward"]["hysteresis"] == hff.to_dict()
    # and the round trip through to_dict builds the same loop
    again = Scenario.from_dict(sc.to_dict())
    assert again.loop().hysteresis_feedforward.to_dict() == hff.to_dict()


def test_scenario_jenkins_feedforward_compensates_table1():
    sc = Scenario.from_dict(with_feedforward({"model": "jenkins", "k": 20, "fc": 0.05}))
    hff = sc.loop().hysteresis_feedforward
    assert isinstance(hff, Jenkins)
    assert (hff.k, hff.fc) == (20.0, 0.05)
    plain = Scenario.from_file(default_scenario_path()).loop()
    assert plain.hysteresis_feedforward is None
    with_ff = periodic_steady_state(sc.loop(), A_REF, F_REF).error_hysteresis_rms
    without = periodic_steady_state(plain, A_REF, F_REF).error_hysteresis_rms
    assert without / with_ff > 1000


def test_feedforward_section_without_hysteresis_has_none():
    d = paper_dict()
    assert "hysteresis" not in d["feedforward"]
    assert Scenario.from_dict(d).loop().hysteresis_feedforward is None


@pytest.mark.parametrize(
    ("table", "fragment"),
    [
        ({"model": "maxwell-slip", "k": [8, 6], "fc": [0.01, 0.03, 0.06]}, "same length"),
        ({"model": "maxwell-slip", "k": [], "fc": []}, "k"),
        ({"model": "maxwell-slip", "k": [8, -6], "fc": [0.01, 0.03]}, "k[1]"),
        ({"model": "maxwell-slip", "k": [8, float("nan")], "fc": [0.01, 0.03]}, "k[1]"),
        ({"model": "maxwell-slip", "k": 8, "fc": 0.01}, "k"),
        ({"model": "maxwell-slip", "k": [8, True], "fc": [0.01, 0.03]}, "k[1]"),
        ({"model": "jenkins", "k": [20], "fc": 0.05}, "k"),
        ({"model": "jenkins", "k": 20}, "fc: missing"),
        ({"model": "jenkins", "k": "20", "fc": 0.05}, "k"),
        ({"model": "jenkins", "k": 0, "fc": 0.05}, "k"),
        ({"model": "jenkins", "k": 20, "fc": 0.05, "extra": 1}, "extra: unknown key"),
        ({"model": "preisach", "k": 20, "fc": 0.05}, "preisach"),
        ({"k": 20, "fc": 0.05}, "model"),
        ("jenkins", ""),
    ],
)
def test_feedforward_hysteresis_errors_are_one_line(table, fragment):
    with pytest.raises(ScenarioError) as info:
        Scenario.from_dict(with_feedforward(table), source="ff.toml")
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith("ff.toml: ")
    assert "[feedforward] hysteresis" in msg
    assert fragment in msg


def test_feedforward_hysteresis_error_from_file_names_the_file(tmp_path):
    text = default_scenario_path().read_text().replace(
        "[reference]",
        'hysteresis = { model = "maxwell-slip", k = [8, 6], fc = [0.01] }\n\n[reference]')
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        Scenario.from_file(path)
    msg = str(info.value)
    assert "\n" not in msg and str(path) in msg
    assert "[feedforward] hysteresis" in msg and "same length" in msg
