"""Input-output identification of a stage with a Bouc-Wen link.

The link of the benchmark (Noel and Schoukens 2016) in the general form,
``z' = alpha y' - beta (gamma |y'| |z|^(nu-1) z + delta y' |z|^nu)``, on a
mass-spring-damper (:func:`identify_bouc_wen_msd`) or on the floating two-mass stage
of eqs. (1)-(2) (:func:`identify_bouc_wen_two_mass`, its starts :func:`_two_mass_start`).
The simulation residuals and their exact Jacobian, from forward sensitivities
integrated with the model (:func:`~motionhyst.time.openloop.simulate_bouc_wen`), are
:class:`_BoucWenProblem`'s; the trust-region refinement is :func:`_solve`.

``beta`` only enters as ``beta*gamma`` and ``beta*delta``, so those products are
estimated and the returned link is normalised to ``|gamma| + |delta| = 1``
(:func:`_bouc_wen_link`).

On a mass-damper (a positioning axis) the link is a friction link and is searched as
the registry's element links are
(:func:`~motionhyst.identify.io_friction.bouc_wen_friction`).
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult

from motionhyst.core.blas import few_blas_threads
from motionhyst.hysteresis import BoucWen, Hysteresis
from motionhyst.identify.io_budget import BudgetSpent, EvaluationBudget, solve_within
from motionhyst.identify.io_memory import REMEDY, check_bouc_wen_memory
from motionhyst.identify.io_records import IORecord, short_records
from motionhyst.identify.io_results import IOIdentification, per_record_errors
from motionhyst.identify.io_start import (
    best_linear_approximation,
    best_linear_approximation_two_mass,
    check_substeps,
)
from motionhyst.identify.io_uncertainty import (
    SINGULAR_RTOL,
    correlated_errors,
    covariance_table,
    undetermined_notes,
)
from motionhyst.time.openloop import (
    MIN_SUBSTEPS,
    STEPS_PER_MODE_PERIOD,
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    fine_input,
    simulate_bouc_wen,
)

__all__ = []


class _BoucWenProblem:
    """Simulation residuals of the stage with a general Bouc-Wen link, and their Jacobian.

    The parameter vector: the plant's first three parameters, ``alpha,
    beta*gamma, beta*delta, nu``, then the plant's others (a two-mass stage's
    ``k``), so that the link's always sit at 3-6.  `plant` gives the kind of
    plant (default: a mass-spring-damper).
    """

    def __init__(self, records: list[IORecord], periodic: bool, substeps: int,
                 free: NDArray[np.bool_], fixed: NDArray[np.float64], y_scale: float,
                 force_scale: float = 1.0, plant: MassSpringDamper | TwoMass | None = None,
                 output_offset: bool = False, budget: EvaluationBudget | None = None):
        self.y_scale = y_scale  # residuals in units of the output's RMS
        self.plant = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
        n_plant = len(self.plant.PARAMETERS)
        # problem order -> simulation order (the plant's parameters, then the link's)
        self.order = np.r_[0:3, 7:4 + n_plant, 3:7]
        # a floating stage's periodic output is known up to a constant: compared without means
        self.centre = periodic and isinstance(self.plant, TwoMass)
        # each record's position offset, linear: projected out (the residuals and their
        # sensitivities without their means per record); the offsets are the means
        self.output_offset = output_offset
        # with nu free the products are searched as beta*gamma F^(nu - 1) (and delta): the
        # size of beta*gamma |z|^nu at |z| ~ F, which then does not move with nu
        self.force_scale = force_scale if free[6] else 1.0
        self.records = records
        self.periodic = periodic
        self.r = substeps
        self.free = free
        self.fixed = fixed
        self.fine = [fine_input(rec.u, 2 * substeps, periodic) for rec in records]
        self.n_eval = 0  # the runs, each charged to the search's budget first
        self.budget = budget if budget is not None else EvaluationBudget()

    def full(self, q_free: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray:
        """Parameters ``m, c, k, alpha, beta*gamma, beta*delta, nu`` (and a two-mass stage's
        ``k``) of the search variables."""
        p = self.fixed.copy()
        p[self.free] = q_free * scale[self.free]
        if self.force_scale != 1.0:
            p[4:6] *= self.force_scale ** (1.0 - p[6])
        return p

    def variables(self, p: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray:
        """The search variables of the parameters `p` (inverse of :meth:`full`)."""
        q = p / scale
        if self.force_scale != 1.0:
            q[4:6] /= self.force_scale ** (1.0 - p[6])
        return q[self.free]

    def jacobian(self, dy_dp: NDArray[np.float64], p: NDArray[np.float64],
                 scale: NDArray[np.float64]) -> NDArray:
        """Derivatives in the search variables from those in the parameters (chain rule)."""
        J = dy_dp * scale
        if self.force_scale != 1.0:
            f = self.force_scale ** (1.0 - p[6])
            J[:, 6] -= math.log(self.force_scale) * scale[6] * (dy_dp[:, 4] * p[4]
                                                                 + dy_dp[:, 5] * p[5])
            J[:, 4:6] *= f
        return J[:, self.free]

    def run(self, p: NDArray[np.float64], jac: bool):
        self.budget.charge(1)
        self.n_eval += 1

        def one(i):
            rec = self.records[i]
            try:
                y, s = simulate_bouc_wen(p[self.order], rec.u, rec.fs, self.r,
                                         periodic=self.periodic, sensitivities=jac,
                                         upsampled=self.fine[i], plant=self.plant)
            except ValueError:  # no periodic steady state: a point the search must leave
                return np.full(rec.u.size, np.nan), np.zeros((rec.u.size, p.size))
            if jac:
                s_problem = np.empty_like(s)
                s_problem[:, self.order] = s
                s = s_problem
            return y, s

        if len(self.records) > 1:  # the compiled runs release the GIL: one thread per record
            with ThreadPoolExecutor(max_workers=min(len(self.records), os.cpu_count() or 1)
                                    ) as pool:
                outs = list(pool.map(one, range(len(self.records))))
        else:
            outs = [one(0)]
        res = [y - (rec.y - np.mean(rec.y) if self.centre else rec.y)
               for (y, _), rec in zip(outs, self.records, strict=True)]
        rows = [s for _, s in outs]
        if self.output_offset:
            res = [e - np.mean(e) for e in res]
            if jac:
                rows = [s - np.mean(s, axis=0) for s in rows]
        r = np.concatenate(res) / self.y_scale
        if not np.all(np.isfinite(r)):
            r = np.full_like(r, 1e3)
        return r, (np.concatenate(rows) / self.y_scale if jac else None)


def _solve(prob: _BoucWenProblem, p0: NDArray[np.float64], scale: NDArray[np.float64],
           tol: float, max_nfev: int, share: int | None = None):
    """Trust-region refinement of the free parameters (m > 0; c, k, alpha >= 0; nu >= 1),
    within `share` more of the problem's budget (at its start if not even that runs)."""
    cache: dict = {}

    # the sensitivities cost ~40 % of a run and are needed at every accepted point:
    # computed with every residual, kept for the Jacobian of the same point
    def evaluate(q):
        key = q.tobytes()
        hit = cache.get(key)
        if hit is not None:
            return hit
        p = prob.full(q, scale)
        r, s = prob.run(p, True)
        cache.clear()
        cache[key] = (r, s, p)
        return r, s, p

    def fun(q):
        return evaluate(q)[0]

    def jacobian(q):
        _, s, p = evaluate(q)
        return prob.jacobian(s, p, scale)

    q0 = prob.variables(p0, scale)
    # m > 0 and c, k, alpha >= 0 (a stage and link that exist), nu >= 1
    low = np.array([1e-6, 0.0, 0.0, 0.0, -np.inf, -np.inf, 1.0 / scale[6]])
    if prob.fixed.size > 7:  # a two-mass stage (m1, m2, b, ..., k): m1, m2, k > 0, b >= 0
        low = np.array([1e-6, 1e-6, 0.0, 0.0, -np.inf, -np.inf, 1.0 / scale[6], 1e-6])
    lower = low[prob.free]
    q0 = np.where(np.isfinite(lower), np.maximum(q0, lower + 1e-9 * np.abs(q0) + 1e-12), q0)
    rows = sum(rec.y.size for rec in prob.records)
    with prob.budget.share(share), few_blas_threads(rows, q0.size):  # each step's SVD: small
        try:
            return solve_within(fun, q0, jac=jacobian, method="trf", x_scale=1.0, ftol=tol,
                                xtol=tol, gtol=tol, max_nfev=max_nfev, bounds=(lower, np.inf))
        except BudgetSpent:
            return OptimizeResult(x=q0, cost=math.inf, status=0, nfev=0,
                                  message="The budget of model evaluations is spent.")


