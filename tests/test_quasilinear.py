"""Tests of the quasi-linear analysis, paper sections III-C and IV (eqs. 12-22)."""

from __future__ import annotations

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionhyst.analysis.quasilinear import (
    analyze,
    f_star,
    loop_mismatch,
    mismatch,
    mismatch_asymptote,
    mismatch_crossover,
    mismatch_crossover_exact,
    quasi_linear_plant,
    self_consistent_amplitude,
    sensitivity_s1,
)
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import freqresp
from motionhyst.hysteresis.jenkins import Jenkins

A_REF = 0.01


def parts(stage, controller, omega):
    """C, P1, P2, Pr, Pf2 from the stage's own transfer functions."""
    return (freqresp(controller, omega), freqresp(stage.P1, omega), freqresp(stage.P2, omega),
            freqresp(stage.Pr, omega), freqresp(stage.Pf2, omega))


# ---------------------------------------------------------------------------
# Quasi-linear plant, eq. (12)
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("A", [1e-4, 1e-3, 0.01, 0.1, 1.0])
def test_quasi_linear_plant_tends_to_p2_above_f_star(stage, link, A):
    fs = f_star(link.k, stage.M)
    D = link.describing_function(A)
    omega = 2 * np.pi * np.array([0.1 * fs, 10 * fs, 100 * fs])
    P1, P2 = freqresp(stage.P1, omega), freqresp(stage.P2, omega)
    dev = np.abs(quasi_linear_plant(P1, P2, D) / P2 - 1)
    # |D P1| ~ |D| / (M w^2) = (|D| / kJ) (f* / f)^2
    scale = abs(D) / link.k
    assert dev[1] == pytest.approx(scale / 100, rel=0.02)
    assert dev[2] == pytest.approx(scale / 1e4, rel=0.02)
    assert dev[1] <= 0.0102
    # well below f* the link dominates: with P1 ~ Pr = -1 / (M w^2) = -100 / kJ,
    # |P^phi / P2| ~ 1 / |1 - 100 D / kJ|
    low = abs(quasi_linear_plant(P1[0], P2[0], D) / P2[0])
    assert low == pytest.approx(1 / abs(1 - 100 * D / link.k), rel=1e-3)


def test_f_star_table1(stage, link):
    assert f_star(link.k, stage.M) == pytest.approx(np.sqrt(20 / 22.5) / (2 * np.pi), rel=1e-15)
    assert round(f_star(link.k, stage.M), 3) == 0.150


def test_quasi_linear_plant_no_slip_is_spring_on_stage(stage, link):
    """For zeta >= 1 the element is the spring kJ: P^phi is the stage held by that spring."""
    A = 0.5 * link.slip_displacement
    D = link.describing_function(A)
    assert D == link.k
    m1, m2, b, k, kj = stage.m1, stage.m2, stage.b, stage.k, link.k
    Amat = [[0, 0, 1, 0], [0, 0, 0, 1], [-(k + kj) / m1, k / m1, -b / m1, b / m1],
            [k / m2, -k / m2, b / m2, -b / m2]]
    spring = control.ss(Amat, [[0], [0], [1 / m1], [0]], [[0, 1, 0, 0]], [[0]])
    f = np.array([0.01, 0.1, 0.2, 1.0, 10.0, 100.0, 1000.0])  # not at f* (ill-conditioned)
    omega = 2 * np.pi * f
    ref = np.array([complex(spring(1j * w)) for w in omega])
    P1, P2 = freqresp(stage.P1, omega), freqresp(stage.P2, omega)
    assert_allclose(quasi_linear_plant(P1, P2, D), ref, rtol=1e-8)
    # well below f* the spring holds the stage: y2 / u = 1 / (kJ - M w^2)
    assert abs(ref[0]) == pytest.approx(1 / (kj - stage.M * omega[0] ** 2), rel=1e-6)


def test_sensitivity_s1(stage, link):
    omega = 2 * np.pi * np.array([0.1, 1.0, 10.0])
    P1 = freqresp(stage.P1, omega)
    D = link.describing_function(A_REF)
    S1 = sensitivity_s1(P1, D)
    assert_allclose(S1 * (1 + D * P1), 1.0, rtol=1e-14)
    assert_allclose(sensitivity_s1(P1, 0.0), 1.0, rtol=0)


# ---------------------------------------------------------------------------
# Mismatch, eqs. (17)-(22)
# ---------------------------------------------------------------------------


def error_eq17(C, P2, Pr, S1):
    """Quasi-linear tracking error per unit reference, eq. (17)."""
    return (1 - P2 / Pr * S1) / (1 + P2 * C * S1)


