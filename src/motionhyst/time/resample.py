"""Sampled force records: their uniform time grid and band-limited upsampling.

A sampled force says nothing about the force between samples; like the
Bouc-Wen benchmark's own data, a record is taken as band-limited and upsampled
by zero-padding its spectrum (:func:`upsample`: exact for a periodic record,
the record's even extension otherwise, so that its ends do not ring) before
the open loop integrates it with a fine step (:mod:`motionhyst.time.openloop`).

Examples
--------
>>> import numpy as np
>>> t = np.arange(64) / 64
>>> fine = fine_input(np.sin(2 * np.pi * 3 * t), 4, periodic=True)   # one period and its start
>>> fine.size, bool(np.isclose(fine[4], np.sin(2 * np.pi * 3 / 64)))
(257, True)
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["BLOCK_NODES", "SINC_HALF_WIDTH", "STAMP_TOLERANCE", "block_samples", "check_record",
           "check_whole_periods", "fine_blocks", "fine_input", "held_nodes", "is_periodic_record",
           "period_upsampling_bytes", "sampling_rate", "upsample"]

#: Half-width of the windowed-sinc interpolator of a record that is not periodic [samples].
SINC_HALF_WIDTH = 64

#: Fine nodes of a block of :func:`fine_blocks` (at least 256 record samples a block)
BLOCK_NODES = 1 << 21


#: Largest distance of a time stamp from the record's uniform grid, in sampling intervals
#: (time columns written with few digits, e.g. 12.3457 s at 750 Hz, are off by up to 4 %)
STAMP_TOLERANCE = 0.05


def check_record(t: ArrayLike, force: ArrayLike, what: str = "force"
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A uniform time grid and a finite force of the same length, as float arrays.

    The grid is the uniform one nearest to `t` (:func:`sampling_rate`);
    stamps rounded when written are accepted within :data:`STAMP_TOLERANCE` of
    a sampling interval.  Raises ``ValueError`` (one line) otherwise.

    Parameters
    ----------
    t : array_like
        Time stamps [s].
    force : array_like
        Force at the stamps [N] (or the record's other quantity).
    what : str
        The quantity `force` is, as messages name it (``"displacement"``).

    Examples
    --------
    >>> t = np.round(np.arange(3000) / 750, 4)   # stamps written with 4 decimals
    >>> tt, u = check_record(t, np.zeros(3000))
    >>> print(f"{sampling_rate(tt):.4f}")
    750.0000
    >>> try:
    ...     check_record([0.0, 0.1, 0.3], [1.0, 2.0, 3.0])
    ... except ValueError as exc:
    ...     print(exc)
    time must increase in uniform steps (the stamp 0.1 s is 0.22 sampling intervals off the
    uniform grid)
    >>> try:
    ...     check_record([0.0, 0.1, 0.2], [1.0, np.nan, 3.0], what="displacement")
    ... except ValueError as exc:
    ...     print(exc)
    displacement must be finite: sample 2 (t = 0.1 s) is nan
    """
    tt = np.asarray(t, dtype=float)
    u = np.asarray(force, dtype=float)
    if tt.ndim != 1 or u.ndim != 1 or tt.size != u.size:
        raise ValueError(f"time and {what} must be 1-D and of equal length")
    if tt.size < 2:
        raise ValueError("a record needs at least 2 samples")
    for name, v in (("time", tt), (what, u)):
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            i = int(bad[0])
            at = f" (t = {tt[i]:.9g} s)" if name != "time" else ""
            more = f", and {bad.size - 1} more" if bad.size > 1 else ""
            raise ValueError(f"{name} must be finite: sample {i + 1}{at} is {v[i]}{more}")
    back = np.flatnonzero(np.diff(tt) <= 0)
    if back.size:
        i = int(back[0]) + 1
        raise ValueError(f"time must increase (sample {i + 1} at {tt[i]:.9g} s follows "
                         f"{tt[i - 1]:.9g} s)")
    t0, dt = _uniform_grid(tt)
    off = np.abs(tt - (t0 + dt * np.arange(tt.size))) / dt
    worst = int(np.argmax(off))
    if off[worst] > STAMP_TOLERANCE:
        raise ValueError(f"time must increase in uniform steps (the stamp {tt[worst]:.9g} s is "
                         f"{off[worst]:.2g} sampling intervals off the uniform grid)")
    return tt, u