def _force_scale(p: NDArray[np.float64], y_scale: float) -> float:
    """A typical link force ``|z|`` [N]: ``alpha y_scale``, or the ultimate force if smaller."""
    alpha, b, nu = p[3], p[4] + p[5], p[6]
    f = abs(alpha) * y_scale
    if b > 0.0 and alpha > 0.0:
        f = min(f, (alpha / b) ** (1.0 / nu))
    return f if math.isfinite(f) and f > 0.0 else 1.0


def identify_bouc_wen_msd(records: list[IORecord], periodic: bool, nu: float | None,
                          substeps: int | None, tol: float, max_nfev: int, t_start: float,
                          output_offset: bool = False,
                          budget: EvaluationBudget | int | None = None) -> IOIdentification:
    """The mass-spring-damper and a Bouc-Wen link (problem order ``m, c, k, alpha,
    beta*gamma, beta*delta, nu``): the linear model by simulation error on a short part
    of the records, the starts of :func:`_bouc_wen_starts` screened there by one
    simulation each and the best refined there, then :func:`_refine` on all records from
    the best start whose result is a valid system.  With `output_offset` each record's
    position offset is estimated too (projected out of the search: the residuals are
    compared without their means; the offsets and their standard errors at the end).
    `budget` (its limit ``identify --max-evaluations``) is charged by every run."""
    plan = budget if isinstance(budget, EvaluationBudget) else EvaluationBudget(budget)
    used0, n_chosen = plan.used, len(BASIC_STARTS) + START_REFINED
    _, shares = plan.plan_starts(1 + n_chosen, 1, runs=len(_bouc_wen_starts(
        np.ones(7), 1.0, 1.0)))
    bla = best_linear_approximation(records)
    fs = records[0].fs
    r = substeps or OpenLoop(bla).default_substeps(fs)
    check_substeps(records, r, None)  # its steps, as every stage's, before the starts run
    check_bouc_wen_memory([rec.u.size for rec in records], r)
    y_scale = float(np.sqrt(np.mean(np.concatenate([rec.y for rec in records]) ** 2)))
    # scales: m, c, k from the BLA; alpha like k; the products like 1 / y_scale; nu 1
    scale = np.array([bla.m, max(bla.c, 1e-3 * bla.m), bla.k, bla.k, 1.0 / y_scale,
                      1.0 / y_scale, 1.0])
    free = np.array([True] * 6 + [nu is None])
    nu0 = 1.0 if nu is None else float(nu)

    # 1. the linear model by simulation error (link off), on a short part of the records
    short = short_records(records, periodic)
    lin_free = np.array([True, True, True, False, False, False, False])
    prob = _BoucWenProblem(short, periodic, r, lin_free,
                           np.array([bla.m, bla.c, bla.k, 0.0, 0.0, 0.0, nu0]), y_scale,
                           output_offset=output_offset, budget=plan)
    sol = _solve(prob, prob.fixed, scale, 1e-10, 30, next(shares))
    lin = prob.full(sol.x, scale)

    # 2. starts (nu at its start value; a free nu joins in the refinement): each simulated
    # once on the short part of the records; the basic ones and the best others refined there
    free_start = free.copy()
    free_start[6] = False
    sp = _BoucWenProblem(short, periodic, r, free_start, lin, y_scale,
                         output_offset=output_offset, budget=plan)
    screened = []
    for i, p0 in enumerate(_bouc_wen_starts(lin, y_scale, nu0)):
        try:
            res, _ = sp.run(p0, False)
        except BudgetSpent:  # the linear fit took the screening's part: screened so far
            break
        screened.append((float(res @ res), i, p0))
    screened.sort(key=lambda c: c[:2])
    chosen = [c for c in screened if c[1] < len(BASIC_STARTS)]
    chosen += [c for c in screened if c[1] >= len(BASIC_STARTS)][:START_REFINED]
    refined = []
    for _, _, p0 in chosen:
        sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale,
                             output_offset=output_offset, budget=plan)
        s = _solve(sp, p0, scale, 1e-6, 12, next(shares))
        refined.append((float(s.cost), len(refined), sp.full(s.x, scale)))
    refined.sort(key=lambda c: c[:2])
    # 3. refinement on all records, from the best start whose result is a valid system
    error = None
    for _, _, p_start in refined[:FINAL_ATTEMPTS]:
        if error is not None and plan.left is not None and plan.left < 3 + output_offset:
            raise error  # no budget for another attempt
        p, free_used, sol, res, errors, notes, _ = _refine(
            records, periodic, r, free, p_start, y_scale, scale, tol, max_nfev,
            output_offset=output_offset, budget=plan, keep=1 + output_offset)
        try:
            link = _bouc_wen_link(p[3], p[4], p[5], p[6])
            plant = MassSpringDamper(p[0], p[1], p[2])
        except ValueError as exc:
            error = error or exc
            if plan.limit is not None and sol.status == 0:
                from motionhyst.identify.io_checks import FitFailed

                error = FitFailed(f"the fit failed: the search stopped on its budget of "
                                  f"{plan.limit} model evaluations ({plan.used} used) before "
                                  f"it reached a valid Bouc-Wen link (a larger "
                                  f"--max-evaluations may let it)")
            continue
        break
    else:
        raise error
    free = free_used
    rss = float(res @ res)
    names = ["m", "c", "k", "alpha", "beta*gamma", "beta*delta", "nu"]
    free_names = [n for n, f in zip(names, free, strict=True) if f]
    estimates = {n: float(v) for n, v in zip(names, p, strict=True) if n in free_names}
    std: dict[str, float | None] = {}
    not_ident = {"beta": "only the products beta*gamma and beta*delta enter the model "
                         "(z is not measured); beta is fixed by |gamma| + |delta| = 1",
                 "gamma": "see beta", "delta": "see beta", **notes}
    judged = _finite(free_names, errors.white_std)
    for n, s in zip(free_names, errors.std, strict=True):
        std[n] = float(s) if math.isfinite(s) else None
    not_ident.update(undetermined_notes(free_names, errors.groups, SINGULAR_RTOL))
    per_record = per_record_errors(records, res)
    extra: dict = {"covariance": covariance_table(free_names, errors.cov, std),
                   "budget_reached": bool(sol.status == 0), **errors.flags}
    if output_offset:
        offsets, offset_std, offset_judged = _output_offsets(records, periodic, r, free, p,
                                                             y_scale, plan)
        for i, (value, sd, sw) in enumerate(zip(offsets, offset_std, offset_judged,
                                                strict=True)):
            name = "output_offset" if len(records) == 1 else f"output_offset[{i}]"
            estimates[name], std[name], judged[name] = value, sd, sw
        extra["offsets"] = {"input": 0.0, "output": offsets}
    # with each record's position offset estimated, the fit is judged on the records' variations
    warnings = _judged(records, res, plant, link, {"m": plant.m}, floating=False,
                       centred=bool(output_offset))
    return IOIdentification(
        plant=plant, hysteresis=link, estimates=estimates, std=std,
        not_identifiable=not_ident, fit_rms=float(np.sqrt(rss / res.size)),
        records=per_record, seconds=time.perf_counter() - t_start, periodic=periodic,
        stopping=f"{sol.message} (ftol = xtol = gtol = {tol:g}, at most {max_nfev} "
                 f"evaluations; {sol.nfev} used)",
        n_evaluations=plan.used - used0, substeps=r, extra=extra, warnings=warnings,
        data=list(records), residuals=res, judged_std=judged)


