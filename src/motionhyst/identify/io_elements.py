"""Input-output identification of a stage with a link from the model registry.

Links of exact-update elements (Jenkins, Maxwell-slip, Dahl, LuGre: every
registered model but Bouc-Wen and the Iwan one), their parameters taken from
the registry's :class:`~motionhyst.hysteresis.registry.Parameter` list
(:class:`_LinkLayout`), on a mass-spring-damper or the floating two-mass stage
of eqs. (1)-(2) (:func:`identify_elements_io`).  The simulation residuals and
their Jacobian (exact, from the forward sensitivities of
:func:`~motionhyst.time.openloop.simulate_elements`, or by finite differences for
an element kind without them) are :class:`_ElementProblem`'s.
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from motionhyst.hysteresis import Hysteresis, Parameter
from motionhyst.identify.io_records import short_records
from motionhyst.identify.io_results import IOIdentification, per_record_errors
from motionhyst.identify.io_start import (
    best_linear_approximation,
    best_linear_approximation_two_mass,
    check_substeps,
)
from motionhyst.identify.io_uncertainty import (
    FD_SINGULAR_RTOL,
    SINGULAR_RTOL,
    standard_errors,
    undetermined_notes,
    weak_notes,
)
from motionhyst.time.openloop import (
    MIN_SUBSTEPS,
    STEPS_PER_MODE_PERIOD,
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    fine_input,
    simulate_elements,
)

__all__ = []

# start values and search scales by the parameter's unit (registry.Parameter.unit)
_STIFFNESS, _FORCE, _DAMPING, _VELOCITY, _LENGTH = "N/m", "N", "N s/m", "m/s", "m"


@dataclass
class _LinkLayout:
    """How a registered link model's parameters enter the search.

    Built from the model's :class:`~motionhyst.hysteresis.registry.Parameter`
    list alone, so a newly registered model needs no edit here: each value
    (a list parameter gives `n` values) is estimated, as a logarithm when it
    must be positive, linearly (scaled, bounded below by 0) when it may be 0;
    a parameter that only adds a spring or damper in parallel (``parallel``)
    is fixed at 0, since the stage's ``k`` or ``c`` holds the sum.
    """

    model: str
    cls: type
    entries: list[tuple[Parameter, int]]  # (parameter, number of values; -1: a scalar)
    fixed: dict[str, float]

    @classmethod
    def of(cls, model: str, n: int) -> _LinkLayout:
        from motionhyst.hysteresis import model_class

        klass = model_class(model)
        entries, fixed = [], {}
        for par in klass.parameters:
            if par.parallel:
                fixed[par.name] = 0.0
            elif par.many:  # a list: n values (none if the model's default is no element)
                entries.append((par, 0 if par.default == () else n))
            else:
                entries.append((par, -1))
        return cls(model, klass, entries, fixed)

    def _values(self):
        for par, count in self.entries:
            if count < 0:
                yield par, None
            else:
                for i in range(count):
                    yield par, i

    @property
    def names(self) -> list[str]:
        """Names of the estimates, ``link.`` before the model's parameter names."""
        return [f"link.{par.name}" if i is None else f"link.{par.name}[{i}]"
                for par, i in self._values()]

    @property
    def logarithmic(self) -> NDArray[np.bool_]:
        """True for the values searched as logarithms (those that must be positive)."""
        return np.array([par.kind == "positive" for par, _ in self._values()], dtype=bool)

    def build(self, v: NDArray[np.float64]) -> Hysteresis:
        """The link of the values `v` (in the order of :attr:`names`)."""
        kwargs: dict = dict(self.fixed)
        j = 0
        for par, count in self.entries:
            if count < 0:
                kwargs[par.name] = float(v[j])
                j += 1
            else:
                kwargs[par.name] = [float(x) for x in v[j:j + count]]
                j += count
        return self.cls(**kwargs)

    def scales(self, k: float, c: float, y_scale: float, v_scale: float
               ) -> NDArray[np.float64]:
        """Typical magnitude of each value, by its unit (for the linear ones' search)."""
        unit = {_STIFFNESS: k, _FORCE: k * y_scale, _DAMPING: c, _VELOCITY: v_scale,
                _LENGTH: y_scale}
        return np.array([unit.get(par.unit, 1.0) for par, _ in self._values()])

    def start(self, k_link: float, y_scale: float, v_scale: float, c: float,
              slip: float = 1.0) -> NDArray[np.float64]:
        """Start values: stiffness `k_link` slipping across the record's displacement range.

        The stiffness values share `k_link`; element ``i`` of a list slips at a
        displacement from ``0.05`` to ``2`` times `y_scale` (geometric), a
        scalar force at ``0.5 y_scale`` times the link's stiffness (a second
        force half as large again), all times `slip`; a velocity is ``0.1`` of
        `v_scale`, a damping `c`; a parameter with a default starts there.
        """
        values = list(self._values())
        n_stiff = sum(1 for par, _ in values if par.unit == _STIFFNESS)
        k_each = k_link / max(n_stiff, 1)
        n_list = max([count for _, count in self.entries] + [1])
        y_scale = y_scale * slip
        d_list = y_scale * np.geomspace(0.05, 2.0, n_list)
        n_len = sum(1 for par, i in values if par.unit == _LENGTH and i is None)
        d_len = y_scale * np.geomspace(0.05, 2.0, max(n_len, 1))
        out, n_force, j_len = [], 0, 0
        for par, i in values:
            if par.default not in (None, ()) and not par.many:
                out.append(float(par.default))  # type: ignore[arg-type]
            elif par.unit == _STIFFNESS:
                out.append(k_each)
            elif par.unit == _FORCE:
                if i is not None:
                    out.append(k_each * d_list[i])
                else:
                    out.append(k_link * 0.5 * y_scale * 1.5 ** n_force)
                    n_force += 1
            elif par.unit == _LENGTH:
                out.append(d_list[i] if i is not None else d_len[j_len])
                j_len += i is None
            elif par.unit == _VELOCITY:
                out.append(0.1 * v_scale)
            elif par.unit == _DAMPING:
                out.append(c)
            else:
                out.append(1.0)
        return np.array(out)


