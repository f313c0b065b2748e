"""The refinement of an element link's search from more than one start: the end of least
cost is kept, whatever the starts cost (a Jenkins axis started from its rigid limit, the
Coulomb fit, whose start cost less, ended higher than from the short runs' best)."""

import numpy as np
from scipy.optimize import OptimizeResult

from motionhyst.identify.io_budget import EvaluationBudget
from motionhyst.identify.io_refine import refine


class TwoWells:
    """A search problem with two wells: the one at -1 costs less where a search enters it
    (0.8 at -0.1, against 0.9 at 0.5) and more at its bottom (0.6 against 0.2 at 2)."""

    def __init__(self) -> None:
        self.budget, self.fd_step, self.n_eval, self.starts = EvaluationBudget(), 1e-6, 0, []

    def cost(self, q):
        return 0.8 if q[0] < 0 else 0.9

    def solve(self, q, tol, max_nfev):
        self.starts.append(float(q[0]))
        self.budget.charge(10)
        self.n_eval += 10
        return OptimizeResult(x=np.array([-1.0 if q[0] < 0 else 2.0]),
                              cost=0.6 if q[0] < 0 else 0.2)


def test_the_end_of_least_cost_is_kept_from_every_start():
    prob = TwoWells()
    sol, start, _ = refine(prob, np.array([-0.1]), 1e-8, None, 0, False)
    assert sol.x[0] == -1.0 and prob.starts == [-0.1]  # one start: its own well
    prob = TwoWells()
    sol, start, _ = refine(prob, np.array([-0.1]), 1e-8, None, 0, False,
                           others=[np.array([0.5])])
    assert prob.starts == [-0.1, 0.5]
    assert sol.x[0] == 2.0 and sol.cost == 0.2 and start[0] == 0.5


def test_the_starts_share_a_budget():
    """With a budget, each start's refinement has an equal part of what those before it
    left, less what is kept for what follows."""
    prob = TwoWells()
    prob.budget = EvaluationBudget(1000)
    shares = []
    solve = prob.solve

    def counted(q, tol, max_nfev):
        shares.append(max_nfev)
        return solve(q, tol, max_nfev)

    prob.solve = counted
    refine(prob, np.array([-0.1]), 1e-8, None, 100, False, others=[np.array([0.5])])
    assert shares == [450, 890]  # (1000 - 100 kept) / 2, then all 890 the first left
