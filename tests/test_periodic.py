"""Tests of the exact periodic harmonics of the stop operator (hysteresis/periodic.py).

Conventions: a periodic signal is given by its ``rfft / N`` harmonics ``X_0 .. X_M``,
``x(theta) = X_0 + 2 Re sum_m X_m exp(j m theta)``.  For ``x = A sin(theta + phase)``
this is ``X_1 = A exp(j phase) / (2 j)``, and the describing function (paper eq. 7) of
the element is ``D = 2 j W_1 / (A exp(j phase))``.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import quad
from scipy.optimize import brentq

from motionhyst.hysteresis.jenkins import Jenkins
from motionhyst.hysteresis.periodic import (
    significant_harmonics,
    stop_periodic_harmonics,
    trig_eval,
)

K, FC = 20.0, 0.05  # Table I link
N_SAMPLED = 2**18  # samples a period of the independent sampled computation
H_OUT = 15

ZETAS = [1e-3, 0.01, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 0.99, 0.999, 1.0 - 1e-6]
PHASES = [0.0, 0.3, 1.234, -2.1, np.pi, 2.9]


@pytest.fixture(scope="module")
def el() -> Jenkins:
    return Jenkins(k=K, fc=FC)


def sine_harmonics(A: float, phase: float = 0.0) -> np.ndarray:
    X = np.zeros(2, dtype=complex)
    X[1] = A * np.exp(1j * phase) / 2j
    return X


def sampled_harmonics(el: Jenkins, x_of_theta, n_harmonics: int) -> np.ndarray:
    """Independent reference: run the exact sampled element over two periods, FFT the second."""
    theta = np.arange(2 * N_SAMPLED) * (2 * np.pi / N_SAMPLED)
    w = el.response(x_of_theta(theta))[N_SAMPLED:]
    return (np.fft.rfft(w) / N_SAMPLED)[: n_harmonics + 1]


def df_from_harmonics(W: np.ndarray, A: float, phase: float) -> complex:
    return complex(2j * W[1] / (A * np.exp(1j * phase)))


# --------------------------------------------------------------------------- sine input


@pytest.mark.parametrize("phase", PHASES)
@pytest.mark.parametrize("zeta", ZETAS)
def test_sine_reproduces_closed_form_describing_function(el, zeta, phase):
    A = FC / (K * zeta)
    W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 9)
    D_closed = el.describing_function(A)
    assert abs(df_from_harmonics(W, A, phase) - D_closed) <= 1e-12 * abs(D_closed)


@pytest.mark.parametrize("zeta", [1e-6, 1e-5, 1e-4])
def test_small_zeta_accuracy_is_limited_only_by_conditioning(el, zeta):
    """For small zeta the stick pieces k x (size fc / zeta) cancel to a force of size fc."""
    A = FC / (K * zeta)
    D_closed = el.describing_function(A)
    assert D_closed.imag == pytest.approx(4 / np.pi * K * zeta, rel=2 * zeta)  # eq. (11)
    for phase in (0.0, 0.3, -2.1):
        W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 3)
        err = abs(df_from_harmonics(W, A, phase) - D_closed) / abs(D_closed)
        assert err <= 1e-15 / zeta


@pytest.mark.parametrize("phase", [0.0, 0.7, -2.3])
@pytest.mark.parametrize("zeta", [0.1, 0.25, 0.5, 0.75])
def test_symmetric_input_has_no_mean_and_no_even_harmonics(zeta, phase):
    A = FC / (K * zeta)
    W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 20)
    assert W.shape == (21,)
    assert np.max(np.abs(W[0::2])) <= 1e-13 * abs(W[1])


@pytest.mark.parametrize(("zeta", "phase"), [(0.1, 0.0), (0.25, 0.3), (0.5, -1.1), (0.8, 2.5)])
def test_sine_harmonics_match_sampled_fft(el, zeta, phase):
    A = FC / (K * zeta)
    W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, H_OUT)
    W_ref = sampled_harmonics(el, lambda th: A * np.sin(th + phase), H_OUT)
    assert_allclose(W[1::2], W_ref[1::2], rtol=0, atol=1e-6 * abs(W[1]))
    # the higher odd harmonics are really there (not a trivially zero comparison)
    assert abs(W[3]) > 1e-2 * abs(W[1])


@pytest.mark.parametrize("A", [1e-3, 2.4e-3, 2.4999e-3])
def test_no_slip_amplitude_is_a_spring(A):
    """Below the slip displacement fc / k = 2.5 mm the output is W = k X (zero mean)."""
    phase = 0.4
    X = sine_harmonics(A, phase)
    W = stop_periodic_harmonics(X, K, FC, 7)
    assert W[1] == pytest.approx(K * X[1], rel=1e-13)
    assert np.max(np.abs(np.delete(W, 1))) <= 1e-13 * abs(W[1])


def test_no_slip_with_offset_returns_symmetric_solution():
    """Without slip the periodic output is defined up to a constant: the symmetric one."""
    X = sine_harmonics(1e-3, 0.2)
    X[0] = 0.37  # a mean displacement does not change the force
    W = stop_periodic_harmonics(X, K, FC, 5)
    assert abs(W[0]) <= 1e-15
    assert W[1] == pytest.approx(K * X[1], rel=1e-13)


def test_mean_displacement_does_not_change_slipping_output():
    A, phase = 0.01, 0.3
    W0 = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 9)
    X = sine_harmonics(A, phase)
    X[0] = -0.2
    W = stop_periodic_harmonics(X, K, FC, 9)
    assert_allclose(W, W0, rtol=0, atol=1e-14 * abs(W0[1]))


def test_zero_and_constant_input_give_zero_output():
    assert np.all(stop_periodic_harmonics(np.zeros(4, complex), K, FC, 5) == 0)
    assert np.all(stop_periodic_harmonics(np.array([0.3 + 0j, 0, 0]), K, FC, 5) == 0)


def test_scaling_with_k_and_fc():
    """W / fc depends only on zeta: scale fc and k together with A."""
    A, phase = 0.01, 0.5
    W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 9)
    W2 = stop_periodic_harmonics(sine_harmonics(A, phase), 10 * K, 10 * FC, 9)
    assert_allclose(W2, 10 * W, rtol=0, atol=1e-14 * abs(W2[1]))
    W3 = stop_periodic_harmonics(sine_harmonics(A / 4, phase), 4 * K, FC, 9)
    assert_allclose(W3, W, rtol=0, atol=1e-14 * abs(W[1]))


@pytest.mark.parametrize("zeta", [0.25, 0.5])
def test_reversal_on_grid_point(el, zeta):
    """x = A sin(theta + pi/4) reverses at theta = pi/4, grid point 128 of 1024."""
    A, phase = FC / (K * zeta), np.pi / 4
    W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 5)
    assert abs(df_from_harmonics(W, A, phase) - el.describing_function(A)) <= (
        1e-12 * abs(el.describing_function(A)))


def test_reversals_on_every_grid_point(el):
    """Phases that put the reversals of x on each point of the 1024-point root grid."""
    A = FC / (K * 0.25)
    D = el.describing_function(A)
    worst = 0.0
    for j in range(1024):
        phase = np.pi / 2 - 2 * np.pi * j / 1024
        W = stop_periodic_harmonics(sine_harmonics(A, phase), K, FC, 4)
        worst = max(worst, abs(df_from_harmonics(W, A, phase) - D) / abs(D),
                    float(np.max(np.abs(W[0::2])) / abs(W[1])))
    assert worst <= 1e-12


@pytest.mark.parametrize("zeta", [1.0 - 1e-13, 1.0 - 1e-15])
def test_closed_form_near_zeta_one(el, zeta):
    A = FC / (K * zeta)
    W = stop_periodic_harmonics(sine_harmonics(A), K, FC, 3)
    D_exact = df_from_harmonics(W, A, 0.0)
    # the exact harmonics are right: D -> k with Im D = (4 / pi) k zeta (1 - zeta) -> 0
    assert abs(D_exact - K) <= 1e-12 * K
    assert abs(el.describing_function(A) - D_exact) <= 1e-12 * abs(D_exact)


# --------------------------------------------------------------------- two-harmonic input


@pytest.mark.parametrize("A", [0.01, 0.004, 0.003])
def test_two_harmonic_input_with_minor_loops_matches_sampled_fft(el, A):
    """x = A sin(theta) + 0.3 A sin(3 theta + 0.4) reverses six times a period (minor loops)."""
    phase3 = 0.4
    X = np.zeros(4, dtype=complex)
    X[1] = A / 2j
    X[3] = 0.3 * A * np.exp(1j * phase3) / 2j

    def x_of_theta(th):
        return A * np.sin(th) + 0.3 * A * np.sin(3 * th + phase3)

    # the input has minor loops: six reversals a period
    th = np.arange(4096) * (2 * np.pi / 4096)
    dx = np.diff(x_of_theta(np.append(th, 2 * np.pi)))
    assert np.count_nonzero(np.sign(dx) != np.sign(np.roll(dx, 1))) == 6
    assert_allclose(trig_eval(X, th), x_of_theta(th), rtol=0, atol=1e-15)

    W = stop_periodic_harmonics(X, K, FC, H_OUT)
    W_ref = sampled_harmonics(el, x_of_theta, H_OUT)
    assert_allclose(W, W_ref, rtol=0, atol=1e-5 * abs(W[1]))
    # half-wave symmetric input: even harmonics vanish
    assert np.max(np.abs(W[0::2])) <= 1e-12 * abs(W[1])


def test_significant_harmonics():
    X = np.array([5.0, 1.0, 0.0, 0.5, 1e-20, 0.0], dtype=complex)
    assert significant_harmonics(X) == 3
    assert significant_harmonics(np.array([1.0, 0.0, 0.0], dtype=complex)) == 0


# ------------------------------------------------- independent reference at round-off


def quadrature_harmonics(X: np.ndarray, k: float, fc: float, n_harmonics: int) -> np.ndarray:
    """Independent reference: ``W_n`` by adaptive quadrature of the exact periodic force.

    Reversals (roots of ``x'``) and slip onsets are found by ``brentq`` from sign changes
    on a fine grid, the element is run twice round the reversals from the global maximum
    (from ``k (x - mid-range)``, the symmetric solution where it never slips), and
    ``w(theta) exp(-j n theta)`` is integrated by ``quad`` between its corners.
    """
    m = np.arange(1, len(X))

    def x(t):
        return X[0].real + 2 * np.real(np.sum(X[1:] * np.exp(1j * m * t)))

    def dx(t):
        return 2 * np.real(np.sum(1j * m * X[1:] * np.exp(1j * m * t)))

    grid = np.linspace(0.0, 2 * np.pi, 4097)
    dv = [dx(t) for t in grid]
    rev = [brentq(dx, grid[i], grid[i + 1], xtol=1e-15) for i in range(4096)
           if np.sign(dv[i]) != np.sign(dv[i + 1])]
    i0 = int(np.argmax([x(t) for t in rev]))
    rev = rev[i0:] + [t + 2 * np.pi for t in rev[:i0]] + [rev[i0] + 2 * np.pi]
    xs = [x(t) for t in rev]
    w = min(max(k * (xs[0] - 0.5 * (max(xs) + min(xs))), -fc), fc)  # symmetric if no slip
    for _ in range(2):
        ws = [w]
        for a, b in pairwise(xs):
            w = min(max(w + k * (b - a), -fc), fc)
            ws.append(w)
    W = np.zeros(n_harmonics + 1, dtype=complex)
    for i in range(len(rev) - 1):
        d = 1.0 if xs[i + 1] > xs[i] else -1.0
        level = xs[i] + (d * fc - ws[i]) / k
        corners = [rev[i], rev[i + 1]]
        if d * (xs[i + 1] - level) > 0:
            corners.insert(1, brentq(lambda t, lv=level: x(t) - lv, rev[i], rev[i + 1],
                                     xtol=1e-15))

        def force(t, i=i):
            return min(max(ws[i] + k * (x(t) - xs[i]), -fc), fc)

        for a, b in pairwise(corners):
            for n in range(n_harmonics + 1):
                re = quad(lambda t, n=n: force(t) * np.cos(n * t), a, b, epsabs=1e-18,
                          epsrel=1e-15, limit=200)[0]
                im = quad(lambda t, n=n: -force(t) * np.sin(n * t), a, b, epsabs=1e-18,
                          epsrel=1e-15, limit=200)[0]
                W[n] += re + 1j * im
    return W / (2 * np.pi)


def rich_input(A: float) -> np.ndarray:
    """A mean, a second and a third harmonic: six reversals a period (minor loops)."""
    return np.array([0.001, A / 2j, 0.1 * A * np.exp(0.7j) / 2j, 0.3 * A * np.exp(0.4j) / 2j])


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_rich_input_matches_quadrature_to_round_off():
    X = rich_input(0.004)
    W = stop_periodic_harmonics(X, K, FC, 6)
    assert_allclose(W, quadrature_harmonics(X, K, FC, 6), rtol=0, atol=5e-15 * abs(W[1]))


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_parallel_elements_are_the_sum_of_single_elements():
    """Maxwell-slip in one pass: elements that slip, slip in minor loops, or never slip."""
    k, fc = np.array([8.0, 6.0, 4.0]), np.array([0.01, 0.03, 0.06])
    X = rich_input(0.01)
    W = stop_periodic_harmonics(X, k, fc, 9)
    singles = [stop_periodic_harmonics(X, ki, fi, 9) for ki, fi in zip(k, fc, strict=True)]
    assert_allclose(W, sum(singles), rtol=0, atol=1e-15 * abs(W[1]))
    W_quad = sum(quadrature_harmonics(X, ki, fi, 4) for ki, fi in zip(k, fc, strict=True))
    assert_allclose(W[:5], W_quad, rtol=0, atol=5e-15 * abs(W[1]))


def dominated_input(M: int, A: float = 0.01, seed: int = 0) -> np.ndarray:
    """``A sin(theta)`` and `M` - 1 small higher harmonics (a stiff loop's ``y1``): the
    first harmonic dominates, so the reversals are bracketed without a grid."""
    rng = np.random.default_rng(seed)
    m = np.arange(2, M + 1)
    X = np.zeros(M + 1, dtype=complex)
    X[1] = A / 2j
    X[2:] = 1e-6 * A * (rng.standard_normal(m.size) + 1j * rng.standard_normal(m.size)) / m**3
    return X


@pytest.mark.parametrize(("n", "M", "H"), [(40, 60, 60), (400, 140, 139)])
def test_many_elements_are_the_sum_of_single_elements(n, M, H):
    """Many elements in one pass (their slip onsets from the grid's cubic, and with 400
    elements the jump sums binned) agree with each element alone (exact Newton, direct
    sums) to round-off; slip displacements from 1e-4 to 2 amplitudes, some never slip."""
    X = dominated_input(M)
    u = np.geomspace(1e-6, 0.02, n)  # slip displacements fc / k [m]
    k = np.linspace(0.5, 2.0, n)
    W = stop_periodic_harmonics(X, k, k * u, H)
    singles = sum(stop_periodic_harmonics(X, ki, ki * ui, H) for ki, ui in zip(k, u, strict=True))
    assert_allclose(W, singles, rtol=0, atol=1e-14 * abs(W[1]))
    assert abs(W[3]) > 1e-3 * abs(W[1])  # the elements slip: the output is not a spring


@pytest.mark.parametrize(("n", "M", "H"), [(40, 61, 60), (400, 139, 139)])
def test_half_wave_symmetric_input_runs_half_a_period(n, M, H):
    """An input without even harmonics (a symmetric loop's ``y1``) is run over half a period,
    its mirror giving the other half: the output agrees with the elements one by one
    (exact Newton onsets, direct sums), has no even harmonics, and agrees with the whole
    period's computation of an input whose even harmonics are 1e-12 of the odd ones."""
    X = dominated_input(M)
    X[2::2] = 0.0
    u = np.geomspace(1e-6, 0.02, n)  # slip displacements fc / k [m]
    k = np.linspace(0.5, 2.0, n)
    W = stop_periodic_harmonics(X, k, k * u, H)
    singles = sum(stop_periodic_harmonics(X, ki, ki * ui, H) for ki, ui in zip(k, u, strict=True))
    assert_allclose(W, singles, rtol=0, atol=1e-14 * abs(W[1]))
    assert np.all(W[0::2] == 0.0)
    assert abs(W[3]) > 1e-3 * abs(W[1])  # the elements slip: the output is not a spring
    X_whole = X.copy()
    X_whole[2] = 1e-12 * abs(X[1])
    W_whole = stop_periodic_harmonics(X_whole, k, k * u, H)
    assert_allclose(W_whole, W, rtol=0, atol=1e-10 * abs(W[1]))
    assert np.max(np.abs(W_whole[0::2])) > 0.0  # the whole period was run


def test_mismatched_parallel_parameters_raise():
    with pytest.raises(ValueError, match="equal length"):
        stop_periodic_harmonics(sine_harmonics(0.01), [1.0, 2.0], [0.1], 3)


@pytest.mark.parametrize("b", [0.11112, 0.1112])
def test_close_reversals_rotate_with_the_input(b):
    """A time shift of the input rotates every harmonic: W_q -> W_q exp(j q phase).

    ``x = A (sin theta + b sin 3 theta)`` has two reversals 0.012 rad (b = 0.11112,
    about two grid cells) and 0.05 rad apart near theta = pi/2; the shifts move them
    across the grid on which the roots are bracketed.
    """
    el = Jenkins(20.0, 0.05)
    X = np.zeros(4, dtype=complex)
    X[1], X[3] = 0.01 / 2j, b * 0.01 / 2j
    W0 = el.periodic_harmonics(X, 7)
    q = np.arange(8)
    for phase in np.linspace(0.0, 2 * np.pi, 60, endpoint=False):
        W = el.periodic_harmonics(X * np.exp(1j * np.arange(4) * phase), 7)
        assert_allclose(W * np.exp(-1j * q * phase), W0, rtol=0, atol=1e-13 * abs(W0[1]))


def test_negative_harmonic_count_raises():
    with pytest.raises(ValueError, match="n_harmonics must be >= 0"):
        Jenkins(20.0, 0.05).periodic_harmonics(np.array([0.0, 0.01 / 2j]), -1)
