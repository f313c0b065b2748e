"""Limit cycles and stability (analysis/stability.py, ``motionhyst stability``).

The hunting loop of Olsson and Astrom (2001) is checked against a stiff-ODE
simulation written here from the physics, independently of the library: a 1 kg
mass, LuGre friction, a PID on the position with the setpoint at 0.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from motionhyst import BoucWen, Dahl, LuGre, default_scenario, load_scenario
from motionhyst.analysis.stability import link_loop_response, stability
from motionhyst.cli import main as cli_main
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
HUNTING = EXAMPLES / "hunting.toml"

# the hunting loop's parameters (Olsson and Astrom 2001)
M, KP, KI, KD = 1.0, 3.0, 4.0, 6.0
S0, S1, S2, FC, FS, VS = 1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3


def independent_run(fs: float, y0: float, t_end: float):
    """The hunting loop from rest at ``y = y0``: states y, v, the integral of y, z."""
    def f(t, x):
        y, v, xi, z = x
        g = FC + (fs - FC) * math.exp(-(v / VS) ** 2)
        zdot = v - S0 * abs(v) * z / g
        w = S0 * z + S1 * zdot + S2 * v
        u = -(KP * y + KI * xi + KD * v)
        return [v, (u - w) / M, y, zdot]

    def up(t, x):
        return x[0]

    up.direction = 1.0

    def turn(t, x):
        return x[1]

    return solve_ivp(f, (0.0, t_end), [y0, 0.0, 0.0, 0.0], method="LSODA", rtol=1e-11,
                     atol=[1e-13, 1e-13, 1e-13, 1e-17], events=(up, turn))


@pytest.fixture(scope="module")
def hunting():
    return stability(load_scenario(HUNTING).loop())


@pytest.fixture(scope="module")
def reference():
    return independent_run(FS, 0.01, 400.0)


def test_hunting_cycle_matches_an_independent_stiff_simulation(hunting, reference):
    assert len(hunting.exact) == 1
    cycle = hunting.exact[0]
    t_up = reference.t_events[0]
    period = float(t_up[-1] - t_up[-2])
    last = reference.t_events[1] > t_up[-2]
    y_turns = reference.y_events[1][last, 0]
    p2p = float(y_turns.max() - y_turns.min())
    # measured: period 24.43679 s, peak-to-peak 0.127805 m, both agree to 1e-8 or better
    assert cycle.period_s == pytest.approx(period, rel=1e-4)
    assert cycle.peak_to_peak == pytest.approx(p2p, rel=1e-4)
    assert cycle.stable and cycle.confirmed


def test_hunting_floquet_multiplier_matches_the_decay_onto_the_cycle(hunting, reference):
    # on the section y = 0 (upward), the deviation of the integrator's state from the
    # cycle's shrinks by |mu|max a period once it is small
    xi = reference.y_events[0][:, 2]
    d = np.abs(xi[:-1] - xi[-1])
    k = int(np.nonzero((d > 1e-6) & (d < 1e-3))[0][-1])
    ratio = d[k + 1] / d[k]
    mu = hunting.exact[0].floquet_max
    assert 1e-3 < mu < 1e-2            # measured 6.146e-3: the sticking forgets the past
    assert abs(ratio - mu) < 1e-3
    assert abs(hunting.exact[0].simulated_ratio - mu) < 1e-3


def test_the_describing_function_of_the_link_misses_the_hunting(hunting):
    # the link's -1/N(A, w) runs up the positive imaginary axis; G of a loop whose
    # linear part is stable stays off it: no intersection
    assert [p for p in hunting.predicted if p.method == "link"] == []
    T, A = hunting.exact[0].period_s, hunting.exact[0].peak_to_peak / 2
    w = 2 * math.pi / T
    link = LuGre(S0, S1, S2, FC, FS, VS)
    G = complex(link_loop_response(load_scenario(HUNTING).loop(), [w])[0])
    N = complex(link.describing_function(A, w))
    # at the exact cycle's amplitude and frequency G N = -1.36 + 0.32j (measured): its
    # magnitude 1.40 instead of 1, its angle 167 deg instead of 180 deg (the sinusoid misses
    # the sticking, whose phase lag would close the balance)
    assert abs(1 + G * N) > 0.3
    assert 160.0 < math.degrees(math.atan2((G * N).imag, (G * N).real)) < 175.0


def test_the_cut_at_the_integrator_predicts_the_hunting(hunting):
    # the describing function of the mass with its friction and the PD part, driven by the
    # integral action's force: measured T 25.59 s (+4.7 %), y1 peak-to-peak 0.1329 m
    # (+4.0 %) against the exact 24.437 s and 0.1278 m; stable by Loeb's criterion
    [p] = [p for p in hunting.predicted if p.method == "integral-cut"]
    cycle = hunting.exact[0]
    assert cycle.found_by == "prediction" and cycle.predicted is p
    assert 1.0 / p.frequency_hz == pytest.approx(cycle.period_s, rel=0.07)
    assert p.peak_to_peak == pytest.approx(cycle.peak_to_peak, rel=0.07)
    assert p.stable
    # the integral force's amplitude lies below the break-away force fs (the stuck mass
    # holds part of it with the P action), above fc
    assert FC < p.force_amplitude < FS


def test_the_cut_predicts_a_second_hunting_loop():
    # twice the integral gain (ki = 8): a faster hunt, so the agreement above is no
    # coincidence of one loop; measured: exact 13.360 s and 0.1327 m, the cut 14.36 s
    # (+7.5 %) and 0.1276 m (-3.8 %)
    from motionhyst import Scenario

    data = load_scenario(HUNTING).to_dict()
    data["controller"]["ki"] = 8.0
    res = stability(Scenario.from_dict(data).loop())
    [cycle] = res.exact
    p = cycle.predicted
    assert p is not None and p.method == "integral-cut" and cycle.stable
    assert 1.0 / p.frequency_hz == pytest.approx(cycle.period_s, rel=0.10)
    assert p.peak_to_peak == pytest.approx(cycle.peak_to_peak, rel=0.10)
    assert cycle.period_s == pytest.approx(13.36, rel=1e-3)


def test_without_stribeck_dip_no_hunting():
    sc = load_scenario(HUNTING)
    data = sc.to_dict()
    data["hysteresis"]["fs"] = FC
    from motionhyst import Scenario

    loop = Scenario.from_dict(data).loop()
    res = stability(loop)
    assert res.predicted == [] and res.exact == []
    # the cut at the integrator: where |L N| = 1 the phase of L N stays 10 deg and more
    # short of -180 deg for every force amplitude (measured -163 to -168 deg); the balance
    # needs -180 deg, reached with a Stribeck dip (the jump the dip causes adds the lag)
    from scipy.optimize import brentq

    from motionhyst.analysis.integral_cut import IntegralCut

    cut = IntegralCut(loop)

    def gain(U, w):
        return cut.line(w) * cut.response(U, w).describing_function

    for U in (1.15, 1.4, 2.0):
        w = math.exp(brentq(lambda lw, U=U: math.log(abs(gain(U, math.exp(lw)))),
                            math.log(0.05), math.log(1.0), xtol=1e-3))
        assert -172.0 < math.degrees(np.angle(gain(U, w))) < -150.0
    run = independent_run(FC, 0.01, 400.0)
    # the independent simulation sticks and slips too, but each slip ends nearer the
    # setpoint (measured: 10 mm, 4.5 mm, 2.0 mm): it converges, no cycle
    y, t = np.abs(run.y[0]), run.t

    def peak(a, b):
        return y[(t >= a) & (t < b)].max()

    assert peak(200.0, 400.0) < 0.5 * peak(50.0, 200.0) < 0.25 * peak(0.0, 50.0)


def test_table_one_has_no_limit_cycle():
    res = stability(default_scenario().loop())
    assert res.to_dict() == {"predicted": [], "exact": []}
    # the Nyquist curve of G is five orders of magnitude inside -1/N (the link's 20 N/m
    # against a controller of 6e6 N/m)
    assert np.max(np.abs(res.nyquist)) < 1e-5 * np.min(np.abs(res.loci))
    assert any("jenkins link switches" in n for n in res.notes)


def test_cli_json_keys(capsys):
    assert cli_main(["stability", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out == {"predicted": [], "exact": []}


def test_cli_hunting_json(capsys, hunting):
    assert cli_main(["stability", str(HUNTING), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out) == ["predicted", "exact"]
    assert [sorted(c) for c in out["predicted"]] == [["amplitude", "frequency_hz", "method",
                                                      "peak_to_peak", "stable"]]
    assert out["predicted"][0]["method"] == "integral-cut"
    assert [sorted(c) for c in out["exact"]] == [["floquet_max", "peak_to_peak", "period_s",
                                                  "stable"]]
    assert out["exact"][0]["period_s"] == pytest.approx(hunting.exact[0].period_s, rel=1e-6)


def test_cli_figure_and_bad_input(tmp_path, capsys):
    fig = tmp_path / "nyquist.png"
    assert cli_main(["stability", "--no-exact", "--figure", str(fig)]) == 0
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli_main(["stability", "--figure", str(tmp_path / "x.txt")]) == 2
    err = capsys.readouterr().err
    assert "give a .png, .pdf or .svg" in err and err.count("\n") == 1


def test_a_pure_derivative_needs_a_strictly_proper_loop_gain():
    import control

    from motionhyst import Loop
    from motionhyst.controllers.pid import Pid
    from motionhyst.plants import MassDamper

    pid = Pid(KP, KI, KD).tf()                       # improper: 6 s + 3 + 4 / s
    loop = Loop(MassDamper(M, 0.0), pid, feedforward=None)
    # the closed loop from the link force: s / (s^3 + 6 s^2 + 3 s + 4)
    G = link_loop_response(loop, [2.0])[0]
    s = 2j
    assert G == pytest.approx(s / (s**3 + 6 * s**2 + 3 * s + 4), rel=1e-12)
    lag = control.tf([1.0], [1.0, 1.0])              # P2 falling once: C P2 not proper
    with pytest.raises(ValueError, match="strictly proper"):
        Loop((lag, lag), pid, feedforward=None)


def test_table_one_with_an_integrator_and_a_jenkins_link_comes_to_rest():
    import control

    from motionhyst import Jenkins, Loop, PointToPoint, simulate

    base = default_scenario().loop()
    C = base.controller * control.tf([1.0, 2 * math.pi * 5.0], [1.0, 0.0])   # PI zero at 5 Hz
    loop = Loop(base.plant, C, Jenkins(k=20.0, fc=0.05))
    loop.check_stable()
    res = stability(loop)
    assert res.predicted == [] and res.exact == []
    assert abs(link_loop_response(loop, [1e-3])[0]) < 1e-11      # G(0) = 0: integral action
    move = PointToPoint(0.02, 0.5, 10.0, 1000.0)
    sim = simulate(loop, move, move.duration + 1.0)
    before = simulate(base, move, move.duration + 1.0)
    # after the move the link stays stuck holding its slip force (measured 0.049998 N); the
    # integrator takes it over, so the error goes to zero instead of fc / C(0) (8.1e-9 m
    # without the integrator): no hunting, the Jenkins element has no falling friction
    assert abs(sim.w[-1]) == pytest.approx(0.05, rel=1e-3)
    assert abs(before.e[-1]) == pytest.approx(8.06e-9, rel=1e-2)
    assert abs(sim.e[-1]) < 1e-15


def test_links_work_in_python_control_and_agree():
    # python-control's describing-function analysis takes our link objects (their
    # describing_function(A)); where its assumptions hold (a rate-independent link) its
    # intersection agrees with ours, found by another search and refinement
    import warnings

    import control

    from motionhyst import Jenkins
    from motionhyst.analysis.stability import intersections

    H = control.tf([-2.0], [1.0, 3.0, 3.0, 1.0])
    link = Jenkins(k=1.0, fc=0.1)
    ours = intersections(H, link, np.geomspace(0.1, 100, 50), np.geomspace(0.01, 10, 60))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = control.describing_function_response(H, link, np.geomspace(0.1, 100, 200))
    assert len(ours) == len(theirs.intersections) == 1
    a, w = theirs.intersections[0]
    # measured: both A = 0.2239884, w = 0.2129935 rad/s, to 3e-8
    assert ours[0].amplitude == pytest.approx(a, rel=1e-6)
    assert 2 * math.pi * ours[0].frequency_hz == pytest.approx(w, rel=1e-6)
    # stable: the loop with the link stuck (N = k) is unstable, without it (N = 0) stable
    assert ours[0].stable
    assert np.max(control.feedback(H, 1.0).poles().real) > 0


def test_two_intersections_one_unstable_one_stable():
    # a mass on a spring, 1 / (s^2 + 0.4 s + 1), whose Jenkins link pushes (y1 = +0.95 P w):
    # its hysteresis feeds energy in. Stuck (N = k) and absent (N = 0) the loop is stable;
    # between, the equilibrium is unstable: two cycles, the smaller unstable (Loeb)
    import control

    from motionhyst import Jenkins
    from motionhyst.analysis.stability import intersections

    H = control.tf([-0.95], [1.0, 0.4, 1.0])
    small, large = intersections(H, Jenkins(k=1.0, fc=0.1), np.geomspace(1e-3, 1e3, 80),
                                 np.geomspace(1e-3, 100, 120))
    assert not small.stable and large.stable
    assert small.amplitude < large.amplitude

    def settled_amplitude(v0, t_end=400.0, h=1e-3):
        """An independent run from the equilibrium with a velocity kick (symplectic Euler,
        the stop operator's exact update)."""
        x, v, w = 0.0, v0, 0.0
        n = int(t_end / h)
        tail = []
        for i in range(n):
            v += h * (-0.4 * v - x + 0.95 * w)
            dx = h * v
            x += dx
            w = min(max(w + dx, -0.1), 0.1)
            if i >= n - int(50.0 / h):
                tail.append(x)
        return (max(tail) - min(tail)) / 2

    w_small = 2 * math.pi * small.frequency_hz
    # a kick below the unstable cycle dies out; one well above it ends on the stable cycle,
    # whose amplitude the describing function gives within its own error (measured 0.2084
    # against 0.2146: 3 %)
    assert settled_amplitude(0.9 * small.amplitude * w_small) < 1e-9
    assert settled_amplitude(3.0 * small.amplitude * w_small) == pytest.approx(
        large.amplitude, rel=0.05)


@pytest.mark.parametrize("link", [
    Dahl(k=20.0, fc=0.05), Dahl(k=20.0, fc=0.05, alpha=2.0),
    BoucWen(k=20.0, fc=0.05, n=1.0, beta=0.5, gamma=0.5),
    BoucWen(k=20.0, fc=0.05, n=2.0, beta=0.7, gamma=0.3)], ids=repr)
def test_state_equations_of_dahl_and_bouc_wen(link):
    # the derivatives are those of the state equation (central differences) ...
    for z, v in [(0.02, 0.01), (-0.03, 0.02), (0.01, -0.005)]:
        _, w, dzz, dzv, dwz, dwv = link.state_equation([z], v)
        assert w == z and dwz.tolist() == [1.0] and dwv == 0.0

        def zdot(zz, vv):
            return float(link.state_equation([zz], vv)[0][0])

        h = 1e-7
        assert dzz[0, 0] == pytest.approx((zdot(z + h, v) - zdot(z - h, v)) / (2 * h),
                                          rel=1e-5, abs=1e-9)
        assert dzv[0] == pytest.approx((zdot(z, v + h) - zdot(z, v - h)) / (2 * h), rel=1e-5)
    # ... and the state equation integrated along x = A sin t gives the model's own
    # describing function (its exact periodic loop), measured to 1e-10
    A = 0.004
    sol = solve_ivp(lambda t, z: link.state_equation(z, A * math.cos(t))[0], (0.0, 20 * math.pi),
                    [0.0], method="LSODA", rtol=1e-11, atol=1e-14, dense_output=True)
    t = np.linspace(18 * math.pi, 20 * math.pi, 4096, endpoint=False)
    c = 2.0 * np.fft.rfft(sol.sol(t)[0])[1] / t.size
    assert c / (-1j * A) == pytest.approx(complex(link.describing_function(A)), rel=1e-7)


def test_two_cycles_exact_with_a_dahl_link():
    # the loop of the two intersections with a Dahl link, whose state equation gives the
    # exact orbits of both: the smaller cycle unstable, the larger stable, each confirmed
    # by a run beside it (measured: |mu| 1.816 and 0.584; the describing function's period
    # +7.5 % and -1.6 %, peak-to-peak -11.3 % and +5.2 %)
    import control

    from motionhyst import Loop

    P = control.tf([1.0], [1.0, 0.4, 1.0])
    loop = Loop((-0.95 * P, P), control.tf([0.0], [1.0]), Dahl(k=1.0, fc=0.1),
                feedforward=None, mass=1.0)
    res = stability(loop, amplitudes=np.geomspace(1e-3, 1e3, 80),
                    frequencies_hz=np.geomspace(1e-3, 100, 120) / (2 * math.pi))
    small, large = res.predicted
    assert not small.stable and large.stable
    assert [c.stable for c in res.exact] == [False, True]
    assert all(c.confirmed and c.found_by == "prediction" for c in res.exact)
    assert res.exact[0].floquet_max > 1.5 and res.exact[1].floquet_max < 0.7
    for c in res.exact:
        p = c.predicted
        assert 1.0 / p.frequency_hz == pytest.approx(c.period_s, rel=0.15)
        assert p.peak_to_peak == pytest.approx(c.peak_to_peak, rel=0.15)


def test_the_hunting_loop_is_refused_by_a_time_simulation_naming_the_filter(tmp_path, capsys):
    """Its PID has a pure derivative (kd, no derivative_filter_hz): no continuous realisation
    to run in time.  ``simulate`` says so in one line naming the key that gives one, before
    the run, and writes nothing; before, python-control's "transfer function is non-proper;
    can't convert to StateSpace system" came out of the run, naming no key."""
    out = tmp_path / "h.csv"
    argv = ["simulate", str(HUNTING), "--time-series", str(out), "--duration", "1"]
    assert cli_main(argv) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if "error" in ln]
    assert err == ["motionhyst: error: the controller is not proper (more zeros than poles: "
                   "a PID's kd without derivative_filter_hz): a time simulation needs "
                   "[controller] derivative_filter_hz, or sample_rate_hz to run it sampled"]
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="derivative_filter_hz"):
        simulate(load_scenario(HUNTING).loop(), SineReference(0.01, 0.1), 0.1)
