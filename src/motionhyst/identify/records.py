"""Measured records for identification: reading them (CSV, arrays, DataFrames) and checking
that they can be identified from (length, finite values, increasing time, reversals)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.compiled import njit
from motionhyst.io.csvdata import Source, describe
from motionhyst.io.records import read_record

__all__ = ["count_reversals", "load_closed_loop_csv", "load_force_displacement_csv"]

MIN_SAMPLES = 50
"""Fewest samples accepted in a record."""


REVERSAL_BAND = 0.01
"""A reversal is a retreat of more than this fraction of the range from a running extreme."""


@njit(cache=True)
def _count_reversals(x, band):  # pragma: no cover - compiled
    """Direction changes of `x` that retreat more than `band` from a running extreme."""
    n_rev = 0
    direction = 0
    hi = x[0]
    lo = x[0]
    ext = x[0]
    for i in range(1, x.shape[0]):
        v = x[i]
        if direction == 0:
            hi = max(hi, v)
            lo = min(lo, v)
            if v - lo > band:
                direction = 1
                ext = v
            elif hi - v > band:
                direction = -1
                ext = v
        elif direction == 1:
            if v > ext:
                ext = v
            elif ext - v > band:
                n_rev += 1
                direction = -1
                ext = v
        else:
            if v < ext:
                ext = v
            elif v - ext > band:
                n_rev += 1
                direction = 1
                ext = v
    return n_rev


def count_reversals(x: ArrayLike, band: float | None = None) -> int:
    """Number of direction reversals of a sampled signal.

    Parameters
    ----------
    x : array_like
        Samples.
    band : float, optional
        Excursions smaller than this are ignored (noise); by default
        ``REVERSAL_BAND`` times the range of `x`.

    Returns
    -------
    int
        How often `x` turns back by more than `band` from its running extreme.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify import count_reversals
    >>> t = np.linspace(0.0, 2.0, 2001)
    >>> count_reversals(np.sin(2 * np.pi * 2.0 * t))        # 2 Hz for 2 s: 8 extrema
    8
    """
    xs = np.ascontiguousarray(x, dtype=float)
    if xs.size < 2:
        return 0
    if band is None:
        band = REVERSAL_BAND * float(np.ptp(xs))
    return int(_count_reversals(xs, float(band)))


def _reverses(x: NDArray[np.float64]) -> bool:
    """``count_reversals(x) >= 1``, with numpy alone (a record's check imports no compiler):
    once `x` has left its first band (up from its running minimum, or down from its
    running maximum, as the count decides), does it retreat by more than the band from its
    running extreme?"""
    band = REVERSAL_BAND * float(np.ptp(x))
    up = np.flatnonzero(x - np.minimum.accumulate(x) > band)
    down = np.flatnonzero(np.maximum.accumulate(x) - x > band)
    if up.size == 0 and down.size == 0:
        return False
    if down.size == 0 or (up.size and up[0] <= down[0]):  # moving up first (the count's order)
        seg = x[up[0]:]
        return bool(np.any(np.maximum.accumulate(seg) - seg > band))
    seg = x[down[0]:]
    return bool(np.any(seg - np.minimum.accumulate(seg) > band))


def check_signals(x: NDArray, named: dict[str, NDArray], t: NDArray | None,
                  xname: str = "displacement") -> None:
    """``ValueError`` (one line, no file) for records that cannot be identified from."""
    arrays = {xname: x, **named}
    if t is not None:
        arrays = {"time": t, **arrays}
    lengths = {k: v.shape for k, v in arrays.items()}
    if any(v.ndim != 1 for v in arrays.values()) or len(set(lengths.values())) != 1:
        raise ValueError("inconsistent lengths: " + ", ".join(
            f"{k} {v.size}" for k, v in arrays.items()))
    if x.size < MIN_SAMPLES:
        raise ValueError(f"too short: {x.size} samples, need at least {MIN_SAMPLES}")
    for k, v in arrays.items():
        if not np.all(np.isfinite(v)):
            raise ValueError(f"non-finite value in {k} (sample {int(np.argmin(np.isfinite(v)))})")
    if t is not None and np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise ValueError(f"time must be strictly increasing (sample {i + 1})")
    if not np.ptp(x) > 0:
        raise ValueError(f"constant {xname}: nothing to identify from")
    if not _reverses(x):
        raise ValueError(f"no reversal: the {xname} must move back and forth at least once")


def _load(source: Source, names: tuple[str, str, str], xname: str, columns=None, scale=None):
    data = read_record(source, names, columns=columns, scale=scale)
    t, x, v = data[:, 0], data[:, 1], data[:, 2]
    try:
        check_signals(x, {names[2]: v}, t, xname=xname)
    except ValueError as exc:
        raise ValueError(f"{describe(source)}: {exc}") from None
    return t, x, v


def load_force_displacement_csv(source: Source, *, columns: dict[str, str] | None = None,
                                scale: dict[str, float] | None = None
                                ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                           NDArray[np.float64]]:
    """Read a force-displacement record from CSV or MATLAB ``.mat`` (or an array or DataFrame).

    The record has the columns ``time,displacement,force`` (s, m, N; other
    columns are ignored), under those names or under the file's own mapped by
    `columns`, scaled by `scale` (read by :func:`motionhyst.io.records.read_record`:
    CSV dialects, MATLAB levels 4 to 7.3).  A DataFrame has those columns by
    name, an array those three columns in order.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        The CSV file, or the columns themselves.
    columns : dict, optional
        Quantity (``"time"``, ``"displacement"``, ``"force"``) -> the file's name for it; a quantity
        not mapped is read under its own name.
    scale : dict, optional
        Quantity -> gain its column is multiplied by (to SI units).

    Returns
    -------
    t, x, w : ndarray
        Time [s], displacement [m], force [N].

    Raises
    ------
    ValueError
        With one line naming the file: unreadable, missing column, non-numeric
        or non-finite value, rows of inconsistent length, fewer than
        ``MIN_SAMPLES`` samples, time not strictly increasing, constant
        displacement or force, or no reversal of the displacement.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from motionhyst import Jenkins
    >>> from motionhyst.identify import load_force_displacement_csv
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> x = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    >>> path = Path(tempfile.mkdtemp()) / "record.csv"
    >>> np.savetxt(path, np.column_stack([t, x, Jenkins(k=20.0, fc=0.05).response(x)]),
    ...            delimiter=",", header="time,displacement,force", comments="")
    >>> t, x, w = load_force_displacement_csv(path)
    >>> t.size, float(w.max())
    (1001, 0.05)
    """
    t, x, w = _load(source, ("time", "displacement", "force"), "displacement", columns, scale)
    if not np.ptp(w) > 0:  # said before a fit is loaded, which would find no stop operator
        raise ValueError(f"{describe(source)}: no hysteresis found: the force is constant")
    return t, x, w


def load_closed_loop_csv(source: Source, *, columns: dict[str, str] | None = None,
                         scale: dict[str, float] | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                    NDArray[np.float64]]:
    """Read a closed-loop record: columns ``time,y1,u`` (s, m, N), CSV or MATLAB ``.mat``.

    The file's own names are mapped by `columns` and scaled by `scale` (as
    :func:`load_force_displacement_csv`); an array (those columns in order) or
    a DataFrame is accepted as well.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        The CSV file, or the columns themselves.
    columns : dict, optional
        Quantity (``"time"``, ``"y1"``, ``"u"``) -> the file's name for it; a quantity not mapped is
        read under its own name.
    scale : dict, optional
        Quantity -> gain its column is multiplied by (to SI units).

    Returns
    -------
    t, y1, u : ndarray
        Time [s], position of the actuated mass [m], actuator force [N].

    Raises
    ------
    ValueError
        As :func:`load_force_displacement_csv` (with ``y1`` in place of the
        displacement).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify import load_closed_loop_csv
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> record = np.column_stack([t, 0.01 * np.sin(2 * np.pi * 2.0 * t), np.cos(2 * np.pi * t)])
    >>> t, y1, u = load_closed_loop_csv(record)           # columns time, y1, u (or a CSV file)
    >>> y1.shape
    (1001,)
    """
    return _load(source, ("time", "y1", "u"), "y1", columns, scale)
