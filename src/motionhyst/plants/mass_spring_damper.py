"""One mass on a linear spring and damper to the ground: the stage of the Bouc-Wen benchmark
(Noel and Schoukens 2016) and of any single-mass test rig."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.base import LumpedPlant
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.registry import FORCE_OFFSET, PlantParameter, register

__all__ = ["MassSpringDamper"]


@register
class MassSpringDamper(LumpedPlant):
    """A single mass on a linear spring and damper: ``m y'' + c y' + k y = u + f0 - w``.

    ``P1 = P2 = 1 / (m s^2 + c s + k)``, the link on the measured position.

    Parameters
    ----------
    m : float
        Mass [kg], > 0.
    c : float
        Viscous damping [N s/m], >= 0.
    k : float
        Stiffness [N/m], >= 0 (0: a floating mass, :class:`~motionhyst.plants.MassDamper`).
    force_offset : float
        Constant force ``f0`` added to the force on the mass [N] (default 0).

    Examples
    --------
    >>> from motionhyst.plants import MassSpringDamper
    >>> p = MassSpringDamper(m=2.0, c=10.0, k=5e4)
    >>> round(p.resonance_hz, 2), round(p.damping_ratio, 4)
    (25.16, 0.0158)
    >>> abs(p.frequency_response(0.0))   # 1 / k at DC
    2e-05
    """

    name: ClassVar[str] = "mass-spring-damper"
    parameters: ClassVar[tuple[PlantParameter, ...]] = (
        PlantParameter("m", "kg", "mass"),
        PlantParameter("c", "N s/m", "viscous damping to the ground", "nonnegative"),
        PlantParameter("k", "N/m", "spring to the ground", "nonnegative"),
        FORCE_OFFSET,
    )
    #: Names of the parameters, in the order of :meth:`values`.
    PARAMETERS: ClassVar[tuple[str, ...]] = ("m", "c", "k")
    has_inertia: ClassVar[bool] = True

    def __init__(self, m: float, c: float, k: float, force_offset: float = 0.0) -> None:
        self._set_checked(m=m, c=c, k=k, force_offset=force_offset)

    @property
    def M(self) -> float:
        """Rigid-body mass ``m`` [kg]."""
        return self.m

    @property
    def resonance_hz(self) -> float:
        """Undamped natural frequency ``sqrt(k/m) / (2 pi)`` [Hz]."""
        return math.sqrt(self.k / self.m) / (2 * math.pi)

    @property
    def damping_ratio(self) -> float:
        """``c / (2 sqrt(k m))`` [-] (inf for ``k = 0``)."""
        return self.c / (2 * math.sqrt(self.k * self.m)) if self.k > 0 else math.inf

    def polynomials(self) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                   NDArray[np.float64]]:
        """Numerators of :attr:`P1` and :attr:`P2` (one mass: the same) and their denominator
        ``m s^2 + c s + k`` (highest power first), known without python-control.

        Examples
        --------
        >>> from motionhyst.plants import MassSpringDamper
        >>> [p.tolist() for p in MassSpringDamper(m=2.0, c=10.0, k=5e4).polynomials()]
        [[1.0], [1.0], [2.0, 10.0, 50000.0]]
        """
        return np.ones(1), np.ones(1), np.array([self.m, self.c, self.k])

    @property
    def P1(self) -> Any:
        """``y / (u - w) = 1 / (m s^2 + c s + k)`` (the link acts on the measured mass)."""
        import control

        num, _, den = self.polynomials()
        return control.tf(num, den)

    @property
    def P2(self) -> Any:
        """The same as :attr:`P1`: one mass."""
        return self.P1

    @property
    def Pf2(self) -> Any:
        """``Pr - P2 = (c s + k) / (m s^2 (m s^2 + c s + k))``: not a flexible mode."""
        import control

        m = self.m
        return control.tf([self.c, self.k], [m * m, m * self.c, m * self.k, 0.0, 0.0])

    def dynamic_stiffness(self, s: NDArray[np.complex128], k_link: float, c_link: float
                          ) -> NDArray[np.complex128]:
        """``m s^2 + (c + c_link) s + k + k_link``: force over displacement [N/m].

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
        return self.m * s * s + (self.c + c_link) * s + (self.k + k_link)

    def mechanics(self, values: ArrayLike | None = None) -> Mechanics:
        """The plant (or the unchecked ``(m, c, k) = values``) as :class:`Mechanics`.

        Parameters
        ----------
        values : array_like, optional
            ``m, c, k`` instead of the plant's own.

        Returns
        -------
        Mechanics
        """
        m, c, k = self.values() if values is None else np.asarray(values, dtype=float)
        return Mechanics([m], [[c]], [[k]], [[1.0], [0.0], [0.0]],
                         [[[0.0]], [[1.0]], [[0.0]]], [[[0.0]], [[0.0]], [[1.0]]], 0, 0,
                         force_offset=self.force_offset)
