"""The figure style, and the figures that results draw of themselves (``result.plot()``).

Each function returns a matplotlib :class:`~matplotlib.figure.Figure` (not
attached to pyplot, so nothing is shown or kept open) and attaches the
plotted data as ``fig.motionhyst_data``.  The paper's figures are in
:mod:`motionhyst.present.plots`, in the same style.  This module imports no analysis:
the results call it (lazily) from their ``plot()`` methods.  Figures are
saved several at a time by :mod:`motionhyst.present.figure_writer` (its
:class:`FigureWriter` and :func:`save_figures` are also importable from here).

Examples
--------
>>> from motionhyst import analyze, default_scenario
>>> fig = analyze(default_scenario().loop(), 0.01, [5.0, 10.0]).plot()
>>> fig.motionhyst_data["f"].tolist()
[5.0, 10.0]
"""

from __future__ import annotations

import matplotlib
import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

from motionhyst.present.figure_writer import FigureWriter, save_figures

__all__ = ["STYLE", "DecadeFormatter", "FigureWriter", "MinorLogLocator", "minor_log_ticks",
           "new_figure", "plot_analysis", "plot_describing_function", "plot_digital",
           "plot_frf_fit", "plot_link", "plot_margins", "plot_simulation", "plot_steady_state",
           "save_figures"]

STYLE = {
    "figure.figsize": (6.4, 4.2), "figure.dpi": 110, "savefig.dpi": 150, "axes.grid": True,
    "grid.alpha": 0.3, "axes.spines.top": False, "axes.spines.right": False, "font.size": 9,
    "legend.fontsize": 8, "legend.frameon": False, "lines.linewidth": 1.4,
    # titles just above their axes (nothing is drawn above an axes but its title): matplotlib
    # would otherwise look for a place clear of the axes' tick labels at every draw
    "axes.titley": 1.0,
}
MODE2_COLOR, MODE3_COLOR, LINEAR_COLOR = "0.15", "tab:red", "tab:blue"


class MinorLogLocator(matplotlib.ticker.LogLocator):
    """Minor ticks of a log axis at 2 and 5 times each decade (a 1-2-5 grid).

    None when the axis spans more than `max_decades` decades, where minor
    grid lines would be a few pixels apart.  Besides reading better, the
    figures draw faster: each tick is a handful of matplotlib artists, and
    the full 2-9 minor ticks were a fifth of the time spent saving a figure.

    Parameters
    ----------
    max_decades : float
        Widest axis (in decades) that has minor ticks.

    Examples
    --------
    >>> from motionhyst.present.figures import MinorLogLocator
    >>> MinorLogLocator().tick_values(1.0, 100.0).tolist()
    [0.2, 0.5, 2.0, 5.0, 20.0, 50.0, 200.0, 500.0]
    >>> MinorLogLocator(max_decades=6).tick_values(1e-1, 1e7).tolist()
    []
    """

    def __init__(self, max_decades: float = 6.0) -> None:
        super().__init__(subs=(2.0, 5.0))
        self.max_decades = float(max_decades)

    def tick_values(self, vmin: float, vmax: float):
        """The minor ticks between `vmin` and `vmax` (none on an axis of too many decades).

        Parameters
        ----------
        vmin : float
            Lower end of the axis.
        vmax : float
            Upper end of the axis.
        """
        if vmin > 0 and vmax > 0 and abs(np.log10(vmax / vmin)) > self.max_decades:
            return np.array([])
        return super().tick_values(vmin, vmax)


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076"
                                            "\u2077\u2078\u2079")


