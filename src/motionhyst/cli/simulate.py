"""``motionhyst simulate``: a transient run of the nonlinear loop from rest (``--time-series``).

Without ``--time-series`` it is the old spelling of ``motionhyst steady``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from motionhyst.cli._common import UsageError, positive, print_json


def run(args: argparse.Namespace) -> int:
    """A transient run from rest (``--time-series``); without it, the old spelling of ``steady``."""
    from motionhyst.cli import steady
    from motionhyst.scenario import load_scenario

    if not args.time_series:
        print("motionhyst simulate: without --time-series this computes the periodic steady "
              "state; the command for that is now `motionhyst steady`", file=sys.stderr)
        return steady.run(args)
    sc = load_scenario(args.scenario)
    freqs = args.frequency or sc.frequencies
    amplitude = args.amplitude or sc.amplitude
    return _time_series(args, sc, amplitude, freqs[0])


def _time_series(args: argparse.Namespace, sc, amplitude: float, frequency: float) -> int:
    """Transient run from rest, written to CSV atomically."""
    from motionhyst.references import PointToPoint, SineReference, load_reference_csv
    from motionhyst.simulate import simulate

    if args.reference_csv and args.profile:
        raise UsageError("motionhyst simulate: give --reference-csv or --profile, not both")
    if args.reference_csv:
        ref = load_reference_csv(args.reference_csv)
        duration = args.duration or ref.duration
        what = f"reference from {args.reference_csv}"
    elif args.profile:
        ref = PointToPoint(args.distance, args.v_max, args.a_max, args.j_max)
        duration = args.duration or ref.duration + 0.2
        what = f"point-to-point move of {args.distance:g} m"
    else:
        ref = SineReference(amplitude, frequency)
        duration = args.duration or 1.0
        what = f"r = {amplitude:g} m sin(2 pi {frequency:g} t)"
    sim = simulate(sc.loop(), ref, duration)
    cols = sim.columns()
    out = Path(args.time_series)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", dir=out.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(",".join(cols) + "\n")
            np.savetxt(fh, np.column_stack(list(cols.values())), delimiter=",", fmt="%.12e")
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    summary = {"time_series": str(out), "samples": len(sim.t), "duration_s": float(sim.t[-1]),
               "dt_s": float(sim.t[1] - sim.t[0]), "error_peak": float(np.max(np.abs(sim.e))),
               "error_linear_peak": float(np.max(np.abs(sim.e_linear)))}
    if args.json:
        print_json(summary)
    else:
        print(f"Simulated {summary['duration_s']:.4g} s of {sc.source}, {what}: "
              f"{summary['samples']} samples (dt = {summary['dt_s']:.3g} s) -> {out}")
        print(f"  peak |e| = {summary['error_peak']:.4g} m "
              f"(without hysteresis {summary['error_linear_peak']:.4g} m)")
    return 0


def add_parser(sub) -> None:
    """Add the ``simulate`` command to the subparsers `sub`."""
    q = sub.add_parser("simulate", help="transient run of the nonlinear loop from rest, "
                       "written to CSV (--time-series)")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--frequency", type=positive, nargs="+", help="frequencies [Hz]")
    q.add_argument("--amplitude", type=positive, help="reference amplitude [m]")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.add_argument("--time-series", metavar="OUT.csv",
                   help="write a transient run from rest to CSV (sine of the first frequency, "
                        "or --reference-csv / --profile)")
    q.add_argument("--reference-csv", metavar="FILE", help="reference CSV: time,position [s, m]")
    q.add_argument("--profile", choices=["point-to-point"], help="built-in reference profile")
    q.add_argument("--distance", type=float, default=0.01, help="move length [m] (0.01)")
    q.add_argument("--v-max", type=positive, default=0.5, help="velocity limit [m/s] (0.5)")
    q.add_argument("--a-max", type=positive, default=10.0, help="acceleration limit [m/s^2] (10)")
    q.add_argument("--j-max", type=positive, default=1000.0, help="jerk limit [m/s^3] (1000)")
    q.add_argument("--duration", type=positive, help="simulated time [s]")
    q.set_defaults(func=run)
