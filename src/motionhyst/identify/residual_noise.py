"""The records' noise in a fit's residuals: how much of it is white, how it is correlated
from sample to sample, and what that says of the fit's standard errors.

:func:`white_noise_variance` (the third differences' scatter) is the one estimate of a
signal's white noise that every part uses (the input-output standard errors, ``predict``'s
error, a closed-loop record's passivity check, ``predict --init-from``'s same-run check);
:func:`bartlett_sum` the one Newey-West sum of every standard error robust to the
residuals' correlation (the inverse dynamics' checks over :func:`regression_lags`, a fit's
over :class:`ResidualCorrelation`'s bandwidth);
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
           "bartlett_sum", "bartlett_weights", "lower_bound_note", "regression_lags",
           "white_noise_variance"]


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
    """The lags of a linear regression's Newey-West sum (the inverse dynamics' checks:
    :func:`~motionhyst.identify.io_checks.robust_least_squares`,
    :func:`~motionhyst.identify.io_consistency.check_one_stage`): ``max(4 n^(1/3), window)``,
    at most ``n - 1``.

    A fixed rule, not :class:`ResidualCorrelation`'s Andrews bandwidth: the thresholds of
    the decisions these regressions make (a record without inertia, a mass of another
    stage, friction by direction) were measured with it (the one-stage check: none of 3618
    pairs of the EMPS record's windows refused).  Andrews' rule on their residuals (a linear
    model's error of a link's force, ``rho`` 0.89-0.95) would sum over more lags: 64-80
    for 54 on a 2500-sample Jenkins axis, 248 for 116 on the EMPS record.  `window` is the
    derivative filter's length: the rates are correlated over it whatever the residuals.

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
    703-708, 1987: a weighting that keeps ``Omega`` positive semi-definite); ``B`` is
    Andrews' (Econometrica 59, 817-858, 1991) for a first-order autoregression of the
    residuals, ``1.1447 (alpha N)^(1/3)``, ``alpha = (2 rho / (1 - rho^2))^2``, at most
    :data:`MAX_LAG_SHARE` of the shortest record.  White residuals give ``B`` of a few
    samples and the usual standard errors within their own scatter.

    Parameters
    ----------
    parts : list of ndarray
        Each record's residuals, in time order (the rows of ``J``, record by record).

    Attributes
    ----------
    lags : int
        ``B``.
    kernel : ndarray
        ``w_l gamma_l / gamma_0``, ``l = 0 .. B``.

    Examples
    --------
    White residuals: one or two lags, the usual standard errors; a first-order
    autoregression with ``rho = 0.9``: ``sqrt((1 + rho) / (1 - rho)) = 4.4`` times wider
    for a mean.

    >>> rng = np.random.default_rng(0)
    >>> e = rng.standard_normal(20000)
    >>> J = np.ones((20000, 1))
    >>> white = ResidualCorrelation([e])
    >>> white.lags <= 3, round(float(np.sqrt(white.inner(J / np.sqrt(20000))[0, 0])), 1)
    (True, 1.0)
    >>> from scipy.signal import lfilter
    >>> ar = ResidualCorrelation([lfilter([1.0], [1.0, -0.9], e)])
    >>> round(float(np.sqrt(ar.inner(J / np.sqrt(20000))[0, 0])), 1)
    4.4
    """

    def __init__(self, parts: list[NDArray[np.float64]]) -> None:
        parts = [np.asarray(p, dtype=float) for p in parts]
        self.sizes = [p.size for p in parts]
        n = sum(self.sizes)
        g0 = sum(float(p @ p) for p in parts)
        g1 = sum(float(p[1:] @ p[:-1]) for p in parts if p.size > 1)
        rho = min(max(g1 / g0, -0.999999), 0.999999) if g0 > 0 else 0.0
        alpha = (2.0 * rho / (1.0 - rho * rho)) ** 2
        most = int(MAX_LAG_SHARE * min(self.sizes)) if self.sizes else 0
        self.lags = max(min(math.ceil(BARTLETT_BANDWIDTH * (alpha * n) ** (1 / 3)), most), 0)
        gamma = np.zeros(self.lags + 1)
        for p in parts:
            if p.size == 0:
                continue
            spec = np.fft.rfft(p, 2 * p.size)
            acov = np.fft.irfft(spec * np.conj(spec), 2 * p.size)[:p.size]
            m = min(self.lags + 1, p.size)
            gamma[:m] += acov[:m]
        weights = np.concatenate([[1.0], bartlett_weights(self.lags)])
        self.kernel = weights * gamma / gamma[0] if gamma[0] > 0 else np.eye(1, self.lags + 1)[0]
        self.rho = rho

    def inner(self, U: NDArray[np.float64]) -> NDArray[np.float64]:
        """``U^T C U`` with ``C`` the residuals' weighted autocorrelation (Toeplitz within
        each record, its diagonal 1): ``U^T U`` for white residuals.

        Parameters
        ----------
        U : ndarray
            A matrix whose rows are the residuals' (record by record).

        Returns
        -------
        ndarray
            ``U^T C U``.
        """
        U = np.asarray(U, dtype=float)
        if self.lags == 0:
            return U.T @ U
        out = np.zeros((U.shape[1], U.shape[1]))
        a = 0
        for size in self.sizes:  # each record's own sum (:func:`bartlett_sum`)
            out += bartlett_sum(U[a:a + size], self.kernel[1:])
            a += size
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
        The lags over which it was summed (:attr:`ResidualCorrelation.lags`).
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
    wider = (f"; widened {widened:.2g} times for the residuals' correlation over {lags} "
             f"samples (Newey-West)" if widened > 1.05 else "")
    return (f"standard errors are lower bounds: the fit {what}, model error (a search that "
            f"stopped short, a link or plant unlike the records') or noise that is not "
            f"white{wider}")
