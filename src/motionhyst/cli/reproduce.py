"""``motionhyst reproduce``: the paper's figures and numbers for a scenario, as a report."""

from __future__ import annotations

import argparse

from motionhyst.cli._common import (
    add_force_option,
    refuse_along_stroke_for,
    release_held,
    warn_plant_fit,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def run(args: argparse.Namespace) -> int:
    """The paper's figures and numbers for a scenario, as a report."""
    from motionhyst.core.budget import cpu_time_limit, max_seconds
    from motionhyst.io.outputs import MANIFEST
    from motionhyst.present.report import reproduce
    from motionhyst.scenario import load_scenario

    # the loop is built (and checked) inside reproduce, while the first figures are drawn; the
    # warnings held until then are shown once its steady states have answered (checked): a
    # loop that hunts is refused in one line
    sc = load_scenario(args.scenario, check=False)
    refuse_along_stroke_for(sc, "reproduce")
    # no formula sizes the report's figures: its CPU time is bounded as a search's is, and a
    # report stopped writes none of its files
    with cpu_time_limit(max_seconds(), "reproduce", "raise --max-seconds (Table I's report "
                        "takes about a minute of CPU time)"):
        reproduce(sc, args.out, quiet=args.quiet, is_paper=args.scenario is None,
                  force=args.force, inputs=sc.files, checked=release_held)
    warn_plant_fit(sc)
    if not args.quiet:
        print(f"wrote {args.out}/report.md, summary.json and fig5-fig11 (.png, .pdf), listed in "
              f"{MANIFEST}")
    return 0


def add_parser(sub) -> None:
    """Add the ``reproduce`` command to the subparsers `sub`."""
    q = sub.add_parser("reproduce", help="the paper's figures and numbers, as a report")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--out", default="out",
                   help="output folder (default: ./out); other files in it are left alone, the "
                        "report's files are listed in its motionhyst-manifest.json")
    q.add_argument("--quiet", action="store_true", help="no progress bar or summary line")
    add_force_option(q)
    q.set_defaults(func=run)
