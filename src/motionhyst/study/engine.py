"""Running a study: batches of points in this process, a local process pool or on dask.

A batch goes out as plain parameters (the study's dictionary, once per worker, and flat point
indices) and comes back as compact records: the indices, a status byte and the output fields
(8 or 16 bytes each) per point.  A worker builds the study once and warms the compiled kernels
on its first point; consecutive points of a batch share one loop (the reference axes vary
fastest).  A point's numbers do not depend on its batch, its worker or the engine.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
import warnings
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.warnings import MotionhystWarning
from motionhyst.study.heap import heap_kept
from motionhyst.study.outputs import OUTPUTS, Point, fields_of, nan_of
from motionhyst.study.spec import StudyDefinition, is_scenario_key
from motionhyst.study.store import FAILED, OK

__all__ = ["BATCH_SECONDS", "DASK_BATCH_SECONDS", "DASK_CLUSTER_CONFIG", "ENOUGH_SECONDS",
           "Batch", "Evaluator", "dask_environment", "evaluate_batch", "quiet_cluster",
           "run_batches"]

BATCH_SECONDS = 0.1
"""Least work in one batch of the local pool [s]: below it, sending and collecting cost more
than computing."""

ENOUGH_SECONDS = 0.05
"""A point that takes this long [s] is timed on two points, its loop's first and the next
(:func:`seconds_per_point`): half of a batch's least work, known well enough."""

DASK_BATCH_SECONDS = 0.5
"""Least work in one batch on dask [s]: a task costs its scheduler, client and worker about
5 ms of CPU together, 1 % of this."""

DASK_CLUSTER_CONFIG: dict[str, object] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
}
"""dask's settings for a cluster that runs studies: the timers of dask's own diagnostics at a
pace that costs a study little.  A cluster runs them whether it computes or not, and a study
pays for them as long as it runs: a scheduler and two single-thread workers with their nannies
take 0.07-0.11 s of CPU a second idle with dask's defaults, 0.005-0.016 s with these (on two
idle cores dask's cost past the local pool's for the same points: +3.2 % and +1.1 % of the
pool's CPU time, ``benchmarks/study.py``).  Each server's event-loop health
check (a warning when the loop was blocked for 3 s) every second rather than every 20 ms,
the most of it; no statistical profiler (a sample of the stack of every thread running a task
every 10 ms, for the dashboard's profile); the workers' and nannies' memory monitor (spilling,
pausing and restarting a worker at its memory limits) every second rather than every 0.1 s (a
study's memory is flat: its batches come back as compact records); the system monitor (the
dashboard's CPU, memory and network plots) every 5 s rather than 0.5 s.  Work stealing costs
nothing measurable idle.  :func:`dask_environment` gives them as the environment of ``dask
scheduler`` and ``dask worker``; a study run on a cluster started otherwise sets its timers to
this pace while it runs (:func:`quiet_cluster`)."""

# dask's timers (a server's periodic callbacks) that DASK_CLUSTER_CONFIG paces, and the key of
# each one's interval
_TIMERS = {"tick": "distributed.admin.tick.interval",
           "monitor": "distributed.admin.system-monitor.interval",
           "memory_monitor": "distributed.worker.memory.monitor-interval"}
_PROFILER = ("profile", "profile-cycle")

# why a point failed (motionhyst.study.store.REASONS)
_LOOP, _CONVERGE, _OUTPUT, _NUMERIC = 1, 2, 3, 4


class Batch(NamedTuple):
    """The compact records of one batch of points.

    Parameters
    ----------
    indices : ndarray of int64
        Flat indices of the points.
    status : ndarray of int8
        ``OK`` or ``FAILED`` per point.
    values : dict of str to ndarray
        Each output field per point (NaN where the point failed).
    reason : ndarray of int8
        Why a point failed (:data:`motionhyst.study.store.REASONS`; 0 if it did not).
    failures : dict of int to str
        The message of the batch's first failed point of each reason.
    cpu_seconds : float
        CPU time of the thread that computed the points [s] (the work of the points, apart
        from what the engine costs around them).

    Examples
    --------
    >>> b = Batch(np.array([3]), np.array([OK], np.int8), {"e1": np.array([1j])},
    ...           np.array([0], np.int8), {})
    >>> b.indices.tolist(), b.status.tolist(), b.cpu_seconds
    ([3], [1], 0.0)
    """

    indices: NDArray[np.int64]
    status: NDArray[np.int8]
    values: dict[str, NDArray]
    reason: NDArray[np.int8]
    failures: dict[int, str]
    cpu_seconds: float = 0.0


