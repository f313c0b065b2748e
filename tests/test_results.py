"""Results present themselves: to_dict (the JSON keys), __str__ (a readable table) and plot()
(a figure carrying the data it draws) agree with the result's own numbers."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst import SineReference, analyze, default_scenario, periodic_steady_state, simulate
from motionhyst.analysis.comparison import compare_with_describing_function
from motionhyst.core.textfmt import g
from motionhyst.hysteresis import MaxwellSlip
from motionhyst.identify import identify_maxwell_slip


@pytest.fixture(scope="module")
def loop():
    return default_scenario().loop()


def test_analysis_prints_and_plots_its_points(loop):
    res = analyze(loop, 0.01, [5.0, 10.0])
    text = str(res)
    for p in res.points:
        assert g(abs(p.value)) in text
    assert g(res.mismatch_crossover_hz) in text and g(res.f_star_hz) in text
    data = res.plot().motionhyst_data
    np.testing.assert_array_equal(data["E"], [p.value for p in res.points])


def test_steady_state_prints_and_plots_one_period(loop):
    ss = periodic_steady_state(loop, 0.01, 5.0)
    text = str(ss)
    assert g(abs(ss.mismatch)) in text and g(abs(ss.e[3])) in text
    data = ss.plot().motionhyst_data
    assert np.max(np.abs(data["e"])) == pytest.approx(ss.error_peak, rel=1e-12)


def test_comparison_is_its_points(loop):
    cmp = compare_with_describing_function(loop, 0.01, [5.0, 10.0])
    d = cmp.to_dict()
    assert [p["frequency_hz"] for p in d["points"]] == [5.0, 10.0]
    text = str(cmp)
    for p in d["points"]:
        assert g(p["mismatch_df_abs"]) in text and g(p["mismatch_simulated_abs"]) in text
    assert len(cmp.plot().axes) == 2


def test_simulation_summary_matches_its_signals(loop):
    sim = simulate(loop, SineReference(0.01, 5.0), 0.2)
    d = sim.to_dict()
    assert d["samples"] == sim.t.size
    assert d["error_peak"] == np.max(np.abs(sim.e))
    assert d["error_rms"] == pytest.approx(np.sqrt(np.mean(sim.e ** 2)), rel=1e-14)
    assert d["link_force_peak"] == pytest.approx(0.05, rel=1e-9)  # the Jenkins link slips
    assert g(d["error_peak"]) in str(sim)
    np.testing.assert_array_equal(sim.plot().motionhyst_data["w"], sim.w)


def test_identification_prints_its_elements_and_draws_the_model():
    t = np.linspace(0.0, 4.0, 4001)
    x = 0.01 * np.exp(-t / 2) * np.sin(2 * np.pi * 2.0 * t)
    ident = identify_maxwell_slip(x, MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x),
                                  t=t)
    text = str(ident)
    assert "elements: 2" in text and g(10.0, 6) in text and g(0.03, 6) in text
    loops = list(ident.plot().motionhyst_data.values())  # amplitudes 0.5, 1, 2, 4 x fc / k
    peaks = [float(np.max(xw[1])) for xw in loops]
    assert peaks[-1] == pytest.approx(float(np.sum(ident.model.fc)), rel=1e-9)  # all slip
    assert peaks[0] < peaks[-1]
