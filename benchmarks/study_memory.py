"""Benchmark of a study's memory: a 1 M-point study in the memory of a small one.

Runs ``motionhyst study`` as a user would, under ``/usr/bin/time -v``, on two studies of the
Table I loop that differ only in their number of Monte-Carlo samples (the large one 50 times
the small one's points; by default 20 000 and 1 000 000 points: 10 amplitudes x 100
frequencies x 10 values of ``hysteresis.fc`` x 2 or 100 samples of ``hysteresis.k``, output
``E``), with two local workers.  Reported: the largest resident set of one process
(``/usr/bin/time``: the command or one of its workers) and the largest sum over the command
and its workers (sampled every 0.2 s), for both; the study's results are never held whole
(they go to the zarr store chunk by chunk), so both stay flat (target: under 1 GB for 1 M
points).  Run with ``make bench`` (a few minutes on two cores) or
``python benchmarks/study_memory.py [--samples-small N] [--samples N] [--workers N] [--json]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from motionhyst.scenario import default_scenario_path

STUDY = """\
scenario = "paper.toml"
outputs = ["E"]
[axes]
amplitude = {{ geomspace = [0.0005, 0.02, 10] }}
frequency_hz = {{ geomspace = [1.0, 200.0, 100] }}
"hysteresis.fc" = {{ linspace = [0.03, 0.07, 10] }}
[samples]
n = {samples}
seed = 0
"hysteresis.k" = {{ lognormal = [20.0, 0.1] }}
"""


def measure(folder: Path, samples: int, workers: int) -> dict:
    """Run one study under /usr/bin/time -v; peak RSS of one process and of the tree."""
    import psutil

    study = folder / f"study{samples}.toml"
    study.write_text(STUDY.format(samples=samples))
    store = folder / f"s{samples}.zarr"
    cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "motionhyst.cli", "study", str(study),
           "--out", str(store), "--workers", str(workers), "--json"]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    tree_peak = 0
    root = psutil.Process(proc.pid)
    while proc.poll() is None:
        try:
            procs = [root, *root.children(recursive=True)]
            tree_peak = max(tree_peak, sum(p.memory_info().rss for p in procs
                                           if p.name() != "time"))
        except psutil.Error:
            pass
        time.sleep(0.2)
    out, err = proc.communicate()
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"study of {samples} samples failed: {err.strip()}")
    report = json.loads(out)
    peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", err).group(1))
    shutil.rmtree(store)
    return {"points": report["points"], "failed": report["failed"], "seconds": seconds,
            "max_rss_one_process_mb": peak_kb / 1024, "max_rss_tree_mb": tree_peak / 2**20}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples-small", type=int, default=2)
    ap.add_argument("--samples", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    if not Path("/usr/bin/time").exists():
        raise SystemExit("needs /usr/bin/time (GNU time)")
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        shutil.copy(default_scenario_path(), folder / "paper.toml")
        small = measure(folder, args.samples_small, args.workers)
        large = measure(folder, args.samples, args.workers)
    out = {"load_before": load, "load_after": os.getloadavg(), "small": small, "large": large,
           "ratio_one_process": large["max_rss_one_process_mb"]
           / small["max_rss_one_process_mb"],
           "ratio_tree": large["max_rss_tree_mb"] / small["max_rss_tree_mb"]}
    if args.json:
        print(json.dumps(out, indent=2))
        return
    print(f"study memory ({args.workers} workers; load average {load[0]:.1f} before, "
          f"{out['load_after'][0]:.1f} after)")
    for r in (small, large):
        print(f"  {r['points']:>9} points in {r['seconds']:6.0f} s ({r['failed']} failed): peak "
              f"RSS {r['max_rss_one_process_mb']:6.0f} MB one process, "
              f"{r['max_rss_tree_mb']:6.0f} MB command and workers")
    print(f"  large / small: {out['ratio_one_process']:.2f} (one process), "
          f"{out['ratio_tree']:.2f} (command and workers); target: under 1 GB for 1 M points")


if __name__ == "__main__":
    main()
