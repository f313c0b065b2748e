"""A link with a spring and damper in parallel from force-displacement records.

The force-displacement route of the quasi-static plant (:func:`identify_link_force`): the
displacement imposed, the force measured and fitted by its error, from the starts and
refinement of :func:`~motionhyst.identify.io_quasi_static.identify_quasi_static_io`.
"""

from __future__ import annotations

from motionhyst.core.warnings import warn
from motionhyst.hysteresis import BoucWen
from motionhyst.identify.determinacy import judge_link_force
from motionhyst.identify.displacement_noise import estimate_displacement
from motionhyst.identify.io_checks import budget_note
from motionhyst.identify.io_quasi_static import identify_quasi_static_io
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_results import IOIdentification
from motionhyst.identify.io_uncertainty import (
    BOUC_WEN_SCALE,
    judge_determined,
    widened_note,
    zero_allowed,
)

__all__ = ["identify_link_force"]


def identify_link_force(records: list[IORecord], link: type, *, n_elements: int = 3,
                        offset: str = "auto", max_evaluations: int | None = None,
                        tol: float = 1e-10, nu: float | None = None) -> IOIdentification:
    """A link with a spring and damper in parallel from force-displacement records, by the
    force's error.

    A friction damper or a link on a test machine: the displacement imposed (``y``),
    the force measured (``u``).  The model is the quasi-static plant's balance
    ``u - u_0 = w(y) + k y + c y'`` evaluated on the measured displacement
    (:func:`~motionhyst.time.quasi_static.force_from_displacement`, one pass of the
    link) and fitted to the measured force, from the starts of
    :func:`~motionhyst.identify.io_quasi_static.identify_quasi_static_io`; offset ``auto``
    is the force's (the load cell's zero; a displacement offset is a constant force through
    the spring).  A fit that does not describe the records (a systematic error above
    :data:`~motionhyst.identify.io_checks.SYSTEMATIC_SHARE` of the force's RMS beyond
    the noise) is a failure, not a model.

    Parameters
    ----------
    records : list of IORecord
        ``u`` the measured force [N], ``y`` the imposed displacement [m].
    link : type
        The link's model, a registered :class:`~motionhyst.hysteresis.Hysteresis` class.
    n_elements : int
        Elements of a list model (Maxwell-slip).
    offset : {"auto", "none", "input", "output", "both"}
        Offsets estimated (``input``: the force's, ``output``: the displacement's).
    max_evaluations : int, optional
        The budget of model evaluations.
    tol : float
        ``ftol = xtol = gtol`` of the refinement.
    nu : float, optional
        A Bouc-Wen link's exponent ``n``, fixed; None (default): estimated with the rest
        (from ``n = 2``, once the starts are refined there).

    Returns
    -------
    IOIdentification
        With ``output = "force"``: the fit RMS and residuals in newtons.

    Raises
    ------
    FitFailed
        A fit that is no result, or with a positive parameter not two standard errors from 0
        (:func:`~motionhyst.identify.determinacy.judge_link_force`), or of whose parameters
        the records determine at most half
        (:func:`~motionhyst.identify.io_uncertainty.judge_determined`; fewer not determined
        are one of the result's ``warnings``, and so are the values that only its standard
        errors widened for the residuals' correlation leave undetermined or not
        distinguishable from 0, :func:`~motionhyst.identify.io_uncertainty.widened_note`).

    Examples
    --------
    A Dahl link and a spring measured with a load cell's offset of 5 N:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Dahl
    >>> from motionhyst.plants.quasi_static import QuasiStatic
    >>> from motionhyst.time.quasi_static import force_from_displacement
    >>> t = np.arange(4000) / 200.0
    >>> x = 0.01 * np.sin(2 * np.pi * 0.5 * t) * np.minimum(1.0, t / 4)
    >>> u = force_from_displacement(QuasiStatic(k=2e4), Dahl(k=5e5, fc=800.0), t, x) + 5.0
    >>> fit = identify_link_force([IORecord(t, u, x)], Dahl)
    >>> est = fit.estimates
    >>> round(est["k"]), round(est["link.k"]), round(est["link.fc"], 3), round(est["c"], 6)
    (20000, 500000, 800.0, 0.0)
    >>> round(est["input_offset"], 6), fit.output
    (5.0, 'force')
    """
    noise = [estimate_displacement(rec.t, rec.y) for rec in records]
    used = [rec if x is rec.y else IORecord(rec.t, rec.u, x, rec.name)
            for rec, (x, _) in zip(records, noise, strict=True)]
    fit = identify_quasi_static_io(used, link, periodic=False, n_elements=n_elements,
                                   offset=offset, max_evaluations=max_evaluations, tol=tol,
                                   output="force", nu=nu)
    fit.extra["displacement_noise"] = [est.to_dict() for _, est in noise]
    if fit.extra.get("budget_reached"):  # a good fit all the same: said, not refused
        fit.warnings.append(budget_note(fit.n_evaluations))
    invariant, zero = BOUC_WEN_SCALE if link is BoucWen else (), zero_allowed(fit.plant, link)
    said = list(fit.warnings)  # the search's own (a Stribeck curve the records do not hold)
    # parameters the records do not determine: a warning, or (most of them) a failed fit
    fit.warnings.extend(judge_determined(fit.estimates, fit.judged_std or fit.std, invariant,
                                         zero))
    # a positive one not two standard errors from 0: a failed fit
    judge_link_force(fit.estimates, fit.judged_std or fit.std, invariant, zero, link.name,
                     said)
    widened = widened_note(fit.estimates, fit.std, fit.judged_std, invariant, zero) \
        if fit.judged_std and fit.extra.get("std_lower_bound") else None
    if widened is not None:  # determined on white residuals, not beyond the model's error
        fit.warnings.append(widened)
    for line in fit.warnings:  # for every caller to see, as identify_io's
        warn(line)
    return fit

