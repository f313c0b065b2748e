"""The Maxwell-slip element (parallel Jenkins elements): sums, closed form, validation, energy."""

from __future__ import annotations

import json

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from motionhyst.hysteresis import Jenkins, MaxwellSlip
from motionhyst.hysteresis.periodic import (
    stop_harmonics_base,
    stop_harmonics_update,
    stop_periodic_harmonics,
    stop_twiddles,
)
from motionhyst.scenario import hysteresis_from_dict

K3, FC3 = [8.0, 6.0, 4.0], [0.01, 0.03, 0.06]
# amplitudes below, at and far above the slip displacements fc/k of the elements
AMPLITUDES = np.array([1e-4, 0.00125, 0.004, 0.005, 0.01, 0.05, 1.0])


def sine_periods(A: float, n_per_period: int, periods: int = 2) -> np.ndarray:
    """``A sin(theta)`` over `periods` periods, closing sample included."""
    th = 2 * np.pi * np.arange(periods * n_per_period + 1) / n_per_period
    return A * np.sin(th)


def loop_area(x: np.ndarray, w: np.ndarray) -> float:
    """Work done on the element over one closed loop, ``oint w dx``, by the shoelace formula.

    The shoelace sum ``(1/2) sum (x_i w_{i+1} - x_{i+1} w_i)`` is the signed area, positive
    for a counter-clockwise loop in the (x, w) plane; a dissipating element runs clockwise,
    so the work is its negative.
    """
    assert x[0] == pytest.approx(x[-1], abs=1e-15 * np.max(np.abs(x)))
    assert w[0] == pytest.approx(w[-1], abs=1e-12 * np.max(np.abs(w)))
    return -0.5 * float(np.sum(x[:-1] * w[1:] - x[1:] * w[:-1]))


@pytest.fixture
def link3() -> MaxwellSlip:
    return MaxwellSlip(k=K3, fc=FC3)


# ---------------------------------------------------------- one element = Jenkins
def test_one_element_describing_function_equals_jenkins():
    ms, j = MaxwellSlip([20.0], [0.05]), Jenkins(20.0, 0.05)
    a = np.concatenate([[0.0], AMPLITUDES])
    assert_allclose(ms.describing_function(a), j.describing_function(a), rtol=1e-15, atol=0)
    assert isinstance(ms.describing_function(0.01), complex)
    assert ms.describing_function(0.01) == pytest.approx(j.describing_function(0.01), rel=1e-15)


def test_one_element_response_equals_jenkins():
    rng = np.random.default_rng(1)
    x = np.cumsum(rng.normal(scale=0.003, size=5000))
    ms, j = MaxwellSlip([20.0], [0.05]), Jenkins(20.0, 0.05)
    assert_array_equal(ms.response(x), j.response(x))
    assert_array_equal(ms.response(x, w0=0.03), j.response(x, w0=0.03))


def test_one_element_periodic_harmonics_equal_jenkins():
    ms, j = MaxwellSlip([20.0], [0.05]), Jenkins(20.0, 0.05)
    X = np.array([0.001, 0.01 / 2j, 0.002 - 0.001j, 0.0, 0.0005j])  # a rich periodic input
    assert_array_equal(ms.periodic_harmonics(X, 11), j.periodic_harmonics(X, 11))


def test_one_element_hosidf_equals_jenkins():
    ms, j = MaxwellSlip([20.0], [0.05]), Jenkins(20.0, 0.05)
    a = np.concatenate([[0.0], AMPLITUDES])
    assert_array_equal(ms.hosidf(a, 9), j.hosidf(a, 9))
    with np.errstate(divide="ignore", invalid="ignore"):  # A = 0: see test_hosidf.py
        assert_array_equal(ms.hosidf_closed_form(a, 9), j.hosidf_closed_form(a, 9))


