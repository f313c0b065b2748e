"""The checks that a closed-loop record's inferred link force is a link's, with numpy alone.

:func:`~motionhyst.identify.closed_loop.identify_closed_loop` runs them on the force it
infers through its prefilters before its fit; :func:`light_link_force` infers the same force
(its prefilters as finite impulse responses, equal to the first-order-hold filters to 1e-10
of the force) from the plant's lumped masses, so that a command refuses a record before the
loop's libraries load.  A record is judged by the prefiltered force ``lf.w`` and position
``lf.lowpass(y1 - y1[0])`` after the prefilter settles (``lf.settle_index``)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.records import REVERSAL_BAND
from motionhyst.identify.residual_noise import white_noise_variance

__all__ = ["FirFilter", "LightForce", "check_link", "force_rms", "light_link_force",
           "likely_cause"]


PASSIVE_SIGMAS = 5.0
"""A closed-loop record's inferred link force creates energy, and is refused, when its work
over the record's whole cycles is below zero by more than this many times its noise spread,
beyond the energy a link's elements could have released (:func:`check_passive`)."""


def whole_cycles(z: NDArray[np.float64], start: int) -> tuple[int, int, int]:
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


def check_not_a_damper(lf, cause: str = "") -> None:
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


def noise_variances(lf, u: NDArray[np.float64], a: int, b: int
                     ) -> tuple[float, float]:
    """The white noise variances of `u` and ``y1`` over the samples `a` to `b` judged: the
    mean square of their third differences
    (:func:`~motionhyst.identify.residual_noise.white_noise_variance`, an upper estimate
    that counts the controller's fast action as noise), not over the whole record: a record
    from rest starts with the loop's transient, whose differences are no noise (the paper's
    loop at 5 Hz from rest: 1.2 N on u over the record, 1e-6 N over its cycles)."""
    return (white_noise_variance(u[a:b + 1], robust=False),
            white_noise_variance(lf.y1[a:b + 1], robust=False))


def check_passive(lf, L_over_P1, u: NDArray[np.float64],
                   cause: str = "") -> None:
    """Refuse a closed-loop record whose inferred link force provably creates energy.

    A link (any passive element between the stage and the world) dissipates: over whole
    cycles of its position the work of its force on it is at least minus the energy its
    elements had stored.  The work of the prefiltered force ``L w`` along ``L y1`` over the
    whole cycles after the prefilter settles (from the first to the last rise through the
    middle of the range), the line of ``L w`` in ``L y1`` taken out (a spring and an offset
    do no work over whole cycles), is compared with its noise spread (the white noise of
    ``u`` and ``y1`` over those cycles, :func:`noise_variances`, carried through ``L`` and
    ``L / P1`` exactly) and with what a link could release: its elements' stored energy, at
    most a quarter of the force's spread about the line times half the range of ``L y1``.
    Below zero by :data:`PASSIVE_SIGMAS` spreads plus that energy, the record is refused:
    noise alone, or a link's own nonlinearity, does not cross it.  `cause`, where given,
    names what makes the record a link's (:func:`likely_cause`)."""
    z = lf.lowpass(lf.y1 - lf.y1[0])
    a, b, cycles = whole_cycles(z, lf.settle_index)
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
    var_u, var_y1 = noise_variances(lf, u, a, b)
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
strokes) it falls by more than this share of its swing (:func:`check_rate_independent`):
slipping elements' forces do not fall along the motion (measured on Jenkins, Maxwell-slip,
Bouc-Wen, Dahl and LuGre links in the paper's loop, 1-20 Hz, sampled controllers: -0.18 to
+0.21), a damper's falls to its spring's as the stroke slows to its end (a sample's offset
of the columns at 5-20 Hz: 0.68-0.83)."""

FALL_SIGMAS = 8.0
"""... and by more than this many times its standard error (from the falls' scatter over
the strokes: noise, and strokes unlike each other, widen it)."""

MIN_STROKES = 4
"""Fewest strokes (ending in a turn, after the prefilter settles) on which a closed-loop
record's force is judged for a fall along the motion (:func:`check_rate_independent`)."""


def strokes(z: NDArray[np.float64], start: int) -> list[tuple[int, int]]:
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


