"""A closed-loop record judged before its loop is built: is its inferred force a link's?"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from motionhyst.identify._link_checks import check_link, light_link_force, likely_cause

__all__ = ["check_closed_loop_link"]


def check_closed_loop_link(t: ArrayLike, y1: ArrayLike, u: ArrayLike, mechanics,
                           cutoff_hz: float, settle: int) -> None:
    """Refuse a continuous loop's record whose inferred link force is no link's, with numpy
    alone: the checks :func:`~motionhyst.identify.closed_loop.identify_closed_loop` makes
    before its fit (the force creates energy, is a spring's and a damper's, or grows with
    the speed; the slip that makes it a link's named), on the same force inferred through
    the plant's lumped masses, before python-control and the compiled filters load.

    Parameters
    ----------
    t, y1, u : array_like
        The record: uniform time [s], position of the actuated mass [m], force [N].
    mechanics : Mechanics
        The plant's lumped masses (:meth:`~motionhyst.plants.registry.Plant.mechanics`).
    cutoff_hz : float
        The prefilter's cut-off [Hz], and `settle` the first sample after its transient
        (:func:`~motionhyst.identify.records.prefilter_cutoff`).
    settle : int
        See `cutoff_hz`.

    Raises
    ------
    ValueError
        One line naming what makes the force no link's.

    Examples
    --------
    A made-up record: ``y1`` a 2 Hz sine, ``u`` a sine leading it, on the paper's stage:
    its inferred force is a spring's and a damper's.

    >>> from motionhyst import TwoMassStage
    >>> mech = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7).mechanics()
    >>> t = np.arange(20_000) / 1e4
    >>> y1, u = 0.01 * np.sin(4 * np.pi * t), 50.0 * np.sin(4 * np.pi * t + 0.2)
    >>> try:
    ...     check_closed_loop_link(t, y1, u, mech, 43.3, 2310)
    ... except ValueError as exc:
    ...     print(str(exc)[:85])
    no hysteresis in the record: the link force inferred through the plant is a spring's
    """
    ts, ys, us = (np.asarray(x, dtype=float) for x in (t, y1, u))

    def infer(tt, yy, uu):
        return light_link_force(tt, yy, uu, mechanics, cutoff_hz, settle)

    inferred = infer(ts, ys, us)
    if inferred is None:  # P1 with a zero at s = 0: the inference itself refuses it
        return
    lf, l_over_p1 = inferred
    try:
        check_link(lf, l_over_p1, us)
    except ValueError:
        cause = likely_cause(lf, us, infer)
        if not cause:
            raise
        check_link(lf, l_over_p1, us, cause)
