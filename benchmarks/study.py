"""Benchmark of ``motionhyst study``: scaling over local workers and dask's overhead per point.

One run computes the same Monte-Carlo study of the Table I loop (``hysteresis.k`` and
``hysteresis.fc`` drawn, frequencies 1-100 Hz, two amplitudes; outputs e1, mismatch,
error_rms) into fresh stores:

1. in this process (``workers=0``): the time a point costs without any engine;
2. the local process pool with one worker, then two: wall time of the whole run (start of the
   workers, warm-up and writes included), the start-up alone (a study of two points a worker)
   and the ratio one / two of the time past the start-up (target >= 1.8 on a quiet 2-core
   machine);
3. dask.distributed on a local cluster of two single-thread worker processes (a scheduler and
   workers started by ``distributed.LocalCluster``, running and warmed by a study of four
   points): the same batches; its overhead per point against the local pool's time past its
   start-up (target <= 5 %).

Every run's numbers are checked equal to the first's.  Run with ``make bench`` or
``python benchmarks/study.py [--points-per-sample N] [--samples N] [--json]``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results, run_study
from motionhyst.study.engine import batch_size, seconds_per_point


def make_study(samples: int, frequencies: int) -> Study:
    base = tomllib.loads(default_scenario_path().read_text())
    return Study.from_dict({
        "outputs": ["e1", "mismatch", "error_rms"],
        "axes": {"amplitude": [0.001, 0.01],
                 "frequency_hz": {"geomspace": [1.0, 100.0, frequencies]}},
        "samples": {"n": samples, "seed": 0, "hysteresis.k": {"lognormal": [20.0, 0.1]},
                    "hysteresis.fc": {"lognormal": [0.05, 0.1]}}}, scenario=base)


def timed(study: Study, folder: Path, name: str, **kw) -> tuple[float, object]:
    t0 = time.perf_counter()
    rep = run_study(study, folder / f"{name}.zarr", **kw)
    seconds = time.perf_counter() - t0
    assert rep.computed == study.n_points and rep.failed == 0, rep
    return seconds, open_results(folder / f"{name}.zarr")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20, help="Monte-Carlo samples")
    ap.add_argument("--frequencies", type=int, default=50, help="frequencies 1-100 Hz")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    study = make_study(args.samples, args.frequencies)
    n = study.n_points
    per = seconds_per_point(study, 20)
    batch = batch_size(per, n, 2)
    out: dict = {"points": n, "batch": batch, "seconds_per_point_measured": per}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        t0, ref = timed(study, folder, "inprocess", workers=0, batch=batch)
        t1, one = timed(study, folder, "pool1", workers=1, batch=batch)
        t2, two = timed(study, folder, "pool2", workers=2, batch=batch)
        s1, _ = timed(make_study(1, 1), folder, "start1", workers=1, batch=1)
        s2, _ = timed(make_study(1, 2), folder, "start2", workers=2, batch=1)
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.wait_for_workers(2)
            # the workers import the library and load the kernels at their first batch
            timed(make_study(1, 2), folder, "dask_warm", client=client, batch=1)
            td, dsk = timed(study, folder, "dask", client=client, batch=batch)
        for other in (one, two, dsk):
            for name in ("e1", "mismatch", "error_rms", "status"):
                np.testing.assert_array_equal(ref[name].values, other[name].values)
    out.update({
        "in_process_s": t0, "pool_1_s": t1, "pool_2_s": t2, "dask_2_s": td,
        "ms_per_point_in_process": 1e3 * t0 / n,
        "start_1_s": s1, "start_2_s": s2,
        "speedup_2_over_1": t1 / t2,
        "speedup_2_over_1_past_start": (t1 - s1) / (t2 - s2),
        "dask_overhead_per_point_ms": 1e3 * (td - (t2 - s2)) / n,
        "dask_overhead_fraction": (td - (t2 - s2)) / (t2 - s2),
    })
    if args.json:
        print(json.dumps(out, indent=2))
        return
    print(f"study of {n} points (batches of {batch}), numbers equal in every engine")
    print(f"  in this process        {t0:7.2f} s  ({out['ms_per_point_in_process']:.3f} ms a "
          f"point)")
    print(f"  local pool, 1 worker   {t1:7.2f} s  (start-up {s1:.2f} s)")
    print(f"  local pool, 2 workers  {t2:7.2f} s  (start-up {s2:.2f} s) -> "
          f"{out['speedup_2_over_1']:.2f}x one worker, "
          f"{out['speedup_2_over_1_past_start']:.2f}x past the start-up "
          f"(target >= 1.8 on a quiet machine)")
    print(f"  dask, 2 workers        {td:7.2f} s  (warm) -> overhead "
          f"{out['dask_overhead_per_point_ms']:+.3f} ms a point, "
          f"{100 * out['dask_overhead_fraction']:+.1f} % of the local pool (target <= 5 %)")


if __name__ == "__main__":
    main()
