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

from motionhyst.core.blas import few_blas_threads
from motionhyst.identify.io_checks import check_inertia
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_start import LINEAR_MODEL_RESIDUAL, equation_rows
from motionhyst.identify.residual_noise import (
    bartlett_sum,
    bartlett_weights,
    newey_west_lags,
    white_noise_variance,
)

__all__ = ["CLOSE_STAGE_RATIO", "CLOSE_STAGE_SIGMAS", "ONE_STAGE_RATIO", "ONE_STAGE_SIGMAS",
           "SI_READINGS", "UNIT_FACTORS",
           "UNIT_READINGS", "check_one_stage", "mass_units_note"]

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

CLOSE_STAGE_RATIO = 1.4
CLOSE_STAGE_SIGMAS = 15.0
"""Records whose own masses differ by less than :data:`ONE_STAGE_RATIO` are of different
stages all the same where they differ by more than this factor and this many robust standard
errors (:func:`check_one_stage`): one axis's records, slow, stepped, small or noisy, differ
by up to a factor 3.4 at 7.7 standard errors at most (787 pairs), two stages of 2 and 3-8 kg
by 1.47-3.91 at 21-62 of them."""

OWN_MASS_WINDOWS = 20
"""A record's own mass is judged (:func:`check_one_stage`) only where it holds at least this
many of the fixed rule's Newey-West lags (``max(4 n^(1/3), 10 ms)``; 716 samples at 1 kHz):
a shorter one's standard error is no measure of its linear model's error (80 samples of a 2 kg
axis: 0.45 +- 0.2 kg)."""

ACCELERATION_NOISE = 0.1
"""A record's own mass is judged (:func:`check_one_stage`) only where its position's white
noise makes at most this share of its acceleration's variance: noise in a regressor draws
its coefficient towards zero (a slow record's mass 0.014 kg for 2 kg)."""


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
    10.7 kg); where the masses and one column's readings differ by a factor of
    :data:`UNIT_FACTORS`, the line names that record's unit instead (a record in mm beside
    one in m: 0.00195 kg against 1.99 kg).  Their joint fit would search for minutes a stage
    that is neither (a stage's record and a link's: over 120 s, to the work budget).

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
    with few_blas_threads(max(rec.y.size for rec in records), 5):  # a record's rows at most
        _check_one_stage(records, floating, single_mass)


def _check_one_stage(records: list[IORecord], floating: bool, single_mass: bool) -> None:
    own = [_shows_a_mass(rec) for rec in records]
    if all(own) and not single_mass:
        return
    pieces = [_Pieces(rec) for rec in records]  # any set's fit from sums: linear in records
    total, others = _leave_one_out(pieces)
    columns = [0, 1, 2, 3] if floating else [0, 1, 4, 3]  # a, v, sign(v) or y, 1
    for i, rec in enumerate(records):  # a record without inertia first: its message says why
        rest = records[:i] + records[i + 1:]
        if own[i] or not any(own[:i] + own[i + 1:]):  # none shows a mass to compare with
            continue
        x, covs, _ = pieces[i].fit(columns)
        x_rest, covs_rest, _ = others[i].fit(columns)
        w2, noise = pieces[i].w2, pieces[i].acceleration_noise()
        gradient, spring = np.array([1.0, 0.0, 0.0, 0.0]), ""
        if not floating and w2 > 0:  # at its frequencies a mass is a negative spring
            gradient, spring = np.array([1.0, 0.0, -1.0 / w2, 0.0]), " with the others' spring"
        m = float(gradient @ x + x_rest[0] - gradient @ x_rest)  # m + (k_rest - k) / w2
        m_rest = float(x_rest[0])
        if m_rest <= 0:  # the others' inertia is not this model's mass: nothing to compare
            continue
        std, std_rest = _widest_std(covs, gradient), _widest_std(covs_rest, gradient)
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
    judged = [_own_mass(piece) for piece in pieces]  # (mass, std) where a record shows it
    if any(j is None for j in judged):
        return
    for i, rec in enumerate(records):
        rest = records[:i] + records[i + 1:]
        together = _own_mass(others[i])
        if together is None:
            continue
        (m, std), (m_rest, std_rest) = judged[i], together
        if m <= 0 or m_rest <= 0:
            continue
        ratio, z = max(m / m_rest, m_rest / m), abs(m - m_rest) / math.hypot(std, std_rest)
        if (ratio > ONE_STAGE_RATIO and z > ONE_STAGE_SIGMAS) or (
                ratio > CLOSE_STAGE_RATIO and z > CLOSE_STAGE_SIGMAS):
            slip = _unit_slip(rec, rest, judged[i], together)
            if slip is not None:
                raise ValueError(slip)
            joint = float(total.fit(columns)[0][0])
            raise ValueError(f"{rec.name}: an inverse-dynamics mass of {m:.3g} +- {std:.2g} "
                             f"kg, while {_names(rest)} {m_rest:.3g} +- {std_rest:.2g} kg: "
                             f"records of stages of different masses (together {joint:.3g} kg, "
                             f"neither's); identify each stage from its own records")


