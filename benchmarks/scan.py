"""Benchmark of ``motionhyst scan``: a scan with three compensations and 10 ILC trials.

One run measures, on the Table I loop with a link model 4 % off (``examples/scan.toml``)
and the scan of ``examples/scan_compensation.py`` (15 mm at 50 mm/s and back, 1.07 s):

1. motionhyst: :func:`motionhyst.scan.scanning.run_scan` with ``none``, ``model`` and ``ilc``
   (10 trials) and the carry-over at half the speed, 14 simulations in all (median of
   3 after a warm-up), and the whole command ``motionhyst scan ...`` as a new process
   (imports included);
2. its accuracy: the scan metrics at the default step against a run at a quarter of it;
3. the peer: one trial as a python-control user would run it (the interconnected loop
   of ``benchmarks/run.py``, eq. (3) as a ``control.nlsys``, driven by the profile's
   ``r`` and ``M r''`` through ``control.input_output_response`` at ``rtol=1e-6``),
   capped at ``--peer-cap`` seconds, and its error against motionhyst's;
4. the ratio: the peer's time for the 14 simulations against motionhyst's.

Run with ``make bench`` or ``python benchmarks/scan.py [--json] [--peer-cap S]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import control as ct
import numpy as np

from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import run_scan
from motionhyst.scenario import Scenario
from motionhyst.time.simulation import default_step

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "examples" / "scan.toml"
LENGTH, SPEED, WINDOW, TRIALS = 0.015, 0.05, 0.05, 10
LIMITS = {"a_max": 2.0, "j_max": 50.0, "s_max": 1e3}
SIMULATIONS = 14  # none, model, 9 more ILC trials; carry-over: none, model, ilc
REPEATS = 3
TARGET_S = 10.0   # issue 14: the whole command


def _peer_module():
    spec = importlib.util.spec_from_file_location("peer_run", Path(__file__).with_name("run.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_peer(profile, duration: float, mass: float, cap_s: float, t_mh, e_mh) -> dict:
    """One trial of the scan through python-control (no compensation)."""
    peer = _peer_module()
    start = time.perf_counter()
    element = peer.JenkinsODE(peer.KJ, peer.FC, start + cap_s)
    T = np.linspace(0.0, duration, round(duration / 1e-6) + 1)
    r, a = profile(T)
    out = {"capped": False}
    try:
        res = ct.input_output_response(peer.build_peer(element), T, np.vstack([r, mass * a]),
                                       X0=0.0, t_eval=t_mh,
                                       solve_ivp_kwargs={"rtol": 1e-6})
    except peer.PeerCapped:
        res = None
    out["wall_s"] = time.perf_counter() - start
    out["rhs_calls"] = element.calls
    if res is None:
        out.update(capped=True, t_reached_s=element.t_reached, rel_error=None)
        return out
    e = res.outputs[0]
    out["rel_error"] = float(np.max(np.abs(e - e_mh)) / np.max(np.abs(e_mh)))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--peer-cap", type=float, default=120.0, help="peer wall-time cap [s]")
    args = ap.parse_args(argv)

    loop = Scenario.from_file(SCENARIO).loop()
    profile = scan(LENGTH, SPEED, back_and_forth=True, start=0.01, **LIMITS)
    other = scan(LENGTH, SPEED / 2, back_and_forth=True, start=0.01, **LIMITS)

    def compare(dt=None):
        return run_scan(loop, profile, WINDOW, ("none", "model", "ilc"), TRIALS,
                        other_profile=other, dt=dt)

    t0 = time.perf_counter()
    res = compare()
    first_s = time.perf_counter() - t0
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        res = compare()
        times.append(time.perf_counter() - t0)
    wall = statistics.median(times)
    cmd = [sys.executable, "-m", "motionhyst.cli", "scan", str(SCENARIO), "--length",
           str(LENGTH), "--speed", str(SPEED), "--a-max", "2", "--j-max", "50", "--s-max",
           "1000", "--window", str(WINDOW), "--back-and-forth", "--ilc-trials", str(TRIALS),
           "--json"]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    command_s = time.perf_counter() - t0

    # accuracy: the metrics at the default step against a quarter of it
    dt = default_step(loop, profile.max_frequency_hz)
    fine = run_scan(loop, profile, WINDOW, ("none", "model"), dt=dt / 4)
    acc = {}
    for c in ("none", "model"):
        a, b = res.run(c), fine.run(c)
        acc[c] = {"ma_max": abs(a.ma_max - b.ma_max) / b.ma_max,
                  "msd_max": abs(a.msd_max - b.msd_max) / b.msd_max}

    none = res.run("none")
    duration = float(none.t[-1])
    peer = run_peer(profile, duration, loop.M, args.peer_cap, none.t, none.e)
    out = {"run_scan_s": wall, "run_scan_first_call_s": first_s, "command_s": command_s,
           "simulations": SIMULATIONS, "samples": len(none.t), "dt_s": dt,
           "duration_s": duration, "metric_change_at_dt_over_4": acc, "peer": peer,
           "ratio_time": (peer["wall_s"] * SIMULATIONS / wall) if not peer["capped"] else None,
           "ratio_time_lower_bound": (args.peer_cap * duration / max(peer.get("t_reached_s",
                                      duration), 1e-9) * SIMULATIONS / wall)
           if peer["capped"] else None,
           "reductions": {c: {"ma": none.ma_max / res.run(c).ma_max,
                              "msd": none.msd_max / res.run(c).msd_max}
                          for c in ("model", "ilc")}}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"motionhyst scan benchmark: {profile}")
    print(f"  run_scan, 3 compensations, {TRIALS} ILC trials, carry-over ({SIMULATIONS} "
          f"simulations of {len(none.t)} steps): {wall:.2f} s (median of {REPEATS}; first "
          f"call {first_s:.2f} s)")
    print(f"  the command as a new process: {command_s:.2f} s (target <= {TARGET_S:g} s)")
    for c, d in acc.items():
        print(f"  {c}: max MA and max MSD change by {d['ma_max']:.1e} and {d['msd_max']:.1e} "
              "at a quarter of the step")
    if peer["capped"]:
        print(f"  peer (python-control, rtol=1e-6): capped at {args.peer_cap:g} s after "
              f"{peer['t_reached_s']:.3g} s of {duration:.3g} s; 14 trials >= "
              f"{out['ratio_time_lower_bound']:.0f}x motionhyst")
    else:
        print(f"  peer (python-control, rtol=1e-6): one trial {peer['wall_s']:.1f} s, error "
              f"{peer['rel_error']:.1e} of the peak against motionhyst; 14 trials "
              f"{out['ratio_time']:.0f}x motionhyst's time")
    for c, r in out["reductions"].items():
        print(f"  {c} cuts max MA {r['ma']:.3g}x, max MSD {r['msd']:.3g}x (target >= 10x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
