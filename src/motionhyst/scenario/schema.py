"""Scenario files (TOML): the one place where user input about a loop is validated.

A scenario names the stage (or a measured plant), the hysteresis, the
controller, the feedforward and the reference.  The paper's Table I ships as
``examples/paper.toml`` and is the default everywhere (:func:`default_scenario`).
Every problem in a file is reported as a :class:`ScenarioError` with one line
naming the file, the key and the problem.  The tables' models are in
:mod:`motionhyst.scenario.sections`; :class:`Scenario` reads a file with them and
builds the loop, the plant, the link and the reference.
"""

from __future__ import annotations

import dataclasses
import math
import re
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from motionhyst.controllers.characteristic import (
    as_transfer,
    check_sampled_stable,
    check_stable,
    leadlag_coefficients,
    loop_denominator,
    strictly_proper,
    stuck_characteristic,
)
from motionhyst.core.validation import check_magnitudes
from motionhyst.hysteresis import Hysteresis
from motionhyst.io.inputs import InputFileError, read_toml
from motionhyst.scenario.sections import (
    ScenarioError,
    ScenarioModel,
    build_hysteresis,
    format_error,
    open_loop_kinds,
    open_loop_what,
)
from motionhyst.scenario.sections import hysteresis_from_dict as hysteresis_from_dict

__all__ = ["MAX_VALUES", "Scenario", "ScenarioError", "default_scenario",
           "default_scenario_path", "hysteresis_from_dict", "implausible_stage", "load_scenario",
           "warn_implausible"]

MAX_VALUES = 100_000
"""Most values one list of a scenario holds (a Maxwell-slip link's elements, the reference's
frequencies): reading and checking a value takes some microseconds, and every computation
grows with them (the monodromy of a link of ``m`` elements as ``m^2``); a longer list is
refused before the file is parsed."""

#: a TOML array of numbers (no nested array, string or comment): ``key = [1.0, 2.0, ...]``
_ARRAY = re.compile(r"=[ \t]*\[([^\[\]]*)\]")

if TYPE_CHECKING:  # imported where used: validating a file needs neither python-control nor scipy
    import control

    from motionhyst.controllers.loop import Loop
    from motionhyst.controllers.pid import Pid
    from motionhyst.controllers.sampled import SampledController
    from motionhyst.plants.frf_fit import FrfFit
    from motionhyst.plants.measured import FrdData
    from motionhyst.plants.registry import Plant
    from motionhyst.scenario.sections import FeedforwardSection
    from motionhyst.time.openloop import OpenLoop


