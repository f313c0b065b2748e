"""Figures of the paper (Figs. 5-11), drawn from motionhyst's results.

One style for all figures; each function returns a matplotlib Figure and
attaches the plotted data as ``fig.motionhyst_data`` (a dict of arrays), so
callers and tests can check what is shown without reading pixels.
"""

from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from motionhyst.analysis.figures import fig11_errors
from motionhyst.core.plotting import (
    LINEAR_COLOR,
    MODE2_COLOR,
    MODE3_COLOR,
    STYLE,
    minor_log_ticks,
    new_figure,
)
from motionhyst.hysteresis import Hysteresis, Jenkins
from motionhyst.hysteresis.periodic import TWO_PI

__all__ = ["describing_function_curve", "fig5_loops", "fig6_modes", "fig7_time",
           "fig8_describing_function", "fig9_quasilinear_plant", "fig10_mismatch", "fig11_errors",
           "switching_instants"]

if TYPE_CHECKING:
    from motionhyst.analysis.quasilinear import QuasiLinearAnalysis
    from motionhyst.analysis.steady import SteadyState
    from motionhyst.controllers.loop import Loop


def _phase_deg(P) -> np.ndarray:
    """Unwrapped phase in degrees, starting in (-360, 0]."""
    ph = np.degrees(np.unwrap(np.angle(P)))
    return ph - 360.0 * np.ceil(ph[0] / 360.0)


def _grid(loop: Loop, f_range, n: int) -> np.ndarray:
    """`n` log-spaced frequencies in `f_range` [Hz]; for raw measured data its lines there."""
    if not loop.plant.is_lti:
        f = loop.plant.frequency_hz
        return f[(f >= f_range[0]) & (f <= f_range[1])]
    return np.geomspace(*_frequency_range(loop, f_range), n)


def _frequency_range(loop: Loop, f_range):
    """`f_range` clipped to the measured range of a measured plant."""
    lo, hi = loop.plant.frequency_range_hz or f_range
    return max(f_range[0], lo), min(f_range[1], hi)


def describing_function_curve(el: Hysteresis, A: float, omega: ArrayLike, stride: int = 12,
                              rtol: float = 1e-4) -> np.ndarray:
    """``D(A, omega)`` (eq. 7) of `el` along a dense frequency grid, for a figure's curve.

    A rate-independent link has one value.  For a rate-dependent one (LuGre),
    each value is a periodic steady state; along a smooth curve of hundreds
    of frequencies most of them can be interpolated: ``D`` is computed on
    every `stride`-th frequency and at the last, and interpolated in
    between by a cubic spline in ``log omega``; it is also computed at the
    middle of each interval, and wherever the spline is off there by more
    than `rtol` times ``|D|`` every frequency of the interval is computed.
    The rest is interpolated through the coarse grid and the middles.

    Parameters
    ----------
    el : Hysteresis
        The link model.
    A : float
        Amplitude [m].
    omega : array_like
        Increasing angular frequencies [rad/s], > 0.
    stride : int
        Frequencies per interval of the first, coarse grid.
    rtol : float
        Largest relative error of the interpolation at the intervals' middles.

    Returns
    -------
    ndarray of complex
        ``D`` at `omega` [N/m].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import LuGre
    >>> from motionhyst.present.plots import describing_function_curve
    >>> el = LuGre(sigma0=20.0, sigma1=0.1, sigma2=0.01, fc=0.05, fs=0.06, vs=0.01)
    >>> w = 2 * np.pi * np.geomspace(0.1, 100.0, 200)
    >>> D = describing_function_curve(el, 0.01, w)
    >>> exact = el.describing_function(0.01, w)
    >>> bool(np.max(np.abs(D - exact) / np.abs(exact)) < 1e-4)
    True
    """
    w = np.asarray(omega, dtype=float)
    if el.rate_independent:
        return np.full(w.shape, complex(el.describing_function(A)))
    n = len(w)
    if n < 4 * stride or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        return np.asarray(el.describing_function(A, w), dtype=complex)
    from scipy.interpolate import CubicSpline

    x = np.log(w)
    D = np.full(n, np.nan, dtype=complex)
    coarse = np.unique(np.r_[np.arange(0, n, stride), n - 1])
    D[coarse] = el.describing_function(A, w[coarse])
    middle = (coarse[:-1] + coarse[1:]) // 2
    D[middle] = el.describing_function(A, w[middle])
    guess = CubicSpline(x[coarse], D[coarse])(x[middle])
    missed = np.abs(guess - D[middle]) > rtol * np.abs(D[middle])
    for i in np.nonzero(missed)[0]:
        todo = np.arange(coarse[i] + 1, coarse[i + 1])
        D[todo] = el.describing_function(A, w[todo])
    # the rest from the coarse grid and the middles of the smooth intervals only: a sharp
    # turn computed point by point would make a spline through it ring into its neighbours
    knots = np.union1d(coarse, middle[~missed])
    rest = np.isnan(D)
    D[rest] = CubicSpline(x[knots], D[knots])(x[rest])
    return D


