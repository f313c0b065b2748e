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

__all__ = ["check_amplitudes", "check_finite", "check_omega", "check_positive"]


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
