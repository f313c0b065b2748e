"""A rigid body plus flexible modes shared by ``P1`` and ``P2`` (paper eqs. 1-2, modal form).

``P1 = 1/(M s^2) + sum r1_i / (s^2 + 2 z_i w_i s + w_i^2)``,
``P2 = 1/(M s^2) - sum r2_i / (s^2 + 2 z_i w_i s + w_i^2)``: the form a measured
stage is fitted to (:func:`motionhyst.plants.frf_fit.fit_frf`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.base import FixedPlant
from motionhyst.plants.registry import register

__all__ = ["ModalPlant", "Mode"]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Mode:
    """One flexible mode of a :class:`ModalPlant` (its uncertainties are in
    :class:`~motionhyst.plants.frf_fit.FrfFit`).

    Attributes
    ----------
    frequency_hz : float
        Undamped natural frequency ``w / (2 pi)`` [Hz].
    damping : float
        Damping ratio ``z`` [-].
    r1, r2 : float
        Residues of the collocated and non-collocated transfers [1/kg].

    Examples
    --------
    The Table I stage's mode (eq. 2: ``r1 = m2 / (M m1)``, ``r2 = 1 / M``):

    >>> from motionhyst.plants import ModalPlant, Mode
    >>> plant = ModalPlant(22.5, [Mode(694.27, 0.00265, 17.5 / (22.5 * 5.0), 1 / 22.5)])
    >>> f"{plant.pf2_static:.3e}"                          # Pf2(0) = sum r2 / w^2 [m/N]
    '2.336e-09'
    """

    frequency_hz: float
    damping: float
    r1: float
    r2: float


def _modal_polys(M: float, modes: tuple[Mode, ...]):
    """Numerators and denominators of ``P1``, ``P2``, ``Pf1``, ``Pf2`` (highest power first)."""
    from motionhyst.core.lti import polysub_exact, trim

    qs = [np.array([1.0, 2.0 * m.damping * TWO_PI * m.frequency_hz, (TWO_PI * m.frequency_hz) ** 2])
          for m in modes]
    q_all = np.array([1.0])
    for q in qs:
        q_all = np.polymul(q_all, q)
    others = []
    for i in range(len(qs)):
        p = np.array([1.0])
        for j, q in enumerate(qs):
            if j != i:
                p = np.polymul(p, q)
        others.append(p)
    nf1 = sum((m.r1 * p for m, p in zip(modes, others, strict=True)), np.zeros(1))
    nf2 = sum((m.r2 * p for m, p in zip(modes, others, strict=True)), np.zeros(1))
    s2 = np.array([1.0, 0.0, 0.0])
    den = np.polymul(s2, q_all)
    # coefficients that cancel to round-off are exactly zero (for the two-mass stage the
    # leading ones of P2: 1/M - r2 = 0), so the transfer functions keep their true degree
    n1 = trim(polysub_exact(q_all / M, -np.polymul(s2, nf1)))
    n2 = trim(polysub_exact(q_all / M, np.polymul(s2, nf2)))
    return n1, n2, den, nf1, nf2, q_all


@register
class ModalPlant(FixedPlant):
    """Rigid body plus flexible modes shared by ``P1`` and ``P2`` (paper eqs. 1-2, modal form).

    ``P1 = 1/(M s^2) + sum r1_i / (s^2 + 2 z_i w_i s + w_i^2)``,
    ``P2 = 1/(M s^2) - sum r2_i / (s^2 + 2 z_i w_i s + w_i^2)``.  It offers
    what :class:`~motionhyst.plants.two_mass.TwoMassStage` offers (``P1``, ``P2``,
    ``Pr``, ``Pf1``, ``Pf2`` as python-control transfer functions, ``M``), so
    a :class:`~motionhyst.controllers.loop.Loop` and every analysis take it.

    Parameters
    ----------
    M : float
        Rigid-body mass [kg], > 0.
    modes : sequence of Mode
        Flexible modes (may be empty: a pure rigid body).
    source : str
        Where the plant came from.

    Examples
    --------
    >>> from motionhyst.plants import ModalPlant, TwoMassStage
    >>> p = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    >>> round(p.modes[0].frequency_hz, 2), round(p.modes[0].damping, 5)
    (694.26, 0.00265)
    >>> f"{p.pf2_static:.4e}"  # Pf2(0) = m1 m2 / (k M^2) [m/N]
    '2.3357e-09'
    """

    name: ClassVar[str] = "modal"
    output: ClassVar[str] = "y2"
    is_lti: ClassVar[bool] = True
    force_offset: ClassVar[float] = 0.0
    frequency_range_hz: ClassVar[None] = None
    no_parameters: ClassVar[str] = "a modal plant has no parameters to set"
    no_state_space: ClassVar[str] = (
        "a modal plant has no state-space form of lumped masses (its residues "
        "need not be those of masses); the closed loop runs on P1 and P2"
    )

    def __init__(self, M: float, modes=(), source: str = "") -> None:
        M = float(M)
        if not (np.isfinite(M) and M > 0):
            raise ValueError(f"M must be finite and > 0, got {M!r}")
        self.M = M
        self.modes = tuple(sorted((Mode(float(m.frequency_hz), float(m.damping), float(m.r1),
                                        float(m.r2)) for m in modes),
                                  key=lambda m: m.frequency_hz))
        for m in self.modes:
            if not (m.frequency_hz > 0 and m.damping > 0 and np.isfinite(m.r1)
                    and np.isfinite(m.r2)):
                raise ValueError(f"invalid mode {m}")
        self.source = source
        self._tf: dict | None = None  # the polynomials, made when a transfer is asked for

    @classmethod
    def from_two_mass(cls, stage) -> ModalPlant:
        """The modal form of a :class:`~motionhyst.plants.two_mass.TwoMassStage` (eq. 2).

        Parameters
        ----------
        stage : TwoMassStage
            The stage; its one flexible mode becomes the plant's mode.

        Returns
        -------
        ModalPlant
        """
        m1, m2, M = stage.m1, stage.m2, stage.M
        w = np.sqrt(stage.k * M / (m1 * m2))
        mode = Mode(frequency_hz=w / TWO_PI, damping=stage.b * M / (m1 * m2) / (2 * w),
                    r1=m2 / (M * m1), r2=1.0 / M)
        return cls(M, (mode,), source=repr(stage))

    def __repr__(self) -> str:
        return f"ModalPlant(M={self.M:.6g}, modes={list(self.modes)})"

    def _get(self, name: str) -> Any:
        import control

        if self._tf is None:
            n1, n2, den, nf1, nf2, q = _modal_polys(self.M, self.modes)
            self._tf = {"P1": (n1, den), "P2": (n2, den), "Pf1": (nf1, q), "Pf2": (nf2, q)}
        num, den = self._tf[name]
        return control.tf(num, den)

    @property
    def P1(self) -> Any:
        """Collocated transfer ``y1 / (u - w) = Pr + Pf1``, eq. (1)."""
        return self._get("P1")

    @property
    def P2(self) -> Any:
        """Non-collocated transfer ``y2 / (u - w) = Pr - Pf2``, eq. (1)."""
        return self._get("P2")

    @property
    def Pf1(self) -> Any:
        """Flexible part of ``P1`` (sum of the modes' ``r1`` terms)."""
        return self._get("Pf1")

    @property
    def Pf2(self) -> Any:
        """Flexible part of ``P2``, ``Pr - P2`` (sum of the modes' ``r2`` terms)."""
        return self._get("Pf2")

    @property
    def Pr(self) -> Any:
        """Rigid-body dynamics ``1 / (M s^2)``, eq. (1)."""
        import control

        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def pf2_static(self) -> float:
        """``Pf2(0) = sum r2_i / w_i^2`` [m/N]: the flexible compliance that eq. (20) divides by."""
        return float(sum(m.r2 / (TWO_PI * m.frequency_hz) ** 2 for m in self.modes))

    @property
    def resonance_hz(self) -> float:
        """Frequency of the lowest mode [Hz] (nan without modes)."""
        return self.modes[0].frequency_hz if self.modes else float("nan")

    def response(self, omega: ArrayLike) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """``P1(j omega)`` and ``P2(j omega)`` evaluated term by term [m/N].

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].

        Returns
        -------
        P1, P2 : ndarray of complex
            The collocated and the non-collocated responses.
        """
        w = np.asarray(omega, dtype=float)
        s = 1j * w
        with np.errstate(divide="ignore"):
            pr = 1.0 / (self.M * s**2)
        f1 = np.zeros(w.shape, complex)
        f2 = np.zeros(w.shape, complex)
        for m in self.modes:
            wn = TWO_PI * m.frequency_hz
            g = 1.0 / (s**2 + 2 * m.damping * wn * s + wn**2)
            f1 += m.r1 * g
            f2 += m.r2 * g
        return pr + f1, pr - f2

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"type": "modal", "M": self.M,
                "modes": [{"frequency_hz": m.frequency_hz, "damping": m.damping, "r1": m.r1,
                           "r2": m.r2} for m in self.modes]}
