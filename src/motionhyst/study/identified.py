"""Monte-Carlo samples from an identification: the link's parameters drawn from the
multivariate normal distribution of their estimates.

An identification carries the covariance of its estimates, from the fit's Jacobian (the
matrix whose diagonal's square roots are the standard errors):

- ``motionhyst identify ... --save model.toml`` writes it as ``[identification]``:
  ``parameters`` (scenario keys: ``hysteresis.k``, ``hysteresis.fc``, ``stage.m``, ...),
  ``estimates``, ``std`` and ``correlation``;
- ``motionhyst identify ... --json > fit.json`` prints it as ``covariance``: ``parameters``
  (a force-displacement record: ``k``, ``fc``, ``offset``, or ``k[0], ..., fc[0], ...`` for
  several elements; an input-output record: the names of ``estimates``, the link's as
  ``link.NAME``, a Bouc-Wen link's as ``alpha``, ``beta*gamma``, ``beta*delta``, ``nu``) and
  ``matrix``.

The elements of a Maxwell-slip link are the keys ``hysteresis.k[0]``, ``hysteresis.fc[0]``, ...
(the study's scenario has as many elements).  A Bouc-Wen link's are ``hysteresis.alpha``,
``hysteresis.nu`` and the products ``hysteresis.beta*gamma``, ``hysteresis.beta*delta`` (what
the records determine: :func:`~motionhyst.study.spec.set_key` sets ``beta``, ``gamma`` and
``delta`` from them); the products may be of either sign, ``nu`` is at least 1.

A study's ``[samples] from_identification = "model.toml"`` (or ``motionhyst study
--from-identification model.toml``) draws the link's parameters (the keys
``hysteresis.*``) jointly from that distribution, seeded (:class:`JointNormal`), and the
stage's estimates (``stage.m``, ... of an input-output identification) with them when the
scenario's ``[stage]`` is the identified one (:data:`motionhyst.study.spec.STAGE_MATCH`; a
scenario of another stage is refused); ``from_identification_tables = ["hysteresis"]`` draws
the marginal of the link's parameters alone, on the scenario's own stage.  A
parameter
must stay positive (:func:`least_value`): when every drawn positive parameter's relative
standard error is at most :data:`LOG_SPACE_CV`, the draws are those of the normal distribution
itself (a draw at or below 0 would be five standard deviations away, and is drawn again);
above it, of the lognormal distribution with the same means and covariance (moment-matched:
positive by construction; a signed parameter stays normal, with the same covariances).  A
draw below a parameter's least value (a Bouc-Wen ``nu`` below 1) is drawn again.

A JSON of an older ``identify --json``, with standard errors but no covariance, gives
independent lognormal draws (:func:`distributions_from_identification`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.budget import format_size
from motionhyst.core.validation import (
    CORRELATION_ROUNDING,
    check_correlation,
    least_correlation_eigenvalue,
)
from motionhyst.identify.io_uncertainty import BOUC_WEN_IDENTIFIED
from motionhyst.io.inputs import TOML_EXPANSION, InputFileError, read_text, read_toml

__all__ = ["LOG_SPACE_CV", "MAX_IDENTIFICATION_BYTES", "JointNormal",
           "distributions_from_identification", "joint_from_identification", "least_value"]

LOG_SPACE_CV = 0.2
"""Largest relative standard error of a drawn parameter for which the draws are those of the
normal distribution; above it, of the lognormal one with the same means and covariance."""

MAX_IDENTIFICATION_BYTES = 4_000_000
"""Largest identification file read [bytes].  What ``identify --save`` or ``--json`` writes is
a few kB (its largest, 20 Maxwell-slip elements with the stage, under 100 kB: the correlation
of some 50 parameters); a larger file is refused before it is parsed (parsing TOML takes about
0.1 s of CPU per MB)."""



def least_value(key: str) -> float | None:
    """The least value a drawn scenario `key` takes: None for a Bouc-Wen link's products
    (``hysteresis.beta*gamma``, ``hysteresis.beta*delta``: either sign), 1 for its exponent
    ``hysteresis.nu`` (a draw below is drawn again), else 0 (exclusive: a positive parameter).

    Parameters
    ----------
    key : str
        A scenario key.

    Examples
    --------
    >>> least_value("hysteresis.k"), least_value("hysteresis.beta*delta"), least_value(
    ...     "hysteresis.nu")
    (0.0, None, 1.0)
    """
    last = key.rpartition(".")[2]
    if "*" in last:
        return None
    return 1.0 if key == "hysteresis.nu" else 0.0


@dataclass(frozen=True)
class JointNormal:
    """Correlated draws of scenario keys, positive ones (and the signed products of a
    Bouc-Wen link, :func:`least_value`): a multivariate normal distribution (or, where it
    would reach 0, the lognormal one with the same means and covariance).

    Parameters
    ----------
    keys : tuple of str
        Scenario keys (``"hysteresis.k"``, ...).
    mean : tuple of float
        Their means (the estimates), above :func:`least_value` (> 0 for most).
    covariance : tuple of tuple of float
        Their covariance matrix (symmetric, positive semi-definite).
    source : str
        Where it comes from (an identification file), for the results' attributes.

    Examples
    --------
    >>> d = JointNormal(("hysteresis.k", "hysteresis.fc"), (20.0, 0.05),
    ...                 ((0.16, 2e-4), (2e-4, 1e-6)))
    >>> d.log_space, d.correlation[0][1]
    (False, 0.5)
    >>> x = d.draw(np.random.default_rng(0), 20000)
    >>> bool(np.allclose(np.cov(x.T), d.covariance, rtol=0.05))
    True
    """

    keys: tuple[str, ...]
    mean: tuple[float, ...]
    covariance: tuple[tuple[float, ...], ...]
    source: str = "<dict>"

    def __post_init__(self) -> None:
        d = len(self.keys)
        m = np.asarray(self.mean, dtype=float)
        c = np.asarray(self.covariance, dtype=float)
        where = f"{self.source}: " if self.source != "<dict>" else ""
        if d == 0 or m.shape != (d,) or c.shape != (d, d):
            raise ValueError(f"{where}give a mean and a {d} x {d} covariance for {d} keys")
        bad = [k for k, v in zip(self.keys, m, strict=True) if not _admitted(k, v)]
        if bad:
            least = least_value(bad[0])
            what = "a positive number" if not least else f"a number >= {least:g}"
            raise ValueError(f"{where}{bad[0]} = {m[self.keys.index(bad[0])]:g}: a parameter "
                             f"to draw must be {what}")
        if not (np.all(np.isfinite(c)) and np.allclose(c, c.T, rtol=1e-9, atol=0.0)):
            raise ValueError(f"{where}the covariance must be finite and symmetric")
        least = least_correlation_eigenvalue(c)
        if np.any(np.diag(c) < 0) or least < -CORRELATION_ROUNDING * d:
            raise ValueError(f"{where}the covariance is not positive semi-definite (its "
                             f"correlation matrix has the eigenvalue {least:.3g})")

    @property
    def std(self) -> NDArray[np.float64]:
        """Standard deviation of each key."""
        return np.sqrt(np.clip(np.diag(np.asarray(self.covariance, dtype=float)), 0.0, None))

    @property
    def correlation(self) -> list[list[float]]:
        """The correlation matrix (0 where a standard deviation is 0, 1 on the diagonal)."""
        s = self.std
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.asarray(self.covariance, dtype=float) / np.outer(s, s)
        r = np.where(np.outer(s, s) > 0, r, 0.0)
        np.fill_diagonal(r, 1.0)
        return r.tolist()

    @property
    def _positive(self) -> NDArray[np.bool_]:
        return np.array([least_value(k) is not None for k in self.keys])

    @property
    def log_space(self) -> bool:
        """Whether the draws of the positive keys are lognormal: a relative standard error
        above :data:`LOG_SPACE_CV`."""
        pos = self._positive
        return bool(pos.any() and np.max(self.std[pos] / np.asarray(self.mean)[pos])
                    > LOG_SPACE_CV)

    def without(self, keys) -> JointNormal | None:
        """The marginal distribution of the other keys (None if none is left).

        Parameters
        ----------
        keys : iterable of str
            The keys to leave out.
        """
        keep = [i for i, k in enumerate(self.keys) if k not in set(keys)]
        if not keep:
            return None
        c = np.asarray(self.covariance, dtype=float)[np.ix_(keep, keep)]
        return JointNormal(tuple(self.keys[i] for i in keep), tuple(self.mean[i] for i in keep),
                           tuple(map(tuple, c.tolist())), self.source)

    def draw(self, rng: np.random.Generator, n: int) -> NDArray[np.float64]:
        """`n` draws, a row each (columns in the order of :attr:`keys`), from `rng`.

        Normal draws (:attr:`log_space` false): ``mean + L z`` with ``L L^T`` the
        covariance.  Lognormal ones: ``exp(mu + S z)`` with ``S_ij = log(1 + C_ij / (m_i
        m_j))`` and ``mu_i = log m_i - S_ii / 2``, whose means are ``m`` and covariance
        ``C``; a signed key ``j`` stays normal, ``S_ij = C_ij / m_i``, ``S_jj = C_jj``
        (``Cov(exp(y), x) = E[exp(y)] Cov(y, x)``).  A draw with a parameter at or below its
        least value (:func:`least_value`) is drawn again.

        Parameters
        ----------
        rng : numpy.random.Generator
            The generator (the study's, seeded).
        n : int
            Number of draws.
        """
        m = np.asarray(self.mean, dtype=float)
        c = np.asarray(self.covariance, dtype=float)
        p = self._positive
        log = self.log_space
        mu, s = m.copy(), c.copy()
        if log:
            with np.errstate(invalid="ignore"):  # below -1: refused below
                s[np.ix_(p, p)] = np.log1p(c[np.ix_(p, p)] / np.outer(m[p], m[p]))
            s[np.ix_(p, ~p)] = c[np.ix_(p, ~p)] / m[p][:, None]
            s[np.ix_(~p, p)] = s[np.ix_(p, ~p)].T
            mu[p] = np.log(m[p]) - np.diag(s)[p] / 2
        where = f"{self.source}: " if self.source != "<dict>" else ""
        if not np.all(np.isfinite(s)):  # log1p of C_ij / (m_i m_j) <= -1
            i, j = np.argwhere(~np.isfinite(s))[0]
            raise ValueError(f"{where}the covariance of {self.keys[i]} and {self.keys[j]} "
                             f"({c[i, j]:.3g}) is at or below minus the product of their means "
                             f"({m[i]:g} x {m[j]:g}): no lognormal draws have these means and "
                             f"covariance (standard errors {self.std[i]:.3g} and "
                             f"{self.std[j]:.3g}, too wide for the values to draw from)")
        factor = _factor(s)

        def sample(rows: int) -> NDArray[np.float64]:
            w = mu + rng.standard_normal((rows, m.size)) @ factor.T
            if log:
                w[:, p] = np.exp(w[:, p])
            return w

        least = np.array([-np.inf if v is None else v for v in map(least_value, self.keys)])

        def outside(x: NDArray[np.float64]) -> NDArray[np.bool_]:  # as _admitted, by rows
            return np.any(~np.isfinite(x) | (x < least) | ((x == least) & (least == 0.0)),
                          axis=1)

        x = sample(n)
        bad = np.nonzero(outside(x))[0]
        rounds = 0
        while bad.size:
            rounds += 1
            if rounds > MAX_REDRAWS:
                raise ValueError(f"{where}{bad.size} of {n} draws still have a parameter "
                                 f"outside its admitted values after {MAX_REDRAWS} redraws: "
                                 f"the standard errors are too wide for the values to draw "
                                 f"from")
            x[bad] = sample(bad.size)
            bad = bad[outside(x[bad])]
        return x

    def to_dict(self) -> dict:
        """Plain parameters: ``keys``, ``mean``, ``covariance``, ``source``, ``log_space``."""
        return {"keys": list(self.keys), "mean": list(self.mean),
                "covariance": [list(r) for r in self.covariance], "source": self.source,
                "log_space": self.log_space}

    @classmethod
    def from_dict(cls, d: dict) -> JointNormal:
        """The inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            What :meth:`to_dict` gave.
        """
        return cls(tuple(d["keys"]), tuple(float(v) for v in d["mean"]),
                   tuple(tuple(float(v) for v in r) for r in d["covariance"]),
                   d.get("source", "<dict>"))


def _admitted(key: str, value: float) -> bool:
    """Whether `value` is finite and admitted for `key`: above 0, at least 1 for a Bouc-Wen
    ``nu``, of either sign for its products (:func:`least_value`)."""
    least = least_value(key)
    if not math.isfinite(value):
        return False
    return least is None or (value >= least if least else value > least)


MAX_REDRAWS = 1000
"""Rounds of redrawing the draws with a parameter at or below its least value (each round
keeps the admitted ones): a distribution that puts almost all its mass there is refused, not
drawn from forever."""


def _factor(c: NDArray[np.float64]) -> NDArray[np.float64]:
    """``L`` with ``L L^T = c`` for a positive semi-definite `c` (from its eigenvectors)."""
    w, v = np.linalg.eigh(c)
    return v * np.sqrt(np.clip(w, 0.0, None))


def _read(path: Path, where: str):
    try:
        size = path.stat().st_size
    except (OSError, ValueError):  # read_text says why
        size = 0
    if size > MAX_IDENTIFICATION_BYTES:
        raise ValueError(f"{where}: {format_size(size)}, too large for an identification "
                         f"(`motionhyst identify --save` writes a few kB; at most "
                         f"{format_size(MAX_IDENTIFICATION_BYTES)} is read)")
    try:
        if path.suffix.lower() == ".toml":
            return read_toml(path)
        text = read_text(path, TOML_EXPANSION, "JSON")
    except InputFileError as exc:
        raise ValueError(f"{where}: {exc}") from None
    try:
        data = json.loads(text)
    except RecursionError:  # arrays within arrays thousands of levels deep
        raise ValueError(f"{where}: JSON nested too deeply (not what `motionhyst identify "
                         f"--json` printed)") from None
    except ValueError:
        raise ValueError(f"{where}: not JSON (give what `motionhyst identify --json` printed, "
                         f"or the .toml of `identify --save`)") from None
    if not isinstance(data, dict):
        raise ValueError(f"{where}: not an identification (`motionhyst identify --json`)")
    return data


def joint_from_identification(path: str | Path, tables: tuple[str, ...] = ("hysteresis",),
                              check: Callable[[list[str], list[float]], None] | None = None
                              ) -> JointNormal | None:
    """The joint distribution of the link's parameters of an identification, under the
    scenario's ``hysteresis.*`` keys (and the stage's, ``stage.*``, with `tables`); None for a
    JSON without covariance (an older ``identify --json``:
    :func:`distributions_from_identification`).

    Parameters
    ----------
    path : str or Path
        ``motionhyst identify --save`` TOML (its ``[identification]``) or ``identify --json``
        JSON (its ``covariance``).
    tables : tuple of str
        The scenario's tables whose identified parameters are drawn: ``"hysteresis"`` (the
        link), ``"stage"`` (the stage of an input-output identification: a study whose
        scenario is the identified system).
    check : callable, optional
        ``check(keys, estimates)``, called with the scenario keys to draw and their
        estimates before the covariance is read and validated (a large identification's
        names refused first); raises ValueError to refuse them.

    Returns
    -------
    JointNormal or None

    Raises
    ------
    ValueError
        One line: the file cannot be read, is not an identification, or has a link parameter
        whose standard error is not determined.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "model.toml"
    >>> _ = path.write_text('''
    ... [identification]
    ... parameters = ["stage.m", "hysteresis.k", "hysteresis.fc"]
    ... estimates = [2.0, 20.0, 0.05]
    ... std = [0.01, 0.4, 0.001]
    ... correlation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.5], [0.0, 0.5, 1.0]]
    ... ''')
    >>> d = joint_from_identification(path)
    >>> d.keys, d.mean, d.correlation[0][1]
    (('hysteresis.k', 'hysteresis.fc'), (20.0, 0.05), 0.5)
    >>> joint_from_identification(path, ("hysteresis", "stage")).keys
    ('stage.m', 'hysteresis.k', 'hysteresis.fc')
    """
    path = Path(path)
    where = f"from_identification {path}"
    data = _read(path, where)
    if path.suffix.lower() == ".toml":
        if not isinstance(data.get("identification"), dict):
            raise ValueError(f"{where}: no [identification] table (save the identification "
                             f"with `motionhyst identify ... --save MODEL.toml`)")
        raw = data["identification"]
        names, values = raw.get("parameters"), raw.get("estimates")
        if (check is not None and isinstance(names, list) and isinstance(values, list)
                and len(names) == len(values)
                and all(isinstance(n, str) for n in names)
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)):
            at = [i for i, n in enumerate(names) if n.partition(".")[0] in tables]
            check([names[i] for i in at], [float(values[i]) for i in at])
        from pydantic import ValidationError

        from motionhyst.scenario.sections import IdentificationSection, format_error

        try:
            sec = IdentificationSection.model_validate(data["identification"])
        except ValidationError as err:
            raise ValueError(format_error(where, err, ("identification",))) from None
        names = list(sec.parameters)
        mean = dict(zip(names, sec.estimates, strict=True))
        std = np.asarray(sec.std, dtype=float)
        cov = np.asarray(sec.correlation, dtype=float) * np.outer(std, std)
        keys = {n: n for n in names if n.partition(".")[0] in tables}
        missing = []
        hint = "--save"
    else:
        table = data.get("covariance")
        if not isinstance(table, dict):
            return None
        names = list(table.get("parameters", []))
        if isinstance(data.get("elements"), list):  # a force-displacement record
            elements = data["elements"]
            if len(elements) == 1:
                mean = _one_element(elements, where)
            else:  # a Maxwell-slip link: its elements' values, in the file's order
                mean = {f"{p}[{i}]": e.get(p) for p in ("k", "fc")
                        for i, e in enumerate(elements) if isinstance(e, dict)}
            keys = {n: f"hysteresis.{n}" for n in mean if n in ("k", "fc") or "[" in n}
        else:
            mean = dict(data.get("estimates") or {})
            keys = {n: f"hysteresis.{n[5:]}" for n in mean if n.startswith("link.")}
            link = data.get("hysteresis")
            if isinstance(link, dict) and link.get("model") == "bouc-wen":
                keys.update({n: f"hysteresis.{n}" for n in BOUC_WEN_IDENTIFIED if n in mean})
            plant = data.get("plant")
            if "stage" in tables and isinstance(plant, dict):  # its estimates, the stage's keys
                keys.update({n: f"stage.{n}" for n in plant if n != "type" and n in mean})
        # a stage's estimate without a standard error has no distribution (as the TOML of
        # `identify --save` leaves it out of [identification]): the scenario's value stays
        keys = {n: k for n, k in keys.items() if k.partition(".")[0] in tables
                and (n in names or not k.startswith("stage."))}
        missing = [n for n in keys if n not in names]
        hint = "--json"
    if missing:
        raise ValueError(f"{where}: {missing[0]}: its standard error is not determined by the "
                         f"identification; give its distribution in [samples]")
    drawn = [n for n in names if n in keys]
    if not drawn:
        raise ValueError(f"{where}: holds no link parameters with standard errors (give what "
                         f"`motionhyst identify {hint}` wrote)")
    if check is not None and hint == "--json":  # the names before the matrix
        values = [mean[n] for n in drawn]
        if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
            check([keys[n] for n in drawn], [float(v) for v in values])
    if hint == "--json":
        try:
            cov = np.asarray(table.get("matrix", []), dtype=float)
        except (TypeError, ValueError):  # ragged or not numbers: not a matrix
            cov = np.zeros(0)
    at = [names.index(n) for n in drawn]
    if cov.shape != (len(names), len(names)):
        raise ValueError(f"{where}: the covariance is not a {len(names)} x {len(names)} matrix")
    if hint == "--json":  # [identification] of a TOML is checked where it is read
        _check_whole(cov, names, where)
    sub = cov[np.ix_(at, at)]
    try:
        return JointNormal(tuple(keys[n] for n in drawn), tuple(float(mean[n]) for n in drawn),
                           tuple(map(tuple, sub.tolist())), str(path))
    except ValueError as exc:  # named as the other errors of the file
        raise ValueError(f"from_identification {exc}") from None


def _check_whole(cov: NDArray[np.float64], names: list, where: str) -> None:
    """Refuse an ``identify --json`` whose whole covariance (of every parameter it names,
    drawn or not) is no covariance: not finite, not symmetric, or not positive semi-definite
    (:func:`~motionhyst.core.validation.check_correlation`)."""
    if not (np.all(np.isfinite(cov)) and np.allclose(cov, cov.T, rtol=1e-9, atol=0.0)):
        raise ValueError(f"{where}: the covariance of its {len(names)} parameters is not finite "
                         f"and symmetric")
    try:
        check_correlation(cov, names, "--json")
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _one_element(elements: list, where: str) -> dict:
    """The one Jenkins element of a force-displacement record's identification."""
    if len(elements) != 1 or not isinstance(elements[0], dict):
        raise ValueError(f"{where}: {len(elements)} Jenkins elements; a study draws the "
                         f"parameters of one (a Jenkins link), give the others' "
                         f"distributions in [samples]")
    return dict(elements[0])


