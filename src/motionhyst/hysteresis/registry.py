"""The registry of link models: every model, keyed by the name a scenario uses.

A link model is one file of :mod:`motionhyst.hysteresis`: a subclass of
:class:`~motionhyst.hysteresis.base.Hysteresis` that declares its ``name``, its
:class:`Parameter` list and how the compiled time simulation steps it
(:meth:`~motionhyst.hysteresis.base.Hysteresis.time_stepping`).  Registering
the class (the :func:`register` decorator) is all that makes it known to the
scenario schema (``[hysteresis] model = ...``), ``motionhyst df --model``, the
report and the figures: they take their model lists from :data:`MODELS`.

Examples
--------
>>> from motionhyst.hysteresis.registry import MODELS, model_class
>>> list(MODELS)[:2]
['jenkins', 'maxwell-slip']
>>> model_class("jenkins").parameters[0].name
'k'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, TypeVar

__all__ = ["MODELS", "Form", "Parameter", "model_class", "register"]

ParameterKind = Literal["positive", "nonnegative", "finite"]


@dataclass(frozen=True)
class Parameter:
    """One parameter of a link model, as scenarios and the CLI spell it.

    Parameters
    ----------
    name : str
        Keyword of the model's constructor, key in the scenario's
        ``[hysteresis]`` table and ``--name`` option of ``motionhyst df``
        (underscores written as dashes there).
    unit : str
        SI unit (``""`` for a pure number).
    help : str
        One line for ``--help`` and the documentation.
    default : float or tuple of float, optional
        Value when not given (a tuple for a list parameter, ``()`` for none);
        ``None`` makes the parameter required.
    kind : {"positive", "nonnegative", "finite"}
        The range a single value must lie in (the model's constructor states
        any further rule).
    many : bool
        A list of values (one per element of a parallel model).
    parallel : {"", "spring", "damper"}
        ``"spring"`` (``"damper"``) if the parameter only adds a linear spring
        ``p x`` (damper ``p dx/dt``) in parallel with the rest of the link:
        on a stage with its own spring and damper its effect cannot be told
        from the stage's (input-output identification fixes it at 0).
    maximum : float, optional
        The largest value a scenario or ``motionhyst df`` accepts, where the model stops
        describing a link (a typing slip, not a design: refused, naming it); None: no bound.
        An identification's search is not bound by it.

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> [(p.name, p.unit, p.default) for p in Jenkins.parameters]
    [('k', 'N/m', None), ('fc', 'N', None)]
    """

    name: str
    unit: str
    help: str
    default: float | tuple[float, ...] | None = None
    kind: ParameterKind = "positive"
    many: bool = False
    parallel: Literal["", "spring", "damper"] = ""
    maximum: float | None = None

    @property
    def required(self) -> bool:
        """True if the parameter has no default."""
        return self.default is None


@dataclass(frozen=True)
class Form:
    """Another spelling of a link model's parameters, with its own constructor.

    A scenario's ``[hysteresis]`` table with ``model = name`` is read in this
    form when it has one of the form's keys that the model's own
    ``parameters`` lack (e.g. Bouc-Wen's ``alpha``, ``delta``, ``nu``).

    Parameters
    ----------
    name : str
        The form's name in messages (``"general"``).
    constructor : str
        Name of the class method that builds the model from these parameters.
    parameters : tuple of Parameter
        The form's parameters.

    Examples
    --------
    >>> from motionhyst import BoucWen
    >>> form = BoucWen.forms[0]
    >>> form.name, form.constructor, [p.name for p in form.parameters]
    ('general', 'from_general', ['alpha', 'beta', 'gamma', 'delta', 'nu'])
    """

    name: str
    constructor: str
    parameters: tuple[Parameter, ...]


MODELS: dict[str, Any] = {}
"""Every registered link model (a :class:`~motionhyst.hysteresis.base.Hysteresis` subclass),
keyed by its ``name``, in registration order."""

_H = TypeVar("_H")


def register(cls: _H) -> _H:
    """Class decorator: add a link model to :data:`MODELS` under its ``name``.

    Raises
    ------
    ValueError
        If another class is registered under the same name.

    Examples
    --------
    The registry that scenarios and the command line take their models from:

    >>> from motionhyst.hysteresis import MODELS, Jenkins, register
    >>> list(MODELS)[:2]
    ['jenkins', 'maxwell-slip']
    >>> register(Jenkins) is Jenkins                       # registering again is harmless
    True
    """
    name = cls.name  # type: ignore[attr-defined]
    if MODELS.get(name, cls) is not cls:
        raise ValueError(f"a link model named {name!r} is already registered")
    MODELS[name] = cls  # type: ignore[assignment]
    return cls


def model_class(name: str) -> Any:
    """The registered model class of a scenario's ``model = name``.

    Parameters
    ----------
    name : str
        A registered model's name (``[hysteresis] model = name``).

    Raises
    ------
    ValueError
        One line naming the known models.

    Examples
    --------
    >>> from motionhyst.hysteresis import model_class
    >>> model_class("maxwell-slip")(k=[10.0, 6.0], fc=[0.01, 0.03])
    MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03])
    >>> model_class("preisach")                            # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: unknown link model 'preisach'; known: jenkins, maxwell-slip, ...
    """
    try:
        return MODELS[name]
    except KeyError:
        raise ValueError(f"unknown link model {name!r}; known: {', '.join(MODELS)}") from None
