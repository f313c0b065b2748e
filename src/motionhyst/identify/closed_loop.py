"""Closed-loop records: the link force inferred through a proper prefilter ``L``
(``L w = L u - (L / P1) y1``, paper eq. 1) and the Maxwell-slip fit in that domain."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter

from motionhyst.core.lti import TWO_PI, HoldFilter, tf_poly
from motionhyst.core.sampling import HeldInputFilter
from motionhyst.identify.fit import (
    EXTRA_ORDER,
    MAX_ELEMENTS,
    Criterion,
    FitProblem,
    fit_rows,
    identify_prepared,
)
from motionhyst.identify.io_uncertainty import white_noise_variance
from motionhyst.identify.records import (
    MAX_ROWS,
    REVERSAL_BAND,
    UNIFORM_RTOL,
    check_controller_period,
    check_signals,
    prefilter_cutoff,
)
from motionhyst.identify.result import Identification
from motionhyst.plants.registry import Plant

__all__ = ["LinkForce", "identify_closed_loop", "infer_link_force"]

DECIMATED_RATE = 40.0
"""Closed-loop fits run at no less than this multiple of the prefilter cut-off [-]."""


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


PASSIVE_SIGMAS = 5.0
"""A closed-loop record's inferred link force creates energy, and is refused, when its work
over the record's whole cycles is below zero by more than this many times its noise spread,
beyond the energy a link's elements could have released (:func:`_check_passive`)."""


def _whole_cycles(z: NDArray[np.float64], start: int) -> tuple[int, int, int]:
    """The first and last rise of `z` (from `start` on) through the middle of its range, each
    after a fall below it by a tenth of the range, and the whole cycles between them."""
    zs = z[start:]
    mid, band = 0.5 * (float(np.min(zs)) + float(np.max(zs))), 0.1 * float(np.ptp(zs))
    rises = start + 1 + np.flatnonzero((zs[:-1] < mid) & (zs[1:] >= mid))
    below = start + np.flatnonzero(zs < mid - band)
    kept, last = [], -1
    for i in rises:  # a rise counts once z fell below the band since the last one
        j = int(np.searchsorted(below, last + 1))
        if j < below.size and below[j] < i:
            kept.append(int(i))
            last = int(i)
    if len(kept) < 2:
        return 0, 0, 0
    return kept[0], kept[-1], len(kept) - 1


def _check_not_a_damper(lf: LinkForce, cause: str = "") -> None:
    """Refuse a closed-loop record whose inferred link force is a spring's and a damper's.

    The test of :func:`~motionhyst.identify.records.check_loops_open` in the prefiltered
    domain (``L (k y1 + c dy1/dt) = k L y1 + c d(L y1)/dt``): after the prefilter settles,
    a spring and a damper on ``L y1`` leaving less than
    :data:`~motionhyst.identify.records.ELASTIC_CURVE_RATIO` of a straight line's systematic
    error, and less than what a fit may leave, describe loops that widen with the speed,
    which elements that slip do not (they leave a damper at least a fifth of the line's).
    Noise, which the prefilter makes smooth, is left by both alike and refuses nothing.
    `cause`, where given, names what makes the record a link's."""
    from motionhyst.identify.io_checks import SYSTEMATIC_SHARE, systematic_share
    from motionhyst.identify.records import DAMPER_LINE_SHARE, ELASTIC_CURVE_RATIO

    i = lf.settle_index
    z = lf.lowpass(lf.y1 - lf.y1[0])[i:]
    w = lf.w[i:]
    v = np.gradient(z, lf.t[i:])
    if z.size < 3 or not (np.ptp(z) > 0 and np.max(np.abs(v)) > 0):
        return
    shares = []
    for basis in (np.column_stack([np.ones_like(z), z - z[0]]),
                  np.column_stack([np.ones_like(z), z - z[0], v / float(np.max(np.abs(v)))])):
        shares.append(systematic_share(w - basis @ np.linalg.lstsq(basis, w, rcond=None)[0], w))
    line, damper = shares
    if line > DAMPER_LINE_SHARE * SYSTEMATIC_SHARE and \
            damper < min(ELASTIC_CURVE_RATIO * line, SYSTEMATIC_SHARE):
        cause = cause or ("u and y1 sampled at different instants? the plant's damping not the "
                          "record's?")
        raise ValueError(f"no hysteresis in the record: the link force inferred through the "
                         f"plant is a spring's and a damper's (they leave "
                         f"{round(100 * damper, 2):.2g} % of its RMS, a straight line "
                         f"{100 * line:.2g} %): its loops widen with the speed, while a "
                         f"slipping element's follow the path alone ({cause}); nothing "
                         f"identified")


