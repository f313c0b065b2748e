"""Checks of user-given numbers, shared by every model and system: one-line ``ValueError`` messages
naming the parameter.

Examples
--------
>>> check_positive("k", 1e4)
10000.0
>>> check_positive("fc", -1)
Traceback (most recent call last):
...
ValueError: fc must be finite and > 0, got -1
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["CORRELATION_ROUNDING", "MAGNITUDES", "check_amplitudes", "check_correlation",
           "check_finite", "check_magnitude", "check_magnitudes", "check_omega", "check_positive",
           "least_correlation_eigenvalue"]

MAGNITUDES = (1e-30, 1e30)
"""The magnitudes of user-given numbers (in SI units) that motionhyst computes with: beyond
them, squares and products of the loop's quantities over- or underflow (a mass of 1e300 kg
gives inf and NaN, not an answer); 0 is always allowed."""


def check_magnitude(name: str, value: float) -> float:
    """Return `value`, raising ``ValueError`` naming `name` if its magnitude is outside
    :data:`MAGNITUDES` (0 allowed).

    Parameters
    ----------
    name : str
        The key or option, for the message.
    value : float
        Its value.

    Examples
    --------
    >>> check_magnitude("m2", 17.5)
    17.5
    >>> check_magnitude("[stage] m2", 1e300)               # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: [stage] m2 = 1e+300: outside the magnitudes 1e-30 to 1e+30 (or 0, SI units) ...
    """
    v = float(value)
    if v != 0.0 and np.isfinite(v) and not MAGNITUDES[0] <= abs(v) <= MAGNITUDES[1]:
        raise ValueError(f"{name} = {v:g}: outside the magnitudes {MAGNITUDES[0]:g} to "
                         f"{MAGNITUDES[1]:g} (or 0, SI units) that motionhyst computes with")
    return value


def check_magnitudes(data, where: str = "") -> None:
    """Check every number in the nested tables and lists `data` (a parsed TOML file) with
    :func:`check_magnitude`, naming the first one outside as ``[table] key``.

    Parameters
    ----------
    data : dict or list or number
        The parsed file, or a part of it.
    where : str
        The name of `data` itself (``[stage] m2``, ``[hysteresis] k[2]``).

    Examples
    --------
    >>> check_magnitudes({"stage": {"m1": 5.0, "m2": 17.5}, "reference": {"frequencies": [5, 10]}})
    >>> check_magnitudes({"hysteresis": {"model": "maxwell-slip", "k": [20.0, 1e-300]}})
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: [hysteresis] k[1] = 1e-300: outside the magnitudes 1e-30 to 1e+30 ...
    """
    if isinstance(data, dict):
        for key, value in data.items():
            if isinstance(value, dict):
                inner = f"{where[1:-1]}.{key}" if where.startswith("[") else str(key)
                check_magnitudes(value, f"[{inner}]")
            else:
                check_magnitudes(value, f"{where} {key}".strip())
    elif isinstance(data, list):
        if _numbers_checked(data, where):
            return
        for i, value in enumerate(data):
            check_magnitudes(value, f"{where}[{i}]")
    elif isinstance(data, int | float) and not isinstance(data, bool):
        check_magnitude(where, data)


def _numbers_checked(values: list, where: str) -> bool:
    """Whether the list `values` holds only numbers (int, float), checked at once as
    :func:`check_magnitude` checks each (the first outside raised, named ``where[i]``): a
    scenario's list of 100 000 values in milliseconds, not a second."""
    if not {type(v) for v in values} <= {float, int}:
        return False
    try:
        a = np.abs(np.asarray(values, dtype=float))
    except OverflowError:  # an integer beyond a float: said where each is checked in turn
        return False
    outside = (a != 0.0) & np.isfinite(a) & ((a < MAGNITUDES[0]) | (a > MAGNITUDES[1]))
    if outside.any():
        i = int(np.argmax(outside))
        check_magnitude(f"{where}[{i}]", values[i])
    return True


def check_finite(name: str, value: float) -> float:
    """Return `value` as float, raising ``ValueError`` unless it is a finite number.

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : float
        Its value.

    Examples
    --------
    >>> from motionhyst.core.validation import check_finite
    >>> check_finite("beta", "0.5")
    0.5
    >>> check_finite("beta", float("nan"))
    Traceback (most recent call last):
    ...
    ValueError: beta must be finite, got nan
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def check_positive(name: str, value: float) -> float:
    """Return `value` as float, raising ``ValueError`` unless finite and > 0.

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : float
        Its value.

    Examples
    --------
    >>> from motionhyst.core.validation import check_positive
    >>> check_positive("k", 20)
    20.0
    >>> check_positive("k", -1.0)
    Traceback (most recent call last):
    ...
    ValueError: k must be finite and > 0, got -1.0
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