# ----------------------------------------------------------------- sums of elements
def test_two_elements_describing_function_is_the_sum():
    ms = MaxwellSlip([1.0, 2.0], [1.0, 0.5])
    j1, j2 = Jenkins(1.0, 1.0), Jenkins(2.0, 0.5)
    a = np.concatenate([[0.0], AMPLITUDES, [0.3, 0.75, 3.0]])
    assert_allclose(ms.describing_function(a),
                    j1.describing_function(a) + j2.describing_function(a), rtol=1e-14)
    # A = 0: both springs stuck
    assert ms.describing_function(0.0) == 3.0


def test_two_elements_response_is_the_sum():
    ms = MaxwellSlip([1.0, 2.0], [1.0, 0.5])
    j1, j2 = Jenkins(1.0, 1.0), Jenkins(2.0, 0.5)
    rng = np.random.default_rng(2)
    x = np.cumsum(rng.normal(scale=0.4, size=4000))
    assert_allclose(ms.response(x), j1.response(x) + j2.response(x), rtol=0, atol=1e-15)
    w0 = np.array([-0.5, 0.25])
    assert_allclose(ms.response(x, w0=w0),
                    j1.response(x, w0=-0.5) + j2.response(x, w0=0.25), rtol=0, atol=1e-15)


def test_two_elements_hosidf_is_the_sum():
    ms = MaxwellSlip([1.0, 2.0], [1.0, 0.5])
    j1, j2 = Jenkins(1.0, 1.0), Jenkins(2.0, 0.5)
    a = np.array([0.3, 0.75, 1.2, 3.0, 40.0])
    n = 11
    h = ms.hosidf(a, n)
    h_sum = j1.hosidf(a, n) + j2.hosidf(a, n)
    scale = np.abs(h[..., :1])
    assert np.all(np.abs(h - h_sum) <= 1e-12 * scale)
    hc = ms.hosidf_closed_form(a, n)
    assert np.all(np.abs(hc - (j1.hosidf_closed_form(a, n) + j2.hosidf_closed_form(a, n)))
                  <= 1e-14 * scale)
    assert np.all(np.abs(h - hc) <= 1e-12 * scale)
    assert h.shape == (5, n)


# --------------------------------------------------------- python-control interface
def test_control_describing_function_uses_the_closed_form(link3, monkeypatch):
    amps = [0.001, 0.005, 0.02, 0.1]
    d = control.describing_function(link3, amps)
    assert_allclose(d, link3.describing_function(np.array(amps)), rtol=1e-15)
    calls = []
    closed = link3.describing_function

    def spy(A, *args, **kwargs):
        calls.append(A)
        return closed(A, *args, **kwargs)

    monkeypatch.setattr(link3, "describing_function", spy)
    control.describing_function(link3, 0.02)
    assert calls, "python-control did not call MaxwellSlip.describing_function"


@pytest.mark.parametrize("A", [0.001, 0.005, 0.02, 0.1])
def test_control_describing_function_numerics_agree(link3, A):
    """python-control's own quadrature (``try_method=False``) drives ``__call__``.

    One amplitude per call: python-control warms a stateful element up with one cycle at
    the smallest amplitude only, so with an array of amplitudes the larger ones are
    evaluated on a transient first cycle (a python-control limitation, several % off).
    """
    closed = complex(np.squeeze(control.describing_function(link3, A)))
    numeric = complex(np.squeeze(control.describing_function(link3, A, try_method=False)))
    assert abs(numeric - closed) <= 1e-3 * abs(closed)
    if A > min(f / k for k, f in zip(K3, FC3, strict=True)):
        assert numeric != closed  # a different computation: 100-point quadrature


