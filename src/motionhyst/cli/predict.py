"""``motionhyst predict``: the displacement of an open-loop system for a force record, or the
force of a system without inertia for a displacement record."""

from __future__ import annotations

import argparse
import math

import numpy as np

from motionhyst.cli._common import UsageError, add_record_options, print_json, release_held

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []

INIT_WINDOW = 20  # the EMPS benchmark's initialisation window [samples]

SHORTER = "give a shorter record, or write --out where there is room"
"""What the user of ``predict`` can change when its output does not fit."""


def add_parser(sub) -> None:
    """Add the ``predict`` command to the subparsers `sub`."""
    q = sub.add_parser("predict", help="displacement of an open-loop system (a scenario without "
                       "controller) for a force record, or force of a system without inertia "
                       "for a displacement record (CSV)")
    q.add_argument("scenario", metavar="MODEL.toml",
                   help='open-loop scenario: [stage] type = "mass-spring-damper", '
                        '"mass-damper", "quasi-static" (no inertia), or a two-mass [stage] '
                        'with output = "y2" or "y1" (the position written), and [hysteresis] '
                        "(as written by motionhyst identify --save)")
    q.add_argument("data", metavar="INPUT.csv", help="force record: time,force [s, N]; or, for "
                   "a quasi-static model (the link alone, as a force-displacement record's "
                   "identify --save writes it), displacement record: time,displacement [s, "
                   "m]; uniform time steps (stamps within 0.05 of a step of a uniform grid); "
                   "CSV with a header or MATLAB .mat")
    add_record_options(q, "time,force or time,displacement", "time=t,force=vir")
    q.add_argument("--predict", choices=["displacement", "force"],
                   help="what to predict from INPUT, where it holds both a force and a "
                        "displacement (a quasi-static model only: the force from the "
                        "displacement, or the displacement from the force; default: what the "
                        "record the model was identified from measured, its [identification] "
                        "record: a force-displacement record's force, an input-output "
                        "record's position; a model with inertia predicts the displacement)")
    q.add_argument("--periodic", action="store_true",
                   help="the record is one period (or whole periods) of a periodic force: "
                        "output the periodic steady state (default: from rest; a floating "
                        "two-mass stage: with zero mean, an error if it drifts)")
    q.add_argument("--out", required=True, metavar="OUT.csv",
                   help="output CSV: time,displacement [s, m] on the input's time grid (a "
                        "two-mass stage: the position its [stage] output names); for a "
                        "displacement record time,force [s, N]")
    q.add_argument("--substeps", type=int, metavar="N",
                   help="integration steps per sample (default: >= 20 and >= 400 per period "
                        "of the stage's fastest mode; a quasi-static model has none)")
    q.add_argument("--init-from", metavar="REC.csv",
                   help="a measured record of the same run and samples (time,force,"
                        "displacement; one whose force varies independently of INPUT's is "
                        "refused, a load cell's offset, drift, gain or white noise is not, nor "
                        "other noise up to about the force's RMS (mains hum up to 1.7 times "
                        "it); low-frequency noise larger than that may make the same run's "
                        "force look another's): "
                        "the "
                        "model's initial state (velocity, and position or the position's "
                        "offset) is set from its first --init-window samples, and the error "
                        "after them is reported (the benchmark convention)")
    q.add_argument("--init-window", type=int, metavar="N",
                   help=f"with --init-from: samples that set the state (default "
                        f"{INIT_WINDOW}, the EMPS benchmark's)")
    q.add_argument("--force", action="store_true", help="replace OUT.csv if it exists")
    q.add_argument("--json", action="store_true", help="print a JSON summary")
    q.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Simulate the scenario's open-loop system for the force record and write the output."""
    from motionhyst.io.records import read_record
    from motionhyst.scenario import Scenario
    from motionhyst.time.kernel import StepNotConverged
    from motionhyst.time.resample import check_whole_periods

    if args.substeps is not None and not 1 <= args.substeps <= 10000:
        raise UsageError(f"motionhyst predict: --substeps must be from 1 to 10000, got "
                         f"{args.substeps}")
    from motionhyst.io.outputs import OutputFile
    from motionhyst.scenario.files import read_files

    target = OutputFile(args.out, force=args.force,
                        inputs=[*read_files(args.scenario), args.data, args.init_from],
                        option="--out")  # refused before any work
    if args.init_window is not None and args.init_from is None:
        raise UsageError("motionhyst predict: --init-window applies with --init-from only")
    if args.init_from is not None and args.periodic:
        raise UsageError("motionhyst predict: --init-from sets the state of a run from a "
                         "start; a --periodic steady state has none")
    window = INIT_WINDOW if args.init_window is None else args.init_window
    if window < 2:
        raise UsageError(f"motionhyst predict: --init-window must be at least 2, got {window}")
    sc = Scenario.from_file(args.scenario, check=False)  # a loop is refused, not built
    system = sc.open_loop()
    if args.substeps is not None and not system.plant.has_inertia:
        raise UsageError(f"motionhyst predict: --substeps sets the integration steps of a "
                         f"model with inertia; {sc.source} is quasi-static (its balance is "
                         f"solved at each sample, with no steps between)")
    if _input_quantity(args, sc, system) == "displacement":
        return _predict_force(args, sc, system, target)
    # the maps may also name the position (the --init-from record's, or INPUT's measured one,
    # as the map given to identify): only time and force are read from INPUT
    if args.init_from is None:
        _check_named_unread(args, "displacement", "force")
    _check_unread(args, system)
    data = read_record(args.data, ("time", "force"),
                       columns=_without(args.columns, "displacement"),
                       scale=_without(args.scale, "displacement"))
    t, u = data[:, 0], data[:, 1]
    target.check_csv_size(t.size, 2, "%.17g", remedy=SHORTER)
    if args.periodic:
        check_whole_periods(u, str(args.data))
    _check_step(system, t, args)
    pred = rec = None
    if args.init_from is not None:  # its errors name it, not the input record
        from motionhyst.identify.io_records import load_io_csv

        rec = load_io_csv(args.init_from, columns=args.columns, scale=args.scale)
        if rec.y.size != t.size or not np.allclose(rec.t, t, rtol=0.0,
                                                   atol=1e-6 * float(np.ptp(t))):
            raise UsageError(f"motionhyst predict: {args.init_from} must have the samples "
                             f"of {args.data} (the same time column)")
        _check_same_run(args, u, rec.u)
    u_model, noise = u, None
    zero = 0.0 if rec is not None else _position_offset(sc, system)
    release_held()  # the run starts: the warnings so far are shown
    try:
        if not system.plant.has_inertia:  # the link's input without the load cell's white
            from motionhyst.identify.displacement_noise import estimate_displacement

            # noise, as identify estimates it (a stage with inertia filters it itself)
            u_model, noise = estimate_displacement(t, u, periodic=args.periodic,
                                                   quantity="force", unit="N")
        if rec is not None:
            from motionhyst.identify.io_predict import predict_from_window  # scipy.optimize

            pred = predict_from_window(system, t, u_model, rec.y, window, args.substeps)
            out_t, out_y = pred.t, pred.displacement
        else:
            out = system.simulate(t, u_model, periodic=args.periodic, substeps=args.substeps)
            out_t, out_y = out.t, out.displacement + zero
    except StepNotConverged as exc:  # the library's remedy names its argument
        raise ValueError(f"{args.data}: {exc.what}; give more --substeps") from None
    except (ValueError, ArithmeticError) as exc:  # a model the simulation refuses
        raise ValueError(f"{args.data}: {exc or type(exc).__name__}") from None
    if pred is None or "link_state" not in pred.initial_state:  # else set from the window
        _warn_loaded_start(args, system, u)  # a prediction made: a refusal stays one line
    target.write_csv({"time": out_t, "displacement": out_y}, fmt="%.17g")
    summary = {"out": str(args.out), "samples": int(t.size), "periodic": bool(args.periodic),
               "predicted": "displacement",
               "displacement_rms": float(np.sqrt(np.mean(out_y ** 2))),
               "displacement_peak": float(np.max(np.abs(out_y)))}
    if pred is not None:
        summary.update(pred.to_dict())
    else:
        summary["position_offset"] = zero
    if noise is not None:
        summary["force_noise"] = noise.to_dict()
    if args.json:
        print_json(summary)
    else:
        what = ("periodic steady state" if args.periodic else "from rest" if pred is None
                else f"state set from the first {window} samples of {args.init_from}")
        print(f"Predicted the displacement of {sc.source} ({what}) for the {t.size} force "
              f"samples of {args.data} -> {args.out}")
        print(f"  displacement RMS {summary['displacement_rms']:.4g} m, peak "
              f"{summary['displacement_peak']:.4g} m")
        if zero:
            print(f"  {_offset_text(zero)}")
        if pred is not None:
            print(f"  initial position {pred.initial_state['position']:.6g} m, velocity "
                  f"{pred.initial_state['velocity']:.6g} m/s; RMS error from sample {window + 1} "
                  f"on {pred.rmse:.4g} m (fit {pred.fit_percent:.2f} %)")
            if "link_state" in pred.initial_state:
                print(f"  the link's state at the first sample set from the window too "
                      f"({', '.join(f'{v:.6g}' for v in pred.initial_state['link_state'])})")
            if pred.floor_text():
                print(f"  ({pred.floor_text()})")
        if noise is not None and noise.sigma > 0:
            print(f"  force: {noise.reason}")
    return 0


