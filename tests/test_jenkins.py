"""Tests of the Jenkins (elasto-plastic) element, paper eqs. (3)-(11)."""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal
from scipy.integrate import quad

from motionhyst.hysteresis import Hysteresis
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function

# ---------------------------------------------------------------------------
# Independent reference: the exact periodic steady state for x = A sin(theta)
# ---------------------------------------------------------------------------


def steady_loop_pieces(k: float, fc: float, A: float):
    """Pieces ``(theta0, u_start, u_end, w(u))`` of the steady force, ``theta = theta0 + u``.

    Derived from the element's definition (spring in series with a slider) for
    ``x = A sin(theta)`` and ``zeta = fc / (k A) <= 1``, over one period
    ``theta in [pi/2, 5 pi/2]``:

    * at the maximum ``theta = pi/2`` the slider has just slipped: ``w = fc``;
    * descending stick: ``w = fc + k A (sin theta - 1) = fc - 2 k A sin^2(u/2)`` until it
      reaches ``-fc``, i.e. ``sin^2(u1/2) = zeta``, ``u1 = 2 asin(sqrt(zeta))``
      (``sin theta = 1 - 2 zeta``);
    * slip at ``-fc`` until the minimum ``theta = 3 pi/2``;
    * ascending stick: ``w = -fc + k A (sin theta + 1) = -fc + 2 k A sin^2(u/2)``, again for
      ``u < u1`` (``sin theta = 2 zeta - 1``);
    * slip at ``+fc`` until ``5 pi/2``.

    The half-angle form keeps every piece free of cancellation (``|w| <= fc``), so the
    Fourier integrals are accurate to round-off of ``fc`` even for tiny ``zeta``.
    """
    zeta = fc / (k * A)
    assert zeta <= 1.0
    u1 = 2.0 * math.asin(math.sqrt(zeta))
    return [
        (0.5 * math.pi, 0.0, u1, lambda u: fc - 2.0 * k * A * math.sin(0.5 * u) ** 2),
        (0.5 * math.pi, u1, math.pi, lambda u: -fc),
        (1.5 * math.pi, 0.0, u1, lambda u: -fc + 2.0 * k * A * math.sin(0.5 * u) ** 2),
        (1.5 * math.pi, u1, math.pi, lambda u: fc),
    ]


def steady_loop_force(k: float, fc: float, A: float, theta: np.ndarray) -> np.ndarray:
    """The piecewise steady force of :func:`steady_loop_pieces` at ``theta`` in [pi/2, 5 pi/2]."""
    out = np.full(theta.shape, np.nan)
    for theta0, lo, hi, fun in steady_loop_pieces(k, fc, A):
        u = theta - theta0
        sel = (u >= lo) & (u <= hi)
        out[sel] = [fun(v) for v in u[sel]]
    assert not np.any(np.isnan(out))
    return out


def reference_describing_function(k: float, fc: float, A: float) -> complex:
    """``(b1 + j a1) / A`` (eq. 7) of the exact steady force, each piece integrated by quad.

    With ``theta = theta0 + u``: ``sin(pi/2 + u) = cos u``, ``cos(pi/2 + u) = -sin u``,
    ``sin(3 pi/2 + u) = -cos u``, ``cos(3 pi/2 + u) = sin u``.
    """
    trig = {
        0.5 * math.pi: (math.cos, lambda u: -math.sin(u)),
        1.5 * math.pi: (lambda u: -math.cos(u), math.sin),
    }
    # far below the 1e-9 asserted: |D| >= k zeta on (0, 1], so |D| A pi >= pi fc
    opts = {"epsabs": 1e-12 * fc, "epsrel": 1e-13, "limit": 200}
    a1 = b1 = 0.0
    for theta0, lo, hi, fun in steady_loop_pieces(k, fc, A):
        if hi <= lo:
            continue
        sin_t, cos_t = trig[theta0]
        b1 += quad(lambda u, f=fun, g=sin_t: f(u) * g(u), lo, hi, **opts)[0]
        a1 += quad(lambda u, f=fun, g=cos_t: f(u) * g(u), lo, hi, **opts)[0]
    return complex(b1, a1) / (math.pi * A)


