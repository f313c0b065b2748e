"""Whether input-output records describe one stage in SI units, judged before the search.

The records' inverse-dynamics estimate (:func:`~motionhyst.identify.io_start.inverse_dynamics`,
linear in its parameters, a fraction of a second) gives the mass a fit would end at: a mass
far outside a motion stage's betrays a unit (:func:`mass_units_note`), and a record that
shows no inertia beside records that do is of another system (:func:`check_one_stage`).
Both are said before a search of minutes, not after it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.io_checks import check_inertia, robust_least_squares
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_start import LINEAR_MODEL_RESIDUAL, equation_rows
from motionhyst.identify.io_uncertainty import white_noise_variance

__all__ = ["ONE_STAGE_RATIO", "ONE_STAGE_SIGMAS", "SI_READINGS", "check_one_stage",
           "mass_units_note"]

ONE_STAGE_SIGMAS = 5.0
"""A record whose mass lies more than this many robust standard errors from the other records'
is not of their stage (:func:`check_one_stage`; a link's force-displacement record beside a
stage's: 102 of them on a mass-damper, 73 on a spring)."""

ONE_STAGE_RATIO = 4.0
"""A record that shows a mass of its own is of another stage only where that mass and the
other records' differ by more than this factor too (:func:`check_one_stage`): a linear model's
mass errs with the record (EMPS's windows of 1000-12000 samples: within 3 %, up to 3.7
standard errors; generated axes' slow, noisy or small records, their link stuck: up to a
factor 3.3, 7 standard errors)."""

OWN_MASS_WINDOWS = 20
"""A record's own mass is judged (:func:`check_one_stage`) only where it holds at least this
many of its Newey-West lags (``max(4 n^(1/3), 10 ms)``; 716 samples at 1 kHz): a shorter
one's standard error is no measure of its linear model's error (80 samples of a 2 kg axis:
0.45 +- 0.2 kg)."""

ACCELERATION_NOISE = 0.1
"""A record's own mass is judged (:func:`check_one_stage`) only where its position's white
noise makes at most this share of its acceleration's variance: noise in a regressor draws
its coefficient towards zero (a slow record's mass 0.014 kg for 2 kg)."""


def _linear_fit(records: list[IORecord], floating: bool
                ) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float]:
    """:func:`~motionhyst.identify.io_start.inverse_dynamics`'s coefficients (``m, c``, ``fc``
    or ``k``, ``u0``), their robust covariance
    (:func:`~motionhyst.identify.io_checks.robust_least_squares`), the records' squared
    angular frequency ``-sum(y'' y) / sum(y^2)`` (``y`` about its mean) [rad^2/s^2] and
    the share of their acceleration their position's noise makes
    (:func:`_acceleration_noise`)."""
    rows, rhs = equation_rows(records, floating)
    x, cov = robust_least_squares(rows, rhs, max(7, 2 * round(0.005 * records[0].fs) + 1))
    acc = np.concatenate([r[:, 0] for r in rows])
    y = np.concatenate([rec.y - np.mean(rec.y) for rec in records])
    yy = float(np.dot(y, y))
    return (x, cov, float(-np.dot(acc, y)) / yy if yy > 0 else 0.0,
            _acceleration_noise(records, acc))


def _shows_a_mass(record: IORecord) -> bool:
    try:
        check_inertia([record])
    except ValueError:
        return False
    return True


