"""The maxwell-iwan link: a spring, Maxwell branches and a uniform Iwan element in parallel."""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import quad

from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.cli import main
from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis import MODELS, Jenkins, MaxwellIwan, jenkins_describing_function
from motionhyst.hysteresis.maxwell_iwan import iwan_describing_function
from motionhyst.hysteresis.periodic import stop_periodic_harmonics
from motionhyst.hysteresis.stepping import GL_T, GL_W, MAXWELL, Stepping, open_loop
from motionhyst.present import plots
from motionhyst.scenario import (
    ScenarioError,
    default_scenario,
    default_scenario_path,
    hysteresis_from_dict,
)
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

TWO_PI = 2.0 * np.pi
# the example: k0 = 5 N/m, two Maxwell branches, an Iwan element of 30 N/m slipping
# between 0.1 and 4 mm
PARAMS = {"k0": 5.0, "kv": [8.0, 3.0], "cv": [0.4, 0.02], "ki": 30.0, "d_min": 1e-4,
          "d_max": 4e-3}
OMEGA = TWO_PI * 10.0


@pytest.fixture(scope="module")
def link() -> MaxwellIwan:
    return MaxwellIwan(**PARAMS)


def quad_iwan(ki, d_min, d_max, A):
    """``ki / (d_max - d_min)`` times the integral of eq. (10) over ``d``, by scipy's quad."""
    pts = [A] if d_min < A < d_max else None

    def part(d, which):
        return getattr(jenkins_describing_function(1.0, d / A), which)

    re = quad(part, d_min, d_max, args=("real",), points=pts, epsabs=0.0, epsrel=1e-13,
              limit=200)[0]
    im = quad(part, d_min, d_max, args=("imag",), points=pts, epsabs=0.0, epsrel=1e-13,
              limit=200)[0]
    return ki / (d_max - d_min) * complex(re, im)


# ------------------------------------------------------------------ describing function

@pytest.mark.parametrize("d_min, d_max", [(1e-4, 4e-3), (0.0, 2e-3), (1e-3, 1.01e-3),
                                          (1e-3, 1.0000001e-3)])
def test_describing_function_matches_quadrature_of_eq10(d_min, d_max):
    """Closed form (and, for d_max - d_min < 1e-3 d_max, the Gauss rule) within 1e-9 of quad
    across amplitudes from below d_min to 2500 d_max; measured 7e-15 (3e-13 for the 1 %
    range, where the difference of the antiderivative cancels by d / (d_max - d_min))."""
    A = np.geomspace(0.2 * max(d_min, 1e-5), 2500.0 * d_max, 45)
    D = iwan_describing_function(30.0, d_min, d_max, A)
    ref = np.array([quad_iwan(30.0, d_min, d_max, a) for a in A])
    assert np.max(np.abs(D - ref) / np.abs(ref)) < 1e-9
    # each part, where it is not negligible
    assert np.max(np.abs(D.real - ref.real) / np.abs(ref)) < 1e-9
    big = ref.imag > 1e-6 * np.abs(ref)
    assert np.max(np.abs(D.imag - ref.imag)[big] / ref.imag[big]) < 1e-9


def test_describing_function_is_linear_part_plus_iwan(link):
    A = np.array([0.0, 5e-5, 1e-3, 2e-2])
    om = np.array([0.0, 3.0, OMEGA, 1e4])
    D = link.describing_function(A[:, None], om[None, :])
    assert D.shape == (4, 4) and D.dtype == complex
    jw = 1j * om
    lin = 5.0 + 8.0 * jw * 0.4 / (8.0 + jw * 0.4) + 3.0 * jw * 0.02 / (3.0 + jw * 0.02)
    expect = lin[None, :] + np.array([quad_iwan(30.0, 1e-4, 4e-3, a) if a > 1e-4 else 30.0
                                      for a in A])[:, None]
    assert np.max(np.abs(D - expect) / np.abs(expect)) < 1e-9
    assert isinstance(link.describing_function(1e-3, OMEGA), complex)
    # A = 0 and A <= d_min: nothing slips
    assert D[0, 2] == D[1, 2] == lin[2] + 30.0
    # |D| never exceeds the instantaneous stiffness k0 + sum kv + ki
    assert np.all(np.abs(D) <= link.initial_stiffness * (1 + 1e-15))


