"""The figure an input-output identification draws of itself (:meth:`IOIdentification.plot
<motionhyst.identify.io_results.IOIdentification.plot>`), in the style of
:mod:`motionhyst.core.plotting`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from motionhyst.core.plotting import LINEAR_COLOR, new_figure

__all__ = ["plot_io_identification"]


def plot_io_identification(fit, ax=None) -> Figure:
    """Per record, the measured and the predicted position against time, and their difference.

    The prediction is the identified model's output as the fit compared it with the record:
    its offsets and initial state included (a floating stage's periodic output, known up
    to a constant, at the record's mean).

    Parameters
    ----------
    fit : IOIdentification
        What :func:`~motionhyst.identify.input_output.identify_io` returned.
    ax : sequence of matplotlib.axes.Axes, optional
        Two axes per record to draw into (positions, residual); default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        Its ``motionhyst_data`` holds, per record name, the rows ``t``, measured,
        predicted.

    Raises
    ------
    ValueError
        If the result carries no records (made by hand, not by an identification).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.identify.input_output import identify_io
    >>> from motionhyst.identify.io_records import IORecord
    >>> from motionhyst.plants import QuasiStatic
    >>> from motionhyst.time.quasi_static import displacement_from_force
    >>> t = np.arange(1000) / 500.0
    >>> u = 300.0 * np.sin(2 * np.pi * 2 * t)
    >>> y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
    >>> fig = plot_io_identification(identify_io([IORecord(t, u, y, "sine")], Jenkins,
    ...                                          plant=QuasiStatic))
    >>> len(fig.axes), fig.motionhyst_data["sine"].shape
    (2, (3, 1000))
    """
    if not fit.data:
        raise ValueError("this identification carries no records to plot (made by hand, not "
                         "by identify_io)")
    fig, axes = new_figure(2 * len(fit.data), sharex=False, ax=ax)
    start = 0
    for i, rec in enumerate(fit.data):
        res = np.asarray(fit.residuals[start:start + rec.y.size])
        start += rec.y.size
        predicted = rec.y + res
        top, bottom = axes[2 * i], axes[2 * i + 1]
        top.plot(rec.t, rec.y * 1e3, color="k", label="measured")
        top.plot(rec.t, predicted * 1e3, "--", color=LINEAR_COLOR, label="identified model")
        top.set_ylabel("y [mm]")
        top.set_title(f"{rec.name}: fit RMS {np.sqrt(np.mean(res ** 2)):.3g} m", loc="left",
                      fontsize=9)
        top.legend(loc="upper right")
        bottom.plot(rec.t, res * 1e6, color="tab:red")
        bottom.set_ylabel("model - measured [um]")
        bottom.set_xlabel("time [s]")
        fig.motionhyst_data[rec.name] = np.vstack([rec.t, rec.y, predicted])
    return fig
