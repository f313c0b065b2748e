"""A mass in a force-displacement record: inertia beside the link, told from hysteresis.

A link's force against an imposed displacement has no inertia.  A record taken with a mass
between the actuator and the load cell (a fixture, a carriage: ``F = m x'' + link``), or a
stage's input-output record read as force-displacement (the two kinds share the header
``time,force,displacement``), has: a link fitted to it absorbs ``m x''`` as hysteresis it
does not have, or fails after the whole fit.

The mass is the coefficient of the acceleration in one least-squares regression of the force
on the acceleration, the velocity, the displacement, an offset per record *and* stop
operators (Maxwell-slip elements per unit slip force, :data:`STOPS_PER_DECADE` slip
displacements a decade from :data:`STOP_SPAN` of the half range to the half range, and the
limit of zero slip, a Coulomb element): a link's own hysteresis, which correlates with the
acceleration at some frequencies (a regression without the stops gave links of no mass 5 to
128 standard errors of "mass" at 80-150 Hz), is described by the stops and cannot pose as a
mass.  Rates are central differences; every column and the force pass the same zero-phase
low-pass filter (a triangle of about 5 ms), so that the regression holds in any band and the
position noise in the acceleration is damped.  The rows are those after the record has swept
:data:`SWEPT` of its range (every stop up to nearly the half range then slips whatever its
state at the start), evenly strided to at most :data:`MAX_ROWS`.  The standard error is
Newey-West's (:func:`~motionhyst.identify.io_checks.robust_least_squares`).

A mass is *proven* when it is positive by :data:`MASS_SIGMAS` standard errors and explains
at least :data:`MASS_EXPLAINED` of what the link's columns leave of the force (a link's
misfit that correlates with the acceleration explains a small part of it; standard errors
that shrink with a record's length alone do not pass this); a proven mass whose force
``m x''`` is :data:`REFUSE_SHARE` of the force's RMS or more, or whose force beyond what the
link's columns describe is more than a fit may leave
(:data:`~motionhyst.identify.io_checks.SYSTEMATIC_SHARE`), is refused
(:func:`check_no_inertia`); one of :data:`WARN_SHARE` or more is a warning.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.blas import few_blas_threads
from motionhyst.hysteresis import Jenkins
from motionhyst.identify.io_checks import SYSTEMATIC_SHARE, robust_least_squares
from motionhyst.identify.io_records import IORecord

__all__ = ["DRIVEN_SHARE", "MASS_EXPLAINED", "MASS_SIGMAS", "REFUSE_SHARE", "WARN_SHARE",
           "LinkInertia", "check_no_inertia", "driven_mass", "link_inertia"]

#: Slip displacements of the regression's stop operators per decade
STOPS_PER_DECADE = 6
#: The shortest slip displacement (but the limit of zero slip), in units of the half range
STOP_SPAN = 1e-5
#: The share of its range a record has swept before its rows are used
SWEPT = 0.9
#: Most rows of the regression (the filtered columns evenly strided)
MAX_ROWS = 10_000
#: The low-pass filter's length [s]: a triangle of two boxes of half of it
FILTER_SECONDS = 0.005
#: A mass is proven when it is positive by this many standard errors ...
MASS_SIGMAS = 5.0
#: ... and explains at least this share of the force's variance that the link's columns
#: (stops, spring, damper, offsets) leave
MASS_EXPLAINED = 0.5
#: A proven mass whose force ``m x''`` is this share of the force's RMS or more is refused
REFUSE_SHARE = 0.1
#: ... and one of this share or more is a warning
WARN_SHARE = 0.01
#: A mass that a displacement lagging the force by at most this many samples would give
#: through the damping found (``m = c tau``) is said to be that, as well
LAG_SAMPLES = 5.0


@dataclass(frozen=True)
class LinkInertia:
    """The mass a force-displacement record's force accelerates, beside a link.

    Attributes
    ----------
    mass : float
        The coefficient of the acceleration [kg].
    std : float
        Its Newey-West standard error [kg].
    share : float
        ``|m| x''`` (RMS) over the force's RMS about its mean, both filtered.
    explained : float
        The share of what the other columns leave of the force that the mass explains.
    beyond : float
        What the mass explains that the link's columns do not, RMS over the force's RMS:
        about what a link fitted to the record leaves for it.
    damping : float
        The velocity's coefficient [N s/m]: with it the mass is also a displacement that
        lags the force by ``mass / damping`` (``c x'(t + tau) = c x' + c tau x''``).

    Examples
    --------
    >>> found = LinkInertia(mass=0.5, std=1e-3, share=0.4, explained=0.99, beyond=0.15,
    ...                     damping=0.0)
    >>> found.proven
    True
    """

    mass: float
    std: float
    share: float
    explained: float
    beyond: float
    damping: float

    @property
    def proven(self) -> bool:
        """Whether the mass is positive by :data:`MASS_SIGMAS` standard errors and explains
        :data:`MASS_EXPLAINED` of what the link's columns leave."""
        return self.mass > MASS_SIGMAS * self.std and self.explained >= MASS_EXPLAINED


