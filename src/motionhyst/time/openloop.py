"""Open-loop systems: a stage with a dynamic link, force in, a position out.

The stage is any plant of :mod:`motionhyst.plants` with inertia: its
state-space form :class:`~motionhyst.plants.mechanics.Mechanics`
(``M q'' + C q' + K q = e (u + f0 - w)``, ``x = (q, q')``), the force ``u``
(with the plant's constant offset ``f0``) and the link force ``w`` acting on
the link's coordinate, ``w`` the force of a hysteresis model (any model of
:mod:`motionhyst.hysteresis`) of that coordinate's position; for example

* :class:`~motionhyst.plants.MassSpringDamper`, the stage of the Bouc-Wen
  benchmark (Noel and Schoukens 2016) and of any single-mass test rig
  without feedback, ``m y'' + c y' + k y + w = u``, output ``y``;
* :class:`~motionhyst.plants.MassDamper`, a positioning axis (no spring);
* :class:`~motionhyst.plants.TwoMassStage`, the floating two-mass stage of
  the paper's eqs. (1)-(2) without its controller: ``m1`` actuated (position
  ``y1``, where the link acts), ``m2`` the point of control (``y2``), spring
  ``k`` and damper ``b`` between them; output ``y2`` (default) or ``y1``
  (``TwoMass``, its older name here).

:class:`OpenLoop` simulates the response to a sampled force record from rest,
or the periodic steady state when the record is one period of a periodic
force.  Only the link holds a floating stage (the two-mass stage, or
``k = 0``) in place: from rest, a force the link cannot hold makes it run
away (the simulation says so by its numbers); a periodic steady state exists
only if the position repeats too, is then defined up to a constant and
returned with zero mean, and a stage that moves on by the same distance
every period (a slipping element, a Bouc-Wen link ratcheting under an
unsymmetric force) is reported as having none.

Accuracy
--------
A sampled force says nothing about the force between samples; like the
benchmark's own data, the record is taken as band-limited and upsampled
(:mod:`motionhyst.time.resample`).  The system is then integrated with a fine
fixed step, ``substeps`` per sample (default: at least 20 and at least 400 per
period of the undamped mode):

* Bouc-Wen links and the linear stage: classical fourth-order Runge-Kutta on
  ``(q, q', z)`` with the forward sensitivities when asked
  (:mod:`motionhyst.time.bouc_wen_rk4`, what the Bouc-Wen benchmark's
  identification fits with);
* the other links: on the time engine (:mod:`motionhyst.time.engine`), the
  stage discretised exactly for a force linear between fine steps
  (first-order hold) and the link advanced by its exact update (as
  :func:`motionhyst.time.simulation.simulate`), implicit in ``w`` and solved by
  a fixed-point iteration, or in closed form for a lone Coulomb slider; second
  order in the step.  One compiled run (:func:`simulate_elements`) for both
  plants, with the forward sensitivities of the output to the plant's and the
  link's parameters when asked.

Periodic runs repeat the period until the output settles
(:mod:`motionhyst.time.periodic_runs`).  A run from a start goes through the
record in blocks (:func:`~motionhyst.time.resample.fine_blocks`), its state
carried from one block to the next, with the numbers of one run over the whole
upsampled record (bit for bit; to rounding for a record of whole periods longer
than a block, upsampled from its period): its memory is the record's and one
block's, whatever its length.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.budget import check_memory
from motionhyst.hysteresis import BoucWen, Hysteresis
from motionhyst.hysteresis.along_stroke import FIXED_IN_OPEN_LOOP, AlongStroke
from motionhyst.hysteresis.stepping import (
    DIFFERENTIATED,
    N_PARAMS,
    Stepping,
)
from motionhyst.plants.mass_spring_damper import MassSpringDamper
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.time.bouc_wen_rk4 import BW_PARAMETERS as BW_PARAMETERS
from motionhyst.time.bouc_wen_rk4 import bouc_wen_general, simulate_bouc_wen
from motionhyst.time.engine import FohStep, LoopState, run_steps
from motionhyst.time.kernel import MAX_FIXED_POINT_ITERATIONS, OPEN, StepNotConverged
from motionhyst.time.periodic_runs import MAX_PERIODIC_DECAYS as MAX_PERIODIC_DECAYS
from motionhyst.time.periodic_runs import PERIODIC_RTOL as PERIODIC_RTOL
from motionhyst.time.periodic_runs import (
    PeriodExtrapolation,
    floating_linear_periodic,
    max_periods,
    newton_periodic,
    periodic_output,
    whole_periods,
)
from motionhyst.time.resample import SINC_HALF_WIDTH as SINC_HALF_WIDTH
from motionhyst.time.resample import STAMP_TOLERANCE as STAMP_TOLERANCE
from motionhyst.time.resample import (
    block_samples,
    check_record,
    fine_blocks,
    fine_input,
    held_nodes,
    period_upsampling_bytes,
    sampling_rate,
)
from motionhyst.time.resample import is_periodic_record as is_periodic_record
from motionhyst.time.resample import upsample as upsample

# the record helpers, the periodic runs and the Bouc-Wen integrator have modules of their own in
# motionhyst.time (resample, periodic_runs, bouc_wen_rk4); imported here too, where they were
__all__ = ["FINE_BYTES", "MAX_SHOOTING_STATES", "MIN_SUBSTEPS", "ONE_BLOCK_BYTES",
           "REST_NODE_BYTES", "REST_SAMPLE_BYTES", "SAMPLE_BYTES",
           "STEPS_PER_MODE_PERIOD", "OpenLoop", "OpenLoopResponse", "simulate_elements"]

MIN_SUBSTEPS = 20
STEPS_PER_MODE_PERIOD = 400
#: States (the plant's and the link elements') up to which a periodic run is found by Newton's
#: method on the period map: each of them is a further column of sensitivities every period
MAX_SHOOTING_STATES = 40
FINE_BYTES = 48
"""Memory of one integration step of an open-loop run: fine input, midpoints, output [bytes]."""
SAMPLE_BYTES = 64
"""Memory of one record sample of an open-loop run: time, force, output and their copies [bytes]."""
REST_NODE_BYTES = 21
"""Memory of one integration step of an open-loop run from rest, the record's force at the
steps of one block at a time [bytes] (measured, traced, blocks of 2.1e6 steps: 16.6 a step
for Jenkins on an axis at 20 and 100 substeps, 17.5-18.7 for Bouc-Wen on a two-mass stage by
RK4, in blocks or one; 12-27 % above)."""
REST_SAMPLE_BYTES = 20
"""Memory of one record sample of an open-loop run from rest: time, force, output [bytes]
(measured: 16 traced; 25 % above)."""
ONE_BLOCK_BYTES = (10, 48)
"""Memory of a run from rest of a link stepped as elements whose record is upsampled in one
block, a step and a sample [bytes] (measured, traced, Jenkins on an axis: 8 and 40, within
3 % at 2e4 and 1e5 samples of 5 and 20 steps; 20 % above)."""


#: The two-mass stage's name as an open-loop plant before the plants had one class.
TwoMass = TwoMassStage

Plant = MassSpringDamper | TwoMassStage
"""An open-loop plant: force in, the link on its (first) mass, a position out."""


# ----------------------------------------------------------------- the system
@dataclass
class OpenLoopResponse:
    """Response of an :class:`OpenLoop` on the record's time grid.

    Attributes
    ----------
    t : ndarray
        Time [s].
    force : ndarray
        Input force [N].
    displacement : ndarray
        The plant's output position [m] (``y``; ``y2`` or ``y1`` of a two-mass stage).
    periodic : bool
        True for a periodic steady state, False for a run from rest.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(256) / 750
    >>> out = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4)).simulate(t, np.sin(2 * np.pi * 6 * t))
    >>> list(out.columns()), out.periodic
    (['time', 'displacement'], False)
    """

    t: NDArray[np.float64]
    force: NDArray[np.float64]
    displacement: NDArray[np.float64]
    periodic: bool

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """The output signals by CSV column name."""
        return {"time": self.t, "displacement": self.displacement}


class OpenLoop:
    """An open-loop plant with a hysteresis link, force in, a position out.

    Parameters
    ----------
    plant : Plant
        The stage (:class:`~motionhyst.plants.registry.Plant`); the force and the
        link act on its link coordinate.  A plant without inertia
        (:class:`~motionhyst.plants.quasi_static.QuasiStatic`) is the link's balance
        at each sample (:mod:`motionhyst.time.quasi_static`).
    hysteresis : Hysteresis or None
        The link's model (None: the linear stage alone).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> sys = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=1e4, fc=1.0))
    >>> t = np.arange(512) / 750
    >>> out = sys.simulate(t, 20 * np.sin(2 * np.pi * 3 * t), periodic=True)
    >>> round(float(np.max(out.displacement)) * 1e4, 2)   # between 20 N/(k + kJ) and 20 N/k
    4.63

    A two-mass stage held by a Bouc-Wen link, ``y2`` measured:

    >>> from motionhyst.hysteresis import BoucWen
    >>> sys = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5), BoucWen(k=5e4, fc=20.0, beta=0.6,
    ...                                                        gamma=0.2))
    >>> out = sys.simulate(t, 20 * np.sin(2 * np.pi * 3 * t))   # from rest
    >>> round(float(np.max(np.abs(out.displacement))) * 1e4, 1)
    11.3
    """

    def __init__(self, plant: Plant, hysteresis: Hysteresis | None = None) -> None:
        if isinstance(hysteresis, AlongStroke):
            raise ValueError(FIXED_IN_OPEN_LOOP)
        self.plant = plant
        self.hysteresis = hysteresis

    def __repr__(self) -> str:
        return f"OpenLoop({self.plant!r}, {self.hysteresis!r})"

    def _k_link(self) -> float:
        return self.hysteresis.initial_stiffness if self.hysteresis is not None else 0.0

    def default_substeps(self, fs: float) -> int:
        """Integration steps per record sample: >= 20 and >= 400 per period of the fastest
        mode (the link taken as its initial stiffness); 1 for a plant without inertia (no
        mode: the balance is solved at the samples, :mod:`motionhyst.time.quasi_static`).

        Parameters
        ----------
        fs : float
            Sampling rate of the record [Hz].

        Returns
        -------
        int

        Examples
        --------
        >>> from motionhyst.hysteresis import Jenkins
        >>> sys = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=5e4, fc=20.0))
        >>> sys.default_substeps(750.0)          # at least 20
        20
        >>> sys.default_substeps(50.0)           # 400 a period of its 35.6 Hz mode
        285
        """
        if not self.plant.has_inertia:
            return 1
        f_n = self.plant.mechanics().natural_frequency_hz(self._k_link())
        return max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n / fs))

    def _shooting_states(self) -> int:
        """States whose sensitivities a periodic run of exact-update elements carries
        (:func:`simulate_elements`' Newton steps on the period map); 0 where it repeats
        periods instead."""
        if self.hysteresis is None or not hasattr(self.hysteresis, "time_stepping"):
            return 0
        codes = self.hysteresis.time_stepping().codes
        n = 2 * self.plant.mechanics().n + codes.size
        return n if np.all(np.isin(codes, DIFFERENTIATED)) and n <= MAX_SHOOTING_STATES else 0

    def _bw_parameters(self) -> NDArray[np.float64] | None:
        h = self.hysteresis
        if h is None:
            return np.array([*self.plant.values(), 0.0, 0.0, 0.0, 1.0])
        if isinstance(h, BoucWen):
            return np.array([*self.plant.values(), *bouc_wen_general(h)])
        return None

    def simulate(self, t: ArrayLike, force: ArrayLike, *, periodic: bool = False,
                 substeps: int | None = None) -> OpenLoopResponse:
        """The output position for a force record, from rest or as the periodic steady state.

        Parameters
        ----------
        t : array_like
            Uniform time grid [s], at least 2 samples.
        force : array_like
            Force at the instants `t` [N].
        periodic : bool
            False: from rest (``q = q' = 0``, link relaxed) at ``t[0]``.  True:
            `force` is one period (or whole periods) of a periodic force; the
            response is the periodic steady state, reached by repeating the
            period until the output changes by less than ``1e-12`` of its
            amplitude from one period to the next.  A floating plant (no spring
            to the ground: the two-mass stage, or ``k = 0``) has such a state
            only if the link carries the force's mean, and then at any constant
            offset: it is returned with zero mean.  Not for a plant whose
            force offset drifts (``force_drift``: its force at ``t`` is ``u(t) +
            f0 + f1 t``, which repeats no period).
        substeps : int, optional
            Integration steps per sample (default :meth:`default_substeps`; a plant
            without inertia has none: ignored).

        Returns
        -------
        OpenLoopResponse
        """
        tt, u = check_record(t, force)
        recorded = u
        drift = float(getattr(self.plant, "force_drift", 0.0))
        if drift:  # the force offset at each sample's time (the constant part: mechanics)
            if periodic:
                raise ValueError(f"a force offset drifting at {drift:g} N/s has no periodic "
                                 f"steady state; simulate from a start")
            u = u + drift * tt
        if not self.plant.has_inertia:  # no masses: the link balances the force at each sample
            from motionhyst.time.quasi_static import displacement_from_force

            y = displacement_from_force(self.plant, self.hysteresis, tt, u, periodic=periodic)
            return OpenLoopResponse(tt, u, y, periodic)
        fs = sampling_rate(tt)
        r = substeps or self.default_substeps(fs)
        mech = self.plant.mechanics()
        p = self._rk4_parameters()
        states = self._shooting_states() if periodic and p is None else 0
        check_memory(self.memory(u, r, periodic=periodic),
                     f"{u.size} samples of {r} integration steps each"
                     + (f" (and the periodic steady state's sensitivities to its {states} "
                        f"states)" if states else ""), "fewer samples or substeps")
        if periodic and self.hysteresis is None and mech.floating:
            y = floating_linear_periodic(self.plant.mechanics(), u, fs)
        elif p is not None:
            y, _ = simulate_bouc_wen(p, u, fs, r, periodic=periodic, sensitivities=False,
                                     plant=self.plant)
        else:
            y = self._simulate_elements(u, fs, r, periodic)
        return OpenLoopResponse(tt, recorded, y, periodic)

    def memory(self, force: ArrayLike, substeps: int, *, periodic: bool = False) -> float:
        """Bytes :meth:`simulate` needs for the force record `force`, as it checks them
        against the memory budget before its run: from a start, the record's force at the
        integration steps of one block at a time (:func:`~motionhyst.time.resample.fine_blocks`,
        :data:`REST_NODE_BYTES` a step) and the record (:data:`REST_SAMPLE_BYTES` a sample),
        or a link's elements stepped on a record in one block (:data:`ONE_BLOCK_BYTES`);
        a periodic run as :meth:`_periodic_memory` says.

        Parameters
        ----------
        force : array_like
            The force record [N].
        substeps : int
            Integration steps per sample.
        periodic : bool
            As for :meth:`simulate`.

        Returns
        -------
        float

        Examples
        --------
        >>> from motionhyst.hysteresis import Jenkins
        >>> sys = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=5e4, fc=20.0))
        >>> u = np.sin(np.arange(20000) / 7.0)
        >>> round(sys.memory(u, 28) / 1e6, 1)                  # 5.6e5 steps from rest
        6.6
        """
        u = np.asarray(force, dtype=float)
        if not periodic:
            nodes = held_nodes(u, int(substeps))
            if u.size - 1 <= block_samples(int(substeps)) and self._rk4_parameters() is None:
                return ONE_BLOCK_BYTES[0] * nodes + ONE_BLOCK_BYTES[1] * u.size
            return REST_NODE_BYTES * nodes + REST_SAMPLE_BYTES * u.size
        return self._periodic_memory(u, int(substeps), self._rk4_parameters() is not None)

    def _rk4_parameters(self) -> NDArray[np.float64] | None:
        """The parameters of a run by RK4 (a Bouc-Wen link, or none), None for a link stepped
        as elements: the plant's viscous friction by direction is stepped with the link's
        elements, and so is a Bouc-Wen link on a positioning axis (one floating mass): a
        friction link, whose exact update in the displacement follows its sticking however
        stiff (RK4 in time diverges there once k |y'| / fc exceeds the step's stability
        limit)."""
        mech = self.plant.mechanics()
        axis = isinstance(self.hysteresis, BoucWen) and mech.floating and mech.n == 1
        return None if getattr(self.plant, "c_skew", 0.0) or axis else self._bw_parameters()

    def _periodic_memory(self, u: NDArray[np.float64], r: int, rk4: bool) -> float:
        """Bytes of a periodic run of the force `u` (:meth:`simulate`): the record and the
        output (:data:`SAMPLE_BYTES` a sample), and the larger of the upsampling of its period
        (:func:`~motionhyst.time.resample.period_upsampling_bytes`) and the run of it: the
        period's fine force (steps and their midpoints for a Bouc-Wen link run by RK4),
        the outputs of two periods and, for Newton's steps on the period map, the output's
        sensitivities to the start states (16 bytes a state and sample), with the kernel's
        record of them, three rows a sample, for a block of the period (two blocks' while
        the next is made).  Measured (address space above a warmed process): a Dahl link on
        a spring, 3 states, 1e5 samples of 1, 20, 100 steps: 16, 65, 320 MB (estimate 23,
        70, 326); Maxwell-slip of 38 elements, 40 states: 98 and 163 MB at 1e5 and 2e5
        samples of 1 step (106 and 179)."""
        m = u.size // whole_periods(u)  # the steady state of one period, repeated
        if self.hysteresis is None and self.plant.mechanics().floating:
            return SAMPLE_BYTES * u.size + 16.0 * m  # in the frequency domain, per sample
        factor = 2 * r if rk4 else r
        cols = 0 if rk4 else self._shooting_states()
        step = block_samples(max(factor, 3 * (1 + cols)))
        record = 0 if rk4 else 24.0 * (1 + cols) * min(m, step) * (2 if m > step else 1)
        run = 8.0 * (m * factor + 1) + record + (16.0 + 16.0 * cols) * m
        return SAMPLE_BYTES * u.size + max(period_upsampling_bytes(m, factor), run)

    def _simulate_elements(self, u, fs, r, periodic, upsampled=None):
        """Displacement of a link of exact-update elements (`upsampled`: ``fine_input(u, r,
        periodic)`` if already computed)."""
        st = Stepping.empty() if self.hysteresis is None else self.hysteresis.time_stepping()
        y, _ = simulate_elements(self.plant.mechanics(), st, u, fs, r, periodic=periodic,
                                 k_link=self._k_link(), upsampled=upsampled)
        return y


def _with_offset(fine: NDArray[np.float64], mech: Mechanics) -> NDArray[np.float64]:
    """The fine input with the plant's constant force offset added (contiguous floats)."""
    fine = np.ascontiguousarray(fine, dtype=float)
    return fine + mech.force_offset if mech.force_offset else fine


