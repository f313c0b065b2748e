"""One Newey-West sum for every standard error robust to the residuals' correlation (issue 21).

The inverse dynamics' checks (io_checks.robust_least_squares: a record without inertia, a mass
far from the records' linear estimate, friction by direction), the one-stage check's sums
(io_consistency) and a fit's standard errors (residual_noise.ResidualCorrelation) each had
their own implementation; they now share residual_noise.bartlett_sum (measured against main:
the same covariances to 6e-15, the one-stage sums identical)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

import motionhyst.identify.residual_noise as residual_noise
from motionhyst.identify.io_checks import robust_least_squares
from motionhyst.identify.io_consistency import _Pieces
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.residual_noise import (
    ResidualCorrelation,
    bartlett_sum,
    bartlett_weights,
    newey_west_lags,
    regression_lags,
    widest_covariance,
)


def _direct(D: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The sum as its definition has it: a product for each lag."""
    out = D.T @ D
    for lag in range(1, k.size + 1):
        g = D[lag:].T @ D[:-lag]
        out += k[lag - 1] * (g + g.T)
    return out


@pytest.mark.parametrize("lags", [0, 1, 37, 300])
def test_the_sum_in_blocks_is_the_products_sum(monkeypatch, lags):
    """Spectra of 1024 points (2048 for 300 lags: a record of 5000 rows in 4 to 5 blocks,
    given whole or made block by block): the products' sum to 1e-12 of its size."""
    monkeypatch.setattr(residual_noise, "BLOCK_FFT", 1024)
    D = np.random.default_rng(lags).standard_normal((5000, 4)).cumsum(axis=0)
    k = bartlett_weights(lags)
    expected = _direct(D, k)
    tol = 1e-12 * np.abs(expected).max()
    np.testing.assert_allclose(bartlett_sum(D, k), expected, rtol=0.0, atol=tol)
    made = []

    def rows(start, stop):
        made.append(stop - start)
        return D[start:stop]
    np.testing.assert_allclose(bartlett_sum(rows, k, 5000), expected, rtol=0.0, atol=tol)
    assert len(made) >= 4 and max(made) < 2048  # a block's rows and its lags, not the record
    assert bartlett_sum(D[:0], k).shape == (4, 4)


def test_the_regressions_and_the_fits_take_the_same_sum():
    """robust_least_squares' covariance is the widest of the sandwiches of the scores' sums
    over newey_west_lags of its residuals (none, the fixed rule, Andrews'); the one-stage
    check's covariances from its record's sums are those sandwiches on the same rows;
    ResidualCorrelation.inners are ``J^T C J`` with ``C`` Toeplitz in each kernel, record by
    record (each to 1e-9; the one-stage check's to 1e-7: its residuals from the normal
    equations)."""
    rng = np.random.default_rng(3)
    n = 3000
    A = np.column_stack([rng.standard_normal(n), np.ones(n)])
    b = A @ [2.0, 0.5] + lfilter([1.0], [1.0, -0.8], rng.standard_normal(n))
    x, cov = robust_least_squares([A], [b], 11)
    bread = np.linalg.inv(A.T @ A)
    e = b - A @ x
    scores = A * e[:, None]
    lags = newey_west_lags([e], 11)
    assert lags[1] == regression_lags(n, 11) and lags[2] > 11
    covs = [bread @ _direct(scores, bartlett_weights(k)) @ bread for k in lags]
    np.testing.assert_allclose(cov, widest_covariance(covs), rtol=1e-9)

    t = np.arange(n) / 1000.0
    y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    v = np.gradient(y, t)
    u = 2.0 * np.gradient(v, t) + 30.0 * v + 0.01 * rng.standard_normal(n)
    pieces = _Pieces(IORecord(t, u, y, "r"))
    from motionhyst.identify.io_start import equation_rows

    rows, rhs = equation_rows([IORecord(t, u, y, "r")], floating=True)
    window = max(7, 2 * round(0.005 * 1000.0) + 1)
    _, cov_rows = robust_least_squares([np.column_stack([rows[0], y])], rhs, window)
    np.testing.assert_allclose(widest_covariance(pieces.fit([0, 1, 2, 3, 4])[1]), cov_rows,
                               rtol=1e-7, atol=1e-12 * np.abs(cov_rows).max())

    e = lfilter([1.0], [1.0, -0.9], rng.standard_normal(n))
    corr = ResidualCorrelation([e[:1000], e[1000:]])
    J = rng.standard_normal((n, 3))
    assert corr.rules[0] == 0 and min(corr.rules[1:]) > 5 and corr.lags == max(corr.rules)
    for kernel, inner in zip(corr.kernels, corr.inners(J), strict=True):
        expected = sum(_direct(J[a:b], kernel[1:]) for a, b in ((0, 1000), (1000, n)))
        np.testing.assert_allclose(inner, expected, rtol=1e-9)


