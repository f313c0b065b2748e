"""The least an input-output identification needs, from the records' lengths, before its checks.

``identify --record input-output`` checks its records (the inertia they show, their viscous
friction by direction, their best linear approximation) before its search sizes itself from
the start those checks give (:func:`~motionhyst.identify.io_start.check_search_memory`); on
a record of 1e6 samples the checks alone took 640 MB and 3.8 s of CPU before that estimate
refused a small ``--max-memory``.  :func:`check_io_floor` refuses at once, from the records'
samples, the model and the options alone, what no search of them can do within the budget:

* more integration steps than one simulation of the records may take
  (:data:`~motionhyst.identify.io_start.MAX_FINE_SAMPLES`: a stage with inertia runs at least
  :data:`~motionhyst.time.openloop.MIN_SUBSTEPS` steps a sample, every plant and link);
* more memory than the budget for the least search of the records: the element links' at
  the fewest steps a sample and the fewest parameters of the model and its offsets
  (:func:`search_floor`), the Bouc-Wen link's at the fewest steps (:func:`bouc_wen_memory`,
  measured), a quasi-static stage's as a link's fit by the force's error
  (:func:`~motionhyst.identify.fd_memory.check_link_force_memory`).

The search's own estimate, from its start, still follows (it can only be larger).
"""

from __future__ import annotations

from motionhyst.core.budget import RECORDS_REMEDY, BudgetError, format_size, max_memory
from motionhyst.hysteresis import MODELS as REGISTERED

__all__ = ["BOUC_WEN_SAMPLE_BYTES", "BOUC_WEN_STEP_BYTES", "bouc_wen_memory",
           "check_bouc_wen_memory", "check_io_floor", "search_floor"]

BOUC_WEN_STEP_BYTES = 16
"""Bytes per integration step of the Bouc-Wen link's search on a mass-spring-damper: the
records' force upsampled at twice the steps (the midpoints of its Runge-Kutta steps), whole."""

BOUC_WEN_SAMPLE_BYTES = 900
"""Bytes per sample of that search besides: its runs' sensitivities to the seven parameters,
their reordered, scaled and joined copies and the trust-region solver's (measured with 100
evaluations, 20 steps a sample: 13 MB of 24 estimated at 2e4 samples, 101 MB of 122 at
1e5)."""

IO_MODELS = ("bouc-wen", *(name for name in REGISTERED if name not in ("bouc-wen",
                                                                         "maxwell-iwan")))
"""Link models for input-output records (:data:`~motionhyst.identify.input_output.MODELS`):
Bouc-Wen (exact sensitivities) and every other registered model but maxwell-iwan, whose Iwan
element of 256 stop operators makes a simulation too slow for a search.  Here, where the
command checks its options before it reads the records (the fit's module loads scipy)."""

REMEDY = RECORDS_REMEDY
"""What a user can change when the least search of the records is above the budget."""


