"""A memory and work budget for every computation: sizes estimated before the work starts.

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
whichever is smallest); ``motionhyst COMMAND --max-memory SIZE`` (every command) or
the environment variable ``MOTIONHYST_MAX_MEMORY`` set it explicitly
(:func:`set_max_memory`).

The work of a computation whose time follows from its inputs (frequencies
times harmonics, stop elements cubed) is estimated likewise, in seconds at
the nominal costs its module states (measured on one core of a quiet
machine: a loaded one takes longer), and refused above the work budget with
:func:`check_work`: :data:`DEFAULT_SECONDS` unless ``motionhyst COMMAND
--max-seconds S`` (every command) or ``MOTIONHYST_MAX_SECONDS`` raise it
(:func:`set_max_seconds`).  A search that no formula sizes (a fit that stops when it
converges) is stopped after that much CPU time instead (:func:`cpu_time_limit`).  A command
never runs for hours unasked.

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
>>> from motionhyst.core.budget import check_work, set_max_seconds
>>> set_max_seconds(60.0)
>>> try:
...     check_work(1e4, "the Floquet multipliers at 1e5 frequencies", "give fewer frequencies")
... except BudgetError as exc:
...     print(exc)
the Floquet multipliers at 1e5 frequencies would take about 2.8 h, above the work budget \
of 1 min (--max-seconds); give fewer frequencies
>>> set_max_seconds(None)
"""

from __future__ import annotations

import contextlib
import os
import re
import resource
import signal
import sys
import threading
from collections.abc import Iterator

__all__ = ["DEFAULT_FRACTION", "DEFAULT_SECONDS", "ENV_VARIABLE", "RECORDS_REMEDY",
           "SECONDS_VARIABLE",
           "BudgetError", "available_disk", "available_memory", "check_disk", "check_memory",
           "check_work", "cpu_time_limit", "format_duration", "format_size", "machine_memory",
           "max_memory", "max_seconds", "parse_size", "set_max_memory", "set_max_seconds"]

DEFAULT_FRACTION = 0.5
"""Share of :func:`available_memory` one computation may take unless a budget is given."""

ENV_VARIABLE = "MOTIONHYST_MAX_MEMORY"
"""Environment variable with the budget (as ``--max-memory``: ``2G``, ``500M``, bytes)."""

RECORDS_REMEDY = "a larger --max-memory if the machine has it, or shorter records"
"""What the user of a command can change when the work its records need is above the
budget (``identify``'s search, the check run of the model it identified)."""

_UNITS = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}

DEFAULT_SECONDS = 3600.0
"""Work budget of one command [s of estimated run time] unless one is given (an hour)."""

SECONDS_VARIABLE = "MOTIONHYST_MAX_SECONDS"
"""Environment variable with the work budget in seconds (as ``--max-seconds``)."""

_budget: int | None = None
_seconds: float | None = None


class BudgetError(ValueError):
    """A computation above the memory or work budget: one line naming its size and the remedy.

    The message is :attr:`cause` and :attr:`remedy`, the caller's own way to a smaller
    computation (a library function's arguments); a command whose options differ says its
    own remedy instead (:meth:`with_remedy`).

    Parameters
    ----------
    cause : str
        What is too large, and the budget.
    remedy : str
        What the caller can change ("" for none).

    Examples
    --------
    >>> from motionhyst.core.budget import BudgetError
    >>> issubclass(BudgetError, ValueError)              # exit code 2 on the command line
    True
    >>> err = BudgetError("a run of 6e7 time steps: too many", "shorten the duration")
    >>> print(err)
    a run of 6e7 time steps: too many; shorten the duration
    >>> print(err.with_remedy("shorten the setpoint (--length)"))
    a run of 6e7 time steps: too many; shorten the setpoint (--length)
    """

    def __init__(self, cause: str, remedy: str = ""):
        super().__init__(f"{cause}; {remedy}" if remedy else cause)
        self.cause = cause
        self.remedy = remedy

    def with_remedy(self, remedy: str) -> BudgetError:
        """The same refusal with `remedy` in place of the caller's.

        Parameters
        ----------
        remedy : str
            What the user of a command can change.

        Returns
        -------
        BudgetError
        """
        return type(self)(self.cause, remedy)


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
    >>> parse_size("1e400")
    Traceback (most recent call last):
    ...
    ValueError: not a size: '1e400' (give bytes or a number with K, M, G or T, such as 2G)
    """
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kmgtKMGT]?)(?:i?[bB])?\s*",
                     str(text))
    if m is None:
        raise ValueError(f"not a size: {text!r} (give bytes or a number with K, M, G or T, "
                         f"such as 2G)")
    value = float(m.group(1)) * _UNITS[m.group(2).upper()]
    if not value >= 1:
        raise ValueError(f"a size must be at least 1 byte, got {text!r}")
    if value == float("inf"):  # 1e400: no integer of bytes
        raise ValueError(f"not a size: {text!r} (give bytes or a number with K, M, G or T, "
                         f"such as 2G)")
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


def machine_memory() -> int | None:
    """Bytes of memory the machine (or its container) has: past them the operating system
    kills a process rather than refusing it memory (an address-space limit refuses instead).

    Returns
    -------
    int or None
        The smaller of the machine's physical memory and the container's limit; None where
        neither is known.

    Examples
    --------
    >>> machine_memory() > 0
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
    return min(limits) if limits else None


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
    machine = machine_memory()
    limits = [] if machine is None else [machine]
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
        raise BudgetError(f"{what} needs {format_size(nbytes)}, above the memory budget of "
                          f"{format_size(budget)} (--max-memory)", remedy)


