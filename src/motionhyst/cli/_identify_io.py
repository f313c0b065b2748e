"""``motionhyst identify --record input-output``: the stage and its link from force and position."""

from __future__ import annotations

import argparse
import warnings

from motionhyst.cli._common import UsageError, g, print_json, release_held, table, whole_number


def plant_choices() -> list[str]:
    """``--plant``: the registry's stages (identification simulates each: with inertia, or
    the quasi-static balance); read from the registry, so that ``--help`` imports nothing
    heavy."""
    from motionhyst.plants.registry import stage_types

    return stage_types()


def _nu(text: str) -> float | str:
    """argparse type: a Bouc-Wen exponent >= 1, or ``free`` to estimate it."""
    if text == "free":
        return text
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number >= 1 or 'free', got {text!r}") from None
    if not v >= 1.0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a number >= 1 or 'free', got {text!r}")
    return v


def add_input_output_arguments(q: argparse.ArgumentParser) -> None:
    """The options of input-output identification."""
    from motionhyst.hysteresis import MODELS

    q.add_argument("--plant", choices=plant_choices(),
                   help="input-output records: the stage's model (default mass-spring-damper, "
                        "or mass-damper for records from a start that show no spring, said on "
                        "stderr; mass-damper: a positioning axis, no spring; two-mass: the "
                        "floating "
                        "stage of eqs. 1-2, force and link on m1; quasi-static: no inertia "
                        "(piezo actuators, friction dampers), the link with a parallel spring "
                        "and damper, any --model)")
    q.add_argument("--offset", choices=("auto", "none", "input", "output", "both"),
                   help="input-output records: the offsets estimated with the model: of the "
                        "force (one) and of the position (one per record); default auto: both "
                        "for a floating stage's records from a start (mass-damper, two-mass), "
                        "none for its periodic ones, the position's for a stage on a spring "
                        "(where a force offset is only a position offset), both for a "
                        "quasi-static plant (a force offset moves where on its loops the link "
                        "works); closed-loop records: the force offset, estimated (auto, "
                        "input) or none")
    q.add_argument("--from-rest", action="store_true",
                   help="input-output records: each record starts at rest (default: its "
                        "initial velocity, and position where a spring holds the stage, are "
                        "estimated)")
    q.add_argument("--init-window", type=whole_number(2, 100000, "samples"), metavar="N",
                   help="input-output records: each record's initial state (and a floating "
                        "stage's position offset) is set from its first N samples as the fit "
                        "runs, as predict --init-from --init-window N sets it (the EMPS "
                        "benchmark's convention: 20); only the force offset is estimated")
    q.add_argument("--asymmetric", action="store_true",
                   help="input-output records, --plant mass-damper, an element link: viscous "
                        "friction by direction (the stage's c_skew: c + c_skew forward, "
                        "c - c_skew backward; --model coulomb: its c_pos or c_neg on top of "
                        "the stage's c); the default where the records' inverse dynamics "
                        "shows it (said in a warning)")
    q.add_argument("--symmetric", action="store_true",
                   help="input-output records, --plant mass-damper: one viscous coefficient "
                        "for both directions, even where the records show two")
    q.add_argument("--drift", action="store_true",
                   help="input-output records, --plant mass-damper: the force offset drifts "
                        "in time (a machine warming up): its rate [N/s] over the records' own "
                        "time is estimated with it and saved as the stage's force_drift")
    q.add_argument("--max-evaluations", type=whole_number(10, 100000, "evaluations"), metavar="N",
                   help="input-output records: the search's budget of model evaluations, "
                        "starts and refinement together (default: the starts', then at most "
                        "200 for the refinement); records from a start whose state is "
                        "estimated are refined in stages (from the starts' best, from the "
                        "state their first samples set and, for a link on an axis, from a fit "
                        "on the records' segments, a Coulomb link's also with finer secants), "
                        "each stage with an equal part of what the stages before it left")
    q.add_argument("--output", choices=("y2", "y1"),
                   help="input-output records, --plant two-mass: the measured position, y2 "
                        "(the point of control, default) or y1 (the actuated mass)")
    q.add_argument("--model", choices=list(MODELS),
                   help="input-output records: the link's model (default bouc-wen); "
                        "force-displacement records: the link's model with a spring and "
                        "damper in parallel, fitted by the force's error (default: "
                        "Maxwell-slip elements alone, their number chosen by --criterion)")
    q.add_argument("--periodic", action="store_true",
                   help="input-output records: each record holds whole periods of a periodic "
                        "steady state (default: each is an experiment from rest)")
    q.add_argument("--nu", type=_nu, metavar="NU|free",
                   help="--model bouc-wen: the exponent nu, fixed or 'free' to estimate it "
                        "(input-output records: default 1; --plant quasi-static: by fits of "
                        "nu fixed at 1, 1.5, 2, 3 and around the best; force-displacement "
                        "records: default free, estimated with the rest)")
    q.add_argument("--save", metavar="MODEL.toml",
                   help="input-output records: write the identified system as a scenario "
                        "(read by motionhyst predict); force-displacement records: the link "
                        "as a system without inertia (a quasi-static [stage]), whose force "
                        "predict gives for a displacement record")
    q.add_argument("--force", action="store_true", help="replace the --save file if it exists")


