"""The result of an identification: :class:`Identification`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.textfiles import toml_table
from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis import MaxwellSlip
from motionhyst.identify.io_uncertainty import identification_toml, widened_note
from motionhyst.plants.quasi_static import QuasiStatic

__all__ = ["Identification"]


@dataclass
class Identification:
    """Identified Maxwell-slip (parallel Jenkins) hysteresis and the quality of the fit.

    Attributes
    ----------
    model : MaxwellSlip
        The identified elements, ordered by slip displacement ``fc / k``.
    elements : list of dict
        Per element ``{"k", "fc", "k_std", "fc_std"}`` [N/m, N]; ``*_std`` are
        standard errors (``inf`` where the data do not determine the value).
    offset : float
        Constant force offset ``c`` of the record [N] (sensor bias).
    offset_std : float
        Its standard error [N].
    initial_forces : ndarray
        Each element's force at the first sample [N] (zero when started relaxed).
    fit_rms : float
        RMS of the residual [N].
    fit_nrms : float
        ``fit_rms`` over the RMS of the force about its mean [-].
    r2 : float
        Coefficient of determination ``1 - RSS / TSS`` [-].
    n_samples : int
        Samples in the residual.
    criterion : str
        How the number of elements was chosen.
    candidates : list of dict
        Every order tried: ``{"n_elements", "fit_rms", "bic"}``.
    signal : str
        What was fitted: ``"force"`` or, for closed-loop records,
        ``"prefiltered force"`` (the residual is in the prefiltered domain).
    cutoff_hz : float or None
        Cut-off of the prefilter of a closed-loop record [Hz]; None for a
        force-displacement record.
    covariance : dict or None
        ``{"parameters": [...], "matrix": [[...]]}``: the covariance of the determined
        estimates (``k``, ``fc`` and ``offset``; ``k[0], ..., fc[0], ...`` for several
        elements) from the fit's Jacobian, whose diagonal's square roots are the standard
        errors (:func:`~motionhyst.identify.io_uncertainty.covariance`).
    std_lower_bound : str or None
        Why the standard errors are lower bounds (the fit leaves more than the record's
        noise: :func:`~motionhyst.identify.residual_noise.lower_bound_note`; a line of the
        printed result says it, the table marks them ``>=``), else None.
    judged_std : dict
        Where the standard errors take the residuals' autocorrelation, those of white
        residuals, ``{"k[i]": .., "fc[i]": .., "offset": ..}`` (element ``i`` in the order of
        `elements`; the offset's where it is estimated and determined; not in
        :meth:`to_dict`): what judges whether a slip force is determined
        (:meth:`widened_note`); empty: those of `elements`.
    order_stop : str or None
        Why the automatic order search stopped before its largest order (its systematic
        error's trend could not reach the share asked: ``target_share`` of
        :func:`~motionhyst.identify.fit.identify_maxwell_slip`), else None.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import MaxwellSlip
    >>> from motionhyst.identify import identify_maxwell_slip
    >>> t = np.linspace(0.0, 4.0, 4001)
    >>> x = 0.01 * np.exp(-t / 2) * np.sin(2 * np.pi * 2.0 * t)
    >>> ident = identify_maxwell_slip(x, MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x))
    >>> print(f"R^2 = {ident.r2:.6f}, {ident.n_samples} samples")
    R^2 = 1.000000, 4001 samples
    >>> w = ident.predict(0.005 * np.sin(np.linspace(0.0, 4 * np.pi, 200)))   # any displacement
    >>> print(ident.scenario_fragment())                   # doctest: +ELLIPSIS
    # identified from 4001 samples: ...
    [hysteresis]
    model = "maxwell-slip"
    k = [10.0, 6.0]      # spring stiffnesses [N/m]
    fc = [0.01, 0.03]     # slip forces [N]
    """

    model: MaxwellSlip
    elements: list[dict[str, float]]
    offset: float
    offset_std: float
    initial_forces: NDArray[np.float64]
    fit_rms: float
    fit_nrms: float
    r2: float
    n_samples: int
    criterion: str
    candidates: list[dict] = field(default_factory=list)
    signal: str = "force"
    cutoff_hz: float | None = None
    covariance: dict | None = None
    std_lower_bound: str | None = None
    judged_std: dict[str, float] = field(default_factory=dict, repr=False)
    order_stop: str | None = None

    @property
    def n_elements(self) -> int:
        """Number of Jenkins elements."""
        return len(self.elements)

    def predict(self, x: ArrayLike, w0: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Force of the identified model for displacement `x`, plus the offset [N].

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float or array_like
            Initial force per element [N] (default: relaxed).
        """
        return self.model.response(x, w0) + self.offset

    def to_dict(self) -> dict:
        """Result as a JSON-ready dictionary."""
        return {"model": "maxwell-slip", "elements": [dict(e) for e in self.elements],
                "fit_rms": self.fit_rms, "fit_nrms": self.fit_nrms, "r2": self.r2,
                "n_samples": self.n_samples, "offset": self.offset,
                "offset_std": self.offset_std, "criterion": self.criterion, "signal": self.signal,
                "candidates": [dict(c) for c in self.candidates],
                **({} if self.cutoff_hz is None else {"cutoff_hz": self.cutoff_hz}),
                **({} if self.covariance is None else {"covariance": self.covariance}),
                **({} if self.std_lower_bound is None else
                   {"std_lower_bound": True, "std_note": self.std_lower_bound}),
                **({} if self.order_stop is None else {"order_stop": self.order_stop})}

    def __str__(self) -> str:
        at_least = ">= " if self.std_lower_bound else ""

        def std_text(value: float, std: float) -> str:
            return "not determined" if not math.isfinite(std) else \
                f"{at_least}{std:.2g} ({100 * std / value:.2g} %)"

        rows = [[str(i), g(e["k"], 6), std_text(e["k"], e["k_std"]), g(e["fc"], 6),
                 std_text(e["fc"], e["fc_std"]), g(e["fc"] / e["k"] * 1e3)]
                for i, e in enumerate(self.elements, start=1)]
        k = sum(e["k"] for e in self.elements)
        fc = sum(e["fc"] for e in self.elements)
        return "\n".join([
            f"  elements: {self.n_elements}   ({self.criterion})",
            f"  fit RMS {g(self.fit_rms)} N = {100 * self.fit_nrms:.3g} % of the "
            f"{self.signal} RMS, R^2 = {self.r2:.6f}, offset {g(self.offset)} N",
            "",
            table(["i", "k [N/m]", "std k [N/m]", "fc [N]", "std fc [N]", "fc/k [mm]"], rows),
            *([f"  {self.std_lower_bound}"] if self.std_lower_bound else []),
            "",
            f"  total stiffness {g(k, 6)} N/m, total slip force {g(fc, 6)} N"])

    def widened_note(self) -> str | None:
        """The elements' values and the offset whose standard error, widened for the
        residuals' correlation, exceeds them where that of white residuals (`judged_std`)
        does not (:func:`~motionhyst.identify.io_uncertainty.widened_note`, as an
        input-output fit's): one warning's line, or None (also for standard errors that are
        not lower bounds, `std_lower_bound` None).

        Returns
        -------
        str or None
            Names as the covariance has them (``k``, ``fc`` for one element, ``k[0]``, ...
            for several, ``offset``).

        Examples
        --------
        A slip force and an offset of a fit that leaves model error or coloured noise: the
        offset's widened standard error exceeds it, the white one does not.

        >>> import numpy as np
        >>> from motionhyst import MaxwellSlip
        >>> ident = Identification(
        ...     MaxwellSlip(k=[20.0], fc=[0.05]),
        ...     [{"k": 20.0, "fc": 0.05, "k_std": 0.4, "fc_std": 0.001}], offset=0.002,
        ...     offset_std=0.003, initial_forces=np.zeros(1), fit_rms=0.01, fit_nrms=0.02,
        ...     r2=0.999, n_samples=1000, criterion="given",
        ...     std_lower_bound="standard errors are lower bounds: ...",
        ...     judged_std={"k[0]": 0.1, "fc[0]": 0.0002, "offset": 0.0005})
        >>> print(ident.widened_note()[:66])
        with residuals beyond white noise (model error or coloured noise),
        >>> print(ident.widened_note()[67:120])
        offset (0.002 +- 0.003) is not distinguishable from 0
        """
        if not self.std_lower_bound or not self.judged_std:
            return None
        n = self.n_elements

        def named(p: str, i: int) -> str:
            return p if n == 1 else f"{p}[{i}]"

        def finite(value: float | None) -> float | None:
            return value if value is not None and math.isfinite(value) else None
        estimates = {named(p, i): e[p] for p in ("k", "fc") for i, e in enumerate(self.elements)}
        std = {named(p, i): finite(e[f"{p}_std"]) for p in ("k", "fc")
               for i, e in enumerate(self.elements)}
        judged = {named(p, i): finite(self.judged_std.get(f"{p}[{i}]"))
                  for p in ("k", "fc") for i in range(n)}
        if "offset" in self.judged_std:
            estimates["offset"] = self.offset
            std["offset"] = finite(self.offset_std)
            judged["offset"] = finite(self.judged_std["offset"])
        return widened_note(estimates, std, judged)

    def plot(self, ax=None):
        """The identified link's force-displacement loops.

        Drawn by :func:`~motionhyst.hysteresis.figures.plot_link`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.hysteresis.figures import plot_link

        return plot_link(self.model, title=f"Identified Maxwell-slip link, "
                         f"{self.n_elements} element(s)", ax=ax)

    def link_model(self) -> tuple[QuasiStatic, MaxwellSlip]:
        """The identified link as a system without inertia: the force ``u`` that holds it at
        a displacement ``x`` is the link's plus the record's offset.

        :class:`~motionhyst.plants.quasi_static.QuasiStatic` (no spring, no damper,
        ``force_offset = -offset``) and :attr:`model`, what
        :func:`~motionhyst.time.quasi_static.force_from_displacement` runs.

        Returns
        -------
        (QuasiStatic, MaxwellSlip)

        Examples
        --------
        >>> import numpy as np
        >>> from motionhyst import MaxwellSlip
        >>> from motionhyst.identify import identify_maxwell_slip
        >>> from motionhyst.time.quasi_static import force_from_displacement
        >>> t = np.linspace(0.0, 4.0, 4001)
        >>> x = 0.01 * np.sin(2 * np.pi * t)
        >>> w = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x) + 0.002
        >>> plant, link = identify_maxwell_slip(x, w, initial_state="relaxed").link_model()
        >>> round(plant.force_offset, 6)
        -0.002
        >>> bool(np.allclose(force_from_displacement(plant, link, t, x), w, atol=1e-9))
        True
        """
        return QuasiStatic(force_offset=-self.offset), self.model

    def scenario_text(self, source: str = "a force-displacement record") -> str:
        """A whole scenario (TOML) of the link as a system without inertia, for ``predict``.

        ``[stage] type = "quasi-static"`` (:meth:`link_model`: the record's force
        offset) and the ``[hysteresis]`` of :meth:`scenario_fragment`; ``motionhyst
        predict`` gives its force for a displacement record (time,displacement) and
        its displacement for a force record.  One element's ``k`` and ``fc`` come with
        their standard errors and correlations in ``[identification]`` (several elements' as
        ``hysteresis.k[0]``, ...)
        (:func:`~motionhyst.identify.io_uncertainty.identification_toml`).

        Parameters
        ----------
        source : str
            What it was identified from (the first comment line).

        Returns
        -------
        str
        """
        plant, _ = self.link_model()
        head = (f"# the link identified from {source}, without inertia: motionhyst predict "
                f"gives its force\n# for a displacement record (time,displacement), its "
                f"displacement for a force record\n")
        text = head + toml_table("stage", plant.to_dict()) + "\n" + self.scenario_fragment()
        if self.covariance is None:  # the record's kind all the same: what predict predicts
            return text + "\n" + identification_toml({}, {}, {}, "force-displacement")
        names = [n for n in self.covariance["parameters"] if n != "offset"]
        if self.n_elements == 1:
            estimates = dict(self.elements[0])
        else:
            estimates = {f"{p}[{i}]": e[p] for p in ("k", "fc")
                         for i, e in enumerate(self.elements)}
        ident = identification_toml(self.covariance, estimates,
                                    {n: f"hysteresis.{n}" for n in names}, "force-displacement",
                                    lower_bound=self.std_lower_bound)
        return text + ("\n" + ident if ident else "")

    def scenario_fragment(self) -> str:
        """A ``[hysteresis]`` section of a scenario file (TOML), ready to paste.

        One element is written as ``model = "jenkins"`` with scalars, more as
        ``model = "maxwell-slip"`` with lists.
        """
        k, fc = self.model.k, self.model.fc
        head = (f"# identified from {self.n_samples} samples: fit NRMS "
                f"{100 * self.fit_nrms:.3g} %, R^2 {self.r2:.6f}\n")
        if k.size == 1:
            entries = {"model": "jenkins", "k": k[0], "fc": fc[0]}
            comments = {"k": "spring stiffness k_J [N/m]", "fc": "slip force f_c [N]"}
        else:
            entries = {"model": "maxwell-slip", "k": k, "fc": fc}
            comments = {"k": "spring stiffnesses [N/m]", "fc": "slip forces [N]"}
        return head + toml_table("hysteresis", entries, comments, digits=7)