# ------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("k", "fc", "pattern"),
    [
        ([1.0, 2.0], [1.0], r"k and fc must have the same length \(2 != 1\)"),
        ([1.0], [1.0, 2.0, 3.0], r"k and fc .*same length"),
        ([1.0], [], r"k and fc .*same length"),
        ([], [], r"k must be a non-empty"),
        ([1.0, 0.0], [1.0, 1.0], r"k\[1\] must be finite and > 0"),
        ([-1.0], [1.0], r"k\[0\] must be finite and > 0"),
        ([1.0, 1.0], [1.0, -0.5], r"fc\[1\] must be finite and > 0"),
        ([1.0], [0.0], r"fc\[0\] must be finite and > 0"),
        ([float("nan")], [1.0], r"k\[0\] must be finite and > 0"),
        ([1.0, 2.0], [1.0, float("nan")], r"fc\[1\] must be finite and > 0"),
        ([1.0], [float("inf")], r"fc\[0\] must be finite and > 0"),
    ],
)
def test_invalid_parameters_raise_naming_the_parameter(k, fc, pattern):
    with pytest.raises(ValueError, match=pattern):
        MaxwellSlip(k, fc)


def test_invalid_initial_force_and_input(link3):
    with pytest.raises(ValueError, match="w0"):
        link3.response(np.zeros(3), w0=[0.0, 0.0, 0.07])
    with pytest.raises(ValueError, match="finite"):
        link3.response(np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match="one-dimensional"):
        link3.response(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="amplitude"):
        link3.describing_function(-1.0)


# ------------------------------------------------------------------- properties
def test_response_stays_within_total_slip_force(link3):
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(scale=0.01, size=20000))
    w = link3.response(x)
    total = sum(FC3)
    assert np.max(np.abs(w)) <= total * (1 + 1e-12)
    # a long monotone stroke makes every element slip: the bound is reached exactly
    ramp = link3.response(np.linspace(0.0, 1.0, 101))
    assert ramp[-1] == pytest.approx(total, rel=1e-15)
    assert link3.slip_force == pytest.approx(total)


def test_initial_stiffness_is_sum_of_stiffnesses(link3):
    assert link3.initial_stiffness == pytest.approx(18.0, rel=1e-15)
    # small motions from rest: a spring of that stiffness
    x = np.linspace(0.0, 1e-4, 11)
    assert_allclose(link3.response(x), 18.0 * x, rtol=1e-13)
    # and |D| never exceeds it
    a = np.geomspace(1e-5, 10.0, 200)
    assert np.all(np.abs(link3.describing_function(a)) <= 18.0 * (1 + 1e-14))
    assert link3.describing_function(0.0) == pytest.approx(18.0)


@pytest.mark.parametrize("zeta", [0.1, 0.25, 0.5, 0.7, 0.95])
def test_dissipated_energy_equals_pi_a2_im_d_jenkins(zeta):
    j = Jenkins(20.0, 0.05)
    A = j.fc / (j.k * zeta)
    n = 2**16
    x = sine_periods(A, n)
    w = j.response(x)
    area = loop_area(x[n:], w[n:])  # second period: the periodic loop
    assert area == pytest.approx(np.pi * A**2 * j.describing_function(A).imag, rel=1e-8)


@pytest.mark.parametrize("A", [0.002, 0.004, 0.01, 0.05])
def test_dissipated_energy_equals_pi_a2_im_d_maxwell(link3, A):
    n = 2**16
    x = sine_periods(A, n)
    w = link3.response(x)
    area = loop_area(x[n:], w[n:])
    expected = np.pi * A**2 * link3.describing_function(A).imag
    assert expected > 0
    assert area == pytest.approx(expected, rel=1e-8)


def test_no_dissipation_below_the_smallest_slip_displacement(link3):
    A = 0.5 * min(f / k for k, f in zip(K3, FC3, strict=True))
    n = 4096
    x = sine_periods(A, n)
    w = link3.response(x)
    assert abs(loop_area(x[n:], w[n:])) <= 1e-15
    assert link3.describing_function(A) == pytest.approx(18.0, rel=1e-15)


# ---------------------------------------------------------------- serialisation
def test_to_dict_round_trips_through_hysteresis_from_dict(link3):
    d = link3.to_dict()
    assert d == {"model": "maxwell-slip", "k": K3, "fc": FC3}
    back = hysteresis_from_dict(json.loads(json.dumps(d)))
    assert isinstance(back, MaxwellSlip)
    assert back.to_dict() == d
    a = np.array([0.001, 0.01, 0.1])
    assert_array_equal(back.describing_function(a), link3.describing_function(a))
    assert repr(back) == repr(link3)


