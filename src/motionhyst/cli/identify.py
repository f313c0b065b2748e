"""``motionhyst identify``: Maxwell-slip hysteresis from a measured record (CSV)."""

from __future__ import annotations

import argparse
import math
import warnings
from collections.abc import Sequence
from pathlib import Path

from motionhyst.cli._common import (
    UsageError,
    add_record_options,
    g,
    positive,
    print_json,
    refuse_unused,
    warn_plant_fit,
    whole_number,
)
from motionhyst.cli._identify_io import (
    add_input_output_arguments,
    check_not_input_output,
    refuse_repeated,
    run_input_output,
    save_target,
    search_budget,
)

# the command is the interface (see motionhyst.cli.main); nothing here is a library API
__all__ = []

RECORD_KINDS = {"force-displacement": ("time", "displacement", "force"),
                "closed-loop": ("time", "y1", "u")}
"""CSV columns that identify a record's kind (``motionhyst identify``)."""


_element_count = whole_number(1, 20, "Jenkins elements")


def record_kind(path: str | Path, kind: str | None = None,
                columns: dict[str, str] | None = None) -> str:
    """The kind of a measured record from its columns (a CSV header, a MATLAB file's variables).

    Parameters
    ----------
    path : str or Path
        CSV file with a header row, or MATLAB ``.mat`` file.
    kind : str, optional
        The kind the user asked for (``--record``); checked against the header.
    columns : dict, optional
        The file's names of the columns (``--columns``), as
        :func:`motionhyst.io.records.record_columns` maps them.

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

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst.cli import record_kind
    >>> path = Path(tempfile.mkdtemp()) / "record.csv"
    >>> _ = path.write_text("time,y1,u\\n0.0,0.0,0.0\\n")
    >>> record_kind(path)
    'closed-loop'
    """
    from motionhyst.io.records import record_columns

    names = record_columns(path, columns)
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
    hint = "" if columns else "; map the file's names with --columns NAME=COLUMN,..."
    raise ValueError(f"{path}: unknown record header {','.join(names)!r}; expected "
                     f"{expected}{hint}")


def feedforward_fragment(k: Sequence[float], fc: Sequence[float]) -> str:
    """A ``[feedforward]`` section with the identified hysteresis, ready to paste (TOML).

    One element is written as ``model = "jenkins"`` with scalars, more as
    ``model = "maxwell-slip"`` with lists (as
    :meth:`motionhyst.identify.Identification.scenario_fragment`).

    Parameters
    ----------
    k : sequence of float
        Stiffnesses of the identified elements [N/m].
    fc : sequence of float
        Their slip forces [N].

    Examples
    --------
    >>> from motionhyst.cli import feedforward_fragment
    >>> print(feedforward_fragment([10.0, 6.0], [0.01, 0.03]))
    [feedforward]
    type = "rigid-body"   # u_ff = M r'' + phi_hat(r)
    hysteresis = { model = "maxwell-slip", k = [10.0, 6.0], fc = [0.01, 0.03] }
    <BLANKLINE>
    """
    from motionhyst.core.textfiles import toml_table

    link = ({"model": "jenkins", "k": k[0], "fc": fc[0]} if len(k) == 1
            else {"model": "maxwell-slip", "k": list(k), "fc": list(fc)})
    return toml_table("feedforward", {"type": "rigid-body", "hysteresis": link},
                      comments={"type": "u_ff = M r'' + phi_hat(r)"}, digits=7)