class Scenario:
    """A validated scenario; builds the loop and holds the reference.

    Use :meth:`from_file`, :meth:`from_dict` or :func:`default_scenario`.

    Parameters
    ----------
    model : ScenarioModel
        The validated content of the file.
    source : str
        Where it comes from, for messages.
    base_dir : Path, optional
        Folder that relative file names in it are read from (default: the working folder).

    Examples
    --------
    A scenario from a dictionary (the layout of a TOML file):

    >>> from motionhyst import Scenario
    >>> sc = Scenario.from_dict({
    ...     "stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7},
    ...     "hysteresis": {"model": "jenkins", "k": 20.0, "fc": 0.05},
    ...     "controller": {"type": "leadlag-lowpass", "K": 6.2e6, "f1": 60.0, "f2": 240.0,
    ...                    "flp": 700.0, "beta": 0.6},
    ...     "reference": {"amplitude": 0.01, "frequencies": [5.0, 10.0]}})
    >>> sc.hysteresis(), sc.frequencies
    (Jenkins(k=20.0, fc=0.05), [5.0, 10.0])
    >>> loop = sc.loop()                                   # a motionhyst.Loop
    """

    def __init__(self, model: ScenarioModel, source: str = "<dict>",
                 base_dir: Path | None = None) -> None:
        self.model = model
        self.source = source
        self.base_dir = base_dir or Path.cwd()
        self._loop: Loop | None = None
        self._plant = None
        self._fit: FrfFit | None = None
        self._fit_warned = False
        self._masses_unwarned = False  # set for a user's file (load_scenario)

    @classmethod
    def from_dict(cls, data: dict, source: str = "<dict>",
                  base_dir: Path | None = None, check: bool = True) -> Scenario:
        """Validate a parsed scenario; raises :class:`ScenarioError`.

        With `check` (the default) the loop is also built and checked for
        stability now; without, at the first :meth:`loop`, which raises the
        same :class:`ScenarioError` (a command that can do other work first).

        Parameters
        ----------
        data : dict
            The scenario, laid out as its TOML file.
        source : str
            Where it comes from, for messages.
        base_dir : Path, optional
            Folder of relative file names (default: the working folder).
        check : bool
            Build the loop and check that it is stable (a :class:`ScenarioError` if not).
        """
        _check_list_lengths(data, source)
        try:
            check_magnitudes(data)  # 1e300 or 1e-300 would give inf and NaN, not an answer
        except ValueError as exc:
            raise ScenarioError(f"{source}: {exc}") from None
        try:
            model = ScenarioModel.model_validate(data)
        except ValidationError as err:
            raise ScenarioError(format_error(source, err)) from None
        sc = cls(model, source, base_dir)
        if model.open_loop and sc.along_stroke:
            from motionhyst.hysteresis.along_stroke import FIXED_IN_OPEN_LOOP

            raise ScenarioError(f"{source}: {FIXED_IN_OPEN_LOOP}")
        if check and not (model.open_loop or model.plant_only):
            sc.loop()  # builds and checks stability
        return sc

    @classmethod
    def from_file(cls, path: str | Path, check: bool = True) -> Scenario:
        """Read and validate a TOML scenario; raises :class:`ScenarioError`.

        `check` as for :meth:`from_dict`.

        Parameters
        ----------
        path : str or Path
            The TOML file.
        check : bool
            Build the loop and check that it is stable (a :class:`ScenarioError` if not).
        """
        path = Path(path)
        try:
            data = read_toml(path, check=lambda text: _check_array_lengths(text, str(path)))
        except InputFileError as exc:
            raise ScenarioError(f"{path}: {exc}") from None
        return cls.from_dict(data, str(path), path.parent, check=check)

    @property
    def is_open_loop(self) -> bool:
        """True for an open-loop system (a stage of one position, such as a mass-spring-damper,
        or a two-mass stage with an ``output``): force in, position out, no controller."""
        return self.model.open_loop

    @property
    def along_stroke(self) -> bool:
        """True where the link or the feedforward's link model varies along the stroke
        (``along``: :class:`~motionhyst.hysteresis.along_stroke.AlongStroke`)."""
        return bool(self.along_keys)

    @property
    def along_keys(self) -> list[str]:
        """The keys that vary a link along the stroke, as the scenario writes them
        (``[hysteresis] along``, ``[feedforward] hysteresis.along``): named in refusals."""
        from motionhyst.hysteresis.along_stroke import FEEDFORWARD_KEY, LINK_KEY

        ff = self.model.feedforward
        sections = ((self.model.hysteresis, LINK_KEY),
                    (getattr(ff, "hysteresis", None), FEEDFORWARD_KEY))
        return [key for section, key in sections
                if getattr(section, "along", None) is not None]

    def _closed(self, what: str) -> None:
        if self.model.plant_only and not self.model.open_loop:
            raise ScenarioError(f"{self.source}: describes only a plant (no [hysteresis], "
                                f"[controller] or [reference]); {what} needs a closed loop")
        if self.model.open_loop:
            kind = open_loop_what(self.model.stage)
            raise ScenarioError(f"{self.source}: [stage] is {kind} (an open-loop system "
                                f"without [controller] or [reference]); {what} needs a closed "
                                f"loop (use motionhyst predict for open-loop systems)")

    @property
    def files(self) -> list[Path]:
        """The files the scenario was read from: its TOML and a measured plant's CSV.

        A command never writes over these (:mod:`motionhyst.io.outputs`).
        """
        files = [Path(self.source)] if Path(self.source).is_file() else []
        if self.model.stage is None and self.model.plant is not None:
            f = Path(self.model.plant.file)
            files.append(f if f.is_absolute() else self.base_dir / f)
        return files

    @property
    def amplitude(self) -> float:
        """Reference amplitude [m]."""
        self._closed("the reference")
        return self.model.reference.amplitude

    @property
    def frequencies(self) -> list[float]:
        """Reference frequencies [Hz]."""
        self._closed("the reference")
        return list(self.model.reference.frequencies)

    def open_loop(self) -> OpenLoop:
        """The open-loop system of the stage and its link (force in, a position out)."""
        if not self.model.open_loop:
            what = ("has a measured [plant], not a [stage]" if self.model.stage is None else
                    f"[stage] is not a {open_loop_kinds()} nor a two-mass stage with an output")
            raise ScenarioError(f"{self.source}: {what}; an open-loop system needs a [stage] of "
                                f"type {open_loop_kinds()}, or a two-mass [stage] with output = "
                                f"\"y2\" or \"y1\" (and no [controller])")
        from motionhyst.time.openloop import OpenLoop

        return OpenLoop(self.plant(), self.hysteresis())

    def plant(self) -> Plant:
        """The stage (a plant of the registry, :mod:`motionhyst.plants`), the model fitted to
        a measured plant, or the raw measured plant."""
        if self._plant is not None:
            return self._plant
        m = self.model
        if m.open_loop:
            return m.stage.build()
        if m.stage is not None:
            self._plant = m.stage.build(closed_loop=True)
            return self._plant
        from motionhyst.plants.measured import frd_plant, read_frd

        f = Path(m.plant.file)
        if not f.is_absolute():
            f = self.base_dir / f
        try:
            data = read_frd(f, m.plant.mass)
        except ValueError as exc:
            raise ScenarioError(f"{self.source}: [plant] file: {exc}") from None
        self._check_frd(data, f)
        # imported once the data are read and checked (a bad file is refused before they
        # load), and for a measured plant only: a [stage] needs neither the fit nor
        # python-control
        from motionhyst.plants.frf_fit import (
            ABOVE_NOISE,
            NEEDLE_SEEN_RATIO,
            NONE_DETERMINED,
            SEEN_RATIO,
            fit_frf,
        )
        fit_data = (data.frequency_hz, data.P1, data.P2)
        if m.plant.use == "data":
            # the data's resolution: their scatter around the rigid body + modes fit
            try:
                scatter = fit_frf(*fit_data, mass=m.plant.mass).rms_relative_error
            except ValueError:
                scatter = None
            self._plant = dataclasses.replace(frd_plant(data), resolution=scatter)
            return self._plant
        try:  # the BIC's modes, less those the lines do not determine (fit_frf drops them)
            self._fit = fit_frf(*fit_data, modes=m.plant.modes, mass=m.plant.mass,
                                source=data.source, delay=m.plant.delay)
        except ValueError as exc:
            raise ScenarioError(f"{self.source}: [plant] file: {f}: cannot fit a rigid body "
                                f"plus modes: {exc}") from None
        none = [w for w in self._fit.warnings if w.startswith(NONE_DETERMINED)]
        if not self._fit.plant.modes or none:  # Pf2 = 0: eqs. (18)-(21) divide by it
            n, chosen = len(self._fit.frequency_hz), self._fit.bic_modes
            why = (f"{n} measured lines ({self._fit.frequency_hz.min():.4g}-"
                   f"{self._fit.frequency_hz.max():.4g} Hz) determine none of the {chosen} "
                   f"mode(s) the BIC chose (each with its residue r1 within its standard "
                   f"deviation of zero, or changing the response at no line by more than "
                   f"{SEEN_RATIO:g} times the data's noise, {NEEDLE_SEEN_RATIO:g} for a peak "
                   f"narrower than the lines resolve), which leaves" if chosen else
                   "the data show no flexible mode (the BIC keeps a rigid body alone), which "
                   "leaves")
            raise ScenarioError(f"{self.source}: [plant] file: {f}: {why} a rigid body alone, "
                                f"with Pf2 = 0 and no link between P1 and P2 to analyse; "
                                f"give data up to above the first resonance (or modes >= 1)")
        above = [w for w in self._fit.warnings if w.startswith(ABOVE_NOISE)]
        if above:  # every number on this plant would be in doubt: no answer from it
            raise ScenarioError(f"{self.source}: [plant] file: {f}: cannot fit a rigid body plus "
                                f"modes: {above[0].removeprefix('measured plant: ')}; give "
                                f"[plant] modes, or data without those dynamics")
        self._plant = self._fit.plant
        if m.plant_only:  # no loop to check: its doubts are said now
            self._warn_fit()
        return self._plant

    def _check_frd(self, data: FrdData, path: Path) -> None:
        """What a measured plant's lines decide before its fit (:mod:`~motionhyst.plants.
        frf_checks`): too few lines for a mode, a delay, units, phase sense."""
        from motionhyst.plants.frf_checks import FrfInputError, check_response

        sec, n = self.model.plant, data.frequency_hz.size
        if sec.use == "fit" and sec.modes is None and 4 * n < 2 * (4 + (sec.mass is None)):
            raise ScenarioError(f"{self.source}: [plant] file: {path}: {n} measured lines "
                                f"cannot determine a mode (4 parameters more), which leaves "
                                f"a rigid body alone, with Pf2 = 0 and no link between P1 and "
                                f"P2 to analyse; give data up to above the first resonance")
        try:
            check_response(data.frequency_hz, data.P1, data.P2, sec.mass,
                           sec.delay if sec.use == "fit" else None)
        except FrfInputError as exc:
            where = "[plant] delay" if exc.key == "delay" else f"[plant] file: {path}"
            raise ScenarioError(f"{self.source}: {where}: {exc}") from None

    def _warn_fit(self) -> None:
        """The measured plant's fit warnings (:attr:`FrfFit.warnings`) as
        :class:`~motionhyst.core.warnings.MotionhystWarning`, once a scenario: once its
        loop is checked (an unstable loop's error says them itself), or with its plant
        when the scenario has no loop."""
        if self._fit is None or self._fit_warned:
            return
        from motionhyst.core.warnings import warn

        self._fit_warned = True
        for message in self._fit.warnings:
            warn(message)

    def plant_fit(self) -> FrfFit | None:
        """The fit of a measured plant (``[plant] use = "fit"``), else None."""
        self.plant()
        return self._fit

    def hysteresis(self) -> Hysteresis | None:
        """The dynamic link's hysteresis model (None: the scenario describes only a plant)."""
        if self.model.hysteresis is None:
            return None
        return build_hysteresis(self.model.hysteresis)

    def controller(self) -> control.TransferFunction | SampledController:
        """The feedback controller: continuous, or sampled with ``sample_rate_hz``."""
        self._closed("a controller")
        c = self.model.controller
        sampled = self._discretised()
        if sampled is not None and c.type in ("tf-z", "two-dof-z", "pid"):
            return sampled
        import control

        from motionhyst.controllers.leadlag import LeadLagLowpass

        if c.type == "pid":
            return self._pid().tf()
        cont = (LeadLagLowpass(c.K, c.f1, c.f2, c.flp, c.beta) if c.type == "leadlag-lowpass"
                else control.tf(c.num, c.den))
        if sampled is None:
            return cont
        sampled.continuous = cont  # for reports (its own table)
        return sampled

    def _pid(self) -> Pid:
        from motionhyst.controllers.pid import Notch, Pid

        c = self.model.controller
        return Pid(c.kp, c.ki, c.kd, c.derivative_filter_hz,
                   tuple(Notch(n.frequency_hz, n.zeta_zero, n.zeta_pole) for n in c.notches))

    def _discretised(self) -> SampledController | None:
        """:meth:`_sampled_controller`, a ``sample_rate_hz`` the controller does not allow
        refused (without python-control)."""
        try:
            return self._sampled_controller()
        except ValueError as exc:
            raise ScenarioError(f"{self.source}: [controller]: {exc}") from None

    def _sampled_controller(self) -> SampledController | None:
        """The controller with ``sample_rate_hz`` (a continuous one discretised), None for a
        continuous one: from the coefficients, without python-control."""
        from motionhyst.controllers.sampled import SampledController, discretize_coefficients

        c = self.model.controller
        if c.sample_rate_hz is None:
            return None
        delay = c.delay_samples or 0.0
        if c.type == "tf-z":
            return SampledController(c.num, c.den, sample_rate_hz=c.sample_rate_hz,
                                     delay_samples=delay, u_max=c.u_max)
        if c.type == "two-dof-z":
            return SampledController(c.r_num, c.r_den, c.y_num, c.y_den,
                                     sample_rate_hz=c.sample_rate_hz,
                                     delay_samples=delay, u_max=c.u_max)
        method = c.discretization or "tustin"
        if c.type == "pid":
            return self._pid().sampled(c.sample_rate_hz, method, c.prewarp_hz, delay, c.u_max)
        num, den = (leadlag_coefficients(c.K, c.f1, c.f2, c.flp, c.beta)
                    if c.type == "leadlag-lowpass" else (c.num, c.den))
        return SampledController(
            *discretize_coefficients(num, den, c.sample_rate_hz, method, c.prewarp_hz),
            sample_rate_hz=c.sample_rate_hz, delay_samples=delay, u_max=c.u_max,
            discretization=method)

    def _derivative_terms(self, sec: FeedforwardSection) -> dict[str, float]:
        """``[feedforward]`` jerk and snap, ``"plant"`` taken from the plant's inverse."""
        out = {"jerk": sec.jerk or 0.0, "snap": sec.snap or 0.0}
        if "plant" in (sec.jerk, sec.snap):
            from motionhyst.controllers.inverse import stage_inverse

            try:
                inverse = stage_inverse(self.plant())
            except ValueError as exc:
                raise ScenarioError(f"{self.source}: [feedforward]: {exc}") from None
            out = {k: getattr(inverse, k) if v == "plant" else v for k, v in out.items()}
        return out

    def _coefficients(self) -> tuple | None:
        """``n1, d1, n2, d2`` of ``P1`` and ``P2`` as the loop will hold them and the
        controller, ``nc, dc`` (continuous) or a :class:`SampledController`, where they are
        known without python-control: a ``[stage]`` that gives its polynomials, and a
        controller whose loop gain is strictly proper (continuous); else None."""
        m = self.model
        c = m.controller
        if m.stage is None or c.type not in ("leadlag-lowpass", "tf", "pid", "tf-z",
                                             "two-dof-z"):
            return None
        plant = self.plant()
        if not hasattr(plant, "polynomials") or plant.force_offset or \
                getattr(plant, "force_drift", 0.0):
            return None  # the loop's own errors come first
        n1, n2, den = plant.polynomials()
        (n1, d1), (n2, d2) = as_transfer(n1, den), as_transfer(n2, den)
        try:
            sampled = self._sampled_controller()
            if sampled is not None:
                return n1, d1, n2, d2, sampled
            nc, dc = as_transfer(*(self._pid().coefficients() if c.type == "pid" else
                                   leadlag_coefficients(c.K, c.f1, c.f2, c.flp, c.beta)
                                   if c.type == "leadlag-lowpass" else (c.num, c.den)))
        except ValueError:
            return None  # the controller's own errors come with the loop
        if not strictly_proper(n2, d2, nc, dc):
            return None
        return n1, d1, n2, d2, nc, dc

    def _checked_denominator(self, coefficients: tuple, link: Hysteresis | None
                             ) -> NDArray[np.float64] | None:
        """The loop's characteristic polynomial (:func:`loop_denominator`) from its
        `coefficients` (:meth:`_coefficients`), its stability with `link` checked as
        :meth:`Loop.check_stable` does; None for a sampled controller (checked as well)."""
        try:
            if len(coefficients) == 5:  # sampled: the loop's poles are those of z
                n1, d1, n2, d2, sampled = coefficients
                check_sampled_stable(n2, d2, sampled, None if link is None else (
                    n1, d1, link.initial_stiffness))
                return None
            n1, d1, n2, d2, nc, dc = coefficients
            den = loop_denominator(n2, d2, nc, dc)
            check_stable(den, None if link is None else stuck_characteristic(
                n1, d1, n2, d2, nc, dc, link.initial_stiffness))
        except ValueError as exc:
            raise ScenarioError(f"{self.source}: [controller]: {exc}") from None
        return den

    def fastest_pole(self) -> float | None:
        """The largest magnitude of the loop's closed-loop poles [rad/s]
        (:meth:`Loop.closed_loop_poles`), known before the loop is built where the
        coefficients give it (a ``[stage]`` and a continuous lead-lag, ``"tf"`` or PID
        controller), else None.  Raises :class:`ScenarioError` if the loop is unstable
        (checked also for a sampled controller).

        Examples
        --------
        >>> from motionhyst import default_scenario
        >>> sc = default_scenario(check=False)
        >>> print(f"{sc.fastest_pole():.4g} rad/s")             # python-control not loaded
        4344 rad/s
        >>> bool(abs(max(abs(sc.loop().closed_loop_poles())) - sc.fastest_pole()) == 0)
        True
        """
        self._closed("this")
        coefficients = self._coefficients()
        if coefficients is None:
            return None
        den = self._checked_denominator(coefficients, self.hysteresis())
        return None if den is None else float(np.max(np.abs(np.roots(den))))

    def loop(self) -> Loop:
        """The loop (built once, checked for stability)."""
        self._closed("this")
        if self._loop is None:
            sec = self.model.feedforward
            ff = None if sec.type == "none" else "rigid-body"
            if sec.type != "none" and (sec.acceleration is not None or sec.viscous
                                       or sec.coulomb or sec.advance_samples or sec.jerk
                                       or sec.snap):
                from motionhyst.controllers.feedforward import Feedforward

                ff = Feedforward(mass=sec.acceleration, viscous=sec.viscous or 0.0,
                                 coulomb=sec.coulomb or 0.0,
                                 advance_samples=sec.advance_samples or 0.0,
                                 **self._derivative_terms(sec))
            hff = sec.hysteresis
            # each part's own errors name their section: only the loop's are [controller]'s
            coefficients = self._coefficients()
            if coefficients is None:
                if self.model.plant is not None:  # a discretisation refused before a fit
                    self._discretised()
                parts = (self.plant(), self.controller(), self.hysteresis())
            else:  # stable, from the coefficients: checked before python-control loads
                link = self.hysteresis()
                self._checked_denominator(coefficients, link)
                parts = (self.plant(), self.controller(), link)
            if hff is not None:
                hff = build_hysteresis(hff)
                if hff.name == "along-stroke":  # its refusals name the key that gives it
                    from motionhyst.hysteresis.along_stroke import FEEDFORWARD_KEY, AlongStroke

                    hff = AlongStroke(hff.base, hff.position, hff.scales, FEEDFORWARD_KEY)
            from motionhyst.controllers.loop import Loop  # once the parts' files are read

            try:
                loop = Loop(*parts, feedforward=ff, hysteresis_feedforward=hff)
            except ValueError as exc:
                raise ScenarioError(f"{self.source}: [controller]: {exc}") from None
            try:
                loop.check_stable()
            except ValueError as exc:
                if self._fit is not None:  # the fitted plant, not the controller alone
                    raise self._unstable_fit(exc, parts[1:], ff, hff) from None
                raise ScenarioError(f"{self.source}: [controller]: {exc}") from None
            self._loop = loop
            self._warn_fit()
        self._warn_masses()
        return self._loop

    def _unstable_fit(self, exc: ValueError, rest: tuple, ff, hff) -> ScenarioError:
        """The refusal of a loop unstable with a fitted plant: the plant is named (its mass
        and modes), with the fit's first doubt, or else the unit slip of the data that would
        make the loop stable with a plausible mass (:func:`~motionhyst.plants.frf_checks.
        unit_slip_plants`, :data:`~motionhyst.plants.registry.PLAUSIBLE_MASS_KG`), or
        else the units and the controller to check."""
        from motionhyst.controllers.loop import Loop
        from motionhyst.plants.frf_checks import unit_slip_plants
        from motionhyst.plants.registry import PLAUSIBLE_MASS_KG

        fit, file = self._fit, self.model.plant.file
        p = fit.plant
        modes = ", ".join(f"{m.frequency_hz:.4g}" for m in p.modes)
        pole = str(exc).replace("the controller does not stabilise the loop", "").strip()
        head = (f"{self.source}: [plant] file: the loop with the plant fitted to {file} (M = "
                f"{p.M:.3g} kg, modes at {modes} Hz) is unstable {pole}")
        if fit.warnings:
            return ScenarioError(f"{head}, and the fit is in doubt: "
                                 f"{fit.warnings[0].removeprefix('measured plant: ')}")
        slips = []
        for what, plant in unit_slip_plants(p):
            if not PLAUSIBLE_MASS_KG[0] <= plant.M <= PLAUSIBLE_MASS_KG[1]:
                continue
            try:
                Loop(plant, *rest, feedforward=ff, hysteresis_feedforward=hff).check_stable()
            except ValueError:
                continue
            slips.append(f"{what} (M = {plant.M:.3g} kg)")
        why = (f"it stabilises the plant of these data with {' or '.join(slips)}: check the "
               f"units of {file}" if slips else
               f"check the units of {file} (a response in mm/N makes M 1e3 times too small, "
               f"frequencies in rad/s 4 pi^2 times) and the [controller]")
        return ScenarioError(f"{head}: the fitted plant is what the [controller] does not "
                             f"stabilise; {why}")

    def _warn_masses(self) -> None:
        """:func:`warn_implausible` once, for a user's file, once its loop is built: a
        command that refuses the scenario before (too many time steps, say) says one line."""
        if self._masses_unwarned:
            self._masses_unwarned = False
            warn_implausible(self)

    def to_dict(self) -> dict:
        """The validated scenario as a dictionary."""
        return self.model.model_dump(exclude_none=True)


