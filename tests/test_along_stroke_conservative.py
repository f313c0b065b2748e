"""A stop operator whose stiffness varies along the stroke is a conservative spring while it
sticks (hysteresis/along_stroke.py): its force is ``w_s + K(x) - K(x_s)``, ``K`` the integral
of ``k(x)`` (the paper's eq. (3) with ``k_J(x)``), in the open-loop runs (the exact steady
state's), the continuous loop's run and the sampled loop's.  Held piece by piece, a stop that
never slipped drifted 8.6e-7 N a period open loop and 3e-6 N in either closed loop (Jenkins
k 20 N/m, fc 0.05 N, k 0.5x to 2x over 40 mm, at 1 mm: it slips at about 2 mm)."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from conftest import FC_LINK, K_LINK
from test_along_stroke_routes import steady_is_run

from motionhyst import Jenkins, Loop, MaxwellSlip, simulate
from motionhyst.hysteresis import along_stroke
from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.scenario import Scenario, default_scenario
from motionhyst.time.references import SineReference

POSITION, SCALES = [-0.02, 0.02], {"k": [0.5, 2.0]}
F = 5.0


def _k(x):
    """The table's stiffness at `x` [N/m] (linear in between, held beyond the ends)."""
    return K_LINK * np.interp(x, POSITION, SCALES["k"])


def _link() -> AlongStroke:
    return AlongStroke(Jenkins(K_LINK, FC_LINK), POSITION, SCALES)


def _stop_by_substeps(x, fc, substeps=64):
    """The stop operator for the samples `x` (linear in between) from rest: ``w += k dx``
    with ``k`` at each substep's midpoint, held within ``+-fc``."""
    w, out = 0.0, np.empty(len(x))
    out[0] = 0.0
    for i in range(1, len(x)):
        edges = np.linspace(x[i - 1], x[i], substeps + 1)
        for a, b in pairwise(edges):
            w = min(max(w + _k(0.5 * (a + b)) * (b - a), -fc), fc)
        out[i] = w
    return out


def test_the_stiffness_integral_is_the_table_s_integral():
    # against a fine trapezoid quadrature of k(x), within the table and beyond its ends
    x = np.array([-0.03, -0.02, -0.011, 0.0, 0.0137, 0.02, 0.035])
    K = _link().stiffness_integral(x)[:, 0]
    for xi, Ki in zip(x, K, strict=True):
        u = np.linspace(POSITION[0], xi, 200_001)
        assert Ki == pytest.approx(np.trapezoid(_k(u), u), rel=1e-9, abs=1e-12)


