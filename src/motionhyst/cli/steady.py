"""``motionhyst steady``: the exact periodic steady state of the nonlinear loop,
next to the describing function's prediction (paper section V, eq. 18).
"""

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
    """Exact periodic steady state of the nonlinear loop, next to the describing function."""
    from motionhyst.scenario import load_scenario

    args.frequency = distinct(args.frequency, "--frequency", args.command)
    sc = load_scenario(args.scenario, check=False)  # the loop is built once the input is checked
    refuse_along_stroke_for(sc, args.command)
    freqs = scenario_frequencies(sc, args.frequency, args.command)
    loop = sc.loop()  # its own refusals (a plant's file, stability) before the analysis loads
    amplitude = args.amplitude or sc.amplitude
    # imported once the input is read: a refusal does not wait for the analysis to load
    from motionhyst.analysis.comparison import compare_with_describing_function
    from motionhyst.analysis.floquet import check_floquet_budget
    from motionhyst.analysis.plausibility import check_frequency_range
    from motionhyst.analysis.steady import check_steady_frequencies

    floquet = not getattr(args, "no_floquet", False)  # simulate's old spelling has no option
    if floquet:  # refused with what this command can change (the library says its argument)
        given = "--frequency" if args.frequency else f"{sc.source}'s [reference] frequencies"
        option = "--no-floquet" if args.command == "steady" else "motionhyst steady --no-floquet"
        check_floquet_budget(loop, freqs, remedy=f"give fewer frequencies ({given}) or leave "
                                                 f"the multipliers out ({option})")
    check_frequency_range(loop, freqs)  # what the analysis refuses as it starts: before
    check_steady_frequencies(loop, freqs)  # the warnings held are shown
    # the steady states refuse a loop that hunts (or a link too stiff for it) once computed:
    # the warnings stay held until they are, so that a refusal is its one line (they say
    # what an answer means, which a refusal has not); an interruption shows them
    result = compare_with_describing_function(loop, amplitude, freqs,  # warns as it starts
                                              floquet=floquet)
    warn_plant_fit(sc)
    release_held()  # the answer: the warnings so far are shown before it
    if args.json:
        print_json(result.to_dict())
        return 0
    print(f"Exact periodic steady state of {sc.source}, r = {amplitude:g} m sin(2 pi f t)")
    print(result)
    return 0


def add_parser(sub) -> None:
    """Add the ``steady`` command to the subparsers `sub`."""
    q = sub.add_parser("steady", help="exact periodic steady state of the nonlinear loop, "
                       "next to the describing function")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--frequency", type=positive, nargs="+", help="frequencies [Hz]")
    q.add_argument("--amplitude", type=positive, help="reference amplitude [m]")
    q.add_argument("--no-floquet", action="store_true",
                   help="leave out the Floquet multipliers (their work grows as the cube of a "
                        "Maxwell-slip link's elements)")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)
