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
from collections.abc import Sequence

from motionhyst.cli._common import (
    EXIT_USAGE,
    Parser,
    UsageError,
    memory_size,
    one_line,
    positive,
    warnings_on_stderr,
)
from motionhyst.cli.identify import feedforward_fragment, record_kind
from motionhyst.core.budget import set_max_memory, set_max_seconds

COMMANDS = ("df", "analyze", "steady", "stability", "simulate", "scan", "identify", "predict",
            "study", "benchmark", "reproduce")
"""The commands, in the order ``motionhyst --help`` lists them (module names)."""

EXIT_INTERNAL = 1
"""Exit code of a defect of the tool (an exception no input should cause)."""

TRACEBACK_VARIABLE = "MOTIONHYST_TRACEBACK"
"""Environment variable: set, a defect of the tool ends in its traceback instead of one line."""

__all__ = ["COMMANDS", "EXIT_INTERNAL", "EXIT_USAGE", "TRACEBACK_VARIABLE", "UsageError",
           "build_parser", "feedforward_fragment", "main", "record_kind"]


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
                 "is refused before it starts)")
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
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        set_max_memory(args.max_memory)
        set_max_seconds(args.max_seconds)
        with warnings_on_stderr(args.command):
            return args.func(args)
    except BrokenPipeError:  # output piped into head, say: not an error
        sys.stdout = open(os.devnull, "w")
        return 0
    except KeyboardInterrupt:
        print("motionhyst: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        if not _interrupted(exc):
            return _failed(exc)
        print("motionhyst: interrupted", file=sys.stderr)
        return 130
    finally:
        set_max_memory(None)
        set_max_seconds(None)
        if argv is None:  # the work is done or abandoned: a Ctrl-C now must not interrupt the
            with contextlib.suppress(ValueError, OSError):  # interpreter's exit (tracebacks)
                signal.signal(signal.SIGINT, signal.SIG_IGN)


def _interrupted(exc: BaseException) -> bool:
    """Whether `exc` is what a Ctrl-C became: a ``KeyboardInterrupt`` raised inside an import
    of a compiled extension, a numba compilation or a C callback comes out as a SystemError,
    an ImportError or another error whose cause or context is the interrupt."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def _failed(exc: Exception) -> int:
    """One line on stderr for an exception that ended a command; its exit code."""
    try:
        raise exc
    except UsageError as exc:
        print(f"error: {one_line(str(exc))}", file=sys.stderr)
    except (ValueError, OSError, RuntimeError) as exc:
        print(f"motionhyst: error: {one_line(str(exc))}", file=sys.stderr)
    except MemoryError:  # an estimate missed: still one line, and the remedy
        print("motionhyst: error: out of memory; give a smaller problem (or a larger "
              "--max-memory, if the machine has it)", file=sys.stderr)
    except Exception as exc:  # a defect of the tool, not the input: one line, exit 1
        if os.environ.get(TRACEBACK_VARIABLE):
            raise
        print(f"motionhyst: internal error: {one_line(f'{type(exc).__name__}: {exc}')} (a "
              f"defect of motionhyst, please report it; {TRACEBACK_VARIABLE}=1 shows where)",
              file=sys.stderr)
        return EXIT_INTERNAL
    return EXIT_USAGE