def _position_offset(sc, system) -> float:
    """The zero of the position sensor a model without inertia was identified with (its
    ``[identification] position_offset``, written by ``identify --save``) [m]; 0 for a model
    with inertia or one that does not give it."""
    ident = sc.model.identification
    if system.plant.has_inertia or ident is None or ident.position_offset is None:
        return 0.0
    return float(ident.position_offset)


def _offset_text(zero: float) -> str:
    """What the output says of the position offset it applied."""
    return (f"position offset {zero:.6g} m (the sensor's zero the model was identified with, "
            f"its [identification] position_offset)")


def _check_unread(args: argparse.Namespace, system) -> None:
    """Refuse a long force record before it is read where its run cannot fit the memory
    budget: its samples (from the file) times the least its run takes, the record and its
    outputs and, from rest with inertia, one block of integration steps at the least
    substeps (a model without inertia has none)."""
    from motionhyst.core.budget import check_memory
    from motionhyst.io.records import check_unread
    from motionhyst.time.openloop import (
        MIN_SUBSTEPS,
        ONE_BLOCK_BYTES,
        REST_NODE_BYTES,
        REST_SAMPLE_BYTES,
        SAMPLE_BYTES,
    )
    from motionhyst.time.resample import block_samples

    r = args.substeps or MIN_SUBSTEPS
    steps = system.plant.has_inertia

    def least(sizes: list[int]) -> None:
        n = sizes[0]
        if steps and not args.periodic:  # the smaller of a run in blocks and in one block
            nodes = min(n - 1, block_samples(r)) * r + 1
            nbytes = min(REST_NODE_BYTES * nodes + REST_SAMPLE_BYTES * n,
                         ONE_BLOCK_BYTES[0] * nodes + ONE_BLOCK_BYTES[1] * n)
        else:
            nbytes = SAMPLE_BYTES * n
        check_memory(nbytes, f"predicting {n} samples "
                     f"{'as a periodic steady state' if args.periodic else 'from rest'}"
                     + (f" (at least {r} integration steps each)" if steps else ""),
                     "fewer samples or --substeps" if steps else "give a shorter record")

    check_unread([args.data], ("time", "force"), least,
                 columns=_without(args.columns, "displacement"))


