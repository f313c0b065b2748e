"""Time simulation of the nonlinear loop from rest, for any reference.

The loop is split as in :mod:`motionhyst.controllers.loop`: the tracking error and the
deviation ``y1 - r`` are computed directly from the reference's acceleration
``r''`` and the hysteresis force ``w``::

    e      = [T_{r->e} / s^2] r''            + T_{w->e} w
    y1 - r = [(T_{r->y1} - 1) / s^2] r''     + T_{w->y1} w

so no position of size ``r`` is ever subtracted from another.  The linear
part is discretised exactly for inputs that are linear between samples
(first-order hold); the element is advanced with its exact update.  The step
is chosen from the loop's fastest pole and the reference; the user does not
tune it.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from motionhyst.controllers.loop import Loop
from motionhyst.core.budget import check_memory
from motionhyst.core.lti import (
    FohResponse,
    discretize_foh,
    divide_s2,
    dss_filter,
    polysub_exact,
    realize_scaled,
    stack,
    tf_poly,
)
from motionhyst.hysteresis import Hysteresis
from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.hysteresis.stepping import GL_T, GL_W, Stepping, open_loop_calls
from motionhyst.time.engine import FohStep, LoopState, run_steps
from motionhyst.time.kernel import CLOSED, MAX_FIXED_POINT_ITERATIONS, StepNotConverged
from motionhyst.time.sampled import simulate_sampled
from motionhyst.time.simulation_result import Simulation
from motionhyst.time.steps import (
    BYTES_PER_SAMPLE,
    RUN_REMEDY,
    SECONDS_PER_ELEMENT_STEP,
    SECONDS_PER_STEP,
    RunTooLarge,
    a_run,
    check_steps_work,
    pole_step,
)

__all__ = ["RUN_REMEDY", "SECONDS_PER_ELEMENT_STEP", "SECONDS_PER_STEP", "Simulation",
           "check_long_run", "check_proper", "check_run_work", "simulate", "simulate_chunks"]



def check_run_work(loop: Loop, n_steps: int, remedy: str = RUN_REMEDY) -> None:
    """Refuse a run of `n_steps` time steps above the work budget, before it starts.

    Its work is the steps times :data:`SECONDS_PER_STEP` and the link's elements (and its
    feedforward model's) times :data:`SECONDS_PER_ELEMENT_STEP`
    (:func:`motionhyst.time.steps.check_steps_work`).

    Parameters
    ----------
    loop : Loop
        The loop run.
    n_steps : int
        Its time steps.
    remedy : str
        What the user can change, for the message.

    Raises
    ------
    motionhyst.core.budget.BudgetError
        One line: the run's steps and elements, its estimated time, the remedy.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> check_run_work(default_scenario().loop(), 1_000_000)      # about 1.6 s
    """
    check_steps_work(n_steps, (loop.hysteresis, loop.hysteresis_feedforward), remedy)


def _block_systems(loop: Loop, omega0: float):
    """Realisations in scaled time of ``r'' -> (e, y1 - r)`` and ``w -> (e, y1 - r)``."""
    P = loop._poly
    if P is None:
        raise ValueError("time simulation needs LTI plant and controller")
    ry1 = P["r->y1"]
    n_ae = divide_s2(P["r->e"].num, P["r->e"].den, "the error response to the reference")
    n_ay = divide_s2(polysub_exact(ry1.num, ry1.den), ry1.den,
                      "the response of y1 - r to the reference")
    sys_a = stack([realize_scaled(num, den, omega0) for num, den in (n_ae, n_ay)])
    sys_w = stack([realize_scaled(P[name].num, P[name].den, omega0) for name in ("w->e", "w->y1")])
    return sys_a, sys_w


def _elements(h: Hysteresis | None) -> tuple[NDArray[np.int64], NDArray[np.float64],
                                             NDArray[np.float64], float]:
    """Kinds, parameters, initial states (at rest) and a force scale [N] of the link's elements.

    Raises
    ------
    ValueError
        For a model the compiled loop has no exact update for.
    """
    st = Stepping.empty() if h is None else h.time_stepping()
    return st.codes, st.params, st.state0, st.scale


def default_step(loop: Loop, max_frequency_hz: float) -> float:
    """Time step [s] resolving the loop's fastest pole and the reference.

    A loop with a sampled controller runs at its controller's period.
    """
    if loop.sampled is not None:
        return loop.sampled.period
    return pole_step(float(np.max(np.abs(loop.closed_loop_poles()))), max_frequency_hz)


def simulate(loop: Loop, reference, duration: float, dt: float | None = None,
             force=None) -> Simulation:
    """Simulate the nonlinear loop from rest.

    The linear part is discretised exactly for inputs linear between samples
    (first-order hold); the link is advanced between samples by its exact
    update for a displacement linear in time: the stop operator (Jenkins,
    Maxwell-slip), the closed-form Dahl and Bouc-Wen (``n = 1``) solutions or
    converged RK4 sub-steps (Bouc-Wen, other ``n``), and the exponential LuGre
    update for the step's constant velocity (force ``sigma0 z + sigma1 z' +
    sigma2 v`` with the velocity of the step ending at the sample, as in
    :meth:`~motionhyst.hysteresis.LuGre.response`).  Each step is implicit in
    ``w`` through the hold's feedthrough and solved by fixed-point iteration.

    Parameters
    ----------
    loop : Loop
        An LTI loop whose plant has a rigid-body double integrator; its link
        and hysteresis feedforward (if any) one of Jenkins, MaxwellSlip, Dahl,
        BoucWen, LuGre.  With a sampled controller the run is that of the
        hybrid loop at the controller's samples
        (:func:`motionhyst.time.sampled.simulate_sampled`; `dt` is its period).
    reference : callable
        ``reference(t) -> (r, r'')``, e.g. the classes of :mod:`motionhyst.time.references`.
    duration : float
        Simulated time [s], > 0.
    dt : float, optional
        Output and integration step [s]; by default from :func:`default_step`.
    force : callable, optional
        An additional feedforward force [N], ``force(t) -> array`` on the time
        grid (e.g. one learned by :mod:`motionhyst.scan.ilc`); it is added to the
        actuator force like the hysteresis feedforward, linear between samples.

    Returns
    -------
    Simulation

    Raises
    ------
    ValueError
        For invalid arguments, a loop that is not LTI or a link model without
        a time-domain update.
    RuntimeError
        If the implicit step does not converge (a link too stiff for the step).

    Examples
    --------
    The Table I loop running a 20 mm point-to-point move from rest:

    >>> import numpy as np
    >>> from motionhyst import PointToPoint, default_scenario, simulate
    >>> loop = default_scenario().loop()
    >>> move = PointToPoint(0.02, 0.5, 10.0, 1000.0)
    >>> sim = simulate(loop, move, move.duration + 0.2)
    >>> print(f"{sim.t[-1]:.1f} s in {sim.t.size} samples")
    0.3 s in 12001 samples
    >>> print(f"peak error {np.abs(sim.e_linear).max():.2e} m without the link, "
    ...       f"the link adds {np.abs(sim.e - sim.e_linear).max():.2e} m")
    peak error 8.32e-08 m without the link, the link adds 8.28e-09 m
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if loop.sampled is not None:

        if dt is not None and abs(dt - loop.sampled.period) > 1e-9 * loop.sampled.period:
            raise ValueError(f"a sampled loop runs at its controller's period "
                             f"{loop.sampled.period:g} s, not dt = {dt:g} s")
        return simulate_sampled(loop, reference, duration, force=force)
    _check_feedforward(loop)
    engine = _Engine(loop, reference, dt, force)
    n = int(np.ceil(duration / engine.step)) + 1
    if n > 50_000_000:
        raise RunTooLarge(f"{n} time steps of {engine.step:.3g} s: too many", RUN_REMEDY)
    with a_run():
        check_memory(n * BYTES_PER_SAMPLE, f"a run of {n:.3g} time steps", RUN_REMEDY)
    check_run_work(loop, n)
    t = np.arange(n) * engine.step
    h_foh = (t[-1] - t[0]) / (len(t) - 1) if len(t) > 1 else 0.0
    if isinstance(loop.hysteresis, AlongStroke) or isinstance(engine.hff, AlongStroke):
        return _along_stroke(engine, t, h_foh)
    return engine.run(t, 0, h_foh)


