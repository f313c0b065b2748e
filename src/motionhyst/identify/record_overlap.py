"""Records that hold the same samples: one record given twice, in two files.

A fit of several records counts each sample once; a record given twice (a CSV and a MATLAB
file of it, the CSV saved again with another float format, or a part of it cut out) counts
its samples twice, and the standard errors come out ``sqrt(2)`` too small.  Files compared
byte for byte miss every such copy: the records are compared as read, by their values
(:func:`shared_samples`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["MIN_SHARED", "decimal_step", "repeated_record", "shared_samples",
           "significant_digits"]

#: The fewest samples two records share for one to be a part of the other (and not two
#: records that meet by chance at a sample)
MIN_SHARED = 10


def decimal_step(column: NDArray[np.float64]) -> float:
    """The decimal step of a column written with fixed decimals: the largest ``10**-d``
    (``d`` 0 to 15) on whose grid every value lies, or 0 if none does.

    A column saved as ``%.6f`` lies on the grid of 1e-6; one saved with all its digits, or
    with significant digits (``%.6g``), lies on none.

    Parameters
    ----------
    column : ndarray
        The values as read.

    Returns
    -------
    float
        The step, or 0.0.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.sin(np.arange(100) / 10.0)
    >>> decimal_step(np.array([float(f"{v:.6f}") for v in x]))
    1e-06
    >>> decimal_step(x)
    0.0
    """
    ulps = 4.0 * np.spacing(np.abs(column))
    for d in range(16):
        if np.all(np.abs(np.round(column, d) - column) <= ulps):
            return 10.0 ** -d
    return 0.0


def significant_digits(column: NDArray[np.float64]) -> int:
    """The significant digits a column was written with: the fewest ``s`` (1 to 17) such that
    every value lies on the grid of its own ``s``-th significant digit.

    A column saved as ``%.6g`` has 6; one saved with all its digits (``repr``, a MATLAB
    file's doubles) 15 to 17, whatever noise its values carry.

    Parameters
    ----------
    column : ndarray
        The values as read.

    Returns
    -------
    int
        The digits (17 for a column of zeros alone, whose grid is any).

    Examples
    --------
    >>> import numpy as np
    >>> x = 5e-3 + 1e-3 * np.sin(np.arange(100) / 10.0)
    >>> significant_digits(np.array([float(f"{v:.6g}") for v in x])), significant_digits(x) >= 15
    (6, True)
    """
    v = np.asarray(column, dtype=float)
    v = v[np.isfinite(v) & (v != 0.0)]
    if v.size == 0:
        return 17
    exponent = np.floor(np.log10(np.abs(v)))
    ulps = 4.0 * np.spacing(np.abs(v))
    for s in range(1, 17):
        quantum = 10.0 ** (exponent - s + 1)
        if np.all(np.abs(np.round(v / quantum) * quantum - v) <= ulps):
            return s
    return 17


def _half_quantum(values: NDArray[np.float64], digits: int) -> NDArray[np.float64]:
    """Half the step of the `digits`-th significant digit at each value (0 at 0)."""
    big = np.abs(values)
    exponent = np.floor(np.log10(np.where(big > 0.0, big, 1.0)))
    return np.where(big > 0.0, 0.5 * 10.0 ** (exponent - digits + 1), 0.0)


def shared_samples(a: Sequence[NDArray[np.float64]], b: Sequence[NDArray[np.float64]],
                   step_a: float, step_b: float) -> int:
    """How many samples record `b` shares with record `a`, where `b` starts inside `a`
    (equal, a part of it, or overlapping its end): 0 if none.

    Samples are shared when every column (`a` and `b`: the same columns, one array each,
    of the records' own lengths) agrees within what writing it again can change: half the
    step of the last significant digit of the column written with fewer
    (:func:`significant_digits`: a copy saved with 6 significant digits errs by 5e-6 of each
    value at most), or half the decimal step of a column written with fixed decimals
    (:func:`decimal_step`; half of each step added where the two columns have different
    ones), and by nothing more (a few units in the last place): two runs saved with all
    their digits are two records however little their noise, and so are two saved with the
    same digits whose noise moves a digit.  From `b`'s first
    sample to the end of either record, and the records have one time step (the time stamps
    themselves may be shifted: a part cut out of a record and its time set from 0).  A shared
    run must move (every column's range over it above 1e-3 of its largest magnitude, not two
    records that both rest) and hold at least :data:`MIN_SHARED` samples.

    Parameters
    ----------
    a, b : sequence of ndarray
        The records' columns (force, displacement, ...), each of its record's length.
    step_a, step_b : float
        Their time steps [s].

    Returns
    -------
    int
        The number of samples shared (0: none).

    Examples
    --------
    A part of a record, written with 6 significant digits, is found in it:

    >>> import numpy as np
    >>> t = np.arange(1000) / 1000.0
    >>> x, f = np.sin(2 * np.pi * t), 3.0 + np.cos(5 * t)
    >>> part = [np.array([float(f"{v:.6g}") for v in c[200:700]]) for c in (x, f)]
    >>> shared_samples([x, f], part, 1e-3, 1e-3)
    500
    >>> shared_samples([x, f], [x[200:700] + 1e-3, f[200:700]], 1e-3, 1e-3)   # another record
    0

    So is the record written with 8 fixed decimals:

    >>> fixed = [np.array([float(f"{v:.8f}") for v in c]) for c in (x, f)]
    >>> shared_samples([x, f], fixed, 1e-3, 1e-3)
    1000

    Two runs whose noise differs are two records, however small the noise against the
    values (here 1e-9 of a position 2 from its zero, a force that repeats), when they are
    saved with all their digits; a copy of either, saved with 6 significant digits, is one:

    >>> rng = np.random.default_rng(0)
    >>> run = [x + 2.0 + 1e-9 * rng.standard_normal(1000), f]
    >>> other = [x + 2.0 + 1e-9 * rng.standard_normal(1000), f]
    >>> shared_samples(run, other, 1e-3, 1e-3)
    0
    >>> shared_samples(run, [np.array([float(f"{v:.6g}") for v in c]) for c in run], 1e-3, 1e-3)
    1000
    """
    if not a or len(a) != len(b) or not (abs(step_a - step_b) <= 1e-6 * abs(step_a)):
        return 0
    n_a, n_b = a[0].size, b[0].size
    if min(n_a, n_b) < MIN_SHARED:
        return 0
    scale = [max(float(np.max(np.abs(ca))), float(np.max(np.abs(cb))))
             for ca, cb in zip(a, b, strict=True)]
    steps = [(decimal_step(ca), decimal_step(cb)) for ca, cb in zip(a, b, strict=True)]
    # half the coarser step; both halves where the steps differ (two roundings of one value)
    rounding = [0.5 * max(qa, qb) + (0.5 * min(qa, qb) if qa != qb else 0.0)
                for qa, qb in steps]
    digits = [(significant_digits(ca), significant_digits(cb))
              for ca, cb in zip(a, b, strict=True)]

    def same(ca: NDArray[np.float64], cb: NDArray[np.float64], half: float,
             sig: tuple[int, int]) -> NDArray[np.bool_]:
        big = np.maximum(np.abs(ca), np.abs(cb))
        fewer, more = min(sig), max(sig)
        written = _half_quantum(big, fewer) + (_half_quantum(big, more) if more < 15 and
                                               more != fewer else 0.0)
        return np.abs(ca - cb) <= np.maximum(written, half) + 4.0 * np.spacing(big)

    starts = np.ones(n_a, dtype=bool)
    for ca, cb, half, sig in zip(a, b, rounding, digits, strict=True):
        starts &= same(ca, cb[0], half, sig)
    for i in np.flatnonzero(starts)[:100]:  # a resting start matches many: the first hundred
        n = min(n_a - int(i), n_b)
        if n < MIN_SHARED:
            break
        if all(np.all(same(ca[i:i + n], cb[:n], half, sig)) and np.ptp(cb[:n]) > 1e-3 * top
               for ca, cb, half, sig, top in zip(a, b, rounding, digits, scale, strict=True)):
            return n
    return 0


def repeated_record(records: Sequence[tuple[float, Sequence[NDArray[np.float64]]]]
                    ) -> tuple[int, int, int] | None:
    """The first two of `records` that hold the same samples, as read
    (:func:`shared_samples` either way round), or None.

    Parameters
    ----------
    records : sequence of (float, sequence of ndarray)
        Each record's time step [s] and columns (the same columns for all).

    Returns
    -------
    tuple of int or None
        ``(i, j, n)``: records `i` < `j` share `n` samples.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(500) / 100.0
    >>> one = [np.sin(t), np.cos(3 * t)]
    >>> other = [np.sin(t + 1.0), np.cos(3 * t + 1.0)]
    >>> repeated_record([(0.01, one), (0.01, other), (0.01, [c[100:] for c in one])])
    (0, 2, 400)
    >>> repeated_record([(0.01, one), (0.01, other)]) is None
    True
    """
    for j in range(len(records)):
        for i in range(j):
            (da, a), (db, b) = records[i], records[j]
            n = shared_samples(a, b, da, db) or shared_samples(b, a, db, da)
            if n:
                return i, j, n
    return None
