"""Benchmark: the CPU of an input-output search on a positioning axis, as ratios in one run.

The search (:func:`motionhyst.identify.input_output.identify_io`, ``plant="mass-damper"``)
of two generated axes, each record's offset and initial velocity estimated:

- ``coulomb``: 95 kg, 200 N s/m, a Coulomb link of 20 N, a 3 N force offset, two sines and a
  random force, 1e-7 m of position noise (tests/test_identify_segments.py's axis);
- ``jenkins``: the same axis with a stiff Jenkins link (k 1e8 N/m, fc 20 N), three sines and a
  random force, starting at 0.02 m/s (tests/test_identify_segments.py's stiff axis).

Each is fitted three ways in turn, interleaved, ``REPEATS`` times, the least CPU time of this
process kept (its BLAS threads' included):

1. ``refinements``: the baseline, the refinement on the whole records alone (no search on the
   records' segments, no finer secants: the search before issue 21's segments);
2. ``search``: the search as shipped (also refined from the segments' end; a rigid slider's
   with finer secants), its trust-region steps on one BLAS thread where the Jacobian is small
   (:func:`motionhyst.core.blas.few_blas_threads`);
3. ``all threads``: the same search with the machine's BLAS threads in every step.

Reported: ``search / refinements`` (what the segments cost; target <= 4x), ``search / all
threads`` (what one BLAS thread saves; target <= 1: never more CPU), the fit RMS of each in
units of the noise, and the largest relative difference of the estimates between ``search``
and ``all threads`` (rounding only).  On a loaded machine the BLAS threads wait for cores and
spin: the ratio falls with the load.

Run with ``make bench`` or ``python benchmarks/axis_search.py [--json] [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from contextlib import contextmanager

import numpy as np

from motionhyst.core import blas
from motionhyst.hysteresis import Coulomb, Jenkins
from motionhyst.identify import io_elements
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import simulate_elements

REPEATS = 3
FS = 1000.0
NOISE = 1e-7
TARGETS = {"segments": 4.0, "blas": 1.0}


def coulomb_axis(n: int = 6000, seed: int = 1) -> IORecord:
    """The Coulomb axis, `n` samples."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    u = (60.0 * np.sin(2 * np.pi * 1.3 * t) + 25.0 * np.sin(2 * np.pi * 7.1 * t + 1.0)
         + rng.standard_normal(n))
    y, _ = simulate_elements(MassDamper(95.0, 200.0).mechanics(),
                             Coulomb(fc=20.0).time_stepping(), u - 3.0, FS, 20, periodic=False)
    return IORecord(t, u, y + NOISE * rng.standard_normal(n), "coulomb")


def jenkins_axis(n: int = 4000, seed: int = 0) -> IORecord:
    """The stiff Jenkins axis, `n` samples."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    ph = rng.uniform(0, 2 * np.pi, 3)
    u = (30 + 90 * np.sin(2 * np.pi * 0.6 * t + ph[0]) + 40 * np.sin(2 * np.pi * 1.7 * t + ph[1])
         + 15 * np.sin(2 * np.pi * 4.1 * t + ph[2]) + 5 * rng.standard_normal(n))
    y, _ = simulate_elements(MassDamper(95.0, 200.0).mechanics(),
                             Jenkins(k=1e8, fc=20.0).time_stepping(), u + 3.0, FS, 20,
                             periodic=False, x0=np.array([0.0, 0.02]))
    return IORecord(t, u, y + 2e-3 + NOISE * rng.standard_normal(n), "jenkins")


@contextmanager
def variant(name: str):
    """The search as `name` runs it (the package's names patched for the block only)."""
    refine, small = io_elements.refine, blas.SMALL_FLOPS
    if name == "refinements":
        def alone(prob, q0, tol, max_nfev, reserve, from_window, rigid=False, segments=False):
            return refine(prob, q0, tol, max_nfev, reserve, from_window)
        io_elements.refine = alone
    elif name == "all threads":
        blas.SMALL_FLOPS = -1.0  # no matrix is small
    try:
        yield
    finally:
        io_elements.refine, blas.SMALL_FLOPS = refine, small


def fit(rec: IORecord, link: str):
    """The search of one axis, as ``identify --record input-output --plant mass-damper``."""
    return identify_io([rec], link, plant="mass-damper", substeps=20)


def measure(repeats: int = REPEATS, quick: bool = False) -> dict:
    """Least CPU times [s] of each case and variant, their ratios, fit RMS / noise and the
    estimates' largest relative difference with all BLAS threads."""
    cases = {"coulomb": (coulomb_axis(3000 if quick else 6000), "coulomb"),
             "jenkins": (jenkins_axis(2000 if quick else 4000), "jenkins")}
    names = ("refinements", "search", "all threads")
    out = {}
    for case, (rec, link) in cases.items():
        fit(rec, link)  # warm-up: compiled kernels
        cpu: dict[str, float] = {}
        fits = {}
        for _ in range(repeats):
            for name in names:
                with variant(name):
                    t0 = time.process_time()
                    fits[name] = fit(rec, link)
                    cpu[name] = min(cpu.get(name, np.inf), time.process_time() - t0)
        a, b = fits["search"].estimates, fits["all threads"].estimates
        out[case] = {
            "samples": rec.y.size, "cpu_s": cpu,
            "segments_ratio": cpu["search"] / cpu["refinements"],
            "blas_ratio": cpu["search"] / cpu["all threads"],
            "fit_rms_per_noise": {k: f.fit_rms / NOISE for k, f in fits.items()},
            "estimates_rel_diff": max(abs(a[k] - b[k]) / max(abs(b[k]), 1e-300) for k in b),
            "targets": {"segments_ratio": TARGETS["segments"], "blas_ratio": TARGETS["blas"]}}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--quick", action="store_true",
                        help="half the samples, one repeat")
    parser.add_argument("--repeats", type=int, default=REPEATS)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    repeats = 1 if args.quick else args.repeats
    res = measure(repeats, args.quick)
    if args.json:
        print(json.dumps(res, indent=2))
        return
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"input-output search on an axis; least CPU time of {repeats} interleaved "
          f"runs; {platform.python_version()}, numpy {np.__version__}, load {load:.1f}")
    for case, r in res.items():
        c = r["cpu_s"]
        print(f"  {case:<8} {r['samples']} samples: refinements {c['refinements']:6.2f} s, "
              f"search {c['search']:6.2f} s, all threads {c['all threads']:6.2f} s")
        for key, label in (("segments_ratio", "search / refinements"),
                           ("blas_ratio", "search / all threads")):
            ok = "met" if r[key] <= r["targets"][key] else "MISSED"
            print(f"    {label:<21} {r[key]:5.2f}x  target <= {r['targets'][key]:g}x: {ok}")
        rms = ", ".join(f"{k} {v:.3g}" for k, v in r["fit_rms_per_noise"].items())
        print(f"    fit RMS / noise: {rms}; estimates with all threads within "
              f"{r['estimates_rel_diff']:.1e}")


if __name__ == "__main__":
    main()
