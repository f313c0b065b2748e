"""Floating two-mass stage of the paper's Fig. 2, eqs. (1)-(2)."""

from __future__ import annotations

import control
import numpy as np

from motionhyst.core.lti import TWO_PI
from motionhyst.hysteresis.base import check_positive

__all__ = ["TwoMassStage"]


class TwoMassStage:
    """Floating two-mass stage of the paper's Fig. 2, eqs. (1)-(2).

    Mass `m1` is actuated (position ``y1``, where the dynamic link acts), mass
    `m2` carries the point of control (position ``y2``); they are connected
    by a spring `k` and damper `b`.

    Parameters
    ----------
    m1, m2 : float
        Masses [kg], > 0.
    b : float
        Internal damping [N s/m], >= 0.
    k : float
        Internal stiffness [N/m], > 0.

    Attributes
    ----------
    M : float
        Total mass ``m1 + m2`` [kg].

    Examples
    --------
    >>> from motionhyst import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)   # Table I
    >>> stage.M
    22.5
    >>> round(stage.resonance_hz, 1)
    694.3
    >>> import numpy as np
    >>> s = 2j * np.pi * 10.0                  # 10 Hz, far below the resonance
    >>> print(f"{abs(stage.P1(s) / stage.Pr(s)):.4f}")   # P1, Pr: control.TransferFunction
    0.9993
    """

    def __init__(self, m1: float, m2: float, b: float, k: float) -> None:
        self.m1 = check_positive("m1", m1)
        self.m2 = check_positive("m2", m2)
        self.k = check_positive("k", k)
        b = float(b)
        if not np.isfinite(b) or b < 0:
            raise ValueError(f"b must be finite and >= 0, got {b!r}")
        self.b = b
        self.M = self.m1 + self.m2

    def __repr__(self) -> str:
        return f"TwoMassStage(m1={self.m1}, m2={self.m2}, b={self.b}, k={self.k})"

    @property
    def _flex_den(self) -> list[float]:
        M = self.M
        return [M * self.m1 * self.m2, M * self.b * M, M * self.k * M]

    @property
    def Pr(self) -> control.TransferFunction:
        """Rigid-body dynamics ``1 / (M s^2)``, eq. (1)."""
        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def Pf1(self) -> control.TransferFunction:
        """Flexible part of the collocated transfer, eq. (2)."""
        return control.tf([self.m2**2], self._flex_den)

    @property
    def Pf2(self) -> control.TransferFunction:
        """Flexible part of the non-collocated transfer, eq. (2)."""
        return control.tf([self.m1 * self.m2], self._flex_den)

    @property
    def P1(self) -> control.TransferFunction:
        """Collocated transfer ``y1 / (u - w) = Pr + Pf1``, eq. (1)."""
        m1, m2, b, k = self.m1, self.m2, self.b, self.k
        return control.tf([m2, b, k], [m1 * m2, b * self.M, k * self.M, 0.0, 0.0])

    @property
    def P2(self) -> control.TransferFunction:
        """Non-collocated transfer ``y2 / (u - w) = Pr - Pf2``, eq. (1)."""
        b, k = self.b, self.k
        return control.tf([b, k], [self.m1 * self.m2, b * self.M, k * self.M, 0.0, 0.0])

    @property
    def resonance_hz(self) -> float:
        """Undamped frequency of the internal mode, ``sqrt(k M / (m1 m2)) / (2 pi)`` [Hz]."""
        return float(np.sqrt(self.k * self.M / (self.m1 * self.m2)) / TWO_PI)

    def ss(self) -> control.StateSpace:
        """State-space form, state ``(y1, y2, y1', y2')``, input ``u - w``, outputs ``(y1, y2)``."""
        m1, m2, b, k = self.m1, self.m2, self.b, self.k
        A = [[0, 0, 1, 0], [0, 0, 0, 1], [-k / m1, k / m1, -b / m1, b / m1],
             [k / m2, -k / m2, b / m2, -b / m2]]
        B = [[0], [0], [1 / m1], [0]]
        C = [[1, 0, 0, 0], [0, 1, 0, 0]]
        return control.ss(A, B, C, [[0], [0]], inputs="f", outputs=["y1", "y2"])

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"m1": self.m1, "m2": self.m2, "b": self.b, "k": self.k}
