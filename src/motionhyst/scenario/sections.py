"""The tables of a scenario file, one pydantic model each, and their one-line errors.

``[stage]`` (or ``[plant]``), ``[hysteresis]``, ``[controller]``, ``[feedforward]``
and ``[reference]``: the stage and link tables are built from the registries
(:data:`~motionhyst.plants.registry.PLANTS`, :data:`~motionhyst.hysteresis.registry.MODELS`),
so a registered plant or link model is a valid ``type`` / ``model`` with its own
keys.  :class:`~motionhyst.scenario.schema.Scenario` validates a whole file with
:class:`ScenarioModel`; a problem becomes a :class:`ScenarioError` naming the
file, the key and the problem.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    TypeAdapter,
    ValidationError,
    create_model,
    model_validator,
)

from motionhyst.core.validation import check_correlation
from motionhyst.hysteresis import MODELS, Hysteresis, model_class
from motionhyst.hysteresis.registry import Form
from motionhyst.plants.registry import PLANTS, plant_class, stage_types

__all__ = ["ScenarioError", "hysteresis_from_dict"]


class ScenarioError(ValueError):
    """A scenario file that cannot be used; the message is one line.

    Examples
    --------
    >>> from motionhyst import Scenario, ScenarioError
    >>> try:
    ...     Scenario.from_dict({"stage": {"m1": -5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7},
    ...                         "hysteresis": {"model": "jenkins", "k": 20.0, "fc": 0.05},
    ...                         "controller": {"type": "tf", "num": [1.0], "den": [1.0]},
    ...                         "reference": {"amplitude": 0.01, "frequencies": [5.0]}})
    ... except ScenarioError as err:
    ...     print(err)
    <dict>: [stage] m1: Input should be greater than 0 (got -5.0)
    """


PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]
_FIELD_TYPES = {"positive": PositiveFloat, "nonnegative": NonNegativeFloat,
                "finite": Annotated[float, Field(allow_inf_nan=False)]}


class _Section(BaseModel):
    # strict: no strings for numbers; integers are accepted where floats are expected;
    # validators are built at the first validation, not at import (command start-up)
    model_config = ConfigDict(extra="forbid", strict=True, defer_build=True)

    @model_validator(mode="before")
    @classmethod
    def _no_booleans(cls, data):
        if isinstance(data, dict):
            for key, value in data.items():
                if isinstance(value, bool):
                    raise ValueError(f"{key}: expected a number, got a boolean")
        return data


class _StageSection(_Section):
    """A ``[stage]`` section: field types here, the plant's own rules in its class.

    After the fields are validated the plant is built once, so that its
    constructor's checks are the only statement of them.
    """

    @model_validator(mode="after")
    def _plant_accepts(self):
        self.build()
        return self

    def build(self, closed_loop: bool = False):
        """The plant the section describes (the closed loop's: without an ``output``)."""
        values = self.model_dump(exclude={"type"}, exclude_none=True)
        if closed_loop:
            values.pop("output", None)
        return plant_class(self.type)(**values)


#: The plant a ``[stage]`` without ``type`` describes: the paper's two-mass stage.
DEFAULT_STAGE = "two-mass"


def _stage_section(name: str, cls) -> type[_StageSection]:
    """The ``[stage] type = name`` section, from the plant's declared parameters.

    A plant with more than one measurable position takes an ``output`` (which
    makes the stage an open-loop system, force in, that position out); a plant
    with one is one unless the scenario gives a ``[controller]`` (which measures it).
    """
    if name == DEFAULT_STAGE:
        fields: dict = {"type": (Annotated[Literal[name], Field(exclude=True)], name)}
    else:
        fields = {"type": (Literal[name], ...)}
    for p in cls.parameters:  # optional ones left out of the table stay out of its dump
        t = _FIELD_TYPES[p.kind]
        fields[p.name] = (t, ...) if p.required else (t | None, None)
    if len(cls.outputs) > 1:
        fields["output"] = (Literal[cls.outputs] | None, None)
    section = create_model(f"{cls.__name__}Section", __base__=_StageSection, **fields)
    what = ("the default" if name == DEFAULT_STAGE else "open loop: force in, position out"
            + ("" if len(cls.outputs) > 1 else "; with a [controller], its closed loop"))
    section.__doc__ = f"``[stage] type = \"{name}\"``: {first_line(cls)} ({what})."
    return section


def first_line(obj) -> str:
    """The first line of an object's docstring."""
    doc = (obj.__doc__ or "").strip().splitlines()
    return doc[0].strip().rstrip(".") if doc else ""


#: The section of each ``[stage] type = ...``, one per plant built from parameters.
STAGE_SECTIONS: dict[str, type[_StageSection]] = {
    name: _stage_section(name, PLANTS[name]) for name in stage_types()}


def _stage_tag(data) -> str | None:
    """Tag of a ``[stage]`` table: its ``type``, ``"two-mass"`` when absent."""
    if isinstance(data, dict):
        return data.get("type", DEFAULT_STAGE)
    return getattr(data, "type", None)


StageUnion = Annotated[
    Union[tuple(Annotated[section, Tag(tag)]  # noqa: UP007
                for tag, section in STAGE_SECTIONS.items())],
    Discriminator(_stage_tag)]


def _is_open_loop(stage, controller=None) -> bool:
    """A ``[stage]`` of an open-loop system: an ``output`` given, or a plant with one position
    and no ``[controller]`` (with one, the loop measures that position)."""
    return stage is not None and (getattr(stage, "output", None) is not None
                                  or (len(PLANTS[stage.type].outputs) == 1
                                      and controller is None))


def open_loop_kinds() -> str:
    """The ``[stage]`` types that are always open-loop systems, for messages."""
    names = [n for n in STAGE_SECTIONS if len(PLANTS[n].outputs) == 1]
    return ", ".join(names[:-1]) + f" or {names[-1]}" if len(names) > 1 else names[0]


def open_loop_what(stage) -> str:
    """What an open-loop ``[stage]`` is, for messages."""
    if getattr(stage, "output", None) is not None:
        return f'a {stage.type} stage with output = "{stage.output}"'
    return f"a {stage.type} stage"


class PlantSection(_Section):
    """``[plant]``: a measured plant (CSV of P1 and P2, see :func:`load_frd_plant`).

    ``use = "fit"`` (default) fits the data to a rigid body plus ``modes``
    flexible modes (:func:`motionhyst.plants.frf_fit.fit_frf`; the number chosen by
    the BIC when ``modes`` is omitted) and analyses the fitted model;
    ``use = "data"`` keeps the raw data: only measured frequencies are
    evaluated.  ``mass`` fixes the rigid-body mass [kg]; ``delay`` fixes the
    input-output delay of the measurement [s] (default: estimated by the fit).
    """

    type: Literal["frd"] = "frd"
    file: str
    mass: PositiveFloat | None = None
    use: Literal["fit", "data"] = "fit"
    modes: Annotated[int, Field(ge=0, le=20)] | None = None
    delay: NonNegativeFloat | None = None

    @model_validator(mode="after")
    def _modes_need_fit(self):
        for key in ("modes", "delay"):
            if self.use == "data" and getattr(self, key) is not None:
                raise ValueError(f'{key} applies to use = "fit" only')
        if self.modes == 0:  # decided here, not after a fit
            raise ValueError("modes = 0 leaves a rigid body alone, with Pf2 = 0 and no link "
                             "between P1 and P2 to analyse; give modes >= 1, or omit it (the "
                             "BIC chooses them)")
        return self


class _LinkSection(_Section):
    """A ``[hysteresis]`` section: field types here, the model's own rules in its class.

    After the fields are validated the model is built once, so that its
    constructor's checks (``beta >= gamma``, equal lengths, ...) are the only
    statement of them; their messages become validation errors.  A section of
    another :class:`~motionhyst.hysteresis.registry.Form` of a model builds it
    with the form's constructor and rejects the keys of the model's own
    spelling that the form lacks.  ``along = { position = [...], NAME = [...] }``
    scales parameters along the stroke
    (:class:`~motionhyst.hysteresis.along_stroke.AlongStroke`).
    """

    along: dict[str, list[float]] | None = None

    @model_validator(mode="before")
    @classmethod
    def _one_spelling(cls, data):
        form = _SECTION_FORMS.get(cls)
        if form is not None and isinstance(data, dict):
            own = {p.name for p in form.parameters}
            mixed = sorted(k for k in data if k not in ("model", "along") and k not in own)
            if mixed:
                theirs = sorted(own - {p.name for p in model_class(data["model"]).parameters})
                raise ValueError(f"{', '.join(mixed)} (not of the {form.name} form) and "
                                 f"{', '.join(theirs)} ({form.name} form) cannot be mixed in "
                                 f"one {data['model']} table")
        return data

    @model_validator(mode="after")
    def _model_accepts(self):
        self.build()
        return self

    def build(self) -> Hysteresis:
        """The model the section describes."""
        cls = model_class(self.model)
        form = _SECTION_FORMS.get(type(self))
        make = cls if form is None else getattr(cls, form.constructor)
        link = make(**self.model_dump(exclude={"model", "along"}))
        if self.along is None:
            return link
        from motionhyst.hysteresis.along_stroke import AlongStroke

        along = dict(self.along)
        if "position" not in along:
            raise ValueError("along needs position = [...] (the stroke positions [m]) and "
                             "the scales of the parameters there")
        return AlongStroke(link, along.pop("position"), along)



def _link_section(name: str, cls: type[Hysteresis], form: Form | None = None
                  ) -> type[_LinkSection]:
    """The ``[hysteresis] model = name`` section, from the model's declared parameters
    (or those of one of its other forms)."""
    fields: dict = {"model": (Literal[name], ...)}
    for p in cls.parameters if form is None else form.parameters:
        t = _FIELD_TYPES[p.kind]
        if p.maximum is not None:
            t = Annotated[t, Field(le=p.maximum)]
        default = ... if p.required else p.default
        if p.many:  # a list; one with a default (a tuple) may be empty
            t = Annotated[list[t], Field(min_length=1 if p.required else 0)]
            default = default if p.required else list(default)
        fields[p.name] = (t, default)
    suffix = "" if form is None else form.name.capitalize()
    section = create_model(f"{cls.__name__}{suffix}Section", __base__=_LinkSection, **fields)
    what = f"the {cls.__name__} model" + ("" if form is None else f" in its {form.name} form")
    section.__doc__ = f"``[hysteresis] model = \"{name}\"``: {what}."
    if form is not None:
        _SECTION_FORMS[section] = form
    return section


def _form_tag(name: str, form: Form) -> str:
    return f"{name} ({form.name} form)"


#: the other forms of the models, by section
_SECTION_FORMS: dict[type, Form] = {}

#: The section of each ``[hysteresis] model = ...``, one per registered link model.
LINK_SECTIONS: dict[str, type[_LinkSection]] = {
    name: _link_section(name, cls) for name, cls in MODELS.items()}

#: Sections of the models' other forms (:class:`~motionhyst.hysteresis.registry.Form`), by tag.
FORM_SECTIONS: dict[str, type[_LinkSection]] = {
    _form_tag(name, form): _link_section(name, cls, form)
    for name, cls in MODELS.items() for form in getattr(cls, "forms", ())}


def _link_tag(data) -> str | None:
    """Tag of a ``[hysteresis]`` table: its model, or one of the model's other forms when
    the table has a key of that form that the model's own parameters lack."""
    if not isinstance(data, dict):
        section = _SECTION_FORMS.get(type(data))
        model = getattr(data, "model", None)
        return model if section is None else _form_tag(model, section)
    model = data.get("model")
    if not isinstance(model, str):
        return None
    cls = MODELS.get(model)
    for form in getattr(cls, "forms", ()):
        own = {p.name for p in cls.parameters}
        if any(p.name in data and p.name not in own for p in form.parameters):
            return _form_tag(model, form)
    return model


HysteresisSection = Annotated[
    Union[tuple(Annotated[section, Tag(tag)]  # noqa: UP007
                for tag, section in {**LINK_SECTIONS, **FORM_SECTIONS}.items())],
    Discriminator(_link_tag)]


class FeedforwardSection(_Section):
    """``[feedforward]``: rigid-body ``M r''`` or none, plus friction terms and a hysteresis model.

    ``hysteresis = { model = "maxwell-slip", k = [...], fc = [...] }`` adds
    ``phi_hat(r)`` to the feedforward force (identified by ``motionhyst identify``);
    ``acceleration = m`` [kg] replaces the plant's mass in ``m r''``, ``viscous = c``
    [N s/m] adds ``c r'``, ``coulomb = fc`` [N] adds ``fc sign(r')``
    (:class:`~motionhyst.controllers.feedforward.Feedforward`); ``advance_samples = a``
    reads the setpoint ``a`` samples ahead for a sampled controller; ``jerk`` and ``snap``
    [N s^3/m, N s^4/m] add the stage's damping and compliance terms, a number or
    ``"plant"`` (the terms of the plant's inverse, :mod:`motionhyst.controllers.inverse`).
    """

    type: Literal["rigid-body", "none"] = "rigid-body"
    hysteresis: HysteresisSection | None = None
    acceleration: NonNegativeFloat | None = None
    viscous: NonNegativeFloat | None = None   # None: 0, and not written back by to_dict
    coulomb: NonNegativeFloat | None = None
    advance_samples: NonNegativeFloat | None = None
    jerk: Annotated[float, Field(allow_inf_nan=False)] | Literal["plant"] | None = None
    snap: Annotated[float, Field(allow_inf_nan=False)] | Literal["plant"] | None = None

    @model_validator(mode="after")
    def _terms_need_a_feedforward(self):
        if self.type == "none":
            given = [k for k in ("acceleration", "viscous", "coulomb", "advance_samples",
                                 "jerk", "snap")
                     if getattr(self, k)]
            if given:
                raise ValueError(f"{', '.join(given)} cannot go with type = \"none\" (no "
                                 f"feedforward)")
        return self


class _Sampling(_Section):
    """Keys every ``[controller]`` has: the sampling of a real-time computer."""

    sample_rate_hz: PositiveFloat | None = None
    delay_samples: NonNegativeFloat | None = None   # None: 0
    u_max: PositiveFloat | None = None

    @model_validator(mode="after")
    def _sampling_keys_need_a_rate(self):
        if self.sample_rate_hz is None:
            given = [k for k in ("delay_samples", "u_max", "discretization", "prewarp_hz")
                     if getattr(self, k, None)]
            if given:
                raise ValueError(f"{', '.join(given)} needs sample_rate_hz (a sampled "
                                 f"controller)")
        return self


class _Continuous(_Sampling):
    """A continuous controller, sampled when ``sample_rate_hz`` is given."""

    discretization: Literal["tustin", "tustin-prewarp", "zoh", "matched"] | None = None
    prewarp_hz: PositiveFloat | None = None

    @model_validator(mode="after")
    def _prewarp(self):
        if (self.prewarp_hz is not None) != (self.discretization == "tustin-prewarp"):
            raise ValueError('prewarp_hz goes with discretization = "tustin-prewarp" (the '
                             'frequency it maps exactly), and only with it')
        if self.prewarp_hz is not None and self.sample_rate_hz is not None and \
                self.prewarp_hz >= self.sample_rate_hz / 2:
            raise ValueError(f"prewarp_hz = {self.prewarp_hz:g} Hz must lie below the Nyquist "
                             f"frequency {self.sample_rate_hz / 2:g} Hz")
        return self


class LeadLagSection(_Continuous):
    """``[controller] type = "leadlag-lowpass"``: eq. (23)."""

    type: Literal["leadlag-lowpass"]
    K: PositiveFloat
    f1: PositiveFloat
    f2: PositiveFloat
    flp: PositiveFloat
    beta: PositiveFloat


MAX_CONTROLLER_COEFFICIENTS = 101
"""Most coefficients of a continuous controller's polynomial in s (degree 100; a motion
controller's is rarely above 20): the loop's poles are the roots of its characteristic
polynomial, which for 3000 coefficients took 59 s before the command answered."""
MAX_SAMPLED_COEFFICIENTS = 1001
"""Most coefficients of a sampled controller's polynomial in z^-1 (degree 1000): a filter of
the loop's rate counts its taps (the paper's lead-lag with a 150-tap moving-average
reference filter has 153, analysed in 1.5 s of CPU; 1003 in 6.3 s); 3000 took more than
80 s, not stopped by SIGTERM inside LAPACK."""


def _check_order(name: str, coefficients: list[float],
                 limit: int = MAX_CONTROLLER_COEFFICIENTS) -> None:
    if len(coefficients) > limit:
        raise ValueError(f"{name} has {len(coefficients)} coefficients, more than the "
                         f"{limit} (degree {limit - 1}) a controller's polynomial may have: "
                         f"give a controller of lower order")


class TransferFunctionSection(_Continuous):
    """``[controller] type = "tf"``: any controller as polynomial coefficients in s."""

    type: Literal["tf"]
    num: list[Annotated[float, Field(allow_inf_nan=False)]]
    den: list[Annotated[float, Field(allow_inf_nan=False)]]


    @model_validator(mode="after")
    def _proper(self):
        _check_order("num", self.num)
        _check_order("den", self.den)
        if not self.den or all(c == 0 for c in self.den):
            raise ValueError("den must have a non-zero coefficient")
        if not self.num or all(c == 0 for c in self.num):
            raise ValueError("num must have a non-zero coefficient")
        strip = lambda p: p[next(i for i, c in enumerate(p) if c != 0):]  # noqa: E731
        if len(strip(self.num)) > len(strip(self.den)):
            raise ValueError("controller must be proper (deg num <= deg den)")
        return self


class NotchSection(_Section):
    """A notch of a PID: ``frequency_hz``, ``zeta_zero`` (0.01), ``zeta_pole`` (0.5)."""

    frequency_hz: PositiveFloat
    zeta_zero: NonNegativeFloat = 0.01
    zeta_pole: PositiveFloat = 0.5


class PidSection(_Continuous):
    """``[controller] type = "pid"``: ``kp + ki / s + kd s / (1 + s / w_d)`` with notches
    (:class:`~motionhyst.controllers.pid.Pid`); without ``derivative_filter_hz`` a pure
    derivative (sampled: a backward difference; continuous: ``C P2`` must stay strictly
    proper)."""

    type: Literal["pid"]
    kp: NonNegativeFloat
    ki: NonNegativeFloat = 0.0
    kd: NonNegativeFloat = 0.0
    derivative_filter_hz: PositiveFloat | None = None
    notches: list[NotchSection] = Field(default_factory=list)

    @model_validator(mode="after")
    def _realisable(self):
        if self.kp == self.ki == self.kd == 0:
            raise ValueError("a PID needs a non-zero gain (kp, ki or kd)")
        return self


_ZCoef = Annotated[list[Annotated[float, Field(allow_inf_nan=False)]], Field(min_length=1)]


def _check_z(name: str, num: list[float], den: list[float]) -> None:
    _check_order(f"{name}num", num, MAX_SAMPLED_COEFFICIENTS)
    _check_order(f"{name}den", den, MAX_SAMPLED_COEFFICIENTS)
    if den[0] == 0:
        raise ValueError(f"{name}den[0] (the coefficient of u_k) must not be 0: the controller "
                         "would not be causal")
    if not any(num):
        raise ValueError(f"{name}num must have a non-zero coefficient")


class DiscreteTfSection(_Sampling):
    """``[controller] type = "tf-z"``: ``C(z)``, ``num`` and ``den`` in ascending powers of
    ``z^-1``, run at ``sample_rate_hz`` on ``e_k = r_k - y_k``."""

    type: Literal["tf-z"]
    num: _ZCoef
    den: _ZCoef

    @model_validator(mode="after")
    def _causal(self):
        if self.sample_rate_hz is None:
            raise ValueError('type = "tf-z" needs sample_rate_hz')
        _check_z("", self.num, self.den)
        return self


class TwoDofSection(_Sampling):
    """``[controller] type = "two-dof-z"``: ``u = R(z) r - Y(z) y``, polynomials in ascending
    powers of ``z^-1`` (the EMPS cascade: ``R = g kv kp``, ``Y = g kv ((kp + F) - F z^-1)``)."""

    type: Literal["two-dof-z"]
    r_num: _ZCoef
    r_den: _ZCoef
    y_num: _ZCoef
    y_den: _ZCoef

    @model_validator(mode="after")
    def _causal(self):
        if self.sample_rate_hz is None:
            raise ValueError('type = "two-dof-z" needs sample_rate_hz')
        _check_z("r_", self.r_num, self.r_den)
        _check_z("y_", self.y_num, self.y_den)
        return self




class ReferenceSection(_Section):
    """``[reference]``: the sinusoidal reference ``r = A sin(2 pi f t)``."""

    amplitude: PositiveFloat
    frequencies: Annotated[list[PositiveFloat], Field(min_length=1)]

    @model_validator(mode="after")
    def _distinct(self):
        seen = set()
        for f in self.frequencies:
            if f in seen:
                raise ValueError(f"frequencies: {f:g} is given twice")
            seen.add(f)
        return self



class IdentificationSection(_Section):
    """``[identification]`` (optional, written by ``motionhyst identify --save``): the
    estimates of an identified model's parameters, named by their scenario keys, with their
    standard errors and correlations (from the fit's Jacobian); it describes the file's
    ``[stage]`` and ``[hysteresis]`` and changes nothing in the loop.  A Monte-Carlo study
    draws the link's parameters from it (``motionhyst study --from-identification``).
    ``record`` is the kind of record the model was identified from: ``motionhyst predict``
    predicts what that record measured (a force-displacement record's force from a
    displacement, an input-output record's position from a force); a model none of whose
    standard errors the records determine holds ``record`` alone (no parameters).
    ``position_offset`` [m] is the zero of the position sensor of the record(s) a model
    without inertia was identified from (an input-output record's estimated output offset, the
    mean of several records'): ``motionhyst predict`` adds it to a position it predicts and
    subtracts it from a displacement record it predicts the force of (a held-out part of the
    same run has the same sensor); ``predict --init-from`` sets it from the record instead."""

    record: Literal["force-displacement", "input-output"] | None = None
    position_offset: Annotated[float, Field(allow_inf_nan=False)] | None = None
    parameters: list[str] = []
    estimates: list[Annotated[float, Field(allow_inf_nan=False)]] = []
    std: list[NonNegativeFloat] = []
    correlation: list[list[Annotated[float, Field(ge=-1.0, le=1.0, allow_inf_nan=False)]]] = []

    @model_validator(mode="after")
    def _square(self):
        n = len(self.parameters)
        if len(set(self.parameters)) != n:
            raise ValueError("parameters: a name is given twice")
        for name in ("estimates", "std"):
            if len(getattr(self, name)) != n:
                raise ValueError(f"{name}: {len(getattr(self, name))} values for {n} "
                                 f"parameters")
        r = self.correlation
        if len(r) != n or any(len(row) != n for row in r):
            raise ValueError(f"correlation: give {n} rows of {n} values (a row a parameter)")
        for i in range(n):
            if r[i][i] != 1.0 or any(abs(r[i][j] - r[j][i]) > 1e-9 for j in range(i)):
                raise ValueError("correlation: a correlation matrix has 1 on its diagonal and "
                                 "is symmetric")
        try:  # every command that reads the file refuses it, not only a study drawing from it
            check_correlation(r, self.parameters, "--save")
        except ValueError as exc:
            raise ValueError(f"correlation: {exc}") from None
        return self


class ScenarioModel(_Section):
    """The whole file."""

    stage: StageUnion | None = None
    plant: PlantSection | None = None
    hysteresis: HysteresisSection | None = None
    controller: Annotated[LeadLagSection | TransferFunctionSection | PidSection
                          | DiscreteTfSection | TwoDofSection,
                          Field(discriminator="type")] | None = None
    feedforward: FeedforwardSection | None = None
    reference: ReferenceSection | None = None
    identification: IdentificationSection | None = None

    @model_validator(mode="after")
    def _one_plant(self):
        if (self.stage is None) == (self.plant is None):
            raise ValueError("give exactly one of [stage] and [plant]")
        if self.plant_only:
            return self
        if self.open_loop:
            output = getattr(self.stage, "output", None)  # a stage of one position has none
            what = (f"a {self.stage.type} [stage]" if output is None
                    else f'a [stage] with output = "{output}"')
            for name in ("controller", "feedforward", "reference"):
                if getattr(self, name) is not None:
                    raise ValueError(f"[{name}] does not apply to {what} (an open-loop system, "
                                     f"force in, position out)")
            return self
        for name in ("hysteresis", "controller", "reference"):
            if getattr(self, name) is None:
                hint = ""
                if (self.stage is not None and len(PLANTS[self.stage.type].outputs) > 1
                        and self.controller is None and self.reference is None):
                    hint = ' (or give [stage] output = "y2" or "y1" for an open-loop system)'
                raise ValueError(f"[{name}]: missing{hint}")
        if self.feedforward is None:
            self.feedforward = FeedforwardSection()
        if self.feedforward.advance_samples and self.controller.sample_rate_hz is None:
            raise ValueError("[feedforward] advance_samples needs a sampled controller "
                             "([controller] sample_rate_hz)")
        return self

    @property
    def plant_only(self) -> bool:
        """True for a file that describes only a plant: no ``[hysteresis]``, ``[controller]``,
        ``[feedforward]`` or ``[reference]``."""
        return all(getattr(self, name) is None
                   for name in ("hysteresis", "controller", "feedforward", "reference"))

    @property
    def open_loop(self) -> bool:
        """True for a stage of one position (a mass-spring-damper, ...) or one with an
        ``output`` (no controller)."""
        return _is_open_loop(self.stage, self.controller)


# tags of the discriminated unions, left out of the key named in an error message
_UNION_TAGS = {"leadlag-lowpass", "tf", "pid", "tf-z", "two-dof-z", *STAGE_SECTIONS,
               *MODELS, *FORM_SECTIONS}


def build_hysteresis(section) -> Hysteresis:
    """The hysteresis model a validated ``[hysteresis]`` section describes."""
    return section.build()


_HYSTERESIS_ADAPTER = TypeAdapter(HysteresisSection, config=ConfigDict(defer_build=True))


def hysteresis_from_dict(data: dict, source: str = "<dict>") -> Hysteresis:
    """Validate a ``[hysteresis]`` table and build the model; raises :class:`ScenarioError`.

    Parameters
    ----------
    data : dict
        The table's keys and values, as read from TOML (``model`` and the model's parameters).
    source : str
        Where the table comes from, named in error messages.

    Returns
    -------
    Hysteresis
        The link model.

    Examples
    --------
    >>> hysteresis_from_dict({"model": "jenkins", "k": 20.0, "fc": 0.05})
    Jenkins(k=20.0, fc=0.05)
    """
    try:
        section = _HYSTERESIS_ADAPTER.validate_python(data)
    except ValidationError as err:
        raise ScenarioError(format_error(source, err, prefix=("hysteresis",))) from None
    return build_hysteresis(section)


def _discriminator(e: dict) -> str:
    """The key a discriminated union is chosen by (``model`` for the link's callable one)."""
    name = e["ctx"]["discriminator"].strip("'")
    if name == f"{_stage_tag.__name__}()":
        return "type"
    return "model" if name == f"{_link_tag.__name__}()" else name


def format_error(source: str, err: ValidationError, prefix: tuple = ()) -> str:
    """One line naming the file, the section and key, and the problem."""
    e = err.errors()[0]
    loc = [p for p in (*prefix, *e["loc"]) if not (isinstance(p, str) and p in _UNION_TAGS)]
    key = ""
    for p in loc[1:]:
        key += f"[{p}]" if isinstance(p, int) else (f".{p}" if key else str(p))
    where = (f"[{loc[0]}] {key}" if key else f"[{loc[0]}]") if loc else ""
    kind = e["type"]
    if kind == "extra_forbidden":
        msg = "unknown key" if key else "unknown section"
    elif kind == "missing":
        msg = "missing"
    elif kind == "union_tag_invalid":
        tags = e["ctx"]["expected_tags"]
        for tag in FORM_SECTIONS:
            tags = tags.replace(f", {tag!r}", "")
        msg = f"unknown {_discriminator(e)} {e['ctx']['tag']!r}; expected one of {tags}"
    elif kind == "union_tag_not_found":
        msg = f"missing key '{_discriminator(e)}'"
    else:
        msg = e["msg"].removeprefix("Value error, ")
        if "input" in e and not isinstance(e["input"], dict | list):
            msg += f" (got {e['input']!r})"
    return f"{source}: {where}: {msg}" if where else f"{source}: {msg}"