class Evaluator:
    """Computes points of one study; keeps the loop of the last scenario keys.

    Parameters
    ----------
    study : Study
        The study.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict(
    ...     {"outputs": ["mismatch"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> b = Evaluator(st).batch([0, 1])
    >>> b.status.tolist(), [round(float(abs(v)), 3) for v in b.values["mismatch"]]
    ([1, 1], [6.041, 1.24])
    """

    def __init__(self, study: StudyDefinition) -> None:
        self.study = study
        self.fields = fields_of(study.outputs)
        self._key: tuple | None = None
        self._loop = None
        self._unset: tuple[str, ...] = ()
        self._error: Exception | None = None

    def _loop_at(self, values: dict[str, float]):
        from motionhyst.scenario import Scenario, ScenarioError

        key = tuple(v for k, v in values.items() if is_scenario_key(k))
        if key != self._key:
            self._key, self._loop, self._error = key, None, None
            try:
                with warnings.catch_warnings():  # a measured plant's fit: not once a point
                    warnings.simplefilter("ignore", MotionhystWarning)
                    source = self.study.scenario_source
                    sc = Scenario.from_dict(self.study.scenario_at(values),
                                            source="the scenario" if source == "<dict>"
                                            else source, base_dir=self.study.base_dir)
                    self._loop = sc.loop()
                self._unset = tuple(t for t in ("jerk", "snap")
                                    if getattr(sc.model.feedforward, t, 0.0) is None)
            except (ScenarioError, ValueError) as exc:
                self._error = exc
        if self._error is not None:
            raise self._error
        return self._loop

    def point(self, index: int) -> dict:
        """The output fields at the flat `index`; raises if the point cannot be computed.

        Parameters
        ----------
        index : int
            Flat index of the point.
        """
        values = self.study.point(index)
        return self._outputs(self._loop_at(values), values)

    def _outputs(self, loop, values: dict[str, float]) -> dict:
        # a study of scans alone has no reference axes (its points are no sines)
        p = Point(loop, values.get("amplitude", math.nan), values.get("frequency_hz", math.nan),
                  self.study.scan_at(values), self._unset)
        out: dict = {}
        for name in self.study.outputs:
            out.update(OUTPUTS[name].evaluate(p))
        return out

    def _failure(self, index: int) -> tuple[int, str, dict]:
        """Compute the point at `index`: (0, "", fields) or (reason, message, {})."""
        values = self.study.point(index)
        try:
            loop = self._loop_at(values)
        except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError) as exc:
            return _LOOP, str(exc), {}
        try:
            return 0, "", self._outputs(loop, values)
        except RuntimeError as exc:  # a link's step: its remedy is an argument a study lacks
            return _CONVERGE, getattr(exc, "what", str(exc)), {}
        except ValueError as exc:
            return _OUTPUT, str(exc), {}
        except (ArithmeticError, np.linalg.LinAlgError) as exc:
            return _NUMERIC, f"{type(exc).__name__}: {exc}", {}

    def batch(self, indices) -> Batch:
        """Compact records of the points at `indices`: a point that fails is marked failed,
        with its reason; the CPU time they took.

        Parameters
        ----------
        indices : array_like of int
            Flat indices of the points.
        """
        t0 = time.thread_time()
        indices = np.asarray(indices, dtype=np.int64)
        status = np.full(len(indices), OK, dtype=np.int8)
        reason = np.zeros(len(indices), dtype=np.int8)
        failures: dict[int, str] = {}
        values = {name: np.empty(len(indices), dtype=complex if kind == "complex" else float)
                  for name, kind in self.fields.items()}
        for j, i in enumerate(indices):
            code, message, res = self._failure(int(i))
            if code:
                status[j], reason[j] = FAILED, code
                if code not in failures:
                    at = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                                   for k, v in self.study.point(int(i)).items())
                    failures[code] = f"point {int(i)} ({at}): {message}"
                res = {name: nan_of(kind) for name, kind in self.fields.items()}
            for name in self.fields:
                values[name][j] = res[name]
        return Batch(indices, status, values, reason, failures, time.thread_time() - t0)

    def warm(self) -> None:
        """Compile the kernels (the first point of the study, result discarded)."""
        try:
            self.point(int(self.study.order()[0]))
        except (ValueError, RuntimeError, ArithmeticError, np.linalg.LinAlgError):
            return
        _WARMED.add(self.study.fingerprint())


