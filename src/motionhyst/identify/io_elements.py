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
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.blas import few_blas_threads
from motionhyst.hysteresis import Coulomb, Jenkins, MaxwellSlip
from motionhyst.hysteresis.stepping import Stepping
from motionhyst.identify.io_budget import BudgetSpent, EvaluationBudget, settled, solve_within
from motionhyst.identify.io_checks import (
    PROFILE_CHI2,
    flat_profile,
    judge_fit,
    noise_cost,
    plausibility_warnings,
)
from motionhyst.identify.io_differences import REFUSED, forward_differences
from motionhyst.identify.io_force import RecordForce
from motionhyst.identify.io_layout import FORCE_UNIT, VELOCITY_UNIT
from motionhyst.identify.io_layout import LinkLayout as _LinkLayout
from motionhyst.identify.io_offsets import Extras, initial_state
from motionhyst.identify.io_one_way import one_way_slip, slider_slips
from motionhyst.identify.io_predict import run_from_state, state_from_window
from motionhyst.identify.io_records import short_records
from motionhyst.identify.io_refine import refine
from motionhyst.identify.io_results import IOIdentification, per_record_errors
from motionhyst.identify.io_start import (
    best_linear_approximation,
    best_linear_approximation_two_mass,
    check_search_memory,
    check_substeps,
    extras_start,
    inverse_dynamics,
    reference_mass,
)
from motionhyst.identify.io_stiffness import profile_stiffness, stiffness_grid
from motionhyst.identify.io_uncertainty import (
    FD_SINGULAR_RTOL,
    SINGULAR_RTOL,
    WindowNoise,
    correlated_errors,
    covariance_table,
    parallel_note,
    undetermined_notes,
    weak_notes,
    window_price,
)
from motionhyst.identify.residual_noise import white_noise_variance
from motionhyst.identify.rigid_limit import as_rigid_limit, rigid_seed
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import (
    MAX_SHOOTING_STATES,
    MIN_SUBSTEPS,
    STEPS_PER_MODE_PERIOD,
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    simulate_elements,
)

__all__ = []

#: The units of a link's forces and velocities (registry.Parameter.unit)
_FORCE, _VELOCITY = FORCE_UNIT, VELOCITY_UNIT


#: Step of the forward differences where a link has no sensitivities (relative, in the
#: search variables)
FD_STEP = 1e-6
#: Step of the secants of a link with a rigid slider (the Coulomb model)
RIGID_FD_STEP = 1e-3
#: Step of the offsets' and initial states' forward differences, in units of their scales
EXTRA_FD_STEP = 1e-4
#: Rows of the sensitivities scaled into the Jacobian at a time (bounds the temporary copy)
_ROWS = 1 << 16
_TAKEN = object()  # a Jacobian handed to the search: computed again if asked for again
#: Periods a periodic record's run may take at a point of the search: a trial point that has
#: not settled by then (a stage clamped by a stiff link, whose output is rounding noise) is
#: refused as parameters the model cannot run, and the search steps back
SEARCH_PERIODS = 30


