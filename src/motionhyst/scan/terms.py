"""The scan's model feedforward as named terms with coefficients: what ``model`` applies and
``basis`` learns.

On top of the loop's own rigid-body feedforward ``M0 r''`` the terms add::

    u_ff = (m - M0) r'' + cj r''' + cs r'''' + c r' + fc sign(r') + phi_hat(r; p)

with the stage's inverse up to the snap (``m``, ``cj``, ``cs``:
:mod:`motionhyst.controllers.inverse`, the paper's ``C_ff = M s^2`` when only
``m`` is used), viscous and Coulomb friction (``c``, ``fc``) and the link model
``phi_hat`` (eq. 3 for a Jenkins element) with its parameters ``p``.  Every
coefficient enters linearly but the link's; a link parameter is carried as a
scale ``theta`` of the model's value (of each of its elements' values, for a
parallel model).  :meth:`FeedforwardTerms.jacobian` gives the force's
derivatives in the coefficients (the link's by central differences), the
regressors of the learning in :mod:`motionhyst.scan.basis`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from motionhyst.controllers.feedforward import STANDSTILL
from motionhyst.hysteresis import Hysteresis

__all__ = ["TERMS", "FeedforwardTerms", "model_terms", "scan_terms", "setpoint_samples"]

TERMS = ("jerk", "snap", "viscous", "coulomb", "hysteresis")
"""The terms a scan's model feedforward may switch on (the acceleration term is always on)."""

UNITS = {"mass": "kg", "jerk": "N s^3/m", "snap": "N s^4/m", "viscous": "N s/m",
         "coulomb": "N"}

#: Relative step of the central differences in a link parameter's scale.
LINK_STEP = 1e-4


def setpoint_samples(profile, t, step: float | None = None) -> NDArray[np.float64]:
    """The setpoint's derivatives ``(r, r', r'', r''', r'''')`` at `t` for the terms' force.

    With `step`, the derivatives ``r'`` to ``r''''`` are averaged over ``t +- step``
    (from the exact differences of the derivative one order below): a continuous
    run takes its input linear between the samples, and a force sampled at the
    samples would move each jump of the snap (a fourth-order profile's, between
    samples) by up to half a step, an impulse ``cs ds step / 2`` against the
    stage's own ``c5 ds`` (:mod:`motionhyst.controllers.inverse`); the averaged
    samples keep each jump's impulse and its centre.

    Parameters
    ----------
    profile : Profile
        The setpoint.
    t : array_like
        Times [s].
    step : float, optional
        The run's time step [s] (None: the derivatives at `t`).

    Examples
    --------
    >>> from motionhyst.scan.profiles import scan
    >>> p = scan(0.01, 0.1, 10.0, 1000.0, 2e5)
    >>> jump = p.durations[0]                          # the snap switches off here
    >>> float(setpoint_samples(p, [jump], step=1e-4)[4, 0]) / 2e5   # half on, half off
    0.5
    """
    t = np.asarray(t, dtype=float)
    d = profile.derivatives(t)
    if step is None:
        return d
    ahead, behind = profile.derivatives(t + step), profile.derivatives(t - step)
    d[1:] = (ahead[:4] - behind[:4]) / (2.0 * step)
    return d


