"""The rigid limit of a positioning axis's friction link: the Coulomb link.

Every friction link on a mass-damper (a positioning axis: a mass on guides, no spring to
the ground) tends to the rigid slider, the Coulomb link, as its stiffness grows: the Jenkins
link with ``k`` infinite, its sticking exact.  That limit serves the element links' search
(:func:`~motionhyst.identify.io_elements.identify_elements_io`) twice:

- as a start: the Coulomb link's fit, turned into the link's values at its limit
  (:func:`rigid_seed`);
- as the answer: a Jenkins link whose stiffness the records do not resolve
  (:func:`unresolved_stiffness`), or which fits them significantly worse than its limit, is
  reported as that limit (:func:`as_rigid_limit`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.io_checks import PROFILE_CHI2, FitFailed
from motionhyst.identify.io_friction import STUCK_MODE_SAMPLES
from motionhyst.identify.io_results import IOIdentification

__all__ = ["as_rigid_limit", "unresolved_stiffness"]

#: The slip displacement of a link at its rigid limit, in units of the output's RMS
RIGID_SLIP = 1e-5


def rigid_seed(fit_coulomb: Callable[[], IOIdentification], layout, y_scale: float,
               v_scale: float, extra_names: list[str], force: NDArray[np.bool_],
               rate: NDArray[np.bool_], rate_value: float, skew: bool = False,
               rigid: IOIdentification | None = None):
    """A positioning axis's friction link started from the Coulomb link's fit (`rigid`, else
    `fit_coulomb()`, as identify_io fits it: by direction, the link's own): the stage, the
    offsets and initial states (`extra_names`) as fitted, the link's forces (`force`) together
    its slip force, slipping after :data:`RIGID_SLIP` of the output's RMS (its rigid limit),
    its rate scales (`rate`) at `rate_value`; with the evaluations and the fit itself; None
    (0, None) if that fit fails.  `layout` is the search's link layout (its ``start``)."""
    try:
        fit = rigid or fit_coulomb()
    except (FitFailed, ValueError, ArithmeticError):
        return None, 0, None
    link = fit.hysteresis  # viscous friction by direction: the stage's c_skew, or the link's
    skewed = getattr(fit.plant, "c_skew", 0.0) + 0.5 * (link.c_pos - link.c_neg)
    if (not skew and skewed) or any(n not in fit.estimates for n in extra_names):
        raise ValueError("the Coulomb fit reused as the rigid limit has other options")
    fc, c = fit.estimates["link.fc"], fit.plant.c + 0.5 * (link.c_pos + link.c_neg)
    link0 = layout.start(2.0 * fc / (RIGID_SLIP * y_scale), y_scale, v_scale, c, RIGID_SLIP)
    if force.any():
        link0[force] *= fc / np.sum(link0[force])
    if skew:
        link0[-1] = skewed
    link0[rate] = rate_value
    return (np.concatenate([[fit.plant.m, c], link0,
                            [fit.estimates[name] for name in extra_names]]),
            0 if rigid else fit.n_evaluations, fit)


def unresolved_stiffness(k: float, k_std: float | None, m: float, fs: float) -> str | None:
    """Why a Jenkins link's stiffness on a positioning axis is beyond what its records resolve,
    or None.

    Stuck, the axis's mass ``m`` rests on the link's spring ``k``: a mode at
    ``sqrt(k / m) / 2 pi``.  Records sampled at `fs` show a mode only below ``fs /``
    :data:`STUCK_MODE_SAMPLES`; above, or with ``k`` not determined, they cannot tell the
    link from its rigid limit, the Coulomb link (the Jenkins link with ``k`` infinite, its
    sticking exact), and the stiffness found is the search's, not the axis's.

    Parameters
    ----------
    k : float
        The link's stiffness [N/m].
    k_std : float or None
        Its standard error (None: not determined by the records).
    m : float
        The axis's mass [kg].
    fs : float
        The records' sampling rate [Hz].

    Returns
    -------
    str or None
        One phrase saying why; None for a stiffness the records resolve.

    Examples
    --------
    >>> unresolved_stiffness(3e7, 1e6, 95.0, 1000.0) is None   # 89 Hz
    True
    >>> unresolved_stiffness(8.6e8, 2.8e8, 95.0, 1000.0)
    'its stuck mode at 479 Hz with k 8.6e+08 N/m, above 1000 Hz / 4: the records do not resolve it'
    >>> unresolved_stiffness(9.4e9, None, 95.0, 1000.0)
    'k 9.4e+09 N/m, not determined by the records'
    """
    if k_std is None:
        return f"k {k:.2g} N/m, not determined by the records"
    mode = math.sqrt(max(k, 0.0) / m) / (2 * math.pi) if m > 0 else math.inf
    if mode <= fs / STUCK_MODE_SAMPLES:
        return None
    return (f"its stuck mode at {mode:.0f} Hz with k {k:.2g} N/m, above {fs:.0f} Hz / "
            f"{STUCK_MODE_SAMPLES}: the records do not resolve it")


def as_rigid_limit(rigid: IOIdentification, estimates: dict[str, float],
                   std: dict[str, float | None], fs: float, fit_rms: float,
                   link: str = "jenkins") -> IOIdentification | None:
    """A Jenkins link's fit on a positioning axis (or a Maxwell-slip link of one element: a
    Jenkins link) reported as its rigid limit when its records
    do not resolve its stiffness (:func:`unresolved_stiffness`) or the limit fits them
    significantly better (likelihood ratio ``2 N ln(RMS / RMS_limit)`` above
    :data:`~motionhyst.identify.io_checks.PROFILE_CHI2`, ``N`` the residuals: the search, run
    from the limit among other starts, ended in a softer link's poorer minimum; a stuck
    Jenkins link rings at its stuck mode, which the limit does not), else None.

    Parameters
    ----------
    rigid : IOIdentification
        The Coulomb link's fit with the same options (the Jenkins search's start; its
        residuals count ``N``).
    estimates, std : dict
        The Jenkins fit's estimates and standard errors (``m``, ``link.k``; None: not
        determined).
    fs : float
        The records' sampling rate [Hz].
    fit_rms : float
        The Jenkins fit's RMS error [m], compared with the Coulomb link's.
    link : str
        The link fitted: ``"jenkins"``, or ``"maxwell-slip"`` (of one element, its
        ``link.k[0]`` given as ``link.k``).

    Returns
    -------
    IOIdentification or None
        `rigid` with a first warning saying why it is reported (and why in its ``extra``'s
        ``rigid_limit``); None when the records resolve the stiffness.

    Examples
    --------
    >>> from motionhyst.hysteresis import Coulomb
    >>> from motionhyst.plants.mass_damper import MassDamper
    >>> coulomb = IOIdentification(MassDamper(95.0, 200.0), Coulomb(fc=20.0),
    ...                            {"m": 95.0, "c": 200.0, "link.fc": 20.0}, {}, {}, 2.3e-3,
    ...                            [], 1.0, False, "", 10, residuals=np.zeros(2000))
    >>> jenkins = {"m": 94.0, "c": 201.0, "link.k": 9.4e9, "link.fc": 20.7}
    >>> limit = as_rigid_limit(coulomb, jenkins, {"link.k": None}, 1000.0, 2.29e-3)
    >>> limit.warnings[0][:66]
    'the Jenkins link is reported as its rigid limit, the Coulomb link '
    >>> limit.extra["rigid_limit"]
    'jenkins: k 9.4e+09 N/m, not determined by the records'
    >>> as_rigid_limit(coulomb, dict(jenkins, **{"link.k": 3e7}), {"link.k": 1e6}, 1000.0,
    ...                2.29e-3) is None   # resolved (89 Hz), and a better fit than the limit
    True
    >>> as_rigid_limit(coulomb, dict(jenkins, **{"link.k": 3e7}), {"link.k": 1e6}, 1000.0,
    ...                2.3e-3 * (1 + 1e-9)) is None          # worse by nothing that counts
    True
    >>> as_rigid_limit(coulomb, dict(jenkins, **{"link.k": 3e7}), {"link.k": 1e6}, 1000.0,
    ...                2.5e-3).warnings[0][-82:]
    'than k infinite: RMS 0.0025 m against 0.0023 m, likelihood ratio 334 > 3.84 (95 %)'
    >>> one = as_rigid_limit(coulomb, jenkins, {"link.k": None}, 1000.0, 2.29e-3,
    ...                      "maxwell-slip")
    >>> one.extra["rigid_limit"]
    'maxwell-slip: k 9.4e+09 N/m, not determined by the records'
    """
    why = unresolved_stiffness(estimates["link.k"], std.get("link.k"), estimates["m"], fs)
    ratio = (2 * rigid.residuals.size * math.log(fit_rms / rigid.fit_rms)
             if 0 < rigid.fit_rms < fit_rms else 0.0)  # likelihood ratio, Gaussian errors
    if why is None and ratio > PROFILE_CHI2:  # the search ended short of its own limit
        why = (f"k {estimates['link.k']:.2g} N/m fits the records worse than k infinite: "
               f"RMS {fit_rms:.4g} m against {rigid.fit_rms:.4g} m, likelihood ratio "
               f"{ratio:.3g} > {PROFILE_CHI2:g} (95 %)")
    if why is None:
        return None
    title = "Jenkins link" if link == "jenkins" else "Maxwell-slip link of one element"
    note = (f"the {title} is reported as its rigid limit, the Coulomb link (fc "
            f"{rigid.estimates['link.fc']:.4g} N, fit RMS {rigid.fit_rms:.3g} m): {why}")
    return replace(rigid, warnings=[note, *rigid.warnings],
                   extra={**rigid.extra, "rigid_limit": f"{link}: {why}"})
