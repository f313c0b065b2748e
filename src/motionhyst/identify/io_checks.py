"""Whether an input-output fit is a result: failures and implausible estimates.

A fit is *failed*, and nothing of it is a result (:class:`FitFailed`), when
its simulation error exceeds the output's own RMS (a model that predicts
nothing, or the mean, does better) or the best linear model's, when its
prediction is not finite, or when the model it returns cannot be simulated
(the identified model is what ``motionhyst predict`` runs; a mass collapsed
towards zero makes that run need an impossibly fine step).

Before any fit, records whose force shows no inertia (a piezo actuator, a
friction damper, a force-displacement record taken for input-output) are
refused (:func:`check_inertia`): a stage with a mass would collapse it towards
zero after minutes of search.

A fit that succeeded can still be *implausible*: each such finding is a
one-line warning naming the parameter (:func:`plausibility_warnings`): a mass
far from the records' linear estimate or outside those of motion stages (a unit
slip in the records), a parameter at its bound, an inertia
the records do not show (the quasi-static plant describes such records).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.blas import few_blas_threads
from motionhyst.core.budget import RECORDS_REMEDY, BudgetError
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.residual_noise import (
    bartlett_sum,
    bartlett_weights,
    newey_west_lags,
    widest_covariance,
)

__all__ = ["DIRECTION_MOVING", "DIRECTION_NODES", "DIRECTION_SAMPLES", "DIRECTION_SHARE",
           "DIRECTION_SIGNIFICANCE", "DIRECTION_TOP",
           "MASS_FACTOR", "MASS_SHARE", "MASS_SIGMAS", "MAX_PREDICT_SUBSTEPS",
           "NO_HYSTERESIS_GAIN", "PREDICT_SHARE", "SPRING_SHARE", "SYSTEMATIC_SHARE",
           "FitFailed", "StiffFit", "budget_note", "check_inertia", "default_plant", "flat_profile",
           "hysteresis_gain", "judge_fit", "linear_mass_std", "noise_cost",
           "plausibility_warnings", "robust_least_squares", "systematic_share",
           "viscous_direction", "viscous_direction_note"]

#: The finest integration step ``predict`` takes, in steps per record sample; a model that
#: needs more (a collapsed mass on a stiff link) is not a model ``predict`` can run
MAX_PREDICT_SUBSTEPS = 2000
#: A mass more than this factor from the records' linear estimate is reported ...
MASS_FACTOR = 2.0
#: ... and one off by more than this share of it and by more than :data:`MASS_SIGMAS` of
#: its robust standard error (the linear model's own bias on a measured axis: EMPS's friction
#: links' fits lie 1-2 % from it; LuGre's 86.6 kg lay 9 % and 35 standard errors below)
MASS_SHARE = 0.05
MASS_SIGMAS = 3.0
#: Inertia below this share of the force (``m a_rms / u_rms``) is not visible in the records
INERTIA_SHARE = 1e-3
#: A record whose best description by a model class leaves a systematic error above this
#: share of the signal's RMS is not of that class (the record checks that tell a spring's, a
#: damper's or a mass's record from a link's use it)
SYSTEMATIC_SHARE = 0.02
#: A fit whose systematic error exceeds this share of its signal's RMS (a link's force or a
#: stage's position) is no model: it is refused and nothing is saved, because on another
#: record of the same machine its error is a few times larger (measured on generated dampers
#: and piezos: a Dahl link on a damper's forces, 1.5 to 1.9 % on sines, predicted
#: earthquake-like histories at 92.3 to 94.8 %; a Bouc-Wen link on a piezo's positions, 1.8 %,
#: other records at 93 to 98 %; 2.8 to 15 % gave 47 to 90 %), while the right model with a
#: sensor's quantisation, resonance above the band, gain nonlinearity of 0.5 % and a little
#: creep leaves 0.3 to 0.9 % and predicts them at 98.5 to 99.9 %
PREDICT_SHARE = 0.0125


class FitFailed(RuntimeError):
    """An identification that produced no usable model (one line saying what failed).

    Examples
    --------
    >>> try:
    ...     raise FitFailed("the fit failed: its prediction is not finite")
    ... except RuntimeError as exc:   # the command line's error: one line, exit 2
    ...     print(exc)
    the fit failed: its prediction is not finite
    """


class StiffFit(FitFailed):
    """A fit whose model needs more integration steps per sample than ``predict`` takes (a
    link stiffer than the records resolve, or a mass collapsed): a Maxwell-slip link may be
    fitted again with fewer elements.

    Parameters
    ----------
    message : str
        The refusal, one line.
    steps : int, optional
        The integration steps per sample the model needs.
    mode_hz : float, optional
        Its fastest mode [Hz].

    Examples
    --------
    >>> exc = StiffFit("the fit failed: the identified model needs 3643 integration steps per "
    ...                "sample", steps=3643, mode_hz=3.6e5)
    >>> isinstance(exc, FitFailed), exc.steps, exc.mode_hz
    (True, 3643, 360000.0)
    """

    def __init__(self, message: str, steps: int | None = None,
                 mode_hz: float | None = None) -> None:
        super().__init__(message)
        self.steps = steps  # the integration steps per sample the model needs
        self.mode_hz = mode_hz  # its fastest mode [Hz]


def judge_fit(fit_rms: float, records: list[IORecord], predictions: list[NDArray[np.float64]],
              linear_rms: float | None, system, output_offset: bool) -> None:
    """Raise :class:`FitFailed` if the fit is no result.

    Parameters
    ----------
    fit_rms : float
        RMS simulation error of the fit over all records [m].
    records : list of IORecord
        The records.
    predictions : list of ndarray
        The fitted model's output for each record.
    linear_rms : float or None
        RMS simulation error of the best linear model on the same records (None: not known).
    system : OpenLoop
        The identified system as ``predict`` runs it.
    output_offset : bool
        An output offset was estimated (the output's own RMS is then about its mean).

    Raises
    ------
    FitFailed
        The fit is no result.
    BudgetError
        The check run of the identified model is above the memory budget (``--max-memory``):
        not a failed fit, a refusal naming the budget and its remedy.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(100) / 100.0
    >>> rec = IORecord(t, np.sin(t), 1e-3 * np.sin(t))
    >>> try:
    ...     judge_fit(1.0, [rec], [np.zeros(100)], None, None, False)
    ... except FitFailed as exc:
    ...     print(exc)
    the fit failed: its RMS error 1 m exceeds the output's own RMS 0.000519 m (predicting zero
    does better)
    """
    for rec, y in zip(records, predictions, strict=True):
        if not np.all(np.isfinite(y)):
            raise FitFailed(f"the fit failed: the identified model's prediction of {rec.name} "
                            f"is not finite")
    y_all = np.concatenate([rec.y for rec in records])
    own = float(np.std(y_all) if output_offset else np.sqrt(np.mean(y_all ** 2)))
    if not math.isfinite(fit_rms) or fit_rms > own:
        what = "its mean" if output_offset else "zero"
        raise FitFailed(f"the fit failed: its RMS error {fit_rms:.3g} m exceeds the output's "
                        f"own RMS {own:.3g} m (predicting {what} does better)")
    if linear_rms is not None and fit_rms > linear_rms * (1.0 + 1e-9):
        raise FitFailed(f"the fit failed: its RMS error {fit_rms:.3g} m exceeds the best "
                        f"linear model's {linear_rms:.3g} m")
    if system is None:
        return
    try:
        r = system.default_substeps(records[0].fs)
    except (ValueError, OverflowError, ArithmeticError) as exc:
        raise FitFailed(f"the fit failed: the identified model cannot be simulated "
                        f"({exc})") from None
    if r > MAX_PREDICT_SUBSTEPS:
        from motionhyst.time.openloop import STEPS_PER_MODE_PERIOD

        mode = r * records[0].fs / STEPS_PER_MODE_PERIOD
        raise StiffFit(f"the fit failed: the identified model needs {r} integration steps per "
                        f"sample (its fastest mode at {mode:.3g} Hz, {mode / records[0].fs:.3g} "
                        f"times the sampling rate: a link stiffer than the records resolve, or "
                        f"a mass collapsed); if the records show no inertia, use --plant "
                        f"quasi-static", steps=r, mode_hz=mode)
    rec = records[0]
    try:
        y = system.simulate(rec.t, rec.u, substeps=r).displacement
    except BudgetError as exc:  # the model may run: the budget refused its run
        raise BudgetError(f"the identified model's run of {rec.name} (the check that predict "
                          f"can run it): {exc.cause}", RECORDS_REMEDY) from None
    except (ValueError, ArithmeticError) as exc:  # the cause, not a library's argument
        raise FitFailed(f"the fit failed: the identified model cannot be simulated on "
                        f"{rec.name} ({getattr(exc, 'what', exc)})") from None
    if not np.all(np.isfinite(y)):
        raise FitFailed(f"the fit failed: the identified model's simulation of {rec.name} "
                        f"from rest is not finite")


def plausibility_warnings(estimates: dict[str, float], masses: dict[str, float],
                          linear_mass: float, records: list[IORecord],
                          at_bound: list[str], runaway: dict[str, float] | None = None,
                          floating: bool | None = None) -> list[str]:
    """One line for each implausible estimate, naming the parameter.

    Parameters
    ----------
    estimates : dict
        The estimates by name.
    masses : dict
        The plant's masses by name (``{"m": ..}`` or ``{"m1": .., "m2": ..}``).
    linear_mass : float
        The records' linear estimate of the total mass [kg]; NaN where the records'
        linear model does not explain their force
        (:func:`~motionhyst.identify.io_start.reference_mass`): no mass compared.
    records : list of IORecord
        The records (for the inertia they show: ``m`` times the RMS acceleration).
    at_bound : list of str
        Names of the parameters that ended at a bound of the search.
    runaway : dict, optional
        Parameters (without bounds) that ended orders of magnitude from their start:
        name -> final over start value.
    floating : bool, optional
        The plant has no spring (a positioning axis): the linear estimate's model
        (:func:`~motionhyst.identify.io_start.inverse_dynamics`: mass, viscous and Coulomb
        friction, offset) is then the axis's own, and a mass off it by more than
        :data:`MASS_SHARE` and by more than :data:`MASS_SIGMAS` of its robust standard
        error (:func:`linear_mass_std`) is reported too.  On a stage held by a spring a
        link's force biases that estimate (a generated Bouc-Wen stage's true 2 kg against
        1.63 kg): there, and when not given, only a mass beyond :data:`MASS_FACTOR`.

    Returns
    -------
    list of str

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 1000.0
    >>> rec = IORecord(t, 10 * np.sin(2 * np.pi * t), 1e-3 * np.sin(2 * np.pi * t))
    >>> for line in plausibility_warnings({"m": 1e-9}, {"m": 1e-9}, 2.0, [rec], []):
    ...     print(line)
    m = 1e-09 kg is 2e+09 times below the records' linear estimate 2 kg
    m = 1e-09 kg: the inertia is not visible in these records (m times the RMS acceleration is
    3.9e-12 of the force's RMS); a quasi-static plant (--plant quasi-static) describes them
    >>> for line in plausibility_warnings({"m": 2e6}, {"m": 2e6}, 2e6, [rec], []):
    ...     print(line)                                 # the same record, its time in ms
    m = 2e+06 kg, outside the usual 0.001-10000 kg of motion stages: if the records' units are
    not SI, scale them (time in ms makes the mass 1e6 times too large, a position in mm or a
    force in kN 1e3 times too small)
    """
    out = []
    total = float(sum(masses.values()))
    names = "+".join(masses)
    if linear_mass > 0 and total > 0:
        ratio = total / linear_mass
        word = "above" if ratio > 1 else "below"
        if ratio > MASS_FACTOR or ratio < 1.0 / MASS_FACTOR:
            factor = ratio if ratio > 1 else 1.0 / ratio
            out.append(f"{names} = {total:.4g} kg is {factor:.3g} times {word} the records' "
                       f"linear estimate {linear_mass:.4g} kg")
        elif floating and abs(ratio - 1.0) > MASS_SHARE:
            std = linear_mass_std(records, floating)
            if abs(total - linear_mass) > MASS_SIGMAS * std:
                out.append(f"{names} = {total:.4g} kg is {100 * abs(ratio - 1.0):.2g} % "
                           f"{word} the records' linear estimate {linear_mass:.4g} +- "
                           f"{std:.2g} kg ({abs(total - linear_mass) / std:.3g} standard "
                           f"errors): the model may trade inertia for a force it "
                           f"describes poorly")
    a_rms = math.sqrt(np.mean(np.concatenate(
        [np.diff(rec.y, 2) * rec.fs ** 2 for rec in records]) ** 2))
    u_rms = math.sqrt(np.mean(np.concatenate([rec.u - np.mean(rec.u) for rec in records]) ** 2))
    share = total * a_rms / u_rms if u_rms > 0 else math.inf
    if share < INERTIA_SHARE:
        out.append(f"{names} = {total:.4g} kg: the inertia is not visible in these records "
                   f"({names} times the RMS acceleration is {share:.2g} of the force's RMS); "
                   f"a quasi-static plant (--plant quasi-static) describes them")
    else:  # a mass the records show: its size may betray a unit
        out += _unit_slip(names, total)
    for name in at_bound:
        out.append(f"{name} = {estimates[name]:.4g} ended at a bound of the search: the records "
                   f"push it beyond the model's range")
    for name, ratio in (runaway or {}).items():
        word = "above" if ratio > 1 else "below"
        out.append(f"{name} = {estimates[name]:.4g} ran {max(ratio, 1 / ratio):.2g} times "
                   f"{word} its start: the records do not hold it (at the edge of the model's "
                   f"range; a physically meaningless value)")
    return out


def _unit_slip(names: str, total: float) -> list[str]:
    """A mass outside the usual ones of motion stages, as a measured plant's is checked
    (:data:`~motionhyst.plants.frf_fit.PLAUSIBLE_MASS_KG`): a unit slip in the records, or a
    stage lighter than a gram (a flexure, a MEMS device) or heavier than ten tonnes."""
    from motionhyst.plants.frf_fit import PLAUSIBLE_MASS_KG

    low, high = PLAUSIBLE_MASS_KG
    if total <= 0 or low <= total <= high:
        return []
    return [f"{names} = {total:.4g} kg, outside the usual {low:g}-{high:g} kg of motion stages: "
            f"if the records' units are not SI, scale them (time in ms makes the mass 1e6 "
            f"times too large, a position in mm or a force in kN 1e3 times too small)"]


def linear_mass_std(records: list[IORecord], floating: bool) -> float:
    """The robust standard error of the records' linear estimate of the mass
    (:func:`~motionhyst.identify.io_start.reference_mass`): Newey-West, as
    :func:`check_inertia`'s (the residuals of a linear model of a link are no white noise).

    Parameters
    ----------
    records : list of IORecord
        The records.
    floating : bool
        No spring to the ground.

    Returns
    -------
    float
        [kg]

    Examples
    --------
    >>> t = np.arange(3000) / 1000.0
    >>> y = 0.05 * np.sin(2 * np.pi * t) + 0.02 * np.sin(2 * np.pi * 3.3 * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 2.0 * np.gradient(v, t, edge_order=2) + 30.0 * v + 4.0 * np.sign(v)
    >>> noise = 0.05 * np.random.default_rng(0).standard_normal(t.size)
    >>> 0.0 < linear_mass_std([IORecord(t, u + noise, y)], floating=True) < 0.01
    True
    """
    from motionhyst.identify.io_start import equation_rows

    rows, rhs = equation_rows(records, floating)
    _, cov = robust_least_squares(rows, rhs, max(7, 2 * round(0.005 * records[0].fs) + 1))
    return math.sqrt(max(float(cov[0, 0]), 0.0))


def systematic_share(residual: NDArray[np.float64], signal: NDArray[np.float64]) -> float:
    """The fit's systematic error: its residual's RMS beyond white noise, as a share of the
    signal's RMS about its mean.

    The noise is estimated from the residual's differences between successive samples
    (``sigma^2 = mean(diff(r)^2) / 2``: white noise doubles its variance in a difference,
    an error that changes little over a sample cancels), the systematic error is what
    remains, ``sqrt(mean(r^2) - sigma^2)``.  A record sampled coarsely (an error that
    changes much over a sample) counts more of it as noise: the share errs low.

    Parameters
    ----------
    residual : ndarray
        The measured signal minus the fitted model's.
    signal : ndarray
        The measured signal.

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 10.0, 5000)
    >>> f = np.sin(2 * np.pi * t)
    >>> noise = 0.05 * np.random.default_rng(0).standard_normal(t.size)
    >>> round(systematic_share(noise, f + noise), 3)           # noise only
    0.0
    >>> round(systematic_share(noise + 0.03 * f, f + noise), 3)   # and 3 % the model misses
    0.03
    """
    r = np.asarray(residual, dtype=float)
    y = np.asarray(signal, dtype=float)
    spread = float(np.std(y))
    if r.size < 3 or spread == 0:
        return 0.0
    noise = float(np.mean(np.diff(r) ** 2)) / 2.0
    return math.sqrt(max(float(np.mean(r ** 2)) - noise, 0.0)) / spread


#: A link's fit must explain at least this many times the noise's variance beyond the
#: linear model's (a spring, and a damper where the model has one); below, the records show
#: no hysteresis (a link with p parameters fitted to noise alone explains about p of them)
NO_HYSTERESIS_GAIN = 100.0


def hysteresis_gain(linear_ss: float, residual: NDArray[np.float64]) -> float:
    """What a link's fit explains beyond the linear model's, in units of the noise's variance.

    ``(RSS_lin - sum(r^2)) / sigma^2``, the noise's variance ``sigma^2`` from the
    fit's residual's differences between successive samples (as in
    :func:`systematic_share`).  A fit to records without hysteresis (a spring and noise)
    gains about its link's number of parameters; below :data:`NO_HYSTERESIS_GAIN` the
    records show none, and a link's parameters would be a guess.

    Parameters
    ----------
    linear_ss : float
        The sum of squares of the measured signal minus the best linear model's (a spring,
        a damper, an offset).
    residual : ndarray
        The measured signal minus the fit's.

    Returns
    -------
    float

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = np.sin(np.linspace(0.0, 20.0, 2000))
    >>> noise = 0.01 * rng.standard_normal(x.size)
    >>> hysteresis_gain(np.sum(noise ** 2), 0.999 * noise)        # a spring and noise
    3.9...
    >>> friction = 0.05 * np.sign(np.cos(np.linspace(0.0, 20.0, 2000)))
    >>> hysteresis_gain(np.sum((noise + friction) ** 2), noise) > NO_HYSTERESIS_GAIN
    True
    """
    r = np.asarray(residual, dtype=float)
    noise = float(np.mean(np.diff(r) ** 2)) / 2.0 if r.size > 2 else 0.0
    gain = float(linear_ss) - float(np.sum(r ** 2))
    return gain / noise if noise > 0 else (math.inf if gain > 0 else 0.0)


def check_inertia(records: list[IORecord]) -> float:
    """Refuse records that show no inertia, before a stage with a mass is fitted to them.

    The records' inverse-dynamics estimate (least squares on ``u = m y'' + c y' +
    k y + f sign(y') + u0``: a spring, the ground's or a link's that sticks, and
    Coulomb friction, whatever the stage;
    :func:`~motionhyst.identify.io_start.inverse_dynamics`) gives the mass ``m``
    and its inertial force ``m y''`` (the rates from Savitzky-Golay filters of
    10 ms and of 7 and 5 samples: a wide filter loses the acceleration of content
    near the Nyquist frequency, a narrow one takes more noise).  A mass that is not
    positive, or whose force is below :data:`INERTIA_SHARE` of the force's RMS,
    with every filter, is no inertia these records show: a fit would drive it
    towards zero, minutes of search for a model ``predict`` cannot run.  A piezo
    actuator's record or a friction damper's (or a force-displacement record read
    as input-output) give a negative mass: the link's lag, stiffer at the higher
    rates, looks like one.  The message gives the mass with its standard error,
    robust to the residuals' correlation (Newey-West: the link's hysteresis is no
    white noise, and the ordinary standard error is 3-7 times too small).  The sign
    decides, not a significance: a short record of a two-mass stage (256 samples,
    its mode in the band) gives a mass only 0.4 standard errors above zero.

    Parameters
    ----------
    records : list of IORecord
        The records (force in, position out).

    Returns
    -------
    float
        The inverse-dynamics mass that shows the inertia [kg]
        (:func:`~motionhyst.identify.io_consistency.mass_units_note` judges its size).

    Raises
    ------
    ValueError
        One line: the mass and its standard error, and the plant or record kind that
        describes such records.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(2000) / 1000.0
    >>> y = 1e-3 * np.sin(2 * np.pi * 3 * t) + 4e-4 * np.sin(2 * np.pi * 17 * t)
    >>> a = np.gradient(np.gradient(y, t), t)
    >>> round(check_inertia([IORecord(t, 2.0 * a + 5e4 * y, y, "stage.csv")]), 2)
    2.0
    >>> try:                                   # stiffer at 17 Hz than at 3 Hz: no mass
    ...     check_inertia([IORecord(t, 5e4 * y + 2e6 * (y - np.convolve(y, np.ones(25) / 25,
    ...                                                             "same")), y, "piezo.csv")])
    ... except ValueError as exc:
    ...     print(str(exc)[:34])
    piezo.csv: no inertia in the force
    """
    from motionhyst.identify.io_start import equation_rows

    u = np.concatenate([rec.u - np.mean(rec.u) for rec in records])
    u_rms = math.sqrt(float(np.mean(u ** 2)))
    found = []
    for window in (None, 7, 5):
        rows, rhs = equation_rows(records, floating=True, window=window, light=True)
        rows = [np.column_stack([r, rec.y]) for r, rec in zip(rows, records, strict=True)]
        m, std = _mass_and_std(rows, rhs, max(7, 2 * round(0.005 * records[0].fs) + 1))
        a_rms = math.sqrt(float(np.mean(np.concatenate([r[:, 0] for r in rows]) ** 2)))
        if m > 0 and m * a_rms > INERTIA_SHARE * u_rms:
            return m
        found.append((m, std, m * a_rms / u_rms if u_rms > 0 else 0.0))
    m, std, share = found[0]
    why = "not positive" if m <= 0 else f"m y'' is {share:.2g} of the force's RMS"
    names = records[0].name if len(records) == 1 else f"{records[0].name} and the others"
    raise ValueError(f"{names}: no inertia in the force (its inverse-dynamics mass "
                     f"{m:.3g} +- {std:.2g} kg: {why}): no stage with a mass fits; a stage "
                     f"without inertia (a piezo actuator, a damper) is --plant quasi-static, a "
                     f"link's force against an imposed displacement is identified without "
                     f"--record input-output")


def _mass_and_std(rows: list[NDArray[np.float64]], rhs: list[NDArray[np.float64]],
                  window: int) -> tuple[float, float]:
    """The least-squares coefficient of the first column and its Newey-West standard error
    (:func:`robust_least_squares`)."""
    x, cov = robust_least_squares(rows, rhs, window)
    return float(x[0]), math.sqrt(max(float(cov[0, 0]), 0.0))


def robust_least_squares(rows: list[NDArray[np.float64]], rhs: list[NDArray[np.float64]],
                         window: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The least-squares coefficients and their Newey-West covariance (Bartlett weights within
    each record, :func:`~motionhyst.identify.residual_noise.bartlett_sum`, over each lag count
    of :func:`~motionhyst.identify.residual_noise.newey_west_lags` for its residuals, each
    variance the largest: :func:`~motionhyst.identify.residual_noise.widest_covariance`):
    standard errors that hold for residuals correlated over time (a model's error, a filtered
    noise), never narrower than white residuals' or the fixed ``max(4 n^(1/3), window)``
    lags' that the checks' thresholds were measured with.

    Parameters
    ----------
    rows : list of ndarray
        Each record's regressors, one row a sample.
    rhs : list of ndarray
        Each record's observations.
    window : int
        The fewest lags of the Bartlett weights (the samples a residual is correlated over).

    Returns
    -------
    coefficients, covariance : ndarray

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 200)
    >>> A = np.column_stack([t, np.ones_like(t)])
    >>> b = 2.0 * t + 0.5 + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    >>> x, cov = robust_least_squares([A], [b], 7)
    >>> np.round(x, 2).tolist(), bool(np.sqrt(cov[0, 0]) < 0.01)
    ([2.0, 0.5], True)
    """
    As = np.concatenate(rows, dtype=np.float64)  # a copy: scaled in place
    scale = np.linalg.norm(As, axis=0)
    scale[scale == 0] = 1.0
    As /= scale
    with few_blas_threads(*As.shape):  # a small fit: the threads cost more than the work
        x = np.linalg.lstsq(As, np.concatenate(rhs), rcond=None)[0]
        cov = np.linalg.pinv(As.T @ As)
        meats = [np.zeros_like(cov) for _ in range(3)]  # none, fixed and Andrews' lags
        start = 0
        for b in rhs:  # each record's own sums (residual_noise.bartlett_sum)
            n = b.size
            e = b - As[start:start + n] @ x
            xe = As[start:start + n] * e[:, None]
            start += n
            for meat, lags in zip(meats, newey_west_lags([e], window), strict=True):
                meat += bartlett_sum(xe, bartlett_weights(lags))
        covs = [cov @ meat @ cov for meat in meats]
        return x / scale, widest_covariance(covs) / np.outer(scale, scale)


