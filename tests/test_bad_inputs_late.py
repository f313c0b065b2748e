"""Inputs that ran to an answer without a word, or refused only after the work (issue 26:
every refusal within 2 s of start, 0 exit-0 answers from undetermined inputs): an exposure
window that holds one sample, a controller rate that cannot resolve the setpoint.

The corpus cases run the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and assert exit code 2, one
line on stderr naming the option and the cause (no traceback), nothing on stdout, and every
file there before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import limited_process
import pytest
from file_trees import populate, snapshot

from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
SCAN = ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
        "1000", "--s-max", "1e6", "--compensation", "none"]
BASE = {"s.toml": PAPER, "notes.txt": "my notes"}

# (id, extra files, argv, words of the one line on stderr)
CASES = [
    # Table I's loop steps at 3.62e-5 s: a window of 1 ns holds one sample, MSD 0 everywhere
    ("scan-window-shorter-than-a-step", {}, [*SCAN, "--window", "1e-9"],
     ["scan: --window: the exposure window 1e-09 s is shorter than two time steps of the run "
      "(3.62e-05 s): it holds one sample, whose moving standard deviation is 0",
      "give a longer --window (at least 7.23e-05 s)"]),
    ("scan-window-of-one-sample", {}, [*SCAN, "--window", "7e-5"],
     ["--window: the exposure window 7e-05 s is shorter than two time steps"]),
    # the setpoint's acceleration lasts 21 ms: on 1 s samples the move of 0.142 s takes 9 s
    ("scan-rate-slower-than-the-move", {}, [*SCAN, "--rate", "1"],
     ["scan: --rate 1 Hz: its sample period 1 s is longer than the setpoint's acceleration "
      "(0.021 s)", "(0.142 s -> 9 s, peak acceleration 0.05 m/s^2 for --a-max 10)",
      "give the controller's rate (above 47.6 Hz)"]),
    # 100 Hz resolves the setpoint (a warning) but not the carry-over setpoint at 0.1 mm/s:
    # the refusal alone, one line
    ("scan-rate-of-the-carry-over", {},
     [*SCAN[:-1], "ilc", "--other-speed", "1e-4", "--rate", "100"],
     ["--rate 100 Hz: its sample period 0.01 s is longer than the carry-over setpoint "
      "(--other-length, --other-speed)'s acceleration"]),
]


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv, words):
    populate(tmp_path, {**BASE, **files})
    before = snapshot(tmp_path)
    line = limited_process.refusal(argv, tmp_path)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(tmp_path) == before


def test_a_rate_that_stretches_the_setpoint_is_said(capsys):
    """A rate of 100 Hz resolves the setpoint's 21 ms of acceleration, but its switching
    instants on 10 ms samples stretch the move from 0.142 s to 0.18 s, its peak acceleration
    from 9.5 to 5 m/s^2: an answer, with a warning naming --rate."""
    assert main([*SCAN[:1], *SCAN[2:], "--rate", "100"]) == 0
    captured = capsys.readouterr()
    warned = [line for line in captured.err.splitlines() if line.startswith("motionhyst: warn")]
    assert warned == ["motionhyst: warning: scan: --rate 100 Hz: the setpoint's switching "
                      "instants on its samples stretch the move (0.142 s -> 0.18 s, peak "
                      "acceleration 5 m/s^2 for --a-max 10)"], captured.err
    assert "scan of 0.01 m at 0.1 m/s: 0.18 s; peak acceleration 5 m/s^2" in captured.out