def _output_offsets(records, periodic, r, free, p, y_scale, budget):
    """Each record's position offset (the mean of its data less the model's output), its
    standard error and that of white residuals, from the Jacobian of the parameters and
    offsets together."""
    prob = _BoucWenProblem(records, periodic, r, free, p, y_scale, budget=budget)
    res, jac = prob.run(p, True)
    offsets, columns, i = [], [], 0
    for rec in records:
        rows = slice(i, i + rec.y.size)
        offsets.append(float(-np.mean(res[rows]) * y_scale))
        e = np.zeros(res.size)
        e[rows] = 1.0
        columns.append(e)
        i += rec.y.size
    J = np.column_stack([jac[:, free] * y_scale, *columns])
    parts = [e - np.mean(e) for e in _by_record(records, res * y_scale)]  # offsets taken out
    errors = correlated_errors(J, parts)
    return offsets, *([float(s) if math.isfinite(s) else None for s in std[-len(records):]]
                      for std in (errors.std, errors.white_std))


def _judged(records: list[IORecord], res: NDArray[np.float64], plant, link,
            masses: dict[str, float], floating: bool, centred: bool = False) -> list[str]:
    """:func:`~motionhyst.identify.io_checks.judge_fit` (raises ``FitFailed``) and the
    implausible estimates' warnings of a Bouc-Wen fit (`res`: predicted minus measured;
    `centred`: compared without their means, a floating stage's periodic records)."""
    from motionhyst.identify.io_checks import judge_fit, plausibility_warnings
    from motionhyst.identify.io_start import reference_mass

    predictions, i = [], 0
    for rec in records:
        predictions.append(rec.y + res[i:i + rec.y.size])
        i += rec.y.size
    fit_rms = float(np.sqrt(np.mean(res ** 2)))
    judge_fit(fit_rms, records, predictions, None, OpenLoop(plant, link), centred)
    linear_mass = reference_mass(records, floating)
    return plausibility_warnings({}, masses, linear_mass, records, [], floating=floating)