def run(args: argparse.Namespace) -> int:
    """Identify Maxwell-slip hysteresis from a measured record (CSV)."""
    if args.save is None:
        refuse_unused(args, ("--force",), "without --save (the only file identify writes)")
    _refuse_a_record_twice([Path(p) for p in args.data])
    if args.record == "input-output":
        return run_input_output(args)
    check_not_input_output(args, closed_loop=args.record != "force-displacement")
    if args.nu is not None and args.model != "bouc-wen":
        raise UsageError("motionhyst identify: --nu applies to --model bouc-wen only")
    if len(args.data) > 1:
        paths = [Path(p) for p in args.data]
        if any(record_kind(p, args.record, args.columns) != "force-displacement"
               for p in paths):
            raise UsageError("motionhyst identify: several records are read with --record "
                             "input-output, or as force-displacement records (with --model)")
        if args.model is None:
            raise UsageError("motionhyst identify: several force-displacement records are "
                             "fitted together by the force's error: give their link with "
                             "--model (maxwell-slip, dahl, bouc-wen, lugre, ...)")
        check_fd_options(args, paths[0])
        return _run_link_force(args, paths)
    path = Path(args.data[0])
    kind = record_kind(path, args.record, args.columns)
    if kind == "force-displacement":
        check_fd_options(args, path)
    if args.offset in ("output", "both"):
        raise UsageError(f"motionhyst identify: --offset {args.offset}: a closed-loop record's "
                         f"position offset does not enter the link force inferred from it; "
                         f"use --offset auto, input or none")
    if kind == "force-displacement":
        if args.model is not None:
            return _run_link_force(args, [path])
        if args.max_evaluations is not None:
            raise UsageError("motionhyst identify: --max-evaluations applies to input-output "
                             "records and to force-displacement records with --model")
    for option, value in (("--model", args.model), ("--max-evaluations", args.max_evaluations)):
        if value is not None:
            raise UsageError(f"motionhyst identify: {option} applies to input-output and "
                             f"force-displacement records; {path} is a closed-loop record")
    if args.elements is not None and args.criterion is not None:
        raise UsageError("motionhyst identify: --criterion has no effect with --elements (it "
                         "chooses the number of elements)")
    options = {"n_elements": args.elements, "criterion": args.criterion or "rms"}
    extra: dict = {"record": kind, "data": str(path)}
    target = None
    if args.save is not None:  # refused before the work, not after
        if kind != "force-displacement":
            raise UsageError(f"motionhyst identify: --save applies to input-output and "
                             f"force-displacement records; {path} is a closed-loop record")
        target = save_target(args, [path])
    if kind != "force-displacement" and args.scenario is None:
        raise UsageError(f"motionhyst identify: {path} is a closed-loop record: give the "
                         f"loop's plant with --scenario FILE (a [stage], or a measured "
                         f"[plant]); there is no default plant")
    # the record is read and checked by its light reader; the fit engines (python-control,
    # matplotlib, scipy.optimize) are imported once the options and the record are checked
    from motionhyst.identify.records import (
        check_loops_open,
        load_closed_loop_csv,
        load_force_displacement_csv,
    )
    from motionhyst.io.records import check_unread

    if kind == "force-displacement":
        from motionhyst.identify.fd_memory import check_elements_fit_memory

        bound = args.elements is None or target is not None
        check_unread([path], RECORD_KINDS[kind], lambda sizes: check_elements_fit_memory(
            sizes[0], str(path), bound=bound), columns=args.columns)  # a long record: unread
        t, x, w = load_force_displacement_csv(path, columns=args.columns, scale=args.scale)
        measured = [(path, t, x, w)]
        from motionhyst.identify.displacement_noise import estimate_displacement

        x, noise = estimate_displacement(t, x)  # the link's input, as predict estimates it
        extra["displacement_noise"] = noise.to_dict()
        from motionhyst.identify.records import ForceFalls, check_force_follows

        try:  # a force that is noise, or of a sensor reversed: before the mass check and fit
            check_force_follows(x, w, t)
        except ForceFalls as exc:
            _refuse_a_driven_mass(measured)  # a force that drives a mass: said so
            raise ValueError(f"{path}: {exc}") from None
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
    else:
        from motionhyst.identify.fd_memory import check_closed_loop_memory

        check_unread([path], RECORD_KINDS[kind], lambda sizes: check_closed_loop_memory(
            sizes[0], str(path), every=None), columns=args.columns)  # a long record: unread
        t, y1, u = load_closed_loop_csv(path, columns=args.columns, scale=args.scale)
        from motionhyst.identify.records import fit_every, prefilter_cutoff

        try:  # before the plant's scenario loads python-control
            cutoff, settle = prefilter_cutoff(t, y1, args.cutoff)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        # before its link force is inferred: the fit's rows, one every few samples (a record
        # of uniform steps, checked by its reader)
        check_closed_loop_memory(t.size, str(path),
                                 every=fit_every(float(t[-1] - t[0]) / (t.size - 1), cutoff))
        from motionhyst.identify.io_records import IORecord
        from motionhyst.identify.io_response import check_response

        check_response([IORecord(t, u, y1, str(path))])  # y1 of the loop follows u
    share = 0.0  # a force-displacement fit's systematic error, as a share of the force's RMS
    if kind == "force-displacement":
        if args.elements is None or target is not None:  # refused, not reported: at once
            try:
                check_loops_open(x, w, t)
            except ValueError as exc:
                raise ValueError(f"{path}: {exc}") from None
        # the mass check, the bound (where it runs) and the fit, before any of them (after
        # the light checks: its sizes are the fit module's, which loads the fit libraries)
        check_elements_fit_memory(t.size, str(path), bound=args.elements is None
                                  or target is not None)
        # a mass (its stop operators load the compiled kernels: after the light checks)
        mass = _refuse_a_mass(measured)
        from motionhyst.identify.fit import identify_maxwell_slip

        if args.elements is None or target is not None:  # what no fit can pass: before it
            from motionhyst.identify.io_checks import FitFailed

            try:
                _refuse_beyond_bound(path, x, w)
            except FitFailed:
                if mass is not None:  # the cause to name: the mass
                    _refuse_a_mass(measured, refuse=True)
                raise
        if mass is not None:
            from motionhyst.core.warnings import warn

            warn(mass)
        what = "force-displacement record"
        from motionhyst.identify.io_checks import PREDICT_SHARE

        try:  # the fit's warnings on its values wait for its judgement: a refusal is one line
            with search_budget(), warnings.catch_warnings(record=True) as held:
                warnings.simplefilter("always")
                ident = identify_maxwell_slip(x, w, t=t, **options, target_share=(
                    PREDICT_SHARE if args.elements is None else None))
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        _check_determined(path, ident, x, w)
        share = _judge_elements(path, ident, x, w, args.elements is None or target is not None)
        for h in held:
            warnings.warn_explicit(h.message, h.category, h.filename, h.lineno)
        if target is not None:  # the link alone, a system without inertia, for predict
            target.write_text(ident.scenario_text(f"{path}"))
            extra["saved"] = args.save
    else:
        from motionhyst.scenario import load_scenario

        sc = load_scenario(args.scenario, check=False)  # its loop is built below, once checked
        if sc.is_open_loop:
            raise UsageError(f"motionhyst identify: closed-loop records need the plant of a "
                             f"closed loop; {sc.source} is an open-loop system (no "
                             f"[controller]); give a scenario with a two-mass [stage] without "
                             f"output, or identify with --record input-output")
        rate = getattr(sc.model.controller, "sample_rate_hz", None)
        if rate is not None:  # before the sampled loop is built
            from motionhyst.identify.records import check_controller_period

            try:
                check_controller_period(t, 1.0 / rate)
            except ValueError as exc:
                from motionhyst.identify.link_checks import held_rows

                k, first = held_rows(u)  # logged faster than the controller: its rows named
                at = (f" (u is held over {k} rows: take one row in {k}, from row {first + 1})"
                      if k > 1 and abs(k * float(t[1] - t[0]) * rate - 1) < 1e-3 else "")
                raise ValueError(f"{path}: {exc}{at}") from None
        else:  # a sampled controller's staircase read as ramps: no link's force
            from motionhyst.identify.link_checks import check_not_held

            try:
                check_not_held(t, u, f"{sc.source}'s [controller]")
            except ValueError as exc:
                raise ValueError(f"{path}: {exc}") from None
        plant = sc.plant()
        if not plant.is_lti:
            raise UsageError(f"motionhyst identify: closed-loop records need P1 as a model (a "
                             f"[stage], or a [plant] fitted with use = \"fit\"); {sc.source} "
                             f"has a measured [plant] with use = \"data\"")
        try:  # the plant's scales against the record's, before the loop is built
            mechanics = plant.mechanics()
        except ValueError:
            mechanics = None  # a plant without lumped masses: the fit judges the record
        if mechanics is not None:
            from motionhyst.identify.records import check_force_scale

            try:
                check_force_scale(t, y1, u, mechanics, cutoff)
                if rate is None:  # a sampled loop's force is held: its filter is the loop's
                    from motionhyst.identify.link_checks import check_closed_loop_link

                    check_closed_loop_link(t, y1, u, mechanics, cutoff, settle)
            except ValueError as exc:
                raise ValueError(f"{path}: {exc}") from None
        warn_plant_fit(sc)
        extra["scenario"] = sc.source
        # a sampled controller: the record is at its samples, u_k acted held and delayed
        ctrl = sc.loop().sampled
        from motionhyst.identify.closed_loop import identify_closed_loop

        try:
            with search_budget():
                ident = identify_closed_loop(t, y1, u, plant, cutoff_hz=args.cutoff,
                                             controller=ctrl, offset=args.offset or "auto",
                                             **options)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        _check_slips(path, ident, y1)
        what = (f"closed-loop record, plant of {sc.source}, prefilter cut-off "
                f"{g(ident.cutoff_hz)} Hz"
                + ("" if ctrl is None else f", the force held by the controller at "
                   f"{g(ctrl.sample_rate_hz)} Hz, {g(ctrl.delay_samples)} samples late"))
    k = [e["k"] for e in ident.elements]
    fc = [e["fc"] for e in ident.elements]
    if args.json:
        print_json({**ident.to_dict(), **extra})
        return 0
    print(f"Maxwell-slip hysteresis identified from {path} ({what}, {ident.n_samples} samples)")
    print(ident)
    if extra.get("displacement_noise", {}).get("sigma"):
        print(f"  displacement: {extra['displacement_noise']['reason']}")
    from motionhyst.identify.io_checks import SYSTEMATIC_SHARE

    if share > SYSTEMATIC_SHARE:  # an order asked for, not saved: said, not refused
        print(f"  systematic error {100 * share:.2g} % of the force's RMS (beyond its noise): "
              f"{len(k)} element(s) do not describe this record")
    print()
    print("# hysteresis feedforward, to paste into a scenario (replaces its [feedforward];")
    print("# the same inline table is a valid [hysteresis] section to model the link):")
    print(feedforward_fragment(k, fc), end="")
    if target is not None:
        print(f"\nwrote {args.save} (the link without inertia: motionhyst predict gives its "
              f"force for a displacement record)")
    return 0


