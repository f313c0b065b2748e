"""Benchmark: where a user waits, each figure a ratio against a peer measured in the same run.

1. Start-up: wall time of ``motionhyst --help`` and of
   ``motionhyst df --k 20 --fc 0.05 --amplitude 0.01`` against
   ``python -c "import numpy"`` (fresh processes, interleaved, median of
   ``STARTUP_REPEATS``; kernels already compiled and cached).
2. Link models: one steady-state point of the Table I loop
   (``periodic_steady_state``, r = 10 mm at 10-11 Hz, default accuracy) with
   each link model against the same point with the Jenkins element
   (interleaved, each round starting with another model, median over
   ``STEADY_POINTS`` different frequencies, so no model's cache of describing
   functions helps it).  Targets: a link of stop operators within 3x, a link
   whose periodic output runs its equation over a sampled period (Bouc-Wen,
   Dahl, LuGre) within 10x (:data:`TARGETS`).  Timed as this
   process's CPU time: a point takes about a millisecond, and on a machine
   shared with other jobs a wall-clock time that short is often a time slice
   lost to them.
3. Identification at scale: ``motionhyst identify record.csv`` on
   force-displacement records of the same motion (20 s, three Jenkins
   elements, 0.1 % noise) sampled with 1e5 and 1e6 samples: wall time (CSV
   reading included) and peak memory (maximum resident set size; the sizes
   run in increasing order, so the figure of the larger is its own), and the
   ratio of the times.
4. Figures: ``motionhyst reproduce`` (figures, report) against
   ``motionhyst analyze`` (numbers only) on Table I, and on Table I with a
   LuGre link (:data:`LUGRE_LINK`) (fresh processes, interleaved, median of
   ``REPORT_REPEATS``).

Commands run as fresh processes are timed by wall clock (the targets) and by
CPU time (user + system, worker processes included), which a machine shared
with other jobs inflates less.

Run with ``make bench`` or ``python benchmarks/speed.py [--json] [--quick] [--only SECTION ...]``
(``--only steady`` measures the link models alone).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

STARTUP_REPEATS = 15
STEADY_POINTS = 40
REPORT_REPEATS = 5
IDENTIFY_SIZES = (100_000, 1_000_000)

SECTIONS = ("startup", "steady", "identify", "report")
TARGETS = {"help": 3.0, "df": 5.0, "steady": 3.0, "steady_ode": 10.0, "identify_time": 4.0,
           "identify_mb": 700.0, "reproduce": 2.0}
# "steady": a link of stop operators (Maxwell-slip) against the Jenkins point, both compiled
# whole with their exact harmonics in closed form.  "steady_ode": a link whose output is not a
# stop operator's (Bouc-Wen, Dahl, LuGre) runs its equation's segment solutions over a sampled
# period at each step of a Python fixed point; its points (0.6-0.8 ms, as when they were
# 2.1-2.4x a 0.30 ms Jenkins point) are 8.3x (Bouc-Wen), 9.7x (Dahl) and 8.9x (LuGre) the
# compiled Jenkins point (medians of three runs of ``--only steady``, runs 8.2-8.4x,
# 9.5-9.8x, 8.5-8.9x; load average 5-7): 10x is the bound this bench guards, not 3x, and Dahl
# is within 3 % of it.

def _record(n: int, path: Path) -> None:
    """A force-displacement record of `n` samples over the same 20 s of motion (CSV)."""
    from motionhyst.hysteresis import MaxwellSlip

    t = np.linspace(0.0, 20.0, n)
    x = (0.01 * np.sin(2 * np.pi * 0.5 * t) * (1 + 0.5 * np.sin(2 * np.pi * 0.07 * t))
         + 0.002 * np.sin(2 * np.pi * 3.1 * t))
    el = MaxwellSlip(k=[20.0, 8.0, 3.0], fc=[0.02, 0.03, 0.05])
    w = el.response(x) + 1e-4 * np.random.default_rng(0).standard_normal(n) + 0.01
    with path.open("w") as fh:
        fh.write("time,displacement,force\n")
        np.savetxt(fh, np.column_stack([t, x, w]), delimiter=",", fmt="%.12e")


def _command(*args: str) -> list[str]:
    """The ``motionhyst`` console script next to this interpreter, else ``python -m``."""
    script = Path(sys.executable).with_name("motionhyst")
    if script.exists():
        return [str(script), *args]
    return [sys.executable, "-m", "motionhyst.cli", *args]


def _run(cmd: list[str], cwd: str | None = None) -> tuple[float, float]:
    """Wall time and CPU time (user + system, its worker processes included) of a command."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=cwd)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed with exit code {proc.returncode}")
    return wall, usage.ru_utime + usage.ru_stime


