"""Bouc-Wen, Dahl and LuGre elements against references that share no code with the package.

The describing functions of :class:`~motionhyst.hysteresis.BoucWen`,
:class:`~motionhyst.hysteresis.Dahl` and :class:`~motionhyst.hysteresis.LuGre`
are computed numerically from the periodic response.  They are checked here
against

* the model ODEs, written out from their defining equations (Bouc-Wen in the
  classical form of Ismail et al. 2009, eq. 1), integrated in time with
  :func:`scipy.integrate.solve_ivp` together with the Fourier projections of
  the force on ``sin(n w t)`` and ``cos(n w t)`` over one period of the
  periodic solution (:func:`ode_harmonics`);
* closed forms derived below (the loop areas of Dahl with ``alpha = 1`` and of
  Bouc-Wen with ``beta = gamma = 1/2``, the Jenkins element of paper eq. 10)
  and exact identities between the models (LuGre without damping and Stribeck
  effect is Dahl; the viscous term adds ``j w sigma2``);
* the loop area and the FFT of the sampled steady response of :meth:`response`.

Tolerances
----------
The package states "about 1e-10" relative accuracy for its numerical ``D``
(and for Bouc-Wen's RK4 path).  The ODE reference (DOP853, ``rtol = 1e-11``,
``atol = 1e-15`` of the scales) agrees with itself at ``rtol = 1e-12`` to
3e-13 of ``|H_1|`` and moves by at most 3e-11 when ``rtol`` is relaxed to
1e-9, so it adds nothing visible: model and reference are asserted to agree
to ``RTOL_DF = 3e-10`` of ``|H_1|`` (3x the stated accuracy; measured
<= 1.2e-12 for every case here, 9e-11 for the closed form at ``k A / fc = 15``).
Identities that hold exactly in the equations (LuGre/Dahl) use the same
tolerance.  Checks on sampled responses have a discretisation error of known
order in the step ``h`` (trapezoid rule: ``h^2``; LuGre's sampled force, which
takes the rates over the interval ending at each sample: ``h``); the test
asserts that order, removes the leading error by Richardson extrapolation and
bounds the remainder a few times above its measured size, orders of magnitude
below the unextrapolated error.  Limit tests assert the convergence orders and
bounds derived from the equations in their docstrings.
"""

from __future__ import annotations

import math
import re
import tomllib
from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import digamma

from motionhyst.hysteresis import BoucWen, Dahl, Jenkins, LuGre
from motionhyst.scenario import (
    Scenario,
    ScenarioError,
    default_scenario_path,
    hysteresis_from_dict,
)

TWO_PI = 2.0 * np.pi
K, FC = 20.0, 0.05  # the dynamic link of Table I: k = 20 N/m, fc = 0.05 N
RTOL_DF = 3e-10  # 3x the stated accuracy (about 1e-10) of the numerical describing functions

# ---------------------------------------------------------------------------
# Independent reference: the model ODEs integrated in time with solve_ivp
# ---------------------------------------------------------------------------


def bouc_wen_rate(k, fc, n, beta, gamma, A, omega):
    """Classical Bouc-Wen ``z' = a v - b |v| |z|^(n-1) z - c v |z|^n``, ``w = fc z``.

    Ismail et al. (2009), eq. 1, with ``a = k / fc``, ``b = beta k / fc`` and
    ``c = gamma k / fc`` (the normalisation stated in the class docstring).
    """
    a, b, c = k / fc, beta * k / fc, gamma * k / fc

    def rate(t, z):
        v = A * omega * math.cos(omega * t)
        return a * v - b * abs(v) * abs(z) ** (n - 1) * z - c * v * abs(z) ** n, fc * z

    return rate


def dahl_rate(k, fc, alpha, A, omega):
    """Dahl (1968): ``w' = k (1 - sign(v) w / fc)^alpha v``."""

    def rate(t, w):
        v = A * omega * math.cos(omega * t)
        return k * max(1.0 - math.copysign(1.0, v) * w / fc, 0.0) ** alpha * v, w

    return rate


def lugre_rate(sigma0, sigma1, sigma2, fc, fs, vs, A, omega):
    """LuGre (Canudas de Wit et al. 1995): ``z' = v - sigma0 |v| z / g(v)``,
    ``w = sigma0 z + sigma1 z' + sigma2 v``, ``g(v) = fc + (fs - fc) exp(-(v / vs)^2)``."""

    def rate(t, z):
        v = A * omega * math.cos(omega * t)
        g = fc + (fs - fc) * math.exp(-((v / vs) ** 2))
        dz = v - sigma0 * abs(v) * z / g
        return dz, sigma0 * z + sigma1 * dz + sigma2 * v

    return rate


