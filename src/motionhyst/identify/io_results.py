"""The result of an input-output identification: :class:`IOIdentification`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.textfiles import toml_table
from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis import Hysteresis
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.io_uncertainty import BOUC_WEN_IDENTIFIED, identification_toml
from motionhyst.time.openloop import MassSpringDamper, OpenLoop

__all__ = ["IOIdentification"]


@dataclass
class IOIdentification:
    """A plant and link identified from input-output records by simulation error.

    Attributes
    ----------
    plant : MassSpringDamper or TwoMass
        The identified stage.
    hysteresis : Hysteresis
        The link model (Bouc-Wen in the general form, normalised so that
        ``|gamma| + |delta| = 1``; or Maxwell-slip).
    estimates : dict
        Every estimated parameter (identifiable quantities only) by name.
    std : dict
        Standard error of each estimate (same keys); ``None`` where the data
        do not determine it (then listed in `not_identifiable`).  With the residuals'
        autocorrelation (:class:`~motionhyst.identify.io_uncertainty.CorrelatedErrors`):
        wider than `judged_std` where the fit leaves more than white noise.
    not_identifiable : dict
        Parameter name -> why it is not identifiable and what is.
    fit_rms : float
        RMS simulation error over all records [m] (of the force [N], `output` ``"force"``).
    records : list of dict
        Per record: ``{"name", "samples", "fit_rms", "output_rms"}``.
    seconds : float
        Wall time of the identification [s].
    periodic : bool
        Records taken as steady-state periods (True) or from rest (False).
    stopping : str
        Why the refinement stopped (scipy's message) and its tolerances.
    n_evaluations : int
        Model evaluations of the refinement.
    substeps : int
        Integration steps per sample the identification used.
    extra : dict
        The offsets and initial states (``offsets``, ``initial_state``), a force-displacement
        record's displacement noise and whether it was filtered (``displacement_noise``, one
        :meth:`~motionhyst.identify.displacement_noise.DisplacementEstimate.to_dict` per
        record; ``force_noise`` the same of the force driving a quasi-static plant), whether
        the search stopped at its budget (``budget_reached``) and the covariance of the
        determined estimates from the fit's Jacobian (``covariance``: ``{"parameters",
        "matrix"}``,
        :func:`~motionhyst.identify.io_uncertainty.covariance_table`; a Bouc-Wen link's
        under its identified names ``alpha``, ``beta*gamma``, ``beta*delta``, ``nu``), and
        ``std_lower_bound`` (True) where the standard errors are lower bounds, with
        ``std_note``, the line of the result that says why (the fit leaves more than the
        records' white noise, :func:`~motionhyst.identify.residual_noise.lower_bound_note`).
    warnings : list of str
        Implausible estimates, one line each naming the parameter
        (:func:`~motionhyst.identify.io_checks.plausibility_warnings`).
    data : list of IORecord
        The records fitted (not in :meth:`to_dict`); a force-displacement record's
        displacement (a quasi-static plant's force) as estimated without its sensor's white
        noise (:func:`~motionhyst.identify.displacement_noise.estimate_displacement`).
    residuals : ndarray
        The model's output less the measured position, the records one after the other, as
        the fit compared them (offsets and initial states included) [m] (or [N]).
    output : {"position", "force"}
        The signal fitted: the position from the force (input-output records), or the
        force from the displacement (force-displacement records of a link without
        inertia).
    rigid_limit : IOIdentification or None
        On a positioning axis (a mass-damper), the fit of the link's rigid limit, the
        Coulomb link with the same options, that a friction link's search started from (not
        in :meth:`to_dict`): what a Jenkins link whose stiffness the records do not resolve
        is reported as (:func:`~motionhyst.identify.rigid_limit.unresolved_stiffness`).
    judged_std : dict
        The standard errors white residuals give (keys and ``None`` as `std`; not in
        :meth:`to_dict`): what judges whether a parameter is determined
        (:func:`~motionhyst.identify.io_uncertainty.judge_determined`), so that a fit's
        model error widens the standard errors it reports, not what the records determine;
        empty: `std`.

    Examples
    --------
    What :func:`~motionhyst.identify.input_output.identify_io` returns:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.identify.input_output import identify_io
    >>> from motionhyst.identify.io_records import IORecord
    >>> from motionhyst.time.openloop import MassSpringDamper, OpenLoop
    >>> true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=5e4, fc=20.0))
    >>> t = np.arange(1024) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t) + 20 * np.sin(2 * np.pi * 31 * t)
    >>> fit = identify_io([IORecord(t, u, true.simulate(t, u).displacement)], model="jenkins")
    >>> fit.hysteresis.name, round(fit.estimates["m"], 3)   # the mass [kg]
    ('jenkins', 2.0)
    >>> print(str(fit).splitlines()[0])
    mass-spring-damper stage and jenkins link from 1 input-output record(s) (from a start)
    """

    plant: MassSpringDamper
    hysteresis: Hysteresis
    estimates: dict[str, float]
    std: dict[str, float | None]
    not_identifiable: dict[str, str]
    fit_rms: float
    records: list[dict]
    seconds: float
    periodic: bool
    stopping: str
    n_evaluations: int
    substeps: int = 0
    extra: dict = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    data: list[IORecord] = field(default_factory=list, repr=False, compare=False)
    residuals: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0), repr=False,
                                           compare=False)
    output: str = "position"
    rigid_limit: IOIdentification | None = field(default=None, repr=False, compare=False)
    judged_std: dict[str, float | None] = field(default_factory=dict, repr=False,
                                                compare=False)

    @property
    def unit(self) -> str:
        """The unit of the fitted output: ``m`` (the position), ``N`` (the force of a
        force-displacement record)."""
        return "N" if self.output == "force" else "m"

    def system(self) -> OpenLoop:
        """The identified open-loop system."""
        return OpenLoop(self.plant, self.hysteresis)

    def __str__(self) -> str:
        stage = self.plant.to_dict().get("type", type(self.plant).__name__)
        kind = "periodic steady state" if self.periodic else "from a start"
        rows = []
        at_least = ">= " if self.extra.get("std_lower_bound") else ""
        for name, value in self.estimates.items():
            s = self.std.get(name)
            rows.append([name, g(value, 8), "not identifiable" if s is None else
                         at_least + g(s, 2),
                         "" if s is None or value == 0 else f"{100 * s / abs(value):.2g} %"])
        what = "force-displacement" if self.output == "force" else "input-output"
        lines = [f"{stage} stage and {self.hysteresis.name} link from {len(self.records)} "
                 f"{what} record(s) ({kind})",
                 f"  fit RMS {g(self.fit_rms)} {self.unit}; {self.stopping}", "",
                 table(["parameter", "estimate", "std", "std/|value|"], rows)]
        if self.extra.get("std_note"):
            lines.append(f"  {self.extra['std_note']}")
        if self.not_identifiable:
            lines.append("")
            lines += [f"  {name}: {why}" for name, why in self.not_identifiable.items()]
        lines += ["", table(["record", "samples", f"fit RMS [{self.unit}]",
                             f"{'force' if self.output == 'force' else 'output'} RMS "
                             f"[{self.unit}]"],
                            [[r["name"], str(r["samples"]), g(r["fit_rms"]),
                              g(r["output_rms"])] for r in self.records])]
        lines += [f"  {what} of {r['name']}: {est['reason']}"
                  for what in ("displacement", "force") for r, est in
                  zip(self.records, self.extra.get(f"{what}_noise", []), strict=False)
                  if est["sigma"] > 0]
        lines += [f"  warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def plot(self, ax=None):
        """Per record, the measured and the predicted position and their difference.

        Drawn by :func:`~motionhyst.identify.figures.plot_io_identification`.

        Parameters
        ----------
        ax : sequence of matplotlib.axes.Axes, optional
            Two axes per record to draw into (positions, residual); default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.identify.figures import plot_io_identification

        return plot_io_identification(self, ax=ax)

    def to_dict(self) -> dict:
        """JSON-ready: ``plant``, ``hysteresis``, ``std``, ``fit_rms``, ``records``, ``seconds``."""
        return {"plant": self.plant.to_dict(), "hysteresis": self.hysteresis.to_dict(),
                "estimates": dict(self.estimates), "std": dict(self.std),
                "not_identifiable": dict(self.not_identifiable), "fit_rms": self.fit_rms,
                "records": [dict(r) for r in self.records], "seconds": self.seconds,
                "periodic": self.periodic, "stopping": self.stopping,
                "evaluations": self.n_evaluations, "substeps": self.substeps,
                **({"output": "force"} if self.output == "force" else {}),
                **self.extra, "warnings": list(self.warnings)}

    def scenario_text(self) -> str:
        """A scenario file (TOML) of the identified system: ``[stage]`` and ``[hysteresis]``,
        and the estimates' standard errors and correlations under their scenario keys in
        ``[identification]`` (:func:`~motionhyst.identify.io_uncertainty.identification_toml`).
        """
        lines = ([f"# identified from {len(self.records)} force-displacement record(s) by the "
                  f"force's error: fit RMS {self.fit_rms:.4g} N"] if self.output == "force" else
                 [f"# identified from {len(self.records)} input-output record(s) by simulation "
                  f"error: fit RMS {self.fit_rms:.4g} m"])
        offsets = self.extra.get("offsets", {}).get("output") or []
        if any(offsets):
            lines.append(f"# position offset of each record [m] (of its sensor, not the "
                         f"model's): {', '.join(f'{v:.6g}' for v in offsets)}")
        for name, values in self.extra.get("initial_state", {}).items():
            lines.append(f"# initial state {name} of each record: "
                         f"{', '.join(f'{v:.6g}' for v in values)}")
        # a model without inertia rests where its sensor reads this zero: predict applies it
        zero = (float(np.mean(offsets)) if any(offsets) and self.output != "force"
                and not self.plant.has_inertia else None)
        if zero is not None:
            lines.append("# (motionhyst predict applies [identification] position_offset, their "
                         "mean; --init-from REC sets it from a record's first samples)")
        elif (offsets or self.extra.get("initial_state")) and self.output != "force":
            lines.append("# (motionhyst predict --init-from REC sets both from a record's first "
                         "samples)")
        stage, link = self.plant.to_dict(), self.hysteresis.to_dict()
        text = ("\n".join(lines) + "\n" + toml_table("stage", stage) + "\n"
                + toml_table("hysteresis", link))
        # the estimates that are scalar keys of these tables, under those keys
        keys = {**{n: f"stage.{n}" for n, v in stage.items() if _number(v)},
                **{f"link.{n}": f"hysteresis.{n}" for n, v in link.items() if _number(v)},
                # a Bouc-Wen link's identified parameters (the products: study.identified)
                **({n: f"hysteresis.{n}" for n in BOUC_WEN_IDENTIFIED}
                   if link.get("model") == "bouc-wen" else {}),
                **{f"link.{n}[{i}]": f"hysteresis.{n}[{i}]" for n, v in link.items()
                   if isinstance(v, list) for i in range(len(v))}}
        ident = identification_toml(self.extra.get("covariance", {}), self.estimates, keys,
                                    "force-displacement" if self.output == "force"
                                    else "input-output", lower_bound=self.extra.get("std_note"),
                                    position_offset=zero)
        return text + ("\n" + ident if ident else "")


def _number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def per_record_errors(records: list[IORecord], res: NDArray[np.float64],
                      measured: list[NDArray[np.float64]] | None = None) -> list[dict]:
    """Per record: its name, samples, the fit's RMS error and the RMS of the signal fitted
    (`measured`, default: each record's position)."""
    out, i = [], 0
    for j, rec in enumerate(records):
        e = res[i:i + rec.y.size]
        i += rec.y.size
        y = rec.y if measured is None else measured[j]
        out.append({"name": rec.name, "samples": int(rec.y.size),
                    "fit_rms": float(np.sqrt(np.mean(e ** 2))),
                    "output_rms": float(np.sqrt(np.mean(y ** 2)))})
    return out
