"""Run a study into its store, resuming what an earlier run left; estimate it first.

:func:`run_study` opens or creates the store, computes the points whose status is still
missing in batches of at least :data:`~motionhyst.study.engine.BATCH_SECONDS` of work
(:data:`~motionhyst.study.engine.DASK_BATCH_SECONDS` on dask), and gathers the results into
whole chunks of the store (:class:`~motionhyst.study.store.ChunkWriter`).  A point that fails
is recorded as failed, with its reason, and counted; Ctrl-C writes what came back; SIGKILL
or a lost worker lose at most the batches in flight and the last
:data:`~motionhyst.study.store.FLUSH_SECONDS` of results, which the same call computes again.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import resource
import shutil
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from motionhyst.core.budget import check_work, format_duration, max_seconds
from motionhyst.core.textfmt import g
from motionhyst.core.warnings import warn
from motionhyst.study.engine import (
    BATCH_SECONDS,
    DASK_BATCH_SECONDS,
    batch_size,
    run_batches,
    seconds_per_point,
    split,
)
from motionhyst.study.outputs import fields_of
from motionhyst.study.spec import StudyDefinition, StudyError
from motionhyst.study.store import (
    FAILED,
    StudyStore,
    foreign_entries,
    is_study_store,
    listed,
    remove_store,
)

__all__ = ["LOCK_NAME", "Estimate", "RunReport", "check_budget", "estimate_study",
           "machine_load", "run_lock", "run_study"]

LOCK_NAME = "zarr.json"
"""The store's file that a run holds locked (:func:`fcntl.flock`; never rewritten by a run)."""


@dataclass
class RunReport:
    """What one run did: ``points`` in the study, ``computed`` by this run, ``failed`` in the
    store (points that did not converge or whose loop could not be built), ``seconds``, and
    ``cpu_seconds``, the CPU time the points took wherever they ran.

    Parameters
    ----------
    points : int
        Points in the study.
    computed : int
        Points this run computed.
    failed : int
        Points marked failed in the store.
    seconds : float
        Wall time of the run [s].
    cpu_seconds : float
        CPU time of computing the points [s], summed over the workers (the work alone:
        not the engine's sending, collecting and writing around it).

    Examples
    --------
    >>> r = RunReport(points=400, computed=100, failed=2, seconds=4.0, cpu_seconds=7.6)
    >>> print(r)
    400 points: 100 computed in 4.0 s (25 points/s), 2 failed
    >>> print(RunReport(points=2, computed=2, failed=0, seconds=8.7))
    2 points: 2 computed in 8.7 s (0.23 points/s), 0 failed
    >>> sorted(r.to_dict())                                # the ``study --json`` schema
    ['computed', 'cpu_seconds', 'failed', 'points', 'seconds']
    """

    points: int
    computed: int
    failed: int
    seconds: float
    cpu_seconds: float = 0.0

    def to_dict(self) -> dict:
        """The ``study --json`` schema."""
        return {"points": self.points, "computed": self.computed, "failed": self.failed,
                "seconds": self.seconds, "cpu_seconds": self.cpu_seconds}

    def __str__(self) -> str:
        rate = self.computed / self.seconds if self.seconds > 0 else float("nan")
        shown = f"{rate:.0f}" if rate >= 100 else f"{rate:.3g}"  # 0.23, not 0
        return (f"{self.points} points: {self.computed} computed in {self.seconds:.1f} s "
                f"({shown} points/s), {self.failed} failed")


