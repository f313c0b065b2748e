"""Benchmark of ``motionhyst study``: scaling over local workers and dask's overhead per point.

One run computes the same Monte-Carlo study of the Table I loop (``hysteresis.k`` and
``hysteresis.fc`` drawn, frequencies 1-100 Hz, two amplitudes; outputs e1, mismatch,
error_rms) into fresh stores:

1. in this process (``workers=0``): the time and the CPU time a point costs without any
   engine (the baseline);
2. the local process pool with one worker, then two: wall time of the whole run (start of the
   workers, warm-up and writes included) and the CPU time of every process taking part (this
   one and its workers);
3. dask.distributed on a local cluster of two single-thread worker processes (a scheduler and
   workers started by ``distributed.LocalCluster``, warmed by a study of two points): the
   batches ``run_study`` chooses for dask (at least ``DASK_BATCH_SECONDS`` of work), the same
   accounting (scheduler, client and workers).

Wall-time ratios hold on a quiet machine only (the load average is printed before and
after); the CPU times hold on a loaded one too.  From them: the engine's overhead per point
(its CPU time past the baseline's), the parallel efficiency (baseline CPU / the engine's CPU:
two workers give that times 2 on two idle cores; target >= 0.9, i.e. 1.8x) and dask's
overhead against the local pool (target <= 5 %); the idle cluster's CPU per second is
measured too, as its share grows with the wall time (with the load).  Every run's numbers
are checked equal to the first's.  Run with ``make bench`` or
``python benchmarks/study.py [--samples N] [--frequencies N] [--json]``.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import resource
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results, run_study
from motionhyst.study.engine import DASK_BATCH_SECONDS, batch_size, seconds_per_point


def make_study(samples: int, frequencies: int) -> Study:
    base = tomllib.loads(default_scenario_path().read_text())
    return Study.from_dict({
        "outputs": ["e1", "mismatch", "error_rms"],
        "axes": {"amplitude": [0.001, 0.01],
                 "frequency_hz": {"geomspace": [1.0, 100.0, frequencies]}},
        "samples": {"n": samples, "seed": 0, "hysteresis.k": {"lognormal": [20.0, 0.1]},
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
          **kw) -> tuple[float, float, object]:
    """Wall time, CPU time of every process taking part, results."""
    reap = pids is None     # dask's workers (pids) live on; the pool's are joined
    w0, c0, k0 = time.perf_counter(), _cpu_self(), _cpu_children(reap)
    t0 = _cpu_tree(pids) if pids else 0.0
    rep = run_study(study, folder / f"{name}.zarr", **kw)
    seconds = time.perf_counter() - w0
    cpu = (_cpu_self() - c0) + (_cpu_children(reap) - k0)
    if pids:
        cpu += _cpu_tree(pids) - t0
    assert rep.computed == study.n_points and rep.failed == 0, rep
    return seconds, cpu, open_results(folder / f"{name}.zarr")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=100, help="Monte-Carlo samples")
    ap.add_argument("--frequencies", type=int, default=50, help="frequencies 1-100 Hz")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    study = make_study(args.samples, args.frequencies)
    n = study.n_points
    load_before = os.getloadavg()
    per = seconds_per_point(study, 20, cpu=True)   # on CPU time, as run_study (on 6 points)
    batch = batch_size(per, n, 2)
    dask_batch = batch_size(per, n, 2, DASK_BATCH_SECONDS)
    out: dict = {"points": n, "batch": batch, "dask_batch": dask_batch, "cores": os.cpu_count(),
                 "load_before": load_before}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        t0, c0, ref = timed(study, folder, "inprocess", workers=0, batch=batch)
        t1, c1, one = timed(study, folder, "pool1", workers=1, batch=batch)
        t2, c2, two = timed(study, folder, "pool2", workers=2, batch=batch)
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.wait_for_workers(2)
            import psutil

            pids = [p.pid for p in psutil.Process().children(recursive=True)]
            # the workers import the library and load the kernels at their first batch
            timed(make_study(1, 2), folder, "dask_warm", pids=pids, client=client, batch=1)
            # what the idle cluster costs (heartbeats, the scheduler's loop): CPU per second
            w0, i0 = time.perf_counter(), _cpu_self() + _cpu_tree(pids)
            time.sleep(3.0)
            idle = (_cpu_self() + _cpu_tree(pids) - i0) / (time.perf_counter() - w0)
            td, cd, dsk = timed(study, folder, "dask", pids=pids, client=client,
                              batch=dask_batch)
        for other in (one, two, dsk):
            for name in ("e1", "mismatch", "error_rms", "status"):
                np.testing.assert_array_equal(ref[name].values, other[name].values)
    out.update({
        "load_after": os.getloadavg(),
        "in_process_s": t0, "pool_1_s": t1, "pool_2_s": t2, "dask_2_s": td,
        "in_process_cpu_s": c0, "pool_1_cpu_s": c1, "pool_2_cpu_s": c2, "dask_2_cpu_s": cd,
        "ms_per_point_in_process": 1e3 * t0 / n,
        "speedup_2_over_1": t1 / t2,
        "pool_2_overhead_ms_per_point": 1e3 * (c2 - c0) / n,
        "pool_2_efficiency": c0 / c2,
        "dask_overhead_ms_per_point": 1e3 * (cd - c2) / n,
        "dask_overhead_fraction": (cd - c2) / c2,
        "dask_wall_over_pool": td / t2,
        "dask_idle_cpu_per_s": idle,
        # past the idle cluster's share (which grows with the wall time: the load's doing)
        "dask_task_overhead_fraction": (cd - idle * td - c2) / c2,
        # on two idle cores the run would last about half the baseline's CPU time
        "dask_overhead_fraction_quiet": (cd - idle * td + idle * c0 / 2 - c2) / c2,
    })
    if args.json:
        print(json.dumps(out, indent=2))
        return
    la, lb = load_before, out["load_after"]
    print(f"study of {n} points (batches of {batch}, on dask {dask_batch}), numbers equal in "
          f"every engine; {os.cpu_count()} cores, load average {la[0]:.1f} before, "
          f"{lb[0]:.1f} after")
    print(f"  in this process        {t0:7.2f} s, {c0:7.2f} s CPU  "
          f"({out['ms_per_point_in_process']:.3f} ms a point: the baseline)")
    print(f"  local pool, 1 worker   {t1:7.2f} s, {c1:7.2f} s CPU")
    print(f"  local pool, 2 workers  {t2:7.2f} s, {c2:7.2f} s CPU -> "
          f"{out['speedup_2_over_1']:.2f}x one worker's wall time; CPU past the baseline "
          f"{out['pool_2_overhead_ms_per_point']:+.4f} ms a point, efficiency "
          f"{out['pool_2_efficiency']:.3f} (2 x that = "
          f"{2 * out['pool_2_efficiency']:.2f}x on two idle cores; target >= 1.8)")
    print(f"  dask, 2 workers        {td:7.2f} s, {cd:7.2f} s CPU (warm) -> "
          f"{out['dask_wall_over_pool']:.2f}x the pool's wall time; CPU overhead "
          f"{out['dask_overhead_ms_per_point']:+.4f} ms a point, "
          f"{100 * out['dask_overhead_fraction']:+.1f} % of the local pool")
    print(f"    of which the idle cluster {idle:.3f} s CPU a second; past it "
          f"{100 * out['dask_task_overhead_fraction']:+.1f} %; with a run as long as on two idle "
          f"cores {100 * out['dask_overhead_fraction_quiet']:+.1f} % (target <= 5 %)")


if __name__ == "__main__":
    main()
