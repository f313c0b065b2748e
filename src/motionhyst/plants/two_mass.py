"""The floating two-mass stage of the paper's Fig. 2, eqs. (1)-(2): one class for the closed
loop (``P1``, ``P2``) and for the open loop (force in, a position out)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.registry import FORCE_OFFSET, PlantParameter, register

__all__ = ["TwoMassStage"]

__all__ = ["TwoMassStage"]


@register
class TwoMassStage:
    """Floating two-mass stage of the paper's Fig. 2, eqs. (1)-(2).

    .. math::

        m_1 \\ddot y_1 + b (\\dot y_1 - \\dot y_2) + k (y_1 - y_2) + c_1 \\dot y_1
        = u + f_0 - w, \\qquad
        m_2 \\ddot y_2 + b (\\dot y_2 - \\dot y_1) + k (y_2 - y_1) + c_2 \\dot y_2 = 0.

    Mass `m1` is actuated (position ``y1``, where the dynamic link acts, its
    force ``w`` a function of ``y1``), mass `m2` carries the point of control
    (position ``y2``); they are connected by a spring `k` and damper `b`.
    Optional dampers `c1`, `c2` connect the masses to the ground (a guide's
    viscous friction; the paper's stage has none).  In a closed loop the
    stage is ``P1``, ``P2``; as an open-loop plant (force in) the measured
    position is `output`.

    No spring holds the stage to the ground except the link: with a link that
    has no stiffness (or none, ``w = 0``) a force with a nonzero mean makes the
    stage run away, and a periodic steady state is defined up to a constant
    position.

    Parameters
    ----------
    m1, m2 : float
        Masses [kg], > 0.
    b : float
        Damper between the masses [N s/m], >= 0.
    k : float
        Spring between the masses [N/m], > 0.
    output : {"y2", "y1"}, optional
        The measured position of the open-loop plant (force in): given, the
        stage is an open-loop plant as a scenario's ``[stage]`` with
        ``output`` (:attr:`open_loop`); omitted, the stage of a closed loop,
        whose open-loop response is that of ``y2``.
    c1, c2 : float
        Dampers from ``m1`` and ``m2`` to the ground [N s/m], >= 0 (default 0).
    force_offset : float
        Constant force ``f0`` added to the force on ``m1`` [N] (default 0).

    Attributes
    ----------
    M : float
        Total mass ``m1 + m2`` [kg].
    open_loop : bool
        True if built with an `output`; :meth:`to_dict` then names the
        ``type`` and the ``output``, as an open-loop scenario does.

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

    As an open-loop plant, force in, ``y2`` out:

    >>> G = stage.frequency_response([10.0], k_link=0.0)     # y2 / u: nearly 1 / (M s^2)
    >>> round(float(abs(G[0]) * stage.M * (2 * np.pi * 10.0) ** 2), 4)
    1.0002
    """

    name: ClassVar[str] = "two-mass"
    parameters: ClassVar[tuple[PlantParameter, ...]] = (
        PlantParameter("m1", "kg", "actuated mass (the link acts on its position y1)"),
        PlantParameter("m2", "kg", "mass at the point of control (position y2)"),
        PlantParameter("b", "N s/m", "damper between the masses", "nonnegative"),
        PlantParameter("k", "N/m", "spring between the masses"),
        PlantParameter("c1", "N s/m", "damper from m1 to the ground", "nonnegative", 0.0),
        PlantParameter("c2", "N s/m", "damper from m2 to the ground", "nonnegative", 0.0),
        FORCE_OFFSET,
    )
    PARAMETERS: ClassVar[tuple[str, ...]] = ("m1", "m2", "b", "k")
    outputs: ClassVar[tuple[str, ...]] = ("y2", "y1")
    OUTPUTS = outputs
    is_lti: ClassVar[bool] = True
    has_inertia: ClassVar[bool] = True
    frequency_range_hz: ClassVar[None] = None

    def __init__(self, m1: float, m2: float, b: float, k: float, output: str | None = None,
                 c1: float = 0.0, c2: float = 0.0, force_offset: float = 0.0) -> None:
        spec = {p.name: p for p in self.parameters}
        self.m1 = spec["m1"].check(m1)
        self.m2 = spec["m2"].check(m2)
        self.b = spec["b"].check(b)
        self.k = spec["k"].check(k)
        if output is not None and output not in self.outputs:
            raise ValueError(f"output must be 'y2' or 'y1', got {output!r}")
        self.output = output or "y2"
        self.open_loop = output is not None
        self.c1 = spec["c1"].check(c1)
        self.c2 = spec["c2"].check(c2)
        self.force_offset = spec["force_offset"].check(force_offset)
        self.M = self.m1 + self.m2

    def __repr__(self) -> str:
        extra = "".join(f", {name}={value!r}" for name, value, default in (
            ("output", self.output, "" if self.open_loop else "y2"), ("c1", self.c1, 0.0),
            ("c2", self.c2, 0.0), ("force_offset", self.force_offset, 0.0)) if value != default)
        return f"TwoMassStage(m1={self.m1}, m2={self.m2}, b={self.b}, k={self.k}{extra})"

    @property
    def grounded(self) -> bool:
        """True if a damper connects a mass to the ground (``c1`` or ``c2`` > 0)."""
        return self.c1 > 0 or self.c2 > 0

    def polynomials(self) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                   NDArray[np.float64]]:
        """Numerators of ``P1``, ``P2`` and their common denominator (highest power first),
        eq. (1): the coefficients of :attr:`P1` and :attr:`P2`, known without python-control.

        Examples
        --------
        >>> from motionhyst import TwoMassStage
        >>> n1, n2, den = TwoMassStage(m1=1.0, m2=2.0, b=0.0, k=3.0).polynomials()
        >>> n1.tolist(), n2.tolist(), den.tolist()    # (2 s^2 + 3) / (2 s^4 + 9 s^2), ...
        ([2.0, 0.0, 3.0], [0.0, 3.0], [2.0, 0.0, 9.0, 0.0, 0.0])
        """
        m1, m2, b, k = self.m1, self.m2, self.b, self.k
        if not self.grounded:  # eq. (1) as the paper writes it
            den = np.array([m1 * m2, b * self.M, k * self.M, 0.0, 0.0])
            return np.array([m2, b, k]), np.array([b, k]), den
        z1 = np.array([m1, b + self.c1, k])
        z2 = np.array([m2, b + self.c2, k])
        den = np.polysub(np.polymul(z1, z2), np.polymul([b, k], [b, k]))
        den[-1] = 0.0  # exactly: det Z(0) = k^2 - k^2
        return z2, np.array([b, k]), den

    @property
    def _flex_den(self) -> list[float]:
        M = self.M
        return [M * self.m1 * self.m2, M * self.b * M, M * self.k * M]

    @property
    def Pr(self) -> Any:
        """Rigid-body dynamics ``1 / (M s^2)``, eq. (1)."""
        import control

        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def Pf1(self) -> Any:
        """Flexible part of the collocated transfer, eq. (2) (``P1 - Pr`` with ground dampers)."""
        import control

        if self.grounded:
            return control.minreal(self.P1 - self.Pr, verbose=False)
        return control.tf([self.m2**2], self._flex_den)

    @property
    def Pf2(self) -> Any:
        """Flexible part of the non-collocated transfer, eq. (2) (``Pr - P2`` with ground
        dampers)."""
        import control

        if self.grounded:
            return control.minreal(self.Pr - self.P2, verbose=False)
        return control.tf([self.m1 * self.m2], self._flex_den)

    @property
    def pf2_static(self) -> float | None:
        """``Pf2(0) = m1 m2 / (k M^2)`` [m/N] (eq. 21); None with ground dampers, where
        ``Pr - P2`` has no static value."""
        if self.grounded:
            return None
        return self.m1 * self.m2 / (self.k * self.M**2)

    @property
    def P1(self) -> Any:
        """Collocated transfer ``y1 / (u - w) = Pr + Pf1``, eq. (1)."""
        import control

        num, _, den = self.polynomials()
        return control.tf(num, den)

    @property
    def P2(self) -> Any:
        """Non-collocated transfer ``y2 / (u - w) = Pr - Pf2``, eq. (1)."""
        import control

        _, num, den = self.polynomials()
        return control.tf(num, den)

    @property
    def resonance_hz(self) -> float:
        """Undamped frequency of the internal mode, ``sqrt(k M / (m1 m2)) / (2 pi)`` [Hz]."""
        return float(np.sqrt(self.k * self.M / (self.m1 * self.m2)) / (2.0 * np.pi))

    def ss(self) -> Any:
        """State-space form, state ``(y1, y2, y1', y2')``, input ``u - w``, outputs ``(y1, y2)``."""
        import control

        A, B = self.mechanics().state_space()
        C = [[1, 0, 0, 0], [0, 1, 0, 0]]
        return control.ss(A, B[:, None], C, [[0], [0]], inputs="f", outputs=["y1", "y2"])

    def frequency_response(self, f_hz: ArrayLike, k_link: float = 0.0, c_link: float = 0.0
                           ) -> NDArray[np.complex128]:
        """The output over the force at `f_hz` [m/N], the link a spring `k_link` and damper
        `c_link` on ``y1`` (both 0: eq. (1), ``P2`` or ``P1``).

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz].
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m] to the ground.

        Returns
        -------
        ndarray of complex
        """
        return self.mechanics().frequency_response(f_hz, k_link, c_link)

    def values(self) -> NDArray[np.float64]:
        """``(m1, m2, b, k)`` (:attr:`PARAMETERS`)."""
        return np.array([self.m1, self.m2, self.b, self.k])

    def with_parameters(self, values: ArrayLike) -> TwoMassStage:
        """The same stage (output, ground dampers, force offset) with ``(m1, m2, b, k) =
        values`` (checked).

        Parameters
        ----------
        values : array_like
            ``m1, m2, b, k``.

        Returns
        -------
        TwoMassStage
        """
        m1, m2, b, k = (float(v) for v in values)
        return TwoMassStage(m1, m2, b, k, self.output if self.open_loop else None, self.c1,
                            self.c2, self.force_offset)

    def mechanics(self, values: ArrayLike | None = None) -> Mechanics:
        """The stage (or the unchecked ``(m1, m2, b, k) = values``) as :class:`Mechanics`.

        Parameters
        ----------
        values : array_like, optional
            ``m1, m2, b, k`` instead of the stage's own.

        Returns
        -------
        Mechanics
            Coordinates ``(y1, y2)``, the link on ``y1``, the output `output`.
        """
        m1, m2, b, k = self.values() if values is None else np.asarray(values, dtype=float)
        D = np.array([[1.0, -1.0], [-1.0, 1.0]])
        Z = np.zeros((2, 2))
        C = b * D
        if self.grounded:
            C = C + np.diag([self.c1, self.c2])
        return Mechanics([m1, m2], C, k * D, [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0], [0.0, 0.0]],
                         [Z, Z, D, Z], [Z, Z, Z, D], 0, 0 if self.output == "y1" else 1,
                         force_offset=self.force_offset)

    def stage(self) -> TwoMassStage:
        """The same stage (kept for the open-loop plant's callers)."""
        return self

    def to_dict(self) -> dict:
        """The scenario's ``[stage]`` table: ``type`` and ``output`` for an open-loop plant
        (the closed loop's stage is the default type), ``c1``, ``c2``, ``force_offset`` only
        when not 0."""
        out = {"m1": self.m1, "m2": self.m2, "b": self.b, "k": self.k}
        if self.open_loop:
            out = {"type": self.name, **out, "output": self.output}
        out.update({name: v for name, v in (("c1", self.c1), ("c2", self.c2),
                                            ("force_offset", self.force_offset)) if v})
        return out