#: A start whose cost is within this factor of the records' noise (from their repeated
#: periods) ends the search for starts
NOISE_COST_FACTOR = 1.1


def noise_cost(records: list[IORecord], y_scale: float) -> float | None:
    """The least-squares cost that the records' noise alone leaves, times
    :data:`NOISE_COST_FACTOR`: a fit at this cost explains all but the noise.

    The cost is half the sum of squared residuals in units of `y_scale`; the
    noise's variance comes from the spread of the periods of periodic records
    about their mean.

    Parameters
    ----------
    records : list of IORecord
        Periodic records (their input repeats).
    y_scale : float
        The output's unit of the cost [m].

    Returns
    -------
    float or None
        None if a record holds fewer than two periods.

    Examples
    --------
    >>> t = np.arange(400) / 100.0
    >>> u = np.tile(np.sin(2 * np.pi * np.arange(100) / 100), 4)
    >>> y = u + 0.01 * np.random.default_rng(0).standard_normal(400)
    >>> c = noise_cost([IORecord(t, u, y)], 1.0)
    >>> 0.5 * 400 * 0.01 ** 2 * 0.8 < c < 0.5 * 400 * 0.01 ** 2 * 1.4
    True
    """
    from motionhyst.time.periodic_runs import whole_periods

    total = 0.0
    for rec in records:
        p = whole_periods(rec.u)
        if p < 2:
            return None
        n = rec.u.size // p
        y = rec.y[:p * n].reshape(p, n)
        variance = float(np.sum((y - np.mean(y, axis=0)) ** 2)) / (n * (p - 1))
        total += rec.y.size * variance
    return 0.5 * NOISE_COST_FACTOR * total / y_scale ** 2