def save_target(args: argparse.Namespace, inputs):
    """The ``--save`` file, checked before the work as every output is (never one of the
    `inputs`), and refused unless its name ends in ``.toml``: the identified model is a
    scenario TOML, which predict, steady and study read by that name."""
    from pathlib import Path

    from motionhyst.io.outputs import OutputFile

    target = OutputFile(args.save, force=args.force, inputs=inputs, option="--save")
    if Path(args.save).suffix.lower() != ".toml":
        raise UsageError(f"motionhyst identify: --save {args.save}: the identified model is "
                         f"written as a scenario TOML (read by predict, steady and study "
                         f"--from-identification); give a name ending in .toml")
    return target


def check_not_input_output(args: argparse.Namespace, closed_loop: bool = False) -> None:
    """One-line error for input-output options given with another record kind (`closed_loop`:
    a closed-loop record, which takes ``--offset`` too; ``--model`` and ``--max-evaluations``
    are checked with the record's kind)."""
    for option, value in (("--plant", args.plant),
                          ("--periodic", args.periodic or None),
                          ("--output", args.output),
                          ("--offset", None if closed_loop else args.offset),
                          ("--from-rest", args.from_rest or None),
                          ("--init-window", args.init_window),
                          ("--asymmetric", args.asymmetric or None),
                          ("--symmetric", args.symmetric or None),
                          ("--drift", args.drift or None)):
        if value is not None:
            raise UsageError(f"motionhyst identify: {option} applies to --record input-output "
                             f"only")


