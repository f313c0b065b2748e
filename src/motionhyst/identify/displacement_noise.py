"""A displacement sensor's white noise, and the displacement without it (errors in variables).

A force-displacement record's displacement is the *input* of a link model: its
sensor's noise enters the model, not only the comparison.  A link with memory
does not average it out: each reversal the noise makes near a slip opens a
small loop, and a Dahl or Bouc-Wen link run on a displacement sampled at 1 kHz
with 5 to 20 um of white noise gives a force that misses the one of the true,
smooth displacement by 1 to 36 % of its RMS beyond the noise (earthquake-like
and sine histories), an error no fit of the link's parameters can remove and no
judgement of its residual can call noise.  The record's
displacement is therefore estimated first (:func:`estimate_displacement`), the
same way by ``identify`` and by ``predict``:

1. The noise: the scale of the displacement's ``n``-th differences (for white
   noise of deviation ``sigma``, ``C(2n, n) sigma^2``), each by its median
   absolute deviation, which the few samples around a step, a corner or a
   slip do not move (:func:`difference_scales`).  It is white noise when the
   scales of orders 5 and 6 agree within :data:`WHITE_RATIO` (a smooth signal's
   shrink with each order, by ``2 sin(pi f / fs)``) and above
   :data:`MIN_RELATIVE_NOISE` of the displacement's range (rounding is not a
   sensor's noise).  A noise-free record (a staircase, a trapezoid, a stick-slip
   record, a sampled sine) has none and is used as it is, to the bit.
2. The band that holds noise alone: above the highest frequency at which the
   displacement's spectrum (Welch) stands :data:`SIGNAL_TO_NOISE` times above
   the white noise's, times :data:`CUTOFF_MARGIN`; the displacement is low-passed
   there (a Butterworth of order :data:`ORDER` run forwards and backwards: no
   delay), unless that band is less than :data:`MIN_REMOVED_BAND` of the band up
   to half the sampling rate.
3. What the filter removed must be that white noise, everywhere: in a window of
   :data:`BLOCK_SAMPLES` samples around each sample its RMS below :data:`BLOCK_FACTOR`
   times the noise's share above the cut-off.  Where it is above (a step, whose fast
   part is in one place and rings once filtered; motion that fast), the displacement is
   used as measured, over those windows and the filter's ringing beyond them
   (:data:`RING_PERIODS` periods of the cut-off), joined to the filtered one by a
   raised-cosine fade of one such period; elsewhere, over the rest, the RMS removed
   must lie within :data:`REMOVED_RMS_RANGE` of the noise's.  One step does not keep
   the rest of the record from being filtered; a record that is more than
   :data:`MAX_MEASURED_SHARE` such parts is used as it is, and the estimate says why.

Examples
--------
>>> import numpy as np
>>> t = np.arange(20000) / 1000.0
>>> x = 0.01 * np.sin(2 * np.pi * 0.5 * t)
>>> noisy = x + 10e-6 * np.random.default_rng(0).standard_normal(t.size)
>>> x_hat, est = estimate_displacement(t, noisy)
>>> est.filtered, round(est.sigma * 1e6, 1), round(est.cutoff_hz, 3)   # um, Hz
(True, 10.1, 5.859)
>>> round(float(np.std(noisy - x)) * 1e6, 2), round(float(np.std(x_hat - x)) * 1e6, 2)
(9.96, 1.24)
>>> stairs = 1e-3 * np.floor(t)                       # noise-free steps: untouched
>>> same, est = estimate_displacement(t, stairs)
>>> same is stairs, est.filtered, est.sigma
(True, False, 0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.time.resample import check_record, sampling_rate

__all__ = ["BLOCK_FACTOR", "BLOCK_SAMPLES", "CUTOFF_MARGIN", "MAX_MEASURED_SHARE",
           "MIN_RELATIVE_NOISE", "MIN_REMOVED_BAND", "ORDER", "REMOVED_RMS_RANGE", "RING_PERIODS",
           "SIGNAL_TO_NOISE", "WHITE_RATIO", "DisplacementEstimate", "difference_scales",
           "estimate_displacement"]

#: The orders of the differences whose scales must agree for white noise
WHITE_ORDERS = (5, 6)
#: ... to within this ratio (the smaller over the larger)
WHITE_RATIO = 0.85
#: Noise below this share of the displacement's range is rounding, not a sensor's
MIN_RELATIVE_NOISE = 1e-9
#: The displacement's spectrum holds signal where it stands this many times above the noise's
SIGNAL_TO_NOISE = 10.0
#: The cut-off is this many times the highest frequency that holds signal
CUTOFF_MARGIN = 2.0
#: The Butterworth's order (run forwards and backwards: twice that in magnitude)
ORDER = 6
#: A filter that would remove less than this share of the band (up to half the sampling
#: rate) removes too little noise to be worth its risk: the record is used as it is
MIN_REMOVED_BAND = 0.5
#: What the filter removed, as RMS over the white noise's above the cut-off, must lie here
#: (over the samples where it is filtered)
REMOVED_RMS_RANGE = (0.85, 1.1)
#: ... and in the window of this many samples around each sample below this many times that
#: RMS (the RMS of 256 samples of what a cut-off of 20 to 250 Hz removes from white noise at
#: 1 kHz varies by 4.3 to 6.1 %: 1.3 is 5 to 7 of its deviations, crossed now and then by
#: noise alone on long records at high cut-offs, a part then used as measured); where it is
#: not, the displacement is used as measured
BLOCK_SAMPLES, BLOCK_FACTOR = 256, 1.3
#: Around such a part, the filter's ringing: this many periods of the cut-off also as measured
#: (the Butterworth's step response settles within 1 % in 3 of them), and the fade to the
#: filtered displacement over one
RING_PERIODS = 3.0
#: The slope with which a record goes on beyond each end, before the low-pass: that of a
#: quadratic over this many periods of the cut-off (a clean sine of 100-400 times its noise,
#: 300 s at 1 kHz, 24 ends: the removed RMS near the end within 1.21 times the noise's, the
#: estimate's error there within 0.2 times the noise; the odd reflection about the last sample:
#: 2.5 times in 12 of them, 'a step'), and over at least this many samples (its noise)
END_PERIODS, END_SAMPLES = 0.25, 8
#: A record of which more than this share would be used as measured is used as measured
MAX_MEASURED_SHARE = 0.5
#: Records shorter than this many samples are used as they are
MIN_SAMPLES = 512
#: The median absolute deviation of a normal variable, in standard deviations
MAD_NORMAL = 0.6744897501960817


@dataclass
class DisplacementEstimate:
    """What :func:`estimate_displacement` found and did.

    Attributes
    ----------
    sigma : float
        The white noise's standard deviation [m] (0: none found).
    filtered : bool
        Whether the displacement was low-passed.
    cutoff_hz : float or None
        The low-pass's cut-off [Hz] (None: no band of noise alone).
    reason : str
        One line: what was found, and why the record was, or was not, filtered.

    Examples
    --------
    >>> est = DisplacementEstimate(1e-5, True, 29.3, "white noise of 1e-05 m RMS")
    >>> est.to_dict()["cutoff_hz"], str(est)
    (29.3, 'white noise of 1e-05 m RMS')
    """

    sigma: float
    filtered: bool
    cutoff_hz: float | None
    reason: str

    def to_dict(self) -> dict:
        """The JSON form: ``sigma``, ``filtered``, ``cutoff_hz``, ``reason``."""
        return {"sigma": self.sigma, "filtered": self.filtered, "cutoff_hz": self.cutoff_hz,
                "reason": self.reason}

    def __str__(self) -> str:
        return self.reason


def difference_scales(x: ArrayLike, orders: tuple[int, ...] = WHITE_ORDERS
                      ) -> NDArray[np.float64]:
    """The deviation of white noise that each order's differences of `x` show.

    ``MAD(diff(x, n)) / 0.6745 / sqrt(C(2n, n))`` for each ``n`` of `orders`: white noise
    of deviation ``sigma`` gives ``sigma`` at every order, a smooth signal less at each
    higher order, and the samples around a few steps or corners (fewer than half the
    differences) do not count.

    Parameters
    ----------
    x : array_like
        Samples, uniformly spaced.
    orders : tuple of int
        The orders of the differences.

    Returns
    -------
    ndarray
        One deviation per order.

    Examples
    --------
    >>> import numpy as np
    >>> e = np.random.default_rng(1).standard_normal(100000)
    >>> [round(float(s), 2) for s in difference_scales(e, (1, 3, 6))]
    [1.0, 1.0, 1.0]
    >>> x = np.sin(np.arange(100000) / 100.0)            # smooth: each order far less
    >>> [float(f"{s:.2g}") for s in difference_scales(x, (1, 2, 3))]
    [0.0074, 4.3e-05, 2.3e-07]
    """
    x = np.asarray(x, dtype=float)
    out = []
    for n in orders:
        d = np.diff(x, n)
        mad = float(np.median(np.abs(d - np.median(d)))) if d.size else 0.0
        out.append(mad / MAD_NORMAL / math.sqrt(math.comb(2 * n, n)))
    return np.array(out)


def _lowpass(x: NDArray[np.float64], fs: float, cutoff: float, periodic: bool
             ) -> NDArray[np.float64]:
    """`x` low-passed at `cutoff` without delay: the Butterworth of order :data:`ORDER` run
    forwards and backwards (a periodic record: its magnitude squared applied around the
    period).

    The record is extended at each end by three periods of the cut-off so that its value,
    slope and curvature go on (:func:`_extension`); the odd reflection about the last
    sample flips the curvature and doubles that sample's noise into a constant, which the
    filter spread over the record's last seconds (a clean sine with white noise was told to
    end in 'a step', its last 1.6 % used as measured)."""
    from scipy import signal

    if periodic:
        f = np.fft.rfftfreq(x.size, 1.0 / fs)
        gain = 1.0 / (1.0 + (f / cutoff) ** (2 * ORDER))
        return np.fft.irfft(np.fft.rfft(x) * gain, x.size)
    sos = signal.butter(ORDER, cutoff, fs=fs, output="sos")
    pad = min(x.size - 1, math.ceil(3.0 * fs / cutoff))
    n_end = min(x.size, max(END_SAMPLES, math.ceil(END_PERIODS * fs / cutoff)))
    head = _extension(x[::-1], n_end, pad)[::-1]
    tail = _extension(x, n_end, pad)
    y = signal.sosfiltfilt(sos, np.concatenate([head, x, tail]), padtype=None)
    return y[pad:pad + x.size]


def _extension(x: NDArray[np.float64], n_end: int, pad: int) -> NDArray[np.float64]:
    """`pad` samples after the end of `x`: `x` reflected about its last sample (even: its
    curvature goes on, its noise is not doubled) plus twice the slope at the end times the
    distance (its slope goes on), the slope from a quadratic over its last `n_end` samples."""
    k = np.arange(1, pad + 1, dtype=float)
    u = np.arange(-n_end + 1, 1, dtype=float)
    slope = float(np.polyfit(u, x[-n_end:], 2)[1])
    return x[-pad - 1:-1][::-1] + 2.0 * slope * k


def _removed_share(fs: float, cutoff: float) -> float:
    """The share of white noise's variance that the low-pass removes (``mean |1 - H|^2``
    over the band up to half the sampling rate)."""
    f = np.linspace(0.0, fs / 2.0, 4097)
    removed = 1.0 - 1.0 / (1.0 + (f / cutoff) ** (2 * ORDER))
    return float(np.mean(removed ** 2))


def estimate_displacement(t: ArrayLike, x: ArrayLike, *, periodic: bool = False,
                          quantity: str = "displacement", unit: str = "m"
                          ) -> tuple[NDArray[np.float64], DisplacementEstimate]:
    """The displacement without its sensor's white noise, where the record shows such noise
    and a band that holds it alone (see the module); else `x` itself.

    The same for any model's input measured with white noise: the force of a record without
    inertia driven by a force (`quantity` ``"force"``, `unit` ``"N"``), whose load cell's
    noise drives the link's small loops as a displacement sensor's does.

    Parameters
    ----------
    t : array_like
        Uniform time grid [s].
    x : array_like
        The measured displacement [m] (or `quantity`, in `unit`).
    periodic : bool
        `x` holds whole periods (filtered around the period).
    quantity : str
        What `x` is, as the messages name it.
    unit : str
        Its unit, as the messages give it.

    Returns
    -------
    x_hat : ndarray
        The displacement estimated: `x` itself (the same object, if it was an ndarray of
        floats) unless filtered.
    estimate : DisplacementEstimate
        The noise found, the cut-off, and why.

    Examples
    --------
    A sampled sine without noise is used as it is:

    >>> import numpy as np
    >>> t = np.arange(4000) / 200.0
    >>> x = 0.003 * np.sin(2 * np.pi * 2.0 * t)
    >>> x_hat, est = estimate_displacement(t, x)
    >>> bool(np.array_equal(x_hat, x)), est.filtered
    (True, False)
    >>> print(est)
    no white noise: used as measured

    A force with a load cell's 5 N of white noise, the input of a link without inertia:

    >>> f = 3000.0 * np.sin(2 * np.pi * 0.5 * t)
    >>> noisy = f + 5.0 * np.random.default_rng(1).standard_normal(t.size)
    >>> f_hat, est = estimate_displacement(t, noisy, quantity="force", unit="N")
    >>> print(est)
    white noise of 5.2 N RMS, alone above 7.03 Hz: low-passed there (the link's input estimated:
    errors in variables)
    >>> round(float(np.std(f_hat - f)), 2)    # N
    1.3
    """
    tt, xs = check_record(t, x, what=quantity)
    if not (isinstance(x, np.ndarray) and x.dtype == np.float64):
        x = xs
    none = DisplacementEstimate(0.0, False, None, "no white noise: used as measured")
    span = float(np.ptp(xs)) if xs.size else 0.0
    if xs.size < MIN_SAMPLES or not span > 0:
        return x, none
    s5, s6 = difference_scales(xs)
    if not (min(s5, s6) >= WHITE_RATIO * max(s5, s6) and s6 > MIN_RELATIVE_NOISE * span):
        return x, none
    sigma = float(s6)
    fs = sampling_rate(tt)
    from scipy import signal

    nperseg = int(min(xs.size, max(256, 2 ** round(math.log2(xs.size / 8)))))
    f, p = signal.welch(xs, fs=fs, nperseg=nperseg)
    floor = 2.0 * sigma ** 2 / fs  # white noise's one-sided density
    above = np.nonzero(p > SIGNAL_TO_NOISE * floor)[0]
    f_signal = float(f[above[-1]]) if above.size else float(f[1])
    cutoff = CUTOFF_MARGIN * max(f_signal, float(f[1]))
    what = f"white noise of {sigma:.2g} {unit} RMS"
    if cutoff > (1.0 - MIN_REMOVED_BAND) * fs / 2.0:
        return x, DisplacementEstimate(sigma, False, None,
                                       f"{what}, but the {quantity}'s spectrum stands "
                                       f"above it up to {f_signal:.3g} Hz: used as measured")
    x_hat = _lowpass(xs, fs, cutoff, periodic)
    removed = xs - x_hat
    expected = sigma * math.sqrt(_removed_share(fs, cutoff))
    local = _moving_rms(removed)
    measured = _fast_parts(local > BLOCK_FACTOR * expected, fs / cutoff)
    keep = measured < 1.0
    rms = float(np.sqrt(np.mean(removed[keep] ** 2))) if np.any(keep) else math.inf
    worst = float(np.max(local))
    low, high = REMOVED_RMS_RANGE
    share = float(np.mean(measured))
    if share > MAX_MEASURED_SHARE:
        return x, DisplacementEstimate(sigma, False, cutoff,
                                       f"{what}, but it moves faster than a low-pass at "
                                       f"{cutoff:.3g} Hz passes (steps) over {100 * share:.2g} % "
                                       f"of the record (more than "
                                       f"{100 * MAX_MEASURED_SHARE:g} %): used as measured")
    if not low * expected <= rms <= high * expected:
        return x, DisplacementEstimate(sigma, False, cutoff,
                                       f"{what}, but what a low-pass at {cutoff:.3g} Hz would "
                                       f"remove is not that noise (RMS {rms:.3g} {unit}, "
                                       f"{worst:.3g} {unit} in one part, against "
                                       f"{expected:.3g} {unit}: "
                                       f"a step, or motion that fast): used as measured")
    x_hat = x_hat + measured * removed
    parts = ""
    if share > 0.0:
        n_parts = int(np.count_nonzero(np.diff(np.concatenate([[0], measured > 0, [0]])) > 0))
        parts = (f", except {n_parts} part{'s' if n_parts > 1 else ''} ({100 * share:.2g} % of "
                 f"the record) where it moves that fast (a step: {worst:.3g} {unit} removed "
                 f"there against {expected:.3g} {unit}), used as measured")
    return x_hat, DisplacementEstimate(sigma, True, cutoff,
                                       f"{what}, alone above {cutoff:.3g} Hz: low-passed "
                                       f"there{parts} (the link's input estimated: errors in "
                                       f"variables)")


def _moving_rms(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """The RMS of `r` in the window of :data:`BLOCK_SAMPLES` samples centred on each sample
    (shorter at the ends)."""
    half = BLOCK_SAMPLES // 2
    n = r.size
    c = np.empty(n + 1)  # the running sum of squares, in place: two arrays of the record
    c[0] = 0.0
    np.square(r, out=c[1:])
    np.cumsum(c[1:], out=c[1:])
    out = np.empty(n)
    if n > 2 * half:  # the whole windows, then the shorter ones at the ends
        np.subtract(c[2 * half:n], c[:n - 2 * half], out=out[half:n - half])
        out[half:n - half] /= 2 * half
        ends = np.r_[0:half, n - half:n]
    else:
        ends = np.arange(n)
    lo, hi = np.maximum(ends - half, 0), np.minimum(ends + half, n)
    out[ends] = (c[hi] - c[lo]) / (hi - lo)
    return np.sqrt(out, out=out)


def _fast_parts(fast: NDArray[np.bool_], period: float) -> NDArray[np.float64]:
    """Per sample, how much of the displacement is used as measured (0 to 1): 1 in the
    window (:data:`BLOCK_SAMPLES`) of each `fast` sample (one whose window's RMS removed is
    too high) and :data:`RING_PERIODS` cut-off `period` (in samples) beyond, fading to 0
    over one period (a raised cosine)."""
    if not np.any(fast):
        return np.zeros(fast.size)
    reach = BLOCK_SAMPLES // 2 + math.ceil(RING_PERIODS * period)
    fade = max(1, math.ceil(period))
    # the distance of each sample from the nearest fast one, in samples: the last fast one
    # at or before it and the first at or after it, by running extremes of their indices
    # (in place: four arrays of the record at most, not eight)
    n = fast.size
    i = np.arange(n)
    last = np.where(fast, i, -n)
    np.maximum.accumulate(last, out=last)
    np.subtract(i, last, out=last)             # from the last fast sample (n or more: none)
    first = np.where(fast, i, 2 * n)[::-1]
    np.minimum.accumulate(first, out=first)
    first = first[::-1]
    np.subtract(first, i, out=first)           # to the next fast sample (n or more: none)
    np.minimum(last, first, out=last)
    del i, first
    part = last.astype(float)
    del last
    part -= reach                              # beyond the reach: fading over `fade`
    inside = part <= 0
    np.divide(part, fade, out=part)
    np.clip(part, 0.0, 1.0, out=part)
    np.multiply(part, np.pi, out=part)
    np.cos(part, out=part)
    part += 1.0
    part *= 0.5
    part[inside] = 1.0
    return part