def _lognormal(key: str, value, std, where: str) -> tuple[str, float, float]:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ValueError(f"{where}: {key} = {value!r}: a link parameter to draw must be a "
                         f"positive number")
    if std is None or not (isinstance(std, int | float) and math.isfinite(std) and std >= 0):
        raise ValueError(f"{where}: {key}: its standard error is not determined by the "
                         f"identification ({std!r}); give its distribution in [samples]")
    return ("lognormal", float(value), float(std) / float(value))


def distributions_from_identification(path: str | Path) -> dict[str, tuple[str, float, float]]:
    """The link's parameters of an identification (``identify --json``) as independent
    distributions of the scenario's ``hysteresis.*`` keys, from their standard errors alone
    (what a JSON without ``covariance`` gives: :func:`joint_from_identification` reads the
    covariance where there is one).

    Each is lognormal around its estimate with the relative standard error as sigma (a
    positive parameter stays positive; for errors of a few percent this is the normal
    distribution of the estimate).

    Parameters
    ----------
    path : str or Path
        The JSON that ``motionhyst identify --json`` printed.

    Returns
    -------
    dict of str to (kind, a, b)
        ``{"hysteresis.k": ("lognormal", median, sigma), ...}``: the distributions of a study's
        ``[samples]``.

    Raises
    ------
    ValueError
        One line: the file cannot be read, is not an identification, has more than one
        element, or a parameter whose standard error is not determined.

    Examples
    --------
    >>> import json, tempfile
    >>> path = Path(tempfile.mkdtemp()) / "fit.json"
    >>> _ = path.write_text(json.dumps({"model": "maxwell-slip", "elements": [
    ...     {"k": 20.0, "k_std": 0.4, "fc": 0.05, "fc_std": 0.002}]}))
    >>> distributions_from_identification(path)
    {'hysteresis.k': ('lognormal', 20.0, 0.02), 'hysteresis.fc': ('lognormal', 0.05, 0.04)}
    """
    path = Path(path)
    where = f"from_identification {path}"
    data = _read(path, where)
    if isinstance(data.get("elements"), list):  # a force-displacement record
        e = _one_element(data["elements"], where)
        return {f"hysteresis.{name}": _lognormal(name, e.get(name), e.get(f"{name}_std"), where)
                for name in ("k", "fc")}
    estimates, std = data.get("estimates"), data.get("std")
    if isinstance(estimates, dict) and isinstance(std, dict):  # an input-output record
        out = {f"hysteresis.{name[5:]}": _lognormal(name, value, std.get(name), where)
               for name, value in estimates.items() if name.startswith("link.")}
        if out:
            return out
    raise ValueError(f"{where}: holds no link parameters with standard errors (give what "
                     f"`motionhyst identify --json` printed)")