class _SubstepsNotConverged(StepNotConverged, ValueError):
    """The link's implicit step of an open-loop run that did not converge: a ``ValueError``
    too, which a search takes for a point of the parameters to leave."""


def _check_converged(worst: int) -> None:
    if worst > MAX_FIXED_POINT_ITERATIONS:
        raise _SubstepsNotConverged(f"the link's implicit step did not converge in "
                                    f"{MAX_FIXED_POINT_ITERATIONS} iterations: the link is too "
                                    f"stiff (or too strongly damped) for the integration step",
                                    "use more substeps")


def simulate_elements(mech: Mechanics, stepping: Stepping, u: NDArray[np.float64], fs: float,
                      r: int, *, periodic: bool, k_link: float = 0.0,
                      upsampled: NDArray[np.float64] | Iterable[NDArray[np.float64]] | None = None,
                      dparams: NDArray[np.float64] | None = None,
                      x0: NDArray[np.float64] | None = None, periods: int | None = None,
                      shooting: bool = True, skew_column: int | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Output of a plant with a link of exact-update elements, and its sensitivities (FOH).

    The plant is discretised exactly for a force linear over each of the `r`
    fine steps per sample (:meth:`Mechanics.foh`), the elements advanced by
    their exact update (:func:`~motionhyst.hysteresis.stepping.advance`), the
    step's link force solved by a fixed-point iteration; with `dparams`, the
    forward sensitivities of the output are carried along in the same compiled
    run (the partials of each element's update,
    :func:`~motionhyst.hysteresis.stepping.advance_partials`, and of the
    implicit link force).  What :meth:`OpenLoop.simulate` runs for such a link,
    and the exact Jacobian of :mod:`motionhyst.identify.input_output`; the
    output is the same with or without the sensitivities, bit for bit.  The plant's
    viscous friction by direction (``mech.c_skew``) is stepped with the link's elements
    (:meth:`~motionhyst.hysteresis.stepping.Stepping.with_viscous`); from a start only.

    Parameters
    ----------
    mech : Mechanics
        The plant.
    stepping : Stepping
        The link's rows (:meth:`Hysteresis.time_stepping`; empty: no link).
    u : ndarray
        Force record [N] at `fs`.
    fs : float
        Sampling rate of the record [Hz].
    r : int
        Fine steps per sample.
    periodic : bool
        From rest (False) or the periodic steady state of the period `u`
        (True: the output to :data:`PERIODIC_RTOL` of its amplitude and, with
        `dparams`, the sensitivities to 1e-8 of theirs, found as `shooting`
        says; returned with zero mean for a floating plant, as
        :meth:`OpenLoop.simulate`).
    k_link : float
        The link's initial stiffness [N/m] (bounds the periods a periodic run may take).
    upsampled : ndarray or iterator of ndarray, optional
        ``fine_input(u, r, periodic)``, if already computed; for a run that is not
        periodic also its consecutive blocks, each sharing its last node with the next
        block's first (as :func:`~motionhyst.time.resample.fine_blocks` yields them).
    dparams : ndarray, shape (elements, N_PARAMS, P_link), optional
        The derivatives of the rows' parameters in the link's `P_link`
        parameters (every element of a kind in
        :data:`~motionhyst.hysteresis.stepping.DIFFERENTIATED`); None: no
        sensitivities.
    x0 : ndarray, shape (2n,), optional
        The plant's state ``(q, q')`` at the first sample of a run that is not
        periodic (default: at rest, ``0``); the link starts relaxed.
    periods : int, optional
        Most periods a periodic run takes before it is refused as not settling
        (default: until the slowest mode has decayed
        :data:`~motionhyst.time.periodic_runs.MAX_PERIODIC_DECAYS` times, at most
        1000); a search caps its trial points' runs with it.
    shooting : bool
        A periodic run's steady state by Newton's method on the period map
        (:func:`~motionhyst.time.periodic_runs.newton_periodic`: two periods
        where the map is affine) for elements of the kinds
        :data:`~motionhyst.hysteresis.stepping.DIFFERENTIATED` and at most
        :data:`MAX_SHOOTING_STATES` states (default; the sensitivities of a link
        that never slips on a plant with a spring, whose preload the path from
        rest sets, by repeated periods); False: periods repeated (and
        extrapolated) until the output repeats.  Both give
        the steady state to the tolerances above.
    skew_column : int, optional
        With `dparams`: its column (a link parameter the rows do not depend on) that
        stands for ``mech.c_skew``, whose derivative it then holds.

    Returns
    -------
    y : ndarray
        Output position at the samples [m].
    dy : ndarray, shape (len(u), p + P_link)
        Its derivatives in the plant's `p` parameters (the rows of
        ``mech.dmass``), then the link's; ``(len(u), 0)`` without `dparams`.

    Examples
    --------
    A Jenkins link ``(k, fc)``: its row ``(k, fc)`` moves one for one with them.

    >>> from motionhyst.hysteresis import Jenkins
    >>> link = Jenkins(k=2e4, fc=10.0)
    >>> t = np.arange(256) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t)
    >>> dparams = np.zeros((1, N_PARAMS, 2))
    >>> dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0
    >>> plant = MassSpringDamper(2.0, 10.0, 5e4)
    >>> y, dy = simulate_elements(plant.mechanics(), link.time_stepping(), u, 750.0, 10,
    ...                           periodic=False, dparams=dparams)
    >>> ref = OpenLoop(plant, link).simulate(t, u, substeps=10)
    >>> bool(np.array_equal(y, ref.displacement)), dy.shape    # m, c, k, link k, fc
    (True, (256, 5))
    """
    if mech.c_skew or skew_column is not None:
        if periodic:
            raise ValueError("viscous friction by direction (c_skew) is run from a start, "
                             "not as a periodic steady state")
        n_own = stepping.codes.size
        stepping = stepping.with_viscous(mech.c_skew, -mech.c_skew,
                                         keep_zero=skew_column is not None)
        if dparams is not None and stepping.codes.size > n_own:  # the added row's
            dparams = np.concatenate([dparams, np.zeros((1, *dparams.shape[1:]))])
        if dparams is not None and skew_column is not None:
            # c_pos = +c_skew, c_neg = -c_skew of the last row (of a lone rigid slider, which
            # took them into its own viscous terms)
            j = 2 if stepping.codes.size == n_own else 0
            dparams = np.array(dparams, dtype=float)
            dparams[-1, j, skew_column] += 1.0
            dparams[-1, j + 1, skew_column] -= 1.0
    n_periods = whole_periods(u) if periodic else 1
    if n_periods > 1:  # the steady state of one period, repeated
        y, dy = simulate_elements(mech, stepping, u[: u.size // n_periods], fs, r,
                                  periodic=True, k_link=k_link, dparams=dparams,
                                  periods=periods, shooting=shooting)
        return np.tile(y, n_periods), np.tile(dy, (n_periods, 1))
    h = 1.0 / (fs * r)
    sens = dparams is not None
    Ad, B0, B1, dAd, dB0, dB1 = mech.foh(h, derivatives=sens)
    ns = Ad.shape[0]
    n_el = stepping.codes.size
    if sens:
        if not np.all(np.isin(stepping.codes, DIFFERENTIATED)):
            raise ValueError("sensitivities need elements of the kinds advance_partials "
                             "differentiates (stop, Dahl, LuGre, Maxwell)")
        dp = np.ascontiguousarray(dparams, dtype=float)
        n_sens = dAd.shape[0] + dp.shape[2]
    else:
        dp = np.zeros((n_el, N_PARAMS, 0))
        n_sens = 0
    ftol = 1e-13 * stepping.scale

    steps = [FohStep(Ad, B0, B1, h, dAd, dB0, dB1)]
    C = np.zeros((3, ns))  # the output, then the link's displacement and velocity
    C[0, mech.output] = 1.0
    C[1, mech.link] = 1.0
    C[2, ns // 2 + mech.link] = 1.0

    def run(x, s, sx, ss, dpp=dp, blocks=None, n_out=None):
        # each period starts afresh from the state the previous one left; a run from a start
        # goes through the record's fine input block by block (`n_out` samples in all), the
        # state carried on; a period through views of its fine input, as many samples at a
        # time as keep the kernel's record of the sensitivities (three rows) within a block's
        state = LoopState(x, s, sx, ss)
        if blocks is None:
            n_out = (fine.size - 1) // r + 1
            step = block_samples(max(r, 3 * (1 + sx.shape[1])))
            blocks = (fine[a * r:min(a + step, n_out - 1) * r + 1]
                      for a in range(0, max(n_out - 1, 1), step))
        y, sy, k = np.empty(n_out), np.empty((n_out, sx.shape[1])), 0
        for a in blocks:
            Y, SY, _, _, worst, _ = run_steps(steps, C, np.zeros(3), 1, stepping, a, state,
                                              vel_row=2, convention=OPEN, ftol=ftol,
                                              record_every=r, record_initial=k == 0,
                                              dparams=dpp if sx.shape[1] else None)
            _check_converged(worst)
            y[k:k + Y.shape[0]], sy[k:k + Y.shape[0]] = Y[:, 0], SY[:, 0, :]
            k += Y.shape[0]
        return y, sy, state.z, state.s, state.sx, state.ss

    x, s = np.zeros(ns), np.array(stepping.state0, dtype=float)
    sx, ss = np.zeros((ns, n_sens)), np.zeros((n_el, n_sens))
    if x0 is not None and not periodic:
        x = np.array(x0, dtype=float)
        if x.shape != (ns,):
            raise ValueError(f"the initial state has {x.size} values; the plant has {ns}")
    if not periodic:
        blocks = (fine_blocks(u, r) if upsampled is None else
                  [upsampled] if isinstance(upsampled, np.ndarray) else upsampled)
        y, sy, *_ = run(x, s, sx, ss, blocks=(_with_offset(b, mech) for b in blocks),
                        n_out=u.size)
        return y, sy
    fine = _with_offset(upsampled if upsampled is not None else fine_input(u, r, periodic), mech)
    most = max_periods(mech, k_link, u.size / fs)
    most = most if periods is None else min(most, int(periods))
    if (shooting and np.all(np.isin(stepping.codes, DIFFERENTIATED))
            and ns + n_el <= MAX_SHOOTING_STATES):
        out = _shooting(run, x, s, dp, n_sens, mech, stepping, most)
        if out is not None:
            return out
    state = [x, s, sx, ss]
    extrapolate = PeriodExtrapolation(bounded={1: stepping.state_bounds()}, weighted=(0, 1),
                                      own=(2, 3))

    def next_period():
        y, sy, *state[:] = run(*state)
        finite = bool(np.all(np.isfinite(state[0])))
        jump = extrapolate(state) if finite else None
        if jump is not None:
            state[:] = jump
        return y, sy, finite

    return periodic_output(next_period, most, mech.floating, sens)


def _shooting(run, x, s, dp, n_sens, mech, stepping, periods):
    """The periodic steady state of :func:`simulate_elements` by Newton's method on the
    period map (:func:`~motionhyst.time.periodic_runs.newton_periodic`): each period run
    with the sensitivities to its start state as further columns (no parameter of the
    plant's or the link's moves them: zero rows' derivatives)."""
    ns, n_el = x.size, s.size
    nz = ns + n_el
    dp_all = np.concatenate([dp, np.zeros((n_el, N_PARAMS, nz))], axis=2)
    start_x = np.hstack([np.eye(ns), np.zeros((ns, n_el))])
    start_s = np.hstack([np.zeros((n_el, ns)), np.eye(n_el)])

    def run_period(z, S):
        y, sy, x_end, s_end, sx_end, ss_end = run(
            z[:ns], z[ns:], np.hstack([S[:ns], start_x]), np.hstack([S[ns:], start_s]), dp_all)
        return y, sy, np.concatenate([x_end, s_end]), np.vstack([sx_end, ss_end])

    lo, hi = stepping.state_bounds()
    bounds = (np.concatenate([np.full(ns, -np.inf), lo]), np.concatenate([np.full(ns, np.inf), hi]))
    gauge = np.concatenate([np.ones(ns // 2), np.zeros(ns // 2 + n_el)])  # masses' positions
    return newton_periodic(run_period, np.concatenate([x, s]), n_sens, periods, mech.floating,
                           bounds, gauge)
