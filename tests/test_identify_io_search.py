"""The input-output search: its trials, its budget.

A trial the model refuses (a mass run to 0, an exponential overflowing) is the search's large
residual, with no numpy warning on the user's terminal; ``--max-evaluations N`` is the
search's whole budget (every start, profile point, rigid-limit fit and refinement counted).
"""

from __future__ import annotations

import warnings

import limited_process
import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb, Jenkins
from motionhyst.identify import io_budget
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_checks import FitFailed
from motionhyst.identify.io_elements import identify_elements_io
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

FS = 1000.0


def _axis(n: int = 4000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A positioning axis (2 kg, 10 N s/m, a Jenkins link) driven by three sines, its position
    with 2 um of noise: time, force, position."""
    t = np.arange(n) / FS
    u = (30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
         + 5 * np.sin(2 * np.pi * 7 * t))
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(t, u).displacement
    return t, u, y + 2e-6 * np.random.default_rng(0).standard_normal(n)


def _write(path, t, u, y) -> None:
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="time,force,displacement",
               comments="")


def test_refused_trials_of_an_inconsistent_record_raise_no_numpy_warning():
    """A step force beside another record's position, searched as a Coulomb axis: the search
    tries masses near 0 and overflowing exponentials (numpy warned 'invalid value encountered
    in divide', 'overflow encountered in exp', four lines on identify's stderr); such a trial
    is a large residual, without a warning.  The search itself, past the checks that refuse
    such a record before it (the force's response, its inertia)."""
    t, _, y = _axis()
    rec = IORecord(t, np.where(t > 1.0, 30.0, 0.0), y, "step")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = identify_elements_io([rec], Coulomb, False, None, 1e-12, 200, 1, 0.0, None,
                                   MassDamper(1.0, 1.0), "auto", False)
    assert fit.n_evaluations > 100  # the search ran
    numpy_lines = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert not numpy_lines, numpy_lines


def _record(n: int = 2500) -> IORecord:
    """A positioning axis with a Jenkins link (2 kg, 10 N s/m, k 2e4 N/m, fc 4 N), a force
    offset of 3 N, 2 um of noise."""
    t = np.arange(n) / FS
    u = (30 + 90 * np.sin(2 * np.pi * 0.6 * t + 0.1) + 40 * np.sin(2 * np.pi * 1.7 * t + 0.3)
         + 15 * np.sin(2 * np.pi * 4.1 * t + 0.2))
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(t, u - 3.0).displacement
    return IORecord(t, u, y + 2e-6 * np.random.default_rng(0).standard_normal(n), "axis")


def _bouc_wen_record() -> IORecord:
    """A mass-spring-damper with a Bouc-Wen link (identify_io's example)."""
    from motionhyst.hysteresis import BoucWen
    from motionhyst.time.openloop import MassSpringDamper

    t = np.arange(1024) / 750
    u = 40 * np.sin(2 * np.pi * 8 * t) + 20 * np.sin(2 * np.pi * 31 * t)
    true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=5e4, fc=20.0, beta=0.6,
                                                               gamma=0.2))
    return IORecord(t, u, true.simulate(t, u).displacement, "bouc-wen")


@pytest.mark.parametrize("model, plant, budget", [
    ("jenkins", "mass-damper", 40),        # starts, then the Coulomb fit it starts from
    ("lugre", "mass-damper", 80),          # and the profile of its rate scale
    ("maxwell-slip", "mass-damper", 60),
    ("dahl", "mass-damper", 60),
    ("coulomb", "mass-damper", 30),        # forward differences
    ("bouc-wen", "mass-spring-damper", 120),   # the Bouc-Wen search with a mass
])
def test_a_budget_of_n_evaluations_uses_at_most_n(model, plant, budget):
    """Every model evaluation counts (each start, the Coulomb fit a friction link starts from,
    the refinement, the standard errors' Jacobian): the search ran about 250 on these records
    whatever the budget, the starts and the Coulomb fit uncounted.  Counted through the budget
    itself: every run charges it before it runs."""
    spent = []
    real = io_budget.EvaluationBudget.charge

    def charge(self, n=1):
        real(self, n)
        spent.append(n)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(io_budget.EvaluationBudget, "charge", charge)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                fit = identify_io([_bouc_wen_record() if model == "bouc-wen" else _record()],
                                  model, plant=plant, max_evaluations=budget, substeps=20)
            except FitFailed:  # a poor fit in so few evaluations: refused, within its budget
                fit = None
    assert 0 < sum(spent) <= budget
    if fit is not None:
        assert fit.n_evaluations == sum(spent)


def test_without_a_budget_every_evaluation_is_counted():
    """The count of an unbounded search is the evaluations it ran (each charged first)."""
    spent = []
    real = io_budget.EvaluationBudget.charge

    def charge(self, n=1):
        real(self, n)
        spent.append(n)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(io_budget.EvaluationBudget, "charge", charge)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit = identify_io([_record()], "jenkins", plant="mass-damper", substeps=20)
    assert fit.n_evaluations == sum(spent) > 150
    assert fit.estimates["link.k"] == pytest.approx(2e4, rel=1e-2)


def test_a_search_stopped_by_its_whole_budget_says_so_and_keeps_a_good_fit():
    """A Jenkins search on a positioning axis whose refinement its budget ends: the fit is
    the best point evaluated, said in one warning naming --max-evaluations."""
    with pytest.warns(UserWarning, match="--max-evaluations") as caught:
        fit = identify_io([_record()], "jenkins", plant="mass-damper", max_evaluations=34,
                          substeps=20)
    assert fit.extra["budget_reached"] is True and fit.n_evaluations <= 34
    assert sum("budget of model evaluations" in str(w.message) for w in caught) == 1
    assert fit.estimates["m"] == pytest.approx(2.0, rel=2e-2)


def test_a_budget_below_what_the_search_needs_is_refused_naming_the_least(tmp_path):
    """Fewer evaluations than one for each start and two steps of the refinement: one line,
    exit 2, naming the least."""
    rec = _record()
    _write(tmp_path / "axis.csv", rec.t, rec.u, rec.y)
    code, _, err = limited_process.run(
        ["identify", "axis.csv", "--record", "input-output", "--plant", "mass-damper",
         "--model", "jenkins", "--max-evaluations", "12"], tmp_path)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "a budget of 12 model evaluations is below the least this search needs" in err
