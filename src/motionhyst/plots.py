"""Figures of the paper (Figs. 5-11), drawn from motionhyst's results.

One style for all figures; each function returns a matplotlib Figure and
attaches the plotted data as ``fig.motionhyst_data`` (a dict of arrays), so
callers and tests can check what is shown without reading pixels.
"""

from __future__ import annotations

import matplotlib
import matplotlib.ticker
import numpy as np
from numpy.typing import ArrayLike

from motionhyst.figures import LINEAR_COLOR, MODE2_COLOR, MODE3_COLOR, _figure
from motionhyst.hysteresis import Hysteresis, Jenkins
from motionhyst.loop import Loop
from motionhyst.quasilinear import QuasiLinearAnalysis, loop_mismatch, mismatch_asymptote
from motionhyst.steady import SteadyState
from motionhyst.systems import TWO_PI, freqresp


def _phase_deg(P) -> np.ndarray:
    """Unwrapped phase in degrees, starting in (-360, 0]."""
    ph = np.degrees(np.unwrap(np.angle(P)))
    return ph - 360.0 * np.ceil(ph[0] / 360.0)


def _frequency_range(loop: Loop, f_range):
    """`f_range` clipped to the measured range of a measured plant."""
    lo, hi = getattr(loop.plant, "frequency_range_hz", f_range)
    return max(f_range[0], lo), min(f_range[1], hi)


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
    """
    _check_frequency(el, frequency_hz)
    fig, (ax,) = _figure()
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
    """Fig. 6: the two nonlinear modes: stick-to-slip at x w <= 0 (mode 2) and x w > 0 (mode 3)."""
    fig, (ax,) = _figure()
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


def fig7_time(el: Jenkins, A: float, frequency_hz: float = 1.0):
    """Fig. 7: w(t) over a period, slip intervals shaded, and its first harmonic."""
    fig, (ax,) = _figure()
    x, w = _sine_loop(el, A)
    t = np.linspace(0.0, 1.0 / frequency_hz, len(x))
    D = el.describing_function(A)
    w1 = A * np.abs(D) * np.sin(TWO_PI * frequency_hz * t + np.angle(D))
    slip = np.isclose(np.abs(w), el.fc)
    ax.fill_between(t, -el.fc * 1.1, el.fc * 1.1, where=slip, color="0.85", step="mid",
                    label="slipping")
    ax.plot(t, w, color="k", label="w(t), exact")
    ax.plot(t, w1, "--", color="tab:red", label="first harmonic (describing function)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("force w [N]")
    ax.set_title(f"Fig. 7: element output for x = A sin(2 pi f t), zeta = {el.zeta(A):.3g}")
    ax.legend(loc="lower left")
    fig.motionhyst_data.update(t=t, w=w, w_first_harmonic=w1, slip=slip)
    return fig


def fig8_describing_function(el: Hysteresis, zeta_range=(1e-3, 10.0),
                              frequency_hz: float | None = None):
    """Fig. 8: ``|D| / k`` and angle of ``D`` against zeta (eq. 10), mode regions shaded.

    For other models than Jenkins, ``zeta = fc / (k A)`` with the total slip
    force and the initial stiffness, without the Jenkins element's modes; a
    rate-dependent element is drawn at `frequency_hz`.
    """
    _check_frequency(el, frequency_hz)
    fig, (ax1, ax2) = _figure(2)
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
    ax1.set_ylabel("|D| / k [-]")
    ax2.set_ylabel("angle D [deg]")
    if jenkins:
        ax2.set_xlabel("zeta = fc / (k A) [-]")
        ax1.set_title("Fig. 8: describing function of the Jenkins element, eq. (10)")
        ax1.legend(loc="upper left")
    else:
        ax2.set_xlabel("zeta = fc / (k A) [-], k the initial stiffness")
        ax1.set_title(f"Fig. 8: describing function, {_describe(el, frequency_hz)}",
                      fontsize=9)
    fig.motionhyst_data.update(zeta=z, abs_over_k=np.abs(D) / k0,
                               phase_deg=np.degrees(np.angle(D)))
    return fig


def fig9_quasilinear_plant(loop: Loop, zetas: ArrayLike = (0.01, 0.1, 0.25, 0.5, 0.75, 1.0),
                           f_range=(0.01, 100.0), f_star_hz: float | None = None):
    """Fig. 9: Bode plot of the quasi-linear plant ``P^phi`` (eq. 12) for zeta in (0, 1].

    For a Jenkins element the curves are labelled by zeta (eq. 4); for other
    models by the amplitude ``fc_total / (k_total zeta)`` they correspond to.
    """
    el = loop.hysteresis
    fig, (ax1, ax2) = _figure(2)
    f = np.geomspace(*_frequency_range(loop, f_range), 600)
    w = TWO_PI * f
    P1, P2 = freqresp(loop.P1, w), freqresp(loop.P2, w)
    cmap = matplotlib.colormaps["viridis"]
    jenkins = el.defines_zeta  # the paper's Jenkins element: slip modes by zeta (eq. 4)
    fc_total = _force_scale(el)
    for i, z in enumerate(zetas):
        A = fc_total / (el.initial_stiffness * z)
        D = el.describing_function(A, w if not el.rate_independent else None)
        Pphi = P2 / (1.0 + D * P1)
        c = cmap(i / max(1, len(zetas) - 1))
        label = f"zeta = {z:g}" if jenkins else f"A = {A:.3g} m"
        ax1.semilogx(f, 20 * np.log10(np.abs(Pphi)), color=c, label=label)
        ax2.semilogx(f, _phase_deg(Pphi), color=c)
        fig.motionhyst_data[f"zeta={z:g}"] = Pphi
    ax1.semilogx(f, 20 * np.log10(np.abs(P2)), "k--", label="P2 (no link)")
    ax2.semilogx(f, _phase_deg(P2), "k--")
    if f_star_hz:
        for ax in (ax1, ax2):
            ax.axvline(f_star_hz, color="tab:red", ls=":", lw=1)
        ax1.annotate(f"f* = {f_star_hz:.3g} Hz", (f_star_hz, ax1.get_ylim()[1]),
                     xytext=(4, -12), textcoords="offset points", color="tab:red")
    ax1.set_ylabel("|P^phi| [dB re 1 m/N]")
    ax2.set_ylabel("angle P^phi [deg]")
    ax2.set_xlabel("frequency [Hz]")
    ax1.set_title("Fig. 9: quasi-linear plant, eq. (12)")
    ax1.legend(ncol=2, loc="lower left")
    fig.motionhyst_data.update(f=f, P2=P2)
    return fig


def fig10_mismatch(loop: Loop, analysis: QuasiLinearAnalysis,
                   exact: list[SteadyState] | None = None, f_range=(0.1, 1000.0)):
    """Fig. 10: ``|E|`` (eq. 18), asymptote (eq. 20), crossovers; exact points as markers."""
    fig, (ax,) = _figure()
    f = np.geomspace(*_frequency_range(loop, f_range), 800)
    E = loop_mismatch(loop, f, analysis.amplitude)
    w = TWO_PI * f
    Pr = 1.0 / (loop.M * (1j * w) ** 2)
    Pf2 = freqresp(loop.plant.Pf2, w) if hasattr(loop.plant, "Pf2") else Pr - freqresp(loop.P2, w)
    Et = mismatch_asymptote(Pr, Pf2, analysis.D)
    ax.loglog(f, np.abs(E), color="k", label="|E|, eq. (18)")
    ax.loglog(f, np.abs(Et), "--", color="tab:red", label="asymptote, eq. (20)")
    if exact:
        fe = np.array([s.frequency_hz for s in exact])
        Ee = np.array([abs(s.mismatch) for s in exact])
        ax.loglog(fe, Ee, "o", mfc="none", color="tab:blue",
                  label="exact steady state (nonlinear loop)")
        fig.motionhyst_data.update(f_exact=fe, E_exact=Ee)
    ax.axhline(1.0, color="0.5", lw=0.8)
    for fx, lab, ls in ((analysis.mismatch_crossover_hz, "eq. (21)", ":"),
                        (analysis.mismatch_crossover_exact_hz, "|E - 1| = 1", "-.")):
        if np.isfinite(fx):
            ax.axvline(fx, color="tab:green", ls=ls, lw=1, label=f"crossover {lab}: {fx:.3g} Hz")
    ax.set_ylim(0.5, max(10.0, float(np.abs(E).max()) * 2))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|E| [-]")
    at = (f"zeta = {analysis.zeta:.3g}" if np.isfinite(analysis.zeta)
          else f"A = {analysis.amplitude:.3g} m")
    ax.set_title(f"Fig. 10: feedforward mismatch, {at}")
    ax.legend(loc="upper right")
    fig.motionhyst_data.update(f=f, E=E, asymptote=Et)
    return fig


def fig11_errors(states: list[SteadyState], mismatch_df: ArrayLike,
                 harmonics_df: list[ArrayLike] | None = None):
    """Fig. 11: steady-state error over a period, with and without hysteresis, and the DF.

    `harmonics_df`, per state, the predicted error harmonics 1, 2, ... from the
    higher-order describing functions, adds their sum as a dotted line.
    """
    fig, axes = _figure(len(states), sharex=False)
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


def fig_frf_fit(fit, f_range: tuple[float, float] | None = None):
    """Bode figure of a measured plant (markers) and its rigid-body + modes fit (lines).

    `fit` is a :class:`motionhyst.frf_fit.FrfFit`.  The fitted ``P1`` and
    ``P2`` are drawn densely (so a resonance between measured lines shows),
    with the fitted modes' frequencies marked.
    """
    f_data = fit.frequency_hz
    lo, hi = f_range if f_range is not None else (f_data.min() / 1.5, f_data.max() * 1.5)
    f = np.geomspace(lo, hi, 2000)
    if fit.plant.modes:
        f = np.union1d(f, [m.frequency_hz for m in fit.plant.modes if lo <= m.frequency_hz <= hi])
    m1, m2 = fit.plant.response(TWO_PI * f)
    fig, (ax1, ax2) = _figure(2)
    for P, D, color, name in ((m1, fit.P1_data, "tab:blue", "P1 (collocated)"),
                              (m2, fit.P2_data, "tab:red", "P2 (non-collocated)")):
        ax1.semilogx(f, 20 * np.log10(np.abs(P)), color=color, label=f"{name}, fit")
        ax1.semilogx(f_data, 20 * np.log10(np.abs(D)), "o", ms=3, mfc="none", color=color,
                     label=f"{name}, measured")
        ph = _phase_deg(P)
        # the data on the fit's branch of the phase
        at_data = fit.plant.response(TWO_PI * f_data)[0 if P is m1 else 1]
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
    ax1.set_title(f"Measured plant and fit: rigid body M = {fit.plant.M:.4g} kg + "
                  f"{len(fit.plant.modes)} mode(s), RMS relative error "
                  f"{fit.rms_relative_error:.2g}", fontsize=9)
    ax1.legend(loc="lower left")
    fig.motionhyst_data.update(f=f, P1_fit=m1, P2_fit=m2, f_data=f_data, P1_data=fit.P1_data,
                               P2_data=fit.P2_data)
    return fig