#: The search layout of a registered link's parameters, for the other identification modules
#: (the quasi-static plant's, :mod:`~motionhyst.identify.io_quasi_static`)
LinkLayout = _LinkLayout


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
                 plant: MassSpringDamper | TwoMass | None = None,
                 extras: Extras | None = None, window: int | None = None,
                 budget: EvaluationBudget | None = None):
        self.records, self.periodic, self.r = records, periodic, substeps
        self.layout, self.y_scale = layout, y_scale
        self.plant = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
        self.n_plant = len(self.plant.PARAMETERS)
        self.n_link = len(layout.names)
        self.extras = extras if extras is not None else Extras(False, False, (),
                                                               len(records))
        # a floating stage's periodic output is known up to a constant: compared without means
        self.centre = periodic and isinstance(self.plant, TwoMass)
        self.log = np.concatenate([np.ones(self.n_plant, bool), layout.logarithmic,
                                   np.zeros(self.extras.size, bool)]).astype(bool)
        self.signed = np.arange(self.log.size) >= self.n_plant + self.n_link
        if layout.skew:  # the stage's viscous friction by direction: either sign
            self.signed[self.n_plant + self.n_link - 1] = True
        self.scale = scale
        self.free = np.ones(self.log.size, bool) if free is None else free
        self.fixed = np.zeros(self.log.size) if fixed is None else fixed
        self.window = window  # each record's state set from its first samples (None: extras)
        self._forces: list[RecordForce] | None = None  # upsampled at the first run
        self.n_eval = 0  # the evaluations, each charged to the search's budget first
        self.budget = budget if budget is not None else EvaluationBudget()
        self.exact: bool | None = None if exact else False  # sensitivities (None: untried)
        self.fd_step = FD_STEP
        if getattr(layout.cls, "rigid", False):
            # a rigid slider's stick and slip events change step by step with the parameters:
            # the simulation's own derivative misses what they do together; secants see it
            self.exact, self.fd_step = False, RIGID_FD_STEP
        self._last: tuple | None = None

    @property
    def forces(self) -> list[RecordForce]:
        """Each record's upsampled force, made at the first run (not held before it)."""
        if self._forces is None:
            self._forces = [RecordForce(rec, self.r, self.periodic, self.extras.input_offset,
                                        self.extras.input_drift) for rec in self.records]
        return self._forces

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
        """Lower bound 0 on the linearly searched link values, none on the logarithms and
        the offsets and initial states."""
        lower = np.where(self.log | self.signed, -np.inf, 0.0)[self.free]
        return lower, np.full(lower.size, np.inf)

    def outputs(self, v: NDArray[np.float64], sens: bool = False,
                only: int | None = None) -> list[tuple[NDArray, NDArray]]:
        """Each record's simulated output (with its offsets and initial state) and, with
        `sens`, its sensitivities in the plant's and the link's parameters; `only`: that
        record alone.  Raises ``ValueError`` for parameters the model refuses."""
        from motionhyst.identify._element_sensitivities import row_derivatives

        k, nl = self.n_plant, self.n_link
        u0, y0, init = self.extras.split(v[k + nl:])
        drift = self.extras.drift(v[k + nl:])
        link = self.layout.build(v[k:k + nl])
        dparams = None
        if sens:
            dparams = row_derivatives(self.layout.build, v[k:k + nl])
            if dparams is None:
                raise LookupError("no sensitivities for this link")
        stepping = link.time_stepping()
        mech = self.mechanics(v)
        skew = nl - 1 if self.layout.skew else None
        k_link = link.initial_stiffness

        def one(i):
            rec = self.records[i]
            u, fine = self._inputs(i, u0, drift)
            if self.window is not None:
                return self._from_window(mech, stepping, k_link, rec, u, fine, dparams, skew)
            y, sy = simulate_elements(mech, stepping, u, rec.fs, self.r,
                                      periodic=self.periodic, k_link=k_link, upsampled=fine(),
                                      dparams=dparams, skew_column=skew,
                                      x0=initial_state(mech.n, self.extras.initial, init[i]),
                                      periods=SEARCH_PERIODS)
            return y + y0[i], sy

        which = range(len(self.records)) if only is None else [only]
        if len(which) > 1:  # the compiled runs release the GIL
            with ThreadPoolExecutor(max_workers=min(len(which), os.cpu_count() or 1)) as pool:
                return list(pool.map(one, which))
        return [one(i) for i in which]

    def mechanics(self, v: NDArray[np.float64]):
        """The stage's mechanics at the parameters `v` (with its viscous friction by
        direction when the layout estimates it)."""
        mech = self.plant.mechanics(v[:self.n_plant])
        if self.layout.skew:
            mech.c_skew = float(v[self.n_plant + self.n_link - 1])
            if abs(mech.c_skew) > float(mech.C[0, 0]):  # a direction with negative friction
                raise ValueError("c_skew beyond the stage's c: parameters the model refuses")
        return mech

    def stage(self, v: NDArray[np.float64]):
        """The stage (a plant) at the parameters `v`, its ``c_skew`` included."""
        plant = self.plant.with_parameters(v[:self.n_plant])
        if self.layout.skew:
            plant.c_skew = float(v[self.n_plant + self.n_link - 1])
        return plant

    def _from_window(self, mech, stepping, k_link, rec, u, fine, dparams, skew=None):
        """A record run from the state its first :attr:`window` samples set
        (:func:`~motionhyst.identify.io_predict.state_from_window`), as ``predict
        --init-from`` runs it; the sensitivities include the state's own dependence on
        the parameters (its least squares over the window, to first order); `fine()` gives the
        upsampled force (:meth:`_inputs`)."""
        p, vel = state_from_window(mech, stepping, k_link, u, rec.y, rec.fs, self.r,
                                   self.window)
        y, sy = run_from_state(mech, stepping, k_link, u, rec.fs, self.r, p, vel, fine(),
                               dparams, skew)
        if dparams is None or sy.shape[1] == 0:
            return y, sy
        S = self._state_columns(mech, stepping, k_link, rec, u, fine, p, vel, y)
        w = self.window
        d_state = -np.linalg.lstsq(S[:w], sy[:w], rcond=None)[0]
        return y, sy + S @ d_state

    def _state_columns(self, mech, stepping, k_link, rec, u, fine, p, vel, y
                       ) -> NDArray[np.float64]:
        """``d y / d (position, velocity)`` of a record's run from the state ``p, vel``
        (`y`): a floating stage's position exactly (its offset), the rest by forward
        differences."""
        cols = []
        for dp, dv in ((1.0, 0.0), (0.0, 1.0)):
            if dp and mech.floating:
                cols.append(np.ones_like(y))
                continue
            step = EXTRA_FD_STEP * (dp * max(abs(p), self.y_scale)
                                    + dv * max(abs(vel), self.y_scale * rec.fs / self.window))
            y2, _ = run_from_state(mech, stepping, k_link, u, rec.fs, self.r, p + dp * step,
                                   vel + dv * step, fine())
            cols.append((y2 - y) / step)
        return np.column_stack(cols)

    def _inputs(self, i: int, u0: float, drift: float):
        """Record `i`'s force less the force offset `u0` and its drift, and a callable
        giving its upsampled run's: a period's whole, a run from a start's blocks (a fresh
        iterator at each call; :class:`~motionhyst.identify.io_force.RecordForce`)."""
        rec, force = self.records[i], self.forces[i]
        u = rec.u - u0
        if self.extras.input_drift:  # the offset drifting over the record's time
            u = u - drift * rec.t
        if self.periodic:
            return u, lambda: force.whole(u0, drift)
        return u, lambda: force.blocks(u0, drift)

    def window_states(self, v: NDArray[np.float64], window: int | None = None
                      ) -> list[tuple[float, float]]:
        """Each record's ``(position, velocity)`` set from its window (or its first `window`
        samples) at the parameters `v`."""
        k, nl = self.n_plant, self.n_link
        u0 = self.extras.split(v[k + nl:])[0]
        drift = self.extras.drift(v[k + nl:])
        link = self.layout.build(v[k:k + nl])
        mech = self.mechanics(v)
        return [state_from_window(mech, link.time_stepping(), link.initial_stiffness,
                                  rec.u - u0 - drift * rec.t, rec.y, rec.fs, self.r,
                                  window or self.window)
                for rec in self.records]

    def window_noise(self, v: NDArray[np.float64], sigma2: float) -> WindowNoise:
        """How the noise of each record's window reaches its residuals at the parameters `v`
        (:class:`~motionhyst.identify.io_uncertainty.WindowNoise`, the positions' noise
        variance `sigma2`): the run's sensitivity to the state its window sets, and that
        state's least squares over the window (a simulation per record and state column, a
        floating stage's position exact; the window's own least squares runs only its
        samples)."""
        k, nl = self.n_plant, self.n_link
        u0 = self.extras.split(v[k + nl:])[0]
        drift = self.extras.drift(v[k + nl:])
        link = self.layout.build(v[k:k + nl])
        mech, stepping, k_link = self.mechanics(v), link.time_stepping(), link.initial_stiffness
        parts, row = [], 0
        for i, rec in enumerate(self.records):
            u, fine = self._inputs(i, u0, drift)
            p, vel = state_from_window(mech, stepping, k_link, u, rec.y, rec.fs, self.r,
                                       self.window)
            y, _ = run_from_state(mech, stepping, k_link, u, rec.fs, self.r, p, vel, fine())
            self.charge(3 - int(mech.floating))  # the run and its state's columns
            S = self._state_columns(mech, stepping, k_link, rec, u, fine, p, vel, y)
            parts.append((row, S, np.linalg.pinv(S[:self.window])))
            row += rec.y.size
        return WindowNoise(row, parts, sigma2)

    def _measured(self, rec) -> NDArray[np.float64]:
        return rec.y - np.mean(rec.y) if self.centre else rec.y

    # a value the model refuses (a mass run to 0 or overflowing) is a large residual, without
    # numpy's warnings on stderr; threaded, so on each run and not around the search
    @np.errstate(all="ignore")
    def run_rows(self, q_free: NDArray[np.float64], only: int | None = None
                 ) -> NDArray[np.float64] | None:
        """The residuals (of record `only` alone: its rows), non-finite ones as
        :data:`~motionhyst.identify.io_differences.REFUSED`; None for values the model
        refuses."""
        v = self.values(self.whole(q_free))
        recs = self.records if only is None else [self.records[only]]
        try:
            res = [y - self._measured(rec)
                   for (y, _), rec in zip(self.outputs(v, only=only), recs, strict=True)]
        except (ValueError, ArithmeticError):  # parameters the model refuses
            return None
        r = np.concatenate(res) / self.y_scale
        return np.where(np.isfinite(r), r, REFUSED)

    def _run(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        r = self.run_rows(q_free)
        return np.full(sum(rec.y.size for rec in self.records), REFUSED) if r is None else r

    def errors_at(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """The output errors [m] of the model at the values `v`, every record's (not counted
        in the search's budget; ``ValueError`` for values the model refuses)."""
        return np.concatenate([y - self._measured(rec) for (y, _), rec
                               in zip(self.outputs(v), self.records, strict=True)])

    def _extra_columns(self, v: NDArray[np.float64], y: list[NDArray[np.float64]]
                       ) -> NDArray[np.float64]:
        """Derivatives of the outputs in the offsets and initial states (rows of all the
        records): the position offsets exactly, the others by forward differences (the
        force offset from a run of every record, an initial state from its record's)."""
        ex = self.extras
        base = self.n_plant + self.n_link
        n_rows = [rec.y.size for rec in self.records]
        starts = np.concatenate([[0], np.cumsum(n_rows)])
        J = np.zeros((starts[-1], ex.size))
        for j in range(int(ex.input_offset) + int(ex.input_drift)):  # those of every record
            step = EXTRA_FD_STEP * max(abs(v[base + j]), self.scale[base + j])
            w = v.copy()
            w[base + j] += step
            self.charge(1)
            J[:, j] = (np.concatenate([yy for yy, _ in self.outputs(w)])
                       - np.concatenate(y)) / step
        for i in range(len(self.records)):
            rows = slice(starts[i], starts[i + 1])
            for j in ex.columns_of_record(i):
                name = ex.names[j].split("[")[0]
                if name == "output_offset":
                    J[rows, j] = 1.0
                    continue
                step = EXTRA_FD_STEP * max(abs(v[base + j]), self.scale[base + j])
                w = v.copy()
                w[base + j] += step
                self.charge(1)
                J[rows, j] = (self.outputs(w, only=i)[0][0] - y[i]) / step
        return J

    def _split_rows(self, res: NDArray[np.float64], measured: bool = False
                    ) -> list[NDArray[np.float64]]:
        """Rows of all records split by record (`measured`: residuals plus the data)."""
        out, i = [], 0
        for rec in self.records:
            part = res[i:i + rec.y.size]
            out.append(part + self._measured(rec) if measured else part)
            i += rec.y.size
        return out

    def _with_extras(self, q_free: NDArray[np.float64], J: NDArray[np.float64],
                     r0: NDArray[np.float64]) -> NDArray[np.float64]:
        """The Jacobian of the sensitivities (free plant and link columns) with the offsets'
        and initial states' columns in their places."""
        if not self.extras.size:
            return J
        v = self.values(self.whole(q_free))
        k = self.n_plant + self.n_link
        full = np.zeros((J.shape[0], int(self.free.sum())))
        full[:, :J.shape[1]] = J
        try:
            Je = self._extra_columns(v, self._split_rows(r0 * self.y_scale, measured=True))
            Je *= self.derivative(v)[k:]
            Je /= self.y_scale
            full[:, J.shape[1]:] = Je[:, self.free[k:]]
        except (ValueError, ArithmeticError):  # parameters the model refuses
            pass  # a model the simulation refuses: the residuals are flat there
        return full

    @np.errstate(all="ignore")  # as _run
    def _run_exact(self, q_free: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Residuals and their exact Jacobian in the free plant and link variables (forward
        sensitivities; the offsets' and initial states' columns are added by
        :meth:`jacobian`); None if the link has an element kind without them."""
        v = self.values(self.whole(q_free))
        n_rows = sum(rec.y.size for rec in self.records)
        k = self.n_plant + self.n_link
        n_sens = int(self.free[:k].sum())
        try:
            outs = self.outputs(v, sens=True)
            r = np.concatenate([y - self._measured(rec)
                                for (y, _), rec in zip(outs, self.records, strict=True)])
        except LookupError:
            return None
        except (ValueError, ArithmeticError):  # parameters the model refuses
            return np.full(n_rows, 1e3), np.zeros((n_rows, n_sens))
        r = r / self.y_scale
        if not np.all(np.isfinite(r)):
            return np.full(n_rows, 1e3), np.zeros((n_rows, n_sens))
        # the free columns of (sensitivities x d value / d variable) / y_scale, checked finite,
        # a block of rows at a time into one array (each record's released once copied)
        d, free = self.derivative(v)[:k], self.free[:k]
        J, at = np.empty((n_rows, n_sens)), 0
        for i in range(len(outs)):
            sy, outs[i] = outs[i][1], None
            for a in range(0, sy.shape[0], _ROWS):
                part = sy[a:a + _ROWS] * d
                if not np.all(np.isfinite(part)):
                    return np.full(n_rows, 1e3), np.zeros((n_rows, n_sens))
                J[at + a:at + a + part.shape[0]] = part[:, free]
            at += sy.shape[0]
        J /= self.y_scale
        return r, J

    def cost(self, q_free: NDArray[np.float64]) -> float:
        """The sum of the squared :meth:`residuals`."""
        return float(np.sum(self.residuals(q_free) ** 2))

    def residuals(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """Output errors in units of the output's RMS."""
        self.charge(1)
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
        differences (:func:`~motionhyst.identify.io_differences.forward_differences`)."""
        if (self._last is not None and self._last[0] == q_free.tobytes()
                and self._last[2] is not _TAKEN):
            r0, J = self._last[1], self._last[2]
        else:
            r0 = self.residuals(q_free)
            J = self._last[2]
        if J is not None:
            self._last = (self._last[0], r0, _TAKEN)  # not held beside the search's copy
            return self._with_extras(q_free, J, r0)
        return forward_differences(self, q_free, r0,
                                   self.fd_step * np.maximum(1.0, np.abs(q_free)))

    def charge(self, n: int) -> None:
        """Count `n` evaluations about to run (the search's budget first)."""
        self.budget.charge(n)
        self.n_eval += n

    def solve(self, q0_free: NDArray[np.float64], tol: float, max_nfev: int):
        """Trust-region refinement of the free variables from `q0_free`, ended where its
        budget is spent (:func:`~motionhyst.identify.io_budget.solve_within`); on one BLAS
        thread where its Jacobian is small (:func:`~motionhyst.core.blas.few_blas_threads`:
        each step's SVD of it)."""
        rows = sum(rec.y.size for rec in self.records)
        with few_blas_threads(rows, int(self.free.sum())):
            return solve_within(self.residuals, q0_free, jac=self.jacobian, method="trf",
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


def identify_elements_io(records, link, periodic, substeps, tol, max_nfev, n, t_start,
                         start_nfev, plant, offset="none", from_rest=True, budget=None,
                         init_window=None, asymmetric=False, drift=False,
                         skew=False, rigid=None, rigid_limit=False) -> IOIdentification:
    """Stage and a link of exact-update elements by simulation error.

    Starts (on a short part of the records): for the shares of the best linear
    stiffness of stage and link and the slip displacements of
    :data:`STARTS`, the link's values are refined with its
    rate scales (velocities) held at the first of :data:`RATE_GRID`; from the
    better, with the rate scales held at each other value of the grid (a
    profile: the rate scale and the force it shapes form a long valley when
    searched together); the best is refined with everything free on all
    records.  Periodic records of whole periods end the starts at the first
    whose fit leaves no more than their noise (its variance from the periods'
    spread about their mean, :func:`noise_cost`): no later start can fit them
    better.

    A two-mass stage (floating: the link is its only hold) starts from
    :func:`best_linear_approximation_two_mass`, the link's stiffness 1, 4 and
    16 times the linear one (its initial stiffness is above that secant one),
    its forces together 0.3, 1 or 3 times the records' force RMS; a parameter
    that adds a spring or damper in parallel is fixed at 0 (the stage has none
    to the ground to hold it).

    A mass-damper (a positioning axis: no spring, friction holds it) starts from
    the records' inverse-dynamics mass, damper, Coulomb force and force offset
    (:func:`~motionhyst.identify.io_start.inverse_dynamics`), the link's forces
    together that Coulomb force or half of it, slipping after 0.001 to 0.1 of
    the output's RMS (:data:`AXIS_STARTS`).  With `asymmetric` (the Coulomb link
    on a mass-damper) the viscous friction depends on the direction: the stage's
    ``c`` is the smaller one, the link's ``c_pos`` or ``c_neg`` the excess in the
    other direction (chosen, and started, from the inverse dynamics with a
    viscous term per direction), its slip force ``fc`` the same both ways.  With
    `skew` (any link on a mass-damper) the stage's own viscous friction depends on
    the direction: its ``c_skew`` is estimated with the link (started from the
    inverse dynamics' ``(c_pos - c_neg) / 2``, ``c`` from their mean).

    A link other than the rigid slider on a mass-damper also starts from the
    Coulomb link's fit (:func:`~motionhyst.identify.rigid_limit.rigid_seed`: every friction
    link's limit; `rigid`, one already made, is reused), when that fits the records better than
    the other starts (reported instead with `rigid_limit`:
    :func:`~motionhyst.identify.rigid_limit.as_rigid_limit`).

    The offsets and initial states of `offset` and `from_rest`
    (:class:`~motionhyst.identify.io_offsets.Extras`) are estimated with them:
    started at zero (the position offset of a floating stage at the record's
    first sample, its velocity at the first samples' slope); the refinement on all
    records runs from the best start and from it with each record's initial state as
    its first :data:`~motionhyst.identify.io_predict.INIT_WINDOW` samples set it there
    (:func:`~motionhyst.identify.io_refine.refine`), and the better end is kept.  A Jenkins
    link (or a Maxwell-slip link of one element) on a mass-damper is then profiled over its
    stiffness (:func:`~motionhyst.identify.io_stiffness.profile_stiffness`): a held stiffness
    that fits the records better than that end is refined from, and the better end kept.

    `link` is the link model's class, `plant` a plant instance of the stage's class and
    measured output (its values are not used): a floating stage of two masses is the
    two-mass stage, of one a mass-damper, else a mass-spring-damper.
    """
    shape = plant.mechanics(np.ones(len(plant.PARAMETERS)))  # the structure, whatever values
    axis = shape.floating and shape.n == 1  # a positioning axis: friction holds it
    idim = inverse_dynamics(records, shape.floating, asymmetric or skew)
    faster = None
    if asymmetric and not skew:  # the stage's c is the smaller viscous friction, the link
        # adds the rest
        faster = "c_pos" if idim["c_pos"] >= idim["c_neg"] else "c_neg"
        idim["c"] = min(idim["c_pos"], idim["c_neg"])
    layout = _LinkLayout.of(link, n, faster, skew)
    y_all = np.concatenate([rec.y - (np.mean(rec.y) if periodic and shape.n > 1
                                     else 0.0) for rec in records])
    y_scale = float(np.sqrt(np.mean(y_all ** 2)))
    v_scale = float(np.sqrt(np.mean(np.concatenate(
        [np.gradient(rec.y, rec.t) for rec in records]) ** 2)))
    u_rms = float(np.sqrt(np.mean(np.concatenate([rec.u for rec in records]) ** 2)))
    force = np.array([par.unit == _FORCE for par, _ in layout._values()], dtype=bool)
    if shape.n > 1:
        bla, k_link, c_link = best_linear_approximation_two_mass(records, plant.output, periodic)
        structure: MassSpringDamper | TwoMass | MassDamper = bla
        f_n = bla.mechanics().natural_frequency_hz(16.0 * k_link)
        r = substeps or max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n
                                                    / records[0].fs))
        check_substeps(records, r, f_n)
        mu = bla.m1 * bla.m2 / bla.M
        c_scale = max(c_link, 1e-3 * bla.M * 2 * np.pi * records[0].fs)
        stage0 = [bla.m1, bla.m2, max(bla.b, 1e-3 * math.sqrt(bla.k * mu)), bla.k]
        scale = np.concatenate([stage0, layout.scales(k_link, c_scale, y_scale, v_scale)])
        starts = []
        for stiffer in (1.0, 4.0, 16.0):
            for held_force in (0.3, 1.0, 3.0):
                link0 = layout.start(stiffer * k_link, y_scale, v_scale, c_link)
                if force.any():
                    link0[force] *= held_force * u_rms / np.sum(link0[force])
                starts.append(np.concatenate([stage0, link0]))
    elif axis:
        bla = best_linear_approximation(records)
        m0 = idim["m"] if idim["m"] > 0 else bla.m
        c0 = idim["c"] if idim["c"] > 0 else bla.c
        f0 = idim["fc"] if idim["fc"] > 0 else 0.3 * u_rms
        structure = MassDamper(m0, c0)
        c_scale = max(c0, 1e-3 * m0 * 2 * np.pi * records[0].fs)
        k_ref = u_rms / y_scale  # a stiffness whose force over the output's RMS is the force's
        scale = np.concatenate([[m0, c_scale], layout.scales(k_ref, c_scale, y_scale,
                                                             v_scale)])
        starts = []
        for share, slip in AXIS_STARTS:
            k0 = 2.0 * share * f0 / (slip * y_scale)  # its forces at share * f0
            link0 = layout.start(k0, y_scale, v_scale, c0, slip)
            if faster is not None:
                link0[1] = abs(idim["c_pos"] - idim["c_neg"])
            if skew:
                link0[-1] = 0.5 * (idim["c_pos"] - idim["c_neg"])
            starts.append(np.concatenate([[m0, c0], link0]))
        r = substeps or OpenLoop(structure, layout.build(starts[0][2:])).default_substeps(
            records[0].fs)
    else:
        bla = best_linear_approximation(records)
        structure = MassSpringDamper(bla.m, bla.c, bla.k)
        r = substeps or OpenLoop(bla).default_substeps(records[0].fs)
        c_scale = max(bla.c, 1e-3 * bla.m * 2 * np.pi * records[0].fs)
        scale = np.concatenate([[bla.m, c_scale, bla.k],
                                layout.scales(bla.k, c_scale, y_scale, v_scale)])
        starts = [np.concatenate([[bla.m, bla.c, stage * bla.k],
                                  layout.start(share * bla.k, y_scale, v_scale, bla.c, slip)])
                  for stage, share, slip in STARTS]
    if shape.n == 1:  # a stage of one mass (a two-mass stage's steps are checked above)
        check_substeps(records, r, None)
    n_plant = len(structure.PARAMETERS)
    floating = structure.mechanics().floating
    extras = Extras.choose(offset, floating=floating, periodic=periodic, from_rest=from_rest,
                           n_records=len(records), window=init_window is not None, drift=drift)
    t_span = max(float(rec.t[-1] - rec.t[0]) for rec in records)
    scale = np.concatenate([scale, extras.scales(u_rms, y_scale, v_scale, t_span)])
    # the whole search's memory (its Coulomb fit's is no more), before anything is upsampled;
    # a link's on an axis also refines on the records' segments (its Coulomb fit's first)
    states = (2 * structure.mechanics().n
              + layout.build(starts[0][n_plant:]).time_stepping().codes.size) if periodic else 0
    own = init_window is None and not periodic  # each record's state estimated from its start
    rigid_link = bool(getattr(layout.cls, "rigid", False))
    segments = (rigid_link or axis) and own and floating and extras.output_offset \
        and extras.initial == ("v0",)
    check_search_memory(records, r, scale.size, n_plant + len(layout.names),
                        periodic=periodic, drift=extras.input_drift, segments=segments,
                        states=states if states <= MAX_SHOOTING_STATES else 0)
    rate = np.concatenate([np.zeros(n_plant, bool),
                           [par.unit == _VELOCITY for par, _ in layout._values()],
                           np.zeros(extras.size, bool)]).astype(bool)
    short = short_records(records, periodic)
    short_extras = Extras(extras.input_offset, extras.output_offset, extras.initial, 1,
                          extras.input_drift)
    n_base = n_plant + len(layout.names)
    short_scale = np.concatenate([scale[:n_base], short_extras.scales(
        u_rms, y_scale, v_scale, float(short[0].t[-1] - short[0].t[0]))])
    short_rate = rate[:n_base + short_extras.size]
    n_eval = 0
    n_start = start_nfev or 15 * scale.size
    plan = budget if isinstance(budget, EvaluationBudget) else EvaluationBudget(budget)
    final, shares = plan.plan_starts(len(starts) + (len(RATE_GRID) - 1) * rate.any(),
                                     1 + scale.size, axis and not getattr(layout.cls, "rigid",
                                                                         False) and not rigid)

    def held(p0: NDArray[np.float64], nfev: int):
        """A start refined on the short records within its share of the starts' budget."""
        prob = _ElementProblem(short, periodic, r, layout, y_scale, short_scale, ~short_rate,
                               plant=structure, extras=short_extras, window=init_window,
                               budget=plan)
        prob.fixed = prob.variables(p0)
        with plan.share(next(shares)):
            try:
                sol = prob.solve(prob.fixed[~short_rate], 1e-6, nfev)
            except BudgetSpent:  # not even the start ran: no better than any
                return math.inf, p0, prob.n_eval
        return sol.cost, prob.values(prob.whole(sol.x)), prob.n_eval

    short_start = extras_start(short_extras, short, floating, idim["u0"])
    floor = noise_cost(short, y_scale) if periodic else None
    best = None
    for p0 in starts:
        p0 = np.concatenate([p0, short_start])
        p0[short_rate] = RATE_GRID[0] * v_scale
        cost, p, used = held(p0, n_start)
        n_eval += used
        if best is None or cost < best[0]:
            best = (cost, p)
        if floor is not None and best[0] <= floor:
            break  # the records fitted to their own noise: no further start can do better
    profile = [best[0]]
    if rate.any():
        p_rest = best[1]
        for fraction in RATE_GRID[1:]:
            p0 = p_rest.copy()
            p0[short_rate] = fraction * v_scale
            cost, p, used = held(p0, n_start)
            n_eval += used
            profile += [cost] if math.isfinite(cost) else []  # one its budget did not run
            if cost < best[0]:
                best = (cost, p)
    full_start = extras_start(extras, records, floating, idim["u0"])
    # the short run's force offset and first record's offset and initial state carry over
    for j, name in enumerate(short_extras.names):
        full_start[extras.names.index(name if len(records) == 1 or name == "input_offset"
                                      else f"{name}[0]")] = best[1][n_base + j]
    prob = _ElementProblem(records, periodic, r, layout, y_scale, scale, plant=structure,
                           extras=extras, window=init_window, budget=plan)
    q0 = prob.variables(np.concatenate([best[1][:n_base], full_start]))
    coulomb, other = None, []
    if axis and not getattr(layout.cls, "rigid", False):
        # the rigid slider is every friction link's limit: its fit is a start for theirs
        with plan.share(None if plan.left is None else (plan.left - final) // 2):
            seed, used, coulomb = rigid_seed(
                lambda: identify_elements_io(
                    records, Coulomb, periodic, substeps, tol, max_nfev, 1, t_start,
                    start_nfev, plant, offset, from_rest, budget=plan, init_window=init_window,
                    drift=extras.input_drift, asymmetric=skew),
                layout, y_scale, v_scale, extras.names, force, rate[n_plant:n_base],
                RATE_GRID[0] * v_scale, skew, rigid)
        n_eval += used
        if seed is not None:  # both refined (refine's others): a start's cost is no guide
            q_seed = prob.variables(seed)
            q0, other = (q_seed, [q0]) if prob.cost(q_seed) < prob.cost(q0) else (q0, [q_seed])
    # what the standard errors at the end take: a run and the Jacobian's differences
    reserve = (1 + (prob.extras.size if prob.exact else q0.size)
               + (3 * len(records) if init_window is not None else 0))
    # the initial state the records' first samples set at the start's other values: the state
    # carried over from the starts may lie in another well of the initial velocity (a friction
    # link slipping at the start, the position offset making up for it; a Jenkins axis of 1e5
    # samples ended at 19.5 times its noise there).  Both are refined and the better end kept:
    # the lower cost at the start is no guide (two Coulomb records, one moving each way: the
    # window's state fitted better at the start and ended at fc 18.5 N for a true 20 N)
    sol, q_start, most = refine(prob, q0, tol, max_nfev, reserve, bool(extras.initial) and own,
                                rigid_link, segments, other)
    # a Jenkins link, or a Maxwell-slip link of one element (a Jenkins link): its stiffness
    k_name = ("link.k" if layout.cls is Jenkins else "link.k[0]"
              if layout.cls is MaxwellSlip and n == 1 else None)
    if axis and k_name is not None:  # the stiffness's other wells, as the records' cost says
        v_end = prob.values(prob.whole(sol.x))
        at = n_plant + layout.names.index(k_name)
        sol = profile_stiffness(prob, sol, at, stiffness_grid(
            records, v_end[0], float(np.sum(v_end[n_plant:n_base][force])), v_end[at]),
            reserve)
    v = prob.values(sol.x)
    res = prob.residuals(sol.x) * y_scale
    rss = float(res @ res)
    J = prob.jacobian(sol.x) * y_scale / prob.derivative(v)  # d residual / d parameter
    n_eval += prob.n_eval
    rtol = SINGULAR_RTOL if prob.exact else FD_SINGULAR_RTOL
    # a window's state moves with its samples' noise, and so every residual after it
    noise = (prob.window_noise(v, white_noise_variance(prob._split_rows(res)))
             if init_window is not None else None)
    # the residuals' correlation widens them; a fit above the noise makes them lower bounds;
    # what the records determine is judged as white residuals say
    errors = correlated_errors(
        J, prob._split_rows(res), rtol, noise,
        signal_rms=float(np.sqrt(np.mean(np.concatenate([rec.y for rec in records]) ** 2))))
    std_v, groups, cov, white = errors.std, errors.groups, errors.cov, errors.white_std
    names = [*prob.plant.PARAMETERS, *layout.names, *extras.names]
    estimates = {nm: float(x) for nm, x in zip(names, v, strict=True)}
    std: dict[str, float | None] = {}
    for nm, sd in zip(names, std_v, strict=True):
        std[nm] = float(sd) if math.isfinite(sd) else None
    two_mass = isinstance(structure, TwoMass)
    not_ident = {f"link.{name}": parallel_note(layout.cls, name, two_mass)
                 if faster is None else
                 (f"the viscous friction moving {'backward' if name == 'c_neg' else 'forward'} "
                  f"is the stage's c (the link's {faster} adds to it in the other "
                  f"direction): fixed at 0")
                 for name in layout.fixed}
    not_ident.update(undetermined_notes(names, groups, rtol))
    weak = weak_notes(names, v, white, J, rtol, ~prob.log)
    n_short = sum(rec.y.size for rec in short)
    if rate.any() and flat_profile(profile, n_short - short_scale.size):
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
    slips = (slider_slips(layout.build(v[n_plant:n_base]), prob._split_rows(res, measured=True))
             if shape.n == 1 else None)  # the link moves with the measured position
    one_way = one_way_slip(names, v, rss, res.size, prob.errors_at, cov, layout.cls.name, slips)
    for name in one_way.names if one_way is not None else ():  # one force: the sum's known
        std[name] = None
        not_ident[name] = one_way.note
    limit = (as_rigid_limit(coulomb, {"m": estimates["m"], "link.k": estimates[k_name]},
                            {"link.k": std[k_name]}, records[0].fs, math.sqrt(rss / res.size),
                            layout.cls.name)
             if rigid_limit and coulomb is not None and k_name is not None else None)
    if limit is not None:  # before the checks: a stiffness beyond the records may not step
        return replace(limit, n_evaluations=n_eval, seconds=time.perf_counter() - t_start)
    u0, y0, init = extras.split(v[n_base:])
    initial_state_out = {name: init[:, a].tolist() for a, name in enumerate(extras.initial)}
    if init_window is not None:  # the window's state: a floating stage's position is its offset
        states = np.array(prob.window_states(v))
        if floating:
            y0 = states[:, 0]
            initial_state_out = {"v0": states[:, 1].tolist()}
        else:
            initial_state_out = {"y0": states[:, 0].tolist(), "v0": states[:, 1].tolist()}
    fitted = prob.stage(v)
    if extras.input_offset:
        fitted.force_offset = -u0  # the offset of the measured force, on the plant
    drift_rate = extras.drift(v[n_base:])
    if extras.input_drift:
        fitted.force_drift = -drift_rate
    link = layout.build(v[n_plant:n_base])
    judge_fit(float(np.sqrt(rss / res.size)), records, prob._split_rows(res, measured=True),
              _linear_rms(records, structure, r, periodic, extras.output_offset),
              OpenLoop(prob.stage(v), link),
              extras.output_offset or (init_window is not None and floating))
    bound = [nm for nm, x, lin, sc in zip(names[:n_base], v[:n_base],
                                          ~(prob.log | prob.signed)[:n_base],
                                          scale[:n_base], strict=True)
             if lin and nm not in not_ident and abs(x) <= 1e-9 * sc]
    # a positive parameter searched as a logarithm has no bound: one that ran orders of
    # magnitude from the final search's start (the short runs' best or the rigid seed) is at
    # the edge of the model's range all the same
    runaway = {nm: x / x0 for nm, x, x0, lg in zip(names[:n_base], v[:n_base],
                                                    prob.values(q_start)[:n_base],
                                                    prob.log[:n_base], strict=True)
               if lg and x0 > 0 and not RUNAWAY ** -1 < x / x0 < RUNAWAY}
    masses = {nm: float(x) for nm, x in zip(prob.plant.PARAMETERS, v, strict=False)
              if nm in ("m", "m1", "m2")}
    notes = plausibility_warnings(estimates, masses, reference_mass(records, shape.floating),
                                  records, bound, runaway, shape.floating)
    if one_way is not None:
        notes.append(one_way.line)
    if noise is not None:
        notes.extend(window_price(J, rss, res.size, rtol, noise, names[:n_base], init_window))
    calm = settled(sol, prob.values, std_v)  # on its cap, still to 1 % of the reported std
    return IOIdentification(
        plant=fitted, hysteresis=link, warnings=notes,
        estimates=estimates, std=std, not_identifiable=not_ident,
        fit_rms=float(np.sqrt(rss / res.size)), records=per_record_errors(records, res),
        seconds=time.perf_counter() - t_start, periodic=periodic,
        stopping=f"{sol.message} ({'exact' if prob.exact else 'finite-difference'} "
                 f"Jacobian; ftol = xtol = gtol = {tol:g}, "
                 f"at most {most} evaluations; {sol.nfev} used"
                 f"{'; settled to 1 % of each reported (widened) std' if calm else ''})",
        n_evaluations=n_eval, substeps=r, data=list(records), residuals=res, rigid_limit=coulomb,
        extra={"offsets": {"input": u0, "output": y0.tolist(),
                           **({"input_drift": drift_rate} if extras.input_drift else {})},
               "initial_state": initial_state_out, "init_window": init_window,
               "budget_reached": bool(sol.status == 0 and not calm),
               "covariance": covariance_table(names, cov, std),
               **errors.flags,
               **({"one_way": one_way.to_dict()} if one_way is not None else {})},
        judged_std={nm: None if s is None else float(w)
                    for (nm, s), w in zip(std.items(), white, strict=True)})


def _linear_rms(records, structure, r, periodic, output_offset) -> float | None:
    """RMS simulation error of the best linear model (the start's stage without its link)
    on the records, about its mean with an output offset; None if it cannot be run."""
    try:
        mech = structure.mechanics()
        res = np.concatenate([simulate_elements(mech, Stepping.empty(), rec.u, rec.fs, r,
                                                periodic=periodic)[0] - rec.y
                              for rec in records])
    except (ValueError, ArithmeticError):
        return None
    if not np.all(np.isfinite(res)):
        return None
    return float(np.std(res) if output_offset else np.sqrt(np.mean(res ** 2)))


#: A positive parameter that ends this factor from its start value is reported as at the edge
RUNAWAY = 1e4


#: Starts of a link on a mass-damper: (the link's forces as a share of the records'
#: inverse-dynamics Coulomb force, the displacement it slips after in units of the output's
#: RMS)
AXIS_STARTS = ((1.0, 1e-3), (0.5, 1e-2), (1.0, 1e-1))