def run_input_output(args: argparse.Namespace) -> int:
    """Identify the stage and its link from input-output records; print, optionally save."""
    for option, value in (("--scenario", args.scenario), ("--cutoff", args.cutoff),
                          ("--criterion", args.criterion)):
        if value is not None:
            raise UsageError(f"motionhyst identify: {option} does not apply to --record "
                             f"input-output")
    plant = args.plant or "mass-spring-damper"
    model = args.model or "bouc-wen"
    from motionhyst.identify.io_memory import IO_MODELS

    if model not in IO_MODELS:  # known from the name: before the records are read
        raise UsageError(f"motionhyst identify: --model {model} is not available for "
                         f"input-output records; use {', '.join(IO_MODELS)}")
    from motionhyst.plants.registry import PLANTS

    if args.output is not None and len(PLANTS[plant].outputs) < 2:
        raise UsageError(f"motionhyst identify: --output applies to --plant two-mass only (a "
                         f"{plant} has one position)")
    if args.elements is not None and model != "maxwell-slip":
        raise UsageError("motionhyst identify: --elements applies to --model maxwell-slip only")
    if args.nu is not None and model != "bouc-wen":
        raise UsageError("motionhyst identify: --nu applies to --model bouc-wen only")
    target = None
    if args.save is not None:  # refused before the work, not after
        target = save_target(args, args.data)
        _check_savable_plant(plant)
    nu = None if args.nu == "free" else (1.0 if args.nu is None else args.nu)
    # on a mass-damper the Bouc-Wen link is a friction link, fitted as the element links
    bouc_wen_own = model == "bouc-wen" and plant not in ("quasi-static", "mass-damper")
    if args.nu == "free" and model == "bouc-wen" and plant == "mass-damper":
        raise UsageError("motionhyst identify: on --plant mass-damper the Bouc-Wen exponent "
                         "is given (--nu NU, default 1), not estimated")
    if bouc_wen_own and (
            args.from_rest or args.init_window is not None
            or args.offset not in (None, "none", "auto", "output")
            or (args.offset == "output" and plant != "mass-spring-damper")):
        raise UsageError("motionhyst identify: --model bouc-wen starts its records at rest "
                         "and estimates only their position offsets (--offset output, on a "
                         "mass-spring-damper); --from-rest, --init-window and the force offset "
                         "apply to the element links and to bouc-wen on --plant mass-damper")
    for option, value in (("--init-window", args.init_window), ("--from-rest", args.from_rest)):
        if value and plant == "quasi-static":
            raise UsageError(f"motionhyst identify: {option} sets a stage's state; a "
                             f"quasi-static plant has none")
    if args.init_window is not None and (args.periodic or args.from_rest):
        raise UsageError("motionhyst identify: --init-window sets the state of records from a "
                         "start; not with --periodic or --from-rest")
    if args.asymmetric and args.symmetric:
        raise UsageError("motionhyst identify: --asymmetric and --symmetric exclude each other")
    if args.symmetric and plant != "mass-damper":
        raise UsageError("motionhyst identify: --symmetric applies to --plant mass-damper")
    if args.asymmetric and plant != "mass-damper":
        raise UsageError("motionhyst identify: --asymmetric applies to --plant mass-damper")
    if args.asymmetric and args.periodic and model != "coulomb":
        raise UsageError("motionhyst identify: --asymmetric with --periodic applies to --model "
                         "coulomb only (the stage's c_skew is run from a start)")
    if args.drift and (plant != "mass-damper" or args.periodic):
        raise UsageError("motionhyst identify: --drift applies to records from a start on "
                         "--plant mass-damper")
    if args.periodic and args.from_rest:
        raise UsageError("motionhyst identify: --from-rest does not apply to --periodic records "
                         "(a steady state has no start)")
    # the records are read and checked by their light reader; the fit engines (python-control,
    # matplotlib, scipy.optimize) are imported once options, output and records are checked
    from motionhyst.hysteresis import model_class
    from motionhyst.identify.io_memory import check_io_floor
    from motionhyst.identify.io_records import check_records, load_io_csv
    from motionhyst.io.records import check_unread
    from motionhyst.plants.registry import plant_class

    # the least search of the records, from their lengths, before any check looks at them (a
    # positioning axis may be chosen from the records below: the smaller of the two counts)
    chosen = (plant_class(plant) if args.plant is not None or args.periodic
              else (plant_class(plant), plant_class("mass-damper")))

    def floor(sizes: list[int]) -> None:
        check_io_floor(sizes, chosen, model_class(model), n_elements=args.elements or 3, nu=nu,
                       periodic=args.periodic, offset=args.offset or "auto",
                       from_rest=args.from_rest, window=args.init_window is not None,
                       drift=args.drift)

    # long records from their files' sizes, unread; then from what was read
    check_unread(args.data, ("time", "force", "displacement"), floor, columns=args.columns)
    records = [load_io_csv(path, columns=args.columns, scale=args.scale) for path in args.data]
    floor([rec.u.size for rec in records])
    check_records(records, args.periodic)  # identify_io checks them again: nothing is skipped
    refuse_repeated([(path, rec.t, (rec.u, rec.y)) for path, rec in zip(args.data, records,
                                                                        strict=True)])
    from motionhyst.identify.io_response import check_response

    check_response(records)  # a position that does not depend on the force: no fit explains it

    notes = []  # warnings, once nothing is refused: a refusal is one line
    if plant_class(plant).has_inertia and not args.periodic:  # as identify_io will, but first
        from motionhyst.identify.io_checks import check_inertia
        from motionhyst.identify.io_consistency import mass_units_note

        # the fit would end at a mass of another unit: said before its search
        notes.append(mass_units_note(records, check_inertia(records)))
    unit_slip = any(note is not None for note in notes)
    if args.plant is None and not args.periodic:  # a positioning axis: no spring to fit
        from motionhyst.identify.io_checks import default_plant

        plant, note = default_plant(records)
        notes.append(note)
        bouc_wen_own = model == "bouc-wen" and plant not in ("quasi-static", "mass-damper")
    checked = plant_class(plant).has_inertia and not args.periodic  # identify_io: not again
    if checked:  # the plant now decided
        from motionhyst.identify.io_consistency import check_one_stage

        check_one_stage(records, floating=plant in ("mass-damper", "two-mass"),
                        single_mass=plant != "two-mass")
    from motionhyst.core.warnings import warn

    for note in notes:
        if note is not None:
            warn(note)
    from motionhyst.identify.input_output import identify_io
    from motionhyst.identify.io_budget import EvaluationBudget

    # the warnings above are shown once the search's plan passes its evaluation budget: a
    # refusal of the plan (a --max-evaluations below its least) is one line
    budget = EvaluationBudget(args.max_evaluations, planned=release_held)
    extras = ({"offset": args.offset or "auto", "max_evaluations": budget}
              if bouc_wen_own else
              {"offset": args.offset or "auto", "from_rest": args.from_rest,
               "max_evaluations": budget, "init_window": args.init_window,
               "asymmetric": True if args.asymmetric else (False if args.symmetric else None),
               "drift": args.drift,
               "fewer_elements": args.elements is None, "rigid_limit": True})
    from motionhyst.identify.io_checks import FitFailed

    try:  # the fit's warnings wait for its judgement: a refusal is one line
        with search_budget(release=False), warnings.catch_warnings(record=True) as held:
            warnings.simplefilter("always")
            if unit_slip:  # the fit's own line on the mass's size says it again
                warnings.filterwarnings("ignore", message=r".* kg, outside the usual .* of "
                                        r"motion stages: if the records' units are not SI")
            fit = identify_io(records, model_class(model), periodic=args.periodic, nu=nu,
                              n_elements=args.elements or 3, plant=plant_class(plant),
                              output=args.output, checked=checked, **extras)
    except FitFailed as exc:  # the records it was refused on, named once
        if any(str(path) in str(exc) for path in args.data):
            raise
        raise FitFailed(f"{', '.join(map(str, args.data))}: {exc}") from None
    for h in held:
        warnings.warn_explicit(h.message, h.category, h.filename, h.lineno)
    result = {**fit.to_dict(), "records": fit.records}
    reference = reference_forms(fit, records) if plant == "mass-damper" else []
    if reference:
        result["reference_form"] = reference
    if target is not None:
        text = fit.scenario_text()
        _check_readable(text, fit)
        target.write_text(text)
        result["saved"] = args.save
    if args.json:
        print_json(result)
        return 0
    kind = ("periodic steady state" if fit.periodic else "from rest"
            if args.from_rest or bouc_wen_own
            else f"state set from the first {args.init_window} samples"
            if args.init_window is not None else "initial state estimated")
    stage = (f"Two-mass stage ({args.output or 'y2'} measured)" if plant == "two-mass"
             else "Stage")
    if fit.extra.get("rigid_limit"):
        model = f"{fit.hysteresis.name} link (the {model} link's rigid limit)"
    else:
        model = f"{model} link"
    print(f"{stage} and {model} identified from {len(records)} input-output record(s) "
          f"({kind}) by simulation error in {fit.seconds:.3g} s")
    print(f"  fit RMS {g(fit.fit_rms)} m; {fit.stopping}")
    rows = []
    at_least = ">= " if fit.extra.get("std_lower_bound") else ""  # why: the line below
    for name, value in fit.estimates.items():
        s = fit.std.get(name)
        rows.append([name, g(value, 8), "not identifiable" if s is None else at_least + g(s, 2),
                     "" if s is None or value == 0 else f"{100 * s / abs(value):.2g} %"])
    print()
    print(table(["parameter", "estimate", "std", "std/|value|"], rows))
    if fit.extra.get("std_note"):
        print(f"  {fit.extra['std_note']}")
    if fit.not_identifiable:
        print()
        for name, why in fit.not_identifiable.items():
            print(f"  {name}: {why}")
    for form in reference:
        print()
        print(_reference_line(form, at_least))
    print()
    print(table(["record", "samples", "fit RMS [m]", "output RMS [m]"],
                [[r["name"], str(r["samples"]), g(r["fit_rms"]), g(r["output_rms"])]
                 for r in fit.records]))
    for r, est in zip(fit.records, fit.extra.get("force_noise", []), strict=False):
        if est["sigma"] > 0:  # the model's input without its load cell's white noise
            print(f"  force of {r['name']}: {est['reason']}")
    if args.save is not None:
        print(f"\nwrote {args.save}")
    else:
        print("\n# the identified system, a scenario for motionhyst predict (or give --save):")
        print(fit.scenario_text(), end="")
    return 0