def _too_many(source: str, where: str, n: int) -> ScenarioError:
    return ScenarioError(f"{source}: {where}: {n} values, more than the {MAX_VALUES} a list of "
                         f"a scenario may hold (every computation grows with them); give "
                         f"fewer (a link of fewer elements)")


def _check_array_lengths(text: str, source: str) -> None:
    """Refuse an array of more than :data:`MAX_VALUES` numbers in a scenario's text, before it
    is parsed (a million numbers take seconds to parse and check): counted by their commas,
    in arrays that hold no string or comment (any other is counted once parsed)."""
    for m in _ARRAY.finditer(text):
        body = m.group(1)
        if len(body) <= 2 * MAX_VALUES or any(c in body for c in "\"'#"):
            continue  # too short to hold that many (a value and a comma each), or not plain
        n = body.count(",") + (not body.rstrip().endswith(","))
        if n > MAX_VALUES:
            line = text.rfind("\n", 0, m.start()) + 1
            table = re.findall(r"^[ \t]*(\[[^\[\]\n]+\])", text[:line], re.M)
            key = (re.findall(r"[\w.\"'-]+", text[line:m.start()]) or ["a list"])[-1]
            raise _too_many(source, f"{table[-1] + ' ' if table else ''}{key}", n)


def _check_list_lengths(data: dict, source: str, where: str = "") -> None:
    """Refuse a list of more than :data:`MAX_VALUES` values in the parsed tables `data`."""
    for key, value in data.items():
        name = f"{where} {key}".strip() if where else f"[{key}]"
        if isinstance(value, dict):
            _check_list_lengths(value, source, name)
        elif isinstance(value, list) and len(value) > MAX_VALUES:
            raise _too_many(source, name, len(value))


