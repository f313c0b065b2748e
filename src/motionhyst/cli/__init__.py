"""Command-line interface: ``motionhyst df | analyze | steady | stability | simulate | scan |
identify | predict | study | benchmark | reproduce``.

A thin layer: it parses arguments, calls the library and prints tables or
JSON.  Every user error ends in one line on stderr and exit code 2.  Each
command is one module of this package with ``add_parser(sub)`` and
``run(args) -> int``; a new command is a new module listed in
:data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import gc
import importlib
import os
import signal
import sys
import threading
from collections.abc import Sequence

from motionhyst.cli._common import (
    EXIT_USAGE,
    HeldWarnings,
    Parser,
    UsageError,
    memory_size,
    one_line,
    positive,
    release_held,
    warnings_on_stderr,
)
from motionhyst.cli.identify import feedforward_fragment, record_kind
from motionhyst.core.budget import (
    format_size,
    machine_memory,
    max_memory,
    max_seconds,
    set_max_memory,
    set_max_seconds,
)
from motionhyst.core.deferred import defer_control_extras
from motionhyst.core.interrupts import DEFERRED, defer, in_numba, interrupted

COMMANDS = ("df", "analyze", "steady", "stability", "simulate", "scan", "identify", "predict",
            "study", "benchmark", "reproduce")
"""The commands, in the order ``motionhyst --help`` lists them (module names)."""

_STOPPED = {"df": "; the computation is stopped after S s of CPU time",
            "identify": "; its search, which no formula sizes, is stopped after S s of CPU time",
            "reproduce": "; the report is stopped after S s of CPU time"}
# what --max-seconds also stops once it runs, by command (core.budget.cpu_time_limit's callers)

FILE_OUTPUTS = ("out", "time_series", "save", "figure", "table")
"""Options naming a file or folder a command writes its results to: given one, a command
started with its standard output closed still runs (only its summary is lost)."""

EXIT_INTERNAL = 1
"""Exit code of a defect of the tool (an exception no input should cause)."""

TRACEBACK_VARIABLE = "MOTIONHYST_TRACEBACK"
"""Environment variable: set, a defect of the tool ends in its traceback instead of one line."""

__all__ = ["COMMANDS", "EXIT_INTERNAL", "EXIT_USAGE", "FILE_OUTPUTS", "TRACEBACK_VARIABLE",
           "UsageError", "build_parser", "feedforward_fragment", "main", "record_kind"]


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``motionhyst`` command.

    Examples
    --------
    >>> from motionhyst.cli import build_parser
    >>> args = build_parser().parse_args(["analyze", "--frequency", "5", "10"])
    >>> args.command, args.frequency
    ('analyze', [5.0, 10.0])
    """
    p = Parser(prog="motionhyst", description="Hysteresis of dynamic links in motion control "
               "loops: describing functions, quasi-linear analysis, exact steady state.")
    budget = {"--max-memory": memory_size, "--max-seconds": positive}
    for option, kind in budget.items():  # before the command too: every command has them
        p.add_argument(option, type=kind, metavar="SIZE" if option == "--max-memory" else "S",
                       dest="before_" + option[2:].replace("-", "_"),
                       help=f"as the command's {option}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name in COMMANDS:
        importlib.import_module(f"motionhyst.cli.{name}").add_parser(sub)
        sub.choices[name].add_argument(
            "--max-memory", type=memory_size, metavar="SIZE",
            help="memory one computation may take, such as 4G or 500M (default: half of the "
                 "memory available; a larger one is refused before it starts)")
        sub.choices[name].add_argument(
            "--max-seconds", type=positive, metavar="S",
            help="estimated run time a computation may take [s] (default: 3600; a longer one "
                 f"is refused before it starts{_STOPPED.get(name, '')})")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``motionhyst`` command; returns the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments; by default the command line (``sys.argv[1:]``).

    Notes
    -----
    Run as the command (`argv` None), it also skips the interpreter's last
    garbage collections at exit: they would go through every object of the
    libraries imported (0.2-0.4 s, a sixth of a command's time) only to free
    memory the operating system takes back anyway.

    Examples
    --------
    The ``motionhyst`` command, called from Python (the exit code is returned):

    >>> from motionhyst.cli import main
    >>> main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"])   # doctest: +ELLIPSIS
    Describing function of the jenkins element, k = 20 N/m, fc = 0.05 N ...
    A [m]  zeta [-]  Re D [N/m]  Im D [N/m]  |D| [N/m]  |D|/k_init [-]  angle D [deg]
    -----  --------  ----------  ----------  ---------  --------------  -------------
     0.01      0.25        3.91       4.775      6.171          0.3086          50.69
    ...
    0
    >>> main(["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"])  # one line on stderr
    2
    """
    if argv is None:
        # every atexit handler still runs and every object freed by reference counting still
        # is (files and temporary folders are closed by the command itself); only unreachable
        # cycles are left to the operating system
        atexit.register(gc.freeze)
    defer_control_extras()  # a loop's refusal does not wait for python-control's plots to load
    interrupts = _Interrupts()
    held = HeldWarnings()
    closed = not _writable(sys.stdout)  # ``>&-`` (None) or opened for reading (``1</dev/null``)
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        _budget_given_once(args)
        if closed:
            if not any(getattr(args, name, None) for name in FILE_OUTPUTS):
                state = "closed" if sys.stdout is None else "not open for writing"
                raise UsageError(f"motionhyst {args.command}: standard output is {state} and "
                                 f"the command writes no file: its results would be lost; give "
                                 f"it an output (a terminal, a file or a pipe)")
            sys.stdout = open(os.devnull, "w")  # the files are the results; the summary is lost
        else:
            sys.stdout = _NamedOutput(sys.stdout)
        set_max_memory(args.before_max_memory if args.max_memory is None else args.max_memory)
        set_max_seconds(args.before_max_seconds if args.max_seconds is None
                        else args.max_seconds)
        max_memory(), max_seconds()  # MOTIONHYST_MAX_* set to no size: refused by every command
        with warnings_on_stderr(args.command, held):
            held.hold()  # until the command's checks before its work pass: a refusal is one line
            _warn_budget_beyond_machine(args)  # shown when the work (what may be killed) starts
            code = args.func(args)
        if interrupts.received:  # a library swallowed it (an optional import that failed)
            raise KeyboardInterrupt
        sys.stdout.flush()  # a full disk said here, naming the output, not at the exit
        return code
    except BrokenPipeError:  # output piped into head, say: not an error
        sys.stdout = open(os.devnull, "w")
        held.release()
        return 0
    except KeyboardInterrupt:
        interrupts.close()
        held.release()  # no warning lost: an interrupted run shows what it was warned of
        _say("motionhyst: interrupted")
        return 130
    except Exception as exc:
        interrupts.close()
        if not (interrupts.received or interrupted(exc)):
            return _failed(exc, held)
        held.release()
        _say("motionhyst: interrupted")
        return 130
    finally:
        interrupts.close()  # a signal from here on is noted, not raised
        if isinstance(sys.stdout, _NamedOutput):
            sys.stdout = sys.stdout.stream
        set_max_memory(None)
        set_max_seconds(None)
        if closed and sys.stdout is not None:
            sys.stdout.close()
            sys.stdout = None
        # run as the command, the work is done or abandoned: a signal now must neither
        # interrupt the interpreter's exit (tracebacks) nor turn a finished run into an
        # interrupted one; called from Python, the handlers found are put back
        interrupts.restore(ignore=argv is None)


class _Interrupts:
    """Ctrl-C (SIGINT) and SIGTERM end a command the same way, whenever they come: exit 130,
    the old files intact.

    Each raises ``KeyboardInterrupt`` and is remembered (:attr:`received`): one that
    reached an import of a compiled extension may come out as another error (numpy's
    ImportError) that no longer names it, and one raised inside a C callback (numba's
    compiler caching a kernel) is swallowed there, reported to ``sys.unraisablehook``: it
    is noted, not shown, and the signal sent again a moment later.  One that finds numba's
    own Python code running (boxing a kernel's results) is not raised there (numba would
    hand back a tuple with an item missing: a segmentation fault): the kernel's call raises
    it once numba has returned (:mod:`motionhyst.core.interrupts`).  Only in this process:
    a worker forked from it ends at SIGTERM by the signal's default, as its parent expects,
    and takes Ctrl-C as Python does.  Outside the main thread nothing is installed, and a
    signal ignored by the process that started this one (``nohup``) stays ignored.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self):
        self.received: list[int] = []
        self.previous: dict[int, object] = {}
        self.pid = os.getpid()
        self.closing = False
        self.again: threading.Timer | None = None
        for sig in self.SIGNALS:
            try:
                if signal.getsignal(sig) is signal.SIG_IGN:  # ignored by who started us
                    continue  # (nohup, a background job): so it stays, as Python does
                previous = signal.signal(sig, self._handler)
            except ValueError:  # not the main thread
                break
            self.previous[sig] = signal.SIG_DFL if previous is None else previous
        self.hook = sys.unraisablehook
        if self.previous:
            sys.unraisablehook = self._unraisable

    def _handler(self, signum, frame):
        if os.getpid() != self.pid:  # a forked worker
            if signum == signal.SIGINT:
                signal.default_int_handler(signum, frame)
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        self.received.append(signum)
        if self.closing:  # the command is ending: its exit code says it
            return
        name = signal.Signals(signum).name
        if in_numba(frame):  # numba boxing a kernel's results: raised there, it would hand
            defer(name)  # back a broken tuple; the kernel's call raises it (or, if no kernel
            self._later(signum, deferred=True)  # call returns soon, the signal sent again)
            return
        DEFERRED.clear()
        raise KeyboardInterrupt(name)

    def _unraisable(self, unraisable) -> None:
        # raised inside a C callback (numba's compiler caching a kernel), the interrupt is
        # swallowed there with a traceback on stderr and the work goes on: noted, not shown,
        # and the signal sent again a moment later, when the callback has returned
        if os.getpid() != self.pid or not isinstance(unraisable.exc_value, KeyboardInterrupt):
            if os.getpid() == self.pid and self.received:  # after a signal: what it left
                return  # half-built (_finalisers_silent)
            self.hook(unraisable)
            return
        name = str(unraisable.exc_value.args[0]) if unraisable.exc_value.args else ""
        sig = getattr(signal, name, None) if name in ("SIGINT", "SIGTERM") else None
        if sig not in self.previous:
            sig = next(iter(self.previous))
        self.received.append(sig)
        self._later(sig)

    def _later(self, sig: int, deferred: bool = False) -> None:
        """Send `sig` again a moment later, where it can be raised (`deferred`: unless a
        kernel's call has raised it meanwhile)."""
        if not self.closing and (self.again is None or not self.again.is_alive()):
            self.again = threading.Timer(0.05, self._resend, (sig, deferred))
            self.again.daemon = True
            self.again.start()

    def _resend(self, sig: int, deferred: bool = False) -> None:
        if not self.closing and (DEFERRED or not deferred):
            os.kill(self.pid, sig)

    def close(self) -> None:
        """The command is ending: no signal raises any more, none is sent again."""
        self.closing = True
        DEFERRED.clear()
        if self.again is not None:
            self.again.cancel()
            if self.again is not threading.current_thread():
                self.again.join()

    def restore(self, ignore: bool = False) -> None:
        """Put back the handlers found (`ignore`: ignore the signals instead)."""
        self.close()
        for sig, previous in self.previous.items():
            with contextlib.suppress(ValueError, OSError, TypeError):
                signal.signal(sig, signal.SIG_IGN if ignore else previous)
        if sys.unraisablehook == self._unraisable:
            sys.unraisablehook = self.hook
        if ignore and self.received:  # an interrupted command's last moments: a finaliser of
            sys.unraisablehook = _finalisers_silent  # what the signal left half-built raises


def _finalisers_silent(unraisable) -> None:
    """An interrupted command exits 130 with one line: the errors Python cannot raise as
    it ends (a finaliser of an object the signal left half-built, llvmlite's compiler's
    when it came while a kernel compiled) are not shown."""


class _NamedOutput:
    """The standard output, its write errors naming it: ``> /dev/full`` ends in "standard
    output: No space left on device", not in an error that names nothing (a broken pipe
    stays what it is: output piped into ``head`` is no error)."""

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> int:
        release_held()  # the results begin: the warnings held so far come first
        try:
            return self.stream.write(text)
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, "standard output") from None

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, "standard output") from None

    def __getattr__(self, name: str):
        return getattr(self.stream, name)


