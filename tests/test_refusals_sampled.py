"""An unstable sampled or PID loop is refused from the scenario's coefficients (issue 26).

A controller with ``sample_rate_hz`` (``tf-z``, ``two-dof-z``, a discretised lead-lag,
``tf`` or PID) and a continuous PID are checked before python-control is imported
(:meth:`Scenario.fastest_pole <motionhyst.scenario.Scenario.fastest_pole>`, the check of
:meth:`Scenario.loop`).  The verdict must be python-control's: for whole samples of delay
the loop of ``c2d(P2, T, "zoh") z^-D`` and the controller's ``Y(z)`` closed with
``control.feedback``; for a fractional delay the loop's own poles
(:meth:`Loop.closed_loop_poles`, the held plant's exact pulse transfer function); the
message the one the loop gives once built.
"""

from __future__ import annotations

import copy

import control
import numpy as np
import pytest

from motionhyst import Scenario, ScenarioError
from motionhyst.controllers.loop import Loop

STAGE = {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}
LEADLAG = {"type": "leadlag-lowpass", "K": 6.2e6, "f1": 60.0, "f2": 240.0, "flp": 700.0,
           "beta": 0.6}
PID = {"type": "pid", "kp": 6e6, "ki": 1e7, "kd": 2e4, "derivative_filter_hz": 1500.0,
       "notches": [{"frequency_hz": 694.0, "zeta_zero": 0.005, "zeta_pole": 0.7}]}
F, G, KP = 1e3, 35.15065 * 243.45, 160.18          # the EMPS cascade, on a 95 kg axis
CASCADE = {"type": "two-dof-z", "r_num": [G * KP], "r_den": [1.0],
           "y_num": [G * (KP + F), -G * F], "y_den": [1.0], "sample_rate_hz": F}
MASS = {"type": "mass-spring-damper", "m": 95.0, "c": 200.0, "k": 0.0}


def _scenario(controller: dict, stage: dict | None = None, kj: float = 20.0) -> Scenario:
    data = {"stage": copy.deepcopy(stage or STAGE), "controller": copy.deepcopy(controller),
            "hysteresis": {"model": "jenkins", "k": kj, "fc": 0.05},
            "reference": {"amplitude": 0.01, "frequencies": [5.0]},
            "feedforward": {"type": "none"}}
    return Scenario.from_dict(data, "s.toml", check=False)


def _precheck(sc: Scenario) -> str | None:
    """The refusal of the check from the coefficients (None: stable)."""
    try:
        sc.fastest_pole()
    except ScenarioError as exc:
        return str(exc)
    return None


def _loop_message(sc: Scenario) -> str | None:
    """The refusal of the loop built with python-control, the check from the coefficients
    bypassed."""
    loop = Loop(sc.plant(), sc.controller(), sc.hysteresis())
    try:
        loop.check_stable()
    except ValueError as exc:
        return f"s.toml: [controller]: {exc}"
    return None


def _plants(sc: Scenario) -> list[control.TransferFunction]:
    """``P2``, and with the link stuck ``P2 / (1 + kJ P1)``, as python-control forms them."""
    plant = sc.plant()
    out = [plant.P2]
    if sc.hysteresis() is not None:
        out.append(control.minreal(plant.P2 / (1 + sc.hysteresis().initial_stiffness
                                               * plant.P1), verbose=False))
    return out


def _stable_by_python_control(sc: Scenario) -> bool:
    """Every pole of the sampled loop inside the unit circle, from python-control's
    zero-order-hold equivalent (whole samples of delay only)."""
    c = sc.controller()
    assert c.delay_samples == int(c.delay_samples)
    T, D = c.period, int(c.delay_samples)
    Y = c.tf("y")
    for P in _plants(sc):
        Gd = control.c2d(P, T, "zoh") * control.tf([1.0], [1.0] + [0.0] * D, T)
        poles = control.feedback(Gd, Y).poles()
        if np.max(np.abs(poles)) >= 1.0:
            return False
    return True


def _stable_by_the_loop_poles(sc: Scenario) -> bool:
    """Every pole of the loop (link absent) inside the unit circle: ``Re ln z / T < 0``."""
    loop = Loop(sc.plant(), sc.controller(), None)
    return bool(np.max(loop.closed_loop_poles().real) < 0)


