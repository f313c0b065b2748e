"""What a measured response is refused for before its fit (:mod:`motionhyst.plants.frf_fit`).

Checks on the measured ``P1``, ``P2`` of a stage (paper eq. 1) that need no fit,
each refusing with one line that names the cause:

- the rigid body at the lowest lines: ``P1`` and ``P2`` there are both ``1/(M s^2)``
  (``Re P < 0``), a stage's flexible part being small below its first mode;
- a given delay ``tau`` that, divided out, turns lowest lines that are a rigid body
  into lines that are not (:func:`check_delay`);

They cost milliseconds where the fit costs a second or more, and python-control is
not loaded for them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from motionhyst.plants.modal import TWO_PI

__all__ = ["FrfInputError", "check_delay", "check_response", "rigid_body_share"]

#: A line is a rigid body's when its phase is within 60 deg of -180 deg: the median of
#: ``-Re P / |P|`` (the cosine of that angle) over the lowest decade at least this.
RIGID_SHARE_MIN = 0.5


class FrfInputError(ValueError):
    """A measured response refused before its fit, and what it blames.

    Parameters
    ----------
    message : str
        The one line that says why.
    key : str
        What is blamed: ``"file"`` (the data) or ``"delay"`` (the delay given); a scenario
        names ``[plant] file`` or ``[plant] delay`` after it.

    Examples
    --------
    >>> err = FrfInputError("1 s turns the phase of the lowest lines ...", "delay")
    >>> err.key, isinstance(err, ValueError)
    ('delay', True)
    """

    def __init__(self, message: str, key: str = "file") -> None:
        super().__init__(message)
        self.key = key


def rigid_body_share(f: NDArray[np.float64], p1: NDArray[np.complex128],
                     p2: NDArray[np.complex128]) -> float:
    """Median of ``-Re P / |P|`` of ``P1`` and ``P2`` over the lowest measured decade: 1 for
    a rigid body ``1/(M s^2)``, the cosine of the median angle of the lines from -180 deg.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Responses at `f` [m/N].

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> rigid_body_share(f, p, p), rigid_body_share(f, -p, -p)
    (1.0, -1.0)
    """
    low = f <= f[0] * 10.0
    q = np.concatenate([p1[low], p2[low]])
    return float(np.median(-q.real / np.abs(q)))


def check_delay(f: NDArray[np.float64], p1: NDArray[np.complex128],
                p2: NDArray[np.complex128], delay: float) -> None:
    """Refuse a given delay [s] that turns lowest lines that are a rigid body into lines
    that are not.

    A measurement chain delays both transfers by ``e^{-s tau}`` with ``tau`` of
    microseconds to milliseconds (sample-and-hold, computation): divided out, it leaves
    the lowest lines the rigid body they are.  A delay that turns them by a large angle
    while they are a rigid body without it (:func:`rigid_body_share` at least
    :data:`RIGID_SHARE_MIN`) is not the data's: 1 s turns the lines of 1-10 Hz by whole
    turns.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Measured responses at `f` [m/N], the delay not divided out.
    delay : float
        The delay given [s].

    Raises
    ------
    FrfInputError
        With ``key = "delay"``.

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> check_delay(f, p, p, 50e-6)                        # microseconds: as it should be
    >>> check_delay(f, p, p, 1.0)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: 1 s turns the phase of the lowest lines \
(1-9.237 Hz) by 360-3325 deg: with it divided out they are no longer a rigid body \
1/(M s^2) (median 76 deg from -180 deg), which they are without it; a measurement chain delays by \
microseconds to milliseconds: is it in seconds? (omit it: the fit estimates the delay)
    """
    if not delay > 0:
        return
    rot = np.exp(1j * TWO_PI * f * delay)
    after = rigid_body_share(f, p1 * rot, p2 * rot)
    if after >= RIGID_SHARE_MIN or rigid_body_share(f, p1, p2) < RIGID_SHARE_MIN:
        return
    top = f[f <= f[0] * 10.0][-1]
    raise FrfInputError(
        f"{delay:g} s turns the phase of the lowest lines ({f[0]:.4g}-{top:.4g} Hz) by "
        f"{360 * f[0] * delay:.4g}-{360 * top * delay:.4g} deg: with it divided out they are "
        f"no longer a rigid body 1/(M s^2) (median {np.degrees(np.arccos(after)):.0f} deg from "
        f"-180 deg), which they are without it; a measurement chain delays by microseconds "
        f"to milliseconds: is it in seconds? (omit it: the fit estimates the delay)", "delay")


def check_response(f: NDArray[np.float64], p1: NDArray[np.complex128],
                   p2: NDArray[np.complex128], mass: float | None = None,
                   delay: float | None = None) -> None:
    """Every check of this module, cheapest and most specific first: a given delay, then
    the rigid body at the lowest decade (when the mass is fitted).

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], positive and increasing.
    p1, p2 : ndarray of complex
        Measured responses at `f` [m/N], finite and nonzero, the delay not divided out.
    mass : float, optional
        The rigid-body mass when given [kg] (then the rigid body is not checked).
    delay : float, optional
        The delay given [s].

    Raises
    ------
    FrfInputError

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> check_response(f, p, p)
    >>> check_response(f, -p, -p)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: the data do not look like a rigid body \
1/(M s^2) at the lowest measured frequencies (Re P > 0); give the mass or check the data
    """
    if delay:
        check_delay(f, p1, p2, delay)
        rot = np.exp(1j * TWO_PI * f * delay)
        p1, p2 = p1 * rot, p2 * rot
    if mass is None:
        low = f <= f[0] * 10.0
        w2 = (TWO_PI * f[low]) ** 2
        if not float(np.median(np.concatenate([-w2 * p1[low].real, -w2 * p2[low].real]))) > 0:
            raise FrfInputError("the data do not look like a rigid body 1/(M s^2) at the "
                                "lowest measured frequencies (Re P > 0); give the mass or "
                                "check the data")
