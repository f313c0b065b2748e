"""Benchmark of the one-stage check of input-output records
(``motionhyst.identify.io_consistency.check_one_stage``): its CPU time grows with the number
of records, not with its square.

Each record is compared with the fit of all the others; the others' fit is summed from each
record's share of the least squares and of its Newey-West covariance, formed once (review
A13b M5: the fit of the others redone for every record took 5.1 s of CPU for 40 records of
10,000 samples, 25 times the check of 2 such records; before ``--max-seconds`` applies).
Records: a 2 kg axis (10 N s/m, a Jenkins link of 2000 N/m and 1 N) driven by two sines at
1 kHz, 10,000 samples each, 1 um of position noise (a different draw each); CPU time of this
process, the median of ``REPEATS``, for ``COUNTS`` records, and each count's ratio of CPU per
record against the smallest count's.  A check linear in the records keeps the ratios near 1
(target: ``TARGET``; measured 0.96 at 40 records); the quadratic one grew them with the count
(1.9 at 16 records, 3.3 at 40: 6.4 s of CPU).

Run with ``make bench`` or ``python benchmarks/one_stage.py [--json]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np

COUNTS = (4, 16, 40)
SAMPLES = 10_000
REPEATS = 3
TARGET = 2.0


def _records(count: int):
    from motionhyst import Jenkins
    from motionhyst.identify.io_records import IORecord
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    t = np.arange(SAMPLES) / 1000.0
    u = 5 * np.sin(2 * np.pi * 1.3 * t) + 3 * np.sin(2 * np.pi * 4.1 * t + 0.4)
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2000.0, fc=1.0)).simulate(t, u).displacement
    return [IORecord(t, u, y + 1e-6 * np.random.default_rng(i).standard_normal(SAMPLES),
                     f"r{i}.csv") for i in range(count)]


def measure() -> dict:
    """CPU seconds of the check for each of :data:`COUNTS` records, and per-record ratios."""
    from motionhyst.identify.io_consistency import check_one_stage

    check_one_stage(_records(2), floating=True)  # imports and caches outside the timing
    runs = []
    for count in COUNTS:
        records = _records(count)
        times = []
        for _ in range(REPEATS):
            c0 = time.process_time()
            check_one_stage(records, floating=True)
            times.append(time.process_time() - c0)
        runs.append({"records": count, "cpu_s": statistics.median(times)})
    base = runs[0]["cpu_s"] / runs[0]["records"]
    for run in runs:
        run["per_record_ratio"] = run["cpu_s"] / run["records"] / base
    return {"samples": SAMPLES, "runs": runs, "target": TARGET}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    args = parser.parse_args()
    res = measure()
    if args.json:
        print(json.dumps(res, indent=2))
        return
    print(f"One-stage check, records of {res['samples']} samples: CPU, and CPU per record "
          f"against {res['runs'][0]['records']} records' (target <= {TARGET:g}x)")
    for run in res["runs"]:
        verdict = "ok" if run["per_record_ratio"] <= TARGET else "ABOVE TARGET"
        print(f"  {run['records']:3d} records {run['cpu_s']:7.3f} s  "
              f"{run['per_record_ratio']:5.2f}x  {verdict}")


if __name__ == "__main__":
    main()
