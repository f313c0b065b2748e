"""Whether input-output records describe one stage in SI units, judged before the search.

The records' inverse-dynamics estimate (:func:`~motionhyst.identify.io_start.inverse_dynamics`,
linear in its parameters, a fraction of a second) gives the mass a fit would end at: a mass
far outside a motion stage's betrays a unit (:func:`mass_units_note`), and a record that
shows no inertia beside records that do is of another system (:func:`check_one_stage`).
Both are said before a search of minutes, not after it.
"""

from __future__ import annotations

import math

from motionhyst.identify.io_checks import check_inertia, linear_mass_std
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_start import inverse_dynamics

__all__ = ["ONE_STAGE_SIGMAS", "check_one_stage", "mass_units_note"]

ONE_STAGE_SIGMAS = 5.0
"""A record without inertia of its own whose mass lies more than this many robust standard
errors from the other records' is not of their stage (:func:`check_one_stage`; a link's
force-displacement record beside a stage's: 7.4)."""


def check_one_stage(records: list[IORecord], floating: bool) -> None:
    """Refuse records that cannot describe one stage, before the search: one that shows no
    inertia on its own (:func:`~motionhyst.identify.io_checks.check_inertia`; a link's
    force-displacement record given with a stage's) and whose inverse-dynamics mass, in the
    model of the plant fitted (a spring to the ground unless `floating`), lies more than
    :data:`ONE_STAGE_SIGMAS` robust standard errors from the mass the others show together.
    A slow record of the same stage, its inertia hidden in its friction, agrees with theirs
    within its larger error.  Their joint fit would search for minutes a stage that is
    neither (a stage's record and a link's: over 120 s, to the work budget).

    Parameters
    ----------
    records : list of IORecord
        The records (nothing is checked for one).
    floating : bool
        The plant fitted has no spring to the ground (mass-damper, two-mass).

    Raises
    ------
    ValueError
        One line: the record, its mass and the others', and what identifies a link's record.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    >>> v = np.gradient(y, t)
    >>> stage = IORecord(t, 2.0 * np.gradient(v, t) + 30.0 * v, y, "stage.csv")
    >>> link = IORecord(t, 400.0 * y + 5.0 * v, y, "link.csv")   # no mass: a damped spring
    >>> check_one_stage([stage, stage], floating=True)
    >>> try:
    ...     check_one_stage([stage, link], floating=True)
    ... except ValueError as exc:
    ...     print(str(exc)[:58])
    link.csv: no inertia in the force (its inverse-dynamics ma
    """
    if len(records) < 2:
        return
    for i, rec in enumerate(records):
        try:
            check_inertia([rec])
            continue  # it shows a mass of its own
        except ValueError:
            pass
        rest = records[:i] + records[i + 1:]
        m, std = inverse_dynamics([rec], floating)["m"], linear_mass_std([rec], floating)
        m_rest = inverse_dynamics(rest, floating)["m"]
        std_rest = linear_mass_std(rest, floating)
        if abs(m - m_rest) > ONE_STAGE_SIGMAS * math.hypot(std, std_rest):
            names = (f"{rest[0].name} shows" if len(rest) == 1
                     else f"{rest[0].name} and the others show")
            raise ValueError(f"{rec.name}: no inertia in the force (its inverse-dynamics mass "
                             f"{m:.3g} +- {std:.2g} kg), while {names} {m_rest:.3g} +- "
                             f"{std_rest:.2g} kg: the records cannot describe one stage; a "
                             f"link's force against an imposed displacement is identified on "
                             f"its own, without --record input-output")


def mass_units_note(records: list[IORecord], mass: float) -> str | None:
    """A warning, before the search, where the records' inverse-dynamics `mass`
    (:func:`~motionhyst.identify.io_checks.check_inertia`) lies outside the usual masses of
    motion stages (:data:`~motionhyst.plants.registry.PLAUSIBLE_MASS_KG`): the unit its
    factor points to, a time column in ms first (it makes the mass 1e6 times too large, and
    the records' sampling rate a thousandth of a stage's).  The fit would end at that mass
    after its search; the warning says so before it.

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
    """
    from motionhyst.plants.registry import PLAUSIBLE_MASS_KG

    low, high = PLAUSIBLE_MASS_KG
    if low <= mass <= high:
        return None
    names = records[0].name if len(records) == 1 else f"{records[0].name} and the others"
    text = (f"{names}: the records' inverse-dynamics mass is {mass:.3g} kg, outside the usual "
            f"{low:g}-{high:g} kg of motion stages: ")
    fs = records[0].fs
    for factor, unit, scale in ((1e-6, "is the time column in ms", "time=0.001"),
                                (1e-3, "is the force in mN", "force=0.001"),
                                (1e3, "is the position in mm or the force in kN",
                                 "displacement=0.001 or force=1000"),
                                (1e6, "is the position in um", "displacement=1e-6")):
        if low <= mass * factor <= high:
            at = f" (sampled at {fs:.3g} Hz)" if factor == 1e-6 else ""
            return f"{text}{unit}{at}? --scale {scale} makes it {mass * factor:.3g} kg"
    return (f"{text}if the records' units are not SI, scale them (--scale; time in ms makes "
            f"the mass 1e6 times too large, a position in mm or a force in kN 1e3 times too "
            f"small)")