def _check_named_unread(args: argparse.Namespace, quantity: str, read: str) -> None:
    """Refuse a ``--columns`` or ``--scale`` entry for the `quantity` the run predicts (and so
    does not read) where INPUT holds no such column: the entry would be dropped without a
    word (``--scale displacement=1e-3`` on a force record does not scale the output).  Where
    INPUT holds it (the measured record itself, read with the map given to identify) the
    entry describes the file and is kept, as the other quantities of that map are."""
    from motionhyst.io.records import record_columns

    columns, scale = args.columns or {}, args.scale or {}
    if quantity not in columns and quantity not in scale:
        return
    if quantity in record_columns(args.data, columns):
        return
    option, held = (("--columns", f"column {columns[quantity]!r}") if quantity in columns
                    else ("--scale", quantity))
    also = " (a measured one is read with --init-from REC)" if quantity == "displacement" else ""
    raise UsageError(f"motionhyst predict: {option} names {quantity!r}, which is not read "
                     f"here: the run predicts the {quantity} from the {read} of {args.data}, "
                     f"which holds no {held}{also}")


def _without(mapping, quantity: str):
    """A --columns or --scale map without its entry for `quantity`, the one INPUT is not read
    for (the position of a force record: the --init-from record's, or INPUT's measured
    position, as the map a user gave identify names it); other names are the reader's to
    judge."""
    return None if mapping is None else {k: v for k, v in mapping.items() if k != quantity}


