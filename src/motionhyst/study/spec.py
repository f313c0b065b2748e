"""A study: a scenario, axes over its keys and the reference, Monte-Carlo samples, outputs.

A study file (TOML) names its scenario (a path relative to the file), its outputs and its
axes; each axis is a list of values or ``{ geomspace = [a, b, n] }`` /
``{ linspace = [a, b, n] }``.  An optional ``[samples]`` table draws ``n`` Monte-Carlo
samples of scenario keys from stated distributions, seeded::

    scenario = "paper.toml"
    outputs = ["e1", "mismatch", "error_rms"]
    [axes]
    amplitude = [0.001, 0.01]
    frequency_hz = { geomspace = [1.0, 100.0, 200] }
    "hysteresis.fc" = [0.03, 0.05]
    [samples]
    n = 100
    seed = 0
    "hysteresis.k" = { lognormal = [20.0, 0.1] }

A distribution that puts more than :data:`MAX_REFUSED_MASS` of its mass where the scenario
refuses the value (a normal one of a positive parameter reaching below 0) is refused: the
bands of the draws left would be of a distribution the file does not state.

The points are the cross product of the axes and the samples (a dimension ``sample``); an axis
``amplitude`` or ``frequency_hz`` not given is the scenario's ``[reference]`` one (a study whose
only output is ``scan``, with axes or samples of its own, has neither: a scan does not follow
the reference's sine, and a dimension of one value would only be carried along); a key of a
list names one value, ``"hysteresis.fc[1]"`` (an element of a Maxwell-slip link).  A ``[scan]``
table and axes ``scan.*`` set the scan of the output ``scan`` (:mod:`motionhyst.study.scans`).
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from statistics import NormalDist

import numpy as np
from numpy.typing import NDArray

from motionhyst.io.inputs import InputFileError, read_toml
from motionhyst.study.identified import (
    JointNormal,
    distributions_from_identification,
    joint_from_identification,
)
from motionhyst.study.outputs import OUTPUTS
from motionhyst.study.scans import COMPENSATIONS, SCAN_AXES, check_scan_value, scan_settings

__all__ = ["DISTRIBUTIONS", "MAX_REFUSED_MASS", "REFERENCE_AXES", "STAGE_MATCH", "StudyDefinition",
           "StudyError", "is_scenario_key", "set_key"]

REFERENCE_AXES = ("amplitude", "frequency_hz")
"""Axes over the reference ``r = amplitude sin(2 pi frequency_hz t)`` (not scenario keys)."""

DISTRIBUTIONS = {
    "lognormal": "[median, sigma of the logarithm]",
    "normal": "[mean, standard deviation]",
    "uniform": "[low, high]",
}
"""Distributions of Monte-Carlo samples and the meaning of their two parameters."""

MAX_POINTS = 100_000_000

MAX_REFUSED_MASS = 0.01
"""Largest fraction of a ``[samples]`` distribution's mass that may lie where the scenario
refuses the value (a normal distribution of a positive parameter reaching below 0): above it
the study is refused before any point runs, as its bands would be of the draws the scenario
admits alone, a truncated distribution the file does not state."""


class StudyError(ValueError):
    """A study file or study definition that cannot be run (one line, naming the key).

    Examples
    --------
    >>> try:
    ...     StudyDefinition.from_dict({"outputs": ["e7"]}, scenario={})
    ... except StudyError as exc:
    ...     print(exc)                                     # doctest: +ELLIPSIS
    'outputs': unknown output 'e7' (known: e1, harmonics, ...)
    """


def is_scenario_key(key: str) -> bool:
    """Whether the axis or sampled `key` is a key of the scenario (not the reference's
    ``amplitude`` or ``frequency_hz``, nor a scan's setting ``scan.*``).

    Parameters
    ----------
    key : str
        An axis or a sampled key.

    Examples
    --------
    >>> is_scenario_key("hysteresis.k"), is_scenario_key("frequency_hz"), is_scenario_key(
    ...     "scan.speed")
    (True, False, False)
    """
    return key not in REFERENCE_AXES and not key.startswith("scan.")


def set_key(data: dict, key: str, value: float) -> None:
    """Set the dotted scenario `key` (``"hysteresis.k"``) of the nested `data` to `value`; a
    key ``"hysteresis.k[1]"`` sets one value of a list (an element of a Maxwell-slip link).

    Parameters
    ----------
    data : dict
        The nested scenario dictionary, changed in place.
    key : str
        Dotted key, ``"hysteresis.k"``, or ``"hysteresis.k[1]"`` (counted from 0).
    value : float
        The value.

    Examples
    --------
    >>> d = {"hysteresis": {"model": "jenkins", "k": 20.0}}
    >>> set_key(d, "hysteresis.k", 25.0)
    >>> d
    {'hysteresis': {'model': 'jenkins', 'k': 25.0}}
    >>> d = {"hysteresis": {"model": "maxwell-slip", "k": [10.0, 6.0], "fc": [0.01, 0.03]}}
    >>> set_key(d, "hysteresis.fc[1]", 0.04)
    >>> d["hysteresis"]["fc"]
    [0.01, 0.04]

    A Bouc-Wen link's product ``beta*gamma`` or ``beta*delta`` (what an identification
    determines) sets ``beta``, ``gamma`` and ``delta`` with ``|gamma| + |delta| = 1``, the
    other product kept:

    >>> d = {"hysteresis": {"model": "bouc-wen", "alpha": 5e4, "beta": 2.0, "gamma": 0.8,
    ...                     "delta": -0.2, "nu": 1.0}}
    >>> set_key(d, "hysteresis.beta*delta", -1.0)
    >>> {k: round(d["hysteresis"][k], 4) for k in ("beta", "gamma", "delta")}
    {'beta': 2.6, 'gamma': 0.6154, 'delta': -0.3846}
    """
    *path, last = key.split(".")
    node = data
    for part in path:
        nxt = node.get(part)
        if not isinstance(nxt, dict):
            raise StudyError(f"{key!r}: the scenario has no table [{part}]")
        node = nxt
    if "*" in last:
        _set_product(node, key, last, value)
        return
    name, bracket, index = last.partition("[")
    if not bracket:
        node[last] = value
        return
    values = node.get(name)
    if not (index.endswith("]") and index[:-1].isdigit()):
        raise StudyError(f"{key!r}: give an index as {name}[0], {name}[1], ...")
    i = int(index[:-1])
    if not isinstance(values, list) or i >= len(values):
        what = (f"{len(values)} values" if isinstance(values, list)
                else "no list" if name in node else "no such key")
        raise StudyError(f"{key!r}: the scenario's [{'.'.join(path)}] {name} has {what}")
    node[name] = [*values[:i], value, *values[i + 1:]]


def _set_product(node: dict, key: str, name: str, value: float) -> None:
    """Set a Bouc-Wen link's ``beta*gamma`` or ``beta*delta`` (`name`) in its table `node`."""
    if name not in ("beta*gamma", "beta*delta") or not all(
            isinstance(node.get(k), int | float) and not isinstance(node.get(k), bool)
            for k in ("beta", "gamma", "delta")):
        raise StudyError(f"{key!r}: a product of keys is beta*gamma or beta*delta, of a "
                         f"Bouc-Wen link given by alpha, beta, gamma, delta and nu")
    bg, bd = node["beta"] * node["gamma"], node["beta"] * node["delta"]
    bg, bd = (value, bd) if name == "beta*gamma" else (bg, value)
    beta = abs(bg) + abs(bd)
    # beta = 0 (a linear spring): the scenario refuses it, as it would a drawn beta of 0
    node["beta"], node["gamma"], node["delta"] = (beta, bg / beta, bd / beta) if beta else (
        0.0, 0.0, 0.0)


