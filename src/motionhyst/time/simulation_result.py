"""The result of a time simulation of the loop: its signals on a time grid.

:class:`Simulation` is what :func:`motionhyst.time.simulation.simulate` returns, for
a continuous controller and for a sampled one
(:func:`motionhyst.time.sampled.simulate_sampled`), and what
:func:`motionhyst.time.simulation.simulate_chunks` yields piece by piece.

Examples
--------
>>> import numpy as np
>>> from motionhyst.time.simulation_result import Simulation
>>> t = np.linspace(0.0, 1e-3, 3)
>>> z = np.zeros(3)
>>> Simulation(t=t, r=z, e=z + 1e-6, y1=z, y2=z, u=z, w=z, e_linear=z).to_dict()["error_peak"]
1e-06
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.textfmt import g, table

__all__ = ["Simulation"]


@dataclass
class Simulation:
    """Result of :func:`~motionhyst.time.simulation.simulate`: signals on the time grid ``t`` [s].

    Attributes
    ----------
    t : ndarray
        Time [s].
    r, e, y1, y2 : ndarray
        Reference, tracking error ``r - y2``, and the two positions [m].
    u : ndarray
        Actuator force [N] (feedback plus feedforward).
    w : ndarray
        Hysteresis force [N].
    e_linear : ndarray
        Error of the same loop without hysteresis and without hysteresis
        feedforward [m].

    Examples
    --------
    >>> from motionhyst import SineReference, default_scenario, simulate
    >>> sim = simulate(default_scenario().loop(), SineReference(0.01, 5.0), 0.2)
    >>> list(sim.columns())                                # the CSV of ``simulate --time-series``
    ['time', 'reference', 'error', 'y1', 'y2', 'u', 'w', 'error_linear']
    >>> bool(abs(sim.w).max() <= 0.05)                      # the Jenkins link's force, |w| <= fc
    True
    >>> sim.to_dict()["samples"] == sim.t.size
    True
    """

    t: NDArray[np.float64]
    r: NDArray[np.float64]
    e: NDArray[np.float64]
    y1: NDArray[np.float64]
    y2: NDArray[np.float64]
    u: NDArray[np.float64]
    w: NDArray[np.float64]
    e_linear: NDArray[np.float64]

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """The signals by name, in CSV column order."""
        return {"time": self.t, "reference": self.r, "error": self.e, "y1": self.y1,
                "y2": self.y2, "u": self.u, "w": self.w, "error_linear": self.e_linear}

    def to_dict(self) -> dict:
        """JSON-ready summary: samples, step, and peak and RMS errors with and without the link.

        The signals themselves are in :meth:`columns` (CSV, not JSON).
        """
        def rms(x: NDArray[np.float64]) -> float:
            return float(np.sqrt(np.mean(x ** 2)))

        return {"samples": int(self.t.size), "duration_s": float(self.t[-1] - self.t[0]),
                "dt_s": float(self.t[1] - self.t[0]) if self.t.size > 1 else None,
                "error_peak": float(np.max(np.abs(self.e))), "error_rms": rms(self.e),
                "error_linear_peak": float(np.max(np.abs(self.e_linear))),
                "error_linear_rms": rms(self.e_linear),
                "link_force_peak": float(np.max(np.abs(self.w)))}

    def __str__(self) -> str:
        d = self.to_dict()
        return "\n".join([
            f"Time simulation from rest: {d['samples']} samples over {g(d['duration_s'])} s "
            f"(dt = {g(d['dt_s'])} s)",
            table(["", "peak |e| [m]", "rms e [m]"],
                  [["with the link", g(d["error_peak"]), g(d["error_rms"])],
                   ["without", g(d["error_linear_peak"]), g(d["error_linear_rms"])]]),
            f"  peak link force {g(d['link_force_peak'])} N"])

    def plot(self, ax=None):
        """The error with and without the link, and the link force, against time
        (:func:`motionhyst.time.figures.plot_simulation`).

        Parameters
        ----------
        ax : sequence of 2 matplotlib.axes.Axes, optional
            Axes to draw into (error, link force); default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.time.figures import plot_simulation

        return plot_simulation(self, ax=ax)
