"""Records of a piezo stack and a friction damper as a lab logs them, checked as a user runs
the tool on them (issue 21: a model that predicts the held-out part, or one line).

Generated, seeded and small; each case is one that went wrong on measured-like records
(/work/team/scratch-other21 holds the campaign that found them).
"""

from __future__ import annotations

import warnings

import numpy as np

from motionhyst.hysteresis import Jenkins
from motionhyst.identify import io_quasi_static as qs
from motionhyst.identify.io_records import IORecord
from motionhyst.plants import QuasiStatic
from motionhyst.time.quasi_static import displacement_from_force


def test_a_trial_step_whose_cost_overflows_is_rejected_without_a_warning():
    # A piezo's search (a Bouc-Wen link, n = 3, on a 24,000-sample record at 20 kHz) tried
    # steps whose predicted positions were so far out that their sum of squares overflowed:
    # "motionhyst: warning: identify: RuntimeWarning: overflow encountered in dot" on the
    # user's terminal, a second line before a refusal's one line.  Such a step has an
    # infinite cost: rejected, the search goes on, silently.
    t = np.arange(1000) / 1000.0
    u = 300.0 * np.sin(2 * np.pi * 2 * t) * np.minimum(1.0, 2 * t)
    y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
    rec = IORecord(t, u, y)
    prob = qs._Problem([rec], qs._layout(Jenkins, 1), False, False, False, 1e5, 10.0,
                       float(np.std(y)), float(np.std(u)), 1.0)
    target = np.array([10.3, 9.8, 10.1, 10.4])
    q0 = target + 1.5

    def residuals(q, equation):  # a saturating error whose Gauss-Newton step overshoots
        d = q - target           # into values whose predictions are 1e200 m
        return np.full(48, 1e200) if np.max(np.abs(d)) > 3.0 else np.repeat(np.tanh(d), 12)

    prob._residuals = residuals
    prob.free = np.ones(q0.size, dtype=bool)
    prob.fixed = np.zeros(q0.size)
    prob.log = np.zeros(q0.size, dtype=bool)
    prob.lower = np.full(q0.size, -np.inf)
    prob.scale = np.ones(q0.size)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = prob.solve(q0, False, 200, 1e-12)
    np.testing.assert_allclose(sol.x, target, atol=1e-8)