def ode_harmonics(rate, A, omega, n_max, s_scale, w_scale, rtol=1e-11):
    """``H_n = (b_n + j a_n) / A``, n = 1 .. n_max, of the periodic force for ``x = A sin(w t)``.

    ``rate(t, s)`` returns the state derivative and the force.  The state and
    the projections ``b_n = (1/pi) int w sin(n theta)``, ``a_n = (1/pi) int w
    cos(n theta)`` are integrated together by DOP853, in half periods between
    the reversals of ``x`` (where ``|v|`` has a kink), each split where the
    state crosses zero (where Bouc-Wen's ``|z|^n`` has a kink).  The elements are odd,
    so the periodic state at the maximum of ``x`` satisfies ``P(s) = -s`` for
    the half-period map ``P``; it is found by secant steps and then checked
    over a full period.
    """
    T = TWO_PI / omega
    n = np.arange(1, n_max + 1)

    def rhs(t, y):
        ds, w = rate(t, y[0])
        out = np.empty(1 + 2 * n_max)
        out[0] = ds
        q = (omega / np.pi) * w
        out[1:n_max + 1] = q * np.sin(n * omega * t)
        out[n_max + 1:] = q * np.cos(n * omega * t)
        return out

    atol = np.full(1 + 2 * n_max, 1e-15 * w_scale)
    atol[0] = 1e-15 * s_scale

    def crossing(t, y):
        return y[0]

    crossing.terminal = True

    def run(t0, t1, s0):
        y0 = np.zeros(1 + 2 * n_max)
        y0[0] = s0
        opts = dict(method="DOP853", rtol=rtol, atol=atol)
        sol = solve_ivp(rhs, (t0, t1), y0, events=crossing, **opts)
        if sol.status == 1:  # stopped at s = 0, a kink of |s|; s is monotone in a half period
            sol = solve_ivp(rhs, (sol.t_events[0][0], t1), sol.y_events[0][0], **opts)
        assert sol.success, sol.message
        return sol.y[:, -1]

    t0 = T / 4  # first maximum of x
    s_prev = run(0.0, t0, 0.0)[0]  # from the virgin state at x = 0
    f_prev = run(t0, t0 + T / 2, s_prev)[0] + s_prev
    s = s_prev - f_prev  # one step of s <- -P(s)
    for _ in range(30):
        y1 = run(t0, t0 + T / 2, s)
        f = y1[0] + s
        if abs(f) <= 1e-12 * s_scale or f == f_prev:
            break
        s, s_prev, f_prev = s - f * (s - s_prev) / (f - f_prev), s, f
    y2 = run(t0 + T / 2, t0 + T, y1[0])
    assert abs(y2[0] - s) <= 1e-12 * s_scale, "reference not periodic"
    q = y1[1:] + y2[1:]
    return (q[:n_max] + 1j * q[n_max:]) / A


# name: (model class, parameters, amplitude [m], angular frequency [rad/s])
CASES = {
    "bouc-wen-n1": (BoucWen, dict(k=K, fc=FC, n=1.0, beta=0.8, gamma=0.2), 5e-3, TWO_PI * 5),
    "bouc-wen-n2": (BoucWen, dict(k=K, fc=FC, n=2.0, beta=0.7, gamma=0.3), 5e-3, TWO_PI * 5),
    "bouc-wen-n2-gamma<0": (BoucWen, dict(k=K, fc=FC, n=2.0, beta=0.5, gamma=-0.2), 5e-3,
                            TWO_PI * 5),
    "dahl-alpha1": (Dahl, dict(k=K, fc=FC, alpha=1.0), 5e-3, TWO_PI * 5),
    "dahl-alpha2": (Dahl, dict(k=K, fc=FC, alpha=2.0), 5e-3, TWO_PI * 5),
    # peak speed A w = 3.1 vs and 1.6 vs: the Stribeck dip is crossed every half period
    "lugre": (LuGre, dict(sigma0=20.0, sigma1=0.1, sigma2=0.05, fc=FC, fs=0.08, vs=0.02),
              5e-3, TWO_PI * 2),
    "lugre-b": (LuGre, dict(sigma0=20.0, sigma1=0.02, sigma2=0.05, fc=FC, fs=0.07, vs=0.1),
                5e-3, TWO_PI * 5),
}
RATE_INDEPENDENT = [name for name, case in CASES.items() if case[0] is not LuGre]
N_HARMONICS = 5


def make(name):
    cls, params, A, omega = CASES[name]
    return cls(**params), A, (omega if cls is LuGre else None)


