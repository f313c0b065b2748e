"""Benchmark of ``motionhyst study``: scaling over local workers and dask's overhead per point.

One run computes the same Monte-Carlo study of the Table I loop (``hysteresis.k`` and
``hysteresis.fc`` drawn, frequencies 1-100 Hz, two amplitudes; outputs e1, mismatch,
error_rms) into fresh stores:

1. in this process (``workers=0``): the time and the CPU time a point costs without any
   engine (the baseline);
2. the local process pool with one worker, then two: wall time of the whole run (start of the
   workers, warm-up and writes included) and the CPU time of every process taking part (this
   one and its workers);
3. dask.distributed on a local cluster of two single-thread worker processes (``dask
   scheduler`` and ``dask worker --nworkers 2 --nthreads 1``, with their nannies, in
   processes of their own; warmed by a study of two points): the
   batches ``run_study`` chooses for dask (at least ``DASK_BATCH_SECONDS`` of work), the same
   accounting (scheduler, client and workers), against the pool of two workers in
   ``--repeats`` pairs of runs, interleaved (pool then dask, dask then pool, ...; a study of
   another seed each pair, as a dask worker keeps the last study it built): the overheads are
   the medians over the pairs, with their range, as the load of a shared machine moves a
   single run's CPU time by several per cent; also the CPU time of the two processes that
   compute the points alone (dask's workers against the pool's), where a cost a point shows
   apart from the scheduler's, the nannies' and the client's.

Wall-time ratios hold on a quiet machine only (the load average is printed before and
after); the CPU times hold on a loaded one too.  From them: the engine's overhead per point
(its CPU time past the baseline's), the parallel efficiency (baseline CPU / the engine's CPU:
two workers give that times 2 on two idle cores; target >= 0.9, i.e. 1.8x) and dask's
overhead against the local pool (target <= 5 %); the idle cluster's CPU per second is
measured too, as its share grows with the wall time (with the load).  The numbers of a study
are checked equal in every engine.  Run with ``make bench`` or
``python benchmarks/study.py [--samples N] [--frequencies N] [--repeats N] [--json]``.
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
from pathlib import Path

import numpy as np

from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results, run_study
from motionhyst.study.engine import DASK_BATCH_SECONDS, batch_size, seconds_per_point


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
    """CPU time of live processes (dask's workers and their nannies)."""
    import psutil

    total = 0.0
    for pid in pids:
        t = psutil.Process(pid).cpu_times()
        total += t.user + t.system
    return total


def timed(study: Study, folder: Path, name: str, pids: list[int] | None = None,
          computing_pids: list[int] | None = None, **kw) -> tuple[float, float, object, float]:
    """Wall time, CPU time of every process taking part, results, CPU time of the processes
    that compute the points (the pool's workers, or dask's `computing_pids` among `pids`)."""
    reap = pids is None     # dask's workers (pids) live on; the pool's are joined
    w0, c0, k0 = time.perf_counter(), _cpu_self(), _cpu_children(reap)
    t0 = _cpu_tree(pids) if pids else 0.0
    p0 = _cpu_tree(computing_pids) if computing_pids else 0.0
    rep = run_study(study, folder / f"{name}.zarr", **kw)
    seconds = time.perf_counter() - w0
    children = _cpu_children(reap) - k0
    cpu = (_cpu_self() - c0) + children
    computing = children
    if pids:
        cpu += _cpu_tree(pids) - t0
        computing = _cpu_tree(computing_pids) - p0 if computing_pids else 0.0
    assert rep.computed == study.n_points and rep.failed == 0, rep
    return seconds, cpu, open_results(folder / f"{name}.zarr"), computing


@contextlib.contextmanager
def dask_cluster(folder: Path) -> Iterator[tuple[object, list[int], list[int]]]:
    """A scheduler and two single-thread workers (with their nannies, as ``dask worker``
    starts them) in processes of their own; the client, the pids of every process and those
    of the two workers (the nannies' children)."""
    from distributed import Client

    sched_file = folder / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL,
             "start_new_session": True}
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

            pids = [q.pid for p in procs for q in [psutil.Process(p.pid),
                                                    *psutil.Process(p.pid).children(True)]]
            workers = [q.pid for q in psutil.Process(procs[1].pid).children(True)]
            yield client, pids, workers
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


