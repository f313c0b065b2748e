"""The records' noise in a fit's residuals: how much of it is white, how it is correlated
from sample to sample, and what that says of the fit's standard errors.

:func:`white_noise_variance` (the third differences' scatter) is the one estimate of a
signal's white noise that every part uses (the input-output standard errors, ``predict``'s
error, a closed-loop record's passivity check, ``predict --init-from``'s same-run check);
:class:`ResidualCorrelation` the residuals' autocorrelation that the standard errors'
sandwich takes (:func:`~motionhyst.identify.io_uncertainty.correlated_errors`);
:func:`lower_bound_note` the line of a result that says its standard errors are lower
bounds.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["EXACT_SHARE", "LOWER_BOUND_FACTOR", "ResidualCorrelation", "lower_bound_note",
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
        weights = 1.0 - np.arange(self.lags + 1) / (self.lags + 1.0)
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
        from scipy.signal import oaconvolve

        U = np.asarray(U, dtype=float)
        if self.lags == 0:
            return U.T @ U
        k = np.concatenate([self.kernel[:0:-1], self.kernel])
        out = np.zeros((U.shape[1], U.shape[1]))
        a = 0
        for size in self.sizes:  # a column at a time: memory of a record, not of U
            block = U[a:a + size]
            for j in range(block.shape[1]):
                out[:, j] += block.T @ oaconvolve(block[:, j], k, mode="same")
            a += size
        return (out + out.T) / 2


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
