"""Tests of the linear parts: two-mass stage (eqs. 1-2), controller (eq. 23), measured plants."""

from __future__ import annotations

import csv

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionhyst.controllers.leadlag import LeadLagLowpass, bandwidth
from motionhyst.core.lti import freqresp
from motionhyst.plants.measured import MeasuredPlant, load_frd_plant
from motionhyst.plants.two_mass import TwoMassStage

FREQS_HZ = np.array([0.01, 0.1, 1.0, 10.0, 100.0, 500.0, 694.0, 1000.0, 5000.0])


def paper_parts(m1, m2, b, k, s):
    """Pr, Pf1, Pf2 of eqs. (1)-(2) evaluated directly at complex `s`."""
    M = m1 + m2
    q = M * (m1 * m2 * s**2 + b * M * s + k * M)
    return 1.0 / (M * s**2), m2**2 / q, m1 * m2 / q


def eq23(K, f1, f2, flp, beta, s):
    """Controller of eq. (23) evaluated directly."""
    wl = 2 * np.pi * flp
    return (K * (f2 / f1) * (s + 2 * np.pi * f1) / (s + 2 * np.pi * f2)
            * wl**2 / (s**2 + 4 * beta * np.pi * flp * s + wl**2))


# ---------------------------------------------------------------------------
# TwoMassStage
# ---------------------------------------------------------------------------


def test_stage_transfers_match_eqs_1_2(stage):
    s = 2j * np.pi * FREQS_HZ
    Pr, Pf1, Pf2 = paper_parts(stage.m1, stage.m2, stage.b, stage.k, s)
    omega = 2 * np.pi * FREQS_HZ
    assert_allclose(freqresp(stage.P1, omega), Pr + Pf1, rtol=1e-12)
    assert_allclose(freqresp(stage.P2, omega), Pr - Pf2, rtol=1e-12)
    assert_allclose(freqresp(stage.Pr, omega), Pr, rtol=1e-12)
    assert_allclose(freqresp(stage.Pf1, omega), Pf1, rtol=1e-12)
    assert_allclose(freqresp(stage.Pf2, omega), Pf2, rtol=1e-12)
    # python-control's own evaluation agrees with motionhyst.freqresp
    assert_allclose([complex(stage.P1(si)) for si in s], Pr + Pf1, rtol=1e-12)
    assert_allclose([complex(stage.P2(si)) for si in s], Pr - Pf2, rtol=1e-12)
    assert stage.M == stage.m1 + stage.m2 == 22.5


def test_stage_state_space_matches_transfer_functions(stage):
    sys = stage.ss()
    assert (sys.ninputs, sys.noutputs, sys.nstates) == (1, 2, 4)
    omega = 2 * np.pi * FREQS_HZ
    resp = np.array([sys(1j * w)[:, 0] for w in omega])
    assert_allclose(resp[:, 0], freqresp(stage.P1, omega), rtol=1e-9)
    assert_allclose(resp[:, 1], freqresp(stage.P2, omega), rtol=1e-9)


def test_stage_resonance(stage):
    wr = np.sqrt(stage.k * stage.M / (stage.m1 * stage.m2))
    assert stage.resonance_hz == pytest.approx(wr / (2 * np.pi), rel=1e-14)
    assert stage.resonance_hz == pytest.approx(694.27, abs=0.01)
    poles = control.poles(stage.P1)
    flex = poles[np.abs(poles) > 1.0]
    assert flex.size == 2
    assert_allclose(np.abs(flex), wr, rtol=1e-12)
    # damping ratio of the mode: b M / (2 sqrt(k M m1 m2))
    zeta_mode = stage.b * stage.M / (2 * np.sqrt(stage.k * stage.M * stage.m1 * stage.m2))
    assert_allclose(-flex.real / np.abs(flex), zeta_mode, rtol=1e-9)
    # two rigid-body poles at the origin
    assert np.sum(np.abs(poles) < 1e-9) == 2
    # the collocated transfer has an antiresonance at sqrt(k / m2)
    zeros = control.zeros(stage.P1)
    assert_allclose(np.abs(zeros), np.sqrt(stage.k / stage.m2), rtol=1e-12)
    # and its magnitude peaks near the resonance (lightly damped mode)
    f = np.linspace(600, 800, 20001)
    mag = np.abs(freqresp(stage.Pf1, 2 * np.pi * f))
    assert f[np.argmax(mag)] == pytest.approx(stage.resonance_hz, abs=0.05)


def test_stage_to_dict_and_zero_damping():
    st = TwoMassStage(m1=1.0, m2=2.0, b=0.0, k=3.0)
    assert st.to_dict() == {"m1": 1.0, "m2": 2.0, "b": 0.0, "k": 3.0}


