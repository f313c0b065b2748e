"""The ``motionhyst`` console script: Ctrl-C and SIGTERM handled from its first line.

A module of its own beside the package, not inside it: the console script imports it first,
and importing ``motionhyst.entry`` would first run the package's ``__init__`` (and what it
imports).  This module imports nothing the interpreter has not already loaded at start-up (the
compiled ``_signal``, not the ``signal`` module, which loads ``enum``, ``functools`` and
``collections`` first), and :func:`main` installs its handlers before the command line
interface is imported.  A signal at any moment from then on ends the command as every other
interruption does: ``motionhyst: interrupted`` on stderr, exit code 130.

What comes before is the interpreter's own start (loading itself, its encodings and ``site``:
15 ms on an idle machine, 40 ms at a load of 13 on 2 cores, 100 ms and more at 20), which no
code of the command can shorten: until the interpreter installs its own Ctrl-C handler,
SIGINT and SIGTERM end the process by their defaults (a shell reports 130 and 143); from then
on to the console script's first line a Ctrl-C ends it with the interpreter's traceback (or,
in CPython's check of the script's path, is dropped), and SIGTERM still by its default.
The library never touches signals: only the console script runs this.

Examples
--------
>>> from _motionhyst_entry import main
>>> main(["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"])   # one line on stderr
2
"""

import sys

try:
    import _signal as signals  # compiled, loaded by the interpreter before any script runs
except ImportError:  # an interpreter without it
    import signal as signals

__all__ = ["INTERRUPTED", "main"]

INTERRUPTED = 130
"""Exit code of a command ended by Ctrl-C or SIGTERM (128 + SIGINT, as a shell reports it)."""

_ENDED: list[bool] = []
"""Not empty once the command has returned or been interrupted: a signal then raises nothing."""

_RECEIVED: list[int] = []
"""The signals received before the command's own handlers took over."""


def main(argv: list[str] | None = None) -> int:
    """Run the ``motionhyst`` command (:func:`motionhyst.cli.main`); its exit code.

    Ctrl-C and SIGTERM raise ``KeyboardInterrupt`` from the first line on (a signal ignored
    by the process that started this one stays ignored; outside the main thread nothing is
    installed): one that comes before the command's own handlers ends in exit code 130 with
    one line on stderr, also one raised where an exception cannot propagate (a callback of
    the import system's locks, reported to ``sys.unraisablehook``: noted there, not shown,
    and the command not started).  Once the command has returned its exit code stands.  The
    handlers found are put back at the end (both signals ignored meanwhile); run as the command
    (`argv` None), both stay ignored, as the command leaves them (the interpreter's exit is
    not interrupted).

    Parameters
    ----------
    argv : list of str, optional
        The arguments; by default the command line (``sys.argv[1:]``).

    Returns
    -------
    int
        The command's exit code; 130 when a signal ended it.

    Examples
    --------
    >>> from _motionhyst_entry import main
    >>> main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "--json"]
    ...      )  # doctest: +ELLIPSIS
    {...}
    0
    """
    found = {}
    code = None
    del _ENDED[:], _RECEIVED[:]
    hook = sys.unraisablehook

    def unraisable(info):  # swallowed where it was raised (a callback): noted, not shown
        if not (_RECEIVED and isinstance(info.exc_value, KeyboardInterrupt)):
            hook(info)

    try:  # a Ctrl-C that comes before the handlers (the interpreter's own) ends here too
        for sig in (signals.SIGINT, signals.SIGTERM):
            previous = signals.getsignal(sig)
            if previous is signals.SIG_IGN:  # nohup: it stays ignored
                continue
            found[sig] = signals.SIG_DFL if previous is None else previous
            try:
                signals.signal(sig, _interrupt)
            except ValueError:  # not the main thread
                del found[sig]
                break
        if found:
            sys.unraisablehook = unraisable
        from motionhyst.cli import main as command

        if _RECEIVED:  # a signal the import swallowed
            raise KeyboardInterrupt
        sys.unraisablehook = hook  # the command's own handlers note it from here on
        code = command(argv)
    except KeyboardInterrupt:
        pass
    except Exception as exc:  # an interrupt inside an import of a compiled extension
        from motionhyst.core.interrupts import interrupted

        if not (_RECEIVED or interrupted(exc)):
            raise
    finally:
        _ENDED.append(True)  # nothing interrupts the putting back
        if sys.unraisablehook is unraisable:
            sys.unraisablehook = hook
        for sig in found:
            signals.signal(sig, signals.SIG_IGN)
        if argv is not None:  # called from Python; as the command they stay ignored to its exit
            for sig, previous in found.items():
                signals.signal(sig, previous)
    if code is not None:  # the command returned: its exit code stands
        return code
    try:
        print("motionhyst: interrupted", file=sys.stderr)
    except (OSError, ValueError):  # a stderr that cannot be written: the exit code says it
        pass
    return INTERRUPTED


def _interrupt(signum, frame):
    if not _ENDED:
        _RECEIVED.append(signum)
        raise KeyboardInterrupt("SIGINT" if signum == signals.SIGINT else "SIGTERM")


if __name__ == "__main__":  # python -m _motionhyst_entry: the console script's route
    sys.exit(main())
