"""The figure style every plot shares, and the axes a result's ``plot(ax=)`` draws into.

The results draw themselves with these (each subpackage's ``figures`` module:
:mod:`motionhyst.analysis.figures`, :mod:`motionhyst.time.figures`, ...), and so do
the paper's figures (:mod:`motionhyst.present.plots`).  Only a ``plot()`` imports this
module, so that computing never loads matplotlib.  Every figure is a matplotlib
:class:`~matplotlib.figure.Figure` not attached to pyplot (nothing is shown or kept
open) and carries its plotted data as ``fig.motionhyst_data``.

Examples
--------
>>> fig, (ax,) = new_figure()
>>> _ = ax.plot([0.0, 1.0], [0.0, 2.0])
>>> fig.motionhyst_data
{}
"""

from __future__ import annotations

import logging

import matplotlib
import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

# matplotlib logs a "findfont: ... not found" line on stderr for each math font family its
# font cache lacks (a cache built without its own STIX fonts) and draws with DejaVu Sans: the
# figure is the same, and a command's stderr stays its one line
logging.getLogger("matplotlib.font_manager").setLevel(logging.ERROR)

__all__ = ["LINEAR_COLOR", "MODE2_COLOR", "MODE3_COLOR", "STYLE", "DecadeFormatter",
           "MinorLogLocator", "minor_log_ticks", "new_figure"]

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
    >>> from motionhyst.core.plotting import MinorLogLocator
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
    >>> from motionhyst.core.plotting import DecadeFormatter
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