def _refuse_a_record_twice(paths: list[Path]) -> None:
    """One record given twice (the same file by two names, or two files of identical bytes)
    would count its samples twice: the standard errors sqrt(2) too small.  Refused before any
    reading (files of different sizes differ; equal sizes are compared in blocks)."""
    import os

    seen: dict[tuple[int, int], Path] = {}
    sizes: dict[int, list[Path]] = {}
    for path in paths:
        try:
            st = os.stat(path)
        except OSError:
            continue  # the reader names what is wrong with it
        first = seen.setdefault((st.st_dev, st.st_ino), path)
        if first is not path:
            what = (f"{path} is given twice" if str(first) == str(path)
                    else f"{first} and {path} are the same file")
            raise UsageError(f"motionhyst identify: {what}: a record given twice counts its "
                             f"samples twice (standard errors too small); give each record "
                             f"once")
        if not os.path.isfile(path):
            continue
        for other in sizes.setdefault(st.st_size, []):
            if _same_bytes(other, path):
                raise UsageError(f"motionhyst identify: {other} and {path} hold the same "
                                 f"record byte for byte: a record given twice counts its "
                                 f"samples twice (standard errors too small); give each "
                                 f"record once")
        sizes[st.st_size].append(path)


def _same_bytes(a: Path, b: Path, block: int = 1 << 20) -> bool:
    """Whether the files `a` and `b` (of one size) hold the same bytes."""
    try:
        with open(a, "rb") as fa, open(b, "rb") as fb:
            while True:
                x, y = fa.read(block), fb.read(block)
                if x != y:
                    return False
                if not x:
                    return True
    except OSError:
        return False