SAME_RUN_CORRELATION = 0.5
"""An ``--init-from`` record whose force's variations (de-meaned, or less a line: a load
cell's drift) correlate with INPUT's by at least this (in magnitude) is taken for the same
run: a load cell's offset, drift or gain error leaves the correlation 1, white noise of 15 % of the
force's RMS 0.989, and noise of any colour up to that RMS keeps it above 0.5 (20 seeds of each
of white noise, 50 Hz hum and noise below 50, 20, 10, 5, 2, 1 and 0.5 Hz, on a 3 s record:
all pass; white noise and hum up to 1.7 times the RMS too, while band-limited noise of 1.5
times passes in 14-20 of 20 seeds, of 1.7 times in 10: the correlation of a few independent
values scatters; 50 Hz hum or noise below 20 Hz of twice the force's RMS brings it to 0.45
or 0.41: the same run refused, its white-noise escape blind to them)."""

SAME_RUN_NOISE_FACTOR = 2.0
"""Below :data:`SAME_RUN_CORRELATION`, the two forces are still taken for the same run when
what one does not share with the other is, in RMS, within this factor of their sensors'
white noise (:func:`~motionhyst.identify.residual_noise.white_noise_variance`, the mean
square of the third differences): a load cell's noise larger than the force."""


def _check_same_run(args: argparse.Namespace, u, u_rec) -> None:
    """Refuse an ``--init-from`` record that is provably of another run than INPUT: its
    position would set the state, and be the reference of the error reported, of another run.

    Judged by the forces' shapes, not their levels: a load cell's offset, gain error or sign
    (a sensor of the same run) change neither the magnitude of the correlation of the
    de-meaned forces nor how far they differ beyond their noise, and its drift (a line over
    the record) neither of the forces less their lines (de-meaned, a drift of 1.5 times the
    force's RMS against its trend correlated by 0.39 and was refused; review A13b M1; less a
    line, the input's own slow content goes too: hum of 1.7 times the RMS 0.5 -> 0.49, so
    both are judged).  Refused only when, both ways, the correlation is below
    :data:`SAME_RUN_CORRELATION` and what the record's force does not share with INPUT's
    exceeds :data:`SAME_RUN_NOISE_FACTOR` times the white noise of the two; a force constant
    in either record, or non-finite samples, are not judged (the record's force is not
    used)."""
    from motionhyst.identify.residual_noise import white_noise_variance

    ok = np.isfinite(u) & np.isfinite(u_rec)
    judged = []
    for line in (False, True):  # de-meaned, and less a line (a drift): either may pass
        a, b = _centred(u, ok, line), _centred(u_rec, ok, line)
        aa, bb = float(a @ a), float(b @ b)
        if a.size < 4 or not (aa > 0 and bb > 0):
            return
        rho = float(a @ b) / np.sqrt(aa * bb)
        if abs(rho) >= SAME_RUN_CORRELATION:
            return
        unshared = (1.0 - rho ** 2) * bb / b.size  # b's variance about its regression on a
        noise = (white_noise_variance(u_rec[ok], robust=False)
                 + rho ** 2 * bb / aa * white_noise_variance(u[ok], robust=False))
        if unshared <= SAME_RUN_NOISE_FACTOR ** 2 * noise:
            return
        judged.append((abs(rho), rho, unshared, noise))
    _, rho, unshared, noise = max(judged)
    beyond = (f"differ by {np.sqrt(unshared / noise):.3g} times their white noise"
              if noise > 0 else "differ while neither has white noise")
    raise UsageError(f"motionhyst predict: {args.init_from} is not the run of {args.data}: "
                     f"their forces vary independently (de-meaned or less a line, they "
                     f"correlate by {rho:.2g}, less than {SAME_RUN_CORRELATION:g} in "
                     f"magnitude, and "
                     f"{beyond}), while a sensor's offset, drift, gain error or white noise "
                     f"keeps one run's forces correlated; its position would set the state, and "
                     f"score the prediction, of another run (if it is this run's, noise "
                     f"other than white, low-frequency noise above about the force's RMS or "
                     f"mains hum above 1.7 times it, decorrelates them: filter its force "
                     f"column, which sets nothing)")