def search_floor(sizes: list[int], substeps: int, plant: type, link: type, *,
                 n_elements: int = 3, periodic: bool = False, offset: str = "auto",
                 from_rest: bool = False, window: bool = False, drift: bool = False
                 ) -> dict[str, float]:
    """Bytes an element link's input-output search of records of `sizes` samples needs at
    least: :func:`~motionhyst.identify.io_start.search_memory` for the fewest parameters
    the model and its offsets have, the runs' exact sensitivities and one block of fine
    force (a record that repeats a period needs more, and so does a run by forward
    differences).

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    substeps : int
        Integration steps per sample.
    plant : type
        The stage's class (:mod:`motionhyst.plants.registry`).
    link : type
        The link's model class.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    periodic, offset, from_rest, window, drift
        As for :func:`~motionhyst.identify.input_output.identify_io` (`window`: an
        initialisation window is given).

    Returns
    -------
    dict
        ``force``, ``runs``, ``jacobian``, their ``total`` [bytes] and the search's
        ``parameters``.

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> need = search_floor([1_000_000], 20, MassDamper, Jenkins)
    >>> {k: round(v / 1e6) for k, v in need.items() if k != "parameters"}, need["parameters"]
    ({'force': 160, 'runs': 197, 'jacobian': 336, 'total': 693}, 7)
    """
    from motionhyst.identify.io_layout import LinkLayout
    from motionhyst.identify.io_offsets import Extras
    from motionhyst.identify.io_start import JACOBIAN_COPIES
    from motionhyst.time.openloop import FINE_BYTES, SAMPLE_BYTES
    from motionhyst.time.resample import block_samples

    r = int(substeps)
    n_all = sum(int(n) for n in sizes)
    shape = plant(*[1.0] * len(plant.PARAMETERS)).mechanics()
    extras = Extras.choose(offset, floating=shape.floating, periodic=periodic,
                           from_rest=from_rest, n_records=len(sizes), window=window,
                           drift=drift)
    sensitivities = len(plant.PARAMETERS) + len(LinkLayout.of(link, n_elements).names)
    parameters = sensitivities + extras.size
    force = 8.0 * (2 if drift else 1) * sum(r * (int(n) - 1) + 1 for n in sizes)
    block = max(FINE_BYTES * (r * int(n) if periodic else min(int(n) - 1, block_samples(r))
                              * r + 1) for n in sizes)
    runs = block + (SAMPLE_BYTES + 8.0 * sensitivities) * n_all
    jacobian = JACOBIAN_COPIES * 8.0 * n_all * parameters
    return {"force": force, "runs": runs, "jacobian": jacobian,
            "total": force + runs + jacobian, "parameters": parameters}


def bouc_wen_memory(sizes: list[int], substeps: int) -> dict[str, float]:
    """Bytes the Bouc-Wen link's input-output search on a mass-spring-damper needs at most.

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    substeps : int
        Integration steps per sample.

    Returns
    -------
    dict
        ``force`` (upsampled), ``runs`` (their sensitivities and the solver's copies) and
        the ``total`` [bytes].

    Examples
    --------
    >>> need = bouc_wen_memory([100_000], 20)
    >>> {k: round(v / 1e6) for k, v in need.items()}
    {'force': 32, 'runs': 90, 'total': 122}
    """
    n_all = sum(int(n) for n in sizes)
    force = BOUC_WEN_STEP_BYTES * int(substeps) * n_all
    runs = BOUC_WEN_SAMPLE_BYTES * n_all
    return {"force": float(force), "runs": float(runs), "total": float(force + runs)}


def check_bouc_wen_memory(sizes: list[int], substeps: int, least: bool = False) -> None:
    """Refuse the Bouc-Wen link's search on a mass-spring-damper above the memory budget,
    before its starts run (:func:`bouc_wen_memory`).

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    substeps : int
        Integration steps per sample.
    least : bool
        `substeps` are the fewest the search may take (its size at least).

    Raises
    ------
    BudgetError
        One line: the search, what it needs and what takes it, the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> set_max_memory(50 << 20)
    >>> try:
    ...     check_bouc_wen_memory([100_000], 20)
    ... except BudgetError as exc:
    ...     print(exc)
    identify's Bouc-Wen search of 100000 samples (20 integration steps each) needs 122 MB, \
above the memory budget of 52.4 MB (--max-memory); its runs take 90 MB, the upsampled force \
32 MB: a larger --max-memory if the machine has it, or shorter records
    >>> set_max_memory(None)
    """
    need = bouc_wen_memory(sizes, substeps)
    budget = max_memory()
    if need["total"] > budget:
        at_least = "at least " if least else ""
        raise BudgetError(f"identify's Bouc-Wen search of {sum(int(n) for n in sizes)} samples "
                          f"({at_least}{int(substeps)} integration steps each) needs "
                          f"{at_least}{format_size(need['total'])}, above the memory budget of "
                          f"{format_size(budget)} (--max-memory)",
                          f"its runs take {format_size(need['runs'])}, the upsampled force "
                          f"{format_size(need['force'])}: {REMEDY}")