def check_amplitudes(A: ArrayLike) -> NDArray[np.float64]:
    """Return amplitudes as a float array, raising ``ValueError`` unless finite and >= 0.

    Parameters
    ----------
    A : array_like
        Amplitude(s) [m].

    Examples
    --------
    >>> from motionhyst.core.validation import check_amplitudes
    >>> check_amplitudes([0.0, 0.01])
    array([0.  , 0.01])
    """
    a = np.asarray(A, dtype=float)
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError("amplitude must be finite and >= 0")
    return a


def check_omega(omega, model: str) -> float:
    """The angular frequency [rad/s] a rate-dependent `model` needs, as a float >= 0.

    Parameters
    ----------
    omega : float or None
        Angular frequency [rad/s].
    model : str
        The model's name, for the message.

    Raises
    ------
    ValueError
        One line: missing (None), not a number, negative or not finite.

    Examples
    --------
    >>> check_omega(10.0, "lugre")
    10.0
    """
    if omega is None:
        raise ValueError(f"the {model} model is rate-dependent: give the angular frequency "
                         "omega [rad/s]")
    try:
        om = float(omega)
    except (TypeError, ValueError):
        raise ValueError(f"omega must be a number, got {omega!r}") from None
    if not np.isfinite(om) or om < 0:
        raise ValueError(f"omega must be finite and >= 0, got {omega!r}")
    return om


CORRELATION_ROUNDING = 1e-9
"""How far below 0, per parameter, the least eigenvalue of a saved correlation matrix may lie
(``identify --save`` rounds it to 1e-12): below, no estimates have that matrix."""


def least_correlation_eigenvalue(c: ArrayLike) -> float:
    """The least eigenvalue of the correlation matrix of the covariance `c` (a standard
    deviation of 0 counted as 1): negative for a matrix that is no covariance.

    Parameters
    ----------
    c : array_like
        A symmetric n x n matrix (a covariance or a correlation matrix), n >= 1.

    Examples
    --------
    >>> round(least_correlation_eigenvalue([[4.0, 1.0], [1.0, 1.0]]), 3)
    0.5
    """
    c = np.asarray(c, dtype=float)
    s = np.sqrt(np.clip(np.diag(c), 0.0, None))
    s = np.where(s > 0, s, 1.0)
    return float(np.linalg.eigvalsh(c / np.outer(s, s))[0])


def check_correlation(c: ArrayLike, names: list[str], hint: str) -> None:
    """Refuse the covariance or correlation matrix `c` of an identification's parameters
    `names` when a variance is negative or its correlation matrix has an eigenvalue below
    ``-CORRELATION_ROUNDING * n``: no estimates have it.  The check of the whole matrix, of
    every parameter, drawn or not (a block may look fine while the whole is impossible).

    Parameters
    ----------
    c : array_like
        Symmetric and finite, n x n.
    names : list of str
        The n parameters (named in the message when they are at most 8).
    hint : str
        The option of ``motionhyst identify`` that writes the file (``--save``, ``--json``).

    Raises
    ------
    ValueError
        One line: the matrix, its least eigenvalue, and the remedy.

    Examples
    --------
    >>> check_correlation([[1.0, 0.5], [0.5, 1.0]], ["k", "fc"], "--save")
    >>> try:
    ...     check_correlation([[1.0, 1.5], [1.5, 1.0]], ["k", "fc"], "--save")
    ... except ValueError as exc:
    ...     print(str(exc).split(" (it has")[0])
    the correlation matrix of its 2 parameters (k, fc) is not positive semi-definite
    """
    c = np.asarray(c, dtype=float)
    n = len(names)
    least = least_correlation_eigenvalue(c) if n else 0.0
    if np.any(np.diag(c) < 0) or least < -CORRELATION_ROUNDING * n:
        named = f" ({', '.join(map(str, names))})" if n <= 8 else ""
        raise ValueError(f"the correlation matrix of its {n} parameters{named} is not positive "
                         f"semi-definite (it has the eigenvalue {least:.3g}): no estimates have "
                         f"it; write the identification again (`motionhyst identify ... "
                         f"{hint}`)")
