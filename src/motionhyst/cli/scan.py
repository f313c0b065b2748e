"""``motionhyst scan``: a fourth-order setpoint through the loop, graded by the moving
average and moving standard deviation of the error over the exposure window, with the
compensations compared (none, the scenario's model feedforward, learning control of a
force, learning of the model's coefficients).
"""

from __future__ import annotations

import argparse
import math

from motionhyst.cli._common import (
    UsageError,
    check_link_damping_for,
    fast_pole,
    g,
    in_the_commands_terms,
    nonnegative,
    positive,
    print_json,
    refuse_unused,
    release_held,
    warn_plant_fit,
    whole_number,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []

PROG = "motionhyst scan"

REMEDY = ("shorten the setpoint (--length, --dwell) or --tail, or raise its limits (--speed, "
          "--a-max, --j-max, --s-max)")
"""What the user of ``scan`` can change to make its runs shorter."""
LEAD_IN = 0.01
"""Rest before the setpoint starts [s]: room for the learned force to act ahead of it."""


_count = whole_number(1, 1000, "trials")

ILC_DEFAULTS = {"ilc_trials": 10, "ilc_gain": 1.0, "ilc_cutoff": 300.0, "ilc_order": 2}
"""Learning control's options unless given (they apply with ``--compensation ilc`` only)."""

BASIS_TRIALS = 4
"""Trials of ``--compensation basis`` unless given (the first is the model's run)."""

TERMS = ("jerk", "snap", "viscous", "coulomb", "hysteresis")
"""The model feedforward's terms ``--feedforward`` switches on (motionhyst.scan.terms.TERMS)."""


def add_parser(sub) -> None:
    """Register ``scan`` on the subcommand parsers `sub`."""
    q = sub.add_parser("scan", help="scan or point-to-point setpoint: MA/MSD of the error, "
                       "compensation by the model feedforward and by learning")
    q.add_argument("scenario", nargs="?", help="scenario TOML (default: the paper's Table I)")
    q.add_argument("--length", type=positive, required=True,
                   help="scan length at constant velocity (point-to-point: move length) [m]")
    q.add_argument("--speed", type=positive, required=True,
                   help="scan speed (point-to-point: velocity limit) [m/s]")
    q.add_argument("--a-max", type=positive, required=True, help="acceleration limit [m/s^2]")
    q.add_argument("--j-max", type=positive, required=True, help="jerk limit [m/s^3]")
    q.add_argument("--s-max", type=positive, required=True, help="snap limit [m/s^4]")
    q.add_argument("--point-to-point", action="store_true",
                   help="a point-to-point move of --length instead of a scan")
    q.add_argument("--back-and-forth", action="store_true",
                   help="scan, then scan back to the start")
    q.add_argument("--dwell", type=nonnegative, default=0.0,
                   help="rest between a scan and its return [s] (0)")
    q.add_argument("--rate", type=positive, metavar="HZ",
                   help="controller rate: switching instants on its samples [Hz]")
    q.add_argument("--window", type=positive, default=0.01, metavar="W",
                   help="exposure window of MA and MSD, slit width / scan speed [s] (0.01)")
    q.add_argument("--compensation", nargs="+", choices=["none", "model", "ilc", "basis"],
                   help="compensations to compare (default: none, model if the scenario has "
                        "a model feedforward, ilc, basis)")
    q.add_argument("--feedforward", nargs="+", choices=TERMS, metavar="TERM",
                   help="the model feedforward's terms beside M r'': jerk, snap (the "
                        "scenario's, else the plant's inverse), viscous, coulomb, hysteresis "
                        "(default: those of the scenario's [feedforward], and the stage's jerk and "
                        "snap from the plant where it leaves them unset)")
    q.add_argument("--basis-trials", type=_count, metavar="N",
                   help="trials of the basis learning; the first runs the model (4)")
    q.add_argument("--ilc-trials", type=_count, metavar="N",
                   help="learning trials; the last is the ilc result (10)")
    q.add_argument("--ilc-gain", type=positive,
                   help="learning gain in (0, 2): L = gain / PS, PS = P2 / (1 + C P2) (1)")
    q.add_argument("--ilc-cutoff", type=positive, metavar="HZ",
                   help="corner of the zero-phase Butterworth robustness filter Q [Hz] (300)")
    q.add_argument("--ilc-order", type=_count,
                   help="order of the Butterworth filter whose squared magnitude is Q (2)")
    q.add_argument("--other-length", type=positive, metavar="L",
                   help="carry-over setpoint: length [m] (default: --length)")
    q.add_argument("--other-speed", type=positive, metavar="V",
                   help="carry-over setpoint: speed [m/s] (default: half of --speed)")
    q.add_argument("--at", type=float, metavar="X",
                   help="where on the stroke the scan starts, for links whose parameters vary "
                        "along it ([hysteresis] along) [m] (0)")
    q.add_argument("--settle-tol", type=positive, default=1e-9, metavar="M",
                   help="error band of the settling time [m] (1e-9)")
    q.add_argument("--tail", type=nonnegative, default=0.05,
                   help="time simulated after the setpoint ends [s] (0.05)")
    q.add_argument("--time-series", metavar="OUT.csv",
                   help="write time, r, scan and e_c, ma_c, msd_c per compensation to CSV")
    q.add_argument("--force", action="store_true", help="overwrite an existing --time-series")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)