def check_fd_options(args: argparse.Namespace, path: Path) -> None:
    """Refuse the options a force-displacement record (`path`) has no use for."""
    if args.offset is not None:
        raise UsageError("motionhyst identify: --offset applies to input-output and closed-loop "
                         "records only (a force-displacement record's offset is always "
                         "estimated)")
    for option, value in (("--scenario", args.scenario), ("--cutoff", args.cutoff)):
        if value is not None:
            raise UsageError(f"motionhyst identify: {option} applies to closed-loop "
                             f"records (time,y1,u) only; {path} is a force-displacement "
                             f"record")


def _run_link_force(args: argparse.Namespace, paths: list[Path]) -> int:
    """Force-displacement records' link of `--model`, with a spring and damper in parallel,
    fitted by the force's error (the records together: one link, each record's own
    displacement offset); printed, optionally saved (a quasi-static system)."""
    if args.criterion is not None:
        raise UsageError("motionhyst identify: --criterion chooses the number of Maxwell-slip "
                         "elements of a fit without --model")
    if args.elements is not None and args.model != "maxwell-slip":
        raise UsageError("motionhyst identify: --elements applies to --model maxwell-slip only")
    target = None
    if args.save is not None:  # refused before the work, not after
        target = save_target(args, paths)
    from motionhyst.hysteresis import model_class
    from motionhyst.identify.fd_memory import check_link_force_memory
    from motionhyst.identify.records import load_force_displacement_csv
    from motionhyst.io.records import check_unread

    nu = None if args.nu in (None, "free") else args.nu

    def check(sizes: list[int]) -> None:
        check_link_force_memory(sizes, model_class(args.model), args.elements or 3, nu)

    # a long record is refused unread
    check_unread(paths, RECORD_KINDS["force-displacement"], check, columns=args.columns)
    records = []
    for path in paths:
        t, x, w = load_force_displacement_csv(path, columns=args.columns, scale=args.scale)
        records.append((path, t, x, w))
    refuse_repeated([(path, t, (x, w)) for path, t, x, w in records])
    _check_forces_follow(records)  # light: before the fit's sizes load its libraries
    check([t.size for _, t, _, _ in records])  # before the mass check and the starts
    from motionhyst.identify.determinacy import check_samples_per_parameter
    from motionhyst.identify.fd_memory import link_force_parameters

    names = ", ".join(str(p) for p in paths)
    try:  # a record too short for the model: no search
        check_samples_per_parameter([t.size for _, t, _, _ in records], link_force_parameters(
            model_class(args.model), args.elements or 3, nu), f"the {args.model} link's fit")
    except ValueError as exc:
        raise ValueError(f"{names}: {exc}") from None
    mass = _refuse_a_mass(records)
    if mass is not None:
        from motionhyst.core.warnings import warn

        warn(mass)
    from motionhyst.identify.io_link_force import identify_link_force
    from motionhyst.identify.io_records import IORecord

    try:
        with search_budget():
            fit = identify_link_force([IORecord(t, w, x, str(p)) for p, t, x, w in records],
                                      model_class(args.model), n_elements=args.elements or 3,
                                      max_evaluations=args.max_evaluations,
                                      nu=nu)
    except (ValueError, RuntimeError) as exc:
        raise type(exc)(f"{names}: {exc}") from None
    result = {**fit.to_dict(), "record": "force-displacement",
              "data": str(paths[0]) if len(paths) == 1 else [str(p) for p in paths]}
    if target is not None:
        target.write_text(fit.scenario_text())
        result["saved"] = args.save
    if args.json:
        print_json(result)
        return 0
    samples = sum(t.size for _, t, _, _ in records)
    what = "record" if len(paths) == 1 else f"{len(paths)} records"
    print(f"{args.model} link with a spring and damper in parallel identified from {names} "
          f"(force-displacement {what}, {samples} samples) by the force's error in "
          f"{fit.seconds:.3g} s")
    print("\n".join(str(fit).splitlines()[1:]))
    if target is not None:
        print(f"\nwrote {args.save} (the link without inertia: motionhyst predict gives its "
              f"force for a displacement record)")
    else:
        print("\n# the identified link, a scenario for motionhyst predict (or give --save):")
        print(fit.scenario_text(), end="")
    return 0