ZETAS = [1e-12, 1e-6, 1e-4, 1e-3, 0.01, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 0.999, 1 - 1e-9, 1.0]


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("zeta", ZETAS)
def test_describing_function_matches_exact_fourier_integral(zeta):
    k, A = 20.0, 0.01
    fc = zeta * k * A
    ref = reference_describing_function(k, fc, A)
    got = Jenkins(k=k, fc=fc).describing_function(A)
    assert abs(got - ref) <= 1e-9 * abs(ref)
    # the module-level function agrees with the method
    assert complex(jenkins_describing_function(k, zeta)) == pytest.approx(got, rel=1e-14)


@pytest.mark.parametrize("zeta", [0.1, 0.25, 0.5, 0.8, 1.0])
def test_response_matches_analytical_steady_loop(zeta):
    """The sampled exact update reproduces the analytical loop at every sample."""
    k, A = 20.0, 0.01
    fc = zeta * k * A
    theta = np.linspace(0.5 * np.pi, 2.5 * np.pi, 4001)  # contains the minimum 3 pi / 2
    w = Jenkins(k=k, fc=fc).response(A * np.sin(theta), w0=fc)
    assert_allclose(w, steady_loop_force(k, fc, A, theta), rtol=0, atol=1e-10 * k * A)


@pytest.mark.parametrize("zeta", [0.05, 0.25, 0.5, 0.7, 0.95])
def test_response_first_harmonic_from_rest(zeta):
    """Two periods from rest: the second one's first harmonic is the closed form."""
    k, A, n = 20.0, 0.01, 4096
    fc = zeta * k * A
    theta = np.arange(2 * n + 1) * (2 * np.pi / n)
    w = Jenkins(k=k, fc=fc).response(A * np.sin(theta), w0=0.0)
    th, wp = theta[n:-1], w[n:-1]
    b1 = 2.0 / n * np.sum(wp * np.sin(th))
    a1 = 2.0 / n * np.sum(wp * np.cos(th))
    D = Jenkins(k=k, fc=fc).describing_function(A)
    assert abs(complex(b1, a1) / A - D) <= 1e-5 * abs(D)


def test_loop_area_from_response_equals_dissipation(link):
    """Shoelace area of the sampled steady loop equals pi A^2 Im D (energy per cycle)."""
    A, n = 0.01, 20000
    theta = np.linspace(0.5 * np.pi, 2.5 * np.pi, n + 1)
    x = A * np.sin(theta)
    w = link.response(x, w0=link.fc)
    area = 0.5 * abs(np.sum(x[:-1] * w[1:] - x[1:] * w[:-1]))
    assert area == pytest.approx(np.pi * A**2 * link.describing_function(A).imag, rel=1e-6)


# ---------------------------------------------------------------------------
# Properties of the closed form
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("z0", [0.5, 1.0])
def test_describing_function_continuous_at_mode_boundaries(z0):
    lo, mid, hi = jenkins_describing_function(1.0, [z0 - 1e-7, z0, z0 + 1e-7])
    assert abs(hi - lo) <= 1e-6
    assert abs(mid - lo) <= 1e-6


def test_describing_function_continuous_where_series_takes_over():
    # the closed form switches to a series for small zeta; no visible seam
    z0 = 1e-3
    lo, hi = jenkins_describing_function(1.0, [z0 * (1 - 1e-12), z0 * (1 + 1e-12)])
    assert abs(hi - lo) <= 1e-11 * abs(hi)  # the slope alone gives 2e-12


def test_describing_function_at_one_is_k_and_above_exactly_k():
    k = 7.0
    D = jenkins_describing_function(k, [1.0, 1.0 + 1e-12, 2.0, 1e9, np.inf])
    assert_array_equal(D, np.full(5, k + 0j))
    el = Jenkins(k=k, fc=0.5)
    assert el.describing_function(el.slip_displacement) == k + 0j
    assert el.describing_function(0.5 * el.slip_displacement) == k + 0j