def _writable(stream) -> bool:
    """Whether `stream` (the standard output) can take the command's results: not closed
    (None) and, when it is a file descriptor, not opened for reading only (``1</dev/null``,
    where every write fails with "Bad file descriptor", naming nothing)."""
    if stream is None:
        return False
    try:
        import fcntl

        flags = fcntl.fcntl(stream.fileno(), fcntl.F_GETFL)
    except (AttributeError, ImportError, OSError, ValueError):  # no descriptor: a StringIO
        return True
    return flags & os.O_ACCMODE != os.O_RDONLY


def _say(line: str) -> None:
    """`line` on stderr; a stderr that cannot be written (a full disk) leaves the exit code
    to say what happened."""
    with contextlib.suppress(OSError, ValueError):
        print(line, file=sys.stderr)


def _budget_given_once(args: argparse.Namespace) -> None:
    """Refuse ``--max-memory`` or ``--max-seconds`` given both before the command and after it
    (``motionhyst --max-memory 1G steady paper.toml --max-memory 2G``): the two parsers each
    see it once, and one of the values would be dropped without a word."""
    for option in ("--max-memory", "--max-seconds"):
        dest = option[2:].replace("-", "_")
        if getattr(args, "before_" + dest) is not None and getattr(args, dest) is not None:
            raise UsageError(f"motionhyst {args.command}: {option} is given twice (before the "
                             f"command and after it); give it once")


