"""``motionhyst simulate``: a transient run of the nonlinear loop from rest (``--time-series``).

Without ``--time-series`` it is the old spelling of ``motionhyst steady``.
"""

from __future__ import annotations

import argparse
import math

from motionhyst.cli._common import (
    UsageError,
    add_force_option,
    add_record_options,
    check_link_damping_for,
    distinct,
    fast_pole,
    in_the_commands_terms,
    old_spelling,
    output_file,
    positive,
    print_json,
    refuse_unused,
    release_held,
    warn_plant_fit,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []

TIME_SERIES_ONLY = ("--reference-csv", "--columns", "--scale", "--profile", "--distance",
                    "--v-max", "--a-max", "--j-max", "--duration", "--output-rate",
                    "--settle-band", "--force")
"""Options that only shape a ``--time-series`` run."""

PROFILE_DEFAULTS = {"distance": 0.01, "v_max": 0.5, "a_max": 10.0, "j_max": 1000.0}
"""Limits of the built-in point-to-point profile unless given [m, m/s, m/s^2, m/s^3]."""

OUTPUT_RATE_FACTORS = (10.0, 1000.0)
"""An ``--output-rate`` above the rate a continuous loop's step needs (its fastest pole's,
or the reference's; Table I's loop: 27.6 kHz) by the first factor is warned of, by the
second refused: its rows only make the run's step finer than the loop's dynamics need
(1e9 Hz: 5e7 rows of a 0.05 s run, 8.4 GB)."""

SLOWEST_REFERENCE_HZ = 100.0
"""A reference file sampled slower than this is warned of: a record logged in milliseconds
reads as one sampled a thousand times slower (a setpoint log of the paper's 10 kHz loop as
10 Hz), and its 2 s as 2000 s of simulation (a stage's setpoints are logged at 100 Hz to
100 kHz)."""


def run(args: argparse.Namespace) -> int:
    """A transient run from rest (``--time-series``); without it, the old spelling of ``steady``."""
    from motionhyst.cli import steady
    from motionhyst.scenario import load_scenario

    if not args.time_series:  # its notice shown with its warnings, or ending its refusal
        old_spelling("motionhyst simulate: without --time-series this computes the periodic "
                     "steady state; the command for that is now `motionhyst steady`",
                     "`motionhyst simulate` without --time-series is now `motionhyst steady`")
    args.frequency = distinct(args.frequency, "--frequency", "simulate")
    if not args.time_series:
        refuse_unused(args, TIME_SERIES_ONLY, "without --time-series (it shapes the transient "
                      "run written to CSV)")
        return steady.run(args)
    # the loop is built (python-control) once the run's options and files are checked
    return _time_series(args, load_scenario(args.scenario, check=False))


def _reference(args: argparse.Namespace, sc):
    """The reference of a ``--time-series`` run, its default duration and a description."""
    from motionhyst.time.references import PointToPoint, SineReference, load_reference_csv

    if args.reference_csv and args.profile:
        raise UsageError("motionhyst simulate: give --reference-csv or --profile, not both")
    if not args.profile:
        refuse_unused(args, ("--distance", "--v-max", "--a-max", "--j-max", "--settle-band"),
                      "without --profile point-to-point")
    if args.reference_csv or args.profile:
        given = "--reference-csv" if args.reference_csv else "--profile"
        refuse_unused(args, ("--frequency", "--amplitude"),
                      f"with {given} (the reference is the "
                      f"{'file' if args.reference_csv else 'profile'}, not a sine)")
    if not args.reference_csv:
        refuse_unused(args, ("--columns", "--scale"), "without --reference-csv (they map and "
                      "scale its columns)")
    if args.reference_csv:
        ref = load_reference_csv(args.reference_csv, columns=args.columns, scale=args.scale)
        return ref, ref.duration, f"reference from {args.reference_csv}"
    if args.profile:
        limits = {k: (getattr(args, k) if getattr(args, k) is not None else v)
                  for k, v in PROFILE_DEFAULTS.items()}
        if limits["distance"] == 0:
            raise UsageError("motionhyst simulate: --distance must be non-zero")
        ref = PointToPoint(**limits)
        return (ref, ref.duration + 0.2,
                f"point-to-point move of {limits['distance']:g} m")
    freqs = args.frequency or sc.frequencies
    if len(freqs) > 1:
        where = "--frequency" if args.frequency else f"the scenario's {len(freqs)} frequencies"
        raise UsageError(f"motionhyst simulate: --time-series runs one sine; {where} gives "
                         f"{len(freqs)} (give one --frequency)")
    amplitude = args.amplitude or sc.amplitude
    return (SineReference(amplitude, freqs[0]), 1.0,
            f"r = {amplitude:g} m sin(2 pi {freqs[0]:g} t)")


def _reference_unit_notes(source: str, ref) -> tuple[str | None, str | None]:
    """What looks like a unit slip in a reference file, judged once it is read and before the
    run is sized: a position spanning more than a stage's stroke (millimetres read as
    metres), and samples slower than :data:`SLOWEST_REFERENCE_HZ` (a time in milliseconds,
    whose run is a thousand times too long).  The warning of each, or None; the second
    ends where a refusal of the run's size goes on with its remedy (:func:`_with_unit_hint`)."""
    import numpy as np

    from motionhyst.analysis.plausibility import PLAUSIBLE_AMPLITUDE_M

    span = float(np.ptp(ref.r))
    position = None
    if span > 2 * PLAUSIBLE_AMPLITUDE_M:
        position = (f"{source}: the reference's position spans {span:.3g} m, more than the "
                    f"{2 * PLAUSIBLE_AMPLITUDE_M:g} m stroke of a motion stage: if it is not "
                    f"in metres, scale it (--scale position=0.001 for mm)")
    step = float(np.median(np.diff(ref.t)))
    time = None
    if step * SLOWEST_REFERENCE_HZ > 1.01:  # slower, beyond the rounding of a logged time
        time = (f"{source}: the reference is sampled at {1 / step:.3g} Hz ({ref.t.size} "
                f"samples over {float(ref.t[-1] - ref.t[0]):.4g} s): if its time is not in "
                f"seconds, scale it (--scale time=0.001 for ms)")
    return position, time


def _unread_time_note(args: argparse.Namespace) -> str | None:
    """:func:`_reference_unit_notes`' time note of a reference file refused before it was
    read (for its size), judged on its first rows (64 kB of a CSV file, read as the whole
    file would be), or None."""
    import io

    import numpy as np
    import pandas as pd

    from motionhyst.io.records import is_mat_file, read_record

    path = args.reference_csv
    try:
        if is_mat_file(path):
            return None
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
        head = head[:head.rfind(b"\n") + 1].decode("utf-8", errors="replace")
        t = read_record(pd.read_csv(io.StringIO(head)), ("time", "position"),
                        columns=args.columns, scale=args.scale)[:, 0]
    except Exception:  # rows that say nothing (any error) leave the refusal as it is
        return None
    step = float(np.median(np.diff(t))) if t.size > 2 else 0.0
    if step * SLOWEST_REFERENCE_HZ <= 1.01:
        return None
    return (f"{path}: the reference is sampled at {1 / step:.3g} Hz (its first {t.size} "
            f"samples): if its time is not in seconds, scale it (--scale time=0.001 for ms)")


def _with_unit_hint(exc, time_note: str):
    """A refusal of a run's size (a :class:`~motionhyst.core.budget.BudgetError`) whose
    reference's time looks like milliseconds (`time_note`): its one line names that first,
    then the refusal's own remedy."""
    return exc.with_remedy(f"{time_note}; else {exc.remedy}" if exc.remedy else time_note)


def _check_size(args: argparse.Namespace, sc, ref, duration: float, out) -> str:
    """Refuse a run of far too many rows or steps, of too much work (a link of many
    elements) or memory (a sampled controller's run is held whole), before its loop is
    built: the step is the
    loop's own where its coefficients give its poles (:func:`~motionhyst.time.steps.pole_step`;
    an unstable loop is refused there), else at most the sampled controller's period or the
    reference's (:func:`~motionhyst.time.steps.longest_step`; a file's samples do not set
    it).  The refusal names what sets the step (the reference's frequency, or the loop's
    fastest pole and the ``[stage]`` value that likely makes it fast) and the options that
    shorten the run.  A CSV that would not fit where `out` is written (the disk's free
    space, the file size limit) is refused too, naming ``--output-rate`` and ``--duration``.
    Returns that remedy, for the run's own refusals."""
    from motionhyst.time.references import SampledReference
    from motionhyst.time.steps import (
        MAX_ROWS,
        check_steps_work,
        longest_step,
        pole_step,
        step_set_by,
        time_series_grid,
    )
    from motionhyst.time.timeseries import (
        COLUMNS,
        DEFAULT_OUTPUT_RATE_HZ,
        check_time_series_memory,
        reference_rate_hz,
    )

    controller = sc.model.controller
    sampled = isinstance(ref, SampledReference)
    f = 0.0 if sampled else float(getattr(ref, "max_frequency_hz", 0.0) or 0.0)
    pole = None if controller is None else sc.fastest_pole()  # None when sampled
    rate = getattr(controller, "sample_rate_hz", None)
    output_rate = args.output_rate or rate or (reference_rate_hz(ref) if sampled
                                               else DEFAULT_OUTPUT_RATE_HZ)
    by_pole = pole is not None and pole_step(pole, f) >= pole_step(pole)
    # the loop's pole or the controller's period sets the step: a lower frequency helps not
    # a lower output rate shortens the run where its rows are too many, or where it sets the
    # step (a row every step, finer than the loop's poles need); not where they set it
    finer = (args.output_rate is not None and pole is not None
             and 1.0 / args.output_rate < pole_step(pole, f))
    remedy = _remedy(args, by_pole or rate is not None,
                     duration * output_rate > MAX_ROWS or finer)
    if controller is None:  # no loop: the scenario's own refusal comes first
        return remedy
    why = ""
    if pole is not None:
        step = pole_step(pole, f)
        why = step_set_by(pole, f)
        cause = fast_pole(sc, pole) if by_pole else ""
        why += f", {cause}" if cause else ""
    else:
        step = (math.inf if f <= 0 and rate is None
                else longest_step(f, None if rate is None else 1.0 / rate))
    with in_the_commands_terms(sc, remedy):
        rows, per_row, run_step = time_series_grid(duration, output_rate, step, rate,
                                                   at_least=rate is None and pole is None,
                                                   set_by=why)
        out.check_csv_size(rows, len(COLUMNS), remedy=f"lower --output-rate ({output_rate:g} "
                           f"Hz) or shorten --duration ({duration:g} s), or write "
                           f"--time-series where there is room")
        check_steps_work((rows - 1) * per_row + 1, (sc.hysteresis(),), remedy, rows)
        check_time_series_memory((rows - 1) * per_row + 1, per_row, rate is not None, remedy,
                                 ref)
    if pole is not None or rate is not None:  # the run's own step, before its loop is built
        check_link_damping_for(sc, None if pole is None else run_step)
    return remedy


def _check_output_rate(args: argparse.Namespace, sc, ref) -> str | None:
    """Refuse an ``--output-rate`` above the rate a continuous loop's step needs by more than
    the second of :data:`OUTPUT_RATE_FACTORS`; above the first, the warning to give once the
    run is not refused (None otherwise, for a rate at or below the default's, and for a
    sampled controller, whose samples set the run)."""
    from motionhyst.time.references import SampledReference
    from motionhyst.time.steps import pole_step, step_set_by
    from motionhyst.time.timeseries import DEFAULT_OUTPUT_RATE_HZ

    if args.output_rate is None or sc.model.controller is None:
        return None
    pole = sc.fastest_pole()
    if pole is None:
        return None
    f = (0.0 if isinstance(ref, SampledReference)
         else float(getattr(ref, "max_frequency_hz", 0.0) or 0.0))
    needed = 1.0 / pole_step(pole, f)
    factor = args.output_rate / needed
    warn_above, refuse_above = OUTPUT_RATE_FACTORS
    if factor <= warn_above or (factor <= refuse_above
                                and args.output_rate <= DEFAULT_OUTPUT_RATE_HZ):
        return None  # the default's rate, or below it, is no choice to warn of
    what = (f"--output-rate {args.output_rate:g} Hz is {factor:.3g} times the rate the loop "
            f"needs ({needed:.3g} Hz: {step_set_by(pole, f)})")
    if factor > refuse_above:
        raise UsageError(f"motionhyst simulate: {what}: its rows would only make the run's "
                         f"step finer than the loop's dynamics need; give --output-rate "
                         f"{needed:.3g} (at most {refuse_above:g} times it)")
    return (f"{what}: its rows make the run's step and the file {factor:.3g} times finer and "
            f"longer than the loop's dynamics need; --output-rate {needed:.3g} resolves it")


def _remedy(args: argparse.Namespace, fixed_step: bool, rows: bool) -> str:
    """What the user of ``simulate --time-series`` can change to make the run smaller: the
    options of its reference (the frequency of a sine, unless the loop sets the step; a
    move's length and speed), ``--duration``, and ``--output-rate`` where the rows are too
    many or it sets the step."""
    shorten = ("--duration (or the file)" if args.reference_csv
               else "--duration or the move (--distance, --v-max)" if args.profile
               else "--duration" if fixed_step else "--duration or lower --frequency")
    return f"shorten {shorten}" + (", or lower --output-rate" if rows else "")


def _time_series(args: argparse.Namespace, sc) -> int:
    """Transient run from rest, streamed to CSV atomically, with its summary."""
    from motionhyst.core.warnings import warn
    from motionhyst.time.references import SineReference
    from motionhyst.time.timeseries import run_time_series

    if not sc.plant().is_lti:
        raise UsageError(f"motionhyst simulate: --time-series needs a plant model; {sc.source} "
                         f"uses its measured [plant] as raw data (use = \"data\"), which has no "
                         f"time-domain model; use = \"fit\" fits one")
    warn_plant_fit(sc)
    from motionhyst.core.budget import BudgetError

    try:
        ref, default_duration, what = _reference(args, sc)
    except BudgetError as exc:  # a reference file refused unread: its first rows' units
        note = _unread_time_note(args) if args.reference_csv else None
        if note is None:
            raise
        raise _with_unit_hint(exc, note) from None
    inputs = [*sc.files, args.reference_csv]
    out = output_file(args.time_series, args, "--time-series", inputs)
    duration = args.duration or default_duration
    # a file's units are judged before its run is sized: a time in ms makes the run 1000 times
    # too long, which the size's refusal then names; warned of once the run is not refused
    notes = _reference_unit_notes(args.reference_csv, ref) if args.reference_csv else ()
    try:
        remedy = _check_size(args, sc, ref, duration, out)
    except BudgetError as exc:  # too many steps or rows, too much memory, disk or work
        if not notes or notes[1] is None:
            raise
        raise _with_unit_hint(exc, notes[1]) from None
    rate_note = _check_output_rate(args, sc, ref)
    from motionhyst.analysis.plausibility import check_plausible, check_stroke

    if args.profile:  # once it is not refused: a refusal is one line
        check_stroke(ref.distance, "--distance")
    for note in notes:
        if note is not None:
            warn(note)

    if isinstance(ref, SineReference):
        check_plausible(sc.loop(), ref.amplitude, [ref.frequency_hz])
        if 1.0 / ref.frequency_hz > duration:
            warn(f"the period 1/{ref.frequency_hz:g} Hz = {1 / ref.frequency_hz:.3g} s exceeds "
                 f"--duration {duration:g} s: no full period, the run is start-up only")
    if rate_note is not None:
        warn(rate_note)
    options = {"output_rate_hz": args.output_rate}
    if args.settle_band is not None:
        options["settle_band"] = args.settle_band
    loop = sc.loop()
    if loop.sampled is None:  # a pure derivative has no run: refused before the warnings show
        from motionhyst.time.simulation import check_long_run, check_proper

        check_proper(loop)
        check_long_run(loop)
    release_held()  # the run starts: the warnings so far are shown
    with out.open(newline="") as fh, in_the_commands_terms(sc, remedy):
        s = run_time_series(loop, ref, duration, fh, **options)
    s = {"time_series": str(out.path), **s}
    if args.json:
        print_json(s)
        return 0
    print(f"Simulated {s['duration_s']:.4g} s of {sc.source}, {what}: {s['steps']} steps of "
          f"{s['dt_s']:.3g} s, {s['samples']} rows at {s['output_rate_hz']:g} Hz -> {out.path}")
    print(f"  whole run from rest: peak |e| = {s['error_peak']:.4g} m (without hysteresis "
          f"{s['error_linear_peak']:.4g} m), start-up transient included")
    if "last_period" in s:
        lp = s["last_period"]
        if lp is None:
            print("  last full period: none (the run is shorter than one period)")
        else:
            print(f"  last full period ({lp['start_s']:.4g}-{lp['end_s']:.4g} s): peak |e| = "
                  f"{lp['error_peak']:.4g} m, RMS {lp['error_rms']:.4g} m; without hysteresis "
                  f"peak {lp['error_linear_peak']:.4g} m, RMS {lp['error_linear_rms']:.4g} m")
    if "move" in s:
        mv = s["move"]

        def settle(v):
            return "not within the run" if v is None else f"{v * 1e3:.4g} ms"

        print(f"  while moving ({mv['start_s']:.4g}-{mv['end_s']:.4g} s): peak |e| = "
              f"{mv['error_peak']:.4g} m (without hysteresis {mv['error_linear_peak']:.4g} m)")
        print(f"  settling into +-{mv['settle_band']:.3g} m after the move: "
              f"{settle(mv['settling_time_s'])} (without hysteresis "
              f"{settle(mv['settling_time_linear_s'])})")
    print(f"  final error {s['error_final']:.4g} m (without hysteresis "
          f"{s['error_linear_final']:.4g} m)")
    return 0


def add_parser(sub) -> None:
    """Add the ``simulate`` command to the subparsers `sub`."""
    q = sub.add_parser("simulate", help="transient run of the nonlinear loop from rest, "
                       "written to CSV (--time-series)")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--frequency", type=positive, nargs="+", help="frequencies [Hz]")
    q.add_argument("--amplitude", type=positive, help="reference amplitude [m]")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.add_argument("--time-series", metavar="OUT.csv",
                   help="write a transient run from rest to CSV (sine of one frequency, "
                        "or --reference-csv / --profile); an existing file needs --force")
    q.add_argument("--reference-csv", metavar="FILE",
                   help="reference record: time,position [s, m]; CSV (comma or semicolon, "
                        "any case) or MATLAB .mat")
    add_record_options(q, "time,position (--reference-csv)", "time=t,position=qg")
    q.add_argument("--profile", choices=["point-to-point"], help="built-in reference profile")
    q.add_argument("--distance", type=float, help="move length [m] (0.01)")
    q.add_argument("--v-max", type=positive, help="velocity limit [m/s] (0.5)")
    q.add_argument("--a-max", type=positive, help="acceleration limit [m/s^2] (10)")
    q.add_argument("--j-max", type=positive, help="jerk limit [m/s^3] (1000)")
    q.add_argument("--duration", type=positive,
                   help="simulated time [s] (sine 1, profile its length + 0.2, file its length)")
    q.add_argument("--output-rate", type=positive, metavar="HZ",
                   help="rows per second of the CSV (default: the reference file's own rate, "
                        "10 kHz for sines and profiles); the integration step follows the "
                        "loop's dynamics, or the rows where they are finer (a rate 10 times "
                        "what the loop needs is warned of, 1000 times refused)")
    q.add_argument("--settle-band", type=positive, metavar="M",
                   help="point-to-point: half-width of the settling band [m] (1e-8 = 10 nm)")
    add_force_option(q)
    q.set_defaults(func=run)
