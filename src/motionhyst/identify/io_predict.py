"""Predicting a measured record with an identified model, its state set from a window.

The benchmark convention for models of measured records (the EMPS benchmark,
Janot, Gautier and Brunot 2019): the model runs open loop from the force
alone over the whole record, the first ``N`` samples (``N = 20``) may be used
to set its initial state, and the error is scored after them, from sample ``N + 1`` on
(samples counted from 1, as every message counts them).
:func:`predict_from_window` estimates the stage's initial state (its
velocity and its position, or the position offset of a floating stage, which
is the same thing) by least squares over the window, then simulates the
record from the force alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from motionhyst.core.budget import check_memory
from motionhyst.hysteresis.stepping import Stepping
from motionhyst.identify.residual_noise import white_noise_variance
from motionhyst.time.openloop import (
    OpenLoop,
    check_record,
    sampling_rate,
    simulate_elements,
)
from motionhyst.time.resample import fine_blocks, held_nodes

__all__ = ["INIT_WINDOW", "LOADED_START", "LOADED_START_SAMPLES", "WINDOW_NODE_BYTES",
           "WINDOW_RUN_SAMPLE_BYTES", "WINDOW_SAMPLE_BYTES", "WindowPrediction",
           "link_state_from_window", "predict_from_window", "run_from_state", "start_load",
           "state_from_window", "window_memory", "window_noise_floor"]

LOADED_START = 0.05
"""A model without inertia whose force record starts farther than this share of the force's
range from the model's rest (``-f0``, its force offset) starts under a load whose link state
is not known: the later half of a piezo's record, predicted from its link relaxed at its
first sample, scored 0.5 % (from the whole record's history: 98.9 %)."""

LOADED_START_SAMPLES = 10
"""The first samples of a force record whose median is where it starts
(:data:`LOADED_START`): one sample's noise or spike does not decide."""


def start_load(u: NDArray[np.float64], force_offset: float) -> float | None:
    """How far a force record `u` starts from the rest of a model without inertia whose
    force offset is `force_offset` (``u = -f0`` at rest), or None where it starts at rest
    (within :data:`LOADED_START` of its range, from the median of its first
    :data:`LOADED_START_SAMPLES`).

    Parameters
    ----------
    u : ndarray
        The force record [N].
    force_offset : float
        The model's force offset ``f0`` [N].

    Returns
    -------
    float or None
        The median of the first samples less the rest ``-f0`` [N]; None at rest.

    Examples
    --------
    >>> import numpy as np
    >>> u = np.concatenate([np.full(10, 48.0), np.linspace(48.0, -32.0, 90)])
    >>> start_load(u, force_offset=12.0), start_load(u - 60.0, force_offset=12.0)
    (60.0, None)
    """
    start = float(np.median(u[:LOADED_START_SAMPLES]))
    span = float(np.ptp(u))
    away = start + float(force_offset)
    return away if span > 0 and abs(away) > LOADED_START * span else None


#: The benchmark's initialisation window [samples]
INIT_WINDOW = 20

WINDOW_SAMPLE_BYTES = 560
"""Memory of :func:`predict_from_window` per record sample where its samples decide [bytes]
(the noise floor's runs and sensitivities, :func:`window_noise_floor`): measured 384.0 traced
and 352 of address space, Jenkins, Dahl, Maxwell-slip, LuGre and Bouc-Wen links, on a
mass-spring-damper, an axis and a two-mass stage, 2e4 to 2e5 samples at 5 to 20 steps; with
numpy 2.4.6 the address space rises by 520 a sample at 2e5 samples (360 at 2e4); 8 % above
that."""
WINDOW_NODE_BYTES = 40
"""Memory of :func:`predict_from_window` per fine node of a block where its blocks decide
[bytes]: measured 31 of address space (16.4 traced: the compiled kernels' arrays are not),
blocks of 2e6 nodes, 2e4 to 1e5 samples at 20 to 100 steps; with
:data:`WINDOW_RUN_SAMPLE_BYTES` a sample, 25-31 % above."""
WINDOW_RUN_SAMPLE_BYTES = 60
"""Memory of :func:`predict_from_window` per record sample beside its blocks [bytes]
(measured 46 of address space, 32 traced)."""


def window_memory(u: NDArray[np.float64], substeps: int) -> float:
    """Bytes :func:`predict_from_window` needs at most for the force `u` at `substeps`
    integration steps a sample: the larger of its samples' (:data:`WINDOW_SAMPLE_BYTES` a
    sample) and its blocks' (:data:`WINDOW_NODE_BYTES` a node held,
    :func:`~motionhyst.time.resample.held_nodes`, and :data:`WINDOW_RUN_SAMPLE_BYTES` a
    sample); main's 48 a node and 64 a sample were 1.5-1.6 times the peak where the
    blocks decide, and below it where the samples do (2e4 samples at 5 steps: 6.1 MB against
    7.7 traced).

    Parameters
    ----------
    u : ndarray
        The record's force.
    substeps : int
        Integration steps per sample.

    Returns
    -------
    float

    Examples
    --------
    >>> round(window_memory(np.zeros(200_000), 10) / 1e6, 1)       # its samples decide
    112.0
    >>> round(window_memory(np.zeros(20_000), 100) / 1e6, 1)       # its blocks
    81.2
    """
    return max(WINDOW_SAMPLE_BYTES * float(u.size),
               WINDOW_NODE_BYTES * float(held_nodes(u, int(substeps)))
               + WINDOW_RUN_SAMPLE_BYTES * float(u.size))


@dataclass
class WindowPrediction:
    """The prediction of a record from its force, the state set from its first samples.

    Attributes
    ----------
    t, displacement : ndarray
        Time [s] and predicted position [m] (with the estimated position offset).
    window : int
        Samples used to set the state; the error counts from the next on (sample
        ``window + 1``, counted from 1).
    initial_state : dict
        ``{"position": .., "velocity": ..}`` set from the window [m, m/s].
    rmse : float or None
        RMS error after the first `window` samples [m] (None without a measured position).
    fit_percent : float or None
        ``100 (1 - ||y - yhat|| / ||y - mean(y)||)`` over the same samples.
    noise_floor : float or None
        The RMS error after the first `window` samples that the measured positions' noise
        gives the true model, through the state its window sets (:func:`window_noise_floor`)
        [m]; None where there is no state (a stage without inertia).
    noise : float or None
        That noise [m] (the error's third differences:
        :func:`~motionhyst.identify.residual_noise.white_noise_variance`).

    Examples
    --------
    >>> pred = WindowPrediction(np.arange(3) / 1e3, np.zeros(3), 2,
    ...                         {"position": 0.0, "velocity": 0.0}, 1e-3, 90.0, 1e-5, 1e-6)
    >>> print(pred)
    predicted 3 samples, state set from the first 2 (position 0 m, velocity 0 m/s); RMS error
    from sample 3 on 0.001 m (fit 90.00 %); the positions' noise (1e-06 m), carried by the
    state the window sets, gives a true model an RMS error of about 1e-05 m
    """

    t: NDArray[np.float64]
    displacement: NDArray[np.float64]
    window: int
    initial_state: dict
    rmse: float | None = None
    fit_percent: float | None = None
    noise_floor: float | None = None
    noise: float | None = None

    def to_dict(self) -> dict:
        """JSON-ready summary (no arrays)."""
        return {"samples": int(self.t.size), "init_window": self.window,
                "initial_state": dict(self.initial_state), "rmse": self.rmse,
                "fit_percent": self.fit_percent, "noise_floor_rmse": self.noise_floor,
                "noise": self.noise}

    def floor_text(self) -> str:
        """What the noise alone would leave of the error (empty without it)."""
        if self.noise_floor is None or self.noise is None:
            return ""
        return (f"the positions' noise ({self.noise:.3g} m), carried by the state the window "
                f"sets, gives a true model an RMS error of about {self.noise_floor:.4g} m")

    def __str__(self) -> str:
        s = (f"predicted {self.t.size} samples, state set from the first {self.window} "
             f"(position {self.initial_state['position']:.6g} m, velocity "
             f"{self.initial_state['velocity']:.6g} m/s)")
        if self.rmse is not None:
            s += (f"; RMS error from sample {self.window + 1} on {self.rmse:.4g} m "
                  f"(fit {self.fit_percent:.2f} %)")
        if self.floor_text():
            s += f"; {self.floor_text()}"
        return s

    def plot(self, ax=None):
        """The predicted position against time; returns the Figure.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw (a new figure when None).

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        fig = ax.figure if ax is not None else plt.figure()
        ax = ax if ax is not None else fig.add_subplot()
        ax.plot(self.t, self.displacement, label="predicted")
        ax.axvline(self.t[min(self.window, self.t.size - 1)], color="0.6", lw=0.8)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("position [m]")
        ax.legend()
        return fig


def run_from_state(mech, stepping: Stepping, k_link: float, u, fs: float, r: int,
                   position: float, velocity: float, upsampled=None, dparams=None,
                   skew_column: int | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A record simulated from the force, the stage moving as one body at the first sample.

    Parameters
    ----------
    mech : Mechanics
        The plant (:meth:`~motionhyst.plants.registry.Plant.mechanics`).
    stepping : Stepping
        The link's rows (empty: no link); the link starts relaxed.
    k_link : float
        The link's initial stiffness [N/m].
    u : ndarray
        Force [N] at `fs` [Hz].
    fs : float
        Sampling rate [Hz].
    r : int
        Integration steps per sample.
    position, velocity : float
        The first sample's position [m] (a floating stage's: the offset added to
        its output) and velocity [m/s].
    upsampled, dparams : ndarray, optional
        As for :func:`~motionhyst.time.openloop.simulate_elements`.
    skew_column : int, optional
        As for :func:`~motionhyst.time.openloop.simulate_elements`.

    Returns
    -------
    y, dy : ndarray
        The position [m] and its sensitivities (as
        :func:`~motionhyst.time.openloop.simulate_elements`).

    Examples
    --------
    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> mech = MassSpringDamper(2.0, 0.0, 0.0).mechanics()
    >>> y, _ = run_from_state(mech, Stepping.empty(), 0.0, np.zeros(3), 10.0, 4, 1.0, 0.5)
    >>> y.round(6).tolist()
    [1.0, 1.05, 1.1]
    """
    n = mech.n
    x0 = np.zeros(2 * n)
    floating = mech.floating
    x0[n:] = velocity
    if not floating:
        x0[:n] = position
    y, dy = simulate_elements(mech, stepping, u, fs, r, periodic=False, k_link=k_link, x0=x0,
                              upsampled=upsampled, dparams=dparams,
                              skew_column=skew_column)
    return (y + position if floating else y), dy


def state_from_window(mech, stepping: Stepping, k_link: float, u, y, fs: float, r: int,
                      window: int = INIT_WINDOW, upsampled=None) -> tuple[float, float]:
    """The stage's position and velocity at the first sample that best explain its first
    `window` positions (least squares), the model run from the force alone.

    The window is run on the force the whole record's run takes there: the head of the
    record's upsampled force, not the window's samples upsampled alone (band-limited
    interpolation of 20 samples differs near their end, and the state found for that
    force is another run's: a true Jenkins axis predicted from its own noise-free window
    was 6.6e-7 m off on a 0.15 m stroke, now to round-off).

    Parameters
    ----------
    mech, stepping, k_link, fs, r
        As for :func:`run_from_state`.
    u, y : ndarray
        The record's force [N] and measured position [m] (at least `window` samples).
    window : int
        Samples that set the state, at least 2.
    upsampled : ndarray, optional
        The record's force upsampled for its run (``fine_input(u, r, False)``, as
        :func:`run_from_state` takes it), if already computed (default: the head of its
        first block, :func:`~motionhyst.time.resample.fine_blocks`).

    Returns
    -------
    position, velocity : float
        [m] and [m/s].

    Examples
    --------
    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> mech = MassSpringDamper(2.0, 0.0, 0.0).mechanics()
    >>> y = 1e-3 + 0.004 * np.arange(20) / 1000.0
    >>> p, v = state_from_window(mech, Stepping.empty(), 0.0, np.zeros(20), y, 1000.0, 2)
    >>> round(p, 9), round(v, 9)
    (0.001, 0.004)
    """
    yw = np.asarray(y[:window], dtype=float)
    uw = np.asarray(u[:window], dtype=float)
    if upsampled is None:  # the head of the record's first block: that of the whole record
        upsampled = next(fine_blocks(np.asarray(u, dtype=float), r))
    fine = np.asarray(upsampled[:(window - 1) * r + 1], dtype=float)
    v_start = (yw[-1] - yw[0]) * fs / (window - 1)
    scale_y = max(float(np.ptp(yw)), 1e-12 * max(1.0, abs(float(yw[0]))), 1e-15)

    def res(p):
        return (run_from_state(mech, stepping, k_link, uw, fs, r, p[0], p[1], fine)[0]
                - yw) / scale_y

    sol = least_squares(res, [yw[0], v_start], x_scale=[scale_y, scale_y * fs / window])
    return float(sol.x[0]), float(sol.x[1])


def predict_from_window(system: OpenLoop, t, force, displacement,
                        window: int = INIT_WINDOW, substeps: int | None = None
                        ) -> WindowPrediction:
    """Simulate a record from its force, the initial state set from its first samples.

    A plant without inertia (:class:`~motionhyst.plants.quasi_static.QuasiStatic`)
    has no state but its link's: the window sets the position's offset (reported as
    the initial position, velocity 0) and, for a link of one element (Bouc-Wen, Dahl,
    LuGre, Jenkins), the element's state and the displacement before the first sample
    (:func:`link_state_from_window`); the elements of a Maxwell-slip link start
    relaxed (how the force splits among them needs the record's history).

    Parameters
    ----------
    system : OpenLoop
        The identified stage and link (its plant's ``force_offset`` is part of its
        mechanics' run).
    t, force : array_like
        The record's time [s] and force [N].
    displacement : array_like
        Its measured position [m]: the first `window` samples set the state, the
        rest scores the prediction.
    window : int
        Samples that set the state (the benchmark's 20), at least 2.
    substeps : int, optional
        Integration steps per sample (default: the system's own choice).

    Returns
    -------
    WindowPrediction

    Examples
    --------
    A positioning axis with Coulomb friction, moving at 5 mm/s when the record starts:

    >>> from motionhyst.hysteresis import Coulomb
    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> true = OpenLoop(MassSpringDamper(95.0, 200.0, 0.0), Coulomb(fc=20.0))
    >>> t = np.arange(2000) / 1000.0
    >>> u = 80 * np.sin(2 * np.pi * 0.5 * t) + 25.0
    >>> y, _ = run_from_state(true.plant.mechanics(), true.hysteresis.time_stepping(),
    ...                       true.hysteresis.initial_stiffness, u, 1000.0, 20, 0.01, 0.005)
    >>> pred = predict_from_window(true, t, u, y, window=20)
    >>> round(pred.initial_state["velocity"], 6), pred.rmse < 1e-9
    (0.005, True)
    """
    if not (isinstance(window, int | np.integer) and window >= 2):
        raise ValueError(f"the initialisation window must be at least 2 samples, got {window}")
    tt, u = check_record(t, force)
    y = np.asarray(displacement, dtype=float)
    if y.shape != tt.shape or not np.all(np.isfinite(y)):
        raise ValueError("the measured position must be finite and as long as the force")
    if tt.size < 2 * window:  # a score of one sample (no spread) was "fit -inf %"
        raise ValueError(f"the record has {tt.size} samples, fewer than twice the "
                         f"initialisation window of {window} (the error is scored on at least "
                         f"as many samples after it as set the state)")
    if system.hysteresis is not None and not hasattr(system.hysteresis, "time_stepping"):
        raise ValueError("this link cannot be simulated")
    fs = sampling_rate(tt)
    if not system.plant.has_inertia:  # no state but the link's, and the position's offset
        return _quasi_static_from_window(system, tt, u, y, window)
    r = substeps or system.default_substeps(fs)
    u = u + float(getattr(system.plant, "force_drift", 0.0)) * tt  # a drifting force offset
    mech = system.plant.mechanics()
    st = Stepping.empty() if system.hysteresis is None else system.hysteresis.time_stepping()
    k_link = system.hysteresis.initial_stiffness if system.hysteresis is not None else 0.0
    # the record's force in blocks (time.resample.fine_blocks), as OpenLoop.simulate runs it
    check_memory(window_memory(u, r), f"{u.size} samples of {r} integration steps each",
                 "fewer samples or substeps")
    position, velocity = state_from_window(mech, st, k_link, u, y, fs, r, window)
    yhat, _ = run_from_state(mech, st, k_link, u, fs, r, position, velocity)
    pred = _scored(tt, yhat, y, window, position, velocity)
    pred.noise = math.sqrt(white_noise_variance([yhat - y]))
    pred.noise_floor = window_noise_floor(mech, st, k_link, u, fs, r, position, velocity, yhat,
                                          window, pred.noise)
    return pred


def link_state_from_window(system: OpenLoop, t, u, y, window: int = INIT_WINDOW
                           ) -> tuple[float, float, NDArray[np.float64] | None]:
    """The position offset, the displacement before the first sample and the link's state
    there that best explain the first `window` positions of a model without inertia.

    Without inertia the window's forces and positions fix the link's force at each of its
    samples (``w = u + f0 - k x - c x'``); a link of one element (its state one number) is
    set by least squares of the run over the window, with the position offset and the
    displacement before the first sample (the first velocity).  A link of several
    elements (Maxwell-slip) keeps them relaxed at the offset: how the force splits among
    them needs the record's history, not its window.

    Parameters
    ----------
    system : OpenLoop
        A quasi-static plant and its link.
    t, u, y : ndarray
        The record's time [s], force [N] and measured position [m].
    window : int
        Samples that set the state, at least 2.

    Returns
    -------
    position : float
        The position offset [m] (the sensor's reading where the model is at 0).
    x_before : float
        The model's displacement before the first sample [m].
    states : ndarray or None
        The link's element states there (None: relaxed, several elements or none).

    Examples
    --------
    A Dahl damper cut from a longer run, loaded at its first sample:

    >>> from motionhyst.hysteresis import Dahl
    >>> from motionhyst.plants import QuasiStatic
    >>> from motionhyst.time.quasi_static import displacement_from_force
    >>> system = OpenLoop(QuasiStatic(k=1e4, c=50.0), Dahl(k=3e5, fc=300.0))
    >>> t = np.arange(400) / 1000.0
    >>> u = 400.0 + 300.0 * np.sin(2 * np.pi * 3 * t)
    >>> x = displacement_from_force(system.plant, system.hysteresis, t, u,
    ...                             initial=(0.03, [0.6]))
    >>> p, xb, s = link_state_from_window(system, t, u, x + 1e-3)
    >>> round(p * 1e3, 6), round(xb * 1e3, 4), round(float(s[0]), 6)
    (1.0, 30.0, 0.6)
    """
    from motionhyst.time.quasi_static import displacement_from_force

    x = displacement_from_force(system.plant, system.hysteresis, t, u)
    position = float(np.mean(y[:window] - x[:window]))
    st = None if system.hysteresis is None else system.hysteresis.time_stepping()
    if st is None or st.codes.size != 1:
        return position, 0.0, None
    yw, tw, uw = y[:window], t[:window], u[:window]
    scale = max(float(np.ptp(yw)), 1e-12 * max(1.0, abs(float(yw[0]))), 1e-15)

    def res(p):
        with np.errstate(all="ignore"):
            try:
                xw = displacement_from_force(system.plant, system.hysteresis, tw, uw,
                                             initial=(p[1], p[2:]))
            except ValueError:  # a state whose force the link does not hold
                return np.full(window, 1e6)
            r = (xw + p[0] - yw) / scale
        return np.where(np.isfinite(r), r, 1e6)

    start = [position, float(yw[0]) - position - float(yw[1] - yw[0]),
             *np.asarray(st.state0, dtype=float)]
    sol = least_squares(res, start, x_scale="jac")
    if not sol.cost < 0.5 * float(res(start) @ res(start)):  # no better than relaxed
        return position, 0.0, None
    return float(sol.x[0]), float(sol.x[1]), np.asarray(sol.x[2:], dtype=float)


def _quasi_static_from_window(system: OpenLoop, tt, u, y, window: int) -> WindowPrediction:
    """:func:`predict_from_window` for a model without inertia (its link's state set from
    the window: :func:`link_state_from_window`)."""
    from motionhyst.time.quasi_static import displacement_from_force

    u = u + float(getattr(system.plant, "force_drift", 0.0)) * tt  # as OpenLoop.simulate
    position, x_before, states = link_state_from_window(system, tt, u, y, window)
    if start_load(u, system.plant.force_offset) is None:  # starts at rest: relaxed
        x = displacement_from_force(system.plant, system.hysteresis, tt, u)
        position = float(np.mean(y[:window] - x[:window]))
        return _scored(tt, x + position, y, window, position, 0.0)
    initial = None if states is None else (x_before, states)
    x = displacement_from_force(system.plant, system.hysteresis, tt, u, initial=initial)
    pred = _scored(tt, x + position, y, window, position, 0.0)
    if states is not None:
        pred.initial_state["link_state"] = [float(v) for v in states]
    return pred


def window_noise_floor(mech, stepping: Stepping, k_link: float, u, fs: float, r: int,
                       position: float, velocity: float, y, window: int, noise: float
                       ) -> float:
    """The RMS error after the first `window` samples that white noise of `noise` [m] on the
    measured positions gives the true model, its state set from those samples.

    The state is the least squares of the run over the window (:func:`state_from_window`):
    its error is ``B e_w``, ``B = (S_w^T S_w)^-1 S_w^T`` with ``S`` the run's sensitivity to
    the state, and it moves sample ``n`` by ``S_n B e_w``; with the noise of the sample
    itself, ``sqrt(noise^2 (1 + mean_n ||S_n B||^2))``.  On a floating stage a velocity
    error integrates into the position while the stage slides: 20 samples at 1 kHz leave a
    positioning axis some 15 times its noise, 200 samples 1.1 times.

    Parameters
    ----------
    mech, stepping, k_link, u, fs, r, position, velocity
        As for :func:`run_from_state` (the state the window set).
    y : ndarray
        The run from that state (:func:`run_from_state`'s position).
    window : int
        Samples that set the state.
    noise : float
        The positions' noise [m].

    Returns
    -------
    float
        [m].

    Examples
    --------
    A free mass (no force) whose position and velocity are set from 20 samples: a straight
    line fitted to them, carried on over 200.

    >>> from motionhyst.time.openloop import MassSpringDamper
    >>> mech = MassSpringDamper(1.0, 0.0, 0.0).mechanics()
    >>> y, _ = run_from_state(mech, Stepping.empty(), 0.0, np.zeros(200), 1000.0, 2, 0.0, 0.0)
    >>> floor = window_noise_floor(mech, Stepping.empty(), 0.0, np.zeros(200), 1000.0, 2,
    ...                            0.0, 0.0, y, 20, 1e-6)
    >>> round(floor * 1e6, 2)     # um: sqrt(1 + 1/20 + mean (n - 9.5)^2 / 665) of 1 um
    4.49
    """
    scale = max(float(np.ptp(y)), 1e-12 * max(1.0, abs(position)), 1e-15)
    cols = []
    for dp, dv in ((1.0, 0.0), (0.0, 1.0)):
        if dp and mech.floating:
            cols.append(np.ones_like(y))
            continue
        step = 1e-4 * (dp * max(abs(position), scale) + dv * max(abs(velocity),
                                                                scale * fs / window))
        y2, _ = run_from_state(mech, stepping, k_link, u, fs, r, position + dp * step,
                               velocity + dv * step)
        cols.append((y2 - y) / step)
    S = np.column_stack(cols)
    G = S[window:] @ np.linalg.pinv(S[:window])
    return float(noise * math.sqrt(1.0 + float(np.mean(np.sum(G * G, axis=1)))))


def _scored(tt, yhat, y, window, position, velocity) -> WindowPrediction:
    """The prediction with its error after the first `window` samples."""
    if not np.all(np.isfinite(yhat)):
        raise ValueError("the model's prediction is not finite")
    e = yhat[window:] - y[window:]
    ref = y[window:] - np.mean(y[window:])
    rmse = float(np.sqrt(np.mean(e ** 2)))
    denom = float(np.linalg.norm(ref))
    fit = 100.0 * (1.0 - float(np.linalg.norm(e)) / denom) if denom > 0 else -math.inf
    return WindowPrediction(tt, yhat, int(window), {"position": position, "velocity": velocity},
                            rmse, fit)
