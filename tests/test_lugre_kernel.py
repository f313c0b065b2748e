"""LuGre periodic state at high ``omega A / vs``: the Stribeck window resolved inside the kernel.

Near a reversal the Stribeck curve ``g(v) = fc + (fs - fc) exp(-(v / vs)^2)``
varies only while ``|v| < 6 vs``, an angle ``~ 6 vs / (omega A)`` wide: at
``A = 0.01 m``, ``vs = 1 mm/s`` and 1 kHz that is 1e-4 rad, a sixteenth of a
grid cell at ``N = 4096``.  :func:`~motionhyst.hysteresis._lugre_kernels.lugre_periodic_state`
cuts the steps that meet the window into substeps (``omega x'`` changes by
at most ``vs / 48`` in each near the reversal), so :meth:`LuGre.default_samples`
no longer grows with ``omega A / vs``.  These tests check

* the grid size does not depend on ``omega`` (bounded by the rate-independent
  criteria, 4096 for the elements below);
* ``D`` against an adaptive reference written from the model equation alone
  (:func:`reference_harmonics`) where the Stribeck curve changes ``D`` by far
  more than the tolerance, so a window that was missed or under-resolved would
  fail (the former kernel, without substeps, on the same grid is off by 3.6e-10
  to 3e-7 at these points);
* that sampling ``z`` on the coarse grid does not alias the narrow change the
  window makes in ``z`` (results do not move when the grid is refined);
* inputs with several harmonics: two reversals close together, and a minimum
  of ``|x'|`` inside the window without a reversal.

Tolerances
----------
The reference integrates ``z`` and its Fourier projections with DOP853 at
``rtol = 1e-13``, with breakpoints at the reversals and at the window edges
``|omega x'| = 8 vs``; it agrees with itself at ``rtol = 1e-11`` to 3e-11 or
better (measured), so at ``rtol = 1e-13`` it adds nothing visible.
:meth:`LuGre.default_samples` states about 1e-10 relative accuracy for ``D``,
so ``D`` is asserted to ``RTOL_DF = 1e-10`` (measured: <= 1.4e-12 at every
point here); each point is checked to have a Stribeck effect on ``D`` of at
least ``100 RTOL_DF``.  Harmonics for the multi-harmonic
inputs are computed on ``N = 65536`` to leave out the default grid's own error
for such inputs (up to 9e-10 of ``|W_1|``, the same with ``fs = fc`` and at
1 Hz: not from the window) and asserted to ``RTOL_FINE = 1e-11`` of ``|W_1|``
(measured <= 1.5e-12).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from motionhyst.hysteresis import LuGre

TWO_PI = 2.0 * np.pi
RTOL_DF = 1e-10
RTOL_FINE = 1e-11

# (sigma0, sigma1, sigma2, fc, fs, vs)
P1 = (20.0, 0.01, 0.0, 0.05, 0.06, 0.001)
P2 = (20.0, 0.01, 0.001, 0.05, 0.08, 0.01)
STIFF = (1e5, 5.0, 0.0, 1.0, 2.0, 0.001)  # sigma0 A / fc = 50 .. 1000


def reference_harmonics(params, X, omega, n_harmonics, rtol=1e-13):
    """``W_0 .. W_H`` (``rfft / N`` scaling) of the periodic LuGre force for the input
    ``x = sum_k 2 Re(X_k exp(j k theta))``, from the model equation alone.

    ``dz/dtheta = x' - sigma0 |x'| z / g(omega x')`` is linear in ``z``: the
    particular solution from ``z = 0`` and the homogeneous one from ``z = 1`` are
    integrated over one period with the projections ``int z exp(-j m theta)``;
    the periodic start is ``z0 = z_p(2 pi) / (1 - z_h(2 pi))``.  Then
    ``W_m = (sigma0 + j m omega sigma1) Z_m + j m omega sigma2 X_m``.  The
    integration restarts at each reversal and at each edge ``|omega x'| = 8 vs``
    of the Stribeck window (found on a fine grid, refined by Brent's method),
    so the adaptive steps cannot jump over the window.
    """
    s0, s1, s2, fc, fs, vs = params
    X = np.asarray(X, dtype=complex)
    k = np.arange(X.size)
    H = int(n_harmonics)
    m = np.arange(H + 1)

    def xp(th):
        return float(2.0 * np.real(np.sum(X * 1j * k * np.exp(1j * k * th))))

    def g(v):
        return fc + (fs - fc) * np.exp(-((v / vs) ** 2))

    th = np.linspace(0.0, TWO_PI, 400_001)
    d = 2.0 * np.real(np.exp(1j * np.outer(th, k)) @ (X * 1j * k))
    edges = [0.0, TWO_PI]
    for level in (0.0, 8.0 * vs / omega, -8.0 * vs / omega):
        e = d - level
        for i in np.nonzero(np.sign(e[:-1]) != np.sign(e[1:]))[0]:
            edges.append(brentq(lambda t, lv=level: xp(t) - lv, th[i], th[i + 1], xtol=1e-15))
    edges = sorted(set(edges))

    def rhs(t, y):
        v = xp(t)
        lam = s0 * abs(v) / g(omega * v)
        e = np.exp(-1j * m * t)
        return np.concatenate([[v - lam * y[0], -lam * y[1]], (y[0] * e).real,
                               (y[0] * e).imag, (y[1] * e).real, (y[1] * e).imag])

    n = H + 1
    y = np.zeros(2 + 4 * n)
    y[1] = 1.0
    for a, b in itertools.pairwise(edges):
        y = solve_ivp(rhs, (a, b), y, method="DOP853", rtol=rtol, atol=1e-22,
                      max_step=(b - a) / 8).y[:, -1]
    z0 = y[0] / (1.0 - y[1])
    Z = (y[2:2 + n] + 1j * y[2 + n:2 + 2 * n]
         + z0 * (y[2 + 2 * n:2 + 3 * n] + 1j * y[2 + 3 * n:2 + 4 * n])) / TWO_PI
    Xm = np.zeros(n, dtype=complex)
    Xm[:min(n, X.size)] = X[:n]
    return (s0 + 1j * m * omega * s1) * Z + 1j * m * omega * s2 * Xm


def reference_df(params, A, omega):
    """``D = 2 j W_1 / A`` for ``x = A sin(theta)`` from :func:`reference_harmonics`."""
    W = reference_harmonics(params, np.array([0.0, A / 2j]), omega, 1)
    return complex(2j * W[1] / A)


def flat(params):
    """The same element without the Stribeck effect (``fs = fc``)."""
    s0, s1, s2, fc, _, vs = params
    return (s0, s1, s2, fc, fc, vs)


# (params, A [m], f [Hz]): omega A / vs from 630 to 1.6e4, Stribeck effect on D >= 1e-8
HIGH_RATIO = [(P2, 0.01, 100.0), (P2, 0.01, 1000.0), (P1, 0.001, 100.0),
              (STIFF, 0.0005, 250.0), (STIFF, 0.0005, 1000.0), (STIFF, 0.01, 250.0)]


@pytest.mark.parametrize("params", [P1, P2, STIFF])
@pytest.mark.parametrize("A", [0.0005, 0.001, 0.01])
def test_grid_size_does_not_grow_with_frequency(params, A):
    """N comes from the rate-independent criteria only (harmonics, the transition
    width ``sqrt(2 fc / (sigma0 A))`` and ``1100 (sigma0 A / fc)^(1/3)``), so it is the
    same at every frequency; the old criterion (12 samples across ``vs / (omega A)``)
    asked for 4.7e6 samples at 1 kHz for ``P1``, ``A = 0.01``."""
    el = LuGre(*params)
    X = np.array([0.0, A / 2j])
    n0 = el.default_samples(X, 0.0)
    for f in (0.1, 1.0, 10.0, 1e2, 1e3, 1e4, 1e5):
        assert el.default_samples(X, TWO_PI * f) == n0
    r = params[0] * A / min(params[3], params[4])
    bound = max(4096, 2 * 1100 * max(r, 1.0) ** (1 / 3), 2 * 12 * TWO_PI * np.sqrt(r / 2))
    assert n0 <= bound
    if params in (P1, P2):  # sigma0 A / fc <= 4: the minimum grid
        assert n0 == 4096


@pytest.mark.parametrize(("params", "A", "f"), HIGH_RATIO)
def test_df_matches_adaptive_reference_at_high_omega_A_over_vs(params, A, f):
    omega = TWO_PI * f
    ref = reference_df(params, A, omega)
    effect = abs(reference_df(flat(params), A, omega) - ref)
    assert effect >= 100 * RTOL_DF * abs(ref)  # the window matters at this point
    D = LuGre(*params).describing_function(A, omega)
    assert abs(D - ref) <= RTOL_DF * abs(ref)


@pytest.mark.parametrize("params", [P1, P2])
@pytest.mark.parametrize("A", [0.001, 0.01])
def test_df_up_to_10_kHz(params, A):
    """The analysis range: 0.1 Hz .. 10 kHz, omega A / vs up to 6e5."""
    el = LuGre(*params)
    for f in (0.1, 1.0, 10.0, 100.0, 1000.0, 10000.0):
        ref = reference_df(params, A, TWO_PI * f)
        assert abs(el.describing_function(A, TWO_PI * f) - ref) <= RTOL_DF * abs(ref)


@pytest.mark.parametrize(("params", "A", "f"), HIGH_RATIO)
def test_coarse_grid_does_not_alias_the_window(params, A, f):
    """``z`` has a narrow change of size ``~ (vs / (omega A))^2`` across each window;
    the FFT of its samples on the default grid gives the harmonics of the 16 times
    finer grid to ``RTOL_DF`` (measured <= 5.5e-12, as large with ``fs = fc``: the
    grid's own error), and the forces at the common samples agree to 1e-11 of their
    peak (measured <= 5e-13: the substeps' error inside the window, which grows to
    5e-11 if ``omega x'`` may change by ``vs / 12`` per substep instead of ``vs / 48``)."""
    el = LuGre(*params)
    omega = TWO_PI * f
    X = np.array([0.0, A / 2j])
    N = el.default_samples(X, omega)
    W = el.periodic_harmonics(X, 3, omega)
    W_fine = el.periodic_harmonics(X, 3, omega, n_samples=16 * N)
    assert np.max(np.abs(W - W_fine)) <= RTOL_DF * abs(W_fine[1])
    _, w = el.periodic_samples(X, omega)
    _, w_fine = el.periodic_samples(X, omega, n_samples=16 * N)
    assert np.max(np.abs(w - w_fine[::16])) <= 1e-11 * np.max(np.abs(w_fine))


def test_stribeck_effect_vanishes_as_vs_over_omega_A_squared():
    """Across a window the Stribeck curve changes ``z`` by ``~ sigma0 vs^2 / (omega^2 A)``
    (the displacement inside the window, ``~ vs^2 / (omega^2 A)``, times ``sigma0 / g``),
    so its effect on ``Z_1`` falls as ``(omega A / vs)^-2``: a factor 100 per decade of
    frequency, here from 63 (window resolved by the grid) to 6.3e4 (window a tenth
    of a grid cell), measured within 3e-4 of 100.  At ``omega A / vs = 6e6`` the effect
    on ``D`` is below round-off (measured 1.3e-14)."""
    A = 0.01
    X = np.array([0.0, A / 2j])
    dz = []
    for f in (10.0, 100.0, 1000.0, 1e4):
        omega = TWO_PI * f
        dW = (LuGre(*P2).periodic_harmonics(X, 1, omega)[1]
              - LuGre(*flat(P2)).periodic_harmonics(X, 1, omega)[1])
        dz.append(abs(dW / (P2[0] + 1j * omega * P2[1])))
    ratios = np.array(dz[:-1]) / np.array(dz[1:])
    assert np.all(np.abs(ratios - 100.0) <= 0.1), ratios
    omega = TWO_PI * 1e6
    D = LuGre(*P2).describing_function(A, omega)
    assert abs(D - LuGre(*flat(P2)).describing_function(A, omega)) <= 1e-12 * abs(D)


@pytest.mark.parametrize("f", [100.0, 1000.0])
@pytest.mark.parametrize("kind", ["two close reversals", "touches without reversal"])
@pytest.mark.parametrize("depth", [0.5, 2.0])
def test_multi_harmonic_velocity_dips_into_the_window(f, kind, depth):
    """``x = A sin(theta) + b A sin(2 theta)`` with ``b = (1 +- eps) / 2``: near ``theta = pi``
    ``x' ~ +-eps A - 1.5 A u^2``, so with ``omega eps A = depth vs`` the velocity either
    reverses twice within ``2 sqrt(2 eps / 3)`` rad or has a maximum at ``-depth vs``
    inside the window (a step with an interior extremum of ``x'``)."""
    A = 0.01
    omega = TWO_PI * f
    eps = depth * P2[5] / (omega * A)
    b = 0.5 * (1.0 + eps if kind == "two close reversals" else 1.0 - eps)
    X = np.array([0.0, A / 2j, b * A / 2j])
    ref = reference_harmonics(P2, X, omega, 3)
    effect = np.max(np.abs(reference_harmonics(flat(P2), X, omega, 3) - ref))
    assert effect >= 100 * RTOL_FINE * abs(ref[1])
    W = LuGre(*P2).periodic_harmonics(X, 3, omega, n_samples=65536)
    assert np.max(np.abs(W - ref)) <= RTOL_FINE * abs(ref[1])
