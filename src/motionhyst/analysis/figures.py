"""The figures the analyses' results draw of themselves (``result.plot()``).

One function a result: the quasi-linear analysis, the steady state, the margins, the
sampled loop, the describing function, the stability analysis and its Floquet
multipliers, and Fig. 11 (the steady state against the describing function's
prediction).  Each takes the result and optional axes, returns a matplotlib
:class:`~matplotlib.figure.Figure` in the style of :mod:`motionhyst.core.plotting` and
puts its data in ``fig.motionhyst_data``.  They read the results' attributes only: this
module imports no analysis, the results import it inside their ``plot()``.

Examples
--------
>>> from motionhyst import analyze, default_scenario
>>> fig = analyze(default_scenario().loop(), 0.01, [5.0, 10.0]).plot()
>>> fig.motionhyst_data["f"].tolist()
[5.0, 10.0]
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from motionhyst.core.plotting import LINEAR_COLOR, minor_log_ticks, new_figure
from motionhyst.hysteresis.periodic import TWO_PI

__all__ = ["fig11_errors", "plot_analysis", "plot_describing_function", "plot_digital",
           "plot_margins", "plot_multipliers", "plot_stability", "plot_steady_state"]

#: Loci drawn at most (every k-th amplitude of the result's grid).
MAX_LOCI = 12


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
    >>> from motionhyst.analysis.figures import plot_analysis
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
    >>> from motionhyst.analysis.figures import plot_steady_state
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


def plot_stability(result, ax=None) -> Figure:
    """``G(j omega)`` and ``-1/N(A, omega)`` in the complex plane, the predicted cycles marked.

    The view is that of the Nyquist curve (1.3 times its largest value); loci outside
    it are left out of view, and the title says how far the nearest one is.  When the
    result has exact cycles or a cycle predicted with its waveform (the cut at the
    integrator), a second panel shows one period of the link's displacement of each,
    from its upward crossing of 0.

    Parameters
    ----------
    result : StabilityResult
        What :func:`~motionhyst.analysis.stability.stability` returned.
    ax : matplotlib.axes.Axes or sequence of two Axes, optional
        Axes to draw into (one Axes: the Nyquist curve only); default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        With the plotted data as ``fig.motionhyst_data``.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.analysis.stability import stability
    >>> fig = plot_stability(stability(default_scenario().loop()))
    >>> fig.motionhyst_data["G"].shape == fig.motionhyst_data["omega"].shape
    True
    """
    waves = [p for p in result.predicted if p.waveform is not None]
    two = bool(result.exact or waves) and (ax is None or hasattr(ax, "__len__"))
    fig, axes = new_figure(2 if two else 1, sharex=False, ax=ax)
    a = axes[0]
    G, loci, A = result.nyquist, result.loci, result.amplitudes
    rate_independent = result.link is not None and result.link.rate_independent
    a.plot(G.real, G.imag, color="tab:blue", label="G(jw), w > 0")
    a.plot(G.real[:1], G.imag[:1], "o", ms=3, color="tab:blue")
    step = max(1, int(np.ceil(A.size / MAX_LOCI)))
    finite = np.isfinite(loci)
    if rate_independent:
        col = loci[:, 0]
        a.plot(col.real, col.imag, color="tab:red", label="-1/N(A)")
    else:
        for i in range(0, A.size, step):
            row = loci[i][finite[i]]
            a.plot(row.real, row.imag, color="tab:red", lw=0.8, alpha=0.6,
                   label="-1/N(A, w), one per A" if i == 0 else None)
    reach = 1.3 * float(np.max(np.abs(G)))
    a.set_xlim(-reach, reach)
    a.set_ylim(-reach, reach)
    a.set_aspect("equal", adjustable="box")
    for p in result.predicted:
        if p.method != "link":          # the cut's balance is not on this curve
            continue
        w = 2 * np.pi * p.frequency_hz
        z = G[int(np.argmin(np.abs(result.omega - w)))]
        a.plot(z.real, z.imag, "x" if not p.stable else "o", ms=7, mfc="none",
               color="k", label=f"{'stable' if p.stable else 'unstable'}: A = {p.amplitude:.3g} "
               f"m, {p.frequency_hz:.3g} Hz")
    nearest = float(np.min(np.abs(loci[finite]))) if finite.any() else np.inf
    a.set_title(f"Nyquist curve and -1/N of the {result.link.name} link")
    if nearest > reach:
        a.text(0.02, 0.02, f"-1/N lies beyond |z| = {nearest:.3g} m/N", transform=a.transAxes,
               fontsize=8)
    a.set_xlabel("Re [m/N]")
    a.set_ylabel("Im [m/N]")
    a.legend(loc="best", fontsize=8)
    fig.motionhyst_data.update(omega=result.omega, G=G, A=A, loci=loci,
                               locus_omega=result.locus_omega,
                               predicted=[p.to_dict() for p in result.predicted])
    if two:
        _plot_waveforms(axes[1], result, waves)
    return fig


def _from_upward_crossing(t, y):
    """One period of ``y`` rolled to start at its upward crossing of 0."""
    t, y = np.asarray(t)[:-1], np.asarray(y)[:-1]
    up = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    k = int(up[0]) + 1 if up.size else 0
    y = np.roll(y, -k)
    return np.append(t - t[0], t[-1] - t[0] + (t[1] - t[0])), np.append(y, y[0])


def _plot_waveforms(a, result, waves) -> None:
    """One period of the link's displacement of each exact and each predicted cycle."""
    data = {}
    for i, c in enumerate(result.exact):
        a.plot(c.t, c.y1, color="k", lw=1.5, label=f"exact: T = {c.period_s:.4g} s, "
               f"{c.peak_to_peak:.4g} m p-p")
        data[f"exact_{i}"] = (c.t, c.y1)
    for i, p in enumerate(waves):
        t, y = _from_upward_crossing(*p.waveform)
        a.plot(t, y, "--", color="tab:red", label=f"{p.method} DF: T = {1 / p.frequency_hz:.4g}"
               f" s, {p.peak_to_peak:.4g} m p-p")
        data[f"predicted_{i}"] = (t, y)
    a.set_xlabel("time from the upward crossing of y1 = 0 [s]")
    a.set_ylabel("y1 [m]")
    a.set_title("One period of the link's displacement")
    a.legend(loc="best", fontsize=8)
    result_data = a.figure.motionhyst_data
    result_data["waveforms"] = data


