"""The closing summary of a study: worst case per axis, where the link dominates the tracking
error (``|E - 1| > 1``) and, with Monte-Carlo samples, the band of each output's worst case
over the samples (the spread of a fleet of machines)."""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field

import numpy as np

from motionhyst.core.textfmt import g, table
from motionhyst.study.store import FAILED, OK, REASONS, field_names

__all__ = ["BAND", "DOMINANCE_FIELDS", "NEVER_FIELDS", "StudySummary", "failure_reasons",
           "plot_band", "summarize"]

BAND = (5.0, 50.0, 95.0)
"""Percentiles of the Monte-Carlo band [%]."""

DOMINANCE_FIELDS = ("mismatch", "E")
"""Fields that are a mismatch ``E = e1 / e1_linear`` (exact, and eq. 18's): the error the link
adds to the first harmonic is ``(E - 1) e1_linear``; where ``|E - 1| > 1`` it exceeds the linear
loop's error (the link dominates; compare the crossover frequency of eq. 21)."""

NEVER_FIELDS = {"settling_time_s": "never settle within the band"}
"""Fields whose missing value at a computed point is the worst case, not an unknown: a scan
whose error does not settle has no settling time (the output ``scan``); to what they say."""


@dataclass
class StudySummary:
    """Per output field (magnitudes for complex fields): the worst case over the study and where,
    the worst case along each axis, and the Monte-Carlo band.

    Attributes
    ----------
    points, computed, failed : int
        Points of the study, computed (converged), failed.
    worst : dict
        Field to ``{"value": .., "at": {axis: value}}``: the largest magnitude.
    per_axis : dict
        Field to axis to ``{"values": [...], "worst": [...]}``: along each axis, the largest
        magnitude over all other axes.
    band : dict
        Field to ``{"5": .., "50": .., "95": ..}``: percentiles over the samples of each
        sample's worst case (empty without samples).
    widest : dict
        Field to ``{"at": {axis: value}, "5": .., "50": .., "95": ..}``: the percentiles over
        the samples at the point of the axes where they spread most, relative to the median
        (where the machines of a fleet differ most).
    band_samples : dict
        Field to ``{"band": .., "widest": .., "of": ..}``: how many samples :attr:`band` and
        :attr:`widest` are over, of all samples (fewer where points failed: the bands are
        then of the samples left, which the text says: "of 36/50 samples").
    failures : dict
        Reason (:data:`~motionhyst.study.store.REASONS`) to ``{"points": .., "example": ..}``:
        how many points failed for it and the message of the first.
    never : dict
        Field of :data:`NEVER_FIELDS` to ``{"points": .., "of": .., "at": {axis: value}}``:
        the computed points without a value (their worst case: a scan that never settles),
        of all computed, and the first of them; its :attr:`worst` is over the others.
    dominates : dict
        Field of :data:`DOMINANCE_FIELDS` to ``{"points": .., "of": .., "crossover_hz": ..}``:
        the computed points where ``|E - 1| > 1`` (the link dominates: the error it adds
        exceeds the linear loop's) of all computed, and, over ``frequency_hz``, the highest
        frequency where it does for each value of the other axes (and samples): ``{"min",
        "median", "max"}`` of those, ``"never"`` how many have none, ``"top"`` the axis'
        highest frequency.

    Examples
    --------
    >>> s = StudySummary(points=10, computed=9, failed=1,
    ...                  failures={"the steady state did not converge":
    ...                            {"points": 1, "example": "point 7: ..."}})
    >>> print(s)
    10 points: 9 computed, 1 failed, 0 not computed yet
      1 failed: the steady state did not converge (point 7: ...)
    """

    points: int
    computed: int
    failed: int
    worst: dict = field(default_factory=dict)
    per_axis: dict = field(default_factory=dict)
    band: dict = field(default_factory=dict)
    widest: dict = field(default_factory=dict)
    failures: dict = field(default_factory=dict)
    dominates: dict = field(default_factory=dict)
    never: dict = field(default_factory=dict)
    band_samples: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``study --summary --json`` schema)."""
        return {"points": self.points, "computed": self.computed, "failed": self.failed,
                "worst": self.worst, "per_axis": self.per_axis, "band": self.band,
                "widest": self.widest, "failures": self.failures, "dominates": self.dominates,
                "never": self.never, "band_samples": self.band_samples}

    def _of(self, name: str, which: str) -> str:
        """``, of 36/50 samples`` where a band is over fewer than all samples."""
        n = self.band_samples.get(name, {})
        if n.get(which, n.get("of")) == n.get("of"):
            return ""
        return f", of {n[which]}/{n['of']} samples"

    def __str__(self) -> str:
        lines = [f"{self.points} points: {self.computed} computed, {self.failed} failed, "
                 f"{self.points - self.computed - self.failed} not computed yet"]
        for why, f in self.failures.items():
            lines.append(f"  {f['points']} failed: {why}"
                         + (f" ({f['example']})" if f.get("example") else ""))
        for name in dict.fromkeys([*self.worst, *self.never]):
            if name in self.never:
                nv = self.never[name]
                at = ", ".join(f"{k} = {_text(v)}" for k, v in nv["at"].items())
                lines.append(f"{name}: {nv['points']} of {nv['of']} computed points "
                             f"{NEVER_FIELDS[name]} (the worst case; the first at {at})")
            if name not in self.worst:
                continue
            w = self.worst[name]
            at = ", ".join(f"{k} = {_text(v)}" for k, v in w["at"].items())
            which = " of the others" if name in self.never else ""
            lines.append(f"{name}: worst |{name}|{which} = {g(w['value'])} at {at}")
            rows = []
            for axis, d in self.per_axis[name].items():
                i = int(np.nanargmax(d["worst"])) if np.any(np.isfinite(d["worst"])) else 0
                rows.append([axis, _text(d["values"][i]), g(d["worst"][i]),
                             g(float(np.nanmin(d["worst"])))])
            lines.append(table(["axis", "worst at", "worst", "best of the worst"], rows))
            if name in self.band:
                b = self.band[name]
                lines.append(f"  Monte Carlo, each sample's worst case{self._of(name, 'band')}"
                             ": " + ", ".join(f"{k} % {g(v)}" for k, v in b.items()))
            if name in self.widest:
                w = dict(self.widest[name])
                at = ", ".join(f"{k} = {_text(v)}" for k, v in w.pop("at").items())
                lines.append(f"  Monte Carlo, widest band at {at}{self._of(name, 'widest')}: "
                             + ", ".join(f"{k} % {g(v)}" for k, v in w.items()))
            if name in self.dominates:
                lines.append("  " + _dominance_text(name, self.dominates[name]))
        return "\n".join(lines)

    def plot(self, ax=None):
        """The worst case of each field along ``frequency_hz`` (a line per field).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.core.plotting import new_figure

        _, (ax,) = new_figure(ax=ax)
        for name, axes in self.per_axis.items():
            axis = "frequency_hz" if "frequency_hz" in axes else next(iter(axes))
            ax.loglog(axes[axis]["values"], axes[axis]["worst"], label=name)
            ax.set_xlabel(axis)
        ax.legend()
        return ax.figure


