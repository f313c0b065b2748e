"""The fit engine: Maxwell-slip parameters from a force-displacement record.

NNLS over a grid of stop operators, joint refinement from several starts, a
derivative-free scan across kinks and the model-order choice (the method is
described in :mod:`motionhyst.identify`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares, nnls

from motionhyst.core.warnings import warn
from motionhyst.hysteresis import MaxwellSlip
from motionhyst.identify._stop_operators import maxwell_at, stops_at
from motionhyst.identify.io_checks import systematic_share
from motionhyst.identify.io_uncertainty import covariance, covariance_table
from motionhyst.identify.records import MAX_ROWS, check_signals
from motionhyst.identify.result import Identification

if TYPE_CHECKING:  # a closed-loop record's prefilter (python-control): a force-displacement
    from motionhyst.core.lti import HoldFilter  # fit needs neither

__all__ = ["correlated_std", "identify_maxwell_slip", "residuals_and_jacobian"]

N_GRID = 40
"""Candidate slip displacements in the NNLS stage."""


GRID_SPAN = 1e-3
"""Smallest candidate slip displacement relative to the half-range of x."""


PRUNE = 0.005
"""Elements of the NNLS stage with less than this share of the total slip force are dropped."""


MAX_ELEMENTS = 8
"""Largest number of elements tried when the order is chosen automatically."""


SCAN_SPAN = 0.3
"""The scan covers ``1 / (1 + SCAN_SPAN)`` to ``1 + SCAN_SPAN`` times each slip displacement."""


SCAN_POINTS = 61
"""Values per slip displacement in the derivative-free scan (denser near the current one)."""


HOPS = 3
"""Most scan-and-refine rounds per model order."""


MAX_NFEV = 100
"""Most residual evaluations of one refinement."""


SCREEN_NFEV = 15
"""Residual evaluations after which the starts of one order are compared (the best goes on)."""


EXTRA_ORDER = 2
"""Order of the prefilter beyond ``deg d1``: ``L / P1`` then rolls off at high frequency."""



Criterion = Literal["rms", "bic"]


@dataclass
class FitProblem:
    """Data of one fit: operators run on `x`; residual on `rows` of `target`."""

    x: NDArray[np.float64]
    target: NDArray[np.float64]
    rows: NDArray[np.intp]
    filt: HoldFilter | None
    fit_initial: bool
    grid_d: NDArray[np.float64] | None = None
    grid_A: NDArray[np.float64] | None = None  # unit stop columns / d at the rows
    fit_offset: bool = True  # the force offset c estimated (else fixed at 0)

    @property
    def y(self) -> NDArray[np.float64]:
        return self.target[self.rows]


@dataclass
class _Fit:
    k: NDArray[np.float64]
    fc: NDArray[np.float64]
    alpha: NDArray[np.float64]
    c: float
    rss: float
    J: NDArray[np.float64] = field(repr=False)
    resid: NDArray[np.float64] = field(repr=False)

    @property
    def n(self) -> int:
        return int(self.k.size)


def _pack(k, fc, alpha, c, fit_initial: bool) -> NDArray[np.float64]:
    parts = [k, fc] + ([alpha] if fit_initial else []) + [[c]]
    return np.concatenate([np.asarray(p, dtype=float) for p in parts])


def _unpack(theta, n: int, fit_initial: bool):
    k, fc = theta[:n], theta[n:2 * n]
    alpha = theta[2 * n:3 * n] if fit_initial else np.zeros(n)
    return k, fc, alpha, float(theta[-1])


def _evaluate(prob: FitProblem, theta, n: int, jac: bool):
    """Residual (model - target) at the rows and, optionally, its Jacobian.

    Without a prefilter the operators keep only the rows (memory and time
    per evaluation linear in the record, not in the record times the
    parameters); with one they keep every sample, which the filter needs.
    """
    k, fc, alpha, c = _unpack(theta, n, prob.fit_initial)
    k = np.ascontiguousarray(k)
    fc = np.ascontiguousarray(fc)
    keep = prob.rows if prob.filt is None else np.arange(prob.x.size)
    W, sign, before = maxwell_at(prob.x, k, fc, np.ascontiguousarray(alpha * fc), keep)
    cols = [W.sum(axis=1)[:, None]]
    if jac:
        # d w_i / d fc_i = sigma_i: the sign of the last saturation (alpha_i before the first);
        # d w_i / d k_i = (w_i - fc_i sigma_i) / k_i; d w_i / d alpha_i = fc_i before the first.
        sigma = np.where(before, alpha, sign)
        cols += [(W - fc * sigma) / k, sigma]
        if prob.fit_initial:
            cols.append(before * fc)
    M = np.concatenate(cols, axis=1)
    if prob.filt is not None:
        M = prob.filt(M)[prob.rows]
    # a constant offset passes the prefilter with its DC gain (1 by construction)
    r = M[:, 0] + (c if prob.fit_offset else 0.0) - prob.y
    if not jac:
        return r, None
    J = np.column_stack([M[:, 1:], np.full(r.size, 1.0 if prob.fit_offset else 0.0)])
    return r, J


def _refine(prob: FitProblem, k, fc, alpha, c, max_nfev: int = MAX_NFEV) -> _Fit:
    """Joint bounded least-squares refinement of all parameters."""
    n = len(k)
    c = c if prob.fit_offset else 0.0  # fixed: its column is zero, it stays there
    theta0 = _pack(k, fc, np.clip(alpha, -0.999, 0.999), c, prob.fit_initial)
    k_lo = 1e-9 * float(np.sum(k))
    fc_lo = 1e-9 * float(np.sum(fc))
    lo = _pack(np.full(n, k_lo), np.full(n, fc_lo), -np.ones(n), -np.inf, prob.fit_initial)
    hi = _pack(np.full(n, np.inf), np.full(n, np.inf), np.ones(n), np.inf, prob.fit_initial)
    theta0[:n] = np.maximum(theta0[:n], 2 * k_lo)
    theta0[n:2 * n] = np.maximum(theta0[n:2 * n], 2 * fc_lo)
    cache: dict = {}

    def fun(th):
        r, J = _evaluate(prob, th, n, True)
        cache["th"], cache["J"] = th.copy(), J
        return r

    def jacobian(th):
        if "th" in cache and np.array_equal(cache["th"], th):
            return cache["J"]
        return _evaluate(prob, th, n, True)[1]

    sol = least_squares(fun, theta0, jac=jacobian, bounds=(lo, hi), x_scale="jac",
                        method="trf", tr_solver="lsmr", ftol=1e-10, xtol=1e-10, gtol=1e-10,
                        max_nfev=max_nfev)
    k, fc, alpha, c = _unpack(sol.x, n, prob.fit_initial)
    r, J = _evaluate(prob, sol.x, n, True)
    return _Fit(k=k.copy(), fc=fc.copy(), alpha=alpha.copy(), c=c, rss=float(r @ r), J=J,
                resid=r)


def _rss_only(prob: FitProblem, k, fc, alpha, c) -> float:
    r, _ = _evaluate(prob, _pack(k, fc, alpha, c, prob.fit_initial), len(k), False)
    return float(r @ r)


def _unit_columns(prob: FitProblem, d, w0, per_slip_force: bool = False
                  ) -> NDArray[np.float64]:
    """Unit-stiffness stop operators of thresholds `d` started at `w0`, at the rows.

    With `per_slip_force` each column is divided by its ``d`` (unit slip force
    instead of unit stiffness) before the prefilter: dividing after it would
    change the closed-loop fits at round-off level, enough to move the
    refinement to a neighbouring local minimum.
    """
    d = np.ascontiguousarray(d, dtype=float)
    w0 = np.ascontiguousarray(w0, dtype=float)
    if prob.filt is None:
        return stops_at(prob.x, d, w0, prob.rows, per_slip_force)
    # the prefilter needs every sample: one column at a time keeps memory to a few records
    every = np.arange(prob.x.size)
    S = np.empty((prob.rows.size, d.size))
    for j in range(d.size):
        col = stops_at(prob.x, d[j:j + 1], w0[j:j + 1], every, per_slip_force)
        S[:, j] = prob.filt(col)[prob.rows, 0]
    return S


def _nnls_start(prob: FitProblem) -> tuple[NDArray, NDArray, float]:
    """Stage 1-2: stop-operator regressor on a threshold grid, NNLS, merge and prune."""
    h = 0.5 * float(np.ptp(prob.x))
    d = np.geomspace(GRID_SPAN * h, h, N_GRID)
    A = _unit_columns(prob, d, np.zeros_like(d), per_slip_force=True)  # started relaxed
    prob.grid_d, prob.grid_A = d, A
    y = prob.y
    a_mean, y_mean = A.mean(axis=0), float(y.mean())
    if not prob.fit_offset:  # no offset: the elements alone carry the mean
        a_mean, y_mean = np.zeros_like(a_mean), 0.0
    R = np.linalg.qr(np.column_stack([A - a_mean, y - y_mean]), mode="r")
    f, _ = nnls(R[:N_GRID, :N_GRID], R[:N_GRID, N_GRID], maxiter=50 * N_GRID)
    c = y_mean - float(a_mean @ f)
    on = f > 1e-12 * max(float(f.max()), 1e-300)
    ks, fcs = [], []
    j = 0
    while j < N_GRID:
        if not on[j]:
            j += 1
            continue
        run = slice(j, j + int(np.argmin(np.append(on[j:], False))))
        fcs.append(float(f[run].sum()))
        ks.append(float((f[run] / d[run]).sum()))
        j = run.stop
    ks_a, fcs_a = np.array(ks), np.array(fcs)
    if ks_a.size == 0:
        xr = prob.x[prob.rows]  # the force's rows: a closed-loop fit's skip the settling
        x0, y0 = xr - np.mean(xr), y - y_mean
        if np.dot(x0, y0) < -0.5 * np.linalg.norm(x0) * np.linalg.norm(y0):
            why = ("is one sensor's sign reversed? --scale force=-1" if prob.filt is None
                   else "the force inferred through the plant: is the sign of u or y1 "
                        "reversed (--scale u=-1), or the plant not the record's?")
            raise ValueError(f"no hysteresis found: the force falls as the displacement rises "
                             f"({why})")
        raise ValueError("no hysteresis found: the force does not follow any stop operator "
                         "of the displacement")
    keep = fcs_a >= PRUNE * fcs_a.sum()
    return ks_a[keep], fcs_a[keep], c


def _sorted(k, fc, alpha):
    order = np.argsort(fc / k)
    return k[order], fc[order], alpha[order]


def _merge(k, fc, alpha, i):
    """Merge elements i and i + 1 (sorted by slip displacement); keep the initial force."""
    fcm = fc[i] + fc[i + 1]
    am = (alpha[i] * fc[i] + alpha[i + 1] * fc[i + 1]) / fcm
    k2 = np.concatenate([k[:i], [k[i] + k[i + 1]], k[i + 2:]])
    fc2 = np.concatenate([fc[:i], [fcm], fc[i + 2:]])
    a2 = np.concatenate([alpha[:i], [am], alpha[i + 2:]])
    return k2, fc2, a2


def _best_merge(prob, k, fc, alpha, c):
    """The merge of two adjacent elements that increases the residual least."""
    k, fc, alpha = _sorted(k, fc, alpha)
    options = [_merge(k, fc, alpha, i) for i in range(len(k) - 1)]
    costs = [_rss_only(prob, *o, c) for o in options]
    return options[int(np.argmin(costs))]


def _grow(prob: FitProblem, fit: _Fit):
    """Add the grid element that best explains the residual (greedy, non-negative)."""
    A = prob.grid_A - prob.grid_A.mean(axis=0)
    e = -(fit.resid - fit.resid.mean())
    num = A.T @ e
    den = np.einsum("ij,ij->j", A, A)
    score = np.where(num > 0, num**2 / np.maximum(den, 1e-300), -np.inf)
    j = int(np.argmax(score))
    f = num[j] / den[j] if np.isfinite(score[j]) else 0.01 * float(fit.fc.sum())
    d = prob.grid_d[j]
    return _sorted(np.append(fit.k, f / d), np.append(fit.fc, f), np.append(fit.alpha, 0.0))


def _collapsed(fit: _Fit) -> bool:
    """An element fell onto its lower bound: the fit has in effect fewer elements."""
    return bool(np.any(fit.fc <= 1e-6 * fit.fc.sum()) or np.any(fit.k <= 1e-6 * fit.k.sum()))


def _scan_thresholds(prob: FitProblem, fit: _Fit):
    """A start across the kinks next to a refined fit, or ``None`` if there is none better.

    With the slip displacements ``d_i = fc_i / k_i`` (and the initial states
    ``alpha_i``) fixed, the force is linear in the stiffnesses and the offset.
    Each ``d_i`` in turn is scanned over ``SCAN_POINTS`` values within a
    factor ``1 + SCAN_SPAN`` of its value (0.03 % apart near it, 1.7 % at the
    ends), the stiffnesses and offset re-solved by non-negative least squares
    (variable projection; the other elements' columns are factored once per
    ``d_i``), and the best kept.  The objective has a kink wherever a slip
    onset moves from one sample to the next (``2 d_i`` equal to the travel
    from a reversal to a sample), hence many local minima; the gradient-based
    refinement stops in one, this search steps over kinks.  A start is
    returned only if it lowers the residual sum of squares by more than the
    noise variance ``RSS / (n - p)``: a smaller gain moves the estimate by
    less than about one standard error.
    """
    n = fit.n
    y = prob.y
    yc = y - y.mean()
    yy = float(yc @ yc)
    d = fit.fc / fit.k
    A = _unit_columns(prob, d, fit.alpha * d)
    a_mean = A.mean(axis=0)
    Ac = A - a_mean
    k, rnorm = nnls(Ac, yc)
    best = min(float(rnorm**2), fit.rss)
    ref = best
    found = False
    t = np.linspace(-1.0, 1.0, SCAN_POINTS)
    factors = (1.0 + SCAN_SPAN) ** (t * np.abs(t))  # dense near 1: the kinks are close
    for i in range(n):
        trial = d[i] * factors
        T = _unit_columns(prob, trial, fit.alpha[i] * trial)
        t_mean = T.mean(axis=0)
        # (a plain nnls per trial on all rows re-factors them each time: ~1.3-1.5x slower at 50k)
        # split every trial column and y into parts in and orthogonal to the other columns:
        # ||O k_o + T_j k_i - y||^2 = ||R0 k_o + P_j k_i - P_y||^2 + ||E_j k_i - E_y||^2
        others = np.delete(Ac, i, axis=1)
        if n > 1:
            Q0, R0 = np.linalg.qr(others)
        else:
            Q0, R0 = np.zeros((y.size, 0)), np.zeros((0, 0))
        B = np.column_stack([T - t_mean, yc])
        P = Q0.T @ B
        E = B - Q0 @ P
        e_jj = np.einsum("ij,ij->j", E[:, :-1], E[:, :-1])
        e_jy = E[:, :-1].T @ E[:, -1]
        e_yy = float(E[:, -1] @ E[:, -1])
        jbest = -1
        for j in np.flatnonzero(e_jj > 0):
            sj = np.sqrt(e_jj[j])
            small = np.zeros((n, n))
            small[:n - 1, :n - 1] = R0
            small[:n - 1, -1] = P[:, j]
            small[-1, -1] = sj
            kj, _ = nnls(small, np.append(P[:, -1], e_jy[j] / sj))
            if not np.all(kj > 0):  # a zero stiffness drops an element
                continue
            top = float(np.sum((small[:n - 1] @ kj - P[:, -1]) ** 2))
            ki = kj[-1]
            if top + (e_jj[j] * ki - 2.0 * e_jy[j]) * ki + e_yy > best + 1e-12 * yy:
                continue  # not better (the expanded square is exact to rounding of y^T y)
            rss = top + float(np.sum((E[:, j] * ki - E[:, -1]) ** 2))
            if rss < best:
                best, jbest = rss, j
                k = np.insert(kj[:n - 1], i, kj[-1])
        if jbest >= 0:
            found = True
            d[i] = trial[jbest]
            Ac[:, i] = T[:, jbest] - t_mean[jbest]
            a_mean[i] = t_mean[jbest]
    sigma2 = fit.rss / max(prob.rows.size - fit.J.shape[1], 1)
    if not found or best > ref - sigma2:
        return None
    return (*_sorted(k, k * d, fit.alpha.copy()), float(y.mean() - a_mean @ k))


def _merge_chain(prob: FitProblem, k, fc, c) -> dict[int, tuple]:
    """Starts ``(k, fc, alpha, c)`` per order: the NNLS elements merged pairwise down to 1.

    Each step merges the adjacent pair (by slip displacement) whose merge
    raises the residual least, without refinement.
    """
    kk, ff, aa = _sorted(k, fc, np.zeros(k.size))
    chain = {kk.size: (kk, ff, aa, c)}
    while kk.size > 1:
        kk, ff, aa = _best_merge(prob, kk, ff, aa, c)
        chain[kk.size] = (kk, ff, aa, c)
    return chain


def _fit_order(prob: FitProblem, n: int, chain: dict[int, tuple],
               fits: dict[int, _Fit]) -> _Fit | None:
    """Best refined ``n``-element fit over several starts; ``None`` if every start collapses.

    Starts: (a) the NNLS elements merged down to ``n`` (`chain`), (b) the
    best ``n - 1`` element fit plus the grid element that best explains its
    residual; each is refined for ``SCREEN_NFEV`` evaluations and the best
    one to convergence.  That fit is then moved across kinks of the
    objective by :func:`_scan_thresholds` and refined again, at most ``HOPS``
    times, while that helps.  The starts depend only on the data and on the
    fits of lower order, so the ``n``-element fit is the same whether ``n``
    was requested or reached by the automatic order search.
    """
    starts = [chain[n]] if n in chain else []
    if n - 1 in fits:
        prev = fits[n - 1]
        starts.append((*_grow(prob, prev), prev.c))
    # screen the starts with a few evaluations each, then refine the best to convergence
    # (the next best if that collapses)
    screen = SCREEN_NFEV if len(starts) > 1 else MAX_NFEV
    tried = [_refine(prob, *start, max_nfev=screen) for start in starts]
    best = None
    for fit in sorted((f for f in tried if not _collapsed(f)), key=lambda f: f.rss):
        if screen < MAX_NFEV:
            fit = _refine(prob, fit.k, fit.fc, fit.alpha, fit.c)
        if not _collapsed(fit):
            best = fit
            break
    for _ in range(HOPS if best is not None else 0):
        start = _scan_thresholds(prob, best)
        if start is None:
            break
        fit = _refine(prob, *start)
        if _collapsed(fit) or fit.rss >= best.rss:
            break
        best = fit
    return best


def _bic(rss: float, n_rows: int, n_params: int) -> float:
    return float(n_rows * np.log(max(rss, 1e-300) / n_rows) + n_params * np.log(n_rows))


def _n_params(n_el: int, fit_initial: bool, fit_offset: bool = True) -> int:
    return (3 if fit_initial else 2) * n_el + int(fit_offset)


def _covariance_std(fit: _Fit, n_rows: int) -> NDArray[np.float64]:
    """Standard deviations ``sqrt(diag(sigma^2 (J^T J)^-1))``; inf where not identifiable."""
    J = fit.J
    p = J.shape[1]
    sigma2 = fit.rss / max(n_rows - p, 1)
    scale = np.linalg.norm(J, axis=0)
    scale[scale == 0] = 1.0
    _, s, Vt = np.linalg.svd(J / scale, full_matrices=False)
    good = s > max(s[0], 1e-300) * 1e-9
    inv = (Vt[good].T / s[good] ** 2) @ Vt[good]
    std = np.sqrt(np.clip(np.diag(inv), 0.0, None) * sigma2) / scale
    if (~good).any():
        weak = np.linalg.norm(Vt[~good], axis=0) > 1e-6
        std[weak] = np.inf
    return std


def _covariance_of(fit: _Fit, n_rows: int, order: NDArray[np.intp],
                   std: NDArray[np.float64]) -> dict:
    """The covariance of ``k``, ``fc`` (``k[0], k[1], ..., fc[0], ...`` for several elements,
    in the elements' order) and ``offset``: of the Jacobian that gives :func:`_covariance_std`."""
    n = fit.n
    idx = [*order, *(n + order), fit.J.shape[1] - 1]
    names = (["k", "fc"] if n == 1 else [f"{p}[{i}]" for p in ("k", "fc") for i in range(n)])
    names.append("offset")
    sd = {nm: float(std[i]) if np.isfinite(std[i]) else None
          for nm, i in zip(names, idx, strict=True)}
    cov = covariance(fit.J, fit.rss, n_rows, 1e-9)[np.ix_(idx, idx)]
    return covariance_table(names, cov, sd)


def identify_prepared(prob: FitProblem, n_elements: int | None, criterion: Criterion, rtol: float,
                      atol: float, max_elements: int, signal_name: str, *,
                      cutoff_hz: float | None = None, target_share: float | None = None
                      ) -> Identification:
    """Stages 1-5 of the module docstring on a prepared problem (`target_share`: the
    automatic order search stops where its trend cannot reach it,
    :func:`_reachable_share`)."""
    if criterion not in ("rms", "bic"):
        raise ValueError(f"unknown criterion {criterion!r}; use 'rms' or 'bic'")
    if n_elements is not None and (int(n_elements) != n_elements or n_elements < 1):
        raise ValueError(f"n_elements must be a positive integer, got {n_elements!r}")
    for name, v in (("rtol", rtol), ("atol", atol)):
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"{name} must be finite and >= 0, got {v!r}")
    n_rows = prob.rows.size
    w_rms = float(np.std(prob.y))

    def rms(fit: _Fit) -> float:
        return float(np.sqrt(fit.rss / n_rows))

    def margin(r: float) -> float:  # an RMS change smaller than this is not significant
        return max(rtol * r, atol * w_rms)

    chain = _merge_chain(prob, *_nnls_start(prob))
    fits: dict[int, _Fit] = {}
    # automatic: every order up to the NNLS stage's, then on while an element still helps
    n_top = int(n_elements) if n_elements is not None else max(1, int(max_elements))
    n_nnls = min(max(chain), n_top)
    shares: dict[int, float] = {}
    stopped = None
    for n in range(1, n_top + 1):
        fit = _fit_order(prob, n, chain, fits)
        if fit is None:  # every start collapsed: the data hold no more elements
            break
        fits[n] = fit
        if n_elements is None and target_share is not None and n < n_top:
            shares[n] = systematic_share(fit.resid, prob.y)
            reach = _reachable_share(shares, n_top)
            if reach > target_share:
                stopped = (f"the order search stopped at {n} elements: their systematic error "
                           f"({', '.join(f'{100 * shares[m]:.2g}' for m in sorted(shares))} % "
                           f"of the force's RMS with {min(shares)} to {n}) falls at a rate "
                           f"that leaves at least {100 * reach:.2g} % at {n_top}, above "
                           f"{100 * target_share:g} %")
                break
        if (n_elements is None and n >= max(n_nnls, 2)
                and rms(fit) > rms(fits[n - 1]) - margin(rms(fits[n - 1]))):
            break
    if n_elements is not None:
        chosen = fits[min(fits, key=lambda m: (abs(m - int(n_elements)), m))]
        how = f"fixed: {int(n_elements)} element(s) requested"
    else:
        orders = sorted(fits)
        if criterion == "rms":
            best = min(rms(fits[n]) for n in orders)
            chosen = fits[next(n for n in orders if rms(fits[n]) <= best + margin(best))]
            how = (f"rms: smallest N with RMS residual within {100 * rtol:g} % of the best or "
                   f"{100 * atol:g} % of the force RMS (N tried: {', '.join(map(str, orders))})")
        else:
            bics = {n: _bic(fits[n].rss, n_rows,
                            _n_params(n, prob.fit_initial, prob.fit_offset)) for n in orders}
            chosen = fits[min(bics, key=bics.get)]
            how = f"bic: smallest BIC (N tried: {', '.join(map(str, orders))})"
        if stopped is not None:
            how += f"; {stopped}"

    std = _covariance_std(chosen, n_rows)
    n = chosen.n
    order = np.argsort(chosen.fc / chosen.k)
    k_std, fc_std = std[:n], std[n:2 * n]
    elements = [{"k": float(chosen.k[i]), "fc": float(chosen.fc[i]),
                 "k_std": float(k_std[i]), "fc_std": float(fc_std[i])} for i in order]
    y = prob.y
    tss = float(np.sum((y - y.mean()) ** 2))
    fit_rms = rms(chosen)
    ref_rms = float(np.sqrt(tss / n_rows))
    candidates = [{"n_elements": m, "fit_rms": rms(fits[m]),
                   "bic": _bic(fits[m].rss, n_rows,
                               _n_params(m, prob.fit_initial, prob.fit_offset))}
                  for m in sorted(fits)]
    return Identification(
        model=MaxwellSlip(chosen.k[order], chosen.fc[order]),
        elements=elements,
        offset=chosen.c if prob.fit_offset else 0.0,
        offset_std=float(std[-1]) if prob.fit_offset else 0.0,
        initial_forces=(chosen.alpha * chosen.fc)[order],
        fit_rms=fit_rms,
        fit_nrms=fit_rms / ref_rms if ref_rms > 0 else float("inf"),
        r2=1.0 - chosen.rss / tss if tss > 0 else float("nan"),
        n_samples=int(n_rows),
        criterion=how,
        candidates=candidates,
        signal=signal_name,
        cutoff_hz=cutoff_hz,
        covariance=_covariance_of(chosen, n_rows, order, std),
        order_stop=stopped,
    )


