"""What input-output records determine: standard errors and the parameters they do not.

From the Jacobian ``J`` of the simulation residuals at the optimum, standard
errors ``sqrt(diag(sigma^2 (J^T J)^-1))`` with ``sigma^2 = RSS / (N - p)``,
a direction of ``J`` with a singular value below :data:`SINGULAR_RTOL` of the
largest (:data:`FD_SINGULAR_RTOL` for a finite-difference Jacobian) being one
the data do not determine (:func:`standard_errors`), and the notes that say so
(:func:`undetermined_notes`, :func:`weak_notes`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = []

SINGULAR_RTOL = 1e-8
FD_SINGULAR_RTOL = 1e-5  # finite-difference Jacobians (step 1e-6) are no more exact than this


def standard_errors(J: NDArray[np.float64], rss: float, n_rows: int,
                    rtol: float = SINGULAR_RTOL
                    ) -> tuple[NDArray[np.float64], list[list[int]]]:
    """Standard errors of the parameters and the groups the data cannot separate.

    The columns of `J` are normalised; a right singular vector whose singular
    value is below `rtol` of the largest is a direction the data do not
    determine, and the parameters with a component above 1e-3 in it form a
    group (only other combinations of them are determined).  Their standard
    errors are NaN; the others come from the pseudo-inverse.
    """
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    Jn = J / norms
    _, sv, vt = np.linalg.svd(Jn, full_matrices=False)
    p = J.shape[1]
    sigma2 = rss / max(n_rows - p, 1)
    good = sv > rtol * sv[0]
    groups = [list(np.nonzero(np.abs(vt[i]) > 1e-3)[0]) for i in np.nonzero(~good)[0]]
    cov = (vt[good].T / sv[good] ** 2) @ vt[good]
    std = np.sqrt(sigma2 * np.diag(cov)) / norms
    for g in groups:
        std[g] = np.nan
    return std, groups


def undetermined_notes(names: list[str], groups: list[list[int]], rtol: float
                       ) -> dict[str, str]:
    notes: dict[str, str] = {}
    for g in groups:
        members = [names[i] for i in g]
        for i in g:
            others = [m for m in members if m != names[i]]
            what = (f"only a combination with {', '.join(others)} is" if others
                    else "it has no effect on the output")
            notes[names[i]] = (f"not determined by these records: {what} (a direction of "
                               f"the Jacobian with a singular value below {rtol:g} of the "
                               f"largest)")
    return notes


def _correlation(J: NDArray[np.float64], rtol: float) -> NDArray[np.float64]:
    """Correlation matrix of the estimates, ``(J^T J)^+`` over the determined directions."""
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    _, sv, vt = np.linalg.svd(J / norms, full_matrices=False)
    good = sv > rtol * sv[0]
    cov = (vt[good].T / sv[good] ** 2) @ vt[good]
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return cov / np.outer(d, d)


def weak_notes(names: list[str], values: NDArray[np.float64], std: NDArray[np.float64],
               J: NDArray[np.float64], rtol: float, may_be_zero: NDArray[np.bool_]
               ) -> dict[str, str]:
    """Parameters whose standard error exceeds their value: not determined by the records.

    A parameter that must be positive is then reported with the parameters its
    estimate is correlated with (``|r| > 0.99``: only that combination is
    determined), or as having almost no effect at the records' noise; one that
    may be zero as not distinguishable from 0.
    """
    corr = _correlation(J, rtol)
    notes: dict[str, str] = {}
    for i, name in enumerate(names):
        s = std[i]
        if not (math.isfinite(s) and s > abs(values[i])):
            continue
        if may_be_zero[i]:
            notes[name] = (f"not distinguishable from 0 by these records (estimate "
                           f"{values[i]:.4g} +- {s:.2g})")
            continue
        partners = [f"{names[j]} (r = {corr[i, j]:+.4f})" for j in range(len(names))
                    if j != i and abs(corr[i, j]) > 0.99]
        what = (f"only a combination with {', '.join(partners)} is" if partners else
                "it has almost no effect on the output at the records' noise")
        notes[name] = (f"not determined by these records: its standard error {s:.2g} exceeds "
                       f"the estimate {values[i]:.4g}; {what}")
    return notes
