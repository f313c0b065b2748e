"""Benchmark of ``motionhyst study``: scaling over local workers and dask's overhead per point.

One run computes the same Monte-Carlo study of the Table I loop (``hysteresis.k`` and
``hysteresis.fc`` drawn, frequencies 1-100 Hz, two amplitudes; outputs e1, mismatch,
error_rms; 150,000 points by default, so that a run's fixed costs weigh little) into fresh
stores:

1. in this process (``workers=0``): the time and the CPU time a point costs without any
   engine (the baseline);
2. the local process pool with one worker, then two: wall time of the whole run (start of the
   workers, warm-up and writes included) and the CPU time of every process taking part (this
   one and its workers);
3. dask.distributed on a local cluster of two single-thread worker processes (``dask
   scheduler`` and ``dask worker --nworkers 2 --nthreads 1``, with their nannies, in
   processes of their own; warmed by a study of two points) with the batches ``run_study``
   chooses for dask (at least ``DASK_BATCH_SECONDS`` of work), against the pool of two
   workers in ``--repeats`` pairs of runs, interleaved (a study of another seed each pair, as
   a dask worker keeps the last study it built), the two in alternating order.  The cluster
   runs with the settings for studies (``engine.DASK_CLUSTER_CONFIG``, in its processes'
   environment, as the README starts one), or is started with dask's defaults
   (``--dask-defaults``), whose diagnostics a study sets to that pace while it runs
   (``engine.quiet_cluster``); the idle cluster's CPU is measured at that pace too.

Each run counts the CPU time of every process by role (this process, the client, which sends
the batches and writes the store; the workers; on dask the scheduler and the nannies too) and
the CPU time the points themselves took (each batch's thread CPU time, which the run reports
as ``RunReport.cpu_seconds``).  The points are the same work in both engines, but a shared
machine's load moves their CPU time by several per cent from one run to the next (the caches
and cores the other jobs take): compared whole, two runs' CPU times hide a 5 % overhead.  An
engine's cost is therefore its run's CPU time past the points' work, and dask's overhead is
its engine's cost past the pool's, a share of the pool's CPU time (target <= 5 %): the
median over the pairs, with the range, and the same past the idle cluster's CPU a second
(heartbeats, ticks, profiler; measured between the pairs), which grows with the wall time,
i.e. with the load, and as it would be on two idle cores.  The wall times of the pairs are
reported too; their ratios hold on a quiet machine only (the load average is printed before
and after).  From the first runs: the pool's overhead per point past the baseline and its
parallel efficiency (baseline CPU / the pool's, the pool's points' work taken as the
baseline's: two workers give that times 2 on two idle cores; target >= 0.9, i.e. 1.8x).
The numbers of a study are checked equal in every engine.  Run with ``make bench`` or
``python benchmarks/study.py [--samples N] [--frequencies N] [--repeats N]
[--dask-batch-seconds S] [--dask-defaults] [--json]``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results, run_study
from motionhyst.study.engine import (
    DASK_BATCH_SECONDS,
    DASK_CLUSTER_CONFIG,
    batch_size,
    dask_environment,
    quiet_cluster,
    seconds_per_point,
)

ENGINES = ("pool", "dask")
"""The runs of each pair: the local pool and dask."""


def make_study(samples: int, frequencies: int, seed: int = 0) -> Study:
    base = tomllib.loads(default_scenario_path().read_text())
    return Study.from_dict({
        "outputs": ["e1", "mismatch", "error_rms"],
        "axes": {"amplitude": [0.001, 0.01],
                 "frequency_hz": {"geomspace": [1.0, 100.0, frequencies]}},
        "samples": {"n": samples, "seed": seed, "hysteresis.k": {"lognormal": [20.0, 0.1]},
                    "hysteresis.fc": {"lognormal": [0.05, 0.1]}}}, scenario=base)


def _cpu_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _cpu_children(reap: bool) -> float:
    """CPU time of the reaped children (the pool's workers, once they are joined)."""
    deadline = time.monotonic() + 30
    while reap and multiprocessing.active_children() and time.monotonic() < deadline:
        time.sleep(0.01)
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _cpu_tree(pids: list[int]) -> float:
    """CPU time of live processes (dask's scheduler, nannies and workers)."""
    import psutil

    total = 0.0
    for pid in pids:
        t = psutil.Process(pid).cpu_times()
        total += t.user + t.system
    return total


@dataclass
class Run:
    """One run of a study: its wall time, the CPU time of each role taking part (``client``:
    this process, which sends the batches and writes the store; ``workers``; on dask also
    ``scheduler`` and ``nannies``), and ``work``, the CPU time the points took in the
    workers (each batch's thread CPU time, ``RunReport.cpu_seconds``)."""

    wall: float
    cpu: dict[str, float]
    work: float
    results: object = field(repr=False)

    @property
    def total(self) -> float:
        return sum(self.cpu.values())

    @property
    def engine(self) -> float:
        """The CPU time of everything but the points: what the engine costs."""
        return self.total - self.work


def timed(study: Study, folder: Path, name: str, roles: dict[str, list[int]] | None = None,
          **kw) -> Run:
    """Run `study` into a fresh store; `roles`: the pids of dask's processes by role (the
    pool's workers are this process's children, counted once joined)."""
    reap = roles is None
    w0, c0, k0 = time.perf_counter(), _cpu_self(), _cpu_children(reap)
    r0 = {role: _cpu_tree(pids) for role, pids in (roles or {}).items()}
    rep = run_study(study, folder / f"{name}.zarr", **kw)
    wall = time.perf_counter() - w0
    cpu = {"client": _cpu_self() - c0}
    if roles is None:
        cpu["workers"] = _cpu_children(reap) - k0
    else:
        cpu.update({role: _cpu_tree(pids) - r0[role] for role, pids in roles.items()})
    assert rep.computed == study.n_points and rep.failed == 0, rep
    return Run(wall, cpu, rep.cpu_seconds, open_results(folder / f"{name}.zarr"))


@contextlib.contextmanager
def dask_cluster(folder: Path, defaults: bool = False
                 ) -> Iterator[tuple[object, dict[str, list[int]]]]:
    """A scheduler and two single-thread workers (with their nannies, as ``dask worker``
    starts them) in processes of their own, with the settings for studies
    (:func:`dask_environment`) unless `defaults`; the client and the pids of the processes by
    role (``scheduler``; ``nannies``, the ``dask worker`` process that holds them;
    ``workers``, its children)."""
    from distributed import Client

    sched_file = folder / "scheduler.json"
    env = {k: v for k, v in os.environ.items() if not k.startswith("DASK_")}
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL,
             "start_new_session": True, "env": env if defaults else {**env, **dask_environment()}}
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1",
                               "--port", "0", "--no-dashboard", "--scheduler-file",
                               str(sched_file)], **quiet)]
    try:
        deadline = time.monotonic() + 120
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "dask", "worker", "--scheduler-file", str(sched_file),
             "--nworkers", "2", "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1",
             "--local-directory", str(folder / "workers")], **quiet))
        with Client(scheduler_file=str(sched_file), timeout="60s") as client:
            client.wait_for_workers(2, timeout=120)
            import psutil

            sched = psutil.Process(procs[0].pid)
            roles = {"scheduler": [sched.pid, *(q.pid for q in sched.children(True))],
                     "nannies": [procs[1].pid],
                     "workers": [q.pid for q in psutil.Process(procs[1].pid).children(True)]}
            yield client, roles
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


