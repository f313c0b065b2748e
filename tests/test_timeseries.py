"""Long transient runs: chunked integration equals one run, rows at the output rate, summaries."""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest

from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis import BoucWen, LuGre, MaxwellSlip
from motionhyst.time.references import PointToPoint, SampledReference, SineReference
from motionhyst.time.simulation import default_step, simulate, simulate_chunks
from motionhyst.time.timeseries import COLUMNS, dynamics_step, run_time_series

A_REF = 0.01  # reference amplitude of section V [m]


def _loops(stage, controller, link):
    yield "jenkins+ff", Loop(stage, controller, link, feedforward="rigid-body",
                             hysteresis_feedforward=link)
    ms = MaxwellSlip([10.0, 6.0, 4.0], [0.01, 0.02, 0.03])
    yield "maxwell-slip+ff", Loop(stage, controller, ms, feedforward="rigid-body",
                                  hysteresis_feedforward=MaxwellSlip([9.0, 7.0], [0.02, 0.03]))
    yield "bouc-wen", Loop(stage, controller, BoucWen(k=20.0, fc=0.05, n=2.0),
                           feedforward="rigid-body")
    lugre = LuGre(sigma0=1e3, sigma1=5.0, sigma2=0.5, fc=0.05, fs=0.07, vs=1e-3)
    yield "lugre+ff", Loop(stage, controller, lugre, feedforward="rigid-body",
                           hysteresis_feedforward=lugre)


@pytest.mark.parametrize("chunk", [1, 7, 1000])
def test_a_run_in_chunks_is_the_run(stage, controller, link, chunk):
    ref = SineReference(A_REF, 20.0)
    for name, loop in _loops(stage, controller, link):
        whole = simulate(loop, ref, 0.02)
        pieces = list(simulate_chunks(loop, ref, 0.02, chunk=chunk))
        assert sum(len(p.t) for p in pieces) == len(whole.t), name
        for col, x in whole.columns().items():
            got = np.concatenate([p.columns()[col] for p in pieces])
            scale = np.max(np.abs(x)) or 1.0
            # the same arithmetic sample by sample; u's controller filter takes the step as
            # given rather than from the grid's end points, a difference of one ulp of dt
            tol = 1e-9 if col == "u" else 1e-13
            assert np.max(np.abs(got - x)) <= tol * scale, (name, col)


def test_the_step_follows_the_loop_not_the_reference_file(stage, controller, link):
    loop = Loop(stage, controller, link, feedforward="rigid-body")
    t = np.arange(0, 20_001) * 1e-4  # a 10 kHz setpoint file of 2 s
    ref = SampledReference(t, 1e-3 * (1 - np.cos(2 * np.pi * t)))
    h = dynamics_step(loop, ref)
    pole = float(np.max(np.abs(loop.closed_loop_poles())))
    assert h == pytest.approx(2 * np.pi / (40 * pole))
    assert h > 50 * default_step(loop, ref.max_frequency_hz)  # the old rule: 400 per sample
    buf = io.StringIO()
    s = run_time_series(loop, ref, 2.0, buf)
    assert s["output_rate_hz"] == pytest.approx(1e4) and s["samples"] == 20_001
    # the integration step divides the output period and stays at the loop's
    assert s["dt_s"] <= h and 1e-4 / s["dt_s"] == pytest.approx(round(1e-4 / s["dt_s"]))
    assert s["steps"] < 1.5 * 2.0 / h
    rows = pd.read_csv(io.StringIO(buf.getvalue()))
    assert list(rows.columns) == list(COLUMNS)
    np.testing.assert_allclose(rows["time"], t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rows["reference"], ref.r, rtol=0, atol=1e-12 * 2e-3)


def test_rows_are_samples_of_the_run(stage, controller, link):
    loop = Loop(stage, controller, link, feedforward="rigid-body")
    ref = SineReference(A_REF, 10.0)
    buf = io.StringIO()
    s = run_time_series(loop, ref, 0.3, buf, output_rate_hz=2000.0)
    rows = pd.read_csv(io.StringIO(buf.getvalue()))
    sim = simulate(loop, ref, 0.3, dt=s["dt_s"])
    k = round(1 / 2000.0 / s["dt_s"])
    assert len(rows) == 601 == s["samples"]
    for col, x in sim.columns().items():
        scale = np.max(np.abs(x)) or 1.0
        np.testing.assert_allclose(rows[col], x[::k][:601], rtol=0, atol=1e-11 * scale)


def test_sine_summary_separates_the_start_up(stage, controller, link):
    loop = Loop(stage, controller, link, feedforward="rigid-body")
    ref = SineReference(A_REF, 5.0)
    s = run_time_series(loop, ref, 1.0, None)
    lp = s["last_period"]
    assert (lp["start_s"], lp["end_s"]) == pytest.approx((0.8, 1.0))
    sim = simulate(loop, ref, 1.0, dt=s["dt_s"])
    last = (sim.t >= 0.8 - 0.5 * s["dt_s"]) & (sim.t < 1.0 - 0.5 * s["dt_s"])
    assert lp["error_peak"] == pytest.approx(np.max(np.abs(sim.e[last])), rel=1e-12)
    assert lp["error_rms"] == pytest.approx(np.sqrt(np.mean(sim.e[last] ** 2)), rel=1e-12)
    assert lp["error_linear_rms"] == pytest.approx(np.sqrt(np.mean(sim.e_linear[last] ** 2)),
                                                   rel=1e-12)
    # the start-up dominates the whole-run peak, with and without hysteresis alike; over the
    # last period the hysteresis shows: its error is several times the linear loop's
    assert s["error_peak"] > 1000 * lp["error_peak"]
    assert s["error_peak"] == pytest.approx(s["error_linear_peak"], rel=1e-3)
    assert lp["error_rms"] > 3 * lp["error_linear_rms"]
    short = run_time_series(loop, ref, 0.1, None)
    assert short["last_period"] is None


def test_point_to_point_summary(stage, controller, link):
    loop = Loop(stage, controller, link, feedforward="rigid-body")
    ref = PointToPoint(0.01, 0.5, 10.0, 1000.0)
    band = 1e-8
    s = run_time_series(loop, ref, ref.duration + 0.2, None, settle_band=band)
    mv = s["move"]
    sim = simulate(loop, ref, s["duration_s"], dt=s["dt_s"])
    moving = sim.t <= ref.duration
    assert mv["error_peak"] == pytest.approx(np.max(np.abs(sim.e[moving])), rel=1e-12)
    outside = np.flatnonzero(np.abs(sim.e) > band)
    assert mv["settling_time_s"] == pytest.approx(sim.t[outside[-1]] + s["dt_s"]
                                                  - ref.duration, rel=1e-9)
    assert abs(s["error_final"]) <= band
    # a band the run never reaches: not settled, said as None
    tight = run_time_series(loop, ref, ref.duration + 0.2, None, settle_band=1e-12)
    assert tight["move"]["settling_time_s"] is None


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"duration": 0.0}, "duration"),
    ({"output_rate_hz": -1.0}, "output rate"),
    ({"output_rate_hz": 1.0}, "longer than the duration"),
    ({"settle_band": 0.0}, "settle band"),
    ({"duration": 200.0, "output_rate_hz": 1e6}, "too many"),
])
def test_bad_arguments(stage, controller, link, kwargs, match):
    loop = Loop(stage, controller, link)
    args = {"duration": 0.1, **kwargs}
    duration = args.pop("duration")
    with pytest.raises(ValueError, match=match):
        run_time_series(loop, SineReference(A_REF, 5.0), duration, None, **args)
