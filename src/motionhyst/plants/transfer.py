"""A plant given as two python-control systems ``P1``, ``P2`` and a rigid-body mass."""

from __future__ import annotations

from typing import Any, ClassVar

from motionhyst.plants.base import FixedPlant
from motionhyst.plants.registry import register

__all__ = ["TransferPlant"]


@register
class TransferPlant(FixedPlant):
    """Any plant as python-control systems: ``y1 = P1 (u - w)``, ``y2 = P2 (u - w)``.

    What a :class:`~motionhyst.controllers.loop.Loop` makes of a tuple ``(P1, P2)``: the
    analyses take ``Pf2 = Pr - P2`` and know no static flexible compliance
    (eq. 21 needs a model of the modes: a :class:`~motionhyst.plants.ModalPlant`).

    Parameters
    ----------
    P1, P2 : python-control LTI system
        Collocated and non-collocated transfers [m/N].
    M : float or None
        Rigid-body mass [kg] (None: no feedforward ``M s^2``).

    Examples
    --------
    >>> import control
    >>> from motionhyst.plants import TransferPlant
    >>> P = control.tf([1.0], [22.5, 0.0, 0.0])
    >>> plant = TransferPlant(P, P, 22.5)
    >>> plant.is_lti, plant.pf2_static
    (True, None)
    """

    name: ClassVar[str] = "transfer-functions"
    is_lti: ClassVar[bool] = True
    frequency_range_hz: ClassVar[None] = None
    output: str = "y2"
    force_offset: float = 0.0
    Pf2: ClassVar[None] = None
    pf2_static: ClassVar[None] = None
    no_parameters: ClassVar[str] = "a plant of transfer functions has no parameters"
    no_state_space: ClassVar[str] = (
        "a plant of transfer functions has no state-space form of masses; "
        "give a stage of the plant registry"
    )

    def __init__(self, P1: Any, P2: Any, M: float | None = None) -> None:
        import control

        for s in (P1, P2):
            if not isinstance(s, control.TransferFunction | control.StateSpace):
                raise TypeError(f"P1 and P2 must be python-control LTI systems (measured data: "
                                f"a MeasuredPlant), got {type(s).__name__}")
        self.P1, self.P2 = P1, P2
        self.M = None if M is None else float(M)

    def __repr__(self) -> str:
        return f"TransferPlant(P1={self.P1!r}, P2={self.P2!r}, M={self.M!r})"

    def to_dict(self) -> dict:
        """``type`` and the rigid-body mass (the systems are not written)."""
        return {"type": self.name, "M": self.M}
