"""The input-output search's trials.

A trial the model refuses (a mass run to 0, an exponential overflowing) is the search's large
residual, with no numpy warning on the user's terminal.
"""

from __future__ import annotations

import warnings

import numpy as np

from motionhyst.hysteresis import Coulomb, Jenkins
from motionhyst.identify.input_output import IORecord
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
