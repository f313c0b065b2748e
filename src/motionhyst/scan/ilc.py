"""Frequency-domain iterative learning control (ILC) of a feedforward force.

Each trial runs the same setpoint from rest; after trial ``j`` the force is
updated from the trial's error ``e_j`` over the whole trial (non-causally)::

    f_{j+1} = Q (f_j + L e_j),     L = gain / PS,     PS = P2 / (1 + C P2)

``PS`` is the loop's process sensitivity, the transfer from a force at the
actuator to the error (``e = -PS u_ff + PS w``, the paper's ``w -> e``
transfer, see :mod:`motionhyst.controllers.loop`).  In the linear loop the error then
contracts by ``Q (1 - gain)`` per trial, up to what the robustness filter
``Q`` leaves out.  ``Q`` is a zero-phase low-pass: the squared magnitude of a
Butterworth filter, ``Q = 1 / (1 + (f / cutoff_hz)^(2 order))``, i.e. a
Butterworth filter run forwards and backwards; it keeps the improper ``1 /
PS`` from growing without bound and sets what the learning may trust.

The hysteresis of the dynamic link is a repetitive disturbance of a trial that
starts from rest (the link force depends on the position, which the learned
force moves only by the size of the error), so the learning removes it; the
learned force, a function of time, belongs to its setpoint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI
from motionhyst.time.simulation import Simulation, default_step, simulate

__all__ = ["ILCFilters", "ILCResult", "learn", "process_sensitivity"]


def process_sensitivity(loop: Loop, f_hz) -> NDArray[np.complex128]:
    """``PS = P2 / (1 + C P2)`` of `loop` at `f_hz` [Hz]: a force at the actuator gives ``-PS f``.

    For a sampled controller, at its rate on the error's samples (a force added to
    its output): ``PS = G_d / (1 + Y G_d)`` at ``z = e^{j 2 pi f T}``.

    Parameters
    ----------
    loop : Loop
        The loop.
    f_hz : array_like
        Frequencies [Hz].

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> ps = process_sensitivity(default_scenario().loop(), [0.0])
    >>> print(f"{ps[0].real:.4g} m/N")                    # 1 / C(0): no integrator
    1.613e-07 m/N
    """
    w = TWO_PI * np.asarray(f_hz, dtype=float)
    if loop.sampled is not None:  # at the controller's samples: G_d / (1 + Y G_d)
        return loop.sampled_parts.process_sensitivity(w)
    return loop.transfer("w->e", w)


@dataclass(frozen=True)
class ILCFilters:
    """Learning filter ``L = gain / PS`` and robustness filter ``Q`` of the update.

    Parameters
    ----------
    gain : float
        Learning gain in (0, 2): the error contracts by ``|1 - gain|`` per
        trial where ``Q = 1`` (1: at once, in the linear loop).
    cutoff_hz : float
        Corner of the robustness filter [Hz], > 0.
    order : int
        Order of the Butterworth filter whose squared magnitude is ``Q``, >= 1.

    Examples
    --------
    >>> q = ILCFilters(gain=0.8, cutoff_hz=300.0, order=2)
    >>> [round(float(x), 4) for x in q.robustness([0.0, 300.0, 3000.0])]
    [1.0, 0.5, 0.0001]
    """

    gain: float = 1.0
    cutoff_hz: float = 300.0
    order: int = 2

    def __post_init__(self):
        if not (math.isfinite(self.gain) and 0 < self.gain < 2):
            raise ValueError(f"ILC gain must be in (0, 2), got {self.gain!r}")
        if not (math.isfinite(self.cutoff_hz) and self.cutoff_hz > 0):
            raise ValueError(f"ILC cutoff must be finite and > 0 Hz, got {self.cutoff_hz!r}")
        if not (isinstance(self.order, int) and self.order >= 1):
            raise ValueError(f"ILC filter order must be a whole number >= 1, got {self.order!r}")

    def robustness(self, f_hz) -> NDArray[np.float64]:
        """``Q(f) = 1 / (1 + (f / cutoff_hz)^(2 order))``, real and zero-phase.

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz].
        """
        x = np.asarray(f_hz, dtype=float) / self.cutoff_hz
        return 1.0 / (1.0 + x ** (2 * self.order))

    def learning(self, loop: Loop, f_hz) -> NDArray[np.complex128]:
        """``L(f) = gain / PS(j 2 pi f)`` with ``PS = P2 / (1 + C P2)`` of `loop`.

        For a sampled controller the learning runs at its rate on the error's
        samples, the force added to its output: ``PS = G_d / (1 + Y G_d)`` at
        ``z = e^{j 2 pi f T}``.  Where ``PS`` vanishes (a controller with an
        integrator at DC) ``L`` is 0.

        Parameters
        ----------
        loop : Loop
            The loop with its link.
        f_hz : array_like
            Frequencies [Hz].
        """
        ps = process_sensitivity(loop, f_hz)
        out = np.zeros(ps.shape, dtype=complex)
        ok = np.abs(ps) > 0
        out[ok] = self.gain / ps[ok]
        return out

    def update(self, loop: Loop, t: NDArray[np.float64], force: NDArray[np.float64],
               error: NDArray[np.float64]) -> NDArray[np.float64]:
        """The next trial's force ``Q (f + L e)`` on the uniform grid `t`.

        The trial is padded to at least twice its length by holding its last
        values, then its first ones (the loop at rest before and after), so
        the non-causal filters see no jump at its ends and do not wrap its
        end onto its start.

        Parameters
        ----------
        loop : Loop
            The loop with its link.
        t : ndarray
            Uniform time grid [s].
        force : ndarray
            This trial's learned force [N].
        error : ndarray
            This trial's error [m].
        """
        n = len(t)
        dt = (t[-1] - t[0]) / (n - 1)
        nfft = next_fast_len(2 * n, real=True)
        f_hz = rfftfreq(nfft, dt)

        def padded(x):
            x = np.asarray(x, dtype=float)
            half = (nfft - n) // 2
            return np.concatenate([x, np.full(half, x[-1]), np.full(nfft - n - half, x[0])])

        spectrum = self.robustness(f_hz) * (rfft(padded(force))
                                            + self.learning(loop, f_hz) * rfft(padded(error)))
        return irfft(spectrum, nfft)[:n]

    def to_dict(self) -> dict:
        """The filters' settings (JSON keys spelled here)."""
        return {"learning_filter": "gain / PS, PS = P2 / (1 + C P2)", "gain": self.gain,
                "robustness_filter": "zero-phase Butterworth magnitude squared",
                "robustness_cutoff_hz": self.cutoff_hz, "robustness_order": self.order}


