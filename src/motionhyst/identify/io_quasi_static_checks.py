"""Whether a fit of a link on the quasi-static plant is a result.

The bars of :func:`~motionhyst.identify.io_quasi_static.identify_quasi_static_io`: the
linear spring and damper's simulation error (:func:`linear_rms`), a force fit that is
finite and better than the force's spread and the linear model (:func:`judge_force_fit`),
a link that explains more than the linear model within the noise
(:func:`judge_hysteresis`), and a systematic error within
:data:`~motionhyst.identify.io_checks.PREDICT_SHARE` (:func:`judge_systematic`); the
warning for Maxwell-slip elements of a number the user fixed, shown and not saved, that
leave more (:func:`systematic_warning`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.io_checks import (
    NO_HYSTERESIS_GAIN,
    PREDICT_SHARE,
    FitFailed,
    hysteresis_gain,
    systematic_share,
)
from motionhyst.identify.io_records import IORecord
from motionhyst.plants.quasi_static import QuasiStatic
from motionhyst.time.quasi_static import displacement_from_force

__all__: list[str] = []  # the search's internals, for the identification modules


def linear_rms(records: list[IORecord], K: float, C: float, periodic: bool) -> float | None:
    """Simulation error of the linear model ``K, C`` with the best output offset per record
    (the bar a model with a link must pass); None if it cannot run."""
    try:
        err = []
        for rec in records:
            x = displacement_from_force(QuasiStatic(max(K, 0.0), max(C, 0.0)), None, rec.t,
                                        rec.u - np.mean(rec.u), periodic=periodic)
            e = x - rec.y
            err.append(e - np.mean(e))
        rms = float(np.sqrt(np.mean(np.concatenate(err) ** 2)))
    except ValueError:
        return None
    return rms if math.isfinite(rms) else None


def judge_force_fit(fit_rms: float, res: NDArray[np.float64], records: list[IORecord],
                     forces: list[NDArray[np.float64]], K: float, C: float,
                     b: NDArray[np.float64]) -> float:
    """Raise :class:`FitFailed` unless the forces predicted from the displacement are a
    result: finite, better than the force's own spread and than the linear model's
    ``K y + C y' + b``, and describing the records to within
    :data:`~motionhyst.identify.io_checks.PREDICT_SHARE` of the force's RMS beyond
    the noise (:func:`~motionhyst.identify.io_checks.systematic_share`, returned)."""
    if not all(np.all(np.isfinite(f)) for f in forces) or not math.isfinite(fit_rms):
        raise FitFailed("the fit failed: the identified link's force is not finite")
    u = np.concatenate([rec.u for rec in records])
    own = float(np.std(u))
    if fit_rms > own:
        raise FitFailed(f"the fit failed: its RMS error {fit_rms:.3g} N exceeds the force's "
                        f"own spread {own:.3g} N (predicting its mean does better)")
    linear = np.concatenate([rec.u - K * rec.y - C * np.gradient(rec.y, rec.t) - bi
                             for rec, bi in zip(records, b, strict=True)])
    linear_rms = float(np.sqrt(np.mean(linear ** 2)))
    if fit_rms > linear_rms * (1.0 + 1e-9):  # as the records' own check says it
        raise FitFailed(f"no hysteresis in the records: a spring of {K:.4g} N/m and a damper "
                        f"of {max(C, 0.0):.4g} N s/m describe the force better than the link "
                        f"(RMS error {linear_rms:.3g} N against its {fit_rms:.3g} N): its "
                        f"parameters would be a guess; nothing identified")
    judge_hysteresis(float(np.sum(linear ** 2)), res, "force", K, C)
    return judge_systematic(res, [rec.u for rec in records], "force")


def judge_hysteresis(linear_ss: float, res: NDArray[np.float64], what: str, K: float,
                      C: float) -> None:
    """Raise :class:`FitFailed` if the link explains no more of the `what` than the linear
    spring and damper ``K, C`` (sum of squares `linear_ss`), within the noise
    (:func:`~motionhyst.identify.io_checks.hysteresis_gain` below
    :data:`~motionhyst.identify.io_checks.NO_HYSTERESIS_GAIN`): the records show no
    hysteresis, and the link's parameters would be a guess."""
    gain = hysteresis_gain(linear_ss, res)
    if gain < NO_HYSTERESIS_GAIN:
        raise FitFailed(f"no hysteresis in the records: a spring of {K:.4g} N/m and a damper "
                        f"of {max(C, 0.0):.4g} N s/m explain the {what} as well as the link, "
                        f"within the noise (the link explains {max(gain, 0.0):.3g} times the "
                        f"noise's variance more, below {NO_HYSTERESIS_GAIN:g}): its parameters "
                        f"would be a guess; nothing identified")


def judge_systematic(res: NDArray[np.float64], measured: list[NDArray[np.float64]],
                      what: str) -> float:
    """The largest systematic share of the residuals `res` (the records one after the
    other) over the records; raise :class:`FitFailed` if it is above
    :data:`~motionhyst.identify.io_checks.PREDICT_SHARE` of a record's `measured`
    signal (:func:`~motionhyst.identify.io_checks.systematic_share`): a model that does
    not describe its records (a piezo's creep, a rate dependence the link lacks) does not
    predict another one (a fit below 95 %)."""
    parts = np.split(res, np.cumsum([m.size for m in measured])[:-1])
    share = max(systematic_share(r, m) for r, m in zip(parts, measured, strict=True))
    if share > PREDICT_SHARE:
        raise FitFailed(f"the fit failed: the model leaves a systematic error of "
                        f"{100 * share:.2g} % of the {what}'s RMS (above "
                        f"{100 * PREDICT_SHARE:g} %, beyond the noise): it does not describe "
                        f"these records (a creep, a rate dependence or a link another --model "
                        f"describes) and would predict another one below 95 %; nothing saved")
    return share


def systematic_warning(share: float, what: str, remedy: str) -> str | None:
    """The warning for a fit shown but not saved (Maxwell-slip elements of a number the user
    fixed) that leaves a systematic `share` of the `what`'s RMS beyond the noise above
    :data:`~motionhyst.identify.io_checks.PREDICT_SHARE`: on another record of the machine
    its error may be a few times larger; `remedy` says what may describe the records better.
    None below."""
    if not share > PREDICT_SHARE:
        return None
    return (f"the model leaves a systematic error of {100 * share:.2g} % of the {what}'s RMS "
            f"beyond the noise (above {100 * PREDICT_SHARE:g} %): on another record "
            f"of this machine its error may be a few times larger (a fit below 95 %); {remedy}")
