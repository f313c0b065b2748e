"""Records on which the fitted link slips one way only: its slip force and the force offset.

A friction link that slips in one direction only over every record (a stop-and-go axis: the
velocity never reverses) holds its slip force ``fc`` there, a constant force on the stage like
the force offset ``input_offset`` (the stage receives ``u - input_offset``): the output sees
``input_offset + fc`` (forward; ``input_offset - fc`` backward) and nothing else of the two.
Where the link would slip back (``u - input_offset < -fc`` while it sticks) the records do not
go: they bound ``fc`` from below and leave it open above.

The question is answered by the fitted model itself, which is exact, not by the measured
positions (a back move below their noise may be a slip that separates the two, and one above it
the elastic unloading of a link that never slips back), in two ways, either enough
(:func:`one_way_slip`): its sliders, run on its own simulated positions (:func:`slider_slips`),
never slip back; or its slip forces doubled and the force offset moved by as much the other way
(a Dahl link's stiffness so that its force curve moves with them), each record's initial state
refitted, fit the records as well as the fit (a residual sum of squares larger by less than
:data:`ONE_WAY_CHI2` residual variances: inside the 95 % likelihood region of one parameter).
Jacobian-based standard errors do not see it: the search ends where the link is about to slip
back, a kink, and their differences there report both to a few tenths of a per cent (a
stop-and-go axis: fc 5.007 +- 0.019 N, offset 11.993 +- 0.017 N for a true 20 and -3).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.hysteresis import Jenkins, MaxwellSlip

__all__ = ["NEVER_SLIPS", "ONE_WAY_CHI2", "REFIT_CAP", "OneWay", "one_way_slip", "slider_slips"]

#: The 95 % point of the chi-square distribution with one degree of freedom: a model whose
#: residual sum of squares exceeds the fit's by less than this many residual variances fits
#: the records as well
ONE_WAY_CHI2 = 3.841

#: A slider's slip the other way up to this share of its slip one way is round-off: it never
#: slips back
NEVER_SLIPS = 1e-9

#: A shifted model (:func:`one_way_slip`) that costs more than this many residual variances
#: has its initial states refitted only up to here: beyond, no initial state makes it up (the
#: stop-and-go Jenkins fit's shift costs 9.4e3 before its initial velocity is refitted, two-way
#: records' 2.5e5 to 4.7e7 and more)
REFIT_CAP = 1e5


@dataclass
class OneWay:
    """A fit whose link slips one way only (:func:`one_way_slip`).

    Attributes
    ----------
    direction : int
        ``+1`` (it slips forward only) or ``-1`` (backward only).
    names : list of str
        The slip forces and ``input_offset`` (last): not determined one by one.
    combination : str
        What the records determine, ``"input_offset + link.fc"`` (or ``-``).
    value : float
        Its value [N].
    std : float or None
        Its standard error [N] (None where the covariance does not give one).
    line : str
        The warning.
    note : str
        The note on each of `names` (why it has no standard error).

    Examples
    --------
    >>> found = OneWay(1, ["link.fc", "input_offset"], "input_offset + link.fc", 17.0, 0.0025,
    ...                "the fitted link slips forward only ...", "not determined ...")
    >>> found.to_dict()["direction"], found.to_dict()["value"]
    ('forward', 17.0)
    """

    direction: int
    names: list[str]
    combination: str
    value: float
    std: float | None
    line: str
    note: str

    def to_dict(self) -> dict:
        """The JSON form: direction, parameters, and the combination with its value and
        standard error."""
        return {"direction": "forward" if self.direction > 0 else "backward",
                "parameters": list(self.names), "combination": self.combination,
                "value": self.value, "std": self.std}


def slider_slips(link, positions: list[NDArray[np.float64]]) -> tuple[float, float]:
    """The largest slips back and forward [m] of the link's sliders over records whose link
    moves with `positions` (the fitted model's simulated ones, from a relaxed link).

    A Jenkins link's slider, or each Maxwell-slip element's, follows the position through
    its play ``fc / k`` (its spring takes the rest: elastic unloading is no slip); any other
    link slips with the position itself (the Coulomb link's rigid slider; a Dahl or LuGre
    link's force turns with the velocity).

    Parameters
    ----------
    link : Hysteresis
        The fitted link.
    positions : list of ndarray
        Each record's simulated position of the link's input [m].

    Returns
    -------
    (float, float)
        The largest fall of any slider from its running maximum, and the largest rise from
        its running minimum, over every record.

    Examples
    --------
    >>> from motionhyst.hysteresis import Coulomb, Jenkins
    >>> x = np.array([0.0, 1.0, 0.9, 2.0])          # back by 0.1, within the play of 0.5
    >>> slider_slips(Jenkins(k=10.0, fc=5.0), [x]), slider_slips(Coulomb(fc=5.0), [x])
    ((0.0, 1.5), (0.1, 2.0))
    """
    plays = np.atleast_1d(np.asarray(link.fc, dtype=float) / np.asarray(link.k, dtype=float)) \
        if isinstance(link, Jenkins | MaxwellSlip) else np.zeros(1)
    back = ahead = 0.0
    for x in positions:
        x = np.asarray(x, dtype=float)
        for play in plays:
            z = x if play == 0.0 else np.empty_like(x)  # a rigid slider: the position
            zi = x[0] if x.size else 0.0  # relaxed at the first sample
            for i, xi in enumerate(x if play > 0.0 else ()):
                zi = min(max(zi, xi - play), xi + play)
                z[i] = zi
            if z.size:
                back = max(back, float(np.max(np.maximum.accumulate(z) - z)))
                ahead = max(ahead, float(np.max(z - np.minimum.accumulate(z))))
    return back, ahead


def _states_refitted(names: list[str], w: NDArray[np.float64],
                     errors_at: Callable[[NDArray[np.float64]], NDArray[np.float64]]
                     ) -> NDArray[np.float64]:
    """`w` with each record's initial state and position offset (``v0``, ``y0``,
    ``output_offset``) refitted to the records (a few evaluations)."""
    from scipy.optimize import least_squares

    free = [i for i, n in enumerate(names) if n.split("[")[0] in ("v0", "y0", "output_offset")]
    if not free:
        return w
    size = float(np.sqrt(np.mean(errors_at(w) ** 2))) or 1.0  # errors of order 1: the
    # solver's tolerances are relative to them

    def errors(x: NDArray[np.float64]) -> NDArray[np.float64]:
        u = w.copy()
        u[free] = x
        return errors_at(u) / size

    sol = least_squares(errors, w[free], x_scale="jac", max_nfev=10 * (len(free) + 1))
    out = w.copy()
    out[free] = sol.x
    return out


def _slip_forces(names: list[str]) -> list[int]:
    """Indices of the link's slip forces (``link.fc``, ``link.fc[i]``) among `names`."""
    return [i for i, n in enumerate(names) if n == "link.fc" or n.startswith("link.fc[")]


def _shifted(names: list[str], v: NDArray[np.float64], direction: int, link: str
             ) -> NDArray[np.float64]:
    """The values with every slip force doubled and the force offset moved by their sum the
    other way (``input_offset - direction * sum fc``); a Dahl link's stiffness ``k`` times
    ``2^alpha``, which moves its force curve with its slip force."""
    w = np.array(v, dtype=float)
    forces = _slip_forces(names)
    w[forces] *= 2.0
    w[names.index("input_offset")] -= direction * float(np.sum(v[forces]))
    if link == "dahl" and "link.k" in names and "link.alpha" in names:
        w[names.index("link.k")] *= 2.0 ** float(v[names.index("link.alpha")])
    return w


def one_way_slip(names: list[str], v: NDArray[np.float64], rss: float, n_rows: int,
                 errors_at: Callable[[NDArray[np.float64]], NDArray[np.float64]],
                 cov: NDArray[np.float64] | None = None, link: str = "",
                 slips: tuple[float, float] | None = None) -> OneWay | None:
    """Whether the fitted link slips one way only over the records, so that its slip forces
    and the force offset are one constant force.

    Two ways of the fitted model's own, either enough: its sliders (`slips`,
    :func:`slider_slips`) never slip back (to :data:`NEVER_SLIPS` of their slip forward:
    round-off), or the model with its slip forces doubled and
    the force offset moved by as much fits the records as well as the fit (by
    :data:`ONE_WAY_CHI2`), each record's initial state refitted where that shift costs at
    most :data:`REFIT_CAP` residual variances (a search's free initial velocity makes the
    link slip back at the start, where the slip force then matters).

    Parameters
    ----------
    names : list of str
        The fit's parameters (``m``, ``link.fc``, ``input_offset``, ...).
    v : ndarray
        Their fitted values.
    rss : float
        The fit's residual sum of squares [m^2].
    n_rows : int
        Its residuals.
    errors_at : callable
        The output errors [m] of the model at other values (the fit's own runs: the same
        windows and integration steps); it may raise ``ValueError`` for values the model
        refuses.
    cov : ndarray, optional
        The fit's covariance (`names` by `names`): the standard error of the combination.
    link : str
        The link model's name (``"dahl"``: its stiffness moves with the slip force).
    slips : (float, float), optional
        The fitted model's largest slips back and forward [m] (None: not known, a link that
        moves with a position the records do not measure).

    Returns
    -------
    OneWay or None
        None when the records separate the two, or the fit has no force offset or slip
        force.

    Examples
    --------
    A Coulomb axis that only ever slips forward: its output depends on ``input_offset +
    fc`` alone (here modelled by that dependence).

    >>> names = ["m", "c", "link.fc", "input_offset"]
    >>> v = np.array([95.0, 200.0, 5.0, 12.0])
    >>> def errors_at(w):
    ...     return np.full(1000, 1e-6) + 1e-3 * (w[2] + w[3] - 17.0)
    >>> found = one_way_slip(names, v, float(np.sum(errors_at(v) ** 2)), 1000, errors_at)
    >>> found.direction, found.combination, found.value
    (1, 'input_offset + link.fc', 17.0)
    >>> found.line[:60]
    'the fitted link slips forward only over these records (doubl'
    """
    forces = _slip_forces(names)
    if not forces or "input_offset" not in names or n_rows <= len(names):
        return None
    sigma2 = rss / (n_rows - len(names))
    rms = math.sqrt(rss / n_rows)
    found = None  # (direction, the reason)
    if slips is not None:  # a slider that never slips back: exactly (to round-off)
        back, ahead = slips
        never = NEVER_SLIPS * max(back, ahead)
        if back <= never < ahead or ahead <= never < back:
            direction = 1 if back <= never else -1
            found = (direction, f"its slider never slips {'back' if direction > 0 else 'forward'}")
    for direction in (1, -1) if found is None and sigma2 > 0 else ():
        w = _shifted(names, v, direction, link)
        try:
            grown = float(np.sum(errors_at(w) ** 2)) - rss
            if ONE_WAY_CHI2 * sigma2 < grown <= REFIT_CAP * sigma2:
                w = _states_refitted(names, w, errors_at)
                grown = float(np.sum(errors_at(w) ** 2)) - rss
        except (ValueError, ArithmeticError):
            continue
        if math.isfinite(grown) and grown <= ONE_WAY_CHI2 * sigma2:
            shown = ", ".join(f"{names[i]} {w[i]:.4g} N" for i in forces)
            found = (direction, f"doubling its slip force ({shown}) and moving the force "
                                f"offset by as much (input_offset "
                                f"{w[names.index('input_offset')]:.4g} N) fits them as well "
                                f"(RMS {math.sqrt(max(rss + grown, 0.0) / n_rows):.3g} m, "
                                f"the fit's {rms:.3g} m)")
            break
    if found is None:
        return None
    direction, why = found
    fc_names = [names[i] for i in forces]
    sign = "+" if direction > 0 else "-"
    combination = f"input_offset {sign} " + f" {sign} ".join(fc_names)
    weights = np.zeros(len(names))
    weights[names.index("input_offset")] = 1.0
    weights[forces] = direction
    value = float(weights @ v)
    std = None
    if cov is not None:
        used = weights != 0
        sub = np.asarray(cov, dtype=float)[np.ix_(used, used)]
        var = float(weights[used] @ sub @ weights[used]) if np.all(np.isfinite(sub)) \
            else math.nan
        std = math.sqrt(var) if math.isfinite(var) and var >= 0 else None
    out_names = [*fc_names, "input_offset"]
    way, back_way = ("forward", "back") if direction > 0 else ("backward", "forward")
    total = f"{value:.4g} N" + (f" +- {std:.2g} N" if std is not None else "")
    line = (f"the fitted link slips {way} only over these records ({why}): its slip force "
            f"and the force offset are one constant force, so {', '.join(out_names)} are not "
            f"determined one by one, only {combination} = {total} is (their values are the "
            f"search's; a record in which the axis slips {back_way} as well separates them)")
    note = (f"not determined by these records: the link slips {way} only, where its slip "
            f"force and the force offset are one constant force; only {combination} = "
            f"{total} is")
    return OneWay(direction, out_names, combination, value, std, line, note)