def available_disk(folder: str | os.PathLike) -> tuple[int, str]:
    """Bytes one file written in `folder` may take, and what sets them.

    The free space of its file system for this user (:func:`shutil.disk_usage`; a folder
    not created yet: its nearest existing parent's), or the process's file size limit
    (``RLIMIT_FSIZE``, ``ulimit -f``), whichever is smaller.

    Parameters
    ----------
    folder : str or path-like
        The folder the file is written in.

    Returns
    -------
    nbytes : int
        The bytes.
    what : str
        What sets them, for a message (``"free in /data"``).

    Examples
    --------
    >>> import tempfile
    >>> nbytes, what = available_disk(tempfile.gettempdir())
    >>> nbytes > 0, what.startswith(("free in", "a file may take"))
    (True, True)
    """
    import shutil
    from pathlib import Path

    where = Path(folder)  # as given: a relative path is short under however deep a folder
    while not where.is_dir() and where != where.parent:
        where = where.parent
    try:
        free, what = shutil.disk_usage(where).free, f"free in {os.path.abspath(where)}"
    except OSError:  # a file system that does not say: the limit alone
        free, what = None, ""
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    if soft != resource.RLIM_INFINITY and (free is None or soft < free):
        return int(soft), "a file may take (the file size limit, ulimit -f)"
    return (int(free), what) if free is not None else (2 ** 63 - 1, "")


def check_disk(nbytes: float, folder: str | os.PathLike, what: str, remedy: str = "") -> None:
    """Refuse to write a file of `nbytes` into `folder` where it does not fit
    (:func:`available_disk`), before anything is computed or written.

    Parameters
    ----------
    nbytes : float
        The file's estimated size [bytes].
    folder : str or path-like
        Where it is written (a temporary file beside the target, then renamed: the old
        file stays until the new one is whole).
    what : str
        The file, as the message names it (``"--time-series o.csv: 5e+07 rows"``).
    remedy : str
        What the user can change.

    Raises
    ------
    BudgetError
        One line: `what` needs so much, above the space there, and `remedy`.

    Examples
    --------
    >>> import tempfile
    >>> check_disk(1e3, tempfile.gettempdir(), "a small file")
    >>> try:
    ...     check_disk(1e30, tempfile.gettempdir(), "out.csv: 1e+28 rows", "lower --output-rate")
    ... except BudgetError as exc:
    ...     print(str(exc)[:32], "...", exc.remedy)
    out.csv: 1e+28 rows needs 1e+18 ... lower --output-rate
    """
    budget, where = available_disk(folder)
    if nbytes > budget:
        raise BudgetError(f"{what} needs {format_size(nbytes)}, above the "
                          f"{format_size(budget)} {where}", remedy)


def format_duration(seconds: float) -> str:
    """A duration for messages (``"40 s"``, ``"12 min"``, ``"2.8 h"``, ``"3.1 days"``).

    Parameters
    ----------
    seconds : float
        The duration [s].

    Returns
    -------
    str
        Two or three significant digits and a unit.

    Examples
    --------
    >>> format_duration(42.0), format_duration(720.0), format_duration(1e4), format_duration(3e5)
    ('42 s', '12 min', '2.8 h', '3.5 days')
    """
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.2g} {unit}"
    return f"{seconds:.2g} s"


def set_max_seconds(seconds: float | None) -> None:
    """Set the work budget of one command [s]; None: the default (environment or an hour).

    Parameters
    ----------
    seconds : float or None
        The budget, finite and > 0, or None for the default.

    Examples
    --------
    >>> set_max_seconds(7200.0); max_seconds()
    7200.0
    >>> set_max_seconds(None); max_seconds() == DEFAULT_SECONDS
    True
    """
    global _seconds
    if seconds is not None and not 0 < seconds < float("inf"):
        raise ValueError(f"the work budget must be finite and > 0 s, got {seconds!r}")
    _seconds = None if seconds is None else float(seconds)


def max_seconds() -> float:
    """The work budget of one command [s]: as set, else from ``MOTIONHYST_MAX_SECONDS``,
    else :data:`DEFAULT_SECONDS`.

    Returns
    -------
    float
        Seconds of estimated run time.

    Examples
    --------
    >>> max_seconds() > 0
    True
    """
    if _seconds is not None:
        return _seconds
    env = os.environ.get(SECONDS_VARIABLE)
    if env:
        try:
            value = float(env)
        except ValueError:
            value = float("nan")
        if not 0 < value < float("inf"):
            raise BudgetError(f"{SECONDS_VARIABLE}={env!r}: not a number of seconds > 0")
        return value
    return DEFAULT_SECONDS