def check_one_stage(records: list[IORecord], floating: bool, single_mass: bool = True) -> None:
    """Refuse records that cannot describe one stage, before the search.

    Each record's inverse-dynamics mass, in the model of the plant fitted (a spring to the
    ground unless `floating`), is compared with the mass the other records show together.  A
    record that shows no inertia on its own
    (:func:`~motionhyst.identify.io_checks.check_inertia`; a link's force-displacement
    record given with a stage's) is refused where its mass lies more than
    :data:`ONE_STAGE_SIGMAS` robust standard errors from theirs; on a spring its mass is
    taken with the others' spring (at one frequency a mass is a negative spring: alone, a
    link's record shows -1.2 +- 0.99 kg beside a stage's 1.9 +- 0.048, with the stage's
    spring -0.11 +- 0.0024 kg).  A slow record of the same stage, its inertia hidden in its
    friction, agrees with theirs within its larger error, less what its position's noise
    takes from its mass (by the share of its acceleration that noise makes: a 0.5 Hz record
    of 20 s with 1 um of noise shows 1.33 +- 0.11 kg beside 1.93, 5.4 errors below, not
    refused).  A record that shows a mass of its own (with a single-mass stage,
    `single_mass`) is refused where its mass and the others' differ by more than
    :data:`ONE_STAGE_SIGMAS` standard errors and by more than the factor
    :data:`ONE_STAGE_RATIO`, each mass in a model that takes any stage's force and only
    where the record determines it (records of a 2 kg and a 20 kg stage: a joint mass of
    10.7 kg).  Their joint fit would search for minutes a stage that is neither (a stage's
    record and a link's: over 120 s, to the work budget).

    Parameters
    ----------
    records : list of IORecord
        The records (nothing is checked for one).
    floating : bool
        The plant fitted has no spring to the ground (mass-damper, two-mass).
    single_mass : bool
        The plant fitted has one mass (a two-mass stage's records are judged only where one
        shows no inertia: their single mass is no model of them).

    Raises
    ------
    ValueError
        One line: the record, its mass and the others', and what identifies a link's record
        or why the records are of two stages.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    >>> v = np.gradient(y, t)
    >>> stage = IORecord(t, 2.0 * np.gradient(v, t) + 30.0 * v, y, "stage.csv")
    >>> link = IORecord(t, 400.0 * y + 5.0 * v, y, "link.csv")   # no mass: a damped spring
    >>> heavy = IORecord(t, 20.0 * np.gradient(v, t) + 30.0 * v, y, "heavy.csv")
    >>> check_one_stage([stage, stage], floating=True)
    >>> for other in (link, heavy):
    ...     try:
    ...         check_one_stage([stage, other], floating=True)
    ...     except ValueError as exc:
    ...         print(str(exc)[:42])
    link.csv: no inertia in the force (its inv
    stage.csv: an inverse-dynamics mass of 2.0
    """
    if len(records) < 2:
        return
    own = [_shows_a_mass(rec) for rec in records]
    for i, rec in enumerate(records):  # a record without inertia first: its message says why
        rest = records[:i] + records[i + 1:]
        if own[i] or not any(own[:i] + own[i + 1:]):  # none shows a mass to compare with
            continue
        x, cov, w2, noise = _linear_fit([rec], floating)
        x_rest, cov_rest, _, _ = _linear_fit(rest, floating)
        gradient, spring = np.array([1.0, 0.0, 0.0, 0.0]), ""
        if not floating and w2 > 0:  # at its frequencies a mass is a negative spring
            gradient, spring = np.array([1.0, 0.0, -1.0 / w2, 0.0]), " with the others' spring"
        m = float(gradient @ x + x_rest[0] - gradient @ x_rest)  # m + (k_rest - k) / w2
        m_rest = float(x_rest[0])
        if m_rest <= 0:  # the others' inertia is not this model's mass: nothing to compare
            continue
        std = math.sqrt(max(float(gradient @ cov @ gradient), 0.0))
        std_rest = math.sqrt(max(float(gradient @ cov_rest @ gradient), 0.0))
        # the position's noise draws the record's mass towards zero: so far is no gap
        gap = m - m_rest if m > m_rest else min(0.0, m - (1.0 - noise) * m_rest)
        if abs(gap) > ONE_STAGE_SIGMAS * math.hypot(std, std_rest):
            raise ValueError(f"{rec.name}: no inertia in the force (its inverse-dynamics mass"
                             f"{spring} {m:.3g} +- {std:.2g} kg), while {_names(rest)} "
                             f"{m_rest:.3g} +- {std_rest:.2g} kg: the records cannot describe "
                             f"one stage; a link's force against an imposed displacement is "
                             f"identified on its own, without --record input-output")
    if not single_mass:
        return
    judged = [_own_mass([rec]) for rec in records]  # (mass, std) where a record shows it
    for i, rec in enumerate(records):
        rest = records[:i] + records[i + 1:]
        if judged[i] is None or any(j is None for j in judged[:i] + judged[i + 1:]):
            continue
        together = _own_mass(rest)
        if together is None:
            continue
        (m, std), (m_rest, std_rest) = judged[i], together
        if (m > 0 and m_rest > 0 and max(m / m_rest, m_rest / m) > ONE_STAGE_RATIO
                and abs(m - m_rest) > ONE_STAGE_SIGMAS * math.hypot(std, std_rest)):
            joint = float(_linear_fit(records, floating)[0][0])
            raise ValueError(f"{rec.name}: an inverse-dynamics mass of {m:.3g} +- {std:.2g} "
                             f"kg, while {_names(rest)} {m_rest:.3g} +- {std_rest:.2g} kg: "
                             f"records of stages of different masses (together {joint:.3g} kg, "
                             f"neither's); identify each stage from its own records")


