"""The last step of an input-output search of a stage and a link: its refinement on all records.

:func:`~motionhyst.identify.io_elements.identify_elements_io` refines the best of its starts
on all the records.  Where each record's initial state is estimated, the state carried over
from the starts may lie in another well of the initial velocity (a friction link slipping at
the start, the position offset making up for it): the refinement also runs from each record's
initial state as its first :data:`~motionhyst.identify.io_predict.INIT_WINDOW` samples set it
(:func:`state_start`), and the better end is kept (:func:`refine`).

A rigid slider (the Coulomb link) sticks and slips at events that move step by step with the
parameters: on a floating stage a stick mispredicted shifts the whole rest of the record, so
that the records' cost has wells side by side (on a Coulomb axis of 6000 samples, 1e-4 apart
in the logarithm of the mass), and its secants (a step of 1e-3) span many of them.  Its
refinement therefore starts with the records cut into segments
(:func:`~motionhyst.identify.io_records.segment_records`), each with its own position offset
and initial velocity (:func:`on_segments`: a stick mispredicted costs only its segment), and
ends with its secants' step shrunk tenfold in turn (to :data:`FINEST_SECANT`), each end kept
where it fits the records better.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult

from motionhyst.identify.io_budget import BudgetSpent
from motionhyst.identify.io_predict import INIT_WINDOW
from motionhyst.identify.io_records import segment_records
from motionhyst.identify.io_start import extras_start

__all__: list[str] = []

#: The finest step of a rigid slider's secants (relative, in the search variables)
FINEST_SECANT = 1e-6
#: Steps of the whole records' refinement a budget must leave for a rigid slider's segments
#: and finer secants
RIGID_STEPS = 40


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


def on_segments(prob, q_free: NDArray[np.float64], tol: float, max_nfev: int | None
                ) -> NDArray[np.float64]:
    """`q_free` refined on the records of the search problem `prob` (a floating stage's,
    each record's position offset and initial velocity estimated) cut into segments
    (:func:`~motionhyst.identify.io_records.segment_records`), each with its own position offset and
    initial velocity (started at its first sample and its first samples' slope), the stage's
    and link's values and the force offset shared; the records' own offsets and states as
    they were.  `q_free` itself where no record is longer than two segments or the
    refinement cannot run."""
    ex = prob.extras
    base = prob.n_plant + prob.n_link
    parts = [part for _, part in segment_records(prob.records)]
    if len(parts) <= len(prob.records) or not prob.free.all():
        return q_free
    cut = replace(ex, n_records=len(parts))
    size = {name.split("[")[0]: sc for name, sc in zip(ex.names, prob.scale[base:], strict=True)}
    scale = np.concatenate([prob.scale[:base], [size[nm.split("[")[0]] for nm in cut.names]])
    seg = type(prob)(parts, False, prob.r, prob.layout, prob.y_scale, scale, plant=prob.plant,
                     extras=cut, budget=prob.budget)
    seg.exact, seg.fd_step = prob.exact, prob.fd_step
    v = prob.values(q_free)
    shared = int(ex.input_offset) + int(ex.input_drift)
    start = extras_start(cut, parts, True, 0.0)
    start[:shared] = v[base:base + shared]
    try:
        sol = seg.solve(seg.variables(np.concatenate([v[:base], start])), tol, max_nfev)
    except BudgetSpent:
        return q_free
    finally:
        prob.n_eval += seg.n_eval
    w = v.copy()
    w[:base + shared] = seg.values(sol.x)[:base + shared]
    return prob.variables(w)


def refine(prob, q0: NDArray[np.float64], tol: float, max_nfev: int | None, reserve: int,
           from_window: bool, rigid: bool = False, segments: bool = False
           ) -> tuple[OptimizeResult, NDArray[np.float64], int | None]:
    """The search problem `prob` refined from `q0` and, with `from_window`, from
    :func:`state_start` of it too, the end of least cost kept; with `segments`, on segments
    first (:func:`on_segments`), and a `rigid` slider's at its end with its secants' step
    shrunk tenfold in turn to :data:`FINEST_SECANT`, each end kept where it lowers the cost
    (the step set back after: the standard errors' secants are the search's).

    With a budget (``prob.budget``), `reserve` evaluations are kept for what follows and the
    stages share the rest, each an equal part of what those before it left (the refinement
    from the window's state and each shrunk step only where its part is two steps, the
    segments and finer secants only where the rest is :data:`RIGID_STEPS` steps).
    Returns the refinement's result, its start and the evaluations it was allowed.
    """
    plan, secant = prob.budget, prob.fd_step
    if plan.left is not None and plan.left - reserve < RIGID_STEPS * (1 + q0.size):
        rigid = segments = False  # a budget too small for them: the refinements alone
    shrinks = round(np.log10(prob.fd_step / FINEST_SECANT)) if rigid else 0
    stages = [segments, True, from_window, *([True] * shrinks)]

    def part(k: int) -> int | None:  # the share of stage k
        return None if plan.left is None else (plan.left - reserve) // sum(stages[k:])

    def enough(k: int) -> bool:
        return plan.left is None or part(k) >= 2 * (1 + q0.size)

    if segments:
        share = part(0)
        with plan.share(share):
            q1 = on_segments(prob, q0, tol, max_nfev if share is None else share)
        if q1 is not q0:  # near the wells' bottom: the records refined with finer secants
            q0, shrinks = q1, shrinks - 1
            prob.fd_step /= 10.0
            stages.pop()
    runs = [q0]
    if from_window and enough(1):
        q_state = state_start(prob, q0)
        runs += [] if q_state is None else [q_state]
    stages[2] = len(runs) > 1
    sol, start, most = None, q0, max_nfev
    for k, q in enumerate(runs, 1):
        share = part(k)
        try:
            with plan.share(share):
                end = prob.solve(q, tol, max_nfev if share is None else share)
        except BudgetSpent:
            if sol is None:
                raise
            continue  # the further refinement's share ran not even its start
        if sol is None or end.cost < sol.cost:
            sol, start, most = end, q, max_nfev if share is None else share
    for k in range(3, 3 + shrinks):
        if not enough(k):
            break
        prob.fd_step /= 10.0
        share = part(k)
        try:
            with plan.share(share):
                end = prob.solve(sol.x, tol, max_nfev if share is None else share)
        except BudgetSpent:
            break
        if end.cost < sol.cost:
            sol, most = end, max_nfev if share is None else share
    prob.fd_step = secant  # the standard errors' differences as the search's
    return sol, start, most