def test_single_element_to_dict_stays_a_list():
    d = MaxwellSlip([3.0], [1.0]).to_dict()
    assert d == {"model": "maxwell-slip", "k": [3.0], "fc": [1.0]}
    assert isinstance(hysteresis_from_dict(d), MaxwellSlip)


def test_parameters_are_read_only_and_the_slip_order_is_kept_whatever_the_caller_does():
    """The elements in slip order are derived once: the parameters cannot change under them,
    and a caller changing the arrays it was given does not change the link's."""
    link = MaxwellSlip([1.0, 2.0, 4.0], [1.0, 0.5, 0.2])
    for values in (link.k, link.fc):
        with pytest.raises(ValueError, match="read-only"):
            values[0] = 9.0
    k, fc = link.periodic_stops()
    assert_array_equal(k, [4.0, 2.0, 1.0])
    assert_array_equal(fc, [0.2, 0.5, 1.0])
    k[:] = 7.0
    fc[:] = 7.0
    assert_array_equal(link.periodic_stops()[0], [4.0, 2.0, 1.0])
    assert_array_equal(link.periodic_stops()[1], [0.2, 0.5, 1.0])
    assert_array_equal(link.k, [1.0, 2.0, 4.0])  # the link's own order
    k, fc = np.array([1.0, 2.0]), np.array([1.0, 0.5])
    link = MaxwellSlip(k, fc)
    link.periodic_stops()
    k[:] = [100.0, 200.0]  # the caller's arrays, written after: not the link's
    fc[:] = 9.0
    assert_array_equal(link.k, [1.0, 2.0])
    assert link.initial_stiffness == 3.0
    assert_array_equal(link.periodic_stops()[0], [2.0, 1.0])


def test_many_elements_steady_state_is_the_same_whatever_came_before():
    """The binned jump sums' weights are kept from one point to the next: the steady state
    of each point is the same, bit for bit, whichever points were computed before."""
    from motionhyst import Loop, default_scenario, periodic_steady_state

    loop = default_scenario().loop()
    u = np.geomspace(0.1, 10.0, 400) * 2.5e-3  # slip displacements fc / k [m]
    k = np.full(400, 0.05)
    link = Loop(loop.plant, loop.controller, MaxwellSlip(k, k * u * 0.05 / np.sum(k * u)))
    points = [(0.01, 10.5), (0.003, 10.0), (0.01, 3.7), (0.02, 10.2)]
    forward = [periodic_steady_state(link, A, f).e for A, f in points]
    backward = [periodic_steady_state(link, A, f).e for A, f in reversed(points)][::-1]
    for a, b in zip(forward, backward, strict=True):
        assert_array_equal(a, b)
    assert abs(forward[0][3]) > 1e-3 * abs(forward[0][1])  # the elements slip


@pytest.mark.parametrize("A", [0.004, 0.01])
def test_half_period_onsets_on_the_cubic_are_the_general_pass(A):
    """The half-period pass over elements sorted by slip displacement (one walk along the
    branch) gives the general pass's pieces exactly: elements that slip, that never slip,
    and several with the same slip displacement."""
    from motionhyst.hysteresis import _fft, _kernels
    from motionhyst.hysteresis.periodic import stop_twiddles

    M, n = 41, 1024
    rng = np.random.default_rng(2)
    X = np.zeros(M + 1, dtype=complex)
    X[1] = A / 2j
    X[3::2] = 1e-6 * A * (rng.standard_normal(20) + 1j * rng.standard_normal(20))
    m = np.arange(M + 1)
    C1, C2 = 1j * m * X, -(m**2) * X
    ok, rev, xr = _kernels.dominant_reversals(X, C1, C2, True)
    assert ok
    x = _fft.synthesize(X, n, stop_twiddles(M, M))
    u = np.sort(np.concatenate([np.geomspace(1e-6, 0.02, 300), [1e-3] * 5]))
    k = rng.uniform(0.5, 2.0, u.size)
    top = 1 if xr[1] > xr[0] else 0
    general = _kernels.stop_pieces(X, C1, x, rev, xr, k, k * u, _kernels.GRID_CUBIC, True)
    walked = _kernels.half_cubic_pieces(x, rev[top], xr[top], k, k * u)
    for a, b in zip(general, walked, strict=True):
        assert_array_equal(a, b)
    assert 0 < general[0].size - 1 < u.size  # some elements slip, some never do


