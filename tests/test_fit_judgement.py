"""How an input-output fit is judged before it is a result (issue 21, "honest results").

A fit whose check run (the identified model run as ``predict`` runs it) is above the memory
budget did not fail: the budget refused the run, and the user's remedy is ``--max-memory``.
The record checks that refuse records of another stage (inertia, one stage) run once per
command, before the search."""

from __future__ import annotations

import re

import numpy as np
import pytest

import motionhyst.identify.input_output as input_output
import motionhyst.identify.io_checks as io_checks
import motionhyst.identify.io_consistency as io_consistency
from motionhyst.cli import main
from motionhyst.core.budget import BudgetError, set_max_memory
from motionhyst.hysteresis import Jenkins
from motionhyst.identify.io_checks import FitFailed, judge_fit
from motionhyst.identify.io_records import IORecord
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop, simulate_elements

FS = 1000.0


def _axis() -> IORecord:
    """A positioning axis (95 kg, 200 N s/m, a Jenkins link of 1e8 N/m and 20 N): 2500
    samples at 1 kHz, 0.1 um of white noise."""
    t = np.arange(2500) / FS
    u = 30 + 90 * np.sin(2 * np.pi * 0.6 * t) + 40 * np.sin(2 * np.pi * 1.7 * t)
    y, _ = simulate_elements(MassDamper(95.0, 200.0).mechanics(),
                             Jenkins(k=1e8, fc=20.0).time_stepping(), u, FS, 20,
                             periodic=False)
    y = y + 1e-7 * np.random.default_rng(0).standard_normal(t.size)
    return IORecord(t, u, y, "axis.csv")


def test_a_check_run_above_the_memory_budget_is_the_budget_not_a_failed_fit():
    """The model (66 integration steps a sample, 8.08 MB for its run) under a budget of
    50 kB: main said "the fit failed: the identified model cannot be simulated on axis.csv
    (... fewer samples or substeps)", a library's remedy; now a BudgetError (exit 2) naming
    the run, the budget and the command's remedy."""
    rec = _axis()
    system = OpenLoop(MassDamper(95.0, 200.0), Jenkins(k=1e8, fc=20.0))
    set_max_memory(50_000)
    try:
        with pytest.raises(BudgetError) as caught:
            judge_fit(1e-7, [rec], [rec.y], None, system, True)
    finally:
        set_max_memory(None)
    text = str(caught.value)
    assert not isinstance(caught.value, FitFailed)
    assert "the fit failed" not in text and "cannot be simulated" not in text
    assert re.match(r"the identified model's run of axis\.csv \(the check that predict can "
                    r"run it\): 2500 samples of \d+ integration steps each needs [\d.]+ MB",
                    text), text  # measured: 66 steps, 8.08 MB (the run's size is predict's)
    assert "above the memory budget of 50 kB (--max-memory)" in text
    assert text.endswith("a larger --max-memory if the machine has it, or shorter records")
    judge_fit(1e-7, [rec], [rec.y], None, system, True)  # within the default budget: a result


class _Stop(FitFailed):
    """The search, not run: the checks before it are what is counted."""


@pytest.mark.parametrize("library", [False, True])
def test_the_records_are_checked_for_one_stage_once(tmp_path, monkeypatch, capsys, library):
    """identify: the inertia and one-stage checks ran twice on main (the command's, to refuse
    before its warnings, and identify_io's); once now.  identify_io called alone checks them
    itself."""
    rec = _axis()
    path = tmp_path / "axis.csv"
    np.savetxt(path, np.c_[rec.t, rec.u, rec.y], delimiter=",",
               header="time,force,displacement", comments="")
    calls = {"check_one_stage": 0, "check_inertia": 0}

    def counted(module, name):
        real = getattr(module, name)

        def count(*args, **kwargs):
            calls[name] += 1
            return real(*args, **kwargs)
        monkeypatch.setattr(module, name, count)

    for module in (io_consistency, input_output):
        counted(module, "check_one_stage")
    for module in (io_checks, input_output):
        counted(module, "check_inertia")

    def stop(*args, **kwargs):
        raise _Stop("the search, not run")
    monkeypatch.setattr(input_output, "identify_elements_io", stop)
    if library:
        with pytest.raises(_Stop):
            input_output.identify_io([rec], "coulomb", plant="mass-damper")
    else:
        assert main(["identify", str(path), "--record", "input-output", "--model", "coulomb",
                     "--plant", "mass-damper"]) != 0
        assert "the search, not run" in capsys.readouterr().err
    assert calls == {"check_one_stage": 1, "check_inertia": 1}
