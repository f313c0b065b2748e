"""A loop that hunts has no steady state: one line says so, early (issue 26).

``examples/hunting.toml`` (Olsson and Astrom 2001: a 1 kg mass on LuGre friction with a
Stribeck dip under a PID) has a stable self-excited cycle of 24.437 s (tests/test_stability.py
checks its exact orbit against a stiff-ODE run).  Driven at 0.002 Hz, 10 mm (its integrator
winds up over the reference's half period of 250 s to ki A / w = 3.2 N, past the 1.5 N of
breakaway: no stuck state holds it; at 0.005 Hz, 1.27 N, a stuck steady state exists beside
the hunting a run from rest finds) it slips at that cycle's rhythm and has
no steady state of the reference's period: the fixed point makes no progress.  Main said so
after the fixed point's 50 passes and the whole stability analysis (9.3 s of CPU at a load
of 10), on a second line below a warning about f*; ``study`` and ``reproduce`` said "the
dynamic link is too stiff".  Now the mixed passes stall, runs in time of the loop with its
setpoint held and of the driven loop find the cycle and that the driven loop keeps to it, and
every command says it in one line.  (At 0.1 Hz the driven loop sticks and follows the
reference: it is not said to hunt, tests/test_hunting_driven.py.)
A loop close to hunting (fs = fc: no Stribeck dip), or the hunting loop driven where it slides
throughout or sticks throughout, keeps its steady state, which agrees with an independent run
in time.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_probe import probe
from file_trees import populate, snapshot

from motionhyst.analysis.hunting import hunting_period, steady_state_unless_hunting
from motionhyst.scenario import Scenario, load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HUNTING = (EXAMPLES / "hunting.toml").read_text()
#: The exact orbit's period (tests/test_stability.py: an independent stiff-ODE run to 1e-8).
PERIOD = 24.436786


def _hunting(**keys) -> Scenario:
    """The hunting loop with `keys` (``"section.key": value``) changed."""
    data = tomllib.loads(HUNTING)
    for key, value in keys.items():
        section, name = key.split(".")
        data[section][name] = value
    return Scenario.from_dict(data, "hunting.toml")


def _one_refusal(out: dict, period: str = "24.44 s") -> str:
    """The refusal's one line, checked: exit 2, no traceback, the loop hunts, its period."""
    assert out["rc"] == 2, out
    lines = out["err"].splitlines()
    assert len(lines) == 1 and "Traceback" not in out["err"], out["err"]
    assert lines[0].startswith("motionhyst: error: "), lines
    assert "the loop hunts" in lines[0] and f"period {period}" in lines[0], lines
    assert "too stiff" not in lines[0]
    return lines[0]


def test_the_run_from_rest_finds_the_cycle_and_its_period():
    loop = load_scenario(EXAMPLES / "hunting.toml").loop()
    assert hunting_period(loop, 0.01) == pytest.approx(PERIOD, rel=1e-5)
    assert hunting_period(loop, 0.1) == pytest.approx(PERIOD, rel=1e-5)
    # twice the integral gain: the exact orbit of test_stability.py, 13.360 s
    assert hunting_period(_hunting(**{"controller.ki": 8.0}).loop(), 0.01) == pytest.approx(
        13.360, rel=1e-3)
    # no Stribeck dip: each slip ends nearer the setpoint, no cycle
    assert hunting_period(_hunting(**{"hysteresis.fs": 1.0}).loop(), 0.01) is None
    with pytest.raises(ValueError, match="smooth state equation"):
        hunting_period(load_scenario(EXAMPLES / "paper.toml").loop(), 0.01)  # Jenkins


def test_steady_refuses_in_one_line_without_the_warning_it_makes_moot(tmp_path):
    """Main printed the warning 'below f* = 50.3 Hz' (held while the input was checked, shown
    as the work started) and the refusal below it; the warnings now wait for the answer.
    Driven at 0.002 Hz, 10 mm, the loop hunts."""
    populate(tmp_path, {"hunting.toml": HUNTING})
    before = snapshot(tmp_path)
    line = _one_refusal(probe(["steady", "hunting.toml", "--frequency", "0.002"], tmp_path))
    assert line.startswith("motionhyst: error: steady state at 0.002 Hz: the loop hunts: driven "
                           "from rest, a run in time slips at its own rhythm"), line
    # the remedy names what a run in time of this loop needs: its PID has a pure derivative
    assert "derivative_filter_hz" in line
    assert snapshot(tmp_path) == before


