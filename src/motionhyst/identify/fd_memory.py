"""Memory of identify's force-displacement routes, estimated before they run.

A force-displacement record (displacement imposed, force measured) is fitted by one of two
routes, each sized here from the record's samples alone and refused above the memory budget
(:func:`motionhyst.core.budget.check_memory`, ``--max-memory``) before any of its work:

* Maxwell-slip elements by non-negative least squares (``identify`` without ``--model``):
  the check that the loops open (:func:`~motionhyst.identify.records.check_loops_open`), the
  bound of what any elements leave (:func:`~motionhyst.identify.fd_bound.systematic_share_bound`:
  at most :data:`~motionhyst.identify.fd_bound.BOUND_COLUMNS` stop operators on
  :data:`~motionhyst.identify.fd_bound.BOUND_ROWS` samples) and the fit (its operators on at most
  :data:`~motionhyst.identify.records.MAX_ROWS` samples), one after the other: the largest of
  them counts (:func:`elements_fit_memory`).
* A link with a spring and damper in parallel fitted by the force's error (``--model``:
  Maxwell-slip, Dahl, LuGre, Bouc-Wen, ...;
  :func:`~motionhyst.identify.io_link_force.identify_link_force`), and a quasi-static
  stage's input-output records: a least-squares search whose Jacobian of all samples x
  parameters is held :data:`~motionhyst.identify.io_start.JACOBIAN_COPIES` times, after the
  elements' fit it starts from (:func:`link_force_memory`).

The figures per sample and per row are measured (address space above a warmed-up process,
``VmPeak``, one BLAS thread, the record's reading included): a record of 2e4 samples fitted
without ``--model`` took 66 MB of 92 estimated, 1e5 samples 177 MB of 215; with ``--model
dahl`` 74 MB of 78 and 182 MB of 215.
"""

from __future__ import annotations

from motionhyst.core.budget import check_memory, format_size

__all__ = ["BOUND_COPIES", "CLOSED_LOOP_BYTES", "CLOSED_LOOP_ROW_BYTES", "FIT_ROW_BYTES",
           "LOOP_BYTES", "MIN_BOUND_COLUMNS", "RECORD_BYTES", "bound_columns",
           "check_closed_loop_memory", "check_elements_fit_memory", "check_link_force_memory",
           "elements_fit_memory", "link_force_memory", "link_force_parameters"]

FIT_ROW_BYTES = 3500
"""Bytes of the Maxwell-slip fit per row of its residual (its 40 stop operators and their
copies; measured 2980 at 2e4 and 5e4 rows)."""

LOOP_BYTES = 216
"""Bytes per sample of the check that the record's loops open (measured 192-200)."""

RECORD_BYTES = 400
"""Bytes per sample held through a fit besides its own arrays: the record as read and its
columns, the displacement the fit uses, its prediction and residuals (measured: the
Maxwell-slip fit of 1e5 samples took 17.9 MB beyond its rows' share)."""

BOUND_COPIES = 7
"""Copies of the bound's samples x stop operators held at once at most (the operators of
one refinement and the neighbours they are compared with, or at its end the columns, their
matrix, its centred copy and the non-negative least squares' own)."""

MIN_BOUND_COLUMNS = 300
"""Fewest stop operators of the bound's refinement within a small budget (its first grid
holds up to 49; a hundred leave no bound on a record of a Jenkins element and a damper that
three hundred bound at 0.079 of its 0.094)."""

CLOSED_LOOP_BYTES = 500
"""Bytes per sample of a closed-loop record's link force, inferred through the stage and the
prefilter (:func:`~motionhyst.identify.closed_loop.infer_link_force`), besides the fit's rows
(:data:`CLOSED_LOOP_ROW_BYTES`), its elements fitted on every q-th sample
(:func:`~motionhyst.identify.records.fit_every`) up to
:data:`~motionhyst.identify.records.MAX_ROWS` rows."""

