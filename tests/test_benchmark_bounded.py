"""``benchmark bouc-wen``: its progress is shown on a terminal only, as one status line
cleared as the run ends, and ``--max-seconds`` stops it in one line with or without ``--json``
(as ``benchmark emps``, tests/test_emps_bounded.py).  Before, each step was a line of its own
on stderr wherever it went, and ``--max-seconds 2`` bounded nothing (the run went on past
30 s of CPU time)."""

import sys
import time

import pytest

from motionhyst.cli import main

STOP = ("motionhyst: error: benchmark bouc-wen did not finish within the work budget of 0.3 s "
        "of CPU time (--max-seconds); give a larger --max-seconds")


@pytest.fixture
def endless(monkeypatch):
    """The benchmark's run replaced by one that says its first step, then computes without
    end (2 s of CPU time at most: then it fails, as a run the budget did not stop)."""
    import motionhyst.identify.benchmark as benchmark

    def run(directory, *, seed=0, progress=None):
        progress("training data: 2 x 5 periods of 8192 samples (6.5 s)")
        start = time.process_time()
        while time.process_time() - start < 2.0:
            sum(range(1000))
        raise RuntimeError("the work budget did not stop the run")

    monkeypatch.setattr(benchmark, "run_benchmark", run)


@pytest.mark.parametrize("terminal", [True, False])
@pytest.mark.parametrize("json", [True, False])
def test_a_run_over_max_seconds_is_one_line(tmp_path, capsys, monkeypatch, endless, json,
                                            terminal):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: terminal)
    assert main(["benchmark", "bouc-wen", "--data", str(tmp_path), "--max-seconds", "0.3",
                 *(["--json"] if json else [])]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1, err
    shown = err.rsplit("\r", 1)[-1]  # what a terminal shows: the status line was cleared
    assert shown.startswith(STOP), err
    # the status line ran on a terminal without --json, and nowhere else
    assert ("benchmark bouc-wen, training data" in err) == (terminal and not json), err