def idle_rate(pids: list[int], seconds: float) -> float:
    """CPU time a second of the idle cluster (heartbeats, ticks, profiler) and this process."""
    w0, i0 = time.perf_counter(), _cpu_self() + _cpu_tree(pids)
    time.sleep(seconds)
    return (_cpu_self() + _cpu_tree(pids) - i0) / (time.perf_counter() - w0)


def _equal(a, b) -> None:
    for name in ("e1", "mismatch", "error_rms", "status"):
        np.testing.assert_array_equal(a[name].values, b[name].values)


def _spread(values: list[float]) -> dict:
    return {"median": float(np.median(values)), "min": float(min(values)),
            "max": float(max(values)), "runs": [float(v) for v in values]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=100, help="Monte-Carlo samples")
    ap.add_argument("--frequencies", type=int, default=50, help="frequencies 1-100 Hz")
    ap.add_argument("--repeats", type=int, default=5,
                    help="pairs of runs, local pool and dask, interleaved")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    study = make_study(args.samples, args.frequencies)
    n = study.n_points
    load_before = os.getloadavg()
    per = seconds_per_point(study, 20, cpu=True)   # on CPU time, as run_study (on 6 points)
    batch = batch_size(per, n, 2)
    dask_batch = batch_size(per, n, 2, DASK_BATCH_SECONDS)
    out: dict = {"points": n, "batch": batch, "dask_batch": dask_batch, "cores": os.cpu_count(),
                 "repeats": args.repeats, "load_before": load_before}
    pool_cpu, dask_cpu, dask_wall, pool_wall, idles = [], [], [], [], []
    pool_computing: list[float] = []
    dask_computing: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        t0, c0, ref, _ = timed(study, folder, "inprocess", workers=0, batch=batch)
        t1, c1, one, _ = timed(study, folder, "pool1", workers=1, batch=batch)
        t2, c2, two, _ = timed(study, folder, "pool2", workers=2, batch=batch)
        _equal(ref, one)
        _equal(ref, two)
        with dask_cluster(folder) as (client, pids, dask_workers):
            # the workers import the library and load the kernels at their first batch
            timed(make_study(1, 2), folder, "dask_warm", pids=pids, client=client, batch=1)
            for r in range(args.repeats):
                # a study of its own each pair (another seed): a dask worker keeps the last
                # study built, a pool's workers build it anew; the order alternates, so that
                # a load rising or falling over the pairs weighs on both engines alike
                st = make_study(args.samples, args.frequencies, seed=1 + r)
                idles.append(idle_rate(pids, 1.0))
                runs = {}
                for engine in (("pool", "dask") if r % 2 == 0 else ("dask", "pool")):
                    if engine == "pool":
                        runs[engine] = timed(st, folder, f"pair{r}_pool", workers=2, batch=batch)
                    else:
                        runs[engine] = timed(st, folder, f"pair{r}_dask", pids=pids,
                                             computing_pids=dask_workers, client=client,
                                             batch=dask_batch)
                _equal(runs["pool"][2], runs["dask"][2])
                pool_wall.append(runs["pool"][0])
                pool_cpu.append(runs["pool"][1])
                pool_computing.append(runs["pool"][3])
                dask_computing.append(runs["dask"][3])
                dask_wall.append(runs["dask"][0])
                dask_cpu.append(runs["dask"][1])
                for name in (f"pair{r}_pool", f"pair{r}_dask"):
                    shutil.rmtree(folder / f"{name}.zarr")
            idles.append(idle_rate(pids, 1.0))
    idle = float(np.median(idles))
    raw = [(d - p) / p for d, p in zip(dask_cpu, pool_cpu, strict=True)]
    past = [(d - idle * w - p) / p for d, w, p in zip(dask_cpu, dask_wall, pool_cpu, strict=True)]
    # on two idle cores a run lasts about half the baseline's CPU time
    quiet = [(d - idle * w + idle * c0 / 2 - p) / p
             for d, w, p in zip(dask_cpu, dask_wall, pool_cpu, strict=True)]
    out.update({
        "load_after": os.getloadavg(),
        "in_process_s": t0, "pool_1_s": t1, "pool_2_s": t2,
        "in_process_cpu_s": c0, "pool_1_cpu_s": c1, "pool_2_cpu_s": c2,
        "ms_per_point_in_process": 1e3 * t0 / n,
        "ms_cpu_per_point_in_process": 1e3 * c0 / n,
        "speedup_2_over_1": t1 / t2,
        "pool_2_overhead_ms_per_point": 1e3 * (c2 - c0) / n,
        "pool_2_efficiency": c0 / c2,
        "pairs": {"pool_2_s": pool_wall, "pool_2_cpu_s": pool_cpu, "dask_2_s": dask_wall,
                  "dask_2_cpu_s": dask_cpu, "pool_2_workers_cpu_s": pool_computing,
                  "dask_2_workers_cpu_s": dask_computing},
        # the processes computing the points alone (dask's: heartbeats, ticks and profiler
        # of a worker included; scheduler, nannies and client not)
        "dask_workers_over_pool_workers": _spread(
            [d / p - 1 for d, p in zip(dask_computing, pool_computing, strict=True)]),
        "pool_cpu_noise": (max(pool_cpu) - min(pool_cpu)) / float(np.median(pool_cpu)),
        "dask_idle_cpu_per_s": _spread(idles),
        "dask_overhead_ms_per_point": 1e3 * float(np.median(
            [d - p for d, p in zip(dask_cpu, pool_cpu, strict=True)])) / n,
        "dask_overhead_fraction": _spread(raw),
        # past the idle cluster's share (which grows with the wall time: the load's doing)
        "dask_task_overhead_fraction": _spread(past),
        "dask_overhead_fraction_quiet": _spread(quiet),
        "dask_wall_over_pool": float(np.median(
            [d / p for d, p in zip(dask_wall, pool_wall, strict=True)])),
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
          f"{lb[0]:.1f} after")
    print(f"  in this process        {t0:7.2f} s, {c0:7.2f} s CPU  "
          f"({out['ms_cpu_per_point_in_process']:.3f} ms CPU a point: the baseline)")
    print(f"  local pool, 1 worker   {t1:7.2f} s, {c1:7.2f} s CPU")
    print(f"  local pool, 2 workers  {t2:7.2f} s, {c2:7.2f} s CPU -> "
          f"{out['speedup_2_over_1']:.2f}x one worker's wall time; CPU past the baseline "
          f"{out['pool_2_overhead_ms_per_point']:+.4f} ms a point, efficiency "
          f"{out['pool_2_efficiency']:.3f} (2 x that = "
          f"{2 * out['pool_2_efficiency']:.2f}x on two idle cores; target >= 1.8)")
    print(f"  dask against the local pool, 2 workers each, {args.repeats} pairs of runs "
          f"interleaved (another seed each pair):")
    print(f"    pool {np.median(pool_cpu):.2f} s CPU, dask {np.median(dask_cpu):.2f} s CPU "
          f"(medians; the pool's own spread {100 * out['pool_cpu_noise']:.0f} %); dask "
          f"{out['dask_wall_over_pool']:.2f}x the pool's wall time")
    print(f"    dask's CPU past the pool's: {out['dask_overhead_ms_per_point']:+.4f} ms a point, "
          f"{pct(out['dask_overhead_fraction'])}")
    print(f"    dask's two workers alone against the pool's: "
          f"{pct(out['dask_workers_over_pool_workers'])}")
    print(f"    the idle cluster {idle:.3f} s CPU a second; past it "
          f"{pct(out['dask_task_overhead_fraction'])}")
    print(f"    with a run as long as on two idle cores {pct(out['dask_overhead_fraction_quiet'])}"
          f" (target <= 5 %)")


if __name__ == "__main__":
    main()