#: 95 % point of the chi-square distribution with one degree of freedom
PROFILE_CHI2 = 3.84


def flat_profile(costs: list[float], dof: int) -> bool:
    """True if no cost of a profile exceeds the least by the 95 % likelihood-ratio bound:
    the profiled parameter is not determined by the records.

    ``(RSS_i - RSS_min) / sigma^2 < 3.84`` for every point, ``sigma^2 = RSS_min / dof``.

    Parameters
    ----------
    costs : list of float
        The fit's residual sum of squares at each value of the profiled parameter.
    dof : int
        The fit's degrees of freedom (residuals less parameters).

    Returns
    -------
    bool

    Examples
    --------
    >>> flat_profile([1.000, 1.001, 1.002], dof=1000), flat_profile([1.0, 1.5], dof=1000)
    (True, False)
    """
    least = min(costs)
    return bool(least > 0 and (max(costs) - least) / least * max(dof, 1) < PROFILE_CHI2)


#: Viscous friction by direction is reported when its two coefficients differ by more than this
#: many (robust) standard errors of their difference ...
DIRECTION_SIGNIFICANCE = 3.0
#: ... and by more than this share of their mean (a difference that biases a symmetric fit)
DIRECTION_SHARE = 0.1
#: Samples slower than this share of the velocity's RMS are left out of that comparison: where
#: the axis sticks, turns or breaks away, friction is no function of the velocity (a LuGre link
#: driven 2.5-3 times faster one way than the other, symmetric, showed a difference of 60-130
#: N s/m with 0.1 of the RMS, none beyond its standard error with 0.3; EMPS the same 75 N s/m)
DIRECTION_MOVING = 0.3
#: Each direction must hold at least this share of the samples compared (a direction driven 3
#: times faster than the other passes the slower one's speeds in 6 % of them)
DIRECTION_SAMPLES = 0.02
#: The speeds compared reach the slower direction's quantile of this level (not one sample's
#: peak, where the other direction would be compared with itself alone)
DIRECTION_TOP = 0.99
#: Nodes of the piecewise-linear friction curve ``f(|v|) sign(v)`` fitted with the difference
DIRECTION_NODES = 6


