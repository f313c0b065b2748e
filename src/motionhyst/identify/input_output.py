"""Grey-box identification of a stage and its link from input-output records.

The records are force ``u`` in, position ``y`` out (the link force is not
measured), each an experiment from rest or, with ``periodic=True``, whole
periods of a periodic steady state.  The plant (a :class:`MassSpringDamper`,
or the floating two-mass stage of eqs. (1)-(2), :class:`~motionhyst.time.openloop.TwoMass`,
with ``y2`` or ``y1`` measured) and the link are estimated jointly by
minimising the *simulation* error

.. math::

    V(\\theta) = \\sum_{records} \\sum_i \\left(\\hat y_i(\\theta; u) - y_i\\right)^2,

the model being run from the input alone (:class:`~motionhyst.time.openloop.OpenLoop`),
as the Bouc-Wen benchmark scores it (Noel and Schoukens 2016).

Method
------
1. Start, plant: the best linear approximation ``1 / (m s^2 + c s + k)`` fitted
   to the records' frequency response ``G = sum Y U* / sum |U|^2`` at the lines
   carrying input power (weighted by ``|G|``, i.e. the relative output error).
2. Start, link: the linear fit by simulation error; then the link's force is
   introduced by splitting the best linear stiffness ``k`` between the stage
   and the link (Bouc-Wen: ``alpha`` split from ``k`` or added to it, a grid
   of ``beta*gamma`` and ``delta/gamma``, each start screened by one
   simulation, see :func:`~motionhyst.identify.io_bouc_wen._bouc_wen_starts`;
   the full refinement runs from the best start, or the next when it ends
   outside the model's accepted set; the other links, from the model
   registry: parameters started by their units, the link slipping within the
   records or hardly at all, a rate scale such as LuGre's ``vs`` held on a
   grid, see :func:`~motionhyst.identify.io_elements.identify_elements_io`).
   Several starts are refined on a short part of the records and the best
   continues, refined on all records both from there and from there with each
   record's initial state as its first 20 samples set it (the state carried
   over from the starts may lie in another well of the initial velocity, where
   a friction link slips at the start); the better end is kept.  The two-mass stage:
   :func:`~motionhyst.identify.io_start.best_linear_approximation_two_mass`
   (the link a spring and damper to the ground; from rest, the frequency
   response of an ARX model of the records), then the link's initial
   stiffness 1, 3 and 9 times that spring with mild to strong nonlinearity,
   then three splits of the mass at the same internal mode (see
   :func:`~motionhyst.identify.io_bouc_wen._two_mass_start`); its element
   links from 1, 4 and 16 times that spring and forces of 0.3 to 3 times the
   force's RMS (see :func:`~motionhyst.identify.io_elements.identify_elements_io`).
3. Refinement: :func:`scipy.optimize.least_squares` (trust-region reflective)
   on parameters scaled by their start values.  Bouc-Wen: the exact Jacobian
   from forward sensitivities integrated with the model (RK4); other links:
   the exact Jacobian from the forward sensitivities of their simulation, on
   either plant (:func:`~motionhyst.time.openloop.simulate_elements`; finite differences,
   columns in parallel threads, for an element kind without them).  Stopping rule:
   the first of a relative cost reduction below ``ftol``, a relative step below ``xtol`` or a scaled
   gradient below ``gtol`` (all ``1e-12`` by default), or ``max_nfev``
   evaluations.
4. Standard errors ``sqrt(diag(sigma^2 (J^T J)^-1))``, ``sigma^2 = RSS/(N - p)``,
   from the scaled Jacobian's singular values: a direction whose singular
   value is below ``1e-8`` of the largest (``1e-5`` for a finite-difference
   Jacobian) is not determined by the data; its parameters are reported as
   not identifiable, with the others they combine with (never as a huge
   standard error), and the rest from the pseudo-inverse.  Other links also
   report a parameter whose standard error exceeds its value (with the
   parameters its estimate is correlated with), a rate scale whose profile is
   flat (95 % likelihood ratio), and a parameter that only adds a spring or
   damper in parallel with the stage's (``Parameter.parallel``, e.g. LuGre's
   ``sigma2``: only ``c + sigma2`` enters the output; fixed at 0).  With an
   initialisation window the noise of its samples moves the state it sets, and
   with it every later residual: the covariance is the sandwich of
   :class:`~motionhyst.identify.io_uncertainty.WindowNoise`.

The benchmark's Bouc-Wen parameters ``beta, gamma, delta`` enter the model only
as ``beta*gamma`` and ``beta*delta`` (``z`` is not measured and ``beta`` always
multiplies ``gamma`` or ``delta``), so those products are what is estimated;
``beta`` itself is not identifiable and is fixed by the normalisation
``|gamma| + |delta| = 1`` in the returned model.

Modules
-------
io_records
    :class:`~motionhyst.identify.io_records.IORecord`, reading and checking records.
io_start
    The best linear approximations the fits start from.
io_bouc_wen
    The Bouc-Wen link: starts, screening, refinement.
io_elements
    The registry's other links.
io_friction
    The Bouc-Wen and LuGre links as a positioning axis's friction, in their search's spellings.
io_uncertainty
    Standard errors and what the records do not determine.
io_results
    :class:`~motionhyst.identify.io_results.IOIdentification`.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from motionhyst.core.warnings import warn
from motionhyst.hysteresis import BoucWen, Coulomb, Hysteresis, LuGre, MaxwellSlip, model_class
from motionhyst.identify.io_bouc_wen import BASIC_STARTS as BASIC_STARTS
from motionhyst.identify.io_bouc_wen import FINAL_ATTEMPTS as FINAL_ATTEMPTS
from motionhyst.identify.io_bouc_wen import START_PRODUCTS as START_PRODUCTS
from motionhyst.identify.io_bouc_wen import START_RATIOS as START_RATIOS
from motionhyst.identify.io_bouc_wen import START_REFINED as START_REFINED
from motionhyst.identify.io_bouc_wen import START_SHARES as START_SHARES
from motionhyst.identify.io_bouc_wen import identify_bouc_wen_msd, identify_bouc_wen_two_mass
from motionhyst.identify.io_budget import EvaluationBudget
from motionhyst.identify.io_checks import (
    FitFailed,
    StiffFit,
    budget_note,
    check_inertia,
    viscous_direction_note,
)
from motionhyst.identify.io_consistency import check_one_stage
from motionhyst.identify.io_elements import PROFILE_CHI2 as PROFILE_CHI2
from motionhyst.identify.io_elements import RATE_GRID as RATE_GRID
from motionhyst.identify.io_elements import STARTS as STARTS
from motionhyst.identify.io_elements import identify_elements_io
from motionhyst.identify.io_friction import bouc_wen_friction, lugre_stribeck, presliding_note
from motionhyst.identify.io_memory import IO_MODELS
from motionhyst.identify.io_records import MIN_SAMPLES as MIN_SAMPLES
from motionhyst.identify.io_records import IORecord, check_records
from motionhyst.identify.io_records import load_io_csv as load_io_csv
from motionhyst.identify.io_response import check_response
from motionhyst.identify.io_results import IOIdentification
from motionhyst.identify.io_start import BLA_STARTS as BLA_STARTS
from motionhyst.identify.io_start import best_linear_approximation as best_linear_approximation
from motionhyst.identify.io_start import (
    best_linear_approximation_two_mass as best_linear_approximation_two_mass,
)
from motionhyst.identify.io_start import two_mass_response as two_mass_response
from motionhyst.identify.io_uncertainty import (
    BOUC_WEN_SCALE,
    judge_determined,
    undetermined,
    widened_note,
    zero_allowed,
)
from motionhyst.identify.io_uncertainty import FD_SINGULAR_RTOL as FD_SINGULAR_RTOL
from motionhyst.identify.io_uncertainty import SINGULAR_RTOL as SINGULAR_RTOL
from motionhyst.identify.link_slips import check_link_slips
from motionhyst.plants import MassSpringDamper, Plant, plant_class
from motionhyst.time.openloop import is_periodic_record
from motionhyst.time.resample import check_whole_periods

__all__ = ["identify_io"]

#: Link models for input-output records: Bouc-Wen (exact sensitivities) and every other
#: registered model (its parameters taken from the registry); not maxwell-iwan, whose Iwan
#: element of 256 stop operators makes a simulation too slow for a search
MODELS = IO_MODELS
PLANTS = ("mass-spring-damper", "mass-damper", "two-mass", "quasi-static")
#: The element links' refinement takes at least this many evaluations unless given a budget
ELEMENT_NFEV = 200


STEADY_RATIO = 1.5
"""A periodic record's first period may differ from its last by this many times the scatter
between its last two (the noise); more is a transient: the record is not a steady state.
(Noise alone gives 1 within a few per cent for periods of 50 samples or more.)"""


def check_steady_state(rec: IORecord, period: int) -> None:
    """Refuse a record of three or more periods of its force whose output is not periodic.

    In a periodic steady state every period of the output is the same up to the
    noise: the first differs from the last as much as the last two differ.  A
    record from rest carries a transient in its first periods, which a fit under
    ``periodic`` would take for the system (biased estimates, a fit error far
    above the noise).

    Parameters
    ----------
    rec : IORecord
        The record.
    period : int
        Samples per period of its force.

    Raises
    ------
    ValueError
        One line: how far the first period is from the last, and what to do.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(300) / 750
    >>> u = np.sin(2 * np.pi * 7.5 * t)
    >>> check_steady_state(IORecord(t, u, 1e-5 * u, name="steady.csv"), 100)
    >>> try:
    ...     check_steady_state(IORecord(t, u, 1e-5 * u * (1 - np.exp(-t / 0.05)),
    ...                                 name="from-rest.csv"), 100)
    ... except ValueError as exc:
    ...     print(str(exc)[:42])
    from-rest.csv: not a periodic steady state
    """
    n = rec.y.size // period
    if n < 3 or period < 50:
        return
    y = rec.y[: n * period].reshape(n, period)
    first = float(np.sqrt(np.mean((y[0] - y[-1]) ** 2)))
    last = float(np.sqrt(np.mean((y[-2] - y[-1]) ** 2)))
    scale = float(np.sqrt(np.mean(rec.y ** 2)))
    if first > 1e-3 * scale and first > STEADY_RATIO * last:
        raise ValueError(f"{rec.name}: not a periodic steady state: its first period differs "
                         f"from its last by {first:.3g} m RMS, {first / max(last, 1e-300):.3g} "
                         f"times the scatter of its last two; a record from rest? identify "
                         f"without --periodic, or drop the periods before the steady state")


def identify_io(records: list[IORecord], model: type[Hysteresis] | Hysteresis | str = BoucWen,
                *, periodic: bool = False, nu: float | None = 1.0, substeps: int | None = None,
                tol: float = 1e-12, max_nfev: int = 60, n_elements: int = 4,
                start_nfev: int | None = None, plant: Plant | type | str = MassSpringDamper,
                output: str | None = None, offset: str = "auto", from_rest: bool = False,
                max_evaluations: int | EvaluationBudget | None = None,
                init_window: int | None = None,
                asymmetric: bool | None = None, drift: bool = False,
                fewer_elements: bool = False, rigid_limit: bool = False,
                rigid: IOIdentification | None = None, checked: bool = False
                ) -> IOIdentification:
    """Identify a stage and its link from input-output records.

    Parameters
    ----------
    records : list of IORecord
        Force in, displacement out; each from rest (``y = y' = 0``, link relaxed
        at the first sample) or, with `periodic`, whole periods of a steady state.
    model : Hysteresis class or instance, or str
        The link's model (an instance stands for its class: its values are
        estimated, not used): :class:`~motionhyst.hysteresis.BoucWen` with exact
        sensitivities, the registry's others (:data:`MODELS`: Jenkins,
        Maxwell-slip, Dahl, LuGre, Coulomb) from their parameter lists (LuGre's
        viscous ``sigma2`` is not estimated: it adds to ``c``).  A registered
        name (``"jenkins"``) is taken for its class.
    periodic : bool
        Records are steady-state periods (each record one period or several
        whole periods of its force).  A floating stage's (the two-mass one) is
        known up to a constant position: records and model are compared with
        their means removed.
    plant : plant instance or class, or str
        The stage whose parameters are estimated (an instance stands for its
        class and measured ``output``; its values are not used), or its
        registered name (:data:`PLANTS`): :class:`~motionhyst.plants.MassSpringDamper`
        (``m, c, k``),
        :class:`~motionhyst.plants.mass_damper.MassDamper` (``m, c``: a positioning
        axis, friction the link; the Bouc-Wen link there is a friction link, searched
        with the element links as
        :func:`~motionhyst.identify.io_friction.bouc_wen_friction` spells it, its exponent
        fixed at `nu`; LuGre's static force there at least its Coulomb force,
        :func:`~motionhyst.identify.io_friction.lugre_stribeck`), the floating
        :class:`~motionhyst.time.openloop.TwoMass` of eqs. (1)-(2)
        (``m1, m2, b, k``; the force and the link on ``m1``, no spring to the
        ground but the link's) or, for records without visible inertia (piezo
        actuators, friction dampers), :class:`~motionhyst.plants.quasi_static.QuasiStatic`
        (``k, c`` in parallel with the link, any link Bouc-Wen included;
        :mod:`~motionhyst.identify.io_quasi_static`).  A stage with inertia is
        refused before the search (a ValueError) for records that show none
        (:func:`~motionhyst.identify.io_checks.check_inertia`), or among which one shows
        none and a mass the others do not share, or of single-mass stages whose masses
        differ by a factor (:func:`~motionhyst.identify.io_consistency.check_one_stage`).
        Records whose position does not depend on their force (noise, another record's
        position) are refused first, whatever the stage
        (:func:`~motionhyst.identify.io_response.check_response`).
    output : {"y2", "y1"}, optional
        With a two-mass stage given by its name or class: the measured position
        (``y2``, the point of control, the default, or ``y1``, the actuated mass);
        an instance says it itself (``TwoMassStage(..., output="y1")``).
    nu : float or None
        Bouc-Wen exponent: fixed at this value, or estimated (``nu >= 1``) when
        None, starting from 1.  With ``nu`` free the products ``beta*gamma`` and
        ``beta*delta`` change units with it (``N^(1-nu)/m``), and searched as they
        are they crawl along a long valley with ``nu``; the search therefore takes
        ``beta*gamma F^(nu-1)`` and ``beta*delta F^(nu-1)`` (the size of the
        nonlinear terms at a typical link force ``F``: ``alpha`` times the
        output's RMS, or the ultimate force if smaller), which do not move with
        ``nu``; the sensitivities follow by the chain rule.  The estimates are
        still ``beta*gamma`` and ``beta*delta`` at the estimated ``nu``.
    n_elements : int
        Maxwell-slip: number of Jenkins elements.
    fewer_elements : bool
        Maxwell-slip: records that do not determine every element's stiffness and slip force
        (:func:`~motionhyst.identify.io_uncertainty.undetermined`) are fitted again with as
        many elements as the fit determined (at least 1: the Jenkins element), said in a
        warning, and so is a fit refused for an element stiffer than they resolve
        (:class:`~motionhyst.identify.io_checks.StiffFit`: with one element fewer); else the
        fit is judged as it is.
    rigid_limit : bool
        A Jenkins link (or a Maxwell-slip link of one element, a Jenkins link) on a
        mass-damper whose stiffness the records do not resolve (not
        determined, or its stuck mode ``sqrt(k / m) / 2 pi`` above a quarter of the sampling
        rate: :func:`~motionhyst.identify.rigid_limit.unresolved_stiffness`), or any friction
        link there of whose parameters the records determine at most half (a failed fit
        otherwise), is reported as its rigid limit, the Coulomb link's fit with the same
        options that its search started from, said in a warning; else it is judged as it is.
    start_nfev : int, optional
        Links other than Bouc-Wen: evaluations of each start's refinement on the
        short part of the records (default ``15 p``, ``p`` parameters).
    substeps : int, optional
        Integration steps per sample (default: the model's
        :meth:`~motionhyst.time.openloop.OpenLoop.default_substeps` at the start).
    tol : float
        ``ftol = xtol = gtol`` of the refinement.
    max_nfev : int
        Largest number of model evaluations of the refinement (the element links: at
        least 200 unless `max_evaluations` says otherwise).
    offset : {"auto", "none", "input", "output", "both"}
        The offsets estimated with the model (the element links;
        :class:`~motionhyst.identify.io_offsets.Extras`): of the force (the plant
        receives ``u - input_offset``; one for all records) and of the measured
        position (one per record); ``auto``: both for a floating stage's records
        from a start, none for its periodic records, the position's for a stage
        on a spring (where a force offset is only a position offset ``u0 / k``).
        Bouc-Wen (but on a mass-damper, where it is a friction link as the others):
        ``auto`` and ``none`` estimate none, ``output`` each record's position offset
        (on a mass-spring-damper).
    from_rest : bool
        The records start at rest; otherwise each record's initial velocity (and
        position, on a spring) is estimated (the element links).
    max_evaluations : int or EvaluationBudget, optional
        The search's whole budget of model evaluations: every start, profile point,
        Coulomb fit a friction link starts from, refinement and the standard errors'
        evaluations, and a refit with fewer elements, together
        (:class:`~motionhyst.identify.io_budget.EvaluationBudget`; one given is charged,
        and told when the search starts).
    init_window : int, optional
        The element links: each record's initial state (and a floating stage's
        position offset) is not estimated but set, at every step of the search,
        from its first `init_window` samples as ``predict --init-from
        --init-window`` sets it (:func:`~motionhyst.identify.io_predict.state_from_window`;
        the EMPS benchmark's convention, 20): the model is fitted the way it is
        scored.  Only the force offset is estimated with it (a floating stage).
    asymmetric : bool or None
        A mass-damper's viscous friction by direction (a positioning axis's
        ``Fv+``, ``Fv-``), with any link: the stage's ``c_skew``
        estimated with ``c`` (``c + c_skew`` moving forward, ``c - c_skew``
        backward); the Coulomb link holds it itself (its ``c_pos`` or ``c_neg`` on
        top of the stage's ``c``, the smaller).  Its force offset is then another
        number than a symmetric model's: the symmetric one takes up the mean of the
        difference.  None, the default (``identify``'s too, and ``benchmark emps``'s for a
        model named without ``-asymmetric`` or ``-symmetric``): by direction where the
        records show it, said in a warning; else one coefficient.  The records show it
        when their inverse dynamics finds a difference at the speeds both directions
        cover, beyond three standard errors and a tenth of the mean coefficient
        (:func:`~motionhyst.identify.io_checks.viscous_direction_note`; a symmetric fit's
        mass is biased there): friction that is higher at low speed alike both ways (the
        Stribeck effect) is no difference, however differently the two directions were
        driven.  True (``--asymmetric``) fits two coefficients, False (``--symmetric``)
        one, whatever the records show.  On the EMPS record's period splits (1-2 > 3-4,
        3-4 > 1-2, 1-3 > 4, 2-4 > 1, the held-out periods predicted from a 20-sample
        window) the Jenkins link's error fell from 5.57, 9.71, 3.17, 6.10 mm to 5.19, 6.31,
        1.06, 3.34 mm, the Coulomb link's from 5.10, 9.71, 3.17, 6.10 to 5.19, 6.31, 1.18,
        3.24 mm.
    drift : bool
        A mass-damper whose force offset drifts in time: its rate ``input_drift``
        [N/s] is estimated with the force offset (the plant receives ``u -
        input_offset - input_drift t``, ``t`` each record's own time; the
        fitted plant's ``force_drift``).  A machine warming up over a record
        (EMPS); it assumes a record to be predicted starts as the identified
        ones did.
    rigid : IOIdentification, optional
        A friction link on a mass-damper starts (among others) from the Coulomb link's fit,
        its rigid limit: that fit, made already on the same records with the same options
        (offsets, window, drift; viscous friction by direction in either spelling), is
        reused instead of being fitted again.
    checked : bool
        The records passed :func:`~motionhyst.identify.io_checks.check_inertia` and
        :func:`~motionhyst.identify.io_consistency.check_one_stage` for this stage already
        (``identify`` checks them before it says anything else): not checked again.

    Returns
    -------
    IOIdentification

    Raises
    ------
    FitFailed
        A fit that is no result (:mod:`~motionhyst.identify.io_checks`), or of whose
        parameters the records determine at most half
        (:func:`~motionhyst.identify.io_uncertainty.judge_determined`; fewer not determined
        are one of the result's ``warnings``).

    Warns
    -----
    MotionhystWarning
        One for each line of the result's ``warnings`` (an estimate the records do not
        hold: a mass far from the records' inertia, a parameter at its bound or run
        away from its start, parameters the records do not determine).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.time.openloop import MassSpringDamper, OpenLoop
    >>> from motionhyst.hysteresis import BoucWen
    >>> true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=5e4, fc=20.0, beta=0.6,
    ...                                                            gamma=0.2))
    >>> t = np.arange(1024) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t) + 20 * np.sin(2 * np.pi * 31 * t)
    >>> y = true.simulate(t, u).displacement
    >>> fit = identify_io([IORecord(t, u, y)], BoucWen, plant=MassSpringDamper)
    >>> round(fit.plant.m, 6), round(fit.estimates["alpha"])
    (2.0, 50000)
    """
    t_start = time.perf_counter()
    link = _link_class(model)
    if asymmetric and periodic and link is not Coulomb:
        raise ValueError("the stage's viscous friction by direction is identified from records "
                         "from a start, not periodic ones (the Coulomb link's own: both)")
    records = check_records(list(records), periodic)
    check_response(records)  # milliseconds: before anything else looks at the records
    if periodic:
        for rec in records:
            check_whole_periods(rec.u, rec.name)
            rec_period = is_periodic_record(rec.u)
            if rec_period is not None:
                check_steady_state(rec, rec_period)
    stage = _stage(plant, output)
    by_direction = None
    if asymmetric is None:  # by direction where the records show it
        by_direction = _by_direction(records, stage, link, periodic)
        asymmetric = by_direction is not None
    link = _searched(link, stage, nu, records)
    if init_window is not None:
        if not (isinstance(init_window, int | np.integer) and init_window >= 2):
            raise ValueError(f"the initialisation window must be at least 2 samples, got "
                             f"{init_window}")
        short = [rec.name for rec in records if rec.y.size <= 2 * init_window]
        if short:
            raise ValueError(f"{short[0]}: too short for an initialisation window of "
                             f"{init_window} samples")
    if stage.has_inertia:  # once, before the search (refits too)
        shape = stage.mechanics(np.ones(len(stage.PARAMETERS)))  # its structure, any values
        if asymmetric and not (shape.floating and shape.n == 1):
            raise ValueError(_ASYMMETRIC)
        if not checked:
            check_inertia(records)
            check_one_stage(records, shape.floating, single_mass=shape.n == 1)
        names = {p.name for p in _link_class(model).parameters}
        if (shape.n == 1 and not periodic and {"k", "fc"} <= names
                and (shape.floating or link is not BoucWen)):
            check_link_slips(records, link.name, stage_k=not shape.floating)
    fewer, budget = None, (max_evaluations if isinstance(max_evaluations, EvaluationBudget)
                           else EvaluationBudget(max_evaluations))  # the whole search's, refits
    why: dict[int, str] = {}  # why a Maxwell-slip fit of so many elements was given up
    while True:
        try:
            fit = _route(records, link, stage, periodic=periodic, nu=nu, substeps=substeps,
                         tol=tol, max_nfev=max_nfev, n_elements=n_elements,
                         start_nfev=start_nfev, offset=offset, from_rest=from_rest,
                         max_evaluations=budget, init_window=init_window,
                         asymmetric=asymmetric, drift=drift, t_start=t_start,
                         rigid_limit=rigid_limit, rigid=rigid)
        except StiffFit as exc:  # an element stiffer than the records resolve: one fewer
            if not (fewer_elements and link is MaxwellSlip and n_elements > 1):
                raise
            fewer = (fewer[0] if fewer else n_elements, n_elements - 1)
            mode = f"its fastest mode at {exc.mode_hz:.3g} Hz, " if exc.mode_hz else ""
            steps = f"{exc.steps} integration steps per sample" if exc.steps else "too many " \
                "integration steps per sample"
            why[n_elements] = (f"an element ran stiffer than the records resolve ({mode}"
                               f"{steps})")
            n_elements -= 1
            continue
        invariant, zero = BOUC_WEN_SCALE if link is BoucWen else (), zero_allowed(stage, link)
        failed = None
        try:  # parameters the records do not determine: a warning, or (most) a failed fit
            determined = judge_determined(fit.estimates, fit.judged_std or fit.std, invariant,
                                          zero, _one_way_names(fit), link.name)
        except FitFailed as exc:
            failed = exc
        kept = (_determined_elements(fit, n_elements, invariant, zero)
                if fewer_elements and link is MaxwellSlip and n_elements > 1 else n_elements)
        if kept < n_elements:  # elements the records do not determine: fewer of them
            fewer = (fewer[0] if fewer else n_elements, kept)
            why[n_elements] = "the records do not determine every element's parameters"
            n_elements = kept
            continue
        if failed is not None and rigid_limit and fit.rigid_limit is not None:
            fit, determined = _undetermined_link(fit, failed, stage, invariant, zero)
        elif failed is not None:
            raise failed
        break
    fit.n_evaluations = budget.used  # refits with fewer elements included
    if not fit.extra.get("rigid_limit"):
        _refuse_a_stuck_link(fit, records, set(undetermined(
            fit.estimates, fit.judged_std or fit.std, invariant, zero)) - _one_way_names(fit))
    if (stage.has_inertia and not asymmetric and _is_axis(stage)
            and (not periodic or isinstance(fit.hysteresis, Coulomb))):
        note = viscous_direction_note(records)  # a symmetric fit's mass is biased: its rigid
        if note is not None:  # limit's too (the fit reported when the link is not resolved)
            fit.warnings.append(note)
    if by_direction is not None:
        fit.warnings.append(by_direction)
    if fewer is not None:
        fit.warnings.append(_fewer_line(fewer, why))
    if isinstance(fit.hysteresis, LuGre) and link is not LuGre:  # a positioning axis's
        note = presliding_note(fit.hysteresis, records)
        if note is not None:
            fit.warnings.append(note)
    if fit.extra.get("budget_reached"):  # a good fit all the same: said, not refused
        fit.warnings.append(budget_note(fit.n_evaluations))
    fit.warnings.extend(determined)
    widened = widened_note(fit.estimates, fit.std, fit.judged_std, invariant, zero) \
        if fit.judged_std and fit.extra.get("std_lower_bound") else None
    if widened is not None:  # determined on white residuals, not beyond the model's error
        fit.warnings.append(widened)
    for line in fit.warnings:  # the plausibility checks, for every caller to see
        warn(line)
    return fit


def _route(records: list[IORecord], link: type[Hysteresis], stage: Plant, *, periodic: bool,
           nu: float | None, substeps: int | None, tol: float, max_nfev: int, n_elements: int,
           start_nfev: int | None, offset: str, from_rest: bool,
           max_evaluations: EvaluationBudget,
           init_window: int | None, asymmetric: bool, drift: bool, t_start: float,
           rigid_limit: bool = False, rigid: IOIdentification | None = None
           ) -> IOIdentification:
    """The fit of :func:`identify_io` that the stage's structure and the link call for."""
    if drift and not any(p.name == "force_drift" for p in stage.parameters):
        raise ValueError("a drifting force offset is identified on a mass-damper")
    if not stage.has_inertia:  # the link's balance (any link, Bouc-Wen too)
        if asymmetric:
            raise ValueError(_ASYMMETRIC)
        from motionhyst.identify.io_quasi_static import identify_quasi_static_io

        if init_window is not None:
            raise ValueError("a stage without inertia has no state for an initialisation "
                             "window to set")
        max_evaluations.charge(0)  # no plan of starts: the search starts here
        fit = identify_quasi_static_io(records, link, periodic=periodic,
                                       n_elements=n_elements, offset=offset,
                                       max_evaluations=max_evaluations.left, tol=tol,
                                       t_start=t_start, nu=nu)
        max_evaluations.used += fit.n_evaluations
        return fit
    shape = stage.mechanics(np.ones(len(stage.PARAMETERS)))  # its structure, whatever values
    if link is not BoucWen:
        return identify_elements_io(records, link, periodic, substeps, tol,
                                    max(max_nfev, ELEMENT_NFEV), n_elements, t_start, start_nfev,
                                    stage, offset, from_rest, max_evaluations,
                                    int(init_window) if init_window is not None else None,
                                    asymmetric, bool(drift),
                                    skew=asymmetric and link is not Coulomb,
                                    rigid_limit=rigid_limit, rigid=rigid)
    bouc_wen_offset = offset == "output" and not shape.floating
    if (offset not in ("auto", "none") and not bouc_wen_offset) or from_rest \
            or init_window is not None:
        raise ValueError("the Bouc-Wen link's records start at rest and only its position "
                         "offsets are estimated (offset 'output', on a mass-spring-damper); "
                         "other offsets and initial states are estimated with the element links")
    if max_evaluations.limit is not None:
        max_nfev = max_evaluations.limit
    if shape.n > 1:
        return identify_bouc_wen_two_mass(records, periodic, nu, substeps, tol, max_nfev,
                                          stage.output, t_start, max_evaluations)
    return identify_bouc_wen_msd(records, periodic, nu, substeps, tol, max_nfev, t_start,
                                 bouc_wen_offset, max_evaluations)