def _sine_loop(el: Hysteresis, A: float, frequency_hz: float | None = None):
    """One period of the periodic response to ``x = A sin(theta)``: ``x, w``."""
    return el.sine_loop(A, None if el.rate_independent else TWO_PI * frequency_hz)


def _force_scale(el: Hysteresis) -> float:
    """Total slip (Coulomb) force of the element [N]: the scale of its loops."""
    return float(np.sum(el.fc))


def _describe(el: Hysteresis, frequency_hz: float | None) -> str:
    def show(v):
        return "[" + ", ".join(f"{x:g}" for x in v) + "]" if isinstance(v, list) else f"{v:g}"

    params = ", ".join(f"{k} = {show(v)}" for k, v in el.to_dict().items() if k != "model")
    at = "" if el.rate_independent else f", f = {frequency_hz:g} Hz"
    return f"{el.name} element\n{params}{at}"


def _check_frequency(el: Hysteresis, frequency_hz: float | None) -> None:
    if not el.rate_independent and frequency_hz is None:
        raise ValueError(f"the {el.name} element is rate-dependent: give frequency_hz")


def fig5_loops(el: Hysteresis, zetas: ArrayLike = (0.25, 0.5, 0.75, 1.25),
               frequency_hz: float | None = None):
    """Fig. 5: displacement-force loops of the element for sinusoids at several zeta.

    ``zeta = fc / (k A)`` (eq. 4); for other models ``fc`` is the total slip
    force and ``k`` the initial stiffness, and a rate-dependent element needs
    `frequency_hz`.

    Parameters
    ----------
    el : Hysteresis
        The link element.
    zetas : array_like
        ``zeta = fc / (k A)`` of the loops (eq. 4).
    frequency_hz : float, optional
        Frequency [Hz] for a rate-dependent element.

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> len(fig5_loops(Jenkins(k=20.0, fc=0.05)).axes)
    1
    """
    _check_frequency(el, frequency_hz)
    fig, (ax,) = new_figure()
    fc = _force_scale(el)
    for z in zetas:
        A = fc / (el.initial_stiffness * z)
        x, w = _sine_loop(el, A, frequency_hz=frequency_hz)
        ax.plot(x * 1e3, w, label=f"zeta = {z:g} (A = {A * 1e3:.3g} mm)")
        fig.motionhyst_data[f"zeta={z:g}"] = np.vstack([x, w])
    ax.axhline(fc, color="0.5", ls=":", lw=0.8)
    ax.axhline(-fc, color="0.5", ls=":", lw=0.8)
    ax.set_xlabel("displacement x [mm]")
    ax.set_ylabel("force w [N]")
    if el.defines_zeta:
        ax.set_title(f"Fig. 5: Jenkins element, k = {el.k:g} N/m, fc = {el.fc:g} N")
    else:
        ax.set_title(f"Fig. 5: {_describe(el, frequency_hz)}", fontsize=9)
    ax.legend()
    return fig