def idle_rate(client, roles: dict[str, list[int]], seconds: float) -> float:
    """CPU time a second of the idle cluster (heartbeats, ticks, profiler) and this process,
    its diagnostics at the pace a study sets while it runs (:func:`quiet_cluster`)."""
    pids = [pid for group in roles.values() for pid in group]
    with quiet_cluster(client):
        w0, i0 = time.perf_counter(), _cpu_self() + _cpu_tree(pids)
        time.sleep(seconds)
        return (_cpu_self() + _cpu_tree(pids) - i0) / (time.perf_counter() - w0)


def _timers(dask_worker) -> dict:
    return {name: (pc.callback_time, pc.is_running())
            for name, pc in dask_worker.periodic_callbacks.items()
            if name in ("tick", "monitor", "memory_monitor", "profile")}


def _cluster_timers(client) -> dict:
    """The intervals [ms] of the diagnostics' timers of the scheduler, workers and nannies
    and whether they run."""
    nannies = any(w.get("nanny") for w in client.scheduler_info()["workers"].values())
    return {"scheduler": client.run_on_scheduler(_timers),
            "workers": list(client.run(_timers).values()),
            "nannies": list(client.run(_timers, nanny=True).values()) if nannies else []}


def _equal(a, b) -> None:
    for name in ("e1", "mismatch", "error_rms", "status"):
        np.testing.assert_array_equal(a[name].values, b[name].values)


