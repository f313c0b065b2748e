"""Closed-loop records: the link force inferred through a proper prefilter ``L``
(``L w = L u - (L / P1) y1``, paper eq. 1) and the Maxwell-slip fit in that domain."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter

from motionhyst.core.lti import TWO_PI, HoldFilter, tf_poly
from motionhyst.core.sampling import HeldInputFilter
from motionhyst.core.warnings import warn
from motionhyst.identify._inferred_force_checks import check_link, likely_cause
from motionhyst.identify.fit import (
    EXTRA_ORDER,
    MAX_ELEMENTS,
    Criterion,
    FitProblem,
    fit_rows,
    identify_prepared,
    residuals_and_jacobian,
)
from motionhyst.identify.io_uncertainty import covariance, covariance_table, standard_errors
from motionhyst.identify.link_checks import check_not_held
from motionhyst.identify.records import DECIMATED_RATE as DECIMATED_RATE
from motionhyst.identify.records import (
    MAX_ROWS,
    UNIFORM_RTOL,
    check_controller_period,
    check_signals,
    fit_every,
    prefilter_cutoff,
)
from motionhyst.identify.residual_noise import (
    ResidualCorrelation,
    lower_bound_note,
    white_noise_variance,
)
from motionhyst.identify.result import Identification
from motionhyst.plants.registry import Plant

__all__ = ["LinkForce", "identify_closed_loop", "infer_link_force"]


def _p1_poly(stage) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Coefficients of ``P1`` of a stage (or of an LTI ``P1`` itself), leading zeros dropped."""
    try:
        num, den = tf_poly(stage.P1 if isinstance(stage, Plant) else stage, "P1")
    except (TypeError, ValueError):
        raise TypeError("closed-loop identification needs an LTI model of P1 (a plant of "
                        "motionhyst.plants with transfer functions, or a python-control "
                        f"system), got {type(stage).__name__}") from None
    return np.trim_zeros(num, "f"), np.trim_zeros(den, "f")


@dataclass
class LinkForce:
    """Link force inferred from a closed-loop record, in the prefiltered domain.

    Attributes
    ----------
    t, y1 : ndarray
        Time [s] and position of the actuated mass [m].
    w : ndarray
        ``L w = L u - (L / P1) y1`` [N]: the link force through the prefilter ``L``.
    lowpass : HoldFilter
        The prefilter ``L``; apply it to a model's force to compare with `w`.
    cutoff_hz : float
        Cut-off of the Butterworth part of ``L`` [Hz].
    settle_index : int
        First sample after the prefilter's start-up transient.

    Examples
    --------
    >>> from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate
    >>> from motionhyst.identify import infer_link_force
    >>> sc = default_scenario()
    >>> loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    >>> sim = simulate(loop, SineReference(0.01, 2.0), 1.5, dt=2e-4)
    >>> lf = infer_link_force(sim.t, sim.y1, sim.u, sc.plant())
    >>> print(f"cut-off {lf.cutoff_hz:.1f} Hz, settled after {lf.t[lf.settle_index]:.3f} s")
    cut-off 46.7 Hz, settled after 0.214 s
    """

    t: NDArray[np.float64]
    y1: NDArray[np.float64]
    w: NDArray[np.float64]
    lowpass: HoldFilter
    cutoff_hz: float
    settle_index: int