def test_steady_still_warns_when_it_answers(tmp_path):
    """The hunting loop driven at 10 Hz, 10 mm slides throughout: a steady state, and the
    f* warning held until it is computed, then shown before the table."""
    populate(tmp_path, {"hunting.toml": HUNTING})
    out = probe(["steady", "hunting.toml", "--frequency", "10", "--no-floquet"], tmp_path)
    assert out["rc"] == 0, out
    assert out["err"].splitlines() == [
        "motionhyst: warning: steady: 10 Hz below f* = 50.3 Hz (eq. 13): the link shapes the "
        "plant there, the asymptote of eq. (20) and the crossover of eq. (21) do not apply"]


def test_study_points_say_the_loop_hunts(tmp_path):
    study = ('scenario = "hunting.toml"\noutputs = ["e1"]\n\n[axes]\namplitude = [0.01]\n'
             'frequency_hz = [0.002, 0.003]\n')
    populate(tmp_path, {"hunting.toml": HUNTING, "s.toml": study})
    line = _one_refusal(probe(["study", "s.toml", "--out", "s.zarr", "--workers", "0"],
                              tmp_path))
    assert "every one of its 2 points failed" in line, line


def test_reproduce_refuses_in_one_line_before_writing(tmp_path):
    """With rigid-body feedforward (eq. 18's mismatch needs it): main printed three warnings
    (f*, numpy's divide by zero twice) and 'the dynamic link is too stiff'."""
    scenario = HUNTING.replace('[feedforward]\ntype = "none"', '[feedforward]\ntype = "rigid-body"'
                               ).replace("frequencies = [0.1]", "frequencies = [0.002]")
    assert scenario.count("0.002") == 1 and "rigid-body" in scenario
    populate(tmp_path, {"h.toml": scenario})
    before = snapshot(tmp_path)
    _one_refusal(probe(["reproduce", "h.toml", "--out", "rep", "--quiet"], tmp_path))
    assert snapshot(tmp_path) == before


def test_a_fixed_point_that_came_near_an_answer_is_not_called_hunting(monkeypatch):
    """A fixed point that ended its passes within a tenth of an answer (main's hunting loop at
    5 Hz: relative change 0.0068 after 50 passes, its 10 mm reference keeping it sliding; the
    mixed passes now answer there) is no cycle of the loop's own: its refusal stands, and no
    run is made."""
    from motionhyst.analysis import hunting
    from motionhyst.analysis._fixed_point import not_converged

    def run(loop, offset):
        raise AssertionError("a run for a fixed point that came near an answer")

    monkeypatch.setattr(hunting, "hunting_period", run)
    loop = load_scenario(EXAMPLES / "hunting.toml").loop()
    near = not_converged(5.0, 50, 0.0068)
    assert hunting.hunting_refusal(loop, near, 0.01) is near


def _independent_run(fs: float, f: float, amplitude: float, t_end: float, ki: float = 4.0,
                     integral: float = 0.0):
    """The hunting loop with friction `fs` (and integral gain `ki`) driven by ``r = amplitude
    sin(2 pi f t)`` from rest (the PID's integral of the error starting at `integral`), written
    out (states y, v, the integral of the error, z; no feedforward)."""
    from scipy.integrate import solve_ivp

    m, kp, kd = 1.0, 3.0, 6.0
    s0, s1, s2, fc, vs = 1e5, math.sqrt(1e5), 0.4, 1.0, 1e-3
    w = 2 * math.pi * f

    def rhs(t, x):
        y, v, _, z = x
        r, rd = amplitude * math.sin(w * t), amplitude * w * math.cos(w * t)
        g = fc + (fs - fc) * math.exp(-(v / vs) ** 2)
        zdot = v - s0 * abs(v) * z / g
        u = kp * (r - y) + ki * x[2] + kd * (rd - v)
        return [v, (u - (s0 * z + s1 * zdot + s2 * v)) / m, r - y, zdot]

    return solve_ivp(rhs, (0.0, t_end), [0.0, 0.0, integral, 0.0], method="LSODA", rtol=1e-9,
                     atol=[1e-12, 1e-12, 1e-12, 1e-16], dense_output=True)


def test_a_loop_close_to_hunting_keeps_its_steady_state():
    """fs = fc (no Stribeck dip, no cycle) at 10 Hz, 10 mm: the steady state answers and its
    error agrees with a run in time of 40 s.  The loop's slowest poles, -0.20 +- 0.82j 1/s,
    leave the start's transient slowly, nearly a constant over a period of 0.1 s (2.7e-5 m
    over the 40th second): the first harmonic agrees to 1.5e-5 (the friction moves it by
    3 %, |E| = 0.972), the third, the friction's alone, to 1e-3, the rest of the waveform to
    4e-5 of its peak (measured)."""
    f, amplitude = 10.0, 0.01
    ss = steady_state_unless_hunting(_hunting(**{"hysteresis.fs": 1.0}).loop(), amplitude, f)
    run = _independent_run(1.0, f, amplitude, 40.0)
    t = 39.0 + np.arange(4000) / (4000 * f)        # a period, from the reference's zero
    e = amplitude * np.sin(2 * math.pi * f * t) - run.sol(t)[0]
    E = 2 * np.fft.rfft(e) / t.size
    assert abs(E[1]) == pytest.approx(abs(ss.e[1]), rel=5e-5)
    assert abs(E[3]) == pytest.approx(abs(ss.e[3]), rel=3e-3)
    d = ss.time_series(t.size)["e"] - e
    assert np.max(np.abs(d - d.mean())) < 1e-4 * np.max(np.abs(e))