def _axis_values(key: str, spec, where: str) -> NDArray:
    if key.startswith("scan.") and key not in SCAN_AXES:
        raise StudyError(f"{where}{key!r}: not a scan axis (those are {', '.join(SCAN_AXES)})")
    if key == "scan.compensation":
        if (not isinstance(spec, list) or not spec or any(v not in COMPENSATIONS for v in spec)
                or len(set(spec)) != len(spec)):
            raise StudyError(f"{where}{key!r}: give a list of distinct compensations among "
                             f"{', '.join(COMPENSATIONS)}")
        return np.array(spec, dtype=str)
    if isinstance(spec, dict):
        if len(spec) != 1 or next(iter(spec)) not in ("geomspace", "linspace"):
            raise StudyError(f"{where}{key!r}: give a list or {{ geomspace = [a, b, n] }} or "
                             f"{{ linspace = [a, b, n] }}")
        kind, args = next(iter(spec.items()))
        if (not isinstance(args, list) or len(args) != 3
                or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in args)
                or not isinstance(args[2], int) or args[2] < 1):
            raise StudyError(f"{where}{key!r}: {kind} needs [a, b, n] with numbers a, b and a "
                             f"whole number n >= 1")
        a, b, n = args
        if n > MAX_POINTS:  # before the values are made
            raise StudyError(f"{where}{key!r}: {n} values, more than the {MAX_POINTS} points a "
                             f"study holds; split the study")
        if kind == "geomspace" and (a <= 0 or b <= 0):
            raise StudyError(f"{where}{key!r}: geomspace needs a, b > 0")
        values = (np.geomspace if kind == "geomspace" else np.linspace)(float(a), float(b), n)
    elif isinstance(spec, list):
        if not spec or not all(isinstance(v, int | float) and not isinstance(v, bool)
                               for v in spec):
            raise StudyError(f"{where}{key!r}: give a non-empty list of numbers")
        values = np.asarray(spec, dtype=float)
    else:
        raise StudyError(f"{where}{key!r}: give a list or {{ geomspace = [a, b, n] }} or "
                         f"{{ linspace = [a, b, n] }}")
    if not np.all(np.isfinite(values)):
        raise StudyError(f"{where}{key!r}: values must be finite")
    if len(np.unique(values)) != len(values):
        raise StudyError(f"{where}{key!r}: values repeat")
    if key in REFERENCE_AXES and np.any(values <= 0):
        raise StudyError(f"{where}{key!r}: values must be > 0")
    for v in values if key.startswith("scan.") else ():
        try:
            check_scan_value(key[5:], float(v), f"{where}{key!r}")
        except ValueError as exc:
            raise StudyError(str(exc)) from None
    return values


