"""``benchmark emps --max-seconds``: the run is bounded.  Before, the option bounded nothing
(6.5 min of CPU time at ``--max-seconds 1`` on DATA_EMPS): a run estimated above it is
refused before its first fit, and one that runs over it is stopped, each in one line, exit 2."""

import numpy as np
import pytest
from scipy.io import savemat

from motionhyst.cli import main
from motionhyst.identify.emps import DRIVE_GAIN
from motionhyst.identify.emps_reference import reference_system

PERIOD = 1000


@pytest.fixture
def data(tmp_path, monkeypatch):
    """A folder with a generated DATA_EMPS.mat of four periods of 1000 samples."""
    import motionhyst.identify.emps as emps

    t = np.arange(4 * PERIOD) / 1000.0
    u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    y = reference_system().simulate(t, u).displacement
    savemat(tmp_path / "DATA_EMPS.mat", {"t": t[:, None], "vir": u[:, None] / DRIVE_GAIN,
                                         "qm": y[:, None], "gtau": DRIVE_GAIN})
    monkeypatch.setattr(emps, "PERIOD", PERIOD)
    return tmp_path


def test_a_run_estimated_above_max_seconds_is_refused_before_it_starts(data, capsys,
                                                                         monkeypatch):
    """Three models on both halves of 4000 samples, 1 ms a sample: about 12 s, refused at
    --max-seconds 1 before any fit (identify_io is never called)."""
    import motionhyst.identify.emps as emps

    fits = []

    def stub(*args, **kwargs):
        fits.append(args)
        raise ValueError("a stub's fit")

    monkeypatch.setattr(emps, "identify_io", stub)
    assert main(["benchmark", "emps", "--data", str(data), "--max-seconds", "1"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == ("motionhyst: error: benchmark emps would take about 12 s, above the work "
                   "budget of 1 s (--max-seconds); give fewer --models, one split (--periods "
                   "1-2), or a larger --max-seconds\n")
    assert fits == []
    # fewer models, one split: 2 s, within 3 s: it starts (its one fit a stub that fails)
    assert main(["benchmark", "emps", "--data", str(data), "--max-seconds", "3", "--periods",
                 "1-2", "--models", "coulomb", "--json"]) == 2
    assert len(fits) == 1
    assert "1 of 1 fits failed" in capsys.readouterr().err


@pytest.mark.parametrize("json", [True, False])
def test_a_run_over_max_seconds_is_stopped(data, capsys, monkeypatch, json):
    """The estimate set aside (a machine slower than the nominal cost), the fits themselves
    are stopped at --max-seconds of CPU time: one line, exit 2, no table.  Without --json on a
    terminal the progress is one status line, cleared before the refusal (review C19 M4: each
    fit's progress was a line of its own, printed before the refusal's)."""
    import sys

    import motionhyst.cli.benchmark as command

    monkeypatch.setattr(command, "EMPS_SECONDS_PER_SAMPLE", 0.0)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main(["benchmark", "emps", "--data", str(data), "--max-seconds", "0.5",
                 "--models", "jenkins", *(["--json"] if json else [])]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1
    shown = err.rsplit("\r", 1)[-1]  # what the terminal shows: the status line was cleared
    assert shown.startswith("motionhyst: error: benchmark emps did not finish within the work "
                            "budget of 0.5 s of CPU time (--max-seconds); give fewer --models")
    assert ("benchmark emps, jenkins: identifying" in err) != json  # the status line ran