class DecadeFormatter(matplotlib.ticker.LogFormatterSciNotation):
    """Labels of a log axis with its decades as plain text: ``10⁻¹``, ``10⁰``, ``10³``.

    Other labels as :class:`matplotlib.ticker.LogFormatterSciNotation` gives
    them.  Plain text with Unicode superscripts looks like matplotlib's math
    text and needs no math-text layout at each draw.

    Examples
    --------
    >>> from motionhyst.present.figures import DecadeFormatter
    >>> DecadeFormatter()(0.01), DecadeFormatter()(1000.0)
    ('10⁻²', '10³')
    """

    def __call__(self, x: float, pos: int | None = None) -> str:
        """The label of the tick at `x`."""
        label = super().__call__(x, pos)
        if label and x > 0:
            exponent = round(float(np.log10(x)))
            if np.isclose(x, 10.0**exponent, rtol=1e-9, atol=0.0):
                return "10" + str(exponent).translate(_SUPERSCRIPT)
        return label


def minor_log_ticks(where) -> None:
    """Give every log axis the 1-2-5 minor ticks of :class:`MinorLogLocator` and the labels of
    :class:`DecadeFormatter`.

    Called once the data is plotted (setting a log scale resets an axis's locators).

    Parameters
    ----------
    where : Figure or sequence of Axes
        A figure (all its axes) or the axes a result drew into.

    Examples
    --------
    >>> fig, (ax,) = new_figure()
    >>> _ = ax.loglog([1.0, 100.0], [1.0, 10.0])
    >>> minor_log_ticks(fig)
    >>> type(ax.xaxis.get_minor_locator()).__name__
    'MinorLogLocator'
    """
    for ax in getattr(where, "axes", where):
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                axis.set_minor_locator(MinorLogLocator())
                axis.set_major_formatter(DecadeFormatter())


def new_figure(nrows: int = 1, sharex: bool = True, ax=None):
    """A figure of `nrows` axes in one column, in the package's style; or the axes `ax` given.

    What every ``plot(ax=...)`` of a result calls: without `ax` a new
    :class:`~matplotlib.figure.Figure` (not attached to pyplot); with `ax`
    the caller's axes, drawn into as they are, and their figure.  Either way
    the figure carries ``fig.motionhyst_data``, the dictionary the plots put
    their data in.

    Parameters
    ----------
    nrows : int
        Number of axes the plot draws.
    sharex : bool
        New axes share their x axis.
    ax : matplotlib.axes.Axes or sequence of Axes, optional
        The axes to draw into: one Axes if `nrows` is 1, else a sequence of `nrows`.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : ndarray of Axes, shape (nrows,)

    Raises
    ------
    ValueError
        If `ax` holds another number of axes than `nrows`.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> mine = Figure().subplots(1, 2)
    >>> fig, axes = new_figure(2, ax=mine)
    >>> fig is mine[0].figure, len(axes), fig.motionhyst_data
    (True, 2, {})
    """
    if ax is not None:
        axes = np.empty(1, dtype=object)
        if hasattr(ax, "figure") and not hasattr(ax, "__len__"):
            axes[0] = ax
        else:
            axes = np.array(list(ax), dtype=object)
        if axes.size != nrows:
            raise ValueError(f"this plot draws {nrows} axes; ax= gives {axes.size}")
        fig = axes[0].figure
        if not hasattr(fig, "motionhyst_data"):
            fig.motionhyst_data = {}
        return fig, axes
    with matplotlib.rc_context(STYLE):
        fig = Figure(figsize=(6.4, 4.2 if nrows == 1 else 5.6), layout="constrained")
        axes = fig.subplots(nrows, 1, sharex=sharex, squeeze=False)
    for ax in axes.ravel():
        ax.grid(True, which="both", alpha=0.3)
    fig.motionhyst_data = {}
    return fig, axes[:, 0]