def _own_mass(pieces: _Pieces) -> tuple[float, float] | None:
    """The records' inverse-dynamics mass and its robust standard error in the model that
    takes any stage's force (:func:`~motionhyst.identify.io_checks.check_inertia`'s: viscous
    and Coulomb friction, a spring), from their :class:`_Pieces`, or None where they do not
    determine it: the linear model leaves more than
    :data:`~motionhyst.identify.io_start.LINEAR_MODEL_RESIDUAL` of the force (a link that
    carries it), the position's white noise makes more than :data:`ACCELERATION_NOISE` of the
    acceleration's variance (the mass then errs low), or a record is shorter than
    :data:`OWN_MASS_WINDOWS` of its Newey-West lags."""
    if pieces.short:
        return None
    x, covs, residual = pieces.fit([0, 1, 2, 3, 4])
    spread = pieces.bb - pieces.g[3] ** 2 / pieces.n  # the force's squares about its mean
    if not (spread > 0 and residual <= LINEAR_MODEL_RESIDUAL ** 2 * spread):
        return None
    if not pieces.acceleration_noise() <= ACCELERATION_NOISE:
        return None
    return float(x[0]), _widest_std(covs, np.eye(1, len(x))[0])


def _widest_std(covs: list[NDArray[np.float64]], gradient: NDArray[np.float64]) -> float:
    """The standard error of ``gradient @ x``, the largest over the covariances of the lag
    counts (:func:`~motionhyst.identify.residual_noise.newey_west_lags`: never narrower than
    white residuals' or the fixed rule's)."""
    return math.sqrt(max(max(float(gradient @ c @ gradient) for c in covs), 0.0))