def _smooth(column: NDArray[np.float64], half: int) -> NDArray[np.float64]:
    """`column` through two boxes of `half` samples (a triangle), where it is whole."""
    for _ in range(2):
        c = np.concatenate([[0.0], np.cumsum(column)])
        column = (c[half:] - c[:-half]) / half
    return column


def _columns(rec: IORecord, d: NDArray[np.float64]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The record's filtered regressors (acceleration, velocity, displacement, the stops of
    slip displacements `d`) and force, at its rows; None for a record too short."""
    x = np.ascontiguousarray(rec.y, dtype=float)
    n = x.size
    dt = float(rec.t[-1] - rec.t[0]) / (n - 1)
    span = np.maximum.accumulate(x) - np.minimum.accumulate(x)
    start = max(int(np.searchsorted(span, SWEPT * span[-1])), 1)
    half = max(1, round(0.5 * FILTER_SECONDS / dt))
    inner = slice(start, n - 1)  # where both central differences exist
    if inner.stop - inner.start < 2 * half + 8:
        return None
    keep = np.arange(0, inner.stop - inner.start - 2 * (half - 1), 1)
    stride = max(1, math.ceil(keep.size / MAX_ROWS))
    keep = keep[::stride]

    def filtered(column: NDArray[np.float64]) -> NDArray[np.float64]:
        return _smooth(column[inner], half)[keep]

    a = (x[2:] - 2.0 * x[1:-1] + x[:-2]) / dt ** 2
    v = (x[2:] - x[:-2]) / (2.0 * dt)
    cols = [filtered(np.concatenate([[0.0], a, [0.0]])),
            filtered(np.concatenate([[0.0], v, [0.0]])), filtered(x)]
    cols += [filtered(Jenkins(k=1.0 / s, fc=1.0).response(x)) for s in d]
    return np.column_stack(cols), filtered(np.asarray(rec.u, dtype=float))


def link_inertia(records: list[IORecord]) -> LinkInertia | None:
    """The mass the force of force-displacement `records` accelerates beside a link (the
    module's regression); None where no record has the rows for it.

    Parameters
    ----------
    records : list of IORecord
        The records, uniformly sampled: the force as ``u``, the displacement as ``y``.

    Returns
    -------
    LinkInertia or None

    Examples
    --------
    A Jenkins element and a spring, alone and with 0.5 kg attached, under two sines:

    >>> from motionhyst.hysteresis import Jenkins
    >>> t = np.arange(20000) / 10000.0
    >>> x = 5e-5 * (np.sin(2 * np.pi * 80 * t) + 0.4 * np.sin(2 * np.pi * 184 * t))
    >>> w = Jenkins(k=1e7, fc=20.0).response(x) + 1e5 * x
    >>> alone = link_inertia([IORecord(t, w, x)])
    >>> alone.proven, bool(alone.share < 0.01)
    (False, True)
    >>> a = np.gradient(np.gradient(x, t), t)
    >>> found = link_inertia([IORecord(t, w + 0.5 * a, x)])
    >>> found.proven, round(found.mass, 2), round(found.share, 1)
    (True, 0.5, 0.4)
    """
    halves = [0.5 * float(np.ptp(rec.y)) for rec in records]
    top = max(halves)
    if not top > 0:
        return None
    low = STOP_SPAN * min(h for h in halves if h > 0) if any(halves) else STOP_SPAN * top
    d = np.geomspace(low, top, max(2, math.ceil(STOPS_PER_DECADE * math.log10(top / low)) + 1))
    steps = np.concatenate([np.abs(np.diff(rec.y)) for rec in records])
    steps = steps[steps > 0]
    d = np.append(min(0.25 * float(steps.min()), 0.5 * low), d)  # the zero-slip limit
    parts = [p for p in (_columns(rec, d) for rec in records) if p is not None]
    if not parts:
        return None
    offsets = [np.zeros((p[0].shape[0], len(parts))) for p in parts]
    for i, o in enumerate(offsets):
        o[:, i] = 1.0
    rows = [np.column_stack([p[0], o]) for p, o in zip(parts, offsets, strict=True)]
    rhs = [p[1] for p in parts]
    coef, cov = robust_least_squares(rows, rhs, 7)
    A, b = np.concatenate(rows), np.concatenate(rhs)
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    with few_blas_threads(*A.shape):  # a small fit: its threads cost more than the work
        rest = np.linalg.lstsq(A[:, 1:] / scale[1:], b, rcond=None)[0]
    left = b - A[:, 1:] @ (rest / scale[1:])
    full = b - A @ coef
    left_ss, full_ss = float(left @ left), float(full @ full)
    centred = np.concatenate([r - np.mean(r) for r in rhs])
    u_rms = math.sqrt(float(np.mean(centred ** 2)))
    a_rms = math.sqrt(float(np.mean(A[:, 0] ** 2)))
    m = float(coef[0])
    return LinkInertia(mass=m, std=math.sqrt(max(float(cov[0, 0]), 0.0)),
                       share=abs(m) * a_rms / u_rms if u_rms > 0 else 0.0,
                       explained=1.0 - full_ss / left_ss if left_ss > 0 else 0.0,
                       beyond=(math.sqrt(max(left_ss - full_ss, 0.0) / b.size) / u_rms
                               if u_rms > 0 else 0.0), damping=float(coef[1]))


def check_no_inertia(records: list[IORecord], refuse: bool = False) -> str | None:
    """Refuse force-displacement `records` whose force accelerates a proven mass of
    :data:`REFUSE_SHARE` of its RMS or more, or more beyond what a link describes than a
    fit may leave, before a link is fitted to them; a warning line for a proven mass of
    :data:`WARN_SHARE` or more (:func:`link_inertia`).

    Parameters
    ----------
    records : list of IORecord
        The records, uniformly sampled: the force as ``u``, the displacement as ``y``.
    refuse : bool
        Refuse a proven mass of :data:`WARN_SHARE` or more too (a record the link's fit
        cannot describe: the mass is the cause to name).

    Returns
    -------
    str or None
        The warning, naming the mass; None where no mass is proven (or a negligible one).

    Raises
    ------
    ValueError
        One line: the mass, its standard error and share, and what identifies such records.

    Examples
    --------
    >>> t = np.arange(20000) / 10000.0
    >>> x = 5e-5 * (np.sin(2 * np.pi * 80 * t) + 0.4 * np.sin(2 * np.pi * 184 * t))
    >>> a = np.gradient(np.gradient(x, t), t)
    >>> check_no_inertia([IORecord(t, 1e5 * x, x, "spring.csv")]) is None
    True
    >>> try:
    ...     check_no_inertia([IORecord(t, 1e5 * x + 0.5 * a, x, "rig.csv")])
    ... except ValueError as exc:
    ...     print(str(exc)[:40])
    rig.csv: the force accelerates a mass of
    """
    found = link_inertia(records)
    if found is None or not found.proven or found.share < WARN_SHARE:
        return None
    names = records[0].name if len(records) == 1 else f"{records[0].name} and the others"
    what = (f"a mass of {found.mass:.3g} +- {found.std:.2g} kg, whose force m x'' is "
            f"{100 * found.share:.3g} % of the force's RMS, {100 * found.beyond:.3g} % beyond "
            f"what a link describes (its hysteresis as stop operators in the same regression)")
    dt = float(records[0].t[-1] - records[0].t[0]) / (records[0].t.size - 1)
    align = ""
    if 0.0 < found.mass <= LAG_SAMPLES * dt * found.damping:  # a sensor's delay, as well
        lag = found.mass / found.damping
        what += (f", or equally the displacement lagging the force by {1e3 * lag:.2g} ms "
                 f"({lag / dt:.2g} samples) through a damping of {found.damping:.3g} N s/m")
        align = ", or advance the displacement by its lag"
    if refuse or found.share >= REFUSE_SHARE or found.beyond > SYSTEMATIC_SHARE:
        raise ValueError(f"{names}: the force accelerates {what}: a link's force against an "
                         f"imposed displacement has no inertia; identify the mass and its "
                         f"link with --record input-output --plant mass-damper (or "
                         f"mass-spring-damper), or subtract m x'' from the force{align}; "
                         f"nothing identified")
    return (f"{names}: the force accelerates {what}: the link identified absorbs it (a mass "
            f"and its link are --record input-output --plant mass-damper)")


#: A force that falls as the position rises drives a mass (:func:`driven_mass`) where the
#: inverse-dynamics mass's force ``m y''`` is at least this share of the force's RMS
DRIVEN_SHARE = 0.1


def driven_mass(records: list[IORecord]) -> tuple[float, float, float] | None:
    """The mass of records whose force (``u``) falls as the position (``y``) rises because it
    drives that mass (a stage's input-output record above its resonance: the position lags
    the force by nearly 180 degrees), not because a sensor's sign is reversed; or None.

    The records' inverse dynamics (``u = m y'' + c y' + f sign(y') + u0 + k y``, the rates by
    Savitzky-Golay filters of about 10 ms:
    :func:`~motionhyst.identify.io_start.equation_rows`, as input-output identification
    checks a stage's inertia) show such a mass positive by :data:`MASS_SIGMAS` Newey-West
    standard errors, its force ``m y''`` at least :data:`DRIVEN_SHARE` of the force's RMS,
    and a spring ``k`` that is not negative by as many (a sensor's sign reversed makes the
    spring negative, not the mass positive).

    Parameters
    ----------
    records : list of IORecord
        The records (force as ``u``, position as ``y``), uniformly sampled.

    Returns
    -------
    tuple of float or None
        ``(m, std, share)``: the mass [kg], its standard error and its force's share.

    Examples
    --------
    A 2 kg mass on a spring of 500 N/m (its resonance at 2.5 Hz) driven at 3 and 17 Hz, and
    a spring's record with its force's sign reversed:

    >>> t = np.arange(2000) / 1000.0
    >>> y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    >>> a = np.gradient(np.gradient(y, t), t)
    >>> m, std, share = driven_mass([IORecord(t, 2.0 * a + 500.0 * y, y, "stage.csv")])
    >>> round(m, 1), share > 0.5
    (2.0, True)
    >>> driven_mass([IORecord(t, -500.0 * y, y, "reversed.csv")]) is None
    True
    """
    from motionhyst.identify.io_start import equation_rows

    rows, rhs = equation_rows(records, floating=True, light=True)
    rows = [np.column_stack([r, rec.y - np.mean(rec.y)]) for r, rec in zip(rows, records,
                                                                           strict=True)]
    fs = (records[0].t.size - 1) / float(records[0].t[-1] - records[0].t[0])
    with few_blas_threads(sum(r.shape[0] for r in rows), rows[0].shape[1]):
        coef, cov = robust_least_squares(rows, rhs, max(7, 2 * round(0.005 * fs) + 1))
    m, k = float(coef[0]), float(coef[-1])
    m_std, k_std = (math.sqrt(max(float(cov[i, i]), 0.0)) for i in (0, -1))
    u = np.concatenate([b - np.mean(b) for b in rhs])
    a = np.concatenate([r[:, 0] for r in rows])
    u_rms = math.sqrt(float(np.mean(u ** 2)))
    share = m * math.sqrt(float(np.mean(a ** 2))) / u_rms if u_rms > 0 else 0.0
    if m > MASS_SIGMAS * m_std and share >= DRIVEN_SHARE and k > -MASS_SIGMAS * k_std:
        return m, m_std, share
    return None