def plot_analysis(analysis, ax=None) -> Figure:
    """The mismatch of a quasi-linear analysis at its frequencies.

    `analysis` is a :class:`~motionhyst.analysis.quasilinear.QuasiLinearAnalysis`.

    ``|E|`` (eq. 18) and the asymptote ``|E~|`` (eq. 20) at the analysed
    frequencies, the crossover of eq. (21) and the exact crossover
    ``|E - 1| = 1``.  (:func:`~motionhyst.present.plots.fig10_mismatch` draws it on a dense grid
    from the loop.)

    Parameters
    ----------
    analysis : QuasiLinearAnalysis
        What :func:`~motionhyst.analysis.quasilinear.analyze` returned.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import analyze, default_scenario
    >>> from motionhyst.present.figures import plot_analysis
    >>> fig = plot_analysis(analyze(default_scenario().loop(), 0.01, [5.0, 10.0, 15.0]))
    >>> type(fig).__name__                                 # save it with fig.savefig(...)
    'Figure'
    """
    fig, axes = new_figure(ax=ax)
    (ax,) = axes
    f = np.array([p.frequency_hz for p in analysis.points])
    E = np.array([p.value for p in analysis.points])
    Et = np.array([p.asymptote for p in analysis.points])
    ax.loglog(f, np.abs(E), "o-", color="k", label="|E|, eq. (18)")
    ax.loglog(f, np.abs(Et), "s--", color="tab:red", mfc="none", label="|E~|, eq. (20)")
    ax.axhline(1.0, color="0.5", lw=0.8)
    for fx, lab, ls in ((analysis.mismatch_crossover_hz, "eq. (21)", ":"),
                        (analysis.mismatch_crossover_exact_hz, "|E - 1| = 1", "-.")):
        if np.isfinite(fx):
            ax.axvline(fx, color="tab:green", ls=ls, lw=1, label=f"crossover {lab}: {fx:.3g} Hz")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|E| [-]")
    ax.set_title(f"Feedforward mismatch, A_r = {analysis.amplitude:.3g} m")
    ax.legend(loc="upper right")
    minor_log_ticks(axes)
    fig.motionhyst_data.update(f=f, E=E, asymptote=Et)
    return fig


def plot_steady_state(state, ax=None) -> Figure:
    """One period of a :class:`~motionhyst.analysis.steady.SteadyState`: the error with and without
    hysteresis.

    Parameters
    ----------
    state : SteadyState
        One periodic steady state.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import default_scenario, periodic_steady_state
    >>> from motionhyst.present.figures import plot_steady_state
    >>> fig = plot_steady_state(periodic_steady_state(default_scenario().loop(), 0.01, 5.0))
    >>> len(fig.axes) >= 1
    True
    """
    fig, axes = new_figure(ax=ax)
    (ax,) = axes
    ts = state.time_series()
    t_ms = ts["t"] * 1e3
    ax.plot(t_ms, ts["e"] * 1e9, color="k", label="with hysteresis (exact)")
    ax.plot(t_ms, ts["e_linear"] * 1e9, color=LINEAR_COLOR, label="without hysteresis")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("e [nm]")
    ax.set_title(f"Periodic steady state, r = {state.amplitude:g} m sin(2 pi "
                 f"{state.frequency_hz:g} Hz t)")
    ax.legend()
    fig.motionhyst_data.update(t=ts["t"], e=ts["e"], e_linear=ts["e_linear"])
    return fig