def _centred(u, ok, line: bool):
    """The finite samples `ok` of `u` less their mean, or less their least-squares `line`
    over the samples (a load cell's drift, a thermal ramp, is no variation of the force)."""
    x = u[ok] - np.mean(u[ok])
    if not line:
        return x
    k = np.flatnonzero(ok).astype(float)
    k -= np.mean(k)
    kk = float(k @ k)
    return x - (float(k @ x) / kk) * k if kk > 0 else x


def _warn_loaded_start(args: argparse.Namespace, system, u) -> None:
    """Warn when a model without inertia is run from a force record that starts under load
    (:func:`~motionhyst.identify.io_predict.start_load`): its link starts relaxed there,
    where the force balances the model's offset alone, which a record cut from a longer run
    does not."""
    from motionhyst.core.warnings import warn
    from motionhyst.identify.io_predict import start_load

    if system.plant.has_inertia or system.hysteresis is None or args.periodic:
        return  # a periodic steady state has no start
    offset = float(getattr(system.plant, "force_offset", 0.0))
    rest = -offset if offset else 0.0  # u + f0 = w(y) + k y + c y': at rest u = -f0
    away = start_load(u, offset)
    if away is not None:
        start, span = rest + away, float(np.ptp(u))
        share = f"{100 * abs(start - rest) / span:.0f} % of its force's range"
        where = (f", {abs(start - rest):.4g} N ({share}) from where the model rests ({rest:.4g} "
                 f"N, its force offset)" if offset else f" ({share} from where the model rests, "
                 f"0 N)")
        why = (" (--init-from sets the state of a link of one element; how the force splits "
               "among several needs the record's history)" if args.init_from else "")
        warn(f"{args.data} starts under load, at {start:.4g} N{where}: a model without inertia "
             f"starts its link relaxed{why}, not where on its loops the part of a longer run "
             f"begins, and may miss by the loops' width; predict the record from its start (or "
             f"a record that starts at rest)")


SETTLED_FACTOR = 0.25
"""The factor of the link's damping on an implicit step
(:func:`~motionhyst.time.steps.damping_factor`) that the ``--substeps`` a refusal for the
damping suggests bring it to: runs converged below 0.34 in every case measured."""


