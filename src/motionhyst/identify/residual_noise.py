"""The records' noise in a fit's residuals: how much of it is white, how it is correlated
from sample to sample, and what that says of the fit's standard errors.

:func:`white_noise_variance` (the third differences' scatter) is the one estimate of a
signal's white noise that every part uses (the input-output standard errors, ``predict``'s
error, a closed-loop record's passivity check, ``predict --init-from``'s same-run check);
:func:`bartlett_sum` the one Newey-West sum of every standard error robust to the
residuals' correlation, over the lags of one rule, :func:`newey_west_lags` (none, the fixed
:func:`regression_lags` and Andrews' bandwidth: each standard error the widest they give,
:func:`widest_covariance`), for the inverse dynamics' checks as for a fit's standard errors;
:class:`ResidualCorrelation` the residuals' autocorrelation that the standard errors'
sandwich takes (:func:`~motionhyst.identify.io_uncertainty.correlated_errors`);
:func:`lower_bound_note` the line of a result that says its standard errors are lower
bounds.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["BLOCK_FFT", "EXACT_SHARE", "LOWER_BOUND_FACTOR", "ResidualCorrelation",
           "bartlett_sum", "bartlett_weights", "lower_bound_note", "newey_west_lags",
           "regression_lags", "white_noise_variance", "widest_covariance"]


#: Differences whose scatter measures a record's white noise (:func:`white_noise_variance`):
#: the third, which take a smooth error down to its jerk times the step cubed and white
#: noise to ``20 sigma^2``
NOISE_DIFFERENCES = 3


def white_noise_variance(parts: NDArray[np.float64] | list[NDArray[np.float64]],
                         robust: bool = True) -> float:
    """The variance of a signal's white noise, from its third differences: one estimate
    for every part of motionhyst that needs a record's noise (the standard errors of an
    input-output fit, ``predict``'s error, a closed-loop record's passivity check,
    ``predict --init-from``'s same-run check).

    A residual (or a measured signal) is noise plus something smooth: a simulated stage's
    error, a force sampled well above its bandwidth.  The smooth part's third differences
    are its jerk times the step cubed, far below its size, while white noise's have
    ``20 sigma^2`` (``C(6, 3)``).  With `robust` (the default) their median absolute
    deviation is taken, which keeps a few steps out (a slider sticking a sample early);
    without, their mean square, which counts every fast move as noise (a controller's fast
    action on a closed loop's force: an upper estimate, what a check that must not refuse
    noise needs).  A record's quantisation (an encoder's step ``q``: ``q^2 / 12``) counts
    as its noise.

    Parameters
    ----------
    parts : ndarray or list of ndarray
        The signal [any unit], or several records' (each differenced on its own; a part
        of 3 samples or fewer does not count).
    robust : bool
        The median absolute deviation (default) rather than the mean square.

    Returns
    -------
    float
        ``sigma^2`` [the signal's unit squared] (0 for records too short).

    Examples
    --------
    A model's error of 100 um, slow, and 1 um of white noise: the noise is found.

    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(5000) / 1000.0
    >>> smooth = 1e-4 * np.sin(2 * np.pi * 3 * t)
    >>> e = smooth + 1e-6 * rng.standard_normal(t.size)
    >>> round(float(np.sqrt(white_noise_variance(e))) * 1e6, 2)
    1.0
    >>> round(float(np.sqrt(white_noise_variance([e[:2500], e[2500:]], robust=False))) * 1e6, 2)
    1.0
    """
    k = NOISE_DIFFERENCES
    if isinstance(parts, np.ndarray) and parts.ndim == 1:
        parts = [parts]
    d = [np.diff(np.asarray(r, dtype=float), k) for r in parts if len(r) > k]
    if not d:
        return 0.0
    d = np.concatenate(d)
    if not robust:
        return float(np.mean(d ** 2)) / math.comb(2 * k, k)
    mad = float(np.median(np.abs(d - np.median(d))))
    return (1.4826 * mad) ** 2 / math.comb(2 * k, k)


#: Points of the spectra of a block of samples in :func:`bartlett_sum` (a few MB a column,
#: whatever the record's length)
BLOCK_FFT = 1 << 15


def bartlett_sum(rows: NDArray[np.float64] | Callable[[int, int], NDArray[np.float64]],
                 weights: NDArray[np.float64], n: int | None = None) -> NDArray[np.float64]:
    """``sum_t D_t^T D_t + sum_l k_l sum_t (D_{t+l}^T D_t + D_t^T D_{t+l})``, ``l = 1, ..., L``,
    over one record's rows ``D_t``: the Newey-West sum that every standard error of
    motionhyst robust to the residuals' correlation takes (one implementation).

    With ``D_t`` a regression's scores (regressors times residual, ``x_t e_t``) and ``k_l``
    the Bartlett weights ``1 - l / (L + 1)`` (:func:`bartlett_weights`) it is Newey and
    West's meat (:func:`~motionhyst.identify.io_checks.robust_least_squares`, the one-stage
    check's sums, :func:`~motionhyst.identify.io_consistency.check_one_stage`); with ``D_t``
    a Jacobian's rows and ``k_l`` the residuals' weighted autocorrelation it is
    ``J^T Omega J`` (:meth:`ResidualCorrelation.inner`).  In blocks of samples, each with
    the ``L`` after it, by FFT (:data:`BLOCK_FFT` points at most, unless ``4 L`` is more):
    a product for each lag took minutes on a record of millions of samples.

    Parameters
    ----------
    rows : ndarray or callable
        ``D``, one row a sample, or a function of ``(start, stop)`` giving its rows
        ``start .. stop - 1`` (a record whose rows are made block by block: its memory
        is a block's, not the record's).
    weights : ndarray
        ``k_1 .. k_L``.
    n : int, optional
        The rows' number (required with a callable).

    Returns
    -------
    ndarray
        The symmetric ``p x p`` sum.

    Examples
    --------
    The same as a product for each lag:

    >>> rng = np.random.default_rng(0)
    >>> D = rng.standard_normal((500, 3))
    >>> w = bartlett_weights(4)
    >>> direct = D.T @ D + sum(w[l - 1] * (D[l:].T @ D[:-l] + D[:-l].T @ D[l:])
    ...                        for l in range(1, 5))
    >>> bool(np.allclose(bartlett_sum(D, w), direct))
    True
    """
    if not callable(rows):
        data = np.asarray(rows, dtype=np.float64)
        n = data.shape[0]

        def rows(start: int, stop: int) -> NDArray[np.float64]:
            return data[start:stop]
    if not n:
        p = np.asarray(rows(0, 0)).shape[-1]
        return np.zeros((p, p))
    weights = np.asarray(weights, dtype=np.float64)
    lags = weights.size
    size = min(max(BLOCK_FFT, 1 << (4 * lags).bit_length()), 1 << (n + 2 * lags).bit_length())
    block = size - 2 * lags - 1  # a block and its lags convolved with the weights: no wrap
    kernel = np.fft.rfft(np.concatenate([[0.0], weights]), size) if lags else None
    out = np.zeros(0)
    for s in range(0, n, block):
        e = min(n, s + block)
        f = min(n, e + lags)
        D = np.asarray(rows(s, f), dtype=np.float64).T
        head = D[:, :e - s]
        out = head @ head.T if s == 0 else out + head @ head.T
        if lags > 0:  # sum over l of k_l D[t + l] D[t]^T, and its transpose
            ahead = np.fft.irfft(np.fft.rfft(D[:, ::-1], size) * kernel, size)
            lag = ahead[:, f - e:f - s][:, ::-1] @ head.T
            out += lag + lag.T
    return (out + out.T) / 2


def bartlett_weights(lags: int) -> NDArray[np.float64]:
    """The Bartlett kernel's weights ``1 - l / (L + 1)``, ``l = 1, ..., L`` (Newey and West,
    Econometrica 55, 703-708, 1987: weights that keep the sum positive semi-definite).

    Parameters
    ----------
    lags : int
        ``L``.

    Returns
    -------
    ndarray

    Examples
    --------
    >>> bartlett_weights(3).tolist()
    [0.75, 0.5, 0.25]
    """
    return 1.0 - np.arange(1, lags + 1) / (lags + 1.0)


def regression_lags(n: int, window: int) -> int:
    """The fixed lag count of :func:`newey_west_lags`: ``max(4 n^(1/3), window)``, at most
    ``n - 1``.

    The rule the inverse dynamics' checks were measured with (a record without inertia, a
    mass of another stage, friction by direction; the one-stage check: none of 3618 pairs of
    the EMPS record's windows refused), and the floor of every Newey-West standard error:
    a residual whose autocovariance turns negative at long lags (a slow record's periodic
    model error) sums to less over Andrews' longer bandwidth, and a standard error over it
    alone narrowed below this rule's (a good record refused as no inertia: 1.33 +- 0.019 kg,
    0.11 with this rule).  `window` is the derivative filter's length: the rates are
    correlated over it whatever the residuals.

    Parameters
    ----------
    n : int
        The record's samples.
    window : int
        The fewest lags.

    Returns
    -------
    int

    Examples
    --------
    >>> regression_lags(2500, 11), regression_lags(1000, 60), regression_lags(20, 60)
    (54, 60, 19)
    """
    return max(min(n - 1, max(int(4 * n ** (1 / 3)), window)), 0)


#: Andrews' (1991) constant of the Bartlett kernel's bandwidth, ``1.1447 (alpha N)^(1/3)``
BARTLETT_BANDWIDTH = 1.1447
#: The residuals' autocovariance is summed over at most this share of a record's samples:
#: beyond, a series whose mean the fit took out (an offset's column) sums to nothing
MAX_LAG_SHARE = 0.25


def newey_west_lags(parts: list[NDArray[np.float64]], window: int = 0) -> tuple[int, int, int]:
    """The lags of every Newey-West sum of motionhyst, one rule for every route (a fit's
    standard errors, :class:`ResidualCorrelation`; the inverse dynamics' checks,
    :func:`~motionhyst.identify.io_checks.robust_least_squares` and
    :func:`~motionhyst.identify.io_consistency.check_one_stage`): three lag counts, each
    standard error the widest of the three (:func:`widest_covariance`).

    ``0``: the residuals taken as white, the usual standard errors.  The fixed
    :func:`regression_lags` of all the records' samples, at most the shortest record's less
    one.  Andrews' (Econometrica 59, 817-858, 1991) bandwidth of the Bartlett kernel for a
    first-order autoregression of the residuals, ``1.1447 (alpha N)^(1/3)``,
    ``alpha = (2 rho / (1 - rho^2))^2`` (``rho`` their lag-one autocorrelation pooled over
    the records, ``N`` their samples), at least `window`, at most :data:`MAX_LAG_SHARE` of
    the shortest record: the lags grow with how long the residuals stay correlated (a
    regression under AR(1) residuals, ``rho`` 0.99, 25,000 samples: 4 n^(1/3) = 116 lags put
    the truth within 3 standard errors in 90 % of draws, Andrews' 700-odd in 98 %).  None of
    them alone is safe: Andrews' longer sum takes in the negative autocovariances of a
    periodic model error and narrows the standard error below the white residuals' or the
    fixed rule's.  The widest of the three never does.

    Parameters
    ----------
    parts : list of ndarray
        Each record's residuals, in time order.
    window : int
        The fewest lags of the fixed rule and of Andrews' (a derivative filter's length).

    Returns
    -------
    tuple of int
        ``(0, fixed, Andrews)`` (zeros for no samples).

    Examples
    --------
    White residuals: Andrews' rule takes a few lags, the fixed one ``4 N^(1/3)``; a
    first-order autoregression of ``rho = 0.95`` over 25,000 samples: 245.

    >>> from scipy.signal import lfilter
    >>> e = np.random.default_rng(0).standard_normal(25000)
    >>> newey_west_lags([e]), newey_west_lags([e], 11)
    ((0, 116, 2), (0, 116, 11))
    >>> newey_west_lags([lfilter([1.0], [1.0, -0.95], e)])
    (0, 116, 245)
    """
    sizes = [np.asarray(p).size for p in parts]
    if not sizes or not min(sizes):
        return 0, 0, 0
    n, shortest = sum(sizes), min(sizes)
    rho = _lag_one(parts)
    alpha = (2.0 * rho / (1.0 - rho * rho)) ** 2
    bandwidth = max(math.ceil(BARTLETT_BANDWIDTH * (alpha * n) ** (1 / 3)), window)
    fixed = min(regression_lags(n, window), shortest - 1)
    return 0, max(fixed, 0), max(min(bandwidth, int(MAX_LAG_SHARE * shortest)), 0)


def _lag_one(parts: list[NDArray[np.float64]]) -> float:
    """The residuals' lag-one autocorrelation pooled over the records (within +-0.999999)."""
    g0 = sum(float(np.dot(p, p)) for p in parts)
    g1 = sum(float(np.dot(p[1:], p[:-1])) for p in parts if np.asarray(p).size > 1)
    return min(max(g1 / g0, -0.999999), 0.999999) if g0 > 0 else 0.0


