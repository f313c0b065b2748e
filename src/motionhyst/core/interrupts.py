"""What a Ctrl-C became: the interrupt behind another exception.

A ``KeyboardInterrupt`` raised inside an import of a compiled extension, a numba
compilation or a C callback comes out as another error (a SystemError, numpy's
ImportError) whose cause or context is the interrupt; the command line reports it as the
interruption it was (exit code 130), not as an error.

A signal whose handler would raise while numba runs its own Python code (a kernel's
compiled wrapper unpickles an array's type as it boxes the results of a kernel returning
several arrays) must not raise there: numba would hand back a tuple with an item missing,
and the caller crash with a segmentation fault.  The handler notes it instead
(:func:`defer`) and the main thread's next kernel call raises it once numba has returned
(:func:`raise_deferred`, from :class:`motionhyst.core.compiled.Kernel`).  Every handler of
the package that raises does so through :func:`raise_or_defer`: the command's own and an
output file's while it is written (a handler that raised there unconditionally ended a
long run in a segmentation fault instead of exit 130).

Examples
--------
>>> try:
...     try:
...         raise KeyboardInterrupt
...     except KeyboardInterrupt:
...         raise ImportError("numpy failed to import")
... except ImportError as exc:
...     interrupted(exc)
True
>>> interrupted(ValueError("a bad value"))
False
"""

from __future__ import annotations

import os
import signal
import threading

__all__ = ["DEFERRED", "RESEND_SECONDS", "defer", "in_numba", "interrupted", "raise_deferred",
           "raise_or_defer"]

RESEND_SECONDS = 0.05
"""A signal deferred is sent again after this time [s] if no kernel's call has raised it
meanwhile (numba compiling, not boxing a kernel's results: no call returns soon)."""

DEFERRED: list[str] = []
"""Names of the signals noted while numba's own code ran, not yet raised."""


def interrupted(exc: BaseException) -> bool:
    """Whether `exc` is, or was caused by, a ``KeyboardInterrupt`` (its cause or context,
    however deep).

    Parameters
    ----------
    exc : BaseException
        The exception that ended the work.

    Examples
    --------
    >>> interrupted(KeyboardInterrupt())
    True
    """
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def in_numba(frame) -> bool:
    """Whether `frame` (where a signal found the interpreter) runs numba's own Python code.

    Parameters
    ----------
    frame : frame or None
        The frame a signal handler is given.

    Examples
    --------
    >>> import sys
    >>> in_numba(sys._getframe())
    False
    >>> in_numba(None)
    False
    """
    name = frame.f_globals.get("__name__") if frame is not None else None
    return isinstance(name, str) and name.partition(".")[0] == "numba"


def defer(name: str) -> None:
    """Note the signal `name` ("SIGINT", "SIGTERM"), to be raised by :func:`raise_deferred`.

    Parameters
    ----------
    name : str
        The signal's name, the ``KeyboardInterrupt``'s argument.

    Examples
    --------
    >>> defer("SIGINT")
    >>> try:
    ...     raise_deferred()
    ... except KeyboardInterrupt as exc:
    ...     print(exc, DEFERRED)
    SIGINT []
    """
    DEFERRED.append(name)


def raise_deferred() -> None:
    """Raise the first signal :func:`defer` noted as ``KeyboardInterrupt`` (none: return).

    Only in the main thread, where Python runs signal handlers: a kernel called on a worker
    thread (identify's thread pools) leaves the signal to the main thread's next kernel call
    (or to the handler's sending it again).

    Examples
    --------
    >>> raise_deferred()        # nothing noted
    """
    if DEFERRED and threading.current_thread() is threading.main_thread():
        name = DEFERRED[0]
        DEFERRED.clear()
        raise KeyboardInterrupt(name)


def raise_or_defer(signum: int, frame) -> None:
    """What a SIGINT or SIGTERM handler of the package does: raise ``KeyboardInterrupt``
    (named by the signal), or, where the signal found numba's own Python code running
    (:func:`in_numba`), note it (:func:`defer`) and send it again a moment later
    (:data:`RESEND_SECONDS`) unless a kernel's call has raised it meanwhile.

    Parameters
    ----------
    signum : int
        The signal.
    frame : frame or None
        Where it found the interpreter (the handler's argument).

    Raises
    ------
    KeyboardInterrupt
        Outside numba's code.

    Examples
    --------
    >>> import signal, sys
    >>> try:
    ...     raise_or_defer(signal.SIGTERM, sys._getframe())
    ... except KeyboardInterrupt as exc:
    ...     print(exc)
    SIGTERM
    """
    name = signal.Signals(signum).name
    if in_numba(frame):
        defer(name)
        again = threading.Timer(RESEND_SECONDS, _resend, (os.getpid(), signum))
        again.daemon = True
        again.start()
        return
    DEFERRED.clear()
    raise KeyboardInterrupt(name)


def _resend(pid: int, signum: int) -> None:
    """Send `signum` to this process again if it is still deferred (and this is the process
    that deferred it)."""
    if DEFERRED and os.getpid() == pid:
        os.kill(pid, signum)