@pytest.mark.parametrize(
    "kwargs",
    [{"m1": 0.0}, {"m1": -1.0}, {"m2": np.nan}, {"k": 0.0}, {"k": np.inf}, {"b": -1.0},
     {"b": np.nan}],
)
def test_stage_invalid_parameters(kwargs):
    params = {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7} | kwargs
    with pytest.raises(ValueError):
        TwoMassStage(**params)


# ---------------------------------------------------------------------------
# LeadLagLowpass and bandwidth
# ---------------------------------------------------------------------------


def test_controller_matches_eq_23(controller):
    assert isinstance(controller, control.TransferFunction)
    s = 2j * np.pi * FREQS_HZ
    ref = eq23(6.2e6, 60.0, 240.0, 700.0, 0.6, s)
    assert_allclose(freqresp(controller, 2 * np.pi * FREQS_HZ), ref, rtol=1e-12)
    assert_allclose([complex(controller(si)) for si in s], ref, rtol=1e-12)
    # the gain K is the DC gain, and the high-frequency roll-off is -2 (relative degree 2)
    assert complex(controller(0)) == pytest.approx(6.2e6, rel=1e-14)
    assert controller.to_dict() == {"type": "leadlag-lowpass", "K": 6.2e6, "f1": 60.0,
                                    "f2": 240.0, "flp": 700.0, "beta": 0.6}


def test_controller_is_stable_minimum_phase(controller):
    assert np.all(control.poles(controller).real < 0)
    assert_allclose(control.zeros(controller), [-2 * np.pi * 60.0], rtol=1e-12)


@pytest.mark.parametrize(
    "kwargs",
    [{"K": 0.0}, {"K": -1.0}, {"f1": 0.0}, {"f2": np.nan}, {"flp": -700.0}, {"beta": 0.0},
     {"beta": np.inf}],
)
def test_controller_invalid_parameters(kwargs):
    params = {"K": 6.2e6, "f1": 60.0, "f2": 240.0, "flp": 700.0, "beta": 0.6} | kwargs
    with pytest.raises(ValueError):
        LeadLagLowpass(**params)


def test_table1_bandwidth(stage, controller):
    fbw = bandwidth(controller, stage.P2)
    assert 115.0 < fbw < 125.0  # the paper: 120 Hz
    assert fbw == pytest.approx(120.65, abs=1.0)
    # it really is the first 0 dB crossing of C P2 (eq. 23 and eq. 1 evaluated directly)
    s = 2j * np.pi * fbw
    Pr, _, Pf2 = paper_parts(stage.m1, stage.m2, stage.b, stage.k, s)
    L = eq23(6.2e6, 60.0, 240.0, 700.0, 0.6, s) * (Pr - Pf2)
    assert abs(L) == pytest.approx(1.0, rel=1e-9)
    f_below = np.geomspace(1e-3, fbw, 2000)[:-1]
    sb = 2j * np.pi * f_below
    Pr, _, Pf2 = paper_parts(stage.m1, stage.m2, stage.b, stage.k, sb)
    assert np.all(np.abs(eq23(6.2e6, 60.0, 240.0, 700.0, 0.6, sb) * (Pr - Pf2)) > 1.0)


def test_bandwidth_nan_without_crossing(stage, controller):
    assert np.isnan(bandwidth(controller, stage.P2, f_min=200.0, f_max=500.0))


def test_freqresp_rejects_unknown_type():
    with pytest.raises(TypeError):
        freqresp("not a system", [1.0])


# ---------------------------------------------------------------------------
# Measured plants from CSV
# ---------------------------------------------------------------------------

FRD_HZ = np.geomspace(0.5, 3000.0, 40)


def write_csv(path, header, rows):
    with path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        writer.writerows(rows)
    return path


def stage_csv(path, stage, fmt):
    omega = 2 * np.pi * FRD_HZ
    p1, p2 = freqresp(stage.P1, omega), freqresp(stage.P2, omega)
    if fmt == "reim":
        header = ["frequency_hz", "p1_re", "p1_im", "p2_re", "p2_im"]
        cols = [FRD_HZ, p1.real, p1.imag, p2.real, p2.imag]
    else:
        header = ["frequency_hz", "p1_abs", "p1_phase_deg", "p2_abs", "p2_phase_deg"]
        cols = [FRD_HZ, np.abs(p1), np.degrees(np.angle(p1)), np.abs(p2),
                np.degrees(np.angle(p2))]
    rows = [[repr(float(v)) for v in row] for row in zip(*cols, strict=True)]
    return write_csv(path, header, rows)