def default_scenario_path() -> Path:
    """Path of the shipped Table I scenario (``data/paper.toml`` in this package).

    Examples
    --------
    >>> default_scenario_path().name
    'paper.toml'
    """
    return Path(str(resources.files("motionhyst.scenario") / "data" / "paper.toml"))


def default_scenario(check: bool = True) -> Scenario:
    """The paper's Table I scenario (`check` as for :meth:`Scenario.from_dict`).

    Parameters
    ----------
    check : bool
        Build the loop and check that it is stable (a :class:`ScenarioError` if not).

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> sc = default_scenario()
    >>> sc.amplitude, sc.frequencies
    (0.01, [5.0, 10.0, 15.0])
    >>> sc.loop().hysteresis
    Jenkins(k=20.0, fc=0.05)
    """
    sc = Scenario.from_file(default_scenario_path(), check=check)
    sc.source = "paper.toml (Table I, built in)"
    return sc


def load_scenario(path: str | Path | None, check: bool = True) -> Scenario:
    """The scenario at `path`, or the default (Table I) when `path` is None.

    `check` as for :meth:`Scenario.from_dict`: without it the loop is built
    and checked at the first :meth:`Scenario.loop`.

    Parameters
    ----------
    path : str, Path or None
        The TOML file; None for the paper's Table I (:func:`default_scenario`).
    check : bool
        Build the loop and check that it is stable (a :class:`ScenarioError` if not).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst import load_scenario
    >>> load_scenario(None).source                         # no file: the paper's Table I
    'paper.toml (Table I, built in)'
    >>> path = Path(tempfile.mkdtemp()) / "slab.toml"
    >>> _ = path.write_text('''
    ... [stage]
    ... m1 = 5.0
    ... m2 = 17.5
    ... b = 90.0
    ... k = 7.4e7
    ... [hysteresis]
    ... model = "maxwell-slip"
    ... k = [10.0, 6.0, 4.0]
    ... fc = [0.01, 0.02, 0.03]
    ... [controller]
    ... type = "leadlag-lowpass"
    ... K = 6.2e6
    ... f1 = 60.0
    ... f2 = 240.0
    ... flp = 700.0
    ... beta = 0.6
    ... [reference]
    ... amplitude = 0.01
    ... frequencies = [5.0]
    ... ''')
    >>> load_scenario(path).hysteresis()
    MaxwellSlip(k=[10.0, 6.0, 4.0], fc=[0.01, 0.02, 0.03])
    >>> sc = load_scenario(path, check=False)              # the loop is built at sc.loop()
    >>> sc.hysteresis(), sc.loop().hysteresis
    (MaxwellSlip(k=[10.0, 6.0, 4.0], fc=[0.01, 0.02, 0.03]), MaxwellSlip(k=[10.0, 6.0, 4.0], \
fc=[0.01, 0.02, 0.03]))
    """
    if path is None:
        return default_scenario(check)
    sc = Scenario.from_file(path, check)
    sc._masses_unwarned = True
    if sc._loop is not None:  # built and checked by from_file
        sc._warn_masses()
    return sc