def _by_direction(records: list[IORecord], stage: Plant, link: type[Hysteresis],
                  periodic: bool) -> str | None:
    """The line saying a fit is made with viscous friction by direction because its records
    show it (:func:`~motionhyst.identify.io_checks.viscous_direction_note`), on a
    mass-damper where that applies (records from a start, or the Coulomb link's periodic
    ones); else None."""
    if not (stage.has_inertia and _is_axis(stage) and (not periodic or link is Coulomb)):
        return None
    note = viscous_direction_note(records)
    if note is None:
        return None
    seen = note.split(": a fit with one viscous coefficient")[0]
    return (f"{seen}: fitted with one viscous coefficient per direction, as --asymmetric fits "
            f"it (a symmetric fit's mass is biased; --symmetric fits one)")


def _is_axis(stage: Plant) -> bool:
    """A positioning axis: one mass, no spring to the ground (a mass-damper)."""
    shape = stage.mechanics(np.ones(len(stage.PARAMETERS)))  # its structure, whatever values
    return bool(shape.floating and shape.n == 1)


def _undetermined_link(fit: IOIdentification, failed: FitFailed, stage: Plant,
                       invariant: tuple[str, ...], zero: set[str]
                       ) -> tuple[IOIdentification, list[str]]:
    """A friction link on a positioning axis most of whose parameters the records do not
    determine, reported as its rigid limit: the Coulomb link's fit its search started from,
    with one warning naming what the records did not determine, and that fit's own notes of
    :func:`~motionhyst.identify.io_uncertainty.judge_determined`; `failed` raised if the
    limit is no result either."""
    rigid = fit.rigid_limit
    if rigid is None:
        raise failed
    try:
        determined = judge_determined(rigid.estimates, rigid.judged_std or rigid.std, (),
                                      zero_allowed(stage, Coulomb), _one_way_names(rigid),
                                      Coulomb.name)
    except FitFailed:
        raise failed from None
    names = undetermined(fit.estimates, fit.judged_std or fit.std, invariant, zero)
    why = f"the records do not determine its {', '.join(names)}"
    note = (f"the {fit.hysteresis.name} link is reported as its rigid limit, the Coulomb link "
            f"(fc {rigid.estimates['link.fc']:.4g} N, fit RMS {rigid.fit_rms:.3g} m): {why}")
    return replace(rigid, warnings=[note, *rigid.warnings], n_evaluations=fit.n_evaluations,
                   seconds=fit.seconds, extra={**rigid.extra,
                                               "rigid_limit": f"{fit.hysteresis.name}: {why}"}
                   ), determined