def fig6_modes(el: Jenkins, zeta_mode2: float = 0.4, zeta_mode3: float = 0.7):
    """Fig. 6: the two nonlinear modes: stick-to-slip at x w <= 0 (mode 2) and x w > 0 (mode 3).

    Parameters
    ----------
    el : Jenkins
        The Jenkins element.
    zeta_mode2 : float
        zeta of the mode-2 loop.
    zeta_mode3 : float
        zeta of the mode-3 loop.

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> len(fig6_modes(Jenkins(k=20.0, fc=0.05)).axes)
    1
    """
    fig, (ax,) = new_figure()
    for z, color, mode in ((zeta_mode2, MODE2_COLOR, 2), (zeta_mode3, MODE3_COLOR, 3)):
        A = el.fc / (el.k * z)
        x, w = _sine_loop(el, A)
        slip = np.isclose(np.abs(w), el.fc)
        onset = np.nonzero(slip & ~np.roll(slip, 1))[0]
        ax.plot(x * 1e3, w, color=color, label=f"mode {mode}: zeta = {z:g}")
        ax.plot(x[onset] * 1e3, w[onset], "o", color="tab:blue", ms=5)
        fig.motionhyst_data[f"mode{mode}"] = np.vstack([x, w])
        fig.motionhyst_data[f"mode{mode}_onsets"] = np.vstack([x[onset], w[onset]])
    ax.axvline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("displacement x [mm]")
    ax.set_ylabel("force w [N]")
    ax.set_title("Fig. 6: modes 2 and 3 of the element (dots: stick to slip)")
    ax.legend()
    return fig


def switching_instants(el: Jenkins, A: float, frequency_hz: float) -> np.ndarray:
    """Switching instants ``tau_i`` of the Jenkins element for ``x = A sin(2 pi f t)`` [s].

    Within one period ``[0, 1/f)``: stick begins where ``x`` reverses
    (``omega t = pi/2, 3 pi/2``) and slip begins where the stuck spring
    reaches ``-+fc`` (``omega t = pi + gamma, 2 pi + gamma``, ``gamma`` of
    eq. 6).  Sorted; empty for ``zeta >= 1`` (no slip).

    Parameters
    ----------
    el : Jenkins
        The Jenkins element.
    A : float
        Amplitude [m].
    frequency_hz : float
        Frequency [Hz].

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> switching_instants(Jenkins(k=20.0, fc=0.05), 0.01, 1.0).round(4).tolist()
    [0.25, 0.4167, 0.75, 0.9167]
    """
    z = float(el.zeta(A))
    if z >= 1.0:
        return np.zeros(0)
    gamma = np.arcsin(2.0 * z - 1.0)
    theta = np.remainder([np.pi / 2, np.pi + gamma, 3 * np.pi / 2, 2 * np.pi + gamma], TWO_PI)
    return np.sort(theta) / (TWO_PI * frequency_hz)


