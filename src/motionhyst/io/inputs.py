"""Input files checked before they are opened: a regular file of a size the memory holds.

Every reader of a user's file (scenarios, studies, CSV and MATLAB records,
identification results) asks :func:`input_problem` first.  A device such as
``/dev/zero`` or ``/dev/urandom`` would be read until the memory runs out, a
named pipe (FIFO) would block the command until some other program writes
into it, and a file far larger than the memory budget would be read for
minutes before the operating system kills the process: each is refused at
once, in one line, instead.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from motionhyst.core.budget import check_memory, format_size

__all__ = ["CSV_EXPANSION", "TOML_EXPANSION", "input_problem"]

TOML_EXPANSION = 16.0
"""Bytes of memory per byte of a TOML or JSON file read (each number a Python object)."""

CSV_EXPANSION = 4.0
"""Bytes of memory per byte of a CSV or MATLAB file read (its columns, parsed, and a copy)."""


def input_problem(path: str | os.PathLike, expansion: float) -> str | None:
    """Why `path` cannot be read as an input file, or None (also when it does not exist:
    opening it then says so in the reader's own words).

    Parameters
    ----------
    path : str or os.PathLike
        The file (a symbolic link is followed).
    expansion : float
        Bytes of memory reading it takes per byte of the file (text parsed into
        numbers and objects: a TOML scenario about 16, a CSV table about 4).

    Returns
    -------
    str or None
        ``"it is a folder"`` or ``"not a regular file: a device, a pipe or a socket"``.

    Raises
    ------
    motionhyst.core.budget.BudgetError
        Reading the file would take more than the memory budget (one line: the
        file's size, the memory it needs, the budget).

    Examples
    --------
    >>> input_problem("/dev/zero", 4.0)
    'not a regular file: a device, a pipe or a socket'
    >>> import tempfile
    >>> input_problem(tempfile.gettempdir(), 4.0)
    'it is a folder'
    >>> input_problem("no-such-file.csv", 4.0) is None
    True
    """
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if stat.S_ISDIR(st.st_mode):
        return "it is a folder"
    if not stat.S_ISREG(st.st_mode):
        return "not a regular file: a device, a pipe or a socket"
    check_memory(expansion * st.st_size, f"reading {Path(path).name} "
                 f"({format_size(st.st_size)})", "give a smaller file")
    return None