# the studies whose kernels this process compiled (a worker forked from it has them too)
_WARMED: set[str] = set()


_FREE: dict[str, list[Evaluator]] = {}
_FREE_LOCK = threading.Lock()


def _evaluator(key: str, plain: dict, warm: bool = True) -> Evaluator:
    """A warm evaluator of the study `key` that no other thread uses (a worker keeps them
    between batches whichever of its threads runs the next one; only the last study's);
    `warm` False: the process has the study's kernels already."""
    with _FREE_LOCK:
        free = _FREE.get(key)
        if free is None:
            _FREE.clear()
            free = _FREE[key] = []
        if free:
            return free.pop()
    ev = Evaluator(StudyDefinition.from_plain(plain))
    if warm:
        ev.warm()
    return ev


def _release(key: str, ev: Evaluator) -> None:
    with _FREE_LOCK:
        free = _FREE.get(key)
        if free is not None:
            free.append(ev)


def evaluate_batch(key: str, plain: dict, indices) -> Batch:
    """Compute one batch in a worker (the study built and warmed at its first batch).

    Parameters
    ----------
    key : str
        The study's fingerprint (a worker keeps one study's evaluator).
    plain : dict
        The study's :meth:`~motionhyst.study.spec.Study.to_dict`.
    indices : array_like of int
        Flat indices of the points.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0]}},
    ...                      scenario=base)
    >>> b = evaluate_batch(st.fingerprint(), st.to_dict(), [0])
    >>> print(f"{b.values['error_rms'][0]:.3e} m")
    8.176e-09 m
    """
    with heap_kept():   # a dask worker's trim threshold would return the heap after each point
        ev = _evaluator(key, plain)
        try:
            return ev.batch(indices)
        finally:
            _release(key, ev)


def dask_environment() -> dict[str, str]:
    """:data:`DASK_CLUSTER_CONFIG` as the environment variables dask reads when its processes
    start (``DASK_`` and the key in capitals, ``__`` between its levels).

    Examples
    --------
    >>> for name, value in dask_environment().items():
    ...     print(f"{name}={value}")
    DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL=1s
    DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False
    DASK_DISTRIBUTED__WORKER__MEMORY__MONITOR_INTERVAL=1s
    DASK_DISTRIBUTED__ADMIN__SYSTEM_MONITOR__INTERVAL=5s
    """
    return {"DASK_" + key.upper().replace(".", "__").replace("-", "_"): str(value)
            for key, value in DASK_CLUSTER_CONFIG.items()}


def _pace(quiet: bool, dask_worker) -> None:
    """The timers of one dask server (scheduler, worker or nanny: ``client.run`` passes it as
    `dask_worker`) at the pace of :data:`DASK_CLUSTER_CONFIG` (`quiet`), or at the one its
    own configuration gives (whatever a run stopped by SIGKILL left)."""
    import dask.config
    from dask.utils import parse_timedelta

    timers = getattr(dask_worker, "periodic_callbacks", {})
    for name, key in _TIMERS.items():
        if name in timers:
            value = DASK_CLUSTER_CONFIG[key] if quiet else dask.config.get(key)
            timers[name].callback_time = 1000 * parse_timedelta(value, default="ms")
    for name in _PROFILER:
        if name in timers:      # its configuration enables the profiler
            if quiet:
                timers[name].stop()
            elif not timers[name].is_running():
                timers[name].start()


def _pace_cluster(client, quiet: bool) -> None:
    client.run_on_scheduler(_pace, quiet)
    client.run(_pace, quiet, on_error="ignore")
    if any(info.get("nanny") for info in client.scheduler_info()["workers"].values()):
        client.run(_pace, quiet, nanny=True, on_error="ignore")