@dataclass(frozen=True)
class FeedforwardTerms:
    """The coefficients of the model feedforward's terms (module docstring).

    Parameters
    ----------
    base_mass : float
        ``M0`` [kg]: the acceleration term the loop applies itself.
    coefficients : dict
        ``mass`` and the terms switched on (``jerk``, ``snap``, ``viscous``,
        ``coulomb``) by name, in the units of :data:`UNITS`.
    link : Hysteresis, optional
        The link model ``phi_hat`` at scale 1 (None: no hysteresis term).
    link_scales : dict, optional
        ``theta`` of each of the link's parameters (default 1).

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> terms = FeedforwardTerms(22.5, {"mass": 22.5, "snap": 1.18e-6}, Jenkins(20.0, 0.05))
    >>> terms.names()
    ['mass', 'snap', 'link k', 'link fc']
    >>> terms.values()
    {'mass': 22.5, 'snap': 1.18e-06, 'link k': 20.0, 'link fc': 0.05}
    """

    base_mass: float
    coefficients: dict[str, float]
    link: Hysteresis | None = None
    link_scales: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = set(self.coefficients) - set(UNITS)
        if unknown or "mass" not in self.coefficients:
            raise ValueError(f"the coefficients are mass and some of {', '.join(UNITS)}; "
                             f"got {sorted(self.coefficients)}")
        if self.link is not None:
            if not self.link.rate_independent:
                raise ValueError(f"the scan's feedforward terms take a rate-independent link "
                                 f"model, not {self.link.name}")
            scales = {p.name: float(self.link_scales.get(p.name, 1.0))
                      for p in self.link.parameters}
            object.__setattr__(self, "link_scales", scales)

    # ------------------------------------------------------------ coefficients
    def names(self) -> list[str]:
        """The coefficients' names in the learning's order (link parameters as ``link NAME``)."""
        return [*self.coefficients, *(f"link {p}" for p in self.link_scales)]

    def vector(self) -> NDArray[np.float64]:
        """The coefficients in :meth:`names`' order, the link's as scales."""
        return np.array([*self.coefficients.values(), *self.link_scales.values()])

    def with_vector(self, theta) -> FeedforwardTerms:
        """These terms with the coefficients `theta` (in :meth:`names`' order).

        Parameters
        ----------
        theta : array_like
            Coefficients, the link's as scales of the model's values.
        """
        theta = [float(x) for x in np.ravel(theta)]
        n = len(self.coefficients)
        return replace(self, coefficients=dict(zip(self.coefficients, theta[:n], strict=True)),
                       link_scales=dict(zip(self.link_scales, theta[n:], strict=True)))

    def scaled_link(self, scales: dict[str, float] | None = None) -> Hysteresis | None:
        """The link model with its parameters scaled (by :attr:`link_scales` by default).

        Parameters
        ----------
        scales : dict, optional
            Scale of each parameter.
        """
        if self.link is None:
            return None
        scales = self.link_scales if scales is None else scales
        base = getattr(self.link, "base", self.link)  # a link along the stroke: its base
        d = base.to_dict()
        kw = {}
        for p in base.parameters:
            v = d[p.name]
            kw[p.name] = ([x * scales[p.name] for x in v] if isinstance(v, list)
                          else v * scales[p.name])
        scaled = type(base)(**kw)
        return self.link.with_base(scaled) if base is not self.link else scaled

    def values(self) -> dict[str, float | list[float]]:
        """The coefficients by name, the link's parameters as values (lists: a parallel model)."""
        out: dict = dict(self.coefficients)
        link = self.scaled_link()
        if link is not None:
            d = getattr(link, "base", link).to_dict()
            out.update({f"link {p}": d[p] for p in self.link_scales})
        return out

    # ------------------------------------------------------------------ force
    def force(self, derivatives: NDArray[np.float64]) -> NDArray[np.float64]:
        """The terms' force [N] for the setpoint's derivatives ``(r, r', r'', r''', r'''')``.

        Parameters
        ----------
        derivatives : ndarray
            Shape ``(5, n)``, as :meth:`motionhyst.scan.profiles.Profile.derivatives`.
        """
        return self._linear_columns(derivatives) @ self._linear_vector() + self._link_force(
            derivatives[0], self.link_scales)

    def force_function(self, profile, advance: float = 0.0, step: float | None = None):
        """The force as a function of time for `profile` (``force(t) -> array``).

        Parameters
        ----------
        profile : Profile
            The setpoint.
        advance : float
            Read the setpoint this much ahead [s] (a sampled controller's advance).
        step : float, optional
            The time step of a continuous run: the linear terms averaged over
            ``t +- step`` (:func:`setpoint_samples`).
        """
        def force(t):
            return self.force(setpoint_samples(profile, np.asarray(t, dtype=float) + advance,
                                               step))

        return force

    def jacobian(self, derivatives: NDArray[np.float64]) -> NDArray[np.float64]:
        """The force's derivatives in the coefficients, shape ``(n, len(names()))``.

        Parameters
        ----------
        derivatives : ndarray
            Shape ``(5, n)``: the setpoint's derivatives at the samples.
        """
        cols = [self._linear_columns(derivatives)]
        r = derivatives[0]
        for name, s in self.link_scales.items():
            h = LINK_STEP * max(abs(s), 1e-3)
            up = {**self.link_scales, name: s + h}
            down = {**self.link_scales, name: s - h}
            cols.append(((self._link_force(r, up) - self._link_force(r, down)) / (2 * h))[:, None])
        return np.hstack(cols)

    def _linear_vector(self) -> NDArray[np.float64]:
        c = dict(self.coefficients)
        c["mass"] = c["mass"] - self.base_mass
        return np.array(list(c.values()))

    def _linear_columns(self, d: NDArray[np.float64]) -> NDArray[np.float64]:
        v = d[1]
        signal = {"mass": d[2], "jerk": d[3], "snap": d[4], "viscous": v,
                  "coulomb": np.where(np.abs(v) <= STANDSTILL, 0.0, np.sign(v))}
        return np.column_stack([signal[name] for name in self.coefficients])

    def _link_force(self, r, scales) -> NDArray[np.float64]:
        link = self.scaled_link(scales)
        return np.zeros(np.shape(r)) if link is None else link.response(np.asarray(r, float))

    def to_dict(self) -> dict:
        """The coefficients by name (JSON keys spelled here), with their units."""
        units = dict(UNITS)
        if self.link is not None:
            units.update({f"link {p.name}": p.unit for p in self.link.parameters})
        values = self.values()
        return {"coefficients": values, "units": {k: units[k] for k in values},
                **({"link_model": self.link.name} if self.link is not None else {})}