def _warn_budget_beyond_machine(args: argparse.Namespace) -> None:
    """Warn of a memory budget larger than the machine: a computation it lets through is
    killed by the operating system (or swaps for hours) instead of refused in one line.
    Under an address-space limit (``ulimit -v``) within the machine's memory the limit
    refuses first (a MemoryError, one line): no warning."""
    import resource

    from motionhyst.core.warnings import warn

    budget, machine = max_memory(), machine_memory()
    limit, _ = resource.getrlimit(resource.RLIMIT_AS)
    if limit != resource.RLIM_INFINITY and machine is not None and limit <= machine:
        return
    if machine is not None and budget > machine:
        option = args.max_memory if args.max_memory is not None else args.before_max_memory
        given = "--max-memory" if option is not None else "MOTIONHYST_MAX_MEMORY"
        text = (getattr(option, "text", "") if option is not None  # as given: 100T, not 110 TB
                else os.environ.get("MOTIONHYST_MAX_MEMORY", "").strip())
        size = f"{text} ({format_size(budget)})" if text else format_size(budget)
        warn(f"{given} {size} is more than the {format_size(machine)} of memory this machine "
             f"has: a computation that large would be killed by the system, not refused")


def _failed(exc: Exception, held: HeldWarnings) -> int:
    """One line on stderr for an exception that ended a command; its exit code.  The
    warnings `held` while the command checked its input are dropped for a refusal of it,
    shown before the line of a defect of the tool."""
    if isinstance(exc, (UsageError, OSError, ValueError, RuntimeError, MemoryError)):
        held.drop()
    else:
        held.release()
    # an old spelling's new one ends the refusal's line (cli._common.old_spelling)
    tail = f" ({held.postscript})" if held.postscript else ""
    try:
        raise exc
    except UsageError as exc:  # "motionhyst identify: ..." -> "motionhyst: error: identify: ..."
        # "motionhyst identify: ..." of a command's parser, "motionhyst: ..." of the top one
        text = str(exc).removeprefix("motionhyst ").removeprefix("motionhyst: ")
        _say(f"motionhyst: error: {one_line(text)}{tail}")
    except OSError as exc:  # "No space left on device: out.csv", not "[Errno 28] ... 'out.csv'"
        text = (f"{exc.filename}: {exc.strerror}" if exc.strerror and exc.filename is not None
                else exc.strerror or str(exc))
        _say(f"motionhyst: error: {one_line(text)}{tail}")
    except (ValueError, RuntimeError) as exc:
        _say(f"motionhyst: error: {one_line(str(exc))}{tail}")
    except MemoryError:  # an estimate missed: still one line, and the remedy
        _say("motionhyst: error: out of memory; give a smaller problem (or a larger "
             f"--max-memory, if the machine has it){tail}")
    except Exception as exc:  # a defect of the tool, not the input: one line, exit 1
        if os.environ.get(TRACEBACK_VARIABLE):
            raise
        _say(f"motionhyst: internal error: {one_line(f'{type(exc).__name__}: {exc}')} (a "
             f"defect of motionhyst, please report it; {TRACEBACK_VARIABLE}=1 shows where)")
        return EXIT_INTERNAL
    return EXIT_USAGE
