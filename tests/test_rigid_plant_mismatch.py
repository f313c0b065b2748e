"""A rigid plant under rigid-body feedforward: the mismatch of eq. (18) is not defined.

A mass-damper with ``c = 0`` has no flexible part (``Pf2 = Pr - P2 = 0``): the feedforward
``M r''`` cancels it, the loop without the link has no error (``e_hat = 0``), and
``E = e / e_hat`` (eqs. 18, 20) compares the link's error with nothing.  ``analyze`` and
``steady`` printed ``|E| = inf`` with numpy's "divide by zero" warnings (review of session
18); now E is nan with one line saying why, and no numpy warning reaches the user.
"""

from __future__ import annotations

import json
import tomllib
import warnings

import numpy as np
import pytest

from motionhyst import Loop, analyze, periodic_steady_state
from motionhyst.analysis.comparison import compare_with_describing_function
from motionhyst.analysis.quasilinear import NO_ERROR_WITHOUT_LINK, loop_mismatch
from motionhyst.cli import main
from motionhyst.scenario import Scenario

RIGID = """[stage]
type = "mass-damper"
m = 1.0
c = {c}

[hysteresis]
model = "jenkins"
k = 100.0
fc = 0.5

[controller]
type = "pid"
kp = 4e4
ki = 1e5
kd = 400.0
derivative_filter_hz = 500.0

[feedforward]
type = "rigid-body"

[reference]
amplitude = 0.01
frequencies = [1.0, 5.0]
"""


def _loop(c: float) -> Loop:
    """The scenario's loop: a 1 kg mass with viscous damping `c`, a PID, a Jenkins link."""
    return Scenario.from_dict(tomllib.loads(RIGID.format(c=c)), "md.toml").loop()


def test_the_mismatch_of_a_rigid_plant_is_nan_without_numpy_warnings():
    loop = _loop(0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = analyze(loop, 0.01, [1.0, 5.0])
        E = loop_mismatch(loop, [1.0, 5.0], 0.01)
        ss = periodic_steady_state(loop, 0.01, 5.0)
        E_sim = ss.mismatch
        text, d = str(ss), ss.to_dict()
    assert np.all(np.isnan(E)) and all(np.isnan(p.value) and np.isnan(p.asymptote)
                                       for p in res.points)
    assert NO_ERROR_WITHOUT_LINK.format(plant="mass-damper") in res.unresolved
    assert ss.e_linear[1] == 0 and abs(ss.e[1]) > 0 and np.isnan(E_sim)
    # the steady state's own text and dictionary: not defined, never inf (main printed
    # "|E| = inf, angle 45.00 deg" with numpy's warning, review C19 M2)
    assert "|E| = |e1 / e1_linear|: not defined, the loop without the link has no error" in text
    assert "inf" not in text.split()
    assert np.isnan(d["mismatch_simulated_abs"]) and np.isnan(d["mismatch_simulated_phase_deg"])
    # a little viscous damping gives the linear loop an error again: E is a number
    damped = analyze(_loop(1.0), 0.01, [1.0, 5.0])
    assert all(np.isfinite(p.value) for p in damped.points)
    assert not any("not defined" in u for u in damped.unresolved)


def test_the_exact_mismatch_is_e1_over_the_linear_e1_elsewhere():
    loop = _loop(1.0)
    ss = periodic_steady_state(loop, 0.01, 5.0)
    assert ss.mismatch == pytest.approx(ss.e[1] / ss.e_linear[1], rel=1e-15)
    assert "|E| = |e1 / e1_linear| = " in str(ss)


@pytest.mark.parametrize("command", ["analyze", "steady"])
def test_the_commands_say_why_and_show_no_numpy_warning(tmp_path, capsys, monkeypatch, command):
    (tmp_path / "md.toml").write_text(RIGID.format(c=0.0))
    monkeypatch.chdir(tmp_path)
    assert main([command, "md.toml"]) == 0
    out, err = capsys.readouterr()
    assert "RuntimeWarning" not in err and "divide" not in err, err
    assert "inf" not in out.split() and "not defined" in out, out
    assert main([command, "md.toml", "--json"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    rows = data["mismatch"] if command == "analyze" else data["points"]
    key = "abs" if command == "analyze" else "mismatch_simulated_abs"
    assert all(row[key] is None for row in rows) and "RuntimeWarning" not in err


def test_the_comparison_s_table_names_the_undefined_mismatch():
    cmp = compare_with_describing_function(_loop(0.0), 0.01, [5.0], floquet=False)
    assert "not defined where |e1 lin| = 0" in str(cmp)
    assert "not defined" not in str(compare_with_describing_function(_loop(1.0), 0.01, [5.0],
                                                                     floquet=False))


def test_a_nan_of_another_cause_is_not_blamed_on_a_rigid_plant(monkeypatch):
    """``analyze`` named 'the plant has no flexible part' for any non-finite E (review C19
    L4): a nan at one frequency of a plant with one (c = 1: Pf2 != 0) is not said to be it."""
    from motionhyst.analysis import quasilinear

    def one_nan(real):
        def at_the_two_points(*args):
            out = np.array(real(*args), dtype=complex)
            if out.size == 2:  # not the crossover's search
                out[-1] = complex(np.nan, np.nan)
            return out
        return at_the_two_points

    for name in ("mismatch", "residual_mismatch"):
        monkeypatch.setattr(quasilinear, name, one_nan(getattr(quasilinear, name)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(_loop(1.0), 0.01, [1.0, 5.0])
    assert np.isfinite(res.points[0].value) and np.isnan(res.points[1].value)
    assert not any("no flexible part" in u for u in res.unresolved), res.unresolved


def test_the_removed_exact_mismatch_is_a_deprecated_alias_of_the_property():
    """Review C20 L2: ``comparison.exact_mismatch`` (public in 0.1) was removed without an
    alias.  It is back, warning that ``SteadyState.mismatch`` replaces it, and gives that value;
    both are the exact e1 over the linear loop's error ``A (1 - P2 Cff) / (1 + C P2)`` at the
    frequency, evaluated here from the controller, plant and feedforward alone (python-control),
    not from the steady state's harmonics."""
    import control

    from motionhyst import default_scenario
    from motionhyst.analysis.comparison import exact_mismatch

    loop, A, f = default_scenario().loop(), 0.01, 5.0
    ss = periodic_steady_state(loop, A, f)
    with pytest.warns(DeprecationWarning, match=r"exact_mismatch\(state\) is deprecated: use "
                                                 r"state\.mismatch \(SteadyState\.mismatch\)"):
        E = exact_mismatch(ss)
    assert E == ss.mismatch
    w = 2.0 * np.pi * f
    C, P2 = (complex(control.evalfr(sys, 1j * w)) for sys in (loop.controller, loop.P2))
    e1_linear = A * (1.0 - P2 * loop.ff.linear_response(np.array([w]))[0]) / (1.0 + C * P2)
    assert E == pytest.approx(ss.e[1] / e1_linear, rel=1e-9)
    assert abs(E) == pytest.approx(6.04, abs=0.005)
    with pytest.warns(DeprecationWarning):
        assert np.isnan(exact_mismatch(periodic_steady_state(_loop(0.0), 0.01, 5.0)))