def _spread(values: list[float]) -> dict:
    return {"median": float(np.median(values)), "min": float(min(values)),
            "max": float(max(values)), "runs": [float(v) for v in values]}


def _config_of_this_process() -> dict:
    import dask.config

    return {key: dask.config.get(key) for key in DASK_CLUSTER_CONFIG}


def _cluster_config(client) -> dict:
    """The settings of :data:`DASK_CLUSTER_CONFIG` as the cluster's scheduler and workers run
    with them (the environment they were started with)."""
    return {"scheduler": client.run_on_scheduler(_config_of_this_process),
            "workers": list(client.run(_config_of_this_process).values())}


def _fraction(d: Run, p: Run, idle: float = 0.0, quiet: float | None = None) -> float:
    """Dask's engine cost past the pool's, a share of the pool's CPU time (the points' work
    taken out of both: it is the same work, and its time moves with the load): `idle` the
    idle cluster's CPU a second, taken out over the run's wall time; `quiet` the wall time
    the run would last on idle cores, over which it is put back."""
    extra = d.engine - p.engine - idle * d.wall + (0.0 if quiet is None else idle * quiet)
    return extra / p.total


def _per_run_and_per_second(runs: list[Run]) -> tuple[np.ndarray, np.ndarray] | None:
    """An engine's cost as a fixed part per run (its points' and tasks' cost: the runs are
    of one size) plus a part per second of wall time (the background of its processes:
    heartbeats, ticks, profiler), fitted over the runs, whose wall times the load varies:
    the coefficients [per second, per run] and their covariance (the less the wall times
    vary, the larger); None for fewer than four runs or wall times all alike."""
    wall = np.array([r.wall for r in runs])
    if len(runs) < 4 or np.ptp(wall) < 1e-3 * np.mean(wall):
        return None
    return np.polyfit(wall, [r.engine for r in runs], 1, cov=True)


def _quiet_from_fit(pairs: list[tuple[Run, Run]]) -> dict | None:
    """Dask's engine cost past the pool's on two idle cores, a share of the pool's CPU time,
    from each engine's fit (:func:`_per_run_and_per_second`) at the wall time of a run on two
    idle cores (half its points' work): the value and its standard error."""
    fits = [_per_run_and_per_second([r[i] for r in pairs]) for i in (0, 1)]
    if None in fits:
        return None
    value, var = 0.0, 0.0
    for sign, (coef, cov), runs in zip((-1.0, 1.0), fits, zip(*pairs, strict=True),
                                       strict=True):
        x = np.array([np.mean([r.work for r in runs]) / 2, 1.0])
        value += sign * float(x @ coef)
        var += float(x @ cov @ x)
    total = float(np.mean([p.total for p, _ in pairs]))
    return {"value": value / total, "std": var ** 0.5 / total,
            "dask_cpu_per_s": float(fits[1][0][0]), "pool_cpu_per_s": float(fits[0][0][0]),
            "dask_per_run_s": float(fits[1][0][1]), "pool_per_run_s": float(fits[0][0][1])}


