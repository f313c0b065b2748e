"""Running a study: batches of points in this process, a local process pool or on dask.

A batch goes out as plain parameters (the study's dictionary, once per worker, and flat point
indices) and comes back as compact records: the indices, a status byte and the output fields
(8 or 16 bytes each) per point.  A worker builds the study once and warms the compiled kernels
on its first point; consecutive points of a batch share one loop (the reference axes vary
fastest).  A point's numbers do not depend on its batch, its worker or the engine.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.study.outputs import OUTPUTS, Point, fields_of, nan_of
from motionhyst.study.spec import REFERENCE_AXES, Study
from motionhyst.study.store import FAILED, OK

__all__ = ["BATCH_SECONDS", "Evaluator", "evaluate_batch", "run_batches"]

BATCH_SECONDS = 0.1
"""Least work in one batch [s]: below it, sending and collecting cost more than computing."""

Batch = tuple[NDArray[np.int64], NDArray[np.int8], dict[str, NDArray]]


class Evaluator:
    """Computes points of one study; keeps the loop of the last scenario keys.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["mismatch"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> idx, status, values = Evaluator(st).batch([0, 1])
    >>> status.tolist(), [round(float(abs(v)), 3) for v in values["mismatch"]]
    ([1, 1], [6.041, 1.24])
    """

    def __init__(self, study: Study) -> None:
        self.study = study
        self.fields = fields_of(study.outputs)
        self._key: tuple | None = None
        self._loop = None
        self._error: Exception | None = None

    def _loop_at(self, values: dict[str, float]):
        from motionhyst.scenario import Scenario, ScenarioError

        key = tuple(v for k, v in values.items() if k not in REFERENCE_AXES)
        if key != self._key:
            self._key, self._loop, self._error = key, None, None
            try:
                self._loop = Scenario.from_dict(self.study.scenario_at(values),
                                                base_dir=self.study.base_dir).loop()
            except (ScenarioError, ValueError) as exc:
                self._error = exc
        if self._error is not None:
            raise self._error
        return self._loop

    def point(self, index: int) -> dict:
        """The output fields at the flat `index`; raises if the point cannot be computed."""
        values = self.study.point(index)
        loop = self._loop_at(values)
        p = Point(loop, values["amplitude"], values["frequency_hz"])
        out: dict = {}
        for name in self.study.outputs:
            out.update(OUTPUTS[name].evaluate(p))
        return out

    def batch(self, indices) -> Batch:
        """Compact records of the points at `indices`: a point that fails is marked failed."""
        indices = np.asarray(indices, dtype=np.int64)
        status = np.full(len(indices), OK, dtype=np.int8)
        values = {name: np.empty(len(indices), dtype=complex if kind == "complex" else float)
                  for name, kind in self.fields.items()}
        for j, i in enumerate(indices):
            try:
                res = self.point(int(i))
            except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError):
                status[j] = FAILED
                res = {name: nan_of(kind) for name, kind in self.fields.items()}
            for name in self.fields:
                values[name][j] = res[name]
        return indices, status, values

    def warm(self) -> None:
        """Compile the kernels (the first point of the study, result discarded)."""
        try:
            self.point(int(self.study.order()[0]))
        except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError):
            pass


_LOCAL = threading.local()


def _evaluator(key: str, plain: dict) -> Evaluator:
    cache = getattr(_LOCAL, "cache", None)
    if cache is None or key not in cache:
        ev = Evaluator(Study.from_plain(plain))
        ev.warm()
        _LOCAL.cache = {key: ev}
    return _LOCAL.cache[key]


def evaluate_batch(key: str, plain: dict, indices) -> Batch:
    """Compute one batch in a worker (the study built and warmed at its first batch).

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0]}},
    ...                      scenario=base)
    >>> idx, status, values = evaluate_batch(st.fingerprint(), st.to_dict(), [0])
    >>> print(f"{values['error_rms'][0]:.3e} m")
    8.176e-09 m
    """
    return _evaluator(key, plain).batch(indices)


def _init_worker(key: str, plain: dict) -> None:
    # Ctrl-C reaches the whole process group: the command stops its workers itself
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _evaluator(key, plain)


def _pool_batch(key: str, indices) -> Batch:
    return _LOCAL.cache[key].batch(indices)


def split(indices: NDArray[np.int64], size: int) -> list[NDArray[np.int64]]:
    """`indices` in consecutive batches of `size` (the last one shorter).

    Examples
    --------
    >>> [b.tolist() for b in split(np.arange(5), 2)]
    [[0, 1], [2, 3], [4]]
    """
    return [indices[i:i + size] for i in range(0, len(indices), size)]


@dataclass
class _Pool:
    workers: int
    key: str
    plain: dict

    def run(self, batches: list) -> Iterator[Batch]:
        import multiprocessing as mp

        pending = list(range(len(batches)))
        restarts = 0
        # forked workers start with this process's modules and compiled kernels (a spawned
        # one imports and loads them again: seconds on a loaded machine)
        method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
        while pending:
            ctx = mp.get_context(method)
            pool = ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_init_worker,
                                       initargs=(self.key, self.plain))
            try:
                futures = {pool.submit(_pool_batch, self.key, batches[i]): i for i in pending}
                while futures:
                    done, _ = wait(futures, return_when=FIRST_COMPLETED)
                    for f in done:
                        i = futures.pop(f)
                        yield f.result()
                        pending.remove(i)
            except BrokenProcessPool:
                restarts += 1
                if restarts > 3:
                    raise RuntimeError("the local workers died four times; giving up (the "
                                       "store keeps what was computed)") from None
            except BaseException:
                # Ctrl-C or the caller stopped: no batch in the workers' hands is worth waiting
                procs = getattr(pool, "_processes", None) or {}
                for proc in list(procs.values()):
                    proc.terminate()
                raise
            finally:
                pool.shutdown(wait=False, cancel_futures=True)


def _dask_run(client, key: str, plain: dict, batches: list) -> Iterator[Batch]:
    from distributed import as_completed

    [plain_f] = client.scatter([plain], broadcast=True, hash=False)
    futures = [client.submit(evaluate_batch, key, plain_f, b, pure=False) for b in batches]
    try:
        for f in as_completed(futures):
            yield f.result()
            f.release()
    finally:
        client.cancel(futures)


def run_batches(study: Study, batches: list, workers: int = 1, client=None
                ) -> Iterator[Batch]:
    """Compute `batches` (lists of flat indices) and yield their records as they finish.

    ``workers = 0`` computes in this process; ``workers >= 1`` in a local process pool;
    `client` (a ``distributed.Client``) on its cluster.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> [idx.tolist() for idx, _, _ in run_batches(st, [[0], [1]], workers=0)]
    [[0], [1]]
    """
    key = study.fingerprint()
    plain = study.to_dict()
    if client is not None:
        yield from _dask_run(client, key, plain, batches)
    elif workers == 0:
        ev = Evaluator(study)
        for b in batches:
            yield ev.batch(b)
    else:
        yield from _Pool(workers, key, plain).run(batches)


def seconds_per_point(study: Study, n: int = 3) -> float:
    """Time of one point, measured on up to `n` points spread over the study (warm)."""
    ev = Evaluator(study)
    ev.warm()
    order = study.order()
    pick = order[np.linspace(0, len(order) - 1, min(n, len(order))).astype(int)]
    t0 = time.perf_counter()
    ev.batch(pick)
    return (time.perf_counter() - t0) / len(pick)


def batch_size(seconds: float, n_missing: int, workers: int) -> int:
    """Points in a batch: at least BATCH_SECONDS of work, else enough batches for the workers.

    Examples
    --------
    >>> batch_size(0.001, 10_000, 2)        # 1 ms a point: 8 batches a worker of >= 0.1 s
    625
    >>> batch_size(0.001, 500, 2)           # a small study: batches of 0.1 s
    100
    """
    least = max(1, math.ceil(BATCH_SECONDS / max(seconds, 1e-9)))
    spread = max(1, math.ceil(n_missing / (8 * max(workers, 1))))
    return max(least, min(spread, 10 * least))