@contextlib.contextmanager
def quiet_cluster(client) -> Iterator[None]:
    """dask's diagnostics on `client`'s cluster at the pace of :data:`DASK_CLUSTER_CONFIG`
    while the block runs, then at the pace each process's configuration gives.

    The scheduler's, the workers' and the nannies' event-loop health check, system monitor
    and memory monitor take their intervals from :data:`DASK_CLUSTER_CONFIG`, and the workers'
    profiler stops; after the block (an error or Ctrl-C included) each takes the interval of
    its process's configuration again and the profiler runs again where it is enabled.  What
    runs on the cluster meanwhile, a study's batches or others' work, is neither profiled nor
    health-checked as often.  A run killed (SIGKILL) leaves the pace as it was set, until the
    next run's end.  A cluster that refuses ``Client.run`` is left as it is.

    Parameters
    ----------
    client : distributed.Client
        The cluster's client.

    Examples
    --------
    >>> from distributed import Client, LocalCluster
    >>> def tick(dask_worker):      # the worker's event-loop health check [ms]
    ...     return dask_worker.periodic_callbacks["tick"].callback_time
    >>> with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
    ...                   dashboard_address=":0") as cluster, Client(cluster) as client:
    ...     with quiet_cluster(client):
    ...         during = list(client.run(tick).values())
    ...     after = list(client.run(tick).values())
    >>> during, after
    ([1000], [20.0])
    """
    from distributed.comm.core import CommClosedError

    try:
        _pace_cluster(client, True)
    except (OSError, TimeoutError, CommClosedError, ValueError):
        pass
    try:
        yield
    finally:
        try:
            _pace_cluster(client, False)
        except (OSError, TimeoutError, CommClosedError, ValueError):
            pass


_WORKER_STUDY: dict = {}


def _init_worker(key: str, plain: dict, warm: bool) -> None:
    # Ctrl-C reaches the whole process group: the command stops its workers itself
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER_STUDY["plain"] = plain
    _release(key, _evaluator(key, plain, warm))


def _pool_batch(key: str, indices) -> Batch:
    # the study came once, with the worker's start
    return evaluate_batch(key, _WORKER_STUDY["plain"], indices)


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

        done_batches: set[int] = set()
        restarts = 0
        # forked workers start with this process's modules and compiled kernels (a spawned
        # one imports and loads them again: seconds on a loaded machine)
        method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
        # forked from a process that computed a point of this study: the kernels are compiled
        # (a point to warm them costs a worker a point's time: a long scan's, seconds)
        warm = method != "fork" or self.key not in _WARMED
        # a few batches a worker in flight: waiting on every batch of a large study at once
        # costs this process O(batches) at each completion (a quarter of the workers' time
        # at 2000 batches), and holds them all
        window = 3 * self.workers
        while len(done_batches) < len(batches):
            ctx = mp.get_context(method)
            pool = ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_init_worker,
                                       initargs=(self.key, self.plain, warm))
            try:
                todo = iter([i for i in range(len(batches)) if i not in done_batches])
                futures: dict = {}
                while True:
                    for i in todo:
                        futures[pool.submit(_pool_batch, self.key, batches[i])] = i
                        if len(futures) >= window:
                            break
                    if not futures:
                        break
                    done, _ = wait(futures, return_when=FIRST_COMPLETED)
                    for f in done:
                        i = futures.pop(f)
                        yield f.result()
                        done_batches.add(i)
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

    # the study's dictionary (about 1 kB) goes with each batch: scattered, its only copy left
    # by dask's memory manager on a worker that dies would cancel every batch still to run
    with quiet_cluster(client):
        futures = [client.submit(evaluate_batch, key, plain, b, pure=False)
                   for b in batches]
        try:
            for f in as_completed(futures):
                yield f.result()
                f.release()
        finally:
            client.cancel(futures)


