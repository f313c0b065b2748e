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
refinement therefore also runs from the end of one on the records cut into segments, each
with its own position offset and initial velocity (:func:`on_segments`: a stick mispredicted
costs only its segment), and its best end is refined again with its secants' step shrunk
tenfold in turn (to :data:`FINEST_SECANT`), each end kept where it fits the records better.
Where the model does not fit the records to their noise (a measured axis) the segments' end
can be the worse start, and the segments' own offsets make its cost on the whole records no
guide: the ends are compared, not the starts.  Every other link on an axis refines from the
segments' end too: a stiff Jenkins link sticks and slips as sharply (k 1e8 N/m on 95 kg).
"""

from __future__ import annotations

from collections.abc import Sequence
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
    (:func:`~motionhyst.identify.io_records.segment_records`), each with its own position
    offset and initial velocity, the stage's and link's values and the force offset shared.
    Each segment starts at the state its first samples set at `q_free`'s other values
    (:func:`state_start`; where the model refuses them, a record's first segment at the
    record's own offset and state, the others at their first sample and their first
    samples' slope: a state in another well of the initial velocity, its position offset
    making up for it, is where a segment's refinement stops short), and a record's first
    segment gives its end back to the record.  `q_free` itself where no record is cut (none
    is two segments long) or the refinement cannot run."""
    ex = prob.extras
    base = prob.n_plant + prob.n_link
    cut_of = segment_records(prob.records)
    if len(cut_of) <= len(prob.records) or not prob.free.all():
        return q_free
    parts = [part for _, part in cut_of]
    cut = replace(ex, n_records=len(parts))
    size = {name.split("[")[0]: sc for name, sc in zip(ex.names, prob.scale[base:], strict=True)}
    scale = np.concatenate([prob.scale[:base], [size[nm.split("[")[0]] for nm in cut.names]])
    seg = type(prob)(parts, False, prob.r, prob.layout, prob.y_scale, scale, plant=prob.plant,
                     extras=cut, budget=prob.budget)
    seg.exact, seg.fd_step = prob.exact, prob.fd_step
    v = prob.values(q_free)
    shared = int(ex.input_offset) + int(ex.input_drift)
    first = {i: k for k, (i, _) in reversed(list(enumerate(cut_of)))}  # each record's first
    start = extras_start(cut, parts, True, 0.0)
    start[:shared] = v[base:base + shared]
    for i, k in first.items():
        start[cut.columns_of_record(k)] = v[base + np.array(ex.columns_of_record(i))]
    q_seg = seg.variables(np.concatenate([v[:base], start]))
    q_win = state_start(seg, q_seg)
    try:
        sol = seg.solve(q_seg if q_win is None else q_win, tol, max_nfev)
    except BudgetSpent:
        return q_free
    finally:
        prob.n_eval += seg.n_eval
    w, end = v.copy(), seg.values(sol.x)
    w[:base + shared] = end[:base + shared]
    for i, k in first.items():
        w[base + np.array(ex.columns_of_record(i))] = end[base + np.array(cut.columns_of_record(k))]
    return prob.variables(w)


def refine(prob, q0: NDArray[np.float64], tol: float, max_nfev: int | None, reserve: int,
           from_window: bool, rigid: bool = False, segments: bool = False,
           others: Sequence[NDArray[np.float64]] = ()
           ) -> tuple[OptimizeResult, NDArray[np.float64], int | None]:
    """The search problem `prob` refined from `q0` and, with `from_window`, from
    :func:`state_start` of it too; from each of `others` (starts whose cost was higher at the
    start, which is no guide to where they end: a Jenkins axis whose force offset drifts,
    EMPS periods 1-2, started from its rigid limit ended at 0.288 mm, from the short runs'
    best at 0.234 mm); with `segments`, also from the end of a refinement on the
    records' segments (:func:`on_segments`; near a well's bottom: a rigid slider's with
    secants a tenth as wide); the end of least cost kept.  A `rigid` slider's best end is
    refined again with its secants' step shrunk tenfold in turn to :data:`FINEST_SECANT`,
    each end kept where it lowers the cost (the step set back after: the standard errors'
    secants are the search's).

    With a budget (``prob.budget``), `reserve` evaluations are kept for what follows and the
    stages share the rest, each an equal part of what those before it left (a refinement
    from a window's state and each shrunk step only where its part is two steps, the
    segments and finer secants only where the rest is :data:`RIGID_STEPS` steps).
    Returns the refinement's result, its start (each variable the nearest of the starts
    refined: a value that ends near any of them has not run away from the search) and the
    evaluations it was allowed.
    """
    plan, secant = prob.budget, prob.fd_step
    if plan.left is not None and plan.left - reserve < RIGID_STEPS * (1 + q0.size):
        rigid = segments = False  # a budget too small for them: the refinements alone
    shrinks = round(np.log10(secant / FINEST_SECANT)) if rigid else 0
    stages = [segments, *([True] * (1 + len(others) + from_window + segments + shrinks))]

    def part(k: int) -> int | None:  # the share of stage k
        return None if plan.left is None else (plan.left - reserve) // max(sum(stages[k:]), 1)

    def enough(k: int) -> bool:
        return plan.left is None or part(k) >= 2 * (1 + q0.size)

    starts = [(q0, secant)]
    if segments:
        share = part(0)
        with plan.share(share):
            q1 = on_segments(prob, q0, tol, max_nfev if share is None else share)
        if q1 is not q0:  # near a well's bottom: a rigid slider's with finer secants
            starts.append((q1, secant / 10.0 if rigid else secant))
    runs = starts[:1]
    if from_window and enough(1):  # where the first refinement's share is two steps
        q_state = state_start(prob, q0)
        runs += [] if q_state is None else [(q_state, secant)]
    runs += [(q, secant) for q in others]
    runs += starts[1:]  # the segments' end: each record's state its first segment's
    stages[1:2 + len(others) + from_window + segments] = [True] * len(runs)
    sol, start, most, at = None, q0, max_nfev, secant
    for k, (q, step) in enumerate(runs, 1):
        share = part(k)
        prob.fd_step = step
        try:
            with plan.share(share):
                end = prob.solve(q, tol, max_nfev if share is None else share)
        except BudgetSpent:
            if sol is None:
                raise
            continue  # the further refinement's share ran not even its start
        if sol is None or end.cost < sol.cost:
            sol, start, most, at = end, q, max_nfev if share is None else share, step
    k = len(runs) + 1
    while rigid and at > FINEST_SECANT * 1.5 and enough(k):
        at /= 10.0
        prob.fd_step, share = at, part(k)
        k += 1
        try:
            with plan.share(share):
                end = prob.solve(sol.x, tol, max_nfev if share is None else share)
        except BudgetSpent:
            break
        if end.cost < sol.cost:
            sol, most = end, max_nfev if share is None else share
    prob.fd_step = secant  # the standard errors' differences as the search's
    tried = np.array([q for q, _ in runs] + [start])
    nearest = np.argmin(np.abs(tried - sol.x), axis=0)
    return sol, tried[nearest, np.arange(sol.x.size)], most
