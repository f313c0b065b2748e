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
from collections.abc import Callable
from pathlib import Path

from motionhyst.core.budget import check_memory, format_size

__all__ = ["CSV_EXPANSION", "TOML_EXPANSION", "InputFileError", "input_problem", "read_text",
           "read_toml"]

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


class InputFileError(ValueError):
    """A user's input file that cannot be read as asked: one line, without the file's name
    (the caller names it as its message does: ``path: ...``, ``'scenario': path: ...``).

    Examples
    --------
    >>> issubclass(InputFileError, ValueError)           # exit code 2 on the command line
    True
    """


def read_text(path: str | os.PathLike, expansion: float, kind: str = "text") -> str:
    """The text of an input file, checked first (:func:`input_problem`).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    expansion : float
        Bytes of memory reading it takes per byte of the file.
    kind : str
        What the file should be, for the message of one not UTF-8 (``"TOML"``, ``"JSON"``).

    Returns
    -------
    str

    Raises
    ------
    InputFileError
        ``cannot read (why)`` or ``not a text file (... must be UTF-8)``.
    motionhyst.core.budget.BudgetError
        Reading it would take more than the memory budget.

    Examples
    --------
    >>> try:
    ...     read_text("/dev/zero", TOML_EXPANSION)
    ... except InputFileError as exc:
    ...     print(exc)
    cannot read (not a regular file: a device, a pipe or a socket)
    """
    why = input_problem(path, expansion)
    if why:
        raise InputFileError(f"cannot read ({why})")
    try:
        return Path(path).read_text(encoding="utf-8")  # whatever the locale
    except OSError as exc:
        raise InputFileError(f"cannot read ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise InputFileError(f"not a text file ({kind} must be UTF-8)") from None


def read_toml(path: str | os.PathLike, check: Callable[[str], None] | None = None) -> dict:
    """The tables of a TOML input file (a scenario, a study, a saved identification).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    check : callable, optional
        Called with the text before it is parsed (a check that refuses, say, sizes whose
        parsing alone would take long); what it raises goes through.

    Returns
    -------
    dict

    Raises
    ------
    InputFileError
        One line without the file's name: it cannot be read (:func:`read_text`) or its
        TOML syntax is wrong (``TOML syntax error: ...``).

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "s.toml"
    >>> _ = path.write_text('outputs = ["e1"]\\n')
    >>> read_toml(path)
    {'outputs': ['e1']}
    >>> _ = path.write_text('\\ufeffoutputs = ["e1"]\\n')      # a byte-order mark first
    >>> read_toml(path)
    {'outputs': ['e1']}
    >>> _ = path.write_text("outputs = [\\n")
    >>> try:
    ...     read_toml(path)
    ... except InputFileError as exc:
    ...     print(str(exc).split(":")[0])
    TOML syntax error
    """
    import tomllib

    # a byte-order mark (an editor's "UTF-8 with BOM") is no statement: TOML's parser would
    # refuse the file's first line for it
    text = read_text(path, TOML_EXPANSION, "TOML").removeprefix("\ufeff")
    if check is not None:
        check(text)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputFileError(f"TOML syntax error: {exc}") from None
    except RecursionError:  # tomllib parses nested arrays and tables recursively
        raise InputFileError("TOML nested too deeply: arrays or tables within each other "
                             "hundreds of levels deep") from None