def _quantile(kind: str, a: float, b: float, p: float) -> float:
    """The value below which a `kind` distribution of parameters `a`, `b`
    (:data:`DISTRIBUTIONS`) puts the fraction `p` of its mass."""
    if kind == "uniform":
        return a + p * (b - a)
    z = NormalDist().inv_cdf(p)
    return a + b * z if kind == "normal" else a * math.exp(b * z)


def _distribution(key: str, spec) -> tuple[str, float, float]:
    if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
        names = ", ".join(f"{{ {k} = {v} }}" for k, v in DISTRIBUTIONS.items())
        raise StudyError(f"[samples] {key!r}: give one of {names}")
    kind, args = next(iter(spec.items()))
    if (not isinstance(args, list) or len(args) != 2
            or not all(isinstance(a, int | float) and not isinstance(a, bool)
                       and math.isfinite(a) for a in args)):
        raise StudyError(f"[samples] {key!r}: {kind} needs two finite numbers "
                         f"{DISTRIBUTIONS[kind]}")
    a, b = float(args[0]), float(args[1])
    if kind == "lognormal" and (a <= 0 or b < 0):
        raise StudyError(f"[samples] {key!r}: lognormal needs a median > 0 and a sigma >= 0")
    if kind == "normal" and b < 0:
        raise StudyError(f"[samples] {key!r}: normal needs a standard deviation >= 0")
    if kind == "uniform" and not a < b:
        raise StudyError(f"[samples] {key!r}: uniform needs low < high")
    return kind, a, b


