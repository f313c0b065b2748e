"""The figure a measured plant's fit draws of itself (:meth:`FrfFit.plot
<motionhyst.plants.frf_fit.FrfFit.plot>`), in the style of :mod:`motionhyst.core.plotting`.
"""

from __future__ import annotations

import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

from motionhyst.core.plotting import minor_log_ticks, new_figure

__all__ = ["plot_frf_fit"]


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
    >>> from motionhyst.plants.figures import plot_frf_fit
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
