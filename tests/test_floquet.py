"""Floquet multipliers of forced periodic steady states (analysis/floquet.py, ``steady --json``).

Checked against what they mean: the decay of a simulation onto the steady state (the
time engine, independent of the monodromy's matrix exponentials), the closed-loop poles
where the link stays stuck, and the stage's resonance in Table I.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from motionhyst import (
    Jenkins,
    Loop,
    LuGre,
    SineReference,
    default_scenario,
    periodic_steady_state,
    simulate,
)
from motionhyst.analysis.floquet import from_monodromy, steady_state_floquet
from motionhyst.cli import main as cli_main
from motionhyst.controllers.pid import Pid
from motionhyst.core.lti import tf_poly


@pytest.fixture(scope="module")
def slow_loop():
    """Table I's stage under a 10 Hz PID and a stiffer link: deviations live several periods."""
    base = default_scenario().loop()
    kp = 22.5 * (2 * math.pi * 10.0) ** 2
    C = Pid(kp=kp, ki=kp * 2 * math.pi * 2.0, kd=22.5 * 2 * math.pi * 10.0,
            derivative_filter_hz=200.0).tf()
    loop = Loop(base.plant, C, Jenkins(k=2000.0, fc=0.5))
    loop.check_stable()
    return loop


def test_table_one_decays_as_the_stage_resonance():
    loop = default_scenario().loop()
    fl = steady_state_floquet(loop, periodic_steady_state(loop, 0.01, 5.0))
    # the two-mass resonance is barely touched by the loop: it decays at b (1/m1 + 1/m2) / 2
    decay = 90.0 * (1 / 5.0 + 1 / 17.5) / 2
    assert fl.floquet_max == pytest.approx(math.exp(-decay * 0.2), rel=1e-3)
    assert fl.stable


def test_multipliers_match_the_simulated_decay(slow_loop):
    A, f = 0.01, 20.0
    fl = steady_state_floquet(slow_loop, periodic_steady_state(slow_loop, A, f))
    T = 1.0 / f
    sim = simulate(slow_loop, SineReference(A, f), 12 * T)
    per = round(T / (sim.t[1] - sim.t[0]))
    d = np.array([np.max(np.abs(sim.e[(k + 1) * per:(k + 2) * per] - sim.e[k * per:(k + 1) * per]))
                  for k in range(10)])
    rate = (d[9] / d[1]) ** (1 / 8)             # the deviation's shrinking a period
    # measured: floquet_max 0.6334, the simulation 0.633
    assert 0.5 < fl.floquet_max < 0.8
    assert abs(rate - fl.floquet_max) < 1e-3


def test_a_stuck_link_gives_the_poles_of_the_loop_with_a_spring(slow_loop):
    fl = steady_state_floquet(slow_loop, periodic_steady_state(slow_loop, 1e-7, 20.0))
    n1, d1 = tf_poly(slow_loop.P1)
    n2, _ = tf_poly(slow_loop.P2)
    nc, dc = tf_poly(slow_loop.controller)
    char = np.polyadd(np.polymul(np.polyadd(d1, 2000.0 * n1), dc), np.polymul(n2, nc))
    expected = np.max(np.abs(np.exp(np.roots(char) / 20.0)))
    # the stuck element's preload (a neutral multiplier 1) is left out
    assert fl.floquet_max == pytest.approx(expected, rel=1e-6)


def test_lugre_link_through_its_state_equation():
    base = default_scenario().loop()
    link = LuGre(sigma0=20.0, sigma1=0.0, sigma2=0.0, fc=0.05, fs=0.06, vs=0.01)
    loop = Loop(base.plant, base.controller, link)
    # 64 harmonics (320 Hz) carry the soft link's motion; the variations are integrated
    # along them
    fl = steady_state_floquet(loop, periodic_steady_state(loop, 0.01, 5.0, n_harmonics=64))
    assert fl.floquet_max == pytest.approx(
        steady_state_floquet(base, periodic_steady_state(base, 0.01, 5.0)).floquet_max,
        rel=1e-3)


def test_autonomous_multiplier_one_left_out():
    fl = from_monodromy(np.diag([1.0, 0.3, -0.5]), 1.0, autonomous=True)
    assert fl.multipliers.tolist() == [-0.5, 0.3]


def test_steady_json_gains_floquet_max_and_stable(capsys):
    assert cli_main(["steady", "--frequency", "5", "--json"]) == 0
    p = json.loads(capsys.readouterr().out)["points"][0]
    assert p["stable"] is True
    assert p["floquet_max"] == pytest.approx(0.0988, abs=1e-4)


def test_a_loop_whose_time_scales_span_too_much_gets_no_multipliers_that_mean_nothing():
    """A stage stiffness of 1e20 N/m gave |mu| = 1e239, 'UNSTABLE' (issue 26): now a reason."""
    from motionhyst.analysis.floquet import MAX_TIME_SCALE_RATIO, unresolved_time_scales
    from motionhyst.plants.two_mass import TwoMassStage

    loop = default_scenario().loop()
    stiff = Loop(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=1e20), loop.controller,
                 loop.hysteresis)
    p = np.abs(stiff.closed_loop_poles())
    assert p.max() > MAX_TIME_SCALE_RATIO * p[p > 0].min()
    why = unresolved_time_scales(stiff)
    assert why is not None and "not resolved in double precision" in why
    with pytest.raises(ValueError, match="Floquet multipliers not computed"):
        steady_state_floquet(stiff, periodic_steady_state(stiff, 0.01, 10.0))
    assert unresolved_time_scales(loop) is None


def test_a_stage_with_several_modes_balances_without_a_warning():
    """Balancing a three-mode stage's state equation warned 'invalid value encountered in
    cast' from scipy's permutation read-out (balancing factors past 2**63), a line on stderr
    of every `steady` run on such a stage."""
    import warnings

    from motionhyst import ModalPlant, TwoMassStage
    from motionhyst.plants.modal import Mode

    base = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    plant = ModalPlant(base.M, (base.modes[0], Mode(1520.0, 0.01, 0.02, -0.005),
                                Mode(2630.0, 0.015, 0.03, 0.004)))
    table = default_scenario().loop()
    loop = Loop(plant, table.controller, table.hysteresis)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fl = steady_state_floquet(loop, periodic_steady_state(loop, 0.01, 10.0))
    assert np.isfinite(fl.floquet_max) and 0.0 < fl.floquet_max < 1.0
    assert fl.stable