SAMPLED = [  # (controller, stage, the link's kJ)
    # the paper's loop at 10 kHz: stable up to 3 samples of delay, unstable from 4
    *[(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=d), None, 20.0) for d in (1, 3, 4, 8)],
    *[(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=d, discretization=m), None, 20.0)
      for m in ("zoh", "matched") for d in (2, 3, 4)],
    *[(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=d, discretization="tustin-prewarp",
            prewarp_hz=700.0), None, 20.0) for d in (3, 4)],
    *[(dict(LEADLAG, sample_rate_hz=r), None, 20.0) for r in (1e3, 700.0)],   # too slow
    # a link stiff enough to make the loop with it stuck unstable (1e7 is not)
    *[(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=1), None, k) for k in (1e7, 5e7)],
    *[(dict(PID, sample_rate_hz=10e3, delay_samples=d), None, 20.0) for d in (1, 8, 12)],
    *[(dict(PID, derivative_filter_hz=None, kd=kd, sample_rate_hz=10e3), None, 20.0)
      for kd in (1e4, 6e4)],                                 # a pure derivative, sampled
    ({"type": "tf-z", "num": [2e6, -1.9e6], "den": [1.0, -0.5], "sample_rate_hz": 10e3},
     None, 20.0),
    ({"type": "tf-z", "num": [2e7, -1.9e7], "den": [1.0, -0.5], "sample_rate_hz": 10e3},
     None, 20.0),
    *[(dict(CASCADE, delay_samples=d), MASS, 20.0) for d in (0, 3, 5)],
    *[(dict(CASCADE, y_num=[f * G * (KP + F), -f * G * F]), MASS, 20.0) for f in (10, 30)],
    (CASCADE, MASS, 1e9),
]


@pytest.mark.parametrize("controller, stage, kj", SAMPLED)
def test_a_sampled_loop_is_judged_as_python_control_judges_it(controller, stage, kj):
    sc = _scenario(controller, stage, kj)
    refused = _precheck(sc)
    assert (refused is None) == _stable_by_python_control(sc), refused
    assert refused == _loop_message(sc)
    if refused is not None:
        assert refused.startswith("s.toml: [controller]: the sampled controller does not "
                                  "stabilise the loop")
        with pytest.raises(ScenarioError) as exc:
            sc.loop()
        assert str(exc.value) == refused


def test_the_verdicts_cover_both_sides_and_the_stuck_link():
    verdicts = [_precheck(_scenario(*case)) for case in SAMPLED]
    assert sum(v is None for v in verdicts) >= 8
    assert sum(v is not None for v in verdicts) >= 8
    assert any(v is not None and "with the dynamic link stuck" in v for v in verdicts)


@pytest.mark.parametrize("delay", [2.5, 3.5, 3.75, 3.9])
def test_a_fractional_delay_is_judged_as_the_loop_poles_judge_it(delay):
    """Near the border (between 3.75 and 3.9 samples) the held plant's exact poles decide."""
    sc = _scenario(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=delay))
    refused = _precheck(sc)
    assert (refused is None) == _stable_by_the_loop_poles(sc), refused
    assert refused == _loop_message(sc)


def test_the_border_lies_between_the_fractional_delays():
    stable = [_precheck(_scenario(dict(LEADLAG, sample_rate_hz=10e3, delay_samples=d),
                                  )) is None for d in (2.5, 3.5, 3.75, 3.9)]
    assert stable == [True, True, True, False]


PIDS = [dict(PID, ki=1e7 * f) for f in (1.0, 1e3, 1e4)] + [
    dict(PID, kp=6e6 * f, kd=2e4 * f) for f in (0.01, 0.1, 10.0)]


@pytest.mark.parametrize("controller", PIDS)
def test_a_continuous_pid_loop_is_refused_as_the_loop_refuses_it(controller):
    sc = _scenario(controller)
    refused = _precheck(sc)
    assert refused == _loop_message(sc)
    poles = [control.feedback(P, sc.controller()).poles() for P in _plants(sc)]
    assert (refused is None) == all(np.max(p.real) < 0 for p in poles), refused


def test_the_pid_verdicts_cover_both_sides():
    verdicts = [_precheck(_scenario(c)) for c in PIDS]
    assert None in verdicts and any(v is not None for v in verdicts)


@pytest.mark.parametrize("controller", [
    dict(PID, sample_rate_hz=10e3, discretization="matched"),
    {"type": "tf", "num": [1e6, 1e8], "den": [1.0, 0.0], "sample_rate_hz": 1e4,
     "discretization": "matched"},
])
def test_a_matched_discretisation_of_an_integrator_is_refused_naming_the_section(controller):
    """It has no gain at s = 0 to keep: python-control's c2d gave NaN coefficients, refused
    as "num must be a non-empty list of finite numbers", naming neither file nor cause."""
    with pytest.raises(ScenarioError, match=r'^s\.toml: \[controller\]: discretization = '
                                            r'"matched" keeps the gain at s = 0'):
        _scenario(controller).loop()
