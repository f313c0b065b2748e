"""The Jacobian of an input-output search by forward differences, in one pool of threads.

A link without sensitivities (the rigid slider, whose secants see its stick and slip events
move) has its Jacobian by forward differences: the records run again with one search
variable stepped.  A variable that moves one record alone (its position offset, its initial
state) runs that record alone, the other records' rows being zero; every other variable runs
every record.  Each (variable, record) pair is one task of a single pool of the machine's
cores, so no task starts threads of its own: a search of many records (a rigid slider's
segments, :func:`~motionhyst.identify.io_refine.on_segments`) holds as many runs at once as
there are cores, as :func:`~motionhyst.identify.io_start.search_memory` counts them, and no
more threads (each with its stack) than that.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numpy.typing import NDArray

__all__: list[str] = []

#: A residual of a value the model refuses (as the search's own runs give it)
REFUSED = 1e3


def owners(prob) -> NDArray[np.int64]:
    """The record each free variable of the search problem `prob` moves alone (-1: every
    record)."""
    free = np.flatnonzero(prob.free)
    base = prob.n_plant + prob.n_link
    out = np.full(free.size, -1)
    for i in range(len(prob.records)):
        for j in prob.extras.columns_of_record(i):
            out[free == base + j] = i
    return out


def forward_differences(prob, q_free: NDArray[np.float64], r0: NDArray[np.float64],
                        steps: NDArray[np.float64]) -> NDArray[np.float64]:
    """The Jacobian of the residuals `r0` of the search problem `prob` at `q_free`, by
    forward differences of `steps`; a variable at which the model refuses the values has
    the residuals of a refused run (:data:`REFUSED`) in every row, as a run of all the
    records gives them.  The evaluations are charged to the search's budget: a whole one
    for each variable that moves every record, the records' share of the samples for the
    others."""
    sizes = [rec.y.size for rec in prob.records]
    rows = np.concatenate([[0], np.cumsum(sizes)])
    owner = owners(prob)
    tasks = [(j, i) for j in range(q_free.size)
             for i in (range(len(sizes)) if owner[j] < 0 else [int(owner[j])])]
    local = sum(sizes[i] for i in owner if i >= 0) / rows[-1]
    prob.charge(int(np.sum(owner < 0)) + math.ceil(local - 1e-9))
    out = np.zeros((r0.size, q_free.size))
    refused: set[int] = set()

    def task(pair: tuple[int, int]) -> None:
        j, i = pair
        q = q_free.copy()
        q[j] += steps[j]
        r = prob.run_rows(q, i if len(sizes) > 1 else None)
        if r is None:
            refused.add(j)
        else:
            out[rows[i]:rows[i + 1], j] = (r - r0[rows[i]:rows[i + 1]]) / steps[j]

    with ThreadPoolExecutor(max_workers=min(len(tasks), os.cpu_count() or 1)) as pool:
        list(pool.map(task, tasks))
    for j in refused:
        out[:, j] = (REFUSED - r0) / steps[j]
    return out