def widest_covariance(covs: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    """One covariance from those of the lag counts of :func:`newey_west_lags`: each variance
    the largest of them, the correlations those of the last (Andrews' lags, in that
    function's order), so that no standard error is narrower than white residuals' or the
    fixed rule's.

    The largest variance of each parameter, not of every combination: a check that judges
    a combination (:func:`~motionhyst.identify.io_consistency.check_one_stage`'s mass with
    another record's spring) takes the largest of its variances over the lag counts itself.

    Parameters
    ----------
    covs : list of ndarray
        The ``p x p`` covariances, the last's correlations kept.

    Returns
    -------
    ndarray
        ``D C D``, ``C`` the last covariance, ``D`` the diagonal that makes its variances
        the largest; positive semi-definite where ``C`` is (a parameter whose variance in
        ``C`` is 0 keeps the largest, uncorrelated).

    Examples
    --------
    >>> white = np.array([[4.0, 1.0], [1.0, 1.0]])
    >>> longer = np.array([[1.0, -0.5], [-0.5, 9.0]])
    >>> widest_covariance([white, longer]).tolist()
    [[4.0, -1.0], [-1.0, 9.0]]
    """
    covs = [np.asarray(c, dtype=np.float64) for c in covs]
    top = np.max([np.diag(c) for c in covs], axis=0)
    last = np.diag(covs[-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(last > 0, np.sqrt(top / np.where(last > 0, last, 1.0)), 0.0)
    out = covs[-1] * np.outer(scale, scale)
    np.fill_diagonal(out, top)
    return out


class ResidualCorrelation:
    """The residuals' autocorrelation, for standard errors that do not take them for white
    noise.

    The usual ``sigma^2 (J^T J)^-1`` holds when the residuals are independent.  Noise
    that is coloured (a closed-loop record's force noise through its prefilter, a
    force's noise through a stage) or a model's error (a search that stopped short) is
    correlated from sample to sample, and there are fewer independent samples than
    rows: the estimates' covariance is the sandwich
    ``(J^T J)^-1 J^T Omega J (J^T J)^-1`` with ``Omega`` the residuals' covariance.
    It is taken Toeplitz within each record (a stationary residual) with the
    residuals' own autocovariance ``gamma_l``, pooled over the records, weighted by the
    Bartlett kernel ``1 - l / (B + 1)`` up to lag ``B`` (Newey and West, Econometrica 55,
    703-708, 1987: a weighting that keeps ``Omega`` positive semi-definite), for each ``B``
    of :func:`newey_west_lags` (none, the fixed rule's, Andrews'): the standard errors are
    the widest they give (:func:`widest_covariance`).  White residuals give the usual
    standard errors within the fixed rule's scatter (a few per cent).

    Parameters
    ----------
    parts : list of ndarray
        Each record's residuals, in time order (the rows of ``J``, record by record).

    Attributes
    ----------
    rules : tuple of int
        The lag counts (:func:`newey_west_lags`).
    lags : int
        The most of them.
    kernels : list of ndarray
        For each, ``w_l gamma_l / gamma_0``, ``l = 0 .. B``.

    Examples
    --------
    White residuals: the usual standard error of a mean, the fixed rule's scatter above it
    (6 % in this draw); a first-order autoregression with ``rho = 0.9``:
    ``sqrt((1 + rho) / (1 - rho)) = 4.4`` times wider.

    >>> rng = np.random.default_rng(0)
    >>> e = rng.standard_normal(20000)
    >>> J = np.ones((20000, 1)) / np.sqrt(20000)
    >>> white = ResidualCorrelation([e])
    >>> white.rules, [round(float(np.sqrt(c[0, 0])), 2) for c in white.inners(J)]
    ((0, 108, 1), [1.0, 1.06, 1.0])
    >>> from scipy.signal import lfilter
    >>> ar = ResidualCorrelation([lfilter([1.0], [1.0, -0.9], e)])
    >>> round(float(np.sqrt(max(c[0, 0] for c in ar.inners(J)))), 1)
    4.4
    """

    def __init__(self, parts: list[NDArray[np.float64]]) -> None:
        parts = [np.asarray(p, dtype=float) for p in parts]
        self.sizes = [p.size for p in parts]
        self.rho = _lag_one(parts)
        self.rules = newey_west_lags(parts)
        self.lags = max(self.rules)
        gamma = np.zeros(self.lags + 1)
        for p in parts:
            if p.size == 0:
                continue
            spec = np.fft.rfft(p, 2 * p.size)
            acov = np.fft.irfft(spec * np.conj(spec), 2 * p.size)[:p.size]
            m = min(self.lags + 1, p.size)
            gamma[:m] += acov[:m]
        self.kernels = []
        for lags in self.rules:
            weights = np.concatenate([[1.0], bartlett_weights(lags)])
            self.kernels.append(weights * gamma[:lags + 1] / gamma[0] if gamma[0] > 0
                                else np.eye(1, lags + 1)[0])

    def inners(self, U: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """``U^T C U`` for each lag count, ``C`` the residuals' weighted autocorrelation
        (Toeplitz within each record, its diagonal 1): ``U^T U`` for white residuals.

        Parameters
        ----------
        U : ndarray
            A matrix whose rows are the residuals' (record by record).

        Returns
        -------
        list of ndarray
            ``U^T C U``, one for each of :attr:`rules`.
        """
        U = np.asarray(U, dtype=float)
        out = []
        for kernel in self.kernels:
            if kernel.size == 1:
                out.append(U.T @ U)
                continue
            total = np.zeros((U.shape[1], U.shape[1]))
            a = 0
            for size in self.sizes:  # each record's own sum (:func:`bartlett_sum`)
                total += bartlett_sum(U[a:a + size], kernel[1:])
                a += size
            out.append(total)
        return out


#: A fit that leaves more than this many times its records' white noise (RMS) leaves
#: residuals that are not that noise: model error or coloured noise
LOWER_BOUND_FACTOR = 1.5

#: A fit that leaves at most this share of its records' RMS fits them to the precision of
#: its arithmetic (records without noise: their standard errors say nothing either way)
EXACT_SHARE = 1e-9


def lower_bound_note(fit_rms: float, noise_rms: float, widened: float, lags: int,
                     unit: str, signal_rms: float = 0.0) -> str | None:
    """Why a fit's standard errors are lower bounds (one line of its result), or None.

    Standard errors say how far noise moves the estimates.  A fit whose residuals are
    more than :data:`LOWER_BOUND_FACTOR` times the records' white noise (its RMS from
    their third differences, :func:`white_noise_variance`) leaves something else: the
    model's error (a search that stopped in another well, a link or plant that is not
    the records') or noise that is not white.  The residuals' correlation widens the
    standard errors (:class:`ResidualCorrelation`), but a model's error is not noise and
    moves the estimates by more than any spread of the residuals says: the standard
    errors are then lower bounds.  Such a fit is a result (a measured axis's model error
    is thousands of times its encoder's noise), not a failure: the line is part of the
    result (its table marks the standard errors ``>=``), not a warning.

    Parameters
    ----------
    fit_rms : float
        The fit's RMS residual.
    noise_rms : float
        The records' white noise (RMS) in the residuals' unit.
    widened : float
        How many times the residuals' correlation widened the standard errors (the most).
    lags : int
        The most lags over which it was summed (:attr:`ResidualCorrelation.lags`).
    unit : str
        The residuals' unit.
    signal_rms : float
        The records' RMS: a fit within :data:`EXACT_SHARE` of it is exact (noise-free
        records), not said.

    Returns
    -------
    str or None
        One line naming the cause; None when the fit leaves the noise, or nothing.

    Examples
    --------
    >>> lower_bound_note(1.02e-7, 1e-7, 1.01, 2, "m") is None
    True
    >>> lower_bound_note(1.3e-6, 1e-7, 3.2, 140, "m")[:89]
    "standard errors are lower bounds: the fit leaves 13 times its records' white noise (1e-07"
    """
    if not (fit_rms > LOWER_BOUND_FACTOR * noise_rms and fit_rms > EXACT_SHARE * signal_rms):
        return None
    what = (f"leaves {fit_rms / noise_rms:.2g} times its records' white noise "
            f"({noise_rms:.2g} {unit})" if noise_rms > 0 else
            f"leaves {fit_rms:.2g} {unit} RMS where its records have no white noise")
    wider = (f"; widened {widened:.2g} times for the residuals' correlation over up to {lags} "
             f"samples (Newey-West)" if widened > 1.05 else "")
    return (f"standard errors are lower bounds: the fit {what}, model error (a search that "
            f"stopped short, a link or plant unlike the records') or noise that is not "
            f"white{wider}")
