"""The Jenkins stiffness profiled on a grid (identify/io_stiffness.py): the search past the
local minimum it stopped in on EMPS periods 3-4 (tests/test_emps.py), chosen by the
estimation records' cost, and a search that found the stiffness left as it ends."""

import math
import warnings

import numpy as np
import pytest

from motionhyst.hysteresis import Jenkins
from motionhyst.identify import io_elements
from motionhyst.identify.emps import score
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_friction import PRESLIDING_BOUND, STUCK_MODE_SAMPLES
from motionhyst.identify.io_stiffness import PER_DECADE, stiffness_grid
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop


def jenkins_axis(k: float, noise: float = 1e-9) -> IORecord:
    """A Jenkins axis (95 kg, 200 N s/m, fc 20 N, force offset -3.2 N) at 1 kHz, two periods
    of 1000 samples of a path a loop follows, its state set from its first samples."""
    t = np.arange(2000) / 1000.0
    w = 2 * np.pi
    path = 0.02 * np.sin(w * t) + 0.006 * np.sin(3 * w * t + 1.0)
    v = 0.02 * w * np.cos(w * t) + 0.018 * w * np.cos(3 * w * t + 1.0)
    acc = -w ** 2 * (0.02 * np.sin(w * t) + 0.054 * np.sin(3 * w * t + 1.0))
    u = 95.0 * acc + 200.0 * v + 20.0 * np.sign(v) - 3.2
    true = OpenLoop(MassDamper(95.0, 200.0, force_offset=3.2), Jenkins(k=k, fc=20.0))
    y = score(true, IORecord(t, u, path, "path"))[1]
    return IORecord(t, u, y + noise * np.random.default_rng(7).standard_normal(t.size), "axis")


def test_the_grid_spans_the_stiffnesses_the_records_resolve():
    """From a slip displacement fc / k of PRESLIDING_BOUND of the stroke to a stuck mode
    sqrt(k / m) / 2 pi at fs / STUCK_MODE_SAMPLES, PER_DECADE values a decade."""
    rec = jenkins_axis(1e7)
    grid = stiffness_grid([rec], 95.0, 20.0)
    stroke = float(np.ptp(rec.y))
    assert 20.0 / grid[0] == pytest.approx(PRESLIDING_BOUND * stroke, rel=1e-12)
    assert math.sqrt(grid[-1] / 95.0) / (2 * math.pi) == pytest.approx(
        1000.0 / STUCK_MODE_SAMPLES, rel=1e-12)
    steps = np.diff(np.log10(grid))
    assert np.allclose(steps, steps[0]) and steps[0] <= 1.0 / PER_DECADE


@pytest.mark.parametrize("k", [3e6, 3e7])
def test_a_search_that_finds_the_stiffness_is_left_as_it_ends(k, monkeypatch):
    """On a generated Jenkins axis the search's own starts find the true stiffness (stuck
    modes at 28 and 89 Hz); the profile finds no held fit below that end, and the fit is the
    one without it, to the last digit."""
    rec = jenkins_axis(k)
    kwargs = {"plant": "mass-damper", "init_window": 20, "asymmetric": False}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = identify_io([rec], "jenkins", **kwargs)
        monkeypatch.setattr(io_elements, "profile_stiffness", lambda prob, sol, *a: sol)
        alone = identify_io([rec], "jenkins", **kwargs)
    assert fit.estimates["link.k"] == pytest.approx(k, rel=0.01)
    assert fit.estimates["m"] == pytest.approx(95.0, rel=1e-3)
    assert fit.estimates == alone.estimates
    assert fit.n_evaluations > alone.n_evaluations  # the profile ran