SCAN_UNITS = {"scan.length": "m", "scan.speed": "m/s", "scan.a_max": "m/s^2",
              "scan.j_max": "m/s^3", "scan.s_max": "m/s^4", "scan.window": "s"}
"""Units of the scan axes, for a figure's label."""


def plot_band(ds, name: str | None = None, ax=None):
    """``|name|`` over frequency, a line per amplitude: the median over the Monte-Carlo samples
    and the band from 5 to 95 % (the worst case over any other axis).  A study of scans (a
    single frequency) is drawn over its first scan axis (``scan.speed``, ...), a line per
    ``scan.compensation``.

    Parameters
    ----------
    ds : xarray.Dataset
        A study's results (:func:`motionhyst.study.open_results`) with a ``frequency_hz`` axis
        (or a numeric ``scan.*`` axis).
    name : str, optional
        The output field; by default ``E`` if the study has it, else its first field.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> f = [1.0, 10.0, 100.0]
    >>> ds = xr.Dataset({"E": (("frequency_hz", "sample"), np.ones((3, 4)) * (1 + 1j)),
    ...                  "status": (("frequency_hz", "sample"), np.ones((3, 4), np.int8))},
    ...                 coords={"frequency_hz": f, "sample": np.arange(4)})
    >>> fig = plot_band(ds)
    >>> fig.axes[0].get_ylabel()
    '|E|'
    """
    from motionhyst.core.plotting import new_figure

    names = field_names(ds)
    name = name or ("E" if "E" in names else names[0])
    if name not in names:
        raise ValueError(f"no output {name!r} in the study (it has {', '.join(names)})")
    dims = ds["status"].dims
    x, lines = "frequency_hz", "amplitude"
    if ds.sizes.get("frequency_hz", 0) <= 1:
        scan = [d for d in dims if d in SCAN_UNITS and ds.sizes[d] > 1]
        if scan:
            x, lines = scan[0], "scan.compensation"
    if x not in dims:
        raise ValueError("the figure needs a frequency_hz axis (or a scan axis)")
    mag = abs(ds[name]).where(ds["status"] == OK)
    others = [d for d in mag.dims if d not in (x, lines, "sample")]
    if others:
        mag = mag.max(others)
    _, (ax,) = new_figure(ax=ax)
    values = mag[lines].values if lines in mag.dims else [None]
    f = mag[x].values
    for a in values:
        m = mag if a is None else mag.sel({lines: a})
        label = ("" if a is None else f"A = {g(float(a))} m" if lines == "amplitude"
                 else str(a))
        if "sample" in m.dims:
            q = m.quantile([BAND[0] / 100, BAND[1] / 100, BAND[2] / 100], dim="sample")
            (line,) = ax.plot(f, q.isel(quantile=1).transpose(x).values,
                              label=f"{label} median".strip())
            ax.fill_between(f, q.isel(quantile=0).transpose(x).values,
                            q.isel(quantile=2).transpose(x).values,
                            color=line.get_color(), alpha=0.25,
                            label=f"{label} {BAND[0]:g}-{BAND[2]:g} %".strip())
        else:
            ax.plot(f, m.transpose(x).values, "o-" if f.size < 10 else "-",
                    label=label or name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]" if x == "frequency_hz" else f"{x} [{SCAN_UNITS[x]}]")
    ax.set_ylabel(f"|{name}|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax.figure


def failure_reasons(ds) -> dict:
    """Why the failed points of a study's results failed: reason (:data:`REASONS`) to
    ``{"points": count, "example": the message of the first}``.

    Parameters
    ----------
    ds : xarray.Dataset
        The results (:func:`motionhyst.study.open_results`).

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"status": (("f",), np.array([1, 2, 2], np.int8)),
    ...                  "reason": (("f",), np.array([0, 2, 2], np.int8))},
    ...                 attrs={"failures": '{"2": "point 1: did not converge"}'})
    >>> failure_reasons(ds)
    {'the steady state did not converge': {'points': 2, 'example': 'point 1: did not converge'}}
    """
    if "reason" not in ds:
        return {}
    examples = json.loads(ds.attrs.get("failures", "{}"))
    codes, counts = np.unique(ds["reason"].values[ds["status"].values == FAILED],
                              return_counts=True)
    return {REASONS.get(code, f"reason {code}"): {"points": count,
                                                  "example": examples.get(str(code), "")}
            for code, count in zip(codes.tolist(), counts.tolist(), strict=True)}


def _dominance_text(name: str, d: dict) -> str:
    text = (f"the link dominates (|{name} - 1| > 1: it adds more error than the linear loop "
            f"has) at "
            f"{d['points']} of {d['of']} points")
    c = d.get("crossover_hz")
    if not c:
        return text
    top = " (the highest frequency studied)" if c["max"] >= d["top"] else ""
    spread = (f"{g(c['median'])} Hz" if c["min"] == c["max"] else
              f"{g(c['median'])} Hz (median; {g(c['min'])} to {g(c['max'])}{top} over the other "
              f"axes)")
    never = f"; never for {d['never']} of them" if d["never"] else ""
    return f"{text}; up to {spread}{never}"


def _dominance(ds, name: str, ok: np.ndarray) -> dict:
    """:attr:`StudySummary.dominates` of the field `name`."""
    mag = np.where(ok, np.abs(ds[name].values - 1.0), np.nan)
    over = np.nan_to_num(mag, nan=0.0) > 1.0
    out: dict = {"points": int(np.count_nonzero(over)), "of": int(np.count_nonzero(ok))}
    dims = list(ds[name].dims)
    if "frequency_hz" not in dims:
        return out
    k = dims.index("frequency_hz")
    f = ds["frequency_hz"].values.astype(float)
    order = np.argsort(f)
    over = np.moveaxis(over, k, -1)[..., order].reshape(-1, f.size)
    seen = np.moveaxis(np.isfinite(mag), k, -1).reshape(-1, f.size).any(axis=1)
    any_over = over.any(axis=1)
    last = f.size - 1 - np.argmax(over[:, ::-1], axis=1)
    cross = f[order][last][any_over & seen]
    out["never"] = int(np.count_nonzero(seen & ~any_over))
    out["top"] = float(f.max())
    if cross.size:
        out["crossover_hz"] = {"min": float(cross.min()), "median": float(np.median(cross)),
                               "max": float(cross.max())}
    return out


def _coordinate(v) -> float | str:
    """An axis value: a number, or a name (``scan.compensation``)."""
    return str(v) if isinstance(v, str | np.str_) else float(v)


def _text(v) -> str:
    return v if isinstance(v, str) else g(v)


def summarize(ds) -> StudySummary:
    """The summary of a study's results (:func:`motionhyst.study.open_results`).

    Parameters
    ----------
    ds : xarray.Dataset
        The results (:func:`motionhyst.study.open_results`).

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from pathlib import Path
    >>> from motionhyst.scenario import default_scenario_path
    >>> from motionhyst.study import Study, open_results, run_study
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["error_rms"],
    ...                       "axes": {"frequency_hz": [5.0, 10.0, 15.0]}}, scenario=base)
    >>> path = Path(tempfile.mkdtemp()) / "s.zarr"
    >>> _ = run_study(st, path, workers=0)
    >>> s = summarize(open_results(path))
    >>> s.worst["error_rms"]["at"]
    {'frequency_hz': 15.0, 'amplitude': 0.01}
    """
    status = ds["status"].values
    dims = list(ds["status"].dims)
    ok = status == OK
    out = StudySummary(points=int(status.size), computed=int(np.count_nonzero(ok)),
                       failed=int(np.count_nonzero(status == FAILED)))
    out.failures = failure_reasons(ds)
    for name in DOMINANCE_FIELDS:
        if name in field_names(ds) and np.any(ok):
            out.dominates[name] = _dominance(ds, name, ok)
    for name in field_names(ds):
        mag = np.where(ok, np.abs(ds[name].values), np.nan)
        if name in NEVER_FIELDS:
            never = ok & np.isnan(mag)
            if np.any(never):
                idx = np.unravel_index(int(np.argmax(never)), never.shape)
                out.never[name] = {"points": int(np.count_nonzero(never)),
                                   "of": out.computed,
                                   "at": {d: _coordinate(ds[d].values[i])
                                          for d, i in zip(dims, idx, strict=True)}}
        if not np.any(np.isfinite(mag)):
            continue
        flat = int(np.nanargmax(mag))
        idx = np.unravel_index(flat, mag.shape)
        at = {d: _coordinate(ds[d].values[i]) for d, i in zip(dims, idx, strict=True)}
        out.worst[name] = {"value": float(mag[idx]), "at": at}
        out.per_axis[name] = {}
        for k, d in enumerate(dims):
            others = tuple(j for j in range(len(dims)) if j != k)
            with np.errstate(all="ignore"):
                worst = np.nanmax(np.where(np.isfinite(mag), mag, -np.inf), axis=others)
            worst = np.where(np.isfinite(worst), worst, np.nan)
            out.per_axis[name][d] = {"values": [_coordinate(v) for v in ds[d].values],
                                     "worst": worst.tolist()}
        if "sample" in dims:
            per_sample = np.array(out.per_axis[name]["sample"]["worst"], dtype=float)
            per_sample = per_sample[np.isfinite(per_sample)]
            if per_sample.size:
                out.band[name] = {f"{p:g}": float(np.percentile(per_sample, p)) for p in BAND}
            k = dims.index("sample")
            out.band_samples[name] = {"band": int(per_sample.size), "of": int(mag.shape[k])}
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                q = np.nanpercentile(mag, BAND, axis=k)
                spread = (q[2] - q[0]) / np.abs(q[1])
            if np.any(np.isfinite(spread)):
                j = np.unravel_index(int(np.nanargmax(spread)), spread.shape)
                grid = [d for d in dims if d != "sample"]
                out.widest[name] = {
                    "at": {d: _coordinate(ds[d].values[i]) for d, i in zip(grid, j, strict=True)},
                    **{f"{p:g}": float(q[(n, *j)]) for n, p in enumerate(BAND)}}
                out.band_samples[name]["widest"] = int(np.count_nonzero(
                    np.isfinite(np.moveaxis(mag, k, -1)[j])))
    return out