def _uniform_grid(t: NDArray[np.float64]) -> tuple[float, float]:
    """Start and step of the uniform grid nearest to `t` (least squares)."""
    i = np.arange(t.size, dtype=float) - 0.5 * (t.size - 1)
    tc = t - t.mean()
    dt = float(i @ tc / (i @ i))
    return float(t.mean() - 0.5 * (t.size - 1) * dt), dt


def sampling_rate(t: NDArray[np.float64]) -> float:
    """Rate of a record's uniform grid [Hz]: the step fitted to all its stamps.

    Exact for exact stamps; for stamps rounded when written, far more exact
    than the difference of two of them.

    Parameters
    ----------
    t : ndarray
        The record's time stamps [s].

    Examples
    --------
    >>> import numpy as np
    >>> t = np.round(np.arange(1000) / 750, 4)     # stamps written with 4 decimals
    >>> print(f"{1 / (t[1] - t[0]):.1f} Hz from two stamps, {sampling_rate(t):.3f} Hz from all")
    769.2 Hz from two stamps, 750.000 Hz from all
    """
    return 1.0 / _uniform_grid(np.asarray(t, dtype=float))[1]


def upsample(u: ArrayLike, factor: int, periodic: bool) -> NDArray[np.float64]:
    """Band-limited upsampling of a record.

    Parameters
    ----------
    u : array_like
        Samples, 1-D, at least 2.
    factor : int
        New samples per old sample, >= 1.
    periodic : bool
        True if the record is a whole number of periods of a periodic signal:
        the spectrum is zero-padded (exact for a signal band-limited below half
        the sampling rate) when the record's length has no prime factor above
        7, else as below with the record wrapped around.  False: the record is
        extended by its mirror image at both ends (no jump) and interpolated by
        a Kaiser-windowed sinc (beta = 14) spanning 128 samples, flat to
        about 1e-7 up to 0.8 of the Nyquist frequency.

    Returns
    -------
    ndarray
        ``(len(u) - 1) * factor + 1`` samples (``len(u) * factor`` if periodic);
        every `factor`-th one is the input sample (to the interpolator's accuracy).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(64) / 64
    >>> fine = upsample(np.sin(2 * np.pi * 3 * t), 4, periodic=True)
    >>> bool(np.allclose(fine, np.sin(2 * np.pi * 3 * np.arange(256) / 256)))
    True
    >>> t = np.arange(2000) / 2000   # 40.1 cycles: not periodic in the record
    >>> fine = upsample(np.sin(2 * np.pi * 40.1 * t), 8, periodic=False)
    >>> exact = np.sin(2 * np.pi * 40.1 * np.arange(fine.size) / 16000)
    >>> bool(np.max(np.abs(fine - exact)[400:-400]) < 1e-5)   # away from the ends
    True
    """
    x = np.asarray(u, dtype=float)
    n = x.size
    if factor == 1:
        return x.copy()
    if periodic and _smooth_length(n):
        spec = np.fft.rfft(x)
        if n % 2 == 0:
            spec[-1] *= 0.5  # the Nyquist line splits between +f and -f
        padded = np.zeros(n * factor // 2 + 1, dtype=complex)
        padded[: spec.size] = spec
        return np.fft.irfft(padded, n * factor) * factor
    # scipy.signal (which imports scipy.optimize) only where used: checking a record does not
    from scipy.signal import firwin, resample_poly

    half = SINC_HALF_WIDTH
    pad = half + 2
    ext = np.pad(x, pad, mode="wrap" if periodic else "reflect")
    taps = firwin(2 * half * factor + 1, 1.0 / factor, window=("kaiser", 14.0))
    fine = resample_poly(ext, factor, 1, window=taps)[pad * factor:]
    return fine[: n * factor] if periodic else fine[: (n - 1) * factor + 1]


def _smooth_length(n: int) -> bool:
    for p in (2, 3, 5, 7):
        while n % p == 0:
            n //= p
    return n == 1


def fine_input(u: NDArray[np.float64], factor: int, periodic: bool) -> NDArray[np.float64]:
    """The record upsampled for integration: one period plus its first sample again if
    `periodic`, else ``(len(u) - 1) * factor + 1`` samples.

    A record from rest that holds two or more whole periods of its signal
    (:func:`is_periodic_record`) is upsampled as periodic (exact), otherwise
    through its mirror image (:func:`upsample`).

    Parameters
    ----------
    u : ndarray
        The record's samples.
    factor : int
        Fine samples per record sample, >= 1.
    periodic : bool
        True if `u` is one period of a periodic force.

    Examples
    --------
    >>> import numpy as np
    >>> fine_input(np.zeros(10), 4, periodic=False).size, fine_input(np.zeros(10), 4, True).size
    (37, 41)
    """
    if periodic:
        fine = upsample(u, factor, periodic=True)
        return np.concatenate([fine, fine[:1]])
    if is_periodic_record(u) is not None:
        return upsample(u, factor, periodic=True)[: (u.size - 1) * factor + 1]
    return upsample(u, factor, periodic=False)


def fine_blocks(u: NDArray[np.float64], factor: int, nodes: int | None = None
                ) -> Iterator[NDArray[np.float64]]:
    """:func:`fine_input` of a record from rest in consecutive blocks, for long records.

    Block ``k`` holds the fine nodes of record samples ``k S`` to ``(k + 1) S``
    (``S = max(256, nodes // factor)`` samples; the last block to the record's
    end), both ends included: consecutive blocks share a node.  Their nodes are
    those of ``fine_input(u, factor, periodic=False)``: bit for bit where the
    record is interpolated by the windowed sinc (each block from the samples
    around it), to rounding where it holds whole periods of its signal (the
    period's spectrum, zero-padded, repeated).  Memory: one block, whatever the
    record's length.

    Parameters
    ----------
    u : ndarray
        The record's samples (at least 2).
    factor : int
        Fine samples per record sample, >= 1.
    nodes : int, optional
        Fine nodes a block holds at most, but at least 256 samples' worth (default
        :data:`BLOCK_NODES`).

    Yields
    ------
    ndarray
        The blocks' fine nodes.

    Examples
    --------
    >>> import numpy as np
    >>> u = np.cos(np.arange(3201) / 7.0)
    >>> blocks = list(fine_blocks(u, 4, nodes=4000))
    >>> [b.size for b in blocks]
    [4001, 4001, 4001, 801]
    >>> whole = fine_input(u, 4, periodic=False)
    >>> bool(np.array_equal(np.concatenate([blocks[0]] + [b[1:] for b in blocks[1:]]), whole))
    True
    """
    x = np.asarray(u, dtype=float)
    n = x.size
    step = block_samples(factor, nodes)
    if n - 1 <= step or factor == 1:
        yield fine_input(x, factor, periodic=False)
        return
    p = is_periodic_record(x)
    if p is not None and _smooth_length(n):  # the whole record's spectrum: the period's
        period = upsample(x[:p], factor, periodic=True)
        for i0 in range(0, n - 1, step):
            i1 = min(i0 + step, n - 1)
            yield period[np.arange(i0 * factor, i1 * factor + 1) % period.size]
        return
    from scipy.signal import firwin, resample_poly

    half = SINC_HALF_WIDTH
    pad = half + 2  # as upsample: the record extended, then each block with `pad` around it
    ext = np.pad(x, pad, mode="reflect" if p is None else "wrap")
    taps = firwin(2 * half * factor + 1, 1.0 / factor, window=("kaiser", 14.0))
    for i0 in range(0, n - 1, step):
        i1 = min(i0 + step, n - 1)
        fine = resample_poly(ext[i0:i1 + 2 * pad + 1], factor, 1, window=taps)
        yield fine[pad * factor: (pad + i1 - i0) * factor + 1]


def block_samples(factor: int, nodes: int | None = None) -> int:
    """Record samples of a block of :func:`fine_blocks` (the last block may hold fewer).

    Parameters
    ----------
    factor : int
        Fine samples per record sample.
    nodes : int, optional
        As for :func:`fine_blocks`.

    Examples
    --------
    >>> block_samples(20), block_samples(10000)
    (104857, 256)
    """
    return max(256, int(BLOCK_NODES if nodes is None else nodes) // int(factor))


def held_nodes(u: NDArray[np.float64], factor: int, nodes: int | None = None) -> int:
    """Fine nodes :func:`fine_blocks` holds at once at most: a block's, and a record of whole
    periods' upsampled period.

    Parameters
    ----------
    u : ndarray
        The record's samples.
    factor : int
        Fine samples per record sample.
    nodes : int, optional
        As for :func:`fine_blocks`.

    Examples
    --------
    >>> held_nodes(np.arange(10.0), 20), held_nodes(np.arange(1e6), 20)
    (181, 2097141)
    >>> held_nodes(np.tile([0.0, 1.0, 0.5, 0.2], 25000), 20, nodes=100)   # 256-sample blocks
    5281
    """
    x = np.asarray(u, dtype=float)
    step = block_samples(factor, nodes)
    block = (min(x.size - 1, step) * factor + 1) if x.size > 1 else x.size
    p = is_periodic_record(x) if x.size - 1 > step and factor > 1 else None
    period = p * factor if p is not None and _smooth_length(x.size) else 0
    return block + 2 * period  # with the block's index into the period


def period_upsampling_bytes(samples: int, factor: int) -> int:
    """Memory :func:`fine_input` of one period takes while it upsamples it [bytes]: by its
    spectrum (a length without a prime factor above 7) the zero-padded spectrum, the
    transform's own buffer and the result, 32 bytes a fine node of address space (measured:
    32.0-32.8 at 3e4-1e5 samples, 20-2000 nodes a sample); by the windowed sinc the wrapped
    record's filtered copy and the result, 17 (16.1-16.5).

    Parameters
    ----------
    samples : int
        The period's samples.
    factor : int
        Fine samples per record sample.

    Examples
    --------
    >>> period_upsampling_bytes(100000, 20), period_upsampling_bytes(100003, 20)
    (64000032, 34001037)
    """
    nodes = int(samples) * int(factor) + 1
    if factor == 1:
        return 16 * nodes  # a copy, and the first node again
    return (32 if _smooth_length(int(samples)) else 17) * nodes


def check_whole_periods(u: NDArray[np.float64], name: str) -> None:
    """Refuse a record given as whole periods of a periodic signal whose ends do not join.

    A record of one period (or several) of a periodic signal continues from its
    last sample into its first as from any sample into the next; one whose ends
    lie further apart than twice the largest step between neighbouring samples is
    not such a record (a transient from rest, or periods cut anywhere), and a
    periodic steady state computed from it would be no answer.

    Parameters
    ----------
    u : ndarray
        The signal that repeats (the force; a displacement for a record without inertia).
    name : str
        The record, for the message.

    Raises
    ------
    ValueError
        One line naming the record.

    Examples
    --------
    >>> t = np.arange(200) / 200.0
    >>> check_whole_periods(np.cos(2 * np.pi * 3 * t), "three.csv")   # three whole periods
    >>> try:
    ...     check_whole_periods(np.cos(2 * np.pi * 2.5 * t), "cut.csv")
    ... except ValueError as exc:
    ...     print(exc)
    cut.csv: not whole periods of a periodic signal: its ends do not join (first sample 1, \
last -0.997; the largest step between samples 0.0785)
    """
    step = float(np.max(np.abs(np.diff(u)))) if u.size > 1 else 0.0
    if is_periodic_record(u) is None and abs(u[0] - u[-1]) > 2.0 * step:
        raise ValueError(f"{name}: not whole periods of a periodic signal: its ends do not "
                         f"join (first sample {u[0]:.3g}, last {u[-1]:.3g}; the largest step "
                         f"between samples {step:.3g})")


def is_periodic_record(u: NDArray[np.float64], rtol: float = 1e-9) -> int | None:
    """Samples per period if `u` is two or more whole periods of one signal, else None.

    Parameters
    ----------
    u : ndarray
        The record's samples.
    rtol : float
        Tolerance of the repetition, relative to the largest sample.

    Examples
    --------
    >>> import numpy as np
    >>> is_periodic_record(np.tile([0.0, 1.0, 0.5], 4)), is_periodic_record(np.arange(6.0))
    (3, None)
    """
    n = u.size
    scale = float(np.max(np.abs(u))) if n else 0.0
    tol = rtol * scale
    small = [p for p in range(2, int(n ** 0.5) + 1) if n % p == 0]
    large = [n // p for p in reversed(small) if n // p != p and n // p <= n // 2]
    for p in small + large:  # the divisors of n, ascending; a first sample that differs: not p
        if abs(u[p] - u[0]) <= tol and np.all(np.abs(u.reshape(-1, p) - u[:p]) <= tol):
            return p
    return None