def _interleaved(cmds: dict[str, list[str]], repeats: int, cwd: str | None = None
                 ) -> dict[str, float]:
    """Median wall and CPU time of each command, run in turn `repeats` times (after a warm-up).

    Keys ``name`` (wall [s]) and ``name_cpu`` (CPU [s]).
    """
    for cmd in cmds.values():
        _run(cmd, cwd)  # compile kernels, fill the OS's file cache
    times: dict[str, list[tuple[float, float]]] = {k: [] for k in cmds}
    for _ in range(repeats):
        for k, cmd in cmds.items():
            times[k].append(_run(cmd, cwd))
    out = {}
    for k, v in times.items():
        out[k] = statistics.median(w for w, _ in v)
        out[f"{k}_cpu"] = statistics.median(c for _, c in v)
    return out


def startup(repeats: int) -> dict:
    t = _interleaved({
        "numpy": [sys.executable, "-c", "import numpy"],
        "help": _command("--help"),
        "df": _command("df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"),
    }, repeats)
    return {**t, "help_ratio": t["help"] / t["numpy"], "df_ratio": t["df"] / t["numpy"],
            "help_cpu_ratio": t["help_cpu"] / t["numpy_cpu"],
            "df_cpu_ratio": t["df_cpu"] / t["numpy_cpu"]}


def steady_models(points: int) -> dict:
    from motionhyst import (
        BoucWen,
        Dahl,
        Jenkins,
        LeadLagLowpass,
        Loop,
        LuGre,
        MaxwellSlip,
        TwoMassStage,
        periodic_steady_state,
    )

    stage = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)
    controller = LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6)
    links = {
        "Jenkins (k = 20, fc = 0.05)": Jenkins(20.0, 0.05),
        "Maxwell-slip, 3 elements": MaxwellSlip([12.0, 5.0, 3.0], [0.02, 0.02, 0.01]),
        "Bouc-Wen, n = 2": BoucWen(k=20.0, fc=0.05, n=2.0, beta=0.7, gamma=0.3),
        "Dahl, alpha = 1": Dahl(20.0, 0.05),
        "LuGre": LuGre(sigma0=20.0, sigma1=0.01, sigma2=0.001, fc=0.05, fs=0.06, vs=0.01),
    }
    loops = {name: Loop(stage, controller, el) for name, el in links.items()}
    for loop in loops.values():
        periodic_steady_state(loop, 0.01, 9.0)  # compile
    freqs = np.linspace(10.0, 11.0, points)
    times: dict[str, list[float]] = {name: [] for name in loops}
    for i, f in enumerate(freqs):
        names = list(loops)
        for name in names[i % len(names):] + names[:i % len(names)]:  # none always first
            t0 = time.process_time()
            periodic_steady_state(loops[name], 0.01, float(f))
            times[name].append(time.process_time() - t0)
    med = {name: statistics.median(v) for name, v in times.items()}
    base = med["Jenkins (k = 20, fc = 0.05)"]
    return {name: {"seconds": s, "ratio": s / base,
                   "stops": links[name].periodic_stops() is not None}
            for name, s in med.items()}


