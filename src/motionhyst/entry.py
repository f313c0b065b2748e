"""The ``motionhyst`` console script: Ctrl-C and SIGTERM handled from its first line.

The command's own handlers (:func:`motionhyst.cli.main`) are installed once the command
line interface is imported; a signal before them (the first tenth of a second: argparse
and the interface's modules) would end the process Python's way, with a traceback or
killed by SIGTERM.  :func:`main` installs handlers before that import, so a signal at any
moment after ``import motionhyst`` (which imports next to nothing) ends the command as
every other interruption does: ``motionhyst: interrupted`` on stderr, exit code 130.
The library never touches signals: only the console script runs this.

Examples
--------
>>> from motionhyst.entry import main
>>> main(["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"])   # one line on stderr
2
"""

from __future__ import annotations

import signal
import sys

__all__ = ["INTERRUPTED", "main"]

INTERRUPTED = 130
"""Exit code of a command ended by Ctrl-C or SIGTERM (128 + SIGINT, as a shell reports it)."""


def main(argv: list[str] | None = None) -> int:
    """Run the ``motionhyst`` command (:func:`motionhyst.cli.main`); its exit code.

    Ctrl-C and SIGTERM raise ``KeyboardInterrupt`` from the first line on (a signal ignored
    by the process that started this one stays ignored; outside the main thread nothing is
    installed): one that comes before the command's own handlers ends in exit code 130 with
    one line on stderr.  Once the command has returned its exit code stands.  The handlers
    found are put back at the end (both signals ignored meanwhile); run as the command
    (`argv` None), both stay ignored, as the command leaves them (the interpreter's exit is
    not interrupted).

    Parameters
    ----------
    argv : list of str, optional
        The arguments; by default the command line (``sys.argv[1:]``).

    Examples
    --------
    >>> from motionhyst.entry import main
    >>> main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "--json"]
    ...      )  # doctest: +ELLIPSIS
    {...}
    0
    """
    found = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            if signal.getsignal(sig) is not signal.SIG_IGN:  # nohup: it stays ignored
                previous = signal.signal(sig, _interrupt)
                found[sig] = signal.SIG_DFL if previous is None else previous
        except ValueError:  # not the main thread
            break
    code = None
    try:
        from motionhyst.cli import main as command

        code = command(argv)
    except KeyboardInterrupt:
        pass
    except Exception as exc:  # an interrupt inside an import of a compiled extension
        from motionhyst.core.interrupts import interrupted

        if not interrupted(exc):
            raise
    finally:
        for sig in found:  # nothing interrupts the putting back
            signal.signal(sig, signal.SIG_IGN)
        if argv is not None:  # called from Python; as the command they stay ignored to its exit
            for sig, previous in found.items():
                signal.signal(sig, previous)
    if code is not None:  # the command returned: its exit code stands
        return code
    try:
        print("motionhyst: interrupted", file=sys.stderr)
    except (OSError, ValueError):  # a stderr that cannot be written: the exit code says it
        pass
    return INTERRUPTED


def _interrupt(signum, frame):
    raise KeyboardInterrupt(signal.Signals(signum).name)