def check_io_floor(sizes: list[int], plant: type | tuple[type, ...], link: type, *,
                   n_elements: int = 3,
                   nu: float | None = None, periodic: bool = False, offset: str = "auto",
                   from_rest: bool = False, window: bool = False, drift: bool = False
                   ) -> None:
    """Refuse at once, from the records' samples, an input-output identification that no
    search of them can run: too many integration steps, or above the memory budget at its
    least (see the module).

    Parameters
    ----------
    sizes : list of int
        Each record's samples.
    plant : type or tuple of type
        The stage's class; several: the one chosen from the records later (the least of
        their searches counts).
    link : type
        The link's model class.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    nu : float, optional
        A Bouc-Wen link's exponent, fixed (None: estimated).
    periodic, offset, from_rest, window, drift
        As for :func:`search_floor`.

    Raises
    ------
    BudgetError
        One line: what the least search needs, the budget, and the remedy.
    ValueError
        One line: more integration steps than a simulation of the records may take.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> try:
    ...     check_io_floor([3_000_000], MassDamper, Jenkins)
    ... except ValueError as exc:
    ...     print(exc)
    identify's search of 3000000 samples runs at least 20 integration steps a sample (6e+07 \
in all), more than 5e+07 in one simulation of the records; give shorter records
    >>> set_max_memory(50 << 20)
    >>> try:
    ...     check_io_floor([1_000_000], MassDamper, Jenkins)
    ... except BudgetError as exc:
    ...     print(exc)
    identify's search of 1000000 samples (at least 20 integration steps each, 7 parameters) \
needs at least 693 MB, above the memory budget of 52.4 MB (--max-memory); its Jacobian's \
copies take 336 MB, its runs 197 MB, the upsampled force 160 MB: a larger --max-memory if \
the machine has it, or shorter records
    >>> set_max_memory(None)
    """
    from motionhyst.identify.io_start import MAX_FINE_SAMPLES
    from motionhyst.time.openloop import MIN_SUBSTEPS

    n_all = sum(int(n) for n in sizes)
    plants = plant if isinstance(plant, tuple) else (plant,)
    if not any(p.has_inertia for p in plants):  # the link's balance at the samples
        from motionhyst.identify.fd_memory import check_link_force_memory

        check_link_force_memory(list(sizes), link, n_elements, nu, "input-output",
                                output_offsets=offset in ("auto", "output", "both"))
        return
    r = MIN_SUBSTEPS
    if n_all * r > MAX_FINE_SAMPLES:
        raise ValueError(f"identify's search of {n_all} samples runs at least {r} integration "
                         f"steps a sample ({n_all * r:.3g} in all), more than "
                         f"{MAX_FINE_SAMPLES:.0e} in one simulation of the records; give "
                         f"shorter records")
    from motionhyst.hysteresis import BoucWen
    from motionhyst.plants.mass_damper import MassDamper

    needs = []  # the Bouc-Wen link's own search, but on a mass-damper (a friction link there)
    for p in plants:
        if link is BoucWen and p is not MassDamper:
            needs.append(bouc_wen_memory(sizes, r))
        elif p.has_inertia:
            needs.append(search_floor(sizes, r, p, link, n_elements=n_elements,
                                      periodic=periodic, offset=offset, from_rest=from_rest,
                                      window=window, drift=drift))
    need = min(needs, key=lambda need: need["total"])
    if "jacobian" not in need:
        check_bouc_wen_memory(sizes, r, least=True)
        return
    parts = sorted(((need["runs"], "its runs"), (need["jacobian"], "its Jacobian's copies"),
                    (need["force"], "the upsampled force")), reverse=True)
    takes = ", ".join(f"{name} {'take ' if i == 0 else ''}{format_size(size)}"
                      for i, (size, name) in enumerate(parts))
    budget = max_memory()
    if need["total"] > budget:
        raise BudgetError(f"identify's search of {n_all} samples (at least {r} integration "
                          f"steps each, {need['parameters']} parameters) needs at least "
                          f"{format_size(need['total'])}, above the memory budget of "
                          f"{format_size(budget)} (--max-memory)", f"{takes}: {REMEDY}")
