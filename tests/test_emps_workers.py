"""The EMPS benchmark's fits spread over worker processes (``benchmark emps --workers``): the
models come in chains (a Jenkins link after the Coulomb fit it starts from), each chain of each
split in one process, and every figure is the one the fits give in one process, to the last
digit."""

import math
import multiprocessing
import time

import numpy as np
import pytest

from motionhyst.hysteresis import Jenkins
from motionhyst.identify.emps import cross_validate, score
from motionhyst.identify.emps_workers import map_in_workers
from motionhyst.identify.input_output import IORecord
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

PERIOD = 1000


def jenkins_axis() -> IORecord:
    """Two periods of 1000 samples at 1 kHz of a mass-damper (95 kg, 200 N s/m, OF -3.2 N)
    with a Jenkins link (3e6 N/m, 20 N), the position simulated from the force, 1e-6 m noise."""
    t = np.arange(2 * PERIOD) / 1000.0
    u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    axis = OpenLoop(MassDamper(95.0, 200.0, force_offset=3.2), Jenkins(k=3e6, fc=20.0))
    y = score(axis, IORecord(t, u, np.zeros(t.size), "axis"))[1]
    return IORecord(t, u, y + 1e-6 * np.random.default_rng(3).standard_normal(t.size), "axis")


def figures(runs) -> list:
    """Every figure of the runs but the seconds each fit took."""
    rows = []
    for res in runs:
        for m in res.models:
            rows.append((res.estimation_record.name, m.name, m.parameters, m.std, m.estimation,
                         m.validation, m.warnings, m.error, m.limit, m.prediction.tobytes()))
    return rows


def test_workers_give_the_figures_of_one_process_to_the_last_digit():
    """Coulomb, Jenkins (from the Coulomb fit) and the Coulomb link with a drifting offset on
    both periods: four chains in two workers, every parameter, standard error, score, warning
    and predicted sample equal (==, not approx) to the fits in this process, in the same order;
    and the Jenkins link found (3e6 N/m within 10 %, the generated truth)."""
    rec = jenkins_axis()
    models = ("coulomb", "jenkins", "coulomb-drift")
    said: list[str] = []
    alone = cross_validate(rec, models=models, period=PERIOD)
    spread = cross_validate(rec, models=models, period=PERIOD, workers=2, progress=said.append)
    assert figures(spread) == figures(alone)
    for res in spread:
        assert [m.name for m in res.models] == list(models)
        jenkins = res.models[1]
        assert jenkins.error is None and jenkins.limit is None
        assert jenkins.model_parameters["k"] == pytest.approx(3e6, rel=0.1)
        assert jenkins.parameters["m"] == pytest.approx(95.0, rel=0.01)
    # each chain said as it is handed out, each model as it ends
    assert said[:2] == ["coulomb, jenkins: identifying on axis period 1 (1000 samples) ...",
                        "coulomb, jenkins: identifying on axis period 2 (1000 samples) ..."]
    assert sum("identifying" in line for line in said) == 4
    assert sum(" mm on axis " in line for line in said) == 6


def test_a_task_that_raises_ends_the_map_with_its_exception():
    """The first task that raises: its exception, here, as the task raised it."""
    with pytest.raises(ValueError, match="math domain error"):
        map_in_workers(math.sqrt, [4.0, -1.0, 9.0], workers=2)
    assert map_in_workers(math.sqrt, [4.0, 9.0, 16.0], workers=2) == [2.0, 3.0, 4.0]


def _sleep_or_raise(task):
    """A task that sleeps `task` seconds, or raises for ``"raise"``."""
    if task == "raise":
        raise ValueError("the task failed")
    time.sleep(task)
    return task


def test_a_task_that_raises_stops_the_workers_still_running():
    """The map ends with the first error at once: the worker still sleeping through its
    10-minute task is stopped, not waited for (before, leaving the pool waited for every
    running chain: Ctrl-C or SIGTERM on ``benchmark emps`` took minutes to exit)."""
    before = set(multiprocessing.active_children())
    with pytest.raises(ValueError, match="the task failed"):
        map_in_workers(_sleep_or_raise, [600.0, "raise"], workers=2)
    workers = set(multiprocessing.active_children()) - before
    for worker in workers:
        worker.join(30.0)
    assert not any(worker.is_alive() for worker in workers)