def test_single_slip_displacement_is_the_jenkins_element():
    """d_min = d_max: one Jenkins element k = ki, fc = ki d (eq. 10) exactly; nearby ranges
    approach it continuously."""
    A = np.geomspace(1e-5, 1.0, 40)
    jenkins = Jenkins(k=30.0, fc=30.0 * 1e-3).describing_function(A)
    one = MaxwellIwan(k0=0.0, ki=30.0, d_min=1e-3, d_max=1e-3)
    assert np.max(np.abs(one.describing_function(A, 1.0) - jenkins)) <= 1e-15 * 30.0
    for rel in (1e-4, 1e-7):
        near = MaxwellIwan(k0=0.0, ki=30.0, d_min=1e-3, d_max=1e-3 * (1 + rel))
        assert np.max(np.abs(near.describing_function(A, 1.0) - jenkins)) < 2 * rel * 30.0


def test_maxwell_branch_limits():
    """kv -> 0: no branch; cv -> inf: a spring kv in parallel; cv -> 0: no branch; and the
    branch is exactly kv j w cv / (kv + j w cv)."""
    A, om = 1e-3, OMEGA
    iwan = MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3)
    base = iwan.describing_function(A, om)
    soft = MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3, kv=[1e-12], cv=[0.4])
    assert abs(soft.describing_function(A, om) - base) < 1e-11
    stiff = MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3, kv=[8.0], cv=[1e12])
    assert abs(stiff.describing_function(A, om) - (base + 8.0)) < 1e-9
    free = MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3, kv=[8.0], cv=[1e-12])
    assert abs(free.describing_function(A, om) - base) < 1e-9
    one = MaxwellIwan(k0=5.0, ki=30.0, d_min=1e-4, d_max=4e-3, kv=[8.0], cv=[0.4])
    tau = 0.4 / 8.0  # the branch: 8 (j w tau) / (1 + j w tau)
    assert one.describing_function(A, om) - base == pytest.approx(
        8.0 * 1j * om * tau / (1 + 1j * om * tau), rel=1e-14)


def test_large_amplitude_is_eq11_over_the_slip_force(link):
    """A >> d_max: D_Iwan -> (4/pi) j ki mean(d) / A (eq. 11): the imaginary part to
    O(d_max / A), the real part is O((d_max / A)^(3/2)) (eq. 10: (16 / 3 pi) zeta^(3/2))."""
    mean_d = 0.5 * (1e-4 + 4e-3)
    for A in (0.4, 40.0):
        D_iwan = link.describing_function(A, OMEGA) - link.linear_gain(OMEGA)
        limit = 4.0 / np.pi * 30.0 * mean_d / A
        r = 4e-3 / A
        assert abs(D_iwan.imag - limit) < r * limit
        assert abs(D_iwan.imag - limit) > 0.1 * r * limit  # not the same thing
        assert 0.0 < D_iwan.real < 2.0 * np.sqrt(r) * limit


@pytest.mark.parametrize("A", [5e-5, 2e-4, 1e-3, 3e-3, 1e-2])
def test_dissipated_energy_is_the_loop_area(link, A):
    """pi A^2 Im D equals the area of the exact loop (sine_loop); measured 2e-9, the error of
    the trapezoidal rule on 2^14 samples."""
    x, w = link.sine_loop(A, OMEGA, 2**14)
    area = np.trapezoid(w, x)
    assert area == pytest.approx(np.pi * A**2 * link.describing_function(A, OMEGA).imag,
                                 rel=1e-7)


# ------------------------------------------------------------------ periodic output, HOSIDF

@pytest.mark.parametrize("A", [5e-5, 2e-4, 1e-3, 3e-3, 1e-2])
def test_hosidf_matches_fft_of_the_exact_loop(link, A):
    """H_1 .. H_9 from periodic_harmonics within 1e-12 of |H_1| of the FFT of the closed-form
    Masing loop (measured 1e-15 to 9e-15); H_1 is the closed-form describing function."""
    n = 2**16
    _, w = link.sine_loop(A, OMEGA, n)
    fft = 2j * (np.fft.rfft(w[:-1]) / n)[1:10] / A
    H = link.hosidf(A, 9, OMEGA)
    assert np.max(np.abs(H - fft)) < 1e-12 * abs(H[0])
    assert abs(H[0] - link.describing_function(A, OMEGA)) < 1e-12 * abs(H[0])
    assert np.all(H[1::2] == 0)  # half-wave symmetry


