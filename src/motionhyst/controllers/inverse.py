"""The stage's inverse as a series in the setpoint's derivatives: the derivative feedforward.

A feedforward ``u_ff = C_ff r`` that makes the error ``e = PS (1/P2 - C_ff) r``
vanish is ``C_ff = 1 / P2``, improper: a setpoint gives only the derivatives
its profile has (a fourth-order profile: up to the snap ``r''''``, piecewise
constant).  The Taylor series of ``1 / P2`` about ``s = 0``::

    1 / P2(s) = c1 s + c2 s^2 + c3 s^3 + c4 s^4 + c5 s^5 + ...

gives the feedforward ``u_ff = c1 r' + c2 r'' + c3 r''' + c4 r''''`` (viscous,
acceleration, jerk, snap) and leaves ``PS c5 r^(5) + ...``: for a fourth-order
profile, impulses at the switching instants of the snap.  For the floating
two-mass stage of eqs. (1)-(2), ``P2 = (b s + k) / (s^2 (m1 m2 s^2 + M (b s +
k)))`` with dampers ``c1``, ``c2`` to the ground zero, the series is::

    1 / P2 = M s^2 + (m1 m2 / k) s^4 - (m1 m2 b / k^2) s^5 + ...

the compliance (snap) term ``m1 m2 / k = M^2 P_f2(0)`` (eq. 21) and no jerk
term: the internal damper ``b`` enters with the fifth derivative.  Dampers to
the ground give the velocity and jerk terms::

    c1 + c2,   M + c1 c2 / k,   (m1 c2 + m2 c1) / k - b c1 c2 / k^2,
    m1 m2 / k - b (m1 c2 + m2 c1) / k^2 + b^2 c1 c2 / k^3

(for ``s``, ``s^2``, ``s^3``, ``s^4``).  A fitted modal plant (``P2 = 1 / (M
s^2) - P_f2``) gives ``M s^2 + M^2 P_f2(0) s^4 + M^2 P_f2'(0) s^5 + ...`` from
its fit: the same computation on its polynomials.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from motionhyst.core.lti import tf_poly

__all__ = ["StageInverse", "stage_inverse"]

#: Orders of the series' terms and their names, as the feedforward calls them.
TERMS = {1: "viscous", 2: "acceleration", 3: "jerk", 4: "snap", 5: "crackle"}


@dataclass(frozen=True)
class StageInverse:
    """The Taylor coefficients c1 to c5 of ``1 / P2(s)`` about ``s = 0``.

    Parameters
    ----------
    viscous, acceleration, jerk, snap : float
        ``c1`` [N s/m], ``c2`` [kg], ``c3`` [N s^3/m], ``c4`` [N s^4/m]: the
        feedforward's coefficients of ``r'``, ``r''``, ``r'''``, ``r''''``.
    crackle : float
        ``c5`` [N s^5/m]: the first term a fourth-order profile cannot give.

    Examples
    --------
    >>> from motionhyst import TwoMassStage
    >>> inv = stage_inverse(TwoMassStage(5.0, 17.5, 90.0, 7.4e7))
    >>> print(f"M = {inv.acceleration:.6g} kg, m1 m2 / k = {inv.snap:.4g} N s^4/m")
    M = 22.5 kg, m1 m2 / k = 1.182e-06 N s^4/m
    >>> inv.jerk                                # the internal damper gives no jerk term
    0.0
    """

    viscous: float
    acceleration: float
    jerk: float
    snap: float
    crackle: float

    def to_dict(self) -> dict:
        """The coefficients by name (JSON keys spelled here)."""
        return {name: getattr(self, name) for name in TERMS.values()}


def _series_ratio(num_desc, den_desc, order: int) -> np.ndarray:
    """Taylor coefficients ``q_0 .. q_order`` of ``num(s) / den(s)`` (``den(0) != 0``)."""
    n = np.asarray(num_desc, dtype=float)[::-1]
    d = np.asarray(den_desc, dtype=float)[::-1]
    n = np.concatenate([n, np.zeros(max(0, order + 1 - n.size))])
    d = np.concatenate([d, np.zeros(max(0, order + 1 - d.size))])
    q = np.zeros(order + 1)
    for i in range(order + 1):
        q[i] = (n[i] - np.dot(q[:i], d[i:0:-1])) / d[0]
    return q


def stage_inverse(plant) -> StageInverse:
    """The series of ``1 / P2`` of `plant` up to ``s^5`` (module docstring).

    Parameters
    ----------
    plant : Plant
        A plant of :mod:`motionhyst.plants` whose ``P2`` is a rational transfer
        of a free rigid body (an integrator at least: two-mass stage, modal
        plant, ...).

    Returns
    -------
    StageInverse

    Raises
    ------
    ValueError
        For a plant without a rational ``P2`` (measured data), held by a spring,
        or whose ``1 / P2`` has no series at ``s = 0`` (``P2`` with a zero there).

    Examples
    --------
    The modal form of the stage gives the same compliance term from its fit:

    >>> from motionhyst import TwoMassStage
    >>> from motionhyst.plants import ModalPlant
    >>> stage = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)
    >>> a, b = stage_inverse(stage), stage_inverse(ModalPlant.from_two_mass(stage))
    >>> round(b.snap / a.snap, 9), round(b.acceleration, 9)
    (1.0, 22.5)
    """
    try:
        num, den = tf_poly(plant.P2, "the plant's P2")
    except (TypeError, ValueError, AttributeError):
        raise ValueError("the derivative feedforward needs a plant model with a rational P2 "
                         "(a measured plant has none: fit it)") from None
    num = np.trim_zeros(np.asarray(num, dtype=float), "f")
    if num.size == 0 or num[-1] == 0.0:
        raise ValueError("the plant's P2 is zero at s = 0: its inverse has no series there")
    if den.size < 2 or den[-1] != 0.0:
        raise ValueError("the plant's P2 is not a free rigid body (held by a spring, 1 / P2 "
                         "has a static term)")
    c = _series_ratio(den, num, 5)
    if not all(math.isfinite(x) for x in c):
        raise ValueError("the plant's P2 has no finite inverse series at s = 0")
    vals = [float(x) for x in c[1:6]]
    return StageInverse(*vals)