def _check_forces_follow(records: list[tuple]) -> None:
    """Refuse force-displacement records ``(path, t, x, w)`` of which one has a force that
    does not follow its displacement (noise, or a sensor's sign reversed:
    :func:`~motionhyst.identify.records.check_force_follows`, on the displacement the fit
    takes, its sensor's noise estimated), before the mass check and any link's fit: the same
    refusal for every ``--model`` as for the elements' fit (a Dahl link's fit refused white
    noise only after its start)."""
    from motionhyst.identify.displacement_noise import estimate_displacement
    from motionhyst.identify.records import ForceFalls, check_force_follows

    for path, t, x, w in records:
        try:
            check_force_follows(estimate_displacement(t, x)[0], w, t)
        except ForceFalls as exc:
            _refuse_a_driven_mass([(path, t, x, w)])  # a force that drives a mass: said so
            raise ValueError(f"{path}: {exc}") from None
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None


def _refuse_a_mass(records: list[tuple], refuse: bool = False) -> str | None:
    """Force-displacement records ``(path, t, x, w)`` whose force accelerates a mass (a
    fixture, a carriage, or a stage's input-output record, which has the same header) are
    refused before a link is fitted to them; a smaller mass is returned as a warning's line,
    or refused with `refuse`
    (:func:`~motionhyst.identify.fd_inertia.check_no_inertia`: a regression in which the
    link's hysteresis, as stop operators, cannot pose as a mass).  Records whose stamps are
    not uniform are not judged."""
    from motionhyst.identify.fd_inertia import check_no_inertia
    from motionhyst.identify.io_records import IORecord
    from motionhyst.time.resample import check_record

    uniform = []
    for path, t, x, w in records:
        try:
            check_record(t, w)
        except ValueError:
            return None
        uniform.append(IORecord(t, w, x, str(path)))
    return check_no_inertia(uniform, refuse)