def _rich_symmetric_input(M: int, A: float, seed: int) -> np.ndarray:
    """A sine of amplitude `A` with small odd harmonics up to `M` (a symmetric loop's y1)."""
    rng = np.random.default_rng(seed)
    X = np.zeros(M + 1, dtype=complex)
    X[1] = A / 2j
    n_odd = X[3::2].size
    X[3::2] = 1e-3 * A * (rng.standard_normal(n_odd) + 1j * rng.standard_normal(n_odd))
    X[3::2] /= np.arange(3, M + 1, 2) ** 2
    return X


def _many_elements() -> tuple[np.ndarray, np.ndarray]:
    """300 elements, some of which never slip at the amplitudes used (``fc / k`` up to 0.02)."""
    u = np.geomspace(1e-5, 0.02, 300)
    k = np.random.default_rng(5).uniform(0.5, 2.0, u.size)
    return k, k * u


def _full(X, k, fc, H, tw, grid=None):
    """:func:`stop_harmonics_base` with nothing kept: the output computed in full (the grid
    of its binned sums in `grid`)."""
    grid = np.zeros(2, dtype=np.int64) if grid is None else grid
    return stop_harmonics_base(X, k, fc, H, tw, np.empty((0, 0)), grid, 2 * H, 1e-17)


@pytest.mark.parametrize("direction", ["amplitude", "phase", "harmonics"])
def test_small_change_of_the_input_is_followed_to_first_order(direction):
    """Near an input whose output was computed in full, the output of an input within 1e-10
    of it is that output plus the first-order change: the same as computed in full to 1e-14
    of the largest harmonic, while the change is 6e-12 to 5e-11 of it (a wrong or missing
    first-order term shows)."""
    k, fc = _many_elements()
    M, H = 41, 60
    X = _rich_symmetric_input(M, 0.01, 1)
    tw = stop_twiddles(M, H)
    grid = np.zeros(2, dtype=np.int64)
    Wb, table, base, Xb, S, zs, t_b, js, x_top, moments = _full(X, k, fc, H, tw, grid)
    assert base and 0 < t_b.size - 1 < k.size  # some elements slip, some never do
    eps = 5e-11
    if direction == "amplitude":
        Xn = X * (1 + eps)
    elif direction == "phase":
        Xn = X * np.exp(-1j * eps * np.arange(M + 1))
    else:
        Xn = X.copy()
        Xn[3::2] += eps * abs(X[1]) / 20 * np.exp(1j * np.arange(3, M + 1, 2))
    full = _full(Xn, k, fc, H, tw)[0]
    ok, W = stop_harmonics_update(Xn, H, tw, Wb, Xb, S, zs, t_b, js, x_top, moments, table,
                                  grid)
    assert ok
    scale = np.max(np.abs(full))
    assert np.max(np.abs(full - Wb)) > 1e-12 * scale
    assert_allclose(W, full, rtol=0, atol=1e-14 * scale)