def viscous_direction(records: list[IORecord]
                      ) -> dict[str, float | tuple[float, float]] | None:
    """The difference of a positioning axis's viscous friction between its directions, as the
    records show it at the speeds both directions cover, with its standard error.

    Friction that depends on the speed in any way the same in both directions (the
    Stribeck effect: higher at low speed) is an odd function of the velocity, ``f(|v|)
    sign(v)``; viscous friction by direction (Janot et al. 2019, eq. 12: ``c_pos`` moving
    forward, ``c_neg`` backward) adds an even part ``(c_pos - c_neg) / 2 |v|``, and a
    force offset or Coulomb forces by direction a constant.  The inverse dynamics
    (:func:`~motionhyst.identify.io_start.equation_rows`) ``u = m y'' + f(|y'|) sign(y') +
    (c_pos - c_neg) / 2 |y'| + u0``, ``f`` piecewise linear in the speed
    (:data:`DIRECTION_NODES` nodes at its quantiles), one linear solve, tells the two
    apart only over the band of speeds both directions cover: from :data:`DIRECTION_MOVING`
    of the velocity's RMS (slower, the axis sticks, turns or breaks away) to the slower
    direction's :data:`DIRECTION_TOP` quantile.  Compared at other speeds (the direction
    driven faster is seen where the Stribeck curve is flat, the slower one where it falls)
    the curve's shape would read as a difference.  The standard error is robust to the
    residuals' correlation (Newey-West, as :func:`check_inertia`).  The mean coefficient
    ``c`` is the one-coefficient inverse dynamics' on the moving samples with that even
    part taken out.

    Parameters
    ----------
    records : list of IORecord
        Records of a positioning axis (a mass-damper: force in, position out).

    Returns
    -------
    dict or None
        ``c_pos``, ``c_neg``, ``difference`` (``c_pos - c_neg``), ``std`` (its standard
        error), ``c`` (the mean), ``band`` (lowest and highest speed compared [m/s]); None
        when a direction holds fewer than :data:`DIRECTION_SAMPLES` of the samples in the
        band (nothing to compare).

    Examples
    --------
    >>> t = np.arange(4000) / 1000.0
    >>> y = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(6 * np.pi * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 95 * np.gradient(v, t, edge_order=2) + 160 * v + 20 * np.sign(v)
    >>> noise = np.random.default_rng(0).standard_normal(t.size)
    >>> est = viscous_direction([IORecord(t, u + 80 * np.minimum(v, 0) + noise, y)])
    >>> round(est["difference"], 1), round(est["std"], 1), round(est["c"], 1)
    (-80.2, 0.3, 200.1)
    """
    from motionhyst.identify.io_start import equation_rows

    if not records or any(rec.y.size < 16 for rec in records):
        return None
    rows, rhs = equation_rows(records, floating=True, asymmetric=True)
    velocities = [r[:, 1] + r[:, 2] for r in rows]  # columns: y'', max(y', 0), min(y', 0), ..
    v = np.concatenate(velocities)
    low = DIRECTION_MOVING * math.sqrt(float(np.mean(v ** 2)))
    if not (np.sum(v > low) and np.sum(v < -low)):
        return None
    high = min(float(np.quantile(v[v > low], DIRECTION_TOP)),
               float(np.quantile(-v[v < -low], DIRECTION_TOP)))
    speed = np.abs(v)
    band = (speed > low) & (speed <= high)
    if min(np.sum(band & (v > 0)), np.sum(band & (v < 0))) < max(
            DIRECTION_SAMPLES * np.sum(band), DIRECTION_NODES + 4):
        return None  # one direction barely seen at the other's speeds: nothing to compare
    nodes = np.quantile(speed[band], np.linspace(0.0, 1.0, DIRECTION_NODES))
    nodes[0], nodes[-1] = low, high
    shapes = np.eye(DIRECTION_NODES)
    compared, forces = [], []
    for r, b, vel in zip(rows, rhs, velocities, strict=True):
        s = np.abs(vel)
        inside = (s > low) & (s <= high)
        cols = np.empty((int(np.sum(inside)), 3 + DIRECTION_NODES))  # filled, not stacked
        cols[:, 0], cols[:, 1], cols[:, 2] = r[inside, 0], s[inside], 1.0
        sign = np.sign(vel[inside])
        for i, shape in enumerate(shapes):
            cols[:, 3 + i] = np.interp(cols[:, 1], nodes, shape) * sign
        compared.append(cols)
        forces.append(b[inside])
    x, cov = robust_least_squares(compared, forces,
                                   max(7, 2 * round(0.005 * records[0].fs) + 1))
    even, even_std = float(x[1]), math.sqrt(max(float(cov[1, 1]), 0.0))
    moving = speed > low  # the one-coefficient inverse dynamics, that even part taken out
    A = np.column_stack([np.concatenate([r[:, 0] for r in rows]), v, np.sign(v),
                         np.ones_like(v)])[moving]
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    b = np.concatenate(rhs)[moving] - even * speed[moving]
    c = float(np.linalg.lstsq(A / scale, b, rcond=None)[0][1] / scale[1])
    return {"c_pos": c + even, "c_neg": c - even, "difference": 2.0 * even,
            "std": 2.0 * even_std, "c": c, "band": (low, high)}


