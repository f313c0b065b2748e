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
    regression_lags,
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
    """robust_least_squares' covariance is the sandwich of the scores' sum over
    regression_lags; the one-stage check's covariance from its record's sums is
    robust_least_squares' on the same rows; ResidualCorrelation.inner is ``J^T C J`` with
    ``C`` Toeplitz in its kernel, record by record (each to 1e-9)."""
    rng = np.random.default_rng(3)
    n = 3000
    A = np.column_stack([rng.standard_normal(n).cumsum(), np.ones(n), rng.standard_normal(n)])
    b = A @ [1.0, 2.0, 3.0] + lfilter([1.0], [1.0, -0.95], rng.standard_normal(n))
    x, cov = robust_least_squares([A], [b], 11)
    bread = np.linalg.inv(A.T @ A)
    scores = A * (b - A @ x)[:, None]
    expected = bread @ _direct(scores, bartlett_weights(regression_lags(n, 11))) @ bread
    np.testing.assert_allclose(cov, expected, rtol=1e-9)

    t = np.arange(n) / 1000.0
    y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    y = y + 1e-7 * rng.standard_normal(n)
    v = np.gradient(y, t)
    u = 5.0 * np.gradient(v, t) + 20.0 * np.sign(v) + rng.standard_normal(n)
    pieces = _Pieces(IORecord(t, u, y, "r"))
    from motionhyst.identify.io_start import equation_rows

    rows, rhs = equation_rows([IORecord(t, u, y, "r")], floating=True)
    window = max(7, 2 * round(0.005 * 1000.0) + 1)
    _, cov_rows = robust_least_squares([rows[0][:, :4]], rhs, window)
    np.testing.assert_allclose(pieces.fit([0, 1, 2, 3])[1], cov_rows, rtol=1e-9,
                               atol=1e-12 * np.abs(cov_rows).max())

    e = lfilter([1.0], [1.0, -0.9], rng.standard_normal(n))
    J = rng.standard_normal((n, 3))
    corr = ResidualCorrelation([e[:1000], e[1000:]])
    assert corr.lags > 5
    expected = sum(_direct(J[a:b], corr.kernel[1:]) for a, b in ((0, 1000), (1000, n)))
    np.testing.assert_allclose(corr.inner(J), expected, rtol=1e-9)
