"""The registry of plants and the protocol every plant follows.

A plant is the linear mechanics a dynamic link acts on: the force ``u`` and
the link's force ``w`` act on one coordinate (the link's displacement, ``y1``
in the paper's Fig. 2), one position is measured.  One file of
:mod:`motionhyst.plants` per plant: a class that declares its ``name``, its
:class:`PlantParameter` list and the attributes of :class:`Plant`.
Registering the class (the :func:`register` decorator) is all that makes it
known to the scenario schema (``[stage] type = ...``), the command line's
``--plant`` choices and the documentation: they take their lists from
:data:`PLANTS`.

Examples
--------
>>> from motionhyst.plants.registry import PLANTS, plant_class
>>> "mass-damper" in PLANTS
True
>>> [p.name for p in plant_class("mass-damper").parameters]
['m', 'c', 'c_skew', 'force_offset', 'force_drift']
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal, Protocol, TypeVar, runtime_checkable

from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    import numpy as np

    from motionhyst.plants.mechanics import Mechanics

__all__ = ["PLANTS", "PLAUSIBLE_MASS_KG", "PLAUSIBLE_POLE_HZ", "Plant", "PlantParameter",
           "plant_class", "register", "stage_types"]

ParameterKind = Literal["positive", "nonnegative", "finite"]

_RANGE = {"positive": "> 0", "nonnegative": ">= 0", "finite": "finite"}


@dataclass(frozen=True)
class PlantParameter:
    """One parameter of a plant, as the scenario's ``[stage]`` table spells it.

    Parameters
    ----------
    name : str
        Keyword of the plant's constructor and key in ``[stage]``.
    unit : str
        SI unit.
    help : str
        One line for the documentation and error messages.
    kind : {"positive", "nonnegative", "finite"}
        The range of the value.
    default : float, optional
        Value when not given; None makes the parameter required.

    Examples
    --------
    >>> m = PlantParameter("m", "kg", "mass")
    >>> m.check(2)
    2.0
    >>> m.check(0.0)
    Traceback (most recent call last):
    ...
    ValueError: m must be finite and > 0, got 0.0
    >>> m.range
    '> 0'
    """

    name: str
    unit: str
    help: str
    kind: ParameterKind = "positive"
    default: float | None = None

    @property
    def required(self) -> bool:
        """True if the parameter has no default."""
        return self.default is None

    @property
    def range(self) -> str:
        """The range as the documentation writes it (``"> 0"``, ``">= 0"``, ``"finite"``)."""
        return _RANGE[self.kind]

    def check(self, value: Any) -> float:
        """`value` as a float in the parameter's range, else a one-line ``ValueError``.

        Parameters
        ----------
        value : float
            The value to check.

        Returns
        -------
        float
        """
        if isinstance(value, bool | str | bytes):
            raise ValueError(f"{self.name} must be a number, got {value!r}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{self.name} must be a number, got {value!r}") from None
        bad = (not math.isfinite(v) or (self.kind == "positive" and v <= 0)
               or (self.kind == "nonnegative" and v < 0))
        if bad:
            rng = "" if self.kind == "finite" else f" and {self.range}"
            raise ValueError(f"{self.name} must be finite{rng}, got {value!r}")
        return v


PLAUSIBLE_MASS_KG = (1e-3, 1e4)
"""Masses of motion stages [kg]: one outside, given or fitted, is a warning (a unit slip)."""

PLAUSIBLE_POLE_HZ = 1e5
"""Fastest pole of a motion stage or its loop [Hz] (its bandwidth is some 100 Hz, its internal
modes some kHz): a stiffness or damping that puts one beyond is a warning (a unit slip)."""

#: The optional constant force on the plant, which every plant built from parameters has.
FORCE_OFFSET = PlantParameter("force_offset", "N", "constant force added to the force on the "
                              "plant (a drive's offset)", "finite", 0.0)


@runtime_checkable
class Plant(Protocol):
    """What every plant offers; the analyses, the time engine and identification use only this.

    The mechanics are ``M q'' + C q' + K q = e (u + f0 - w)``: masses ``M``
    (diagonal), damping ``C`` and stiffness ``K`` between the coordinates
    ``q`` and to the ground, the force ``u``, the constant force offset
    ``f0`` and the link force ``w = phi(q . e)`` acting on one coordinate
    ``e`` (the link's displacement, the paper's ``y1``); the output is the
    position `output`.  A plant known only by measured frequency responses
    (``is_lti`` False) offers ``P1``, ``P2`` at its measured lines and no
    state-space form.

    Who needs what:

    * the quasi-linear analysis (eqs. 12-21) and the margins: ``P1``, ``P2``
      (python-control LTI systems or frequency data), ``M``, ``Pf2`` (the
      flexible part of ``P2``; None: ``Pr - P2``), ``pf2_static`` (eq. 21;
      None: the plant has no flexible compliance, and the analysis says so),
      ``frequency_range_hz`` (None: a model, valid at every frequency);
    * the periodic steady state: ``P1``, ``P2`` at every harmonic, so
      ``is_lti``;
    * the closed loop's feedforward ``M s^2``: ``M``, the rigid-body mass;
    * the time engine: :meth:`mechanics` (the state-space realisation, with
      the derivatives of its matrices in :attr:`PARAMETERS` for the forward
      sensitivities) and ``force_offset``;
    * identification: ``PARAMETERS``, :meth:`values`,
      :meth:`with_parameters`, :meth:`frequency_response`, ``output``;
    * the scenario schema, the command line and the documentation:
      ``name``, ``parameters`` and :meth:`to_dict`.

    Attributes
    ----------
    name : str
        Key in :data:`PLANTS` and the scenario's ``[stage] type``.
    parameters : tuple of PlantParameter
        Every constructor parameter, with unit, range and default (empty for
        plants built from data rather than parameters).
    PARAMETERS : tuple of str
        Names of the parameters that :meth:`with_parameters` and
        :meth:`mechanics` take, in that order: those the state-space matrices
        depend on (identification's stage parameters).
    outputs : tuple of str
        The positions that can be measured; ``output`` is the measured one.
    is_lti : bool
        True for a model (transfer functions at every ``s``, a state-space
        form); False for raw measured data (their measured lines only).
    has_inertia : bool
        False for a quasi-static plant (no mass: no :meth:`mechanics`, no
        rigid-body feedforward).
    M : float
        Rigid-body mass ``M`` of ``Pr = 1 / (M s^2)`` and the feedforward [kg].
    force_offset : float
        Constant force added to the force on the plant [N].

    Examples
    --------
    Every registered plant follows the protocol:

    >>> from motionhyst.plants.registry import PLANTS, Plant
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> isinstance(MassDamper(m=95.0, c=200.0), Plant)
    True
    """

    name: ClassVar[str]
    parameters: ClassVar[tuple[PlantParameter, ...]]
    PARAMETERS: ClassVar[tuple[str, ...]]
    outputs: ClassVar[tuple[str, ...]]
    is_lti: ClassVar[bool]
    has_inertia: ClassVar[bool]
    output: str
    M: float
    force_offset: float

    @property
    def P1(self) -> Any:
        """Collocated transfer ``y1 / (u - w)`` (python-control LTI system or FRD)."""

    @property
    def P2(self) -> Any:
        """Transfer to the measured position of the closed loop, ``y2 / (u - w)``."""

    @property
    def Pf2(self) -> Any:
        """Flexible part ``Pr - P2`` from the model's own terms, or None (then ``Pr - P2``)."""

    @property
    def pf2_static(self) -> float | None:
        """``Pf2(0)`` [m/N], the flexible compliance eq. (21) needs; None if the plant has none."""

    @property
    def frequency_range_hz(self) -> tuple[float, float] | None:
        """Measured frequency range [Hz] of data; None for a model."""

    def frequency_response(self, f_hz: ArrayLike, k_link: float = 0.0,
                           c_link: float = 0.0) -> NDArray[np.complex128]:
        """``output / u`` at `f_hz` [m/N], the link a spring `k_link` and damper `c_link`.

        Parameters
        ----------
        f_hz : array_like
            Frequencies [Hz].
        k_link, c_link : float
            The link taken as a spring [N/m] and damper [N s/m].
        """

    def mechanics(self, values: ArrayLike | None = None) -> Mechanics:
        """The state-space realisation (or that with :attr:`PARAMETERS` at `values`).

        Parameters
        ----------
        values : array_like, optional
            Values of :attr:`PARAMETERS` instead of the plant's own (unchecked).
        """

    def values(self) -> NDArray[np.float64]:
        """The values of :attr:`PARAMETERS`."""

    def with_parameters(self, values: ArrayLike) -> Plant:
        """The same plant with :attr:`PARAMETERS` at `values` (checked), the rest kept.

        Parameters
        ----------
        values : array_like
            One value for each of :attr:`PARAMETERS`.
        """

    def to_dict(self) -> dict:
        """The scenario's ``[stage]`` table, with ``type``."""


PLANTS: dict[str, Any] = {}
"""Every registered plant class, keyed by its ``name``, in registration order.

Complete whenever this module can be used: importing it imports its package
:mod:`motionhyst.plants` first, and that imports (registers) every plant."""

_P = TypeVar("_P")


def register(cls: _P) -> _P:
    """Class decorator: add a plant to :data:`PLANTS` under its ``name``.

    Parameters
    ----------
    cls : type
        A class following :class:`Plant`.

    Returns
    -------
    type
        `cls` itself.

    Raises
    ------
    ValueError
        If another class is registered under the same name.

    Examples
    --------
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> register(MassDamper) is MassDamper                  # registering again is harmless
    True
    """
    name = cls.name  # type: ignore[attr-defined]
    if PLANTS.get(name, cls) is not cls:
        raise ValueError(f"a plant named {name!r} is already registered")
    PLANTS[name] = cls
    return cls


def plant_class(name: str) -> Any:
    """The registered plant class of a scenario's ``[stage] type = name``.

    Parameters
    ----------
    name : str
        The plant's name.

    Returns
    -------
    type

    Raises
    ------
    ValueError
        One line naming the known plants.

    Examples
    --------
    >>> plant_class("mass-damper")(m=95.0, c=200.0)
    MassDamper(m=95.0, c=200.0)
    >>> plant_class("spring")                               # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: unknown plant 'spring'; known: ...
    """
    try:
        return PLANTS[name]
    except KeyError:
        raise ValueError(f"unknown plant {name!r}; known: {', '.join(PLANTS)}") from None


def stage_types() -> list[str]:
    """Names of the plants a scenario's ``[stage]`` table builds from parameters.

    Returns
    -------
    list of str

    Examples
    --------
    >>> "mass-damper" in stage_types()
    True
    """
    return [name for name, cls in PLANTS.items() if cls.parameters]