def plot_frf_fit(fit, f_range: tuple[float, float] | None = None, ax=None) -> Figure:
    """Bode figure of a measured plant (markers) and its rigid-body + modes fit (lines).

    `fit` is a :class:`motionhyst.plants.frf_fit.FrfFit`.  The fitted ``P1`` and
    ``P2`` are drawn densely (so a resonance between measured lines shows),
    with the fitted modes' frequencies marked.

    Parameters
    ----------
    fit : FrfFit
        The fit of a measured plant.
    f_range : (float, float), optional
        Frequency range [Hz]; default: the data's, widened by 1.5 each side.
    ax : sequence of two matplotlib.axes.Axes, optional
        Axes to draw into (magnitude, phase); default: a new figure.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.present.figures import plot_frf_fit
    >>> from motionhyst.plants.frf_fit import ModalPlant, fit_frf
    >>> from motionhyst.plants.two_mass import TwoMassStage
    >>> exact = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    >>> f = np.geomspace(1.0, 3000.0, 60)
    >>> fig = plot_frf_fit(fit_frf(f, *exact.response(2 * np.pi * f)))
    >>> len(fig.axes) >= 2                                 # magnitude and phase
    True
    """
    f_data = fit.frequency_hz
    lo, hi = f_range if f_range is not None else (f_data.min() / 1.5, f_data.max() * 1.5)
    f = np.geomspace(lo, hi, 2000)
    if fit.plant.modes:
        f = np.union1d(f, [m.frequency_hz for m in fit.plant.modes if lo <= m.frequency_hz <= hi])
    m1, m2 = fit.plant.response(2 * np.pi * f)
    fig, axes = new_figure(2, ax=ax)
    ax1, ax2 = axes
    delayed = " (delay divided out)" if fit.delay_s > 0 else ""
    for P, D, color, name in ((m1, fit.P1_data, "tab:blue", "P1 (collocated)"),
                              (m2, fit.P2_data, "tab:red", "P2 (non-collocated)")):
        ax1.semilogx(f, 20 * np.log10(np.abs(P)), color=color, label=f"{name}, fit")
        ax1.semilogx(f_data, 20 * np.log10(np.abs(D)), "o", ms=3, mfc="none", color=color,
                     label=f"{name}, measured{delayed}")
        ph = np.degrees(np.unwrap(np.angle(P)))
        ph -= 360.0 * np.ceil(ph[0] / 360.0)  # starting in (-360, 0]
        # the data on the fit's branch of the phase
        at_data = fit.plant.response(2 * np.pi * f_data)[0 if P is m1 else 1]
        ph_data = np.interp(f_data, f, ph) + np.degrees(np.angle(D / at_data))
        ax2.semilogx(f, ph, color=color)
        ax2.semilogx(f_data, ph_data, "o", ms=3, mfc="none", color=color)
    for i, m in enumerate(fit.plant.modes):
        for ax in (ax1, ax2):
            ax.axvline(m.frequency_hz, color="0.5", ls=":", lw=0.8)
        ax1.annotate(f"mode {i + 1}: {m.frequency_hz:.4g} Hz", (m.frequency_hz, 1.0),
                     xycoords=("data", "axes fraction"), xytext=(3, -10),
                     textcoords="offset points", fontsize=7, color="0.3")
    ax2.yaxis.set_major_locator(matplotlib.ticker.MultipleLocator(90))
    ax1.set_ylabel("magnitude [dB re 1 m/N]")
    ax2.set_ylabel("phase [deg]")
    ax2.set_xlabel("frequency [Hz]")
    delay = f", delay {fit.delay_s * 1e6:.3g} us" if fit.delay_s > 0 else ""
    ax1.set_title(f"Measured plant and fit: rigid body M = {fit.plant.M:.4g} kg + "
                  f"{len(fit.plant.modes)} mode(s){delay},\nRMS relative error "
                  f"{fit.rms_relative_error:.2g}", fontsize=9)
    ax1.legend(loc="lower left")
    minor_log_ticks(axes)
    fig.motionhyst_data.update(f=f, P1_fit=m1, P2_fit=m2, f_data=f_data, P1_data=fit.P1_data,
                               P2_data=fit.P2_data)
    return fig



def plot_link(link, amplitudes=None, title: str | None = None, ax=None) -> Figure:
    """Force-displacement loops of a link model for sines of several amplitudes.

    Parameters
    ----------
    link : Hysteresis
        A rate-independent link model.
    amplitudes : array_like, optional
        Amplitudes [m]; default 0.5, 1, 2 and 4 times the displacement
        ``fc / k`` at which the whole link slips (total slip force over
        initial stiffness).
    title : str, optional
        Figure title (default: the model's name).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import MaxwellSlip
    >>> fig = plot_link(MaxwellSlip(k=[8.0, 4.0], fc=[0.01, 0.06]), amplitudes=[0.01])
    >>> x, w = fig.motionhyst_data["A=0.01"]
    >>> round(float(w.max()), 6)                    # the first element slips, the second not
    0.05
    """
    fig, axes = new_figure(ax=ax)
    (ax,) = axes
    fc = float(np.sum(link.fc))
    if amplitudes is None:
        amplitudes = fc / link.initial_stiffness * np.array([0.5, 1.0, 2.0, 4.0])
    for A in np.atleast_1d(amplitudes):
        x, w = link.sine_loop(float(A))
        ax.plot(x * 1e3, w, label=f"A = {A * 1e3:.3g} mm")
        fig.motionhyst_data[f"A={A:g}"] = np.vstack([x, w])
    ax.set_xlabel("displacement x [mm]")
    ax.set_ylabel("force w [N]")
    ax.set_title(title or f"{link.name} link")
    ax.legend()
    return fig


