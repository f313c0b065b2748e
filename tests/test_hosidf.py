"""Higher-order sinusoidal-input describing functions (HOSIDF) and the quasi-linear error harmonics.

``H_n(A) = Y_n / A`` with ``Y_n`` the complex amplitude of the output's n-th harmonic relative to
``sin(n theta)`` for ``x = A sin(theta)``; ``H_1`` is the describing function of paper eq. (10).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from motionhyst.analysis.comparison import compare_with_describing_function
from motionhyst.analysis.quasilinear import error_harmonics_df
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis import Jenkins, MaxwellSlip
from motionhyst.scenario import default_scenario

K_J, FC = 20.0, 0.05  # Table I
N_MAX = 15
# zeta in (0, 1): both slip modes (eq. 6: switching for x w <= 0 up to 0.5), their boundary
# and both ends
ZETAS = [1e-3, 0.01, 0.1, 0.25, 0.4999, 0.5, 0.5001, 0.75, 0.9, 0.999, 1.0 - 1e-9]


@pytest.fixture
def link() -> Jenkins:
    return Jenkins(K_J, FC)


def amplitude_for(el: Jenkins, zeta: float) -> float:
    return el.fc / (el.k * zeta)


def eq10(k: float, zeta: float) -> complex:
    """Paper eq. (10), written out as printed, with gamma of eq. (6)."""
    gamma = np.arcsin(2 * zeta - 1)
    real = (1 / (2 * zeta)) * ((2 * zeta - 1) * np.sqrt(zeta * (1 - zeta)) + gamma / 2
                               + np.pi / 4)
    return k * 4 * zeta / np.pi * (real + (1 - zeta) * 1j)


def sampled_harmonics(el, A: float, n: tuple[int, ...], samples: int = 2**18) -> list[complex]:
    """``Y_n / A`` from the sampled response over the second of two periods (independent of
    the exact periodic integration): ``Y_n = b_n + j a_n``, as in eqs. (7)-(8)."""
    th = 2 * np.pi * np.arange(2 * samples) / samples
    w = el.response(A * np.sin(th))[samples:]
    t = th[:samples]
    return [complex((2 / samples) * np.sum(w * np.sin(m * t)),
                    (2 / samples) * np.sum(w * np.cos(m * t))) / A for m in n]


# --------------------------------------------------------------- closed form vs exact
@pytest.mark.parametrize("zeta", ZETAS)
def test_closed_form_equals_numerical_hosidf(link, zeta):
    A = amplitude_for(link, zeta)
    exact = link.hosidf(A, N_MAX)
    closed = link.hosidf_closed_form(A, N_MAX)
    assert exact.shape == closed.shape == (N_MAX,)
    h1 = abs(exact[0])
    assert np.max(np.abs(closed - exact)) <= 1e-12 * h1


@pytest.mark.parametrize("zeta", [1e-4, 1e-6])
def test_closed_form_accuracy_at_very_small_zeta_as_documented(link, zeta):
    """Terms of size k A = fc / zeta cancel: the docstring promises about 1e-16 / zeta."""
    A = amplitude_for(link, zeta)
    exact = link.hosidf(A, N_MAX)
    closed = link.hosidf_closed_form(A, N_MAX)
    h1 = abs(exact[0])
    assert np.max(np.abs(closed - exact)) <= 1e-15 / zeta * h1
    assert np.max(np.abs(closed[1::2])) <= 1e-15 / zeta * h1


@pytest.mark.parametrize("zeta", ZETAS)
def test_first_harmonic_is_eq10(link, zeta):
    A = amplitude_for(link, zeta)
    d = eq10(K_J, zeta)
    for h in (link.hosidf(A, 3)[0], link.hosidf_closed_form(A, 3)[0]):
        assert abs(h - d) <= 1e-12 * abs(d)
    assert abs(link.describing_function(A) - d) <= 1e-12 * abs(d)


def test_first_harmonic_limits_eq11(link):
    # zeta -> 0: D -> (4/pi) k zeta j (eq. 11), phase -> 90 deg
    zeta = 1e-3
    h1 = link.hosidf_closed_form(amplitude_for(link, zeta), 1)[0]
    assert h1.imag == pytest.approx(4 / np.pi * K_J * zeta * (1 - zeta), rel=1e-12)
    assert np.degrees(np.angle(h1)) > 87.0
    # zeta -> 1: D -> k
    h1 = link.hosidf_closed_form(amplitude_for(link, 1 - 1e-9), 1)[0]
    assert h1 == pytest.approx(K_J, rel=1e-8)


@pytest.mark.parametrize("zeta", ZETAS)
def test_even_harmonics_vanish(link, zeta):
    A = amplitude_for(link, zeta)
    exact = link.hosidf(A, N_MAX)
    closed = link.hosidf_closed_form(A, N_MAX)
    assert np.all(exact[1::2] == 0)  # snapped to exactly zero
    assert np.max(np.abs(closed[1::2])) < 1e-13 * abs(closed[0])
    if zeta < 0.999:  # odd harmonics are genuinely non-zero while the element slips
        assert np.all(np.abs(exact[2::2]) > 0)


def test_maxwell_even_harmonics_vanish():
    ms = MaxwellSlip([8.0, 6.0, 4.0], [0.01, 0.03, 0.06])
    h = ms.hosidf(np.array([0.002, 0.004, 0.01, 0.1]), 8)
    assert np.all(h[:, 1::2] == 0)
    assert np.all(np.abs(h[:, 2::2]) > 0)


@pytest.mark.parametrize("zeta", [1.0, 1.0 + 1e-12, 1.5, 10.0, 1e6])
def test_no_slip_is_a_spring(link, zeta):
    A = amplitude_for(link, zeta)
    expected = np.zeros(N_MAX, dtype=complex)
    expected[0] = K_J
    np.testing.assert_array_equal(link.hosidf_closed_form(A, N_MAX), expected)
    np.testing.assert_allclose(link.hosidf(A, N_MAX), expected, rtol=1e-14, atol=0)


@pytest.mark.parametrize("zeta", [0.25, 0.7])
def test_third_harmonic_against_sampled_fft(link, zeta):
    A = amplitude_for(link, zeta)
    h1_fft, h3_fft = sampled_harmonics(link, A, (1, 3))
    h = link.hosidf_closed_form(A, 3)
    assert abs(h3_fft - h[2]) <= 1e-6 * abs(h[2])
    assert abs(h1_fft - h[0]) <= 1e-6 * abs(h[0])
    assert abs(h[2]) > 0.05 * abs(h[0])  # a third harmonic worth checking


def test_zero_amplitude_row(link):
    a = np.array([0.0, 0.01])
    expected0 = np.array([K_J, 0, 0, 0, 0], dtype=complex)
    h = link.hosidf(a, 5)
    np.testing.assert_array_equal(h[0], expected0)
    np.testing.assert_allclose(h[1], link.hosidf(0.01, 5), rtol=1e-15)
    with np.errstate(divide="ignore", invalid="ignore"):
        hc = link.hosidf_closed_form(a, 5)
    np.testing.assert_array_equal(hc[0], expected0)
    assert np.all(np.isfinite(hc))
    ms = MaxwellSlip([8.0, 6.0, 4.0], [0.01, 0.03, 0.06])
    np.testing.assert_array_equal(ms.hosidf(0.0, 3), [18.0, 0, 0])


def test_zero_amplitude_closed_form_is_silent(link):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        link.hosidf_closed_form(np.array([0.0, 0.01]), 5)


def test_output_shape_follows_amplitudes(link):
    a = np.full((2, 3), 0.01)
    assert link.hosidf(a, 4).shape == (2, 3, 4)
    assert link.hosidf_closed_form(a, 4).shape == (2, 3, 4)
    assert link.hosidf(0.01, 4).shape == (4,)


@pytest.mark.parametrize("n_max", [0, -1])
def test_n_max_below_one_raises(link, n_max):
    with pytest.raises(ValueError, match="n_max"):
        link.hosidf(0.01, n_max)
    with pytest.raises(ValueError, match="n_max"):
        link.hosidf_closed_form(0.01, n_max)
    with pytest.raises(ValueError, match="n_max"):
        MaxwellSlip([1.0], [1.0]).hosidf(0.01, n_max)


def test_negative_or_nan_amplitude_raises(link):
    for bad in (-0.01, np.nan):
        with pytest.raises(ValueError, match="amplitude"):
            link.hosidf(bad, 3)
        with pytest.raises(ValueError, match="amplitude"):
            link.hosidf_closed_form(bad, 3)


# -------------------------------------------- quasi-linear error harmonics vs exact
A_REF = 0.01
FREQS = (5.0, 10.0, 15.0)


@pytest.fixture(scope="module")
def table1_loop() -> Loop:
    return default_scenario().loop()


@pytest.fixture(scope="module")
def exact_and_df(table1_loop):
    return {f: (periodic_steady_state(table1_loop, A_REF, f),
                error_harmonics_df(table1_loop, A_REF, f, n_max=5)) for f in FREQS}


def phase_error_deg(a: complex, b: complex) -> float:
    return abs(float(np.degrees(np.angle(a / b))))


@pytest.mark.parametrize("f", FREQS)
def test_first_error_harmonic_within_one_percent(exact_and_df, f):
    ss, edf = exact_and_df[f]
    assert abs(edf[0]) == pytest.approx(abs(ss.e[1]), rel=0.01)
    assert phase_error_deg(edf[0], ss.e[1]) < 2.0


@pytest.mark.parametrize("f", FREQS)
@pytest.mark.parametrize("n", [3, 5])
def test_higher_error_harmonics_within_two_percent(exact_and_df, f, n):
    ss, edf = exact_and_df[f]
    assert abs(edf[n - 1]) == pytest.approx(abs(ss.e[n]), rel=0.02)
    assert phase_error_deg(edf[n - 1], ss.e[n]) < 3.0
    assert abs(ss.e[n]) > 1e-3 * abs(ss.e[1])  # a real harmonic, far above round-off
    if f == 5.0:  # not negligible next to the first harmonic (the paper's conclusion)
        assert abs(ss.e[n]) > 0.05 * abs(ss.e[1])


@pytest.mark.parametrize("f", FREQS)
def test_even_error_harmonics(exact_and_df, f):
    ss, edf = exact_and_df[f]
    assert edf.shape == (5,)
    assert edf[1] == 0 and edf[3] == 0
    assert abs(ss.e[2]) < 1e-12 * abs(ss.e[1]) and abs(ss.e[4]) < 1e-12 * abs(ss.e[1])


def test_steady_to_dict_reports_error_harmonics_df(table1_loop, exact_and_df):
    points = compare_with_describing_function(table1_loop, A_REF, [5.0]).to_dict()["points"]
    p = points[0]
    edf = exact_and_df[5.0][1]
    assert [h["n"] for h in p["error_harmonics_df"]] == [1, 3, 5]
    for h in p["error_harmonics_df"]:
        assert h["abs"] == pytest.approx(abs(edf[h["n"] - 1]), rel=1e-12)
        assert h["phase_deg"] == pytest.approx(np.degrees(np.angle(edf[h["n"] - 1])), abs=1e-9)
    ss = exact_and_df[5.0][0]
    assert "error_harmonics_df" not in ss.to_dict()
    d = ss.to_dict(harmonics=(1, 2, 3), error_harmonics_df=edf)
    assert [h["n"] for h in d["error_harmonics_df"]] == [1, 2, 3]
    assert d["error_harmonics_df"][1]["abs"] == 0.0