def scan_terms(loop, unset: tuple[str, ...] | list[str] = ()) -> list[str]:
    """The terms a scan's model feedforward runs unless told (``motionhyst scan`` without
    ``--feedforward``): those of the loop's feedforward and, if it has any, the stage's jerk
    and snap of `unset` (the scenario's ``[feedforward]`` leaves them unset) where the
    plant's inverse has a series.

    Parameters
    ----------
    loop : Loop
        The loop.
    unset : sequence of {"jerk", "snap"}
        The stage terms the scenario leaves unset (``jerk`` and ``snap`` absent from its
        ``[feedforward]``).

    Examples
    --------
    >>> from motionhyst import Scenario
    >>> from motionhyst.scenario import default_scenario_path
    >>> import tomllib
    >>> d = tomllib.loads(default_scenario_path().read_text())
    >>> d["feedforward"] = {"hysteresis": {"model": "jenkins", "k": 20.8, "fc": 0.052}}
    >>> scan_terms(Scenario.from_dict(d).loop(), ["jerk", "snap"])
    ['jerk', 'snap', 'hysteresis']
    >>> scan_terms(Scenario.from_dict(d).loop())
    ['hysteresis']
    """
    ff = loop.ff
    terms = [t for t in TERMS[:-1] if ff is not None and getattr(ff, t)]
    terms += ["hysteresis"] if loop.hysteresis_feedforward is not None else []
    if not terms or not unset:  # a model feedforward inverts the stage too, unless told how
        return terms
    from motionhyst.controllers.inverse import stage_inverse

    try:
        stage_inverse(loop.plant)
    except (ValueError, TypeError, AttributeError, NotImplementedError):
        return terms
    return [*[t for t in ("jerk", "snap") if t in unset], *terms]


def model_terms(loop, names=None) -> FeedforwardTerms:
    """The model feedforward's terms of `loop` (its ``[feedforward]``), or the terms `names`.

    Parameters
    ----------
    loop : Loop
        The loop: its feedforward's mass, jerk, snap, viscous and Coulomb
        coefficients and its hysteresis feedforward.
    names : sequence of str, optional
        The terms to switch on, of :data:`TERMS` (default: those the loop's
        feedforward has).  A jerk or snap term the loop's feedforward does not
        give takes the plant's (:func:`~motionhyst.controllers.inverse.stage_inverse`);
        a viscous or Coulomb term it does not give starts at 0.

    Returns
    -------
    FeedforwardTerms

    Raises
    ------
    ValueError
        For an unknown term, ``hysteresis`` without a hysteresis feedforward, or a
        plant without an inverse series.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> terms = model_terms(default_scenario().loop(), ["snap"])
    >>> print(f"{terms.coefficients['snap']:.4g}")                   # m1 m2 / k
    1.182e-06
    """
    ff = loop.ff  # without one the acceleration term starts at 0 (and the loop applies none)
    mass = 0.0 if ff is None else (loop.M if ff.mass is None else ff.mass)
    have = {k: getattr(ff, k, 0.0) if ff is not None else 0.0
            for k in ("jerk", "snap", "viscous", "coulomb")}
    if names is None:
        names = [k for k, v in have.items() if v]
        if loop.hysteresis_feedforward is not None:
            names.append("hysteresis")
    names = list(names)
    unknown = [n for n in names if n not in TERMS]
    if unknown:
        raise ValueError(f"unknown feedforward term {unknown[0]!r}; use {', '.join(TERMS)}")
    coefficients = {"mass": float(mass)}
    inverse = None
    for name in ("jerk", "snap", "viscous", "coulomb"):
        if name not in names:
            continue
        value = have[name]
        if not value and name in ("jerk", "snap"):
            if inverse is None:
                from motionhyst.controllers.inverse import stage_inverse

                inverse = stage_inverse(loop.plant)
            value = getattr(inverse, name)
        coefficients[name] = float(value)
    link = None
    if "hysteresis" in names:
        link = loop.hysteresis_feedforward
        if link is None:
            raise ValueError("the hysteresis term needs a hysteresis feedforward model "
                             "(a scenario's [feedforward] hysteresis)")
    return FeedforwardTerms(0.0 if ff is None else float(loop.M), coefficients, link)