def viscous_direction_note(records: list[IORecord]) -> str | None:
    """A warning when the records' viscous friction differs by direction: the mass of a fit
    with one viscous coefficient is biased then.

    The difference and its standard error at the speeds both directions cover
    (:func:`viscous_direction`: friction that depends on the speed alike both ways, the
    Stribeck effect, is no difference, however differently the two directions were
    driven); beyond :data:`DIRECTION_SIGNIFICANCE` standard errors and
    :data:`DIRECTION_SHARE` of the mean coefficient it is reported, with the option that
    estimates it (``--asymmetric``), unless a coefficient comes out negative (a damper that
    drives the axis is no friction: a short record whose directions share a narrow band of
    speeds).  On EMPS: c+ 158, c- 234 N s/m.

    Parameters
    ----------
    records : list of IORecord
        Records of a positioning axis (a mass-damper: force in, position out).

    Returns
    -------
    str or None
        The warning's line, or None.

    Examples
    --------
    >>> t = np.arange(4000) / 1000.0
    >>> y = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(6 * np.pi * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 95 * np.gradient(v, t, edge_order=2) + 160 * v + 20 * np.sign(v)
    >>> noise = np.random.default_rng(0).standard_normal(t.size)
    >>> viscous_direction_note([IORecord(t, u + noise, y)]) is None
    True
    >>> print(viscous_direction_note([IORecord(t, u + 80 * np.minimum(v, 0) + noise, y)]))
    the records' inverse dynamics (IDIM-LS) gives viscous friction by direction, c+ 160 and
    c- 240.2 N s/m (difference 80.2 +- 0.33 at the speeds both directions cover, 56.5-377
    mm/s): a fit with one viscous coefficient biases the mass; --asymmetric estimates one per
    direction
    """
    est = viscous_direction(records)
    if est is None:
        return None
    diff, std, mean = est["difference"], est["std"], est["c"]
    if not (mean > 0 and abs(diff) > DIRECTION_SIGNIFICANCE * std
            and abs(diff) > DIRECTION_SHARE * mean):
        return None
    if not (est["c_pos"] > 0 and est["c_neg"] > 0):  # a damper that drives: no friction
        return None
    low, high = est["band"]
    return (f"the records' inverse dynamics (IDIM-LS) gives viscous friction by direction, "
            f"c+ {est['c_pos']:.4g} and c- {est['c_neg']:.4g} N s/m (difference {abs(diff):.3g}"
            f" +- {std:.2g} at the speeds both directions cover, {1e3 * low:.3g}-"
            f"{1e3 * high:.3g} mm/s): a fit with one viscous coefficient biases the mass; "
            f"--asymmetric estimates one per direction")


