"""``motionhyst stability``: will the loop hunt?  Limit cycles of the loop with its link,
predicted by the describing function and refined to exact orbits with their Floquet
multipliers (:func:`motionhyst.analysis.stability.stability`).
"""

from __future__ import annotations

import argparse

from motionhyst.cli._common import (
    UsageError,
    output_file,
    print_json,
    refuse_along_stroke_for,
    refuse_unused,
    release_held,
    warn_plant_fit,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def run(args: argparse.Namespace) -> int:
    """Limit cycles of the scenario's loop with its link."""
    from motionhyst.scenario import load_scenario
    from motionhyst.scenario.files import read_files

    figure = None
    if args.figure is None:
        refuse_unused(args, ("--force",), "without --figure (the only file stability writes)")
    else:
        figure = output_file(args.figure, args, "--figure",
                             read_files(args.scenario))
        if figure.path.suffix.lower() not in FIGURE_SUFFIXES:
            raise UsageError("stability --figure: give a .png, .pdf or .svg file")
    sc = load_scenario(args.scenario)
    refuse_along_stroke_for(sc, "stability")
    try:
        loop = sc.loop()  # an open-loop scenario is refused before the analysis loads
    except ValueError as exc:
        raise _refusal(sc, exc) from None
    from motionhyst.analysis.stability import stability

    release_held()  # the search for cycles starts: the warnings so far are shown
    try:
        result = stability(loop, exact=not args.no_exact)
    except ValueError as exc:
        raise _refusal(sc, exc) from None
    warn_plant_fit(sc)
    if figure is not None:
        import io

        buf = io.BytesIO()
        result.plot().savefig(buf, format=figure.path.suffix.lower().lstrip("."), dpi=150)
        figure.write_bytes(buf.getvalue())
    if args.json:
        print_json(result.to_dict())
        return 0
    print(f"Stability of {sc.source}, the setpoint held at 0")
    print(result)
    return 0


def _refusal(sc, exc: ValueError) -> UsageError:
    """The one line of a refusal of the scenario `sc`, named once: the scenario's own errors
    begin with its name already."""
    text = str(exc)
    where = "" if text.startswith(f"{sc.source}:") else f"{sc.source}: "
    return UsageError(f"stability: {where}{text}")


def add_parser(sub) -> None:
    """Add the ``stability`` command to the subparsers `sub`."""
    q = sub.add_parser(
        "stability", help="limit cycles of the loop with its link: describing-function "
        "prediction, exact orbits, Floquet multipliers",
        description="Will the loop hunt?  The Nyquist curve of the loop seen by the link "
        "(G = P1 / (1 + C P2)) against the link's -1/N(A, w) loci, every intersection a "
        "predicted limit cycle with the describing function's stability criterion; for a "
        "controller with integral action also the describing function with the loop cut at "
        "the integrator (it predicts hunting); each "
        "refined to the exact orbit of the nonlinear loop with its Floquet multipliers, with "
        "the cycles a simulation from kicked rest states settles on.")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--no-exact", action="store_true",
                   help="the describing functions' predictions only (the link's, and the loop "
                   "cut at the controller's integrator)")
    q.add_argument("--figure", metavar="OUT.png", help="also draw the Nyquist curve and the "
                   "loci (.png, .pdf or .svg)")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.add_argument("--force", action="store_true",
                   help="replace an existing --figure file (never one of the command's inputs)")
    q.set_defaults(func=run)