@dataclass
class Estimate:
    """What a study costs before it runs (:func:`estimate_study`).

    Parameters
    ----------
    points : int
        Points of the study.
    missing : int
        Points not computed yet (in the store given).
    seconds_per_point : float
        Measured CPU time of one point on one core [s] (as a run measures it).
    workers : int
        Processes the run would use.
    disk_bytes : int
        Size of the finished store [bytes].
    memory_bytes : int
        Memory the command holds at most [bytes]: its libraries and compiled kernels (what
        it holds once it computed points) and the study's arrays.
    budget_seconds : float, optional
        The work budget (``--max-seconds``) the run is held to [s].
    load_average : float, optional
        The machine's load average over the last minute when the point was timed.
    cores : int, optional
        The machine's cores.

    Examples
    --------
    >>> e = Estimate(points=1_000_000, missing=1_000_000, seconds_per_point=5e-4, workers=2,
    ...              disk_bytes=17_000_000, memory_bytes=10_000_000, budget_seconds=60.0)
    >>> print(f"{e.core_hours:.3f} core-hours")
    0.139 core-hours
    >>> print(str(e).splitlines()[-1])
      work budget            1 min (--max-seconds): above it, the run would be refused
    >>> e.load_average, e.cores = 9.3, 2                  # timed on a loaded machine: said
    >>> print(*str(e).splitlines()[2:4], sep=chr(10))
      measured under load    load average 9.3 on 2 cores: a point's CPU time,
                             the work and the time below read up to 3-4 times an idle machine's
    """

    points: int
    missing: int
    seconds_per_point: float
    workers: int
    disk_bytes: int
    memory_bytes: int
    budget_seconds: float | None = None
    load_average: float | None = None
    cores: int | None = None

    @property
    def loaded(self) -> bool:
        """Whether the point was timed with more runnable processes than cores (its CPU time
        then reads more than on an idle machine: caches and cores shared)."""
        return (self.load_average is not None and self.cores is not None
                and self.load_average > self.cores)

    @property
    def core_hours(self) -> float:
        """Core-hours of the points still to compute."""
        return self.missing * self.seconds_per_point / 3600.0

    @property
    def wall_seconds(self) -> float:
        """The run's time on :attr:`workers` idle cores [s]."""
        return self.missing * self.seconds_per_point / max(self.workers, 1)

    @property
    def within_budget(self) -> bool | None:
        """Whether the run fits the work budget (None: no budget given)."""
        return None if self.budget_seconds is None else self.wall_seconds <= self.budget_seconds

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {"points": self.points, "missing": self.missing,
                "seconds_per_point": self.seconds_per_point, "core_hours": self.core_hours,
                "workers": self.workers, "wall_seconds": self.wall_seconds,
                "disk_bytes": self.disk_bytes, "memory_bytes": self.memory_bytes,
                "budget_seconds": self.budget_seconds, "within_budget": self.within_budget,
                "load_average": self.load_average, "cores": self.cores}

    def __str__(self) -> str:
        lines = [
            f"  points                 {self.points} ({self.missing} to compute)",
            f"  one point              {g(self.seconds_per_point * 1e3)} ms of CPU (measured "
            f"here)"]
        if self.loaded:
            lines += [f"  measured under load    {_load_text(self.load_average, self.cores)}: "
                      f"a point's CPU time,",
                      "                         the work and the time below read up to 3-4 "
                      "times an idle machine's"]
        lines += [
            f"  work                   {g(self.core_hours)} core-hours, about "
            f"{self.wall_seconds:.0f} s on {self.workers} worker(s)",
            f"  store on disk          at most {g(self.disk_bytes / 1e6)} MB",
            f"  memory of this process about {g(self.memory_bytes / 1e6)} MB (a worker: at most "
            f"as much)"]
        if self.budget_seconds is not None:
            verdict = "the run fits" if self.within_budget else "above it, the run would be refused"
            lines.append(f"  work budget            {format_duration(self.budget_seconds)} "
                         f"(--max-seconds): {verdict}")
        return "\n".join(lines)


def machine_load() -> tuple[float | None, int]:
    """The load average over the last minute (None where the system does not give it) and the
    cores: a point's CPU time measured with more runnable processes than cores reads more
    than on an idle machine (3-4 times at a load of 4-6 a core), the caches and cores shared.

    Examples
    --------
    >>> load, cores = machine_load()
    >>> cores >= 1 and (load is None or load >= 0)
    True
    """
    try:
        load: float | None = os.getloadavg()[0]
    except OSError:
        load = None
    return load, os.cpu_count() or 1