#: Starts of the Bouc-Wen link, screened by one simulation each: the link's initial
#: stiffness ``alpha`` as a share of the linear model's stiffness ``k``, taken from the
#: stage's (``split``) or added to it (a link that saturates early hardly shows in ``k``);
#: ``beta*gamma`` in units of 1/output-RMS; ``delta/gamma``: no ultimate force on loading
#: (-1), an ultimate force ``alpha/(beta*gamma)`` (0), or an in-between (-0.5)
START_SHARES = (0.25, 0.5, 0.75)
START_PRODUCTS = (0.5, 2.0, 8.0, 32.0)
START_RATIOS = (-1.0, -0.5, 0.0)
#: The starts always refined on the short part of the records (share, beta*gamma in units
#: of 1/output-RMS, delta/gamma = -1), and how many of the other screened starts join them
BASIC_STARTS = tuple((share, lam) for share in START_SHARES for lam in (0.5, 2.0))
START_REFINED = 2
#: Refinements on all records tried, best start first, until one gives a valid link
FINAL_ATTEMPTS = 3


def _bouc_wen_starts(lin: NDArray[np.float64], y_scale: float, nu: float
                     ) -> list[NDArray[np.float64]]:
    """Start parameters ``m, c, k, alpha, beta*gamma, beta*delta, nu`` around the linear fit."""
    starts = [np.array([lin[0], lin[1], (1.0 - share) * lin[2], share * lin[2], lam / y_scale,
                        -lam / y_scale, nu]) for share, lam in BASIC_STARTS]
    for share in START_SHARES:
        for split in (True, False):
            k = (1.0 - share) * lin[2] if split else lin[2]
            for lam in START_PRODUCTS:
                for ratio in START_RATIOS:
                    if split and ratio == -1.0 and lam in (0.5, 2.0):
                        continue  # a basic start
                    starts.append(np.array([lin[0], lin[1], k, share * lin[2], lam / y_scale,
                                            ratio * lam / y_scale, nu]))
    return starts