def _noise_variances(lf: LinkForce, u: NDArray[np.float64], a: int, b: int
                     ) -> tuple[float, float]:
    """The white noise variances of `u` and ``y1`` over the samples `a` to `b` judged: the
    mean square of their third differences
    (:func:`~motionhyst.identify.io_uncertainty.white_noise_variance`, an upper estimate
    that counts the controller's fast action as noise), not over the whole record: a record
    from rest starts with the loop's transient, whose differences are no noise (the paper's
    loop at 5 Hz from rest: 1.2 N on u over the record, 1e-6 N over its cycles)."""
    return (white_noise_variance(u[a:b + 1], robust=False),
            white_noise_variance(lf.y1[a:b + 1], robust=False))


def _check_passive(lf: LinkForce, L_over_P1: HoldFilter, u: NDArray[np.float64],
                   cause: str = "") -> None:
    """Refuse a closed-loop record whose inferred link force provably creates energy.

    A link (any passive element between the stage and the world) dissipates: over whole
    cycles of its position the work of its force on it is at least minus the energy its
    elements had stored.  The work of the prefiltered force ``L w`` along ``L y1`` over the
    whole cycles after the prefilter settles (from the first to the last rise through the
    middle of the range), the line of ``L w`` in ``L y1`` taken out (a spring and an offset
    do no work over whole cycles), is compared with its noise spread (the white noise of
    ``u`` and ``y1`` over those cycles, :func:`_noise_variances`, carried through ``L`` and
    ``L / P1`` exactly) and with what a link could release: its elements' stored energy, at
    most a quarter of the force's spread about the line times half the range of ``L y1``.
    Below zero by :data:`PASSIVE_SIGMAS` spreads plus that energy, the record is refused:
    noise alone, or a link's own nonlinearity, does not cross it.  `cause`, where given,
    names what makes the record a link's (:func:`_likely_cause`)."""
    z = lf.lowpass(lf.y1 - lf.y1[0])
    a, b, cycles = _whole_cycles(z, lf.settle_index)
    if cycles < 1:
        return  # no whole cycle: nothing to judge
    zz, ww = z[a:b + 1], lf.w[a:b + 1]
    basis = np.column_stack([np.ones_like(zz), zz - zz[0]])
    r = ww - basis @ np.linalg.lstsq(basis, ww, rcond=None)[0]
    rbar, dz = 0.5 * (r[1:] + r[:-1]), np.diff(zz)
    work = float(rbar @ dz)
    # the work's first-order response to the force (ga) and to L y1 (gb) at each sample
    ga, gb = np.zeros(z.size), np.zeros(z.size)
    ga[a:b] += 0.5 * dz
    ga[a + 1:b + 1] += 0.5 * dz
    gb[a:b] -= rbar
    gb[a + 1:b + 1] += rbar
    L = lf.lowpass

    def transposed(f, x):  # sum_j x_j (f v)_j = sum_i v_i (transposed(f, x))_i
        return f(x[::-1])[::-1]

    on_u = transposed(L, ga)
    on_y1 = transposed(L, gb) - transposed(L_over_P1, ga)
    var_u, var_y1 = _noise_variances(lf, u, a, b)
    spread = float(np.sqrt(var_u * (on_u @ on_u) + var_y1 * (on_y1 @ on_y1)))
    stored = 0.125 * float(np.ptp(r)) * float(np.ptp(zz))
    if work + PASSIVE_SIGMAS * spread + stored < 0:
        cause = cause or "u or y1 of the wrong sign? the plant not the record's?"
        raise ValueError(
            f"the link force inferred through the plant creates energy: over the record's "
            f"{cycles} whole cycle(s) of y1 (t = {lf.t[a]:.4g} to {lf.t[b]:.4g} s, "
            f"prefiltered) its work on the stage is {work:.3g} J, below zero by more than "
            f"{PASSIVE_SIGMAS:g} times its noise spread ({spread:.2g} J) and the energy a "
            f"link could have stored ({stored:.2g} J), while a link dissipates: not a link's "
            f"force ({cause}); nothing identified")


FALL_SHARE = 0.5
"""A closed-loop record's inferred link force is refused as growing with the speed when from
the fastest tenth of a stroke of ``L y1`` to its last tenth (the median over the record's
strokes) it falls by more than this share of its swing (:func:`_check_rate_independent`):
slipping elements' forces do not fall along the motion (measured on Jenkins, Maxwell-slip,
Bouc-Wen, Dahl and LuGre links in the paper's loop, 1-20 Hz, sampled controllers: -0.18 to
+0.21), a damper's falls to its spring's as the stroke slows to its end (a sample's offset
of the columns at 5-20 Hz: 0.68-0.83)."""

