"""Warnings held while a command checks its input (issue 26; reviews A16 H2, B16 M2): a refusal
of the input is its one line even after warnings, and no warning is lost: those held are shown
as the work starts, before ``motionhyst: interrupted`` when the run is stopped, and a memory
budget beyond the machine is warned of at once, before a run the system may kill.
"""

from __future__ import annotations

import io
import os
import re
import resource
import select
import signal
import subprocess
import time
import types
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

LIGHT = ("motionhyst: warning: {command}: s.toml: [stage] m1 = 0.0009 kg, a factor 1.1 below "
         "the 0.001-10000 kg of motion stages: is it in kg?")
"""The warning a stage of 0.9 g gives once its loop is built."""

SEVEN_HZ = ("motionhyst: error: the steady state of a loop sampled at 10000 Hz needs a whole "
            "number of samples per period: 7 Hz has 1428.57; the nearest frequency that has "
            "one is 6.997900629811 Hz (1429 samples)")


def _light_10khz(frequencies: str = "[5.0, 10.0]") -> str:
    """The paper's loop at 10 kHz with an actuated mass of 0.9 g (warned of) and the
    reference's `frequencies`."""
    text = (EXAMPLES / "paper_10khz.toml").read_text()
    assert "m1 = 5.0" in text
    text = text.replace("m1 = 5.0", "m1 = 0.0009", 1)
    return re.sub(r"frequencies = \[[^\]]*\]", f"frequencies = {frequencies}", text)


def _mm_record(path: Path) -> None:
    """A force-displacement record in mm (a 200 'm' stroke: warned of) whose force is noise."""
    t = np.arange(4000) / 1000.0
    x = 200.0 * np.sin(2 * np.pi * t)
    w = 0.01 * np.random.default_rng(0).standard_normal(t.size)
    np.savetxt(path, np.column_stack([t, x, w]), delimiter=",",
               header="time,displacement,force", comments="", fmt="%.9g")


def _days_record(path: Path) -> None:
    """A force record of 3 s at 1 kHz stamped in days (warned of), not whole periods."""
    n = np.arange(3000)
    np.savetxt(path, np.column_stack([n / 1000.0 / 86400.0, np.sin(2 * np.pi * 1.3 * n / 1e3)]),
               delimiter=",", header="time,force", comments="", fmt="%.12g")


OPEN_LOOP = ('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
             '[hysteresis]\nmodel = "jenkins"\nk = 100.0\nfc = 1.0\n')

REFUSED_AFTER_A_WARNING = [
    # the stage's mass is warned of as its loop is built; 7 Hz is no whole number of samples
    ("steady", {"s.toml": _light_10khz()}, ["steady", "s.toml", "--frequency", "7"], SEVEN_HZ),
    # a displacement in mm is warned of as the record is read; its force follows nothing
    ("identify", {"r.csv": _mm_record}, ["identify", "r.csv"],
     "motionhyst: error: r.csv: no hysteresis in the record: its force does not follow"),
    # a time in days is warned of as the record is read; it is no whole number of periods
    ("predict", {"m.toml": OPEN_LOOP, "f.csv": _days_record},
     ["predict", "m.toml", "f.csv", "--out", "p.csv", "--periodic"],
     "motionhyst: error: f.csv: not whole periods of a periodic signal"),
]


@pytest.mark.parametrize(("files", "argv", "error"), [c[1:] for c in REFUSED_AFTER_A_WARNING],
                         ids=[c[0] for c in REFUSED_AFTER_A_WARNING])
def test_a_refusal_after_a_warning_is_its_one_line(tmp_path, capsys, monkeypatch, files, argv,
                                                   error):
    """main 5c12916: the warning, then the refusal (2 lines)."""
    populate(tmp_path, files)
    before = snapshot(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith(error), err
    assert snapshot(tmp_path) == before


def test_reproduce_refusing_its_scenario_after_a_warning_is_one_line_before_the_work(tmp_path):
    """Review B16 M2's case: reproduce refuses a scenario once its loop is built, after the
    stage's mass was warned of.  The 10 kHz loop's 7 Hz has no whole number of samples: main
    5c12916 said it after the analysis and the first steady states (230 s at a load of 16),
    below the mass's warning (2 lines); now before any steady state, in one line, no folder
    made."""
    populate(tmp_path, {"s.toml": _light_10khz("[5.0, 7.0]")})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["reproduce", "s.toml", "--out", "o"], tmp_path,
                                   limit=limited_process.RUN_LIMIT)
    assert line == SEVEN_HZ
    assert snapshot(tmp_path) == before


