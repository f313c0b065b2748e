"""``motionhyst study``: a scenario swept over axes and Monte-Carlo samples, computed on every
local core (or a dask cluster) into a resumable zarr store; ``--summary`` reads a store.
"""

from __future__ import annotations

import argparse
import ipaddress
import json
import os
import sys

from motionhyst.cli._common import (
    UsageError,
    output_file,
    print_json,
    release_held,
    whole_number,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def _summary(args: argparse.Namespace) -> int:
    from motionhyst.study import StudyError, open_results, summarize

    for opt, given in (("--out", args.out), ("--estimate", args.estimate),
                       ("--from-identification", args.from_identification is not None),
                       ("--scheduler", args.scheduler), ("--workers", args.workers is not None)):
        if given:
            raise UsageError(f"study --summary: {opt} is for running a study")
    if args.study is not None:
        raise UsageError("study --summary STORE: give the store alone, not a study file")
    if args.force and not (args.table or args.netcdf or args.figure):
        raise UsageError("study --summary: --force has no effect without --table, --netcdf or "
                         "--figure (a summary replaces no other file)")
    try:
        ds = open_results(args.summary)
    except StudyError as exc:
        raise UsageError(f"study --summary: {exc}") from None
    _exports(ds, args)
    s = summarize(ds)
    if args.json:
        print_json(s.to_dict())
    else:
        print(f"Study {ds.attrs.get('study')} on {ds.attrs.get('scenario')} "
              f"(motionhyst {ds.attrs.get('version')}, seed {ds.attrs.get('seed')})")
        joint = json.loads(ds.attrs.get("joint", "null"))
        if joint:
            print(f"  {ds.attrs.get('n_samples')} samples of {', '.join(joint['keys'])} drawn "
                  f"jointly from {joint['source']} ("
                  f"{'lognormal' if joint['log_space'] else 'normal'}, its covariance)")
        print(s)
    return 0


def _exports(ds, args: argparse.Namespace) -> None:
    """Write --table, --netcdf and --figure: each made first, then all written one after
    the other (an interrupt while they are made leaves every old file as it was)."""
    from motionhyst.study.export import to_netcdf_bytes, to_table

    made = []
    if args.table_file is not None:
        made.append((args.table_file, to_table(ds).encode("utf-8")))
    if args.netcdf_file is not None:
        made.append((args.netcdf_file, to_netcdf_bytes(ds)))
    if args.figure_file is not None:
        import io

        from motionhyst.study.summary import plot_band

        try:
            fig = plot_band(ds)
        except ValueError as exc:
            raise UsageError(f"study --figure: {exc}") from None
        buf = io.BytesIO()
        fig.savefig(buf, format=args.figure_file.path.suffix.lstrip(".") or "png", dpi=150)
        made.append((args.figure_file, buf.getvalue()))
    for out, data in made:
        out.write_bytes(data)


def _check_options(args: argparse.Namespace) -> None:
    """Refuse what a run would ignore or could not write, before the work: an option without
    effect on an estimate; a store named "-", by a symbolic link without --force (no writer
    follows one; with it, the link itself is replaced) or where no file can be created."""
    if args.estimate and args.summary is None:
        for opt, given in (("--table", args.table), ("--netcdf", args.netcdf),
                           ("--figure", args.figure), ("--force", args.force),
                           ("--scheduler", args.scheduler)):
            if given:
                raise UsageError(f"study --estimate: {opt} has no effect (an estimate computes "
                                 f"and writes nothing)")
    if args.out is not None and args.summary is None:
        from motionhyst.io.outputs import check_output_folder

        check_output_folder(args.out, "--out", force=args.force)
    _check_files(args)
    if args.scheduler is not None and args.workers is not None and args.summary is None:
        raise UsageError("study: --workers has no effect with --scheduler (the cluster's "
                         "workers compute the points)")
    if args.scheduler is not None and not args.estimate and args.summary is None:
        _check_reachable(args.scheduler)


def _check_reachable(address: str) -> None:
    """A scheduler address nothing answers at is refused at once (dask would try for 10 s)."""
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    if parts.scheme != "tcp" or not parts.hostname:  # tls://, ucx://: dask's own connection
        return
    try:
        with socket.create_connection((parts.hostname, parts.port or 8786), timeout=2.0):
            pass
    except OSError as exc:
        raise UsageError(f"study --scheduler {address}: cannot connect "
                         f"({exc.strerror or exc})") from None


def _check_files(args: argparse.Namespace) -> None:
    """--table, --netcdf and --figure name three files, none inside the store (a file there is
    not the study's: the store is replaced as a whole, and a reader takes it for damage)."""
    store = args.out if args.summary is None else args.summary
    seen: dict[str, str] = {}
    for opt, path in (("--table", args.table), ("--netcdf", args.netcdf),
                      ("--figure", args.figure)):
        if not path:
            continue
        where = os.path.realpath(path)
        if where in seen:
            raise UsageError(f"study {opt} {path}: also the {seen[where]} file; give each "
                             f"output its own file")
        seen[where] = opt
        if store and os.path.commonpath([where, os.path.realpath(store)]) == \
                os.path.realpath(store):
            raise UsageError(f"study {opt} {path}: inside the store {store}; write it "
                             f"outside the store")


def run(args: argparse.Namespace) -> int:
    """Run a study (or resume it), or summarize a store."""
    _check_options(args)
    from motionhyst.scenario.files import read_files

    inputs = [*read_files(args.study), args.from_identification]
    args.table_file = (None if args.table is None
                       else output_file(args.table, args, "--table", inputs))
    args.netcdf_file = (None if args.netcdf is None
                        else output_file(args.netcdf, args, "--netcdf", inputs))
    args.figure_file = (None if args.figure is None
                        else output_file(args.figure, args, "--figure", inputs))
    if args.figure_file is not None and args.figure_file.path.suffix.lower() not in (
            ".png", ".pdf", ".svg"):
        raise UsageError("study --figure: give a .png, .pdf or .svg file")
    if args.summary is not None:
        return _summary(args)
    from motionhyst.study import Study, StudyError, estimate_study, open_results, run_study

    if args.study is None:
        raise UsageError("study: give a study file (or --summary STORE)")
    try:
        study = Study.from_file(args.study, from_identification=args.from_identification)
    except StudyError as exc:
        raise UsageError(f"study: {exc}") from None
    if args.estimate:
        workers = args.workers if args.workers is not None else os.cpu_count() or 1
        est = estimate_study(study, workers, args.out)
        if args.json:
            print_json(est.to_dict())
        else:
            print(f"Study {args.study}: estimate")
            print(est)
        return 0
    if args.out is None:
        raise UsageError("study: give --out STORE (a zarr store, resumed if it holds this study)")
    client = None
    if args.scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise UsageError("study --scheduler: needs dask.distributed (pip install "
                             "'motionhyst[distributed]')") from None
        try:
            client = Client(args.scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise UsageError(f"study --scheduler {args.scheduler}: cannot connect ({exc})"
                             ) from None
        except (MemoryError, ValueError, TypeError):  # a frame length read from another
            raise UsageError(f"study --scheduler {args.scheduler}: what answers there is not "
                             f"a dask scheduler") from None  # service's reply: 3 EiB
    release_held()  # the runs start: the warnings so far are shown
    try:
        report = run_study(study, args.out, workers=args.workers, client=client,
                           force=args.force, progress=not args.json and sys.stderr.isatty())
    except StudyError as exc:
        raise UsageError(f"study: {exc}") from None
    finally:
        if client is not None:
            client.close()
    ds = open_results(args.out)
    from motionhyst.study.summary import failure_reasons

    if report.points and report.failed == report.points:  # an answer from nothing: no tables
        why, first = next(iter(failure_reasons(ds).items()), ("", {"example": ""}))
        raise ValueError(f"study: every one of its {report.points} points failed ({why}; the "
                         f"first: {first['example']}); nothing exported ({args.out} records "
                         f"why)")
    _exports(ds, args)
    if args.json:
        print_json(report.to_dict())
    else:
        print(report)
        for why, f in failure_reasons(ds).items():
            print(f"  {f['points']} failed: {why}; the first: {f['example']}")
    return 0


def scheduler_address(text: str) -> str:
    """A dask scheduler's address as ``--scheduler`` takes it, refused at once when it cannot
    name one (a numeric host that is no IP address, a port outside 1-65535), rather than
    after the connection's timeout.

    Parameters
    ----------
    text : str
        ``[PROTOCOL://]HOST[:PORT]``, as dask.distributed's ``Client`` takes it.

    Returns
    -------
    str
        `text`, unchanged.

    Raises
    ------
    argparse.ArgumentTypeError
        One line saying what is wrong.

    Examples
    --------
    >>> scheduler_address("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    >>> try:
    ...     scheduler_address("tcp://256.1.1.1:99999")
    ... except argparse.ArgumentTypeError as exc:
    ...     print(exc)
    '256.1.1.1' is not an IP address
    """
    from urllib.parse import urlsplit

    parts = urlsplit(text if "://" in text else f"tcp://{text}")
    host = parts.hostname or ""
    if not host:
        raise argparse.ArgumentTypeError(f"{text!r} names no host")
    if all(c.isdigit() or c == "." for c in host):
        try:
            ipaddress.ip_address(host)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{host!r} is not an IP address") from None
    try:
        port = parts.port
    except ValueError:
        port = -1
    if port is not None and not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r}: the port must be from 1 to 65535")
    return text


def add_parser(sub) -> None:
    """Add the ``study`` command to the subparsers `sub`."""
    q = sub.add_parser(
        "study", help="a scenario over axes and Monte-Carlo samples, on every core or a "
        "dask cluster, into a resumable zarr store",
        description="Compute every point of a study file (a scenario, axes over its keys, "
        "amplitude and frequency_hz, Monte-Carlo [samples], outputs) into a zarr store; the "
        "same command after an interruption computes only the missing points.")
    q.add_argument("study", nargs="?", help="study TOML")
    q.add_argument("--out", metavar="STORE", help="zarr store (a folder) of the results")
    q.add_argument("--workers", type=whole_number(0, 4096, "--workers"),
                   help="local worker processes (default: every core; 0: this process)")
    q.add_argument("--scheduler", metavar="ADDRESS", type=scheduler_address,
                   help="run on a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786")
    q.add_argument("--from-identification", metavar="MODEL.toml",
                   help="draw the link's parameters jointly from an identification's estimates "
                        "and their covariance (the TOML of `motionhyst identify --save`, or "
                        "the JSON of `identify --json`; [samples] n and seed from the study "
                        "file, else 100 and 0)")
    q.add_argument("--estimate", action="store_true",
                   help="state points, time, core-hours, disk and memory; compute nothing")
    q.add_argument("--table", metavar="OUT.csv", help="also write the results as CSV, a row a "
                   "point")
    q.add_argument("--netcdf", metavar="OUT.nc", help="also write the results as netCDF")
    q.add_argument("--figure", metavar="OUT.png", help="also draw |E| (or the first output) "
                   "over frequency with its Monte-Carlo band, or, for a study of scans, over "
                   "its first scan axis (.png, .pdf or .svg)")
    q.add_argument("--summary", metavar="STORE", help="summarize a store: worst case per axis, "
                   "Monte-Carlo band")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.add_argument("--force", action="store_true",
                   help="replace a store holding another study, or an existing --table/--netcdf")
    q.set_defaults(func=run)