def run_batches(study: StudyDefinition, batches: list, workers: int = 1, client=None
                ) -> Iterator[Batch]:
    """Compute `batches` (lists of flat indices) and yield their records as they finish.

    ``workers = 0`` computes in this process; ``workers >= 1`` in a local process pool;
    `client` (a ``distributed.Client``) on its cluster.

    Parameters
    ----------
    study : Study
        The study.
    batches : list of lists of int
        The batches, each a list of flat indices.
    workers : int
        0: in this process; >= 1: a local process pool of that size.
    client : distributed.Client, optional
        A dask cluster's client to compute on instead.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict(
    ...     {"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> [b.indices.tolist() for b in run_batches(st, [[0], [1]], workers=0)]
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


def seconds_per_point(study: StudyDefinition, n: int = 3, cpu: bool = False) -> float:
    """Time of one point over the study, measured on about `n` points (warm).

    Consecutive points share their loop (:meth:`StudyDefinition.order`) and what it
    computes once per frequency: the first point on a loop costs more than the next ones.
    The points are timed in runs of consecutive ones from spread places of the study; a
    run's first point's extra counts once for each loop of the study, not once a point.  A
    point that takes :data:`ENOUGH_SECONDS` or more (a long scan's) is timed with the next
    point of its loop alone; cheaper runs are timed twice past their first point, the smaller
    time kept (on a loaded machine a point interrupted by another process reads more).

    Parameters
    ----------
    study : StudyDefinition
        The study.
    n : int
        Points to time (at least 2).
    cpu : bool
        The CPU time of the thread computing them (the work, whatever the load of the
        machine: what a batch's size is chosen from) rather than the wall time.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0]}},
    ...                                scenario=base)
    >>> 0 < seconds_per_point(st, cpu=True) < 1
    True
    """
    clock = time.thread_time if cpu else time.perf_counter
    ev = Evaluator(study)
    ev.warm()
    order = study.order()
    runs = 1 if n < 4 else 2
    size = max(2, n // runs)
    starts = np.linspace(0, max(len(order) - size, 0), runs).astype(int)
    first = rest = 0.0
    n_rest = timed = 0
    for s in starts:
        run = order[s:s + size]
        ev._key = None      # its loop built anew (the warm-up's point may be the run's first)
        t0 = clock()
        ev.batch(run[:1])
        t1 = clock()
        dear = t1 - t0 >= ENOUGH_SECONDS and timed == 0
        if dear:
            # a dear point (a long scan's): the next point of its loop gives its cost past the
            # loop's construction well enough; timing more would throw seconds of work away
            run = run[:2]
        ev.batch(run[1:])
        t2 = clock()
        steady = t2 - t1
        if not dear and t2 - t0 < ENOUGH_SECONDS:
            # the same points again, the smaller time kept: a point that another process
            # interrupted (its caches taken) reads more, the more so the more loaded the machine
            ev.batch(run[1:])
            steady = min(steady, clock() - t2)
        first += t1 - t0
        rest += steady
        n_rest += len(run) - 1
        timed += 1
        if dear:
            break
    if n_rest == 0:
        return first / timed
    steady = rest / n_rest
    loops = math.prod(len(v) for k, v in study.axes.items() if is_scenario_key(k)) * (
        study.n_samples if any(map(is_scenario_key, study.sampled_keys)) else 1)
    return steady + max(first / timed - steady, 0.0) * loops / study.n_points


def batch_size(seconds: float, n_missing: int, workers: int,
               least_seconds: float = BATCH_SECONDS) -> int:
    """Points in a batch: at least `least_seconds` of work, else enough batches for the
    workers (eight each, for the balance), at most ten times the least.

    Parameters
    ----------
    seconds : float
        Time of one point [s].
    n_missing : int
        Points to compute.
    workers : int
        Workers computing them.
    least_seconds : float
        Least work in a batch [s] (:data:`BATCH_SECONDS`, :data:`DASK_BATCH_SECONDS`).

    Examples
    --------
    >>> batch_size(0.001, 10_000, 2)        # 1 ms a point: 8 batches a worker of >= 0.1 s
    625
    >>> batch_size(0.001, 500, 2)           # a small study: batches of 0.1 s
    100
    >>> batch_size(0.001, 10_000, 2, DASK_BATCH_SECONDS)
    625
    >>> batch_size(0.001, 1_000_000, 2, DASK_BATCH_SECONDS)
    5000
    """
    least = max(1, math.ceil(least_seconds / max(seconds, 1e-9)))
    spread = max(1, math.ceil(n_missing / (8 * max(workers, 1))))
    return max(least, min(spread, 10 * least))