def _refuse_a_driven_mass(records: list[tuple]) -> None:
    """Refuse force-displacement records ``(path, t, x, w)`` whose force falls as the
    displacement rises because it drives a mass
    (:func:`~motionhyst.identify.fd_inertia.driven_mass`): a stage's input-output record,
    which has the same header, read by default as force-displacement; its refusal named a
    sensor's sign ("--scale force=-1"), and following it led to two more refusals, none
    naming --record input-output.  Records whose stamps are not uniform are not judged."""
    from motionhyst.identify.fd_inertia import driven_mass
    from motionhyst.identify.io_records import IORecord
    from motionhyst.time.resample import check_record

    for _, t, _, w in records:
        try:
            check_record(t, w)
        except ValueError:
            return
    found = driven_mass([IORecord(t, w, x, str(path)) for path, t, x, w in records])
    if found is not None:
        m, _, share = found
        raise ValueError(f"{records[0][0]}: no hysteresis found: the force falls as the "
                         f"displacement rises as a force that drives a mass does (the "
                         f"record's inverse dynamics: a mass of about {m:.2g} kg, its force "
                         f"m x'' {100 * share:.2g} % of the force's RMS): a stage's "
                         f"input-output record (force in, position out)? identify its mass "
                         f"and link with --record input-output (--plant mass-damper or "
                         f"mass-spring-damper); nothing identified")


def _check_determined(path: Path, ident, x, w) -> None:
    """No answer from a record without hysteresis: when a spring explains the force as well
    as the elements within the noise (:func:`~motionhyst.identify.io_checks.hysteresis_gain`),
    or when no element of the fit slips in the record (each one's slip displacement fc/k
    reaches :data:`SLIP_SHARE` of half the record's displacement range: its fc is not
    determined, any larger one fits as well, whatever its standard error says), the force
    follows the displacement as a spring's, or is noise, and a slip force would be a guess.
    (An element that never slips beside others that do is the model's parallel spring: kept,
    its fc "not determined" in the table.)"""
    import numpy as np

    from motionhyst.identify.io_checks import NO_HYSTERESIS_GAIN, hysteresis_gain

    half = 0.5 * float(x.max() - x.min())
    never = [e for e in ident.elements if e["fc"] / e["k"] >= SLIP_SHARE * half]
    for e in never:  # pinned at the record's end by the fit, not found in it
        e["fc_std"] = math.inf
    if never and ident.covariance is not None and ident.n_elements > 1:  # nor saved as one
        from motionhyst.identify.io_uncertainty import covariance_table

        names = ident.covariance["parameters"]
        std = {n: None if n in {f"fc[{ident.elements.index(e)}]" for e in never} else 1.0
               for n in names}
        ident.covariance = covariance_table(names, np.array(ident.covariance["matrix"]), std)
    # a spring (and offset) by least squares: what the elements explain beyond it, in noise
    # variances (the smallest slip displacement can fall short of the half-range by noise)
    A = np.column_stack([x, np.ones_like(x)])
    linear = w - A @ np.linalg.lstsq(A, w, rcond=None)[0]
    gain = hysteresis_gain(float(np.sum(linear ** 2)),
                           w - ident.predict(x, ident.initial_forces))
    if gain < NO_HYSTERESIS_GAIN:
        raise ValueError(
            f"{path}: no hysteresis in the record: a spring explains its force as well as "
            f"{ident.n_elements} Maxwell-slip element(s), within the noise (they explain "
            f"{max(gain, 0.0):.3g} times the noise's variance more, below "
            f"{NO_HYSTERESIS_GAIN:g}; R^2 = {ident.r2:.3g}): a slip force would be a guess; "
            f"nothing identified (a record whose displacement makes the link slip, a larger "
            f"amplitude, may)")
    if never and len(never) == len(ident.elements):
        e = min(never, key=lambda e: e["fc"] / e["k"])
        spring = float(np.linalg.lstsq(A, w, rcond=None)[0][0])
        raise ValueError(
            f"{path}: no hysteresis in the record: no element slips in it (the smallest slip "
            f"displacement fitted, fc/k = {g(e['fc'] / e['k'])} m, reaches "
            f"{100 * SLIP_SHARE:g} % of the record's half-range {g(half)} m, where any larger "
            f"fc fits as well; R^2 = {ident.r2:.3g}): the force follows the displacement as a "
            f"spring's (k = {g(spring)} N/m), or is noise, and a slip force would be a guess; "
            f"nothing identified (a record whose displacement makes the link slip, a larger "
            f"amplitude, may)")


