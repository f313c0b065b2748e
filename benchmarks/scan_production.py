"""Benchmark of ``motionhyst scan`` at production speed: none, model, ilc and basis.

One run measures, on the Table I loop whose feedforward inverts the stage up to the snap
and carries a link model 4 % off (``examples/scan_production.toml``), the scan of issue 24
(0.1 m at 0.5 m/s, 20 m/s^2, 2000 m/s^3, 4e5 m/s^4, a 10 ms window, 10 ILC trials,
4 basis trials, the carry-over at half the speed):

1. the baselines, measured in the same run: one simulation of the scan (the run ``none``,
   median of 5) and the command with ``--compensation none`` alone as a new process
   (imports included, median of 3);
2. motionhyst: :func:`motionhyst.scan.scanning.run_scan` with the four compensations
   (median of 3 after a warm-up) and the whole command ``motionhyst scan ...`` as a new
   process (median of 3);
3. the ratios: ``run_scan`` over one simulation (it costs that many simulations of its
   scan), the command over the command without compensations, and the command's time
   against the issue's 20 s;
4. the accuracy: model's and basis's metrics at the default step against a quarter of it.

Run with ``make bench`` or ``python benchmarks/scan_production.py [--json]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

from motionhyst.controllers.loop import Loop
from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import run_scan
from motionhyst.scenario import Scenario
from motionhyst.time.simulation import default_step, simulate

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "examples" / "scan_production.toml"
LENGTH, SPEED, WINDOW, TRIALS = 0.1, 0.5, 0.01, 10
LIMITS = {"a_max": 20.0, "j_max": 2000.0, "s_max": 4e5}
COMPENSATIONS = ("none", "model", "ilc", "basis")
TARGET_S = 20.0   # issue 24: the whole command


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)

    loop = Scenario.from_file(SCENARIO).loop()
    profile = scan(LENGTH, SPEED, start=0.01, **LIMITS)
    other = scan(LENGTH, SPEED / 2, start=0.01, **LIMITS)
    duration = profile.end + 0.05
    bare = Loop(loop.plant, loop.controller, loop.hysteresis)  # M r'' alone: the run none
    simulate(bare, profile, duration)  # warm-up (compilation)
    baseline = _median_time(lambda: simulate(bare, profile, duration), 5)

    def compare(dt=None):
        return run_scan(loop, profile, WINDOW, COMPENSATIONS, TRIALS, other_profile=other,
                        dt=dt)

    res = compare()
    wall = _median_time(compare, 3)
    cmd = [sys.executable, "-m", "motionhyst.cli", "scan", str(SCENARIO), "--length",
           str(LENGTH), "--speed", str(SPEED), "--a-max", "20", "--j-max", "2000", "--s-max",
           "4e5", "--window", str(WINDOW), "--compensation", *COMPENSATIONS, "--ilc-trials",
           str(TRIALS), "--json"]
    command = _median_time(lambda: subprocess.run(cmd, check=True, capture_output=True), 3)
    bare_cmd = [*cmd[:cmd.index("--compensation") + 1], "none", "--json"]
    command_none = _median_time(
        lambda: subprocess.run(bare_cmd, check=True, capture_output=True), 3)

    dt = default_step(loop, profile.max_frequency_hz)
    fine = run_scan(loop, profile, WINDOW, ("none", "model", "basis"), dt=dt / 4)
    acc = {c: {"ma_max": abs(res.run(c).ma_max - fine.run(c).ma_max) / fine.run(c).ma_max,
               "msd_max": abs(res.run(c).msd_max - fine.run(c).msd_max) / fine.run(c).msd_max}
           for c in ("none", "model", "basis")}
    none = res.run("none")
    out = {"baseline": "one simulation of the scan (compensation none)",
           "baseline_s": baseline, "command_baseline": "the command with --compensation none",
           "command_baseline_s": command_none, "run_scan_s": wall, "command_s": command,
           "ratio_run_scan": wall / baseline, "ratio_command": command / command_none,
           "command_target_s": TARGET_S, "samples": len(none.t), "dt_s": dt,
           "metric_change_at_dt_over_4": acc,
           "reductions": {c: {"ma": none.ma_max / res.run(c).ma_max,
                              "msd": none.msd_max / res.run(c).msd_max}
                          for c in COMPENSATIONS[1:]},
           "carry_over_reductions": {
               c: {"ma": res.carry_over.run("none").ma_max / res.carry_over.run(c).ma_max,
                   "msd": res.carry_over.run("none").msd_max / res.carry_over.run(c).msd_max}
               for c in COMPENSATIONS[1:]}}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"motionhyst scan at production speed: {profile}")
    print(f"  baseline, one simulation of the scan ({len(none.t)} steps): {baseline:.3f} s "
          f"(median of 5)")
    print(f"  run_scan, 4 compensations, {TRIALS} ILC trials, carry-over: {wall:.2f} s = "
          f"{out['ratio_run_scan']:.1f}x the baseline")
    print(f"  the command as a new process: {command:.2f} s = {out['ratio_command']:.1f}x the "
          f"command with --compensation none ({command_none:.2f} s; target <= {TARGET_S:g} s)")
    for c, d in acc.items():
        print(f"  {c}: max MA and max MSD change by {d['ma_max']:.1e} and {d['msd_max']:.1e} "
              "at a quarter of the step")
    for what in ("reductions", "carry_over_reductions"):
        print(f"  {what}: " + "; ".join(f"{c} {r['ma']:.3g}x / {r['msd']:.3g}x"
                                        for c, r in out[what].items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
