"""A lower bound, before any fit, of the error Maxwell-slip elements leave in a record.

:func:`systematic_share_bound`: one non-negative least squares over stop operators of every
slip displacement (to a stated tolerance) bounds from below what any number of Jenkins
elements in parallel (eq. 3) can leave, so that ``identify`` refuses a record no such model
describes before its fit (:mod:`motionhyst.identify.fit`)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import nnls

from motionhyst.identify._stop_operators import stops_at
from motionhyst.identify.io_checks import NO_HYSTERESIS_GAIN, hysteresis_gain

__all__ = ["systematic_share_bound"]

BOUND_TOLERANCE = 1e-3
"""How closely the columns of :func:`systematic_share_bound` stand for every slip displacement
between them: the RMS over its rows by which the stop operator (per unit slip force) of the
geometric mean of two neighbouring slip displacements may differ from the nearest blend of
the two's; where more, the interval is halved.  The bound allows for twice that at every
slip displacement between (measured: at most 1.44 times it, at 24000 random ones on sines,
earthquake-like inputs, 100 Hz sampling and a 1 um encoder)."""


BOUND_PER_DECADE = 4
"""Slip displacements per decade of :func:`systematic_share_bound` before its refinement."""


BOUND_COLUMNS = 2000
"""Most stop operators of :func:`systematic_share_bound` (its refinement stops short of more;
the bound then allows for the error of the coarsest interval left)."""


BOUND_ROWS = 5000
"""Most samples in the residual of :func:`systematic_share_bound`: pairs of successive
samples, evenly strided (a pair's difference is the noise's, as in the fit's judgement)."""


BOUND_SLACK = (1e-3, 1e-2)
"""Shares of the range by which :func:`systematic_share_bound` may also take the record as
swept before it reaches its extremes (a record that reaches them only at its end), where
that leaves it more samples."""


def _bound_columns(x: NDArray[np.float64], rows: NDArray[np.intp], h: float,
                   max_columns: int = BOUND_COLUMNS
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """The stop operators per unit slip force of :func:`systematic_share_bound`, at `rows`.

    Their slip displacements run from a quarter of the smallest step of `x` (every step
    saturates that stop: its column is the limit of zero slip, a Coulomb element's sign of
    the motion since the last reversal) up to `h`, :data:`BOUND_PER_DECADE` a decade from
    1e-12 `h` on, and every interval whose geometric mean's column is farther than
    :data:`BOUND_TOLERANCE` (RMS) from the nearest blend of its ends' is halved, until none
    is or halving them all would make more than `max_columns`.  Returns the slip
    displacements (ascending), the columns and how closely they stand for the slip
    displacements between them (the tolerance, or the error of the coarsest interval left).
    """
    steps = np.abs(np.diff(x))
    zero = min(max(0.25 * float(steps[steps > 0].min()), np.finfo(float).tiny), h)
    low = max(zero, 1e-12 * h)  # below it, one interval to the limit (steps of round-off)
    d = np.geomspace(low, h, max(2, math.ceil(BOUND_PER_DECADE * math.log10(h / low)) + 1))
    d = np.append(zero, d) if zero < low else d
    cols = dict(zip(d.tolist(), stops_at(x, d, np.zeros_like(d), rows, True).T, strict=True))
    pending = list(zip(d[:-1].tolist(), d[1:].tolist(), strict=True))
    left = BOUND_TOLERANCE
    while pending:
        mids = np.array([math.sqrt(a) * math.sqrt(b) for a, b in pending])  # no underflow
        M = stops_at(x, mids, np.zeros_like(mids), rows, True)
        Sa = np.column_stack([cols[a] for a, _ in pending])
        Sb = np.column_stack([cols[b] for _, b in pending])
        span, off = Sa - Sb, M - Sb
        den = np.einsum("ij,ij->j", span, span)
        blend = np.clip(np.einsum("ij,ij->j", off, span) / np.where(den > 0, den, 1.0),
                        0.0, 1.0)
        error = np.sqrt(np.mean((off - span * blend) ** 2, axis=0))
        cols.update(zip(mids.tolist(), M.T, strict=True))
        coarse = [(j, a, b) for j, (a, b) in enumerate(pending)
                  if error[j] > BOUND_TOLERANCE and b > a * (1.0 + 1e-12)]
        pending = [pair for j, a, b in coarse for pair in ((a, mids[j]), (mids[j], b))]
        if pending and len(cols) + len(pending) > max_columns:
            left = max(float(error[j]) for j, _, _ in coarse)
            break
    d = np.array(sorted(cols))
    return d, np.column_stack([cols[v] for v in d.tolist()]), left


def systematic_share_bound(x: ArrayLike, w: ArrayLike, max_rows: int = BOUND_ROWS,
                           max_columns: int = BOUND_COLUMNS) -> float:
    """A lower bound, before any fit, of the systematic error any Maxwell-slip elements leave
    in a force-displacement record (:func:`~motionhyst.identify.io_checks.systematic_share`
    of the whole record, the elements' initial forces and the offset fitted).

    Once the displacement has run from one end of its range to the other, every element
    whose slip displacement is at most half the range has slipped all the way, whatever its
    state at the start, and one whose slip displacement is longer never slips again (a
    spring there, as the longest stop operator and the offset): from then on Maxwell-slip
    elements of any number and any slip displacements, down to the limit of zero slip (a
    Coulomb element), are a non-negative sum of stop operators plus an offset.  The stop
    operators are those of :func:`_bound_columns`: every slip displacement between two of
    them is a blend of the two within twice a tolerance, which the bound allows for (that
    times the slip forces, in RMS).  One non-negative least squares over them
    leaves, on those samples, no more than any fit of any number of elements, and the other
    samples add to a fit's error, never take from it.  The bound is that error, beyond the
    white noise (from the differences of successive samples, as the fit's judgement), over
    the whole record's samples, less four times the spread of that difference's estimate
    (the noise divided by the square root of the pairs).  A record that reaches its extremes
    only at its end (a dithering encoder's last count) is also taken from where it comes
    within :data:`BOUND_SLACK` of them, much earlier: the elements longer than half the
    range swept by then are a spring there, but for moving by the slack left (allowed for:
    the force's range over the swept one times half the slack); the larger bound holds.  It
    errs low (a record sampled coarsely, the noise the many operators absorb), so a refusal
    on it is safe.

    Parameters
    ----------
    x, w : array_like
        The record's displacement [m] and force [N] (checked by the reader).
    max_rows : int
        Most samples in the residual (pairs of successive samples, evenly strided); the
        stop operators run on every one.
    max_columns : int
        Most stop operators (their memory: about seven copies of `max_rows` x
        `max_columns`, :func:`motionhyst.identify.fd_memory.bound_columns`); fewer make a
        lower bound.

    Returns
    -------
    float
        The share of the force's RMS about its mean that every Maxwell-slip model leaves
        as systematic error, at least; 0 where the record is the fit's to judge: no samples
        after the sweep, a force that falls as the displacement rises (a sensor's sign
        reversed) or that a spring explains as well as the stop operators do, within the
        noise (no hysteresis): the fit's own checks name them.

    Examples
    --------
    A Jenkins element with a damper in parallel: loops that widen with the speed, which no
    Maxwell-slip elements have, against elements that describe the force exactly, one of
    them a stiff contact that slips over 2e-6 of the stroke (a Coulomb element, nearly).

    >>> import numpy as np
    >>> from motionhyst import Jenkins, MaxwellSlip
    >>> t = np.arange(600) / 750
    >>> x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    >>> w = Jenkins(k=40.0, fc=0.01).response(x) + 10.0 * x + 1.6 * np.gradient(x, t)
    >>> print(f"{systematic_share_bound(x, w):.3f}")     # the fit's own: 0.101
    0.056
    >>> w = MaxwellSlip(k=[5e3, 6.0, 4.0], fc=[0.004, 0.003, 0.002]).response(x)
    >>> systematic_share_bound(x, w) < 1e-3
    True
    """
    xs = np.ascontiguousarray(np.asarray(x, dtype=float))
    ws = np.asarray(w, dtype=float)
    x0, w0 = xs - xs.mean(), ws - ws.mean()
    spread = float(np.std(ws))
    if not spread > 0 or np.dot(x0, w0) < -0.5 * np.linalg.norm(x0) * np.linalg.norm(w0):
        return 0.0  # as _nnls_start: a force that falls as the displacement rises
    return max(_bound_after(xs, ws, start, slack, max_rows, spread, max_columns)
               for start, slack in _sweeps(xs))


def _sweeps(x: NDArray[np.float64]) -> list[tuple[int, float]]:
    """Where `x` has swept its range (the later of its extremes, slack 0) and, where it
    comes :data:`BOUND_SLACK` of the range short of its extremes a tenth of the record
    earlier, that sample and the displacement left to each extreme (together)."""
    out = [(max(int(np.argmin(x)), int(np.argmax(x))), 0.0)]
    top, bottom = np.maximum.accumulate(x), np.minimum.accumulate(x)
    span = float(top[-1] - bottom[-1])
    for share in BOUND_SLACK:
        near = np.flatnonzero((top >= top[-1] - share * span)
                              & (bottom <= bottom[-1] + share * span))
        start = int(near[0])
        if start < out[-1][0] - x.size // 10:
            out.append((start, float(top[-1] - top[start] + bottom[start] - bottom[-1])))
    return out


def _bound_after(xs: NDArray[np.float64], ws: NDArray[np.float64], start: int, slack: float,
                 max_rows: int, spread: float, max_columns: int = BOUND_COLUMNS) -> float:
    """:func:`systematic_share_bound` on the samples from `start`, where the record has swept
    its range but for `slack` (see there)."""
    if xs.size - start < 4:
        return 0.0
    stride = max(2, math.ceil((xs.size - 1 - start) / max(max_rows // 2, 1)))
    first = np.arange(start, xs.size - 1, stride)
    rows = np.column_stack([first, first + 1]).ravel()
    swept = 0.5 * (float(np.ptp(xs)) - slack)
    d, A, tolerance = _bound_columns(xs, rows, swept, max_columns)
    y = ws[rows]
    if slack > 0:  # the elements longer than the swept half range: a spring, but for slack
        A = np.column_stack([A, xs[rows]])
    A = A - A.mean(axis=0)
    y = y - y.mean()
    # on the columns themselves: a QR of them first (the NNLS stage's way, for its 5e4
    # rows) runs LAPACK's threads, which on a loaded machine take seconds
    f, _ = nnls(A, y, maxiter=50 * d.size)
    r = y - A @ f
    line = xs[rows] - xs[rows].mean()
    linear = y - line * (float(line @ y) / float(line @ line))
    if hysteresis_gain(float(linear @ linear), r) < NO_HYSTERESIS_GAIN:
        return 0.0  # a spring's force: the fit's own check says there is no hysteresis
    noise = float(np.mean((r[1::2] - r[::2]) ** 2)) / 2.0
    slip = max(float(f[:d.size].sum()), 0.5 * float(np.ptp(y)))  # the best model's, about
    # a longer element moves by at most the slack after start: its force differs from a
    # spring's by its stiffness (about the force's range over the swept one) times half it
    longer = 0.5 * slack * float(np.ptp(ws)) / (2.0 * swept) if slack > 0 else 0.0
    rms = max(math.sqrt(float(np.mean(r ** 2))) - 2.0 * tolerance * slip - longer, 0.0)
    covered = xs.size - start  # the samples the rows stand for, of all the record's
    # the residual's mean square less the noise taken from the same pairs is the mean of
    # the products of each pair's two noises: it spreads by noise / sqrt(pairs), 4 of which
    # are allowed (a heavy noise otherwise passes for systematic error)
    margin = 4.0 * noise / math.sqrt(rows.size // 2)
    return math.sqrt(max(rms ** 2 - noise - margin, 0.0) * covered / xs.size) / spread