def _check_slips(path: Path, ident, y1) -> None:
    """No answer from a closed-loop record whose inferred link force shows no hysteresis:
    when no element both slips in the record (its slip displacement fc/k short of half the
    range of y1) and has a slip force the record determines (its standard error below the
    value), the elements are a spring or noise: the inferred force follows y1 as a spring's
    (y1 not in metres, columns swapped, a plant that is not the record's), or is noise."""
    import numpy as np

    half = 0.5 * float(np.ptp(y1))
    judged = [ident.judged_std.get(f"fc[{i}]", e["fc_std"])  # white residuals' std
              for i, e in enumerate(ident.elements)]
    shown = [e for e, s in zip(ident.elements, judged, strict=True)
             if e["fc"] / e["k"] < SLIP_SHARE * half and s < e["fc"]]
    if not shown:
        e = min(ident.elements, key=lambda e: e["fc"] / e["k"])
        std = (f"+- {g(e['fc_std'])} N" if math.isfinite(e["fc_std"])
               else "N, its standard error not determined")
        raise ValueError(
            f"{path}: no hysteresis in the record: no element both slips in it and has a slip "
            f"force the record determines (the smallest slip displacement fitted, fc/k = "
            f"{g(e['fc'] / e['k'])} m against y1's half-range {g(half)} m; fc {g(e['fc'])} "
            f"{std}): the link force inferred through the plant follows y1 as a "
            f"spring's, or is noise (y1 not in metres? u and y1 swapped? the plant not the "
            f"record's?); nothing identified")


SLIP_SHARE = 0.99
"""An element slips in a record when its slip displacement fc/k is short of this share of
half the record's displacement range (one at the range's end is a spring there)."""


def _refuse_beyond_bound(path: Path, x, w) -> None:
    """Refuse, before the fit, a force-displacement record that no number of Maxwell-slip
    elements describes: when even the best of them leave more systematic error
    (:func:`~motionhyst.identify.fd_bound.systematic_share_bound`, a lower bound) than a fit may
    (:data:`~motionhyst.identify.io_checks.PREDICT_SHARE`), the fit would end in
    :func:`_judge_elements`'s refusal after its work.  The checks that name another cause
    (no hysteresis, a sensor's sign reversed) stay the fit's: the bound leaves them alone."""
    from motionhyst.identify.fd_bound import systematic_share_bound
    from motionhyst.identify.fd_memory import bound_columns
    from motionhyst.identify.io_checks import PREDICT_SHARE, FitFailed

    bound = systematic_share_bound(x, w, max_columns=bound_columns(x.size))
    if bound > PREDICT_SHARE:
        raise FitFailed(f"{path}: no Maxwell-slip elements describe this record: any number "
                        f"of them leave a systematic error of at least {100 * bound:.2g} % of "
                        f"the force's RMS (above {100 * PREDICT_SHARE:g} %, beyond the "
                        f"noise) and would predict another record of this link below 95 %; a link "
                        f"with a spring and damper in parallel may (--model dahl, bouc-wen or "
                        f"lugre); nothing identified")


