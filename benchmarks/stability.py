"""Benchmark: the stability analysis (issue 25), each figure against a baseline of the same run.

1. ``table-i``: :func:`motionhyst.stability` of the paper's Table I loop (Jenkins link: the
   prediction over the amplitude-frequency grid; no exact orbit), against the baseline
   :func:`motionhyst.analyze` at 5, 10 and 15 Hz (the quasi-linear analysis a user runs
   first); median CPU time of this process over ``REPEATS`` interleaved runs.  Target: the
   issue's 2 s for the call, reported with the ratio.
2. ``command``: ``motionhyst stability --json`` as a whole process (import, scenario,
   analysis, JSON), wall time, against ``motionhyst analyze --json`` (the baseline);
   target 2 s.
3. ``hunting``: ``stability`` of ``examples/hunting.toml`` (LuGre: the rate-dependent
   loci, the cut at the integrator, the search by simulation, the exact orbit), against the
   same baseline; reported, no target.

Run with ``make bench`` or ``python benchmarks/stability.py [--json]``.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from motionhyst import analyze, default_scenario, load_scenario, stability

REPEATS = 11
PROCESS_REPEATS = 5
TARGET_S = 2.0
HUNTING = Path(__file__).resolve().parent.parent / "examples" / "hunting.toml"


def _cpu(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def _wall(args: list[str]) -> float:
    code = "import sys; from motionhyst.cli import main; sys.exit(main(sys.argv[1:]))"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code, *args], check=True, capture_output=True)
    return time.perf_counter() - t0


def measure(repeats: int = REPEATS) -> dict:
    """Median times [s] of each task and of its baseline, their ratios."""
    loop = default_scenario().loop()
    hunt = load_scenario(HUNTING).loop()

    def baseline():
        analyze(loop, 0.01, [5.0, 10.0, 15.0])

    baseline(), stability(loop)                       # warm-up: compiled kernels
    t_base, t_stab = [], []
    for _ in range(repeats):
        t_base.append(_cpu(baseline))
        t_stab.append(_cpu(lambda: stability(loop)))
    out = {"table-i": {"baseline": statistics.median(t_base),
                       "time": statistics.median(t_stab), "target_s": TARGET_S}}
    w_base, w_cmd = [], []
    for _ in range(PROCESS_REPEATS):
        w_base.append(_wall(["analyze", "--json"]))
        w_cmd.append(_wall(["stability", "--json"]))
    out["command"] = {"baseline": statistics.median(w_base), "time": statistics.median(w_cmd),
                      "target_s": TARGET_S}
    out["hunting"] = {"baseline": out["table-i"]["baseline"],
                      "time": _cpu(lambda: stability(hunt)), "target_s": None}
    for r in out.values():
        r["ratio"] = r["time"] / r["baseline"]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--repeats", type=int, default=REPEATS)
    args = parser.parse_args()
    res = measure(args.repeats)
    if args.json:
        print(json.dumps(res, indent=2))
        return
    print(f"stability: median times, baselines in the same run; {platform.python_version()}, "
          f"numpy {np.__version__}")
    what = {"table-i": "stability(Table I) vs analyze(5, 10, 15 Hz), CPU",
            "command": "motionhyst stability --json vs analyze --json, wall",
            "hunting": "stability(hunting.toml) vs analyze(Table I), CPU"}
    for name, r in res.items():
        target = "" if r["target_s"] is None else (
            f"  target <= {r['target_s']:g} s: {'met' if r['time'] <= r['target_s'] else 'MISSED'}")
        print(f"  {what[name]:<55} {r['time']:8.3f} s  baseline {r['baseline']:8.3f} s  "
              f"ratio {r['ratio']:6.2f}x{target}")


if __name__ == "__main__":
    main()