def infer_link_force(t: ArrayLike, y1: ArrayLike, u: ArrayLike, stage,
                     cutoff_hz: float | None = None, controller=None) -> LinkForce:
    """Infer the link force ``w = u - P1^-1 y1`` from a closed-loop record (paper eq. 1).

    ``P1^-1`` is improper (for the two-mass stage ``s^2 (m1 m2 s^2 + b M s +
    k M) / (m2 s^2 + b s + k)``), so both sides are filtered with the same
    proper filter

    ``L(s) = B(s) n1(s) / n1(0)``,  hence ``L / P1 = B(s) d1(s) / n1(0)``,

    where ``P1 = n1 / d1`` and ``B`` is a Butterworth low-pass of order
    ``deg d1 + 2`` (unit DC gain).  ``L`` contains ``P1``'s zeros, so the
    inverse has no poles from them (for the stage: no lightly damped
    anti-resonance that would ring); both filters have only ``B``'s
    well-damped poles.  The two extra orders make ``L / P1`` roll off above
    the cut-off.  Both filters are discretised with a first-order hold, i.e.
    applied exactly to the linear interpolation of the samples: at low
    frequencies the interpolation error is then common to ``u`` and ``y1``
    and cancels up to ``O(dt^2)`` times ``w`` itself, not times the much
    larger ``u`` (rigid-body forces); the interpolation's images near the
    sampling rate are suppressed by the roll-off.  Keep the cut-off well
    below the sampling rate (the image error grows like ``(cutoff * dt)^2``
    relative to the rigid-body force).  The result is ``L w`` (not ``w``):
    identify in that domain with :func:`identify_closed_loop`, which filters
    the model in the same way.

    Parameters
    ----------
    t : array_like
        Uniformly sampled time [s].
    y1 : array_like
        Position of the actuated mass (where the link acts) [m].
    u : array_like
        Actuator force (feedback plus feedforward) [N].
    stage : TwoMassStage or python-control LTI system
        The stage (its ``P1``) or ``P1 = y1 / (u - w)`` itself.
    cutoff_hz : float, optional
        Cut-off of ``B`` [Hz].  Default: 20 times the record's fundamental
        frequency (estimated from the number of reversals of `y1`), at most a
        twentieth of the sampling rate.
    controller : SampledController, optional
        The known discrete controller that produced `u`, the record taken at its
        samples: ``u_k`` acted on the stage held from ``t_k + d T`` on, so ``L u``
        is the exact response of ``L`` to that staircase
        (:class:`~motionhyst.core.sampling.HeldInputFilter`) instead of to the
        samples' linear interpolation.

    Returns
    -------
    LinkForce

    Examples
    --------
    A closed-loop record of the Table I stage with a two-element link, simulated; the link
    force inferred from ``y1`` and ``u`` matches the simulated one through the prefilter:

    >>> import numpy as np
    >>> from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate
    >>> from motionhyst.identify import infer_link_force
    >>> sc = default_scenario()
    >>> stage = sc.plant()
    >>> loop = Loop(stage, sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    >>> sim = simulate(loop, SineReference(0.01, 2.0), 1.5, dt=2e-4)
    >>> lf = infer_link_force(sim.t, sim.y1, sim.u, stage)
    >>> i = lf.settle_index
    >>> error = np.abs(lf.w[i:] - lf.lowpass(sim.w)[i:]).max()
    >>> bool(error < 5e-3 * np.abs(sim.w).max())             # measured: 0.1 % of the force
    True
    """
    return _infer(t, y1, u, stage, cutoff_hz, controller)[0]


def _infer(t: ArrayLike, y1: ArrayLike, u: ArrayLike, stage, cutoff_hz: float | None,
           controller) -> tuple[LinkForce, HoldFilter]:
    """:func:`infer_link_force`, and its filter ``L / P1``."""
    ts = np.asarray(t, dtype=float)
    ys = np.ascontiguousarray(np.asarray(y1, dtype=float))
    us = np.asarray(u, dtype=float)
    check_signals(ys, {"u": us}, ts, xname="y1")
    dts = np.diff(ts)
    dt = float(np.median(dts))
    if np.max(np.abs(dts - dt)) > UNIFORM_RTOL * dt:
        raise ValueError("closed-loop records must be uniformly sampled; resample first")
    num, den = _p1_poly(stage)
    if num.size > den.size:
        raise ValueError("P1 must be proper")
    if num[-1] == 0:
        raise ValueError("P1 must not have a zero at s = 0")
    cutoff_hz, settle = prefilter_cutoff(ts, ys, cutoff_hz)  # known before the filters run
    wl = TWO_PI * cutoff_hz
    order = den.size - 1 + EXTRA_ORDER
    zb, pb, kb = butter(order, wl, analog=True, output="zpk")
    n0 = float(num[-1])
    L = HoldFilter(np.concatenate([zb, np.roots(num)]), pb, kb * num[0] / n0, dt, wl)
    L_over_P1 = HoldFilter(np.concatenate([zb, np.roots(den)]), pb, kb * den[0] / n0, dt, wl)
    # y1 enters through s^k factors: removing its first value keeps the filter well scaled
    if controller is not None:
        check_controller_period(ts, controller.period)
        held = HeldInputFilter(np.concatenate([zb, np.roots(num)]), pb, kb * num[0] / n0,
                               controller.period, controller.delay_samples, wl)
        Lu = held(us)
    else:
        Lu = L(us)
    w_f = Lu - L_over_P1(ys - ys[0])
    lf = LinkForce(t=ts, y1=ys, w=w_f, lowpass=L, cutoff_hz=cutoff_hz, settle_index=settle)
    return lf, L_over_P1


