"""The force-displacement loops of a link model for sines of several amplitudes, in the
style of :mod:`motionhyst.core.plotting` (what an identified link's ``plot()`` draws).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from motionhyst.core.plotting import new_figure

__all__ = ["plot_link"]


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
    >>> from motionhyst.hysteresis import MaxwellSlip
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