def check_work(seconds: float, what: str, remedy: str = "") -> None:
    """Refuse a computation estimated to run `seconds`, above the work budget, before it starts.

    Parameters
    ----------
    seconds : float
        The estimated run time at the nominal costs of the computation's module [s].
    what : str
        The computation, as the message names it.
    remedy : str
        What the user can change.

    Raises
    ------
    BudgetError
        One line: `what` would take so long, above the budget, and `remedy`.

    Examples
    --------
    >>> check_work(5.0, "three frequencies")
    """
    budget = max_seconds()
    if seconds > budget:
        raise BudgetError(f"{what} would take about {format_duration(seconds)}, above the work "
                          f"budget of {format_duration(budget)} (--max-seconds)", remedy)


_LONGEST_TIMER = 1e9
"""Longest CPU-time limit set as a timer [s]; a longer one (which setitimer may not hold) is
none."""


class _TimeUp(BaseException):
    """Raised by the CPU-time alarm: a BaseException, so that no ``except ValueError`` of a
    model evaluation (values the model refuses) takes it for a bad parameter."""


AGAIN_SECONDS = 0.02
"""CPU time [s] after which the alarm of :func:`cpu_time_limit` comes again while the work
has not stopped: an alarm that came where it may not raise (the kernels' compiler), or
whose exception a C callback swallowed, is raised at the next one."""

_COMPILER = ("numba", "llvmlite")
"""Packages in whose own Python code the alarm does not raise: numba compiling a kernel, or
boxing its results (a tuple would come back with an item missing, and the caller crash), and
llvmlite's callbacks from the compiler (whose exception is printed, then ignored)."""


def _in_compiler(frame) -> bool:
    """Whether `frame`, where the alarm found the interpreter, runs :data:`_COMPILER`'s code."""
    name = frame.f_globals.get("__name__") if frame is not None else None
    return isinstance(name, str) and name.partition(".")[0] in _COMPILER


@contextlib.contextmanager
def cpu_time_limit(seconds: float | None, what: str, remedy: str = "") -> Iterator[None]:
    """Stop the work of the block after `seconds` of this process's CPU time (a BudgetError).

    For a computation whose run time no formula tells in advance (a search
    that stops when it converges): its CPU time, not the wall clock, so a
    loaded machine does not cut it shorter than a quiet one.  Without a limit
    (`seconds` None), outside the main thread, or where the system has no
    profiling timer, the block runs unbounded.

    Parameters
    ----------
    seconds : float or None
        The CPU time allowed [s] (:func:`max_seconds`, say).
    what : str
        The computation, as the message names it.
    remedy : str
        What the user can change.

    Raises
    ------
    BudgetError
        One line: `what` used its budget without finishing, and `remedy`.

    Examples
    --------
    >>> with cpu_time_limit(60.0, "a short sum"):
    ...     total = sum(range(1000))
    >>> with cpu_time_limit(1e10, "a sum without limit"):   # beyond a timer's range: none
    ...     total = sum(range(1000))
    >>> try:
    ...     with cpu_time_limit(0.05, "an endless loop", "give it an end"):
    ...         while True:
    ...             pass
    ... except BudgetError as exc:
    ...     print(exc)
    an endless loop did not finish within the work budget of 0.05 s of CPU time \
(--max-seconds); give it an end
    """
    if (seconds is None or seconds > _LONGEST_TIMER or not hasattr(signal, "setitimer")
            or threading.current_thread() is not threading.main_thread()):
        yield  # (above a timer's range: over thirty years, no limit)
        return
    fired = []

    def alarm(signum, frame):
        fired.append(signum)
        # again soon, until the work stops: raised in the compiler it would break a kernel, or
        # in a C callback be swallowed (with a traceback on stderr) and the work go on
        signal.setitimer(signal.ITIMER_PROF, AGAIN_SECONDS)
        if not _in_compiler(frame):
            raise _TimeUp

    def unraisable(report) -> None:  # the alarm's exception swallowed by a C callback
        if not isinstance(report.exc_value, _TimeUp):
            hook(report)

    previous = signal.getsignal(signal.SIGPROF)
    hook = sys.unraisablehook
    try:
        signal.signal(signal.SIGPROF, alarm)
        sys.unraisablehook = unraisable
        signal.setitimer(signal.ITIMER_PROF, seconds)
        yield
    except BaseException as exc:
        signal.setitimer(signal.ITIMER_PROF, 0)
        # a C extension may turn the alarm's exception into another (as it does a Ctrl-C)
        if fired and not isinstance(exc, KeyboardInterrupt):
            raise BudgetError(f"{what} did not finish within the work budget of "
                              f"{format_duration(seconds)} of CPU time (--max-seconds)",
                              remedy) from None
        raise
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, signal.SIG_DFL if previous is None else previous)
        if sys.unraisablehook is unraisable:
            sys.unraisablehook = hook
