"""Tests of the reference trajectories (references.py)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionhyst.time.references import (
    PointToPoint,
    SampledReference,
    SineReference,
    load_reference_csv,
)

# (distance, v_max, a_max, j_max): long moves that reach v_max, and short ones that do not
LONG_MOVES = [(-0.05, 0.5, 20.0, 1000.0), (0.3, 0.5, 10.0, 500.0), (0.1, 0.2, 50.0, 100.0)]
SHORT_MOVES = [(0.1, 1.0, 10.0, 500.0), (0.002, 1.0, 10.0, 500.0), (1e-4, 1.0, 10.0, 500.0)]


def sample(p: PointToPoint, n: int = 400_001, after: float = 0.05):
    t = np.linspace(0.0, p.start + p.duration + after, n)
    r, a = p(t)
    return t, r, a


# ---------------------------------------------------------------------------------- sine


def test_sine_reference():
    ref = SineReference(0.01, 10.0)
    t = np.linspace(0, 0.3, 1001)
    r, a = ref(t)
    assert_allclose(r, 0.01 * np.sin(2 * np.pi * 10 * t), rtol=0, atol=1e-18)
    assert_allclose(a, -((2 * np.pi * 10) ** 2) * r, rtol=1e-15, atol=0)
    assert ref.initial_velocity == pytest.approx(2 * np.pi * 10 * 0.01)
    assert ref.max_frequency_hz == 10.0


@pytest.mark.parametrize(("A", "f"), [(0.0, 1.0), (-1.0, 1.0), (1.0, 0.0), (np.nan, 1.0),
                                      (1.0, np.inf)])
def test_sine_reference_invalid(A, f):
    with pytest.raises(ValueError):
        SineReference(A, f)


# ------------------------------------------------------------------------ point to point


@pytest.mark.parametrize("move", LONG_MOVES + SHORT_MOVES)
def test_point_to_point_reaches_distance_within_limits(move):
    d, v_max, a_max, j_max = move
    p = PointToPoint(d, v_max, a_max, j_max, start=0.01)
    t, r, a = sample(p)
    h = t[1] - t[0]
    # rest before the start, at the distance after the end
    assert np.all(r[t < p.start] == 0) and np.all(a[t < p.start] == 0)
    end = t >= p.start + p.duration
    assert_allclose(r[end], d, rtol=0, atol=1e-15 * abs(d))
    assert np.all(a[end] == 0)
    assert r[-1] == pytest.approx(d, rel=1e-14)
    # limits
    assert np.max(np.abs(a)) <= a_max * (1 + 1e-12)
    v = np.diff(r) / h
    assert np.max(np.abs(v)) <= v_max * (1 + 1e-9)
    jerk = np.diff(a) / h
    smooth = np.abs(jerk) < 1.5 * j_max  # away from the jerk switches
    assert np.max(np.abs(jerk[smooth])) <= j_max * (1 + 1e-6)
    # monotone in the direction of the move
    assert np.all(np.sign(d) * np.diff(r) >= -1e-18)
    # acceleration is the second derivative of the position (error of the central
    # difference at a jerk switch is at most j_max h / 3)
    acc_num = (r[2:] - 2 * r[1:-1] + r[:-2]) / h**2
    assert np.max(np.abs(acc_num - a[1:-1])) <= j_max * h + 1e-9 * a_max


@pytest.mark.parametrize("move", LONG_MOVES)
def test_long_move_duration_and_cruise(move):
    d, v_max, a_max, j_max = move
    p = PointToPoint(d, v_max, a_max, j_max)
    tv = p._phases()[2]
    if v_max / a_max >= a_max / j_max:  # a_max reached
        expected = abs(d) / v_max + v_max / a_max + a_max / j_max
        assert np.max(np.abs(p(np.linspace(0, p.duration, 100_001))[1])) == pytest.approx(a_max)
    else:  # v_max reached before a_max
        expected = abs(d) / v_max + 2 * np.sqrt(v_max / j_max)
    assert p.duration == pytest.approx(expected, rel=1e-12)
    assert tv > 0
    t, r, _ = sample(p, after=0.0)
    v = np.gradient(r, t)
    assert np.max(np.abs(v)) == pytest.approx(v_max, rel=1e-6)


@pytest.mark.parametrize("move", SHORT_MOVES)
def test_short_move_never_reaches_v_max(move):
    d, v_max, a_max, j_max = move
    p = PointToPoint(d, v_max, a_max, j_max)
    tj, ta, tv = p._phases()
    assert tv == 0.0
    t, r, _ = sample(p)
    assert r[-1] == pytest.approx(d, rel=1e-12)
    v_peak = np.max(np.abs(np.gradient(r, t)))
    assert v_peak < 0.95 * v_max
    # time-optimal short move: four jerk phases, with a constant-acceleration phase if the
    # pure-jerk profile would exceed a_max
    tj = (abs(d) / (2 * j_max)) ** (1 / 3)
    if j_max * tj <= a_max:
        expected = 4 * tj
    else:
        tj = a_max / j_max  # d = a_max (tj + ta) (2 tj + ta)
        ta = (-3 * tj + np.sqrt(tj**2 + 4 * abs(d) / a_max)) / 2
        expected = 2 * (2 * tj + ta)
    assert p.duration == pytest.approx(expected, rel=1e-9)
    assert p.duration >= 2 * np.sqrt(abs(d) / a_max)


def test_point_to_point_negative_distance_is_mirror():
    p = PointToPoint(0.1, 0.5, 10.0, 500.0)
    q = PointToPoint(-0.1, 0.5, 10.0, 500.0)
    t = np.linspace(0, p.duration, 1001)
    rp, ap = p(t)
    rq, aq = q(t)
    assert_allclose(rq, -rp, rtol=0, atol=0)
    assert_allclose(aq, -ap, rtol=0, atol=0)


@pytest.mark.parametrize("kwargs", [
    {"distance": 0.0}, {"distance": np.nan}, {"v_max": 0.0}, {"a_max": -1.0},
    {"j_max": np.inf}, {"start": -0.1},
])
def test_point_to_point_invalid(kwargs):
    args = {"distance": 0.1, "v_max": 0.5, "a_max": 10.0, "j_max": 500.0, **kwargs}
    with pytest.raises(ValueError):
        PointToPoint(**args)


# ------------------------------------------------------------------------------ sampled


def test_sampled_sine_reproduces_acceleration():
    f, A = 3.0, 0.01
    w = 2 * np.pi * f
    t = np.linspace(0.0, 1.0, 2001)
    ref = SampledReference(t, A * np.sin(w * t))
    tt = np.linspace(0.0, 1.0, 3001)
    r, a = ref(tt)
    assert_allclose(r, A * np.sin(w * tt), rtol=0, atol=1e-12 * A)
    assert_allclose(a, -(w**2) * r, rtol=0, atol=1e-6 * w**2 * A)
    assert ref.initial_velocity == pytest.approx(w * A, rel=1e-6)
    assert ref.duration == 1.0
    assert ref.max_frequency_hz == pytest.approx(0.5 / 5e-4)
    # held outside the samples, without acceleration
    r_out, a_out = ref(np.array([-0.5, 2.0]))
    assert_allclose(r_out, [0.0, A * np.sin(w)], rtol=0, atol=1e-12 * A)
    assert np.all(a_out == 0)


@pytest.mark.parametrize(("t", "r", "match"), [
    (np.arange(5.0), np.zeros(5), "at least 6"),
    (np.arange(8.0), np.zeros(7), "equal length"),
    (np.array([0, 1, 2, 2, 3, 4.0]), np.zeros(6), "increasing"),
    (np.array([0, 1, 3, 2, 4, 5.0]), np.zeros(6), "increasing"),
    (np.arange(6.0), np.array([0, 1, np.nan, 0, 0, 0]), "position must be finite: sample 3 is nan"),
])
def test_sampled_reference_invalid(t, r, match):
    with pytest.raises(ValueError, match=match):
        SampledReference(t, r)


# ---------------------------------------------------------------------------------- CSV


def write_csv(path, header, rows):
    path.write_text(header + "\n" + "".join(",".join(map(str, row)) + "\n" for row in rows))
    return path


def test_load_reference_csv(tmp_path):
    t = np.linspace(0.0, 0.5, 51)
    path = write_csv(tmp_path / "ref.csv", "time,position",
                     zip(t, 0.01 * np.sin(2 * np.pi * 2 * t), strict=True))
    ref = load_reference_csv(path)
    assert_allclose(ref.t, t, rtol=0, atol=1e-15)
    r, _ = ref(t)
    assert_allclose(r, 0.01 * np.sin(2 * np.pi * 2 * t), rtol=0, atol=1e-15)
    # extra columns and any column order are fine
    path2 = write_csv(tmp_path / "ref2.csv", "position,extra,time",
                      ((x, 1, ti) for ti, x in zip(t, r, strict=True)))
    assert_allclose(load_reference_csv(path2).r, r, rtol=0, atol=1e-15)


ROWS = [(0.0, 0.0), (0.1, 1e-3), (0.2, 2e-3), (0.3, 3e-3), (0.4, 4e-3), (0.5, 5e-3)]


@pytest.mark.parametrize(("header", "rows"), [
    ("time,pos", ROWS),  # missing column
    ("t,position", ROWS),
    ("time,position", [*ROWS[:3], ("0.3", "abc"), *ROWS[4:]]),  # non-numeric
    ("time,position", [*ROWS[:3], (0.1, 3e-3), *ROWS[4:]]),  # time goes back
    ("time,position", [*ROWS[:3], (0.2, 3e-3), *ROWS[4:]]),  # time repeats
    ("time,position", ROWS[:4]),  # too few rows
    ("time,position", []),  # no rows
    ("time,position", [*ROWS[:3], (0.3, "nan"), *ROWS[4:]]),  # NaN
    ("time,position", [*ROWS[:3], ("inf", 3e-3), *ROWS[4:]]),  # inf
])
def test_load_reference_csv_errors(tmp_path, header, rows):
    path = write_csv(tmp_path / "bad.csv", header, rows)
    with pytest.raises(ValueError, match=r"bad\.csv"):
        load_reference_csv(path)


def test_load_reference_csv_missing_file(tmp_path):
    with pytest.raises(ValueError, match="cannot read"):
        load_reference_csv(tmp_path / "nope.csv")