def test_describing_function_bounds_on_grid():
    zeta = np.linspace(0.0, 1.5, 3001)
    D = jenkins_describing_function(3.0, zeta)
    assert np.all(np.abs(D) <= 3.0 * (1 + 1e-12))
    assert np.all(D.imag >= 0)
    assert np.all(D.real >= 0)
    inside = (zeta > 0) & (zeta <= 1)
    assert np.all(np.abs(D[inside]) >= 3.0 * zeta[inside] * (1 - 1e-12))
    # |D| grows and the phase falls monotonically with zeta (paper Fig. 8)
    assert np.all(np.diff(np.abs(D)) >= -1e-12)
    assert np.all(np.diff(np.angle(D[1:])) <= 1e-12)


@pytest.mark.parametrize("zeta", [1e-4, 1e-6, 1e-8])
def test_small_zeta_limit_eq11(zeta):
    k = 20.0
    D = complex(jenkins_describing_function(k, zeta))
    ratio = D / (4.0 / np.pi * k * zeta * 1j)
    # D = (4/pi) k zeta (1 - zeta) j + (16 / (3 pi)) k zeta^(3/2) + ...
    assert abs(ratio - 1) <= 2.0 * np.sqrt(zeta)
    assert ratio.real == pytest.approx(1.0 - zeta, rel=1e-12)
    assert ratio.imag == pytest.approx(-4.0 / 3.0 * np.sqrt(zeta), rel=1e-3)