def test_a_never_slipping_stop_returns_to_its_force_open_loop():
    # 1 mm around 0 (it slips at about 2 mm): five periods; the force at each period's start
    # is the start's (0) to 1e-12 of its peak, and at the top the closed form
    # k_0 (0.5 (x + 0.02) / 0.04 * 1.5 + ...) integrated: 20 (1.25 A + 18.75 A^2)
    A, n = 1e-3, 8192
    x = A * np.sin(2 * np.pi * np.arange(5 * n + 1) / n)
    w = _link().response(x)
    peak = np.max(np.abs(w))
    assert np.max(np.abs(w[::n])) <= 1e-12 * peak
    assert np.max(np.abs(w[-n - 1:] - w[:n + 1])) <= 1e-12 * peak
    assert w[n // 4] == pytest.approx(K_LINK * (1.25 * A + 18.75 * A * A), rel=1e-12)


def test_a_slipping_stop_follows_the_stiffness_open_loop():
    # 5 mm around 3 mm: it slips both ways; the force against the stop advanced in 64
    # substeps a sample with k at each midpoint (the piece's held k was 1.8e-3 of fc off)
    n = 400
    x = 0.003 + 0.005 * np.sin(2 * np.pi * np.arange(2 * n + 1) / n)
    w = _link().response(x)
    assert np.max(np.abs(w)) == pytest.approx(FC_LINK)
    assert np.max(np.abs(w - _stop_by_substeps(x, FC_LINK))) <= 1e-12 * FC_LINK


def test_the_periodic_force_of_a_never_slipping_stop_is_the_spring_s():
    # the exact steady state's route (refused on main: "no periodic force"): the harmonics of
    # w = K(x) - K(x_s), x_s where it stuck (the run starts at rest at the period's start)
    A, N = 1e-3, 8192
    link = _link()
    W = link.periodic_harmonics(np.array([0.0, A / 2j]), 5)
    x = A * np.sin(2 * np.pi * np.arange(N) / N)
    u = np.linspace(0.0, 1.0, 4001)
    w = [np.trapezoid(_k(xi * u), xi * u) for xi in x]  # integral of k from 0 to x
    ref = (np.fft.rfft(w) / N)[:6]
    assert np.max(np.abs(W - ref)) <= 1e-9 * np.max(np.abs(ref))


def _scenario(rate_hz: float | None, table=(POSITION, SCALES)) -> Scenario:
    """Table I with the Jenkins link along the stroke `table`, continuous or sampled."""
    d = default_scenario().to_dict()
    base = Jenkins(K_LINK, FC_LINK)
    d["hysteresis"] = {**base.to_dict(),
                       "along": {"position": table[0], **table[1]}}
    if rate_hz is not None:
        d["controller"]["sample_rate_hz"] = rate_hz
        d["feedforward"] = {"type": "rigid-body"}
    return Scenario.from_dict(d, "s.toml")


@pytest.mark.parametrize("rate_hz", [None, 10e3])
def test_a_never_slipping_stop_in_a_loop_keeps_its_force_a_function_of_position(rate_hz):
    # Table I at 1 mm 5 Hz, four periods: at each end of the run's pieces (where the force
    # is set) w = K(y1) - K(y1(0)) to 1e-12 of its peak (main: 3e-6 N a period of drift,
    # 5e-4 of the peak after four); within a piece the piece's k, 1.6e-3 of it at most
    link = _link()
    kw = {} if rate_hz else {"dt": 1.0 / (F * 2000)}
    sim = simulate(_scenario(rate_hz).loop(), SineReference(1e-3, F), 4 / F, **kw)
    K = link.stiffness_integral(sim.y1)[:, 0]
    spring = K - K[0]
    peak = np.max(np.abs(sim.w))
    ends = [b - 1 if rate_hz is None else b for _, b in link.pieces(sim.r)][:-1]
    assert len(ends) > 20
    assert np.max(np.abs(sim.w[ends] - spring[ends])) <= 1e-12 * peak
    assert np.max(np.abs(sim.w - spring)) <= 3e-3 * peak


def test_a_slipping_stop_in_a_loop_agrees_with_finer_pieces(monkeypatch):
    # Table I at 10 mm (it slips): the run against one whose pieces are 16x shorter
    # (the parameters held over 1/1024 of the table's spacing): the link's part of the
    # error agrees to 1e-3 of its peak
    table = ([-0.01, 0.01], SCALES)
    ref = SineReference(0.01, F)
    loop = _scenario(None, table).loop()
    run = simulate(loop, ref, 2 / F, dt=1.0 / (F * 4000))
    monkeypatch.setattr(along_stroke, "STEPS_PER_INTERVAL", 1024)
    fine = simulate(_scenario(None, table).loop(), ref, 2 / F, dt=1.0 / (F * 4000))
    part = fine.e - fine.e_linear
    assert np.max(np.abs(run.e - run.e_linear - part)) <= 1e-3 * np.max(np.abs(part))


@pytest.mark.parametrize("base", [Jenkins(K_LINK, FC_LINK),
                                  MaxwellSlip([10.0, 10.0], [0.02, 0.03])])
def test_steady_state_of_a_stiffness_along_the_stroke_is_the_run(stage, controller, base):
    # k 0.5x to 2x over the stroke at 10 mm 5 Hz: the exact steady state against the last of
    # six periods of a run from rest, the link's part of e1 and e3 to 2e-3
    steady_is_run(Loop(stage, controller, AlongStroke(base, [-0.01, 0.01], SCALES)))