def _profile(args, length: float, speed: float, rated: bool = True):
    """The setpoint of `length` and `speed`, its switching instants on ``--rate``'s samples
    unless not `rated`."""
    from motionhyst.scan.profiles import point_to_point, scan

    rate = args.rate if rated else None
    if args.point_to_point:
        if args.back_and_forth or args.dwell:
            raise UsageError(f"{PROG}: --back-and-forth and --dwell apply to scans, not to "
                             "--point-to-point")
        return point_to_point(length, speed, args.a_max, args.j_max, args.s_max,
                              rate_hz=rate, start=LEAD_IN)
    return scan(length, speed, args.a_max, args.j_max, args.s_max,
                back_and_forth=args.back_and_forth, dwell=args.dwell, rate_hz=rate,
                start=LEAD_IN)


RATE_STRETCH = 1.1
"""A setpoint whose switching instants on ``--rate``'s samples last longer than this times the
setpoint asked for is said in a warning: its peak acceleration, jerk and snap are below the
limits given."""

RATE_REFUSED = 2.0
"""... and one that lasts longer than this times the setpoint asked for is refused: the rate
cannot resolve the move, the run would be of another move (1 Hz: 0.142 s -> 9 s)."""


def _check_rate_resolves(args: argparse.Namespace, length: float, speed: float, profile,
                         what: str = "setpoint") -> str:
    """Refuse a ``--rate`` whose samples cannot resolve the setpoint: its switching instants on
    them make it last more than :data:`RATE_REFUSED` times the setpoint the limits give (a
    move of another time scale, its peak acceleration far below ``--a-max``).  One that
    stretches it by more than :data:`RATE_STRETCH` is said in a warning: returned, for the
    caller to issue once every setpoint is checked ("" for none).  `what` names the setpoint
    (the carry-over setpoint's options differ)."""
    if args.rate is None:
        return ""
    asked = _profile(args, length, speed, rated=False)
    got = (f"{g(asked.duration, 3)} s -> {g(profile.duration, 3)} s, peak acceleration "
           f"{g(profile.reached()['acceleration'], 3)} m/s^2 for --a-max {g(args.a_max)}")
    if profile.duration > RATE_REFUSED * asked.duration:
        raise UsageError(f"{PROG}: --rate {args.rate:g} Hz cannot resolve the {what}: its "
                         f"switching instants on the samples make another move ({got}); "
                         f"give the controller's rate")
    if profile.duration > RATE_STRETCH * asked.duration:
        return (f"--rate {args.rate:g} Hz: the {what}'s switching instants on its samples "
                f"stretch the move ({got})")
    return ""


def _output(args):
    """The ``--time-series`` target, checked before any computation (None without it)."""
    from motionhyst.io.outputs import OutputFile
    from motionhyst.scenario.files import read_files

    if not args.time_series:
        return None
    return OutputFile(args.time_series, force=args.force, inputs=read_files(args.scenario),
                      option="--time-series")


def _at(loop, x0: float, source: str):
    """`loop` with its links along the stroke seen from `x0` (the scan starts there)."""
    from motionhyst.scan.scanning import loop_at

    try:
        return loop_at(loop, x0)
    except ValueError as exc:
        raise UsageError(f"{PROG}: --at: {exc} ({source})") from None