def fig7_time(el: Jenkins, A: float, frequency_hz: float = 1.0):
    """Fig. 7: input x(t) and output w(t) over a period, switching instants, first harmonic.

    Upper panel the input ``x = A sin(2 pi f t)``; lower panel the force
    ``w(t)`` (eq. 5) with the slip intervals shaded, the switching instants
    ``tau_i`` (eq. 6) marked, and the first harmonic kept by the describing
    function (eq. 7).

    Parameters
    ----------
    el : Jenkins
        The Jenkins element.
    A : float
        Amplitude [m].
    frequency_hz : float
        Frequency [Hz].

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> len(fig7_time(Jenkins(k=20.0, fc=0.05), 0.01).axes)               # x(t) and w(t)
    2
    """
    fig, (ax_x, ax) = new_figure(2)
    x, w = _sine_loop(el, A)
    t = np.linspace(0.0, 1.0 / frequency_hz, len(x))
    D = el.describing_function(A)
    w1 = A * np.abs(D) * np.sin(TWO_PI * frequency_hz * t + np.angle(D))
    slip = np.isclose(np.abs(w), el.fc)
    taus = switching_instants(el, A, frequency_hz)
    ax_x.plot(t, x * 1e3, color="tab:blue", label="x(t) = A sin(2 pi f t)")
    ax_x.axhline(A * 1e3, color="0.5", ls=":", lw=0.8)
    ax_x.axhline(-A * 1e3, color="0.5", ls=":", lw=0.8)
    ax_x.annotate(f"A = {A * 1e3:.4g} mm", (t[-1], A * 1e3), xytext=(-4, -12),
                  textcoords="offset points", ha="right", fontsize=8, color="0.3")
    ax_x.set_ylabel("input x [mm]")
    ax.fill_between(t, -el.fc * 1.1, el.fc * 1.1, where=slip, color="0.85", step="mid",
                    label="slipping (|w| = fc)")
    ax.plot(t, w, color="k", label="w(t), exact (eq. 5)")
    ax.plot(t, w1, "--", color="tab:red", label="first harmonic (describing function, eq. 7)")
    for i, tau in enumerate(taus, start=1):
        for a in (ax_x, ax):
            a.axvline(tau, color="tab:green", ls="-.", lw=0.8)
        ax.annotate(f"tau{i}", (tau, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(2, -10), textcoords="offset points", fontsize=8,
                    color="tab:green")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("force w [N]")
    ax_x.set_title(f"Fig. 7: Jenkins element (k = {el.k:g} N/m, fc = {el.fc:g} N) for "
                   f"x = A sin(2 pi f t),\nA = {A * 1e3:.4g} mm, f = {frequency_hz:g} Hz, "
                   f"zeta = {el.zeta(A):.3g}; tau_i: switching instants (eq. 6)", fontsize=9)
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=7)
    fig.motionhyst_data.update(t=t, x=x, w=w, w_first_harmonic=w1, slip=slip, tau=taus)
    return fig


def fig8_describing_function(el: Hysteresis, zeta_range=(1e-3, 10.0),
                              frequency_hz: float | None = None,
                              zeta_op: float | None = None):
    """Fig. 8: ``|D| / k`` and angle of ``D`` against zeta (eq. 10), mode regions shaded.

    For other models than Jenkins, ``zeta = fc / (k A)`` with the total slip
    force and the initial stiffness, without the Jenkins element's modes; a
    rate-dependent element is drawn at `frequency_hz`.  `zeta_op` marks an
    operating point (the paper's section V: zeta = 0.25, ``|D| ~ 0.3 k``,
    angle ~50 deg) with its values.

    Parameters
    ----------
    el : Hysteresis
        The link element.
    zeta_range : (float, float)
        Range of zeta drawn.
    frequency_hz : float, optional
        Frequency [Hz] for a rate-dependent element.
    zeta_op : float, optional
        An operating point to mark.

    Examples
    --------
    >>> from motionhyst import Jenkins
    >>> len(fig8_describing_function(Jenkins(k=20.0, fc=0.05)).axes)      # |D|/k and angle
    2
    """
    _check_frequency(el, frequency_hz)
    fig, (ax1, ax2) = new_figure(2)
    jenkins = el.defines_zeta  # the paper's Jenkins element: slip modes by zeta (eq. 4)
    z = np.geomspace(*zeta_range, 800 if jenkins else 200)
    k0 = el.initial_stiffness
    omega = None if el.rate_independent else TWO_PI * frequency_hz
    D = el.describing_function(_force_scale(el) / (k0 * z), omega)
    if jenkins:
        for ax in (ax1, ax2):
            ax.axvspan(zeta_range[0], 0.5, color="tab:red", alpha=0.08, label="mode 2")
            ax.axvspan(0.5, 1.0, color="0.5", alpha=0.12, label="mode 3")
            ax.axvspan(1.0, zeta_range[1], color=LINEAR_COLOR, alpha=0.06,
                       label="linear (no slip)")
    ax1.semilogx(z, np.abs(D) / k0, color="k")
    ax2.semilogx(z, np.degrees(np.angle(D)), color="k")
    if zeta_op is not None and np.isfinite(zeta_op):
        D_op = complex(np.asarray(el.describing_function(
            _force_scale(el) / (k0 * zeta_op), omega)).ravel()[0])
        mag, ph = abs(D_op) / k0, float(np.degrees(np.angle(D_op)))
        # text where the curve is not: upper left of the rising |D|, upper right of the phase
        for ax, v, text, dx, ha in ((ax1, mag, f"|D|/k = {mag:.3g}", -6, "right"),
                                    (ax2, ph, f"angle D = {ph:.3g} deg", 6, "left")):
            ax.axvline(zeta_op, color="tab:orange", ls="--", lw=1)
            ax.plot([zeta_op], [v], "o", color="tab:orange", ms=5,
                    label=f"operating point zeta = {zeta_op:.3g}" if ax is ax1 else None)
            ax.annotate(text, (zeta_op, v), xytext=(dx, 6), textcoords="offset points",
                        fontsize=8, color="tab:orange", ha=ha)
        fig.motionhyst_data.update(zeta_op=zeta_op, D_op=D_op)
    ax1.set_ylabel("|D| / k [-]")
    ax2.set_ylabel("angle D [deg]")
    if jenkins:
        ax2.set_xlabel("zeta = fc / (k A) [-]")
        ax1.set_title("Fig. 8: describing function of the Jenkins element, eq. (10)")
        ax1.legend(loc="center left")
    else:
        ax2.set_xlabel("zeta = fc / (k A) [-], k the initial stiffness")
        ax1.set_title(f"Fig. 8: describing function, {_describe(el, frequency_hz)}",
                      fontsize=9)
    minor_log_ticks(fig)
    fig.motionhyst_data.update(zeta=z, abs_over_k=np.abs(D) / k0,
                               phase_deg=np.degrees(np.angle(D)))
    return fig