def _refuse_a_stuck_link(fit: IOIdentification, records: list[IORecord],
                         names: set[str]) -> None:
    """Refuse a fit whose records determine none of its link's slip forces (`names`, the
    parameters they do not determine, less those a one-way slip's warning names as one
    force): a link with a spring (``link.k``, the stop operators' stiffness, eq. 3) then
    never slips in them, its force is that spring's, and a slip force the model would hold
    is the search's, anything above the spring's force at the records' strokes (a Jenkins
    link stuck throughout ended at fc = 5.6e12 N).  A model saved with it would predict a
    link that never slips, whatever the force: refused, the spring named.  (A link without a
    spring, Coulomb's, is judged by :func:`judge_determined` alone.)"""
    slips = [n for n in fit.estimates if n == "link.fc" or n.startswith("link.fc[")]
    springs = [n for n in fit.estimates if n == "link.k" or n.startswith("link.k[")]
    if not slips or not springs or not set(slips) <= names:
        return
    k = sum(fit.estimates[n] for n in springs)
    half = max(0.5 * float(np.ptp(rec.y)) for rec in records)
    spring = (f"it acts as a spring of {k:.4g} N/m (link.k; any slip force above its "
              f"{k * half:.3g} N at the records' half-stroke {half:.3g} m fits as well)"
              if all(n not in names for n in springs) and k > 0
              else "its force is not a slip's")
    raise FitFailed(f"the fit failed: the link never slips in these records (not determined: "
                    f"{', '.join(slips)}, the search ended at {fit.estimates[slips[0]]:.3g} N): "
                    f"{spring}; a model that keeps that slip force predicts a link that never "
                    f"slips; give a record in which the link slips (a larger force or stroke), "
                    f"or model the stage with that spring (a mass-spring-damper); nothing "
                    f"identified")