def _load_text(load: float | None, cores: int | None) -> str:
    return f"load average {load:.1f} on {cores} core{'s' if cores != 1 else ''}"


def _bytes_per_point(study: StudyDefinition) -> int:
    # the status and the reason byte, then the fields
    return 2 + sum(16 if k == "complex" else 8 for k in fields_of(study.outputs).values())


def estimate_study(study: StudyDefinition, workers: int = 1,
                   store: str | Path | None = None) -> Estimate:
    """Points, time per point (measured on a few points), core-hours, disk and memory.

    Parameters
    ----------
    study : Study
        The study.
    workers : int
        Processes the run would use.
    store : str or Path, optional
        An existing store: only its missing points are counted.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> est = estimate_study(st)
    >>> est.points, est.missing, est.seconds_per_point > 0
    (2, 2, True)
    """
    missing = study.n_points
    if store is not None and is_study_store(store):
        st = StudyStore.open(store)
        if st.matches(study):
            missing = len(st.missing())
    # as the run measures it (the budget's refusal and this estimate agree)
    load, cores = machine_load()
    per = seconds_per_point(study, 6, cpu=True)
    bpp = _bytes_per_point(study)
    # what the process holds now, its libraries and kernels loaded and points computed, then
    # the study's index arrays and the writer's chunks
    held = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * (
        1 if sys.platform == "darwin" else 1024)  # bytes there, kB elsewhere
    return Estimate(points=study.n_points, missing=missing, seconds_per_point=per,
                    workers=max(workers, 1), disk_bytes=study.n_points * bpp,
                    memory_bytes=held + study.n_points * (8 + 1) + 65536 * bpp * 4,
                    budget_seconds=max_seconds(), load_average=load, cores=cores)


def _resumed_store(study: StudyDefinition, path: Path, force: bool) -> StudyStore | None:
    """The store at `path` if it holds `study` (resumed), None if a new one is to be made
    there; raises before anything is changed if `path` may not be replaced.  A symbolic
    link is never followed: with `force` the link itself is replaced by the new store.  What a
    killed run left beside it is cleaned first (a store it was replacing put back)."""
    from motionhyst.io.leftovers import clean_stale

    clean_stale(path.parent)
    if path.is_symlink():
        if not force:
            raise StudyError(f"--out {path} is a symbolic link; give the folder it points to, "
                             f"another name, or --force to replace the link itself (never "
                             f"what it points to)")
        return None
    if path.exists():
        if not is_study_store(path):
            raise StudyError(f"--out {path}: exists and is not a study's store; refusing to "
                             f"replace it")
        try:
            store = StudyStore.open(path)
            if store.matches(study):
                store.status()  # every chunk readable, every value a status
                return store
        except StudyError as exc:  # damaged: replaced as another study's store is
            if not force:
                raise StudyError(f"--out {exc}; give --force to replace it") from None
        if not force:
            raise StudyError(f"--out {path}: holds another study (other scenario, axes, "
                             f"samples or outputs); give --force to replace it")
        foreign = foreign_entries(path)
        if foreign:  # a user's file in the folder is never deleted with the store
            raise StudyError(f"--out {path}: holds {listed(foreign)}, not the study's; "
                             f"--force replaces the store with all in its folder: move them "
                             f"out of it, or give another --out")
    elif not path.parent.is_dir():
        raise StudyError(f"--out {path}: folder {path.parent} does not exist")
    return None