@pytest.mark.parametrize("fmt", ["reim", "absphase"])
def test_load_frd_plant_reproduces_stage(tmp_path, stage, fmt):
    path = stage_csv(tmp_path / f"plant_{fmt}.csv", stage, fmt)
    mp = load_frd_plant(path, mass=stage.M)
    assert isinstance(mp, MeasuredPlant)
    assert isinstance(mp.P1, control.FrequencyResponseData)
    assert mp.M == stage.M
    assert mp.source == str(path)
    omega = 2 * np.pi * FRD_HZ
    assert_allclose(freqresp(mp.P1, omega), freqresp(stage.P1, omega), rtol=1e-12)
    assert_allclose(freqresp(mp.P2, omega), freqresp(stage.P2, omega), rtol=1e-12)
    lo, hi = mp.frequency_range_hz
    assert lo == pytest.approx(FRD_HZ[0], rel=1e-14)
    assert hi == pytest.approx(FRD_HZ[-1], rel=1e-14)
    assert_allclose(freqresp(mp.Pr, omega), freqresp(stage.Pr, omega), rtol=1e-14)


def test_load_frd_plant_estimates_mass(tmp_path, stage):
    mp = load_frd_plant(stage_csv(tmp_path / "plant.csv", stage, "reim"))
    # the flexible part biases -1 / (omega^2 Re P2) by ~ m1 m2 omega^2 / (k M), 1e-5 at 5 Hz
    assert mp.M == pytest.approx(stage.M, rel=1e-5)


def test_load_frd_plant_bandwidth(tmp_path, stage, controller):
    mp = load_frd_plant(stage_csv(tmp_path / "plant.csv", stage, "reim"), mass=stage.M)
    # interpolation between 40 log-spaced points moves the crossing only slightly
    assert bandwidth(controller, mp.P2) == pytest.approx(bandwidth(controller, stage.P2),
                                                         abs=0.5)


def test_load_frd_plant_missing_column(tmp_path):
    path = write_csv(tmp_path / "p.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re"],
                     [[1, 1, 0, 1], [2, 1, 0, 1]])
    with pytest.raises(ValueError, match="need columns p1_re, p1_im, p2_re, p2_im"):
        load_frd_plant(path, mass=1.0)


def test_load_frd_plant_missing_frequency(tmp_path):
    path = write_csv(tmp_path / "p.csv", ["f", "p1_re", "p1_im", "p2_re", "p2_im"],
                     [[1, 1, 0, 1, 0], [2, 1, 0, 1, 0]])
    with pytest.raises(ValueError, match="missing column 'frequency_hz'"):
        load_frd_plant(path, mass=1.0)


def test_load_frd_plant_non_numeric(tmp_path):
    path = write_csv(tmp_path / "p.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re", "p2_im"],
                     [[1, 1, 0, 1, 0], [2, "abc", 0, 1, 0]])
    with pytest.raises(ValueError, match="non-numeric"):
        load_frd_plant(path, mass=1.0)


@pytest.mark.parametrize("freqs", [[1.0, 1.0, 2.0], [1.0, 3.0, 2.0], [0.0, 1.0, 2.0]])
def test_load_frd_plant_bad_frequencies(tmp_path, freqs):
    rows = [[f, -1.0, 0.0, -1.0, 0.0] for f in freqs]
    path = write_csv(tmp_path / "p.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re", "p2_im"],
                     rows)
    with pytest.raises(ValueError, match="positive and increasing"):
        load_frd_plant(path, mass=1.0)


def test_load_frd_plant_other_errors(tmp_path):
    with pytest.raises(ValueError, match="cannot read"):
        load_frd_plant(tmp_path / "nope.csv")
    empty = write_csv(tmp_path / "empty.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re",
                                               "p2_im"], [])
    with pytest.raises(ValueError, match="no data rows"):
        load_frd_plant(empty)
    nonfinite = write_csv(tmp_path / "nan.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re",
                                                 "p2_im"], [[1, 1, 0, 1, 0], [2, "nan", 0, 1, 0]])
    with pytest.raises(ValueError, match="non-finite"):
        load_frd_plant(nonfinite, mass=1.0)
    # P2 with positive real part: no rigid-body mass can be estimated
    positive = write_csv(tmp_path / "pos.csv", ["frequency_hz", "p1_re", "p1_im", "p2_re",
                                                "p2_im"], [[1, 1, 0, 1, 0], [2, 1, 0, 1, 0]])
    with pytest.raises(ValueError, match="rigid-body mass"):
        load_frd_plant(positive)