def _fewer_line(fewer: tuple[int, int], why: dict[int, str]) -> str:
    """The warning of a Maxwell-slip link fitted with fewer elements than asked: each count
    given up and why (not determined, or an element too stiff to run)."""
    if all(cause.startswith("the records do not determine") for cause in why.values()):
        return (f"the records do not determine the parameters of {fewer[0]} Maxwell-slip "
                f"elements: fitted with {fewer[1]} (the most they determine; --elements N "
                f"insists on N)")
    causes = "; ".join(f"with {n}, {cause}" for n, cause in sorted(why.items(), reverse=True))
    return (f"the records do not resolve the parameters of {fewer[0]} Maxwell-slip elements: "
            f"fitted with {fewer[1]} ({causes}; --elements N insists on N)")


def _one_way_names(fit: IOIdentification) -> set[str]:
    """The slip forces and force offset the fit's own warning names as one force
    (:func:`~motionhyst.identify.io_one_way.one_way_slip`)."""
    return set(fit.extra.get("one_way", {}).get("parameters", []))


def _determined_elements(fit: IOIdentification, n: int, invariant: tuple[str, ...],
                         zero: set[str]) -> int:
    """The Maxwell-slip elements the fit's records determine: `n` if they determine every
    element's stiffness and slip force, else as many elements as have both determined, at
    least 1 and at most ``n - 1``."""
    bad = set(undetermined(fit.estimates, fit.judged_std or fit.std, invariant, zero))
    kept = sum(1 for i in range(n) if f"link.k[{i}]" not in bad and f"link.fc[{i}]" not in bad)
    return n if kept == n else max(1, min(kept, n - 1))


