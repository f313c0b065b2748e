"""The old home of the stability analysis's figures, now in :mod:`motionhyst.analysis.figures`
(:func:`~motionhyst.analysis.figures.plot_stability`,
:func:`~motionhyst.analysis.figures.plot_multipliers`); importable from here as before.
"""

from __future__ import annotations

from motionhyst.analysis.figures import MAX_LOCI as MAX_LOCI
from motionhyst.analysis.figures import plot_multipliers as plot_multipliers
from motionhyst.analysis.figures import plot_stability as plot_stability

__all__: list[str] = []