#: The parameters by which a mass-damper's friction differs from one viscous coefficient and a
#: constant force offset (by direction, or an offset drifting in time)
BEYOND_REFERENCE = ("c_skew", "link.c_pos", "link.c_neg", "link.fc_pos", "link.fc_neg",
                    "input_drift")


def refuse_repeated(records: list[tuple]) -> None:
    """Refuse records ``(path, t, columns)`` of which two hold the same samples as read
    (:func:`~motionhyst.identify.record_overlap.repeated_record`: a CSV and a MATLAB file
    of it, the CSV written again with another float format, a part of it cut out), with
    the line of a record given twice by name or byte for byte."""
    from motionhyst.identify.record_overlap import repeated_record

    same = repeated_record([(float(t[-1] - t[0]) / max(t.size - 1, 1), columns)
                            for _, t, columns in records])
    if same is not None:
        i, j, n = same
        raise UsageError(f"motionhyst identify: {records[i][0]} and {records[j][0]} hold the "
                         f"same record as read ({n} samples alike): a record given twice "
                         f"counts its samples twice (standard errors too small); give each "
                         f"record once")


def reference_forms(fit, records) -> list[dict]:
    """A mass-damper fit as one viscous coefficient and a constant force offset, per record.

    With viscous (or Coulomb) friction by direction or a drifting offset, a fit's own force
    offset is near 0 on an axis where a model with one viscous coefficient finds a large one
    (EMPS: 0.05 N against -3.2 N): the even part of the friction, ``(c_pos - c_neg)/2 |q'|``,
    acts as an offset that follows the speed.  On a record's motion it amounts to the
    constant ``(c_pos - c_neg)/2 mean |q'|``; the fit in that form, the form of the
    benchmark's reference model (:func:`~motionhyst.identify.emps_reference.reference_form`,
    standard errors from the fit's covariance), can be set beside such an estimate.

    Parameters
    ----------
    fit : IOIdentificationResult
        A mass-damper's identification.
    records : list of IORecord
        The records it was identified on.

    Returns
    -------
    list of dict
        Per record ``{"record", "parameters": {"c", "fc", "offset"}, "std": {...}}`` (the
        ``offset`` in the sense of ``input_offset``); [] for a fit without such parameters.
    """
    if not any(name in fit.estimates for name in BEYOND_REFERENCE):
        return []
    from motionhyst.identify.emps_reference import fit_parameters, reference_form

    own, std, covariance = fit_parameters(fit)
    forms = []
    for rec in records:
        parameters, errors = reference_form(own, rec, std, covariance)
        forms.append({"record": rec.name,
                      "parameters": {k: parameters[k] for k in ("c", "fc", "offset")
                                     if k in parameters},
                      "std": {k: errors[k] for k in ("c", "fc", "offset") if k in parameters}})
    return forms