def _own_mass(records: list[IORecord]) -> tuple[float, float] | None:
    """The records' inverse-dynamics mass and its robust standard error in the model that
    takes any stage's force (:func:`~motionhyst.identify.io_checks.check_inertia`'s: viscous
    and Coulomb friction, a spring), or None where they do not determine it: the linear model
    leaves more than :data:`~motionhyst.identify.io_start.LINEAR_MODEL_RESIDUAL` of the force
    (a link that carries it), the position's white noise makes more than
    :data:`ACCELERATION_NOISE` of the acceleration's variance (the mass then errs low), or a
    record is shorter than :data:`OWN_MASS_WINDOWS` of its Newey-West lags."""
    window = max(7, 2 * round(0.005 * records[0].fs) + 1)
    if any(rec.y.size < OWN_MASS_WINDOWS * max(int(4 * rec.y.size ** (1 / 3)), window)
           for rec in records):
        return None
    rows, rhs = equation_rows(records, floating=True)
    rows = [np.column_stack([r, rec.y]) for r, rec in zip(rows, records, strict=True)]
    x, cov = robust_least_squares(rows, rhs, window)
    A, u = np.concatenate(rows), np.concatenate(rhs)
    spread = float(np.linalg.norm(u - np.mean(u)))
    if not (spread > 0 and float(np.linalg.norm(A @ x - u)) <= LINEAR_MODEL_RESIDUAL * spread):
        return None
    if not _acceleration_noise(records, A[:, 0]) <= ACCELERATION_NOISE:
        return None
    return float(x[0]), math.sqrt(max(float(cov[0, 0]), 0.0))


def _acceleration_noise(records: list[IORecord], acc: NDArray[np.float64]) -> float:
    """The share of the records' filtered acceleration `acc` (all records' samples, in
    order) that their position's white noise makes (from its third differences, through
    each record's Savitzky-Golay filter, as :func:`~motionhyst.identify.io_start.equation_rows`
    has it); 1 at most.  A regressor's noise draws its coefficient towards zero by about
    this share."""
    from scipy.signal import savgol_coeffs

    noise = 0.0
    for rec in records:
        samples = min(max(7, 2 * round(0.005 * rec.fs) + 1), rec.y.size - (1 - rec.y.size % 2))
        gain = float(np.sum(savgol_coeffs(samples, 3, deriv=2, delta=1.0 / rec.fs) ** 2))
        noise += rec.y.size * gain * white_noise_variance(rec.y, robust=False)
    total = float(np.sum((acc - np.mean(acc)) ** 2))
    return min(1.0, noise / total) if total > 0 else 1.0


def _names(rest: list[IORecord]) -> str:
    return f"{rest[0].name} shows" if len(rest) == 1 else f"{rest[0].name} and the others show"


SI_READINGS = {"rate": 100.0, "stroke": 1.0, "force": (1e-3, 1e4)}
"""What makes a unit slip likely (:func:`mass_units_note`), beside the mass: a sampling rate
below ``rate`` [Hz] (a time column in ms), a position's range above ``stroke`` [m] (in mm or
um), a force's peak outside ``force`` [N] (in kN below, in mN above)."""