@dataclass
class StudyDefinition:
    """A scenario, axes, Monte-Carlo samples and outputs: every point of the cross product.

    Parameters
    ----------
    scenario : dict
        The scenario as a dictionary (the layout of a scenario TOML file).
    axes : dict of str to array
        Axis name (``amplitude``, ``frequency_hz`` or a dotted scenario key) to its values.
    outputs : list of str
        Names in :data:`motionhyst.study.outputs.OUTPUTS`.
    samples : dict of str to (kind, a, b)
        Monte-Carlo distributions of scenario keys (:data:`DISTRIBUTIONS`), each drawn
        independently; may be empty.
    n_samples, seed : int
        Number of samples and the seed of their generator.
    source, scenario_source : str
        The study file and the scenario file (attributes of the results).
    base_dir : Path, optional
        The folder of the scenario's relative file names (a measured plant's data).
    joint : JointNormal, optional
        Scenario keys drawn jointly (an identification's covariance,
        :mod:`motionhyst.study.identified`), after the keys of `samples`.
    scan : dict, optional
        The scan's settings not swept by an axis ``scan.*``, for the output ``scan``
        (:func:`motionhyst.study.scans.scan_settings`).

    Examples
    --------
    >>> from motionhyst.scenario import default_scenario_path
    >>> import tomllib
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["mismatch"],
    ...                       "axes": {"frequency_hz": [5.0, 10.0], "hysteresis.fc": [0.03, 0.05]},
    ...                       "samples": {"n": 3, "seed": 1,
    ...                                   "hysteresis.k": {"lognormal": [20.0, 0.1]}}},
    ...                      scenario=base)
    >>> st.dims, st.shape, st.n_points
    (('frequency_hz', 'hysteresis.fc', 'amplitude', 'sample'), (2, 2, 1, 3), 12)
    >>> st.point(11)                                  # the axes' and samples' values of point 11
    {'frequency_hz': 10.0, 'hysteresis.fc': 0.05, 'amplitude': 0.01, 'hysteresis.k': 20.67...}
    """

    scenario: dict
    axes: dict[str, NDArray[np.float64]]
    outputs: list[str]
    samples: dict[str, tuple[str, float, float]] = field(default_factory=dict)
    n_samples: int = 0
    seed: int = 0
    source: str = "<dict>"
    scenario_source: str = "<dict>"
    base_dir: Path | None = None
    joint: JointNormal | None = None
    scan: dict | None = None

    def __post_init__(self) -> None:
        self.sample_values = self._draw()

    # ---------------------------------------------------------------- reading
    @classmethod
    def from_file(cls, path: str | Path, from_identification: str | Path | None = None
                  ) -> StudyDefinition:
        """Read a study file; raises :class:`StudyError` (one line naming the key).

        Parameters
        ----------
        path : str or Path
            The study file (TOML); its scenario is named relative to it.
        from_identification : str or Path, optional
            An identification (``motionhyst identify --save`` TOML or ``--json``) whose link
            parameters are drawn jointly from their covariance
            (:mod:`motionhyst.study.identified`), as ``[samples] from_identification`` (a
            study without ``[samples]``: 100 samples, seed 0).
        """
        path = Path(path)
        try:
            data = read_toml(path)
        except InputFileError as exc:
            raise StudyError(f"{path}: {exc}") from None
        if from_identification is not None:
            samples = data.get("samples")
            samples = dict(samples) if isinstance(samples, dict) else {"n": 100, "seed": 0}
            samples["from_identification"] = str(Path(from_identification).absolute())
            data["samples"] = samples
        try:
            return cls.from_dict(data, source=str(path), base_dir=path.parent)
        except StudyError as exc:
            raise StudyError(f"{path}: {exc}") from None

    @classmethod
    def from_dict(cls, data: dict, source: str = "<dict>", base_dir: Path | None = None,
                  scenario: dict | None = None) -> StudyDefinition:
        """A study from the layout of a study file; `scenario` given replaces its ``scenario``.

        Raises :class:`StudyError` naming the key at fault.

        Parameters
        ----------
        data : dict
            The study file's tables: ``scenario``, ``outputs``, ``[axes]``, ``[samples]``.
        source : str
            Where it comes from (an attribute of the results).
        base_dir : Path, optional
            The folder the scenario file is named relative to (default: the working folder).
        scenario : dict, optional
            The scenario's tables, instead of reading ``data["scenario"]``.
        """
        unknown = sorted(set(data) - {"scenario", "outputs", "axes", "samples", "scan"})
        if unknown:
            raise StudyError(f"unknown key {unknown[0]!r} (a study has scenario, outputs, "
                             f"[axes], [samples] and [scan])")
        scenario_source = "<dict>"
        if scenario is None:
            name = data.get("scenario")
            if not isinstance(name, str) or not name:
                raise StudyError("'scenario': give the scenario file, relative to the study file")
            spath = Path(name)
            if not spath.is_absolute():
                spath = (base_dir or Path.cwd()) / spath
            if source != "<dict>" and spath.resolve() == Path(source).resolve():
                raise StudyError(f"'scenario': {name} is this study file; give the scenario "
                                 f"it studies (the file of [stage], [controller], ...)")
            try:
                scenario = read_toml(spath)
            except InputFileError as exc:
                raise StudyError(f"'scenario': {spath}: {exc}") from None
            if "scenario" in scenario and "outputs" in scenario:
                raise StudyError(f"'scenario': {name} is a study file (it names a scenario "
                                 f"and outputs); give the scenario it studies (the file of "
                                 f"[stage], [controller], ...)")
            scenario_source = name
        outputs = data.get("outputs")
        if (not isinstance(outputs, list) or not outputs
                or not all(isinstance(o, str) for o in outputs)):
            raise StudyError(f"'outputs': give a list of names among {', '.join(OUTPUTS)}")
        for o in outputs:
            if o not in OUTPUTS:
                raise StudyError(f"'outputs': unknown output {o!r} (known: "
                                 f"{', '.join(OUTPUTS)})")
        if len(set(outputs)) != len(outputs):
            raise StudyError("'outputs': a name repeats")
        axes_spec = data.get("axes", {})
        if not isinstance(axes_spec, dict):
            raise StudyError("'axes': give a table [axes]")
        axes = {key: _axis_values(key, spec, "[axes] ") for key, spec in axes_spec.items()}
        scan = None
        if "scan" in outputs:
            if "scan" in data and not isinstance(data["scan"], dict):
                raise StudyError("'scan': give a table [scan]")
            try:
                scan = scan_settings(data.get("scan"), axes)
            except ValueError as exc:
                raise StudyError(str(exc)) from None
        elif "scan" in data or any(k.startswith("scan.") for k in axes):
            raise StudyError("[scan] and the axes scan.* set the output 'scan'; add it to "
                             "'outputs'")
        ref = scenario.get("reference") if isinstance(scenario.get("reference"), dict) else {}
        scan_only = outputs == ["scan"] and bool(axes or "samples" in data)
        for key, default in (("amplitude", ref.get("amplitude")),
                             ("frequency_hz", ref.get("frequencies"))):
            if key not in axes and not scan_only:
                if default is None:
                    raise StudyError(f"[axes]: give {key} (the scenario has no [reference] "
                                     f"{'amplitude' if key == 'amplitude' else 'frequencies'})")
                if key == "amplitude":
                    default = [default]
                axes[key] = _axis_values(key, default, "[reference] ")
        samples: dict[str, tuple[str, float, float]] = {}
        joint: JointNormal | None = None
        n, seed = 0, 0
        if "samples" in data:
            s = dict(data["samples"]) if isinstance(data["samples"], dict) else None
            if s is None:
                raise StudyError("'samples': give a table [samples]")
            n, seed = s.pop("n", None), s.pop("seed", None)
            identified = s.pop("from_identification", None)
            chosen = "from_identification_tables" in s  # else the stage's as it matches
            tables = s.pop("from_identification_tables", ["hysteresis"])
            if not (isinstance(tables, list) and tables
                    and set(tables) <= {"hysteresis", "stage"}):
                raise StudyError("[samples] 'from_identification_tables': give a list of the "
                                 "tables drawn from the identification, \"hysteresis\" and/or "
                                 "\"stage\"")
            if identified is None and tables != ["hysteresis"]:
                raise StudyError("[samples] 'from_identification_tables': give "
                                 "from_identification too")
            if identified is not None:
                if not isinstance(identified, str) or not identified:
                    raise StudyError("[samples] 'from_identification': give the TOML of "
                                     "`motionhyst identify --save` or the JSON of `identify "
                                     "--json`, relative to the study file")
                ipath = Path(identified)
                if not ipath.is_absolute():
                    ipath = (base_dir or Path.cwd()) / ipath
                try:
                    def before_matrix(keys, values, n=n, seed=seed):
                        _check_count(n, seed)  # an identification's matrix is read after these
                        if not chosen:
                            _check_stage_keys(scenario, keys, values, str(ipath))
                        _check_drawn(scenario, keys, values, axes, base_dir)

                    joint = joint_from_identification(
                        ipath, tuple(tables) if chosen else ("hysteresis", "stage"),
                        check=before_matrix)
                    if joint is not None and not chosen:
                        _check_stage_values(scenario, joint, str(ipath))
                    drawn = {} if joint is not None else distributions_from_identification(ipath)
                except StudyError:
                    raise
                except ValueError as exc:
                    raise StudyError(f"[samples] {exc}") from None
                for key, dist in drawn.items():
                    s.setdefault(key, {dist[0]: [dist[1], dist[2]]})  # the file's own win
                if joint is not None:
                    for key in joint.keys:
                        if key in REFERENCE_AXES or key in axes:
                            raise StudyError(f"[samples] {key!r} (from_identification): "
                                             f"already an axis")
                    joint = joint.without(s)  # the file's own win: the others' marginal
            _check_count(n, seed)
            if not s and joint is None:
                raise StudyError("[samples]: name at least one scenario key and its "
                                 "distribution")
            for key, spec in s.items():
                if key in REFERENCE_AXES or key in axes:
                    raise StudyError(f"[samples] {key!r}: already an axis")
                samples[key] = _distribution(key, spec)
        study = cls(scenario=scenario, axes=axes, outputs=list(outputs), samples=samples,
                    n_samples=n, seed=seed, source=source, scenario_source=scenario_source,
                    base_dir=base_dir, joint=joint, scan=scan)
        study.check()
        return study

    def check(self) -> None:
        """Validate the scenario with the first value of each axis and sample; a key the
        scenario does not accept raises :class:`StudyError` naming it, as does a ``[samples]``
        distribution with more than :data:`MAX_REFUSED_MASS` of its mass where the scenario
        refuses the value; an implausible value of its stage is a warning
        (:func:`~motionhyst.scenario.schema.warn_implausible`)."""
        from motionhyst.hysteresis.along_stroke import NO_DESCRIBING_FUNCTION
        from motionhyst.scenario import Scenario, ScenarioError
        from motionhyst.scenario.schema import warn_implausible

        if self.n_points > MAX_POINTS:
            raise StudyError(f"{self.n_points} points: more than {MAX_POINTS}; split the study")
        first = self.point(0)
        for key, value in first.items():
            if not is_scenario_key(key):
                continue
            data = copy.deepcopy(self.scenario)
            where = "[samples]" if key in self.sampled_keys else "[axes]"
            try:
                set_key(data, key, value)
                Scenario.from_dict(data, source="the scenario", base_dir=self.base_dir,
                                   check=False)
            except StudyError as exc:
                raise StudyError(f"{where} {key!r}: not a key of the scenario ({exc})") from None
            except ScenarioError as exc:
                if str(exc).endswith("unknown key") or "Extra inputs" in str(exc):
                    raise StudyError(f"{where} {key!r}: not a key of the scenario ({exc})"
                                     ) from None
                raise StudyError(f"{where} {key!r} = {value:g}: refused by {exc}") from None
        try:
            sc = Scenario.from_dict(self.scenario_at(first), source="the scenario",
                                    base_dir=self.base_dir, check=False)
        except ScenarioError as exc:
            raise StudyError(str(exc)) from None
        for key in self.samples:  # the first point admitted: a refusal is the key's value
            if is_scenario_key(key):
                self._check_mass(key, first)
        if sc.is_open_loop:
            raise StudyError("the scenario is an open-loop system; a study needs a closed loop")
        if "E" in self.outputs and sc.along_stroke:  # refused before the points run
            raise StudyError("'outputs': E: "
                             f"{NO_DESCRIBING_FUNCTION.format(key=', '.join(sc.along_keys))}")
        sc.source = self.scenario_source  # its stage's implausible values named once
        warn_implausible(sc)

    def _refusal(self, key: str, value: float, first: dict) -> str | None:
        """Why the scenario refuses `key` = `value` at the first point's other values (None:
        admitted)."""
        from motionhyst.scenario import Scenario, ScenarioError

        data = self.scenario_at({**first, key: value})
        name = self.scenario_source if self.scenario_source != "<dict>" else "the scenario"
        try:
            Scenario.from_dict(data, source=name, base_dir=self.base_dir, check=False)
        except ScenarioError as exc:
            return str(exc)
        return None

    def _check_mass(self, key: str, first: dict) -> None:
        """Refuse a ``[samples]`` distribution of `key` that puts more than
        :data:`MAX_REFUSED_MASS` of its mass where the scenario refuses the value, the two
        ends together: from each end the scenario is asked at the distribution's quantile
        1e-9 and, where it refuses there, the edge of the admitted values is found by
        bisection of the quantile (the admitted values an interval)."""
        kind, a, b = self.samples[key]
        shares, reasons = [], []
        for low in (True, False):
            edge = 1e-9
            why = self._refusal(key, _quantile(kind, a, b, edge if low else 1.0 - edge), first)
            if why is None:
                continue
            inner = 0.5
            if self._refusal(key, _quantile(kind, a, b, inner), first) is not None:
                shares.append(1.0)
            else:  # refused near the end, admitted at the median: the edge between
                for _ in range(30):
                    mid = (edge + inner) / 2
                    if self._refusal(key, _quantile(kind, a, b, mid if low else 1.0 - mid),
                                     first) is None:
                        inner = mid
                    else:
                        edge = mid
                shares.append(inner)
            reasons.append((shares[-1], low, why))
        total = sum(shares)
        if total <= MAX_REFUSED_MASS:
            return
        _, low, why = max(reasons)
        share = "more than half" if total >= 0.5 else f"{100 * total:.3g} %"
        remedy = ("a lognormal distribution (positive by construction) or one within the "
                  "admitted values" if low else "a distribution within the admitted values")
        raise StudyError(f"[samples] {key!r}: {kind} [{a:g}, {b:g}] puts {share} of its "
                         f"draws where the scenario refuses them ({why}), more than the "
                         f"{100 * MAX_REFUSED_MASS:g} % a study admits (its bands would "
                         f"be of the draws left); give {remedy}")

    # ---------------------------------------------------------------- points
    def _draw(self) -> NDArray[np.float64]:
        """The Monte-Carlo samples, one column per sampled key (:attr:`sampled_keys`): the
        independent ones in file order, then the joint ones, from one seeded generator."""
        rng = np.random.default_rng(self.seed)
        cols = []
        for kind, a, b in self.samples.values():
            if kind == "lognormal":
                cols.append(a * np.exp(b * rng.standard_normal(self.n_samples)))
            elif kind == "normal":
                cols.append(a + b * rng.standard_normal(self.n_samples))
            else:
                cols.append(rng.uniform(a, b, self.n_samples))
        if self.joint is not None:
            cols.extend(self.joint.draw(rng, self.n_samples).T)
        return np.array(cols, dtype=float).T.reshape(self.n_samples, len(self.sampled_keys))

    @property
    def sampled_keys(self) -> tuple[str, ...]:
        """The keys drawn by Monte Carlo: those of :attr:`samples`, then :attr:`joint`'s."""
        return tuple(self.samples) + (() if self.joint is None else self.joint.keys)

    @property
    def dims(self) -> tuple[str, ...]:
        """The results' dimensions: the axes in file order, then ``sample``."""
        return tuple(self.axes) + (("sample",) if self.sampled_keys else ())

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values along each of :attr:`dims`."""
        return tuple(len(v) for v in self.axes.values()) + (
            (self.n_samples,) if self.sampled_keys else ())

    @property
    def n_points(self) -> int:
        """Number of points (the product of :attr:`shape`)."""
        return math.prod(self.shape)

    def point(self, index: int) -> dict[str, float]:
        """The axes' and samples' values at the flat (C-order) `index` of :attr:`shape`.

        Parameters
        ----------
        index : int
            Flat index of the point.
        """
        idx = np.unravel_index(int(index), self.shape)
        out = {k: str(v[i]) if v.dtype.kind == "U" else float(v[i])
               for (k, v), i in zip(self.axes.items(), idx, strict=False)}
        if self.sampled_keys:
            row = self.sample_values[idx[-1]]
            out.update({k: float(x) for k, x in zip(self.sampled_keys, row, strict=True)})
        return out

    def scenario_at(self, values: dict[str, float]) -> dict:
        """The scenario dictionary with the scenario keys of `values` set.

        Parameters
        ----------
        values : dict of str to float
            Dotted scenario keys (and the reference axes, which are left out) to values.
        """
        data = copy.deepcopy(self.scenario)
        for key, value in values.items():
            if is_scenario_key(key):
                set_key(data, key, value)
        return data

    def scan_at(self, values: dict) -> dict | None:
        """The scan's settings at a point: :attr:`scan` and the point's ``scan.*`` `values`
        (None for a study without the output ``scan``).

        Parameters
        ----------
        values : dict
            The point's values (:meth:`point`).
        """
        if self.scan is None:
            return None
        return {**self.scan, **{k[5:]: v for k, v in values.items() if k.startswith("scan.")}}

    def order(self) -> NDArray[np.int64]:
        """Flat indices in the order points are computed: the reference axes vary fastest,
        so consecutive points share one loop."""
        dims = self.dims
        inner = [i for i, d in enumerate(dims) if d in REFERENCE_AXES]
        outer = [i for i, d in enumerate(dims) if d not in REFERENCE_AXES]
        grid = np.arange(self.n_points, dtype=np.int64).reshape(self.shape)
        return grid.transpose(outer + inner).ravel()

    def fingerprint(self) -> str:
        """A digest of everything that sets the results (a store holds one study)."""
        d = {"scenario": self.scenario, "axes": {k: v.tolist() for k, v in self.axes.items()},
             "outputs": self.outputs, "samples": self.samples, "n": self.n_samples,
             "seed": self.seed}
        if self.joint is not None:  # (absent otherwise: the stores of older studies resume)
            d["joint"] = self.joint.to_dict()
        if self.scan is not None:
            d["scan"] = self.scan
        return hashlib.sha256(json.dumps(d, sort_keys=True, default=str).encode()).hexdigest()

    def to_dict(self) -> dict:
        """Plain parameters (what a worker needs to compute any point)."""
        return {"scenario": self.scenario, "axes": {k: v.tolist() for k, v in self.axes.items()},
                "outputs": self.outputs,
                "samples": {k: list(v) for k, v in self.samples.items()},
                "n_samples": self.n_samples, "seed": self.seed, "source": self.source,
                "scenario_source": self.scenario_source,
                "base_dir": None if self.base_dir is None else str(self.base_dir),
                "joint": None if self.joint is None else self.joint.to_dict(),
                "scan": self.scan}

    @classmethod
    def from_plain(cls, d: dict) -> StudyDefinition:
        """The inverse of :meth:`to_dict` (no file read, no check).

        Parameters
        ----------
        d : dict
            What :meth:`to_dict` gave.
        """
        return cls(scenario=d["scenario"],
                   axes={k: np.asarray(v, dtype=str if k == "scan.compensation" else float)
                         for k, v in d["axes"].items()},
                   outputs=list(d["outputs"]),
                   samples={k: (v[0], float(v[1]), float(v[2]))
                            for k, v in d["samples"].items()},
                   n_samples=d["n_samples"], seed=d["seed"], source=d["source"],
                   scenario_source=d["scenario_source"],
                   base_dir=None if d["base_dir"] is None else Path(d["base_dir"]),
                   joint=None if d.get("joint") is None else JointNormal.from_dict(d["joint"]),
                   scan=d.get("scan"))


def _check_drawn(scenario: dict, keys: list[str], values: list[float], axes: dict,
                 base_dir: Path | None) -> None:
    """Refuse, before an identification's covariance is read, the keys it would draw that are
    an axis or not keys of the scenario (a 1000-element link's 2000 parameters for a
    scenario's Jenkins link): each named, as :meth:`StudyDefinition.check` names them."""
    from motionhyst.scenario import Scenario, ScenarioError

    data = copy.deepcopy(scenario)
    for key, value in zip(keys, values, strict=True):
        if key in REFERENCE_AXES or key in axes:
            raise ValueError(f"{key!r} (from_identification): already an axis")
        try:
            set_key(data, key, value)
        except StudyError as exc:
            raise ValueError(f"{key!r}: not a key of the scenario ({exc})") from None
    try:
        Scenario.from_dict(data, source="the scenario", base_dir=base_dir, check=False)
    except ScenarioError as exc:  # which key: one at a time, as check() does
        if not (str(exc).endswith("unknown key") or "Extra inputs" in str(exc)):
            return  # a value the scenario refuses: named by check() with its point
        for key, value in zip(keys, values, strict=True):
            one = copy.deepcopy(scenario)
            set_key(one, key, value)
            try:
                Scenario.from_dict(one, source="the scenario", base_dir=base_dir, check=False)
            except ScenarioError as err:
                if str(err).endswith("unknown key") or "Extra inputs" in str(err):
                    raise ValueError(f"{key!r}: not a key of the scenario ({err})") from None


STAGE_MATCH = 3.0
"""How many of its standard errors the scenario's ``[stage]`` value of an identified stage
parameter may differ from the estimate for the identification's draws to be of that stage
(then drawn jointly with the link's, as they were estimated)."""

_BY_THE_LINK_ALONE = ('or from_identification_tables = ["hysteresis"] in [samples] to put the '
                      "link alone on the scenario's stage")


def _check_stage_keys(scenario: dict, keys: list[str], values: list[float], source: str
                      ) -> None:
    """Refuse an identification that holds stage parameters (``stage.m``, ... of an
    input-output identification: estimated jointly with the link's) the scenario's
    ``[stage]`` does not have: its link's draws are of another stage."""
    stage = scenario.get("stage") if isinstance(scenario.get("stage"), dict) else None
    held = [(k, v) for k, v in zip(keys, values, strict=True) if k.startswith("stage.")]
    lacking = [(k, v) for k, v in held if stage is None or k[6:] not in stage]
    if not lacking:
        return
    if stage is None:
        what = "the scenario has no [stage] (a measured [plant])"
    else:
        names = [k for k, v in stage.items() if k != "type" and not isinstance(v, dict)]
        kind = f"{stage['type']}: " if isinstance(stage.get("type"), str) else ""
        what = (f"the scenario's [stage] ({kind}{', '.join(names)}) does not have "
                f"{', '.join(k[6:] for k, _ in lacking)}")
    raise ValueError(f"from_identification {source}: its link was identified on a stage "
                     f"({', '.join(f'{k} = {v:.6g}' for k, v in held)}, estimated jointly "
                     f"with it) and {what}; give a scenario of the identified stage, "
                     f"{_BY_THE_LINK_ALONE}")


def _check_stage_values(scenario: dict, joint: JointNormal, source: str) -> None:
    """Refuse an identification whose stage estimates differ from the scenario's ``[stage]``
    values by more than :data:`STAGE_MATCH` standard errors (else they are drawn jointly with
    the link's, about the estimates)."""
    stage = scenario.get("stage") if isinstance(scenario.get("stage"), dict) else {}
    std = joint.std
    for i, key in enumerate(joint.keys):
        if not key.startswith("stage."):
            continue
        value, estimate = stage.get(key[6:]), joint.mean[i]
        number = isinstance(value, int | float) and not isinstance(value, bool)
        off = abs(value - estimate) if number else math.inf
        if off <= STAGE_MATCH * std[i] + 1e-12 * abs(estimate):
            continue
        by = f"{off / std[i]:.3g} standard errors" if std[i] > 0 else "more than its rounding"
        raise ValueError(f"from_identification {source}: the scenario's [stage] {key[6:]} = "
                         f"{value!r} is not the identified {key} = "
                         f"{estimate:.{_digits(estimate, std[i])}g} +- "
                         f"{std[i]:.3g} (off by {by}, more than {STAGE_MATCH:g}): its link "
                         f"was identified on that stage, jointly; give the identified values "
                         f"in the scenario's [stage] (they are then drawn with the link's), "
                         f"{_BY_THE_LINK_ALONE}")


def _digits(estimate: float, std: float) -> int:
    """Significant digits that print `estimate` within a twentieth of its standard error
    `std` (at least 6): the value a refusal asks for, copied as printed, is then accepted."""
    if not (std > 0 and estimate != 0 and math.isfinite(estimate)):
        return 17
    return min(17, max(6, math.ceil(math.log10(abs(estimate) / std)) + 2))


def _check_count(n, seed) -> None:
    """Refuse ``[samples]`` ``n`` and ``seed`` that are not whole numbers in range."""
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise StudyError("[samples] 'n': give a whole number of samples >= 1")
    if n > MAX_POINTS:  # before they are drawn
        raise StudyError(f"[samples] 'n': {n} samples, more than the {MAX_POINTS} "
                         f"points a study holds; split the study")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise StudyError("[samples] 'seed': give a whole number >= 0 (the samples are "
                         "drawn from it, reproducibly)")
