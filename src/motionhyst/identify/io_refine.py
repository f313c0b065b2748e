"""The last step of an input-output search of a stage and a link: its refinement on all records.

:func:`~motionhyst.identify.io_elements.identify_elements_io` refines the best of its starts
on all the records.  Where each record's initial state is estimated, the state carried over
from the starts may lie in another well of the initial velocity (a friction link slipping at
the start, the position offset making up for it): the refinement also runs from each record's
initial state as its first :data:`~motionhyst.identify.io_predict.INIT_WINDOW` samples set it
(:func:`state_start`), and the better end is kept (:func:`refine`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult

from motionhyst.identify.io_budget import BudgetSpent
from motionhyst.identify.io_predict import INIT_WINDOW

__all__: list[str] = []


def state_start(prob, q_free: NDArray[np.float64], window: int = INIT_WINDOW
                ) -> NDArray[np.float64] | None:
    """`q_free` with each record's estimated initial state (and a floating stage's position
    offset) replaced by what its first `window` samples set at its other values (the search
    problem `prob`'s ``window_states``), as ``predict --init-from`` sets them; None where the
    model refuses those values."""
    v = prob.values(prob.whole(q_free))
    base, ex = prob.n_plant + prob.n_link, prob.extras
    try:
        states = prob.window_states(v, window)
    except (ValueError, ArithmeticError):  # parameters the model refuses
        return None
    floating = prob.plant.mechanics(np.ones(prob.n_plant)).floating
    for i, (position, velocity) in enumerate(states):
        cols, offset = ex.columns_of_record(i), 0.0
        if ex.output_offset:  # a floating stage's position is its output offset
            if floating:
                v[base + cols[0]] = position
            else:
                offset = v[base + cols[0]]
            cols = cols[1:]
        for j, name in zip(cols, ex.initial, strict=True):
            v[base + j] = velocity if name == "v0" else position - offset
    if not np.all(np.isfinite(v)):
        return None
    return prob.variables(v)[prob.free]


def refine(prob, q0: NDArray[np.float64], tol: float, max_nfev: int | None, reserve: int,
           from_window: bool) -> tuple[OptimizeResult, NDArray[np.float64], int | None]:
    """The search problem `prob` refined from `q0` and, with `from_window`, from
    :func:`state_start` of it too, the end of least cost kept.

    With a budget (``prob.budget``), `reserve` evaluations are kept for what follows, and the
    two refinements share the rest, each half (the second only where its half is two steps).
    Returns the refinement's result, its start and the evaluations it was allowed.
    """
    plan = prob.budget
    runs = [q0]
    if from_window and (plan.left is None or plan.left - reserve >= 4 * (1 + q0.size)):
        q_state = state_start(prob, q0)
        runs += [] if q_state is None else [q_state]
    sol, start, most = None, q0, max_nfev
    for k, q in enumerate(runs):
        share = None if plan.left is None else (plan.left - reserve) // (len(runs) - k)
        try:
            with plan.share(share):
                end = prob.solve(q, tol, max_nfev if share is None else share)
        except BudgetSpent:
            if sol is None:
                raise
            continue  # the further refinement's share ran not even its start
        if sol is None or end.cost < sol.cost:
            sol, start, most = end, q, max_nfev if share is None else share
    return sol, start, most