def mass_units_note(records: list[IORecord], mass: float) -> str | None:
    """A warning, before the search, where the records' inverse-dynamics `mass`
    (:func:`~motionhyst.identify.io_checks.check_inertia`) lies outside the usual masses of
    motion stages (:data:`~motionhyst.plants.registry.PLAUSIBLE_MASS_KG`).  A unit is named
    only where the records read in SI are unlike a motion stage's as well
    (:data:`SI_READINGS`) and that unit makes the mass usual: a time column in ms first (it
    makes the mass 1e6 times too large, and the sampling rate a thousandth of a stage's),
    a position in mm or um (a range of metres), a force in mN or kN; otherwise the line
    says what each unit would do (a 0.5 g stage sampled at 1 kHz, moving 1 mm under 5 N,
    is no unit slip).  The fit would end at that mass after its search; the warning says
    so before it.

    Parameters
    ----------
    records : list of IORecord
        The records.
    mass : float
        Their inverse-dynamics mass [kg].

    Returns
    -------
    str or None
        One line naming the records, the mass and the likely unit; None for a usual mass.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) * 1.0                          # a 1 kHz record's time in ms
    >>> print(mass_units_note([IORecord(t, np.sin(t), np.cos(t), "io.csv")], 2e6))
    io.csv: the records' inverse-dynamics mass is 2e+06 kg, outside the usual 0.001-10000 kg \
of motion stages: is the time column in ms (sampled at 1 Hz)? --scale time=0.001 makes it \
2 kg
    >>> mass_units_note([IORecord(t / 1e3, np.sin(t), np.cos(t), "io.csv")], 2.0) is None
    True
    >>> print(mass_units_note([IORecord(t / 1e3, np.sin(t), 1e-3 * np.cos(t), "io.csv")],
    ...                       5e-4))                     # a 0.5 g stage: SI readings
    io.csv: the records' inverse-dynamics mass is 0.0005 kg, outside the usual 0.001-10000 kg \
of motion stages: if the records' units are not SI, scale them (--scale; time in ms makes \
the mass 1e6 times too large, a position in mm or a force in kN 1e3 times too small)
    """
    from motionhyst.plants.registry import PLAUSIBLE_MASS_KG

    low, high = PLAUSIBLE_MASS_KG
    if low <= mass <= high:
        return None
    names = records[0].name if len(records) == 1 else f"{records[0].name} and the others"
    text = (f"{names}: the records' inverse-dynamics mass is {mass:.3g} kg, outside the usual "
            f"{low:g}-{high:g} kg of motion stages: ")
    fs = records[0].fs
    stroke = max(float(np.ptp(rec.y)) for rec in records)
    force = max(float(np.max(np.abs(rec.u - np.mean(rec.u)))) for rec in records)
    f_low, f_high = SI_READINGS["force"]
    rate, longest = SI_READINGS["rate"], SI_READINGS["stroke"]
    for factor, unit, scale, unlike in (  # unlike a stage in SI, like one in the unit
            (1e-6, f"is the time column in ms (sampled at {fs:.3g} Hz)", "time=0.001",
             fs < rate <= 1e3 * fs),
            (1e-3, f"is the force in mN (a peak of {force:.3g} N)", "force=0.001",
             force > f_high >= 1e-3 * force),
            (1e3, f"is the position in mm (a range of {stroke:.3g} m)", "displacement=0.001",
             stroke > longest >= 1e-3 * stroke),
            (1e3, f"is the force in kN (a peak of {force:.3g} N)", "force=1000",
             force < f_low <= 1e3 * force),
            (1e6, f"is the position in um (a range of {stroke:.3g} m)", "displacement=1e-6",
             stroke > longest >= 1e-6 * stroke)):
        if unlike and low <= mass * factor <= high:
            return f"{text}{unit}? --scale {scale} makes it {mass * factor:.3g} kg"
    return (f"{text}if the records' units are not SI, scale them (--scale; time in ms makes "
            f"the mass 1e6 times too large, a position in mm or a force in kN 1e3 times too "
            f"small)")