def _refine(records, periodic, r, free, p, y_scale, scale, tol, max_nfev, plant=None,
            output_offset=False, budget=None, keep=1):
    """Refinement on all records; with ``nu`` free and no ultimate force, ``nu = 1`` if the
    data cannot tell it from 1 (the only ``nu`` such links are admitted for).  Of `budget`,
    `keep` runs are left for after it (its standard errors' run is one)."""
    notes: dict[str, str] = {}
    n_eval = 0
    plan = budget if budget is not None else EvaluationBudget()
    while True:
        prob = _BoucWenProblem(records, periodic, r, free, p, y_scale,
                               _force_scale(p, y_scale), plant=plant,
                               output_offset=output_offset, budget=plan)
        sol = _solve(prob, p, scale, tol, max_nfev,
                     None if plan.left is None else plan.left - keep)
        p = prob.full(sol.x, scale)
        res, jac = prob.run(p, True)
        n_eval += prob.n_eval
        res *= y_scale
        errors = correlated_errors(jac[:, free] * y_scale, _by_record(records, res),
                                   signal_rms=_rms(records))
        if not free[6] or p[4] + p[5] >= 0.0:
            break
        nu_std = errors.white_std[int(np.count_nonzero(free[:6]))]  # judged as white
        if not abs(p[6] - 1.0) <= max(3.0 * nu_std, 1e-9) or (
                plan.left is not None and plan.left < keep + 2):  # or no budget to refit
            break
        notes["nu"] = (f"not distinguishable from 1 (estimate {p[6]:.9g} +- {nu_std:.2g}); "
                       f"fixed at 1, as the link has no ultimate force "
                       f"(beta*(gamma + delta) < 0), admitted for nu = 1 only")
        free = free.copy()
        free[6] = False
        p[6] = 1.0
    return p, free, sol, res, errors, notes, n_eval


