"""What input-output records determine: standard errors and the parameters they do not.

From the Jacobian ``J`` of the simulation residuals at the optimum, standard
errors ``sqrt(diag(sigma^2 (J^T J)^-1))`` with ``sigma^2 = RSS / (N - p)``,
a direction of ``J`` with a singular value below :data:`SINGULAR_RTOL` of the
largest (:data:`FD_SINGULAR_RTOL` for a finite-difference Jacobian) being one
the data do not determine (:func:`standard_errors`); where each record's initial state
is set from its first samples (an initialisation window), the noise of those samples
moves every residual after them, and the covariance is the sandwich of
:class:`WindowNoise`.  The covariance whose
diagonal they are the square roots of (:func:`covariance`; ``identify --json`` and
``--save`` carry it for a Monte-Carlo study: :func:`covariance_table`,
:func:`identification_toml`), and the notes that say so (:func:`undetermined_notes`,
:func:`weak_notes`).

The rule for what a fit does with a parameter the records do not determine (its standard
error not finite, or above :data:`UNDETERMINED_FACTOR` times its value: its one-sigma range
reaches zero) is :func:`judge_determined`: a warning naming it (the model holds its search
value, which the records neither confirm nor contradict); when they are more than
:data:`UNDETERMINED_SHARE` of the model's physical parameters, a failed fit, nothing saved
(the model is one of many that fit the records as well: it cannot predict); an offset or
initial state that is not distinguishable from 0 is neither (0 is a value the records
allow).
"""

from __future__ import annotations

import json
import math
import textwrap
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.residual_noise import (
    ResidualCorrelation,
    lower_bound_note,
    white_noise_variance,
    widest_covariance,
)

__all__ = ["AT_ZERO", "BOUC_WEN_SCALE", "UNDETERMINED_FACTOR", "UNDETERMINED_SHARE",
           "WINDOW_INFLATION", "CorrelatedErrors", "WindowNoise", "correlated_errors",
           "judge_determined", "parallel_note", "simpler_link", "undetermined", "widened_note",
           "window_inflation", "zero_allowed"]

SINGULAR_RTOL = 1e-8
BOUC_WEN_IDENTIFIED = ("alpha", "beta*gamma", "beta*delta", "nu")
"""A Bouc-Wen link's parameters an identification estimates: ``beta`` alone is not
determined (``z`` is not measured), only the products ``beta*gamma`` and ``beta*delta`` (the
saved link has ``|gamma| + |delta| = 1``); a saved identification names them
``hysteresis.beta*gamma``, ... (a study draws them and sets ``beta``, ``gamma``, ``delta``)."""
FD_SINGULAR_RTOL = 1e-5  # finite-difference Jacobians (step 1e-6) are no more exact than this
#: A parameter whose standard error exceeds this factor times its value (its one-sigma range
#: reaches zero, a sign the records do not fix) is not determined by the records
UNDETERMINED_FACTOR = 1.0
#: A Bouc-Wen link in the normalised form ``w = fc zeta`` (eq. 2 of
#: :class:`~motionhyst.hysteresis.BoucWen`) enters the force only through ``beta / fc^n`` and
#: ``gamma / fc^n``: scaling these three together changes no output, whatever the record
BOUC_WEN_SCALE = ("link.fc", "link.beta", "link.gamma")
#: A fit that leaves more than this share of its physical parameters (the stage's and the
#: link's) not determined is not a model: the records hold less than it asks
UNDETERMINED_SHARE = 0.5
#: A parameter whose range holds 0 and whose estimate is below this share of the fit's largest
#: estimate ended at 0 (a damper the records do not show)
AT_ZERO = 1e-12
#: Parameters that may be zero or of either sign: offsets, drifts, initial states, the
#: viscous friction's difference by direction, a Bouc-Wen link's shape products
_SIGNED = ("offset", "drift", "y0", "v0", "c_skew", "beta*")