def warn_implausible(sc: Scenario) -> None:
    """Warn of each ``[stage]`` value outside a motion stage's (:func:`implausible_stage`),
    naming it: a unit slip (grams, tonnes) or a value off by orders of magnitude makes every
    number computed on the loop doubtful, and some computations slow (a microgram's pole at
    1e10 Hz sets the step of a time run) or ill-conditioned.  One
    :class:`~motionhyst.core.warnings.MotionhystWarning` each; the command goes on.  A
    scenario read by :func:`load_scenario` says so once its loop is built
    (:meth:`Scenario.loop`).

    Parameters
    ----------
    sc : Scenario
        The scenario read.

    Examples
    --------
    >>> import warnings
    >>> from motionhyst import default_scenario
    >>> sc = default_scenario(check=False)
    >>> sc.model.stage.m1 = 1e-9
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_implausible(sc)
    >>> print(caught[0].message)
    paper.toml (Table I, built in): [stage] m1 = 1e-09 kg, a factor 1e+06 below the \
0.001-10000 kg of motion stages: is it in kg?
    """
    from motionhyst.core.warnings import warn

    for line in implausible_stage(sc):
        warn(line)


def implausible_stage(sc: Scenario) -> list[str]:
    """One line for each ``[stage]`` value outside a motion stage's, naming it.

    A mass outside :data:`~motionhyst.plants.registry.PLAUSIBLE_MASS_KG`; with the masses
    within it, a stiffness or a damping that alone gives the stage a mode or a pole
    faster than :data:`~motionhyst.plants.registry.PLAUSIBLE_POLE_HZ` with the masses it
    joins (a spring or damper between two masses: both in series, as the internal mode sees
    them; a damper from one mass to the ground: that mass).

    Parameters
    ----------
    sc : Scenario
        The scenario read.

    Returns
    -------
    list of str
        The lines, each beginning with the scenario's name; empty for a plausible
        stage or a measured plant (its fit says so of its mass).

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> sc = default_scenario(check=False)
    >>> implausible_stage(sc)
    []
    >>> sc.model.stage.k = 7.4e16                          # N/m: off by 1e9
    >>> print(implausible_stage(sc)[0])
    paper.toml (Table I, built in): [stage] k = 7.4e+16 N/m gives the stage a mode at \
2.2e+07 Hz, beyond the 1e+05 Hz of motion stages: is it in N/m?
    """
    from motionhyst.plants.registry import PLAUSIBLE_MASS_KG, PLAUSIBLE_POLE_HZ, plant_class

    stage = sc.model.stage
    if stage is None:
        return []
    low, high = PLAUSIBLE_MASS_KG
    params = [(p, getattr(stage, p.name, None)) for p in plant_class(stage.type).parameters]
    lines = []
    for p, value in params:
        if p.unit != "kg" or value is None or low <= value <= high:
            continue
        factor, where = (low / value, "below") if value < low else (value / high, "above")
        lines.append(f"{sc.source}: [stage] {p.name} = {value:g} kg, a factor {factor:.2g} "
                     f"{where} the {low:g}-{high:g} kg of motion stages: is it in kg?")
    masses = [v for p, v in params if p.unit == "kg" and v]
    if lines or not masses:
        return lines
    values = stage.model_dump(exclude={"type"}, exclude_none=True)
    values.pop("output", None)
    base = plant_class(stage.type)(**values).mechanics()
    for p, value in params:
        if p.unit not in ("N/m", "N s/m") or not value:
            continue
        stiff = p.unit == "N/m"
        try:  # the value's own matrix (the stage's are linear in it): what it joins
            mech = plant_class(stage.type)(**{**values, p.name: 2.0 * value}).mechanics()
        except (ValueError, TypeError):
            continue
        own = (mech.K - base.K) if stiff else (mech.C - base.C)
        rate = float(np.max(np.abs(np.linalg.eigvals(own / base.mass[:, None]))))
        hz = (math.sqrt(rate) if stiff else rate) / math.tau
        if hz > PLAUSIBLE_POLE_HZ:
            lines.append(f"{sc.source}: [stage] {p.name} = {value:g} {p.unit} gives the stage a "
                         f"{'mode' if stiff else 'pole'} at {hz:.2g} Hz, beyond the "
                         f"{PLAUSIBLE_POLE_HZ:.0e} Hz of motion stages: is it in {p.unit}?")
    return lines