CLOSED_LOOP_ROW_BYTES = 3300
"""Bytes per row of a closed-loop record's Maxwell-slip fit.  With :data:`CLOSED_LOOP_BYTES`,
measured on the paper's loop at 5 kHz, default cut-off (q = 2 or 3), address space above a
warmed process: a two-element link 30.9-34.7 MB at 2e4 samples, 57.8 MB at 5e4 (2600 bytes a
row would say 36 and 68.3; a row a sample, 600 and 3500 bytes, said 82 and 118); a
six-element link's wider Jacobian 36.1 MB at 2e4, above 2600 bytes' 36: 3300 leave a margin
for the elements the order search may reach (43 MB at 2e4)."""

LINK_SAMPLE_BYTES = 160
"""Bytes per sample of one evaluation of a link fitted by the force's error besides its
Jacobian (the link's run, its force and residuals, the forward difference's)."""


def bound_columns(n_samples: int) -> int:
    """The most stop operators the bound of what any Maxwell-slip elements leave
    (:func:`~motionhyst.identify.fd_bound.systematic_share_bound`) may hold within the memory
    budget: :data:`~motionhyst.identify.fd_bound.BOUND_COLUMNS`, fewer within a small one (a
    bound that allows for a coarser interval, lower), at least :data:`MIN_BOUND_COLUMNS`.

    Parameters
    ----------
    n_samples : int
        The record's samples.

    Returns
    -------
    int

    Examples
    --------
    >>> from motionhyst.core.budget import set_max_memory
    >>> set_max_memory(200 << 20)
    >>> bound_columns(100_000)
    606
    >>> set_max_memory(None)
    """
    from motionhyst.core.budget import max_memory
    from motionhyst.identify.fd_bound import BOUND_COLUMNS, BOUND_ROWS

    n = int(n_samples)
    room = max_memory() - RECORD_BYTES * n
    fit = int(room / (8.0 * BOUND_COPIES * max(min(n, BOUND_ROWS), 1)))
    return max(MIN_BOUND_COLUMNS, min(BOUND_COLUMNS, fit))


def elements_fit_memory(n_samples: int, columns: int = MIN_BOUND_COLUMNS) -> dict[str, float]:
    """Bytes the Maxwell-slip fit of a force-displacement record of `n_samples` needs at
    most, by phase (they run one after the other; the record is held throughout).

    Parameters
    ----------
    n_samples : int
        The record's samples.
    columns : int
        The bound's most stop operators (:func:`bound_columns`).

    Returns
    -------
    dict
        ``loops`` (the check that the loops open), ``bound`` (the bound of what any
        elements leave), ``fit`` and the ``total``, the largest of them [bytes].

    Examples
    --------
    >>> need = elements_fit_memory(100_000, 2000)
    >>> {k: round(v / 1e6) for k, v in need.items()}
    {'loops': 62, 'bound': 600, 'fit': 215, 'total': 600}
    """
    from motionhyst.identify.fd_bound import BOUND_ROWS
    from motionhyst.identify.records import MAX_ROWS

    n = int(n_samples)
    record = RECORD_BYTES * n
    phases = {"loops": record + LOOP_BYTES * n,
              "bound": record + 8.0 * BOUND_COPIES * min(n, BOUND_ROWS) * int(columns),
              "fit": record + FIT_ROW_BYTES * min(n, MAX_ROWS)}
    return {**phases, "total": max(phases.values())}