def _searched(link: type[Hysteresis], stage: Plant, nu: float | None,
              records: list[IORecord]) -> type:
    """The link's class as the search takes it: on a mass-damper (a positioning axis) the
    Bouc-Wen and LuGre links are friction links in the spellings of
    :mod:`~motionhyst.identify.io_friction` (a bounded force; the Stribeck effect), searched
    with the element links; any other link, or these on another stage, as it is."""
    if link not in (BoucWen, LuGre) or not stage.has_inertia:
        return link
    shape = stage.mechanics(np.ones(len(stage.PARAMETERS)))
    if not (shape.floating and shape.n == 1):
        return link
    if link is LuGre:
        return lugre_stribeck(records)
    if nu is None:
        raise ValueError("on a mass-damper the Bouc-Wen link's exponent is given, not "
                         "estimated (nu >= 1, default 1)")
    return bouc_wen_friction(nu)


_ASYMMETRIC = "direction-dependent viscous friction is identified on a mass-damper"


def _link_class(model: type[Hysteresis] | Hysteresis | str) -> type[Hysteresis]:
    """The link model's class: `model` itself, an instance's class, or a registered name's
    (converted here once); a one-line error for a model input-output records do not fit."""
    if isinstance(model, str):
        if model not in MODELS:
            raise ValueError(f"unknown link model {model!r} for input-output records; expected "
                             f"one of {', '.join(MODELS)}")
        return model_class(model)
    cls = model if isinstance(model, type) else type(model)
    if not (issubclass(cls, Hysteresis) and getattr(cls, "name", None) in MODELS):
        raise ValueError(f"input-output records fit a link model of {', '.join(MODELS)}, not "
                         f"{model!r}")
    return cls


