"""``motionhyst predict``: the displacement of an open-loop system for a force record."""

from __future__ import annotations

import argparse

import numpy as np

from motionhyst.cli._common import UsageError, add_record_options, print_json

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def add_parser(sub) -> None:
    """Add the ``predict`` command to the subparsers `sub`."""
    q = sub.add_parser("predict", help="displacement of an open-loop system (mass-spring-damper "
                       "or two-mass scenario without controller) for a force record (CSV)")
    q.add_argument("scenario", metavar="MODEL.toml",
                   help='open-loop scenario: [stage] type = "mass-spring-damper", or a two-mass '
                        '[stage] with output = "y2" or "y1" (the position written), and '
                        "[hysteresis] (as written by motionhyst identify --save)")
    q.add_argument("data", metavar="INPUT.csv", help="force record: time,force [s, N], uniform "
                   "time steps (stamps within 0.05 of a step of a uniform grid); CSV with a "
                   "header or MATLAB .mat")
    add_record_options(q, "time,force", "time=t,force=vir")
    q.add_argument("--periodic", action="store_true",
                   help="the record is one period (or whole periods) of a periodic force: "
                        "output the periodic steady state (default: from rest; a floating "
                        "two-mass stage: with zero mean, an error if it drifts)")
    q.add_argument("--out", required=True, metavar="OUT.csv",
                   help="output CSV: time,displacement [s, m] on the input's time grid (a "
                        "two-mass stage: the position its [stage] output names)")
    q.add_argument("--substeps", type=int, metavar="N",
                   help="integration steps per sample (default: >= 20 and >= 400 per period "
                        "of the stage's fastest mode)")
    q.add_argument("--force", action="store_true", help="replace OUT.csv if it exists")
    q.add_argument("--json", action="store_true", help="print a JSON summary")
    q.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Simulate the scenario's open-loop system for the force record and write the output."""
    from motionhyst.io.records import read_record
    from motionhyst.scenario import Scenario

    if args.substeps is not None and not 1 <= args.substeps <= 10000:
        raise UsageError(f"motionhyst predict: --substeps must be from 1 to 10000, got "
                         f"{args.substeps}")
    from motionhyst.io.outputs import OutputFile

    target = OutputFile(args.out, force=args.force, inputs=[args.scenario, args.data],
                        option="--out")  # refused before any work
    sc = Scenario.from_file(args.scenario)
    system = sc.open_loop()
    data = read_record(args.data, ("time", "force"), columns=args.columns, scale=args.scale)
    t, u = data[:, 0], data[:, 1]
    try:
        out = system.simulate(t, u, periodic=args.periodic, substeps=args.substeps)
    except ValueError as exc:
        raise ValueError(f"{args.data}: {exc}") from None
    target.write_csv({"time": out.t, "displacement": out.displacement}, fmt="%.17g")
    summary = {"out": str(args.out), "samples": int(t.size), "periodic": bool(args.periodic),
               "displacement_rms": float(np.sqrt(np.mean(out.displacement ** 2))),
               "displacement_peak": float(np.max(np.abs(out.displacement)))}
    if args.json:
        print_json(summary)
    else:
        what = "periodic steady state" if args.periodic else "from rest"
        print(f"Predicted {t.size} samples of {sc.source} ({what}) for {args.data} -> {args.out}")
        print(f"  displacement RMS {summary['displacement_rms']:.4g} m, peak "
              f"{summary['displacement_peak']:.4g} m")
    return 0
