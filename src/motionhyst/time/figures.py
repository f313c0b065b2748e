"""The figure a time simulation draws of itself (:meth:`Simulation.plot
<motionhyst.time.simulation_result.Simulation.plot>`), in the style of
:mod:`motionhyst.core.plotting`.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from motionhyst.core.plotting import LINEAR_COLOR, new_figure

__all__ = ["plot_simulation"]


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
