"""The text of every file motionhyst writes: TOML tables and CSV columns, one way each.

Scenario files and their fragments (an identified system, a hysteresis
feedforward) are TOML written by :func:`toml_table`; time series, predictions
and scans are CSV written by :func:`csv_header` and :func:`csv_rows`.  The
files themselves are written atomically by :mod:`motionhyst.io.outputs`.

Examples
--------
>>> print(toml_table("stage", {"type": "mass-damper", "m": 95.1, "c": 203},
...                  comments={"m": "moving mass [kg]"}), end="")
[stage]
type = "mass-damper"
m = 95.1      # moving mass [kg]
c = 203.0
>>> import io
>>> out = io.StringIO()
>>> csv_header(out, ["time", "force"])
>>> csv_rows(out, [[0.0, 1.5], [0.001, -2.0]])
>>> print(out.getvalue(), end="")
time,force
0.000000000000e+00,1.500000000000e+00
1.000000000000e-03,-2.000000000000e+00
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import IO, Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["CSV_FORMAT", "csv_header", "csv_rows", "toml_table", "toml_value"]

#: The numbers of a CSV file: 13 significant digits, which a float's round trip through text
#: keeps to 1e-13 relative.
CSV_FORMAT = "%.12e"

#: Column of a comment after ``key = value`` counted from the key's end (TOML files and
#: fragments line their comments up alike).
_COMMENT_GAP = 7


def toml_value(value: Any, digits: int | None = None) -> str:
    """A TOML literal: a string, a float (every number), an array or an inline table.

    Parameters
    ----------
    value : str, bool, float, sequence or mapping
        The value; numbers are written as TOML floats (``1.0``, ``2e-05``,
        ``nan``, ``inf``), which the scenario schema reads wherever it takes a
        number.
    digits : int, optional
        Significant digits of the numbers (default: as many as the float's
        shortest round trip).

    Returns
    -------
    str

    Examples
    --------
    >>> toml_value([10.0, 6], digits=7), toml_value({"model": "jenkins", "k": 20})
    ('[10.0, 6.0]', '{ model = "jenkins", k = 20.0 }')
    >>> toml_value(1 / 3, digits=7), toml_value('say "hi"')
    ('0.3333333', '"say \\\\"hi\\\\""')
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{k} = {toml_value(v, digits)}" for k, v in value.items()) + " }"
    if isinstance(value, Sequence | np.ndarray):
        return "[" + ", ".join(toml_value(v, digits) for v in value) + "]"
    v = float(value)
    s = repr(v if digits is None else float(f"{v:.{digits}g}"))
    return s if any(ch in s for ch in ".en") else s + ".0"


def toml_table(name: str, entries: Mapping[str, Any], comments: Mapping[str, str] | None = None,
               digits: int | None = None) -> str:
    """A TOML table ``[name]`` of `entries`, one ``key = value`` line each.

    Parameters
    ----------
    name : str
        The table's name.
    entries : mapping
        Keys and values (:func:`toml_value`).
    comments : mapping, optional
        A comment to write after a key's value.
    digits : int, optional
        Significant digits of the numbers (:func:`toml_value`).

    Returns
    -------
    str
        The table's lines, each ending in a newline.

    Examples
    --------
    >>> print(toml_table("feedforward", {"type": "rigid-body", "hysteresis": {
    ...     "model": "jenkins", "k": 20, "fc": 0.05}}, comments={"type": "u_ff = M r''"}), end="")
    [feedforward]
    type = "rigid-body"   # u_ff = M r''
    hysteresis = { model = "jenkins", k = 20.0, fc = 0.05 }
    """
    lines = [f"[{name}]"]
    for key, value in entries.items():
        line = f"{key} = {toml_value(value, digits)}"
        if comments and key in comments:
            line += " " * max(1, _COMMENT_GAP - len(key)) + f"# {comments[key]}"
        lines.append(line)
    return "\n".join(lines) + "\n"


def csv_header(out: IO[str], names: Sequence[str]) -> None:
    """Write the header line of a CSV file: the column names, comma-separated.

    Parameters
    ----------
    out : text stream
        Where to write.
    names : sequence of str
        The columns' names.

    Examples
    --------
    >>> import sys
    >>> csv_header(sys.stdout, ["time", "displacement"])
    time,displacement
    """
    out.write(",".join(names) + "\n")


def csv_rows(out: IO[str], block: ArrayLike, fmt: str | None = CSV_FORMAT) -> None:
    """Write rows of numbers to a CSV file (after its :func:`csv_header`).

    Parameters
    ----------
    out : text stream
        Where to write.
    block : array_like, shape (rows, columns)
        The numbers.
    fmt : str or None
        printf format of a number (default :data:`CSV_FORMAT`); None: the shortest text
        that reads back as the same number, a whole number without a decimal point, and
        an empty cell for a number that is not finite (a table for people and
        spreadsheets).

    Examples
    --------
    >>> import sys
    >>> csv_rows(sys.stdout, [[0.0, 1e-6], [0.5, -2e-6]], fmt="%.17g")
    0,9.9999999999999995e-07
    0.5,-1.9999999999999999e-06
    >>> csv_rows(sys.stdout, [[5.0, 1e-6, float("nan")]], fmt=None)
    5,1e-06,
    """
    if fmt is not None:  # as numpy.savetxt writes them, a thousand rows a write (faster)
        rows = np.asarray(block, dtype=float)
        rows = rows.reshape(-1, 1) if rows.ndim == 1 else rows
        line = ",".join([fmt] * rows.shape[1]) + "\n"
        for i in range(0, rows.shape[0], 1000):
            part = rows[i:i + 1000]
            out.write((line * part.shape[0]) % tuple(part.ravel().tolist()))
        return
    for row in np.asarray(block, dtype=float):
        out.write(",".join(_shortest(x) for x in row) + "\n")


def _shortest(x: float) -> str:
    """``repr`` of `x`, a whole number as an integer, an empty string if not finite."""
    x = float(x)
    if not np.isfinite(x):
        return ""
    return repr(int(x)) if x == int(x) and abs(x) < 1e15 else repr(x)
