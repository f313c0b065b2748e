"""Reading measured data from CSV files with a header row (one error line per problem)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from numpy.typing import NDArray


def read_columns(path: str | Path, names: tuple[str, ...]) -> NDArray[np.float64]:
    """The named columns of a CSV file as a float array of shape (rows, len(names)).

    Raises ``ValueError`` with one line naming the file for an unreadable
    file, no data rows, a missing column or a non-numeric value.
    """
    path = Path(path)
    try:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc.strerror}") from None
    if not rows:
        raise ValueError(f"{path}: no data rows")
    missing = [n for n in names if n not in rows[0]]
    if missing:
        raise ValueError(f"{path}: missing column(s) {', '.join(missing)}; "
                         f"need a header with {','.join(names)}")
    try:
        return np.array([[float(r[n]) for n in names] for r in rows])
    except (TypeError, ValueError):
        raise ValueError(f"{path}: non-numeric value in data") from None


def read_header(path: str | Path) -> list[str]:
    """Column names of a CSV file (``ValueError`` if it cannot be read or is empty)."""
    path = Path(path)
    try:
        with path.open(newline="") as fh:
            header = next(csv.reader(fh), [])
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc.strerror}") from None
    if not header:
        raise ValueError(f"{path}: empty file, no data rows")
    return header