def _reference_line(form: dict, at_least: str = "") -> str:
    """One line of :func:`reference_forms`' result (`at_least` ``">= "`` before standard
    errors that are lower bounds)."""
    units = {"c": "N s/m", "fc": "N", "offset": "N"}
    names = {"c": "c", "fc": "link.fc", "offset": "input_offset"}
    parts = []
    for key, value in form["parameters"].items():
        s = form["std"].get(key)
        std = "" if s is None else f" +- {at_least}{g(s, 2)}"
        parts.append(f"{names[key]} {g(value, 4)}{std} {units[key]}")
    return (f"  as one viscous coefficient and a constant force offset on the motion of "
            f"{form['record']}:\n    {', '.join(parts)}")


def _check_readable(text: str, fit) -> None:
    """Refuse to save a model that ``motionhyst predict`` would not read back as it is."""
    import tomllib

    from motionhyst.scenario import Scenario, ScenarioError

    try:
        system = Scenario.from_dict(tomllib.loads(text), "the identified model").open_loop()
    except ScenarioError as exc:
        raise ValueError(f"--save: the identified model cannot be written as a scenario that "
                         f"predict reads ({exc}); nothing saved") from None
    if (system.plant.to_dict() != fit.plant.to_dict()
            or system.hysteresis.to_dict() != fit.hysteresis.to_dict()):
        raise ValueError("--save: the scenario would not give back the identified model; "
                         "nothing saved")


