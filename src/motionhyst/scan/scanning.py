"""Scan metrics of the exact time simulation and compensation compared.

A lithographic scanner grades the servo error of a stage during the
constant-velocity scan by two moving statistics over the exposure window
``W`` (slit width / scan speed): the moving average ``MA(t)``, which shifts
the image (overlay), and the moving standard deviation ``MSD(t)``, which blurs
it (fading).  Here both are taken on the simulation's output grid over the
centred window ``|t_k - t| <= W / 2`` (population standard deviation)::

    MA(t)  = mean_k e(t_k),   MSD(t) = sqrt(mean_k (e(t_k) - MA(t))^2)

Their maxima are taken over the constant-velocity phases, at the centres
whose whole window lies inside the phase (the points a scan exposes).

:func:`run_scan` simulates a setpoint profile (:mod:`motionhyst.scan.profiles`)
from rest with the loop's dynamic link and compares compensations: ``none``
(rigid-body feedforward ``M r''`` only), ``model`` (the model feedforward's
terms, :mod:`motionhyst.scan.terms`: the stage's jerk and snap terms, friction,
the hysteresis model ``phi_hat(r)``, driven by the setpoint), ``ilc`` (a force
learned over trials, :mod:`motionhyst.scan.ilc`) and ``basis`` (the model's
coefficients learned over trials, :mod:`motionhyst.scan.basis`); and, on another
setpoint, whether the learned force, the model and the learned coefficients
carry over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.loop import Loop
from motionhyst.core.compiled import njit
from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.scan.basis import BasisResult, learn_basis
from motionhyst.scan.ilc import ILCFilters, ILCResult, learn
from motionhyst.scan.profiles import PHASE_COLORS, Profile, check_window_samples, shade_phases
from motionhyst.scan.terms import TERMS, FeedforwardTerms, model_terms
from motionhyst.time.simulation import default_step, simulate
from motionhyst.time.steps import check_scan_steps

__all__ = ["ScanResult", "ScanRun", "loop_at", "moving_statistics", "run_scan", "settling_time"]

COMPENSATIONS = ("none", "model", "ilc", "basis")
"""The compensations :func:`run_scan` compares."""

DEFAULT_SETTLE_TOLERANCE = 1e-9
"""Error band for the settling time [m]."""

COLORS = {"none": "tab:red", "model": "tab:blue", "ilc": "tab:green", "basis": "tab:purple"}


@njit(cache=True)
def _window_stats(e, lo, hi):  # pragma: no cover - compiled
    """Mean and population standard deviation of ``e[lo[k]:hi[k]]`` for each k (two passes)."""
    n = e.shape[0]
    ma = np.empty(n)
    msd = np.empty(n)
    for k in range(n):
        s = 0.0
        for i in range(lo[k], hi[k]):
            s += e[i]
        m = hi[k] - lo[k]
        mean = s / m
        q = 0.0
        for i in range(lo[k], hi[k]):
            d = e[i] - mean
            q += d * d
        ma[k] = mean
        msd[k] = math.sqrt(q / m)
    return ma, msd


def _window_bounds(t: NDArray[np.float64], window: float):
    """Index ranges ``[lo, hi)`` of the samples with ``|t_k - t| <= window / 2``."""
    half = 0.5 * window
    slack = 1e-9 * (t[-1] - t[0]) / max(len(t) - 1, 1)  # a sample exactly at the edge counts
    lo = np.searchsorted(t, t - half - slack, side="left")
    hi = np.searchsorted(t, t + half + slack, side="right")
    return lo.astype(np.int64), hi.astype(np.int64)


def moving_statistics(t: ArrayLike, e: ArrayLike,
                      window: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Moving average and moving standard deviation of `e` over a centred `window`.

    Parameters
    ----------
    t : array_like
        Increasing sample times [s].
    e : array_like
        The signal (the tracking error) [m].
    window : float
        Window length ``W`` [s], > 0: each value uses the samples with
        ``|t_k - t| <= W / 2`` (fewer at the ends of the record).

    Returns
    -------
    ma, msd : ndarray
        Mean and population standard deviation at each sample time.

    Examples
    --------
    >>> t = [0.0, 1.0, 2.0, 3.0, 4.0]
    >>> ma, msd = moving_statistics(t, [0.0, 0.0, 3.0, 0.0, 0.0], window=2.0)
    >>> ma.tolist(), [round(float(x), 4) for x in msd]
    ([0.0, 1.0, 1.0, 1.0, 0.0], [0.0, 1.4142, 1.4142, 1.4142, 0.0])
    """
    t = np.asarray(t, dtype=float)
    e = np.ascontiguousarray(e, dtype=float)
    if t.ndim != 1 or t.shape != e.shape or t.size == 0:
        raise ValueError("time and signal must be one-dimensional and of equal length")
    if not (math.isfinite(window) and window > 0):
        raise ValueError(f"window must be finite and > 0 s, got {window!r}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("time must be strictly increasing")
    lo, hi = _window_bounds(t, window)
    return _window_stats(e, lo, hi)


def settling_time(t: NDArray[np.float64], e: NDArray[np.float64], start: float, end: float,
                  tolerance: float) -> float | None:
    """Time from `start` after which ``|e| <= tolerance`` until `end` [s]; None if never.

    Parameters
    ----------
    t : ndarray
        Times [s].
    e : ndarray
        Error [m].
    start : float
        From when [s].
    end : float
        Until when [s].
    tolerance : float
        Band ``|e| <= tolerance`` [m].

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 11)
    >>> settling_time(t, np.exp(-5 * t), 0.0, 1.0, 0.1)
    0.5
    """
    sel = (t >= start) & (t <= end)
    tt, out = t[sel], np.abs(e[sel]) > tolerance
    if tt.size == 0 or out[-1]:
        return None
    if not out.any():
        return 0.0
    return float(tt[np.nonzero(out)[0][-1] + 1] - start)


@dataclass
class ScanRun:
    """The error of one run and its scan metrics.

    Attributes
    ----------
    compensation : str
        ``"none"``, ``"model"``, ``"ilc"`` or ``"basis"`` (``"without link"`` for
        the loop without its dynamic link).
    t, e, ma, msd : ndarray
        Time [s], error, its moving average and moving standard deviation [m].
    ma_max, msd_max : float or None
        Largest ``|MA|`` and ``MSD`` over the constant-velocity phases [m]
        (None when no window fits in one).
    peak_error : float
        Largest ``|e|`` over the run [m].
    settling_time_s : float or None
        For a scan, the longest time from the start of a constant-velocity
        phase until ``|e|`` stays within the tolerance to its end; for a
        point-to-point move, from the end of the move to the end of the run.
        None if the error does not settle.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.scan.profiles import scan
    >>> p = scan(0.005, speed=0.05, a_max=2.0, j_max=50.0, s_max=1e3, start=0.01)
    >>> run = run_scan(default_scenario().loop(), p, window=0.05, tail=0.0).run("none")
    >>> sorted(run.to_dict())[:3]
    ['compensation', 'ma_max', 'msd_max']
    """

    compensation: str
    t: NDArray[np.float64] = field(repr=False)
    e: NDArray[np.float64] = field(repr=False)
    ma: NDArray[np.float64] = field(repr=False)
    msd: NDArray[np.float64] = field(repr=False)
    ma_max: float | None
    msd_max: float | None
    peak_error: float
    settling_time_s: float | None

    def to_dict(self) -> dict:
        """The run's metrics (JSON keys spelled here)."""
        return {"compensation": self.compensation, "ma_max": self.ma_max,
                "msd_max": self.msd_max, "peak_error": self.peak_error,
                "settling_time_s": self.settling_time_s}


def scan_metrics(t: NDArray[np.float64], e: NDArray[np.float64], profile: Profile,
                 window: float, compensation: str = "none",
                 settle_tolerance: float = DEFAULT_SETTLE_TOLERANCE) -> ScanRun:
    """MA, MSD, their maxima over the constant-velocity phases, peak error, settling time.

    See :class:`ScanRun` for the definitions.
    """
    t = np.asarray(t, dtype=float)
    e = np.asarray(e, dtype=float)
    ma, msd = moving_statistics(t, e, window)
    inside = np.zeros(t.shape, dtype=bool)
    for ph in profile.constant_velocity_phases():
        inside |= (t - 0.5 * window >= ph.start - 1e-12) & (t + 0.5 * window <= ph.end + 1e-12)
    ma_max = float(np.max(np.abs(ma[inside]))) if inside.any() else None
    msd_max = float(np.max(msd[inside])) if inside.any() else None
    if profile.kind == "scan":
        times = [settling_time(t, e, ph.start, ph.end, settle_tolerance)
                 for ph in profile.constant_velocity_phases()]
        settle = None if any(x is None for x in times) else max(times)
    else:
        settle = settling_time(t, e, profile.end, t[-1], settle_tolerance)
    return ScanRun(compensation, t, e, ma, msd, ma_max, msd_max, float(np.max(np.abs(e))),
                   settle)


@dataclass
class ScanResult:
    """Result of :func:`run_scan`: the runs of each compensation on one setpoint.

    Attributes
    ----------
    profile : Profile
        The setpoint.
    window : float
        Exposure window ``W`` [s].
    settle_tolerance : float
        Error band of the settling time [m].
    r : ndarray
        The setpoint on the runs' time grid [m].
    runs : list of ScanRun
        One per compensation, in the order asked.
    without_link : ScanRun or None
        The loop without its dynamic link (and without hysteresis feedforward); None when
        :func:`run_scan` was asked not to grade it.
    ilc : ILCResult or None
        The learning's trials, if ``ilc`` was asked.
    carry_over : ScanResult or None
        Another setpoint with the model, the force and the coefficients learned
        on this one.
    terms : FeedforwardTerms or None
        The model feedforward's terms and coefficients (``model``, ``basis``).
    basis : BasisResult or None
        The learning of the coefficients, if ``basis`` was asked.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.scan.profiles import scan
    >>> p = scan(0.005, speed=0.05, a_max=2.0, j_max=50.0, s_max=1e3, start=0.01)
    >>> res = run_scan(default_scenario().loop(), p, window=0.05, tail=0.0)
    >>> [r.compensation for r in res.runs]
    ['none']
    """

    profile: Profile
    window: float
    settle_tolerance: float
    r: NDArray[np.float64] = field(repr=False)
    runs: list[ScanRun]
    without_link: ScanRun | None
    ilc: ILCResult | None = None
    carry_over: ScanResult | None = None
    terms: FeedforwardTerms | None = None
    basis: BasisResult | None = None

    @property
    def t(self) -> NDArray[np.float64]:
        """Time grid [s]."""
        return self.runs[0].t

    def run(self, compensation: str) -> ScanRun:
        """The run of one compensation.

        Parameters
        ----------
        compensation : str
            One of the compensations compared (``"none"``, ``"model"``, ``"ilc"``,
            ``"basis"``).
        """
        for r in self.runs:
            if r.compensation == compensation:
                return r
        raise KeyError(compensation)

    def to_dict(self) -> dict:
        """Window, profile, results, without link, terms, learning, carry-over (JSON keys)."""
        d = {"window_s": self.window, "settle_tolerance": self.settle_tolerance,
             "profile": self.profile.to_dict(), "results": [r.to_dict() for r in self.runs]}
        if self.without_link is not None:
            d["without_link"] = {k: v for k, v in self.without_link.to_dict().items()
                                 if k != "compensation"}
        if self.terms is not None:
            d["feedforward"] = self.terms.to_dict()
        if self.ilc is not None:
            d["ilc"] = self.ilc.to_dict()
        if self.basis is not None:
            d["basis"] = self.basis.to_dict()
        if self.carry_over is not None:
            c = self.carry_over
            d["carry_over"] = {"profile": c.profile.to_dict(),
                               "results": [r.to_dict() for r in c.runs]}
        return d

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """Time series by CSV column: ``time, r, scan``, then ``e_c, ma_c, msd_c`` per run."""
        t = self.t
        in_scan = np.zeros(t.shape)
        for ph in self.profile.constant_velocity_phases():
            in_scan[(t >= ph.start) & (t <= ph.end)] = 1.0
        cols = {"time": t, "r": self.r, "scan": in_scan}
        for run in self.runs:
            cols.update({f"e_{run.compensation}": run.e, f"ma_{run.compensation}": run.ma,
                         f"msd_{run.compensation}": run.msd})
        return cols

    def _table(self, without_link: bool = True) -> str:
        def fmt(x):
            return "-" if x is None else g(x)

        runs = [*self.runs, self.without_link] if (
            without_link and self.without_link is not None) else self.runs
        return table(["compensation", "max |MA| [m]", "max MSD [m]", "peak |e| [m]",
                      "settling [s]"],
                     [[r.compensation, fmt(r.ma_max), fmt(r.msd_max), fmt(r.peak_error),
                       fmt(r.settling_time_s)] for r in runs])

    def __str__(self) -> str:
        out = [f"{self.profile}", f"exposure window {self.window:g} s, settling band "
               f"{self.settle_tolerance:g} m", self._table()]
        if self.ilc is not None:
            out.append(str(self.ilc))
        if self.basis is not None:
            out.append(str(self.basis))
        if self.carry_over is not None:
            out += ["carried over to another setpoint (model, learned force and learned "
                    "coefficients unchanged):",
                    f"{self.carry_over.profile}", self.carry_over._table(without_link=False)]
        return "\n".join(out)

    def plot(self, unit: float = 1e-9, unit_name: str = "nm", ax=None, log: bool = False):
        """Figure of ``e``, ``MA`` and ``MSD`` against time, the profile's phases shaded.

        Parameters
        ----------
        unit : float
            Unit of the errors on the figure [m] (default 1 nm).
        unit_name : str
            Its name.
        ax : sequence of 3 matplotlib.axes.Axes, optional
            Axes to draw into (e, MA, MSD); default: a new figure.
        log : bool
            ``|e|``, ``|MA|`` and ``MSD`` on logarithmic axes (compensations that
            differ by decades).
        """
        from matplotlib.figure import Figure
        from matplotlib.patches import Patch

        if ax is None:
            fig = Figure(figsize=(7.2, 6.4), layout="constrained")
            axes = fig.subplots(3, 1, sharex=True)
        else:
            axes = list(ax) if hasattr(ax, "__len__") else [ax]
            if len(axes) != 3:
                raise ValueError(f"this plot draws 3 axes; ax= gives {len(axes)}")
            fig = axes[0].figure
        shown = np.abs if log else (lambda x: x)
        for ax, name in zip(axes, ("e", "ma", "msd"), strict=True):
            if self.without_link is not None:
                ax.plot(self.t, shown(getattr(self.without_link, name)) / unit, color="0.5",
                        lw=0.9, ls="--", label="without link")
            for r in self.runs:
                ax.plot(r.t, shown(getattr(r, name)) / unit, color=COLORS.get(r.compensation),
                        lw=1.1, label=f"link, {r.compensation}")
            if log:
                ax.set_yscale("log")
                ax.set_ylim(bottom=1e-5 * max(np.max(shown(getattr(r, name))) for r in
                                              self.runs) / unit)
            shade_phases(ax, self.profile)
            ax.grid(True, alpha=0.3)
        bars = ("|", "|") if log else ("", "")
        axes[0].set_ylabel(f"error {bars[0]}e{bars[1]} [{unit_name}]")
        axes[1].set_ylabel(f"{bars[0]}MA{bars[1]} [{unit_name}]")
        axes[2].set_ylabel(f"MSD [{unit_name}]")
        axes[2].set_xlabel("time [s]")
        handles, labels = axes[0].get_legend_handles_labels()
        handles += [Patch(color=c, alpha=0.15) for c in PHASE_COLORS.values()]
        labels += list(PHASE_COLORS)
        axes[0].set_title(f"{self.profile}\nexposure window W = {self.window * 1e3:g} ms",
                          fontsize=8)
        fig.legend(handles, labels, ncol=4, fontsize=7, loc="outside lower center",
                   frameon=False)
        return fig


def loop_at(loop: Loop, x0: float) -> Loop:
    """`loop` with its links along the stroke seen from `x0`: a setpoint from 0 scans there.

    Parameters
    ----------
    loop : Loop
        A loop whose link or hysteresis feedforward varies along the stroke
        (:class:`~motionhyst.hysteresis.along_stroke.AlongStroke`).
    x0 : float
        Where on the stroke the setpoint's 0 lies [m].

    Raises
    ------
    ValueError
        For a loop without a link along the stroke.

    Examples
    --------
    >>> from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage
    >>> from motionhyst.hysteresis.along_stroke import AlongStroke
    >>> link = AlongStroke(Jenkins(20.0, 0.05), [0.0, 0.2], {"fc": [1.0, 2.0]})
    >>> loop = Loop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7),
    ...             LeadLagLowpass(6.2e6, 60, 240, 700, 0.6), link)
    >>> round(loop_at(loop, 0.1).hysteresis.at(0.0).fc, 6)      # 0.1 m on the stroke
    0.075
    """
    links = [loop.hysteresis, loop.hysteresis_feedforward]
    if not any(isinstance(h, AlongStroke) for h in links):
        raise ValueError("a scan's place on the stroke needs a link that varies along it "
                         "([hysteresis] along)")
    h, hff = (x.shifted(x0) if isinstance(x, AlongStroke) else x for x in links)
    return Loop(loop.plant, loop.controller, h, feedforward=loop.ff, mass=loop.M,
                hysteresis_feedforward=hff)


def _rigid_body(loop: Loop, hysteresis_feedforward=None) -> Loop:
    """`loop` with the rigid-body feedforward ``M r''`` alone (advanced as the loop's)."""
    advance = 0.0 if loop.ff is None else loop.ff.advance_samples
    ff = Feedforward(mass=loop.M, advance_samples=advance) if loop.ff is not None else None
    return Loop(loop.plant, loop.controller, loop.hysteresis, feedforward=ff, mass=loop.M,
                hysteresis_feedforward=hysteresis_feedforward)


def run_scan(loop: Loop, profile: Profile, window: float,
             compensations: tuple[str, ...] | list[str] = ("none",), ilc_trials: int = 10,
             ilc_filters: ILCFilters | None = None, other_profile: Profile | None = None,
             settle_tolerance: float = DEFAULT_SETTLE_TOLERANCE, tail: float = 0.05,
             dt: float | None = None, feedforward: tuple[str, ...] | list[str] | None = None,
             basis_trials: int = 4, without_link: bool = True) -> ScanResult:
    """Simulate `profile` from rest with each compensation and grade the scans.

    Parameters
    ----------
    loop : Loop
        The loop with its dynamic link, its feedforward and its hysteresis
        feedforward (a scenario's ``[feedforward]``).
    profile : Profile
        The setpoint.
    window : float
        Exposure window ``W`` [s] of MA and MSD.
    compensations : sequence of {"none", "model", "ilc", "basis"}
        Which to run, in this order.
    ilc_trials : int
        Trials of the learning (the last is the ``ilc`` run).
    ilc_filters : ILCFilters, optional
        Learning and robustness filters.
    other_profile : Profile, optional
        Another setpoint: run without compensation, with the model (if asked),
        with the force learned on `profile` (if ``ilc`` was asked) and with the
        coefficients learned on it (if ``basis`` was asked), unchanged.
    settle_tolerance : float
        Error band of the settling time [m].
    tail : float
        Time simulated after the end of the profile [s].
    dt : float, optional
        Time step [s]; by default the simulation's own.
    feedforward : sequence of str, optional
        The model feedforward's terms, of :data:`~motionhyst.scan.terms.TERMS`
        (default: those of the loop's feedforward;
        :func:`~motionhyst.scan.terms.model_terms`).
    basis_trials : int
        Trials of the coefficients' learning (the first is the ``model`` run).
    without_link : bool
        Also grade the loop without its dynamic link (from the uncompensated run); with
        False the uncompensated run is simulated only if ``none`` or ``ilc`` is asked
        (a study's point graded with the model alone costs one run, not two), and
        :attr:`ScanResult.without_link` is None.

    Returns
    -------
    ScanResult

    Raises
    ------
    ValueError
        For an unknown or repeated compensation, ``model`` on a loop without
        hysteresis feedforward or derivative terms, or a scan whose
        constant-velocity phases are all shorter than the window.

    Examples
    --------
    >>> from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage
    >>> from motionhyst.scan.profiles import scan
    >>> loop = Loop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), LeadLagLowpass(6.2e6, 60, 240, 700, 0.6),
    ...             Jenkins(20.0, 0.05))
    >>> p = scan(0.01, speed=0.05, a_max=2.0, j_max=50.0, s_max=1e3, start=0.01)
    >>> res = run_scan(loop, p, window=0.02, tail=0.0)
    >>> round(res.run("none").ma_max / (0.05 / 6.2e6), 2)   # slipping link: e = fc / C(0)
    1.0
    """
    comps = list(compensations)
    for c in comps:
        if c not in COMPENSATIONS:
            raise ValueError(f"unknown compensation {c!r}; use {', '.join(COMPENSATIONS)}")
    if len(set(comps)) != len(comps) or not comps:
        raise ValueError("give each compensation once, at least one")
    hff = loop.hysteresis_feedforward
    names = None if feedforward is None else list(feedforward)
    if names is None:
        names = [k for k in TERMS[:-1] if loop.ff is not None and getattr(loop.ff, k)]
        names += ["hysteresis"] if hff is not None else []
    if "model" in comps and not names:
        raise ValueError("compensation 'model' needs a hysteresis feedforward model "
                         "(a scenario's [feedforward] hysteresis) or feedforward terms")
    if not (isinstance(basis_trials, int) and basis_trials >= 1):
        raise ValueError(f"basis trials must be a whole number >= 1, got {basis_trials!r}")
    if not (math.isfinite(window) and window > 0):
        raise ValueError(f"window must be finite and > 0 s, got {window!r}")
    if not (math.isfinite(settle_tolerance) and settle_tolerance > 0):
        raise ValueError(f"settling tolerance must be finite and > 0 m, got {settle_tolerance!r}")
    if not (math.isfinite(tail) and tail >= 0):
        raise ValueError(f"tail must be finite and >= 0 s, got {tail!r}")
    for p in (profile, other_profile):
        if p is not None:
            p.check_window(window)
    # a rate-dependent link model stays in the loop (its time update), out of the terms
    in_loop = hff is not None and not hff.rate_independent and "hysteresis" in names
    terms = None
    if "model" in comps or "basis" in comps:
        terms = model_terms(loop, [n for n in names if not (in_loop and n == "hysteresis")])
    bare = _rigid_body(loop)
    modelled = _rigid_body(loop, hff) if in_loop else bare
    setup = _Setup(bare, modelled, terms, _learned_terms(terms), window, ilc_trials,
                   ilc_filters, basis_trials, settle_tolerance, tail, without_link)
    result = setup.runs(profile, comps, dt)
    result.terms = terms
    if other_profile is not None:
        learned = result.ilc.force_function() if result.ilc is not None else None
        basis = result.basis.terms if result.basis is not None else None
        result.carry_over = setup.runs(other_profile, comps, None, learned, basis)
    return result


def _learned_terms(terms: FeedforwardTerms | None) -> FeedforwardTerms | None:
    """The terms ``basis`` learns: the model's, and the stage's mass, jerk and snap always
    (those the model leaves out from 0, the same force as the model's)."""
    if terms is None:
        return None
    c = terms.coefficients
    order = ("mass", "jerk", "snap", "viscous", "coulomb")
    coefficients = {k: c.get(k, 0.0) for k in order if k in c or k in ("jerk", "snap")}
    return FeedforwardTerms(terms.base_mass, coefficients, terms.link, terms.link_scales)


@dataclass
class _Setup:
    """The loops and settings of one :func:`run_scan`."""

    bare: Loop
    modelled: Loop
    terms: FeedforwardTerms | None
    learned_terms: FeedforwardTerms | None
    window: float
    ilc_trials: int
    ilc_filters: ILCFilters | None
    basis_trials: int
    tol: float
    tail: float
    without_link: bool = True

    def runs(self, profile, comps, dt, learned=None, basis=None) -> ScanResult:
        """The runs of one setpoint; with `learned` (`basis`) the ``ilc`` (``basis``) run
        replays that force (those coefficients)."""
        duration = profile.end + self.tail
        bare = self.bare
        step = default_step(bare, profile.max_frequency_hz) if dt is None else dt
        check_scan_steps(duration, step, len(comps))  # each run keeps its signals
        check_window_samples(self.window, step)
        advance = 0.0 if bare.ff is None or bare.sampled is None else (
            bare.ff.advance_samples * bare.sampled.period)
        averaged = None if bare.sampled is not None else step  # see setpoint_samples
        none = None
        if self.without_link or "none" in comps or "ilc" in comps:
            none = simulate(bare, profile, duration, step)
        runs, ilc, model, basis_result = [], None, None, None
        for c in comps:
            if c == "none":
                sim = none
            elif c == "model" or (c == "basis" and basis is None and model is None):
                model = simulate(self.modelled, profile, duration, step,
                                 force=self.terms.force_function(profile, advance, averaged))
                sim = model
            if c == "ilc" and learned is not None:
                sim = simulate(bare, profile, duration, step, force=learned)
            elif c == "ilc":
                ilc = learn(bare, profile, duration, self.ilc_trials, self.ilc_filters, step,
                            first=none)
                sim = ilc.last
            elif c == "basis" and basis is not None:
                sim = simulate(self.modelled, profile, duration, step,
                               force=basis.force_function(profile, advance, averaged))
            elif c == "basis":
                basis_result = learn_basis(self.modelled, self.learned_terms, profile,
                                           duration, self.basis_trials, step, first=model,
                                           advance=advance)
                sim = basis_result.last
            runs.append(scan_metrics(sim.t, sim.e, profile, self.window, c, self.tol))
        without = None if none is None or not self.without_link else scan_metrics(
            none.t, none.e_linear, profile, self.window, "without link", self.tol)
        return ScanResult(profile, self.window, self.tol, (sim if none is None else none).r,
                          runs, without, ilc, basis=basis_result)
