"""Learning the feedforward's coefficients from trials: learning in a basis, which carries over.

The feedforward is the model's terms (:mod:`motionhyst.scan.terms`) with
coefficients ``theta`` (mass, jerk, snap, viscous, Coulomb, the link model's
parameters).  Each trial runs the setpoint from rest; its error ``e_j`` is
the loop's process sensitivity acting on the force's mismatch, so a change
``delta`` of the coefficients changes the error by ``-PS J delta`` with ``J``
the force's derivatives in ``theta`` (its regressors: ``r''``, ``r'''``,
``r''''``, ``r'``, ``sign(r')``, ``d phi_hat / d p``).  The Gauss-Newton
update::

    theta_{j+1} = theta_j + argmin_delta || e_j - Phi_j delta ||^2,   Phi_j = PS J(theta_j)

with ``PS = P2 / (1 + C P2)`` the model of the loop (``G_d / (1 + Y G_d)`` at a
sampled controller's rate) applied to each regressor over the whole trial.
Unlike the force learned by :mod:`motionhyst.scan.ilc`, a function of time
that belongs to its setpoint, the learned coefficients are those of
functions of the setpoint's derivatives and position: they carry over to
another length and speed.  Regressors the trial cannot tell apart (a
Coulomb term beside a slipping link) share the update by its least-norm
solution over the columns scaled to unit norm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

from motionhyst.controllers.loop import Loop
from motionhyst.core.textfmt import g
from motionhyst.scan.ilc import process_sensitivity
from motionhyst.scan.terms import FeedforwardTerms, setpoint_samples
from motionhyst.time.simulation import Simulation, default_step, simulate

__all__ = ["BasisResult", "learn_basis"]

#: Singular values below this fraction of the largest (of the unit-norm regressors) are
#: directions the trial does not determine: left unchanged.
RCOND = 1e-6


def _through_ps(loop: Loop, t: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray:
    """``PS x`` for each column of `x` on the uniform grid `t`, padded at rest (as ILC)."""
    n = len(t)
    dt = (t[-1] - t[0]) / (n - 1)
    nfft = next_fast_len(2 * n, real=True)
    half = (nfft - n) // 2
    x = np.asarray(x, dtype=float)
    padded = np.concatenate([x, np.repeat(x[-1:], half, axis=0),
                             np.repeat(x[:1], nfft - n - half, axis=0)])
    ps = process_sensitivity(loop, rfftfreq(nfft, dt))
    return irfft(ps[:, None] * rfft(padded, axis=0), nfft, axis=0)[:n]


@dataclass
class BasisResult:
    """Result of :func:`learn_basis`: the coefficients of each trial and the last trial.

    Attributes
    ----------
    initial : FeedforwardTerms
        The coefficients of the first trial (the model's).
    terms : FeedforwardTerms
        The coefficients of the last trial (learned from the trials before it).
    history : list of ndarray
        The coefficient vector of each trial.
    rms_errors, peak_errors : list of float
        RMS and peak of each trial's error [m].
    last : Simulation
        The last trial.

    Examples
    --------
    >>> from motionhyst.scan.terms import FeedforwardTerms
    >>> res = BasisResult(FeedforwardTerms(22.5, {"mass": 22.0}),
    ...                   FeedforwardTerms(22.5, {"mass": 22.5}), [], [1e-8, 1e-10],
    ...                   [2e-8, 3e-10], last=None)
    >>> res.trials, res.to_dict()["learned"]
    (2, {'mass': 22.5})
    """

    initial: FeedforwardTerms
    terms: FeedforwardTerms
    history: list[NDArray[np.float64]]
    rms_errors: list[float]
    peak_errors: list[float]
    last: Simulation = field(repr=False)

    @property
    def trials(self) -> int:
        """Number of trials run."""
        return len(self.rms_errors)

    def to_dict(self) -> dict:
        """Trials, the initial and the learned coefficients (JSON keys spelled here)."""
        learned = self.terms.to_dict()
        return {"trials": list(self.rms_errors), "trials_peak_error": list(self.peak_errors),
                "update": "Gauss-Newton, PS = P2 / (1 + C P2)",
                "initial": self.initial.values(), "learned": learned["coefficients"],
                "units": learned["units"]}

    def __str__(self) -> str:
        first, last = self.rms_errors[0], self.rms_errors[-1]
        head = (f"basis, {self.trials} trials: RMS error {first:.4g} m -> {last:.4g} m"
                + (f" ({first / last:.3g}x)" if last > 0 else ""))
        units = self.terms.to_dict()["units"]
        rows = []
        for name, v0 in self.initial.values().items():
            v = self.terms.values()[name]
            fmt = (lambda x: g(x)) if not isinstance(v, list) else (
                lambda x: "[" + ", ".join(g(y) for y in x) + "]")
            rows.append(f"  {name:10s} {fmt(v0):>12s} -> {fmt(v):>12s} {units[name]}")
        return "\n".join([head, "  coefficient   model      -> learned", *rows])


def learn_basis(loop: Loop, terms: FeedforwardTerms, profile, duration: float,
                trials: int = 4, dt: float | None = None, first: Simulation | None = None,
                advance: float = 0.0) -> BasisResult:
    """Learn the coefficients of `terms` over `trials` trials of `profile` from rest.

    Parameters
    ----------
    loop : Loop
        The loop with its link, its feedforward the acceleration term ``M0 r''`` alone
        (the terms add the rest).
    terms : FeedforwardTerms
        The first trial's coefficients (the model's).
    profile : Profile
        The setpoint (its derivatives give the regressors).
    duration : float
        Length of a trial [s].
    trials : int
        Number of trials, >= 1; the first runs with `terms`.
    dt : float, optional
        Time step [s] (default: the simulation's own).
    first : Simulation, optional
        The first trial if already simulated (same loop, force, grid; for a
        continuous loop the force averaged as :func:`~motionhyst.scan.terms.setpoint_samples`).
    advance : float
        The feedforward reads the setpoint this much ahead [s] (a sampled controller's).

    Returns
    -------
    BasisResult

    Examples
    --------
    The Table I loop starting without a snap term and with the link model 25 % stiff
    and 20 % weak learns the stage's compliance ``m1 m2 / k`` and the link:

    >>> from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage
    >>> from motionhyst.scan.profiles import scan
    >>> loop = Loop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), LeadLagLowpass(6.2e6, 60, 240, 700, 0.6),
    ...             Jenkins(20.0, 0.05))
    >>> p = scan(0.01, speed=0.1, a_max=10.0, j_max=1000.0, s_max=2e5, start=0.01)
    >>> start = FeedforwardTerms(22.5, {"mass": 22.5, "snap": 0.0}, Jenkins(25.0, 0.04))
    >>> res = learn_basis(loop, start, p, p.end + 0.01, trials=3)
    >>> print(f"snap {res.terms.coefficients['snap']:.3g} N s^4/m")   # m1 m2 / k = 1.18e-6
    snap 1.18e-06 N s^4/m
    >>> link = res.terms.scaled_link()
    >>> print(f"link: k {link.k:.3g} N/m, fc {link.fc:.3g} N")
    link: k 20 N/m, fc 0.05 N
    """
    if not (isinstance(trials, int) and trials >= 1):
        raise ValueError(f"the number of basis trials must be a whole number >= 1, got {trials!r}")
    if first is None:
        step = None if loop.sampled is not None else (
            default_step(loop, profile.max_frequency_hz) if dt is None else dt)
        first = simulate(loop, profile, duration, dt,
                         force=terms.force_function(profile, advance, step))
    sim = first
    t = sim.t
    step = None if loop.sampled is not None else (t[-1] - t[0]) / (len(t) - 1)
    d = setpoint_samples(profile, t + advance, step)
    current = terms
    history, rms, peak = [], [], []
    for j in range(trials):
        if j > 0:
            phi = _through_ps(loop, t, current.jacobian(d))
            norms = np.sqrt(np.sum(phi ** 2, axis=0))
            ok = norms > 0
            delta = np.zeros(phi.shape[1])
            if ok.any():
                solution = np.linalg.lstsq(phi[:, ok] / norms[ok], sim.e, rcond=RCOND)[0]
                delta[ok] = solution / norms[ok]
            current = current.with_vector(current.vector() + delta)
            sim = simulate(loop, profile, duration, dt,
                           force=current.force_function(profile, advance, step))
        history.append(current.vector())
        rms.append(float(np.sqrt(np.mean(sim.e ** 2))))
        peak.append(float(np.max(np.abs(sim.e))))
    return BasisResult(terms, current, history, rms, peak, sim)
