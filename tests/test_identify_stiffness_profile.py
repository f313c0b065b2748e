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
from motionhyst.identify.io_stiffness import PER_DECADE, SPAN, stiffness_grid
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


@pytest.mark.parametrize("k_end", [3e6, 1e8, 5e4])
def test_the_grid_lies_about_the_end_within_what_the_records_resolve(k_end):
    """PER_DECADE values a decade about the refinement's end (not the end itself), at most
    SPAN decades each side, none softer than a slip displacement fc / k of PRESLIDING_BOUND
    of the stroke or stiffer than a stuck mode sqrt(k / m) / 2 pi at fs / STUCK_MODE_SAMPLES
    (an end near a bound: the values on that side cut off)."""
    rec = jenkins_axis(1e7)
    grid = stiffness_grid([rec], 95.0, 20.0, k_end)
    lo = 20.0 / (PRESLIDING_BOUND * float(np.ptp(rec.y)))
    hi = 95.0 * (2 * math.pi * 1000.0 / STUCK_MODE_SAMPLES) ** 2
    assert grid.size and lo <= grid.min() and grid.max() <= hi
    decades = np.log10(grid / k_end) * PER_DECADE  # whole numbers of steps from the end
    assert np.allclose(decades, np.round(decades)) and np.all(np.round(decades) != 0)
    assert np.abs(np.log10(grid / k_end)).max() <= SPAN + 1e-12
    full = [k for k in k_end * 10.0 ** (np.arange(-9, 10) / PER_DECADE)
            if lo <= k <= hi and k != k_end and abs(math.log10(k / k_end)) <= SPAN + 1e-12]
    assert grid == pytest.approx(full, rel=1e-12)  # every such value, none left out


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
