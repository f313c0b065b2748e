"""A search that ends on its cap of evaluations but has settled is converged, not stopped
short (issue 21, "honest results").

The symmetric Jenkins and Dahl fits of the whole EMPS estimation record used their 200
evaluations (779 and 963 in all) and were warned "stopped on its budget ... the estimates may
still move".  Jenkins's (traced): a link that sticks makes the cost non-smooth below the
search's tolerances (ftol 1e-12), and the trust region kept taking steps that lowered it by
1.3e-5 of itself over its last 100 evaluations, moving the mass by 0.001 kg of its 3.4 kg
standard error (at most 0.09 % of any estimate's over the last 50; its stiffness, 3.1e7 +-
4.3e8 N/m, a direction the records do not see, never moved).  io_budget.settled tells the two
apart: the last quarter of the evaluations moved no estimate by 1 % of its standard error."""

from __future__ import annotations

import numpy as np

from motionhyst.identify.io_budget import SETTLED_SHARE, settled, solve_within


def _rough(x: np.ndarray) -> np.ndarray:
    """Residuals with ripples of 1e-9 (a cost not smooth to ftol = 1e-15)."""
    return np.array([x[0] - 3.0 + 1e-9 * np.sin(1e9 * x[0]),
                     0.5 * (x[1] - 1.0) + 1e-9 * np.cos(3e8 * x[1])])


def test_a_search_on_its_cap_that_no_longer_moves_has_settled():
    """60 evaluations on the rippled cost: on its cap (status 0), at (3, 1) to 1e-8, its last
    quarter moving nothing by 1 % of a standard error of 0.01; not for standard errors of
    1e-12 (the ripples' own scale moves it more than that)."""
    sol = solve_within(_rough, np.array([0.0, 0.0]), max_nfev=60, ftol=1e-15, xtol=1e-15,
                       gtol=1e-15)
    assert sol.status == 0 and sol.nfev == 60
    np.testing.assert_allclose(sol.x, [3.0, 1.0], atol=1e-8)
    assert settled(sol, lambda x: x, np.array([0.01, 0.01]))
    assert not settled(sol, lambda x: x, np.array([1e-12, 1e-12]))
    # a parameter not determined (NaN) is not judged
    assert settled(sol, lambda x: x, np.array([0.01, np.nan]))


def test_a_search_stopped_short_has_not_settled():
    """Rosenbrock's valley from (-1.2, 1) with 12 evaluations: on its cap, still moving by
    far more than 1 % of a standard error of 0.01; a search that ended by its tolerances
    (status not 0) is not 'settled' either (it converged)."""
    def rosen(x):
        return np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])
    sol = solve_within(rosen, np.array([-1.2, 1.0]), max_nfev=12)
    assert sol.status == 0
    assert not settled(sol, lambda x: x, np.array([0.01, 0.01]))
    done = solve_within(rosen, np.array([-1.2, 1.0]), max_nfev=500)
    assert done.status != 0 and not settled(done, lambda x: x, np.array([0.01, 0.01]))
    assert SETTLED_SHARE == 0.01