def plot_simulation(sim, ax=None) -> Figure:
    """A :class:`~motionhyst.time.simulation.Simulation`: the error with and without the link, and
    the link force, against time.

    Parameters
    ----------
    sim : Simulation
        A time simulation.
    ax : sequence of two matplotlib.axes.Axes, optional
        Axes to draw into (top, bottom); default: a new figure.

    Examples
    --------
    >>> from motionhyst import SineReference, default_scenario, simulate
    >>> fig = plot_simulation(simulate(default_scenario().loop(), SineReference(0.01, 5.0), 0.1))
    >>> sorted(fig.motionhyst_data)
    ['e', 'e_linear', 't', 'w']
    """
    fig, axes = new_figure(2, ax=ax)
    ax1, ax2 = axes
    ax1.plot(sim.t, sim.e * 1e9, color="k", label="with the link")
    ax1.plot(sim.t, sim.e_linear * 1e9, color=LINEAR_COLOR, label="without the link")
    ax1.set_ylabel("e [nm]")
    ax1.set_title("Time simulation from rest")
    ax1.legend()
    ax2.plot(sim.t, sim.w, color="tab:red")
    ax2.set_ylabel("link force w [N]")
    ax2.set_xlabel("time [s]")
    fig.motionhyst_data.update(t=sim.t, e=sim.e, e_linear=sim.e_linear, w=sim.w)
    return fig


def plot_margins(margins, ax=None) -> Figure:
    """The open loop ``|L|`` and the sensitivity ``|S| = 1 / |1 + L|`` of a
    :class:`~motionhyst.analysis.margins.LoopMargins` in dB against frequency.

    Two decades either side of the bandwidth (``|L|`` falling through 0 dB, marked) and
    the peak of ``|S|`` (the modulus margin ``1 / max |S|``, marked).

    Parameters
    ----------
    margins : LoopMargins
        What :func:`~motionhyst.analysis.margins.loop_margins` returned.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import default_scenario, loop_margins
    >>> loop = default_scenario().loop()
    >>> fig = plot_margins(loop_margins(loop.controller, loop.P2))
    >>> sorted(fig.motionhyst_data)
    ['L', 'S', 'f']
    """
    if margins.frequency_hz is None:
        raise ValueError("these margins carry no frequency response to plot (made by hand, "
                         "not by loop_margins)")
    fig, axes = new_figure(ax=ax)
    (ax,) = axes
    f = np.asarray(margins.frequency_hz)
    L = np.asarray(margins.open_loop)
    centre = margins.bandwidth_hz
    if not np.isfinite(centre):
        centre = margins.modulus_margin_hz
    if np.isfinite(centre):  # two decades either side of the crossover: where the margins are
        keep = (f >= centre / 100.0) & (f <= centre * 100.0)
        f, L = f[keep], L[keep]
    S = 1.0 / (1.0 + L)
    ax.semilogx(f, 20 * np.log10(np.abs(L)), color="k", label="|L| = |C P2|")
    ax.semilogx(f, 20 * np.log10(np.abs(S)), color=LINEAR_COLOR, label="|S| = 1 / |1 + L|")
    ax.axhline(0.0, color="0.5", lw=0.8)
    if np.isfinite(margins.bandwidth_hz):
        ax.axvline(margins.bandwidth_hz, color="tab:green", ls=":", lw=1,
                   label=f"bandwidth {margins.bandwidth_hz:.4g} Hz")
    peak = -20 * np.log10(margins.modulus_margin)
    ax.plot([margins.modulus_margin_hz], [peak], "o", color="tab:red", mfc="none",
            label=f"max |S| = {peak:.3g} dB at {margins.modulus_margin_hz:.4g} Hz")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("magnitude [dB]")
    ax.set_title(f"Loop margins ({margins.evaluated_on})")
    ax.legend(loc="lower left")
    minor_log_ticks(axes)
    fig.motionhyst_data.update(f=f, L=L, S=S)
    return fig