@pytest.mark.parametrize("A", [A_REF, 1e-3, 0.1])
def test_mismatch_is_ratio_of_quasi_linear_errors(stage, controller, link, A):
    f = np.array([5.0, 10.0, 15.0])
    omega = 2 * np.pi * f
    C, P1, P2, Pr, Pf2 = parts(stage, controller, omega)
    D = link.describing_function(A)
    S1 = 1 / (1 + D * P1)  # eq. (15)
    ratio = error_eq17(C, P2, Pr, S1) / error_eq17(C, P2, Pr, 1.0)
    assert_allclose(mismatch(C, P1, P2, Pr, Pf2, D), ratio, rtol=1e-9)
    loop = Loop(stage, controller, link)
    assert_allclose(loop_mismatch(loop, f, A), ratio, rtol=1e-9)
    # e_hat is the linear loop's r->e transfer
    assert_allclose(error_eq17(C, P2, Pr, 1.0), loop.transfer("r->e", omega), rtol=1e-9)


def test_mismatch_low_frequency_asymptote(loop, stage, controller, link):
    D = link.describing_function(A_REF)
    for f, tol in [(0.1, 1e-2), (0.5, 1e-2)]:
        omega = 2 * np.pi * np.array([f])
        Pr, Pf2 = parts(stage, controller, omega)[3:]
        E = loop_mismatch(loop, f, A_REF)
        Et = mismatch_asymptote(Pr, Pf2, D)
        assert abs(E[0] / Et[0] - 1) < tol
        # eq. (20) directly: Pr^2 D / Pf2
        assert Et[0] == pytest.approx(Pr[0] ** 2 * D / Pf2[0], rel=1e-14)
    # the asymptote falls as f^-4 (quadruple integrator) with the phase of D
    Et = mismatch_asymptote(*parts(stage, controller, 2 * np.pi * np.array([0.1, 1.0]))[3:], D)
    assert abs(Et[0] / Et[1]) == pytest.approx(1e4, rel=1e-4)
    assert np.angle(Et[0]) == pytest.approx(np.angle(D), abs=1e-6)


def test_mismatch_eq19_between_asymptote_and_exact(loop, stage, controller, link):
    """Eq. (19) keeps C + D; with |C| >> |D| it is eq. (20) at low frequency."""
    D = link.describing_function(A_REF)
    omega = 2 * np.pi * np.array([0.1])
    C, _, _, Pr, Pf2 = parts(stage, controller, omega)
    eq19 = C * Pr**2 * D / (Pf2 * (C + D))
    assert abs(loop_mismatch(loop, 0.1, A_REF)[0] / eq19[0] - 1) < 1e-5


def test_mismatch_tends_to_one_at_high_frequency(loop):
    f = np.array([100.0, 1e3, 1e4])
    dev = np.abs(loop_mismatch(loop, f, A_REF) - 1)
    assert dev[0] < 1e-2
    assert dev[1] < 1e-6
    assert dev[2] < 1e-9
    assert np.all(np.diff(dev) < 0)


def test_mismatch_without_hysteresis_is_one(stage, controller):
    omega = 2 * np.pi * np.array([0.1, 5.0, 100.0])
    assert_allclose(mismatch(*parts(stage, controller, omega), 0.0), 1.0, rtol=1e-12)


def test_crossover_estimate_eq21(stage, link):
    D = link.describing_function(A_REF)
    fc = mismatch_crossover(stage.k, stage.m1, stage.m2, abs(D))
    assert fc == pytest.approx((stage.k * abs(D) / (stage.m1 * stage.m2)) ** 0.25 / (2 * np.pi),
                               rel=1e-14)
    assert abs(fc - 7.6) < 0.05
    # eq. (21) is where the asymptote of eq. (20) has unit magnitude (rigid-body region)
    omega = 2 * np.pi * np.array([fc])
    Et = mismatch_asymptote(freqresp(stage.Pr, omega), freqresp(stage.Pf2, omega), D)
    assert abs(Et[0]) == pytest.approx(1.0, rel=1e-3)


def test_exact_crossover(loop):
    fx = mismatch_crossover_exact(loop, A_REF)
    assert abs(fx - 7.6) < 0.2
    assert abs(loop_mismatch(loop, fx, A_REF)[0] - 1) == pytest.approx(1.0, rel=1e-9)
    # and it is the lowest crossing: |E - 1| > 1 everywhere below
    f = np.geomspace(1e-2, fx, 500)[:-1]
    assert np.all(np.abs(loop_mismatch(loop, f, A_REF) - 1) > 1)


def test_exact_crossover_tuple_plant(stage, controller, link, loop):
    """Without Pf2 (Pf2 = Pr - P2 from data) the crossover is found at the same place."""
    other = Loop((stage.P1, stage.P2), controller, link, mass=stage.M)
    assert mismatch_crossover_exact(other, A_REF) == pytest.approx(
        mismatch_crossover_exact(loop, A_REF), rel=1e-6)
    f = np.array([1.0, 5.0, 10.0, 15.0])
    assert_allclose(loop_mismatch(other, f, A_REF), loop_mismatch(loop, f, A_REF), rtol=1e-8)


# ---------------------------------------------------------------------------
# analyze: the paper's numbers for Table I
# ---------------------------------------------------------------------------