def _check_savable_plant(plant: str) -> None:
    """Refuse --save before the work if a scenario cannot hold this kind of stage."""
    import tomllib

    from motionhyst.core.textfiles import toml_table
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.plants.quasi_static import QuasiStatic
    from motionhyst.scenario import Scenario, ScenarioError
    from motionhyst.time.openloop import MassSpringDamper, TwoMass

    stage = {"mass-damper": MassDamper(1.0, 1.0, 1.0), "mass-spring-damper":
             MassSpringDamper(1.0, 1.0, 1.0),
             "two-mass": TwoMass(1.0, 1.0, 1.0, 1.0, output="y2"),
             "quasi-static": QuasiStatic(1.0, 1.0, 1.0)}[plant]
    text = (toml_table("stage", stage.to_dict())
            + toml_table("hysteresis", {"model": "jenkins", "k": 1.0, "fc": 1.0}))
    try:
        Scenario.from_dict(tomllib.loads(text), "--save").open_loop()
    except ScenarioError as exc:
        raise UsageError(f"motionhyst identify: --save cannot write a {plant} stage yet (a "
                         f"scenario does not read one: {exc})") from None


SEARCH_REMEDY = "give a shorter record or fewer --max-evaluations, or a larger --max-seconds"
"""What a user can change when identify's search runs out of its work budget."""


def search_budget(release: bool = True):
    """The work budget of identify's search, a context around the fit alone: no formula sizes
    a search that stops when it converges, so it is stopped after ``--max-seconds`` of CPU
    time (:func:`motionhyst.core.budget.cpu_time_limit`), exit 2, nothing saved.  The search
    is the command's work: the warnings held while its input was checked are shown as it
    starts (here, or with `release` False where its plan passes: an input-output search's
    evaluation budget, :class:`~motionhyst.identify.io_budget.EvaluationBudget`)."""
    from motionhyst.core.budget import cpu_time_limit, max_seconds

    if release:
        release_held()
    return cpu_time_limit(max_seconds(), "identify", SEARCH_REMEDY)
