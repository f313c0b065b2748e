"""Input-output identification of a link without inertia (the quasi-static plant).

Records where no inertia is visible (a piezo actuator below its first resonance, a friction
damper driven slowly) are the force balancing the link and a spring ``k`` and damper ``c`` in
parallel at every sample, :class:`~motionhyst.plants.quasi_static.QuasiStatic`:
``u - u_0 = w(x) + k x + c x'``, the measured position ``y = x + y_0``.  The link (any
registered model with a time step, Bouc-Wen included), ``k``, ``c`` and the offsets are
estimated by the *simulation* error of the position, the model run from the force alone
(:func:`~motionhyst.time.quasi_static.displacement_from_force`), as the other plants are
(:mod:`~motionhyst.identify.input_output`).

Method
------
1. The linear start: ``u = K y + C y' + b`` by least squares (``y'`` by the
   second-order backward difference of the model), per record's ``b``.
2. Starts of the link: the link takes 0.3 or 0.6 of ``K``, the spring the
   rest, slipping across the records' displacement or a tenth of it
   (:data:`STARTS`); a velocity of the link (LuGre's Stribeck velocity) at a
   tenth of the records' velocity RMS and at the RMS
   (:data:`VELOCITY_STARTS`); each is refined by the *equation* error (the force
   predicted from the measured position, one pass of the link per
   evaluation, :func:`~motionhyst.time.quasi_static.force_from_displacement`),
   each for :data:`SCREEN_NFEV` evaluations, the best :data:`SCREEN_KEPT` on to
   :data:`START_NFEV` (:func:`_refined_starts`).
   A link of stop operators (Jenkins, Maxwell-slip) also starts from the
   force-displacement fit of
   :func:`~motionhyst.identify.fit.identify_maxwell_slip` (a grid and
   non-negative least squares: no local minima), its element that slips
   last taken as the spring.  By the force's error, a link that saturates
   (Bouc-Wen, Dahl) starts from that fit's Jenkins element and spring too
   (refined as the others):
   the slope right after each reversal gives its initial stiffness, the
   force's half-range at large stroke its saturation force
   (:func:`_saturation_starts`).  A Bouc-Wen link is searched at a fixed force
   scale with ``beta - gamma >= 0`` a bound
   (:class:`~motionhyst.identify.io_bouc_wen_shape.BoucWenShape`); its exponent, when estimated by
   the force's error, joins the rest from ``n = 2`` once the starts are refined.
3. The start whose simulated position fits best continues by the simulation
   error (trust-region reflective, forward-difference Jacobian).  A result
   must predict: worse than the linear model's simulation error, or
   explaining less than :data:`MIN_FIT_PERCENT` of the position's variation,
   is a failed fit (:func:`~motionhyst.identify.io_checks.judge_fit`,
   ``FitFailed``); a positive value that ran :data:`RUNAWAY_FACTOR` times
   from its start is a warning naming it, and so is a Stribeck curve (LuGre's ``fs``,
   ``vs``) the records do not hold: the fit without it as good, within
   :data:`STRIBECK_GAIN` (:func:`_stribeck_warning`).
"""

from __future__ import annotations

import math
import time

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from motionhyst.hysteresis import BoucWen, Jenkins, MaxwellSlip
from motionhyst.identify.io_bouc_wen_shape import EXPONENT_START, BoucWenShape
from motionhyst.identify.io_checks import FitFailed, judge_fit
from motionhyst.identify.io_elements import LinkLayout
from motionhyst.identify.io_quasi_static_checks import (
    judge_force_fit,
    judge_hysteresis,
    judge_systematic,
    linear_rms,
)
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_results import IOIdentification, per_record_errors
from motionhyst.identify.io_uncertainty import (
    FD_SINGULAR_RTOL,
    correlated_errors,
    covariance_table,
    undetermined_notes,
)
from motionhyst.identify.residual_noise import ResidualCorrelation
from motionhyst.plants.quasi_static import QuasiStatic
from motionhyst.time.openloop import OpenLoop
from motionhyst.time.quasi_static import displacement_from_force, force_from_displacement

__all__: list[str] = []  # the search, for identify_io and io_link_force

#: Starts: (the link's share of the linear stiffness, its slip displacement in units of the
#: records' displacement RMS)
STARTS = ((0.3, 1.0), (0.6, 1.0), (0.3, 0.1), (0.6, 0.1))
#: A link's velocities (LuGre's Stribeck velocity) start at these multiples of the records'
#: velocity RMS, each with each of :data:`STARTS`: at a tenth the Stribeck drop is confined to
#: the reversals and a refinement can lose it (``fs`` or ``vs`` running to 0, the link left
#: with a constant Coulomb force: a local minimum), at the RMS it spans the records' velocities
VELOCITY_STARTS = (0.1, 1.0)
#: Evaluations of each start's equation-error refinement, and of the final refinement
START_NFEV, FINAL_NFEV = 60, 150
#: The starts' refinements are compared after this many evaluations, and only the best this
#: many go on to :data:`START_NFEV` (the others are compared as they are then, as the
#: Maxwell-slip fit screens its starts): from most starts they end at one cost (LuGre on a
#: Dahl damper's 24,000 samples: 7 of 8 within 0.1 %, the 8 refinements 98 % of its CPU)
SCREEN_NFEV, SCREEN_KEPT = 5, 2
#: A residual where the model cannot run (a force it does not hold), in output RMS units
FAILED_RESIDUAL = 1e3
#: A fit that explains less of the position's variation than this [%] predicts nothing
MIN_FIT_PERCENT = 10.0
#: A positive value that ends this many times from its start (either way) is reported
RUNAWAY_FACTOR = 1e6


