"""Benchmark: how soon a refusal comes (issue 26: every refusal within 2 s of start).

Each case is a command line that motionhyst refuses (exit 2, one line on stderr), one
for each way a refusal comes: an argument, a scenario's value, an option against the
scenario, an output, a file, a record, the size of a run, an open-loop scenario where a
loop is needed, an unstable controller (lead-lag, sampled at 10 kHz, PID), a frequency
the loop cannot mean (decades above its fastest pole) and a run whose step
the loop's poles set (from the scenario's coefficients, before python-control builds
the loop), a controller rate or an exposure window that cannot resolve a scan, a list of a
million values, a constant force, an input-output record without inertia (its
inverse-dynamics estimate), a stage's record given with a link's, a force that is a curve
of the displacement without loops, a force whose loops are a damper's, a benchmark without
its data folder or with a text file for its record, an identification file larger than
any, a study's store named by a symbolic link, a force-displacement record whose force
accelerates a mass, and a record no Maxwell-slip elements describe (a Jenkins element, a
spring and a damper: loops, but not a stop operator's; a short record and one of 60000
samples), refused by a bound on what any of them can leave before the fit that took 1.8 s
and 26 s of CPU to refuse them, a closed-loop record with y1 in mm or its columns swapped
(refused from the plant's scales before the loop is built; was after the fit, 3.1 s of
CPU), a link too damped for the step of scan and simulate (from the scenario before the
loop is built; was during the run, 1.45 s), a link model that input-output records cannot
fit (by its name, before the records are read) and a force of white noise (its small
regressions on one BLAS thread).  Each runs as a whole
process (the interpreter, the imports, the checks) in a folder holding its files,
``REPEATS`` times interleaved with the baseline of the same run: ``motionhyst --help``,
the command's start alone.  Reported per case: the least wall time (the least disturbed
run), the processor time of that run (the wall time of a quiet machine), and their ratio
to the baseline's; target 2 s of wall time.

Run with ``make bench`` or ``python benchmarks/refusals.py [--json] [--repeats N]``.
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from motionhyst.hysteresis import Jenkins
from motionhyst.scenario import default_scenario_path

REPEATS = 3
TARGET_S = 2.0
CODE = "import sys; from motionhyst.cli import main; sys.exit(main(sys.argv[1:]))"
PAPER = default_scenario_path().read_text()
SCAN = ["--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
        "--s-max", "1e6"]


def _rows(header: str, *columns) -> str:
    return header + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                    for row in np.column_stack(columns))


def _long_jenkins_damper(n: int = 60_000) -> str:
    """A Jenkins element, a spring and a damper under a sine whose amplitude breathes."""
    t = np.arange(n) / 750
    x = 1e-3 * np.sin(2 * np.pi * 2 * t) * (0.8 + 0.2 * np.cos(2 * np.pi * 0.05 * t))
    return _rows("time,displacement,force", t, x, Jenkins(k=40.0, fc=0.01).response(x)
                 + 10.0 * x + 1.6 * np.gradient(x, t))


def _stage_and_link(n: int = 3000) -> tuple[str, str]:
    """A 2 kg axis's input-output record (viscous friction, a Jenkins link) and a link's
    force-displacement record, which together describe no one stage."""
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    t = np.arange(n) / 750
    u = 5.0 * np.sin(2 * np.pi * 1.3 * t) + 3.0 * np.sin(2 * np.pi * 4.1 * t + 0.4)
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2000.0, fc=1.0)).simulate(t, u).displacement
    x = 1e-3 * np.sin(2 * np.pi * 2 * t) * (0.8 + 0.2 * np.cos(2 * np.pi * 0.05 * t))
    return (_rows("time,force,displacement", t, u, y),
            _rows("time,displacement,force", t, x, Jenkins(k=40.0, fc=0.01).response(x)
                  + 10.0 * x + 1.6 * np.gradient(x, t)))


def _closed_loop() -> dict[str, str]:
    """The paper's loop with a two-element link, 3 s of a 2 Hz sine at 5 kHz: closed-loop
    records with y1 in mm and with u and y1 swapped."""
    from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate

    sc = default_scenario()
    loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    sim = simulate(loop, SineReference(0.01, 2.0), 3.0, dt=2e-4)
    return {"cl-mm.csv": _rows("time,y1,u", sim.t, 1000 * sim.y1, sim.u),
            "cl-swapped.csv": _rows("time,y1,u", sim.t, sim.u, sim.y1)}


def _files() -> dict[str, str]:
    t = np.arange(600) / 750
    u = 50.0 * np.sin(2 * np.pi * 7.0 * t) + 20.0 * np.sin(2 * np.pi * 31.0 * t)
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    head, tail = PAPER[:PAPER.index("[stage]")], PAPER[PAPER.index("[hysteresis]"):]
    x2 = x + 4e-4 * np.sin(2 * np.pi * 31.0 * t)  # a fixture of 2 g on the link: m x''
    nan = x.copy()
    nan[7] = np.nan
    return {
        "s.toml": PAPER,
        "nan.toml": PAPER.replace("m1 = 5.0", "m1 = nan"),
        "unstable.toml": PAPER.replace("flp = 700.0", "flp = 1e12"),
        "unstable-10k.toml": PAPER.replace("beta = 0.6 ", "beta = 0.6\nsample_rate_hz = 1e4\n"
                                           "delay_samples = 8.0 "),  # 8 samples late
        "unstable-pid.toml": PAPER[:PAPER.index("[controller]")] + (
            '[controller]\ntype = "pid"\nkp = 6e6\nki = 1e10\nkd = 2e4\n'
            "derivative_filter_hz = 1500.0\n\n") + PAPER[PAPER.index("[feedforward]"):],
        "open.toml": ('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
                      '[hysteresis]\nmodel = "jenkins"\nk = 100.0\nfc = 1.0\n'),
        "plant-dir.toml": head + '[plant]\nfile = "pl"\n' + tail,
        "fd-nan.csv": _rows("time,displacement,force", t, nan, 20.0 * x),
        "fd-zero.csv": _rows("time,displacement,force", t, x, 0.0 * x),
        "fd-elastic.csv": _rows("time,displacement,force", t, x,
                                np.clip(20.0 * x, -0.01, 0.01)),  # a curve: no loops
        "fd-damper.csv": _rows("time,displacement,force", t, x,
                               20.0 * x + np.gradient(x, t)),  # a damper's loops
        "fd-jenkins-damper.csv": _rows("time,displacement,force", t, x,  # no stop operator fits
                                       Jenkins(k=40.0, fc=0.01).response(x) + 10.0 * x
                                       + 1.6 * np.gradient(x, t)),
        "fd-jenkins-damper-long.csv": _long_jenkins_damper(),
        "fd-mass.csv": _rows("time,displacement,force", t, x2, Jenkins(k=40.0, fc=0.01).response(x2)
                             + 10.0 * x2 + 0.002 * np.gradient(np.gradient(x2, t), t)),
        "study.toml": ('scenario = "s.toml"\noutputs = ["mismatch"]\n\n[axes]\n'
                       'amplitude = [0.01]\nfrequency_hz = [5.0]\n'),
        "big-identification.toml": "#\n" * 2_500_000,  # 5 MB: larger than any
        "emps-text/DATA_EMPS.mat": "t,vir,qm\n0,0,0\n",
        "slip.toml": PAPER.replace('model = "jenkins"', 'model = "maxwell-slip"').replace(
            "k = 20.0 ", "k = [" + "1.0," * 1_000_000 + "] ").replace(
            "fc = 0.05 ", "fc = [" + "0.01," * 1_000_000 + "] "),  # a million elements
        "io.csv": _rows("time,force,displacement", t, u, u / 5e4),  # a spring: no inertia
        **dict(zip(("io-stage.csv", "fd-link.csv"), _stage_and_link(), strict=True)),
        "io-missing.csv": _rows("time,force", t, u),
        "f.mat": "time,force\n0,1\n",
        "damped.toml": PAPER.replace('model = "jenkins"', 'model = "lugre"').replace(
            "k = 20.0 ", "sigma0 = 20.0\nsigma1 = 1e7\nfs = 0.07\nvs = 0.1 "),
        "fd-noise.csv": _rows("time,displacement,force", t, 10 * x,
                              np.random.default_rng(5).standard_normal(t.size)),
        **_closed_loop(),
    }


# (name, argv, what the refusal waits for)
CASES = [
    ("argument", ["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"], "checks"),
    ("scenario value", ["analyze", "nan.toml"], "checks"),
    ("scan option", ["scan", "s.toml", *SCAN, "--ilc-gain", "2"], "checks"),
    ("scan output", ["scan", "s.toml", *SCAN, "--time-series", "s.toml"], "checks"),
    ("scan size", ["scan", "s.toml", *SCAN[:1], "1e6", *SCAN[2:]], "checks"),
    ("simulate size", ["simulate", "s.toml", "--time-series", "o.csv", "--frequency", "5",
                       "--duration", "1e9"], "checks"),
    ("plant file", ["analyze", "plant-dir.toml"], "checks"),
    ("record cell", ["identify", "fd-nan.csv"], "checks"),
    ("record column", ["identify", "io-missing.csv", "--record", "input-output"], "checks"),
    ("text .mat", ["predict", "open.toml", "f.mat", "--out", "p.csv"], "checks"),
    ("frequency far above", ["steady", "s.toml", "--frequency", "1e9"], "checks"),
    ("open loop", ["stability", "open.toml"], "checks"),
    ("unstable loop", ["steady", "unstable.toml"], "checks"),
    ("unstable sampled loop", ["steady", "unstable-10k.toml"], "checks"),
    ("unstable PID loop", ["steady", "unstable-pid.toml"], "checks"),
    ("scan steps of the loop", ["scan", "s.toml", *SCAN, "--tail", "1e4"], "checks"),
    ("scan rate", ["scan", "s.toml", *SCAN, "--rate", "1e-3"], "checks"),
    ("scan window", ["scan", "s.toml", *SCAN, "--window", "1e-9"], "checks"),
    ("records of two systems", ["identify", "io-stage.csv", "fd-link.csv", "--record",
                                "input-output"], "checks"),
    ("a million elements", ["steady", "slip.toml"], "checks"),
    ("constant force", ["identify", "fd-zero.csv"], "checks"),
    ("no inertia", ["identify", "io.csv", "--record", "input-output"], "checks"),
    ("a curve without loops", ["identify", "fd-elastic.csv"], "checks"),
    ("a damper's loops", ["identify", "fd-damper.csv"], "checks"),
    ("benchmark without data", ["benchmark", "emps"], "checks"),
    ("benchmark text .mat", ["benchmark", "emps", "--data", "emps-text"], "checks"),
    ("identification size", ["study", "study.toml", "--from-identification",
                             "big-identification.toml", "--out", "o.zarr"], "checks"),
    ("store named by a link", ["study", "study.toml", "--out", "link.zarr"], "checks"),
    ("no stop operator fits", ["identify", "fd-jenkins-damper.csv"], "checks"),
    ("no stop operator, long", ["identify", "fd-jenkins-damper-long.csv"], "checks"),
    ("a mass on the link", ["identify", "fd-mass.csv"], "checks"),
    ("closed loop, y1 in mm", ["identify", "cl-mm.csv", "--scenario", "s.toml"], "checks"),
    ("closed loop, swapped", ["identify", "cl-swapped.csv", "--scenario", "s.toml"],
     "checks"),
    ("scan, link too damped", ["scan", "damped.toml", *SCAN, "--compensation", "none"],
     "checks"),
    ("simulate, too damped", ["simulate", "damped.toml", "--time-series", "o.csv",
                              "--frequency", "5", "--duration", "0.2"], "checks"),
    ("io, maxwell-iwan", ["identify", "io-stage.csv", "--record", "input-output", "--model",
                          "maxwell-iwan"], "checks"),
    ("force of white noise", ["identify", "fd-noise.csv"], "fit"),
]


def _run(argv: list[str], cwd: Path) -> tuple[float, float, int, str]:
    """Wall and processor time of one process, its exit code and stderr."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", CODE, *argv], cwd=cwd, capture_output=True,
                          text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, proc.returncode, proc.stderr


