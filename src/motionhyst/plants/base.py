"""What plants of one kind share: the code of the :class:`~motionhyst.plants.registry.Plant`
protocol written once.

* :class:`LumpedPlant`: one position, given by its parameters (masses, dampers, springs) and
  a force offset; a subclass declares them and its dynamic stiffness, the rest
  (checking, ``repr``, :meth:`~LumpedPlant.values`, :meth:`~LumpedPlant.with_parameters`,
  :meth:`~LumpedPlant.to_dict`, the frequency response) comes from here.
* :class:`FixedPlant`: a plant with nothing to set (measured lines, a modal fit, a pair of
  transfer functions): no parameters, no state-space form of masses.

Examples
--------
>>> from motionhyst.plants import MassDamper, MeasuredPlant
>>> from motionhyst.plants.base import FixedPlant, LumpedPlant
>>> issubclass(MassDamper, LumpedPlant), issubclass(MeasuredPlant, FixedPlant)
(True, True)
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.plants.registry import PlantParameter

__all__ = ["FixedPlant", "LumpedPlant"]


class LumpedPlant:
    """A plant of one position ``y`` given by its :attr:`PARAMETERS` and a force offset.

    A subclass declares ``name``, ``parameters`` (:class:`PlantParameter` of each
    constructor argument, ``force_offset`` last), ``PARAMETERS`` (the names
    :meth:`values` returns, in the constructor's order) and
    :meth:`dynamic_stiffness`; its constructor calls :meth:`_set_checked`.

    Examples
    --------
    >>> from motionhyst.plants import MassSpringDamper
    >>> msd = MassSpringDamper(2.0, 0.5, 800.0)
    >>> msd.with_parameters([2.0, 0.5, 200.0])
    MassSpringDamper(m=2.0, c=0.5, k=200.0)
    >>> msd.to_dict()
    {'type': 'mass-spring-damper', 'm': 2.0, 'c': 0.5, 'k': 800.0}
    """

    name: ClassVar[str]
    parameters: ClassVar[tuple[PlantParameter, ...]]
    PARAMETERS: ClassVar[tuple[str, ...]]
    outputs: ClassVar[tuple[str, ...]] = ("y",)
    output: str = "y"
    is_lti: ClassVar[bool] = True
    frequency_range_hz: ClassVar[None] = None
    pf2_static: ClassVar[None] = None  # no flexible compliance: eq. (21) does not apply
    force_offset: float

    def _set_checked(self, **values: float) -> None:
        """Each value, checked against its :class:`PlantParameter`, as an attribute."""
        spec = {p.name: p for p in self.parameters}
        for name, value in values.items():
            setattr(self, name, spec[name].check(value))

    def _forces(self) -> dict[str, float]:
        """The parameters besides :attr:`PARAMETERS` (the force offset, and its drift where
        the plant has one), by name."""
        return {p.name: getattr(self, p.name) for p in self.parameters
                if p.name not in self.PARAMETERS}

    def __repr__(self) -> str:
        args = ", ".join(f"{n}={getattr(self, n)!r}" for n in self.PARAMETERS)
        extra = "".join(f", {n}={v!r}" for n, v in self._forces().items() if v)
        return f"{type(self).__name__}({args}{extra})"

    def dynamic_stiffness(self, s: NDArray[np.complex128], k_link: float, c_link: float
                          ) -> NDArray[np.complex128]:
        """Force over displacement at the Laplace variable `s`, the link a spring and damper.

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
        raise NotImplementedError

    def frequency_response(self, f_hz: ArrayLike, k_link: float = 0.0, c_link: float = 0.0
                           ) -> NDArray[np.complex128] | complex:
        """``y / u``, one over :meth:`dynamic_stiffness`, at ``s = 2 pi j f`` [m/N].

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz].
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m] to the ground.

        Returns
        -------
        complex or ndarray of complex
            Same shape as `f_hz` (inf where nothing holds the displacement).
        """
        s = 2j * np.pi * np.asarray(f_hz, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = 1.0 / self.dynamic_stiffness(s, k_link, c_link)
        return complex(out) if np.ndim(out) == 0 else out

    def values(self) -> NDArray[np.float64]:
        """The values of :attr:`PARAMETERS`, in their order."""
        return np.array([getattr(self, n) for n in self.PARAMETERS])

    def with_parameters(self, values: ArrayLike) -> Any:
        """The same kind of plant (same force offset) with :attr:`PARAMETERS` = `values`
        (checked).

        Parameters
        ----------
        values : array_like
            One value for each of :attr:`PARAMETERS`.

        Returns
        -------
        LumpedPlant
            Of the same class.
        """
        values = [float(v) for v in values]
        if len(values) != len(self.PARAMETERS):
            raise ValueError(f"{len(values)} values for the {len(self.PARAMETERS)} parameters "
                             f"{', '.join(self.PARAMETERS)}")
        return type(self)(*values, **self._forces())

    def to_dict(self) -> dict:
        """The scenario's ``[stage]`` table, with ``type`` (``force_offset`` and
        ``force_drift`` only when not 0)."""
        out: dict[str, Any] = {"type": self.name}
        out.update((n, getattr(self, n)) for n in self.PARAMETERS)
        out.update((n, v) for n, v in self._forces().items() if v)
        return out


class FixedPlant:
    """A plant with nothing to set: no :attr:`PARAMETERS`, no state-space form of masses.

    A subclass gives ``P1`` and ``P2`` (or overrides :meth:`response`) and the two
    sentences it refuses with, ``no_parameters`` and ``no_state_space``.

    Examples
    --------
    >>> import control
    >>> from motionhyst.plants import TransferPlant
    >>> plant = TransferPlant(control.tf([1.0], [1.0, 0.0, 0.0]),
    ...                       control.tf([1.0], [1.0, 0.0, 0.0]), M=1.0)
    >>> plant.with_parameters([]) is plant
    True
    >>> print(f"{abs(plant.frequency_response([1.0])[0]) * (2 * 3.141592653589793) ** 2:.6f}")
    1.000000
    """

    parameters: ClassVar[tuple[PlantParameter, ...]] = ()
    PARAMETERS: ClassVar[tuple[str, ...]] = ()
    outputs: ClassVar[tuple[str, ...]] = ("y2",)
    has_inertia: ClassVar[bool] = True
    no_parameters: ClassVar[str] = "this plant has no parameters to set"
    no_state_space: ClassVar[str] = "this plant has no state-space form of masses"
    P1: Any
    P2: Any

    def response(self, omega: ArrayLike) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """``(P1, P2)`` at the angular frequencies `omega`.

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].

        Returns
        -------
        tuple of two ndarray of complex
        """
        from motionhyst.core.lti import freqresp

        return freqresp(self.P1, omega), freqresp(self.P2, omega)

    def frequency_response(self, f_hz: ArrayLike, k_link: float = 0.0, c_link: float = 0.0
                           ) -> NDArray[np.complex128]:
        """``y2 / u`` at `f_hz` [m/N], the link a spring `k_link` and damper `c_link` on ``y1``:
        ``P2 / (1 + Z P1)``.

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz] (for measured lines: inside their range).
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m].

        Returns
        -------
        ndarray of complex
        """
        w = 2.0 * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
        p1, p2 = self.response(w)
        return p2 / (1.0 + (k_link + 1j * w * c_link) * p1)

    def values(self) -> NDArray[np.float64]:
        """No parameters: an empty array."""
        return np.zeros(0)

    def with_parameters(self, values: ArrayLike) -> Any:
        """The plant itself (it has no :attr:`PARAMETERS`).

        Parameters
        ----------
        values : array_like
            Empty.

        Returns
        -------
        FixedPlant
            This plant.
        """
        if np.size(values):
            raise ValueError(self.no_parameters)
        return self

    def mechanics(self, values: ArrayLike | None = None) -> Any:
        """A ``ValueError``: the plant has no state-space form of masses.

        Parameters
        ----------
        values : array_like, optional
            Ignored.
        """
        raise ValueError(self.no_state_space)
