"""Whether one measured signal follows another at all: their coherence where they have power.

A record that determines a link relates its signals through the plant: in a closed loop the
position ``y1 = P1 (u - w)`` follows the actuator force ``u`` (the link force ``w`` is a
function of ``y1``), so ``u`` and ``y1`` are linearly related at the frequencies where they
move, up to the link's harmonics and the noise.  Their magnitude-squared coherence (Welch's
estimate over a few segments) is then near 1 where they have power; signals that are not
the same loop's (a noise column, another record's column, a column shuffled) have a
coherence near the estimate's floor, about one over the number of segments averaged.  The
check costs milliseconds and runs before any fit.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["COHERENCE_SEGMENTS", "MIN_COHERENCE", "band_coherence", "check_follows"]

COHERENCE_SEGMENTS = 8
"""Segments of a record in Welch's estimate (15 windows with half overlap): a floor of about
0.07 for independent signals."""

MIN_COHERENCE = 0.3
"""Least power-weighted coherence of a record whose signals follow each other.  Measured
(:func:`band_coherence` of ``u`` and ``y1``) on the paper's loop: with a two-element link,
3 s of a 2 Hz sine 1.000 (also with 1e-5 to 1e-3 m of encoder noise), half a period 0.999,
a multisine 0.5-11 Hz 0.916; with a 50 N link 0.987 (sine), 0.837 (multisine, 1e-5 m
noise); 0.008-0.087 when ``y1`` is white noise, shuffled or another sine, or ``u`` white
noise."""


def band_coherence(a: ArrayLike, b: ArrayLike, fs: float,
                   segments: int = COHERENCE_SEGMENTS) -> float:
    """The magnitude-squared coherence of `a` and `b`, averaged over frequency with the
    weight ``sqrt(P_a P_b)`` (normalised): near 1 where two signals are linearly related in
    the band where both have power, near ``1 / segments`` for independent ones.

    Parameters
    ----------
    a, b : array_like
        Two signals sampled together (equal length, at least ``4 segments`` samples).
    fs : float
        Their sampling rate [Hz].
    segments : int, optional
        Welch segments a record is cut into (half overlap).

    Returns
    -------
    float
        In [0, 1]; 0 when either signal is constant.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> u = np.sin(2 * np.pi * 2 * t) + 0.3 * np.sin(2 * np.pi * 7 * t)
    >>> y = np.convolve(u, np.ones(20) / 20, "same")        # u through a low-pass
    >>> noise = np.random.default_rng(0).standard_normal(t.size)
    >>> round(band_coherence(u, y, 1000.0), 2), band_coherence(u, noise, 1000.0) < 0.2
    (1.0, True)
    """
    from scipy.signal import coherence, welch

    x, y = (np.asarray(s, dtype=float) for s in (a, b))
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError("the two signals must be 1-D and of equal length")
    n = x.size // segments
    if n < 8 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return 0.0
    x, y = x - x.mean(), y - y.mean()
    _, c = coherence(x, y, fs, nperseg=n)
    _, px = welch(x, fs, nperseg=n)
    _, py = welch(y, fs, nperseg=n)
    w = np.sqrt(px / px.sum() * py / py.sum())
    total = float(w.sum())
    return float(np.sum(w * c) / total) if total > 0 else 0.0


def check_follows(t: ArrayLike, y1: ArrayLike, u: ArrayLike) -> None:
    """Refuse a closed-loop record whose position does not follow its force: ``y1`` and ``u``
    of one loop are coherent where they have power (:func:`band_coherence` at least
    :data:`MIN_COHERENCE`); a noise column, or another record's, would give elements fitted
    to nothing.

    Parameters
    ----------
    t, y1, u : array_like
        The record (as :func:`~motionhyst.identify.closed_loop.infer_link_force`).

    Raises
    ------
    ValueError
        One line with the coherence measured.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify.coherence import check_follows
    >>> t = np.arange(3000) / 1000.0
    >>> u = np.sin(2 * np.pi * 2 * t)
    >>> check_follows(t, -u / (2 * np.pi * 2) ** 2 / 20.0, u)          # a mass: follows
    >>> check_follows(t, np.random.default_rng(0).standard_normal(t.size), u)
    Traceback (most recent call last):
    ...
    ValueError: y1 does not follow u: their coherence where they have power is 0.0082 (...
    """
    ts = np.asarray(t, dtype=float)
    if ts.size < 2:
        return  # too short: infer_link_force says so
    coh = band_coherence(u, y1, 1.0 / float(np.median(np.diff(ts))))
    if coh < MIN_COHERENCE:
        raise ValueError(f"y1 does not follow u: their coherence where they have power is "
                         f"{coh:.2g} (a loop's position follows its force at about 1, "
                         f"unrelated signals at about 0.1; below {MIN_COHERENCE:g}): the "
                         f"columns are not one loop's, or one is noise; nothing identified")
