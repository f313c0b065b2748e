"""The figure of the stability analysis: the Nyquist curve of the loop seen by the link
against the link's ``-1/N(A, omega)`` loci (:mod:`motionhyst.analysis.stability`).

Examples
--------
>>> from motionhyst import default_scenario
>>> from motionhyst.analysis.stability import stability
>>> fig = plot_stability(stability(default_scenario().loop()))
>>> sorted(fig.motionhyst_data)
['A', 'G', 'loci', 'locus_omega', 'omega', 'predicted']
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from motionhyst.present.figures import new_figure

__all__ = ["plot_multipliers", "plot_stability"]

#: Loci drawn at most (every k-th amplitude of the result's grid).
MAX_LOCI = 12


def plot_stability(result, ax=None) -> Figure:
    """``G(j omega)`` and ``-1/N(A, omega)`` in the complex plane, the predicted cycles marked.

    The view is that of the Nyquist curve (1.3 times its largest value); loci outside
    it are left out of view, and the title says how far the nearest one is.

    Parameters
    ----------
    result : StabilityResult
        What :func:`~motionhyst.analysis.stability.stability` returned.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; default: a new figure.

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
    fig, axes = new_figure(1, ax=ax)
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
    a.legend(loc="best")
    fig.motionhyst_data.update(omega=result.omega, G=G, A=A, loci=loci,
                               locus_omega=result.locus_omega,
                               predicted=[p.to_dict() for p in result.predicted])
    return fig


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
