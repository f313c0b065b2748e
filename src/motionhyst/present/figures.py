"""The old home of the figure style and of the figures results draw of themselves.

Kept so that ``from motionhyst.present.figures import plot_analysis`` and the like go on
working: the style and :func:`new_figure` are in :mod:`motionhyst.core.plotting`, each
result's figure beside the result (:mod:`motionhyst.analysis.figures`,
:mod:`motionhyst.time.figures`, :mod:`motionhyst.plants.figures`,
:mod:`motionhyst.hysteresis.figures`).  Figures are saved several at a time by
:mod:`motionhyst.present.figure_writer` (its :class:`FigureWriter` and
:func:`save_figures` are also importable from here).
"""

from __future__ import annotations

from motionhyst.analysis.figures import plot_analysis as plot_analysis
from motionhyst.analysis.figures import plot_describing_function as plot_describing_function
from motionhyst.analysis.figures import plot_digital as plot_digital
from motionhyst.analysis.figures import plot_margins as plot_margins
from motionhyst.analysis.figures import plot_steady_state as plot_steady_state
from motionhyst.core.plotting import LINEAR_COLOR as LINEAR_COLOR
from motionhyst.core.plotting import MODE2_COLOR as MODE2_COLOR
from motionhyst.core.plotting import MODE3_COLOR as MODE3_COLOR
from motionhyst.core.plotting import STYLE as STYLE
from motionhyst.core.plotting import DecadeFormatter as DecadeFormatter
from motionhyst.core.plotting import MinorLogLocator as MinorLogLocator
from motionhyst.core.plotting import minor_log_ticks as minor_log_ticks
from motionhyst.core.plotting import new_figure as new_figure
from motionhyst.hysteresis.figures import plot_link as plot_link
from motionhyst.plants.figures import plot_frf_fit as plot_frf_fit
from motionhyst.present.figure_writer import FigureWriter, save_figures
from motionhyst.time.figures import plot_simulation as plot_simulation

__all__ = ["FigureWriter", "save_figures"]