#: The link and stage the paper states for its Fig. 9 (section III-C): kJ = 1e4 N/m, fc = 100 N.
FIG9_PAPER_LINK = {"k": 1e4, "fc": 100.0}
FIG9_PAPER_STAGE = {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}


def _fig9_panel(ax1, ax2, P1, P2, el, zetas, f, f_star_hz, data, prefix=""):
    """Curves of eq. (12) for each zeta on one column of Fig. 9."""
    w = TWO_PI * f
    cmap = matplotlib.colormaps["viridis"]
    jenkins = el.defines_zeta  # the paper's Jenkins element: slip modes by zeta (eq. 4)
    fc_total = _force_scale(el)
    for i, z in enumerate(zetas):
        A = fc_total / (el.initial_stiffness * z)
        D = describing_function_curve(el, A, w)
        Pphi = P2 / (1.0 + D * P1)
        c = cmap(i / max(1, len(zetas) - 1))
        label = (f"zeta = {z:g} (A = {A * 1e3:.4g} mm)" if jenkins
                 else f"A = {A * 1e3:.4g} mm")
        ax1.semilogx(f, 20 * np.log10(np.abs(Pphi)), color=c, label=label)
        ax2.semilogx(f, _phase_deg(Pphi), color=c)
        data[f"{prefix}zeta={z:g}"] = Pphi
    ax1.semilogx(f, 20 * np.log10(np.abs(P2)), "k--", label="P2 (no link)")
    ax2.semilogx(f, _phase_deg(P2), "k--")
    if f_star_hz:
        for ax in (ax1, ax2):
            ax.axvline(f_star_hz, color="tab:red", ls=":", lw=1)
        ax1.annotate(f"f* = {f_star_hz:.3g} Hz (eq. 13)", (f_star_hz, 1.0),
                     xycoords=("data", "axes fraction"), xytext=(4, -12),
                     textcoords="offset points", color="tab:red", fontsize=8)
    ax1.set_ylabel("|P^phi| [dB re 1 m/N]")
    ax2.set_ylabel("angle P^phi [deg]")
    ax2.set_xlabel("frequency [Hz]")
    ax1.legend(loc="lower left", fontsize=7)
    data[f"{prefix}f"] = f
    data[f"{prefix}P2"] = P2