def _new_store(study: StudyDefinition, path: Path, version: str) -> StudyStore:
    """A new store at `path`; what is there (a symbolic link, another study's store: replaced
    with force) stays until the new store is made beside it and renamed into its place, so a
    failure or an interrupt leaves the one or the other, never neither."""
    if not (path.exists() or path.is_symlink()):
        return StudyStore.create(path, study, version)
    if not path.is_symlink() and not is_study_store(path):
        remove_store(path)  # refuses: not a study's store
    new, old = (path.with_name(f".{path.name}.motionhyst-{os.getpid()}-{end}")
                for end in ("new", "old"))
    try:
        StudyStore.create(new, study, version)
        os.rename(path, old)  # the link itself, or the other study's folder, aside
        try:
            os.rename(new, path)
        except BaseException:
            os.rename(old, path)
            raise
    except BaseException as exc:
        shutil.rmtree(new, ignore_errors=True)
        if isinstance(exc, OSError) and exc.strerror:  # named as the store, not the temporary
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise
    if old.is_symlink():  # what the link points to is left as it is
        old.unlink()
    else:
        remove_store(old)
    return StudyStore.open(path)


def check_budget(study: StudyDefinition, n_missing: int, seconds: float, workers: int,
                 load: tuple[float | None, int] | None = None) -> None:
    """Refuse a study whose missing points would take longer than the work budget
    (:func:`motionhyst.core.budget.check_work`, ``--max-seconds``): their core time shared
    by the `workers`, before anything is computed or written.

    Parameters
    ----------
    study : StudyDefinition
        The study.
    n_missing : int
        Points to compute.
    seconds : float
        CPU time of one point on one core [s] (:func:`seconds_per_point`).
    workers : int
        Processes computing them.
    load : (float, int), optional
        The load average and the cores when `seconds` was measured (:func:`machine_load`):
        above one a core the refusal says the time was measured under that load.

    Raises
    ------
    motionhyst.core.budget.BudgetError
        One line: the points, the time and the remedy.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.core.budget import BudgetError, set_max_seconds
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["e1"], "axes": {
    ...     "frequency_hz": {"geomspace": [1.0, 100.0, 1000]}, "hysteresis.k": [20.0]}},
    ...     scenario=base)
    >>> set_max_seconds(60.0)
    >>> check_budget(st, 1000, 1e-3, 2)                   # 0.5 s on two workers
    >>> try:
    ...     check_budget(st, 1000, 0.5, 2)
    ... except BudgetError as exc:
    ...     print(exc)
    a study of 1000 points (500 ms each on one core) on 2 workers would take about 4.2 min, \
above the work budget of 1 min (--max-seconds); give fewer points (axes, samples), more \
workers (--workers, --scheduler) or a larger --max-seconds
    >>> try:
    ...     check_budget(st, 1000, 0.5, 2, load=(9.3, 2))    # timed on a loaded machine
    ... except BudgetError as exc:
    ...     print(str(exc).split(") on")[0])
    a study of 1000 points (500 ms each on one core, measured under load average 9.3 on 2 cores
    >>> set_max_seconds(None)
    """
    workers = max(workers, 1)
    under = ""
    if load is not None and load[0] is not None and load[0] > load[1]:
        under = f", measured under {_load_text(*load)}"
    check_work(n_missing * seconds / workers,
               f"a study of {n_missing} points ({g(seconds * 1e3)} ms each on one core{under}) "
               f"on {workers} worker{'s' if workers > 1 else ''}",
               "give fewer points (axes, samples), more workers (--workers, --scheduler) "
               "or a larger --max-seconds")