class _Pieces:
    """One record's share of the inverse-dynamics least squares that :func:`check_one_stage`
    solves for a set of records: the normal equations of its rows ``a, v, sign(v), 1, y``
    (acceleration, velocity, direction, offset, position; the rates as
    :func:`~motionhyst.identify.io_start.equation_rows` filters them), its Newey-West meats
    as quadratic forms in the coefficients (one for each lag count of
    :func:`~motionhyst.identify.residual_noise.newey_west_lags`, Andrews' from its own fit's
    residuals), its acceleration's white noise (through the
    filter, from the position's third differences) and whether it is long enough to judge
    its own mass (:data:`OWN_MASS_WINDOWS`).  The sum of records' pieces is their set's: the
    others' fit, for each record, needs no pass over their samples (refitted, the check was
    quadratic in the number of records: 40 records of 10,000 samples, 5.1 s of CPU)."""

    def __init__(self, rec: IORecord) -> None:
        from scipy.signal import savgol_coeffs

        rows, rhs = equation_rows([rec], floating=True)
        A, b = np.column_stack([rows[0], rec.y]), np.asarray(rhs[0], dtype=np.float64)
        n, window = b.size, max(7, 2 * round(0.005 * rec.fs) + 1)
        self.H, self.g, self.bb, self.n = A.T @ A, A.T @ b, float(b @ b), n
        scale = np.linalg.norm(A, axis=0)
        scale[scale == 0] = 1.0
        own = b - (A / scale) @ np.linalg.lstsq(A / scale, b, rcond=None)[0]
        self.G = [_meat_products(A, b, lags) for lags in newey_west_lags([own], window)]
        samples = min(window, n - (1 - n % 2))
        gain = float(np.sum(savgol_coeffs(samples, 3, deriv=2, delta=1.0 / rec.fs) ** 2))
        self.noise = n * gain * white_noise_variance(rec.y, robust=False)
        self.short = n < OWN_MASS_WINDOWS * max(int(4 * n ** (1 / 3)), window)
        y = rec.y - np.mean(rec.y)
        yy = float(y @ y)  # the squared angular frequency -sum(y'' y) / sum(y^2) [rad^2/s^2]
        self.w2 = float(-(A[:, 0] @ y)) / yy if yy > 0 else 0.0

    def __add__(self, other: _Pieces) -> _Pieces:
        out = object.__new__(_Pieces)
        for name in ("H", "g", "bb", "n", "noise"):
            setattr(out, name, getattr(self, name) + getattr(other, name))
        out.G = [a + b for a, b in zip(self.G, other.G, strict=True)]  # lag count by count
        out.short, out.w2 = self.short or other.short, math.nan  # w2: one record's only
        return out

    def fit(self, columns: list[int]
            ) -> tuple[NDArray[np.float64], list[NDArray[np.float64]], float]:
        """The least-squares coefficients of `columns` (indices into ``a, v, sign(v), 1,
        y``), their Newey-West covariances (one for each lag count, each record's lags its
        own: :func:`~motionhyst.identify.io_checks.robust_least_squares`' covariance is
        their :func:`~motionhyst.identify.residual_noise.widest_covariance`) and the
        residual's sum of squares."""
        H, g = self.H[np.ix_(columns, columns)], self.g[columns]
        scale = np.sqrt(np.diag(H))
        scale[scale == 0] = 1.0
        inverse = (np.linalg.pinv(H / np.outer(scale, scale), rcond=1e-12)
                   / np.outer(scale, scale))
        x = inverse @ g
        p, q = self.H.shape[0], len(columns)
        flat = np.array([[i * (p + 1) + a for a in (0, *(c + 1 for c in columns))]
                         for i in columns]).ravel()
        z = np.concatenate([[1.0], -x])  # the residual b - A x is [b, A] @ z
        covs = [inverse @ np.einsum("iajb,a,b->ij",
                                    G[np.ix_(flat, flat)].reshape(q, q + 1, q, q + 1), z, z)
                @ inverse for G in self.G]
        residual = self.bb - 2.0 * float(x @ g) + float(x @ H @ x)
        return x, covs, max(residual, 0.0)

    def acceleration_noise(self) -> float:
        """The share of the acceleration's variance that the position's white noise makes
        (1 at most): a regressor's noise draws its coefficient towards zero by about it."""
        total = float(self.H[0, 0] - self.H[0, 3] ** 2 / self.H[3, 3])
        return min(1.0, self.noise / total) if total > 0 else 1.0


def _leave_one_out(pieces: list[_Pieces]) -> tuple[_Pieces, list[_Pieces]]:
    """All records' pieces, and for each record the others', from sums before and after it
    (a difference of sums would lose a record read in other units to round-off)."""
    before, after = [pieces[0]], [pieces[-1]]
    for piece in pieces[1:-1]:
        before.append(before[-1] + piece)
    for piece in pieces[-2:0:-1]:
        after.append(after[-1] + piece)
    after.reverse()  # after[i]: the records from i + 1 on
    k = len(pieces)
    others = [after[0]] + [before[i - 1] + after[i] for i in range(1, k - 1)] + [before[-1]]
    return before[-1] + pieces[-1], others


def _meat_products(A: NDArray[np.float64], b: NDArray[np.float64], lags: int
                   ) -> NDArray[np.float64]:
    """The Newey-West sums (:func:`~motionhyst.identify.residual_noise.bartlett_sum`, as
    :func:`~motionhyst.identify.io_checks.robust_least_squares`) of the products of the
    columns ``A[:, i] [b, A][:, a]``: the meat of the residual ``b - A x`` is their quadratic
    form in ``[1, -x]``, for any ``x``.  The products made a block of samples at a time (a
    few MB, whatever the record's length)."""
    p = A.shape[1]
    # A_i b, and A_i A_j once for i <= j: 20 products of the 30 (p = 5)
    pairs = [(i, 0) for i in range(p)] + [(i, 1 + j) for i in range(p) for j in range(i, p)]
    first, second = (np.array(k) for k in zip(*pairs, strict=True))

    def products(start: int, stop: int) -> NDArray[np.float64]:
        C = np.column_stack([b[start:stop], A[start:stop]])
        return A[start:stop][:, first] * C[:, second]
    G = bartlett_sum(products, bartlett_weights(lags), b.size)
    where = {pair: k for k, pair in enumerate(pairs)}  # each of the 30 products' row
    index = [where[(i, 0)] if a == 0 else where[(min(i, a - 1), 1 + max(i, a - 1))]
             for i in range(p) for a in range(p + 1)]
    return G[np.ix_(index, index)]