def identification(sizes: tuple[int, ...]) -> dict:
    runs = []
    with tempfile.TemporaryDirectory() as d:
        for n in sizes:
            path = Path(d) / f"record-{n}.csv"
            _record(n, path)
            t0 = time.perf_counter()
            proc = subprocess.Popen(_command("identify", str(path), "--json"),
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            out, err = proc.communicate()
            seconds = time.perf_counter() - t0
            usage = resource.getrusage(resource.RUSAGE_CHILDREN)  # the largest child so far
            if proc.returncode != 0:
                raise RuntimeError(f"motionhyst identify failed: {err.strip()}")
            ident = json.loads(out)
            runs.append({"samples": n, "seconds": seconds, "peak_mb": usage.ru_maxrss / 1024,
                         "k": [e["k"] for e in ident["elements"]],
                         "fc": [e["fc"] for e in ident["elements"]]})
    return {"runs": runs, "time_ratio": runs[-1]["seconds"] / runs[0]["seconds"],
            "length_ratio": runs[-1]["samples"] / runs[0]["samples"]}


#: The Table I scenario with a LuGre link instead of the Jenkins element (a rate-dependent link:
#: its figures need periodic steady states for their describing functions).
LUGRE_LINK = ("[hysteresis]\nmodel = \"lugre\"\nsigma0 = 20.0\nsigma1 = 0.1\nsigma2 = 0.01\n"
              "fc = 0.05\nfs = 0.06\nvs = 0.01\n")


def _lugre_scenario(folder: str) -> str:
    """The Table I scenario file with :data:`LUGRE_LINK` as its link, written into `folder`."""
    from motionhyst.scenario import default_scenario_path

    text = default_scenario_path().read_text()
    start = text.index("[hysteresis]")
    end = text.index("\n[", start) + 1  # the next section
    path = Path(folder) / "lugre.toml"
    path.write_text(text[:start] + LUGRE_LINK + "\n" + text[end:])
    return str(path)


def report(repeats: int) -> dict:
    with tempfile.TemporaryDirectory() as d:
        lugre = _lugre_scenario(d)
        t = _interleaved({"analyze": _command("analyze"),
                          "reproduce": _command("reproduce", "--out", "out", "--quiet"),
                          "analyze_lugre": _command("analyze", lugre),
                          "reproduce_lugre": _command("reproduce", lugre, "--out", "out-lugre",
                                                      "--quiet")},
                         repeats, cwd=d)
    return {**t, "ratio": t["reproduce"] / t["analyze"],
            "cpu_ratio": t["reproduce_cpu"] / t["analyze_cpu"],
            "ratio_lugre": t["reproduce_lugre"] / t["analyze_lugre"],
            "cpu_ratio_lugre": t["reproduce_lugre_cpu"] / t["analyze_lugre_cpu"]}


def _verdict(value: float, target: float) -> str:
    return "met" if value <= target else "NOT met"


def print_results(res: dict) -> None:
    m = res["machine"]
    print(f"motionhyst speed benchmark ({m['platform']}, {m['cores']} cores, "
          f"Python {m['python']}); every ratio from one run")
    if "startup" in res:
        s = res["startup"]
        print()
        print("Start-up (median of fresh processes, interleaved): wall time, ratio; CPU ratio")
        print(f"  python -c 'import numpy'                {s['numpy'] * 1e3:8.0f} ms   1.00x")
        print(f"  motionhyst --help                       {s['help'] * 1e3:8.0f} ms "
              f"{s['help_ratio']:6.2f}x; CPU {s['help_cpu_ratio']:.2f}x  (target <= "
              f"{TARGETS['help']:g}x: {_verdict(s['help_ratio'], TARGETS['help'])})")
        print(f"  motionhyst df --k 20 --fc 0.05 --amplitude 0.01 {s['df'] * 1e3:5.0f} ms "
              f"{s['df_ratio']:6.2f}x; CPU {s['df_cpu_ratio']:.2f}x  (target <= "
              f"{TARGETS['df']:g}x: {_verdict(s['df_ratio'], TARGETS['df'])})")
    if "steady" in res:
        print()
        print("One steady-state point of the Table I loop (median CPU time, interleaved), "
              "against Jenkins")
        for name, v in res["steady"].items():
            bound = TARGETS["steady" if v["stops"] else "steady_ode"]
            target = "" if name.startswith("Jenkins") else (
                f"  (target <= {bound:g}x: {_verdict(v['ratio'], bound)})")
            print(f"  {name:<30} {v['seconds'] * 1e3:8.2f} ms {v['ratio']:6.2f}x{target}")
    if "identify" in res:
        i = res["identify"]
        print()
        print("motionhyst identify on a force-displacement record (CSV)")
        for r in i["runs"]:
            print(f"  {r['samples']:>9,} samples  {r['seconds']:7.2f} s  "
                  f"peak {r['peak_mb']:6.0f} MB  k = {', '.join(f'{v:.4g}' for v in r['k'])}")
        peak = max(r["peak_mb"] for r in i["runs"])
        print(f"  time ratio {i['time_ratio']:.2f}x for {i['length_ratio']:.0f}x the samples "
              f"(target <= {TARGETS['identify_time']:g}x: "
              f"{_verdict(i['time_ratio'], TARGETS['identify_time'])}); peak {peak:.0f} MB "
              f"(target < {TARGETS['identify_mb']:g} MB: {_verdict(peak, TARGETS['identify_mb'])})")
    if "report" in res:
        r = res["report"]
        print()
        print("Figures (median of fresh processes, interleaved): wall time, ratio; CPU time, ratio")
        print(f"  motionhyst analyze                      {r['analyze']:8.2f} s    1.00x; "
              f"CPU {r['analyze_cpu']:.2f} s")
        print(f"  motionhyst reproduce (figures in PNG and PDF) {r['reproduce']:6.2f} s "
              f"{r['ratio']:6.2f}x; CPU {r['reproduce_cpu']:.2f} s, {r['cpu_ratio']:.2f}x  "
              f"(target <= {TARGETS['reproduce']:g}x: "
              f"{_verdict(r['ratio'], TARGETS['reproduce'])})")
        print("  the same scenario with a LuGre link:")
        print(f"  motionhyst analyze lugre.toml           {r['analyze_lugre']:8.2f} s    1.00x; "
              f"CPU {r['analyze_lugre_cpu']:.2f} s")
        print(f"  motionhyst reproduce lugre.toml         {r['reproduce_lugre']:8.2f} s "
              f"{r['ratio_lugre']:6.2f}x; CPU {r['reproduce_lugre_cpu']:.2f} s, "
              f"{r['cpu_ratio_lugre']:.2f}x")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of the tables")
    parser.add_argument("--quick", action="store_true",
                        help="fewer repeats and 1e4/1e5 samples (a smoke run, not for the README)")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, metavar="SECTION",
                        help=f"run only these sections ({', '.join(SECTIONS)}); default: all")
    args = parser.parse_args(argv)
    quick = args.quick
    res = {"machine": {"platform": platform.platform(terse=True), "cores": os.cpu_count(),
                       "python": platform.python_version()}}
    for key, what, run in (
            ("startup", "start-up", lambda: startup(3 if quick else STARTUP_REPEATS)),
            ("steady", "link models", lambda: steady_models(5 if quick else STEADY_POINTS)),
            ("identify", "identification",
             lambda: identification((10_000, 100_000) if quick else IDENTIFY_SIZES)),
            ("report", "reproduce vs analyze", lambda: report(1 if quick else REPORT_REPEATS))):
        if args.only and key not in args.only:
            continue
        print(f"running {what} ...", file=sys.stderr, flush=True)
        res[key] = run()
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        print_results(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
