"""Tests of motionhyst.analysis.margins: gain, phase, modulus margins of C P2 vs python-control."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

from motionhyst.analysis.margins import BANDWIDTH_DEFINITION, loop_margins
from motionhyst.analysis.quasilinear import analyze
from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import freqresp
from motionhyst.plants.frf_fit import ModalPlant, Mode
from motionhyst.plants.measured import MeasuredPlant
from motionhyst.plants.two_mass import TwoMassStage

TABLE_I = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)


def reference(C, P2):
    """python-control's margins of C P2, frequencies in Hz."""
    gm, pm, sm, wg, wp, ws = control.stability_margins(C * P2)
    return gm, pm, sm, wg / (2 * np.pi), wp / (2 * np.pi), ws / (2 * np.pi)


CASES = [
    pytest.param(LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6), TABLE_I.P2, id="table-I"),
    pytest.param(LeadLagLowpass(2.0e6, 30.0, 120.0, 400.0, 0.7), TABLE_I.P2, id="slower"),
    pytest.param(LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6),
                 ModalPlant(22.5, [Mode(694.0, 0.003, 0.1555, 0.0444),
                                   Mode(1800.0, 0.01, 0.05, -0.02)]).P2, id="two-modes"),
    pytest.param(control.tf([3.0e4, 1.0e6], [1 / 600**2, 2 / 600, 1.0]),
                 control.tf([1.0], [2.0, 10.0, 0.0]), id="filtered-pd-on-mass-damper"),
]


@pytest.mark.parametrize(("C", "P2"), CASES)
def test_margins_agree_with_python_control(C, P2):
    m = loop_margins(C, P2)
    gm, pm, sm, fg, fp, fs = reference(C, P2)
    assert m.gain_margin == pytest.approx(gm, rel=1e-6)
    assert m.gain_margin_hz == pytest.approx(fg, rel=1e-6)
    assert m.phase_margin_deg == pytest.approx(pm, rel=1e-6, abs=1e-6)
    assert m.phase_margin_hz == pytest.approx(fp, rel=1e-6)
    assert m.modulus_margin == pytest.approx(sm, rel=1e-6)
    assert m.modulus_margin_hz == pytest.approx(fs, rel=1e-3)
    # the definitions themselves, evaluated here
    w = 2 * np.pi * np.array([m.gain_margin_hz, m.phase_margin_hz])
    L = freqresp(C, w) * freqresp(P2, w)
    assert abs(L[0].imag) < 1e-6 * abs(L[0]) and L[0].real < 0
    assert abs(L[1]) == pytest.approx(1.0, rel=1e-9)
    assert m.gain_margin_db == pytest.approx(20 * math.log10(gm), rel=1e-6)


def test_table_I_values_and_bandwidth():
    C = LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6)
    m = loop_margins(C, TABLE_I.P2)
    assert m.bandwidth_hz == pytest.approx(120.6, abs=0.1)  # the paper's f_bw = 120 Hz
    assert m.bandwidth_hz == pytest.approx(m.phase_margin_hz, rel=1e-12)  # one crossover
    # modulus margin = 1 / max |S| on a dense grid
    f = np.geomspace(1.0, 1e4, 200001)
    S = 1 / (1 + freqresp(C, 2 * np.pi * f) * freqresp(TABLE_I.P2, 2 * np.pi * f))
    assert m.modulus_margin == pytest.approx(1 / np.max(np.abs(S)), rel=1e-6)
    d = m.to_dict()
    assert d["bandwidth_definition"] == BANDWIDTH_DEFINITION
    assert {"gain_margin_db", "phase_margin_deg", "modulus_margin", "gain_margin_hz",
            "phase_margin_hz", "modulus_margin_hz"} <= d.keys()


def test_no_phase_crossing_gives_infinite_gain_margin():
    m = loop_margins(control.tf([10.0], [1.0, 0.0]), control.tf([1.0], [1.0]))  # L = 10/s
    assert math.isinf(m.gain_margin) and math.isnan(m.gain_margin_hz)
    assert m.phase_margin_deg == pytest.approx(90.0, abs=1e-6)
    assert m.bandwidth_hz == pytest.approx(10 / (2 * np.pi), rel=1e-9)