FALL_SIGMAS = 8.0
"""... and by more than this many times its standard error (from the falls' scatter over
the strokes: noise, and strokes unlike each other, widen it)."""

MIN_STROKES = 4
"""Fewest strokes (ending in a turn, after the prefilter settles) on which a closed-loop
record's force is judged for a fall along the motion (:func:`_check_rate_independent`)."""


def _strokes(z: NDArray[np.float64], start: int) -> list[tuple[int, int]]:
    """The strokes of `z` from `start` on that end in a turn: its pieces from `start` or a
    turn to the next turn, a turn where `z` retreats from its running extreme by more than
    :data:`REVERSAL_BAND` of its range (the first piece may be partial)."""
    zs = z[start:]
    band = REVERSAL_BAND * float(np.ptp(zs))
    d = np.diff(zs)
    # only local extrema can be turns: the walk below visits them alone
    ext = np.flatnonzero((d[:-1] > 0) & (d[1:] <= 0) | (d[:-1] < 0) & (d[1:] >= 0)) + 1
    turns, direction, hi, lo = [0], 0, 0, 0
    for i in [*ext.tolist(), zs.size - 1]:
        if direction == 0:  # the first move beyond the band sets the direction
            hi, lo = (i if zs[i] > zs[hi] else hi), (i if zs[i] < zs[lo] else lo)
            if zs[hi] - zs[lo] > band:
                direction = 1 if hi > lo else -1
        elif direction == 1:
            if zs[i] >= zs[hi]:
                hi = i
            elif zs[hi] - zs[i] > band:
                turns.append(hi)
                direction, lo = -1, i
        else:
            if zs[i] <= zs[lo]:
                lo = i
            elif zs[i] - zs[lo] > band:
                turns.append(lo)
                direction, hi = 1, i
    return [(start + p, start + q) for p, q in itertools.pairwise(turns) if q > p + 2]