def _dask_against_pool(pairs: list[tuple[Run, Run]], idle: float, n: int) -> dict:
    """Dask's runs against the pool's of the same pairs: the CPU a point by role, and dask's
    cost past the pool's, a share of the pool's CPU time, in each of the ways described above."""

    def per_point_us(runs: list[Run], role: str) -> float:
        # a role's CPU a point; the workers' past the points' work
        return 1e6 * float(np.median([r.cpu.get(role, 0.0) - (r.work if role == "workers"
                                                               else 0.0) for r in runs])) / n

    pools, dasks = [p for p, _ in pairs], [d for _, d in pairs]
    return {
        "pairs": [{"pool": {"wall_s": p.wall, "work_s": p.work, **p.cpu},
                   "dask": {"wall_s": d.wall, "work_s": d.work, **d.cpu}} for p, d in pairs],
        # what the load does to the same work: it moves the points' CPU time (both engines)
        "work_dask_over_pool": _spread([d.work / p.work - 1 for p, d in pairs]),
        "pool_cpu_noise": (max(r.total for r in pools) - min(r.total for r in pools))
        / float(np.median([r.total for r in pools])),
        "us_per_point": {engine: {role: per_point_us(runs, role) for role in
                                  ("client", "scheduler", "nannies", "workers")}
                         for engine, runs in (("pool", pools), ("dask", dasks))},
        # the old measure: all CPU, the points' work included (its noise is the load's)
        "dask_total_over_pool": _spread([d.total / p.total - 1 for p, d in pairs]),
        # the engines' costs alone (all CPU past the points' work), against the pool's CPU
        "dask_overhead_fraction": _spread([_fraction(d, p) for p, d in pairs]),
        "dask_task_overhead_fraction": _spread([_fraction(d, p, idle) for p, d in pairs]),
        # on two idle cores a run lasts about half its work
        "dask_overhead_fraction_quiet": _spread([_fraction(d, p, idle, d.work / 2)
                                                 for p, d in pairs]),
        "dask_wall_over_pool": _spread([d.wall / p.wall for p, d in pairs]),
        # the same from the engines' costs fitted over the pairs as a part per run and a part
        # per second of wall time: no idle window measured apart
        "dask_overhead_fraction_quiet_fit": _quiet_from_fit(pairs),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1500, help="Monte-Carlo samples")
    ap.add_argument("--frequencies", type=int, default=50, help="frequencies 1-100 Hz")
    ap.add_argument("--repeats", type=int, default=5,
                    help="pairs of runs, local pool and dask, interleaved")
    ap.add_argument("--dask-batch-seconds", type=float, default=DASK_BATCH_SECONDS,
                    help="least work in a batch on dask [s] (run_study's default: "
                         f"{DASK_BATCH_SECONDS:g})")
    ap.add_argument("--dask-defaults", action="store_true",
                    help="the cluster with dask's default settings, not those for studies")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    study = make_study(args.samples, args.frequencies)
    n = study.n_points
    load_before = os.getloadavg()
    per = seconds_per_point(study, 6, cpu=True)   # on CPU time, as run_study
    batch = batch_size(per, n, 2)
    dask_batch = batch_size(per, n, 2, args.dask_batch_seconds)
    out: dict = {"points": n, "batch": batch, "dask_batch": dask_batch,
                 "dask_batch_seconds": args.dask_batch_seconds, "cores": os.cpu_count(),
                 "repeats": args.repeats, "load_before": load_before}
    pairs: list[tuple[Run, Run]] = []
    idles: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        # the store's libraries imported once, before anything is counted
        timed(make_study(1, 2), folder, "warm", workers=0, batch=1)
        alone = timed(study, folder, "inprocess", workers=0, batch=batch)
        one = timed(study, folder, "pool1", workers=1, batch=batch)
        two = timed(study, folder, "pool2", workers=2, batch=batch)
        _equal(alone.results, one.results)
        _equal(alone.results, two.results)
        with dask_cluster(folder, args.dask_defaults) as (client, roles):
            # the workers import the library and load the kernels at their first batch
            timed(make_study(1, 2), folder, "dask_warm", roles=roles, client=client, batch=1)
            out["dask_cluster_config"] = _cluster_config(client)
            out["dask_timers"] = _cluster_timers(client)
            with quiet_cluster(client):
                out["dask_timers_during_a_study"] = _cluster_timers(client)
            for r in range(args.repeats):
                # a study of its own each pair (another seed): a dask worker keeps the last
                # study built, a pool's workers build it anew; the order alternates, so that
                # a load rising or falling over the pairs weighs on both engines alike
                st = make_study(args.samples, args.frequencies, seed=1 + r)
                idles.append(idle_rate(client, roles, 2.0))
                runs = {}
                for engine in ENGINES[r % 2:] + ENGINES[:r % 2]:
                    if engine == "pool":
                        runs[engine] = timed(st, folder, f"pair{r}_{engine}", workers=2,
                                             batch=batch)
                    else:
                        runs[engine] = timed(st, folder, f"pair{r}_{engine}", roles=roles,
                                             client=client, batch=dask_batch)
                _equal(runs["pool"].results, runs["dask"].results)
                pairs.append((runs["pool"], runs["dask"]))
                for name in ENGINES:
                    shutil.rmtree(folder / f"pair{r}_{name}.zarr")
            idles.append(idle_rate(client, roles, 2.0))
    idle = float(np.median(idles))

    out.update({
        "load_after": os.getloadavg(),
        "in_process_s": alone.wall, "pool_1_s": one.wall, "pool_2_s": two.wall,
        "in_process_cpu_s": alone.total, "pool_1_cpu_s": one.total, "pool_2_cpu_s": two.total,
        "ms_cpu_per_point_in_process": 1e3 * alone.total / n,
        "ms_work_per_point_in_process": 1e3 * alone.work / n,
        "speedup_2_over_1": one.wall / two.wall,
        "pool_2_overhead_ms_per_point": 1e3 * (two.engine - alone.engine) / n,
        # the baseline's CPU over the pool's, its points' work taken as the baseline's (the
        # load moves that work's CPU time; what the pool adds is its engine's cost)
        "pool_2_efficiency": alone.total / (alone.total + two.engine - alone.engine),
        "pool_2_efficiency_all_cpu": alone.total / two.total,
        "work_pool_2_over_in_process": two.work / alone.work - 1,
        "dask_idle_cpu_per_s": _spread(idles),
        "dask": _dask_against_pool(pairs, idle, n),
    })
    if args.json:
        print(json.dumps(out, indent=2))
        return

    def pct(s: dict) -> str:
        return (f"{100 * s['median']:+.1f} % (median of {args.repeats}; "
                f"{100 * s['min']:+.1f} to {100 * s['max']:+.1f})")

    la, lb = load_before, out["load_after"]
    print(f"study of {n} points (batches of {batch}, on dask {dask_batch}), numbers equal in "
          f"every engine; {os.cpu_count()} cores, load average {la[0]:.1f} before, "
          f"{lb[0]:.1f} after; the dask cluster with "
          f"{'dask' if args.dask_defaults else 'the study'}'s settings: "
          f"{out['dask_cluster_config']['workers'][0]}")
    print(f"  in this process        {alone.wall:7.2f} s, {alone.total:7.2f} s CPU  "
          f"({out['ms_cpu_per_point_in_process']:.3f} ms CPU a point: the baseline)")
    print(f"  local pool, 1 worker   {one.wall:7.2f} s, {one.total:7.2f} s CPU")
    print(f"  local pool, 2 workers  {two.wall:7.2f} s, {two.total:7.2f} s CPU -> "
          f"{out['speedup_2_over_1']:.2f}x one worker's wall time; CPU past the points' work "
          f"{out['pool_2_overhead_ms_per_point']:+.4f} ms a point more than the baseline's, "
          f"efficiency {out['pool_2_efficiency']:.3f} (2 x that = "
          f"{2 * out['pool_2_efficiency']:.2f}x on two idle cores; target >= 1.8; from all "
          f"CPU {out['pool_2_efficiency_all_cpu']:.3f}, the points' work moving by "
          f"{100 * out['work_pool_2_over_in_process']:+.1f} %)")
    idle = out["dask_idle_cpu_per_s"]["median"]
    d = out["dask"]
    print(f"  dask against the local pool, 2 workers each, {args.repeats} pairs of runs "
          f"interleaved (another seed each pair):")
    print(f"    the points' work, dask's against the pool's: "
          f"{pct(d['work_dask_over_pool'])} (the load's doing; taken out below)")
    print("    CPU a point past the points' work [us]: client, scheduler, nannies, workers")
    for engine in ("pool", "dask"):
        u = d["us_per_point"][engine]
        print(f"      {engine:5s} " + ", ".join(f"{u[r]:.2f}" for r in
                                               ("client", "scheduler", "nannies",
                                                "workers")))
    print(f"    all CPU, the work included (the load's noise in it): "
          f"{pct(d['dask_total_over_pool'])}")
    print(f"    dask's engine past the pool's: {pct(d['dask_overhead_fraction'])} of the "
          f"pool's CPU")
    print(f"    the idle cluster {idle:.3f} s CPU a second; past it "
          f"{pct(d['dask_task_overhead_fraction'])}")
    print(f"    with a run as long as on two idle cores "
          f"{pct(d['dask_overhead_fraction_quiet'])} (target <= 5 %)")
    fit = d["dask_overhead_fraction_quiet_fit"]
    if fit is None:
        print("    (too few pairs, or wall times all alike, to fit a part per run and a "
              "part per second)")
    else:
        print(f"    fitted over the pairs, per run + per second of wall time: dask "
              f"{fit['dask_per_run_s']:.3f} s + {fit['dask_cpu_per_s']:.4f} s/s, pool "
              f"{fit['pool_per_run_s']:.3f} s + {fit['pool_cpu_per_s']:.4f} s/s; on two "
              f"idle cores {100 * fit['value']:+.1f} % +- {100 * fit['std']:.1f} "
              f"(target <= 5 %)")
    w = d["dask_wall_over_pool"]
    print(f"    wall time, dask over the pool: {w['median']:.2f} ({w['min']:.2f} to "
          f"{w['max']:.2f}; under load it says little)")


if __name__ == "__main__":
    main()