class _ElementProblem:
    """Simulation residuals of the stage with a link of exact-update elements.

    The search variables are the logarithms of the plant's parameters
    (``m, c, k`` or, with `plant` a :class:`~motionhyst.time.openloop.TwoMass`,
    ``m1, m2, b, k``) and the link's values, each as a logarithm or scaled
    (see :class:`_LinkLayout`); those not in `free` stay at their values in
    `fixed`.  The Jacobian is exact, from the
    forward sensitivities of the simulation
    (:func:`~motionhyst.time.openloop.simulate_elements`, computed with the
    residuals), or, for an element kind without them or with `exact` False,
    by forward differences (relative step ``1e-6``), its columns computed in
    parallel.
    """

    def __init__(self, records, periodic, substeps, layout: _LinkLayout, y_scale,
                 scale: NDArray[np.float64], free: NDArray[np.bool_] | None = None,
                 fixed: NDArray[np.float64] | None = None, exact: bool = True,
                 plant: MassSpringDamper | TwoMass | None = None):
        self.records, self.periodic, self.r = records, periodic, substeps
        self.layout, self.y_scale = layout, y_scale
        self.plant = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
        self.n_plant = len(self.plant.PARAMETERS)
        # a floating stage's periodic output is known up to a constant: compared without means
        self.centre = periodic and isinstance(self.plant, TwoMass)
        self.log = np.concatenate([[True] * self.n_plant, layout.logarithmic])
        self.scale = scale
        self.free = np.ones(self.log.size, bool) if free is None else free
        self.fixed = np.zeros(self.log.size) if fixed is None else fixed
        self.fine = [fine_input(rec.u, substeps, periodic) for rec in records]
        self.n_eval = 0
        self.exact: bool | None = None if exact else False  # sensitivities (None: untried)
        self._last: tuple | None = None

    def values(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Parameters ``m, c, k, link...`` of the (whole) search vector `q`."""
        return np.where(self.log, np.exp(np.where(self.log, q, 0.0)), q * self.scale)

    def variables(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """The whole search vector of the parameters `v`."""
        return np.where(self.log, np.log(np.where(self.log, v, 1.0)), v / self.scale)

    def derivative(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """``d v / d q`` of each parameter."""
        return np.where(self.log, v, self.scale)

    def whole(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """The whole search vector: `q_free` where free, the fixed values elsewhere."""
        q = self.fixed.copy()
        q[self.free] = q_free
        return q

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Lower bound 0 on the linearly searched values, none on the logarithms."""
        lower = np.where(self.log, -np.inf, 0.0)[self.free]
        return lower, np.full(lower.size, np.inf)

    def _run(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        v = self.values(self.whole(q_free))
        try:
            k = self.n_plant
            sys = OpenLoop(self.plant.with_parameters(v[:k]), self.layout.build(v[k:]))
            res = [sys._simulate_elements(rec.u, rec.fs, self.r, self.periodic, fine)
                   - (rec.y - np.mean(rec.y) if self.centre else rec.y)
                   for rec, fine in zip(self.records, self.fine, strict=True)]
            r = np.concatenate(res) / self.y_scale
        except ValueError:
            r = np.full(sum(rec.y.size for rec in self.records), np.nan)
        return np.where(np.isfinite(r), r, 1e3)

    def _run_exact(self, q_free: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Residuals and their exact Jacobian in the free variables (forward sensitivities);
        None if the link has an element kind without them."""
        from motionhyst.identify._element_sensitivities import row_derivatives

        v = self.values(self.whole(q_free))
        n_rows = sum(rec.y.size for rec in self.records)
        k = self.n_plant
        try:
            dparams = row_derivatives(self.layout.build, v[k:])
            if dparams is None:
                return None
            link = self.layout.build(v[k:])
            stepping = link.time_stepping()
            mech = self.plant.mechanics(v[:k])

            def one(i):
                rec = self.records[i]
                return simulate_elements(mech, stepping, rec.u, rec.fs, self.r,
                                         periodic=self.periodic, k_link=link.initial_stiffness,
                                         upsampled=self.fine[i], dparams=dparams)

            if len(self.records) > 1:  # the compiled runs release the GIL
                with ThreadPoolExecutor(max_workers=min(len(self.records),
                                                        os.cpu_count() or 1)) as pool:
                    outs = list(pool.map(one, range(len(self.records))))
            else:
                outs = [one(0)]
            r = np.concatenate([y - (rec.y - np.mean(rec.y) if self.centre else rec.y)
                                for (y, _), rec in zip(outs, self.records, strict=True)])
            J = np.concatenate([sy for _, sy in outs]) * self.derivative(v)
        except ValueError:
            return np.full(n_rows, 1e3), np.zeros((n_rows, int(self.free.sum())))
        r = r / self.y_scale
        if not np.all(np.isfinite(r)) or not np.all(np.isfinite(J)):
            return np.full(n_rows, 1e3), np.zeros((n_rows, int(self.free.sum())))
        return r, J[:, self.free] / self.y_scale

    def residuals(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """Output errors in units of the output's RMS."""
        self.n_eval += 1
        if self.exact is not False:
            out = self._run_exact(q_free)
            if out is not None:
                self.exact = True
                self._last = (q_free.tobytes(), *out)
                return out[0]
            self.exact = False
        r = self._run(q_free)
        self._last = (q_free.tobytes(), r, None)
        return r

    def jacobian(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """Exact (forward sensitivities, computed with the residuals), else forward
        differences, one column per free variable, in parallel threads."""
        if self._last is not None and self._last[0] == q_free.tobytes():
            r0, J = self._last[1], self._last[2]
        else:
            r0 = self.residuals(q_free)
            J = self._last[2]
        if J is not None:
            return J
        steps = 1e-6 * np.maximum(1.0, np.abs(q_free))

        def column(j):
            q = q_free.copy()
            q[j] += steps[j]
            return (self._run(q) - r0) / steps[j]

        self.n_eval += q_free.size
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            cols = list(pool.map(column, range(q_free.size)))
        return np.column_stack(cols)

    def solve(self, q0_free: NDArray[np.float64], tol: float, max_nfev: int):
        """Trust-region refinement of the free variables from `q0_free`."""
        return least_squares(self.residuals, q0_free, jac=self.jacobian, method="trf",
                             ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev,
                             bounds=self.bounds())


#: The rate scales (velocity parameters, e.g. LuGre's vs) are held at each of these
#: fractions of the records' RMS velocity in turn, the rest refined; the best continues
RATE_GRID = (0.1, 0.01, 0.03, 0.3, 1.0, 3.0)
#: Starts: (stage's and link's stiffness as shares of the best linear one, the link's slip
#: displacements in units of those spanning the records): the link slipping within the
#: records, hardly at all, or early (a stiff link that slips most of the time adds little
#: to the best linear stiffness)
STARTS = ((0.7, 0.3, 1.0), (0.4, 0.6, 1.0), (0.5, 0.5, 10.0), (1.0, 0.5, 0.1))


def identify_elements_io(records, model, periodic, substeps, tol, max_nfev, n, t_start,
                         start_nfev, plant="mass-spring-damper", output="y2"
                         ) -> IOIdentification:
    """Stage and a link of exact-update elements by simulation error.

    Starts (on a short part of the records): for the shares of the best linear
    stiffness of stage and link and the slip displacements of
    :data:`STARTS`, the link's values are refined with its
    rate scales (velocities) held at the first of :data:`RATE_GRID`; from the
    better, with the rate scales held at each other value of the grid (a
    profile: the rate scale and the force it shapes form a long valley when
    searched together); the best is refined with everything free on all
    records.

    A two-mass stage (floating: the link is its only hold) starts from
    :func:`best_linear_approximation_two_mass`, the link's stiffness 1, 4 and
    16 times the linear one (its initial stiffness is above that secant one),
    its forces together 0.3, 1 or 3 times the records' force RMS; a parameter
    that adds a spring or damper in parallel is fixed at 0 (the stage has none
    to the ground to hold it).
    """
    layout = _LinkLayout.of(model, n)
    y_all = np.concatenate([rec.y - (np.mean(rec.y) if periodic and plant == "two-mass"
                                     else 0.0) for rec in records])
    y_scale = float(np.sqrt(np.mean(y_all ** 2)))
    v_scale = float(np.sqrt(np.mean(np.concatenate(
        [np.gradient(rec.y, rec.t) for rec in records]) ** 2)))
    force = np.array([par.unit == _FORCE for par, _ in layout._values()], dtype=bool)
    if plant == "two-mass":
        bla, k_link, c_link = best_linear_approximation_two_mass(records, output, periodic)
        structure: MassSpringDamper | TwoMass | None = bla
        f_n = bla.mechanics().natural_frequency_hz(16.0 * k_link)
        r = substeps or max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n
                                                    / records[0].fs))
        check_substeps(records, r, f_n)
        mu = bla.m1 * bla.m2 / bla.M
        c_scale = max(c_link, 1e-3 * bla.M * 2 * np.pi * records[0].fs)
        stage0 = [bla.m1, bla.m2, max(bla.b, 1e-3 * math.sqrt(bla.k * mu)), bla.k]
        scale = np.concatenate([stage0, layout.scales(k_link, c_scale, y_scale, v_scale)])
        u_rms = float(np.sqrt(np.mean(np.concatenate([rec.u for rec in records]) ** 2)))
        starts = []
        for stiffer in (1.0, 4.0, 16.0):
            for held_force in (0.3, 1.0, 3.0):
                link0 = layout.start(stiffer * k_link, y_scale, v_scale, c_link)
                if force.any():
                    link0[force] *= held_force * u_rms / np.sum(link0[force])
                starts.append(np.concatenate([stage0, link0]))
    else:
        bla = best_linear_approximation(records)
        structure = None
        r = substeps or OpenLoop(bla).default_substeps(records[0].fs)
        c_scale = max(bla.c, 1e-3 * bla.m * 2 * np.pi * records[0].fs)
        scale = np.concatenate([[bla.m, c_scale, bla.k],
                                layout.scales(bla.k, c_scale, y_scale, v_scale)])
        starts = [np.concatenate([[bla.m, bla.c, stage * bla.k],
                                  layout.start(share * bla.k, y_scale, v_scale, bla.c, slip)])
                  for stage, share, slip in STARTS]
    n_plant = len((structure or MassSpringDamper).PARAMETERS)
    rate = np.concatenate([[False] * n_plant,
                           [par.unit == _VELOCITY for par, _ in layout._values()]])
    short = short_records(records, periodic)
    n_eval = 0
    n_start = start_nfev or 15 * scale.size

    def held(p0: NDArray[np.float64], nfev: int):
        prob = _ElementProblem(short, periodic, r, layout, y_scale, scale, ~rate,
                               plant=structure)
        prob.fixed = prob.variables(p0)
        sol = prob.solve(prob.fixed[~rate], 1e-6, nfev)
        return sol.cost, prob.values(prob.whole(sol.x)), prob.n_eval

    best = None
    for p0 in starts:
        p0[rate] = RATE_GRID[0] * v_scale
        cost, p, used = held(p0, n_start)
        n_eval += used
        if best is None or cost < best[0]:
            best = (cost, p)
    profile = [best[0]]
    if rate.any():
        p_rest = best[1]
        for fraction in RATE_GRID[1:]:
            p0 = p_rest.copy()
            p0[rate] = fraction * v_scale
            cost, p, used = held(p0, n_start)
            n_eval += used
            profile.append(cost)
            if cost < best[0]:
                best = (cost, p)
    prob = _ElementProblem(records, periodic, r, layout, y_scale, scale, plant=structure)
    sol = prob.solve(prob.variables(best[1]), tol, max_nfev)
    v = prob.values(sol.x)
    res = prob.residuals(sol.x) * y_scale
    rss = float(res @ res)
    J = prob.jacobian(sol.x) * y_scale / prob.derivative(v)  # d residual / d parameter
    n_eval += prob.n_eval
    rtol = SINGULAR_RTOL if prob.exact else FD_SINGULAR_RTOL
    std_v, groups = standard_errors(J, rss, res.size, rtol)
    names = [*prob.plant.PARAMETERS, *layout.names]
    estimates = {nm: float(x) for nm, x in zip(names, v, strict=True)}
    std: dict[str, float | None] = {}
    for nm, sd in zip(names, std_v, strict=True):
        std[nm] = float(sd) if math.isfinite(sd) else None
    not_ident = {f"link.{name}": _parallel_note(layout, name, structure)
                 for name in layout.fixed}
    not_ident.update(undetermined_notes(names, groups, rtol))
    weak = weak_notes(names, v, std_v, J, rtol, ~prob.log)
    n_short = sum(rec.y.size for rec in short)
    if rate.any() and _flat_profile(profile, n_short - scale.size):
        lo, hi = min(RATE_GRID) * v_scale, max(RATE_GRID) * v_scale
        for name in np.array(names)[rate]:
            weak[name] = (f"not determined by these records: held anywhere from {lo:.3g} to "
                          f"{hi:.3g} m/s, the other parameters fit the first record as well "
                          f"(likelihood ratio below {PROFILE_CHI2:g}, 95 %): the rate-dependent "
                          f"term is not seen, and the link's forces are its level at the "
                          f"records' velocities")
    for name, why in weak.items():
        if name not in not_ident:
            not_ident[name] = why
            std[name] = None
    return IOIdentification(
        plant=prob.plant.with_parameters(v[:n_plant]), hysteresis=layout.build(v[n_plant:]),
        estimates=estimates, std=std, not_identifiable=not_ident,
        fit_rms=float(np.sqrt(rss / res.size)), records=per_record_errors(records, res),
        seconds=time.perf_counter() - t_start, periodic=periodic,
        stopping=f"{sol.message} ({'exact' if prob.exact else 'finite-difference'} "
                 f"Jacobian; ftol = xtol = gtol = {tol:g}, "
                 f"at most {max_nfev} evaluations; {sol.nfev} used)",
        n_evaluations=n_eval, substeps=r)


#: 95 % point of the chi-square distribution with one degree of freedom
PROFILE_CHI2 = 3.84


def _flat_profile(costs: list[float], dof: int) -> bool:
    """True if no cost of a profile exceeds the least by the 95 % likelihood-ratio bound.

    ``(RSS_i - RSS_min) / sigma^2 < 3.84`` for every point, ``sigma^2 = RSS_min / dof``.
    """
    least = min(costs)
    return bool(least > 0 and (max(costs) - least) / least * max(dof, 1) < PROFILE_CHI2)


def _parallel_note(layout: _LinkLayout, name: str, plant=None) -> str:
    par = next(p for p in layout.cls.parameters if p.name == name)
    what, stage = ("a spring", "k") if par.parallel == "spring" else ("a damper", "c")
    if isinstance(plant, TwoMass):
        return (f"{what} to the ground in parallel with the link; not estimated with a "
                f"two-mass stage (which has none to the ground): fixed at 0")
    return (f"{what} in parallel with the stage's: only the sum {stage} + {name} enters the "
            f"output; fixed at 0, the stage's {stage} holds the sum")