def _check_step(system, t, args) -> None:
    """Refuse, before any work, a model whose own step would be impossibly fine, or whose
    link is too strongly damped for its step (:func:`~motionhyst.time.steps.check_link_damping`:
    the run stopped at the first motion, or ended in a motion of 100-1000 m for 30 N on a
    damped axis, exit 0)."""
    from motionhyst.identify.io_checks import MAX_PREDICT_SUBSTEPS
    from motionhyst.time.openloop import check_record, sampling_rate
    from motionhyst.time.steps import check_link_damping, damping_factor

    try:
        tt, _ = check_record(t, np.zeros(np.size(t)))
    except ValueError as exc:  # the record's time, not the model, is at fault
        raise ValueError(f"{args.data}: {exc}") from None
    if not system.plant.has_inertia:
        return
    fs = sampling_rate(tt)
    r = args.substeps
    if r is None:
        try:
            r = system.default_substeps(fs)
        except (ValueError, OverflowError) as exc:
            raise ValueError(f"{args.scenario}: the model cannot be simulated ({exc})") from None
        if r > MAX_PREDICT_SUBSTEPS:
            raise ValueError(f"{args.scenario}: the model needs {r} integration steps per "
                             f"sample of {args.data} (more than {MAX_PREDICT_SUBSTEPS}): its "
                             f"fastest mode is far above the record's sampling rate {fs:.4g} "
                             f"Hz: a time column not in seconds (--scale time=GAIN), or a mass "
                             f"nearly zero on a stiff link (a quasi-static plant describes a "
                             f"stage without inertia)")
    step = 1.0 / (fs * r)
    try:
        check_link_damping(system.hysteresis, system.plant, step)
    except ValueError as exc:
        need = math.ceil(r * damping_factor(system.hysteresis, system.plant, step)
                         / SETTLED_FACTOR)
        remedy = (f"--substeps {need} ({r} now) would settle it" if need <= 10000
                  else "is the link's damping meant (in SI units)?")
        raise ValueError(f"{args.scenario}: [hysteresis]: {exc} (a step is 1/{r} of a sample "
                         f"of {args.data}): {remedy}") from None


def _input_quantity(args: argparse.Namespace, sc, system) -> str:
    """``force`` or ``displacement``: what INPUT gives the model.  A model with inertia takes
    the force; one without inertia the quantity INPUT holds alone, or, where it holds both,
    the one ``--predict`` does not name, or else the one the model's own record imposed
    (``[identification] record``: a force-displacement record's displacement, an
    input-output record's force); a record with both and a model that does not say is
    refused, not guessed."""
    from motionhyst.io.records import record_columns

    if system.plant.has_inertia:
        if args.predict == "force":
            raise UsageError(f"motionhyst predict: --predict force gives the force of a model "
                             f"without inertia for a displacement record; {sc.source} has "
                             f"inertia (its displacement is predicted from a force)")
        return "force"  # a record without one is refused by its reader, naming the columns
    names = record_columns(args.data, args.columns)
    if args.init_from is not None:
        if args.predict == "force":
            raise UsageError("motionhyst predict: --init-from sets the state of a displacement "
                             "predicted from a force; --predict force predicts no "
                             "displacement")
        if "force" not in names and "displacement" in names:
            raise UsageError(f"motionhyst predict: --init-from applies to a force record (the "
                             f"displacement predicted); {args.data} holds a displacement")
        ident = sc.model.identification
        if ("displacement" in names and args.predict is None and ident is not None
                and ident.record == "force-displacement"):
            # the quantity predicted is the model's, never switched by an option
            raise UsageError(f"motionhyst predict: --init-from sets the state of a "
                             f"displacement predicted from a force; {sc.source} predicts the "
                             f"force of {args.data}'s displacement (its [identification] "
                             f"record is force-displacement), from its link relaxed at the "
                             f"first displacement: leave out --init-from, or give --predict "
                             f"displacement to predict the displacement from the force")
        return "force"
    if args.predict is not None:
        return "force" if args.predict == "displacement" else "displacement"
    if "force" not in names or "displacement" not in names:
        return "displacement" if "displacement" in names else "force"
    ident = sc.model.identification
    record = None if ident is None else ident.record
    if record is None:
        raise UsageError(f"motionhyst predict: {args.data} holds a force and a displacement, "
                         f"and {sc.source} does not say which it was identified to predict "
                         f"(saved before identify --save wrote its record's kind, or written "
                         f"by hand): give --predict force (from the displacement) or --predict "
                         f"displacement (from the force)")
    return "displacement" if record == "force-displacement" else "force"


