"""Polynomial coefficient arrays (highest power first), with numpy alone.

Transfer functions are kept as ratios of such arrays; common factors ``s`` are
cancelled exactly (so ``s = 0`` is exact).  Nothing here imports python-control or
scipy: a scenario's loop is checked from its coefficients before they load
(:mod:`motionhyst.controllers.characteristic`).

Examples
--------
>>> num, den = cancel_s([1.0, 0.0], [1.0, 2.0, 0.0])        # s / (s^2 + 2 s)
>>> num.tolist(), den.tolist()
([1.0], [1.0, 2.0])
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["cancel_s", "trim"]


def trim(p: ArrayLike) -> NDArray[np.float64]:
    """Drop leading coefficients that are exactly zero.

    Parameters
    ----------
    p : array_like
        Coefficients, highest power first.

    Examples
    --------
    >>> from motionhyst.core.polynomials import trim
    >>> trim([0.0, 0.0, 1.0, 2.0])
    array([1., 2.])
    """
    p = np.atleast_1d(np.asarray(p, dtype=float))
    nz = np.nonzero(p != 0.0)[0]
    return p[nz[0]:] if nz.size else np.zeros(1)


def cancel_s(num: ArrayLike, den: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Cancel common factors ``s`` (trailing zero coefficients) of a ratio.

    Parameters
    ----------
    num : array_like
        Numerator coefficients, highest power first.
    den : array_like
        Denominator coefficients, highest power first.

    Examples
    --------
    >>> from motionhyst.core.polynomials import cancel_s
    >>> cancel_s([1.0, 0.0], [1.0, 2.0, 0.0])               # s / (s^2 + 2 s) = 1 / (s + 2)
    (array([1.]), array([1., 2.]))
    """
    num, den = trim(num), trim(den)
    while num.size > 1 and den.size > 1 and num[-1] == 0.0 and den[-1] == 0.0:
        num, den = num[:-1], den[:-1]
    return num, den