def check_proper(loop: Loop) -> None:
    """Refuse a continuous controller with more zeros than poles (a PID's pure derivative):
    its force has no realisation to run in time.

    Parameters
    ----------
    loop : Loop
        A loop with a continuous controller.

    Raises
    ------
    ValueError
        For a controller with more zeros than poles, naming the keys that give it a run.

    Examples
    --------
    >>> import control
    >>> from motionhyst import Loop
    >>> from motionhyst.plants import MassDamper
    >>> pid = control.tf([6.0, 3.0, 4.0], [1.0, 0.0])        # kd s + kp + ki / s
    >>> check_proper(Loop(MassDamper(m=1.0, c=0.0), pid, feedforward=None))
    Traceback (most recent call last):
    ...
    ValueError: the controller is not proper (more zeros than poles: a PID's kd without ...
    """
    num, den = tf_poly(loop.controller, "controller")
    if len(np.trim_zeros(num, "f")) > len(np.trim_zeros(den, "f")):
        raise ValueError("the controller is not proper (more zeros than poles: a PID's kd "
                         "without derivative_filter_hz): a time simulation needs [controller] "
                         "derivative_filter_hz, or sample_rate_hz to run it sampled")


def _along_stroke(engine: _Engine, t: NDArray[np.float64], h_foh: float) -> Simulation:
    """The run in the link's pieces (:meth:`AlongStroke.pieces` of the setpoint), the link at
    the setpoint's mean position over each (the stage's within the error); a feedforward
    model along the stroke on the whole setpoint."""
    r = np.asarray(engine.reference(t)[0], dtype=float)
    # the forces of the whole run (a force may have a state: a link model's), read by piece
    uf = np.zeros(t.shape) if engine.force is None else np.asarray(engine.force(t), float)
    if uf.shape != t.shape:
        raise ValueError("the feedforward force must give one finite value per time")
    if isinstance(engine.hff, AlongStroke):  # phi_hat(r) of the whole run, as a force
        uf = uf + engine.hff.response(r, t=t)  # t: a rate-dependent model's velocity
        engine.hff = None

    def force(tt):
        return np.interp(tt, t, uf)

    engine.force = force
    return _in_pieces(engine, t, 0, h_foh, r)