def _finite(names: list[str], std: NDArray[np.float64]) -> dict[str, float | None]:
    """Standard errors by name, None where not determined (not finite)."""
    return {n: float(s) if math.isfinite(s) else None for n, s in zip(names, std, strict=True)}


def _rms(records: list[IORecord]) -> float:
    """The records' positions' RMS [m]."""
    return float(np.sqrt(np.mean(np.concatenate([rec.y for rec in records]) ** 2)))


def _by_record(records: list[IORecord], res: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """The residuals `res` (the records one after the other) split by record."""
    return np.split(res, np.cumsum([rec.y.size for rec in records])[:-1])


def identify_bouc_wen_two_mass(records, periodic, nu, substeps, tol, max_nfev, output, t_start,
                               budget: EvaluationBudget | int | None = None
                               ) -> IOIdentification:
    """The two-mass stage and a Bouc-Wen link: :func:`_two_mass_start`, then :func:`_refine`
    on all records (problem order ``m1, m2, b, alpha, beta*gamma, beta*delta, nu, k``),
    every run charged to `budget` (its limit ``identify --max-evaluations``)."""
    plan = budget if isinstance(budget, EvaluationBudget) else EvaluationBudget(budget)
    used0 = plan.used
    structure, r, y_scale, scale, free, p, _ = _two_mass_start(records, periodic, nu,
                                                              substeps, output, plan)
    p, free, sol, res, errors, notes, _ = _refine(
        records, periodic, r, free, p, y_scale, scale, tol, max_nfev, plant=structure,
        budget=plan)
    link = _bouc_wen_link(p[3], p[4], p[5], p[6])
    stage = _two_mass_result(p[0], p[1], p[2], p[7], output)
    rss = float(res @ res)
    names = ["m1", "m2", "b", "alpha", "beta*gamma", "beta*delta", "nu", "k"]
    free_names = [n for n, f in zip(names, free, strict=True) if f]
    values = dict(zip(names, p, strict=True))
    std_of = _finite(free_names, errors.std)
    judged = _finite(free_names, errors.white_std)
    # the plant's parameters first, then the link's
    order = ["m1", "m2", "b", "k", "alpha", "beta*gamma", "beta*delta", "nu"]
    estimates = {n: float(values[n]) for n in order if n in free_names}
    std: dict[str, float | None] = {n: std_of[n] for n in estimates}
    not_ident = {"beta": "only the products beta*gamma and beta*delta enter the model "
                         "(z is not measured); beta is fixed by |gamma| + |delta| = 1",
                 "gamma": "see beta", "delta": "see beta", **notes}
    not_ident.update(undetermined_notes(free_names, errors.groups, SINGULAR_RTOL))
    warnings = _judged(records, res, stage, link, {"m1": stage.m1, "m2": stage.m2},
                       floating=True, centred=periodic)
    return IOIdentification(
        plant=stage, hysteresis=link, estimates=estimates, std=std,
        not_identifiable=not_ident, fit_rms=float(np.sqrt(rss / res.size)),
        records=per_record_errors(records, res), seconds=time.perf_counter() - t_start,
        periodic=periodic,
        stopping=f"{sol.message} (ftol = xtol = gtol = {tol:g}, at most {max_nfev} "
                 f"evaluations; {sol.nfev} used)",
        n_evaluations=plan.used - used0, substeps=r, warnings=warnings, data=list(records),
        residuals=res, judged_std={n: judged[n] for n in estimates},
        extra={"covariance": covariance_table(free_names, errors.cov, std),
               "budget_reached": bool(sol.status == 0), **errors.flags})


def _two_mass_start(records: list[IORecord], periodic: bool, nu: float | None,
                    substeps: int | None, output: str, plan: EvaluationBudget):
    """Steps 1-2 for the two-mass stage (problem order ``m1, m2, b, alpha, beta*gamma,
    beta*delta, nu, k``): the linear model with the link a spring ``alpha`` (its only
    hold), then starts with the link's nonlinearity, refined on a short part."""
    bla, k_link, _ = best_linear_approximation_two_mass(records, output, periodic)
    structure = TwoMass(1.0, 1.0, 0.0, 1.0, output)
    fs = records[0].fs
    f_n = bla.mechanics().natural_frequency_hz(k_link)
    r = substeps or max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n / fs))
    check_substeps(records, r, f_n, 2, sized=True)
    check_bouc_wen_memory([rec.u.size for rec in records], r)  # measured on two masses too
    _check_final_run(records[0], OpenLoop(bla), r)
    y_scale = float(np.sqrt(np.mean(np.concatenate([rec.y - (np.mean(rec.y) if periodic else 0.0)
                                                    for rec in records]) ** 2)))
    mu = bla.m1 * bla.m2 / bla.M
    scale = np.array([bla.m1, bla.m2, max(bla.b, 1e-3 * math.sqrt(bla.k * mu)), k_link,
                      1.0 / y_scale, 1.0 / y_scale, 1.0, bla.k])
    free = np.array([True] * 6 + [nu is None, True])
    nu0 = 1.0 if nu is None else float(nu)
    short = short_records(records, periodic)
    free_start = free.copy()
    free_start[6] = False
    n_eval = 0
    best = None
    _, shares = plan.plan_starts(18, 1)  # 15 starts and 3 splits of the mass
    # the link's initial stiffness is above the linear (secant) one, up to an order of
    # magnitude for a link driven into saturation; its nonlinearity neither hardening nor
    # softening (gamma + delta = 0), or softening (delta = 0), mild to strong
    for stiffer in (1.0, 3.0, 9.0):
        for lam_g, lam_d in ((0.5, -0.5), (2.0, -2.0), (8.0, -8.0), (1.0, 0.0), (4.0, 0.0)):
            p0 = np.array([bla.m1, bla.m2, bla.b, stiffer * k_link, lam_g / y_scale,
                           lam_d / y_scale, nu0, bla.k])
            sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale,
                                 plant=structure, budget=plan)
            s = _solve(sp, p0, scale, 1e-6, 12, next(shares))
            n_eval += sp.n_eval
            if best is None or s.cost < best[0]:
                best = (s.cost, sp.full(s.x, scale))
    # the split of the mass is what a linear fit of y2 sees least (and the link's
    # nonlinearity biases): from the best, other splits with the same total mass and
    # internal mode
    m_total = best[1][0] + best[1][1]
    omega2 = best[1][7] * m_total / (best[1][0] * best[1][1])
    for share in (0.25, 0.5, 0.75):
        p0 = best[1].copy()
        p0[0], p0[1] = share * m_total, (1 - share) * m_total
        p0[7] = omega2 * p0[0] * p0[1] / m_total
        sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale, plant=structure,
                             budget=plan)
        s = _solve(sp, p0, scale, 1e-6, 12, next(shares))
        n_eval += sp.n_eval
        if s.cost < best[0]:
            best = (s.cost, sp.full(s.x, scale))
    return structure, r, y_scale, scale, free, best[1], n_eval


