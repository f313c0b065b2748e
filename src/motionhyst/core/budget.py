"""A memory budget for every computation: sizes estimated before the arrays are allocated.

A computation whose size follows from its inputs (time steps of a run,
lines of a measured frequency response times the candidates of a scan,
samples times substeps of an identification) estimates the bytes it needs
with :func:`check_memory` before it allocates them.  Above the budget it is
refused with one line naming the cause and the remedy
(:class:`BudgetError`, a ``ValueError``: exit code 2 on the command line)
instead of being killed by the operating system minutes later.

The budget is :data:`DEFAULT_FRACTION` of the memory the process may use
(:func:`available_memory`: the machine's memory, the container's limit, the
address-space limit ``RLIMIT_AS`` less what the process already uses,
whichever is smallest); ``motionhyst --max-memory SIZE`` (any command) or
the environment variable ``MOTIONHYST_MAX_MEMORY`` set it explicitly
(:func:`set_max_memory`).

Examples
--------
>>> from motionhyst.core.budget import BudgetError, check_memory, parse_size, set_max_memory
>>> parse_size("1.5G"), parse_size("200M"), parse_size("4096")
(1610612736, 209715200, 4096)
>>> set_max_memory(parse_size("1G"))
>>> check_memory(100e6, "a 1e6-line response")          # 100 MB: within 1 GiB, no error
>>> try:
...     check_memory(3e9, "a run of 4e8 time steps", "lower --frequency or --duration")
... except BudgetError as exc:
...     print(exc)
a run of 4e8 time steps needs 3 GB, above the memory budget of 1.07 GB \
(--max-memory); lower --frequency or --duration
>>> set_max_memory(None)                                  # back to the default
"""

from __future__ import annotations

import os
import re
import resource

__all__ = ["DEFAULT_FRACTION", "ENV_VARIABLE", "BudgetError", "available_memory",
           "check_memory", "format_size", "max_memory", "parse_size", "set_max_memory"]

DEFAULT_FRACTION = 0.5
"""Share of :func:`available_memory` one computation may take unless a budget is given."""

ENV_VARIABLE = "MOTIONHYST_MAX_MEMORY"
"""Environment variable with the budget (as ``--max-memory``: ``2G``, ``500M``, bytes)."""

_UNITS = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}

_budget: int | None = None


class BudgetError(ValueError):
    """A computation above the memory budget: one line naming its size and the remedy.

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError
    >>> issubclass(BudgetError, ValueError)              # exit code 2 on the command line
    True
    """


def parse_size(text: str) -> int:
    """Bytes of a size such as ``"2G"``, ``"512M"``, ``"1.5GB"``, ``"800KiB"`` or ``"4096"``.

    Parameters
    ----------
    text : str
        A positive number, optionally followed by ``K``, ``M``, ``G`` or
        ``T`` (powers of 1024; ``B``, ``iB`` and lower case accepted).

    Returns
    -------
    int
        The size in bytes, > 0.

    Raises
    ------
    ValueError
        Not a positive size.

    Examples
    --------
    >>> parse_size("2G"), parse_size("512mib")
    (2147483648, 536870912)
    """
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kmgtKMGT]?)(?:i?[bB])?\s*",
                     str(text))
    if m is None:
        raise ValueError(f"not a size: {text!r} (give bytes or a number with K, M, G or T, "
                         f"such as 2G)")
    value = float(m.group(1)) * _UNITS[m.group(2).upper()]
    if not value >= 1:
        raise ValueError(f"a size must be at least 1 byte, got {text!r}")
    return int(value)


def format_size(nbytes: float) -> str:
    """A size for messages, in decimal units (``"3 GB"``, ``"512 MB"``).

    Parameters
    ----------
    nbytes : float
        Bytes.

    Returns
    -------
    str
        Three significant digits and a unit.

    Examples
    --------
    >>> format_size(2.5e9), format_size(1234), format_size(21.5 * 2**30)
    ('2.5 GB', '1.23 kB', '23.1 GB')
    """
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= size:
            return f"{nbytes / size:.3g} {unit}"
    return f"{nbytes:.0f} B"


def _cgroup_limit() -> int | None:
    """The container's memory limit (cgroup v2 or v1), None if there is none."""
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as fh:
                text = fh.read().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 1 << 60:
            return int(text)
    return None


def _vm_size() -> int:
    """The process's current virtual size [bytes] (0 where unknown)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def available_memory() -> int:
    """Bytes the process may still use: the smallest of the machine's memory, the
    container's limit and the address-space limit less the current size.

    Returns
    -------
    int
        Bytes, > 0.

    Examples
    --------
    >>> available_memory() > 0
    True
    """
    limits = []
    try:
        limits.append(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (OSError, ValueError):  # pragma: no cover - not a POSIX system
        pass
    cgroup = _cgroup_limit()
    if cgroup is not None:
        limits.append(cgroup)
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        limits.append(max(soft - _vm_size(), 1 << 20))
    return max(min(limits), 1 << 20) if limits else 1 << 34


def set_max_memory(nbytes: int | None) -> None:
    """Set the budget of one computation [bytes]; None: the default (environment or fraction).

    Parameters
    ----------
    nbytes : int or None
        The budget, > 0, or None for the default.

    Examples
    --------
    >>> set_max_memory(2 << 30); max_memory()
    2147483648
    >>> set_max_memory(None)
    """
    global _budget
    if nbytes is not None and not nbytes > 0:
        raise ValueError(f"the memory budget must be > 0 bytes, got {nbytes!r}")
    _budget = None if nbytes is None else int(nbytes)


def max_memory() -> int:
    """The budget of one computation [bytes]: as set, else from ``MOTIONHYST_MAX_MEMORY``,
    else :data:`DEFAULT_FRACTION` of :func:`available_memory`.

    Returns
    -------
    int
        Bytes.

    Examples
    --------
    >>> max_memory() > 0
    True
    """
    if _budget is not None:
        return _budget
    env = os.environ.get(ENV_VARIABLE)
    if env:
        try:
            return parse_size(env)
        except ValueError:
            raise BudgetError(f"{ENV_VARIABLE}={env!r}: not a size (such as 2G)") from None
    return int(DEFAULT_FRACTION * available_memory())


def check_memory(nbytes: float, what: str, remedy: str = "") -> None:
    """Refuse a computation of `nbytes` above the budget, before anything is allocated.

    Parameters
    ----------
    nbytes : float
        The estimated size of the computation's arrays [bytes].
    what : str
        The computation, as the message names it (``"a run of 3.3e8 time steps"``).
    remedy : str
        What the user can change (``"lower --frequency or --duration"``).

    Raises
    ------
    BudgetError
        One line: `what` needs so much, above the budget, and `remedy`.

    Examples
    --------
    >>> check_memory(1e3, "a small array")
    """
    budget = max_memory()
    if nbytes > budget:
        tail = f"; {remedy}" if remedy else ""
        raise BudgetError(f"{what} needs {format_size(nbytes)}, above the memory budget of "
                          f"{format_size(budget)} (--max-memory){tail}")