def check_elements_fit_memory(n_samples: int, name: str, bound: bool = True) -> None:
    """Refuse the Maxwell-slip fit of a force-displacement record above the memory budget,
    before any of its work (:func:`elements_fit_memory`, the bound with the fewest stop
    operators: it runs with as many as the budget holds, :func:`bound_columns`).

    Parameters
    ----------
    n_samples : int
        The record's samples.
    name : str
        The record, as messages name it.
    bound : bool
        The bound runs before the fit (not for a number of elements asked for, unsaved).

    Raises
    ------
    BudgetError
        One line: the fit, what it needs and what takes it, the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> set_max_memory(1 << 20)
    >>> try:
    ...     check_elements_fit_memory(2000, "fd.csv")
    ... except BudgetError as exc:
    ...     print(exc)
    fd.csv: the Maxwell-slip fit of 2000 samples needs 34.4 MB, above the memory budget of \
1.05 MB (--max-memory); the bound of what any elements leave takes 34.4 MB, the fit 7.8 MB, \
the check that its loops open 1.23 MB: a larger --max-memory if the machine has it, or a \
shorter record
    >>> set_max_memory(None)
    """
    need = elements_fit_memory(n_samples)
    parts = sorted(((need["fit"], "the fit"), (need["loops"], "the check that its loops open"),
                    *([(need["bound"], "the bound of what any elements leave")] if bound
                      else [])), reverse=True)
    takes = ", ".join(f"{part} {'takes ' if i == 0 else ''}{format_size(size)}"
                      for i, (size, part) in enumerate(parts))
    check_memory(parts[0][0], f"{name}: the Maxwell-slip fit of {int(n_samples)} samples",
                 f"{takes}: a larger --max-memory if the machine has it, or a shorter record")


def link_force_memory(sizes: list[int], parameters: int) -> dict[str, float]:
    """Bytes a link with a spring and damper in parallel fitted to records of `sizes`
    samples by a least-squares search of `parameters` variables needs at most.

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    parameters : int
        The search's variables (the Jacobian's columns).

    Returns
    -------
    dict
        ``starts`` (the elements' fit of the records joined, a start of the search),
        ``search`` (its Jacobian's copies and an evaluation) and the ``total``, the
        larger [bytes].

    Examples
    --------
    >>> need = link_force_memory([100_000], 6)
    >>> {k: round(v / 1e6) for k, v in need.items()}
    {'starts': 215, 'search': 85, 'total': 215}
    """
    from motionhyst.identify.io_start import JACOBIAN_COPIES

    n = sum(int(s) for s in sizes)
    starts = elements_fit_memory(n)["fit"]
    search = (RECORD_BYTES + LINK_SAMPLE_BYTES) * n + JACOBIAN_COPIES * 8.0 * n * parameters
    return {"starts": starts, "search": search, "total": max(starts, search)}


def link_force_parameters(link: type, n_elements: int = 3, nu: float | None = None,
                          n_records: int = 1, output_offsets: bool = False) -> int:
    """The parameters a link's fit by the force's error estimates: the spring and damper in
    parallel, the link's, the force's offset (and each record's position offset).

    Parameters
    ----------
    link : type
        The link's model class.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    nu : float, optional
        A Bouc-Wen link's exponent, fixed; None: estimated (a variable more).
    n_records : int
        The records.
    output_offsets : bool
        Each record's position offset is estimated too.

    Returns
    -------
    int
        The parameters.

    Examples
    --------
    >>> from motionhyst.hysteresis import Dahl, LuGre
    >>> link_force_parameters(Dahl), link_force_parameters(LuGre)
    (6, 8)
    """
    from motionhyst.hysteresis import BoucWen
    from motionhyst.identify.io_bouc_wen_shape import BoucWenShape
    from motionhyst.identify.io_layout import LinkLayout

    layout = (BoucWenShape.of_exponent(nu) if link is BoucWen
              else LinkLayout.of(link, n_elements))  # the search's, with k, c and offsets
    return 2 + len(layout.names) + 1 + (n_records if output_offsets else 0)


