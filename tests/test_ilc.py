"""Tests of the frequency-domain iterative learning control (ilc.py)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import FC_LINK
from numpy.testing import assert_allclose

from motionhyst.controllers.loop import Loop
from motionhyst.scan.ilc import ILCFilters, learn
from motionhyst.scan.profiles import point_to_point, scan
from motionhyst.time.simulation import simulate


def test_filters_as_stated(loop):
    q = ILCFilters(gain=0.5, cutoff_hz=200.0, order=3)
    f = np.array([0.0, 100.0, 200.0, 400.0])
    assert_allclose(q.robustness(f), 1 / (1 + (f / 200.0) ** 6), rtol=1e-15)
    assert_allclose(q.learning(loop, f), 0.5 / loop.transfer("w->e", 2 * np.pi * f),
                    rtol=1e-14)
    d = q.to_dict()
    assert d["gain"] == 0.5 and d["robustness_cutoff_hz"] == 200.0 and d["robustness_order"] == 3


@pytest.mark.parametrize("kw", [{"gain": 0.0}, {"gain": 2.0}, {"gain": np.nan},
                                {"cutoff_hz": 0.0}, {"order": 0}, {"order": 1.5}])
def test_filters_invalid(kw):
    with pytest.raises(ValueError):
        ILCFilters(**kw)


def test_linear_loop_learns_in_one_trial_up_to_the_robustness_filter(stage, controller):
    # without the link the loop is linear: f2 = Q L e1 gives e2 = (1 - Q) e1, which the
    # low-frequency error of a rigid-body-fed move barely has above a 2 kHz Q
    loop = Loop(stage, controller)
    p = point_to_point(0.01, 0.2, 20.0, 2000.0, 1e6, start=0.01)
    res = learn(loop, p, p.end + 0.02, trials=2, filters=ILCFilters(cutoff_hz=2000.0, order=4))
    assert res.rms_errors[1] < 2e-3 * res.rms_errors[0]
    # half the gain halves the error per trial
    half = learn(loop, p, p.end + 0.02, trials=3, filters=ILCFilters(gain=0.5, cutoff_hz=2000.0,
                                                                       order=4))
    assert_allclose(np.array(half.rms_errors[1:]) / half.rms_errors[:-1], 0.5, rtol=0.02)


def test_learned_force_supplies_the_slipping_link_force(loop):
    p = scan(0.01, speed=0.05, a_max=2.0, j_max=50.0, s_max=1e3, start=0.01)
    res = learn(loop, p, p.end + 0.02, trials=4)
    assert res.trials == 4 and len(res.peak_errors) == 4
    assert res.rms_errors[-1] < res.rms_errors[0] / 100
    cv = p.constant_velocity_phases()[0]
    late = (res.t > cv.end - 0.1) & (res.t < cv.end - 0.02)
    # at constant velocity the link slips with w = fc, which the force must supply
    assert_allclose(res.force[late], FC_LINK, rtol=2e-3)
    assert "4 trials" in str(res) and len(res.plot().axes) == 1
    d = res.to_dict()
    assert d["trials"] == res.rms_errors and d["gain"] == 1.0


def test_force_function_is_linear_between_samples_and_held_after(loop):
    p = point_to_point(0.002, 0.05, 2.0, 50.0, 1e3, start=0.005)
    res = learn(loop, p, p.end + 0.01, trials=2)
    f = res.force_function()
    mid = 0.5 * (res.t[10] + res.t[11])
    assert f(mid) == pytest.approx(0.5 * (res.force[10] + res.force[11]), rel=1e-12)
    assert f(-1.0) == 0.0 and f(res.t[-1] + 1.0) == res.force[-1]
    # replayed on the same grid it gives the last trial again
    again = simulate(loop, p, p.end + 0.01, res.t[1] - res.t[0], force=f)
    assert_allclose(again.e, res.last.e, rtol=0, atol=1e-12 * np.max(np.abs(res.last.e)))


def test_invalid_trials(loop):
    p = point_to_point(0.002, 0.05, 2.0, 50.0, 1e3)
    with pytest.raises(ValueError, match="trials"):
        learn(loop, p, 0.1, trials=0)


def test_simulate_rejects_a_force_that_does_not_fit_the_grid(loop):
    p = point_to_point(0.002, 0.05, 2.0, 50.0, 1e3)
    with pytest.raises(ValueError, match="force"):
        simulate(loop, p, 0.05, force=lambda t: np.zeros(3))
    with pytest.raises(ValueError, match="force"):
        simulate(loop, p, 0.05, force=lambda t: np.full(t.shape, np.nan))