def _in_pieces(engine: _Engine, t: NDArray[np.float64], i0: int, h_foh: float,
               r: NDArray[np.float64] | None = None) -> Simulation:
    """``engine.run`` of the samples `t` (indices from `i0`), a link along the stroke updated
    between its pieces of the setpoint `r` (``reference(t)`` if not given), its stop
    operators' stiffness conserved at each piece's end (:meth:`AlongStroke.conserve`: the
    state carried and the piece's last record)."""
    link = engine.loop.hysteresis
    if not isinstance(link, AlongStroke):
        return engine.run(t, i0, h_foh)
    r = np.asarray(engine.reference(t)[0], dtype=float) if r is None else r
    parts = []
    state = engine.state
    for a, b in link.pieces(r):
        engine.stepping.params[:] = link.stepping_params(float(np.mean(r[a:b])))
        s_start = state.s.copy()
        part = engine.run(t[a:b], i0 + a, h_foh)
        y_start = part.y1[0] if engine.y1_end is None else engine.y1_end
        engine.y1_end = float(part.y1[-1])
        dw = link.conserve(state.s, s_start, y_start, engine.y1_end, engine.stepping.params)
        if dw:
            state.scal[0] += dw  # the force at the node the next step starts from
            part.w[-1] += dw
        parts.append(part)
    return Simulation(**{c: np.concatenate([getattr(p, c) for p in parts])
                         for c in ("t", "r", "e", "y1", "y2", "u", "w", "e_linear")})