def test_no_nan_or_warning_at_extremes():
    el = Jenkins(k=20.0, fc=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d0 = el.describing_function(0.0)
        d_huge = el.describing_function(1e300)
        dz = jenkins_describing_function(20.0, [0.0, 1.0])
        z0 = el.zeta(0.0)
    assert d0 == 20.0 + 0j
    assert z0 == np.inf
    assert d_huge.imag == pytest.approx(4 / np.pi * 20.0 * el.zeta(1e300), rel=1e-12)
    assert 0.0 <= d_huge.real <= 1e-12 * d_huge.imag
    assert_array_equal(dz, [0.0, 20.0])


def test_table1_describing_function(link):
    A = 0.01
    assert link.zeta(A) == pytest.approx(0.25, rel=1e-15)
    D = link.describing_function(A)
    assert abs(abs(D) / link.k - 0.309) < 5e-4
    assert abs(np.degrees(np.angle(D)) - 50.7) < 0.05


def test_describing_function_vectorised_and_omega_ignored(link):
    A = np.array([0.0, 0.001, 0.01, 0.1])
    D = link.describing_function(A)
    assert D.shape == (4,)
    assert_array_equal(D, [link.describing_function(a) for a in A])
    Dw = link.describing_function(0.01, omega=np.array([1.0, 10.0, 100.0]))
    assert_array_equal(Dw, np.full(3, link.describing_function(0.01)))


# ---------------------------------------------------------------------------
# python-control interoperability
# ---------------------------------------------------------------------------


def test_is_python_control_nonlinearity(link):
    # python-control's describing-function tools look its nonlinearity interface up by name;
    # the models implement it without deriving from control.DescribingFunctionNonlinearity,
    # so that importing them does not import python-control (the tests below use it)
    assert isinstance(link, Hysteresis)
    for name in ("describing_function", "__call__", "_isstatic"):
        assert callable(getattr(link, name))
    assert link._isstatic() is False
    link.reset(0.01)
    assert link(0.0) == 0.01
    assert link(1.0) == 0.05  # saturates at fc


def test_control_describing_function_uses_closed_form(link):
    A = np.array([0.001, 0.01, 0.1])
    got = control.describing_function(link, A)
    assert_allclose(got, link.describing_function(A), rtol=1e-14)
    assert complex(control.describing_function(link, 0.01)) == link.describing_function(0.01)


@pytest.mark.parametrize("A", [0.003, 0.01, 0.05])
def test_control_numerical_describing_function(A):
    el = Jenkins(k=20.0, fc=0.05)
    num = np.ravel(control.describing_function(el, A, num_points=4000, try_method=False))[0]
    assert abs(num - el.describing_function(A)) <= 1e-3 * abs(el.describing_function(A))


def test_control_describing_function_response_runs(link):
    H = control.tf([8.0], [1, 3, 3, 1])  # 8 / (s + 1)^3, stable, phase to -270 deg
    amps = np.geomspace(1e-3, 10.0, 60)
    resp = control.describing_function_response(H, link, amps, warn_nyquist=False)
    assert_allclose(resp.N_vals, -1.0 / link.describing_function(amps), rtol=1e-14)
    # -1/D runs through the second quadrant, where H passes: one predicted limit cycle,
    # at which H(j omega) D(A) = -1
    assert len(resp.intersections) == 1
    a, omega = resp.intersections[0]
    assert 1e-3 < a < 10.0
    assert abs(1.0 + complex(H(1j * omega)) * link.describing_function(a)) < 1e-4


# ---------------------------------------------------------------------------
# Differential form, eq. (3)
# ---------------------------------------------------------------------------


def test_ode_rhs_modes():
    el = Jenkins(k=20.0, fc=0.05)
    assert el.ode_rhs(0.0, 0.3) == pytest.approx(20.0 * 0.3)
    assert el.ode_rhs(0.02, -0.3) == pytest.approx(-20.0 * 0.3)
    assert el.ode_rhs(-0.049, 0.1) == pytest.approx(2.0)
    # slipping: no change while pushed further
    assert el.ode_rhs(0.05, 0.3) == 0.0
    assert el.ode_rhs(-0.05, -0.3) == 0.0
    # reversal at the slip force: back to the spring
    assert el.ode_rhs(0.05, -0.3) == pytest.approx(-20.0 * 0.3)
    assert el.ode_rhs(-0.05, 0.3) == pytest.approx(20.0 * 0.3)
    assert_allclose(el.ode_rhs([0.0, 0.05, 0.05], [1.0, 1.0, -1.0]), [20.0, 0.0, -20.0])


def test_ode_euler_tracks_exact_response():
    """Explicit Euler on eq. (3) chatters around +-fc but stays within k |xdot| dt of exact."""
    el = Jenkins(k=20.0, fc=0.05)
    A, omega, dt = 0.01, 2 * np.pi, 2e-5
    t = np.arange(int(1.25 / dt) + 1) * dt  # from rest: slip up, down and up again
    x = A * np.sin(omega * t)
    xdot = A * omega * np.cos(omega * t)
    w = np.empty_like(t)
    w[0] = 0.0
    for i in range(t.size - 1):
        w[i + 1] = w[i] + dt * float(el.ode_rhs(w[i], xdot[i]))
    exact = el.response(x, w0=0.0)
    assert np.max(np.abs(w - exact)) <= 3 * el.k * A * omega * dt


# ---------------------------------------------------------------------------
# Validation
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("k", "fc"),
    [(0.0, 1.0), (-1.0, 1.0), (np.nan, 1.0), (np.inf, 1.0), (1.0, 0.0), (1.0, -0.1),
     (1.0, np.nan), ("abc", 1.0)],
)
def test_invalid_parameters(k, fc):
    with pytest.raises(ValueError):
        Jenkins(k=k, fc=fc)


@pytest.mark.parametrize("A", [-0.01, [0.01, -1e-9], np.nan, np.inf])
def test_invalid_amplitude(link, A):
    with pytest.raises(ValueError, match="amplitude"):
        link.describing_function(A)
    with pytest.raises(ValueError, match="amplitude"):
        link.zeta(A)


def test_response_rejects_bad_input(link):
    with pytest.raises(ValueError, match="w0"):
        link.response([0.0, 0.01], w0=0.06)
    with pytest.raises(ValueError, match="finite"):
        link.response([0.0, np.nan])
    with pytest.raises(ValueError, match="one-dimensional"):
        link.response(np.zeros((2, 2)))