def _check_options(args: argparse.Namespace) -> None:
    """The options' own checks, before the scenario's loop is built: each compensation
    and term once, no option that has no effect with the compensations compared, learning
    options filled in from :data:`ILC_DEFAULTS` and in range.

    Without ``--compensation`` the compensations compared are none, model (when there
    is a model feedforward), ilc and basis: every learning option applies to them.
    """
    if args.at is not None and not math.isfinite(args.at):
        raise UsageError(f"{PROG}: --at must be finite, got {args.at}")
    if args.feedforward is not None and len(set(args.feedforward)) != len(args.feedforward):
        raise UsageError(f"{PROG}: --feedforward lists one twice")
    comps = args.compensation or ["none", "ilc", "basis"]
    if len(set(comps)) != len(comps):
        raise UsageError(f"{PROG}: --compensation lists one twice")
    if "ilc" not in comps:
        refuse_unused(args, ("--ilc-trials", "--ilc-gain", "--ilc-cutoff", "--ilc-order"),
                      "without --compensation ilc (it shapes learning control only)")
    if "basis" not in comps:
        refuse_unused(args, ("--basis-trials",), "without --compensation basis")
    if "ilc" not in comps and "basis" not in comps:
        refuse_unused(args, ("--other-length", "--other-speed"),
                      "without --compensation ilc or basis (the carry-over of what they learn)")
    if not {"model", "basis"} & set(comps):
        refuse_unused(args, ("--feedforward",), "without --compensation model or basis")
    for name, value in ILC_DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    if not 0 < args.ilc_gain < 2:
        raise UsageError(f"{PROG}: --ilc-gain must be in (0, 2), got {args.ilc_gain:g}")


def _check_rate(args: argparse.Namespace, sc) -> None:
    """Refuse a ``--rate`` whose samples are not the sampled controller's: the setpoint's
    switching instants would fall between the samples the controller reads it at."""
    rate = getattr(sc.model.controller, "sample_rate_hz", None)
    if args.rate is None or rate is None:
        return
    ratio = rate / args.rate
    if round(ratio) < 1 or abs(ratio - round(ratio)) > 1e-9 * ratio:
        raise UsageError(f"{PROG}: --rate {args.rate:g} Hz: {sc.source}'s controller samples "
                         f"at {rate:g} Hz, which is no whole multiple of it (the setpoint's "
                         f"switching instants would fall between its samples); give --rate "
                         f"{rate:g} or a whole fraction of it")


def _profiles(args: argparse.Namespace):
    """The setpoint and the carry-over setpoint (None unless a compensation learns),
    each checked against the exposure window and ``--rate``, and the warnings of a rate that
    stretches them."""
    learns = {"ilc", "basis"} & set(args.compensation or ["ilc"])
    try:
        profile = _profile(args, args.length, args.speed)
        stretched = [_check_rate_resolves(args, args.length, args.speed, profile)]
        other = None
        if learns:
            length, speed = args.other_length or args.length, args.other_speed or 0.5 * args.speed
            other = _profile(args, length, speed)
            stretched.append(_check_rate_resolves(args, length, speed, other, "carry-over "
                                                  "setpoint (--other-length, --other-speed)"))
    except ValueError as exc:
        raise UsageError(f"{PROG}: {exc}") from None
    for p in (profile, other):
        if p is not None:
            p.check_window(args.window)
    return profile, other, [w for w in stretched if w]


def _check_ilc_cutoff(cutoff: float | None, step: float) -> None:
    """Refuse an ``--ilc-cutoff`` (`cutoff`, None where not given) above the Nyquist frequency
    of the run's samples (a time step of `step`): the robustness filter ``Q`` would be above
    one half at every frequency a trial has, its corner beyond them all, and no longer bound
    the improper ``1 / PS`` it is there for (:mod:`motionhyst.scan.ilc`)."""
    nyquist = 0.5 / step
    if cutoff is not None and cutoff > nyquist:
        raise UsageError(f"{PROG}: --ilc-cutoff {cutoff:g} Hz is above {g(nyquist)} Hz, the "
                         f"Nyquist frequency of the run's samples (a step of {g(step)} s): the "
                         f"robustness filter Q would pass every frequency of a trial (its "
                         f"corner beyond them all); give a corner below it (default "
                         f"{ILC_DEFAULTS['ilc_cutoff']:g} Hz)")