class WindowNoise:
    """How the noise of the measured positions reaches the residuals of a fit whose records'
    initial states are set from their first samples (an initialisation window).

    Record ``i``'s state ``s_i`` (its position and velocity at the first sample) is the
    least-squares fit of the model's run to its first ``N`` measured positions, so it
    moves with their noise: ``d s_i = B_i e_w`` with ``B_i = (S_w^T S_w)^-1 S_w^T``,
    ``S = d y / d s_i`` (the run's sensitivity to the state) and ``S_w`` its first ``N``
    rows.  A residual is then ``r = J dtheta - L e`` with ``L = I - S B`` (block by
    record): the window's noise moves every residual of the record after it, as much as
    the state's error carries (a velocity error of a floating stage integrates into a
    position error for as long as the stage slides).  The least-squares estimate
    ``dtheta = (J^T J)^-1 J^T L e`` has the covariance
    ``sigma_n^2 (J^T J)^-1 J^T L L^T J (J^T J)^-1`` when the residuals are the records'
    noise (variance ``sigma_n^2``; ``L = I``: the usual ``sigma^2 (J^T J)^-1``).  When
    they are mostly the model's error (a measured axis: EMPS's fit RMS is 0.45 mm, its
    encoder's noise 0.02 um), that error is not what the window's samples carry into the
    state; with the positions' own noise ``sigma_n^2`` (`sigma2`,
    :func:`~motionhyst.identify.residual_noise.white_noise_variance`: their residuals' sum of
    squares would take the model's
    error for noise, and the few samples of a short window make it scatter) the covariance
    is

    .. math::

        \\sigma_r^2 (J^T J)^{-1} + \\sigma_n^2 (J^T J)^{-1} J^T (L L^T - I) J (J^T J)^{-1},
        \\qquad \\sigma_r^2 = \\max\\left(\\frac{RSS - \\sigma_n^2 (\\lVert (I - H) L
        \\rVert_F^2 - (N - p))}{N - p}, \\sigma_n^2\\right),

    the first term the usual one for the residuals less what the window's noise adds to
    them in expectation (``H`` the projection on the columns of ``J``), the second what
    that noise moves the estimates by; residuals that are the noise alone give the
    sandwich.

    Parameters
    ----------
    n_rows : int
        The residuals' rows, all records.
    parts : list of (int, ndarray, ndarray)
        For each record, its first row, ``S`` (its rows by the state's columns) and ``B``
        (the state's columns by the window's rows).
    sigma2 : float
        The measured positions' noise variance [m^2].

    Examples
    --------
    A constant measured over 20 samples, its value set from the first 2: their noise
    shifts all 20 residuals together.

    >>> S = np.ones((20, 1))
    >>> noise = WindowNoise(20, [(0, S, np.full((1, 2), 0.5))], 1e-12)
    >>> round(noise.frobenius2(), 6)                    # ||L||^2 = 20 - 2 + 20 * 0.5
    28.0
    >>> X = np.linspace(0.0, 1.0, 20)[:, None]
    >>> np.allclose(noise.left(X), X.T - X.T @ S @ np.array([[0.5, 0.5] + [0.0] * 18]))
    True
    """

    def __init__(self, n_rows: int, parts: list[tuple[int, NDArray[np.float64],
                                                      NDArray[np.float64]]],
                 sigma2: float) -> None:
        self.n_rows = int(n_rows)
        self.parts = [(int(a), np.asarray(S, float), np.asarray(B, float)) for a, S, B in parts]
        self.sigma2 = float(sigma2)

    def left(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """``X^T L`` for ``X`` of `n_rows` rows.

        Parameters
        ----------
        X : ndarray
            A matrix of `n_rows` rows.

        Returns
        -------
        ndarray
            ``X^T L``.
        """
        out = np.array(X, dtype=float).T.copy()
        for a, S, B in self.parts:
            rows = slice(a, a + S.shape[0])
            out[:, a:a + B.shape[1]] -= (out[:, rows] @ S) @ B
        return out

    def residual_variance(self, W: NDArray[np.float64], rss: float, dof: int) -> float:
        """``sigma_r^2``: the residuals' variance less what the window's noise adds to them
        in expectation, at least that noise (``W = U^T L``, ``U`` the Jacobian's left
        singular vectors; `dof` ``N - p``).

        Parameters
        ----------
        W : ndarray
            ``U^T L``.
        rss : float
            The fit's residual sum of squares.
        dof : int
            Its degrees of freedom, ``N - p``.

        Returns
        -------
        float
            ``sigma_r^2``.
        """
        spread = self.frobenius2() - float(np.sum(W * W))  # E RSS / sigma_n^2, noise alone
        return max((rss - self.sigma2 * (spread - dof)) / max(dof, 1), self.sigma2)

    def states(self) -> NDArray[np.float64]:
        """The state's columns of every record, each in its own rows (zero elsewhere)."""
        cols = []
        for a, S, _ in self.parts:
            col = np.zeros((self.n_rows, S.shape[1]))
            col[a:a + S.shape[0]] = S
            cols.append(col)
        return np.hstack(cols) if cols else np.zeros((self.n_rows, 0))

    def velocity_std(self) -> float:
        """The largest standard deviation of a record's initial velocity as its window sets
        it [m/s] (the state's second column; 0 without one)."""
        return max((math.sqrt(self.sigma2 * float((B @ B.T)[1, 1])) for _, _, B in self.parts
                    if B.shape[0] > 1), default=0.0)

    def frobenius2(self) -> float:
        """``||L||_F^2``: ``n_rows - 2 tr(S B) + tr(S^T S B B^T)`` over the records."""
        total = float(self.n_rows)
        for _, S, B in self.parts:
            total += -2.0 * float(np.trace(B @ S[:B.shape[1]])) + float(
                np.sum((S.T @ S) * (B @ B.T)))
        return total


#: An initialisation window whose noise makes a parameter's standard error more than this
#: many times that with the records' states estimated from all their samples is said
WINDOW_INFLATION = 2.0


def _decomposed(J: NDArray[np.float64], rss: float, n_rows: int, rtol: float,
                noise: WindowNoise | None, correlation: ResidualCorrelation | None = None,
                spread: list[float] | None = None):
    """The normalised columns' scales, the covariance of the estimates in normalised
    coordinates over the determined directions (``sigma^2 V S^-2 V^T``; with `noise`,
    ``V S^-1 (sigma_r^2 I + sigma_n^2 (W W^T - I)) S^-1 V^T``, ``W = U^T L``) and the
    undetermined directions (rows of right singular vectors); with `correlation`, the
    residuals' part ``sigma^2 I`` is ``sigma^2 U^T C U``
    (:class:`~motionhyst.identify.residual_noise.ResidualCorrelation`) for each of its lag
    counts, each variance the largest
    (:func:`~motionhyst.identify.residual_noise.widest_covariance`);
    `spread`, if a list, receives ``E RSS / sigma_n^2`` of the window's noise alone."""
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    u, sv, vt = np.linalg.svd(J / norms, full_matrices=False)
    good = sv > rtol * sv[0]
    dof = max(n_rows - J.shape[1], 1)
    eye = np.eye(int(good.sum()))
    owns = [eye] if correlation is None else correlation.inners(u[:, good])
    vg = vt[good].T / sv[good]
    if noise is None:
        covs = [vg @ (rss / dof * own) @ vg.T for own in owns]
    else:
        if noise.n_rows != J.shape[0]:
            raise ValueError("the noise map's rows differ from the Jacobian's")
        W = noise.left(u[:, good])
        if spread is not None:
            spread.append(noise.frobenius2() - float(np.sum(W * W)))
        variance, window = noise.residual_variance(W, rss, dof), noise.sigma2 * (W @ W.T - eye)
        covs = [vg @ (variance * own + window) @ vg.T for own in owns]
    return norms, covs[0] if len(covs) == 1 else widest_covariance(covs), vt[~good]


class CorrelatedErrors(NamedTuple):
    """A fit's standard errors with its residuals' autocorrelation
    (:func:`correlated_errors`), and those white residuals would give.

    The first are the ones reported; the second judge whether a parameter is determined
    (:func:`weak_notes`, :func:`judge_determined`): that a fit leaves model error
    (coloured residuals) widens what it reports, not what the records determine.

    Parameters
    ----------
    std : ndarray
        The standard errors, NaN where not determined.
    groups : list of list of int
        The columns of each direction the data do not determine.
    cov : ndarray
        Their covariance (NaN rows and columns where not determined).
    note : str or None
        Why they are lower bounds (:func:`~motionhyst.identify.residual_noise.lower_bound_note`).
    white_cov : ndarray
        The covariance white residuals give (:func:`covariance`).

    Examples
    --------
    A mean of 1000 samples of white noise: the two standard errors agree (a few lags of
    scatter), nothing is said.

    >>> e = np.random.default_rng(0).standard_normal(1000)
    >>> out = correlated_errors(np.ones((1000, 1)), [e - e.mean()])
    >>> out.note is None, out.flags, round(float(out.std[0] / out.white_std[0]), 1)
    (True, {}, 1.0)
    """

    std: NDArray[np.float64]
    groups: list[list[int]]
    cov: NDArray[np.float64]
    note: str | None
    white_cov: NDArray[np.float64]

    @property
    def white_std(self) -> NDArray[np.float64]:
        """The standard errors white residuals give (NaN where not determined)."""
        return np.sqrt(np.maximum(np.diag(self.white_cov), 0.0))

    @property
    def flags(self) -> dict:
        """``{"std_lower_bound": True, "std_note": note}`` for a result's ``extra`` where
        the standard errors are lower bounds, else empty."""
        return {} if self.note is None else {"std_lower_bound": True, "std_note": self.note}


def correlated_errors(J: NDArray[np.float64], parts: list[NDArray[np.float64]],
                      rtol: float = SINGULAR_RTOL, noise: WindowNoise | None = None,
                      unit: str = "m", signal_rms: float = 0.0) -> CorrelatedErrors:
    """Standard errors, the groups the data cannot separate and the covariance
    (:func:`standard_errors`, :func:`covariance`) with the residuals' autocorrelation
    (:class:`~motionhyst.identify.residual_noise.ResidualCorrelation`), those of white
    residuals, and why they are lower bounds
    (:func:`~motionhyst.identify.residual_noise.lower_bound_note`: the fit leaves more than
    the records' white noise, or with an initialisation window's `noise`, more than that
    noise leaves in expectation; the residuals' correlation is then taken beyond the
    records' states, whose noise the window's sandwich counts).

    Parameters
    ----------
    J : ndarray
        The Jacobian of the residuals (rows: the records' residuals, record by record).
    parts : list of ndarray
        Each record's residuals, in time order.
    rtol : float
        Singular values below this share of the largest are not determined.
    noise : WindowNoise, optional
        An initialisation window's noise map.
    unit : str
        The residuals' unit.
    signal_rms : float
        The records' RMS (:func:`~motionhyst.identify.residual_noise.lower_bound_note`: a
        fit exact to it is not said).

    Returns
    -------
    CorrelatedErrors
        ``std, groups, cov, note, white_cov``.

    Examples
    --------
    A line fitted to a record whose noise is white, then to one whose noise is a
    first-order autoregression (``rho = 0.95``): the offset's standard error widens by
    about ``sqrt((1 + rho) / (1 - rho)) = 6.2``, and the fit leaves more than the white
    noise; the white residuals' standard error is the usual one.

    >>> from scipy.signal import lfilter
    >>> rng = np.random.default_rng(1)
    >>> t = np.linspace(0.0, 1.0, 5000)
    >>> J = np.column_stack([np.ones_like(t), t])
    >>> e = 1e-6 * rng.standard_normal(t.size)
    >>> out = correlated_errors(J, [e - J @ np.linalg.lstsq(J, e)[0]])
    >>> round(float(out.std[0] / (1e-6 * np.sqrt(4 / 5000))), 1), out.note is None
    (1.0, True)
    >>> c = lfilter([1.0], [1.0, -0.95], e)
    >>> out = correlated_errors(J, [c - J @ np.linalg.lstsq(J, c)[0]])
    >>> out.note[:65]
    'standard errors are lower bounds: the fit leaves 5.7 times its re'
    >>> out.note.split("widened ")[1][:3], round(float(out.std[0] / out.white_std[0]), 1)
    ('6.1', 6.1)
    """
    parts = [np.asarray(p, dtype=float) for p in parts]
    res = np.concatenate(parts)
    rss, n_rows = float(res @ res), res.size
    own = parts
    if noise is not None:  # what the window's noise moves along the states: its sandwich's
        X = noise.states()
        own = np.split(res - X @ np.linalg.lstsq(X, res, rcond=None)[0],
                       np.cumsum([p.size for p in parts])[:-1])
    corr = ResidualCorrelation(own)
    spread: list[float] = []
    norms, cov, bad = _decomposed(J, rss, n_rows, rtol, noise, corr, spread)
    groups = [list(np.nonzero(np.abs(row) > 1e-3)[0]) for row in bad]
    std = np.sqrt(np.maximum(np.diag(cov), 0.0)) / norms
    cov = cov / np.outer(norms, norms)
    cov = (cov + cov.T) / 2
    white_cov = covariance(J, rss, n_rows, rtol, noise)
    for row in bad:
        g = np.abs(row) > 1e-3
        cov[g, :] = np.nan
        cov[:, g] = np.nan
    for g in groups:
        std[g] = np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = std / np.sqrt(np.maximum(np.diag(white_cov), 0.0))
    widened = float(np.max(ratio[np.isfinite(ratio)], initial=1.0))
    # the noise's share of the residuals: white, or a window's carried after it
    noise_rms = (math.sqrt(noise.sigma2 * max(spread[0], 0.0) / n_rows) if spread
                 else math.sqrt(white_noise_variance(parts)))
    note = lower_bound_note(math.sqrt(rss / max(n_rows, 1)), noise_rms, widened, corr.lags,
                            unit, signal_rms)
    return CorrelatedErrors(std, groups, cov, note, white_cov)


def standard_errors(J: NDArray[np.float64], rss: float, n_rows: int,
                    rtol: float = SINGULAR_RTOL, noise: WindowNoise | None = None,
                    correlation: ResidualCorrelation | None = None
                    ) -> tuple[NDArray[np.float64], list[list[int]]]:
    """Standard errors of the parameters and the groups the data cannot separate.

    The columns of `J` are normalised; a right singular vector whose singular
    value is below `rtol` of the largest is a direction the data do not
    determine, and the parameters with a component above 1e-3 in it form a
    group (only other combinations of them are determined).  Their standard
    errors are NaN; the others come from the pseudo-inverse, with `noise` (an
    initialisation window's, :class:`WindowNoise`) its sandwich, with `correlation` (the
    residuals', :class:`~motionhyst.identify.residual_noise.ResidualCorrelation`) that of residuals
    that are not white.
    """
    norms, cov, bad = _decomposed(J, rss, n_rows, rtol, noise, correlation)
    groups = [list(np.nonzero(np.abs(row) > 1e-3)[0]) for row in bad]
    std = np.sqrt(np.maximum(np.diag(cov), 0.0)) / norms
    for g in groups:
        std[g] = np.nan
    return std, groups


def covariance(J: NDArray[np.float64], rss: float, n_rows: int, rtol: float = SINGULAR_RTOL,
               noise: WindowNoise | None = None,
               correlation: ResidualCorrelation | None = None) -> NDArray[np.float64]:
    """The covariance ``sigma^2 (J^T J)^+`` of the estimates whose diagonal's square roots
    :func:`standard_errors` gives (the same normalised columns, singular values and
    pseudo-inverse; with `noise`, `correlation` its sandwich); the rows and columns of the
    parameters it marks undetermined are NaN.
    """
    norms, cov, bad = _decomposed(J, rss, n_rows, rtol, noise, correlation)
    cov = cov / np.outer(norms, norms)
    cov = (cov + cov.T) / 2  # symmetric to the last bit (the product is so to round-off)
    for row in bad:
        g = np.abs(row) > 1e-3
        cov[g, :] = np.nan
        cov[:, g] = np.nan
    return cov


def window_inflation(J: NDArray[np.float64], rss: float, n_rows: int, rtol: float,
                     noise: WindowNoise) -> NDArray[np.float64]:
    """How many times the standard errors of a fit whose states its windows set
    (:func:`standard_errors` with `noise`) are those of the same records with each state
    estimated with the parameters from all their samples (``J`` with the states' columns,
    the same residual variance): the price of the window, column by column (NaN where
    either is not determined).

    Parameters
    ----------
    J : ndarray
        The fit's Jacobian (rows: residuals; columns: parameters).
    rss : float
        Its residual sum of squares.
    n_rows : int
        The residuals.
    rtol : float
        Singular values below this share of the largest are not determined.
    noise : WindowNoise
        The windows' noise map.

    Returns
    -------
    ndarray
        One ratio per column of `J` (NaN where either standard error is not determined).

    Examples
    --------
    A line's slope, its offset set from the first 2 of 200 samples (their mean) or
    estimated from all of them: the window's noise more than quadruples the slope's
    standard error.

    >>> t = np.linspace(0.0, 1.0, 200)
    >>> J = (t - t[:2].mean())[:, None]          # the slope's column, the offset set
    >>> noise = WindowNoise(200, [(0, np.ones((200, 1)), np.full((1, 2), 0.5))], 1.0)
    >>> round(float(window_inflation(J, 200.0, 200, SINGULAR_RTOL, noise)[0]), 2)
    4.38
    """
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    u, sv, _ = np.linalg.svd(J / norms, full_matrices=False)
    dof = max(n_rows - J.shape[1], 1)
    sigma2 = noise.residual_variance(noise.left(u[:, sv > rtol * sv[0]]), rss, dof)
    with_window, _ = standard_errors(J, rss, n_rows, rtol, noise)
    joint = np.column_stack([J, noise.states()])
    estimated, _ = standard_errors(joint, sigma2 * (n_rows - joint.shape[1]), n_rows, rtol)
    with np.errstate(invalid="ignore", divide="ignore"):
        return with_window / estimated[:J.shape[1]]


def window_price(J, rss: float, n_rows: int, rtol: float, noise: WindowNoise,
                 names: list[str], window: int) -> list[str]:
    """One line when the noise of the initialisation window's samples makes the standard
    error of one of the stage's or link's parameters (`names`, the first columns of `J`)
    more than :data:`WINDOW_INFLATION` times that with the records' states estimated from
    all their samples (:func:`window_inflation`); else none.  `window` is the window's
    samples."""
    ratio = window_inflation(J, rss, n_rows, rtol, noise)[:len(names)]
    ratio = np.where(np.isfinite(ratio), ratio, 0.0)
    worst = int(np.argmax(ratio)) if ratio.size else 0
    if not ratio.size or ratio[worst] <= WINDOW_INFLATION:
        return []
    return [f"the initialisation window's {window} samples set each record's initial state "
            f"with their noise (its velocity to +- {noise.velocity_std():.2g} m/s): the "
            f"standard errors are up to {ratio[worst]:.3g} times ({names[worst]}) those with "
            f"the state estimated from all the samples (identify without --init-window); a "
            f"longer window narrows them"]


def covariance_table(names: list[str], cov: NDArray[np.float64],
                     std: dict[str, float | None]) -> dict:
    """``{"parameters": [...], "matrix": [[...]]}``: the covariance of the parameters whose
    standard error is determined (`std` not None: the others' rows and columns are left
    out, which leaves the rest's covariance as it is, a marginal of the normal distribution).
    """
    keep = [i for i, n in enumerate(names) if std.get(n) is not None
            and math.isfinite(cov[i, i])]
    return {"parameters": [names[i] for i in keep],
            "matrix": [[float(cov[i, j]) for j in keep] for i in keep]}


def identification_toml(table: dict, estimates: dict[str, float], keys: dict[str, str],
                        record: str | None = None, lower_bound: str | None = None,
                        position_offset: float | None = None) -> str:
    """The ``[identification]`` table of a saved identification (TOML): the kind of `record`
    it was identified from (what ``predict`` predicts), the parameters of the covariance
    `table` (:func:`covariance_table`) that `keys` maps to scenario keys, under those keys,
    with their `estimates`, standard errors and correlations; the kind alone if none (empty
    without a kind).

    Standard errors and correlations rather than covariances: each is a number of the size
    of a parameter or within [-1, 1], whatever the units (a covariance of 1e-40 would be
    outside the magnitudes a scenario accepts); correlations are rounded to 1e-12.  With
    `lower_bound` (why they are lower bounds:
    :func:`~motionhyst.identify.residual_noise.lower_bound_note`) a comment says it, and that
    a study drawn from them understates the spread.  A `position_offset` [m] (the position
    sensor's zero that ``predict`` applies) is written after the kind.
    """
    names = [n for n in table.get("parameters", []) if n in keys]
    head = ("" if record is None else f"record = {json.dumps(record)}\n") + (
        "" if position_offset is None else f"position_offset = {float(position_offset)!r}\n")
    if not names:  # the record's kind alone: what predict predicts
        return f"[identification]\n{head}" if head else ""
    where = [table["parameters"].index(n) for n in names]
    cov = np.array(table["matrix"], dtype=float)[np.ix_(where, where)]
    std = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    corr = np.where(np.outer(std, std) > 0, np.clip(np.round((corr + corr.T) / 2, 12), -1, 1),
                    0.0)
    np.fill_diagonal(corr, 1.0)
    rows = "".join(f"    [{', '.join(repr(float(c)) for c in row)}],\n" for row in corr)
    said = textwrap.wrap(f"{lower_bound}; a study drawn from them understates the spread", 98)
    bound = "".join(f"# {line}\n" for line in said) if lower_bound else ""
    return ("# the estimates' standard errors and correlations (from the fit's Jacobian) for a "
            "Monte-Carlo\n# study: motionhyst study STUDY.toml --from-identification "
            f"THIS_FILE\n{bound}[identification]\n{head}"
            f"parameters = [{', '.join(json.dumps(keys[n]) for n in names)}]\n"
            f"estimates = [{', '.join(repr(float(estimates[n])) for n in names)}]\n"
            f"std = [{', '.join(repr(float(v)) for v in std)}]\n"
            f"correlation = [\n{rows}]\n")


def undetermined_notes(names: list[str], groups: list[list[int]], rtol: float
                       ) -> dict[str, str]:
    notes: dict[str, str] = {}
    for g in groups:
        members = [names[i] for i in g]
        for i in g:
            others = [m for m in members if m != names[i]]
            what = (f"only a combination with {', '.join(others)} is" if others
                    else "it has no effect on the output")
            notes[names[i]] = (f"not determined by these records: {what} (a direction of "
                               f"the Jacobian with a singular value below {rtol:g} of the "
                               f"largest)")
    return notes


def _correlation(J: NDArray[np.float64], rtol: float) -> NDArray[np.float64]:
    """Correlation matrix of the estimates, ``(J^T J)^+`` over the determined directions."""
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    _, sv, vt = np.linalg.svd(J / norms, full_matrices=False)
    good = sv > rtol * sv[0]
    cov = (vt[good].T / sv[good] ** 2) @ vt[good]
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return cov / np.outer(d, d)


def weak_notes(names: list[str], values: NDArray[np.float64], std: NDArray[np.float64],
               J: NDArray[np.float64], rtol: float, may_be_zero: NDArray[np.bool_]
               ) -> dict[str, str]:
    """Parameters whose standard error exceeds their value: not determined by the records
    (`std` those of white residuals, :attr:`CorrelatedErrors.white_std`: a fit's model error
    widens what it reports, not what the records determine).

    A parameter that must be positive is then reported with the parameters its
    estimate is correlated with (``|r| > 0.99``: only that combination is
    determined), or as having almost no effect at the records' noise; one that
    may be zero as not distinguishable from 0.
    """
    corr = _correlation(J, rtol)
    notes: dict[str, str] = {}
    for i, name in enumerate(names):
        s = std[i]
        if not (math.isfinite(s) and s > abs(values[i])):
            continue
        if may_be_zero[i]:
            notes[name] = (f"not distinguishable from 0 by these records (estimate "
                           f"{values[i]:.4g} +- {s:.2g})")
            continue
        partners = [f"{names[j]} (r = {corr[i, j]:+.4f})" for j in range(len(names))
                    if j != i and abs(corr[i, j]) > 0.99]
        what = (f"only a combination with {', '.join(partners)} is" if partners else
                "it has almost no effect on the output at the records' noise")
        notes[name] = (f"not determined by these records: its standard error {s:.2g} exceeds "
                       f"the estimate {values[i]:.4g}; {what}")
    return notes


def zero_allowed(plant, link) -> set[str]:
    """The names (as an identification gives them: ``c``, ``link.sigma2``, ``link.k[2]``) of
    the parameters of `plant` and the link class `link` whose declared range holds 0 (kind
    ``nonnegative`` or ``finite``).

    Parameters
    ----------
    plant : LumpedPlant
        The identified stage (its class's ``parameters``).
    link : type
        The link's model, a registered :class:`~motionhyst.hysteresis.Hysteresis` class.

    Returns
    -------
    set of str
        The names, ``link.`` before the link's.

    Examples
    --------
    >>> from motionhyst.hysteresis import LuGre
    >>> from motionhyst.plants import MassDamper
    >>> sorted(zero_allowed(MassDamper(95.0, 200.0), LuGre))
    ['c', 'c_skew', 'force_drift', 'force_offset', 'link.sigma1', 'link.sigma2']
    """
    out = {p.name for p in plant.parameters if p.kind != "positive"}
    return out | {f"link.{p.name}" for p in link.parameters if p.kind != "positive"}


def undetermined(estimates: dict[str, float], std: dict[str, float | None],
                 invariant: tuple[str, ...] = (), zero: set[str] | frozenset = frozenset()
                 ) -> list[str]:
    """The estimated physical parameters the records do not determine: a standard error that
    is not known (``None``: a direction of the Jacobian the records do not see, or above its
    value where the route says so) or, for a parameter that must be positive, above
    :data:`UNDETERMINED_FACTOR` times the estimate (for one whose range holds 0, names in
    `zero`, an estimate within its standard error of 0 is a value: 0 is one the records
    allow, and so is one at 0, below :data:`AT_ZERO` of the largest estimate); offsets and
    initial states (which may be 0) are left out, and so are the `invariant` parameters (a
    direction in which the model's output is the same for any record:
    :data:`BOUC_WEN_SCALE`).

    Parameters
    ----------
    estimates, std : dict
        The fit's estimates and their standard errors (``None`` where not determined).
    invariant : tuple of str
        Parameters along whose combination the model's output does not change.
    zero : set of str
        The parameters whose range holds 0 (:func:`zero_allowed`).

    Returns
    -------
    list of str
        Their names, in the order of `estimates`.

    Examples
    --------
    >>> undetermined({"m": 2.0, "link.fc": 20.0, "link.k": 5e4, "output_offset": 1e-9},
    ...              {"m": 0.01, "link.fc": None, "link.k": 6e4, "output_offset": 1e-6})
    ['link.fc', 'link.k']
    >>> undetermined({"k": 1e5, "c": 5.5e-18, "link.fc": 100.0},   # c ended at 0
    ...              {"k": 0.3, "c": None, "link.fc": 4e-4}, zero={"k", "c"})
    []
    """
    out = []
    largest = max([abs(v) for v in estimates.values() if math.isfinite(v)] or [0.0])
    for name, value in estimates.items():
        if name in invariant or any(word in name for word in _SIGNED):
            continue
        if name.split("[")[0] in zero and abs(value) <= AT_ZERO * largest:
            continue  # ended at 0, where a forward difference sees no effect: none in the records
        s = std.get(name)
        if s is None or not math.isfinite(s) or (
                name.split("[")[0] not in zero and s > UNDETERMINED_FACTOR * abs(value)):
            out.append(name)
    return out


def simpler_link(link: str | None) -> str:
    """The remedy of a fit whose records determine too little, as far as the link goes: the
    options that make the `link` (its model's name, ``--model``) simpler, and only those
    that apply to it (a Maxwell-slip link's elements; a link of fewer parameters for the
    others; none for a Coulomb link, the simplest).

    Parameters
    ----------
    link : str or None
        The link's model name (``"lugre"``, ``"maxwell-slip"``, ...); None: any link.

    Returns
    -------
    str
        ``", or a simpler link (...)"``, or ``""``.

    Examples
    --------
    >>> simpler_link("maxwell-slip"), simpler_link("jenkins"), simpler_link("coulomb")
    (', or a simpler link (fewer --elements)', ', or a simpler link (--model coulomb)', '')
    >>> simpler_link("lugre")
    ', or a simpler link (--model jenkins or coulomb)'
    """
    if link == "coulomb":
        return ""
    if link == "maxwell-slip":
        return ", or a simpler link (fewer --elements)"
    if link == "jenkins":
        return ", or a simpler link (--model coulomb)"
    return ", or a simpler link (--model jenkins or coulomb)"


def judge_determined(estimates: dict[str, float], std: dict[str, float | None],
                     invariant: tuple[str, ...] = (), zero: set[str] | frozenset = frozenset(),
                     explained: set[str] | frozenset = frozenset(),
                     link: str | None = None) -> list[str]:
    """What the records do not determine, judged: the warnings to give, or a failed fit.

    Parameters
    ----------
    estimates, std : dict
        The fit's estimates and their standard errors (``None`` where not determined): those
        of white residuals (an input-output fit's ``judged_std``,
        :class:`~motionhyst.identify.io_results.IOIdentification`), not the wider ones a fit
        that leaves model error reports.
    invariant : tuple of str
        Parameters along whose combination the model's output does not change for any
        record (:data:`BOUC_WEN_SCALE`): not a question of the records, left out.
    zero : set of str
        The parameters whose range holds 0 (:func:`zero_allowed`).
    explained : set of str
        Parameters another warning names already (a slip force the fit's link holds one
        way only, :func:`~motionhyst.identify.io_one_way.one_way_slip`): counted, not named
        again.
    link : str, optional
        The link's model name: the failed fit's remedy names only what simplifies it
        (:func:`simpler_link`).

    Returns
    -------
    list of str
        One warning naming the parameters the records do not determine, if any.

    Raises
    ------
    FitFailed
        More than :data:`UNDETERMINED_SHARE` of the model's physical parameters (the stage's
        and the link's: offsets and initial states left out) are not determined: the
        records hold less than the model asks, the values saved would be the search's, and
        the model, one of many that fit these records as well, cannot predict another one.

    Examples
    --------
    Two of a stage's and link's four parameters not determined: a warning naming them

    >>> from motionhyst.identify.io_checks import FitFailed
    >>> est = {"m": 2.18, "c": 21.0, "link.k": 946.0, "link.fc": 0.98}
    >>> [line[:71] for line in judge_determined(
    ...     est, {"m": 0.04, "c": 0.7, "link.k": 1.8e7, "link.fc": None})]
    ['the records do not determine link.k, link.fc (their standard errors are']

    Three of four: a failed fit (the command line's error: one line, exit 2, nothing saved)

    >>> try:
    ...     judge_determined(est, {"m": 0.04, "c": None, "link.k": 1.8e7, "link.fc": None})
    ... except FitFailed as exc:
    ...     print(str(exc)[:79])
    the fit failed: the records determine 1 of the model's 4 parameters (not c, lin
    """
    from motionhyst.identify.io_checks import FitFailed

    names = undetermined(estimates, std, invariant, zero)
    if not names:
        return []
    physical = [n for n in estimates
                if n not in invariant and not any(word in n for word in _SIGNED)]
    if len(names) > UNDETERMINED_SHARE * len(physical):
        shown = ", ".join(names[:5]) + (", ..." if len(names) > 5 else "")
        raise FitFailed(f"the fit failed: the records determine {len(physical) - len(names)} "
                        f"of the model's {len(physical)} parameters (not {shown}): its values "
                        f"would be the search's, and the model, one of many that fit these "
                        f"records as well, cannot predict; give a longer or richer record"
                        f"{simpler_link(link)}")
    names = [n for n in names if n not in explained]
    if not names:
        return []
    what = "its search value" if len(names) == 1 else "their search values"
    its = "its standard error is unknown or exceeds its value" if len(names) == 1 else \
        "their standard errors are unknown or exceed their values"
    return [f"the records do not determine {', '.join(names)} ({its}): the model holds "
            f"{what}, which these records neither confirm nor contradict"]


#: Parameters of either sign whose standard error above their value says they are not
#: distinguishable from 0 (:func:`widened_note`): offsets, a drift, the viscous friction's
#: difference by direction (not the records' initial states, nor a Bouc-Wen link's shape)
_OFFSETS = ("offset", "drift", "c_skew")


def widened_note(estimates: dict[str, float], std: dict[str, float | None],
                 judged: dict[str, float | None], invariant: tuple[str, ...] = (),
                 zero: set[str] | frozenset = frozenset()) -> str | None:
    """The parameters whose reported standard error exceeds their value where those of
    white residuals do not: one line of a result's warnings, or None (for a fit whose
    standard errors are lower bounds: :func:`correlated_errors`' note).

    A fit that leaves model error or coloured noise reports standard errors widened for
    the residuals' correlation (lower bounds, :func:`correlated_errors`), while whether the
    records determine a parameter is judged from those of white residuals
    (:func:`judge_determined`: model error does not make a record say less).  Where the
    reported one exceeds the value (a Jenkins stiffness ``4.4e7 +- >= 9.7e7``), the value is
    not determined beyond what the residuals carry besides white noise (the fit's model error
    or coloured noise: the records do not tell them apart), whatever the white one says: said
    here,
    named, for a parameter that must be positive as :func:`undetermined` has it, for an
    offset, a drift or a difference by direction as not distinguishable from 0.  The fit is
    not refused for it (model error is a result), nor is its model changed.

    Parameters
    ----------
    estimates : dict
        The fit's estimates.
    std : dict
        The standard errors it reports (``None`` where not determined).
    judged : dict
        Those of white residuals (``judged_std``).
    invariant, zero
        As :func:`undetermined`.

    Returns
    -------
    str or None

    Examples
    --------
    >>> est = {"m": 95.0, "link.k": 4.4e7, "link.fc": 20.0, "input_offset": 0.031}
    >>> print(widened_note(est, {"m": 0.3, "link.k": 9.7e7, "link.fc": 0.2,
    ...                          "input_offset": 0.043},
    ...                    {"m": 0.02, "link.k": 6e6, "link.fc": 0.01, "input_offset": 0.004}))
    ... # doctest: +NORMALIZE_WHITESPACE
    with residuals beyond white noise (model error or coloured noise), the records do not
    determine link.k (4.4e+07 +- 9.7e+07), and input_offset (0.031 +- 0.043) is not
    distinguishable from 0: standard errors widened for the residuals' correlation exceed the
    values, which the model holds as the search found them
    """
    white = set(undetermined(estimates, judged, invariant, zero))
    names = [n for n in undetermined(estimates, std, invariant, zero) if n not in white]

    def exceeds(table: dict[str, float | None], name: str) -> bool:
        s = table.get(name)
        return s is not None and math.isfinite(s) and s > abs(estimates[name])
    signed = [n for n in estimates if any(w in n for w in _OFFSETS) and n not in invariant
              and exceeds(std, n) and judged.get(n) is not None and not exceeds(judged, n)]
    if not names and not signed:
        return None

    def shown(group: list[str]) -> str:
        return ", ".join(f"{n} ({estimates[n]:.2g} +- {std[n]:.2g})"
                         if std.get(n) is not None and math.isfinite(std[n]) else n
                         for n in group)
    parts = ([f"the records do not determine {shown(names)}"] if names else []) + (
        [f"{shown(signed)} {'is' if len(signed) == 1 else 'are'} not distinguishable from 0"]
        if signed else [])
    return (f"with residuals beyond white noise (model error or coloured noise), "
            f"{', and '.join(parts)}: standard errors widened for the residuals' correlation "
            f"exceed the values, which the model holds as the search found them")


def parallel_note(model: type, name: str, two_mass: bool = False) -> str:
    """Why the link parameter `name` that only adds a spring or damper in parallel
    (``Parameter.parallel``) is fixed at 0.

    Parameters
    ----------
    model : type
        The link model's class.
    name : str
        The parameter.
    two_mass : bool
        The stage is the floating two-mass stage (no spring or damper to the ground).

    Returns
    -------
    str
        The note.

    Examples
    --------
    >>> from motionhyst.hysteresis import LuGre
    >>> parallel_note(LuGre, "sigma2")[:47]
    "a damper in parallel with the stage's: only the"
    """
    par = next(p for p in model.parameters if p.name == name)
    what, stage = ("a spring", "k") if par.parallel == "spring" else ("a damper", "c")
    if two_mass:
        return (f"{what} to the ground in parallel with the link; not estimated with a "
                f"two-mass stage (which has none to the ground): fixed at 0")
    return (f"{what} in parallel with the stage's: only the sum {stage} + {name} enters the "
            f"output; fixed at 0, the stage's {stage} holds the sum")
