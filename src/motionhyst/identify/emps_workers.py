"""Work spread over processes: the EMPS benchmark's fits, each chain of them in a worker.

The benchmark identifies several link models on each split of its record; a Jenkins link
starts from the Coulomb fit with the same options (its rigid limit), so the models come in
chains that run one after another, and the chains of all splits are independent of each
other.  :func:`map_in_workers` runs such tasks in forked worker processes, each task's work
the same computation as in one process: the results are the same to the last digit (a test
holds them to it), only the wall-clock time differs.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_EXCEPTION, ProcessPoolExecutor, wait
from contextlib import AbstractContextManager, nullcontext
from typing import Any

__all__ = ["map_in_workers", "usable_cores"]


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the system says it).

    Returns
    -------
    int
        The count of those cores (one where the system tells none).

    Examples
    --------
    >>> usable_cores() >= 1
    True
    """
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # pragma: no cover - platforms without affinity
        return os.cpu_count() or 1


def map_in_workers(work: Callable[[Any], Any], tasks: Sequence[Any], workers: int,
                   guard: Callable[[], AbstractContextManager] | None = None,
                   started: Callable[[int], None] | None = None,
                   finished: Callable[[int, Any], None] | None = None) -> list[Any]:
    """``[work(task) for task in tasks]``, the tasks run in up to `workers` processes.

    The workers are forked from this process (they see its modules as they are, its
    settings included); where the system cannot fork, or with one worker or one task, the
    tasks run here one after another.  The first task that raises ends the map with its
    exception, and so does an interrupt (Ctrl-C, SIGTERM) here: the tasks not started are
    not, and the workers still running one are stopped at once.

    Parameters
    ----------
    work : callable
        A function of the module level (a worker finds it by its name).
    tasks : sequence
        Its arguments, one a task (picklable, as its results).
    workers : int
        The most processes at once.
    guard : callable, optional
        Returns the context each task runs in within its worker (a CPU-time limit, say:
        a worker's time is its own, not this process's).
    started, finished : callable, optional
        Called here with a task's index as it is handed to a worker, and with its index
        and result as it ends (in the order the tasks end).

    Returns
    -------
    list
        The results in the order of `tasks`.

    Examples
    --------
    >>> map_in_workers(abs, [-3, 2, -1], workers=2)
    [3, 2, 1]
    """
    if workers <= 1 or len(tasks) <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        out = []
        for i, task in enumerate(tasks):
            if started is not None:
                started(i)
            out.append(work(task))
            if finished is not None:
                finished(i, out[-1])
        return out
    results: list[Any] = [None] * len(tasks)
    before = set(multiprocessing.active_children())
    pool = ProcessPoolExecutor(max_workers=min(workers, len(tasks)),
                               mp_context=multiprocessing.get_context("fork"))
    try:
        index = {}
        for i, task in enumerate(tasks):
            index[pool.submit(_guarded, work, task, guard)] = i
            if started is not None:
                started(i)
        pending = set(index)
        while pending:
            done, pending = wait(pending, return_when=FIRST_EXCEPTION)
            for future in sorted(done, key=index.__getitem__):
                if future.exception() is not None:
                    raise future.exception()
                results[index[future]] = future.result()
                if finished is not None:
                    finished(index[future], results[index[future]])
    except BaseException:  # a task's error, Ctrl-C or SIGTERM: the workers end now
        pool.shutdown(wait=False, cancel_futures=True)
        for worker in set(multiprocessing.active_children()) - before:
            worker.terminate()
        raise
    pool.shutdown()
    return results


def _guarded(work: Callable[[Any], Any], task: Any,
             guard: Callable[[], AbstractContextManager] | None) -> Any:
    """`work` of `task` within `guard`'s context (a worker's task)."""
    with nullcontext() if guard is None else guard():
        return work(task)
