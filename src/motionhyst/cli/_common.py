"""What every command of the ``motionhyst`` CLI shares: one-line user errors,
argparse number types, tables and number formatting, JSON output."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence

from motionhyst.core.textfmt import g, table

__all__ = [
    "EXIT_USAGE",
    "HeldWarnings",
    "Parser",
    "UsageError",
    "add_record_options",
    "finite",
    "g",
    "harmonic_count",
    "memory_size",
    "nonnegative",
    "old_spelling",
    "one_line",
    "positive",
    "print_json",
    "release_held",
    "say_later",
    "table",
    "whole_number",
]

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


class _StoreOnce(argparse._StoreAction):
    """An option's value, refused when the option is given again: argparse keeps the last
    (``--frequency 5 --frequency 10`` ran 10 Hz alone, the 5 Hz silently dropped)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = getattr(parser, "given", None)
        if given is not None and option_string is not None:
            if self.dest in given:
                many = (f", all its values after it ({option_string} A B ...)"
                        if self.nargs in ("+", "*") else "")
                parser.error(f"{option_string} is given twice; give it once{many}")
            given.add(self.dest)
        super().__call__(parser, namespace, values, option_string)


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage block); an empty value is an error,
    and so is an option given twice.

    An empty argument (``--time-series ""``, an unset shell variable) would
    otherwise count as an option not given, and an option given twice its last value:
    silently ignored.

    Examples
    --------
    >>> from motionhyst.cli import main
    >>> main(["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
    ...       "--s-max", "1e6", "--time-series", ""])      # one line on stderr, exit code 2
    2
    """

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)
        self.given: set[str] | None = None

    def error(self, message: str):
        raise UsageError(f"{self.prog}: {message}")

    def parse_known_args(self, args=None, namespace=None):
        self.given = set()
        namespace, extras = super().parse_known_args(args, namespace)
        for action in self._actions:
            value = getattr(namespace, action.dest, None)
            if value == "" or (isinstance(value, list) and "" in value):
                name = "/".join(action.option_strings) or action.metavar or action.dest
                self.error(f"{name} is empty; give a value")
        return namespace, extras


def _number(text: str, what: str, positive: bool | None) -> float:
    # here, not at the top: importing the command line loads no numpy, so main() installs its
    # signal handlers sooner (a Ctrl-C or SIGTERM before them is the interpreter's own end)
    from motionhyst.core.validation import MAGNITUDES

    try:
        v = float(text) + 0.0  # -0 is 0: its sign would reach a formula as a direction
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be a number, got {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{what} must be finite, got {text!r}")
    if v != 0.0 and not MAGNITUDES[0] <= abs(v) <= MAGNITUDES[1]:
        raise argparse.ArgumentTypeError(
            f"{text} is outside the magnitudes {MAGNITUDES[0]:g} to {MAGNITUDES[1]:g} (or 0, "
            f"SI units) that motionhyst computes with")
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


def whole_number(lo: int, hi: int, what: str) -> Callable[[str], int]:
    """argparse type: a whole number of `what` from `lo` to `hi`.

    Examples
    --------
    >>> whole_number(1, 20, "elements")("3")
    3
    """
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"must be from {lo} to {hi}, got {text!r}")
        return n

    parse.__doc__ = f"argparse type: a whole number of {what} from {lo} to {hi}."
    return parse


class _GivenSize(int):
    """A size in bytes that keeps the text it was given as (``.text``), for messages."""

    text = ""


def memory_size(text: str) -> int:
    """argparse type: a memory size such as ``4G`` or ``500M`` (bytes; the text given is its
    ``.text``, for messages that quote it).

    Examples
    --------
    >>> size = memory_size("4G")
    >>> size, size.text
    (4294967296, '4G')
    """
    from motionhyst.core.budget import parse_size

    try:
        size = _GivenSize(parse_size(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    size.text = text
    return size


harmonic_count = whole_number(1, 1000, "harmonics")
"""argparse type: a whole number of harmonics from 1 to 1000."""


MAX_MESSAGE = 1000
"""Most characters of a message on stderr (a file's header it quotes may be a whole file)."""


def one_line(text: str) -> str:
    """`text` as one line of plain text: line breaks joined, control characters escaped, cut.

    A message may quote what a user's file holds (a header, a cell); bytes of
    a binary file never reach the terminal as they are.

    Parameters
    ----------
    text : str
        The message.

    Returns
    -------
    str
        One printable line of at most :data:`MAX_MESSAGE` characters.

    Examples
    --------
    >>> print(one_line("bad header 'ti\\x1b[2Jme'\\nexpected time"))
    bad header 'ti\\x1b[2Jme'; expected time
    """
    text = "; ".join(part.strip() for part in text.strip().splitlines() if part.strip())
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    return text if len(text) <= MAX_MESSAGE else text[:MAX_MESSAGE - 3] + "..."


def print_json(obj) -> None:
    """Print `obj` as JSON (NumPy values converted, NaN as null)."""
    from motionhyst.core.jsonio import dumps

    print(dumps(obj))


# ------------------------------------------------------------------ records
def _columns(text: str) -> dict[str, str]:
    from motionhyst.io.records import RecordError, parse_columns

    try:
        return parse_columns(text)
    except RecordError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--columns: ")) from None


def _scale(text: str) -> dict[str, float]:
    from motionhyst.io.records import RecordError, parse_scale

    try:
        return parse_scale(text)
    except RecordError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--scale: ")) from None


class _Pairs(argparse.Action):
    """``--columns`` or ``--scale`` given more than once: their pairs together (a quantity
    named twice is an error), none replacing another's in silence."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = dict(getattr(namespace, self.dest, None) or {})
        for name in values:
            if name in given:
                parser.error(f"argument {option_string}: {name!r} is given twice")
        setattr(namespace, self.dest, {**given, **values})


def add_record_options(q: argparse.ArgumentParser, quantities: str, example: str) -> None:
    """Add ``--columns`` and ``--scale`` (:mod:`motionhyst.io.records`) to a record reader.

    `quantities` names the columns the command reads, `example` is a column map.  Either
    may be given more than once: the pairs of all count.

    Examples
    --------
    >>> q = Parser(prog="motionhyst predict")
    >>> add_record_options(q, "time,force", "time=t,force=vir")
    >>> q.parse_args(["--columns", "time=t", "--columns", "force=vir"]).columns
    {'time': 't', 'force': 'vir'}
    >>> try:
    ...     q.parse_args(["--scale", "force=2", "--scale", "force=3"])
    ... except UsageError as exc:
    ...     print(exc)
    motionhyst predict: argument --scale: 'force' is given twice
    """
    q.add_argument("--columns", type=_columns, action=_Pairs, metavar="NAME=COLUMN,...",
                   help=f"the record's own names (CSV columns or MATLAB variables, "
                        f"STRUCT.FIELD for a structure's field) of {quantities} (e.g. "
                        f"{example}; default: those names)")
    q.add_argument("--scale", type=_scale, action=_Pairs, metavar="NAME=GAIN,...",
                   help="multiply a column by a gain after reading it (e.g. force=35.15065: "
                        "a drive's volts to newtons)")


# ------------------------------------------------------------------ outputs and options
def add_force_option(q: argparse.ArgumentParser) -> None:
    """Add ``--force`` to a command that writes files (see :func:`output_file`)."""
    q.add_argument("--force", action="store_true",
                   help="replace an existing output file (never one of the command's inputs)")


def output_file(path: str, args: argparse.Namespace, option: str, inputs=()):
    """The :class:`~motionhyst.io.outputs.OutputFile` a command writes, checked now.

    Every command that writes a file calls this before it computes anything:
    the file must not exist unless ``--force`` was given (``args.force``), and
    is never one of `inputs` (the scenario, records, references, plant files
    the command reads).  Write it with ``with out.open() as fh: ...``: atomic,
    mode kept or from the umask, SIGINT/SIGTERM leave the old file.

    Raises
    ------
    motionhyst.io.outputs.OutputError
        One line naming `option` and the path (exit 2).
    """
    from motionhyst.io.outputs import OutputFile

    return OutputFile(path, force=bool(getattr(args, "force", False)), inputs=inputs,
                      option=option)


def refuse_unused(args: argparse.Namespace, options: Sequence[str], reason: str,
                  defaults: dict | None = None) -> None:
    """Exit 2 if any of `options` was given although it has no effect (`reason` says why).

    `options` are the command-line spellings (``"--profile"``); an option
    counts as given when its value differs from ``defaults`` (``None`` or
    ``False`` unless stated).
    """
    defaults = defaults or {}
    for option in options:
        dest = option.lstrip("-").replace("-", "_")
        value = getattr(args, dest, None)
        if value is not None and value is not False and value != defaults.get(option):
            raise UsageError(f"motionhyst {args.command}: {option} has no effect {reason}")


def distinct(values: Sequence[float] | None, option: str, command: str):
    """`values` of a list option, refused if one is given twice (exit 2).

    Examples
    --------
    >>> distinct([5.0, 10.0], "--frequency", "analyze")
    [5.0, 10.0]
    """
    if values is None:
        return None
    seen = set()
    for v in values:
        if v in seen:
            raise UsageError(f"motionhyst {command}: {option} {v:g} is given twice")
        seen.add(v)
    return list(values)


def scenario_frequencies(sc, given: Sequence[float] | None, command: str) -> list[float]:
    """The frequencies a sine analysis of scenario `sc` runs at (`given` by --frequency, or
    the scenario's ``[reference] frequencies``), refused where the loop's model means nothing
    (:func:`~motionhyst.analysis.plausibility.check_frequencies`): decided from the
    scenario's numbers where they give the loop's poles, before python-control loads.

    Parameters
    ----------
    sc : Scenario
        The command's scenario, read without building its loop (an open-loop system, an
        unstable loop are refused here).
    given : sequence of float or None
        The --frequency values.
    command : str
        The command's name, for the message.
    """
    from motionhyst.analysis.plausibility import check_frequencies

    freqs = list(given) if given else sc.frequencies  # an open-loop system is refused here
    fastest = sc.fastest_pole()  # an unstable loop is refused here; None: not known yet
    rate = getattr(sc.model.controller, "sample_rate_hz", None)
    if sc.model.stage is None or (fastest is None and rate is None):
        return freqs  # the loop's own check (analyze, steady) decides once it is built
    try:
        check_frequencies(freqs, None if fastest is None else fastest / (2 * math.pi), rate)
    except ValueError as exc:
        where = "--frequency" if given else f"{sc.source}: [reference] frequencies:"
        raise UsageError(f"motionhyst {command}: {where} {exc}") from None
    return freqs


# ----------------------------------------------------------------- plausibility warnings
class HeldWarnings:
    """The warning lines of a running command, held while it checks its input.

    A command reads, judges and sizes its input before its work; a warning raised meanwhile
    (a stage's mass off by orders of magnitude, a record's time in ms) is held
    (:meth:`hold`) until those checks pass (:meth:`release`, from :func:`release_held`),
    then shown at once, and every later one as it comes.  A refusal before the work
    (:meth:`drop`) is then the one line it says; an interruption shows them
    (:meth:`release`) before ``motionhyst: interrupted``.  Nothing is held in a forked
    worker: its lines are shown as they come.

    Examples
    --------
    >>> import contextlib, sys
    >>> with contextlib.redirect_stderr(sys.stdout):       # to show the lines here
    ...     held = HeldWarnings()
    ...     held.hold()
    ...     held.say("motionhyst: warning: steady: a line")    # held: nothing shown yet
    ...     held.release()                                     # the checks passed
    ...     held.say("motionhyst: warning: steady: another")   # shown as it comes
    motionhyst: warning: steady: a line
    motionhyst: warning: steady: another
    """

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.holding = False
        self.pid = os.getpid()
        #: What ends a refusal's one line (an old spelling's new one: :func:`old_spelling`)
        self.postscript = ""

    def hold(self) -> None:
        """Hold the lines from now on, until :meth:`release` or :meth:`drop`."""
        self.holding = True

    def say(self, line: str) -> None:
        """Show `line` on stderr, or hold it while the command checks its input."""
        if self.holding and os.getpid() == self.pid:
            self.lines.append(line)
        else:
            _write_lines([line])

    def release(self) -> None:
        """Show the lines held (one write) and every later one as it comes.

        Ctrl-C and SIGTERM are blocked while they are written and forgotten: a signal then
        comes after, never between (its interruption would show them again, or, forgotten
        first, lose them)."""
        self.holding = False
        if not self.lines:
            return
        mask = getattr(signal, "pthread_sigmask", None)
        previous = None
        try:
            if mask is not None:
                previous = mask(signal.SIG_BLOCK, ())
                mask(signal.SIG_BLOCK, (signal.SIGINT, signal.SIGTERM))
            _write_lines(self.lines)
            self.lines = []
        finally:
            if previous is not None:
                mask(signal.SIG_SETMASK, previous)

    def drop(self) -> None:
        """Forget the lines held: a refusal of the input says all, in one line."""
        self.holding = False
        self.lines = []


_RUNNING: list[HeldWarnings] = []
"""The held warnings of the command running (:func:`warnings_on_stderr`), if any."""


def _write_lines(lines: Sequence[str]) -> None:
    """`lines` on stderr in one write; a stderr that cannot be written loses them."""
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write("".join(f"{line}\n" for line in lines))
        sys.stderr.flush()


def say_later(line: str) -> None:
    """`line` (a warning or notice of the running command) on stderr, held with its warnings
    while the command checks its input (:class:`HeldWarnings`); at once outside a command.

    Parameters
    ----------
    line : str
        The whole line, ``motionhyst: warning: ...``.

    Examples
    --------
    >>> import contextlib, sys
    >>> with contextlib.redirect_stderr(sys.stdout):       # to show the line here
    ...     say_later("motionhyst: warning: analyze: a line")
    motionhyst: warning: analyze: a line
    """
    if _RUNNING:
        _RUNNING[-1].say(line)
    else:
        _write_lines([line])


def old_spelling(notice: str, postscript: str) -> None:
    """The running command was given in an old spelling: `notice` (the whole line) is shown
    with its warnings (:func:`say_later`), and a refusal, which drops them to be one line,
    ends that line with ``(postscript)``: the user learns the new spelling either way.

    Parameters
    ----------
    notice : str
        The line ``motionhyst COMMAND: ... is now ...``.
    postscript : str
        Its short form, ending a refusal's line.

    Examples
    --------
    >>> import contextlib, sys
    >>> with contextlib.redirect_stderr(sys.stdout):       # outside a command: at once
    ...     old_spelling("motionhyst old: the command is now `motionhyst new`",
    ...                  "`motionhyst old` is now `motionhyst new`")
    motionhyst old: the command is now `motionhyst new`
    """
    say_later(notice)
    if _RUNNING:
        _RUNNING[-1].postscript = postscript


def release_held() -> None:
    """The running command's checks before its work have passed (its input read, judged and
    sized): the warnings held so far are shown now, the later ones as they come.

    Every command calls it where its long work starts; its first line of results calls it
    too, so its warnings come before them.

    Examples
    --------
    >>> release_held()  # nothing held outside a command
    """
    if _RUNNING:
        _RUNNING[-1].release()


@contextlib.contextmanager
def warnings_on_stderr(command: str, held: HeldWarnings | None = None) -> Iterator[None]:
    """Show each :class:`~motionhyst.core.warnings.MotionhystWarning` raised inside as one line
    ``motionhyst: warning: COMMAND: message`` on stderr, every time: when it is raised, or,
    while `held` holds (:class:`HeldWarnings`: the command checks its input), once the checks
    pass.

    Another library's warning (numpy's ``invalid value encountered``, say) is one
    such line as well, naming its kind, never a source path and line (with
    ``MOTIONHYST_TRACEBACK`` set, as Python shows it).  The command still
    succeeds (exit 0): a warning says a number may mean less than it seems,
    not that it is wrong.

    Parameters
    ----------
    command : str
        The command's name, put before each message.
    held : HeldWarnings, optional
        Where the lines are held; shown when the block ends normally.  When it ends in an
        exception, its caller decides: :meth:`~HeldWarnings.drop` for a refusal,
        :meth:`~HeldWarnings.release` for an interruption.

    Examples
    --------
    >>> import contextlib, sys
    >>> from motionhyst.core.warnings import warn
    >>> here = contextlib.redirect_stderr(sys.stdout)      # to show the lines here
    >>> with here, warnings_on_stderr("analyze"):
    ...     warn("0.05 Hz below f* = 0.15 Hz (eq. 13)")
    motionhyst: warning: analyze: 0.05 Hz below f* = 0.15 Hz (eq. 13)
    >>> held = HeldWarnings()
    >>> with contextlib.redirect_stderr(sys.stdout):
    ...     try:
    ...         with warnings_on_stderr("analyze", held):
    ...             held.hold()                            # the command checks its input
    ...             warn("0.05 Hz below f* = 0.15 Hz (eq. 13)")
    ...             raise ValueError("refused")            # a refusal before the work
    ...     except ValueError:
    ...         held.drop()                                # its one line is all it says
    """
    from motionhyst.core.compiled import before_notice
    from motionhyst.core.warnings import MotionhystWarning

    held = HeldWarnings() if held is None else held
    _RUNNING.append(held)
    # a first compilation's notice (seconds to minutes of work among the checks) comes
    # after the warnings held so far, in this process (a forked worker holds none)
    pid = os.getpid()
    hook = before_notice(lambda: held.release() if os.getpid() == pid else None)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", MotionhystWarning)
            python_shows = warnings.showwarning

            def show(message, category, filename, lineno, file=None, line=None):
                if issubclass(category, MotionhystWarning):
                    held.say(f"motionhyst: warning: {one_line(f'{command}: {message}')}")
                elif os.environ.get("MOTIONHYST_TRACEBACK"):
                    held.release()
                    python_shows(message, category, filename, lineno, file, line)
                else:
                    text = f"{command}: {category.__name__}: {message}"
                    held.say(f"motionhyst: warning: {one_line(text)}")

            warnings.showwarning = show
            yield
    finally:
        _RUNNING.remove(held)
        before_notice(hook)
    held.release()


def warn_plant_fit(sc) -> None:
    """Fit a measured plant now, before the command's work: its fit's warnings
    (:attr:`motionhyst.FrfFit.warnings`, issued by :meth:`Scenario.plant
    <motionhyst.scenario.Scenario.plant>` as
    :class:`~motionhyst.core.warnings.MotionhystWarning`, one each) come first.

    The data are then not what a rigid body plus modes describes (a stiffness
    to ground, errors far above the noise), so every number computed on the
    fitted plant is in doubt.  Nothing for a modelled stage.

    Parameters
    ----------
    sc : Scenario
        The command's scenario.
    """
    sc.plant_fit()


@contextlib.contextmanager
def in_the_commands_terms(sc, remedy: str) -> Iterator[None]:
    """The library's refusals inside, said in the terms of a command whose options differ
    from the library function's arguments.

    A run too large (:class:`~motionhyst.time.steps.RunTooLarge`) is refused with the
    command's `remedy` in place of the library's (``shorten the duration`` names an
    argument ``scan`` does not have); other refusals keep theirs.  A link's implicit step
    that did not converge
    (:class:`~motionhyst.time.kernel.StepNotConverged`) in a command whose step is its own
    (``scan``, ``simulate``: set from the loop's poles and the reference, no option for
    it): the library's remedy (a smaller ``dt``, more ``substeps``) names arguments the
    command does not have, so the message names the scenario's ``[hysteresis]``, what its
    user can change.

    Parameters
    ----------
    sc : Scenario
        The command's scenario.
    remedy : str
        What the command's user can change to make a run smaller (its options).
    """
    from motionhyst.time.kernel import StepNotConverged
    from motionhyst.time.steps import RunTooLarge

    try:
        yield
    except RunTooLarge as exc:
        elements = " elements" in exc.cause and "link" in exc.cause
        raise exc.with_remedy(remedy + (", or give the link fewer elements ([hysteresis])"
                                        if elements else "")) from None
    except StepNotConverged as exc:
        raise StepNotConverged(f"{sc.source}: [hysteresis]: {exc.what}, which the command "
                               f"sets from the loop's poles and the reference",
                               "is the link's stiffness or damping meant (in SI units)?"
                               ) from None


def check_link_damping_for(sc, step: float | None = None) -> None:
    """Refuse, before a run of ``scan`` or ``simulate`` (whose step is their own: set from the
    loop's poles and the reference, or a sampled controller's period split for the stage's
    fastest mode), a scenario whose link is too strongly damped for that step
    (:func:`~motionhyst.time.steps.check_link_damping`), naming its ``[hysteresis]``: the run
    would stop at the stage's first motion, after its loop was built, or end in no solution.

    Parameters
    ----------
    sc : Scenario
        The command's scenario.
    step : float, optional
        A continuous loop's step [s], known before its loop is built; None: the scenario's
        sampled controller's fine steps (:func:`~motionhyst.time.steps.sampled_steps`).
    """
    from motionhyst.scenario import ScenarioError
    from motionhyst.time.steps import check_link_damping, sampled_steps

    set_by = "set from the loop's poles and the reference"
    shorter = 0.0
    if step is None:
        c = sc.model.controller
        rate, delay = c.sample_rate_hz, c.delay_samples or 0.0
        step, shorter = sampled_steps(sc.plant(), sc.hysteresis(), rate, delay)
        set_by = (f"the sampled controller's period ({rate:g} Hz, {delay:g} samples late) "
                  f"split for the stage's fastest mode")
    try:
        check_link_damping(sc.hysteresis(), sc.plant(), step, shorter=shorter)
    except ValueError as exc:
        raise ScenarioError(f"{sc.source}: [hysteresis]: {exc}; the step is the command's, "
                            f"{set_by}: is the link's damping meant (in SI units)?") from None


def fast_pole(sc, pole: float) -> str:
    """Why a loop's fastest closed-loop pole `pole` [rad/s] is beyond a motion stage's
    (:data:`~motionhyst.plants.registry.PLAUSIBLE_POLE_HZ`), for a refusal of the many
    steps it takes: the implausible ``[stage]`` value that likely sets it, else a question
    about units; "" for a pole within a motion stage's.

    Parameters
    ----------
    sc : Scenario
        The command's scenario.
    pole : float
        Its loop's fastest closed-loop pole [rad/s].
    """
    from motionhyst.plants.registry import PLAUSIBLE_POLE_HZ
    from motionhyst.scenario.schema import implausible_stage

    if pole / math.tau <= PLAUSIBLE_POLE_HZ:
        return ""
    named = implausible_stage(sc)
    return (f"beyond a motion stage's {g(PLAUSIBLE_POLE_HZ)} Hz: "
            + (named[0] if named else f"are {sc.source}'s [stage] and [controller] values in "
               f"SI units?"))


def refuse_along_stroke_for(sc, command: str) -> None:
    """Refuse, before the loop is built, a command that compares with the describing function
    (``steady``, ``analyze``, ``stability``, ``reproduce``) for a scenario whose link or
    feedforward model varies along the stroke (``along``): it has none
    (:data:`~motionhyst.hysteresis.along_stroke.NO_DESCRIBING_FUNCTION`).

    Parameters
    ----------
    sc : Scenario
        The command's scenario.
    command : str
        The command, named in the message.
    """
    if sc.along_stroke:
        from motionhyst.hysteresis.along_stroke import NO_DESCRIBING_FUNCTION

        raise UsageError(f"{command}: {sc.source}: "
                         f"{NO_DESCRIBING_FUNCTION.format(key=', '.join(sc.along_keys))}")