def test_response_rejects_nan_initial_force(link):
    with pytest.raises(ValueError):
        link.response([0.0, 0.01], w0=np.nan)


def test_no_warning_for_subnormal_amplitude(link):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert link.describing_function(1e-320) == link.k + 0j


def test_call_interface_steps_state():
    el = Jenkins(k=10.0, fc=1.0)
    el.reset()
    assert el(0.0) == 0.0
    assert el(0.05) == pytest.approx(0.5)
    assert el(0.5) == 1.0  # slipped
    assert el(0.4) == pytest.approx(0.0)  # stick on the way back
    el.reset(0.3)
    assert el(2.0) == pytest.approx(0.3)  # first sample only sets the input
    assert el.to_dict() == {"model": "jenkins", "k": 10.0, "fc": 1.0}


# ---------------------------------------------------------------------------
# Property tests
# ---------------------------------------------------------------------------

positive = st.floats(min_value=1e-3, max_value=1e4, allow_nan=False, allow_infinity=False)


@settings(max_examples=150, deadline=None)
@given(k=positive, fc=positive, A=st.just(0.0) | st.floats(min_value=1e-12, max_value=1e4))
def test_property_describing_function_bounds(k, fc, A):
    D = Jenkins(k=k, fc=fc).describing_function(A)
    assert np.isfinite(D)
    assert abs(D) <= k * (1 + 1e-12)
    assert D.imag >= 0
    assert D.real >= 0


@settings(max_examples=150, deadline=None)
@given(k=positive, fc=positive, A=positive)
def test_property_dissipated_energy_is_loop_area(k, fc, A):
    """pi A^2 Im D = area of the steady loop (a parallelogram for zeta < 1, else a line)."""
    D = Jenkins(k=k, fc=fc).describing_function(A)
    d = 2 * fc / k  # width of the stick branches
    if d < 2 * A:
        # vertices (x, w) of the loop: corners at the extremes and where stick ends
        verts = np.array([[A, fc], [A - d, -fc], [-A, -fc], [-A + d, fc]])
        xs, ws = verts[:, 0], verts[:, 1]
        area = 0.5 * abs(np.dot(xs, np.roll(ws, -1)) - np.dot(ws, np.roll(xs, -1)))
    else:
        area = 0.0
    assert np.pi * A**2 * D.imag == pytest.approx(area, rel=1e-9, abs=1e-12 * fc * A)


@settings(max_examples=100, deadline=None)
@given(
    k=positive,
    fc=positive,
    steps=st.lists(st.floats(min_value=-3.0, max_value=3.0), min_size=0, max_size=60),
    offset=st.floats(min_value=-1e3, max_value=1e3),
    frac=st.floats(min_value=-1.0, max_value=1.0),
)
def test_property_response_bounded_and_rate_independent(k, fc, steps, offset, frac):
    """Steps of up to 3 slip displacements fc / k mix stick and slip."""
    el = Jenkins(k=k, fc=fc)
    x = offset + fc / k * np.concatenate([[0.0], np.cumsum(steps)])
    w = el.response(x, w0=frac * fc)
    assert w[0] == frac * fc
    assert np.all(np.abs(w) <= fc)
    # inserting midpoints (monotone between samples) does not change the output
    xm = np.empty(2 * x.size - 1)
    xm[0::2] = x
    xm[1::2] = 0.5 * (x[:-1] + x[1:])
    wm = el.response(xm, w0=frac * fc)
    # to round-off: of the force, and of displacement differences times the stiffness
    assert_allclose(wm[0::2], w, rtol=0, atol=1e-12 * (fc + k * np.max(np.abs(x))))
    # in stick (no clipping on the way) the force is the spring law exactly
    stick = np.all(np.abs(frac * fc + k * (x - x[0])) < fc)
    if stick:
        assert_allclose(w, frac * fc + k * (x - x[0]), rtol=0,
                        atol=1e-12 * (fc + k * np.max(np.abs(x))))
