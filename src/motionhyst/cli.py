"""Command-line interface: ``motionhyst df | analyze | simulate | identify | reproduce``.

A thin layer: it parses arguments, calls the library and prints tables or
JSON.  Every user error ends in one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import typing
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from motionhyst.jsonio import dumps

EXIT_USAGE = 2


class UsageError(Exception):
    """A user error: reported as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage block)."""

    def error(self, message: str):
        raise UsageError(f"{self.prog}: {message}")


def _number(text: str, what: str, positive: bool | None) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be a number, got {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{what} must be finite, got {text!r}")
    if positive and v <= 0:
        raise argparse.ArgumentTypeError(f"{what} must be > 0, got {text!r}")
    if positive is False and v < 0:
        raise argparse.ArgumentTypeError(f"{what} must be >= 0, got {text!r}")
    return v


def positive(text: str) -> float:
    """argparse type: a finite number > 0."""
    return _number(text, "value", True)


def _finite(text: str) -> float:
    """argparse type: a finite number."""
    return _number(text, "value", None)


def nonnegative(text: str) -> float:
    """argparse type: a finite number >= 0."""
    return _number(text, "value", False)


def _harmonic_count(text: str) -> int:
    """argparse type: a whole number of harmonics from 1 to 1000."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if not 1 <= n <= 1000:
        raise argparse.ArgumentTypeError(f"must be from 1 to 1000, got {text!r}")
    return n


def _print_json(obj) -> None:
    print(dumps(obj))


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(headers)]
    line = "  ".join(h.rjust(w) for h, w in zip(headers, widths, strict=True))
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in rows]
    return "\n".join(out)


def _g(x: float, digits: int = 4) -> str:
    return "nan" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}g}"


# ---------------------------------------------------------------------------- df
_UNITS = {"k": "N/m", "fc": "N", "sigma0": "N/m", "sigma1": "N s/m", "sigma2": "N s/m",
          "fs": "N", "vs": "m/s"}


def _df_parameters(model: str) -> dict[str, tuple[bool, bool]]:
    """``{option: (takes a list, required)}`` of a model, from its scenario section."""
    from motionhyst.scenario import LINK_SECTIONS

    fields = LINK_SECTIONS[model].model_fields
    return {name: (typing.get_origin(f.annotation) is list, f.is_required())
            for name, f in fields.items() if name != "model"}


def _element_from_args(args: argparse.Namespace):
    """The hysteresis element named by ``--model`` and its parameter options."""
    from motionhyst.scenario import LINK_SECTIONS, ScenarioError, hysteresis_from_dict

    model = args.model
    spec = _df_parameters(model)
    options = dict.fromkeys(n for m in LINK_SECTIONS for n in _df_parameters(m))
    for name in options:
        if getattr(args, name) is not None and name not in spec:
            raise UsageError(f"motionhyst df: --{name} does not apply to --model {model} "
                             f"(its parameters: {', '.join('--' + n for n in spec)})")
    params: dict = {"model": model}
    for name, (many, required) in spec.items():
        values = getattr(args, name)
        if values is None:
            if required:
                raise UsageError(f"motionhyst df: --{name} is required for --model {model}")
            continue
        if many:
            params[name] = list(values)
        elif len(values) != 1:
            hint = " (use --model maxwell-slip for several)" if name in ("k", "fc") else ""
            raise UsageError(f"motionhyst df: --{name} takes one value for --model {model}"
                             f"{hint}")
        else:
            params[name] = values[0]
    try:
        return hysteresis_from_dict(params, source="motionhyst df")
    except ScenarioError as exc:
        msg = str(exc).replace("[hysteresis]: ", "").replace("[hysteresis] ", "--")
        raise UsageError(msg) from None