class _Problem:
    """The search: ``k, c``, the link's values, the input offset, each record's output
    offset; positive link values as logarithms, the rest scaled."""

    def __init__(self, records: list[IORecord], layout: LinkLayout, periodic: bool,
                 input_offset: bool, output_offset: bool, k_scale: float, c_scale: float,
                 y_scale: float, u_scale: float, v_scale: float) -> None:
        self.records, self.layout, self.periodic = records, layout, periodic
        link_log = layout.logarithmic
        self.n_link = link_log.size
        n_rec = len(records)
        self.names = (["k", "c", *layout.names, "input_offset"]
                      + [f"output_offset[{i}]" if n_rec > 1 else "output_offset"
                         for i in range(n_rec)])
        self.log = np.concatenate([[False, False], link_log, [False], np.zeros(n_rec, bool)])
        link_scale = layout.scales(k_scale, c_scale, y_scale, v_scale)
        self.scale = np.concatenate([[k_scale, c_scale], link_scale, [u_scale],
                                     np.full(n_rec, y_scale)])
        # a linear value may be 0 or below only if the model says so ("finite")
        kinds = [par.kind for par, _ in layout._values()]
        self.lower = np.concatenate([[0.0, 0.0], [-np.inf if lg or kind == "finite" else 0.0
                                                  for lg, kind in zip(link_log, kinds,
                                                                      strict=True)],
                                     [-np.inf], np.full(n_rec, -np.inf)])
        self.free = np.ones(self.log.size, dtype=bool)
        self.free[2 + self.n_link] = input_offset
        self.free[3 + self.n_link:] = output_offset
        self.y_scale, self.u_scale = y_scale, u_scale
        self.fixed = np.zeros(self.log.size)
        self.n_eval = 0

    def values(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        with np.errstate(over="ignore"):  # an overflow is a value the model refuses
            return np.where(self.log, np.exp(np.where(self.log, q, 0.0)), q * self.scale)

    def variables(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.where(self.log, np.log(np.where(self.log, v, 1.0)), v / self.scale)

    def whole(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        q = self.fixed.copy()
        q[self.free] = q_free
        return q

    def model(self, v: NDArray[np.float64]) -> tuple[QuasiStatic, object]:
        """The plant (its force offset ``-input_offset``) and the link of values `v`."""
        k = 2 + self.n_link
        return (QuasiStatic(max(v[0], 0.0), max(v[1], 0.0), force_offset=-v[k]),
                self.layout.build(v[2:k]))

    def output_offsets(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        return v[3 + self.n_link:]

    def positions(self, v: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """The measured positions the model predicts (offsets included); ValueError if it
        cannot run."""
        plant, link = self.model(v)
        return [displacement_from_force(plant, link, rec.t, rec.u, periodic=self.periodic)
                + y0 for rec, y0 in zip(self.records, self.output_offsets(v), strict=True)]

    def forces(self, v: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """The forces the model predicts from the measured positions (offsets included)."""
        plant, link = self.model(v)
        return [force_from_displacement(plant, link, rec.t, rec.y - y0, periodic=self.periodic)
                for rec, y0 in zip(self.records, self.output_offsets(v), strict=True)]

    def _residuals(self, q_free: NDArray[np.float64], equation: bool) -> NDArray[np.float64]:
        self.n_eval += 1
        v = self.values(self.whole(q_free))
        n_rows = sum(rec.y.size for rec in self.records)
        try:
            if equation:  # the force from the measured position, in units of the force
                plant, link = self.model(v)
                r = np.concatenate([
                    force_from_displacement(plant, link, rec.t, rec.y - y0,
                                            periodic=self.periodic) - rec.u
                    for rec, y0 in zip(self.records, self.output_offsets(v), strict=True)]
                ) / self.u_scale
            else:
                r = np.concatenate([y - rec.y for y, rec in
                                    zip(self.positions(v), self.records, strict=True)]
                                   ) / self.y_scale
        except (ValueError, ArithmeticError):  # values the model refuses, a force not held
            return np.full(n_rows, FAILED_RESIDUAL)
        return r if np.all(np.isfinite(r)) else np.full(n_rows, FAILED_RESIDUAL)

    def solve(self, q0: NDArray[np.float64], equation: bool, max_nfev: int, tol: float):
        lower = np.where(self.log, -np.inf, self.lower / self.scale)[self.free]
        q0 = np.maximum(q0[self.free], lower)
        # a trial step far out (a piezo's Bouc-Wen link on 24,000 samples) may predict positions
        # whose sum of squares overflows: an infinite cost, a step the search rejects, not a
        # warning on the user's terminal
        with np.errstate(over="ignore"):
            return least_squares(lambda q: self._residuals(q, equation), q0, method="trf",
                                 x_scale=1.0, diff_step=1e-6, ftol=tol, xtol=tol, gtol=tol,
                                 max_nfev=max_nfev, bounds=(lower, np.full(lower.size, np.inf)))



def _layout(link: type, n_elements: int, nu: float | None = 1.0) -> LinkLayout:
    """The link's search layout; Bouc-Wen's
    (:class:`~motionhyst.identify.io_bouc_wen_shape.BoucWenShape`) with its exponent fixed at
    `nu` (default 1: exact steps), or estimated with the rest (None)."""
    if link is BoucWen:
        return BoucWenShape.of_exponent(nu)
    return LinkLayout.of(link, n_elements)


def _stop_operator_fit(records: list[IORecord], n: int):
    """The records' force-displacement fit of
    :func:`~motionhyst.identify.fit.identify_maxwell_slip` with `n` elements (stop
    operators on a grid, non-negative least squares: no local minima), the records joined,
    each relaxed at its first position: ``k, fc`` by slip displacement (the last, which
    slips last, is the spring) and the force offset; None if the records hold no such fit."""
    import warnings

    from motionhyst.core.warnings import MotionhystWarning
    from motionhyst.identify.fit import identify_maxwell_slip

    x = np.concatenate([rec.y - rec.y[0] for rec in records])
    u = np.concatenate([rec.u for rec in records])
    try:
        with warnings.catch_warnings():  # a start: what its values' std say is not the fit's
            warnings.simplefilter("ignore", MotionhystWarning)
            ident = identify_maxwell_slip(x, u, n, initial_state="relaxed")
    except ValueError:
        return None
    k = np.array([e["k"] for e in ident.elements])
    fc = np.array([e["fc"] for e in ident.elements])
    order = np.argsort(fc / k)  # by slip displacement: the last is the spring
    return k[order], fc[order], float(ident.offset)


def _stop_operator_starts(records: list[IORecord], layout: LinkLayout, prob: _Problem,
                          n_elements: int, input_offset: bool, output_offset: bool,
                          fit=None) -> list[NDArray[np.float64]]:
    """For a link of stop operators (Jenkins, Maxwell-slip): the records' stop-operator fit
    (:func:`_stop_operator_fit`, `fit` if given) with one element more, the one that slips
    last taken as the spring ``k``.  None for other links."""
    if layout.cls not in (Jenkins, MaxwellSlip):
        return []
    n = 1 if layout.cls is Jenkins else n_elements
    fit = fit or _stop_operator_fit(records, n + 1)
    if fit is None:
        return []
    k, fc, offset = fit
    link = np.concatenate([k[:-1], fc[:-1]]) if layout.cls is MaxwellSlip else \
        np.array([k[0], fc[0]])
    v = np.concatenate([[k[-1], 0.0], link, [offset if input_offset else 0.0],
                        [rec.y[0] if output_offset else 0.0 for rec in records]])
    return [prob.variables(v)]


def _saturation_starts(records: list[IORecord], layout: LinkLayout, prob: _Problem,
                       fit, input_offset: bool, output_offset: bool
                       ) -> list[NDArray[np.float64]]:
    """For a link with an initial stiffness ``k`` and a force it saturates at (Bouc-Wen,
    Dahl): starts from the records' Jenkins element and spring (`fit`,
    :func:`_stop_operator_fit` with two elements): the link's stiffness is the slope right
    after each reversal less the spring's, its force the force's half-range at large
    stroke (Bouc-Wen: in each shape of :data:`SATURATION_SHAPES`).  None for other links."""
    names = list(layout.names)
    if fit is None or "link.k" not in names or layout.cls is Jenkins or (
            "link.fc" not in names and not isinstance(layout, BoucWenShape)):
        return []
    k, fc, offset = fit
    offsets = np.concatenate([[offset if input_offset else 0.0],
                              [rec.y[0] if output_offset else 0.0 for rec in records]])
    starts = []
    for shape in SATURATION_SHAPES if isinstance(layout, BoucWenShape) else (None,):
        link0 = layout.start(k[0], 1.0, 1.0, 0.0)
        link0[names.index("link.k")] = k[0]
        if isinstance(layout, BoucWenShape):
            link0[1:] = layout.shape(fc[0], *shape)
        else:
            link0[names.index("link.fc")] = fc[0]
        starts.append(prob.variables(np.concatenate([[k[-1], 0.0], link0, offsets])))
    return starts


#: The Bouc-Wen link's shapes ``(beta, gamma)`` started from the records' saturation
#: (:func:`_saturation_starts`): ``beta + gamma = 1`` (the force saturates at ``fc``),
#: unloading as stiff as the link's initial stiffness (``beta = gamma``), or stiffer
SATURATION_SHAPES = ((0.5, 0.5), (0.9, 0.1))


#: A force and position whose correlation is below minus this describe a negative stiffness:
#: a sensor's sign reversed rather than a system without one
SIGN_CORRELATION = 0.5


def _linear_start(records: list[IORecord]) -> tuple[float, float, NDArray[np.float64]]:
    """``K, C`` and each record's ``b`` of ``u = K y + C y' + b`` (least squares)."""
    rows, rhs = [], []
    n = len(records)
    for i, rec in enumerate(records):
        v = np.gradient(rec.y, rec.t)
        A = np.zeros((rec.y.size, 2 + n))
        A[:, 0], A[:, 1], A[:, 2 + i] = rec.y, v, 1.0
        rows.append(A)
        rhs.append(rec.u)
    sol = np.linalg.lstsq(np.concatenate(rows), np.concatenate(rhs), rcond=None)[0]
    return float(sol[0]), float(sol[1]), sol[2:]


def identify_quasi_static_io(records: list[IORecord], link: type, *, periodic: bool,
                             n_elements: int, offset: str, max_evaluations: int | None,
                             tol: float, t_start: float | None = None,
                             output: str = "position", nu: float | None = 1.0,
                             input_noise: bool = True) -> IOIdentification:
    """A quasi-static plant and its link from input-output records (see the module).

    Parameters
    ----------
    records : list of IORecord
        Force in, position out (checked).
    link : type
        The link's model, a registered :class:`~motionhyst.hysteresis.Hysteresis` class.
    periodic : bool
        Records of whole periods of a periodic steady state.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    offset : {"auto", "none", "input", "output", "both"}
        Offsets estimated: ``auto`` is both (a force offset moves where on its
        loops the link works, which a position offset does not).
    max_evaluations : int, optional
        The budget of model evaluations: starts and refinements together, each Jacobian's
        forward differences counted; the search uses at most this many (a budget below
        the least it needs is a ``ValueError``).
    tol : float
        ``ftol = xtol = gtol`` of the refinements.
    t_start : float, optional
        ``time.perf_counter()`` at the start of the identification.
    output : {"position", "force"}
        The error fitted: the position's simulated from the force (a force in, a position
        out), or the force's from the measured displacement (a force-displacement record:
        the displacement imposed, the force measured,
        :func:`~motionhyst.identify.io_link_force.identify_link_force`).
    nu : float or None
        A Bouc-Wen link's exponent ``n``: fixed at this value (default 1), or estimated
        (None: by the force's error, with the rest, from ``n = 2``; by the position's, the
        fit of each exponent of :data:`NU_GRID`, the best refined by a bounded scalar
        search, :func:`_exponent_profile`, its standard error from the curvature of the
        fits' cost in ``n``, `max_evaluations` then holding for each fit).
    input_noise : bool
        By the position's error (a force in): the model run from each record's force
        without its load cell's white noise, estimated as a force-displacement record's
        displacement is (:func:`_without_force_noise`; ``extra["force_noise"]``); False:
        from the force as measured.

    Returns
    -------
    IOIdentification

    Raises
    ------
    FitFailed
        A fit that is no result (worse than the linear model, or than the output's
        own spread; a model that cannot run).

    Examples
    --------
    A spring and a Jenkins link, driven by a force, measured with a position offset:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.time.quasi_static import displacement_from_force
    >>> t = np.arange(2000) / 1000.0
    >>> u = 300.0 * np.sin(2 * np.pi * 2 * t) * np.minimum(1.0, t)
    >>> y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
    >>> fit = identify_quasi_static_io([IORecord(t, u, y + 1e-4)], Jenkins, periodic=False,
    ...                                n_elements=1, offset="auto", max_evaluations=None,
    ...                                tol=1e-12)
    >>> est = fit.estimates
    >>> round(est["k"]), round(est["link.k"]), round(est["link.fc"], 6)   # N/m, N/m, N
    (100000, 300000, 100.0)
    >>> round(est["output_offset"] * 1e6, 6), round(est["input_offset"], 6) + 0.0   # um, N
    (100.0, 0.0)
    """
    t0 = time.perf_counter() if t_start is None else t_start
    force_error = output == "force"
    noise = None
    if input_noise and not force_error:  # the model's input without the load cell's noise
        records, noise = _without_force_noise(records, periodic)
    if nu is None and link is BoucWen and not force_error:
        fit = _exponent_profile(records, periodic=periodic, offset=offset,
                                max_evaluations=max_evaluations, tol=tol, t_start=t0,
                                output=output, input_noise=False)
        return _with_force_noise(fit, noise)
    layout = _layout(link, n_elements, nu)
    K, C, b = _linear_start(records)
    if not K > 0:
        u_all = np.concatenate([rec.u - np.mean(rec.u) for rec in records])
        y_all = np.concatenate([rec.y - np.mean(rec.y) for rec in records])
        if K < 0 and np.dot(u_all, y_all) < -SIGN_CORRELATION * np.linalg.norm(
                u_all) * np.linalg.norm(y_all):
            from motionhyst.identify.fd_inertia import driven_mass

            found = driven_mass(records)  # above a mass's resonance its position falls too
            if found is not None:
                raise ValueError(f"the position falls as the force rises (a stiffness of "
                                 f"{K:.3g} N/m) as a mass's does when the force drives it: "
                                 f"the records' inverse dynamics give a mass of about "
                                 f"{found[0]:.2g} kg (its force m y'' "
                                 f"{100 * found[2]:.2g} % of the force's RMS), which a "
                                 f"quasi-static plant does not have; identify a stage with a "
                                 f"mass (--plant mass-damper or mass-spring-damper)")
            raise ValueError(f"the position falls as the force rises (a stiffness of {K:.3g} "
                             f"N/m): is one sensor's sign reversed? (--scale "
                             f"displacement=-1)")
        raise ValueError("the records show no stiffness (the position does not follow the "
                         "force): a quasi-static plant does not describe them")
    y_all = np.concatenate([rec.y for rec in records])
    u_all = np.concatenate([rec.u for rec in records])
    y_scale = float(np.std(y_all)) or 1.0
    u_scale = float(np.std(u_all)) or 1.0
    v_scale = float(np.sqrt(np.mean(np.concatenate(
        [np.gradient(rec.y, rec.t) for rec in records]) ** 2))) or 1.0
    c_scale = max(abs(C), 1e-3 * K * y_scale / v_scale)
    inp, out = {"auto": (True, not force_error), "none": (False, False),
                "input": (True, False), "output": (False, True), "both": (True, True)}[offset]
    prob = _Problem(records, layout, periodic, inp, out, K, c_scale, y_scale, u_scale,
                    v_scale)
    budget = max_evaluations
    # a refinement's step costs one evaluation, and its Jacobian one for each free value
    # (forward differences; scipy counts the steps only): a budget of evaluations holds
    # when each refinement is given at most its share over this
    per_step = int(np.count_nonzero(prob.free)) + 1
    stop_operators = layout.cls in (Jenkins, MaxwellSlip)
    saturating = force_error and not stop_operators and "link.k" in layout.names and (
        "link.fc" in layout.names or isinstance(layout, BoucWenShape))
    # the records' own stop-operator fit: a start of a link of stop operators (one element
    # more: the spring), and (by the force's error) a Jenkins element and spring for a link
    # that saturates
    n_fit = (1 if layout.cls is Jenkins else n_elements) + 1 if stop_operators else 2
    fit = _stop_operator_fit(records, n_fit) if stop_operators or saturating else None
    if isinstance(layout, BoucWenShape):  # the force scale: the records' saturation
        layout.fc = float(fit[1][0]) if fit is not None and fit[1][0] > 0 else \
            0.15 * K * y_scale
    record_starts = (_stop_operator_starts(records, layout, prob, n_elements, inp, out, fit)
                     + _saturation_starts(records, layout, prob, fit, inp, out))
    velocity = [j for j, (par, _) in enumerate(layout._values()) if par.unit == "m/s"]
    grid = [(share, slip, speed) for share, slip in STARTS
            for speed in (VELOCITY_STARTS if velocity else VELOCITY_STARTS[:1])]
    n_starts = len(grid) + len(record_starts)
    if budget is not None and budget < n_starts + 2 * per_step:
        raise ValueError(f"a budget of {budget} model evaluations is below the least this "
                         f"search needs, {n_starts + 2 * per_step} (one for each of its "
                         f"{n_starts} starts, {per_step} for each step of its refinement with "
                         f"its {per_step - 1} parameters' differences, two steps)")
    # position offsets of the linear fit: u = K (y - y0) + C y' + u0 with u0 = 0 unless estimated
    y0 = np.array([float(-bi / K) if out else 0.0 for bi in b])
    candidates = []
    for share, slip, speed in grid:
        link0 = layout.start(share * K, y_scale, v_scale, 0.0, slip)
        link0[velocity] = speed * v_scale
        candidates.append(prob.variables(np.concatenate([[(1.0 - share) * K, max(C, 0.0)],
                                                         link0, [0.0], y0])))
    if not stop_operators:  # refined as the others (stop operators start at their optimum)
        candidates += record_starts
    n_start = START_NFEV if budget is None else (budget // 2) // (len(candidates) * per_step)
    exponent = prob.names.index("link.n-1") if "link.n-1" in prob.names else None
    if exponent is not None:  # the starts refined at n = 2 (exact steps), n free from the best
        prob.free[exponent] = False
        prob.fixed[exponent] = EXPONENT_START - 1.0
    starts = _refined_starts(prob, candidates, n_start)
    if stop_operators:
        starts += record_starts
    if exponent is not None:
        prob.free[exponent] = True
    # the start that predicts the positions (the forces) best continues
    with np.errstate(over="ignore"):  # a start far out: an infinite cost, never the best
        costs = [float(np.sum(prob._residuals(q[prob.free], force_error) ** 2))
                 for q in starts]
    if not starts or min(costs) >= 0.5 * FAILED_RESIDUAL ** 2 * y_all.size:  # none runs
        raise FitFailed(f"the fit failed: no start of the {link.name} link on a quasi-static "
                        f"plant can run on these records (a force it does not hold)")
    n_final = FINAL_NFEV if budget is None else (budget - prob.n_eval) // per_step
    start = starts[int(np.argmin(costs))]
    sol = prob.solve(start, force_error, n_final, tol)
    q = prob.whole(sol.x)
    v = prob.values(q)
    plant, fitted = prob.model(v)
    stopped = budget is not None and sol.status == 0  # on its budget, before it converged
    try:
        res, fit_rms, _ = _judge(prob, v, records, force_error, K, C, b, periodic, out)
    except FitFailed as exc:
        if not stopped:
            raise
        raise FitFailed(f"{exc}; the search stopped on its budget of {budget} model "
                        f"evaluations ({prob.n_eval} used) before it converged (a larger "
                        f"--max-evaluations may let it)") from None
    what = "force" if force_error else "position"
    measured = [rec.u if force_error else rec.y for rec in records]
    spread = float(np.sqrt(np.sum(np.concatenate([m - np.mean(m) for m in measured]) ** 2)))
    explained = 100.0 * (1.0 - math.sqrt(float(np.sum(res ** 2))) / spread) if spread else 0.0
    if explained < MIN_FIT_PERCENT:
        raise FitFailed(f"the fit failed: the model explains {explained:.2g} % of the "
                        f"{what}'s variation (fit below {MIN_FIT_PERCENT:g} %): these records "
                        f"show no quasi-static relation between force and position")
    # standard errors from the Jacobian in the parameters' own units
    J = (_inward_jacobian(prob, sol, force_error, layout)
         * (prob.u_scale if force_error else prob.y_scale)
         / np.where(prob.log, v, prob.scale)[prob.free])
    errors = correlated_errors(
        J, np.split(res, np.cumsum([rec.y.size for rec in records])[:-1]), FD_SINGULAR_RTOL,
        unit="N" if force_error else "m",
        signal_rms=float(np.sqrt(np.mean(np.concatenate(measured) ** 2))))
    std_free, cov, white = errors.std, errors.cov, errors.white_std
    names = [n for n, f in zip(prob.names, prob.free, strict=True) if f]
    notes = undetermined_notes(names, errors.groups, FD_SINGULAR_RTOL)
    values = v[prob.free]
    if isinstance(layout, BoucWenShape):  # written as the link is: beta + gamma = 1
        shape_notes = [n for n in ("link.beta+gamma", "link.beta-gamma") if n in notes]
        white = np.sqrt(np.maximum(np.diag(layout.normalised(names, values,
                                                             errors.white_cov)[2]), 0.0))
        names, values, cov, fitted = layout.normalised(names, values, cov)
        std_free = np.sqrt(np.maximum(np.diag(cov), 0.0))
        for n in shape_notes:
            why = notes.pop(n)
            for m in ("link.fc", "link.beta", "link.gamma"):
                notes.setdefault(m, why)
        if "link.n-1" in notes:
            notes["link.n"] = notes.pop("link.n-1")
    estimates = {n: float(x) for n, x in zip(names, values, strict=True)}
    std = {n: (None if n in notes or not math.isfinite(s) else float(s))
           for n, s in zip(names, std_free, strict=True)}
    judged = {n: None if std[n] is None else float(w) for n, w in zip(names, white, strict=True)}
    v_start = prob.values(start)
    warnings = [f"{n} = {x:.4g} ran {max(x / x0, x0 / x):.2g} times "
                f"{'above' if x > x0 else 'below'} its start: the records do not hold it (a "
                f"physically meaningless value; the link may not be needed, or another model "
                f"suits them)"
                for n, x, x0, lg, f in zip(prob.names, v, v_start, prob.log, prob.free,
                                           strict=True)
                if lg and f and x > 0 and x0 > 0 and max(x / x0, x0 / x) > RUNAWAY_FACTOR]
    stribeck = _stribeck_warning(prob, sol, force_error, v_scale,
                                 None if budget is None else (budget - prob.n_eval) // per_step)
    if stribeck is not None:
        warnings.append(stribeck)
    extra = {"offsets": {"input": float(v[2 + prob.n_link]),
                         "output": [float(x) for x in prob.output_offsets(v)]},
             "budget_reached": stopped,
             "covariance": covariance_table(names, cov, std), **errors.flags}
    return _with_force_noise(IOIdentification(
        plant=plant, hysteresis=fitted, estimates=estimates, std=std, not_identifiable=notes,
        fit_rms=fit_rms, records=per_record_errors(records, res, measured),
        seconds=time.perf_counter() - t0, periodic=periodic,
        stopping=f"{sol.message} (forward differences; ftol = xtol = gtol = {tol:g}, "
                 f"{prob.n_eval} evaluations with the starts)",
        n_evaluations=prob.n_eval, substeps=1, extra=extra, warnings=warnings,
        data=list(records), residuals=res, output=what, judged_std=judged), noise)


def _without_force_noise(records: list[IORecord], periodic: bool
                         ) -> tuple[list[IORecord], list]:
    """The records with each force estimated without its load cell's white noise
    (:func:`~motionhyst.identify.displacement_noise.estimate_displacement` on the force:
    low-passed above the band that holds the force, where that band holds white noise
    alone), and the estimates.  The force drives a link without inertia directly: a load
    cell's white noise opens small loops of the link at every reversal it makes (a Dahl
    damper's true model, run from a force with 5 N of noise on 3 kN, missed a held-out
    earthquake by 460 um, 94.8 %; from the force without it, 2 um)."""
    from motionhyst.identify.displacement_noise import estimate_displacement

    used, estimates = [], []
    for rec in records:
        u, est = estimate_displacement(rec.t, rec.u, periodic=periodic, quantity="force",
                                       unit="N")
        used.append(rec if u is rec.u else IORecord(rec.t, u, rec.y, rec.name))
        estimates.append(est)
    return used, estimates


def _with_force_noise(fit: IOIdentification, noise: list | None) -> IOIdentification:
    """`fit` with its records' force noise estimates (``extra["force_noise"]``)."""
    if noise is not None:
        fit.extra["force_noise"] = [est.to_dict() for est in noise]
    return fit


#: A Stribeck curve (LuGre's ``fs``, ``vs``) the records hold lowers the fit's RMS error by
#: more than this share against the same link without it (``fs = fc``; a LuGre damper's drop
#: from 3.5 to 2.5 kN leaves 3.1 % of its force's RMS without it; a Dahl damper's records,
#: which hold none: 0.03 and 0.06 %)
STRIBECK_GAIN = 0.01
#: Evaluations (steps) of the fit without the Stribeck curve, from the fit's values
STRIBECK_NFEV = 30
#: ... its Stribeck velocity, fixed this many times above the records' velocity RMS: a
#: friction force ``fs`` at every velocity they hold
STRIBECK_WIDE = 1e3


def _stribeck_warning(prob: _Problem, sol, force_error: bool, v_scale: float,
                      steps: int | None) -> str | None:
    """A warning naming ``fs`` and ``vs`` when the records do not hold the link's Stribeck
    curve: the fit refined for :data:`STRIBECK_NFEV` steps (`steps` where a budget leaves
    fewer) without it (its Stribeck velocity :data:`STRIBECK_WIDE` times the records' velocity
    RMS, ``fs`` the friction force, from the fit's ``fc``) ends within :data:`STRIBECK_GAIN`
    of its RMS error; None for a link without one, or a search left no steps for it."""
    names = prob.names
    if not {"link.fc", "link.fs", "link.vs"} <= set(names):
        return None
    i_fc, i_fs, i_vs = (names.index(n) for n in ("link.fc", "link.fs", "link.vs"))
    steps = STRIBECK_NFEV if steps is None else min(steps, STRIBECK_NFEV)
    if steps < 2 or not all(prob.free[[i_fc, i_fs, i_vs]]):
        return None
    q = prob.whole(sol.x)
    v = prob.values(q)
    nested = q.copy()
    nested[i_fs] = q[i_fc]
    nested[i_vs] = math.log(STRIBECK_WIDE * v_scale)
    free, fixed = prob.free.copy(), prob.fixed.copy()
    prob.free[[i_fc, i_vs]] = False
    prob.fixed[[i_fc, i_vs]] = nested[[i_fc, i_vs]]
    try:
        without = prob.solve(nested, force_error, steps, 1e-10)
    except ValueError:  # values the model refuses: no judgement
        return None
    finally:
        prob.free, prob.fixed = free, fixed
    larger = math.sqrt(without.cost / sol.cost) - 1.0 if sol.cost > 0 else math.inf
    if larger >= STRIBECK_GAIN:
        return None
    what = "force" if force_error else "position"
    how = f"grows by {100 * larger:.2g} %, less than" if larger > 0 else "does not grow by"
    return (f"link.fs = {v[i_fs]:.4g}, link.vs = {v[i_vs]:.4g}: the records hold no Stribeck "
            f"effect (without it, fs = fc, the {what}'s RMS error {how} "
            f"{100 * STRIBECK_GAIN:g} %): fs and vs are the search's, physically "
            f"meaningless; a link without one describes them (--model dahl)")


def _refined_starts(prob: _Problem, candidates: list[NDArray[np.float64]], n_start: int
                    ) -> list[NDArray[np.float64]]:
    """The `candidates` refined by the equation error: each for :data:`SCREEN_NFEV`
    evaluations, the best :data:`SCREEN_KEPT` of them on to `n_start` (all to `n_start`
    where they are no more, none where `n_start` is below 1: a small budget), in the
    candidates' order; a candidate the model refuses is left out."""
    if n_start < 1:  # a small budget: the starts compared as they are
        return list(candidates)
    screen = min(SCREEN_NFEV, n_start) if len(candidates) > SCREEN_KEPT else n_start
    screened = {}
    for i, q0 in enumerate(candidates):
        try:
            screened[i] = prob.solve(q0, True, screen, 1e-10)
        except ValueError:
            continue
    kept = sorted(screened, key=lambda i: screened[i].cost)[:SCREEN_KEPT]
    starts = []
    for i, sol in screened.items():
        if i in kept and sol.status == 0 and n_start > screen:  # stopped by the screen
            try:
                sol = prob.solve(prob.whole(sol.x), True, n_start - screen, 1e-10)
            except ValueError:
                pass
        starts.append(prob.whole(sol.x))
    return starts


def _inward_jacobian(prob: _Problem, sol, force_error: bool, layout: LinkLayout
                     ) -> NDArray[np.float64]:
    """The refinement's Jacobian, with the columns of a Bouc-Wen link's ``beta - gamma`` and
    ``n - 1`` at their bound 0 (``beta = gamma``, ``n = 1``, where the search's Jacobian
    leaves them 0) by forward differences into the accepted set: the records determine them
    as any other value."""
    jac = np.array(sol.jac, dtype=float)
    if not isinstance(layout, BoucWenShape):
        return jac
    free = [n for n, f in zip(prob.names, prob.free, strict=True) if f]
    r0 = None
    for name in ("link.beta-gamma", "link.n-1"):
        if name not in free:
            continue
        j = free.index(name)
        if sol.active_mask[j] == 0 and np.any(jac[:, j]):
            continue
        if r0 is None:
            r0 = prob._residuals(np.array(sol.x, dtype=float), force_error)
        step = 1e-6 * max(1.0, abs(float(sol.x[j])))
        q = np.array(sol.x, dtype=float)
        q[j] += step
        jac[:, j] = (prob._residuals(q, force_error) - r0) / step
    return jac


def _judge(prob: _Problem, v: NDArray[np.float64], records: list[IORecord], force_error: bool,
           K: float, C: float, b: NDArray[np.float64], periodic: bool, out: bool
           ) -> tuple[NDArray[np.float64], float, float]:
    """The fitted model's residuals, RMS error and systematic share
    (:func:`~motionhyst.identify.io_quasi_static_checks.judge_systematic`);
    :class:`FitFailed` if they are no result
    (:func:`~motionhyst.identify.io_quasi_static_checks.judge_force_fit`, or
    :func:`~motionhyst.identify.io_checks.judge_fit` and the link's gain and systematic error
    on the positions)."""
    plant, fitted = prob.model(v)
    if force_error:
        predictions = prob.forces(v)
        res = np.concatenate([f - rec.u for f, rec in zip(predictions, records, strict=True)])
        fit_rms = float(np.sqrt(np.mean(res ** 2)))
        share = judge_force_fit(fit_rms, res, records, predictions, K, C, b)
    else:
        predictions = prob.positions(v)
        res = np.concatenate([y - rec.y for y, rec in zip(predictions, records, strict=True)])
        fit_rms = float(np.sqrt(np.mean(res ** 2)))
        system = OpenLoop(plant, fitted)
        lin_rms = linear_rms(records, K, C, periodic)
        judge_fit(fit_rms, records, predictions, lin_rms, system, out)
        if lin_rms is not None:
            judge_hysteresis(lin_rms ** 2 * res.size, res, "position", K, C)
        share = judge_systematic(res, [rec.y for rec in records], "position")
    return res, fit_rms, share


def _profile_widening(below: IOIdentification, above: IOIdentification,
                      best: IOIdentification, records: list[IORecord]) -> float:
    """How many times the residuals' correlation widens the standard error of a parameter
    profiled by refits (a Bouc-Wen link's exponent, :func:`_exponent_profile`):
    ``sqrt(d^T C d / d^T d)`` with ``d`` the residuals' derivative along the profile (the
    refits' difference either side of the minimum: the other parameters follow, so it is the
    part of the exponent's column that they do not take) and ``C`` the best fit's residuals'
    weighted autocorrelation (:class:`~motionhyst.identify.residual_noise.ResidualCorrelation`,
    the sandwich of the other parameters' standard errors, the largest over its lag counts);
    1 for white residuals."""
    d = above.residuals - below.residuals
    sizes = np.cumsum([rec.y.size for rec in records])[:-1]
    if d.size != best.residuals.size or not float(d @ d) > 0:
        return 1.0
    corr = ResidualCorrelation(np.split(best.residuals, sizes))
    inner = max(float(c[0, 0]) for c in corr.inners(d[:, None]))
    return math.sqrt(max(inner / float(d @ d), 0.0))


#: The exponents of a Bouc-Wen link fitted when it is estimated (``--nu free``): its fits of
#: ``n`` free together with the rest stall (near saturation ``|zeta|^n`` hardly changes
#: with ``n``), fits of ``n`` fixed do not
NU_GRID = (1.0, 1.5, 2.0, 3.0)


def _exponent_profile(records: list[IORecord], **options) -> IOIdentification:
    """A Bouc-Wen link on a quasi-static plant with its exponent estimated: the fit of each
    exponent of :data:`NU_GRID`, the best one's neighbourhood searched by a bounded scalar
    search (to 0.01), the exponent's standard error from the curvature of the fits' cost
    ``RSS(n)`` at its minimum (``sqrt(2 s^2 / RSS'')``, ``s^2`` the residuals' variance: white
    residuals', ``judged_std``), widened for the residuals' correlation as the other
    parameters' are (:func:`_profile_widening`)."""
    from scipy.optimize import minimize_scalar

    fits: dict[float, IOIdentification] = {}

    def cost(nu: float) -> float:
        try:
            fit = identify_quasi_static_io(records, BoucWen, nu=float(nu), n_elements=1,
                                           **options)
        except FitFailed:
            return math.inf
        fits[float(nu)] = fit
        return float(np.sum(fit.residuals ** 2))

    costs = [cost(nu) for nu in NU_GRID]
    i = int(np.argmin(costs))
    if not math.isfinite(costs[i]):
        raise FitFailed(f"the fit failed: no exponent of {', '.join(map(str, NU_GRID))} gives "
                        f"a Bouc-Wen link on a quasi-static plant that describes these records")
    lo, hi = NU_GRID[max(i - 1, 0)], NU_GRID[min(i + 1, len(NU_GRID) - 1)]
    minimize_scalar(cost, bounds=(lo, hi), method="bounded",
                    options={"xatol": 0.01, "maxiter": 8})
    nus = np.array(sorted(fits))
    rss = np.array([float(np.sum(fits[nu].residuals ** 2)) for nu in nus])
    j = int(np.argmin(rss))
    best = fits[float(nus[j])]
    std = white = None
    if 0 < j < nus.size - 1:  # the parabola through the minimum and its neighbours
        a = np.polyfit(nus[j - 1:j + 2] - nus[j], rss[j - 1:j + 2], 2)[0]
        s2 = rss[j] / max(best.residuals.size - len(best.estimates) - 1, 1)
        white = float(np.sqrt(2.0 * s2 / (2.0 * a))) if a > 0 else None
        std = None if white is None else white * _profile_widening(
            fits[float(nus[j - 1])], fits[float(nus[j + 1])], best, records)
    best.estimates["link.n"] = float(nus[j])
    best.std["link.n"], best.judged_std["link.n"] = std, white
    best.stopping += (f"; exponent n by the fits of {nus.size} fixed values from "
                      f"{nus[0]:g} to {nus[-1]:g}")
    return best
