"""A closed-loop record judged before its loop is built: is its inferred force a link's?"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from motionhyst.identify._inferred_force_checks import check_link, light_link_force, likely_cause

__all__ = ["HELD_SHARE", "MIN_HELD_STEPS", "check_closed_loop_link", "check_not_held",
           "held_rows"]


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


MIN_HELD_STEPS = 20
"""Fewest changes of a closed-loop record's u on which it is judged held by a sampled
controller (:func:`held_rows`)."""

HELD_SHARE = 0.9
"""The share of u's changes that must fall on one grid of rows for u to be judged held."""


def held_rows(u: ArrayLike) -> tuple[int, int]:
    """How many rows a closed-loop record's u is held over (a sampled controller's
    zero-order hold, logged faster than it updates), and the first row where u takes a new
    value on that grid; ``(1, 0)`` for a u that is not so held.

    Held over ``k >= 2`` rows when at least :data:`MIN_HELD_STEPS` changes, of which
    :data:`HELD_SHARE` or more fall on one grid of every ``k``-th row, are ``k`` rows apart
    at the median: noise, or a quantised u changing now and then, changes at no such grid
    (0 of 133 continuous and sampled loops' records, u rounded to 0.1 mN to 1 N or to
    float32).

    Parameters
    ----------
    u : array_like
        The record's force column [N].

    Returns
    -------
    (int, int)
        The rows ``k`` and the first row (0-based) of the grid where u changes.

    Examples
    --------
    >>> import numpy as np
    >>> u = np.repeat(np.sin(np.arange(100) / 10.0), 4)[1:]     # held 4 rows, from row 3
    >>> held_rows(u)
    (4, 3)
    >>> held_rows(np.sin(np.arange(400) / 40.0))
    (1, 0)
    """
    changes = np.flatnonzero(np.diff(np.asarray(u, dtype=float)) != 0) + 1
    if changes.size < MIN_HELD_STEPS:
        return 1, 0
    k = int(np.median(np.diff(changes)))
    if k < 2:
        return 1, 0
    phases = np.bincount(changes % k, minlength=k)
    phase = int(np.argmax(phases))
    if phases[phase] < HELD_SHARE * changes.size:
        return 1, 0
    return k, phase


def check_not_held(t: ArrayLike, u: ArrayLike, what: str) -> None:
    """Refuse a closed-loop record whose u is held by a sampled controller (:func:`held_rows`)
    given with a continuous controller: its inferred force reads the staircase as ramps, a lag
    of half the controller's period and more, which the stage's inertia turns into a force no
    link makes (the paper's loop at 5 kHz logged at 10 kHz: "creates energy", -0.16 J, or "a
    time offset of 3 samples").

    Parameters
    ----------
    t, u : array_like
        The record's time [s] and force [N].
    what : str
        What to give the controller's rate (the scenario's section, the library's argument).

    Raises
    ------
    ValueError
        One line: the rows u is held over, the controller's rate, what to give.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(400) / 1e4
    >>> try:
    ...     check_not_held(t, np.repeat(np.sin(np.arange(200) / 10.0), 2), "s.toml's [controller]")
    ... except ValueError as exc:
    ...     print(str(exc)[:73])
    u is held over 2 rows (it takes a new value every 2 rows, from row 1): th
    """
    t = np.asarray(t, dtype=float)
    k, first = held_rows(u)
    if k < 2:
        return
    dt = float(np.median(np.diff(t)))
    rate = 1.0 / (k * dt)
    raise ValueError(f"u is held over {k} rows (it takes a new value every {k} rows, from row "
                     f"{first + 1}): the force of a controller sampled at about {rate:.6g} Hz, "
                     f"which a continuous controller reads as ramps, late by half its period "
                     f"and more; give {what} its sample_rate_hz = {rate:.6g} (and "
                     f"delay_samples), and the record at its samples (one row in {k}, from row "
                     f"{first + 1}); nothing identified")