@dataclass
class ILCResult:
    """Result of :func:`learn`: the trials' errors and the force of the last trial.

    Attributes
    ----------
    filters : ILCFilters
        The update's filters.
    t : ndarray
        Time grid of the trials [s].
    force : ndarray
        Feedforward force of the last trial [N] (learned from the trials before it).
    rms_errors, peak_errors : list of float
        RMS and peak of the error of each trial [m]; the first trial has no
        learned force.
    last : Simulation
        The last trial.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.scan.profiles import point_to_point
    >>> p = point_to_point(0.002, 0.05, 2.0, 50.0, 1e3, start=0.005)
    >>> res = learn(default_scenario().loop(), p, p.end + 0.01, trials=2)
    >>> res.trials, bool(res.rms_errors[-1] < res.rms_errors[0])   # the second trial is better
    (2, True)
    """

    filters: ILCFilters
    t: NDArray[np.float64]
    force: NDArray[np.float64]
    rms_errors: list[float]
    peak_errors: list[float]
    last: Simulation = field(repr=False)

    @property
    def trials(self) -> int:
        """Number of trials run."""
        return len(self.rms_errors)

    def force_function(self):
        """The learned force as a function of time: linear between samples, 0 before
        the first and the last value held after the trial (the stage at rest)."""
        t, f = self.t, self.force

        def force(tt):
            return np.interp(tt, t, f, left=0.0, right=f[-1])

        return force

    def to_dict(self) -> dict:
        """Trials and filters (JSON keys spelled here)."""
        return {"trials": list(self.rms_errors), "trials_peak_error": list(self.peak_errors),
                **self.filters.to_dict()}

    def __str__(self) -> str:
        first, last = self.rms_errors[0], self.rms_errors[-1]
        return (f"ILC, {self.trials} trials (gain {self.filters.gain:g}, Q: "
                f"{self.filters.cutoff_hz:g} Hz order {self.filters.order}): RMS error "
                f"{first:.4g} m -> {last:.4g} m ({first / last:.3g}x)" if last > 0 else
                f"ILC, {self.trials} trials: RMS error {first:.4g} m -> 0")

    def plot(self, ax=None):
        """Figure of the RMS and peak error against the trial.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.
        """
        from matplotlib.figure import Figure

        if ax is None:
            fig = Figure(figsize=(6.4, 3.6), layout="constrained")
            ax = fig.subplots()
        fig = ax.figure
        k = np.arange(1, self.trials + 1)
        ax.semilogy(k, self.rms_errors, "o-", label="RMS error")
        ax.semilogy(k, self.peak_errors, "s--", label="peak error")
        ax.set_xlabel("trial")
        ax.set_ylabel("error [m]")
        ax.set_title(str(self), fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        return fig


def learn(loop: Loop, reference, duration: float, trials: int = 10,
          filters: ILCFilters | None = None, dt: float | None = None,
          first: Simulation | None = None) -> ILCResult:
    """Learn a feedforward force for `reference` over `trials` trials, each from rest.

    Parameters
    ----------
    loop : Loop
        The loop (its link included); any hysteresis feedforward in it stays on.
    reference : callable
        The setpoint, ``reference(t) -> (r, r'')`` (e.g. a :mod:`motionhyst.scan.profiles` profile).
    duration : float
        Length of a trial [s].
    trials : int
        Number of trials, >= 1; the first runs without learned force.
    filters : ILCFilters, optional
        Learning and robustness filters (default ``ILCFilters()``).
    dt : float, optional
        Time step [s]; by default :func:`~motionhyst.time.simulation.default_step`.
    first : Simulation, optional
        The first trial if already simulated (same loop, reference, grid).

    Returns
    -------
    ILCResult

    Examples
    --------
    >>> from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage
    >>> from motionhyst.scan.profiles import point_to_point
    >>> loop = Loop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), LeadLagLowpass(6.2e6, 60, 240, 700, 0.6),
    ...             Jenkins(20.0, 0.05))
    >>> p = point_to_point(0.005, 0.2, 20.0, 2000.0, 1e6, start=0.005)
    >>> res = learn(loop, p, p.end + 0.02, trials=4)
    >>> res.rms_errors[-1] < res.rms_errors[0] / 10
    True
    """
    if not (isinstance(trials, int) and trials >= 1):
        raise ValueError(f"the number of ILC trials must be a whole number >= 1, got {trials!r}")
    filters = ILCFilters() if filters is None else filters
    if loop.sampled is not None:  # the trials at the controller's rate
        if dt is not None and abs(dt - loop.sampled.period) > 1e-9 * loop.sampled.period:
            raise ValueError(f"a sampled loop learns at its controller's period "
                             f"{loop.sampled.period:g} s, not dt = {dt:g} s")
        dt = loop.sampled.period
    elif dt is None:
        dt = default_step(loop, getattr(reference, "max_frequency_hz", 1.0))
    sim = first if first is not None else simulate(loop, reference, duration, dt)
    t = sim.t
    force = np.zeros_like(t)
    rms, peak = [], []
    for j in range(trials):
        if j > 0:
            force = filters.update(loop, t, force, sim.e)
            f = force

            def feed(tt, f=f):
                return np.interp(tt, t, f)

            sim = simulate(loop, reference, duration, dt, force=feed)
        rms.append(float(np.sqrt(np.mean(sim.e ** 2))))
        peak.append(float(np.max(np.abs(sim.e))))
    return ILCResult(filters, t, force, rms, peak, sim)