def _df_frequencies(args: argparse.Namespace, el) -> list[float | None]:
    """The frequencies [Hz] of ``df``: required for rate-dependent elements, else none."""
    if el.rate_independent:
        if args.frequency is not None:
            raise UsageError(f"motionhyst df: --frequency does not apply to --model "
                             f"{args.model}: the element is rate-independent, its describing "
                             f"function depends on the amplitude only")
        return [None]
    if args.frequency is None:
        raise UsageError(f"motionhyst df: --frequency is required for --model {args.model} "
                         f"(rate-dependent: D depends on amplitude and frequency)")
    return list(args.frequency)


def _df_point(amplitude: float, zeta: float, D: complex, frequency_hz: float | None) -> dict:
    point = {"amplitude": float(amplitude)}
    if frequency_hz is not None:
        point["frequency_hz"] = float(frequency_hz)
    point.update({"zeta": float(zeta), "re": float(D.real), "im": float(D.imag),
                  "abs": float(abs(D)), "phase_deg": float(np.degrees(np.angle(D)))})
    return point


def cmd_df(args: argparse.Namespace) -> int:
    """Describing function (and higher harmonics) of a hysteresis element."""
    el = _element_from_args(args)
    freqs = _df_frequencies(args, el)
    A = np.asarray(args.amplitude, dtype=float)
    zeta = np.atleast_1d(el.zeta(A)) if hasattr(el, "zeta") else np.full(A.shape, np.nan)
    points = []
    for f in freqs:
        omega = None if f is None else 2.0 * math.pi * f
        D = np.atleast_1d(el.describing_function(A, omega))
        pts = [_df_point(a, z, d, f) for a, z, d in zip(A, zeta, D, strict=True)]
        if args.harmonics:
            H = el.hosidf(A, args.harmonics, omega)
            for p, h in zip(pts, H, strict=True):
                p["harmonics"] = [{"n": n, "re": float(c.real), "im": float(c.imag),
                                   "abs_over_amplitude": float(abs(c)),
                                   "phase_deg": float(np.degrees(np.angle(c)))}
                                  for n, c in enumerate(h, start=1)]
        points += pts
    result = {**el.to_dict(), "points": points}
    if args.json:
        _print_json(result)
        return 0
    k0 = el.initial_stiffness

    def show(v):
        return ", ".join(f"{x:g}" for x in v) if isinstance(v, list) else f"{v:g}"

    params = ", ".join(f"{k} = {show(v)} {_UNITS.get(k, '')}".rstrip()
                       for k, v in el.to_dict().items() if k != "model")
    print(f"Describing function of the {el.name} element, {params} (SI units; paper eq. 7)")
    rate = el.rate_independent
    head = ["A [m]"] if rate else ["A [m]", "f [Hz]"]

    def lead(p):
        return [_g(p["amplitude"])] + ([] if rate else [_g(p["frequency_hz"])])

    has_zeta = any(not math.isnan(p["zeta"]) for p in points)
    rows = [[*lead(p), *([_g(p["zeta"])] if has_zeta else []), _g(p["re"]), _g(p["im"]),
             _g(p["abs"]), _g(p["abs"] / k0), f"{p['phase_deg']:.2f}"] for p in points]
    print(_table([*head, *(["zeta [-]"] if has_zeta else []), "Re D [N/m]", "Im D [N/m]",
                  "|D| [N/m]", "|D|/k0 [-]", "angle D [deg]"], rows))
    print(f"k0 = {k0:g} N/m, the initial stiffness"
          + (" (|D| -> k0 as A -> 0)" if rate else ""))
    if args.harmonics:
        print()
        print("Higher-order describing functions H_n = Y_n / A [N/m], relative to sin(n w t)")
        rows = [[*lead(p), str(h["n"]), _g(h["abs_over_amplitude"]),
                 f"{h['phase_deg']:.2f}"] for p in points for h in p["harmonics"]]
        print(_table([*head, "n", "|H_n| [N/m]", "angle H_n [deg]"], rows))
    return 0


