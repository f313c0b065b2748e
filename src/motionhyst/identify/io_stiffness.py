"""A friction link's stiffness profiled on a grid: the search past its local minima.

On a positioning axis (a mass-damper, friction its only hold) a Jenkins link sticks and
slips at events that move with its stiffness ``k``, and the records' cost over ``k`` is not
convex: a refinement from the search's starts (the short runs' best and the rigid limit,
:func:`~motionhyst.identify.io_refine.refine`) can end in one well while another, some
stiffnesses away, fits the records better.  Measured on EMPS periods 3-4 (the Jenkins link
with viscous friction by direction and the force offset drifting, the 20-sample
initialisation window): the refinement ends at k 2.3e6 N/m, 0.2337 mm RMS; with ``k`` held
at 1e7 N/m and the other parameters refined, 0.2288 mm.

:func:`profile_stiffness` holds ``k`` at each value of :func:`stiffness_grid` in turn (a
logarithmic grid over the stiffnesses the records resolve), refines the other parameters
from the refinement's end with each, and refines everything from the held fit of least cost
when it fits the records better than that end; the end of least cost is kept.  The choice
is the estimation records' cost alone.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult

from motionhyst.identify.io_budget import BudgetSpent
from motionhyst.identify.io_friction import PRESLIDING_BOUND, STUCK_MODE_SAMPLES
from motionhyst.identify.io_records import IORecord

__all__: list[str] = []  # the element links' search's internals

#: Values of the stiffness grid per decade
PER_DECADE = 3
#: The most steps (evaluations of the residuals) of a refinement with the stiffness held
HELD_STEPS = 25
#: ``ftol``, ``xtol`` and ``gtol`` of a refinement with the stiffness held: it ends once a step
#: gains less than this share of its cost (EMPS periods 3-4: held at a stiffness of a poorer
#: well, after 3-5 steps; at 1.3e7 N/m, still gaining, after 20)
HELD_TOL = 1e-4


def stiffness_grid(records: list[IORecord], m: float, fc: float) -> NDArray[np.float64]:
    """The stiffnesses a Jenkins link on a positioning axis is profiled at [N/m].

    Logarithmic, :data:`PER_DECADE` values a decade, from the stiffness whose slip
    displacement ``fc / k`` is :data:`~motionhyst.identify.io_friction.PRESLIDING_BOUND` of the
    records' stroke (softer, the link is a spring across the motion, no friction) to the one
    whose stuck mode ``sqrt(k / m) / 2 pi`` is at the sampling rate over
    :data:`~motionhyst.identify.io_friction.STUCK_MODE_SAMPLES` (stiffer, the records cannot
    tell the link from its rigid limit, the Coulomb link, which the search starts from
    already), both ends included.

    Parameters
    ----------
    records : list of IORecord
        The records identified from (their stroke and sampling rate).
    m : float
        The axis's mass [kg].
    fc : float
        The link's slip force [N].

    Returns
    -------
    ndarray
        The stiffnesses, ascending; empty where the bounds leave none (no stroke, no mass,
        no slip force).

    Examples
    --------
    A 0.25 m stroke sampled at 1 kHz, 95 kg and 20 N (EMPS): 8e4 to 2.3e8 N/m.

    >>> t = np.arange(1000) / 1000.0
    >>> rec = IORecord(t, np.zeros(t.size), 0.125 * np.sin(2 * np.pi * t))
    >>> [f"{k:.2g}" for k in stiffness_grid([rec], 95.0, 20.0)]
    ['8e+04', '1.7e+05', '3.4e+05', '7.1e+05', '1.5e+06', '3e+06', '6.2e+06', '1.3e+07', \
'2.7e+07', '5.5e+07', '1.1e+08', '2.3e+08']
    >>> stiffness_grid([rec], 95.0, 0.0).size
    0
    """
    stroke = max(float(np.ptp(rec.y)) for rec in records)
    lo = fc / (PRESLIDING_BOUND * stroke) if stroke > 0 else math.inf
    hi = m * (2 * math.pi * records[0].fs / STUCK_MODE_SAMPLES) ** 2
    if not (0 < lo < hi < math.inf):
        return np.empty(0)
    return np.geomspace(lo, hi, math.ceil(PER_DECADE * math.log10(hi / lo)) + 1)


def profile_stiffness(prob, sol: OptimizeResult, index: int, grid: NDArray[np.float64],
                      tol: float, max_nfev: int, reserve: int) -> OptimizeResult:
    """The refinement's end `sol` of the search problem `prob`, or a better one from its
    stiffness profile.

    The variable `index` of `prob` (a link's stiffness, searched as its logarithm) is held
    at each value of `grid` in turn, the others refined from `sol` with it (at most
    :data:`HELD_STEPS` steps each, ended at :data:`HELD_TOL`); from the held fit of least
    cost, if it costs less than `sol`, everything is refined (at most `max_nfev` steps, `tol`
    as the search's), and that end is returned where it costs less than `sol`.

    With a budget (``prob.budget``), `reserve` evaluations are kept for what follows; the
    held fits share half of the rest, each an equal part, and are not run where that part is
    under two steps; the refinement from the best has what they leave.

    Parameters
    ----------
    prob : _ElementProblem
        The search problem on all records (:mod:`~motionhyst.identify.io_elements`).
    sol : OptimizeResult
        Its refinement's end (``x`` the free variables, ``cost`` half the sum of squares).
    index : int
        The stiffness's place among the problem's variables.
    grid : ndarray
        The stiffnesses held [N/m] (:func:`stiffness_grid`).
    tol : float
        The ``ftol``, ``xtol`` and ``gtol`` of the refinement from the best held fit.
    max_nfev : int
        The most steps of the refinement from the best held fit.
    reserve : int
        Evaluations a budget keeps for what follows (the standard errors).

    Returns
    -------
    OptimizeResult
        `sol`, or the refinement from the best held fit where it ends at a lower cost.
    """
    plan = prob.budget
    if not grid.size or not prob.free[index]:
        return sol
    q_end = prob.whole(sol.x)
    free = prob.free.copy()
    free[index] = False
    held = type(prob)(prob.records, prob.periodic, prob.r, prob.layout, prob.y_scale,
                      prob.scale, free, q_end, plant=prob.plant, extras=prob.extras,
                      window=prob.window, budget=plan)
    held.exact, held.fd_step = prob.exact, prob.fd_step
    steps = 1 + int(held.free.sum())  # the evaluations of a step: a run and its Jacobian
    each = None if plan.left is None else (plan.left - reserve) // (2 * grid.size)
    if each is not None and each < 2 * steps:
        return sol  # a budget too small for the profile: the refinement's end as it is
    best = None
    try:
        for k in grid:
            v = prob.values(q_end)
            v[index] = k
            held.fixed = prob.variables(v)
            with plan.share(each):
                try:
                    fit = held.solve(held.fixed[held.free], HELD_TOL, HELD_STEPS)
                except BudgetSpent:
                    continue
            if best is None or fit.cost < best[0]:
                best = (fit.cost, held.whole(fit.x))
    finally:
        prob.n_eval += held.n_eval
    if best is None or best[0] >= sol.cost:
        return sol
    left = None if plan.left is None else plan.left - reserve
    if left is not None and left < 2 * (1 + sol.x.size):
        return sol
    with plan.share(left):
        try:
            end = prob.solve(best[1][prob.free], tol, max_nfev)
        except BudgetSpent:
            return sol
    return end if end.cost < sol.cost else sol
