"""``motionhyst benchmark bouc-wen | emps``: a public benchmark in one command.

``bouc-wen``: Noel and Schoukens' hysteretic benchmark (simulated).  ``emps``:
Janot, Gautier and Brunot's measured positioning axis with friction.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from pathlib import Path

from motionhyst.cli._common import UsageError, g, print_json, release_held, table, whole_number

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def add_parser(sub) -> None:
    """Add the ``benchmark`` command to the subparsers `sub`."""
    q = sub.add_parser("benchmark", help="run a public benchmark end to end (bouc-wen: "
                       "Noel & Schoukens' hysteretic benchmark; emps: Janot, Gautier & "
                       "Brunot's measured positioning axis)")
    q.add_argument("name", choices=["bouc-wen", "emps"], help="the benchmark")
    q.add_argument("--data", metavar="DIR",
                   help="bouc-wen: folder with the official test sets uval_/yval_multisine.mat "
                        "and uval_/yval_sinesweep.mat; emps: folder with DATA_EMPS.mat and, "
                        "if downloaded, the test record DATA_EMPS_PULSES.mat (required: both "
                        "are downloaded from nonlinearbenchmark.org)")
    q.add_argument("--seed", type=whole_number(0, 2**32 - 1, "seed"), default=None,
                   help="bouc-wen: seed of the training multisines and noise (default 0)")
    q.add_argument("--periods", metavar="A-B", type=_periods,
                   help="emps without the test record: the periods of DATA_EMPS to identify "
                        "from, validated on the others (default: both ways, 1-2 then 3-4; "
                        "'all': also 1-3 and 2-4, each validated on the period left out; the "
                        "reference repeats every 6240 samples)")
    q.add_argument("--models", metavar="NAMES",
                   help="emps: the link models on the mass-damper, comma-separated (default: "
                        "coulomb-asymmetric,coulomb-asymmetric-drift,jenkins-asymmetric; "
                        "a link of coulomb, dahl, jenkins, lugre, "
                        "maxwell-slip, ending in -asymmetric for viscous friction by direction "
                        "or -symmetric for one coefficient (neither: by direction where the "
                        "record shows it, as identify fits it) and -drift for a force offset "
                        "drifting in time)")
    q.add_argument("--workers", type=whole_number(1, 4096, "--workers"),
                   help="emps: processes fitting at once, each a chain of models (a Jenkins "
                        "link after the Coulomb link it starts from) on a split (default: "
                        "every core this process may use; 1: this process). The figures are "
                        "the same with any number; --max-seconds holds each chain to it")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)


def _periods(text: str) -> tuple[int, int] | str:
    if text == "all":
        return text
    first, sep, last = text.partition("-")
    try:
        a, b = int(first), int(last if sep else first)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be A-B (whole periods, e.g. 1-2) or all, "
                                         f"got {text!r}") from None
    if not 1 <= a <= b:
        raise argparse.ArgumentTypeError(f"must be A-B with 1 <= A <= B, got {text!r}")
    return a, b


DATA_FILES = {"bouc-wen": "uval_multisine.mat, yval_multisine.mat, uval_sinesweep.mat and "
                          "yval_sinesweep.mat",
              "emps": "DATA_EMPS.mat (and the test record DATA_EMPS_PULSES.mat, if you have it)"}
"""The files ``--data`` names the folder of, per benchmark (downloaded from
nonlinearbenchmark.org; never looked for anywhere else)."""


def run(args: argparse.Namespace) -> int:
    """Run the benchmark named and print its table (or JSON)."""
    if args.name == "emps":
        return run_emps(args)
    for option in ("periods", "models", "workers"):
        if getattr(args, option) is not None:
            raise UsageError(f"motionhyst benchmark: --{option} applies to emps only")
    return run_bouc_wen(args)


def _data(args: argparse.Namespace) -> Path:
    """The folder ``--data`` names (required: the product looks for no data anywhere else)."""
    if args.data is None:
        raise UsageError(f"motionhyst benchmark {args.name}: give --data DIR, the folder with "
                         f"{DATA_FILES[args.name]}, downloaded from nonlinearbenchmark.org")
    data = Path(args.data)
    if not data.is_dir():
        state = "not a folder" if data.exists() else "no such folder"
        raise UsageError(f"motionhyst benchmark {args.name}: --data {data}: {state} (give the "
                         f"folder with {DATA_FILES[args.name]})")
    return data


BOUC_WEN_REMEDY = "give a larger --max-seconds"
"""What a user can change when ``benchmark bouc-wen`` runs over its work budget (its training
data, models and test sets are the benchmark's)."""


@contextmanager
def _progress(name: str, steps: int, quiet: bool, remedy: str) -> Iterator[Callable[[str], None]]:
    """``say(msg)`` for each of the `steps` of ``benchmark name``, in a block stopped at
    ``--max-seconds`` of CPU time.  The progress is shown on a terminal only, as one status
    line cleared as the block ends (`quiet`: never): a run stopped by its budget is the one
    line of its refusal, and the table has each step's figures and time."""
    from tqdm import tqdm

    from motionhyst.core.budget import cpu_time_limit, max_seconds

    with (tqdm(total=steps, desc=f"benchmark {name}", bar_format="{desc}{postfix} [{elapsed}]",
               disable=quiet or not sys.stderr.isatty(), file=sys.stderr, leave=False) as bar,
          cpu_time_limit(max_seconds(), f"benchmark {name}", remedy)):
        def say(msg: str) -> None:
            bar.update()
            bar.set_postfix_str(msg)

        yield say


def run_bouc_wen(args: argparse.Namespace) -> int:
    """Make training data, identify, score on the official test sets, print the table."""
    from motionhyst.identify.benchmark import run_benchmark

    if args.seed is None:
        args.seed = 0
    data = _data(args)

    release_held()  # the work starts: the warnings so far are shown
    # the training data, then each model identified and scored: 1 + 2 x 2 steps
    with _progress("bouc-wen", 5, args.json, BOUC_WEN_REMEDY) as say:
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


def _emps_record(path: Path, name: str):
    from motionhyst.identify.emps_files import COLUMNS, DRIVE_GAIN
    from motionhyst.identify.io_records import IORecord, check_records
    from motionhyst.io.records import read_record

    data = read_record(path, ("time", "force", "displacement"), columns=COLUMNS,
                       scale={"force": DRIVE_GAIN})
    # its values checked as it is read: not in the first fit, minutes later for a test record
    check_records([IORecord(data[:, 0], data[:, 1], data[:, 2], str(path))], periodic=False)
    return IORecord(data[:, 0], data[:, 1], data[:, 2], name)


EMPS_SECONDS_PER_SAMPLE = 1e-3
"""The least CPU time of one model's fit and scores per sample of the record it is identified
from [s] (measured: 18-54 s for the Coulomb and Jenkins links on 12480 samples of DATA_EMPS):
``benchmark emps`` estimates its run from it and refuses one above ``--max-seconds`` before
it starts."""
EMPS_REMEDY = "give fewer --models, one split (--periods 1-2), or a larger --max-seconds"
"""What a user can change when ``benchmark emps`` is above its work budget."""


def _emps_seconds(estimation, test, periods, models) -> float:
    """The least CPU time the fits of ``benchmark emps`` take [s]: each model once a split
    (both halves of DATA_EMPS by default, four splits with ``--periods all``, the whole
    record with the test record), :data:`EMPS_SECONDS_PER_SAMPLE` a sample identified from."""
    from motionhyst.identify.emps import MODELS, PERIOD

    n = estimation.t.size
    if test is not None or periods is None:  # the whole record, or each half once
        samples = n
    elif periods == "all":  # the halves, then all periods but the last and all but the first
        samples = n + 2 * max(n - PERIOD, 0)
    else:
        samples = min((periods[1] - periods[0] + 1) * PERIOD, n)
    return len(MODELS if models is None else models) * samples * EMPS_SECONDS_PER_SAMPLE


def run_emps(args: argparse.Namespace) -> int:
    """Identify the EMPS axis on DATA_EMPS.mat and score each model; print the table or JSON."""
    from motionhyst.identify.emps_files import ESTIMATION_FILE, TEST_FILE
    from motionhyst.identify.emps_models import check_model

    if args.seed is not None:
        raise UsageError("motionhyst benchmark emps: --seed applies to bouc-wen only (the EMPS "
                         "records are measured)")
    models = None
    if args.models is not None:
        models = [name.strip() for name in args.models.split(",")]
        if not all(models) or len(set(models)) < len(models):
            raise UsageError(f"motionhyst benchmark emps: --models {args.models!r}: give "
                             f"distinct names separated by commas")
        for name in models:
            try:
                check_model(name)
            except ValueError as exc:
                raise UsageError(f"motionhyst benchmark emps: --models: {exc}") from None
    data = _data(args)
    est_path, test_path = data / ESTIMATION_FILE, data / TEST_FILE
    for path in (est_path, test_path):  # there, but not a file: never passed over in silence
        if (path.exists() or path.is_symlink()) and not path.is_file():
            raise UsageError(f"motionhyst benchmark emps: {path}: not a regular file (a "
                             f"folder, a pipe, a device or a broken link)")
    if not est_path.is_file():
        raise UsageError(f"motionhyst benchmark emps: {data} has no {ESTIMATION_FILE} (the "
                         f"benchmark's estimation record)")
    estimation = _emps_record(est_path, ESTIMATION_FILE.removesuffix(".mat"))
    test = (_emps_record(test_path, TEST_FILE.removesuffix(".mat"))
            if test_path.is_file() else None)
    if test is not None and args.periods is not None:
        raise UsageError(f"motionhyst benchmark emps: --periods splits DATA_EMPS when there is "
                         f"no test record; {test_path} is there")
    # the optimisers imported once the folder, its records and the options are known good
    from motionhyst.core.budget import check_work, cpu_time_limit, max_seconds
    from motionhyst.identify.emps import CHOSEN, MODELS, choose, cross_validate, run_emps
    from motionhyst.identify.emps_workers import usable_cores

    check_work(_emps_seconds(estimation, test, args.periods, models), "benchmark emps",
               EMPS_REMEDY)
    release_held()  # the fits start: the warnings so far are shown
    splits = 1 if test is not None or args.periods not in (None, "all") else (
        2 if args.periods is None else 4)
    fits = splits * len(MODELS if models is None else models)
    # the workers' CPU time is theirs: each chain of fits is held to the budget in its own
    workers = {"workers": args.workers or usable_cores(), "guard": partial(
        cpu_time_limit, max_seconds(), "benchmark emps", EMPS_REMEDY)}
    with _progress("emps", 2 * fits, args.json, EMPS_REMEDY) as say:  # each fit's start, end
        if test is None and args.periods in (None, "all"):  # one split alone says little
            results = cross_validate(estimation, models=models, progress=say,
                                     splits="halves" if args.periods is None else "all",
                                     **workers)
        else:
            results = [run_emps(estimation, test, models=models,
                                periods=args.periods or (1, 2), progress=say, **workers)]
    chosen = None
    if len(results) > 1:
        picked = choose(results)  # None: every model failed on some split
        if picked is not None:
            chosen = {"name": picked[0], "worse_split_rmse_mm": picked[1]}
    elif test is not None:  # chosen on the splits before the test; its score on the test here
        scored = [m for m in results[0].models if m.name == CHOSEN and m.error is None]
        if scored:
            chosen = {"name": CHOSEN, "rule": "chosen before the test, by the smallest "
                      "validation RMSE on the worse of the two splits of DATA_EMPS",
                      "validation_rmse_mm": scored[0].validation["rmse_mm"]}
    if args.json:
        print_json({"models": [m for res in results for m in res.to_dict()["models"]],
                    **({} if chosen is None else {"chosen": chosen})})
    else:
        print("\n\n".join(str(res) for res in results))
        if len(results) > 1:
            _print_splits(results, chosen)
    failed = [f"{m.name} on {res.estimation_record.name}" for res in results
              for m in res.failed]
    if failed:  # the table or JSON above has every row; the exit code says some failed
        from motionhyst.identify.io_checks import FitFailed

        count = sum(len(res.models) for res in results)
        rows = "its row says" if len(failed) == 1 else "their rows say"
        others = "; the others are above" if len(failed) < count else ""
        raise FitFailed(f"benchmark emps: {len(failed)} of {count} fits failed "
                        f"({', '.join(failed)}): {rows} why{others}")
    return 0


def _print_splits(results, chosen: dict | None) -> None:
    """The mean validation RMSE of each model over the splits, and the rule's choice."""
    two = len(results) == 2
    splits = "both splits" if two else f"the {len(results)} splits"
    worst = "worse" if two else "worst"

    def mean(runs) -> str:
        failed = sum(m.error is not None for m in runs)
        if failed:
            return f"{runs[0].name} - (failed on {failed} of {len(runs)} splits)"
        return f"{runs[0].name} {sum(m.validation['rmse_mm'] for m in runs) / len(runs):.3g} mm"

    print(f"\nMean validation RMSE over {splits}: " + ", ".join(
        mean(runs) for runs in zip(*(res.models for res in results), strict=True)))
    if chosen is None:
        print("No model chosen: every model failed on at least one split")
        return
    print(f"Chosen by the {worst} of {'the two splits' if two else splits} (the rule stated "
          f"in advance): {chosen['name']}, {chosen['worse_split_rmse_mm']:.3g} mm on its "
          f"{worst} split")