def identify_closed_loop(t: ArrayLike, y1: ArrayLike, u: ArrayLike, stage,
                         n_elements: int | None = None, *, cutoff_hz: float | None = None,
                         criterion: Criterion = "rms", rtol: float = 0.01, atol: float = 1e-3,
                         initial_state: Literal["fit", "relaxed"] = "fit",
                         max_elements: int = MAX_ELEMENTS, max_rows: int = MAX_ROWS,
                         controller=None, offset: str = "auto") -> Identification:
    """Identify Maxwell-slip parameters from a closed-loop record ``(t, y1, u)`` of a stage.

    The link force is inferred with :func:`infer_link_force` as ``L w``; the
    model is fitted in the same domain, ``L[phi(y1)] + c`` against ``L w``
    after the prefilter's start-up transient, so the prefilter's smoothing
    and phase lag cause no bias.  Fit quality (``fit_rms`` etc.) refers to
    the prefiltered force.

    Parameters
    ----------
    t, y1, u, stage, cutoff_hz, controller
        As :func:`infer_link_force` (`controller`: a known sampled controller that
        produced `u`, the record at its samples).
    n_elements, criterion, rtol, atol, initial_state, max_elements, max_rows
        As :func:`identify_maxwell_slip`.
    offset : {"auto", "input", "none"}
        The force offset, as the input-output route's ``input_offset``
        (:func:`~motionhyst.identify.input_output.identify_io`): the stage
        receives ``u - offset``, so the inferred link force carries it; estimated
        with its standard error (``auto``, ``input``: the default) or fixed at 0
        (``none``).  A position offset of ``y1`` does not enter ``L / P1`` of a
        floating stage and is a constant force ``k y0`` (the same as a force
        offset) on a spring: ``output`` and ``both`` are refused.

    Returns
    -------
    Identification

    Raises
    ------
    ValueError
        Before the fit, for a record whose inferred link force is no link's: one that
        creates energy over the record's whole cycles beyond its noise and what a link could
        have stored, a spring's and a damper's (loops that widen with the speed), or one
        that grows with the speed (it falls back along the strokes); naming, where one
        makes the record a link's, u's sign reversed or a time offset of the columns.  Without
        `controller`, a record whose u is held over several rows (a sampled controller's
        force logged faster than it updates: :func:`~motionhyst.identify.link_checks.held_rows`).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate
    >>> from motionhyst.identify import identify_closed_loop
    >>> sc = default_scenario()
    >>> loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    >>> sim = simulate(loop, SineReference(0.01, 2.0), 1.5, dt=2e-4)   # the "measurement"
    >>> ident = identify_closed_loop(sim.t, sim.y1, sim.u, sc.plant())
    >>> print(np.round(ident.model.k, 2), np.round(ident.model.fc, 4), ident.signal)
    [10.  6.] [0.01 0.03] prefiltered force
    """
    if offset in ("output", "both"):
        raise ValueError("a closed-loop record's position offset is not estimated: it does not "
                         "enter the link force inferred through a floating stage and is a "
                         "force offset on a spring; use offset 'auto', 'input' or 'none'")
    if offset not in ("auto", "input", "none"):
        raise ValueError(f"unknown offset choice {offset!r}; expected auto, input or none")
    if initial_state not in ("fit", "relaxed"):
        raise ValueError(f"unknown initial_state {initial_state!r}; use 'fit' or 'relaxed'")
    if controller is None:  # a sampled controller's staircase, read as ramps: no link's force
        check_not_held(np.asarray(t, dtype=float), np.asarray(u, dtype=float),
                       "the SampledController (controller=)")
    lf, L_over_P1 = _infer(t, y1, u, stage, cutoff_hz, controller)
    us = np.asarray(u, dtype=float)
    try:
        check_link(lf, L_over_P1, us)  # before the fit's work
    except ValueError:
        cause = likely_cause(lf, us, lambda *tyu: _infer(*tyu, stage, cutoff_hz, controller))
        if not cause:
            raise
        check_link(lf, L_over_P1, us, cause)
    # L w is band-limited: fit on every q-th sample (the model's prefilter re-discretised)
    dt = lf.lowpass.dt
    q = fit_every(dt, lf.cutoff_hz)
    sel = np.arange(0, lf.y1.size, q)
    start = int(np.searchsorted(sel, lf.settle_index))
    prob = FitProblem(x=np.ascontiguousarray(lf.y1[sel]), target=lf.w[sel],
                      rows=fit_rows(start, sel.size, max_rows), filt=lf.lowpass.with_step(q * dt),
                      fit_initial=initial_state == "fit", fit_offset=offset != "none")
    ident = identify_prepared(prob, n_elements, criterion, rtol, atol, max_elements,
                              "prefiltered force", cutoff_hz=lf.cutoff_hz)
    return _correlated_std(ident, prob, _noise_rms(lf, L_over_P1, np.asarray(u, dtype=float)))


