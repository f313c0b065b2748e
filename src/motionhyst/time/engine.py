"""The one time engine: a linear part, a dynamic link around it, and a sampled controller.

Every time-domain run of motionhyst is one loop over time steps
(:func:`~motionhyst.time.kernel.step_loop`, compiled):

* a **linear part** discretised exactly for an input linear over each step
  (first-order hold, :class:`FohStep`): ``z+ = A z + B0 f + B1 f+``, outputs
  ``y = C z + D f``, the input ``f = a + u - w`` the exogenous force ``a``
  (linear between the nodes), the held controller force ``u`` and the link
  force ``w``;
* the **link** of exact-update elements
  (:func:`~motionhyst.hysteresis.stepping.advance`), driven by the increment of
  one output (the link's displacement) plus an exogenous increment; each step
  is implicit in ``w`` through the hold's feedthrough and solved by a
  fixed-point iteration;
* optionally the **forward sensitivities** of the outputs to the parameters of
  the linear part and of the link (:func:`~motionhyst.hysteresis.stepping.advance_partials`);
* optionally a **sampled controller** (:class:`DiscreteController`): every
  `period` steps the output is measured, ``x_{k+1} = Ad x_k + Bd [r_k; y_k]``,
  ``u_k = Cd x_k + Dd [r_k; y_k] + ff_k`` limited to ``|u_k| <= u_max``, and
  ``u_k`` is applied from ``t_k + d T`` on and held until the next one (zero-order
  hold, delay ``d`` in samples, fractional allowed: the period is then split
  at ``d T`` into steps of two lengths).

The closed loop of :func:`motionhyst.time.simulation.simulate` is the loop's
closed linear transfers driven by the link force (the continuous controller
inside the linear part); the open loop (:mod:`motionhyst.time.openloop`) is the
plant driven by a force record; the sampled loop (:func:`run_sampled`) is the
plant with the discrete controller around it, the plant and link integrated
exactly between updates.

Examples
--------
The linear sampled loop (no link) at its samples is the discrete loop of the
zero-order-hold plant:

>>> import control
>>> import numpy as np
>>> from motionhyst.time.engine import DiscreteController, run_sampled
>>> from motionhyst.time.openloop import MassSpringDamper
>>> ctrl = DiscreteController(A=[[1.0]], B=[[1e-3, -1e-3]], C=[2e5], D=[5e3, -5e3],
...                           dt=1e-3)                     # PI: 5e3 e + 2e5 T sum(e)
>>> run = run_sampled(MassSpringDamper(1.0, 20.0, 1e4), None, ctrl, np.ones(300))
>>> print(f"{run.y[-1]:.3f} m after {run.t[-1]:.3f} s")   # the integrator removes the error
1.002 m after 0.299 s
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.hysteresis.stepping import GL_T, GL_W, N_PARAMS, Stepping
from motionhyst.time.kernel import CLOSED as CLOSED
from motionhyst.time.kernel import (
    MAX_FIXED_POINT_ITERATIONS,
    OPEN,
    StepNotConverged,
    step_loop,
)
from motionhyst.time.steps import (
    SAMPLED_MIN_SUBSTEPS,
    SAMPLED_STEPS_PER_MODE_PERIOD,
    SECONDS_PER_ELEMENT_STEP,
    SECONDS_PER_STEP,
    check_link_damping,
    run_delay,
    sampled_substeps,
)

__all__ = [
    "CALL_SECONDS",
    "DiscreteController",
    "FohStep",
    "LoopState",
    "SampledRun",
    "run_sampled",
    "run_steps",
]

@dataclass
class FohStep:
    """A linear part over one step `h` for an input linear over the step (first-order hold).

    ``z(t + h) = A z(t) + B0 f(t) + B1 f(t + h)``, exactly for ``f`` linear over the
    step; ``dA, dB0, dB1`` are the derivatives in the linear part's parameters (first
    axis; empty: none).

    Parameters
    ----------
    A : array_like, shape (n, n)
        State transition over the step.
    B0, B1 : array_like, shape (n,)
        Input matrices of the input at the start and at the end of the step.
    h : float
        The step [s].
    dA, dB0, dB1 : ndarray, optional
        Their derivatives in the linear part's parameters (first axis), none by default.

    Examples
    --------
    >>> step = FohStep.exact([[0.0, 1.0], [-1e4, -20.0]], [0.0, 1.0], 1e-3)  # 1/(s^2+20s+1e4)
    >>> step.A.shape, step.B0.shape, step.dA.shape
    ((2, 2), (2,), (0, 2, 2))
    """

    A: NDArray[np.float64]
    B0: NDArray[np.float64]
    B1: NDArray[np.float64]
    h: float
    dA: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0, 0)))
    dB0: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))
    dB1: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))

    def __post_init__(self) -> None:
        self.A = np.ascontiguousarray(self.A, dtype=float)
        self.B0 = np.ascontiguousarray(np.ravel(self.B0), dtype=float)
        self.B1 = np.ascontiguousarray(np.ravel(self.B1), dtype=float)
        n = self.A.shape[0]
        if self.dA.size == 0:
            self.dA = np.zeros((0, n, n))
            self.dB0 = np.zeros((0, n))
            self.dB1 = np.zeros((0, n))
        self.dA = np.ascontiguousarray(self.dA, dtype=float)
        self.dB0 = np.ascontiguousarray(self.dB0, dtype=float)
        self.dB1 = np.ascontiguousarray(self.dB1, dtype=float)

    @classmethod
    def exact(cls, A: ArrayLike, B: ArrayLike, h: float) -> FohStep:
        """The continuous ``x' = A x + B f`` over a step `h`, from the exponential of
        ``[[A h, B h, 0], [0, 0, 1], [0, 0, 0]]`` (:func:`~motionhyst.core.lti.expm_small`).

        Parameters
        ----------
        A : array_like, shape (n, n)
            The continuous system matrix.
        B : array_like, shape (n,)
            Its input vector.
        h : float
            The step [s].

        Returns
        -------
        FohStep
        """
        A = np.asarray(A, dtype=float)
        B = np.ravel(np.asarray(B, dtype=float))
        ns = A.shape[0]
        M = np.zeros((ns + 2, ns + 2))
        M[:ns, :ns] = A * h
        M[:ns, ns] = B * h
        M[ns, ns + 1] = 1.0
        # imported where used: core.lti imports python-control, which reading and checking a
        # record before a run does not need
        from motionhyst.core.lti import expm_small

        E = expm_small(M)
        B1 = E[:ns, ns + 1]
        return cls(E[:ns, :ns], E[:ns, ns] - B1, B1, float(h))


@dataclass
class LoopState:
    """The state the step loop carries from one call to the next (a run in pieces).

    Parameters
    ----------
    z : array_like
        The linear part's state at the start.
    s : array_like
        The link elements' states at the start.
    sx, ss : array_like
        Sensitivities of ``z`` and ``s`` (columns: parameters).
    nc : int
        Number of states of a sampled controller (0: none).
    n_queue : int
        Length of the queue of controller outputs (the delay in whole samples, plus one).

    Attributes
    ----------
    z : ndarray
        The linear part's state.
    s, s_prev : ndarray
        The link elements' states, now and one step earlier.
    sx, ss, ss_prev : ndarray
        Sensitivities of ``z``, ``s`` and ``s_prev`` (columns: parameters).
    dvec : ndarray, shape (3, P)
        Sensitivities of the previous step's link force, displacement and link output.
    out_prev : ndarray
        The outputs at the last node.
    scal : ndarray
        The link force, displacement increment and length of the last step.
    xc, uq : ndarray
        The controller's state and its queue of outputs ``u_k, u_{k-1}, ...``.
    fresh : bool
        True before the first call: the start is ``z``, ``s`` (and ``sx``, ``ss``).
    i0 : int
        Steps run so far.

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> st = LoopState.at_rest(4, Jenkins(k=20.0, fc=0.05).time_stepping(), parameters=2)
    >>> st.z.shape, st.s.shape, st.sx.shape, st.fresh
    ((4,), (1,), (4, 2), True)
    """

    z: NDArray[np.float64]
    s: NDArray[np.float64]
    sx: NDArray[np.float64]
    ss: NDArray[np.float64]
    nc: int = 0
    n_queue: int = 1
    s_prev: NDArray[np.float64] = field(init=False)
    ss_prev: NDArray[np.float64] = field(init=False)
    dvec: NDArray[np.float64] = field(init=False)
    out_prev: NDArray[np.float64] = field(init=False)
    scal: NDArray[np.float64] = field(init=False)
    xc: NDArray[np.float64] = field(init=False)
    uq: NDArray[np.float64] = field(init=False)
    fresh: bool = True
    i0: int = 0

    def __post_init__(self) -> None:
        self.z = np.array(self.z, dtype=float)
        self.s = np.array(self.s, dtype=float)
        self.sx = np.array(self.sx, dtype=float).reshape(self.z.size, -1)
        self.ss = np.array(self.ss, dtype=float).reshape(self.s.size, self.sx.shape[1])
        self.s_prev = self.s.copy()
        self.ss_prev = self.ss.copy()
        self.dvec = np.zeros((3, self.sx.shape[1]))
        self.out_prev = np.zeros(0)
        self.scal = np.zeros(3)
        self.xc = np.zeros(self.nc)
        self.uq = np.zeros(self.n_queue)

    @classmethod
    def at_rest(cls, n: int, stepping: Stepping, parameters: int = 0, nc: int = 0,
                n_queue: int = 1) -> LoopState:
        """The linear part (`n` states) and the link at rest, `parameters` sensitivities.

        Parameters
        ----------
        n : int
            Number of states of the linear part.
        stepping : Stepping
            The link's time stepping (its elements' initial states).
        parameters : int
            Number of sensitivities carried.
        nc : int
            Number of states of a sampled controller.
        n_queue : int
            Length of the queue of controller outputs.

        Returns
        -------
        LoopState
        """
        m = stepping.codes.size
        return cls(np.zeros(n), np.array(stepping.state0, dtype=float),
                   np.zeros((n, parameters)), np.zeros((m, parameters)), nc, n_queue)


_EMPTY_CONTROLLER = (np.zeros((0, 0)), np.zeros((0, 2)), np.zeros(0), np.zeros(2), np.zeros(0),
                     np.zeros(0), math.inf, 0, 0, 0, 0)


CALL_SECONDS = 0.1
"""Nominal work [s] of one call of the compiled step loop (:data:`SECONDS_PER_STEP` and
:data:`SECONDS_PER_ELEMENT_STEP` a step, times one plus the sensitivities): a longer run is
run in calls of about this much, its state carried from one to the next.  A signal
(Ctrl-C, SIGTERM) is taken between two calls, never inside one: a run of a link of 100
elements held one for 20 s and more."""


def call_steps(n_elements: int, n_sensitivities: int, align: int) -> int:
    """Steps of one call of the compiled step loop (:data:`CALL_SECONDS`): a multiple of
    `align` (the steps between records and of a controller period), at least one.

    Parameters
    ----------
    n_elements : int
        The link's elements.
    n_sensitivities : int
        The sensitivities computed.
    align : int
        What the steps are a multiple of.

    Returns
    -------
    int

    Examples
    --------
    >>> call_steps(1, 0, 1), call_steps(100, 0, 1), call_steps(100, 0, 8)
    (62500, 8695, 8688)
    """
    per_step = (SECONDS_PER_STEP + n_elements * SECONDS_PER_ELEMENT_STEP) * (1 + n_sensitivities)
    return max(1, int(CALL_SECONDS / per_step) // align) * align


def run_steps(steps: list[FohStep], C: ArrayLike, D: ArrayLike, link_row: int,
              stepping: Stepping, a: NDArray[np.float64], state: LoopState, *,
              vel_row: int = -1,
              convention: int, ftol: float, dexo: NDArray[np.float64] | None = None,
              exo: NDArray[np.float64] | None = None, record_every: int = 1,
              record_initial: bool = False, i_first: int = 0,
              dparams: NDArray[np.float64] | None = None, controller: tuple | None = None
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                         NDArray[np.float64], int, int]:
    """Run the step loop over the ``len(a) - 1`` steps between the force nodes `a`.

    The compiled loop is :func:`~motionhyst.time.kernel.step_loop`.

    Parameters
    ----------
    steps : list of FohStep
        The linear part over a step (one, or two for a split controller period:
        ``steps[1]`` the steps before the held force changes).
    C, D : array_like, shapes (p, n), (p,)
        The outputs ``y = C z + D f``.
    link_row : int
        The output that is the link's displacement (with `dexo`).
    vel_row : int
        The output that is the link's velocity (-1: none); with it a lone rigid
        slider's step is solved in closed form.
    stepping : Stepping
        The link's elements (empty: no link).
    a : ndarray
        The exogenous force at the step nodes (linear between them).
    state : LoopState
        The start, updated in place to the end.
    convention : {CLOSED, OPEN} of :mod:`motionhyst.time.kernel`
        The implicit step's convention (:func:`~motionhyst.time.kernel.step_loop`).
    ftol : float
        Tolerance of the link force's fixed point [N].
    dexo, exo : ndarray, optional
        An exogenous increment of the link's displacement per step, and exogenous
        output offsets per step (steps, p).
    record_every, record_initial, i_first
        As :func:`~motionhyst.time.kernel.step_loop`.
    dparams : ndarray, optional
        Derivatives of the elements' rows in the link's parameters (sensitivities).
    controller : tuple, optional
        ``(Ac, Bc, Cc, Dc, ref, ff, u_max, period, r1, meas_row, n_delay)``.

    Returns
    -------
    Y, SY, W, U : ndarray
        Recorded outputs, their sensitivities, the link force, the controller outputs.
    worst : int
        The most fixed-point passes a step took.
    done : int
        Steps run (fewer than asked if a step did not converge).

    Examples
    --------
    A mass on a spring (``k = 1e4 N/m``) held by a Jenkins link, a force of 5 N from
    rest: it overshoots, the link slips both ways, and the stage comes to rest where
    the spring and the link carry the force together.

    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> A, B = MassSpringDamper(1.0, 20.0, 1e4).mechanics().state_space()
    >>> link = Jenkins(k=1e4, fc=1.0).time_stepping()
    >>> state = LoopState.at_rest(2, link)
    >>> Y, _, W, _, worst, done = run_steps(
    ...     [FohStep.exact(A, B, 1e-4)], [[1.0, 0.0]], [0.0], 0, link, np.full(20001, 5.0),
    ...     state, convention=OPEN, ftol=1e-13, record_every=100, record_initial=True)
    >>> Y.shape, done
    ((201, 1), 20000)
    >>> print(f"{1e4 * Y[-1, 0] + W[-1]:.6f} N")   # k y + w = 5 N at rest
    5.000000 N
    """
    C = np.ascontiguousarray(np.atleast_2d(C), dtype=float)
    D = np.ravel(np.asarray(D, dtype=float))
    if convention == OPEN and np.any(D != 0.0):
        raise ValueError("the plant's convention records C z: its outputs have no feedthrough")
    kinds = steps if len(steps) == 2 else [steps[0], steps[0]]
    A = np.ascontiguousarray(np.stack([s.A for s in kinds]))
    B0 = np.ascontiguousarray(np.stack([s.B0 for s in kinds]))
    B1 = np.ascontiguousarray(np.stack([s.B1 for s in kinds]))
    G = np.ascontiguousarray(np.stack([C @ s.B1 + D for s in kinds]))
    hs = np.array([s.h for s in kinds], dtype=float)
    sens = state.sx.shape[1] > 0
    dA, dB0, dB1 = (steps[0].dA, steps[0].dB0, steps[0].dB1) if sens else (
        np.zeros((0, A.shape[1], A.shape[1])), np.zeros((0, A.shape[1])),
        np.zeros((0, A.shape[1])))
    m = stepping.codes.size
    dp = (np.zeros((m, N_PARAMS, 0)) if dparams is None
          else np.ascontiguousarray(dparams, dtype=float))
    if state.out_prev.size != C.shape[0]:
        state.out_prev = np.zeros(C.shape[0])
    ctrl = _EMPTY_CONTROLLER if controller is None else controller
    Ac, Bc, Cc, Dc, ref, ff, u_max, period, r1, meas_row, n_delay = ctrl
    a = np.ascontiguousarray(a, dtype=float)
    dexo = np.zeros(0) if dexo is None else np.ascontiguousarray(dexo, dtype=float)
    exo = (np.zeros((0, C.shape[0])) if exo is None
           else np.ascontiguousarray(exo, dtype=float))
    codes = np.ascontiguousarray(stepping.codes, dtype=np.int64)
    params = np.ascontiguousarray(stepping.params, dtype=float)
    n, P = a.shape[0] - 1, state.sx.shape[1]
    period = int(period)
    # the run in calls of bounded work, each a whole number of records and of controller
    # periods (the kernel counts both from its first step); outputs as one call gives them
    chunk = call_steps(m, P, math.lcm(int(record_every), max(period, 1)))
    if n > chunk:
        n_rec = n // int(record_every) + (1 if record_initial else 0)
        Y, SY = np.zeros((n_rec, C.shape[0])), np.zeros((n_rec, C.shape[0], P))
        W, U = np.zeros(n_rec), np.zeros(-(-n // period) if period > 0 else 0)
    worst = done = rec = 0
    for start in range(0, max(n, 1), chunk):
        steps_here = max(min(chunk, n - start), 0)
        k0 = start // period if period > 0 else 0
        Yc, SYc, Wc, Uc, worst_c, done_c = step_loop(
            A, B0, B1, C, G, hs, dA, dB0, dB1, int(link_row), int(vel_row),
            a[start:start + steps_here + 1], dexo[start:start + steps_here] if dexo.size else dexo,
            exo[start:start + steps_here] if exo.shape[0] else exo, int(record_every),
            bool(record_initial and start == 0), codes, params, dp, GL_T, GL_W, float(ftol),
            MAX_FIXED_POINT_ITERATIONS, int(convention), int(state.i0), int(i_first),
            bool(state.fresh), Ac, Bc, Cc, Dc, ref[k0:] if period > 0 else ref,
            ff[k0:] if period > 0 else ff, float(u_max), period, int(r1), int(meas_row),
            int(n_delay), state.z, state.s, state.s_prev, state.sx, state.ss, state.ss_prev,
            state.dvec, state.out_prev, state.scal, state.xc, state.uq)
        state.fresh = False
        state.i0 += int(done_c)
        if n <= chunk:  # one call: its outputs as they are
            return Yc, SYc, Wc, Uc, int(worst_c), int(done_c)
        Y[rec:rec + Yc.shape[0]], SY[rec:rec + Yc.shape[0]] = Yc, SYc
        W[rec:rec + Yc.shape[0]] = Wc
        U[k0:k0 + Uc.shape[0]] = Uc
        rec += Yc.shape[0]
        worst, done = max(worst, int(worst_c)), done + int(done_c)
        if done_c < steps_here:  # a step did not converge: the run stops there
            break
    return Y, SY, W, U, int(worst), int(done)


# ----------------------------------------------------------------- the sampled loop
class DiscreteController:
    """A discrete controller: ``x_{k+1} = A x_k + B [r_k; y_k]``, ``u_k = C x_k + D [r_k; y_k]``.

    What :func:`run_sampled` needs of a controller (any object with these
    attributes will do, e.g. a python-control discrete ``StateSpace`` with the
    inputs ``(r, y)`` and the output ``u``): the negative feedback is in the
    signs of the ``y`` columns.

    Parameters
    ----------
    A, B, C, D : array_like
        Shapes (nc, nc), (nc, 2), (1, nc) or (nc,), (1, 2) or (2,).
    dt : float
        Sampling interval ``T = 1 / F`` [s].

    Examples
    --------
    A proportional controller ``u = 5 (r - y)``:

    >>> c = DiscreteController(A=np.zeros((0, 0)), B=np.zeros((0, 2)), C=np.zeros(0),
    ...                        D=[5.0, -5.0], dt=1e-4)
    >>> c.D.tolist(), c.dt
    ([5.0, -5.0], 0.0001)
    """

    def __init__(self, A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike,
                 dt: float) -> None:
        self.A = np.ascontiguousarray(np.atleast_2d(np.asarray(A, dtype=float)))
        nc = 0 if np.size(A) == 0 else self.A.shape[0]
        self.A = self.A.reshape(nc, nc)
        self.B = np.ascontiguousarray(np.asarray(B, dtype=float).reshape(nc, 2))
        self.C = np.ascontiguousarray(np.asarray(C, dtype=float).reshape(nc))
        self.D = np.ascontiguousarray(np.asarray(D, dtype=float).reshape(2))
        self.dt = float(dt)
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"the controller's sampling interval must be > 0, got {dt!r}")


@dataclass
class SampledRun:
    """Signals of :func:`run_sampled` at the controller's samples ``t_k = k T``.

    Attributes
    ----------
    t, r : ndarray
        Sampling instants [s] and the reference samples [m].
    y : ndarray
        The measured output at ``t_k`` [m].
    e : ndarray
        ``r - y`` [m].
    u : ndarray
        The controller output computed at ``t_k`` (after the limit) [N], applied from
        ``t_k + d T`` on.
    y_link : ndarray
        The link's displacement at ``t_k`` [m].
    w : ndarray
        The link force at ``t_k`` [N].

    Examples
    --------
    A proportional controller ``u = 5e3 (r - y)`` on a spring of ``1e4 N/m``: the
    error rings down towards ``k / (k + 5e3) = 2/3`` of the step.

    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> ctrl = DiscreteController(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros(0),
    ...                           [5e3, -5e3], 1e-3)
    >>> run = run_sampled(MassSpringDamper(1.0, 20.0, 1e4), None, ctrl, np.ones(500))
    >>> run.t.size, float(run.e[0]), round(float(run.e[-1]), 4)
    (500, 1.0, 0.665)
    """

    t: NDArray[np.float64]
    r: NDArray[np.float64]
    y: NDArray[np.float64]
    e: NDArray[np.float64]
    u: NDArray[np.float64]
    y_link: NDArray[np.float64]
    w: NDArray[np.float64]


#: Fine steps per controller period at least (room for a fractional delay's split), and per
#: period of the plant's fastest mode (:func:`motionhyst.time.steps.sampled_substeps`).
MIN_SUBSTEPS = SAMPLED_MIN_SUBSTEPS
STEPS_PER_MODE_PERIOD = SAMPLED_STEPS_PER_MODE_PERIOD


def _mechanics(plant):
    return plant.mechanics() if hasattr(plant, "mechanics") else plant


def _controller_matrices(controller) -> tuple[NDArray, NDArray, NDArray, NDArray, float]:
    if not hasattr(controller, "A") and callable(getattr(controller, "state_space", None)):
        A, B, C, D = controller.state_space()
        controller = DiscreteController(A, B, C, D, controller.period)
    A = np.asarray(controller.A, dtype=float)
    nc = 0 if A.size == 0 else A.shape[0]
    try:
        Ac = np.ascontiguousarray(A.reshape(nc, nc))
        Bc = np.ascontiguousarray(np.asarray(controller.B, dtype=float).reshape(nc, 2))
        Cc = np.ascontiguousarray(np.asarray(controller.C, dtype=float).reshape(nc))
        Dc = np.ascontiguousarray(np.asarray(controller.D, dtype=float).reshape(2))
    except ValueError:
        raise ValueError("the controller must have two inputs (r, y) and one output u") from None
    dt = float(controller.dt)
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"the controller must be discrete with a sampling interval > 0, "
                         f"got dt = {controller.dt!r}")
    return Ac, Bc, Cc, Dc, dt


def run_sampled(plant, link, controller, r: ArrayLike, *, ff: ArrayLike | None = None,
                delay_samples: float = 0.0, u_max: float = math.inf,
                substeps: int | None = None, x0: ArrayLike | None = None) -> SampledRun:
    """The sampled-data loop from rest: a discrete controller around a plant with a link.

    The plant's output is sampled at ``t_k = k T``; ``u_k = Cd x_k + Dd [r_k; y_k]
    + ff_k`` (limited to ``|u_k| <= u_max``) is applied from ``t_k + d T`` on and held
    until the next update (zero-order hold; before the first arrives the force is 0).
    Between updates the plant is integrated exactly (its matrix exponential, the
    force ``u - w`` linear over each of the `substeps` fine steps per period: exact
    for the held ``u``) and the link by its exact update, each fine step implicit in
    the link force (as :func:`motionhyst.time.simulation.simulate`).  A fractional
    delay splits the period at ``frac(d) T`` into fine steps of two lengths.

    Parameters
    ----------
    plant : MassSpringDamper or TwoMass or Mechanics
        The plant (anything with ``mechanics()``, or the mechanics itself): the force
        and the link act on ``q[link]``, ``q[output]`` is measured.
    link : Hysteresis or None
        The link (a model with a time-domain update), or None.
    controller : DiscreteController
        Or any object with ``A, B, C, D, dt`` of that meaning (a python-control
        discrete ``StateSpace``), or with ``state_space()`` giving ``A, B, C, D`` and
        ``period`` (T).
    r : array_like
        Reference samples at ``t_k`` [m]; ``len(r)`` samples are run.
    ff : array_like, optional
        Feedforward force samples [N] added to ``u_k`` before the limit and the delay.
    delay_samples : float
        ``d >= 0`` [samples].
    u_max : float
        Output limit [N], > 0 (inf: none).
    substeps : int, optional
        Fine steps per controller period (default: at least 2 and at least 40 per
        period of the plant's fastest mode, the link taken as its initial stiffness).
    x0 : array_like, optional
        The plant's initial state ``(q, q')`` (default: rest); the link starts relaxed
        there.

    Returns
    -------
    SampledRun

    Examples
    --------
    One sample of delay against the discrete loop of python-control:

    >>> import control
    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> T = 1e-3
    >>> Cz = control.ss(control.c2d(control.tf([40.0, 4e4], [1.0, 0.0]), T, "tustin"))  # PI
    >>> ctrl = DiscreteController(Cz.A, np.hstack([Cz.B, -Cz.B]), Cz.C,
    ...                           [Cz.D[0, 0], -Cz.D[0, 0]], T)          # u = C(z) (r - y)
    >>> run = run_sampled(MassSpringDamper(1.0, 20.0, 1e4), None, ctrl, np.ones(300),
    ...                   delay_samples=1.0)
    >>> Pz = control.c2d(control.ss(control.tf([1.0], [1.0, 20.0, 1e4])), T, "zoh")
    >>> delay = control.ss(control.tf([1.0], [1.0, 0.0], T))                # z^-1
    >>> loop = control.feedback(Pz * delay * Cz, 1)
    >>> y = control.forced_response(loop, run.t, np.ones(300)).outputs
    >>> bool(np.max(np.abs(run.y - y)) < 1e-13)
    True
    """
    mech = _mechanics(plant)
    if getattr(mech, "c_skew", 0.0):
        raise ValueError("the sampled loop takes no viscous friction by direction on the plant "
                         "(c_skew); the open-loop time runs do")
    Ac, Bc, Cc, Dc, T = _controller_matrices(controller)
    rr = np.ascontiguousarray(np.ravel(np.asarray(r, dtype=float)))
    n_k = rr.size
    if n_k < 1 or not np.all(np.isfinite(rr)):
        raise ValueError("the reference needs at least one finite sample")
    fff = (np.zeros(n_k) if ff is None
           else np.ascontiguousarray(np.ravel(np.asarray(ff, dtype=float))))
    if fff.shape != rr.shape or not np.all(np.isfinite(fff)):
        raise ValueError("the feedforward must give one finite value per reference sample")
    d = float(delay_samples)
    if not (math.isfinite(d) and d >= 0):
        raise ValueError(f"delay_samples must be finite and >= 0, got {delay_samples!r}")
    d = run_delay(d)  # a hair off a whole number: that number, not a fine step of 4e-20 s
    if not (float(u_max) > 0):
        raise ValueError(f"u_max must be > 0, got {u_max!r}")
    stepping = Stepping.empty() if link is None else link.time_stepping()
    k_link = link.initial_stiffness if link is not None else 0.0
    R, r1, h, h1 = sampled_substeps(T, d, substeps, mech.natural_frequency_hz(k_link)
                                    if substeps is None else 0.0)
    if link is not None:  # a damping its steps cannot settle: refused, not run to no answer
        check_link_damping(link, mech, max(h, h1),
                           shorter=min(h, h1) if r1 and h != h1 else 0.0)
    n_delay = math.floor(d)
    A, B = mech.state_space()
    steps = [FohStep.exact(A, B, h)] + ([FohStep.exact(A, B, h1)] if r1 else [])
    ns = A.shape[0]
    Cout = np.zeros((3, ns))  # the measured output, the link's displacement and velocity
    Cout[0, mech.output] = 1.0
    Cout[1, mech.link] = 1.0
    Cout[2, ns // 2 + mech.link] = 1.0
    state = LoopState.at_rest(ns, stepping, nc=Ac.shape[0], n_queue=n_delay + 2)
    if x0 is not None:
        z0 = np.ravel(np.asarray(x0, dtype=float))
        if z0.shape != (ns,) or not np.all(np.isfinite(z0)):
            raise ValueError(f"x0 must be {ns} finite values (q, q'), got {np.shape(x0)}")
        state.z[:] = z0
    # a constant force on the plant (its force offset), beside the held controller force
    a = np.full(n_k * R + 1, float(getattr(mech, "force_offset", 0.0)))
    # a link along the stroke: its parameters at the setpoint's mean over each of its pieces
    # of the samples, held over their controller periods (the continuous run's rule)
    pieces = link.pieces(rr) if isinstance(link, AlongStroke) else [(0, n_k)]
    # each piece's records copied into the run's as it ends: the run held once (its
    # SAMPLED_SAMPLE_BYTES), not again in its pieces
    out: list[NDArray[np.float64]] = []
    rows, worst, done = [0, 0, 0], 0, 0
    y_end = None  # the link's displacement at the last piece's end
    for k0, k1 in pieces:
        if isinstance(link, AlongStroke):
            stepping.params[:] = link.stepping_params(float(np.mean(rr[k0:k1])))
            s_start = state.s.copy()
        ctrl = (Ac, Bc, Cc, Dc, rr[k0:k1], fff[k0:k1], float(u_max), R, r1, 0, n_delay)
        Yp, _, Wp, Up, worst_p, done_p = run_steps(
            steps, Cout, np.zeros(3), 1, stepping, a[k0 * R:k1 * R + 1], state, vel_row=2,
            convention=OPEN, ftol=1e-13 * stepping.scale, record_every=R,
            record_initial=k0 == 0, controller=ctrl)
        if isinstance(link, AlongStroke) and len(Yp):
            # its stop operators' stiffness conserved where they stuck through the piece
            y_start = Yp[0, 1] if y_end is None else y_end
            y_end = float(Yp[-1, 1])
            dw = link.conserve(state.s, s_start, y_start, y_end, stepping.params)
            if dw:
                state.scal[0] += dw  # the force at the node the next step starts from
                Wp[-1] += dw
        for i, p in enumerate((Yp, Wp, Up)):
            if len(pieces) == 1:
                out.append(p)
                continue
            if len(out) < 3:
                out.append(np.empty((n_k + 1, *p.shape[1:])))
            out[i][rows[i]:rows[i] + len(p)] = p
            rows[i] += len(p)
        worst, done = max(worst, worst_p), done + done_p
        if worst > MAX_FIXED_POINT_ITERATIONS:
            break
    Y, W, U = out
    if worst > MAX_FIXED_POINT_ITERATIONS:
        raise StepNotConverged(f"the link's implicit step at t = {done / R * T:.6g} s did "
                               f"not converge in {MAX_FIXED_POINT_ITERATIONS} iterations: the "
                               f"link is too stiff (or too strongly damped) for the time step "
                               f"of {max(h, h1):.3g} s", "use more substeps")
    t = np.arange(n_k) * T
    y = Y[:n_k, 0]
    return SampledRun(t=t, r=rr, y=y, e=rr - y, u=U[:n_k], y_link=Y[:n_k, 1], w=W[:n_k])