def test_a_change_the_first_order_does_not_follow_is_refused():
    """A change above 1e-10 of the input, even harmonics (no half-wave symmetry) or more
    harmonics than the input computed in full: the update says no."""
    k, fc = _many_elements()
    M, H = 41, 60
    X = _rich_symmetric_input(M, 0.01, 2)
    tw = stop_twiddles(M + 2, H)
    grid = np.zeros(2, dtype=np.int64)
    base = _full(X, k, fc, H, tw, grid)
    assert base[2]
    kept = (base[0], *base[3:], base[1], grid)
    assert stop_harmonics_update(X * (1 + 1e-11), H, tw, *kept)[0]
    assert not stop_harmonics_update(X * (1 + 1e-9), H, tw, *kept)[0]
    even = X.copy()
    even[2] = 1e-12 * abs(X[1])
    assert not stop_harmonics_update(even, H, tw, *kept)[0]
    longer = np.concatenate([X, [0.0, 1e-13 * abs(X[1])]])
    assert not stop_harmonics_update(longer, H, tw, *kept)[0]
    no_moments = (*kept[:7], np.empty((0, 0)), *kept[8:])  # none kept from the evaluation
    assert not stop_harmonics_update(X * (1 + 1e-11), H, tw, *no_moments)[0]


def _fixed_point_in_full(lp, A: float, f: float) -> tuple[np.ndarray, int]:
    """The steady state's error harmonics (relative to ``sin(n theta)``) and iterations by the
    same fixed point and stopping rule, every iteration computed in full."""
    from motionhyst.analysis.steady import default_harmonics
    from motionhyst.core.lti import TWO_PI
    from motionhyst.hysteresis.periodic import stop_periodic_harmonics

    H = default_harmonics(lp, f)
    wn = TWO_PI * f * np.arange(H + 1)
    y1_lin = np.zeros(H + 1, dtype=complex)
    y1_lin[1] = lp.transfer("r->y1", wn[1:2])[0] * (-0.5j * A)
    G_1 = lp.transfer("w->y1", wn)
    X, W, previous = y1_lin, np.zeros(H + 1, dtype=complex), np.inf
    for it in range(1, 51):
        W_new = stop_periodic_harmonics(X, lp.hysteresis.k, lp.hysteresis.fc, H)
        residual = abs(W_new[1] - W[1]) / abs(W_new[1])
        change = np.max(np.abs(W_new - W))
        W, X = W_new, y1_lin + G_1 * W_new
        rho = residual / previous if it > 2 else 1.0
        previous = residual
        if it > 1 and (change == 0.0 or (rho < 0.5 and residual * rho / (1 - rho) <= 1e-12)):
            break
    e = lp.transfer("w->e", wn) * W
    e[1] += lp.transfer("r->e", wn[1:2])[0] * (-0.5j * A)
    e_sin = 2j * e
    e_sin[0] = e[0].real
    return e_sin, it


def _many_element_loop(n: int, scale: float = 1.0):
    """The Table I loop with `n` elements (slip displacements over two decades), `k` and `fc`
    multiplied by `scale`."""
    from motionhyst import Loop, default_scenario

    loop = default_scenario().loop()
    u = np.geomspace(0.1, 10.0, n) * 2.5e-3
    k = np.full(n, 20.0 / n)
    return Loop(loop.plant, loop.controller,
                MaxwellSlip(k * scale, scale * k * u * 0.05 / np.sum(k * u)))


def test_many_elements_steady_state_equals_the_fixed_point_of_full_evaluations():
    """The steady state of 1000 elements (its last iteration a first-order update of the one
    before) equals the same fixed point run with every iteration computed in full, to
    1e-13 of the largest harmonic of the error."""
    from motionhyst import periodic_steady_state

    lp = _many_element_loop(1000)
    for A, f in ((0.01, 10.5), (0.003, 3.7)):
        ss = periodic_steady_state(lp, A, f)
        e, it = _fixed_point_in_full(lp, A, f)
        assert it == ss.iterations
        assert_allclose(ss.e, e, rtol=0, atol=1e-13 * np.max(np.abs(e)))