# ----------------------------------------------------------------------- analyze
def cmd_analyze(args: argparse.Namespace) -> int:
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
        _print_json(d)
        return 0
    print(f"Quasi-linear analysis of {sc.source}")
    print(f"  reference amplitude A_r        {amplitude:g} m")
    if d["zeta"] is not None and not math.isnan(d["zeta"]):
        print(f"  zeta = fc/(k A)  (eq. 4)       {_g(d['zeta'])}")
    at = "" if d["df_frequency_hz"] is None else f" at {_g(d['df_frequency_hz'])} Hz"
    eq = "eq. 10" if d["zeta"] is not None and not math.isnan(d["zeta"]) else "eq. 7"
    label = f"|D|/k, angle D  ({eq})"
    print(f"  {label:<31}{_g(d['df_abs_over_k'])}, "
          f"{d['df_phase_deg']:.2f} deg{at}")
    print(f"  f*  (eq. 13)                   {_g(d['f_star_hz'])} Hz")
    print(f"  bandwidth (|C P2| = 1)         {_g(d['bandwidth_hz'])} Hz")
    print(f"  mismatch crossover (eq. 21)    {_g(d['mismatch_crossover_hz'])} Hz")
    print(f"  exact crossover |E - 1| = 1    {_g(d['mismatch_crossover_exact_hz'])} Hz")
    print()
    rows = [[_g(p["frequency_hz"]), _g(p["abs"]), f"{20 * math.log10(p['abs']):.2f}",
             f"{p['phase_deg']:.2f}", _g(p["asymptote_abs"]), _g(p["y1_amplitude"])]
            for p in d["mismatch"]]
    print(_table(["f [Hz]", "|E| [-]", "|E| [dB]", "angle E [deg]", "|E~| (eq. 20)",
                  "A_y1 [m]"], rows))
    return 0


# ---------------------------------------------------------------------- simulate
def cmd_simulate(args: argparse.Namespace) -> int:
    """Exact periodic steady state of the nonlinear loop, next to the describing function."""
    from motionhyst.scenario import load_scenario
    from motionhyst.steady import compare_with_describing_function

    sc = load_scenario(args.scenario)
    freqs = args.frequency or sc.frequencies
    amplitude = args.amplitude or sc.amplitude
    if args.time_series:
        return _time_series(args, sc, amplitude, freqs[0])
    points = compare_with_describing_function(sc.loop(), amplitude, freqs)
    if args.json:
        _print_json({"points": points})
        return 0
    print(f"Exact periodic steady state of {sc.source}, r = {amplitude:g} m sin(2 pi f t)")
    rows = []
    for p in points:
        h = {x["n"]: x for x in p["error_harmonics"]}
        hd = {x["n"]: x for x in p["error_harmonics_df"]}
        rows.append([_g(p["frequency_hz"]), _g(h[1]["abs"]), f"{h[1]['phase_deg']:.1f}",
                     _g(h[3]["abs"]) if 3 in h else "-", _g(hd[3]["abs"]) if 3 in hd else "-",
                     _g(h[5]["abs"]) if 5 in h else "-", _g(hd[5]["abs"]) if 5 in hd else "-",
                     _g(p["error_linear_abs"]), _g(p["mismatch_simulated_abs"]),
                     f"{p['mismatch_simulated_phase_deg']:.2f}", _g(p["mismatch_df_abs"]),
                     f"{p['mismatch_df_phase_deg']:.2f}", _g(p["error_peak"]),
                     _g(p["error_hysteresis_rms"])])
    print(_table(["f [Hz]", "|e1| [m]", "angle e1 [deg]", "|e3| [m]", "|e3| HOSIDF",
                  "|e5| [m]", "|e5| HOSIDF",
                  "|e1 lin| [m]", "|E sim|", "angle E sim", "|E df| (18)", "angle E df",
                  "peak e [m]", "rms e-e_lin [m]"], rows))
    return 0


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
        _print_json(summary)
    else:
        print(f"Simulated {summary['duration_s']:.4g} s of {sc.source}, {what}: "
              f"{summary['samples']} samples (dt = {summary['dt_s']:.3g} s) -> {out}")
        print(f"  peak |e| = {summary['error_peak']:.4g} m "
              f"(without hysteresis {summary['error_linear_peak']:.4g} m)")
    return 0