def test_analyze_table1(loop):
    res = analyze(loop, A_REF, [5.0, 10.0, 15.0])
    d = res.to_dict()
    assert d["amplitude_mode"] == "reference"
    assert d["zeta"] == pytest.approx(0.25, rel=1e-15)
    assert round(d["df_abs_over_k"], 3) == 0.309
    assert abs(d["df_phase_deg"] - 50.7) < 0.05
    assert round(d["f_star_hz"], 3) == 0.150
    assert abs(d["mismatch_crossover_hz"] - 7.6) < 0.05
    fx = d["mismatch_crossover_exact_hz"]
    assert abs(fx - 7.6) < 0.2
    assert abs(loop_mismatch(loop, fx, A_REF)[0] - 1) == pytest.approx(1.0, rel=1e-9)
    assert d["bandwidth_hz"] == pytest.approx(120.65, abs=1.0)
    assert 115 < d["bandwidth_hz"] < 125
    assert complex(d["df_re"], d["df_im"]) == loop.hysteresis.describing_function(A_REF)
    # the mismatch points are eq. (18) and eq. (20) at the requested frequencies
    E = loop_mismatch(loop, [5.0, 10.0, 15.0], A_REF)
    assert [p["frequency_hz"] for p in d["mismatch"]] == [5.0, 10.0, 15.0]
    assert_allclose([p.value for p in res.points], E, rtol=1e-12)
    assert_allclose([p["abs"] for p in d["mismatch"]], np.abs(E), rtol=1e-12)
    assert_allclose([p["phase_deg"] for p in d["mismatch"]], np.degrees(np.angle(E)),
                    rtol=1e-12)
    assert all(p["y1_amplitude"] == A_REF and p["zeta"] == 0.25 for p in d["mismatch"])
    # Fig. 10: a large mismatch at 5 Hz, still visible at 10 Hz, small at 15 Hz
    mags = np.abs(E)
    assert mags[0] > 5 and 1.1 < mags[1] < 1.5 and 1.0 < mags[2] < 1.1


def test_analyze_self_consistent(loop, stage):
    f = np.array([5.0, 10.0, 15.0])
    ref = analyze(loop, A_REF, f)
    sc = analyze(loop, A_REF, f, amplitude_mode="self-consistent")
    assert sc.amplitude_mode == "self-consistent"
    amps = np.array([p.y1_amplitude for p in sc.points])
    # y1 is the actuated mass: it follows the reference through P1 / P2 = 1 + m2 s^2/(b s + k),
    # which is 2e-4, 9e-4, 2.1e-3 below one at 5, 10, 15 Hz
    s = 2j * np.pi * f
    flex = np.abs(1 + stage.m2 * s**2 / (stage.b * s + stage.k))
    assert_allclose(amps / A_REF, flex, rtol=5e-5)
    assert np.all(np.abs(amps[:2] - A_REF) < 1e-3 * A_REF)
    assert np.all(np.abs(amps - A_REF) < 2.5e-3 * A_REF)
    # the mismatch changes little
    assert_allclose([p.value for p in sc.points], [p.value for p in ref.points], rtol=2e-3)
    assert_allclose([p.zeta for p in sc.points], loop.hysteresis.zeta(amps), rtol=1e-14)


def test_self_consistent_amplitude_solves_the_quasi_linear_loop(loop):
    f = 10.0
    omega = np.array([2 * np.pi * f])
    a = self_consistent_amplitude(loop, f, A_REF)
    D = loop.hysteresis.describing_function(a)
    t_r = loop.transfer("r->y1", omega)[0]
    t_w = loop.transfer("w->y1", omega)[0]
    # y1 = T_ry1 r + T_wy1 D y1
    assert abs(t_r / (1 - t_w * D)) * A_REF == pytest.approx(a, rel=1e-10)


@pytest.mark.parametrize("amplitude", [0.0, -0.01, np.nan, np.inf])
def test_analyze_rejects_bad_amplitude(loop, amplitude):
    with pytest.raises(ValueError, match="amplitude"):
        analyze(loop, amplitude, [5.0])


@pytest.mark.parametrize("freqs", [[0.0], [-5.0], [5.0, np.nan]])
def test_analyze_rejects_bad_frequency(loop, freqs):
    with pytest.raises(ValueError, match="frequencies"):
        analyze(loop, A_REF, freqs)


def test_analyze_rejects_unsuitable_loop(stage, controller, link, loop):
    with pytest.raises(ValueError, match="no hysteresis"):
        analyze(Loop(stage, controller), A_REF, [5.0])
    with pytest.raises(ValueError, match="rigid-body feedforward"):
        analyze(Loop(stage, controller, link, feedforward=None), A_REF, [5.0])
    with pytest.raises(ValueError, match="amplitude_mode"):
        analyze(loop, A_REF, [5.0], amplitude_mode="exact")


def test_analyze_no_slip_amplitude(stage, controller):
    """Below the slip displacement the link is a spring: D = kJ, zeta > 1."""
    el = Jenkins(k=20.0, fc=0.05)
    res = analyze(Loop(stage, controller, el), 1e-3, [5.0])
    assert res.zeta == pytest.approx(2.5)
    assert res.D == 20.0
    assert res.to_dict()["df_phase_deg"] == 0.0
    # f* (eq. 13) depends on the link stiffness only, not on the amplitude
    assert res.f_star_hz == pytest.approx(0.150, abs=5e-4)