def test_a_weak_link_in_a_fresh_process_equals_the_fixed_point_of_full_evaluations():
    """A link so weak (stiffnesses and slip forces 1e-9 of Table I's) that its second
    iteration's y1 is within 1e-10 of the first's: in a fresh process (no grid kept from an
    earlier point) the first iteration, a sine's output computed to 1e-10 on a grid of its
    own, is never followed to first order; the point is the fixed point of full evaluations."""
    import subprocess
    import sys

    code = (
        "import json, numpy as np\n"
        "from motionhyst import periodic_steady_state\n"
        "from tests.test_maxwell import _many_element_loop\n"
        "ss = periodic_steady_state(_many_element_loop(400, 1e-9), 0.01, 10.5)\n"
        "print(json.dumps([ss.iterations, ss.e.real.tolist(), ss.e.imag.tolist()]))\n"
    )
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=root, timeout=600)
    assert out.returncode == 0, out.stderr
    iterations, re, im = json.loads(out.stdout.strip().splitlines()[-1])
    e, it = _fixed_point_in_full(_many_element_loop(400, 1e-9), 0.01, 10.5)
    assert iterations == it
    assert_allclose(np.array(re) + 1j * np.array(im), e, rtol=0, atol=1e-13 * np.max(np.abs(e)))


def test_a_sines_slip_onsets_in_closed_form_are_the_cubics():
    """For a sine the slip onsets are ``a + arccos(level / x_top)``, exact to round-off: the
    same pieces as the walk on the grid's cubic, whose onsets (one Newton step on the cell's
    cubic) put the sine within 3e-9 of its amplitude of the level (the output changes with
    the square of an onset's error)."""
    from motionhyst.hysteresis import _fft, _kernels

    X = np.array([0.0, 0.004 * np.exp(0.7j)])
    C1, C2 = 1j * np.arange(2) * X, -(np.arange(2) ** 2) * X
    ok, rev, xr = _kernels.dominant_reversals(X, C1, C2, True)
    assert ok
    top = 1 if xr[1] > xr[0] else 0
    k, fc = _many_elements()
    x = _fft.synthesize(X, 1024, stop_twiddles(1, 1))
    cubic = _kernels.half_cubic_pieces(x, rev[top], xr[top], k, fc)
    closed = _kernels.half_sine_pieces(rev[top], xr[top], k, fc)
    assert 0 < cubic[0].size - 1 < k.size  # some elements slip, some never do
    a = rev[top]
    level = xr[top] - 2 * fc / k  # where an element slips on the way down from +fc
    slips = level > -xr[top]
    assert_allclose(np.cos(closed[0][:-1] - a), level[slips] / xr[top], rtol=0, atol=1e-15)
    assert_allclose(np.cos(closed[0] - a), np.cos(cubic[0] - a), rtol=0, atol=3e-9)
    assert_array_equal(closed[1], cubic[1])
    assert_array_equal(closed[2], cubic[2])
    assert closed[4] == pytest.approx(cubic[4], rel=1e-8)  # the mean stiffness


@pytest.mark.parametrize("N", [64, 128, 256])
def test_binned_sums_of_opposite_mirrors_at_odd_harmonics(N):
    """Points with weights ``w`` and their opposites half a period on: the sums over the
    half grid equal the direct sums ``2 sum_b w_b exp(-j l t_b)`` at odd ``l`` (zero at even
    ``l``) to their round-off, and, with fewer terms, the binned sums of both points on
    the whole grid with as many terms."""
    from motionhyst.hysteresis import _jump_sums

    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.3, 0.3 + np.pi, 500))
    w = rng.standard_normal(500)
    L = 150
    tw = stop_twiddles(L, L)
    P = _jump_sums.chebyshev_terms(np.pi * L / N)
    table = _jump_sums.binned_table(N, P, L)
    tol = 1e-14 * np.sum(np.abs(w))  # the direct sums' round-off (phases up to 500 rad)
    q = np.arange(L + 1)
    direct = 2 * np.exp(-1j * np.outer(q, t)) @ w
    direct[::2] = 0.0
    assert_allclose(_jump_sums.jump_sums_binned_odd(t, w, L, N, P, table, tw), direct,
                    rtol=0, atol=tol)
    whole = _jump_sums.jump_sums_binned(t, w, -w, True, L, N, 9, table, tw)
    odd = _jump_sums.jump_sums_binned_odd(t, w, L, N, 9, table, tw)
    assert_allclose(odd[1::2], whole[1::2], rtol=0, atol=1e-15 * np.sum(np.abs(w)))
    assert_array_equal(odd[::2], 0.0)


