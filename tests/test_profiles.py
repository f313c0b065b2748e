"""Tests of the fourth-order (snap-limited) setpoint profiles (profiles.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import cumulative_trapezoid

from motionhyst.scan.profiles import point_to_point, scan

# (length, v, a, j, s): every limit reached; short moves that reach only some of them
FULL = [(0.1, 0.5, 10.0, 500.0, 5e4), (-0.3, 1.0, 30.0, 3000.0, 1e6)]
SHORT = [(0.002, 1.0, 30.0, 3000.0, 1e6), (1e-5, 1.0, 30.0, 3000.0, 1e6),
         (0.05, 2.0, 50.0, 400.0, 1e6), (0.05, 0.3, 50.0, 4000.0, 2e4)]


def fine(profile, n: int = 200_001, after: float = 0.01):
    t = np.linspace(0.0, profile.end + after, n)
    return t, profile.derivatives(t)


def assert_within_limits(profile, d, rel: float = 1e-9):
    lim = profile.limits
    for k, name in enumerate(("v_max", "a_max", "j_max", "s_max"), start=1):
        assert np.max(np.abs(d[k])) <= lim[name] * (1 + rel), name


@pytest.mark.parametrize("move", FULL + SHORT)
def test_point_to_point_is_exact_and_within_limits(move):
    L, v, a, j, s = move
    p = point_to_point(L, v, a, j, s, start=0.004)
    t, d = fine(p)
    assert_within_limits(p, d)
    assert np.all(d[:, t < p.start] == 0)
    end = t >= p.end
    assert np.all(d[0, end] == L) and np.all(d[1:, end] == 0)
    # the derivatives are those of one another (integrate each to the one below; the
    # trapezoidal rule errs by at most S dt / 2 at each of the 16 jumps of the snap)
    dt = t[1] - t[0]
    for k in range(4):
        integral = d[k, 0] + cumulative_trapezoid(d[k + 1], t, initial=0.0)
        tol = 2e-6 * np.max(np.abs(d[k])) if k < 3 else 8 * dt * np.max(np.abs(d[4]))
        assert np.max(np.abs(integral - d[k])) <= tol, k
    # the snap is +-S in pulses of T_s, the boxcar durations superincreasing
    ts, tj, ta, tv = p.durations
    assert tj >= ts and ta >= ts + tj - 1e-15 and tv >= ts + tj + ta - 1e-15
    assert_allclose(np.abs(d[4][d[4] != 0]), abs(L) / (ts * tj * ta * tv), rtol=1e-12)


@pytest.mark.parametrize("move", FULL)
def test_point_to_point_reaching_every_limit_is_time_optimal(move):
    # all four limits reached: T_s = J/S, T_j = A/J, T_a = V/A, T_v = L/V (Lambrechts 2005)
    L, v, a, j, s = move
    p = point_to_point(L, v, a, j, s)
    assert_allclose(p.durations, (j / s, a / j, v / a, abs(L) / v), rtol=1e-12)
    assert_allclose(list(p.reached().values()), [v, a, j, s], rtol=1e-12)
    _t, d = fine(p)
    for k, lim in enumerate((v, a, j, s), start=1):
        assert np.max(np.abs(d[k])) == pytest.approx(lim, rel=1e-3)


@pytest.mark.parametrize("move", SHORT)
def test_short_move_is_limited_by_its_length(move):
    # a limit not reached has a binding constraint below it: raising that limit alone
    # does not shorten the move, raising all of them does
    L, v, a, j, s = move
    p = point_to_point(L, v, a, j, s)
    reached = p.reached()
    assert reached["speed"] <= v * (1 + 1e-12)
    for k, name in enumerate(("v_max", "a_max", "j_max", "s_max")):
        if list(reached.values())[k] < 0.999 * p.limits[name]:
            lim = [v, a, j, s]
            lim[k] *= 2
            assert point_to_point(L, *lim).duration == pytest.approx(p.duration, rel=1e-9)
    faster = point_to_point(L, 2 * v, 2 * a, 2 * j, 2 * s)
    assert faster.duration < p.duration


def test_scan_phases_speed_and_length():
    p = scan(0.2, speed=0.25, a_max=20.0, j_max=2000.0, s_max=1e6, start=0.01)
    kinds = [ph.kind for ph in p.phases()]
    assert kinds == ["rest", "accelerate", "constant velocity", "decelerate"]
    cv = p.constant_velocity_phases()[0]
    assert cv.duration == pytest.approx(0.2 / 0.25, rel=1e-12)
    t = np.linspace(cv.start, cv.end, 1001)
    d = p.derivatives(t)
    assert np.all(d[1, :-1] == 0.25) and np.all(d[2:, :-1] == 0)  # snap switches at the end
    assert d[0, -1] - d[0, 0] == pytest.approx(0.2, rel=1e-12)
    _tt, dd = fine(p)
    assert_within_limits(p, dd)
    assert p.length == 0.2 and p.reached()["speed"] == pytest.approx(0.25, rel=1e-15)


def test_scan_back_and_forth_returns_to_start_after_the_dwell():
    p = scan(0.1, speed=0.5, a_max=30.0, j_max=3000.0, s_max=1e6, back_and_forth=True,
             dwell=0.02)
    first, second = p.moves
    assert second.start == pytest.approx(first.end + 0.02)
    assert second.length == -first.length
    cvs = p.constant_velocity_phases()
    assert len(cvs) == 2
    assert p.derivatives(0.5 * (cvs[1].start + cvs[1].end))[1] == pytest.approx(-0.5)
    r_end = p.derivatives([p.end, p.end + 1.0])
    assert np.all(np.abs(r_end[0]) <= 1e-15) and np.all(r_end[1:] == 0)
    rest = [ph for ph in p.phases() if ph.kind == "rest"]
    assert len(rest) == 1 and rest[0].duration == pytest.approx(0.02)


@pytest.mark.parametrize("rate", [1e4, 8e3, 2.5e3])
def test_controller_rate_puts_switching_on_samples(rate):
    h = 1.0 / rate
    p2p = point_to_point(0.0123, 0.4, 17.0, 1700.0, 3.3e5, rate_hz=rate)
    sc = scan(0.0123, 0.4, 17.0, 1700.0, 3.3e5, rate_hz=rate, back_and_forth=True)
    for p in (p2p, sc):
        for mv in p.moves:
            for t0, _ in mv.pulses():
                assert abs(t0 / h - round(t0 / h)) < 1e-6
        assert abs(mv.durations[0] / h - round(mv.durations[0] / h)) < 1e-9
        _t, d = fine(p)
        assert_within_limits(p, d)
    assert p2p(p2p.end)[0] == 0.0123
    assert sc.length >= 0.0123 and sc.length < 0.0123 + 0.4 * h * (1 + 1e-9)
    assert sc.reached()["speed"] == pytest.approx(0.4, rel=1e-14)
    s = p2p.sample()
    assert_allclose(np.diff(s["time"]), h, rtol=1e-9)
    assert s["position"][-1] == pytest.approx(0.0123, rel=1e-14)
    assert set(s) == {"time", "position", "velocity", "acceleration", "jerk", "snap"}


def test_feedforward_is_mass_times_exact_acceleration():
    p = point_to_point(0.01, 0.2, 5.0, 500.0, 1e5)
    t = np.linspace(0, p.end, 999)
    assert_allclose(p.feedforward(t, 22.5), 22.5 * p(t)[1], rtol=0, atol=0)
    assert p.initial_velocity == 0.0
    # the default simulation step resolves a snap pulse in 10 steps
    assert 1.0 / (400 * p.max_frequency_hz) == pytest.approx(p.durations[0] / 10)


def test_to_dict_and_text():
    p = scan(0.2, 0.25, 20.0, 2000.0, 1e6, back_and_forth=True, rate_hz=1e4)
    d = p.to_dict()
    assert d["kind"] == "scan" and d["back_and_forth"] is True and d["rate_hz"] == 1e4
    assert d["v_max"] == 0.25 and d["duration_s"] == pytest.approx(p.duration)
    assert [ph["kind"] for ph in d["phases"]].count("constant velocity") == 2
    assert "scan of 0.2 m at 0.25 m/s and back" in str(p)
    fig = p.plot()
    assert len(fig.axes) == 5


@pytest.mark.parametrize(("args", "kw", "what"), [
    ((0.0, 1.0, 1.0, 1.0, 1.0), {}, "length"), ((math.nan, 1.0, 1.0, 1.0, 1.0), {}, "length"),
    ((0.1, 0.0, 1.0, 1.0, 1.0), {}, "v_max"), ((0.1, 1.0, -1.0, 1.0, 1.0), {}, "a_max"),
    ((0.1, 1.0, 1.0, math.inf, 1.0), {}, "j_max"), ((0.1, 1.0, 1.0, 1.0, 0.0), {}, "s_max"),
    ((0.1, 1.0, 1.0, 1.0, 1.0), {"rate_hz": 0.0}, "rate_hz"),
    ((0.1, 1.0, 1.0, 1.0, 1.0), {"start": -1.0}, "start")])
def test_invalid_arguments(args, kw, what):
    with pytest.raises(ValueError, match=what):
        point_to_point(*args, **kw)
    if what not in ("length",) or args[0] != 0.0:
        with pytest.raises(ValueError, match=what.replace("v_max", "v_max")):
            scan(*args, **kw)
    with pytest.raises(ValueError, match="dwell"):
        scan(0.1, 1.0, 1.0, 1.0, 1.0, dwell=-1.0)
