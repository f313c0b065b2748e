"""Time simulation of a loop with a sampled controller, as the real-time computer runs it.

The plant and the link move in continuous time (integrated exactly between
the controller's updates, the link by its exact update, on the one time
engine: :func:`motionhyst.time.engine.run_sampled`); the controller samples
the measured position at ``t_k = k T``, computes ``u_k = R(z) r_k - Y(z) y_k``
plus the feedforward from the setpoint read ``a`` samples ahead::

    u_ff,k = m r''(t_k + a T) + c r'(t_k + a T) + fc sign(r'(t_k + a T)) + phi_hat(r(t_k + a T))

(plus ``cj r'''`` and ``cs r''''`` at ``t_k + a T`` with a jerk and a snap term)

(``phi_hat`` evaluated on the setpoint's samples, as the machine does), limits
it to ``|u| <= u_max`` and applies it from ``t_k + d T`` on, held.  The output
is at the controller's samples.  The same run without the link gives the
linear error beside it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from motionhyst.controllers.loop import Loop
from motionhyst.core.budget import check_memory
from motionhyst.time.engine import run_sampled
from motionhyst.time.references import reference_bytes
from motionhyst.time.simulation_result import Simulation
from motionhyst.time.steps import MAX_SAMPLES, SAMPLED_SAMPLE_BYTES, RunTooLarge, a_run

__all__ = ["simulate_sampled"]


def _velocity(reference, t):
    """The setpoint's velocity at `t`: the reference's own, else from its acceleration."""
    from motionhyst.time.references import SineReference

    if isinstance(reference, SineReference):
        w = 2.0 * math.pi * reference.frequency_hz
        return reference.amplitude * w * np.cos(w * np.asarray(t, dtype=float))
    if callable(getattr(reference, "derivatives", None)):   # a profile: r, r', r'', ...
        return np.asarray(reference.derivatives(t), dtype=float)[1]
    raise ValueError("the viscous and Coulomb feedforward need the setpoint's velocity, which "
                     f"a {type(reference).__name__} does not give")


def feedforward_samples(loop: Loop, reference, t: ArrayLike) -> np.ndarray:
    """The feedforward force [N] the controller computes at its samples `t`.

    Parameters
    ----------
    loop : Loop
        A loop with a sampled controller.
    reference : callable
        ``reference(t) -> (r, r'')``.
    t : array_like
        The sampling instants ``t_k`` [s].

    Returns
    -------
    ndarray
        ``u_ff,k`` from the setpoint ``a`` samples ahead (module docstring).
    """
    ff, hff = loop.ff, loop.hysteresis_feedforward
    t = np.asarray(t, dtype=float)
    out = np.zeros(t.shape)
    if ff is None and hff is None:
        return out
    ahead = t + (0.0 if ff is None else ff.advance_samples) * loop.sampled.period
    r, acc = reference(ahead)
    if ff is not None and (ff.jerk or ff.snap):
        if not callable(getattr(reference, "derivatives", None)):
            raise ValueError("the jerk and snap feedforward need the setpoint's derivatives, "
                             f"which a {type(reference).__name__} does not give")
        d = np.asarray(reference.derivatives(ahead), dtype=float)
        out += ff.force(d[1], d[2], d[3], d[4])
    elif ff is not None:
        v = _velocity(reference, ahead) if (ff.viscous or ff.coulomb) else np.zeros(t.shape)
        out += ff.force(v, acc)
    if hff is not None:  # a rate-dependent model (LuGre) integrated over the samples' times
        r = np.asarray(r, dtype=float)
        out += hff.response(r) if hff.rate_independent else hff.response(r, t=ahead)
    return out


def simulate_sampled(loop: Loop, reference, duration: float, *, force=None,
                     x0: ArrayLike | None = None, substeps: int | None = None,
                     linear: bool = True) -> Simulation:
    """Run `loop` (its controller sampled) from rest for `duration` seconds.

    Parameters
    ----------
    loop : Loop
        A loop with a :class:`~motionhyst.controllers.sampled.SampledController` and a
        plant with a time-domain model (``mechanics()``).
    reference : callable
        ``reference(t) -> (r, r'')`` (:mod:`motionhyst.references`); sampled at ``t_k``.
    duration : float
        Simulated time [s], > 0.
    force : callable, optional
        An additional force [N], ``force(t) -> array``, evaluated at the samples and
        added to the controller's output (e.g. one learned by :mod:`motionhyst.ilc`).
    x0 : array_like, optional
        The plant's initial state ``(q, q')`` (default: rest).
    substeps : int, optional
        Fine steps of plant and link per controller period (default: the engine's).
    linear : bool
        Also run the loop without the link for ``e_linear`` (else it is nan).

    Returns
    -------
    Simulation
        At the controller's samples: ``u`` is the force computed at ``t_k`` (applied
        ``d`` samples later), ``y2`` the measured output, ``y1`` the link's position.

    Examples
    --------
    The EMPS benchmark's axis (a mass and a damper) in its cascade at 1 kHz:

    >>> from motionhyst import Loop, SineReference
    >>> from motionhyst.controllers.two_dof import position_velocity_cascade
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> c = position_velocity_cascade(160.18, 243.45, 35.15065, 1000.0)
    >>> sim = simulate_sampled(Loop(MassDamper(95.1, 203.5), c, None, feedforward=None),
    ...                        SineReference(0.01, 1.0), 1.0)
    >>> sim.t.size, f"{abs(sim.e[-250:]).max():.2e}"            # the cascade's lag at 1 Hz
    (1001, '4.03e-04')
    """
    c = loop.sampled
    if c is None:
        raise ValueError("simulate_sampled needs a loop with a sampled controller")
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if not callable(getattr(loop.plant, "mechanics", None)):
        raise ValueError("the time simulation needs the plant's time-domain model; a "
                         f"{type(loop.plant).__name__} has none")
    n = math.floor(duration * c.sample_rate_hz + 1e-9) + 1
    if n > MAX_SAMPLES:
        raise RunTooLarge(f"{n} controller samples: too many (at most {MAX_SAMPLES:.0e})",
                          "shorten the duration")
    with a_run():
        check_memory(SAMPLED_SAMPLE_BYTES * float(n) + reference_bytes(reference),
                     f"a run of {n} controller samples at {c.sample_rate_hz:g} Hz (held whole)",
                     "shorten the duration")
    t = np.arange(n) * c.period
    r, _ = reference(t)
    r = np.asarray(r, dtype=float)
    ff = feedforward_samples(loop, reference, t)
    if force is not None:
        extra = np.asarray(force(t), dtype=float)
        if extra.shape != t.shape or not np.all(np.isfinite(extra)):
            raise ValueError("the added force must give one finite value per sample")
        ff = ff + extra
    u_max = math.inf if c.u_max is None else c.u_max
    kw = {"ff": ff, "delay_samples": c.delay_samples, "u_max": u_max, "substeps": substeps,
          "x0": x0}
    run = run_sampled(loop.plant, loop.hysteresis, c, r, **kw)
    if linear and loop.hysteresis is not None:
        e_lin = run_sampled(loop.plant, None, c, r, **kw).e
    elif loop.hysteresis is None:
        e_lin = run.e
    else:
        e_lin = np.full(n, np.nan)
    return Simulation(t=t, r=r, e=run.e, y1=run.y_link, y2=run.y, u=run.u, w=run.w,
                      e_linear=e_lin)