def _check_steps(args: argparse.Namespace, sc, profile, other, out=None,
                 cutoff: float | None = None) -> None:
    """Refuse a scan of far too many time steps, or of too much work (a link of many
    elements), before its loop is built: the step is the loop's own where its coefficients
    give its poles (:func:`pole_step`; an unstable loop is refused there), else at most the
    sampled controller's period or the setpoint's (:func:`longest_step`).  An exposure window
    that holds one of those steps, a ``--time-series`` (`out`) that does not fit where it
    is written, and an ``--ilc-cutoff`` (`cutoff`) above the run's Nyquist frequency, are
    refused too."""
    from motionhyst.scan.profiles import check_window_samples
    from motionhyst.time.steps import (
        check_scan_steps,
        check_steps_work,
        longest_step,
        pole_step,
    )

    controller = sc.model.controller
    if controller is None:  # no loop: the scenario's own refusal comes first
        return
    rate = getattr(controller, "sample_rate_hz", None)
    pole = sc.fastest_pole()  # None when sampled: its loop is checked all the same
    runs = len(args.compensation or (["none", "model", "ilc", "basis"] if _model_given(args, sc)
                                     else ["none", "ilc", "basis"]))  # as run() compares
    for p in (profile, other):
        if p is not None:
            step = (longest_step(p.max_frequency_hz, None if rate is None else 1.0 / rate)
                    if pole is None else pole_step(pole, p.max_frequency_hz))
            remedy = REMEDY
            if pole is not None and step < 0.999 * longest_step(p.max_frequency_hz):
                # the loop's own pole sets the step: said, and beyond a motion stage's poles
                # the stage's value that makes it so (a unit slip) rather than the setpoint
                cause = fast_pole(sc, pole)
                remedy = (f"the step resolves the loop's fastest closed-loop pole, "
                          f"{g(pole / math.tau)} Hz" + (f" ({cause})" if cause else "")
                          + f"; {REMEDY}")
            n = check_scan_steps(p.end + args.tail, step, runs, remedy, at_least=pole is None)
            if out is not None and p is profile:  # time, r, scan; e, ma, msd of each run
                out.check_csv_size(n, 3 + 3 * runs,
                                   remedy=f"{REMEDY}, or write --time-series where there "
                                   f"is room")
            if pole is not None or rate is not None:  # the run's own step: before the loop
                check_link_damping_for(sc, None if pole is None else step)
            if pole is not None or rate is not None:  # the run's own step: known
                try:
                    check_window_samples(args.window, step, "give a longer --window")
                except ValueError as exc:
                    raise UsageError(f"{PROG}: --window: {exc}") from None
                if p is profile:
                    _check_ilc_cutoff(cutoff, step)
            with in_the_commands_terms(sc, REMEDY):
                check_steps_work(n, (sc.hysteresis(),), REMEDY)


def _check_at(args: argparse.Namespace, sc) -> None:
    """Refuse ``--at`` before the loop is built where the scenario's link (and its
    feedforward model, if any) does not vary along the stroke (the check of :func:`_at`)."""
    from motionhyst.hysteresis.along_stroke import AlongStroke

    if args.at is None or sc.model.controller is None:
        return
    ff = sc.model.feedforward
    if getattr(ff, "hysteresis", None) is None and not isinstance(sc.hysteresis(), AlongStroke):
        raise UsageError(f"{PROG}: --at: a scan's place on the stroke needs a link that varies "
                         f"along it ([hysteresis] along) ({sc.source})")


def _model_given(args: argparse.Namespace, sc) -> bool:
    """Whether the scan has a model compensation's terms (``--feedforward``, else the
    scenario's ``[feedforward]``: the terms of :func:`scan_terms` on its loop), from the
    scenario's sections before the loop is built: without ``--compensation`` a model run is
    compared only then."""
    if args.feedforward is not None:
        return bool(args.feedforward)
    sec = sc.model.feedforward
    return sec is not None and (sec.hysteresis is not None or (
        sec.type != "none" and any(getattr(sec, t, None) for t in TERMS[:-1])))