QUASI_STATIC_SAMPLE_BYTES = 96
"""Memory of predicting the force of a model without inertia per displacement sample
[bytes]: the record, the estimate of its sensor's noise and the link's run.  Measured,
address space above a warmed process (a Jenkins link on a spring, a sine with a step in 10
um of noise): 3e5 samples 28.2 MB, 1e6 77.6 MB (124.7 before the noise estimate was made in
place)."""


def _check_force_memory(sizes: list[int]) -> None:
    """Refuse a displacement record whose force prediction does not fit the memory budget
    (:data:`QUASI_STATIC_SAMPLE_BYTES` a sample)."""
    from motionhyst.core.budget import check_memory

    n = sizes[0]
    check_memory(QUASI_STATIC_SAMPLE_BYTES * float(n), f"predicting the force of {n} "
                 f"displacement samples (the record, its noise estimate and the link's run)",
                 "give a shorter record")


def _predict_force(args: argparse.Namespace, sc, system, target) -> int:
    """The force that holds a model without inertia at the displacement record INPUT."""
    from motionhyst.io.records import check_unread, read_record
    from motionhyst.time.quasi_static import force_from_displacement
    from motionhyst.time.resample import check_whole_periods

    # the maps may name the force too (as the map a user gave identify)
    _check_named_unread(args, "force", "displacement")
    check_unread([args.data], ("time", "displacement"), _check_force_memory,
                 columns=_without(args.columns, "force"))  # a long record: unread
    data = read_record(args.data, ("time", "displacement"),
                       columns=_without(args.columns, "force"),
                       scale=_without(args.scale, "force"))
    t, x = data[:, 0], data[:, 1]
    zero = _position_offset(sc, system)
    x = x - zero  # the link's displacement: the record's less its sensor's zero
    _check_force_memory([t.size])
    target.check_csv_size(t.size, 2, "%.17g", remedy=SHORTER)
    if args.periodic:
        check_whole_periods(x, str(args.data))
    from motionhyst.identify.displacement_noise import estimate_displacement

    release_held()  # the run starts: the warnings so far are shown
    try:
        # the link's input without the sensor's white noise, as identify estimates it
        x, noise = estimate_displacement(t, x, periodic=args.periodic)
        # the link relaxed where the record starts, as identify fits a force-displacement
        # record (a sensor's zero or a record cut from a run does not load it)
        w = force_from_displacement(system.plant, system.hysteresis, t, x,
                                    periodic=args.periodic, x_before=float(x[0]))
    except (ValueError, ArithmeticError) as exc:  # a record or model the run refuses
        raise ValueError(f"{args.data}: {exc or type(exc).__name__}") from None
    target.write_csv({"time": t, "force": w}, fmt="%.17g")
    summary = {"out": str(args.out), "samples": int(t.size), "periodic": bool(args.periodic),
               "predicted": "force", "force_rms": float(np.sqrt(np.mean(w ** 2))),
               "force_peak": float(np.max(np.abs(w))),
               "displacement_noise": noise.to_dict(), "position_offset": zero}
    if args.json:
        print_json(summary)
        return 0
    what = ("periodic steady state" if args.periodic
            else "the link relaxed at its first displacement")
    print(f"Predicted the force of {sc.source} for the {t.size} displacement samples of "
          f"{args.data} ({what}) -> {args.out}")
    print(f"  force RMS {summary['force_rms']:.4g} N, peak {summary['force_peak']:.4g} N")
    if zero:
        print(f"  {_offset_text(zero)}")
    if noise.sigma > 0:
        print(f"  displacement: {noise.reason}")
    return 0