def _stage(plant: Plant | type | str, output: str | None) -> Plant:
    """The stage as a plant instance whose class and measured output the fit takes (its
    values are not used): `plant` itself, or one built from its class or registered name
    (converted here once) with `output`."""
    if isinstance(plant, str):
        if plant not in PLANTS:
            raise ValueError(f"unknown plant {plant!r} for input-output records; expected one "
                             f"of {', '.join(PLANTS)}")
        plant = plant_class(plant)
    cls = plant if isinstance(plant, type) else type(plant)
    if getattr(cls, "name", None) not in PLANTS or cls is not plant_class(cls.name):
        raise ValueError(f"input-output records identify a {', '.join(PLANTS)} stage, not "
                         f"{plant!r}")
    if isinstance(plant, type):
        several = len(cls.outputs) > 1
        if output is not None and output not in cls.outputs:
            raise ValueError(f"unknown output {output!r}; expected {' or '.join(cls.outputs)}"
                             if several else f"output {output!r}: a {cls.name} stage has one "
                             f"position")
        values = {p.name: 1.0 for p in cls.parameters if p.required}
        return cls(**values, output=output or cls.outputs[0]) if several else cls(**values)
    if output is not None and output != plant.output:
        raise ValueError(f"output {output!r} differs from the plant's own {plant.output!r}")
    return plant