def _check_model_terms(args: argparse.Namespace, sc) -> None:
    """Refuse, before the loop is built, a model compensation the scenario's ``[feedforward]``
    gives no term for (the checks of :func:`run` once the loop is built, where its section
    alone decides them)."""
    sec = sc.model.feedforward
    if sec is None or sc.model.controller is None:
        return  # no loop: the scenario's own refusal comes first
    if "hysteresis" in (args.feedforward or []) and sec.hysteresis is None:
        raise UsageError(f"{PROG}: --feedforward hysteresis needs a [feedforward] hysteresis "
                         f"model, and {sc.source} has none")
    if args.feedforward is None and "model" in (args.compensation or []) \
            and not _model_given(args, sc):
        raise UsageError(f"{PROG}: --compensation model needs a [feedforward] hysteresis "
                         f"model or feedforward terms (--feedforward), and {sc.source} has none")


def run(args: argparse.Namespace) -> int:
    """Simulate the setpoint with each compensation and print the scan metrics."""
    from motionhyst.scenario import load_scenario

    if not args.back_and_forth and not args.point_to_point:
        refuse_unused(args, ("--dwell",), "without --back-and-forth (the rest before the "
                      "return)", {"--dwell": 0.0})
    if not args.time_series:
        refuse_unused(args, ("--force",), "without --time-series (the only file scan writes)")
    # every check the loop is not needed for comes before it is built (python-control,
    # scipy): a refusal does not wait for them
    sc = load_scenario(args.scenario, check=False)
    cutoff = args.ilc_cutoff  # as given (None: the default), against the run's samples
    _check_options(args)
    _check_rate(args, sc)
    out = _output(args)
    _check_model_terms(args, sc)
    _check_at(args, sc)
    profile, other, stretched = _profiles(args)
    _check_steps(args, sc, profile, other, out, cutoff)
    from motionhyst.core.warnings import warn

    for text in stretched:  # once nothing is refused: a refusal is one line
        warn(text)
    from motionhyst.analysis.plausibility import check_stroke

    check_stroke(args.length, "--length")  # once it is not refused: a refusal is one line
    if other is not None and args.other_length is not None:
        check_stroke(args.other_length, "--other-length")
    loop = sc.loop()
    if cutoff is not None and sc.fastest_pole() is None and loop.sampled is None:
        from motionhyst.time.simulation import default_step  # the step known from the loop

        _check_ilc_cutoff(cutoff, default_step(loop, profile.max_frequency_hz))
    from motionhyst.scan.ilc import ILCFilters
    from motionhyst.scan.scanning import run_scan
    from motionhyst.scan.terms import scan_terms

    warn_plant_fit(sc)
    if args.at is not None:
        loop = _at(loop, args.at, sc.source)
    terms = args.feedforward
    if terms is None:
        unset = [t for t in ("jerk", "snap") if getattr(sc.model.feedforward, t, 0.0) is None]
        terms = scan_terms(loop, unset)
    if "hysteresis" in terms and loop.hysteresis_feedforward is None:
        raise UsageError(f"{PROG}: --feedforward hysteresis needs a [feedforward] hysteresis "
                         f"model, and {sc.source} has none")
    has_model = bool(terms)
    comps = args.compensation or (["none", "model", "ilc", "basis"] if has_model
                                  else ["none", "ilc", "basis"])
    if "model" in comps and not has_model:
        raise UsageError(f"{PROG}: --compensation model needs a [feedforward] hysteresis "
                         f"model or feedforward terms (--feedforward), and {sc.source} has none")
    filters = ILCFilters(args.ilc_gain, args.ilc_cutoff, args.ilc_order)
    release_held()  # the runs start: the warnings so far are shown
    try:
        with in_the_commands_terms(sc, REMEDY):
            res = run_scan(loop, profile, args.window, comps, args.ilc_trials, filters, other,
                           args.settle_tol, args.tail, feedforward=terms,
                           basis_trials=args.basis_trials or BASIS_TRIALS)
    except ValueError as exc:
        if "feedforward" in str(exc) or "inverse" in str(exc) or "P2" in str(exc):
            raise UsageError(f"{PROG}: {exc}") from None
        if str(exc).startswith("the exposure window"):  # a step known once the loop is built
            raise UsageError(f"{PROG}: --window: {exc}") from None
        raise
    if out is not None:
        out.write_csv(res.columns())
    if args.json:
        d = {"scenario": sc.source, **res.to_dict()}
        if out is not None:
            d["time_series"] = str(out.path)
        print_json(d)
        return 0
    print(f"{sc.source}: {res}")
    if out is not None:
        print(f"time series ({len(res.t)} samples) -> {out.path}")
    return 0