def check_long_run(loop: Loop) -> None:
    """Refuse, before a run starts, what a continuous loop's run in pieces
    (:func:`simulate_chunks`) does not take: a feedforward other than ``M r''``
    (:func:`_check_feedforward`) and a feedforward model along the stroke, whose force
    :func:`simulate` takes from the whole run's setpoint.  A ``ValueError`` names the
    scenario's key of what is not taken, and what runs it.

    Parameters
    ----------
    loop : Loop
        The loop to run, its controller continuous.

    Examples
    --------
    >>> from motionhyst.scenario import default_scenario
    >>> check_long_run(default_scenario().loop())          # Table I: taken
    """
    _check_feedforward(loop)
    if isinstance(loop.hysteresis_feedforward, AlongStroke):
        raise ValueError(f"a continuous loop's long run in time takes no feedforward model "
                         f"along the stroke ({loop.hysteresis_feedforward.key}): it is run "
                         f"by scan (motionhyst scan)")


def _check_feedforward(loop: Loop) -> None:
    """The continuous run takes the rigid-body feedforward ``M r''`` alone; say so otherwise."""
    ff = loop.ff
    if ff is not None and (ff.viscous or ff.coulomb or ff.mass != loop.M or ff.jerk
                           or ff.snap):
        raise ValueError("the continuous loop's time simulation takes the rigid-body "
                         "feedforward M r'' alone; [feedforward] acceleration, viscous, "
                         "coulomb, jerk and snap are run with a sampled controller "
                         "([controller] sample_rate_hz) or by `scan`, and analysed either way")


def simulate_chunks(loop: Loop, reference, duration: float, dt: float | None = None,
                    force=None, chunk: int = 1 << 16) -> Iterator[Simulation]:
    """:func:`simulate` in consecutive pieces of at most `chunk` samples, for long runs.

    Memory stays bounded by the chunk, whatever the duration; the pieces,
    joined, are the samples of :func:`simulate` (the same integration, its
    state carried from piece to piece).

    Parameters
    ----------
    loop, reference, duration, dt, force
        As :func:`simulate`; `duration` may give any number of steps.
    chunk : int
        Samples per piece, >= 1.

    Yields
    ------
    Simulation
        The samples of one piece, ``t`` continuing where the previous ended.

    Examples
    --------
    >>> from motionhyst.scenario import default_scenario
    >>> from motionhyst.time.references import SineReference
    >>> loop = default_scenario().loop()
    >>> ref = SineReference(0.01, 5.0)
    >>> pieces = list(simulate_chunks(loop, ref, 0.01, chunk=100))
    >>> whole = simulate(loop, ref, 0.01)
    >>> bool(np.allclose(np.concatenate([p.e for p in pieces]), whole.e, rtol=0, atol=1e-15))
    True
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if int(chunk) < 1:
        raise ValueError("chunk must be >= 1")
    if loop.sampled is not None:  # one run at the controller's samples, given in pieces
        whole = simulate(loop, reference, duration, dt, force)
        cols = ("t", "r", "e", "y1", "y2", "u", "w", "e_linear")
        for i0 in range(0, whole.t.size, int(chunk)):
            yield Simulation(**{c: getattr(whole, c)[i0:i0 + int(chunk)] for c in cols})
        return
    check_long_run(loop)
    engine = _Engine(loop, reference, dt, force)
    n = int(np.ceil(duration / engine.step)) + 1
    check_run_work(loop, n)
    for i0 in range(0, n, int(chunk)):
        t = np.arange(i0, min(n, i0 + int(chunk))) * engine.step
        yield _in_pieces(engine, t, i0, engine.step)


#: The discretised linear parts of the last runs: ``(loop, step, omega0, sys_a, disc_a,
#: disc_w)``; a scan's trials run one loop at one step many times (the matrix exponentials
#: were half of their time).  The loop is held, so that its identity is its key.
_DISCRETISED: list[tuple] = []


def _discretised(loop: Loop, step: float):
    """The loop's scale ``omega0``, the system ``r'' -> (e, y1 - r)``, and its and
    ``w -> (e, y1 - r)``'s discretisations at `step` (from :data:`_DISCRETISED` if there)."""
    for entry in _DISCRETISED:
        if entry[0] is loop and entry[1] == step:
            return entry[2:]
    omega0 = float(np.max(np.abs(loop.closed_loop_poles())))
    sys_a, sys_w = _block_systems(loop, omega0)
    entry = (loop, step, omega0, sys_a, discretize_foh(sys_a, omega0 * step),
             discretize_foh(sys_w, omega0 * step))
    _DISCRETISED.insert(0, entry)
    del _DISCRETISED[4:]
    return entry[2:]