def _check_final_run(rec: IORecord, system: OpenLoop, r: int) -> None:
    """Refuse, before the search, a record whose run of the fitted model from rest (the fit's
    judge, :func:`~motionhyst.identify.io_checks.judge_fit`, runs it at the model's own
    steps) would be above the memory budget at the search's `r` steps a sample
    (:meth:`~motionhyst.time.openloop.OpenLoop.memory`, in blocks of about 2.1e6 steps).
    It is above the search's own estimate
    (:func:`~motionhyst.identify.io_memory.bouc_wen_memory`) where a short record has many
    steps a sample (2000 samples: 8.4 MB against 8.2 at 200 steps, 16.8 against 14.6 at
    400; at 37 steps 1.6 against 3.0, and 2e4 samples 15.9 against 29.8): there it would be
    refused only after the search."""
    from motionhyst.core.budget import check_memory

    check_memory(system.memory(rec.u, r), f"{rec.name}: the run of the fitted model from rest "
                 f"({rec.u.size} samples of at least {r} integration steps each)", REMEDY)


def _two_mass_result(m1: float, m2: float, b: float, k: float, output: str) -> TwoMass:
    """The identified two-mass stage (one-line ``ValueError`` for a non-physical one)."""
    try:
        return TwoMass(m1, m2, max(b, 0.0), k, output)
    except ValueError as exc:
        raise ValueError(f"the identified two-mass stage (m1={m1:.6g}, m2={m2:.6g}, b={b:.6g}, "
                         f"k={k:.6g}) is not physical: {exc}") from None