def budget_note(evaluations: int) -> str:
    """The warning of a search that stopped on its budget of model evaluations.

    Parameters
    ----------
    evaluations : int
        The model evaluations the search used in all.

    Returns
    -------
    str
        One line naming ``--max-evaluations``.

    Examples
    --------
    >>> budget_note(200)[:68]
    'the search stopped on its budget of model evaluations (200 used) bef'
    """
    return (f"the search stopped on its budget of model evaluations ({evaluations} used) before "
            f"it converged: the estimates may still move; a larger --max-evaluations lets it "
            f"finish")


SPRING_SHARE = 0.1
"""A spring to the ground is seen in records where, added to a floating stage's inverse
dynamics (mass, viscous and Coulomb friction, force offset), it carries at least this share of
the force's spread.  Measured: the EMPS axis 0.006; generated axes with Coulomb, Jenkins and
Bouc-Wen friction 0.003-0.04; stages on springs of 1e3-1e5 N/m with Coulomb friction 0.75-1.2;
the Bouc-Wen benchmark's stage 1.7."""


def default_plant(records: list[IORecord]) -> tuple[str, str | None]:
    """The stage records from a start call for when none is named, and why.

    A positioning axis (a mass on guides: friction holds it, no spring) is a
    mass-damper; fitted as a mass-spring-damper its spring is not determined, a
    force offset is only a position offset ``u0 / k`` and the mass takes up what
    is left.  The records say which: least squares on ``u = m y'' + c y' + f
    sign(y') + k (y - mean y) + u0`` (:func:`~motionhyst.identify.io_start.equation_rows`);
    a spring whose force ``k (y - mean y)`` is below :data:`SPRING_SHARE` of the
    force's spread, where the floating model explains the force
    (:data:`~motionhyst.identify.io_start.LINEAR_MODEL_RESIDUAL`), is none.

    Parameters
    ----------
    records : list of IORecord
        The records (force in, position out), from a start.

    Returns
    -------
    plant : str
        ``"mass-damper"`` or ``"mass-spring-damper"`` (the default otherwise).
    note : str or None
        For the mass-damper, one line saying why (for the user: it was not named).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> y = 0.05 * np.sin(2 * np.pi * t) + 0.02 * np.sin(2 * np.pi * 3.3 * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 2.0 * np.gradient(v, t, edge_order=2) + 30.0 * v + 4.0 * np.sign(v) - 1.5
    >>> default_plant([IORecord(t, u, y)])[0]
    'mass-damper'
    >>> default_plant([IORecord(t, u + 400.0 * y, y)])[0]   # a spring of 400 N/m
    'mass-spring-damper'
    """
    from motionhyst.identify.io_start import LINEAR_MODEL_RESIDUAL, equation_rows

    rows, rhs = equation_rows(records, floating=True, light=True)
    A = np.concatenate([np.column_stack([r, rec.y - np.mean(rec.y)])
                        for r, rec in zip(rows, records, strict=True)])
    u = np.concatenate(rhs)
    spread = float(np.linalg.norm(u - np.mean(u)))
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    both = np.linalg.lstsq(A / scale, u, rcond=None)[0] / scale
    floating = np.linalg.lstsq(A[:, :-1] / scale[:-1], u, rcond=None)[0] / scale[:-1]
    if not (spread > 0 and np.all(np.isfinite(both))):
        return "mass-spring-damper", None
    share = float(np.linalg.norm(A[:, -1] * both[-1])) / spread
    unexplained = float(np.linalg.norm(A[:, :-1] @ floating - u)) / spread
    if share >= SPRING_SHARE or unexplained > LINEAR_MODEL_RESIDUAL:
        return "mass-spring-damper", None
    return "mass-damper", (f"the records show no spring (one would carry {100 * share:.2g} % "
                           f"of the force; friction and inertia explain all but "
                           f"{100 * unexplained:.2g} %): a positioning axis, identified on "
                           f"--plant mass-damper with its force offset; --plant "
                           f"mass-spring-damper fits a spring")