def test_a_run_that_answers_shows_the_warnings_held(tmp_path, capsys, monkeypatch):
    """The mass's warning, held while the loop's frequencies are checked, is shown as the
    steady state starts, and the answer follows (exit 0)."""
    populate(tmp_path, {"s.toml": _light_10khz()})
    monkeypatch.chdir(tmp_path)
    assert main(["steady", "s.toml", "--frequency", "5", "--no-floquet"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("Exact periodic steady state of s.toml")
    assert err.splitlines()[0] == LIGHT.format(command="steady"), err


def _command_that(monkeypatch, then: BaseException, warned: str = "the input looks odd"):
    """``motionhyst df`` replaced by a command that warns while it checks its input and then
    raises `then`."""
    from motionhyst.cli import df
    from motionhyst.core.warnings import warn

    def run(args):
        warn(warned)
        raise then

    monkeypatch.setattr(df, "run", run)


@pytest.mark.parametrize("interrupt", [KeyboardInterrupt("SIGINT"), KeyboardInterrupt("SIGTERM")])
def test_an_interruption_while_the_input_is_checked_shows_the_warnings_held(
        monkeypatch, capsys, interrupt):
    """A signal before the checks pass: the warnings held so far, then 'interrupted' (130)."""
    _command_that(monkeypatch, interrupt)
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 130
    assert capsys.readouterr().err.splitlines() == [
        "motionhyst: warning: df: the input looks odd", "motionhyst: interrupted"]


def test_a_defect_of_the_tool_shows_the_warnings_held_before_its_line(monkeypatch, capsys):
    """Not a refusal of the input: nothing is hidden (exit 1)."""
    monkeypatch.delenv("MOTIONHYST_TRACEBACK", raising=False)
    _command_that(monkeypatch, TypeError("a defect"))
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 1
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2 and lines[0] == "motionhyst: warning: df: the input looks odd"
    assert lines[1].startswith("motionhyst: internal error: TypeError: a defect"), lines


def _first_line(proc: subprocess.Popen, timeout: float) -> bytes:
    """What `proc` writes on stderr up to its first whole line (or its end, or `timeout` s)."""
    buf, end = b"", time.monotonic() + timeout
    while b"\n" not in buf and time.monotonic() < end:
        if select.select([proc.stderr], [], [], 0.5)[0]:
            chunk = os.read(proc.stderr.fileno(), 65536)
            if not chunk:
                break
            buf += chunk
    return buf


def _ms_reference(path: Path) -> None:
    """0.5 s of a 2 Hz setpoint at 50 Hz logged in ms: read as 500 s, minutes of run."""
    t = np.arange(26) / 50.0
    np.savetxt(path, np.column_stack([1e3 * t, 1e-3 * np.sin(2 * np.pi * 2.0 * t)]),
               delimiter=",", header="time,position", comments="", fmt="%.10g")


@pytest.mark.parametrize("name", ["SIGTERM", "SIGINT"])
def test_a_run_interrupted_after_its_checks_shows_its_warnings_then_interrupted(tmp_path, name):
    """The unit warning of a reference logged in ms is meant to be read during the run it
    lengthens: signalled once the run has started (its warning on stderr), the command shows
    it, then 'motionhyst: interrupted', exit 130, the old output intact and no other file
    (branch sig16 held it to the end and dropped it on the interruption: review A16 H2)."""
    populate(tmp_path, {"ms.csv": _ms_reference, "o.csv": "old\n"})
    before = snapshot(tmp_path)
    with limited_process.ended(limited_process.popen(
            ["simulate", "--reference-csv", "ms.csv", "--time-series", "o.csv", "--force"],
            tmp_path)) as proc:
        first = _first_line(proc, timeout=600)
        assert proc.poll() is None, (proc.returncode, first)
        proc.send_signal(getattr(signal, name))
        _, rest = proc.communicate(timeout=300)
    # numba's first-use notice goes straight to stderr, held or not: not a warning
    lines = [line for line in (first + rest).decode().splitlines()
             if not line.startswith("motionhyst: compiling")]
    assert proc.returncode == 130, lines
    assert lines == ["motionhyst: warning: simulate: ms.csv: the reference is sampled at 0.05 "
                     "Hz (26 samples over 500 s): if its time is not in seconds, scale it "
                     "(--scale time=0.001 for ms)", "motionhyst: interrupted"], lines
    assert snapshot(tmp_path) == before


def test_the_budget_beyond_the_machine_is_warned_of_before_a_kill(tmp_path):
    """The warning that a run may be killed by the system is shown at once: a run of 300 s
    killed (SIGKILL) once it has started has said it (held to the end, it died with it)."""
    proc = limited_process.popen(["simulate", "--max-memory", "100T", "--time-series", "o.csv",
                                  "--frequency", "5", "--duration", "300"], tmp_path,
                                 limit=resource.RLIM_INFINITY)
    try:
        first = _first_line(proc, timeout=600)
        assert proc.poll() is None, (proc.returncode, first)
    finally:
        proc.kill()
        proc.communicate()
    lines = first.decode().splitlines()
    assert len(lines) == 1 and re.fullmatch(
        r"motionhyst: warning: simulate: --max-memory 100T \(110 TB\) is more than the [0-9.]+ "
        r"[kMGT]B of memory this machine has: a computation that large would be killed by the "
        r"system, not refused", lines[0]), lines
    assert list(tmp_path.iterdir()) == []


def _mm_hysteresis_record(path: Path) -> None:
    """A force-displacement record in mm (a 178 'm' stroke: warned of) of a Jenkins element
    (k 1 N/'m', fc 50 N): a link the fit finds."""
    t = np.arange(4000) / 1000.0
    x = 200.0 * np.sin(2 * np.pi * t) + 50.0 * np.sin(6 * np.pi * t)
    w, force = np.zeros_like(x), 0.0
    for i in range(1, x.size):
        force = min(max(force + (x[i] - x[i - 1]), -50.0), 50.0)
        w[i] = force
    w += 0.01 * np.random.default_rng(0).standard_normal(t.size)
    np.savetxt(path, np.column_stack([t, x, w]), delimiter=",",
               header="time,displacement,force", comments="", fmt="%.9g")


MM_STROKE = ("motionhyst: warning: identify: r.csv: displacement reaches 178 m, beyond the 100 m "
             "of a motion stage's stroke: if the positions are not in metres, scale them (--scale "
             "displacement=0.001 for mm, 1e-6 for um)")
"""The warning :func:`_mm_hysteresis_record` gets from identify."""


def test_a_first_compilation_says_nothing_where_stderr_is_not_a_terminal(tmp_path):
    """identify on a cold cache (a fresh install), stderr a pipe as a script has it (review
    B21 F5: the notice of the first compilation made a refusal after it two lines): the
    command says only what it says on a warm cache, the record's unit warning.  Run as the
    console script runs, the notice not left out, with a cache folder of its own."""
    import sys

    populate(tmp_path, {"r.csv": _mm_hysteresis_record})
    proc = subprocess.run([sys.executable, "-m", "motionhyst.cli", "identify", "r.csv"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=900,
                          env=limited_process.environment(NUMBA_CACHE_DIR=str(tmp_path / "c")))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("Maxwell-slip hysteresis identified from r.csv")
    assert list((tmp_path / "c").rglob("*.nbi")), "no kernel was compiled into the cache"
    assert proc.stderr.splitlines() == [MM_STROKE]


class _Terminal(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("terminal", [True, False])
def test_the_warnings_held_come_before_a_first_compilation_s_notice_on_a_terminal(
        monkeypatch, terminal):
    """Review B17 L1: on a terminal the warnings held while a command checks its input come
    before the notice of a first compilation (seconds to minutes), not after it.  Review B21
    F5: elsewhere there is no notice, and the warnings stay held (a refusal then drops them
    and is its one line)."""
    import contextlib

    from motionhyst.cli._common import HeldWarnings, warnings_on_stderr
    from motionhyst.core import compiled
    from motionhyst.core.warnings import warn

    def kernel():
        """A function of the package, as the compile event names its dispatcher's."""

    kernel.__module__ = "motionhyst.hysteresis.jenkins"
    monkeypatch.setitem(compiled._STATE, "announced", False)
    monkeypatch.setitem(compiled._STATE, "cache", True)
    err = _Terminal() if terminal else io.StringIO()
    held = HeldWarnings()
    with contextlib.redirect_stderr(err):
        with pytest.raises(ValueError), warnings_on_stderr("identify", held):
            held.hold()
            warn("r.csv: displacement reaches 178 m")
            compiled._announce(types.SimpleNamespace(py_func=kernel))
            raise ValueError("a refusal after the compilation")
        held.drop()
    notice = "motionhyst: compiling numerical kernels on first use (cached for later runs) ..."
    assert err.getvalue().splitlines() == (
        ["motionhyst: warning: identify: r.csv: displacement reaches 178 m", notice]
        if terminal else [])


OLD_SPELLING = " (`motionhyst simulate` without --time-series is now `motionhyst steady`)"
NOTICE = ("motionhyst simulate: without --time-series this computes the periodic steady state; "
          "the command for that is now `motionhyst steady`")


@pytest.mark.parametrize(("files", "argv", "error"), [
    # refused once the loop is built, after the stage's mass was warned of
    ({"s.toml": _light_10khz()}, ["simulate", "s.toml", "--frequency", "7"], SEVEN_HZ),
    # refused as the scenario is read
    ({}, ["simulate", "none.toml"], "motionhyst: error: none.toml: cannot read"),
    # refused as the options are read
    ({"s.toml": _light_10khz()}, ["simulate", "s.toml", "--duration", "1"],
     "motionhyst: error: simulate: --duration has no effect without --time-series")])
def test_an_old_spelling_s_refusal_is_one_line_that_names_the_new_one(
        tmp_path, capsys, monkeypatch, files, argv, error):
    """Review B18 M2: the old spelling's notice was held with the warnings and dropped by a
    refusal (the user of the old spelling never told the new one); the notice before the
    refusal would be two lines.  Now the refusal's one line ends with the new spelling."""
    populate(tmp_path, files)
    before = snapshot(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1, err
    assert err.startswith(error) and err.endswith(OLD_SPELLING + "\n"), err
    assert snapshot(tmp_path) == before


def test_an_old_spelling_s_answer_comes_with_its_notice(tmp_path, capsys, monkeypatch):
    """An answer shows the notice first (a refusal of the new spelling has no postscript)."""
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", str(EXAMPLES / "paper.toml"), "--frequency", "5"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("Exact periodic steady state") and err.splitlines()[0] == NOTICE
    assert main(["steady", "none.toml"]) == 2
    assert capsys.readouterr().err.endswith("cannot read (No such file or directory)\n")
