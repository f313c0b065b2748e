"""``motionhyst benchmark bouc-wen``: the Bouc-Wen hysteretic benchmark in one command."""

from __future__ import annotations

import argparse
import sys

from motionhyst.cli._common import UsageError, g, print_json, table

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def add_parser(sub) -> None:
    """Add the ``benchmark`` command to the subparsers `sub`."""
    q = sub.add_parser("benchmark", help="run a public benchmark end to end (bouc-wen: "
                       "Noel & Schoukens' hysteretic benchmark)")
    q.add_argument("name", choices=["bouc-wen"], help="the benchmark")
    q.add_argument("--data", metavar="DIR",
                   help="folder with the official test sets uval_/yval_multisine.mat and "
                        "uval_/yval_sinesweep.mat (default: ../shared/benchmarks/bouc-wen "
                        "when it exists)")
    q.add_argument("--seed", type=int, default=0,
                   help="seed of the training multisines and noise (default 0)")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Make training data, identify, score on the official test sets, print the table."""
    from motionhyst.identify.benchmark import default_data_dir, run_benchmark

    data = args.data if args.data is not None else default_data_dir()
    if data is None:
        raise UsageError("motionhyst benchmark: no test sets: give --data DIR (the folder "
                         "with uval_multisine.mat, ...; ../shared/benchmarks/bouc-wen does "
                         "not exist)")

    def say(msg: str) -> None:
        if not args.json:
            print(f"  {msg}", file=sys.stderr, flush=True)

    res = run_benchmark(data, seed=args.seed, progress=say)
    res["data"] = str(data)
    if args.json:
        print_json(res)
        return 0
    tr = res["training"]
    print("Bouc-Wen hysteretic benchmark (Noel & Schoukens 2016), simulation RMSE on the "
          "official test sets")
    print(f"  training: {tr['experiments']} experiments x {tr['periods']} periods of "
          f"{tr['samples_per_period']} samples from rest, output noise {g(tr['noise_rms'])} m "
          f"RMS (seed {tr['seed']}); test sets from {data}")
    print(f"  generator vs official multisine test output: {g(res['generator_check_rms'])} m "
          f"RMS")
    print()
    rows = [[f"motionhyst grey box: {r['model']}", g(r["multisine_rmse"], 3),
             g(r["sinesweep_rmse"], 3), f"{r['identification_s']:.1f}",
             f"{r['simulation_s']:.1f}"] for r in res["models"]]
    rows += [[p["method"], p["multisine_rmse"], "-", "-", "-"] for p in res["published"]]
    print(table(["method", "multisine [m]", "sine sweep [m]", "identify [s]", "test sims [s]"],
                rows))
    return 0
