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
logarithmic grid about the refinement's end, within the stiffnesses the records resolve),
refines the other parameters from the refinement's end with each, and refines everything
from the held fit of least cost when it fits the records better than that end; the end of
least cost is kept.  The choice is the estimation records' cost alone.
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

#: Values of the stiffness grid per decade (EMPS periods 3-4: the better well, 1.13e7 N/m, is
#: 0.16 decade from a value of the grid about the end 2.32e6 N/m; at two a decade the nearest
#: held values, 7.3e6 and 2.3e7 N/m, lie in the poorer wells beside it)
PER_DECADE = 3
#: The grid's span each side of the refinement's end [decades] (EMPS: the better well 0.7
#: decade from the end; the held fits beyond 1.5 decades, 7e4 and 1e8-2e8 N/m, fit the records
#: 1.1-2.5 times worse)
SPAN = 1.5
#: The most steps (evaluations of the residuals) of a refinement with the stiffness held, and
#: of the refinement of everything from the best held fit
HELD_STEPS = 25
#: ``ftol``, ``xtol`` and ``gtol`` of a refinement with the stiffness held, and of the
#: refinement from the best held fit: it ends once a step gains less than this share of its
#: cost (EMPS periods 3-4: held at a stiffness of a poorer well, after 3-5 steps; at 1.3e7
#: N/m, still gaining, after 14; refined from there at the search's 1e-12, 200 steps, 110 s of
#: CPU, gained 0.2 % of its RMS)
HELD_TOL = 1e-4


def stiffness_grid(records: list[IORecord], m: float, fc: float, k: float
                   ) -> NDArray[np.float64]:
    """The stiffnesses a Jenkins link on a positioning axis is profiled at [N/m].

    Logarithmic about the refinement's end `k` (excluded), :data:`PER_DECADE` values a decade,
    at most :data:`SPAN` decades each side of it, and within the stiffnesses the records
    resolve: from the one whose slip displacement ``fc / k`` is
    :data:`~motionhyst.identify.io_friction.PRESLIDING_BOUND` of the records' stroke (softer,
    the link is a spring across the motion, no friction) to the one whose stuck mode
    ``sqrt(k / m) / 2 pi`` is at the sampling rate over
    :data:`~motionhyst.identify.io_friction.STUCK_MODE_SAMPLES` (stiffer, the records cannot
    tell the link from its rigid limit, the Coulomb link, which the search starts from
    already).

    Parameters
    ----------
    records : list of IORecord
        The records identified from (their stroke and sampling rate).
    m : float
        The axis's mass [kg].
    fc : float
        The link's slip force [N].
    k : float
        The link's stiffness at the refinement's end [N/m].

    Returns
    -------
    ndarray
        The stiffnesses, ascending; empty where the bounds leave none (no stroke, no mass,
        no slip force).

    Examples
    --------
    A 0.25 m stroke sampled at 1 kHz, 95 kg and 20 N (EMPS, resolved from 8e4 to 2.3e8 N/m),
    the refinement ended at 2.3e6 N/m: four values a side, the stiffest four within the
    bounds.

    >>> t = np.arange(1000) / 1000.0
    >>> rec = IORecord(t, np.zeros(t.size), 0.125 * np.sin(2 * np.pi * t))
    >>> [f"{k:.2g}" for k in stiffness_grid([rec], 95.0, 20.0, 2.3e6)]
    ['1.1e+05', '2.3e+05', '5e+05', '1.1e+06', '5e+06', '1.1e+07', '2.3e+07', '5e+07']
    >>> [f"{k:.2g}" for k in stiffness_grid([rec], 95.0, 20.0, 1e8)]
    ['4.6e+06', '1e+07', '2.2e+07', '4.6e+07', '2.2e+08']
    >>> stiffness_grid([rec], 95.0, 0.0, 2.3e6).size
    0
    """
    stroke = max(float(np.ptp(rec.y)) for rec in records)
    lo = fc / (PRESLIDING_BOUND * stroke) if stroke > 0 else math.inf
    hi = m * (2 * math.pi * records[0].fs / STUCK_MODE_SAMPLES) ** 2
    if not (0 < lo < hi < math.inf) or not 0 < k < math.inf:
        return np.empty(0)
    side = math.floor(SPAN * PER_DECADE)
    grid = k * 10.0 ** (np.arange(-side, side + 1) / PER_DECADE)
    return grid[(grid != k) & (grid >= lo) & (grid <= hi)]


def profile_stiffness(prob, sol: OptimizeResult, index: int, grid: NDArray[np.float64],
                      reserve: int) -> OptimizeResult:
    """The refinement's end `sol` of the search problem `prob`, or a better one from its
    stiffness profile.

    The variable `index` of `prob` (a link's stiffness, searched as its logarithm) is held
    at each value of `grid` in turn, the others refined from `sol` with it (at most
    :data:`HELD_STEPS` steps each, ended at :data:`HELD_TOL`); from the held fit of least
    cost, if it costs less than `sol`, everything is refined (as the held fits: on a cost that
    is not smooth in the stiffness the search's own tolerance runs to its step limit for a
    fraction of a percent), and that end is returned where it costs less than `sol`.

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
            end = prob.solve(best[1][prob.free], HELD_TOL, HELD_STEPS)
        except BudgetSpent:
            return sol
    return end if end.cost < sol.cost else sol