def measure(repeats: int = REPEATS) -> dict:
    """Each case's least wall time and its processor time, with the baseline's."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "pl").mkdir()
        (folder / "emps-text").mkdir()
        (folder / "link.zarr").symlink_to("pl")
        for name, text in _files().items():
            (folder / name).write_text(text)
        _run(["identify", "fd-jenkins-damper.csv"], folder)  # compiled kernels cached first
        best: dict[str, tuple[float, float, int, str]] = {}
        for _ in range(repeats):
            for name, argv in [("baseline", ["--help"])] + [(c[0], c[1]) for c in CASES]:
                got = _run(argv, folder)
                if name not in best or got[0] < best[name][0]:
                    best[name] = got
    base_wall, base_cpu = best["baseline"][:2]
    rows = []
    for name, argv, waits in CASES:
        wall, cpu, rc, err = best[name]
        rows.append({"case": name, "waits_for": waits, "command": " ".join(argv),
                     "exit": rc, "stderr_lines": len(err.strip().splitlines()),
                     "wall_s": wall, "cpu_s": cpu, "wall_ratio": wall / base_wall,
                     "cpu_ratio": cpu / base_cpu, "message": err.strip()[-100:]})
    slowest = max(rows, key=lambda r: r["wall_s"])
    return {"baseline": {"command": "motionhyst --help", "wall_s": base_wall,
                         "cpu_s": base_cpu},
            "cases": rows, "target_s": TARGET_S, "slowest": slowest["case"],
            "slowest_wall_s": slowest["wall_s"],
            "all_refused": all(r["exit"] == 2 and r["stderr_lines"] == 1 for r in rows),
            "within_target": all(r["wall_s"] <= TARGET_S for r in rows),
            "repeats": repeats, "python": platform.python_version(),
            "machine": platform.machine()}


def main() -> None:
    """Print the table (or JSON)."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", action="store_true")
    p.add_argument("--repeats", type=int, default=REPEATS)
    args = p.parse_args()
    res = measure(args.repeats)
    if args.json:
        print(json.dumps(res, indent=2))
        return
    b = res["baseline"]
    print(f"Refusals as whole processes, least wall time of {res['repeats']} runs; baseline "
          f"`motionhyst --help` {b['wall_s']:.2f} s wall, {b['cpu_s']:.2f} s CPU")
    print(f"{'case':24s} {'waits for':9s} {'exit':>4s} {'wall [s]':>8s} {'CPU [s]':>7s} "
          f"{'x base':>6s}")
    for r in res["cases"]:
        flag = "" if r["exit"] == 2 and r["stderr_lines"] == 1 else "  NOT A ONE-LINE REFUSAL"
        print(f"{r['case']:24s} {r['waits_for']:9s} {r['exit']:4d} {r['wall_s']:8.2f} "
              f"{r['cpu_s']:7.2f} {r['wall_ratio']:6.1f}{flag}")
    verdict = "all within" if res["within_target"] else "NOT all within"
    print(f"slowest: {res['slowest']} {res['slowest_wall_s']:.2f} s; {verdict} the "
          f"{res['target_s']:g} s target")


if __name__ == "__main__":
    main()