class _Engine:
    """The discretised loop of :func:`simulate`, run chunk by chunk with its state carried."""

    def __init__(self, loop: Loop, reference, dt: float | None, force):
        if loop.feedforward != "rigid-body" and loop.feedforward is not None:
            raise ValueError("unknown feedforward")
        check_proper(loop)
        self.loop = loop
        self.reference = reference
        self.force = force
        self.codes, self.params, s0, self.f_scale = _elements(loop.hysteresis)
        self.hff = loop.hysteresis_feedforward
        if self.hff is not None:
            _elements(self.hff)  # the same models are supported as feedforward
        f_ref = getattr(reference, "max_frequency_hz", 1.0)
        step = default_step(loop, f_ref) if dt is None else float(dt)
        if not (np.isfinite(step) and step > 0):
            raise ValueError("dt must be finite and > 0")
        self.step = step
        omega0, sys_a, disc_a, self.disc_w = _discretised(loop, step)
        # a reference that starts with a velocity v0 has r'' = v0 delta(t) + ...: the impulse
        # sets the initial state (delta(t) = omega0 delta(tau) in scaled time)
        v0 = float(getattr(reference, "initial_velocity", 0.0))
        self.x_a = np.ascontiguousarray(sys_a[1][:, 0] * v0 * omega0, dtype=float)
        Ad, Bd, Cd, Dd = disc_a
        self.disc_a = (Ad, np.ascontiguousarray(Bd[:, 0]), Cd, np.ascontiguousarray(Dd[:, 0]))
        self.x_a = np.ascontiguousarray(self.x_a[:, None])
        # the link force drives the linear part as f = u_h - w: w - u_h -> (e, y1 - r), negated
        Ad, Bd, Cd, Dd = self.disc_w
        self.steps = [FohStep(Ad, -Bd[:, 0], np.zeros(Ad.shape[0]), step)]
        self.C, self.D = Cd, -Dd[:, 0]
        self.stepping = Stepping(self.codes, self.params, np.ascontiguousarray(s0, dtype=float),
                                 self.f_scale)
        self.state = LoopState.at_rest(Ad.shape[0], self.stepping)
        self.r_prev = None
        self.y1_end = None  # the link's position at the last sample run
        self.uh_prev = 0.0
        self.hff_history = np.empty(0)
        if self.hff is not None and not self.hff.rate_independent:
            self.hff_codes, self.hff_params, hs0, _ = _elements(self.hff)
            self.hff_s = np.ascontiguousarray(hs0, dtype=float).copy()
            self.hff_s_prev = self.hff_s.copy()
            self.hff_scalars = np.zeros(2)
        self.feedback = None

    def run(self, t: NDArray[np.float64], i0: int, h_foh: float) -> Simulation:
        """The samples at times `t` (indices from `i0`), continuing the previous call."""
        loop, step = self.loop, self.step
        r, a = self.reference(t)
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(a))):
            raise ValueError("the reference has non-finite values")
        r = np.ascontiguousarray(r, dtype=float)
        a = np.ascontiguousarray(a, dtype=float)
        lin = dss_filter(*self.disc_a, a[:, None], self.x_a)[:, :, 0]
        e_lin = np.ascontiguousarray(lin[:, 0])
        # hysteresis feedforward u_h = phi_hat(r) acts like -w on the loop
        hff = self.hff
        if hff is None:
            uh = np.zeros_like(r)
        elif hff.rate_independent:
            uh = self._rate_independent_feedforward(r)
        else:  # as the link in the loop: force with the velocity at the sample
            uh = open_loop_calls(self.hff_codes, self.hff_params, self.hff_s,
                                 self.hff_s_prev, self.hff_scalars, r, step, i0, GL_T, GL_W)
        if self.force is not None:
            uf = np.asarray(self.force(t), dtype=float)
            if uf.shape != t.shape or not np.all(np.isfinite(uf)):
                raise ValueError("the feedforward force must give one finite value per time")
            uh = np.ascontiguousarray(uh + uf)
        # the link between the linear response to r'' and the link force (the engine's
        # closed-loop convention); the first sample is a step of length 0 from rest
        r_prev = r[0] if self.r_prev is None else self.r_prev
        dr = np.ascontiguousarray(np.diff(r, prepend=r_prev))
        nodes = np.concatenate([[self.uh_prev], uh])
        Y, _, w, _, iters, done = run_steps(
            self.steps, self.C, self.D, 1, self.stepping, nodes, self.state,
            convention=CLOSED, ftol=1e-14 * self.f_scale, dexo=dr,
            exo=np.ascontiguousarray(lin), i_first=1)
        if iters > MAX_FIXED_POINT_ITERATIONS:
            raise StepNotConverged(
                f"the implicit step at t = {(i0 + done) * step:.6g} s did not converge in "
                f"{MAX_FIXED_POINT_ITERATIONS} iterations: the link is too stiff (or too "
                f"strongly damped) for the time step of {step:.3g} s", "use a smaller dt")
        self.r_prev = float(r[-1]) if len(r) else self.r_prev
        self.uh_prev = float(uh[-1]) if len(uh) else self.uh_prev
        e = Y[:, 0]
        dev = Y[:, 1]
        y1 = r + dev
        y2 = r - e
        # feedback force C e, the input linear between samples (as control.forced_response)
        if self.feedback is None:
            self.feedback = FohResponse(loop.controller, h_foh)
        u = self.feedback(e)
        if loop.feedforward == "rigid-body":
            u = u + loop.M * a  # the impulse M v0 delta(t) at t = 0 is not representable
        u = u + uh
        return Simulation(t=t, r=r, e=e, y1=y1, y2=y2, u=u, w=w, e_linear=e_lin)

    def _rate_independent_feedforward(self, r: NDArray[np.float64]) -> NDArray[np.float64]:
        """``phi_hat(r)`` of a rate-independent feedforward, continued from the previous chunk.

        A rate-independent element's state after a monotone stretch depends on
        its end point only: the first sample and the reversals seen so far
        replay the state exactly before the new samples.
        """
        hist = self.hff_history
        x = np.concatenate([hist, r]) if len(hist) else r
        out = self.hff.response(x)[len(hist):]
        self.hff_history = _turning_points(x)
        return np.ascontiguousarray(out, dtype=float)


def _turning_points(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The first sample, the reversals and the last sample of `x`: enough to replay its path."""
    if len(x) < 3:
        return x.copy()
    d = np.diff(x)
    nz = np.flatnonzero(d != 0)
    if nz.size == 0:
        return x[[0, -1]].copy()
    sgn = np.sign(d[nz])
    turns = nz[np.flatnonzero(sgn[1:] != sgn[:-1]) + 1]  # first step of a new direction
    keep = np.unique(np.concatenate([[0], turns, [len(x) - 1]]))
    return x[keep].copy()