def _check_rate_independent(lf: LinkForce, cause: str = "") -> None:
    """Refuse a closed-loop record whose inferred link force grows with the speed.

    The force of slipping elements (Maxwell-slip, and any rate-independent link) moves with
    the motion: along a stroke of the position it rises (or, going back, falls) and does not
    turn back before the stroke does.  A damper's force turns back within each stroke, from
    its largest where the stroke is fastest to its spring's as the stroke slows to its end;
    so does the force inferred from a record whose ``u`` and ``y1`` were logged a sample
    apart (the plant's inertia times the motion's jerk times the offset: at 5 Hz and 10 kHz
    a damper of ``M w^2 dt``, 2.2 N s/m for the paper's 22.5 kg, 14 times its link's slip
    force).  Where the prefiltered force falls from the fastest tenth of a stroke of ``L
    y1`` to its last tenth (the median over the strokes that end in a turn, after the
    prefilter settles; at least :data:`MIN_STROKES`) by more than :data:`FALL_SHARE` of its
    swing and :data:`FALL_SIGMAS` times the median's standard error (``1.25 s / sqrt(n)``
    of the falls' scatter ``s`` over the ``n`` strokes), the record is refused: Maxwell-slip
    elements fitted to it model the damper with stiff elements (k 3.5e7 N/m), an answer from
    nothing.  `cause`, where given, names what makes the record a link's."""
    z = lf.lowpass(lf.y1 - lf.y1[0])
    strokes = _strokes(z, lf.settle_index)
    if len(strokes) < MIN_STROKES:
        return
    falls, swings = [], []
    for p, q in strokes:
        f = np.sign(z[q] - z[p]) * lf.w[p:q + 1]
        tenth = max(1, f.size // 10)
        fastest = np.argsort(np.abs(np.gradient(z[p:q + 1])))[-tenth:]
        falls.append(float(np.mean(f[fastest])) - float(np.mean(f[-tenth:])))
        swings.append(float(np.ptp(f)))
    fall, swing = float(np.median(falls)), float(np.median(swings))
    error = 1.2533 * float(np.std(falls, ddof=1)) / np.sqrt(len(falls))
    if fall > FALL_SHARE * swing and fall > FALL_SIGMAS * error:
        cause = cause or "u and y1 logged at different instants? the plant not the record's?"
        raise ValueError(
            f"the link force inferred through the plant grows with the speed: along a stroke "
            f"of y1 it falls {fall:.3g} N from where the stroke is fastest to its end, "
            f"{100 * fall / swing:.0f} % of its swing (the median of {len(strokes)} strokes, "
            f"prefiltered, +- {error:.2g} N), as a damper's does, while slipping "
            f"elements' force follows the stroke to its end ({cause}); nothing identified")


MAX_LOG_SHIFT = 3
"""The samples by which a closed-loop record's u and y1 columns are shifted against each other
(either way) to find a time offset between them, once the record is refused as no link's
(:func:`_likely_cause`): a logging offset of one sample makes a link's record do -0.061 J of
work, 20 times its dissipation, or (the other way) a damper 14 times its slip force."""


def _check_link(lf: LinkForce, L_over_P1: HoldFilter, u: NDArray[np.float64],
                cause: str = "") -> None:
    """The checks that a closed-loop record's inferred force is a link's, before the fit:
    it does not create energy (:func:`_check_passive`), is not a spring's and a damper's
    (:func:`_check_not_a_damper`) and does not grow with the speed
    (:func:`_check_rate_independent`); `cause` names what makes the record a link's."""
    _check_passive(lf, L_over_P1, u, cause)
    _check_not_a_damper(lf, cause)
    _check_rate_independent(lf, cause)


def _force_rms(lf: LinkForce) -> float:
    """The RMS of a record's prefiltered link force about its mean, after the prefilter
    settles: what of ``u`` the plant does not explain."""
    w = lf.w[lf.settle_index:]
    return float(np.sqrt(np.mean((w - w.mean()) ** 2)))


def _likely_cause(lf: LinkForce, u: NDArray[np.float64], stage, cutoff_hz: float | None,
                  controller) -> str:
    """For a record refused by :func:`_check_link`, the words naming a slip that makes it a
    link's, or ``""``.  The slips tried: u's sign reversed (or y1's: the same record seen
    from the other side), and its u column shifted against y1 by up to
    :data:`MAX_LOG_SHIFT` samples either way.  Of those after which the record passes the
    checks, the one whose inferred force is least (the plant explains most of u) is named,
    if it is less than the record's own: a column negated leaves twice the plant's force
    (a spring of ``2 M w^2`` on a sine), a shift a damper (``M w^2 dt`` a sample), and each
    slip undone on the other's record passes the checks too (the spring, or the damper,
    dissipating), with the larger force.  The words ask, they do not assert."""
    t, y1 = lf.t, lf.y1
    found, least = "", _force_rms(lf)
    candidates = [("negated", t, y1, -u)]
    for shift in range(1, MAX_LOG_SHIFT + 1):
        candidates += [((shift, True), t[:-shift], y1[shift:], u[:-shift]),
                       ((shift, False), t[:-shift], y1[:-shift], u[shift:])]
    for slip, ts, ys, us in candidates:  # u's row i beside y1's row i + shift, or the reverse
        other, L_over_P1 = _infer(ts, ys, us, stage, cutoff_hz, controller)
        try:
            _check_link(other, L_over_P1, us)
        except ValueError:
            continue
        if _force_rms(other) >= least:
            continue
        least = _force_rms(other)
        if slip == "negated":
            found = ("u or y1 of the wrong sign? with u negated the record is a link's: "
                     "--scale u=-1 reads it so")
        else:
            shift, later = slip
            pair = (f"u's row i beside y1's row i + {shift}" if later
                    else f"y1's row i beside u's row i + {shift}")
            found = (f"a time offset between the u and y1 columns? shifted by {shift} "
                     f"sample{'s' if shift > 1 else ''} ({pair}) the record is a link's")
    return found + "; or the plant not the record's?" if found else ""


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
        makes the record a link's, u's sign reversed or a time offset of the columns.

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
    lf, L_over_P1 = _infer(t, y1, u, stage, cutoff_hz, controller)
    us = np.asarray(u, dtype=float)
    try:
        _check_link(lf, L_over_P1, us)  # before the fit's work
    except ValueError:
        cause = _likely_cause(lf, us, stage, cutoff_hz, controller)
        if not cause:
            raise
        _check_link(lf, L_over_P1, us, cause)
    # L w is band-limited: fit on every q-th sample (the model's prefilter re-discretised)
    dt = lf.lowpass.dt
    q = max(1, int(1.0 / (dt * DECIMATED_RATE * lf.cutoff_hz)))
    sel = np.arange(0, lf.y1.size, q)
    start = int(np.searchsorted(sel, lf.settle_index))
    prob = FitProblem(x=np.ascontiguousarray(lf.y1[sel]), target=lf.w[sel],
                      rows=fit_rows(start, sel.size, max_rows), filt=lf.lowpass.with_step(q * dt),
                      fit_initial=initial_state == "fit", fit_offset=offset != "none")
    return identify_prepared(prob, n_elements, criterion, rtol, atol, max_elements,
                             "prefiltered force", cutoff_hz=lf.cutoff_hz)