def _judge_elements(path: Path, ident, x, w, refuse: bool) -> float:
    """The systematic share of a force-displacement fit's error
    (:func:`~motionhyst.identify.io_checks.systematic_share`); above
    :data:`~motionhyst.identify.io_checks.PREDICT_SHARE` a failed fit where `refuse` (the
    order chosen by the criterion, or a model to save): elements that do not describe the
    record predict another one of the same link below 95 %; a number of elements the user
    fixed, shown and not saved, is a warning there up to
    :data:`~motionhyst.identify.io_checks.SYSTEMATIC_SHARE`
    (:func:`~motionhyst.identify.io_quasi_static_checks.systematic_warning`)."""
    from motionhyst.identify.io_checks import (
        PREDICT_SHARE,
        SYSTEMATIC_SHARE,
        FitFailed,
        systematic_share,
    )

    share = systematic_share(w - ident.predict(x, ident.initial_forces), w)
    if share > PREDICT_SHARE and refuse:
        raise FitFailed(f"{path}: the fit failed: {ident.n_elements} Maxwell-slip element(s) "
                        f"leave a systematic error of {100 * share:.2g} % of the force's RMS "
                        f"(above {100 * PREDICT_SHARE:g} %, beyond the noise): they do not "
                        f"describe this link and would predict another record of it below "
                        f"95 %{'' if ident.order_stop is None else f' ({ident.order_stop})'}; "
                        f"more --elements than {ident.n_elements} or a link with a spring and "
                        f"damper in parallel may (--model dahl, bouc-wen or lugre); nothing "
                        f"saved")
    if share <= SYSTEMATIC_SHARE:  # above, the record's own checks name the cause (a mass)
        from motionhyst.core.warnings import warn
        from motionhyst.identify.io_quasi_static_checks import systematic_warning

        line = systematic_warning(share, "force", f"more --elements than {ident.n_elements}, "
                                  f"or a link with a spring and damper in parallel (--model "
                                  f"dahl, bouc-wen or lugre), may describe it better")
        if line is not None:
            warn(f"{path}: {line}")
    return share


def add_parser(sub) -> None:
    """Add the ``identify`` command to the subparsers `sub`."""
    q = sub.add_parser("identify", help="identify Maxwell-slip hysteresis from a measured "
                       "record (CSV)")
    q.add_argument("data", metavar="DATA.csv", nargs="+",
                   help="record, CSV with a header or MATLAB .mat: time,displacement,force "
                        "(force-displacement) or time,y1,u (closed-loop) [SI units]; with "
                        "--record input-output one or more records time,force,displacement "
                        "(force in, position out; time stamps within 0.05 of a step of a "
                        "uniform grid)")
    add_record_options(q, "the record's columns", "time=t,force=vir,displacement=qm")
    q.add_argument("--elements", type=_element_count, metavar="N",
                   help="number of Jenkins elements (default: chosen by --criterion; "
                        "input-output records: 3, fewer where the records do not determine "
                        "them or an element runs stiffer than they resolve, said on stderr "
                        "with the cause)")
    q.add_argument("--cutoff", type=positive, metavar="HZ",
                   help="closed-loop records: cut-off of the prefilter through which the link "
                        "force is inferred [Hz] (default: 20 times the record's fundamental, "
                        "at most a twentieth of the sampling rate)")
    q.add_argument("--record", choices=[*RECORD_KINDS, "input-output"],
                   help="the record's kind, where its header has the columns of both "
                        "(default: from the header); input-output: identify the stage and its "
                        "link jointly from force and position (grey box, simulation error)")
    add_input_output_arguments(q)
    q.add_argument("--criterion", choices=["rms", "bic"],
                   help="force-displacement and closed-loop records: model-order criterion "
                        "when --elements is not given (default: rms)")
    q.add_argument("--scenario", metavar="FILE",
                   help="scenario TOML whose [stage] gives P1 for closed-loop records "
                        "(required for them)")
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run)