def check_rate_independent(lf, cause: str = "") -> None:
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
    pieces = strokes(z, lf.settle_index)
    if len(pieces) < MIN_STROKES:
        return
    falls, swings = [], []
    for p, q in pieces:
        f = np.sign(z[q] - z[p]) * lf.w[p:q + 1]
        tenth = max(1, f.size // 10)
        fastest = np.argsort(np.abs(np.gradient(z[p:q + 1])))[-tenth:]
        falls.append(float(np.mean(f[fastest])) - float(np.mean(f[-tenth:])))
        swings.append(float(np.ptp(f)))
    fall, swing = float(np.median(falls)), float(np.median(swings))
    error = 1.2533 * float(np.std(falls, ddof=1)) / np.sqrt(len(falls))
    if fall > FALL_SHARE * swing and fall > FALL_SIGMAS * error:
        cause = cause or ("a viscous force the plant's damping leaves out (the link's, or the "
                          "plant not the record's)? u and y1 logged at different instants?")
        raise ValueError(
            f"the link force inferred through the plant grows with the speed: along a stroke "
            f"of y1 it falls {fall:.3g} N from where the stroke is fastest to its end, "
            f"{100 * fall / swing:.0f} % of its swing (the median of {len(pieces)} strokes, "
            f"prefiltered, +- {error:.2g} N), as a damper's does, while slipping "
            f"elements' force follows the stroke to its end ({cause}); nothing identified")


MAX_LOG_SHIFT = 3
"""The samples by which a closed-loop record's u and y1 columns are shifted against each other
(either way) to find a time offset between them, once the record is refused as no link's
(:func:`likely_cause`): a logging offset of one sample makes a link's record do -0.061 J of
work, 20 times its dissipation, or (the other way) a damper 14 times its slip force."""


def check_link(lf, L_over_P1, u: NDArray[np.float64],
                cause: str = "") -> None:
    """The checks that a closed-loop record's inferred force is a link's, before the fit:
    it does not create energy (:func:`check_passive`), is not a spring's and a damper's
    (:func:`check_not_a_damper`) and does not grow with the speed
    (:func:`check_rate_independent`); `cause` names what makes the record a link's."""
    check_passive(lf, L_over_P1, u, cause)
    check_not_a_damper(lf, cause)
    check_rate_independent(lf, cause)


def force_rms(lf) -> float:
    """The RMS of a record's prefiltered link force about its mean, after the prefilter
    settles: what of ``u`` the plant does not explain."""
    w = lf.w[lf.settle_index:]
    return float(np.sqrt(np.mean((w - w.mean()) ** 2)))


def likely_cause(lf, u: NDArray[np.float64], infer) -> str:
    """For a record refused by :func:`check_link`, the words naming a slip that makes it a
    link's, or ``""``.  The slips tried: u's sign reversed (or y1's: the same record seen
    from the other side), and its u column shifted against y1 by up to
    :data:`MAX_LOG_SHIFT` samples either way.  Of those after which the record passes the
    checks, the one whose inferred force is least (the plant explains most of u) is named,
    if it is less than the record's own: a column negated leaves twice the plant's force
    (a spring of ``2 M w^2`` on a sine), a shift a damper (``M w^2 dt`` a sample), and each
    slip undone on the other's record passes the checks too (the spring, or the damper,
    dissipating), with the larger force.  The words ask, they do not assert.  `infer` is
    ``infer(t, y1, u) -> (lf, L_over_P1)``, the inference the record was judged by."""
    t, y1 = lf.t, lf.y1
    found, least = "", force_rms(lf)
    candidates = [("negated", t, y1, -u)]
    for shift in range(1, MAX_LOG_SHIFT + 1):
        candidates += [((shift, True), t[:-shift], y1[shift:], u[:-shift]),
                       ((shift, False), t[:-shift], y1[:-shift], u[shift:])]
    for slip, ts, ys, us in candidates:  # u's row i beside y1's row i + shift, or the reverse
        try:  # a copy the inference itself refuses names nothing
            other, L_over_P1 = infer(ts, ys, us)
            check_link(other, L_over_P1, us)
        except ValueError:
            continue
        if force_rms(other) >= least:
            continue
        least = force_rms(other)
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


def _det(Z: list[list[np.poly1d]]) -> np.poly1d:
    """The determinant of a small matrix of polynomials (Laplace expansion)."""
    if not Z:
        return np.poly1d([1.0])
    out = np.poly1d([0.0])
    for j in range(len(Z)):
        minor = [row[:j] + row[j + 1:] for row in Z[1:]]
        out = out + (-1) ** j * Z[0][j] * _det(minor)
    return out


class FirFilter:
    """A strictly proper filter ``gain q(s) / prod(s - p)`` applied to samples as the
    first-order hold does (the continuous filter on their linear interpolation, the signal
    constant at its first value before them), through its impulse response (sampled to where
    its slowest pole has decayed by e^-36) and an FFT convolution.

    Parameters
    ----------
    q : array_like
        Numerator coefficients (highest power first), of degree below ``len(poles) - 1``.
    poles : array_like
        Distinct poles [rad/s], conjugate pairs complete, in the left half-plane.
    gain : float
        Gain.
    dt : float
        Sampling interval [s].
    """

    def __init__(self, q, poles, gain: float, dt: float) -> None:
        p = np.asarray(poles, dtype=complex)
        r = gain * np.polyval(q, p) / np.array([np.prod(pk - np.delete(p, k))
                                                 for k, pk in enumerate(p)])
        n = int(np.ceil(36.0 / (float(np.min(-p.real)) * dt))) + 2
        pt = p * dt
        e = np.expm1(pt)
        head = np.sum(r * (e - pt) / (p ** 2 * dt)).real
        tail = (np.exp(np.outer(np.arange(n - 1), pt)) * (r * e ** 2 / (p ** 2 * dt))).sum(1)
        self.h = np.concatenate([[head], tail.real])

    def __call__(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The filtered samples of `x` (1-D)."""
        x = np.asarray(x, dtype=float)
        size = 1 << (x.size + self.h.size - 1).bit_length()
        y = np.fft.irfft(np.fft.rfft(self.h, size) * np.fft.rfft(x - x[0], size), size)
        return y[:x.size] + x[0] * float(np.sum(self.h))


@dataclass
class LightForce:
    """A closed-loop record's link force inferred by :func:`light_link_force` (the
    attributes of :class:`~motionhyst.identify.closed_loop.LinkForce` the checks read).

    Attributes
    ----------
    t, y1, w : ndarray
        Time [s], position of the actuated mass [m], the prefiltered link force [N].
    lowpass : FirFilter
        The prefilter ``L``.
    settle_index : int
        First sample after the prefilter's start-up transient.
    """

    t: NDArray[np.float64]
    y1: NDArray[np.float64]
    w: NDArray[np.float64]
    lowpass: FirFilter
    settle_index: int


def light_link_force(t: NDArray[np.float64], y1: NDArray[np.float64], u: NDArray[np.float64],
                     mechanics, cutoff_hz: float, settle: int, extra_order: int = 2
                     ) -> tuple[LightForce, FirFilter] | None:
    """``L w = L u - (L / P1) y1`` of a continuous loop's record, as
    :func:`~motionhyst.identify.closed_loop.infer_link_force` infers it (``L = B n1 /
    n1(0)``, ``B`` a Butterworth of order ``deg d1 + extra_order``, ``P1 = n1 / d1`` the
    force-to-position response of the plant's lumped masses at the link's coordinate), with
    numpy alone; and ``L / P1``.

    Parameters
    ----------
    t, y1, u : ndarray
        The record: uniform time [s], position [m], force [N].
    mechanics : Mechanics
        The plant's lumped masses.
    cutoff_hz : float
        The prefilter's cut-off [Hz].
    settle : int
        The first sample after its transient.
    extra_order : int
        The Butterworth's order beyond ``deg d1``.

    Returns
    -------
    (LightForce, FirFilter) or None
        None for a ``P1`` with a zero at ``s = 0`` (the inference refuses it).
    """
    n = mechanics.n
    Z = [[np.poly1d([mechanics.mass[i] if i == j else 0.0, mechanics.C[i][j],
                     mechanics.K[i][j]]) for j in range(n)] for i in range(n)]
    keep = [i for i in range(n) if i != mechanics.link]
    num = np.trim_zeros(_det([[Z[i][j] for j in keep] for i in keep]).coeffs, "f")
    den = np.trim_zeros(_det(Z).coeffs, "f")
    if num.size == 0 or not num[-1]:
        return None
    order = den.size - 1 + extra_order
    wc = 2 * np.pi * cutoff_hz
    poles = wc * np.exp(1j * np.pi * (2 * np.arange(order) + order + 1) / (2 * order))
    dt = float(np.median(np.diff(t)))
    lowpass = FirFilter(num, poles, wc ** order / float(num[-1]), dt)
    l_over_p1 = FirFilter(den, poles, wc ** order / float(num[-1]), dt)
    w = lowpass(u) - l_over_p1(y1 - y1[0])
    return LightForce(t=t, y1=y1, w=w, lowpass=lowpass, settle_index=settle), l_over_p1