# ---------------------------------------------------------------------- identify
RECORD_KINDS = {"force-displacement": ("time", "displacement", "force"),
                "closed-loop": ("time", "y1", "u")}
"""CSV columns that identify a record's kind (``motionhyst identify``)."""


def _element_count(text: str) -> int:
    """argparse type: a whole number of Jenkins elements from 1 to 20."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if not 1 <= n <= 20:
        raise argparse.ArgumentTypeError(f"must be from 1 to 20, got {text!r}")
    return n


def record_kind(path: str | Path, kind: str | None = None) -> str:
    """The kind of a measured record from its CSV header.

    Parameters
    ----------
    path : str or Path
        CSV file with a header row.
    kind : str, optional
        The kind the user asked for (``--record``); checked against the header.

    Returns
    -------
    str
        ``"force-displacement"`` (columns ``time,displacement,force``) or
        ``"closed-loop"`` (columns ``time,y1,u``).

    Raises
    ------
    ValueError
        One line naming the file: unreadable, empty, a header of neither kind,
        of both kinds without `kind`, or without the columns of `kind`.
    """
    from motionhyst.csvdata import read_header

    names = read_header(path)
    header = set(names)
    fits = [k for k, cols in RECORD_KINDS.items() if header.issuperset(cols)]
    if kind is not None:
        if kind not in fits:
            raise ValueError(f"{path}: a {kind} record needs the columns "
                             f"{','.join(RECORD_KINDS[kind])}; the header is {','.join(names)!r}")
        return kind
    if len(fits) == 1:
        return fits[0]
    if fits:
        raise ValueError(f"{path}: the header {','.join(names)!r} has the columns of both a "
                         f"force-displacement and a closed-loop record; choose one with --record")
    expected = " or ".join(f"{','.join(n)} ({k})" for k, n in RECORD_KINDS.items())
    raise ValueError(f"{path}: unknown record header {','.join(names)!r}; expected {expected}")


def _toml_float(v: float) -> str:
    """A float as a TOML float literal with 7 significant digits."""
    s = repr(float(f"{float(v):.7g}"))
    return s if any(c in s for c in ".en") else s + ".0"


def feedforward_fragment(k: Sequence[float], fc: Sequence[float]) -> str:
    """A ``[feedforward]`` section with the identified hysteresis, ready to paste (TOML).

    One element is written as ``model = "jenkins"`` with scalars, more as
    ``model = "maxwell-slip"`` with lists (as
    :meth:`motionhyst.identify.Identification.scenario_fragment`).
    """
    if len(k) == 1:
        table = (f'{{ model = "jenkins", k = {_toml_float(k[0])}, '
                 f"fc = {_toml_float(fc[0])} }}")
    else:
        table = (f'{{ model = "maxwell-slip", k = [{", ".join(map(_toml_float, k))}], '
                 f'fc = [{", ".join(map(_toml_float, fc))}] }}')
    return ('[feedforward]\ntype = "rigid-body"   # u_ff = M r\'\' + phi_hat(r)\n'
            f"hysteresis = {table}\n")


def _std_text(value: float, std: float) -> str:
    if not math.isfinite(std):
        return "not determined"
    return f"{std:.2g} ({100 * std / value:.2g} %)"


def cmd_identify(args: argparse.Namespace) -> int:
    """Identify Maxwell-slip hysteresis from a measured record (CSV)."""
    from motionhyst.identify import (
        identify_closed_loop,
        identify_maxwell_slip,
        load_closed_loop_csv,
        load_force_displacement_csv,
    )
    from motionhyst.scenario import load_scenario
    from motionhyst.systems import TwoMassStage

    path = Path(args.data)
    kind = record_kind(path, args.record)
    if kind == "force-displacement":
        for option, value in (("--scenario", args.scenario), ("--cutoff", args.cutoff)):
            if value is not None:
                raise UsageError(f"motionhyst identify: {option} applies to closed-loop "
                                 f"records (time,y1,u) only; {path} is a force-displacement "
                                 f"record")
    options = {"n_elements": args.elements, "criterion": args.criterion}
    extra: dict = {"record": kind, "data": str(path)}
    if kind == "force-displacement":
        t, x, w = load_force_displacement_csv(path)
        what = "force-displacement record"
        try:
            ident = identify_maxwell_slip(x, w, t=t, **options)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
    else:
        sc = load_scenario(args.scenario)
        plant = sc.plant()
        if not isinstance(plant, TwoMassStage):
            raise UsageError(f"motionhyst identify: closed-loop records need a [stage] in the "
                             f"scenario (P1 as a model); {sc.source} has a measured [plant]")
        t, y1, u = load_closed_loop_csv(path)
        extra["scenario"] = sc.source
        try:
            ident = identify_closed_loop(t, y1, u, plant, cutoff_hz=args.cutoff, **options)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        what = (f"closed-loop record, plant of {sc.source}, prefilter cut-off "
                f"{_g(ident.cutoff_hz)} Hz")
    k = [e["k"] for e in ident.elements]
    fc = [e["fc"] for e in ident.elements]
    if args.json:
        _print_json({**ident.to_dict(), **extra})
        return 0
    print(f"Maxwell-slip hysteresis identified from {path} ({what}, {ident.n_samples} samples)")
    print(f"  elements: {ident.n_elements}   ({ident.criterion})")
    print(f"  fit RMS {_g(ident.fit_rms)} N = {100 * ident.fit_nrms:.3g} % of the "
          f"{ident.signal} RMS, R^2 = {ident.r2:.6f}, offset {_g(ident.offset)} N")
    print()
    rows = [[str(i), _g(e["k"], 6), _std_text(e["k"], e["k_std"]), _g(e["fc"], 6),
             _std_text(e["fc"], e["fc_std"]), _g(e["fc"] / e["k"] * 1e3)]
            for i, e in enumerate(ident.elements, start=1)]
    print(_table(["i", "k [N/m]", "std k [N/m]", "fc [N]", "std fc [N]", "fc/k [mm]"], rows))
    print()
    print(f"  total stiffness {_g(sum(k), 6)} N/m, total slip force {_g(sum(fc), 6)} N")
    print()
    print("# hysteresis feedforward, to paste into a scenario (replaces its [feedforward];")
    print("# the same inline table is a valid [hysteresis] section to model the link):")
    print(feedforward_fragment(k, fc), end="")
    return 0


# --------------------------------------------------------------------- reproduce
def cmd_reproduce(args: argparse.Namespace) -> int:
    """The paper's figures and numbers for a scenario, as a report."""
    from motionhyst.report import reproduce
    from motionhyst.scenario import load_scenario

    sc = load_scenario(args.scenario)
    reproduce(sc, args.out, quiet=args.quiet, is_paper=args.scenario is None)
    if not args.quiet:
        print(f"wrote {args.out}/report.md, summary.json and fig5-fig11 (.png, .pdf)")
    return 0