#: The automatic order search's trend is judged from this many orders' systematic errors
TREND_ORDERS = 3


def _reachable_share(shares: dict[int, float], n_top: int) -> float:
    """The least systematic error (a share of the force's RMS) the orders up to `n_top` can
    reach at the trend of the last :data:`TREND_ORDERS` orders' `shares`: each order beyond
    the last multiplies it by the smaller of the last two orders' factors.  Fits of more
    elements gain less and less where elements do not describe the link (a Dahl damper's
    24,000 samples: 11.3, 8.9, 7.0, 6.6, 6.3, 6.2 % from 2 to 7 elements), so that is an
    optimist's trend; 0 until :data:`TREND_ORDERS` orders are fitted.

    Examples
    --------
    >>> round(_reachable_share({2: 0.113, 3: 0.089, 4: 0.070}, 8), 4)  # 0.070 * 0.787 ** 4
    0.0268
    >>> round(_reachable_share({2: 0.2, 3: 0.089, 4: 0.070}, 8), 4)    # 0.070 * 0.445 ** 4
    0.0027
    """
    n = max(shares)
    if any(n - m not in shares for m in range(TREND_ORDERS)):
        return 0.0
    last, before, first = shares[n], shares[n - 1], shares[n - 2]
    if not (before > 0 and first > 0):
        return 0.0
    factor = min(1.0, last / before, before / first)
    return float(last * factor ** (n_top - n))