def fig9_quasilinear_plant(loop: Loop, zetas: ArrayLike = (0.01, 0.1, 0.25, 0.5, 0.75, 1.0),
                           f_range=(0.01, 100.0), f_star_hz: float | None = None,
                           paper: bool = True, paper_f_range=(0.1, 100.0)):
    """Fig. 9: Bode plot of the quasi-linear plant ``P^phi`` (eq. 12) for zeta in (0, 1].

    With `paper` (default) two columns: on the left the figure as the paper
    states it (section III-C: the Table I stage with a Jenkins link of
    ``kJ = 1e4 N/m``, ``fc = 100 N``, so ``f* = 3.4 Hz``), on the right the
    scenario's own loop (`loop`'s plant and link, ``f*`` = `f_star_hz`).
    For a Jenkins element the curves are labelled by zeta (eq. 4) and the
    amplitude; for other models by the amplitude ``fc_total / (k_total zeta)``.
    ``fig.motionhyst_data`` holds the scenario's curves (``f``, ``P2``,
    ``zeta=...``) and the paper's with the prefix ``paper_``.

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    zetas : array_like
        zeta of the curves, in (0, 1].
    f_range : (float, float)
        Frequency range [Hz].
    f_star_hz : float, optional
        ``f*`` to mark (eq. 13); default from the loop.
    paper : bool
        Add the paper's column beside the scenario's.
    paper_f_range : (float, float)
        Frequency range of that column [Hz].

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> len(fig9_quasilinear_plant(default_scenario().loop()).axes) >= 2
    True
    """
    from motionhyst.analysis.equations import f_star
    from motionhyst.core.lti import freqresp
    from motionhyst.hysteresis import Jenkins as _Jenkins
    from motionhyst.plants.two_mass import TwoMassStage

    el = loop.hysteresis
    with matplotlib.rc_context(STYLE):
        ncol = 2 if paper else 1
        fig = Figure(figsize=(11.0 if paper else 6.4, 5.6), layout="constrained")
        axes = fig.subplots(2, ncol, sharex="col", squeeze=False)
    for ax in axes.ravel():
        ax.grid(True, which="both", alpha=0.3)
    fig.motionhyst_data = {}
    if paper:
        stage = TwoMassStage(**FIG9_PAPER_STAGE)
        link = _Jenkins(**FIG9_PAPER_LINK)
        f = np.geomspace(*paper_f_range, 600)
        w = TWO_PI * f
        _fig9_panel(axes[0, 0], axes[1, 0], freqresp(stage.P1, w), freqresp(stage.P2, w), link,
                    zetas, f, f_star(link.k, stage.M), fig.motionhyst_data, prefix="paper_")
        axes[0, 0].set_title("as in the paper: Table I stage, Jenkins kJ = 1e4 N/m, fc = 100 N",
                             fontsize=9)
    f = _grid(loop, f_range, 600)
    w = TWO_PI * f
    _fig9_panel(axes[0, -1], axes[1, -1], freqresp(loop.P1, w), freqresp(loop.P2, w), el, zetas,
                f, f_star_hz, fig.motionhyst_data)
    units = {"k": " N/m", "fc": " N", "sigma0": " N/m", "sigma1": " N s/m", "sigma2": " N s/m",
             "fs": " N", "vs": " m/s"}
    params = [f"{k} = {v:g}{units.get(k, '')}" if not isinstance(v, list) else
              f"{k} = [{', '.join(f'{x:g}' for x in v)}]{units.get(k, '')}"
              for k, v in el.to_dict().items() if k != "model"]
    title = f"this scenario: {el.name} link, " + ", ".join(
        p.replace(" ", "\u00a0") for p in params)  # lines break between parameters only
    # a column is about 70 characters wide at this size: a longer title wraps
    title = textwrap.fill(title, 70 if paper else 120, break_long_words=False)
    axes[0, -1].set_title(title.replace("\u00a0", " "), fontsize=9)
    fig.suptitle("Fig. 9: quasi-linear plant P^phi = P2 / (1 + D P1), eq. (12); "
                 "0 dB = 1 m/N", fontsize=10)
    minor_log_ticks(fig)
    return fig