@pytest.mark.parametrize("N", [64, 128, 256])
def test_binned_sums_at_even_harmonics_on_half_the_grid(N):
    """The points' sums at even ``l`` from the moments folded on half the grid equal the
    direct sums ``sum_b w_b exp(-j l t_b)`` (zero at odd ``l``), and the binned sums on the
    whole grid there."""
    from motionhyst.hysteresis import _jump_sums

    rng = np.random.default_rng(5)
    t = np.sort(rng.uniform(-0.2, 2 * np.pi - 0.2, 400))
    w = rng.standard_normal(400)
    L = 150
    tw = stop_twiddles(L, L)
    P = _jump_sums.chebyshev_terms(np.pi * L / N)
    table = _jump_sums.binned_table(N, P, L)
    bins = _jump_sums.chebyshev_moments(t, w, w, 0, N, P)
    even = _jump_sums.half_grid_sums(bins, 0, False, L, N, P, table, tw)
    q = np.arange(L + 1)
    direct = np.exp(-1j * np.outer(q, t)) @ w
    direct[1::2] = 0.0
    assert_allclose(even, direct, rtol=0, atol=1e-14 * np.sum(np.abs(w)))
    whole = _jump_sums.jump_sums_binned(t, w, w, False, L, N, P, table, tw)
    assert_allclose(even[::2], whole[::2], rtol=0, atol=1e-15 * np.sum(np.abs(w)))
    assert_array_equal(even[1::2], 0.0)


@pytest.mark.parametrize(("M", "n"), [(1, 1024), (131, 1024), (601, 4096)])
def test_samples_of_an_input_without_even_harmonics_in_half_the_transform(M, n):
    """The grid samples of a half-wave symmetric input (the cubic's, for the slip onsets)
    from half the transform equal those of the whole one to round-off."""
    from motionhyst.hysteresis import _fft

    rng = np.random.default_rng(M)
    X = (rng.standard_normal(M + 1) + 1j * rng.standard_normal(M + 1)) / (1 + np.arange(M + 1))
    X[0] = 0.0
    X[2::2] = 0.0
    tw = stop_twiddles(M, M)
    whole = _fft.synthesize(X, n, tw)
    half = _fft.synthesize_odd(X, n, tw)
    assert_allclose(half, whole, rtol=0, atol=4e-15 * np.sum(np.abs(X)))  # |x| <= 2 sum |X_m|
    assert_array_equal(half[n // 2:], -half[: n // 2])


@pytest.mark.parametrize("A", [0.003, 0.05, 0.5])
def test_a_sines_output_to_the_first_iterations_accuracy_from_the_stiffness_jumps_alone(A):
    """For the fixed point's first iteration (a sine, asked to 1e-10) the sums of the jumps
    of ``g`` come from those of ``s`` (``g`` jumps by ``-js x`` at a slip onset): the output
    equals the one computed in full to that accuracy, some elements slipping or all."""
    u = np.geomspace(1e-5, 0.02, 400)
    k = np.random.default_rng(3).uniform(0.5, 2.0, 400)
    fc = k * u
    H = 120
    X = np.array([0.0, A / 2j * np.exp(0.7j)])
    exact = stop_periodic_harmonics(X, k, fc, H)
    grid = np.zeros(2, dtype=np.int64)
    loose = stop_harmonics_base(X, k, fc, H, stop_twiddles(1, H), np.empty((0, 0)), grid, H,
                                1e-10)[0]
    assert grid[0] > 0  # binned
    assert_allclose(loose, exact, rtol=0, atol=1e-10 * A * np.sum(k))
    assert abs(exact[3]) > 1e-6 * abs(exact[1])  # the elements slip
