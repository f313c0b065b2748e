"""``motionhyst analyze``: the quasi-linear analysis of a scenario (paper eqs. 12-21)."""

from __future__ import annotations

import argparse
import math

from motionhyst.cli._common import g, positive, print_json, table


def run(args: argparse.Namespace) -> int:
    """Quasi-linear analysis of a scenario (paper eqs. 12-21)."""
    from motionhyst.quasilinear import analyze
    from motionhyst.scenario import load_scenario

    sc = load_scenario(args.scenario)
    freqs = args.frequency or sc.frequencies
    amplitude = args.amplitude or sc.amplitude
    mode = "self-consistent" if args.self_consistent else "reference"
    res = analyze(sc.loop(), amplitude, freqs, amplitude_mode=mode)
    d = res.to_dict()
    if args.json:
        print_json(d)
        return 0
    print(f"Quasi-linear analysis of {sc.source}")
    print(f"  reference amplitude A_r        {amplitude:g} m")
    if d["zeta"] is not None and not math.isnan(d["zeta"]):
        print(f"  zeta = fc/(k A)  (eq. 4)       {g(d['zeta'])}")
    at = "" if d["df_frequency_hz"] is None else f" at {g(d['df_frequency_hz'])} Hz"
    eq = "eq. 10" if d["zeta"] is not None and not math.isnan(d["zeta"]) else "eq. 7"
    label = f"|D|/k, angle D  ({eq})"
    print(f"  {label:<31}{g(d['df_abs_over_k'])}, "
          f"{d['df_phase_deg']:.2f} deg{at}")
    print(f"  f*  (eq. 13)                   {g(d['f_star_hz'])} Hz")
    print(f"  bandwidth (|C P2| = 1)         {g(d['bandwidth_hz'])} Hz")
    print(f"  mismatch crossover (eq. 21)    {g(d['mismatch_crossover_hz'])} Hz")
    print(f"  exact crossover |E - 1| = 1    {g(d['mismatch_crossover_exact_hz'])} Hz")
    print()
    rows = [[g(p["frequency_hz"]), g(p["abs"]), f"{20 * math.log10(p['abs']):.2f}",
             f"{p['phase_deg']:.2f}", g(p["asymptote_abs"]), g(p["y1_amplitude"])]
            for p in d["mismatch"]]
    print(table(["f [Hz]", "|E| [-]", "|E| [dB]", "angle E [deg]", "|E~| (eq. 20)",
                  "A_y1 [m]"], rows))
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
