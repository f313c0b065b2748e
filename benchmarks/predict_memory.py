"""Benchmark of ``predict``'s memory and time on long records: a record ten times longer in
little more memory, in ten times the time.

Runs ``motionhyst predict`` as a user would, under ``/usr/bin/time -v``, on generated force
records (a positioning axis: 95 kg, 200 N s/m, a Jenkins link k = 1e6 N/m, fc = 20 N; a
band-limited force of twelve sines from 0.1 to 20 Hz at 1 kHz, MATLAB .mat) of a base length
and of longer ones (default 3e5, then 3e6 samples; ``--samples 3e5 3e6 1e7`` for more), 20
integration steps a sample (the model's default).  Reported for each: the largest resident
set, CPU time (user + system) and wall time, and against the base record in the same run: the
ratio of resident sets and of CPU time per sample.  A run from rest goes through the record in
blocks (``motionhyst.time.resample.fine_blocks``): its memory grows with the record's samples
only (reading, output and writing: tens of bytes a sample), not with samples x substeps
(which made 3e6 samples need 2.9 GB before).  With ``--identify N ...`` also ``motionhyst
identify --record input-output --plant mass-damper --model jenkins`` on input-output records
of that axis (its force offset -3 N, 1e-7 m of position noise) of N samples: its search holds
the record's upsampled force once (3e5 samples: peak RSS 793 MB before, 571 MB), CPU about
55 s per 3e5 samples.  Run with ``make bench`` or
``python benchmarks/predict_memory.py [--samples N ...] [--identify N ...] [--json]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MODEL = """\
[stage]
type = "mass-damper"
m = 95.0
c = 200.0
force_offset = -3.0

[hysteresis]
model = "jenkins"
k = 1e6
fc = 20.0
"""
FS = 1000.0


def record(path: Path, n: int) -> None:
    """A force record of `n` samples at 1 kHz (time, force) as a MATLAB file."""
    from scipy.io import savemat

    t = np.arange(n) / FS
    rng = np.random.default_rng(0)
    u = np.zeros(n)
    for f, phase in zip(rng.uniform(0.1, 20.0, 12), rng.uniform(0.0, 2 * np.pi, 12),
                        strict=True):
        u += 30.0 * np.sin(2 * np.pi * f * t + phase)
    savemat(path, {"time": t[:, None], "force": u[:, None]})


def measure(folder: Path, n: int) -> dict:
    """Predict a record of `n` samples under /usr/bin/time -v: peak RSS, CPU and wall."""
    data = folder / f"f{n}.mat"
    record(data, n)
    out = folder / f"p{n}.csv"
    _, usage = _timed(["predict", str(folder / "model.toml"), str(data), "--out", str(out),
                       "--json"], f"predict of {n} samples")
    lines = sum(1 for _ in out.open()) - 1
    data.unlink()
    out.unlink()
    return {"samples": n, "lines_written": lines, **usage}


def _timed(args: list[str], what: str) -> tuple[str, dict]:
    """``motionhyst ARGS`` run under /usr/bin/time -v: its standard output, and its wall and
    CPU seconds and peak resident set [MB]; `what` names it if it fails."""
    cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "motionhyst.cli", *args]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{what} failed: {proc.stderr.strip()[-500:]}")

    def field(name: str) -> float:
        return float(re.search(rf"{re.escape(name)}: ([\d.]+)", proc.stderr).group(1))

    return proc.stdout, {"wall_s": wall,
                         "cpu_s": field("User time (seconds)") + field("System time (seconds)"),
                         "max_rss_mb": field("Maximum resident set size (kbytes)") / 1024}


def measure_identify(folder: Path, n: int) -> dict:
    """Identify the axis from an input-output record of `n` samples under /usr/bin/time -v."""
    from scipy.io import savemat

    from motionhyst.hysteresis import Jenkins
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    t = np.arange(n) / FS
    rng = np.random.default_rng(0)
    u = (60.0 * np.sin(2 * np.pi * 1.3 * t) + 25.0 * np.sin(2 * np.pi * 7.1 * t + 1.0)
         + rng.standard_normal(n))
    system = OpenLoop(MassDamper(95.0, 200.0, force_offset=-3.0), Jenkins(k=1e6, fc=20.0))
    y = system.simulate(t, u).displacement + 1e-7 * rng.standard_normal(n)
    data = folder / f"io{n}.mat"
    savemat(data, {"time": t[:, None], "force": u[:, None], "displacement": y[:, None]})
    out, usage = _timed(["identify", str(data), "--record", "input-output", "--plant",
                         "mass-damper", "--model", "jenkins", "--columns",
                         "time=time,force=force,displacement=displacement", "--json"],
                        f"identify of {n} samples")
    data.unlink()
    return {"samples": n, "estimates": json.loads(out)["estimates"], **usage}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, nargs="+", default=[3e5, 3e6],
                    help="record lengths; the first is the base (default 3e5 3e6)")
    ap.add_argument("--identify", type=float, nargs="*", default=[],
                    help="also identify the axis from input-output records of these lengths")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    if not Path("/usr/bin/time").exists():
        raise SystemExit("needs /usr/bin/time (GNU time)")
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "model.toml").write_text(MODEL)
        # a first small run compiles the kernels (cached), so that no run below pays for it
        measure(folder, 2000)
        runs = [measure(folder, int(n)) for n in args.samples]
        fits = [measure_identify(folder, int(n)) for n in args.identify]
    base = runs[0]
    for r in runs:
        r["rss_ratio"] = r["max_rss_mb"] / base["max_rss_mb"]
        r["cpu_per_sample_ratio"] = (r["cpu_s"] / r["samples"]) / (base["cpu_s"] / base["samples"])
    out = {"load_before": load, "load_after": os.getloadavg(), "runs": runs,
           "identify": fits}
    if args.json:
        print(json.dumps(out, indent=2))
        return
    print(f"predict on long records (load average {load[0]:.1f} before, "
          f"{out['load_after'][0]:.1f} after)")
    for r in runs:
        print(f"  {r['samples']:>9.3g} samples: peak RSS {r['max_rss_mb']:6.0f} MB "
              f"({r['rss_ratio']:.2f}x the base), CPU {r['cpu_s']:6.1f} s "
              f"({r['cpu_per_sample_ratio']:.2f}x the base's per sample), "
              f"wall {r['wall_s']:6.1f} s")
    for r in fits:
        print(f"  identify, {r['samples']:>9.3g} samples: peak RSS {r['max_rss_mb']:6.0f} MB, "
              f"CPU {r['cpu_s']:6.1f} s, wall {r['wall_s']:6.1f} s, m = "
              f"{r['estimates']['m']:.6g} kg, fc = {r['estimates']['link.fc']:.6g} N")


if __name__ == "__main__":
    main()
