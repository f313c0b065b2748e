"""``motionhyst analyze``: the quasi-linear analysis of a scenario (paper eqs. 12-21)."""

from __future__ import annotations

import argparse

from motionhyst.cli._common import (
    distinct,
    positive,
    print_json,
    refuse_along_stroke_for,
    release_held,
    scenario_frequencies,
    warn_plant_fit,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []


def run(args: argparse.Namespace) -> int:
    """Quasi-linear analysis of a scenario (paper eqs. 12-21)."""
    from motionhyst.scenario import load_scenario

    args.frequency = distinct(args.frequency, "--frequency", args.command)
    sc = load_scenario(args.scenario, check=False)  # the loop is built once the input is checked
    refuse_along_stroke_for(sc, args.command)
    freqs = scenario_frequencies(sc, args.frequency, args.command)
    loop = sc.loop()  # its own refusals (a plant's file, stability) before the analysis loads
    amplitude = args.amplitude or sc.amplitude
    # imported once the input is read: a refusal does not wait for the analysis to load
    from motionhyst.analysis.quasilinear import analyze

    mode = "self-consistent" if args.self_consistent else "reference"
    release_held()  # the analysis starts: the warnings so far are shown
    res = analyze(loop, amplitude, freqs, amplitude_mode=mode)
    fit = sc.plant_fit()
    warn_plant_fit(sc)
    if args.json:
        d = res.to_dict()
        if fit is not None:
            d["plant_fit"] = fit.to_dict()
        print_json(d)
        return 0
    if fit is not None:
        print(fit)
        print()
    print(f"Quasi-linear analysis of {sc.source}")
    print(res)
    return 0


def add_parser(sub) -> None:
    """Add the ``analyze`` command to the subparsers `sub`."""
    q = sub.add_parser("analyze", help="quasi-linear analysis of a scenario (eqs. 12-21)")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--frequency", type=positive, nargs="+", help="frequencies [Hz]")
    q.add_argument("--amplitude", type=positive, help="reference amplitude [m]")
    q.add_argument("--self-consistent", action="store_true",
                   help="solve the amplitude of y1 in the quasi-linear loop instead of A_y1 = A_r")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)
