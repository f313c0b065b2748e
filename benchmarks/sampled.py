"""Benchmark: what a sampled controller costs, each figure a ratio against the continuous loop.

The paper's Table I loop with its controller continuous, against the same
controller discretised (Tustin) at 10 kHz, 1.5 samples of delay, feedforward
advanced by 2 samples, measured side by side in one run (interleaved, median
CPU time of this process over ``REPEATS`` runs):

1. ``analysis``: :func:`motionhyst.analyze` at 5, 10, 15 Hz (eq. 18, the
   margins, the crossovers): target ratio sampled / continuous <= 2.
2. ``steady``: one exact periodic steady-state point at 10 Hz (the hybrid
   loop's with the aliasing of 1000 samples a period, against the continuous
   loop's); reported, no target.
3. ``simulation``: :func:`motionhyst.simulate` of 1 s from rest at 10 Hz (the
   run with the link and the one without it, as the summary reports both),
   per controller sample against the continuous loop's per integration step:
   target ratio <= 1.

Run with ``make bench`` or ``python benchmarks/sampled.py [--json]``.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time

import numpy as np

from motionhyst import Jenkins, LeadLagLowpass, Loop, SineReference, TwoMassStage, analyze, simulate
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.sampled import SampledController

REPEATS = 21
SIM_REPEATS = 5
TARGETS = {"analysis": 2.0, "simulation": 1.0}


def loops() -> tuple[Loop, Loop]:
    """Table I with the continuous controller, and at 10 kHz with 1.5 samples of delay."""
    stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
    link = Jenkins(k=20.0, fc=0.05)
    sampled = SampledController.discretize(C, 10e3, delay_samples=1.5)
    return (Loop(stage, C, link),
            Loop(stage, sampled, link, feedforward=Feedforward(advance_samples=2.0)))


def _cpu(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def measure(repeats: int = REPEATS) -> dict:
    """Median CPU times [s] of each task for both loops, and their ratios."""
    cont, samp = loops()
    tasks = {
        "analysis": lambda loop: analyze(loop, 0.01, [5.0, 10.0, 15.0]),
        "steady": lambda loop: periodic_steady_state(loop, 0.01, 10.0),
    }
    out = {}
    for name, task in tasks.items():
        task(cont), task(samp)            # warm-up: compiled kernels, caches of the link
        times: dict[str, list[float]] = {"continuous": [], "sampled": []}
        for _ in range(repeats):
            times["continuous"].append(_cpu(lambda t=task: t(cont)))
            times["sampled"].append(_cpu(lambda t=task: t(samp)))
        med = {k: statistics.median(v) for k, v in times.items()}
        out[name] = {**med, "ratio": med["sampled"] / med["continuous"],
                     "target": TARGETS.get(name)}
    ref = SineReference(0.01, 10.0)
    runs = {"continuous": simulate(cont, ref, 1.0), "sampled": simulate(samp, ref, 1.0)}
    steps = {k: v.t.size for k, v in runs.items()}
    times = {"continuous": [], "sampled": []}
    for _ in range(SIM_REPEATS):
        times["continuous"].append(_cpu(lambda: simulate(cont, ref, 1.0)))
        times["sampled"].append(_cpu(lambda: simulate(samp, ref, 1.0)))
    per = {k: statistics.median(v) / steps[k] for k, v in times.items()}
    out["simulation"] = {**per, "ratio": per["sampled"] / per["continuous"],
                         "target": TARGETS["simulation"], "steps": steps,
                         "unit": "s per integration step (continuous) / controller sample"}
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
    print(f"sampled (10 kHz, 1.5 samples of delay) vs continuous Table I loop; "
          f"median CPU time of {args.repeats} interleaved runs; {platform.python_version()}, "
          f"numpy {np.__version__}")
    for name, r in res.items():
        target = "" if r["target"] is None else (
            f"  target <= {r['target']:g}x: {'met' if r['ratio'] <= r['target'] else 'MISSED'}")
        if name == "simulation":
            print(f"  {name:<9} continuous {r['continuous'] * 1e6:8.2f} us a step ("
                  f"{r['steps']['continuous']} steps), sampled {r['sampled'] * 1e6:8.2f} us a "
                  f"sample ({r['steps']['sampled']} samples)   ratio {r['ratio']:.2f}x{target}")
            continue
        print(f"  {name:<9} continuous {r['continuous'] * 1e3:8.2f} ms   sampled "
              f"{r['sampled'] * 1e3:8.2f} ms   ratio {r['ratio']:.2f}x{target}")


if __name__ == "__main__":
    main()