def check_link_force_memory(sizes: list[int], link: type, n_elements: int = 3,
                            nu: float | None = None, what: str = "force-displacement",
                            output_offsets: bool = False) -> None:
    """Refuse a link's fit by the force's error (or a quasi-static stage's input-output
    search) above the memory budget, before any of its work (:func:`link_force_memory`).

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    link : type
        The link's model class.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    nu : float, optional
        A Bouc-Wen link's exponent, fixed; None: estimated (a variable more).
    what : str
        The records' kind, as the message names them.
    output_offsets : bool
        Each record's position offset is estimated too (the force's always is).

    Raises
    ------
    BudgetError
        One line: the search, what it needs and what takes it, the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> from motionhyst.hysteresis import Dahl
    >>> set_max_memory(10 << 20)
    >>> try:
    ...     check_link_force_memory([20_000, 20_000], Dahl)
    ... except BudgetError as exc:
    ...     print(exc)
    identify's dahl fit of 2 force-displacement records (40000 samples, 6 parameters) needs \
156 MB, above the memory budget of 10.5 MB (--max-memory); its search's Jacobian and runs \
take 33.9 MB, the elements' fit it starts from 156 MB: a larger --max-memory if the machine \
has it, or shorter records
    >>> set_max_memory(None)
    """
    parameters = link_force_parameters(link, n_elements, nu, len(sizes), output_offsets)
    need = link_force_memory(sizes, parameters)
    n = sum(int(s) for s in sizes)
    article = "an" if what[:1] in "aeiou" else "a"
    records = f"{len(sizes)} {what} records" if len(sizes) > 1 else f"{article} {what} record"
    check_memory(need["total"],
                 f"identify's {link.name} fit of {records} ({n} samples, {parameters} "
                 f"parameters)",
                 f"its search's Jacobian and runs take {format_size(need['search'])}, the "
                 f"elements' fit it starts from {format_size(need['starts'])}: a larger "
                 f"--max-memory if the machine has it, or shorter records")


def check_closed_loop_memory(n_samples: int, name: str, every: int | None = 1) -> None:
    """Refuse the Maxwell-slip fit of a closed-loop record above the memory budget, before
    its link force is inferred (:data:`CLOSED_LOOP_BYTES` a sample and
    :data:`CLOSED_LOOP_ROW_BYTES` a row of the fit, one every `every` samples).

    Parameters
    ----------
    n_samples : int
        The record's samples.
    name : str
        The record, as messages name it.
    every : int or None
        Samples between the fit's rows (:func:`~motionhyst.identify.records.fit_every`,
        from the record's sampling interval and its prefilter's cut-off); None where they
        are not known yet (the record unread): its link force alone, what the fit needs at
        least.

    Raises
    ------
    BudgetError
        One line: the fit, what it needs, the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> set_max_memory(20 << 20)
    >>> try:
    ...     check_closed_loop_memory(20_000, "run.csv", every=3)
    ... except BudgetError as exc:
    ...     print(exc)
    run.csv: the Maxwell-slip fit of a closed-loop record of 20000 samples needs 32 MB, \
above the memory budget of 21 MB (--max-memory); its link force takes 10 MB, the fit's rows \
22 MB: a larger --max-memory if the machine has it, or a shorter record
    >>> check_closed_loop_memory(20_000, "run.csv", every=None)       # its link force: 10 MB
    >>> set_max_memory(None)
    """
    n = int(n_samples)
    force = CLOSED_LOOP_BYTES * n
    if every is None:
        check_memory(force, f"{name}: the Maxwell-slip fit of a closed-loop record of {n} "
                     f"samples (its link force)", "a larger --max-memory if the machine has "
                     "it, or a shorter record")
        return
    from motionhyst.identify.records import MAX_ROWS

    rows = CLOSED_LOOP_ROW_BYTES * min(-(-n // max(int(every), 1)), MAX_ROWS)
    check_memory(force + rows, f"{name}: the Maxwell-slip fit of a closed-loop record of {n} "
                 f"samples", f"its link force takes {format_size(force)}, the fit's rows "
                 f"{format_size(rows)}: a larger --max-memory if the machine has it, or a "
                 f"shorter record")
