"""The search's whole budget of model evaluations (``identify --max-evaluations N``).

An input-output search runs many fits: starts on a short part of the records, a profile of
its rate scales, a positioning axis's Coulomb fit (its rigid limit, a start for the other
friction links) and the refinement on all records.  One :class:`EvaluationBudget` is charged
by every model evaluation of them all (a run of the records, each column of a Jacobian's
forward differences); a phase may be given a share of what is left
(:meth:`EvaluationBudget.share`), and a refinement stopped where its share is spent ends at
the best point it has evaluated (:func:`solve_within`).  Without a limit nothing is stopped:
the searches and their numbers are what they are without a budget.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import OptimizeResult, least_squares

__all__ = ["SETTLED_EVALUATIONS", "SETTLED_SHARE", "BudgetSpent", "EvaluationBudget",
           "settled", "solve_within"]


class BudgetSpent(Exception):
    """An evaluation the budget (or the running phase's share of it) has no room for.

    Examples
    --------
    >>> budget = EvaluationBudget(2)
    >>> budget.charge(2)
    >>> try:
    ...     budget.charge()
    ... except BudgetSpent as exc:
    ...     print(exc)
    1 more model evaluations past the budget
    """


class EvaluationBudget:
    """The model evaluations a search may use in all, and those it has used.

    Parameters
    ----------
    limit : int, optional
        The most evaluations in all; None: no limit (only counted).
    planned : callable, optional
        Called once, with no arguments, when the search's plan has passed
        (:meth:`plan_starts`) or its first evaluation is charged: the search starts (the
        ``identify`` command then shows the warnings it held while it checked the records,
        so a refusal of the plan is one line).

    Examples
    --------
    >>> budget = EvaluationBudget(10)
    >>> budget.charge(3)
    >>> with budget.share(4):          # a phase: at most 4 more
    ...     budget.charge(4)
    ...     try:
    ...         budget.charge(1)
    ...     except BudgetSpent:
    ...         print("share spent")
    share spent
    >>> budget.used, budget.left
    (7, 3)
    >>> said = EvaluationBudget(20, planned=lambda: print("the search starts"))
    >>> try:                           # refused before it starts: nothing said
    ...     said.plan_starts(4, 10)
    ... except ValueError:
    ...     print("refused")
    refused
    >>> said.charge()
    the search starts
    """

    def __init__(self, limit: int | None = None,
                 planned: Callable[[], object] | None = None) -> None:
        if limit is not None and not (isinstance(limit, int | np.integer) and limit >= 1):
            raise ValueError(f"a budget of model evaluations is a whole number >= 1, got "
                             f"{limit!r}")
        self.limit = None if limit is None else int(limit)
        self.used = 0
        self._stop = self.limit
        self._planned = planned

    def _start(self) -> None:
        planned, self._planned = self._planned, None
        if planned is not None:
            planned()

    @property
    def left(self) -> int | None:
        """What the running phase may still use (None: no limit)."""
        return None if self._stop is None else max(self._stop - self.used, 0)

    def charge(self, n: int = 1) -> None:
        """Count `n` evaluations about to run.

        Parameters
        ----------
        n : int
            The evaluations.

        Raises
        ------
        BudgetSpent
            If they do not fit in the budget or the running phase's share.

        Examples
        --------
        >>> budget = EvaluationBudget()
        >>> budget.charge(7)
        >>> budget.used, budget.left
        (7, None)
        """
        if self._stop is not None and self.used + n > self._stop:
            raise BudgetSpent(f"{n} more model evaluations past the budget")
        self._start()
        self.used += n

    def plan_starts(self, n_fits: int, per_step: int, seeded: bool = False, runs: int = 0
                    ) -> tuple[int, Iterator[int | None]]:
        """A multi-start search's plan: what it keeps for its refinement, and its starts'
        shares.

        Parameters
        ----------
        n_fits : int
            The fits on the starts (each refined on a short part of the records).
        per_step : int
            The evaluations of one step of the refinement (a run and its Jacobian's
            forward differences, at most).
        seeded : bool
            The search also starts from a Coulomb fit (a positioning axis's friction
            link): it takes a third of the rest, as the starts do.
        runs : int
            Single evaluations among the starts (starts screened by one run each).

        Returns
        -------
        final : int
            Evaluations kept for the refinement: the comparison of its starts, two steps
            and its standard errors.
        shares : iterator
            The share of each fit on the starts in turn: an equal part of what the fits
            before it left of the starts' part (half of the rest, a third if `seeded`,
            with `runs`); None without a limit.

        Raises
        ------
        ValueError
            Naming the least, if what is left is too small for the screening runs, two
            evaluations of each start (three if `seeded`) and the final steps.

        Examples
        --------
        >>> budget = EvaluationBudget(100)
        >>> final, shares = budget.plan_starts(4, 10)
        >>> used = []
        >>> for _ in range(4):         # each fit uses its whole share
        ...     used.append(next(shares))
        ...     budget.charge(used[-1])
        >>> final, used, budget.left
        (22, [9, 10, 10, 10], 61)
        >>> try:
        ...     EvaluationBudget(20).plan_starts(4, 10)
        ... except ValueError as exc:
        ...     print(str(exc)[:72])
        a budget of 20 model evaluations is below the least this search needs, 3
        """
        final = 2 + 2 * per_step
        least = runs + (3 if seeded else 2) * n_fits + final
        left = self.left
        if left is not None and left < least:
            raise ValueError(f"a budget of {left} model evaluations is below the least this "
                             f"search needs, {least}: "
                             f"{f'{runs} to screen starts, ' if runs else ''}"
                             f"{3 if seeded else 2} for each of its {n_fits} starts"
                             f"{' (one for the Coulomb fit it also starts from)' if seeded else ''}"
                             f", {per_step} for each of two steps of its refinement and 2 to "
                             f"choose its start")
        self._start()
        return final, self._shares(n_fits, None if left is None else
                                   runs + (left - final - runs) // (3 if seeded else 2))

    def _shares(self, n: int, of: int | None) -> Iterator[int | None]:
        end = None if of is None else self.used + of
        for k in range(n, 0, -1):
            yield None if end is None else max(end - self.used, 0) // k
        while True:
            yield None if end is None else 0

    @contextmanager
    def share(self, n: int | None) -> Iterator[None]:
        """A phase: inside the block at most `n` more evaluations.

        Parameters
        ----------
        n : int or None
            The phase's share, within what is left (None: all that is left).

        Examples
        --------
        >>> budget = EvaluationBudget(10)
        >>> with budget.share(3):
        ...     budget.left
        3
        >>> budget.left
        10
        """
        stop = self._stop
        if n is not None and stop is not None:
            self._stop = min(stop, self.used + max(int(n), 0))
        try:
            yield
        finally:
            self._stop = stop


def solve_within(fun: Callable[[NDArray[np.float64]], NDArray[np.float64]],
                 x0: NDArray[np.float64], **kwargs) -> OptimizeResult:
    """:func:`scipy.optimize.least_squares`, ended where the budget it charges is spent.

    Parameters
    ----------
    fun : callable
        The residuals of the search variables; it (or the Jacobian in `kwargs`) charges an
        :class:`EvaluationBudget`.
    x0 : ndarray
        The start; the keyword arguments are least_squares' options.

    Returns
    -------
    OptimizeResult
        least_squares' result; where the budget was spent, the best point evaluated, with
        ``status`` 0 (as on ``max_nfev``) and a message saying so; ``path``: the best point
        after each of the search's steps (each evaluation of `fun`, what :func:`settled`
        reads) with a callable ``jac``; None with least_squares' own finite differences
        (``jac="2-point"``...), whose columns' evaluations of `fun` are no steps.

    Raises
    ------
    BudgetSpent
        If not even `x0` could be evaluated.

    Examples
    --------
    >>> budget = EvaluationBudget(5)
    >>> def fun(x):
    ...     budget.charge()
    ...     return np.array([x[0] - 3.0, 0.1 * (x[0] - 3.0) ** 2])
    >>> sol = solve_within(fun, np.array([0.0]))
    >>> sol.status, budget.used, bool(abs(sol.x[0] - 3.0) < 3.0)
    (0, 5, True)
    """
    best: list = [math.inf, None, 0]  # the least cost, its point, the calls of `fun`
    path: list[NDArray[np.float64]] = []
    jac = kwargs.get("jac")

    def tracked(x: NDArray[np.float64]) -> NDArray[np.float64]:
        best[2] += 1
        r = fun(x)
        cost = float(np.dot(r, r))
        if best[1] is None or cost < best[0]:
            best[:2] = [cost, np.array(x, dtype=float)]
        path.append(best[1])
        return r

    try:
        sol = least_squares(tracked, x0, **kwargs)
    except BudgetSpent:
        if best[1] is None:
            raise
        sol = OptimizeResult(x=best[1], cost=0.5 * best[0], status=0, success=False,
                             nfev=best[2], message="The budget of model evaluations is spent.")
    sol.path = np.array(path) if callable(jac) else None
    return sol


#: A search stopped on its cap of evaluations has settled (:func:`settled`) where its last
#: quarter of its steps moved no estimate by more than this share of its standard error ...
SETTLED_SHARE = 0.01
#: ... over at least this many (the evaluations of its steps)
SETTLED_EVALUATIONS = 20


def settled(sol: OptimizeResult, values: Callable[[NDArray[np.float64]], NDArray[np.float64]],
            std: NDArray[np.float64]) -> bool:
    """Whether a search that stopped on its cap of evaluations (``status`` 0) had settled: the
    last quarter of its steps (of at least :data:`SETTLED_EVALUATIONS`) moved no estimate by more
    than :data:`SETTLED_SHARE` of its standard error.

    A model whose cost is not smooth to the search's tolerances (a link that sticks: each
    step's sticking and slipping samples change with the parameters; ``ftol = 1e-12``) keeps
    lowering it by steps far below the records' resolution: the symmetric Jenkins fit of the
    EMPS record used its 200 evaluations, the last 100 lowering the cost by 1.3e-5 of itself
    and moving the mass by 0.001 kg of its 3.4 kg standard error.  Such a
    search has converged at the precision the records give its estimates; one still moving
    has not (:func:`~motionhyst.identify.io_checks.budget_note`).  Only the search's steps
    count (:func:`solve_within`'s ``path``: a search that evaluates its own Jacobian): the
    evaluations of least_squares' finite-difference columns move no estimate, and a search
    30-38 standard errors from its optimum looked settled over them (review B16 L2).

    Parameters
    ----------
    sol : OptimizeResult
        :func:`solve_within`'s result (its ``path``).
    values : callable
        The parameters of a point of the search.
    std : ndarray
        Their standard errors (NaN, 0 or inf where not determined: not judged); the
        caller says which (identify: the reported ones, widened for the residuals'
        correlation).

    Returns
    -------
    bool
        False for a search that ended otherwise (``status`` not 0), without a path (a
        Jacobian of least_squares' own), with fewer steps, or with no estimate judged.

    Examples
    --------
    A search whose 40 steps crept towards 3 (``3 + 1e-3 0.9^k``): its last 10 moved
    ``x`` by 3e-5, settled for a standard error of 0.1, not for one of 1e-4, nor where no
    standard error is known.

    >>> path = np.array([[3.0 + 1e-3 * 0.9 ** k] for k in range(40)])
    >>> sol = OptimizeResult(x=path[-1], status=0, path=path)
    >>> settled(sol, lambda x: x, np.array([0.1])), settled(sol, lambda x: x, np.array([1e-4]))
    (True, False)
    >>> settled(sol, lambda x: x, np.array([np.nan]))
    False
    """
    path = sol.get("path")
    if sol.status != 0 or path is None or len(path) < SETTLED_EVALUATIONS:
        return False
    back = max(len(path) // 4, SETTLED_EVALUATIONS // 4)
    moved = np.abs(values(sol.x) - values(path[-1 - back]))
    std = np.asarray(std, dtype=float)
    judged = np.isfinite(std) & (std > 0)
    if not judged.any():
        return False
    return bool(np.all(moved[judged] <= SETTLED_SHARE * std[judged]))