def run_study(study: StudyDefinition, store: str | Path, workers: int | None = None, client=None,
              force: bool = False, batch: int | None = None, progress: bool = False
              ) -> RunReport:
    """Compute the points of `study` missing from `store` (created if need be).

    Parameters
    ----------
    study : StudyDefinition
        The study.
    store : path
        A zarr store (a folder): new, or holding the same study (then only the missing
        points are computed), or another study's with `force`.
    workers : int, optional
        Local worker processes (default: every core); 0 computes in this process.
    client : distributed.Client, optional
        Run the batches on this dask cluster instead.
    force : bool
        Replace a store holding another study, or a symbolic link named `store` (the link
        itself, never what it points to).
    batch : int, optional
        Points a batch (default: at least 0.1 s of work, measured).
    progress : bool
        Points per second and the time left on stderr.

    Returns
    -------
    RunReport

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["error_rms"],
    ...                       "axes": {"frequency_hz": [5.0, 10.0], "controller.K": [6.2e6, 1e12]}},
    ...                      scenario=base)
    >>> store = Path(tempfile.mkdtemp()) / "s.zarr"
    >>> r = run_study(st, store, workers=0)                # K = 1e12: an unstable loop
    >>> r.points, r.computed, r.failed
    (4, 4, 2)
    >>> run_study(st, store, workers=0).computed           # nothing missing: nothing computed
    0
    """
    from motionhyst import __version__

    t0 = time.perf_counter()
    path = Path(store)
    st = _resumed_store(study, path, force)
    written = "" if st is None else str(st.group.attrs.get("version", ""))
    if written and written != __version__:  # said, not refused: its points stand
        warn(f"{path}: a store of motionhyst {written}, resumed by {__version__}: the points "
             f"it holds stay as that version computed them")
    if workers is None:
        workers = os.cpu_count() or 1
    if client is not None:
        workers = max(1, sum(client.nthreads().values()))
    n_missing = study.n_points if st is None else len(st.missing())
    per = None
    if n_missing:
        # from the CPU time of a point: its wall time on a loaded machine would make batches
        # too small for the work each costs the engine; two runs of three points, at the
        # study's two ends (a point's cost varies along the reference axes)
        load = machine_load()
        per = seconds_per_point(study, 6, cpu=True)
        check_budget(study, n_missing, per, workers, load)
    if st is None:
        st = _new_store(study, path, __version__)
    with run_lock(path):
        computed, cpu = _compute(study, st, workers, client, batch, per, progress)
    failed = int(np.count_nonzero(st.status() == FAILED))
    return RunReport(study.n_points, computed, failed, time.perf_counter() - t0, cpu)


@contextlib.contextmanager
def run_lock(path: Path) -> Iterator[None]:
    """Hold the lock of the store at `path` (a second run is refused while it is held): two
    runs writing one store at once would undo each other's chunks.

    Parameters
    ----------
    path : Path
        The store's folder.

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict(
    ...     {"outputs": ["e1"], "axes": {"frequency_hz": [5.0]}}, scenario=base)
    >>> path = Path(tempfile.mkdtemp()) / "s.zarr"
    >>> _ = StudyStore.create(path, st)
    >>> with run_lock(path):
    ...     try:
    ...         run_study(st, path, workers=0)
    ...     except StudyError as exc:
    ...         print(str(exc).endswith("another run is writing to this store; wait for it "
    ...                                 "or stop it"))
    True
    """
    with open(path / LOCK_NAME, "rb") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise StudyError(f"--out {path}: another run is writing to this store; wait for "
                             f"it or stop it") from None
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _compute(study: StudyDefinition, st: StudyStore, workers: int, client, batch: int | None,
             per: float | None, progress: bool) -> tuple[int, float]:
    todo = st.missing(study.order())
    computed, cpu = 0, 0.0
    if len(todo):
        if per is None:  # (another run computed points between the count and the lock)
            per = seconds_per_point(study, 6, cpu=True)
        size = batch or batch_size(per, len(todo), workers,
                                   BATCH_SECONDS if client is None else DASK_BATCH_SECONDS)
        batches = split(todo, size)
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=len(todo), unit="point", file=sys.stderr, smoothing=0.1,
                       desc="study")
        try:
            # closed at once on any exception (Ctrl-C): the workers stop with the command
            # the writer gathers batches into whole chunks and writes what it holds on the
            # way out, after the workers stopped (Ctrl-C included)
            with (st.writer() as writer,
                  contextlib.closing(run_batches(study, batches, workers, client)) as results):
                for b in results:
                    writer.add(b.indices, b.status, b.values, b.reason, b.failures)
                    computed += len(b.indices)
                    cpu += b.cpu_seconds
                    if bar is not None:
                        bar.update(len(b.indices))
        finally:
            if bar is not None:
                bar.close()
    return computed, cpu