def test_hosidf_at_zero_amplitude_and_shape(link):
    H = link.hosidf([0.0, 1e-3], 3, OMEGA)
    assert H.shape == (2, 3)
    assert H[0, 0] == link.describing_function(0.0, OMEGA)
    assert np.all(H[0, 1:] == 0)


def _minor_loops():
    """x = A sin + 0.6 A sin(3 theta + 0.3): four reversals per period."""
    return np.array([1e-4, 3e-3 / 2j, 0.0, 0.6 * 3e-3 / 2j * np.exp(0.3j)])


def _twenty_harmonics():
    """Twenty random harmonics: twelve reversals and nearly stationary inflections."""
    rng = np.random.default_rng(1)
    X = np.zeros(21, complex)
    X[1] = 3e-3 / 2j
    X[2:] = 0.05 * 3e-3 * (rng.normal(size=19) + 1j * rng.normal(size=19)) / np.arange(2, 21)
    return X


@pytest.mark.parametrize("make_input", [_minor_loops, _twenty_harmonics])
def test_periodic_harmonics_of_multi_harmonic_inputs(link, make_input):
    """Inputs with minor loops: the Iwan integral is cut at half the differences of the
    reversal and inflection values.  Reference: 40,000 stop operators at the midpoints of equal
    cells (second order in their number: 6e-10 and 2e-10 relative at 20,000, 2e-11 and 5e-12
    at 80,000); without the inflection cuts the second input was off by 2e-6."""
    X = make_input()
    W = link.periodic_harmonics(X, 12, OMEGA)
    n = 40_000
    d = 1e-4 + (np.arange(n) + 0.5) * (3.9e-3 / n)
    ref = stop_periodic_harmonics(X, np.full(n, 30.0 / n), 30.0 / n * d, 12)
    m = np.arange(min(13, X.size))
    ref[m] += link.linear_gain(OMEGA * m) * X[m]  # k0 X_0 at m = 0
    assert np.max(np.abs(W - ref)) < 1e-9 * abs(W[1])
    assert abs(W[1]) > 0.01  # a force of the size of the slip force


def test_periodic_harmonics_of_a_constant_input_is_the_spring(link):
    W = link.periodic_harmonics(np.array([2e-3]), 3, OMEGA)
    assert W[0] == pytest.approx(5.0 * 2e-3) and np.all(W[1:] == 0)


# ------------------------------------------------------------------ time domain

def test_maxwell_primitive_is_exact_for_a_ramp():
    """The MAXWELL row of the compiled step: f = cv v (1 - exp(-t kv / cv)) under x = v t, at
    any step size."""
    st = Stepping.from_rows([(MAXWELL, (8.0, 0.4))], 1.0)
    for h in (1e-4, 0.03):
        t = np.arange(50) * h
        w = open_loop(st.codes, st.params, st.state0, 2e-3 * t, h, GL_T, GL_W)
        exact = 0.4 * 2e-3 * -np.expm1(-t * 8.0 / 0.4)
        assert np.max(np.abs(w - exact)) < 1e-15


@pytest.mark.parametrize("n_stops", [64, 256])
def test_response_to_a_sine_approaches_the_exact_loop(n_stops):
    """After the branches' transients (20 periods, tau = cv / kv <= 0.05 s), the response is
    the closed-form loop: the Iwan element as n stop operators errs by at most
    ki (d_max - d_min) / (4 n^2) (measured 6.3e-6 N and 4.4e-7 N for n = 64 and 256 at
    A = 1 mm, bounds 7.1e-6 N and 4.5e-7 N), the branches by O(dt^2) (2e-10 N here)."""
    el = MaxwellIwan(**PARAMS, n_stops=n_stops)
    bound = 30.0 * 3.9e-3 / (4 * n_stops**2)
    n = 2000
    t = np.arange(20 * n + 1) / (n * 10.0)
    for A in (5e-5, 1e-3, 1e-2):
        w = el.response(A * np.sin(OMEGA * t), t=t)
        _, w_exact = el.sine_loop(A, OMEGA, n)
        err = np.max(np.abs(w[-n - 1:] - w_exact))
        assert err < bound + 1e-9
        if A > 4e-3:  # every element slips: the bound is nearly reached
            assert err > 0.5 * bound