def plot_digital(comparison, ax=None) -> Figure:
    """``|E|`` of eq. (18) (lines) and exact (circles) of each variant of a
    :class:`~motionhyst.analysis.digital.DigitalComparison` (continuous, sampled, sampled
    with the feedforward advanced).

    Parameters
    ----------
    comparison : DigitalComparison
        What :func:`~motionhyst.analysis.digital.compare_digital` returned.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.analysis.digital import compare_digital
    >>> fig = plot_digital(compare_digital(default_scenario().loop(), 0.01, [10.0]))
    >>> sorted(fig.motionhyst_data)
    ['continuous', 'sampled', 'sampled, feedforward advanced']
    """
    fig, axes = new_figure(ax=ax)
    (ax,) = axes
    for v in comparison.variants:
        f = np.array([p.frequency_hz for p in v.points])
        E_df = np.array([p.mismatch_df for p in v.points])
        E_exact = np.array([p.mismatch_exact for p in v.points])
        line, = ax.semilogy(f, np.abs(E_df), "-", label=v.name)
        ax.semilogy(f, np.abs(E_exact), "o", color=line.get_color())
        fig.motionhyst_data[v.name] = np.vstack([f, E_df, E_exact])
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|E| [-]")
    ax.set_title(f"Digital loop at {comparison.sample_rate_hz:g} Hz, "
                 f"{comparison.delay_samples:g} samples of delay")
    ax.legend()
    return fig


def plot_describing_function(result, ax=None) -> Figure:
    """``|D| / k_init`` and the angle of ``D`` (eq. 7) against the amplitude, one curve per
    frequency.

    Parameters
    ----------
    result : DescribingFunctionResult
        What :func:`~motionhyst.analysis.describing.describing_function` returned.
    ax : sequence of two matplotlib.axes.Axes, optional
        Axes to draw into (magnitude, angle); default: a new figure.

    Examples
    --------
    >>> from motionhyst import Jenkins, describing_function
    >>> res = describing_function(Jenkins(k=20.0, fc=0.05), [0.001, 0.005, 0.01, 0.1])
    >>> fig = plot_describing_function(res)
    >>> fig.motionhyst_data["A"].tolist(), fig.motionhyst_data["D"].shape
    ([0.001, 0.005, 0.01, 0.1], (1, 4))
    """
    fig, axes = new_figure(2, ax=ax)
    ax1, ax2 = axes
    k_init = result.link.initial_stiffness
    freqs = list(dict.fromkeys(p.frequency_hz for p in result.points))
    A = np.array([p.amplitude for p in result.points if p.frequency_hz == freqs[0]])
    D = np.array([[p.value for p in result.points if p.frequency_hz == f] for f in freqs])
    scale = k_init if np.isfinite(k_init) and k_init > 0 else 1.0
    for f, d in zip(freqs, D, strict=True):
        label = "" if f is None else f"{f:g} Hz"
        ax1.plot(A, np.abs(d) / scale, "o-", ms=3, label=label)
        ax2.plot(A, np.degrees(np.angle(d)), "o-", ms=3, label=label)
    if np.all(A > 0):
        ax1.set_xscale("log")
    ax1.set_ylabel("|D| / k_init [-]" if scale == k_init else "|D| [N/m]")
    ax2.set_ylabel("angle D [deg]")
    ax2.set_xlabel("amplitude A [m]")
    ax1.set_title(f"Describing function of the {result.link.name} link (eq. 7)")
    if freqs[0] is not None:
        ax1.legend()
    minor_log_ticks(axes)
    fig.motionhyst_data.update(A=A, D=D, frequency_hz=freqs)
    return fig