def test_measured_lines_only():
    """On data the margins come from the measured lines: close to the model's on a fine grid."""
    C = LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6)
    f = np.geomspace(1.0, 3000.0, 400)
    w = 2 * np.pi * f
    P2 = control.frd(freqresp(TABLE_I.P2, w), w)
    m, exact = loop_margins(C, P2), loop_margins(C, TABLE_I.P2)
    assert m.evaluated_on == "measured lines"
    assert m.phase_margin_deg == pytest.approx(exact.phase_margin_deg, abs=0.05)
    assert m.gain_margin_db == pytest.approx(exact.gain_margin_db, abs=0.05)
    assert m.bandwidth_hz == pytest.approx(exact.bandwidth_hz, rel=1e-3)
    assert exact.modulus_margin <= m.modulus_margin <= exact.modulus_margin * 1.001
    assert np.any(np.isclose(f, m.modulus_margin_hz, rtol=1e-12))  # a measured line


def test_analyze_reports_margins(loop, controller, stage):
    a = analyze(loop, 0.01, [5.0])
    ref = reference(controller, stage.P2)
    d = a.to_dict()
    assert d["gain_margin_db"] == pytest.approx(20 * math.log10(ref[0]), rel=1e-6)
    assert d["phase_margin_deg"] == pytest.approx(ref[1], rel=1e-6)
    assert d["modulus_margin"] == pytest.approx(ref[2], rel=1e-6)
    assert d["bandwidth_hz"] == pytest.approx(a.margins.bandwidth_hz, rel=1e-6)
    text = str(a)
    for fragment in ("gain margin", "phase margin", "modulus margin 1/max|S|", "crossover "
                     "frequency"):
        assert fragment in text


def test_analyze_margins_on_measured_data(stage, controller, link):
    f = np.geomspace(1.0, 3000.0, 200)
    w = 2 * np.pi * f
    plant = MeasuredPlant(control.frd(freqresp(stage.P1, w), w, smooth=True),
                          control.frd(freqresp(stage.P2, w), w, smooth=True), M=stage.M)
    a = analyze(Loop(plant, controller, link), 0.01, [f[100]])
    assert a.margins.evaluated_on == "measured lines"
    assert a.to_dict()["margins_evaluated_on"] == "measured lines"
    assert "measured lines" in str(a.margins)


@pytest.mark.parametrize("b", [5.0, 0.5])
def test_a_resonance_narrower_than_the_grid_keeps_its_modulus_margin(b):
    """Table I's controller behind 0.375 ms of delay (a 5th-order Pade approximant): the
    Nyquist curve's loop around the stage's mode, at damping ratios 1.5e-4 and 1.5e-5
    (b = 5, 0.5 N s/m), passes nearer -1 than the curve does at the crossover (0.1347 at
    126 Hz). The least |1 + L| there is found, against python-control's exact evaluation of
    L within 5 % of the mode, 60 points a width at b = 0.5, refined by a bounded search."""
    from scipy.optimize import minimize_scalar

    num, den = control.pade(3.75e-4, 5)
    C = LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6) * control.tf(num, den)
    P2 = TwoMassStage(5.0, 17.5, b, 7.4e7).P2
    L = C * P2
    fn = abs(P2.poles()).max() / (2 * np.pi)
    f = fn * (1.0 + np.linspace(-0.05, 0.05, 400001))
    d = np.abs(1.0 + L(2j * np.pi * f))
    i = int(np.argmin(d))

    def dist(x):
        return abs(1.0 + complex(L(2j * np.pi * x)))

    best = minimize_scalar(dist, bounds=(f[i - 1], f[i + 1]), method="bounded",
                           options={"xatol": 1e-12 * fn})
    m = loop_margins(C, P2)
    assert best.fun < 0.13                       # below the crossover's 0.1347
    assert m.modulus_margin == pytest.approx(best.fun, rel=1e-6)
    assert m.modulus_margin_hz == pytest.approx(best.x, rel=1e-7)