@pytest.mark.parametrize(("fs", "e1"), [(1.5, 9.999703392e-3), (1.0, 9.999704790e-3)])
def test_the_driven_loop_that_sticks_has_its_steady_state(fs, e1):
    """At 10 mm and 0.1 Hz the PID's force stays below the friction's (kp A, ki A / w and
    kd A w: 0.03, 0.064 and 0.038 N against fc = 1 N): the stage sticks, its bristles
    (1e5 N/m, 3e4 times the loop's stiffness) deflecting by 1e-6 m.  The fixed point's plain
    and mixed passes grow by the bristles' stiffness each pass (main refused it: 'the loop
    hunts', or with fs = fc 'the link's stiffness'); with the stuck link's spring and damper
    solved with the loop it converges in 4 passes.  An independent run in time whose
    integral of the error starts at its periodic mean (-A / w: 2 pi f A sin integrates to
    A (1 - cos)) is periodic from its first period and agrees to 1e-8 (measured 5e-11 and
    7e-11); from rest it keeps the integral's mean A / w, which a slow mode of the
    integrator against the bristles bleeds off (Floquet multipliers 0.9998 a 10 s period: a
    time constant of 5e4 s; agreement 2e-6 after 3 periods)."""
    from motionhyst import periodic_steady_state

    f, amplitude = 0.1, 0.01
    ss = periodic_steady_state(_hunting(**{"hysteresis.fs": fs}).loop(), amplitude, f)
    assert ss.iterations <= 6
    run = _independent_run(fs, f, amplitude, 30.0, integral=-amplitude / (2 * math.pi * f))
    t = 20.0 + np.arange(4000) / (4000 * f)        # the third period
    e = amplitude * np.sin(2 * math.pi * f * t) - run.sol(t)[0]
    E = 2 * np.fft.rfft(e) / t.size
    assert abs(E[1]) == pytest.approx(abs(ss.e[1]), rel=1e-8)
    assert abs(ss.e[1]) == pytest.approx(e1, rel=1e-8)
    run = _independent_run(fs, f, amplitude, 30.0)
    e = amplitude * np.sin(2 * math.pi * f * t) - run.sol(t)[0]
    assert abs(2 * np.fft.rfft(e)[1] / t.size) == pytest.approx(abs(ss.e[1]), rel=1e-5)


def test_the_run_in_time_the_refusal_advises_is_refused_in_one_line(tmp_path):
    """The remedy's ``simulate --time-series``: the PID's pure derivative has no run in time.
    Main printed the f* warning and the warning that 1 s holds no period of 0.1 Hz, then the
    refusal (3 lines), once the run had started; now the refusal alone, before it."""
    populate(tmp_path, {"hunting.toml": HUNTING})
    before = snapshot(tmp_path)
    out = probe(["simulate", "hunting.toml", "--time-series", "h.csv", "--duration", "1"],
                tmp_path)
    assert out["rc"] == 2, out
    assert out["err"].splitlines() == [
        "motionhyst: error: the controller is not proper (more zeros than poles: a PID's kd "
        "without derivative_filter_hz): a time simulation needs [controller] "
        "derivative_filter_hz, or sample_rate_hz to run it sampled"], out["err"]
    assert snapshot(tmp_path) == before


def test_without_a_cycle_or_a_run_the_fixed_points_refusal_stands(monkeypatch):
    """Table I's Jenkins link has no smooth state equation: the describing function decides
    (it predicts no cycle); a run that fails numerically finds none: the refusal is the fixed
    point's own in both cases."""
    from motionhyst.analysis import hunting
    from motionhyst.analysis._fixed_point import not_converged

    exc = not_converged(5.0, 50, 0.5)
    paper = load_scenario(EXAMPLES / "paper.toml").loop()
    assert hunting.hunting_refusal(paper, exc, 0.01) is exc

    def fails(loop, offset):
        raise RuntimeError("the run failed")

    monkeypatch.setattr(hunting, "hunting_period", fails)
    loop = load_scenario(EXAMPLES / "hunting.toml").loop()
    assert hunting.hunting_refusal(loop, exc, 0.01) is exc
