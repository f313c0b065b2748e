"""Tests of the exact periodic steady state of the nonlinear loop (steady.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionhyst.analysis.comparison import compare_with_describing_function
from motionhyst.analysis.quasilinear import loop_mismatch
from motionhyst.analysis.steady import (
    default_harmonics,
    periodic_steady_state,
    steady_state_sweep,
)
from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis.jenkins import Jenkins
from motionhyst.scenario import default_scenario

A_REF = 0.01  # section V: r = 10 mm sin(2 pi f t)
FREQS = (5.0, 10.0, 15.0)  # Fig. 11
A_LINEAR = 1e-3  # below the slip displacement fc / kJ = 2.5 mm of the Table I link


@pytest.fixture(scope="module")
def loop() -> Loop:
    return default_scenario().loop()


@pytest.fixture(scope="module")
def states(loop):
    return {f: periodic_steady_state(loop, A_REF, f) for f in FREQS}


@pytest.fixture(scope="module")
def linear_loop(loop) -> Loop:
    return Loop(loop.plant, loop.controller, None)


def omega(f):
    return np.array([2 * np.pi * f])


def test_table1_link_and_default_scenario(loop):
    assert isinstance(loop.hysteresis, Jenkins)
    assert (loop.hysteresis.k, loop.hysteresis.fc) == (20.0, 0.05)
    assert loop.feedforward == "rigid-body"


# ------------------------------------------------------------------ paper's claim (Fig. 11)


@pytest.mark.parametrize("f", FREQS)
def test_mismatch_matches_describing_function_within_one_percent(loop, states, f):
    """Section V: the describing function predicts the steady-state error (eq. 18)."""
    E_sim = states[f].mismatch
    E_df = complex(loop_mismatch(loop, f, A_REF)[0])
    assert abs(abs(E_sim) / abs(E_df) - 1.0) < 0.01
    assert abs(np.degrees(np.angle(E_sim / E_df))) < 1.0


def test_mismatch_values(states):
    """Fig. 10 at the Fig. 11 frequencies: large at 5 Hz, near 1 above the crossover."""
    assert abs(states[5.0].mismatch) == pytest.approx(6.04, rel=5e-3)
    assert abs(states[10.0].mismatch) == pytest.approx(1.24, rel=5e-3)
    assert abs(states[15.0].mismatch) == pytest.approx(1.043, rel=5e-3)


@pytest.mark.parametrize("f", FREQS)
def test_mismatch_is_e1_over_linear_e1(loop, states, f):
    ss = states[f]
    e_lin = complex(loop.transfer("r->e", omega(f))[0]) * A_REF
    assert ss.e_linear[1] == pytest.approx(e_lin, rel=1e-12)
    assert np.all(ss.e_linear[2:] == 0) and ss.e_linear[0] == 0
    assert ss.mismatch == pytest.approx(ss.e[1] / e_lin, rel=1e-12)


@pytest.mark.parametrize("f", FREQS)
def test_y1_tracks_reference(states, f):
    """In the stiff loop y1 follows r: its first harmonic is A to within a few 1e-3."""
    ss = states[f]
    assert ss.y1[1] == pytest.approx(A_REF, rel=5e-3)
    assert ss.y1[1] != A_REF


# --------------------------------------------------------------------------- convergence


@pytest.mark.parametrize("f", FREQS)
def test_doubling_harmonics_does_not_change_e1(loop, states, f):
    ss = states[f]
    assert ss.n_harmonics == default_harmonics(loop, f)
    ss2 = periodic_steady_state(loop, A_REF, f, n_harmonics=2 * ss.n_harmonics)
    assert ss2.n_harmonics == 2 * ss.n_harmonics
    assert abs(ss2.e[1] - ss.e[1]) < 1e-10 * abs(ss.e[1])
    assert abs(ss2.e[3] - ss.e[3]) < 1e-8 * abs(ss.e[1])


@pytest.mark.parametrize("f", FREQS)
def test_tighter_tolerance_gives_same_e1(loop, states, f):
    ss = states[f]
    assert ss.residual <= 1e-10
    tight = periodic_steady_state(loop, A_REF, f, tol=1e-15, max_iter=100)
    assert abs(tight.e[1] - ss.e[1]) < 1e-12 * abs(ss.e[1])
    loose = periodic_steady_state(loop, A_REF, f, tol=1e-6)
    assert abs(loose.e[1] - ss.e[1]) < 1e-5 * abs(ss.e[1])


# ---------------------------------------------------------------------------- linear case


def linear_closed_form_e1(loop: Loop, f: float, A: float) -> complex:
    """Loop with the link as a spring kJ (w = kJ y1): closed form from the loop's transfers.

    ``y1 = T_ry1 r + T_wy1 kJ y1`` and ``e = T_re r + T_we kJ y1`` give
    ``e = [T_re + T_we kJ T_ry1 / (1 - T_wy1 kJ)] r``.
    """
    w = omega(f)
    kj = loop.hysteresis.k
    t_re, t_ry1 = loop.transfer("r->e", w)[0], loop.transfer("r->y1", w)[0]
    t_we, t_wy1 = loop.transfer("w->e", w)[0], loop.transfer("w->y1", w)[0]
    return complex((t_re + t_we * kj * t_ry1 / (1 - t_wy1 * kj)) * A)


@pytest.mark.parametrize("f", [2.0, 10.0, 40.0])
def test_below_slip_amplitude_is_linear_loop_with_spring(loop, f):
    ss = periodic_steady_state(loop, A_LINEAR, f)
    # the link really never slips: y1 moves less than the slip displacement each way
    slip = loop.hysteresis.slip_displacement
    assert slip == pytest.approx(2.5e-3)
    assert abs(ss.y1[1]) < 0.5 * slip
    y1 = ss.time_series()["y1"]
    assert y1.max() - y1.min() < 2 * slip
    e1 = linear_closed_form_e1(loop, f, A_LINEAR)
    assert ss.e[1] == pytest.approx(e1, rel=1e-9)
    # the spring differs measurably from no link at all
    assert abs(e1 - ss.e_linear[1]) > 1e-6 * abs(e1)
    # a linear loop responds at the reference frequency only
    assert np.max(np.abs(np.delete(ss.e, 1))) <= 1e-12 * abs(ss.e[1])
    assert np.max(np.abs(ss.time_series()["w"])) < loop.hysteresis.fc


@pytest.mark.parametrize("f", FREQS)
def test_loop_without_hysteresis_gives_linear_error(loop, linear_loop, f):
    ss = periodic_steady_state(linear_loop, A_REF, f)
    assert_allclose(ss.e, ss.e_linear, rtol=0, atol=0)
    assert np.all(ss.w == 0)
    assert ss.mismatch == pytest.approx(1.0, abs=1e-15)
    assert ss.e[1] == pytest.approx(complex(loop.transfer("r->e", omega(f))[0]) * A_REF,
                                    rel=1e-12)
    assert ss.error_hysteresis_rms == 0.0
    assert ss.error_rms == pytest.approx(ss.error_linear_rms, rel=1e-14)


# ----------------------------------------------------------------------- derived measures


@pytest.mark.parametrize("f", FREQS)
def test_error_rms_is_rms_of_time_series(states, f):
    ss = states[f]
    ts = ss.time_series()
    assert ss.error_rms == pytest.approx(np.sqrt(np.mean(ts["e"] ** 2)), rel=1e-10)
    assert ss.error_hysteresis_rms == pytest.approx(
        np.sqrt(np.mean((ts["e"] - ts["e_linear"]) ** 2)), rel=1e-10)
    assert ss.error_linear_rms == pytest.approx(np.sqrt(np.mean(ts["e_linear"] ** 2)), rel=1e-10)
    assert ss.error_peak == pytest.approx(np.max(np.abs(ts["e"])), rel=1e-12)
    assert ss.error_rms < ss.error_peak <= np.sum(np.abs(ss.e))


@pytest.mark.parametrize("f", FREQS)
def test_time_series_is_synthesis_of_harmonics(states, f):
    ss = states[f]
    ts = ss.time_series(n_samples=2048)
    theta = 2 * np.pi * f * ts["t"]
    assert ts["t"][1] == pytest.approx(1 / (2048 * f))
    assert_allclose(ts["r"], A_REF * np.sin(theta), rtol=0, atol=1e-18)
    n = np.arange(1, ss.n_harmonics + 1)
    for key in ("e", "y1", "w", "e_linear"):
        c = getattr(ss, key)
        direct = c[0].real + np.imag(np.exp(1j * np.outer(theta, n)) @ c[1:])
        scale = np.max(np.abs(direct))
        assert_allclose(ts[key], direct, rtol=0, atol=1e-12 * scale)
    # the link force stays within its slip force (up to truncation of the corners of w)
    assert np.max(np.abs(ts["w"])) < 1.01 * 0.05


@pytest.mark.parametrize("f", FREQS)
def test_half_wave_symmetry(states, f):
    ss = states[f]
    for c in (ss.e, ss.y1, ss.w):
        assert np.max(np.abs(c[0::2])) < 1e-12 * abs(c[1])
    # the hysteresis makes odd harmonics: e3 is a sizeable part of the error
    assert abs(ss.e[3]) > 0.01 * abs(ss.e[1])


# --------------------------------------------------------------------------------- to_dict


@pytest.mark.parametrize("f", FREQS)
def test_to_dict_schema(loop, states, f):
    ss = states[f]
    E_df = complex(loop_mismatch(loop, f, A_REF)[0])
    d = ss.to_dict(mismatch_df=E_df)
    keys = {"frequency_hz", "amplitude", "error_harmonics", "error_linear_abs",
            "mismatch_simulated_abs", "mismatch_simulated_phase_deg", "mismatch_df_abs",
            "mismatch_df_phase_deg", "error_peak", "error_rms", "error_hysteresis_rms",
            "y1_amplitude"}
    assert keys <= set(d)
    json.dumps(d, allow_nan=False)  # JSON-ready
    assert d["frequency_hz"] == f and d["amplitude"] == A_REF
    assert [h["n"] for h in d["error_harmonics"]] == [1, 3, 5]
    for h in d["error_harmonics"]:
        assert set(h) == {"n", "abs", "phase_deg"}
        assert h["abs"] == pytest.approx(abs(ss.e[h["n"]]), rel=1e-15)
        assert h["phase_deg"] == pytest.approx(np.degrees(np.angle(ss.e[h["n"]])), abs=1e-12)
    assert d["error_linear_abs"] == pytest.approx(abs(ss.e_linear[1]), rel=1e-15)
    assert d["mismatch_simulated_abs"] == pytest.approx(abs(ss.mismatch), rel=1e-15)
    assert d["mismatch_simulated_phase_deg"] == pytest.approx(np.degrees(np.angle(ss.mismatch)))
    assert d["mismatch_df_abs"] == pytest.approx(abs(E_df), rel=1e-15)
    assert d["mismatch_df_phase_deg"] == pytest.approx(np.degrees(np.angle(E_df)))
    assert d["error_peak"] == pytest.approx(ss.error_peak)
    assert d["error_rms"] == pytest.approx(ss.error_rms)
    assert d["error_hysteresis_rms"] == pytest.approx(ss.error_hysteresis_rms)
    assert d["y1_amplitude"] == pytest.approx(abs(ss.y1[1]), rel=1e-15)
    # without a describing-function value the df keys are absent
    d0 = ss.to_dict()
    assert "mismatch_df_abs" not in d0 and "mismatch_df_phase_deg" not in d0
    assert d0["error_harmonics"] == d["error_harmonics"]


def test_to_dict_skips_harmonics_beyond_kept(loop):
    ss = periodic_steady_state(loop, A_REF, 10.0, n_harmonics=4)
    assert ss.n_harmonics == 4
    assert [h["n"] for h in ss.to_dict()["error_harmonics"]] == [1, 3]


def test_sweep_and_compare(loop, states):
    sweep = steady_state_sweep(loop, A_REF, list(FREQS))
    for ss in sweep:
        assert ss.e[1] == pytest.approx(states[ss.frequency_hz].e[1], rel=1e-14)
    rows = compare_with_describing_function(loop, A_REF, FREQS).to_dict()["points"]
    E_df = loop_mismatch(loop, np.array(FREQS), A_REF)
    assert [r["frequency_hz"] for r in rows] == list(FREQS)
    for row, e in zip(rows, E_df, strict=True):
        assert row["mismatch_df_abs"] == pytest.approx(abs(e), rel=1e-14)
        assert row["mismatch_simulated_abs"] == pytest.approx(abs(e), rel=0.01)


# -------------------------------------------------------------------------------- errors


@pytest.mark.parametrize("bad", [0.0, -0.01, np.nan, np.inf])
def test_invalid_amplitude_raises(loop, bad):
    with pytest.raises(ValueError, match="amplitude"):
        periodic_steady_state(loop, bad, 10.0)


@pytest.mark.parametrize("bad", [0.0, -10.0, np.nan, np.inf])
def test_invalid_frequency_raises(loop, bad):
    with pytest.raises(ValueError, match="frequency"):
        periodic_steady_state(loop, A_REF, bad)


def test_invalid_n_harmonics_raises(loop):
    with pytest.raises(ValueError, match="n_harmonics"):
        periodic_steady_state(loop, A_REF, 10.0, n_harmonics=0)


def test_loops_with_one_linear_part_share_transfers_and_keep_their_links(loop):
    """The transfers a frequency needs are kept by the loop's linear part: another loop with
    the same plant and controller and another link reuses them and gets its own numbers."""
    other = Loop(loop.plant, loop.controller, Jenkins(k=10.0, fc=0.08), loop.feedforward)
    assert other.transfer_key() == loop.transfer_key()
    first = periodic_steady_state(other, A_REF, 7.0)
    mine = periodic_steady_state(loop, A_REF, 7.0)
    again = periodic_steady_state(other, A_REF, 7.0)
    assert np.array_equal(again.e, first.e) and np.array_equal(again.w, first.w)
    assert abs(mine.mismatch - first.mismatch) > 0.1 * abs(mine.mismatch)
    assert Loop(loop.plant, loop.controller, None).transfer_key() == loop.transfer_key()
    softer = Loop(loop.plant, LeadLagLowpass(3.1e6, 60.0, 240.0, 700.0, 0.6), loop.hysteresis)
    assert softer.transfer_key() != loop.transfer_key()