@cache
def reference(name):
    """ODE reference ``H_1 .. H_5`` of a case (cached: shared by several tests)."""
    cls, p, A, omega = CASES[name]
    if cls is BoucWen:
        rate = bouc_wen_rate(p["k"], p["fc"], p["n"], p["beta"], p["gamma"], A, omega)
        s_scale, w_scale = 1.0, p["fc"]
    elif cls is Dahl:
        rate = dahl_rate(p["k"], p["fc"], p["alpha"], A, omega)
        s_scale = w_scale = p["fc"]
    else:
        rate = lugre_rate(*(p[key] for key in ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs")),
                          A, omega)
        w_scale = max(p["fc"], p["fs"])
        s_scale = w_scale / p["sigma0"]
    return ode_harmonics(rate, A, omega, N_HARMONICS, s_scale, w_scale)


@pytest.mark.parametrize("name", list(CASES))
def test_describing_function_matches_ode_reference(name):
    el, A, omega = make(name)
    ref = reference(name)
    D = el.describing_function(A, omega)
    assert isinstance(D, complex)
    assert abs(D - ref[0]) <= RTOL_DF * abs(ref[0]), (D, ref[0])
    assert D.imag > 0.1 * abs(D)  # a genuinely hysteretic operating point


@pytest.mark.parametrize("name", RATE_INDEPENDENT)
def test_rate_independent_df_does_not_depend_on_omega(name):
    el, A, _ = make(name)
    D = el.describing_function(A)
    Dw = el.describing_function(A, omega=np.array([0.1, 10.0, 1e4]))
    assert Dw.shape == (3,)
    np.testing.assert_array_equal(Dw, D)


@pytest.mark.parametrize("name", list(CASES))
def test_hosidf_matches_ode_reference(name):
    """``H_n`` relative to ``sin(n w t)`` (base.hosidf docstring): ``H_n = (b_n + j a_n) / A``."""
    el, A, omega = make(name)
    ref = reference(name)
    H = el.hosidf(A, N_HARMONICS, omega)
    assert H.shape == (N_HARMONICS,)
    scale = abs(ref[0])
    # odd elements: the reference's even harmonics vanish to its own accuracy
    assert np.all(np.abs(ref[1::2]) <= 1e-10 * scale), ref
    assert np.all(np.abs(ref[2::2]) >= 1e-3 * scale)  # odd ones are really there
    np.testing.assert_allclose(H, ref, rtol=0, atol=RTOL_DF * scale)


# ---------------------------------------------------------------------------
# The steady sampled response: loop area (energy) and FFT (HOSIDF)
# ---------------------------------------------------------------------------


def steady_period(el, A, N, omega=None, periods=6):
    """``x``, ``w`` over the last of `periods` periods of ``x = A sin(theta)``, N samples each.

    ``N`` is a multiple of 4 so the reversals are samples; the closed period has N + 1 points.
    """
    theta = TWO_PI * np.arange(periods * N + 1) / N
    x = A * np.sin(theta)
    w = el.response(x) if omega is None else el.response(x, t=theta / omega)
    x, w = x[-N - 1:], w[-N - 1:]
    assert abs(w[-1] - w[0]) <= 1e-11 * np.max(np.abs(w)), "response not yet periodic"
    return x, w


def loop_area(x, w):
    """``oint w dx`` by the trapezoid rule (the shoelace formula of the closed polygon)."""
    return float(np.sum(0.5 * (w[1:] + w[:-1]) * np.diff(x)))


def fft_hosidf(w, A, n_max):
    """``H_n = (b_n + j a_n) / A`` from the FFT.

    ``c_n = (a_n - j b_n) / 2`` for ``w = sum a_n cos(n theta) + b_n sin(n theta)``,
    so ``b_n + j a_n = 2j c_n``.
    """
    c = np.fft.rfft(w[:-1]) / (w.size - 1)
    return 2j * c[1:n_max + 1] / A


def richardson(coarse, fine, order):
    """Limit of a quantity with error ``~ h^order`` from the step ``h`` and ``h / 2``."""
    return fine + (fine - coarse) / (2.0**order - 1.0)


# The trapezoid rule on the piecewise smooth loop has error ~ h^2 (measured 1.6e-6 and 3.9e-7
# of the area at N = 2048 and 4096); LuGre's sampled force takes z' and v over the interval
# ending at each sample, an error ~ h (measured 4.7e-5 at N = 4096, 2.3e-5 at 8192).  After
# extrapolation the remainder measured <= 6e-11 (rate-independent) and 2.5e-7 (LuGre, ~ h^2).
AREA_CASES = {name: (2048, 2, 3e-10) for name in RATE_INDEPENDENT}
AREA_CASES.update({"lugre": (4096, 1, 1e-6), "lugre-b": (4096, 1, 1e-6)})


@pytest.mark.parametrize("name", list(AREA_CASES))
def test_loop_area_is_pi_A2_imag_D(name):
    """Energy per cycle: ``oint w dx = int w A cos(theta) dtheta = pi A a_1 = pi A^2 Im D``."""
    el, A, omega = make(name)
    N, order, rtol = AREA_CASES[name]
    coarse = loop_area(*steady_period(el, A, N, omega))
    fine = loop_area(*steady_period(el, A, 2 * N, omega))
    energy = np.pi * A**2 * el.describing_function(A, omega).imag
    # the plain estimate converges at (at least) its order: the error quarters (trapezoid) or
    # halves (LuGre's sampled rates); a wrong Im D would leave a constant error instead
    ratio = (fine - energy) / (coarse - energy)
    assert 0 < ratio < 1.2 / 2**order, ratio
    assert abs(richardson(coarse, fine, order) - energy) <= rtol * energy


# HOSIDF from the FFT of the sampled response.  Rate-independent elements: the force is exact at
# the samples and the FFT's aliasing error falls as N^-3 (w' is continuous, w'' jumps at the
# reversals), so at N = 4096 the stated accuracy applies (measured: 3e-14 of |H_1|).  LuGre:
# first order in h as above (measured 6e-5 of |H_1| at N = 8192); after extrapolation the
# remainder measured <= 3.5e-8 of |H_1|.
@pytest.mark.parametrize("name", list(CASES))
def test_hosidf_matches_fft_of_steady_response(name):
    el, A, omega = make(name)
    H = el.hosidf(A, 6, omega)
    scale = abs(H[0])
    if omega is None:
        Hf = fft_hosidf(steady_period(el, A, 4096)[1], A, 6)
        atol = RTOL_DF * scale
    else:
        coarse = fft_hosidf(steady_period(el, A, 4096, omega)[1], A, 6)
        fine = fft_hosidf(steady_period(el, A, 8192, omega)[1], A, 6)
        Hf = richardson(coarse, fine, 1)
        atol = 2e-7 * scale
    np.testing.assert_allclose(Hf, H, rtol=0, atol=atol)
    # symmetric (odd) elements: no even harmonics, in the response or in hosidf
    assert np.all(np.abs(Hf[1::2]) <= 1e-10 * scale), Hf
    assert np.all(np.abs(H[1::2]) <= 1e-10 * scale), H
    assert np.all(np.abs(H[::2]) >= 1e-3 * scale)


def test_closed_loop_area_of_dahl_alpha_1():
    """Dahl, ``alpha = 1``, ``zeta = w / fc``, ``u = k x / fc``, ``r = k A / fc``.

    On the rising branch ``1 - zeta = (1 + zeta_m) exp(-u)`` over ``u in [0, 2r]``;
    periodicity gives ``zeta_m = tanh r``, and the loop area is
    ``2 int_0^2r zeta du = 4 (r - tanh r)`` (in ``fc^2 / k``), so
    ``Im D = (4 fc / (pi A)) (1 - tanh(r) / r)``.
    """
    el = Dahl(K, FC)
    r = np.array([0.05, 1.0, 2.0, 100.0, 1e4])
    A = r * FC / K
    expected = 4 * FC / (np.pi * A) * (1 - np.tanh(r) / r)
    np.testing.assert_allclose(el.describing_function(A).imag, expected, rtol=RTOL_DF)


# ---------------------------------------------------------------------------
# Limits and exact identities
# ---------------------------------------------------------------------------


def bouc_wen_corner_area(n):
    """``S_n = int_0^1 (1 - s) s^n / (1 - s^n) ds = sum_k 1 / ((nk + 1)(nk + 2))``.

    The area between the rising branches of Jenkins and of Bouc-Wen with
    ``beta = gamma = 1/2`` in the ``(u, z)`` plane: both are ``z = -1 + u``
    for ``z < 0`` (unloading stiffness ``k``); for ``z > 0`` Bouc-Wen needs
    ``u(z) = int_0^z ds / (1 - s^n)``, i.e. ``int_0^z s^n / (1 - s^n) ds``
    more than Jenkins.  In closed form ``(psi(1 + 2/n) - psi(1 + 1/n)) / n``,
    ``~ pi^2 / (6 n^2)``.
    """
    return (digamma(1 + 2 / n) - digamma(1 + 1 / n)) / n


@pytest.mark.parametrize("n", [1.0, 2.0, 5.0, 20.0])
def test_bouc_wen_half_half_dissipation_closed_form(n):
    """``beta = gamma = 1/2``: the loop is the Jenkins parallelogram (area ``4 (r - 1)``,
    in ``fc^2 / k``) less ``S_n`` at each of its two slipping corners, once the branch
    saturates (``r = 15``: the unsaturated remainder is below ``exp(-n (2 r - 1)) < 1e-12``).
    ``2 S_n`` is 1.8% of the area for ``n = 1`` and 1.3e-4 for ``n = 20``."""
    r = 15.0
    A = r * FC / K
    expected = (FC**2 / K) * (4 * (r - 1) - 2 * bouc_wen_corner_area(n)) / (np.pi * A**2)
    D = BoucWen(K, FC, n=n).describing_function(A)
    assert abs(D.imag - expected) <= RTOL_DF * abs(D)


@pytest.mark.parametrize("r", [2.0, 4.0])
def test_bouc_wen_tends_to_jenkins_as_n_grows(r):
    """``beta = gamma = 1/2``, ``n -> inf``: Jenkins with the same ``k``, ``fc``.

    The loops differ only at the two corners, by ``S_n ~ pi^2 / (6 n^2)``
    (:func:`bouc_wen_corner_area`) each, so ``|D_BW - D_J| ~ 2 S_n fc^2 /
    (pi k A^2) = pi k / (3 n^2 r^2)`` per component: error ``O(n^-2)``.
    """
    A = r * FC / K
    DJ = Jenkins(K, FC).describing_function(A)
    ns = [1, 2, 5, 10, 20, 40]
    err = np.array([abs(BoucWen(K, FC, n=float(n)).describing_function(A) - DJ) for n in ns])
    assert np.all(np.diff(err) < 0), err
    assert 3.4 < err[-2] / err[-1] < 4.2, err  # n = 20 -> 40: second order
    bound = 2 * np.pi * K / (3 * 20**2 * r**2)  # both components at their estimate
    assert err[-2] <= bound, (err[-2], bound)
    assert err[-2] <= 2e-3 * abs(DJ)


LUGRE_GRID = [(1e-4, 0.5), (2e-3, TWO_PI * 10), (1e-2, TWO_PI * 200)]


@pytest.mark.parametrize(("A", "omega"), LUGRE_GRID)
def test_lugre_without_damping_and_stribeck_is_dahl(A, omega):
    """``sigma1 = sigma2 = 0``, ``fs = fc``: ``w = sigma0 z``,
    ``w' = sigma0 v (1 - sign(v) w / fc)``, i.e. Dahl with ``k = sigma0``, ``alpha = 1``
    (Dahl: ``dw/dx = k (1 - sign(dx) w / fc)^alpha``), at every frequency."""
    lugre = LuGre(sigma0=K, sigma1=0.0, sigma2=0.0, fc=FC, fs=FC, vs=0.01)
    Dd = Dahl(k=K, fc=FC, alpha=1.0).describing_function(A)
    assert abs(lugre.describing_function(A, omega) - Dd) <= RTOL_DF * abs(Dd)


@pytest.mark.parametrize(("A", "omega"), LUGRE_GRID)
def test_lugre_with_constant_friction_level_is_damped_dahl(A, omega):
    """``fs = fc``: ``g`` is constant, so ``z(theta)`` does not depend on ``omega`` and
    ``sigma0 z`` is the Dahl force; ``sigma1 z' = j omega (sigma1 / sigma0)`` times it in the
    first harmonic and ``sigma2 v`` adds ``j omega sigma2``:
    ``D = (1 + j omega sigma1 / sigma0) D_Dahl + j omega sigma2``."""
    s0, s1, s2 = K, 0.1, 0.05
    lugre = LuGre(sigma0=s0, sigma1=s1, sigma2=s2, fc=FC, fs=FC, vs=0.01)
    Dd = Dahl(k=s0, fc=FC).describing_function(A)
    expected = (1 + 1j * omega * s1 / s0) * Dd + 1j * omega * s2
    assert abs(lugre.describing_function(A, omega) - expected) <= RTOL_DF * abs(expected)


def test_lugre_low_frequency_limit():
    """``omega -> 0``: every speed ``|v| <= A omega << vs``, so ``g(v) -> fs`` and the
    ``sigma1 z'``, ``sigma2 v`` terms vanish: the limit is Dahl with ``k = sigma0``,
    ``fc = fs``, ``alpha = 1`` (exactly at ``omega = 0``).  ``z`` depends on ``omega`` only
    through ``g(omega x') = fs - (fs - fc) (omega x' / vs)^2 + ...``, so
    ``D = (1 + j omega sigma1 / sigma0) D_Dahl + j omega sigma2 + O(omega^2)``."""
    s0, s1, s2, fs = K, 0.1, 0.05, 0.08
    lugre = LuGre(sigma0=s0, sigma1=s1, sigma2=s2, fc=FC, fs=fs, vs=0.02)
    A = 5e-3
    Dd = Dahl(k=s0, fc=fs, alpha=1.0).describing_function(A)
    assert abs(lugre.describing_function(A, 0.0) - Dd) <= RTOL_DF * abs(Dd)
    omegas = np.array([0.1, 0.01])
    D = lugre.describing_function(A, omegas)
    first = 1j * omegas * (s1 / s0 * Dd + s2)  # the damping terms, first order in omega
    rest = np.abs(D - Dd - first)  # the Stribeck remainder: second order
    assert np.all(rest <= 0.2 * np.abs(first)) and rest[1] <= 0.02 * abs(first[1]), rest
    assert np.all(rest >= 1e-4 * np.abs(first))  # well above the numerical accuracy
    assert 99.0 < rest[0] / rest[1] < 101.0, rest


@pytest.mark.parametrize(("A", "omega"), [*LUGRE_GRID, (5e-3, TWO_PI * 2)])
def test_lugre_viscous_term_adds_j_omega_sigma2(A, omega):
    """``sigma2 v`` is linear in the velocity and does not enter ``z``: it adds exactly
    ``j omega sigma2`` to ``D`` at every amplitude (with damping and Stribeck effect)."""
    p = dict(sigma0=K, sigma1=0.1, fc=FC, fs=0.08, vs=0.02)
    with_viscous = LuGre(sigma2=0.05, **p).describing_function(A, omega)
    without = LuGre(sigma2=0.0, **p).describing_function(A, omega)
    assert abs(with_viscous - without - 1j * omega * 0.05) <= 1e-10 * abs(with_viscous)


def _smallest_fixed_point(f):
    """Smallest fixed point of an increasing map with ``f(0) > 0``, by iteration from 0."""
    p = 0.0
    for _ in range(200):
        p = f(p)
    return p


def small_motion_bound(cls, p, r):
    """``(delta, order)``: relative stiffness spread on the loop at ``r = k A / fc``, and the
    order in ``r`` of ``D - k``.

    With ``rho = max|w| / fc`` the rising branch climbs ``2 rho`` over ``2 r`` (in ``fc``,
    ``fc / k`` units), so ``rho <= r * (max stiffness / k)``: ``rho`` is at most the smallest
    fixed point of that map.  Dahl: stiffness ``k (1 -+ w / fc)^alpha``, ``delta = (1 +
    rho)^alpha - 1``.  Bouc-Wen: ``k (1 - (beta + gamma) |z|^n)`` loading and ``k (1 + (beta -
    gamma) |z|^n)`` unloading, ``delta = (beta + |gamma|) rho^n``.
    """
    if cls is Dahl:
        a = p["alpha"]
        rho = _smallest_fixed_point(lambda q: r * (1 + q) ** a)
        return (1 + rho) ** a - 1, 1
    n, b, g = p["n"], p["beta"], p["gamma"]
    rho = _smallest_fixed_point(lambda q: r * (1 + (b - g) * q**n))
    return (b + abs(g)) * rho**n, round(n)


@pytest.mark.parametrize("name", RATE_INDEPENDENT)
def test_small_amplitude_tends_to_initial_stiffness(name):
    """``A -> 0``: ``D -> k`` (real), with the bound ``|D / k - 1| <= 2 delta``.

    If ``dw/dx`` stays within ``k (1 +- delta)`` on the loop, ``f = w - k x`` has
    ``|df| <= delta k |dx|`` and ``f(theta + pi) = -f(theta)`` (odd element), so
    ``|f| <= delta k A`` and ``|D - k| = |(1 / (pi A)) int f (sin + j cos) dtheta| <= 2 delta
    k``.  ``delta`` (:func:`small_motion_bound`) is of order ``r`` (Dahl, Bouc-Wen ``n = 1``)
    or ``r^2`` (Bouc-Wen ``n = 2``), and so is ``D - k``.
    """
    cls, p, _, _ = CASES[name]
    el = cls(**p)
    assert el.initial_stiffness == K and el.describing_function(0.0) == K
    r = np.array([1e-2, 5e-3, 1e-3])
    dev = np.abs(el.describing_function(r * FC / K) / K - 1)
    delta = [small_motion_bound(cls, p, v) for v in r]
    bound = 2 * np.array([d for d, _ in delta])
    assert np.all(dev <= bound), (dev, bound)
    assert np.all(dev >= 0.05 * bound)  # the bound is not vacuous (measured 0.12-0.21 of it)
    np.testing.assert_allclose(dev[0] / dev[1], 2.0 ** delta[0][1], rtol=1e-2)


@pytest.mark.parametrize("omega", [3.0, 300.0])
def test_lugre_small_amplitude_limit(omega):
    """``A -> 0``: ``D -> sigma0 + j omega (sigma1 + sigma2)``.  ``sigma0 (z - x)`` obeys the
    bound above with ``delta = rho`` (``g >= min(fc, fs)``), and ``sigma1 (z' - v)`` is at most
    ``sigma1 omega rho |x'|``, whose first harmonic is at most ``(4 / pi) sigma1 omega rho``."""
    s0, s1, s2, fc, fs = K, 0.1, 0.05, FC, 0.08
    el = LuGre(sigma0=s0, sigma1=s1, sigma2=s2, fc=fc, fs=fs, vs=0.02)
    limit = s0 + 1j * omega * (s1 + s2)
    assert el.describing_function(0.0, omega) == limit
    # A omega << vs keeps g near fs, so the order in A is not blurred by the Stribeck curve
    r = np.array([2e-3, 1e-3, 2e-4])
    dev = np.abs(el.describing_function(r * min(fc, fs) / s0, omega) - limit)
    rho = r / (1 - r)  # fixed point of rho = r (1 + rho)
    bound = rho * (2 * s0 + 4 / np.pi * omega * s1)
    assert np.all(dev <= bound), (dev, bound)
    assert np.all(dev >= 0.05 * bound)
    np.testing.assert_allclose(dev[0] / dev[1], 2.0, rtol=1e-2)  # first order in A


# ---------------------------------------------------------------------------
# Vectorised calls
# ---------------------------------------------------------------------------

AMPLITUDES = np.array([[0.0, 1e-3, 5e-3], [2e-2, 1e-3, 3e-4]])  # with 0 and a repeat


@pytest.mark.parametrize("name", ["bouc-wen-n2", "dahl-alpha2"])
def test_vectorised_rate_independent_equals_scalar_calls(name):
    cls, params, _, _ = CASES[name]
    D = cls(**params).describing_function(AMPLITUDES)
    H = cls(**params).hosidf(AMPLITUDES, 3)
    assert D.shape == (2, 3) and H.shape == (2, 3, 3)
    for idx, a in np.ndenumerate(AMPLITUDES):
        el = cls(**params)  # fresh instance: no shared cache
        assert D[idx] == el.describing_function(float(a))
        np.testing.assert_array_equal(H[idx], el.hosidf(float(a), 3))
    assert D[0, 0] == K
    np.testing.assert_array_equal(H[0, 0], [K, 0.0, 0.0])


def test_vectorised_lugre_equals_scalar_calls():
    _, params, _, _ = CASES["lugre"]
    omegas = np.array([0.0, 3.0, 30.0, 300.0])
    D = LuGre(**params).describing_function(AMPLITUDES[..., None], omegas)
    assert D.shape == (2, 3, 4)
    for (i, j, m), d in np.ndenumerate(D):
        assert d == LuGre(**params).describing_function(float(AMPLITUDES[i, j]),
                                                        float(omegas[m]))
    H = LuGre(**params).hosidf(AMPLITUDES, 3, 30.0)
    assert H.shape == (2, 3, 3)
    for idx, a in np.ndenumerate(AMPLITUDES):
        np.testing.assert_array_equal(H[idx], LuGre(**params).hosidf(float(a), 3, 30.0))
    np.testing.assert_array_equal(H[0, 0], [LuGre(**params).small_amplitude_limit(30.0), 0, 0])


# ---------------------------------------------------------------------------
# Parameter validation: constructors and scenario sections
# ---------------------------------------------------------------------------

NAN = float("nan")
VALID = {
    "bouc-wen": (BoucWen, dict(k=K, fc=FC, n=2.0, beta=0.7, gamma=0.3)),
    "dahl": (Dahl, dict(k=K, fc=FC, alpha=2.0)),
    "lugre": (LuGre, dict(sigma0=20.0, sigma1=0.1, sigma2=0.05, fc=FC, fs=0.08, vs=0.02)),
}
# (model, changed parameters, text the message must contain)
INVALID = [
    ("bouc-wen", dict(k=-1.0), "k"),
    ("bouc-wen", dict(k=0.0), "k"),
    ("bouc-wen", dict(fc=-0.05), "fc"),
    ("bouc-wen", dict(fc=0.0), "fc"),
    ("bouc-wen", dict(n=0.5), "n"),
    ("bouc-wen", dict(beta=0.2, gamma=0.3), "beta"),
    ("bouc-wen", dict(beta=0.0, gamma=-0.5), "beta + gamma"),
    ("bouc-wen", dict(beta=-0.3, gamma=-0.3), "beta + gamma"),
    ("dahl", dict(k=-20.0), "k"),
    ("dahl", dict(fc=0.0), "fc"),
    ("dahl", dict(alpha=0.0), "alpha"),
    ("dahl", dict(alpha=-1.0), "alpha"),
    ("lugre", dict(sigma0=0.0), "sigma0"),
    ("lugre", dict(sigma0=-1.0), "sigma0"),
    ("lugre", dict(sigma1=-0.1), "sigma1"),
    ("lugre", dict(sigma2=-0.1), "sigma2"),
    ("lugre", dict(fc=0.0), "fc"),
    ("lugre", dict(fs=-0.08), "fs"),
    ("lugre", dict(vs=0.0), "vs"),
    ("lugre", dict(vs=-0.02), "vs"),
]
INVALID += [(model, {key: NAN}, key) for model, (_, params) in VALID.items() for key in params]
INVALID += [(model, {key: math.inf}, key) for model, (_, params) in VALID.items()
            for key in params]
INVALID_IDS = [f"{m}-{'-'.join(f'{k}={v}' for k, v in c.items())}" for m, c, _ in INVALID]


def _names(text, name):
    """Whether `name` (a parameter, or ``beta + gamma``) appears as a word in `text`."""
    return re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", text) is not None


@pytest.mark.parametrize(("model", "change", "name"), INVALID, ids=INVALID_IDS)
def test_invalid_parameters_raise_one_line_value_error(model, change, name):
    cls, params = VALID[model]
    with pytest.raises(ValueError) as info:
        cls(**{**params, **change})
    msg = str(info.value)
    assert "\n" not in msg and _names(msg, name), msg


@pytest.mark.parametrize(("model", "change", "name"), INVALID, ids=INVALID_IDS)
def test_invalid_hysteresis_section_raises_scenario_error(model, change, name):
    section = {"model": model, **VALID[model][1], **change}
    with pytest.raises(ScenarioError) as info:
        hysteresis_from_dict(section)
    msg = str(info.value)
    assert "\n" not in msg and "[hysteresis]" in msg and _names(msg, name), msg


@pytest.mark.parametrize("model", list(VALID))
@pytest.mark.parametrize("A", [-1e-3, NAN, math.inf])
def test_invalid_amplitude_raises(model, A):
    cls, params = VALID[model]
    omega = 10.0 if cls is LuGre else None
    with pytest.raises(ValueError, match="amplitude"):
        cls(**params).describing_function(A, omega)
    with pytest.raises(ValueError, match="amplitude"):
        cls(**params).hosidf(np.array([1e-3, A]), 3, omega)


@pytest.mark.parametrize("omega", [None, -1.0, NAN, math.inf])
def test_lugre_needs_a_valid_frequency(omega):
    el = LuGre(**VALID["lugre"][1])
    with pytest.raises(ValueError, match="omega") as info:
        el.describing_function(1e-3, omega)
    assert "\n" not in str(info.value)
    if omega is not None:
        with pytest.raises(ValueError, match="omega"):
            el.describing_function(np.array([1e-3, 2e-3]), np.array([1.0, omega]))
    with pytest.raises(ValueError, match="omega"):
        el.hosidf(1e-3, 3, omega)
    with pytest.raises(ValueError, match="sample times t"):
        el.response(np.zeros(3))


def _scenario_dict(section):
    data = tomllib.loads(default_scenario_path().read_text())
    data["hysteresis"] = section
    return data


@pytest.mark.parametrize(("model", "change", "name"), INVALID, ids=INVALID_IDS)
def test_invalid_hysteresis_in_scenario_raises_scenario_error(model, change, name):
    data = _scenario_dict({"model": model, **VALID[model][1], **change})
    with pytest.raises(ScenarioError) as info:
        Scenario.from_dict(data, source="link.toml")
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith("link.toml: [hysteresis]"), msg
    assert _names(msg, name), msg


@pytest.mark.parametrize("model", list(VALID))
def test_valid_sections_build_the_model(model):
    cls, params = VALID[model]
    section = {"model": model, **params}
    el = hysteresis_from_dict(section)
    assert type(el) is cls
    assert el.to_dict() == section
    link = Scenario.from_dict(_scenario_dict(section)).hysteresis()
    assert type(link) is cls and link.to_dict() == section
    omega = TWO_PI * 5 if cls is LuGre else None
    assert link.describing_function(5e-3, omega) == cls(**params).describing_function(5e-3, omega)


@pytest.mark.parametrize(("section", "expected"), [
    ({"model": "bouc-wen", "k": 20, "fc": 0.05},
     BoucWen(20.0, 0.05, n=1.0, beta=0.5, gamma=0.5)),
    ({"model": "dahl", "k": 20, "fc": 0.05}, Dahl(20.0, 0.05, alpha=1.0)),
    ({"model": "lugre", "sigma0": 20, "fc": 0.05, "fs": 0.08, "vs": 0.02},
     LuGre(20.0, 0.0, 0.0, 0.05, 0.08, 0.02)),
], ids=["bouc-wen", "dahl", "lugre"])
def test_section_defaults(section, expected):
    el = hysteresis_from_dict(section)
    assert type(el) is type(expected) and el.to_dict() == expected.to_dict()


@pytest.mark.parametrize("A", [1e-8, 1e-9, 1e-10])
def test_dahl_keeps_its_accuracy_at_nanometre_amplitudes(A):
    """Im D = 4 fc / (pi A) (1 - tanh r / r), r = k A / fc, whose series is r^2/3 - 2 r^4/15.

    The loop's area is a part in 1e7..1e9 of the stored energy here: a step formed as
    ``1 - (1 - zeta) exp(-v)`` loses it to cancellation (it was 33x too large at 1e-10 m).
    """
    k, fc = 20.0, 0.05
    r = k * A / fc
    D = Dahl(k, fc).describing_function(A)
    assert D.imag == pytest.approx(4 * fc / (np.pi * A) * (r**2 / 3 - 2 * r**4 / 15), rel=1e-5)
    assert D.real <= k * (1 + 1e-15)
    # LuGre with fs = fc and no damping is the same model, computed by another kernel
    assert D == pytest.approx(LuGre(k, 0.0, 0.0, fc, fc, 0.01).describing_function(A, 10.0),
                              rel=1e-14)
