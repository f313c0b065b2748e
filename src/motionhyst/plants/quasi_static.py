"""A plant without inertia: the force balances the link (and an optional spring and damper).

``u + f0 = w(y) + k y + c y'``: for records where no inertia is visible
(piezo actuators, friction dampers tested slowly), the displacement ``y`` is
where the link's force ``w`` (any model of :mod:`motionhyst.hysteresis`) and
the optional parallel spring ``k`` and damper ``c`` balance the force ``u``
with its offset ``f0``.  It has no state-space form of masses
(:attr:`has_inertia` False): its response is the link's own, force from
displacement, or displacement from force by solving the balance.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.base import LumpedPlant
from motionhyst.plants.registry import FORCE_OFFSET, PlantParameter, register

__all__ = ["QuasiStatic"]


@register
class QuasiStatic(LumpedPlant):
    """No inertia: ``u + f0 = w(y) + k y + c y'``.

    Parameters
    ----------
    k : float
        Spring in parallel with the link [N/m], >= 0 (default 0).
    c : float
        Damper in parallel with the link [N s/m], >= 0 (default 0).
    force_offset : float
        Constant force ``f0`` added to the force [N] (default 0).

    Examples
    --------
    >>> from motionhyst.plants import QuasiStatic
    >>> piezo = QuasiStatic(k=2.0e6)
    >>> piezo
    QuasiStatic(k=2000000.0, c=0.0)
    >>> abs(piezo.frequency_response(0.0))                # 1 / k without a link [m/N]
    5e-07
    >>> piezo.mechanics()                                  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: a quasi-static plant has no inertia, hence no state-space form of masses: ...
    """

    name: ClassVar[str] = "quasi-static"
    parameters: ClassVar[tuple[PlantParameter, ...]] = (
        PlantParameter("k", "N/m", "spring in parallel with the link", "nonnegative", 0.0),
        PlantParameter("c", "N s/m", "damper in parallel with the link", "nonnegative", 0.0),
        FORCE_OFFSET,
    )
    PARAMETERS: ClassVar[tuple[str, ...]] = ("k", "c")
    has_inertia: ClassVar[bool] = False
    M: ClassVar[float] = 0.0
    Pf2: ClassVar[None] = None

    def __init__(self, k: float = 0.0, c: float = 0.0, force_offset: float = 0.0) -> None:
        self._set_checked(k=k, c=c, force_offset=force_offset)

    @property
    def P1(self) -> Any:
        """``y / (u - w) = 1 / (c s + k)`` (ValueError without spring and damper)."""
        import control

        if self.k == 0 and self.c == 0:
            raise ValueError("a quasi-static plant without spring and damper has no transfer "
                             "function: the link alone sets the displacement")
        return control.tf([1.0], [self.c, self.k])

    @property
    def P2(self) -> Any:
        """The same as :attr:`P1`."""
        return self.P1

    def dynamic_stiffness(self, s: NDArray[np.complex128], k_link: float, c_link: float
                          ) -> NDArray[np.complex128]:
        """``(c + c_link) s + k + k_link``: force over displacement [N/m] (0 where nothing
        holds the displacement).

        Parameters
        ----------
        s : ndarray of complex
            ``2 pi j f``.
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m].

        Returns
        -------
        ndarray of complex
        """
        return (self.c + c_link) * s + (self.k + k_link)

    def mechanics(self, values: ArrayLike | None = None) -> Any:
        """None: a ``ValueError``, the plant has no masses.

        Parameters
        ----------
        values : array_like, optional
            Ignored.

        Raises
        ------
        ValueError
            Always.
        """
        raise ValueError("a quasi-static plant has no inertia, hence no state-space form of "
                         "masses: its displacement is where the link's force balances the force")