# --------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``motionhyst`` command."""
    from motionhyst.scenario import LINK_SECTIONS

    p = _Parser(prog="motionhyst", description="Hysteresis of dynamic links in motion control "
                "loops: describing functions, quasi-linear analysis, exact steady state.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    q = sub.add_parser("df", help="describing function of a hysteresis element")
    q.add_argument("--model", choices=list(LINK_SECTIONS), default="jenkins",
                   help="hysteresis model (default: jenkins)")
    q.add_argument("--k", type=positive, nargs="+",
                   help="spring stiffness k [N/m] (one per element for maxwell-slip); "
                        "jenkins, maxwell-slip, bouc-wen, dahl")
    q.add_argument("--fc", type=positive, nargs="+",
                   help="slip (Coulomb) force f_c [N] (one per element for maxwell-slip); "
                        "all models")
    q.add_argument("--n", type=positive, nargs=1, help="bouc-wen: sharpness n >= 1 (1)")
    q.add_argument("--beta", type=_finite, nargs=1, help="bouc-wen: beta (0.5)")
    q.add_argument("--gamma", type=_finite, nargs=1, help="bouc-wen: gamma, <= beta (0.5)")
    q.add_argument("--alpha", type=positive, nargs=1, help="dahl: shape exponent alpha (1)")
    q.add_argument("--sigma0", type=positive, nargs=1, help="lugre: bristle stiffness [N/m]")
    q.add_argument("--sigma1", type=nonnegative, nargs=1,
                   help="lugre: bristle damping [N s/m] (0)")
    q.add_argument("--sigma2", type=nonnegative, nargs=1,
                   help="lugre: viscous friction [N s/m] (0)")
    q.add_argument("--fs", type=positive, nargs=1, help="lugre: static (Stribeck) force [N]")
    q.add_argument("--vs", type=positive, nargs=1, help="lugre: Stribeck velocity [m/s]")
    q.add_argument("--frequency", type=positive, nargs="+",
                   help="frequency(ies) [Hz]; required for the rate-dependent lugre")
    q.add_argument("--amplitude", type=nonnegative, nargs="+", required=True,
                   help="input amplitude(s) A [m]")
    q.add_argument("--harmonics", type=_harmonic_count, metavar="N",
                   help="also the higher-order describing functions H_1 .. H_N")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=cmd_df)

    q = sub.add_parser("analyze", help="quasi-linear analysis of a scenario (eqs. 12-21)")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--frequency", type=positive, nargs="+", help="frequencies [Hz]")
    q.add_argument("--amplitude", type=positive, help="reference amplitude [m]")
    q.add_argument("--self-consistent", action="store_true",
                   help="solve the amplitude of y1 in the quasi-linear loop instead of A_y1 = A_r")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=cmd_analyze)

    q = sub.add_parser("simulate", help="exact periodic steady state of the nonlinear loop")
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
    q.set_defaults(func=cmd_simulate)

    q = sub.add_parser("identify", help="identify Maxwell-slip hysteresis from a measured "
                       "record (CSV)")
    q.add_argument("data", metavar="DATA.csv",
                   help="record with a header: time,displacement,force (force-displacement) or "
                        "time,y1,u (closed-loop) [SI units]")
    q.add_argument("--elements", type=_element_count, metavar="N",
                   help="number of Jenkins elements (default: chosen by --criterion)")
    q.add_argument("--cutoff", type=positive, metavar="HZ",
                   help="closed-loop records: cut-off of the prefilter through which the link "
                        "force is inferred [Hz] (default: 20 times the record's fundamental, "
                        "at most a twentieth of the sampling rate)")
    q.add_argument("--record", choices=list(RECORD_KINDS),
                   help="the record's kind, where its header has the columns of both "
                        "(default: from the header)")
    q.add_argument("--criterion", choices=["rms", "bic"], default="rms",
                   help="model-order criterion when --elements is not given (default: rms)")
    q.add_argument("--scenario", metavar="FILE",
                   help="scenario TOML whose [stage] gives P1 for closed-loop records "
                        "(default: the paper's Table I)")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=cmd_identify)

    q = sub.add_parser("reproduce", help="the paper's figures and numbers, as a report")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--out", default="out", help="output folder (default: ./out)")
    q.add_argument("--quiet", action="store_true", help="no progress bar or summary line")
    q.set_defaults(func=cmd_reproduce)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``motionhyst`` command; returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        return args.func(args)
    except BrokenPipeError:  # output piped into head, say: not an error
        sys.stdout = open(os.devnull, "w")
        return 0
    except UsageError as exc:
        print(f"error: {exc}", file=sys.stderr)
    except (ValueError, OSError, RuntimeError) as exc:
        print(f"motionhyst: error: {exc}", file=sys.stderr)
    except KeyboardInterrupt:
        print("motionhyst: interrupted", file=sys.stderr)
        return 130
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
