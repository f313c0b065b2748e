"""Whether a stage's input-output records show its link slip: decided before the search.

A link with a spring (``k``, the stop operators' stiffness, eq. 3) that never slips in the
records acts as that spring: the stage is then a linear mass-spring-damper, and no slip
force is determined (any above the spring's force at the records' strokes fits as well).
The search found that only at its end (a Jenkins link on a 10 kg axis: 20-43 s of CPU, the
slip force run away to 5.6e12 N, refused by
:func:`~motionhyst.identify.input_output.identify_io` after it).  :func:`check_link_slips`
asks the records first: a linear mass-spring-damper is fitted to them by simulation error
(each record's force offset, initial position and velocity and position offset projected
out, :func:`linear_stage_error`); when it leaves no more than :data:`NOISE_SHARE` times the
white noise of its residual (:func:`~motionhyst.identify.residual_noise.white_noise_variance`), no
slip is in them and the fit is refused in one line, before the search.  A record with a
slip at the noise's level or below is left to the search and its judgement afterwards.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.io_records import IORecord
from motionhyst.identify.residual_noise import white_noise_variance

__all__ = ["NOISE_SHARE", "check_link_slips", "linear_stage_error"]

NOISE_SHARE = 1.5
"""A linear stage's fit RMS, as a multiple of the records' white noise, at or below which
the records show no slip of the link."""


def _responses(m: float, c: float, k: float, rec: IORecord) -> NDArray[np.float64]:
    """The columns of a record's linear-stage output: the response to its force (first
    order hold, as the simulator interpolates the force), to a unit force offset, two
    free responses (the initial state) and a constant (the position offset)."""
    from scipy.signal import cont2discrete, lfilter

    dt = float(rec.t[1] - rec.t[0])
    b, a, _ = cont2discrete(([1.0], [m, c, k]), dt, method="foh")
    b = np.ravel(b)
    n = rec.u.size
    delta = np.zeros(n)
    delta[0] = 1.0
    return np.column_stack([lfilter(b, a, rec.u), lfilter(b, a, np.ones(n)),
                            lfilter([1.0], a, delta), lfilter([0.0, 1.0], a, delta),
                            np.ones(n)])


def _stage_residuals(m: float, c: float, k: float, records: list[IORecord]
                     ) -> list[NDArray[np.float64]] | None:
    """Each record's position less the linear stage's simulation (its force offset, initial
    state and position offset projected out); None if the stage does not run."""
    out = []
    for rec in records:
        cols = _responses(m, c, k, rec)
        if not np.all(np.isfinite(cols)):
            return None
        rest = rec.y - cols[:, 0]
        x = np.linalg.lstsq(cols[:, 1:], rest, rcond=None)[0]
        out.append(rest - cols[:, 1:] @ x)
    return out


def linear_stage_error(records: list[IORecord], start: tuple[float, float, float]
                       ) -> tuple[tuple[float, float, float], float]:
    """The mass-spring-damper ``1 / (m s^2 + c s + k)`` that fits the records best by
    simulation error, each record's force offset, initial state and position offset
    estimated with it (linear in them: projected out).

    Parameters
    ----------
    records : list of IORecord
        Force in, position out, from a start; one sampling rate.
    start : tuple of float
        ``m, c, k`` to start from (positive).

    Returns
    -------
    stage : tuple of float
        ``m, c, k``.
    rms : float
        The fit's RMS [m] over every record.

    Examples
    --------
    >>> from motionhyst.time.openloop import MassSpringDamper, OpenLoop
    >>> t = np.arange(2000) / 500.0
    >>> u = 0.8 * np.sin(2 * np.pi * t) + 0.3 * np.sin(2 * np.pi * 3.75 * t)
    >>> y = OpenLoop(MassSpringDamper(10.0, 20.0, 2000.0)).simulate(t, u).displacement
    >>> (m, c, k), rms = linear_stage_error([IORecord(t, u, y)], (5.0, 10.0, 1000.0))
    >>> round(m, 2), round(c, 1), round(k), rms < 1e-8     # the simulator's own steps: 7e-9
    (10.0, 20.0, 2000, True)
    """
    from scipy.optimize import least_squares

    scale = float(np.sqrt(np.mean(np.concatenate([rec.y for rec in records]) ** 2))) or 1.0

    def residual(logp: NDArray[np.float64]) -> NDArray[np.float64]:
        parts = _stage_residuals(*np.exp(logp), records)
        if parts is None:  # a stage that does not run: no fit there
            return np.full(sum(r.y.size for r in records), 1e6)
        r = np.concatenate(parts) / scale
        return np.where(np.isfinite(r), r, 1e6)

    x0 = np.log(np.maximum(np.asarray(start, dtype=float), 1e-12))
    sol = least_squares(residual, x0, method="trf", x_scale=1.0, max_nfev=200,
                        bounds=(x0 - 20.0, x0 + 20.0))
    m, c, k = (float(v) for v in np.exp(sol.x))
    n = sum(rec.y.size for rec in records)
    return (m, c, k), float(math.sqrt(2.0 * sol.cost / n)) * scale


def check_link_slips(records: list[IORecord], link: str, stage_k: bool) -> None:
    """Refuse records in which a link with a spring never slips, before the search.

    Parameters
    ----------
    records : list of IORecord
        Force in, position out, from a start; a single mass.
    link : str
        The link model's name.
    stage_k : bool
        The stage has a spring of its own (a mass-spring-damper): the spring named is
        theirs together.

    Raises
    ------
    FitFailed
        One line: the linear stage that explains the records within their noise, the
        spring the link acts as, the remedy.

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.identify.io_checks import FitFailed
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> from motionhyst.time.openloop import OpenLoop
    >>> t = np.arange(2000) / 500.0
    >>> u = 0.8 * np.sin(2 * np.pi * t) + 0.3 * np.sin(2 * np.pi * 3.75 * t)
    >>> y = OpenLoop(MassDamper(10.0, 20.0), Jenkins(k=2000.0, fc=2.0)).simulate(t, u)
    >>> noisy = y.displacement + 1e-7 * np.random.default_rng(0).standard_normal(t.size)
    >>> try:
    ...     check_link_slips([IORecord(t, u, noisy)], "jenkins", stage_k=False)
    ... except FitFailed as exc:
    ...     print(str(exc)[:60])
    the fit failed: the link never slips in these records (a mas
    >>> check_link_slips([IORecord(t, 3 * u, OpenLoop(MassDamper(10.0, 20.0),   # it slips
    ...     Jenkins(k=2000.0, fc=2.0)).simulate(t, 3 * u).displacement)], "jenkins", False)
    """
    from motionhyst.identify.io_checks import FitFailed
    from motionhyst.identify.io_start import inverse_dynamics

    idim = inverse_dynamics(records, floating=False)
    start = (idim["m"] if idim["m"] > 0 else 1.0, idim["c"] if idim["c"] > 0 else 1.0,
             idim["k"] if idim.get("k", 0.0) > 0 else 1.0)
    (m, c, k), rms = linear_stage_error(records, start)
    # the noise of the fit's residual, not of the position: a record's own fast motion (a
    # resonance in band, a force of broad band) is no noise, and would hide a small slip
    parts = _stage_residuals(m, c, k, records)
    noise = math.sqrt(white_noise_variance(parts if parts is not None
                                           else [rec.y for rec in records]))
    if not rms <= NOISE_SHARE * noise:
        return
    half = max(0.5 * float(np.ptp(rec.y)) for rec in records)
    whose = "the stage and its link act" if stage_k else "it acts"
    raise FitFailed(f"the fit failed: the link never slips in these records (a mass-spring-"
                    f"damper of m {m:.4g} kg, c {c:.4g} N s/m, k {k:.4g} N/m explains them "
                    f"within their noise: fit RMS {rms:.2g} m, noise {noise:.2g} m): {whose} "
                    f"as a spring of {k:.4g} N/m, and any slip force of the {link} link above "
                    f"its {k * half:.3g} N at the records' half-stroke {half:.3g} m fits as "
                    f"well; give a record in which the link slips (a larger force or stroke), "
                    f"or model the stage with that spring (a mass-spring-damper); nothing "
                    f"identified")