def test_single_slip_displacement_steps_as_the_jenkins_element():
    """d_min = d_max: one stop operator in the time step, the Jenkins element's exact response;
    its periodic output is the Jenkins element's too."""
    one = MaxwellIwan(k0=0.0, ki=30.0, d_min=1e-3, d_max=1e-3)
    st = one.time_stepping()
    assert st.codes.size == 1 and st.scale == pytest.approx(0.03)
    t = np.linspace(0.0, 1.0, 3001)
    x = 3e-3 * np.sin(TWO_PI * 2.0 * t) * np.exp(-t)
    jenkins = Jenkins(k=30.0, fc=0.03)
    assert np.max(np.abs(one.response(x, t=t) - jenkins.response(x))) < 1e-15
    X = np.array([0.0, 2e-3 / 2j, 0.0, 5e-4 / 2j])
    assert np.max(np.abs(one.periodic_harmonics(X, 7, 1.0)
                         - jenkins.periodic_harmonics(X, 7))) < 1e-15


def test_loop_simulation_matches_exact_steady_state():
    """The Table I loop with this link: after settling, the simulated error's harmonics are
    those of the exact periodic steady state (64 stop operators: measured 4.6e-6 in e1 and
    5.7e-5 in e3; 256: 4.9e-7 and 4.2e-6)."""
    loop = default_scenario().loop()
    lp = Loop(loop.plant, loop.controller, MaxwellIwan(**PARAMS, n_stops=64))
    sim = simulate(lp, SineReference(0.01, 10.0), 2.5)
    steady = periodic_steady_state(lp, 0.01, 10.0)
    m = sim.t >= sim.t[-1] - 1.0
    th = TWO_PI * 10.0 * sim.t[m]
    cols = [np.ones_like(th)]
    for k in range(1, 10):
        cols += [np.sin(k * th), np.cos(k * th)]
    c, *_ = np.linalg.lstsq(np.column_stack(cols), sim.e[m], rcond=None)
    c = np.concatenate([[c[0]], c[1::2] + 1j * c[2::2]])
    assert abs(c[1] - steady.e[1]) < 2e-5 * abs(steady.e[1])
    assert abs(c[3] - steady.e[3]) < 3e-4 * abs(steady.e[3])
    # the link matters: half of e1 here
    assert abs(steady.e[1] - steady.e_linear[1]) > 0.4 * abs(steady.e[1])


# ------------------------------------------------------------------ scenario and CLI

def test_registered_with_declared_parameters():
    assert MODELS["maxwell-iwan"] is MaxwellIwan
    assert [p.name for p in MaxwellIwan.parameters] == ["k0", "kv", "cv", "ki", "d_min",
                                                         "d_max"]


def test_scenario_section_builds_the_link():
    el = hysteresis_from_dict({"model": "maxwell-iwan", **PARAMS})
    assert isinstance(el, MaxwellIwan)
    assert el.to_dict() == {"model": "maxwell-iwan", **PARAMS}
    # no Maxwell branches: kv and cv omitted or empty
    for extra in ({}, {"kv": [], "cv": []}):
        bare = hysteresis_from_dict({"model": "maxwell-iwan", "k0": 5.0, "ki": 30.0,
                                     "d_min": 1e-4, "d_max": 4e-3, **extra})
        assert bare.kv.size == 0 and bare.to_dict()["cv"] == []
        assert bare.describing_function(1e-3, 0.0) == bare.describing_function(1e-3, 1e3)


@pytest.mark.parametrize("change, fragment", [
    ({"d_max": 1e-5}, "d_max must be >= d_min"),
    ({"cv": [0.4]}, "kv and cv must have the same length (2 != 1)"),
    ({"kv": [8.0, -3.0]}, "kv"),
    ({"d_min": -1e-4}, "d_min"),
    ({"ki": 0}, "ki"),
    ({"d_mx": 1.0}, "d_mx: unknown key"),
])
def test_scenario_errors_are_one_line(change, fragment):
    with pytest.raises(ScenarioError) as exc:
        hysteresis_from_dict({"model": "maxwell-iwan", **PARAMS, **change}, source="s.toml")
    assert fragment in str(exc.value) and "\n" not in str(exc.value)