UNIT_READINGS = 30.0
"""Records of one stage read positions and forces within this factor of each other (their
amplitudes); a reading :data:`UNIT_FACTORS` times another's, beside a mass off by the same
factor, points to a unit (:func:`check_one_stage`)."""

UNIT_FACTORS = ((1e3, "position", "mm", "displacement=0.001", "m"),
                (1e6, "position", "um", "displacement=1e-6", "m"),
                (1e3, "force", "mN", "force=0.001", "N"))
"""The unit slips :func:`check_one_stage` names between records: a factor of readings, the
column, the unit that reads it, the --scale that undoes it, the SI unit.  A position read
``F`` times too large makes the mass ``F`` times too small, a force ``F`` times too large
(in mN, or the other record's in kN) the mass ``F`` times too large."""


def _unit_slip(rec: IORecord, rest: list[IORecord], mass: tuple[float, float],
               mass_rest: tuple[float, float]) -> str | None:
    """One line naming a unit slip between `rec` and the other records `rest` (their masses
    and standard errors), or None: the masses differ by a factor of :data:`UNIT_FACTORS`
    (within :data:`ONE_STAGE_RATIO`) and one column's readings by that factor too (within
    :data:`UNIT_READINGS`)."""
    readings = {"position": lambda r: float(np.ptp(r.y)),
                "force": lambda r: float(np.max(np.abs(r.u - np.mean(r.u))))}
    (m, std), (m_rest, std_rest) = mass, mass_rest
    for factor, column, unit, scale, si in UNIT_FACTORS:
        own = readings[column](rec)
        other = max(readings[column](r) for r in rest)
        if not (own > 0 and other > 0):
            continue
        ratio = own / other
        d = 1.0 if ratio > 1.0 else -1.0  # rec reads the larger numbers, or the others do
        if not (abs(math.log10(ratio ** d / factor)) <= math.log10(UNIT_READINGS)
                and abs(math.log10((m / m_rest) ** (d if column == "force" else -d) / factor))
                <= math.log10(ONE_STAGE_RATIO)):
            continue
        if d < 0 and len(rest) == 1:  # named from the record that reads the larger numbers
            return _unit_slip(rest[0], [rec], mass_rest, mass)
        whose = f"{rest[0].name}'s" if len(rest) == 1 else "the other records'"
        what = "range" if column == "position" else "peak"
        times = f"{_factor(ratio)} times" if ratio > 1.0 else f"1/{_factor(1.0 / ratio)} of"
        line = (f"{rec.name}: its {column} reads {times} {whose} (a {what} of {own:.3g} {si} "
                f"against {other:.3g} {si}) and its inverse-dynamics mass is {m:.3g} +- "
                f"{std:.2g} kg against {m_rest:.3g} +- {std_rest:.2g} kg: ")
        if d < 0 and len(rest) > 1:  # the others read the larger numbers
            kn = f", or {rec.name}'s in kN" if column == "force" else ""
            return (f"{line}are the other records' {column}s in {unit}{kn}? --scale scales "
                    f"every record alike: write the records in {si}")
        if column == "force":  # mN here or kN there: both read as a stage's force may
            return (f"{line}is {rec.name}'s force in mN, or {whose} in kN? --scale scales "
                    f"every record alike: write the records in N")
        return (f"{line}is {rec.name}'s {column} in {unit}? --scale scales every record "
                f"alike: write {rec.name} in {si}, or identify it alone with --scale {scale}")
    return None


def _factor(x: float) -> str:
    return f"{x:.0f}" if x < 1e4 else f"{x:.2g}"


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