def _bouc_wen_link(alpha: float, bg: float, bd: float, nu: float) -> Hysteresis:
    """The general Bouc-Wen link with ``|gamma| + |delta| = 1`` (``beta`` is not identifiable);
    a one-line ``ValueError`` in the link's terms when the best fit is no such link."""
    beta = abs(bg) + abs(bd)
    why = _not_a_link(alpha, bg, bd, nu)
    if why is None:
        try:
            return BoucWen.from_general(alpha, beta, bg / beta, bd / beta, nu)
        except ValueError:
            why = "a link without a finite force scale (alpha / beta)"
    raise ValueError(f"the records do not determine a Bouc-Wen link: its best fit (alpha="
                     f"{alpha:.6g}, beta*gamma={bg:.6g}, beta*delta={bd:.6g}, nu={nu:.6g}) is "
                     f"{why}; another --model (jenkins, dahl) or records of larger motion may "
                     f"determine one")


def _not_a_link(alpha: float, bg: float, bd: float, nu: float) -> str | None:
    """Why the general Bouc-Wen parameters are no link, in the link's terms (None if they
    are one; :meth:`~motionhyst.hysteresis.BoucWen.from_general`'s accepted set)."""
    if not all(map(math.isfinite, (alpha, bg, bd, nu))):
        return "not finite"
    if not alpha > 0:
        return "no spring at small motion (alpha <= 0)"
    if bg == 0.0 and bd == 0.0:
        return "a linear spring (beta*gamma = beta*delta = 0): no hysteresis"
    if bg < bd:
        return "a link whose loops would give out energy (beta*gamma < beta*delta)"
    if bg + bd <= 0 and nu != 1.0:
        return ("a link whose force grows without bound within a finite motion (beta*gamma "
                "+ beta*delta <= 0 with nu > 1)")
    if bg + bd <= 0 and bg < 0:
        return "a link whose small cycles raise its force without bound (beta*gamma < 0)"
    return None