def run_cli(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(list(args))
        except SystemExit as e:  # argparse
            rc = e.code
    return rc, out.getvalue(), err.getvalue()


DF_ARGS = ("df", "--model", "maxwell-iwan", "--k0", "5", "--kv", "8", "3", "--cv", "0.4",
           "0.02", "--ki", "30", "--d-min", "1e-4", "--d-max", "4e-3")


def test_df_json_one_point_per_amplitude_and_frequency(link):
    rc, out, err = run_cli(*DF_ARGS, "--amplitude", "5e-5", "1e-3", "--frequency", "10", "100",
                           "--harmonics", "3", "--json")
    assert rc == 0 and err == ""
    d = json.loads(out)
    assert {k: d[k] for k in PARAMS} == PARAMS and d["model"] == "maxwell-iwan"
    pts = d["points"]
    assert [(p["frequency_hz"], p["amplitude"]) for p in pts] == [
        (10.0, 5e-5), (10.0, 1e-3), (100.0, 5e-5), (100.0, 1e-3)]
    for p in pts:
        D = link.describing_function(p["amplitude"], TWO_PI * p["frequency_hz"])
        assert complex(p["re"], p["im"]) == D
        assert p["zeta"] is None
        assert [h["n"] for h in p["harmonics"]] == [1, 2, 3]
        assert p["harmonics"][0]["abs_over_amplitude"] == pytest.approx(abs(D), rel=1e-12)


def test_df_text_lists_parameters_and_initial_stiffness():
    rc, out, _ = run_cli("df", "--model", "maxwell-iwan", "--k0", "5", "--ki", "30",
                         "--d-min", "1e-4", "--d-max", "4e-3", "--amplitude", "1e-3",
                         "--frequency", "10")
    assert rc == 0
    assert "k0 = 5 N/m, kv = none, cv = none, ki = 30 N/m, d_min = 0.0001 m" in out
    assert "k_init = 35 N/m" in out


@pytest.mark.parametrize("args, fragments", [
    (("--amplitude", "1e-3"), ("--frequency", "required")),
    (("--d-min", "1e-2", "--amplitude", "1e-3", "--frequency", "1"), ("d_max must be >= d_min",)),
    (("--kv", "8", "--amplitude", "1e-3", "--frequency", "1"), ("kv and cv", "(1 != 0)")),
])
def test_df_errors_are_one_line_exit_2(args, fragments):
    base = {"--k0": "5", "--ki": "30", "--d-min": "1e-4", "--d-max": "4e-3"}
    given = dict(zip(args[::2], args[1::2], strict=True))  # a case's value replaces the base's
    rc, out, err = run_cli("df", "--model", "maxwell-iwan",
                           *(x for kv in {**base, **given}.items() for x in kv))
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert all(f in err for f in fragments)


def test_df_missing_and_foreign_options_name_the_dashed_option():
    rc, _, err = run_cli("df", "--model", "maxwell-iwan", "--k0", "5", "--ki", "30",
                         "--d-max", "4e-3", "--amplitude", "1e-3", "--frequency", "1")
    assert rc == 2 and "--d-min is required for --model maxwell-iwan" in err
    rc, _, err = run_cli("df", "--model", "jenkins", "--k", "20", "--fc", "0.05", "--d-min",
                         "1e-3", "--amplitude", "1e-3")
    assert rc == 2 and "--d-min does not apply to --model jenkins" in err


def test_df_imports_nothing_heavy():
    """The closed-form describing function needs no compiled kernel: ``df`` for this link
    imports neither numba, python-control nor matplotlib (a fresh interpreter)."""
    code = ("import contextlib, io, json, sys\n"
            "from motionhyst.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    rc = main(sys.argv[1:])\n"
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
            "('numba', 'control', 'matplotlib'))\n"
            "print(json.dumps([rc, heavy]))\n")
    proc = subprocess.run([sys.executable, "-c", code, *DF_ARGS, "--amplitude", "1e-3",
                           "--frequency", "10"], capture_output=True, text=True, timeout=600,
                          check=False)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [0, []]


def test_analyze_and_steady_state_of_a_scenario(tmp_path):
    text = default_scenario_path().read_text()
    head, rest = text.split("[hysteresis]", 1)
    tail = rest[rest.index("\n["):]
    link = ('model = "maxwell-iwan"\nk0 = 5.0\nkv = [8.0, 3.0]\ncv = [0.4, 0.02]\nki = 30.0\n'
            'd_min = 1e-4\nd_max = 4e-3\n')
    path = tmp_path / "iwan.toml"
    path.write_text(f"{head}[hysteresis]\n{link}{tail}")
    rc, out, err = run_cli("analyze", str(path), "--frequency", "5", "10", "--json")
    assert rc == 0, err
    a = json.loads(out)
    assert a["df_frequency_hz"] == 5.0  # rate-dependent: D at the first frequency
    rc, out, err = run_cli("steady", str(path), "--frequency", "10", "--json")
    assert rc == 0, err
    (p,) = json.loads(out)["points"]
    # the describing function's prediction of the error is close to the exact steady state
    assert p["mismatch_simulated_abs"] == pytest.approx(p["mismatch_df_abs"], rel=0.02)


def test_figures_of_the_link(link):
    """Figs. 5 and 8 draw this link (reproduce with a maxwell-iwan scenario): the loops are the
    exact ones at zeta = fc / (k A) with fc = ki mean(d), the total slip force."""
    assert link.fc == pytest.approx(30.0 * 2.05e-3, rel=1e-15)
    data = plots.fig5_loops(link, frequency_hz=5.0).motionhyst_data
    A = link.fc / (link.initial_stiffness * 0.5)
    x, w = link.sine_loop(A, TWO_PI * 5.0)
    np.testing.assert_allclose(data["zeta=0.5"], np.vstack([x, w]), rtol=1e-12)
    d8 = plots.fig8_describing_function(link, frequency_hz=5.0).motionhyst_data
    assert np.all(d8["abs_over_k"] <= 1.0)
    assert d8["abs_over_k"][-1] == pytest.approx(
        abs(link.describing_function(0.1 * link.fc / link.initial_stiffness, TWO_PI * 5.0))
        / link.initial_stiffness, rel=1e-12)


# ------------------------------------------------------------------ errors

@pytest.mark.parametrize("kwargs, fragment", [
    ({"k0": -1.0}, "k0 must be finite and >= 0"),
    ({"ki": 0.0}, "ki must be finite and > 0"),
    ({"d_min": float("nan")}, "d_min must be finite"),
    ({"d_max": 0.0}, "d_max must be finite and > 0"),
    ({"d_max": 5e-5}, "d_max must be >= d_min"),
    ({"kv": [8.0]}, "kv and cv must have the same length (1 != 2)"),
    ({"kv": [8.0, 0.0]}, "kv[1] must be finite and > 0"),
    ({"cv": [0.4, float("inf")]}, "cv[1] must be finite and > 0"),
    ({"cv": "abc"}, "cv must be a list of numbers"),
    ({"kv": [[8.0], [3.0]]}, "kv must be a list of numbers"),
    ({"n_stops": 0}, "n_stops must be an integer >= 1"),
])
def test_constructor_errors_name_the_parameter(kwargs, fragment):
    with pytest.raises(ValueError) as exc:
        MaxwellIwan(**{**PARAMS, **kwargs})
    assert fragment in str(exc.value) and "\n" not in str(exc.value)


def test_rate_dependent_calls_need_frequency_or_time(link):
    with pytest.raises(ValueError, match="rate-dependent: give the angular frequency"):
        link.describing_function(1e-3)
    with pytest.raises(ValueError, match="omega must be finite and >= 0"):
        link.describing_function(1e-3, -1.0)
    with pytest.raises(ValueError, match="amplitude must be finite"):
        link.describing_function(-1e-3, 1.0)
    with pytest.raises(ValueError, match="rate-dependent"):
        link.periodic_harmonics(np.array([0, 1e-3 / 2j]), 3)
    with pytest.raises(ValueError, match="needs the sample times"):
        link.response([0.0, 1e-3])
    with pytest.raises(ValueError, match="strictly increasing"):
        link.response([0.0, 1e-3], t=[0.0, 0.0])
    with pytest.raises(ValueError, match="w0 must be 0"):
        link.response([0.0, 1e-3], w0=1.0, t=[0.0, 1.0])
    with pytest.raises(TypeError, match="rate-dependent"):
        link(1e-3)
    with pytest.raises(ValueError, match="n_harmonics"):
        link.periodic_harmonics(np.array([0, 1e-3 / 2j]), -1, 1.0)
