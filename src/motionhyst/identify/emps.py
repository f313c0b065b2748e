"""The EMPS benchmark: a measured positioning axis with friction, identified and scored.

A. Janot, M. Gautier and M. Brunot, "Data Set and Reference Models of EMPS",
Workshop on Nonlinear System Identification Benchmarks, Eindhoven, 2019
(nonlinearbenchmark.org, "EMPS").  A DC motor drives a load through a ball
screw, in closed loop at 1 kHz; the records hold the controller's output
``vir`` [V] (the force on the load is ``F = gtau vir``, ``gtau = 35.15065`` N/V)
and the measured position ``qm`` [m].  The benchmark's reference model
(inverse-dynamics least squares, IDIM-LS) is

.. math::

    M \\ddot q = F - F_v \\dot q - F_c \\operatorname{sign}(\\dot q) - OF,

a mass with viscous and Coulomb friction and a force offset ``OF``.

The benchmark's metric: the position simulated from the force alone (open
loop) over the whole test record, the first :data:`INIT_WINDOW` samples used
only to set the model's initial state; the RMS error in mm of ``qm`` over
samples ``n >= 20`` and the fit ``100 (1 - ||y - yhat|| / ||y - mean(y)||)`` %
over the same samples (:func:`motionhyst.identify.io_predict.predict_from_window`).

:func:`run_emps` identifies each link model of :data:`MODELS` on a mass-damper
(the axis has no spring; friction is the link) from the estimation record by
simulation error, with the force offset estimated and the record's initial
state set from its first :data:`INIT_WINDOW` samples as the fit runs (the
model is fitted the way the metric runs it), then scores it on the test
record (``DATA_EMPS_PULSES.mat``, the same reference with force pulses added;
published separately by the benchmark) or, without it, on the periods of the
estimation record it was not identified from (the reference repeats every :data:`PERIOD` samples).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass, field, replace

import numpy as np

from motionhyst.core.warnings import MotionhystWarning
from motionhyst.identify._emps_cells import failed_table, friction, marked, offset, own, viscous
from motionhyst.identify.emps_files import COLUMNS, DRIVE_GAIN, ESTIMATION_FILE, PERIOD, TEST_FILE
from motionhyst.identify.emps_models import (
    OPTIONS,
    RIGID_LIMIT,
    check_model,
    model_options,
    unresolved_stiffness,
)
from motionhyst.identify.emps_reference import (
    PUBLISHED,
    REFERENCE_ASYMMETRIC,
    REFERENCE_MODEL,
    asymmetric_inverse_dynamics,
    equivalent_offset,
    fit_parameters,
    reference_form,
    reference_notes,
    reference_system,
)
from motionhyst.identify.emps_scores import own_offset_score, period_drift, score
from motionhyst.identify.emps_workers import map_in_workers
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_checks import MAX_PREDICT_SUBSTEPS, FitFailed
from motionhyst.identify.io_predict import INIT_WINDOW
from motionhyst.identify.io_start import inverse_dynamics

__all__ = ["CHOSEN", "COLUMNS", "DRIVE_GAIN", "ESTIMATION_FILE",
           "INIT_WINDOW", "MODELS", "PERIOD", "TEST_FILE",
           "EMPSBenchmark", "EMPSModel", "choose", "cross_validate", "own_offset_score",
           "period_drift", "run_emps", "score", "split_by_periods"]

MODELS = ("coulomb-asymmetric", "coulomb-asymmetric-drift", "jenkins-asymmetric")
"""Link models identified by default: friction of a positioning axis with viscous friction by
direction (``-asymmetric``, ``identify --asymmetric``: the structure of the benchmark's
asymmetric model, eq. 12 of its description; ``jenkins-asymmetric`` is the Jenkins link on a
mass-damper, fitted and scored with the 20-sample initialisation window), the Coulomb link also
with the force offset drifting in time from the record's start (``-drift``, ``identify
--drift``).  On the whole of ``DATA_EMPS`` the first and the third find 93.47 and 92.34 kg
(the Jenkins stiffness profiled: 1.4e6 N/m), within 3 % of the benchmark's 95.1 kg; the
drifting offset takes part of the inertia, 92.05 kg, 3.2 % low, which its warnings say
(:func:`~motionhyst.identify.emps_reference.reference_notes`).  Other models are given by name
(:func:`run_emps`'s `models`, ``benchmark emps --models``): ``jenkins-asymmetric-drift`` (a
stiffness the halves resolve, 3.1e6 and 1.0e7 N/m; 1.17 and 4.39 mm on the two splits, its
worse below ``coulomb-asymmetric-drift``'s, at about 2 min of CPU a fit), those
with one viscous coefficient (``"coulomb-symmetric"``, ``"jenkins-symmetric"``,
``"jenkins-symmetric-drift"``: 90.6-91.5 kg, the difference between the directions taken into
the mass), and those named by their link alone (``"jenkins"``), fitted as ``identify`` fits
them: by direction where the record shows it (this one does)."""
CHOSEN = "coulomb-asymmetric-drift"
"""The physical model whose test-record score is motionhyst's figure, chosen before the test by
the rule of :func:`choose` on the two splits of ``DATA_EMPS``, among :data:`MODELS`: the
smallest worse-split validation RMSE, 4.50 mm (``coulomb-asymmetric`` 6.11 mm,
``jenkins-asymmetric`` 7.2 mm)."""


def choose(runs: Sequence[EMPSBenchmark]) -> tuple[str, float] | None:
    """The model a rule stated in advance picks from runs on several splits: the smallest
    worse-split validation RMSE (a model is judged by the split it does worst on; one whose
    fit failed on a split is not chosen: its worse split has no figure).

    Parameters
    ----------
    runs : sequence of EMPSBenchmark
        The same models identified and validated on each split (:func:`cross_validate`).

    Returns
    -------
    (name, worst) or None
        The model chosen and its validation RMSE on the split it does worst on [mm]; None
        when every model failed on some split.

    Examples
    --------
    >>> def run(**rmse):
    ...     return EMPSBenchmark([EMPSModel(n, {}, {}, {}, {"rmse_mm": r}, 0.0)
    ...                           if r is not None else EMPSModel.failed(n, {}, {}, "no fit")
    ...                           for n, r in rmse.items()], None, None, False, {})
    >>> choose([run(a=1.0, b=3.0), run(a=5.0, b=3.5)])
    ('b', 3.5)
    >>> choose([run(a=1.0, b=3.0), run(a=2.0, b=None)])    # b failed on the second split
    ('a', 2.0)
    >>> choose([run(a=None), run(a=1.0)]) is None
    True
    """
    worst: dict[str, float] = {}
    for res in runs:
        for m in res.models:
            worst[m.name] = max(worst.get(m.name, 0.0),
                                np.inf if m.error is not None else float(m.validation["rmse_mm"]))
    scored = {name: rmse for name, rmse in worst.items() if np.isfinite(rmse)}
    if not scored:
        return None
    name = min(scored, key=scored.__getitem__)
    return name, scored[name]


def split_by_periods(record: IORecord, periods: tuple[int, int] = (1, 2),
                     period: int = PERIOD, name: str = "DATA_EMPS"
                     ) -> tuple[IORecord, IORecord]:
    """Split a record into whole periods for estimation and the rest for validation.

    Parameters
    ----------
    record : IORecord
        The estimation record.
    periods : (int, int)
        First and last period (1-based) to estimate from; the periods before
        and after them are validation records (the one that is not empty; a
        split in the middle is refused, it would make two).
    period : int
        Samples per period.
    name : str
        The record's name in the pieces' names (``"DATA_EMPS periods 1-2"``).

    Returns
    -------
    estimation, validation : IORecord
        Named after their periods (the last one counted even when it is not whole).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(24841) * 1e-3
    >>> est, val = split_by_periods(IORecord(t, np.sin(t), np.cos(t)))
    >>> est.name, est.t.size, val.name, val.t.size
    ('DATA_EMPS periods 1-2', 12480, 'DATA_EMPS periods 3-4', 12361)
    >>> split_by_periods(IORecord(t, np.sin(t), np.cos(t)), (3, 4))[1].name
    'DATA_EMPS periods 1-2'
    """
    n = record.t.size
    count = -(-n // period)
    first, last = (int(p) for p in periods)
    if not 1 <= first <= last <= count:
        raise ValueError(f"periods {first}-{last}: the record has periods 1-{count} of "
                         f"{period} samples")
    if first > 1 and last < count:
        raise ValueError(f"periods {first}-{last} leave periods on both sides; estimate from "
                         f"the first or the last periods")
    if first == 1 and last == count:
        raise ValueError("no period is left for validation")
    a, b = (first - 1) * period, min(last * period, n)
    est_slice, val_slice = slice(a, b), (slice(b, n) if first == 1 else slice(0, a))
    val_periods = (last + 1, count) if first == 1 else (1, first - 1)

    def piece(s: slice, p: tuple[int, int]) -> IORecord:
        label = f"{name} period {p[0]}" if p[0] == p[1] else f"{name} periods {p[0]}-{p[1]}"
        return IORecord(record.t[s], record.u[s], record.y[s], label)

    return piece(est_slice, (first, last)), piece(val_slice, val_periods)


@dataclass
class EMPSModel:
    """One link model on the mass-damper: its parameters and its scores.

    Attributes
    ----------
    name : str
        The link model (``"coulomb"``, ``"jenkins"``, ...).
    parameters, std : dict
        The model in the benchmark's reference model's form, comparable with its
        published parameters, and their standard errors (None: not determined by the
        record): ``m`` [kg], ``c`` [N s/m] (the odd part of viscous friction by
        direction), ``fc`` [N], ``offset`` (the constant force offset ``OF`` [N] the
        model amounts to on the estimation record's motion, the benchmark's sign: the
        plant receives ``F - OF``), and the link's parameters the reference model has
        no place for (``k``, ...) as they are
        (:func:`~motionhyst.identify.emps_reference.reference_form`).  For a model of
        the reference's own structure (``"coulomb"``) these are its own estimates.
    estimation, validation : dict
        ``{"record", "rmse_mm", "fit_percent"}``: the benchmark's metric on the
        record identified from and on the held-out one; the validation also has
        ``"own_offset": {"offset", "rmse_mm"}``, the same model with the force
        offset that suits the held-out record best (:func:`own_offset_score`): a
        diagnosis of how much of the error is the drift of the records' offset,
        not a score.
    seconds : float
        Identification and scoring [s].
    warnings : list of str
        The identification's plausibility warnings.
    prediction : ndarray or None
        The simulated position on the validation record [m] (for plots).
    equivalent_offset : float or None
        ``parameters["offset"]``: the constant offset ``OF`` the model's offset, its
        drift and its direction-dependent viscous friction amount to on the estimation
        record's motion (:func:`~motionhyst.identify.emps_reference.equivalent_offset`)
        [N].
    limit : str or None
        The model whose fit this one is at its limit of (a Jenkins link whose
        stiffness the record does not resolve,
        :func:`~motionhyst.identify.emps_models.unresolved_stiffness`, or ran to where
        ``predict`` cannot step it: the Coulomb link with the same options), or None.
    model_parameters, model_std : dict
        The model's own estimates and standard errors, as ``identify --save`` writes
        them (``offset`` its own force offset, ``c_pos``, ``c_neg``, ``c_skew``,
        ``drift``, ...); empty when not known.
    std_note : str or None
        Why the standard errors are lower bounds (the fit leaves more than the record's white
        noise, :func:`~motionhyst.identify.residual_noise.lower_bound_note`), or None.
    error : str or None
        Why the model's identification or scoring failed (one line), or None; a failed
        model (:meth:`failed`) has no parameters and its records' names alone as its
        estimation and validation.

    Examples
    --------
    >>> score_ = {"record": "DATA_EMPS periods 3-4", "rmse_mm": 6.1, "fit_percent": 92.6}
    >>> m = EMPSModel("coulomb", {"m": 91.3, "offset": -3.25}, {"m": 0.1, "offset": 0.01},
    ...               dict(score_, record="DATA_EMPS periods 1-2", rmse_mm=1.8), score_, 38.0)
    >>> print(m)
    coulomb: validation on DATA_EMPS periods 3-4 6.1 mm (92.60 %), estimation 1.8 mm
    >>> sorted(m.to_dict())
    ['estimation', 'name', 'parameters', 'seconds', 'std', 'validation']
    >>> bad = EMPSModel.failed("dahl", {"record": "DATA_EMPS periods 1-2"},
    ...                        {"record": "DATA_EMPS periods 3-4"}, "the fit failed: ...")
    >>> print(bad)
    dahl: failed on DATA_EMPS periods 1-2: the fit failed: ...
    >>> sorted(bad.to_dict())
    ['error', 'estimation', 'name', 'seconds', 'validation']
    """

    name: str
    parameters: dict[str, float]
    std: dict[str, float | None]
    estimation: dict
    validation: dict
    seconds: float
    warnings: list[str] = field(default_factory=list)
    prediction: np.ndarray | None = field(default=None, repr=False)
    equivalent_offset: float | None = None
    limit: str | None = None
    model_parameters: dict[str, float] = field(default_factory=dict)
    model_std: dict[str, float | None] = field(default_factory=dict)
    std_note: str | None = None
    error: str | None = None

    @classmethod
    def failed(cls, name: str, estimation: dict, validation: dict, error: str,
               seconds: float = 0.0) -> EMPSModel:
        """A model whose identification or scoring failed, and why.

        Parameters
        ----------
        name : str
            The model's name.
        estimation, validation : dict
            ``{"record": name}`` of the records it was to be identified from and scored on.
        error : str
            Why it failed (one line).
        seconds : float
            The time it took to fail [s].

        Returns
        -------
        EMPSModel
            With :attr:`error` set, no parameters.

        Examples
        --------
        >>> EMPSModel.failed("lugre", {"record": "a"}, {"record": "b"}, "no fit").error
        'no fit'
        """
        return cls(name, {}, {}, dict(estimation), dict(validation), seconds, error=error)

    def to_dict(self) -> dict:
        """``{"name", "parameters", "std", "estimation", "validation", "seconds"}``, and
        ``"model_parameters"``, ``"model_std"`` and ``"equivalent_offset"`` when known,
        ``"limit"`` when the model is at one, ``"std_lower_bound"`` (True) and ``"std_note"``
        when the standard errors are lower bounds, ``"warnings"`` when there are any; a
        failed model: ``{"name", "error", "estimation", "validation", "seconds"}``, the two
        records by name alone."""
        if self.error is not None:
            return {"name": self.name, "error": self.error,
                    "estimation": {"record": self.estimation.get("record")},
                    "validation": {"record": self.validation.get("record")},
                    "seconds": self.seconds}
        out = {"name": self.name, "parameters": dict(self.parameters), "std": dict(self.std),
               "estimation": dict(self.estimation), "validation": dict(self.validation),
               "seconds": self.seconds}
        if self.model_parameters:
            out["model_parameters"] = dict(self.model_parameters)
            out["model_std"] = dict(self.model_std)
        if self.equivalent_offset is not None:
            out["equivalent_offset"] = self.equivalent_offset
        if self.limit is not None:
            out["limit"] = self.limit
        if self.std_note is not None:
            out["std_lower_bound"], out["std_note"] = True, self.std_note
        if self.warnings:
            out["warnings"] = list(self.warnings)
        return out

    def __str__(self) -> str:
        est, val = self.estimation, self.validation
        if self.error is not None:
            return f"{self.name}: failed on {est.get('record')}: {self.error}"
        return (f"{self.name}: validation on {val['record']} {val['rmse_mm']:.3g} mm "
                f"({val['fit_percent']:.2f} %), estimation {est['rmse_mm']:.3g} mm")


@dataclass
class EMPSBenchmark:
    """The EMPS benchmark's results: one :class:`EMPSModel` per link model.

    Attributes
    ----------
    models : list of EMPSModel
        The identified models, in the order identified.
    estimation_record, validation_record : IORecord
        What the models were identified from and scored on.
    official_test : bool
        Whether the validation record is the benchmark's test record.
    reference : dict
        The IDIM-LS model's published parameters scored the same way:
        ``{"estimation": {...}, "validation": {...}}``, each ``{"record",
        "rmse_mm", "fit_percent"}``; under ``"idim"`` the same method (inverse
        dynamics, :func:`~motionhyst.identify.io_start.inverse_dynamics`) on the
        estimation record, with its ``"parameters"``: the fair yardstick of a
        split, whose validation periods the published parameters have seen.
    drift : list of dict
        The inverse dynamics of each period of the record the split was cut
        from (:func:`period_drift`; empty with the test record).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(2000) / 1000.0
    >>> u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    >>> y = reference_system().simulate(t, u).displacement
    >>> res = run_emps(IORecord(t, u, y, "axis"), models=("coulomb",), periods=(1, 1),
    ...                period=1000)
    >>> res.official_test, res.validation_record.name, [m.name for m in res.models]
    (False, 'axis period 2', ['coulomb'])
    >>> res.best().validation["rmse_mm"] < 0.01
    True
    """

    models: list[EMPSModel]
    estimation_record: IORecord
    validation_record: IORecord
    official_test: bool
    reference: dict
    drift: list[dict] = field(default_factory=list)

    def to_dict(self) -> dict:
        """``{"models": [...]}``, each as :meth:`EMPSModel.to_dict`."""
        return {"models": [m.to_dict() for m in self.models]}

    def best(self) -> EMPSModel:
        """The model with the smallest validation RMSE (of those that did not fail); when
        every model failed, :class:`~motionhyst.identify.io_checks.FitFailed` (a
        ``RuntimeError``) naming each and why: there is no best of none."""
        fitted = [m for m in self.models if m.error is None]
        if not fitted:
            why = "; ".join(f"{m.name}: {m.error}" for m in self.models) or "no model fitted"
            raise FitFailed(f"no model to choose: every model's fit failed ({why})")
        return min(fitted, key=lambda m: m.validation["rmse_mm"])

    @property
    def failed(self) -> list[EMPSModel]:
        """The models whose identification or scoring failed (:attr:`EMPSModel.error`)."""
        return [m for m in self.models if m.error is not None]

    def __str__(self) -> str:
        from motionhyst.core.textfmt import g, table

        rows, failures = [], {}
        for m in self.models:
            if m.error is not None:  # its reason on its row; the others' columns kept
                failures[len(rows)] = m.error
                rows.append([f"motionhyst: mass-damper + {m.name}", *["-"] * 10])
                continue
            p, s = (m.model_parameters, m.model_std) if m.model_parameters else (m.parameters,
                                                                                 m.std)
            limit = "" if m.limit is None else f" (its rigid limit, {m.limit})"
            rows.append([f"motionhyst: mass-damper + {m.name}{limit}",
                         marked(g(p.get("m"), 4), s, "m"),
                         marked(viscous(p), s, "c", "c_skew", "c_pos", "c_neg"),
                         marked(friction(p), s, "fc", "fc_pos", "fc_neg"),
                         marked(offset(p), s, "offset", "drift"),
                         "-" if m.equivalent_offset is None else
                         marked(g(m.equivalent_offset, 3), m.std, "offset"),
                         f"{m.estimation['rmse_mm']:.3g}", f"{m.validation['rmse_mm']:.3g}",
                         f"{m.validation['fit_percent']:.1f}", own(m.validation),
                         f"{m.seconds:.0f}"])
        ref, est = self.reference, self.estimation_record
        for key, what in (("idim", f"IDIM-LS on {est.name} (one linear solve)"),
                          (None, "IDIM-LS reference (published parameters)"),
                          ("idim_asymmetric", f"IDIM-LS, asymmetric friction (eq. 12), on "
                                              f"{est.name}"),
                          ("asymmetric", "IDIM-LS, asymmetric friction (eq. 12), published")):
            row = ref if key is None else ref.get(key)
            if row is None:
                continue
            q = row.get("parameters", REFERENCE_MODEL)
            of = equivalent_offset(q, est)
            rows.append([what, g(q["m"], 4), viscous(q), friction(q),
                         g(q.get("offset", 0.0), 3), g(of, 3),
                         f"{row['estimation']['rmse_mm']:.3g}",
                         f"{row['validation']['rmse_mm']:.3g}",
                         f"{row['validation']['fit_percent']:.1f}", "-", "-"])
        head = ["model", "m [kg]", "c (+/-) [N s/m]", "fc [N]", "offset [N]", "as OF [N]",
                "est. [mm]",
                "valid. [mm]", "fit [%]", "own offset: valid. [mm]", "time [s]"]
        lines = [f"EMPS benchmark (Janot, Gautier and Brunot 2019): identified on "
                 f"{self.estimation_record.name}, validated on {self.validation_record.name}"
                 + ("" if self.official_test else " (the test record "
                    f"{TEST_FILE} was not given)"),
                 f"RMSE of the position simulated from the force, samples n >= {INIT_WINDOW} "
                 f"(the first {INIT_WINDOW} set the initial state)", "",
                 failed_table(head, rows, failures)]
        pub = [[name, "-" if rmse is None else f"{rmse:.3g}", f"{fit:.1f}"]
               for name, rmse, fit in PUBLISHED]
        lines += ["", "Published, on the test record " + TEST_FILE
                  + ("" if self.official_test else " (not the record above)") + ":",
                  table(["method", "RMSE [mm]", "fit [%]"], pub)]
        if self.official_test and any(m.name == CHOSEN and m.error is None
                                      for m in self.models):
            chosen = next(m for m in self.models if m.name == CHOSEN)
            lines += ["", f"motionhyst's figure on {self.validation_record.name}: {CHOSEN}, "
                      f"{chosen.validation['rmse_mm']:.3g} mm (the physical model chosen before "
                      f"the test, by the worse of the two splits of DATA_EMPS)"]
        lines += ["", "as OF: the constant offset the model's offset, its drift and its "
                  "direction-dependent viscous friction amount to on "
                  f"{self.estimation_record.name}'s motion (the reference model's OF)"]
        lines += ["", "own offset: the model with the force offset that suits "
                  f"{self.validation_record.name} best (a diagnosis, not a score): what is "
                  "left is the model's error, the rest is the offset's drift between records"]
        if self.drift:
            rows = [[str(d["period"]), g(d["offset"], 3), g(d["c_pos"], 4), g(d["c_neg"], 4),
                     g(d["offset_asymmetric"], 3)] for d in self.drift]
            lines += ["", f"Inverse dynamics (IDIM-LS) of each period of "
                      f"{self.estimation_record.name.split(' period')[0]}: the force offset "
                      f"drifts; with viscous friction by direction, the forward one does",
                      table(["period", "offset [N]", "c+ [N s/m]", "c- [N s/m]",
                             "offset, c+/c- [N]"], rows)]
        for m in self.models:
            lines += [f"warning: {m.name}: {w}" for w in m.warnings]
        return "\n".join(lines)

    def plot(self, ax=None):
        """Measured and simulated position on the validation record, and the errors.

        Parameters
        ----------
        ax : sequence of two Axes, optional
            Where to draw the positions and the errors; a new figure otherwise.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        if ax is None:
            fig, axes = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
        else:
            axes = list(ax)
            fig = axes[0].figure
        rec = self.validation_record
        axes[0].plot(rec.t, 1e3 * rec.y, color="k", lw=1.2, label="measured qm")
        for m in self.models:
            if m.prediction is None:
                continue
            axes[0].plot(rec.t, 1e3 * m.prediction, lw=0.9,
                         label=f"{m.name} ({m.validation['rmse_mm']:.3g} mm)")
            axes[1].plot(rec.t[INIT_WINDOW:], 1e3 * (m.prediction - rec.y)[INIT_WINDOW:], lw=0.8,
                         label=m.name)
        axes[0].set_ylabel("position [mm]")
        axes[0].set_title(f"EMPS: simulated from the force, {rec.name}")
        axes[0].legend(fontsize="small")
        axes[1].set_ylabel("error [mm]")
        axes[1].set_xlabel("time [s]")
        return fig


def cross_validate(estimation: IORecord, *, models: Sequence[str] | None = None,
                   period: int | None = None,
                   progress: Callable[[str], None] | None = None,
                   splits: str = "halves", workers: int = 1,
                   guard: Callable[[], AbstractContextManager] | None = None
                   ) -> list[EMPSBenchmark]:
    """The benchmark without its test record: identified on each half of the estimation
    record's periods and scored on the other half, both ways (with ``splits="all"`` also
    on all periods but the last and all but the first, each scored on the one left).

    One split alone says little on this record: its force offset drifts from period
    to period (the inverse-dynamics estimate: -3.00, -3.07, -3.27, -3.34 N over
    periods 1 to 4), and the floating axis integrates the difference over every second
    of the held-out simulation.

    Parameters
    ----------
    estimation : IORecord
        The estimation record (at least two periods).
    models, period, progress, workers, guard
        As for :func:`run_emps` (the fits of every split share the workers).
    splits : {"halves", "all"}
        ``"halves"``: periods 1-2 then 3-4 (of four); ``"all"``: then also 1-3 and
        2-4, each validated on the period it leaves out (a record of three or more
        periods; a split met before is not run twice).

    Returns
    -------
    list of EMPSBenchmark
        Identified on the first half of the periods, then on the second (then on all
        but the last, then on all but the first).

    Examples
    --------
    The reference model's own record, two periods of 1000 samples, both ways:

    >>> import numpy as np
    >>> t = np.arange(2000) / 1000.0
    >>> u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    >>> y = reference_system().simulate(t, u).displacement
    >>> runs = cross_validate(IORecord(t, u, y, "axis"), models=("coulomb",), period=1000)
    >>> [(r.estimation_record.name, r.validation_record.name) for r in runs]
    [('axis period 1', 'axis period 2'), ('axis period 2', 'axis period 1')]
    >>> all(abs(r.models[0].parameters["m"] - 95.1089) < 0.1 for r in runs)
    True

    Three periods, every split:

    >>> t = np.arange(3000) / 1000.0
    >>> u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    >>> y = reference_system().simulate(t, u).displacement
    >>> runs = cross_validate(IORecord(t, u, y, "axis"), models=("coulomb",), period=1000,
    ...                       splits="all")
    >>> [r.estimation_record.name for r in runs]
    ['axis period 1', 'axis periods 2-3', 'axis periods 1-2']
    """
    if splits not in ("halves", "all"):
        raise ValueError(f"splits must be 'halves' or 'all', got {splits!r}")
    period = PERIOD if period is None else int(period)
    count = -(-estimation.t.size // period)
    if count < 2:
        raise ValueError(f"{estimation.name}: {count} period of {period} samples; a "
                         f"cross-validation needs two or more")
    half = count // 2
    ways = [(1, half), (half + 1, count)]
    if splits == "all":
        if count < 3:
            raise ValueError(f"{estimation.name}: {count} periods of {period} samples; "
                             f"every split needs three or more")
        ways += [w for w in ((1, count - 1), (2, count)) if w not in ways]
    models = MODELS if models is None else tuple(models)
    for name in models:
        check_model(name)
    pairs = [split_by_periods(estimation, way, period, name=estimation.name) for way in ways]
    fitted = _fit_splits(pairs, models, workers, guard, progress)
    return [_benchmark(estimation, None, est, val, out, period)
            for (est, val), out in zip(pairs, fitted, strict=True)]


def run_emps(estimation: IORecord, test: IORecord | None = None, *,
             models: Sequence[str] | None = None, periods: tuple[int, int] = (1, 2),
             period: int | None = None, progress: Callable[[str], None] | None = None,
             workers: int = 1, guard: Callable[[], AbstractContextManager] | None = None
             ) -> EMPSBenchmark:
    """Identify the axis with each link model and score it by the benchmark's metric.

    Parameters
    ----------
    estimation : IORecord
        The estimation record ``DATA_EMPS`` (time [s], force [N], position [m]).
    test : IORecord, optional
        The test record ``DATA_EMPS_PULSES``: the models are identified from the
        whole estimation record and scored on it.  Without it they are
        identified from the estimation record's `periods` and scored on the
        other periods.
    models : sequence of str, optional
        Link models on the mass-damper (default :data:`MODELS`).
    periods : (int, int)
        Without `test`: the periods identified from (see :func:`split_by_periods`).
    period : int, optional
        Samples per period of the estimation record (default :data:`PERIOD`).
    progress : callable, optional
        Called with a line of text as each model starts and ends (with workers: as each
        chain of models is handed to one, and as each model ends).
    workers : int
        The most processes fitting at once
        (:func:`~motionhyst.identify.emps_workers.map_in_workers`): the models come in
        chains, a Jenkins link after the Coulomb link with its options (its start), each
        chain in one process; the same figures as in one.
    guard : callable, optional
        With workers: returns the context each chain runs in, in its worker (the caller's
        CPU-time limit counts its own process's time, not the workers').

    Returns
    -------
    EMPSBenchmark

    Raises
    ------
    ValueError
        A record that cannot be used, or a model name that is none of the benchmark's.
        A model whose identification or scoring fails does not end the run: it is a
        row with its reason (:meth:`EMPSModel.failed`) and the others go on.

    Examples
    --------
    The reference model's own record: the Coulomb link on the mass-damper finds it again.

    >>> import numpy as np
    >>> t = np.arange(2000) / 1000.0
    >>> u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    >>> y = reference_system().simulate(t, u).displacement
    >>> res = run_emps(IORecord(t, u, y, "axis"), models=("coulomb",), periods=(1, 1),
    ...                period=1000)
    >>> p = res.models[0].parameters
    >>> round(p["m"], 1), round(p["c"], 1), round(p["fc"], 2), round(p["offset"], 3)
    (95.1, 203.5, 20.39, -3.165)
    """
    models = MODELS if models is None else tuple(models)
    period = PERIOD if period is None else int(period)
    if test is None:
        est, val = split_by_periods(estimation, periods, period, name=estimation.name)
    else:
        est, val = estimation, test
    for name in models:
        check_model(name)
    out = _fit_splits([(est, val)], models, workers, guard, progress)[0]
    return _benchmark(estimation, test, est, val, out, period)


def _benchmark(estimation: IORecord, test: IORecord | None, est: IORecord, val: IORecord,
               out: list[EMPSModel], period: int) -> EMPSBenchmark:
    """The models `out` fitted on `est`, with the reference models scored on `est` and `val`
    and, without `test`, the periods' drift of `estimation`."""
    ref = {"estimation": score(reference_system(), est)[0],
           "validation": score(reference_system(), val)[0],
           "asymmetric": {"parameters": dict(REFERENCE_ASYMMETRIC),
                          "estimation": score(reference_system(REFERENCE_ASYMMETRIC), est)[0],
                          "validation": score(reference_system(REFERENCE_ASYMMETRIC), val)[0]}}
    idim = inverse_dynamics([est], floating=True)  # the benchmark's own method, on this record
    for key, q in (("idim", {"m": idim["m"], "c": idim["c"], "fc": idim["fc"],
                             "offset": idim["u0"]}),
                   ("idim_asymmetric", asymmetric_inverse_dynamics(est))):
        own = reference_system(q)
        ref[key] = {"parameters": q, "estimation": score(own, est)[0],
                    "validation": score(own, val)[0]}
    drift = [] if test is not None else period_drift(estimation, period)
    return EMPSBenchmark(out, est, val, test is not None, ref, drift)


def _fit_splits(splits: list[tuple[IORecord, IORecord]], models: tuple[str, ...], workers: int,
                guard: Callable[[], AbstractContextManager] | None,
                progress: Callable[[str], None] | None) -> list[list[EMPSModel]]:
    """The `models` fitted on each split's estimation record and scored on its validation
    record, in the order of `models`: in this process one after another, or by chains in
    `workers` processes (the chains with a link other than Coulomb, the longest, first)."""
    say = progress or (lambda _msg: None)
    if workers <= 1:
        return [_fit_chain(est, val, models, say) for est, val in splits]
    chains: dict[frozenset, list[str]] = {}  # a link starts from the Coulomb fit of its options
    for name in models:
        chains.setdefault(frozenset(model_options(name)[1]), []).append(name)
    order = sorted(((k, tuple(chain)) for k in range(len(splits)) for chain in chains.values()),
                   key=lambda kc: all(model_options(n)[0] == "coulomb" for n in kc[1]))
    tasks = [(*splits[k], chain) for k, chain in order]

    def started(i: int) -> None:
        est, _, names = tasks[i]
        say(f"{', '.join(names)}: identifying on {est.name} ({est.t.size} samples) ...")

    def finished(i: int, fitted: list[EMPSModel]) -> None:
        for model in fitted:
            say(_ended(model, tasks[i][1]))

    ends = map_in_workers(_chain_task, tasks, workers, guard, started, finished)
    by_fit = {(k, model.name): model
              for (k, _), fitted in zip(order, ends, strict=True) for model in fitted}
    return [[by_fit[k, name] for name in models] for k in range(len(splits))]


def _chain_task(task: tuple[IORecord, IORecord, tuple[str, ...]]) -> list[EMPSModel]:
    """:func:`_fit_chain` of a worker's task ``(est, val, names)``."""
    return _fit_chain(*task)


def _fit_chain(est: IORecord, val: IORecord, names: Sequence[str],
               say: Callable[[str], None] = lambda _msg: None) -> list[EMPSModel]:
    """The models `names` identified on `est` and scored on `val`, one after another (a
    failed fit a row saying why); `say` told as each starts and ends."""
    out: list[EMPSModel] = []
    rigid: dict[frozenset, object] = {}  # the Coulomb fits by options: the others' start
    for name in names:
        say(f"{name}: identifying on {est.name} ({est.t.size} samples) ...")
        t0 = time.perf_counter()
        try:
            model = _model(name, est, val, out, rigid)
        except ValueError as exc:  # this model's row says why; the others' minutes are kept
            why = " ".join(str(exc).removeprefix(f"{name}: ").split())
            model = EMPSModel.failed(name, {"record": est.name}, {"record": val.name}, why)
        model.seconds = time.perf_counter() - t0
        out.append(model)
        say(_ended(model, val))
    return out


def _ended(model: EMPSModel, val: IORecord) -> str:
    """The progress line of a model fitted and scored on `val`."""
    return (f"{model.name}: failed ({model.seconds:.0f} s): {model.error}" if model.error else
            f"{model.name}: {model.validation['rmse_mm']:.3g} mm on {val.name} "
            f"({model.seconds:.0f} s)")


def _model(name: str, est: IORecord, val: IORecord, done: list[EMPSModel], rigid: dict
           ) -> EMPSModel:
    """The model `name` identified on `est` and scored on `val`, or its rigid limit (a
    Jenkins link whose stiffness the record does not resolve); `done`: the models made so
    far, `rigid`: the Coulomb fits by options.  A failure is a ValueError naming the model."""
    link, options = model_options(name)
    try:
        model = _identify_and_score(name, link, options, est, val, rigid)
        why = unresolved_stiffness(name, model.model_parameters, model.model_std, est.fs)
    except FitFailed as exc:
        if link == "coulomb" or RIGID_LIMIT not in str(exc):
            raise ValueError(f"{name}: {exc}") from None
        why = f"a model that needs more than {MAX_PREDICT_SUBSTEPS} {RIGID_LIMIT}"
    if why is not None:  # report the limit, the Coulomb link with the same options
        model = _rigid_limit(name, options, est, val, done, why, rigid)
    return model


def _rigid_limit(name: str, options: set[str], est: IORecord, val: IORecord,
                 done: list[EMPSModel], why: str, rigid: dict) -> EMPSModel:
    """A link reported as its rigid limit: the Coulomb link with the same options (its fit
    among `done` reused), named `name`, with a warning saying `why`."""
    limit = "-".join(["coulomb", *(o for o in OPTIONS if o in options)])
    model = next((m for m in done if m.name == limit), None)
    if model is not None and model.error is not None:  # failed already: not fitted again
        raise ValueError(f"{name}: {why}; its rigid limit {limit}: {model.error}")
    try:
        model = model or _identify_and_score(limit, "coulomb", options, est, val, rigid)
    except (FitFailed, ValueError) as limit_failed:
        what = str(limit_failed).removeprefix(f"{limit}: ")
        raise ValueError(f"{name}: {why}; its rigid limit {limit}: {what}") from None
    return replace(model, name=name, limit=limit, warnings=[
        f"the link's stiffness ran to the rigid limit ({why}): reported as that limit, {limit}",
        *model.warnings])


def _by_direction(options: set[str]) -> bool | None:
    """:func:`~motionhyst.identify.input_output.identify_io`'s `asymmetric` for a model's
    options: True (``-asymmetric``), False (``-symmetric``), else None (by direction where
    the record shows it, ``identify``'s default)."""
    return True if "asymmetric" in options else False if "symmetric" in options else None


def _identify_and_score(name: str, link: str, options: set[str], est: IORecord,
                        val: IORecord, rigid: dict) -> EMPSModel:
    """One model identified on `est` with the benchmark's window and scored on both records;
    `rigid`: the Coulomb fits made so far by options, a friction link's start (one more
    when `link` is the Coulomb link)."""
    key = frozenset(options)
    # a Maxwell-slip link as `identify` fits it: three elements, fewer where the records do
    # not determine them (four, identify_io's own default, failed the command on periods 1-2)
    elements = {"n_elements": 3, "fewer_elements": True} if link == "maxwell-slip" else {}
    try:
        with warnings.catch_warnings():  # the report lists the fit's warnings itself
            warnings.simplefilter("ignore", MotionhystWarning)
            fit = identify_io([est], link, plant="mass-damper", init_window=INIT_WINDOW,
                              asymmetric=_by_direction(options), drift="drift" in options,
                              rigid=None if link == "coulomb" else rigid.get(key), **elements)
        if link == "coulomb":
            rigid[key] = fit
        system = fit.system()
        est_score, _ = score(system, est)
        val_score, yhat = score(system, val)
        val_score["own_offset"] = own_offset_score(system, val)
    except FitFailed:
        raise
    except (ValueError, RuntimeError) as exc:  # the cause, not a library's argument
        raise ValueError(f"{name}: {getattr(exc, 'what', exc)}") from None
    own, own_std, covariance = fit_parameters(fit)
    parameters, std = reference_form(own, est, own_std, covariance)
    return EMPSModel(name, parameters, std, est_score, val_score, 0.0,
                     [*getattr(fit, "warnings", []), *reference_notes(parameters)], yhat,
                     parameters.get("offset"),
                     model_parameters=own, model_std=own_std,
                     std_note=fit.extra.get("std_note"))