def _noise_rms(lf: LinkForce, L_over_P1: HoldFilter, u: NDArray[np.float64]) -> float:
    """The RMS of what the white noise of ``u`` and ``y1`` (their third differences' median
    absolute deviation: the noise, not the controller's fast action, which the passivity
    check's mean square counts as an upper estimate; a flag of lower bounds must not take
    model error for noise) leaves in the prefiltered link force ``L u - (L / P1) y1`` (the
    filters' impulse responses' norms, of an impulse in the record's middle: the filters start
    in steady state on the first sample, so an impulse there is a step that was on before the
    record, and its response 40 times the noise's on Table I's loop)."""
    delta = np.zeros(lf.y1.size)
    delta[lf.y1.size // 2] = 1.0
    h_u, h_y = lf.lowpass(delta), L_over_P1(delta)
    return float(np.sqrt(white_noise_variance(u) * float(h_u @ h_u)
                         + white_noise_variance(lf.y1) * float(h_y @ h_y)))


def _correlated_std(ident: Identification, prob: FitProblem, noise_rms: float
                    ) -> Identification:
    """The standard errors of a closed-loop fit with its residuals' autocorrelation (the
    prefilter makes the noise of ``u`` and ``y1`` coloured:
    :class:`~motionhyst.identify.residual_noise.ResidualCorrelation`), and marked as lower
    bounds, with the line that says why, when the fit leaves more than the records' noise
    (:func:`~motionhyst.identify.residual_noise.lower_bound_note`); the fit's own (white
    residuals') standard errors kept as ``judged_std``, what judges a slip force determined;
    a value its widened standard error exceeds where the white one does not is warned
    (:meth:`~motionhyst.identify.result.Identification.widened_note`)."""
    n = ident.n_elements
    r, J = residuals_and_jacobian(prob, ident)
    rss, rows = float(r @ r), r.size
    corr = ResidualCorrelation([r])
    std, _ = standard_errors(J, rss, rows, 1e-9, correlation=corr)
    white, _ = standard_errors(J, rss, rows, 1e-9)
    idx = [*range(2 * n), J.shape[1] - 1]
    names = (["k", "fc"] if n == 1 else [f"{p}[{i}]" for p in ("k", "fc") for i in range(n)])
    names.append("offset")
    ident.judged_std = {f"{p}[{i}]": e[f"{p}_std"] for i, e in enumerate(ident.elements)
                        for p in ("k", "fc")}
    for i, e in enumerate(ident.elements):  # where the fit says not determined, it stays so
        for name, j in (("k_std", i), ("fc_std", n + i)):
            if math.isfinite(e[name]) and math.isfinite(std[j]):
                e[name] = float(std[j])
    if prob.fit_offset and math.isfinite(std[-1]):
        if math.isfinite(white[-1]):
            ident.judged_std["offset"] = float(white[-1])
        ident.offset_std = float(std[-1])
    sd = {nm: float(std[j]) if math.isfinite(std[j]) else None
          for nm, j in zip(names, idx, strict=True)}
    ident.covariance = covariance_table(
        names, covariance(J, rss, rows, 1e-9, correlation=corr)[np.ix_(idx, idx)], sd)
    with np.errstate(invalid="ignore", divide="ignore"):
        widened = float(np.nanmax(np.where(white > 0, std / white, np.nan), initial=1.0))
    note = lower_bound_note(math.sqrt(rss / rows), noise_rms, widened, corr.lags, "N",
                            float(np.sqrt(np.mean(prob.y ** 2))))
    ident.std_lower_bound = note
    widened_line = ident.widened_note()
    if widened_line is not None:  # determined on white residuals, not beyond the model's error
        warn(widened_line)
    return ident
