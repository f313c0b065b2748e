"""Whether a record's position responds to its force at all, decided before any fit.

An input-output fit explains the measured position by the force
(:func:`~motionhyst.identify.input_output.identify_io`).  A position that is noise,
or another experiment's, or a drift independent of the force leaves nothing to explain:
every model's search then runs for seconds to minutes before the records are found to
determine none of its parameters.  Two tests of the null hypothesis "the position does
not depend on the force", each a p-value, take milliseconds (numpy only, no fit):

* the magnitude-squared coherence ``C(f) = |S_uy|^2 / (S_uu S_yy)`` (Welch's estimate:
  Hann segments overlapping by half, each with its straight line removed), of the
  first differences of force and position (the same filter on both keeps ``C``; it
  takes the drift of a floating stage out of the segments' leakage), at segment
  lengths of a half to a 32nd of the record, over the frequencies where the force has
  power.  With ``K`` segments' worth of independent data, an independent position
  gives ``(1 - C)^(K - 1)`` uniform on [0, 1] at each frequency, so
  ``-(K - 1) ln(1 - C)`` summed over every other such frequency is a Gamma variable
  (:func:`coherence`); the smallest p-value over the segment lengths is kept.  It sees
  a stage without inertia (a piezo actuator, a damper's record) where the position is
  smooth and the force noisy;
* a linear response in time (Granger's test): least squares of the position on its
  own last :data:`LAGS` values, a constant and a straight line, then with the force's
  last values added; the F-test of the force's share.  It sees the slow content of a
  floating stage's record (a stroke whose period is the record's length), which no
  segment resolves.

A record of at least :data:`MIN_JUDGED` samples whose force varies throughout (not one
step or a few pulses, about which neither test can judge: :func:`force_spread`) where
neither test finds the position dependent (p-values above :data:`COHERENCE_P` and
:data:`RESPONSE_P`) is refused in one line by :func:`check_response`; where a test
cannot judge, nothing is refused.  The coherence is computed here with numpy
(:func:`coherence`, equal to ``scipy.signal.coherence`` with a linear detrend): importing
``scipy.signal`` costs 0.75 s of processor time, more than the whole refusal.  Measured
(``benchmarks/refusals.py``'s classes and 600 generated independent pairs of 512 to
24000 samples: white, random-walk, doubly integrated, quantised and drifting positions
against white, sine, random-walk, square and measured forces): independent pairs have
``-log10 p`` at most 2.2 (coherence)
and 8.2 (response), both beyond the thresholds in 1 % of pairs (those are fitted, and
refused by the fit as before); records of stages, at 512 samples and more, at least 2.8
(coherence) or 10 (response): generated floating axes with Jenkins friction and 1-10 %
position noise, mass-spring-dampers with a Bouc-Wen link, two-mass stages with their mode
in the band (y1 and y2 measured, noise to 15 %), piezo actuators and friction dampers
under sines and earthquake histories, and the EMPS axis (whole, each period) 37 and more.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.triangular import upper_triangle
from motionhyst.identify.io_records import IORecord

__all__ = ["BAND_SHARE", "COHERENCE_P", "DIVISIONS", "LAGS", "MIN_JUDGED", "MIN_SPREAD", "PIECE",
           "PIECES", "RESPONSE_P", "SPREAD_BLOCKS", "Dependence", "check_response", "coherence",
           "dependence", "force_spread"]

#: Records shorter than this are not judged: a stage's record of fewer samples can show
#: neither test's evidence (a piezo's 128 samples: coherence p 0.016, response p 3e-4), and
#: its fit is short
MIN_JUDGED = 512
#: The coherence test's p-value above which it finds no dependence (independent pairs: at
#: most 1 in 100 below; stages' records of 512 samples and more: below 1.6e-3 or the response
#: test's below 1e-10)
COHERENCE_P = 10 ** -1.5
#: The response test's p-value above which it finds no dependence (independent pairs: 1 in
#: 100 below)
RESPONSE_P = 1e-4
#: The force's and the position's past values in the response test
LAGS = 9
#: Segment lengths of the coherence test, as divisions of the record
DIVISIONS = (2, 4, 8, 16, 32)
#: The force's frequencies are those with at least this share of its largest power density
BAND_SHARE = 1e-2
#: A force's variation is measured over this many equal blocks of its record ...
SPREAD_BLOCKS = 16
#: ... and a record is judged when it is spread over at least this many of them (a step: 1;
#: pulses: about their number; a force that varies throughout: 16)
MIN_SPREAD = 4.0
#: A longer record is judged on its :data:`PIECES` pieces of this many samples where the
#: force's first differences have the most power (milliseconds, however long the record)
PIECE = 1 << 15
PIECES = 2


class Dependence(NamedTuple):
    """The two p-values of "the position does not depend on the force" for one record.

    Parameters
    ----------
    coherence : float
        The coherence test's p-value (the smallest over the segment lengths).
    response : float
        The linear response test's p-value.

    Examples
    --------
    >>> p = Dependence(coherence=0.4, response=1e-12)          # a response in time
    >>> p.coherence > COHERENCE_P and not p.response > RESPONSE_P
    True
    """

    coherence: float
    response: float


def coherence(u: ArrayLike, y: ArrayLike, nperseg: int, block: int = 1 << 18
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Welch's magnitude-squared coherence of `u` and `y`, the power density of `u`, and
    how many segments carry them.

    ``C(f) = |S_uy(f)|^2 / (S_uu(f) S_yy(f))``, the spectra averaged over Hann
    (periodic) segments of `nperseg` samples overlapping by half, each with its
    least-squares straight line removed: ``scipy.signal.coherence(u, y,
    nperseg=nperseg, detrend="linear")``, in numpy alone and over at most `block`
    samples at a time.  ``C`` is 0 where either spectrum is.

    Parameters
    ----------
    u, y : array_like
        Two signals of one length, at least `nperseg`.
    nperseg : int
        Samples per segment, at least 4.
    block : int
        Samples of segments transformed at once (the memory it takes).

    Returns
    -------
    c : ndarray
        The coherence at the ``nperseg // 2 + 1`` frequencies ``k / nperseg`` times
        the sampling rate.
    p_uu : ndarray
        The power density of `u` there, unscaled (its shape is what counts).
    segments : float
        How many segments carry the signals' power: ``(sum P_s)^2 / sum P_s^2`` of
        the segments' powers ``P_s``, of `u` and of `y`, the less evenly spread of
        the two: the number of segments if both are steady, about one if either is
        one transient (a step of force).  Independent steady signals make ``C`` at a
        frequency a ``Beta(1, K - 1)`` variable, ``K`` the number of independent
        segments; a transient leaves ``C`` no evidence either way.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(4096)
    >>> y = np.convolve(u, [0.5, 0.3, 0.2])[:4096]         # a filter of u: coherent
    >>> c, _, k = coherence(u, y, 256)                  # 31 segments, each alike
    >>> bool(np.min(c[1:-1]) > 0.95), bool(29 < k <= 31)
    (True, True)
    >>> c, _, _ = coherence(u, rng.standard_normal(4096), 256)     # independent
    >>> bool(np.mean(c) < 0.1)
    True
    """
    u = np.asarray(u, dtype=float)
    y = np.asarray(y, dtype=float)
    step = nperseg - nperseg // 2  # scipy.signal.welch: an overlap of nperseg // 2
    count = (u.size - nperseg) // step + 1
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nperseg) / nperseg)
    line = np.arange(nperseg) - (nperseg - 1) / 2.0
    line /= math.sqrt(float(np.sum(line ** 2)))
    views = [np.lib.stride_tricks.sliding_window_view(s, nperseg)[::step][:count]
             for s in (u, y)]
    p_uu = np.zeros(nperseg // 2 + 1)
    p_yy = np.zeros_like(p_uu)
    p_uy = np.zeros(nperseg // 2 + 1, dtype=complex)
    powers = np.zeros((2, count))
    rows = max(1, block // nperseg)
    for i in range(0, count, rows):
        a, b = (_segments(v[i:i + rows], line, window) for v in views)
        aa, bb = a.real ** 2 + a.imag ** 2, b.real ** 2 + b.imag ** 2
        p_uu += np.sum(aa, axis=0)
        p_yy += np.sum(bb, axis=0)
        p_uy += np.sum(np.conj(a) * b, axis=0)
        powers[:, i:i + rows] = np.sum(aa, axis=1), np.sum(bb, axis=1)
    both = p_uu * p_yy
    c = np.zeros_like(p_uu)
    np.divide(np.abs(p_uy) ** 2, both, out=c, where=both > 0)
    squares = np.sum(powers ** 2, axis=1)
    spread = [float(np.sum(q)) ** 2 / s2 for q, s2 in zip(powers, squares, strict=True)
              if s2 > 0]
    return np.minimum(c, 1.0), p_uu, min(spread, default=0.0)


def _segments(view: NDArray[np.float64], line: NDArray[np.float64],
              window: NDArray[np.float64]) -> NDArray[np.complex128]:
    """The spectra of segments (rows) without their mean and straight line, windowed."""
    s = view - np.mean(view, axis=1, keepdims=True)
    s = s - (s @ line)[:, None] * line
    return np.fft.rfft(s * window, axis=1)


def dependence(u: ArrayLike, y: ArrayLike) -> Dependence:
    """The p-values of "the position `y` does not depend on the force `u`" (module text).

    Parameters
    ----------
    u, y : array_like
        One record's force and position, of one length (at least ``2 LAGS + 40``).

    Returns
    -------
    Dependence
        The coherence test's and the response test's p-values.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(2000) / 1000.0
    >>> u = 30 * np.sin(2 * np.pi * 3 * t) + 5 * rng.standard_normal(2000)
    >>> y = np.cumsum(np.cumsum(u)) * 1e-7 + 1e-6 * rng.standard_normal(2000)  # a mass
    >>> p = dependence(u, y)
    >>> p.coherence < 1e-10 and p.response < 1e-10
    True
    >>> p = dependence(u, 1e-3 * rng.standard_normal(2000))                   # noise
    >>> p.coherence > COHERENCE_P and p.response > RESPONSE_P
    True
    """
    u = np.asarray(u, dtype=float)
    y = np.asarray(y, dtype=float)
    return Dependence(_coherence_p(np.diff(u), np.diff(y)), _response_p(u, y))


def _coherence_p(du: NDArray[np.float64], dy: NDArray[np.float64]) -> float:
    """The smallest p-value of the coherence over :data:`DIVISIONS` (module text)."""
    from scipy.special import gammaincc  # the Gamma variable's survival function

    best = 1.0
    for division in DIVISIONS:
        nperseg = du.size // division
        if nperseg < 16:
            continue
        c, p_uu, segments = coherence(du, dy, nperseg)
        p_uu[0] = 0.0
        top = float(np.max(p_uu))
        if not top > 0:
            continue
        band = np.flatnonzero(p_uu >= BAND_SHARE * top)[::2]  # neighbours share a window
        # independent segments' worth: two overlapping by half count as about one
        k = min(du.size / nperseg, segments / 2.0)
        x = float(np.sum(-(k - 1.0) * np.log1p(-np.minimum(c[band], 1.0 - 1e-16))))
        best = min(best, float(gammaincc(band.size, x)) if x > 0 else 1.0)
    return best


def _response_p(u: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    """The F-test's p-value of the force's past in the position's regression (module text).

    Columns: a constant, a straight line, ``y`` at lags 1..LAGS, then ``u`` at lags
    0..LAGS; the upper triangle of a QR of them with ``y`` last
    (:func:`~motionhyst.core.triangular.upper_triangle`) gives both residual sums (without
    and with the force's columns)."""
    from scipy.special import fdtrc  # the F distribution's survival function

    n = y.size
    lags = LAGS
    rows = n - lags
    q = lags + 1
    width = 2 + lags + q + 1
    idx = np.arange(lags, n)
    columns = [np.ones(rows), (idx - lags) / rows - 0.5]
    columns += [y[idx - i] for i in range(1, lags + 1)]
    columns += [u[idx - i] for i in range(q)]
    columns.append(y[idx])
    r = upper_triangle(np.column_stack(columns))
    base = 2 + lags
    full = float(r[-1, -1] ** 2) if r.shape[0] >= width else 0.0
    restricted = float(np.sum(r[base:, -1] ** 2))
    dof = rows - (width - 1)
    if dof <= 0:
        return 1.0
    if not full > 0:
        return 0.0 if restricted > 0 else 1.0
    f = max((restricted - full) / q / (full / dof), 0.0)
    return float(fdtrc(q, dof, f))


def check_response(records: list[IORecord]) -> None:
    """Refuse, before any fit, a record whose position does not depend on its force.

    A record is judged when it has at least :data:`MIN_JUDGED` samples and its force
    varies throughout (:func:`force_spread` at least :data:`MIN_SPREAD`): a step or a
    few pulses of force are one event each, about which neither test can say anything
    (the position's own past absorbs one smooth response), so such a record is left to
    the fit.  A judged record where neither test rejects independence (p-values above
    :data:`COHERENCE_P` and :data:`RESPONSE_P`) shows no response of the position to
    the force's variations: too little excitation (a force steady but for its noise,
    as in a scan at constant speed), or unrelated signals (noise, another experiment's
    position, a drift); no model explains it by the force.

    Parameters
    ----------
    records : list of IORecord
        The records (force in, position out).

    Raises
    ------
    ValueError
        One line naming the record and both p-values.

    Examples
    --------
    >>> rng = np.random.default_rng(2)
    >>> t = np.arange(1000) / 1000.0
    >>> u = 20 * np.sin(2 * np.pi * 4 * t) + 10 * np.sin(2 * np.pi * 23 * t)
    >>> check_response([IORecord(t, u, np.cumsum(np.cumsum(u)) * 1e-7, "axis.csv")])
    >>> try:
    ...     check_response([IORecord(t, u, 1e-3 * rng.standard_normal(1000), "noise.csv")])
    ... except ValueError as exc:
    ...     print(str(exc)[:67])
    noise.csv: the force's variations show no response of the position
    >>> step = np.where(t > 0.2, 60.0, 0.0)                    # one event: not judged
    >>> check_response([IORecord(t, step, 1e-3 * rng.standard_normal(1000), "step.csv")])
    """
    for rec in records:
        if rec.y.size < MIN_JUDGED:
            continue
        pieces = [piece for piece in _pieces(rec.u) if force_spread(rec.u[piece]) >= MIN_SPREAD]
        if not pieces:
            continue
        found = [dependence(rec.u[piece], rec.y[piece]) for piece in pieces]
        p = Dependence(min(f.coherence for f in found), min(f.response for f in found))
        if p.coherence > COHERENCE_P and p.response > RESPONSE_P:
            raise ValueError(
                f"{rec.name}: the force's variations show no response of the position (a "
                f"position independent of the force would show as much coherence, p = "
                f"{p.coherence:.2g}, and linear response, p = {p.response:.2g}): too little "
                f"excitation, or unrelated signals (noise, another record's position); no "
                f"model explains it by the force")


def force_spread(u: ArrayLike) -> float:
    """Over how many of :data:`SPREAD_BLOCKS` equal blocks a force's variation is spread:
    ``(sum P_b)^2 / sum P_b^2`` of the blocks' powers ``P_b`` of its first differences,
    taken after a moving average over a quarter of a block.

    The average keeps a step or a pulse one event (its differences stay in one block) while
    it divides the differences of a force sensor's white noise by the window: a step of
    60 N with 2-4 N of noise counts as one event, not as a force that varies throughout.
    The measure does not depend on the force's scale, so a steady force (a sine, a
    multisine, white noise as an excitation) stays spread over every block.

    Parameters
    ----------
    u : array_like
        A force, at least ``SPREAD_BLOCKS + 1`` samples.

    Returns
    -------
    float
        :data:`SPREAD_BLOCKS` for a force that varies alike throughout, 1-2 for one step
        (two where the averaged step straddles two blocks), about ``k`` for ``k`` separate
        pulses; 0 for a constant force.

    Examples
    --------
    >>> t = np.arange(1600) / 1000.0
    >>> round(force_spread(np.sin(2 * np.pi * 5 * t)), 1)
    16.0
    >>> step = np.where(t > 0.7, 60.0, 0.0)                 # one event, with sensor noise too
    >>> noise = np.random.default_rng(0).standard_normal(t.size)
    >>> round(force_spread(step), 1), round(force_spread(step + 2.0 * noise), 1)
    (1.9, 2.4)
    """
    u = np.asarray(u, dtype=float)
    width = max(1, u.size // SPREAD_BLOCKS // 4)
    if width > 1:
        total = np.concatenate(([0.0], np.cumsum(u)))
        u = (total[width:] - total[:-width]) / width
    d = np.diff(u)
    n = d.size // SPREAD_BLOCKS * SPREAD_BLOCKS
    power = np.sum(d[:n].reshape(SPREAD_BLOCKS, -1) ** 2, axis=1)
    total = float(np.sum(power))
    return total ** 2 / float(np.sum(power ** 2)) if total > 0 else 0.0


def _pieces(u: NDArray[np.float64]) -> list[slice]:
    """The whole record, or its :data:`PIECES` pieces of :data:`PIECE` samples where the
    force's first differences have the most power (in the record's order)."""
    n = u.size
    if n <= PIECES * PIECE:
        return [slice(0, n)]
    count = n // PIECE
    power = [float(np.sum(np.diff(u[i * PIECE:(i + 1) * PIECE]) ** 2)) for i in range(count)]
    best = np.sort(np.argsort(power)[-PIECES:])
    return [slice(int(i) * PIECE, (int(i) + 1) * PIECE) for i in best]