def test_the_regressions_take_the_lags_their_residuals_call_for():
    """One lag rule (newey_west_lags) for the inverse dynamics' checks as for a fit's standard
    errors: a regression whose residuals stay correlated over about 100 samples (a first-order
    autoregression, rho 0.99, 25,000 samples, 40 draws) had its coefficient's robust standard
    error from main's fixed 4 n^(1/3) = 116 lags, 0.64 of the long-run truth (median), the
    truth within 3 of them in 90 % of draws (4.0 away at worst); with Andrews' 700-odd lags
    among the rule's, 0.90 of it, 98 % (3.07 at worst).  Residuals correlated over 10 samples
    (rho 0.9) take about the same (0.96 -> 0.97)."""
    n = 25000
    t = np.linspace(0.0, 1.0, n)
    A = np.column_stack([np.ones(n), np.sin(2 * np.pi * 3 * t)])
    for rho, low in ((0.99, 0.8), (0.9, 0.9)):
        ratios, z = [], []
        for seed in range(40):
            e = lfilter([1.0], [1.0, -rho], np.random.default_rng(seed).standard_normal(n))
            x, cov = robust_least_squares([A], [A @ [1.0, 2.0] + e], 11)
            ratios.append(np.sqrt(cov[0, 0]) * (1 - rho) * np.sqrt(n))  # / the long-run std
            z.append(abs(x[0] - 1.0) / np.sqrt(cov[0, 0]))
        assert low < np.median(ratios) < 1.05, (rho, np.median(ratios))
        assert np.mean(np.array(z) <= 3.0) >= 0.95, (rho, sorted(z)[-3:])
    e = lfilter([1.0], [1.0, -0.99], np.random.default_rng(0).standard_normal(n))
    assert 600 < newey_west_lags([e], 11)[2] <= n // 4


def _periodic_error(seed: int, n: int = 20000) -> np.ndarray:
    """A friction-like model error (a square wave of 0.37 Hz, random phase, 1 unit) and white
    noise of 0.1, 20 s at 1 kHz: a residual whose autocovariance turns negative at lags of
    half its period, well within Andrews' 600-odd lags."""
    rng = np.random.default_rng(100 + seed)
    t = np.arange(n) / 1000.0
    phase = rng.uniform(0.0, 2 * np.pi)
    return np.sign(np.sin(2 * np.pi * 0.37 * t + phase)) + 0.1 * rng.standard_normal(n)


def test_no_standard_error_is_narrower_than_white_residuals_or_the_fixed_rule():
    """A periodic model error (scratch-nw17/lags_cover.py): Andrews' rule alone (std16's
    2421ff6 for the regressions, main's for a fit's standard errors) summed its negative
    autocovariances and made a 3 Hz sine's coefficient's standard error 0.5 of the fixed
    rule's (3.9 against 7.6 times its true scatter over 40 draws); the rule's widest keeps
    the fixed rule's, and never goes below white residuals' either: robust_least_squares
    and a fit's standard errors (correlated_errors, the same Jacobian) alike."""
    from motionhyst.identify.io_uncertainty import correlated_errors

    n = 20000
    t = np.arange(n) / 1000.0
    A = np.column_stack([np.ones(n), np.sin(2 * np.pi * 3 * t)])
    bread = np.linalg.inv(A.T @ A)
    narrowed = 0
    for seed in range(6):
        b = A @ [1.0, 2.0] + _periodic_error(seed)
        x, cov = robust_least_squares([A], [b], 11)
        e = b - A @ x
        lags = newey_west_lags([e], 11)
        white, fixed, andrews = (bread @ _direct(A * e[:, None], bartlett_weights(k)) @ bread
                                 for k in lags)
        assert np.all(np.diag(cov) >= np.maximum(np.diag(white), np.diag(fixed)) * (1 - 1e-9))
        narrowed += andrews[1, 1] < 0.5 * fixed[1, 1]
        fit = correlated_errors(A, [e])  # a fit's: Andrews' alone on main
        assert fit.std[1] >= fit.white_std[1] * (1 - 1e-9)
        corr = ResidualCorrelation([e])
        U = np.linalg.svd(A, full_matrices=False)[0]
        V = np.linalg.lstsq(A, U, rcond=None)[0]  # A^+ U: the sandwich's outer factor
        k = corr.rules.index(regression_lags(n, 0))  # the fixed rule's sandwich
        fixed_fit = V @ (corr.inners(U)[k] * (e @ e) / (n - 2)) @ V.T
        assert fit.std[1] >= np.sqrt(fixed_fit[1, 1]) * (1 - 1e-6), seed
    assert narrowed >= 4  # what Andrews alone did
