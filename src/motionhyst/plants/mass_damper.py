"""A positioning axis: one mass with viscous friction to the ground and no spring.

``m y'' + c y' + d |y'| = u + f0 + f1 t - w``: the carriage of a ball-screw or
linear-motor axis, the force ``u`` of the drive (with an offset ``f0`` that may drift at
``f1`` over the record's time ``t``: a drive or its friction warming up), the link
force ``w`` (friction) on the carriage's position ``y``, which is measured.  The
viscous friction may depend on the direction (``d = c_skew``): ``c + d`` moving
forward, ``c - d`` backward (the EMPS axis's ``Fv+``, ``Fv-``), continuous in the
velocity.  The rigid-body mass ``M = m`` is that of the feedforward ``M s^2``.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.base import LumpedPlant
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.registry import FORCE_OFFSET, PlantParameter, register

__all__ = ["MassDamper"]


@register
class MassDamper(LumpedPlant):
    """One mass with viscous friction to the ground, no spring: ``m y'' + c y' = u + f0 - w``.

    ``P1 = P2 = 1 / (m s^2 + c s)``: the axis floats (only the link holds it).  With
    ``c_skew`` the viscous force is ``c y' + c_skew |y'|``: the transfer functions (and
    the analyses that use them) take its mean ``c``, the time runs from a start the force
    by direction.

    Parameters
    ----------
    m : float
        Mass [kg], > 0.
    c : float
        Viscous damping to the ground [N s/m], >= 0: the mean of the two directions'.
    c_skew : float
        Half the difference of the viscous friction moving forward and backward [N s/m],
        ``|c_skew| <= c``: ``c_pos = c + c_skew`` for ``y' > 0``, ``c_neg = c - c_skew``
        for ``y' < 0`` (the force ``c y' + c_skew |y'|``).  Open-loop time runs from a
        start only (no periodic steady state, no closed loop).
    force_offset : float
        Constant force ``f0`` added to the force on the mass [N].
    force_drift : float
        Rate ``f1`` at which that force changes with the record's time ``t`` [N/s]:
        ``f0 + f1 t`` is added at time ``t`` (the time of the record simulated, its
        first sample not necessarily 0).  A record from a machine warming up (EMPS:
        the force a period of the same motion needs moves by 0.1 N per period);
        simulations from a start only, not periodic steady states.

    Examples
    --------
    The EMPS axis's published values:

    >>> import numpy as np
    >>> from motionhyst.plants import MassDamper
    >>> axis = MassDamper(m=95.1, c=203.5, force_offset=3.16)
    >>> axis
    MassDamper(m=95.1, c=203.5, force_offset=3.16)
    >>> round(axis.corner_hz, 4)                           # c / (2 pi m): friction vs inertia
    0.3406
    >>> G = axis.frequency_response([10.0])[0]             # at 10 Hz nearly 1 / (m s^2)
    >>> print(f"{abs(G) * axis.M * (2 * np.pi * 10.0) ** 2:.4f}")
    0.9994

    Viscous friction by direction (163 N s/m forward, 240 backward):

    >>> axis = MassDamper.by_direction(m=95.1, c_pos=163.0, c_neg=240.0)
    >>> axis.c, axis.c_skew, axis.c_pos, axis.c_neg
    (201.5, -38.5, 163.0, 240.0)
    """

    name: ClassVar[str] = "mass-damper"
    parameters: ClassVar[tuple[PlantParameter, ...]] = (
        PlantParameter("m", "kg", "moving mass"),
        PlantParameter("c", "N s/m", "viscous damping to the ground", "nonnegative"),
        PlantParameter("c_skew", "N s/m", "half the difference of the viscous friction moving "
                       "forward and backward (c + c_skew forward, c - c_skew backward)",
                       "finite", 0.0),
        FORCE_OFFSET,
        PlantParameter("force_drift", "N/s", "rate at which the force offset changes over the "
                       "record's time (a drive or its friction warming up)", "finite", 0.0),
    )
    PARAMETERS: ClassVar[tuple[str, ...]] = ("m", "c")
    has_inertia: ClassVar[bool] = True

    def __init__(self, m: float, c: float, c_skew: float = 0.0, force_offset: float = 0.0,
                 force_drift: float = 0.0) -> None:
        self._set_checked(m=m, c=c, c_skew=c_skew, force_offset=force_offset,
                          force_drift=force_drift)
        if abs(self.c_skew) > self.c:
            raise ValueError(f"c_skew must be within -c .. c (viscous friction >= 0 in both "
                             f"directions), got c_skew = {c_skew!r} with c = {c!r}")

    @classmethod
    def by_direction(cls, m: float, c_pos: float, c_neg: float, force_offset: float = 0.0,
                     force_drift: float = 0.0) -> MassDamper:
        """The axis of viscous friction `c_pos` moving forward and `c_neg` backward.

        Parameters
        ----------
        m : float
            Mass [kg].
        c_pos, c_neg : float
            Viscous friction moving forward and backward [N s/m], >= 0.
        force_offset, force_drift : float
            As for the constructor.

        Returns
        -------
        MassDamper
            ``c = (c_pos + c_neg) / 2``, ``c_skew = (c_pos - c_neg) / 2``.
        """
        return cls(m, 0.5 * (c_pos + c_neg), 0.5 * (c_pos - c_neg), force_offset, force_drift)

    @property
    def c_pos(self) -> float:
        """Viscous friction moving forward ``c + c_skew`` [N s/m]."""
        return self.c + self.c_skew

    @property
    def c_neg(self) -> float:
        """Viscous friction moving backward ``c - c_skew`` [N s/m]."""
        return self.c - self.c_skew

    @property
    def M(self) -> float:
        """Rigid-body mass ``m`` [kg]."""
        return self.m

    @property
    def corner_hz(self) -> float:
        """``c / (2 pi m)`` [Hz]: below it friction dominates the response, above it inertia."""
        return self.c / (2 * np.pi * self.m)

    @property
    def P1(self) -> Any:
        """``y / (u - w) = 1 / (m s^2 + c s)`` (the link acts on the measured mass)."""
        import control

        return control.tf([1.0], [self.m, self.c, 0.0])

    @property
    def P2(self) -> Any:
        """The same as :attr:`P1`: one mass."""
        return self.P1

    @property
    def Pf2(self) -> Any:
        """``Pr - P2 = c / (m s^2 (m s + c))``: the viscous part, not a flexible mode."""
        import control

        return control.tf([self.c], [self.m * self.m, self.m * self.c, 0.0, 0.0])

    def dynamic_stiffness(self, s: NDArray[np.complex128], k_link: float, c_link: float
                          ) -> NDArray[np.complex128]:
        """``m s^2 + (c + c_link) s + k_link``: force over displacement [N/m].

        Parameters
        ----------
        s : ndarray of complex
            ``2 pi j f``.
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m] to the ground.

        Returns
        -------
        ndarray of complex
        """
        return self.m * s * s + (self.c + c_link) * s + k_link

    def mechanics(self, values: ArrayLike | None = None) -> Mechanics:
        """The axis (or the unchecked ``(m, c) = values``) as :class:`Mechanics`.

        Parameters
        ----------
        values : array_like, optional
            ``m, c`` instead of the axis's own.

        Returns
        -------
        Mechanics
            One coordinate, no stiffness (floating), derivatives in ``m, c``; the axis's
            ``c_skew`` and force offset.
        """
        m, c = self.values() if values is None else np.asarray(values, dtype=float)
        return Mechanics([m], [[c]], [[0.0]], [[1.0], [0.0]], [[[0.0]], [[1.0]]],
                         [[[0.0]], [[0.0]]], 0, 0, force_offset=self.force_offset,
                         c_skew=self.c_skew)
