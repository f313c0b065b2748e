"""What every command of the ``motionhyst`` CLI shares: one-line user errors,
argparse number types, tables and number formatting, JSON output."""

from __future__ import annotations

import argparse
import math

from motionhyst.jsonio import dumps
from motionhyst.textfmt import g, table

__all__ = ["EXIT_USAGE", "Parser", "UsageError", "finite", "g", "harmonic_count",
           "nonnegative", "positive", "print_json", "table"]

EXIT_USAGE = 2
"""Exit code of every user error."""


class UsageError(Exception):
    """A user error: reported as one line, exit code 2.

    Examples
    --------
    >>> from motionhyst.cli import UsageError, main
    >>> issubclass(UsageError, Exception)
    True
    >>> main(["identify", "no-such-record.csv"])           # reported as one line, exit code 2
    2
    """


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage block)."""

    def error(self, message: str):
        raise UsageError(f"{self.prog}: {message}")


def _number(text: str, what: str, positive: bool | None) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be a number, got {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{what} must be finite, got {text!r}")
    if positive and v <= 0:
        raise argparse.ArgumentTypeError(f"{what} must be > 0, got {text!r}")
    if positive is False and v < 0:
        raise argparse.ArgumentTypeError(f"{what} must be >= 0, got {text!r}")
    return v


def positive(text: str) -> float:
    """argparse type: a finite number > 0."""
    return _number(text, "value", True)


def finite(text: str) -> float:
    """argparse type: a finite number."""
    return _number(text, "value", None)


def nonnegative(text: str) -> float:
    """argparse type: a finite number >= 0."""
    return _number(text, "value", False)


def harmonic_count(text: str) -> int:
    """argparse type: a whole number of harmonics from 1 to 1000."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if not 1 <= n <= 1000:
        raise argparse.ArgumentTypeError(f"must be from 1 to 1000, got {text!r}")
    return n


def print_json(obj) -> None:
    """Print `obj` as JSON (NumPy values converted, NaN as null)."""
    print(dumps(obj))