def fig10_mismatch(loop: Loop, analysis: QuasiLinearAnalysis,
                   exact: list[SteadyState] | None = None, f_range=(0.1, 1000.0)):
    """Fig. 10: ``|E|`` (eq. 18), asymptote (eq. 20), crossovers; exact points as markers.

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    analysis : QuasiLinearAnalysis
        The analysis whose points are marked.
    exact : list of SteadyState, optional
        Exact steady states to mark.
    f_range : (float, float)
        Frequency range [Hz].

    Examples
    --------
    >>> from motionhyst import analyze, default_scenario
    >>> loop = default_scenario().loop()
    >>> fig = fig10_mismatch(loop, analyze(loop, 0.01, [5.0, 10.0]))
    >>> len(fig.axes)
    1
    """
    from motionhyst.analysis.equations import mismatch_asymptote
    from motionhyst.analysis.quasilinear import loop_mismatch, resolved_lines
    from motionhyst.core.lti import freqresp

    fig, (ax,) = new_figure()
    f = _grid(loop, f_range, 800)
    w = TWO_PI * f
    E = loop_mismatch(loop, f, analysis.amplitude, describing_function=describing_function_curve(
        loop.hysteresis, analysis.amplitude, w))
    Pr = 1.0 / (loop.M * (1j * w) ** 2)
    P2 = freqresp(loop.P2, w)
    Pf2 = Pr - P2 if loop.plant.Pf2 is None else freqresp(loop.plant.Pf2, w)
    Et = mismatch_asymptote(Pr, Pf2, analysis.D)
    if not loop.plant.is_lti:  # raw data: only the lines that resolve Pf2
        ok = resolved_lines(loop.plant, P2, Pf2)
        ax.loglog(f[~ok], np.abs(E[~ok]), "x", color="0.6", ms=4,
                  label="measured lines where Pf2 = Pr - P2 is not resolved (noise)")
        E, Et = np.where(ok, E, np.nan), np.where(ok, Et, np.nan)
    style = "-" if loop.plant.is_lti else "-o"  # data: the measured lines
    ax.loglog(f, np.abs(E), style, ms=2, color="k",
              label="|E| = |e / e_hat|, eq. (18): quasi-linear mismatch")
    ax.loglog(f, np.abs(Et), "--", color="tab:red",
              label="|E~| = |Pr^2 D / Pf2|, eq. (20): low-frequency asymptote")
    if exact:
        fe = np.array([s.frequency_hz for s in exact])
        Ee = np.array([abs(s.mismatch) for s in exact])  # nan where e_hat1 = 0
        ax.loglog(fe, Ee, "o", mfc="none", color="tab:blue",
                  label="|e1 / e_hat1| of the exact periodic steady state (nonlinear loop)")
        fig.motionhyst_data.update(f_exact=fe, E_exact=Ee)
    ax.axhline(1.0, color="0.5", lw=0.8, label="|E| = 1: no mismatch (eq. 22)")
    for fx, lab, ls in ((analysis.mismatch_crossover_hz, "eq. (21), |E~| = 1", ":"),
                        (analysis.mismatch_crossover_exact_hz,
                         "|E - 1| = 1 on eq. (18): added error = error without link", "-.")):
        if np.isfinite(fx):
            ax.axvline(fx, color="tab:green", ls=ls, lw=1, label=f"{lab}: {fx:.4g} Hz")
    ax.set_ylim(0.5, max(10.0, float(np.abs(E).max()) * 2))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|E| [-]")
    at = (f"zeta = {analysis.zeta:.3g}" if np.isfinite(analysis.zeta)
          else f"A = {analysis.amplitude:.3g} m")
    ax.set_title(f"Fig. 10: feedforward mismatch, {at}")
    ax.legend(loc="upper right", fontsize=7)
    minor_log_ticks(fig)
    fig.motionhyst_data.update(f=f, E=E, asymptote=Et)
    return fig