def residuals_and_jacobian(prob: FitProblem, ident: Identification
                           ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The residuals of an identification's link on its fit's problem and their Jacobian:
    what its standard errors come from (:func:`~motionhyst.identify.io_uncertainty.covariance`;
    the closed-loop route's with the residuals' autocorrelation,
    :func:`~motionhyst.identify.closed_loop.identify_closed_loop`).

    Parameters
    ----------
    prob : FitProblem
        The problem `ident` was fitted on (:func:`identify_prepared`).
    ident : Identification
        Its result: the link's elements in their order, their initial forces and the
        offset.

    Returns
    -------
    r : ndarray
        The model's force less the target at the problem's rows [N].
    J : ndarray
        ``d r / d theta``, columns ``k[0..n-1]``, ``fc[0..n-1]``, the elements' initial
        states ``alpha = f_0 / fc`` where the problem estimates them, and the offset (a
        column of zeros where the problem fixes it at 0).

    Examples
    --------
    >>> from motionhyst import MaxwellSlip
    >>> t = np.linspace(0.0, 4.0, 4001)
    >>> x = 0.01 * np.exp(-t / 2) * np.sin(2 * np.pi * 2.0 * t)
    >>> w = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x)
    >>> prob = FitProblem(x=x, target=w, rows=fit_rows(0, x.size, MAX_ROWS), filt=None,
    ...                   fit_initial=True)
    >>> ident = identify_prepared(prob, None, "rms", 0.01, 1e-3, MAX_ELEMENTS, "force")
    >>> r, J = residuals_and_jacobian(prob, ident)
    >>> J.shape, bool(np.sqrt(np.mean(r ** 2)) <= ident.fit_rms * (1 + 1e-9))
    ((4001, 7), True)
    """
    n = ident.n_elements
    k, fc = np.asarray(ident.model.k, float), np.asarray(ident.model.fc, float)
    alpha = np.divide(ident.initial_forces, fc, out=np.zeros(n), where=fc > 0)
    r, J = _evaluate(prob, _pack(k, fc, alpha, ident.offset, prob.fit_initial), n, True)
    return r, J


def fit_rows(start: int, n: int, max_rows: int) -> NDArray[np.intp]:
    stride = max(1, int(np.ceil((n - start) / max(int(max_rows), 1))))
    return np.arange(start, n, stride)


def identify_maxwell_slip(x: ArrayLike, w: ArrayLike, n_elements: int | None = None, *,
                          t: ArrayLike | None = None, criterion: Criterion = "rms",
                          rtol: float = 0.01, atol: float = 1e-3,
                          initial_state: Literal["fit", "relaxed"] = "fit",
                          max_elements: int = MAX_ELEMENTS, max_rows: int = MAX_ROWS,
                          target_share: float | None = None) -> Identification:
    """Identify Maxwell-slip (parallel Jenkins, eq. 3) parameters from a force-displacement record.

    Parameters
    ----------
    x : array_like
        Displacement samples [m], taken as monotone between samples; it must
        reverse at least once.
    w : array_like
        Force samples [N], same length; may contain a constant offset.
    n_elements : int, optional
        Number of Jenkins elements; chosen by `criterion` if omitted.
    t : array_like, optional
        Sample times [s]; only checked (strictly increasing): the element is
        rate-independent.
    criterion : {"rms", "bic"}
        Order selection: ``"rms"`` takes the smallest number of elements whose
        RMS residual exceeds the best over all orders tried by no more than
        ``max(rtol * best, atol * RMS(w - mean w))``; ``"bic"`` minimises the
        Bayesian information criterion ``n log(RSS / n) + p log n``.
    rtol, atol : float
        Relative and absolute (as a fraction of the force's RMS) tolerances of
        the ``"rms"`` criterion; another element is tried only while it
        improves the RMS residual by more than this margin.  `atol` keeps
        elements that explain less than 0.1 % of the force out of nearly
        noise-free fits.
    initial_state : {"fit", "relaxed"}
        ``"fit"`` estimates each element's force at the first sample (records
        that start in an unknown state); ``"relaxed"`` takes every element as
        unstressed there (a system started from rest, as
        :func:`motionhyst.time.simulation.simulate`).
    max_elements : int
        Most elements tried when `n_elements` is omitted.
    max_rows : int
        Most samples used in the residual (evenly strided); the stop operators
        always run on every sample.
    target_share : float, optional
        The systematic error (beyond the residual's white noise, a share of the force's
        RMS: :func:`~motionhyst.identify.io_checks.systematic_share`) a fit must reach: the
        automatic order search stops once the trend of its orders' systematic errors cannot
        reach it by `max_elements` (:func:`_reachable_share`; said in the result's
        ``order_stop``).  None (default): every order is tried while it helps.

    Returns
    -------
    Identification

    Raises
    ------
    ValueError
        For records that are too short, non-finite, of inconsistent lengths,
        with constant displacement, without a reversal, or with non-increasing
        time.

    Notes
    -----
    See the module docstring for the method (grid of stop operators, NNLS,
    bounded least-squares refinement, order criterion, covariance).

    Examples
    --------
    A two-element cable slab measured under a decaying sine:

    >>> import numpy as np
    >>> from motionhyst import MaxwellSlip
    >>> from motionhyst.identify import identify_maxwell_slip
    >>> t = np.linspace(0.0, 4.0, 4001)
    >>> x = 0.01 * np.exp(-t / 2) * np.sin(2 * np.pi * 2.0 * t)
    >>> w = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x)
    >>> ident = identify_maxwell_slip(x, w, t=t)
    >>> ident.n_elements                                   # chosen by the RMS criterion
    2
    >>> print(np.round(ident.model.k, 4), np.round(ident.model.fc, 5))
    [10.  6.] [0.01 0.03]
    """
    xs = np.ascontiguousarray(np.asarray(x, dtype=float))
    ws = np.asarray(w, dtype=float)
    ts = None if t is None else np.asarray(t, dtype=float)
    check_signals(xs, {"force": ws}, ts)
    if initial_state not in ("fit", "relaxed"):
        raise ValueError(f"unknown initial_state {initial_state!r}; use 'fit' or 'relaxed'")
    prob = FitProblem(x=xs, target=ws, rows=fit_rows(0, xs.size, max_rows), filt=None,
                      fit_initial=initial_state == "fit")
    ident = identify_prepared(prob, n_elements, criterion, rtol, atol, max_elements, "force",
                              target_share=target_share)
    return correlated_std(ident, prob)


def correlated_std(ident: Identification, prob: FitProblem) -> Identification:
    """A force-displacement fit's standard errors with its residuals' autocorrelation, as an
    input-output fit's (:func:`~motionhyst.identify.io_uncertainty.correlated_errors`): a
    force sensor's noise through its filter, or a link that is not the record's, leaves
    residuals correlated from sample to sample, and the usual standard errors are too
    narrow (a two-element link under force noise through a first-order low-pass, ``rho``
    0.95: the truth within 3 of them for 25-58 % of 12 records, 13.7 of them away at
    worst).  The elements' and the offset's standard errors and the covariance are widened;
    those of white residuals are kept as ``judged_std`` (what judges a slip force
    determined); a fit leaving more than the record's white noise says its standard errors
    are lower bounds (``std_lower_bound``), and a value its widened standard error exceeds
    where the white one does not is warned (:meth:`Identification.widened_note`).

    Parameters
    ----------
    ident : Identification
        The fit (:func:`identify_prepared`), changed in place.
    prob : FitProblem
        Its problem.

    Returns
    -------
    Identification
        `ident`.

    Examples
    --------
    A two-element link from a record with white force noise: the standard errors as they
    were (within a few %), none said to be lower bounds.

    >>> from motionhyst import MaxwellSlip
    >>> t = np.arange(6000) / 1000.0
    >>> x = 1e-3 * (np.sin(2 * np.pi * 0.5 * t) + 0.4 * np.sin(2 * np.pi * 1.3 * t))
    >>> w = MaxwellSlip(k=[2e4, 8e3], fc=[2.0, 6.0]).response(x)
    >>> w = w + 0.05 * np.random.default_rng(0).standard_normal(t.size)
    >>> ident = identify_maxwell_slip(x, w, 2, t=t)
    >>> white = ident.judged_std["fc[0]"]
    >>> bool(abs(ident.elements[0]["fc_std"] / white - 1) < 0.1), ident.std_lower_bound
    (True, None)
    """
    from motionhyst.identify.io_uncertainty import correlated_errors

    n = ident.n_elements
    r, J = residuals_and_jacobian(prob, ident)
    errors = correlated_errors(J, [r], 1e-9, unit="N",
                               signal_rms=float(np.sqrt(np.mean(prob.y ** 2))))
    ident.judged_std = {f"{p}[{i}]": e[f"{p}_std"] for i, e in enumerate(ident.elements)
                        for p in ("k", "fc")}
    std = errors.std
    for i, e in enumerate(ident.elements):  # where the fit says not determined, it stays so
        for name, j in (("k_std", i), ("fc_std", n + i)):
            if math.isfinite(e[name]) and math.isfinite(std[j]):
                e[name] = float(std[j])
    if prob.fit_offset and math.isfinite(ident.offset_std) and math.isfinite(std[-1]):
        ident.judged_std["offset"] = ident.offset_std
        ident.offset_std = float(std[-1])
    idx = [*range(2 * n), J.shape[1] - 1]  # k, fc in the elements' order, the offset
    names = [*(["k", "fc"] if n == 1 else [f"{p}[{i}]" for p in ("k", "fc") for i in range(n)]),
             "offset"]
    sd = {nm: float(std[j]) if math.isfinite(std[j]) else None
          for nm, j in zip(names, idx, strict=True)}
    if ident.covariance is not None:
        kept = ident.covariance["parameters"]  # where the fit says not determined, left out
        sd = {nm: v if nm in kept else None for nm, v in sd.items()}
        ident.covariance = covariance_table(names, errors.cov[np.ix_(idx, idx)], sd)
    ident.std_lower_bound = errors.note
    note = ident.widened_note()
    if note is not None:  # determined on white residuals, not beyond the model's error
        warn(note)
    return ident