def plot_multipliers(result, ax=None) -> Figure:
    """Floquet multipliers in the complex plane with the unit circle.

    Parameters
    ----------
    result : FloquetResult
        What :func:`~motionhyst.analysis.floquet.steady_state_floquet` returned.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        With the plotted data as ``fig.motionhyst_data``.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.analysis.floquet import from_monodromy
    >>> fig = plot_multipliers(from_monodromy(np.diag([0.5, -0.2]), 1.0))
    >>> fig.motionhyst_data["multipliers"].tolist()
    [(0.5+0j), (-0.2+0j)]
    """
    fig, axes = new_figure(1, ax=ax)
    a = axes[0]
    th = np.linspace(0.0, 2 * np.pi, 361)
    a.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8, label="|mu| = 1")
    mu = np.asarray(result.multipliers, dtype=complex)
    a.plot(mu.real, mu.imag, "x", color="tab:red", label="multipliers")
    a.set_aspect("equal", adjustable="box")
    a.set_xlabel("Re mu")
    a.set_ylabel("Im mu")
    a.set_title(f"Floquet multipliers, T = {result.period_s:.4g} s: "
                f"{'stable' if result.stable else 'unstable'}")
    a.legend(loc="best")
    fig.motionhyst_data.update(multipliers=mu)
    return fig


def fig11_errors(states: list, mismatch_df: ArrayLike,
                 harmonics_df: list[ArrayLike] | None = None, ax=None):
    """Fig. 11: steady-state error over a period, with and without hysteresis, and the DF.

    Parameters
    ----------
    states : list of SteadyState
        The exact steady states, one panel each.
    mismatch_df : array_like of complex
        Eq. (18) per state: the describing function's prediction of the first harmonic.
    harmonics_df : list of array_like, optional
        Per state, the predicted error harmonics 1, 2, ... from the higher-order
        describing functions; their sum is added as a dotted line.
    ax : sequence of matplotlib.axes.Axes, optional
        One axes per state to draw into; default: a new figure.

    Examples
    --------
    >>> from motionhyst import compare_with_describing_function, default_scenario
    >>> cmp = compare_with_describing_function(default_scenario().loop(), 0.01, [5.0, 10.0])
    >>> len(cmp.plot().axes)                               # fig11_errors, one panel a frequency
    2
    """
    fig, axes = new_figure(len(states), sharex=False, ax=ax)
    hdf = harmonics_df if harmonics_df is not None else [None] * len(states)
    for ax, ss, E, h in zip(axes, states, np.atleast_1d(mismatch_df), hdf, strict=True):
        ts = ss.time_series()
        theta = TWO_PI * ss.frequency_hz * ts["t"]
        e_df = np.abs(E * ss.e_linear[1]) * np.sin(theta + np.angle(E * ss.e_linear[1]))
        t_ms = ts["t"] * 1e3
        ax.plot(t_ms, ts["e"] * 1e9, color="k", label="with hysteresis (exact)")
        ax.plot(t_ms, ts["e_linear"] * 1e9, color=LINEAR_COLOR, label="without hysteresis")
        ax.plot(t_ms, e_df * 1e9, "--", color="tab:red", label="describing function")
        if h is not None:
            h = np.asarray(h)
            n = np.arange(1, len(h) + 1)
            e_hdf = np.imag(np.exp(1j * np.outer(theta, n)) @ h)
            ax.plot(t_ms, e_hdf * 1e9, ":", color="tab:green",
                    label=f"higher-order DFs, n <= {len(h)}")
            fig.motionhyst_data[f"f={ss.frequency_hz:g} hosidf"] = e_hdf
        ax.set_ylabel("e [nm]")
        ax.set_title(f"f = {ss.frequency_hz:g} Hz", fontsize=9, loc="left")
        fig.motionhyst_data[f"f={ss.frequency_hz:g}"] = np.vstack(
            [ts["t"], ts["e"], ts["e_linear"], e_df])
    axes[-1].set_xlabel("time [ms]")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=2)
    fig.suptitle("Fig. 11: steady-state tracking error", fontsize=10)
    return fig
