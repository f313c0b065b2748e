"""Measured records for identification: reading them (CSV, arrays, DataFrames) and checking
that they can be identified from (length, finite values, increasing time, reversals)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.blas import few_blas_threads
from motionhyst.io.csvdata import Source, describe
from motionhyst.io.records import read_record

__all__ = ["DECIMATED_RATE", "ELASTIC_CURVE_RATIO", "FOLLOW_GAIN", "SCALE_RATIO",
           "ForceFalls", "check_controller_period", "check_force_follows", "check_force_scale",
           "check_loops_open", "count_reversals", "fit_every", "load_closed_loop_csv",
           "load_force_displacement_csv", "prefilter_cutoff"]

MIN_SAMPLES = 50
"""Fewest samples accepted in a record."""


MAX_ROWS = 50_000
"""Most samples used in the residual of a Maxwell-slip fit (the operators always run on the
full record); here, beside the record's checks, so that a record's size is judged before the
fit's libraries load."""


REVERSAL_BAND = 0.01
"""A reversal is a retreat of more than this fraction of the range from a running extreme."""


def _count_reversals(x: NDArray[np.float64], band: float) -> int:
    """Direction changes of `x` that retreat more than `band` from a running extreme.

    The walk visits only the samples where the sign of ``diff(x)`` changes (and the last):
    between two of them `x` is monotone, and a monotone run moves the walk's state (its
    direction, its running extreme, the count) as its last sample alone does, so the count
    is the sample-by-sample walk's, with numpy and a loop over the turns (no compiler: a
    closed-loop record's cut-off is decided before any kernel loads)."""
    d = np.sign(np.diff(x))
    keep = np.flatnonzero(d[1:] != d[:-1]) + 1
    n_rev, direction = 0, 0
    hi = lo = ext = float(x[0])
    for v in [*x[keep].tolist(), float(x[-1])]:
        if direction == 0:
            hi, lo = max(hi, v), min(lo, v)
            if v - lo > band:
                direction, ext = 1, v
            elif hi - v > band:
                direction, ext = -1, v
        elif direction == 1:
            if v > ext:
                ext = v
            elif ext - v > band:
                n_rev, direction, ext = n_rev + 1, -1, v
        elif v < ext:
            ext = v
        elif v - ext > band:
            n_rev, direction, ext = n_rev + 1, 1, v
    return n_rev


def count_reversals(x: ArrayLike, band: float | None = None) -> int:
    """Number of direction reversals of a sampled signal.

    Parameters
    ----------
    x : array_like
        Samples.
    band : float, optional
        Excursions smaller than this are ignored (noise); by default
        ``REVERSAL_BAND`` times the range of `x`.

    Returns
    -------
    int
        How often `x` turns back by more than `band` from its running extreme.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify import count_reversals
    >>> t = np.linspace(0.0, 2.0, 2001)
    >>> count_reversals(np.sin(2 * np.pi * 2.0 * t))        # 2 Hz for 2 s: 8 extrema
    8
    """
    xs = np.ascontiguousarray(x, dtype=float)
    if xs.size < 2:
        return 0
    if band is None:
        band = REVERSAL_BAND * float(np.ptp(xs))
    return _count_reversals(xs, float(band))


def _reverses(x: NDArray[np.float64]) -> bool:
    """``count_reversals(x) >= 1``, with numpy alone (a record's check imports no compiler):
    once `x` has left its first band (up from its running minimum, or down from its
    running maximum, as the count decides), does it retreat by more than the band from its
    running extreme?"""
    band = REVERSAL_BAND * float(np.ptp(x))
    up = np.flatnonzero(x - np.minimum.accumulate(x) > band)
    down = np.flatnonzero(np.maximum.accumulate(x) - x > band)
    if up.size == 0 and down.size == 0:
        return False
    if down.size == 0 or (up.size and up[0] <= down[0]):  # moving up first (the count's order)
        seg = x[up[0]:]
        return bool(np.any(np.maximum.accumulate(seg) - seg > band))
    seg = x[down[0]:]
    return bool(np.any(seg - np.minimum.accumulate(seg) > band))


def check_signals(x: NDArray, named: dict[str, NDArray], t: NDArray | None,
                  xname: str = "displacement") -> None:
    """``ValueError`` (one line, no file) for records that cannot be identified from."""
    arrays = {xname: x, **named}
    if t is not None:
        arrays = {"time": t, **arrays}
    lengths = {k: v.shape for k, v in arrays.items()}
    if any(v.ndim != 1 for v in arrays.values()) or len(set(lengths.values())) != 1:
        raise ValueError("inconsistent lengths: " + ", ".join(
            f"{k} {v.size}" for k, v in arrays.items()))
    if x.size < MIN_SAMPLES:
        raise ValueError(f"too short: {x.size} samples, need at least {MIN_SAMPLES}")
    for k, v in arrays.items():
        if not np.all(np.isfinite(v)):
            raise ValueError(f"non-finite value in {k} (sample "
                             f"{int(np.argmin(np.isfinite(v))) + 1})")
    if t is not None and np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise ValueError(f"time must be strictly increasing (sample {i + 1})")
    if not np.ptp(x) > 0:
        raise ValueError(f"constant {xname}: nothing to identify from")
    if not _reverses(x):
        raise ValueError(f"no reversal: the {xname} must move back and forth at least once")


#: A force-displacement record whose force a curve of the displacement alone describes to this
#: fraction of a straight line's systematic error has no loops for Maxwell-slip elements
ELASTIC_CURVE_RATIO = 0.1
#: ... where the line's systematic error is this many times what a fit may leave
#: (:data:`~motionhyst.identify.io_checks.SYSTEMATIC_SHARE`): a small curvature is left to the
#: fit, which may describe it within its bound
ELASTIC_CURVE_FACTOR = 3.0
#: Degree of the Chebyshev series in the displacement that stands for "a curve"
ELASTIC_CURVE_DEGREE = 15
#: A damper's loops are told once a straight line leaves this share of
#: :data:`~motionhyst.identify.io_checks.SYSTEMATIC_SHARE` (below, a spring's record: the fit
#: decides, and its own check refuses it)
DAMPER_LINE_SHARE = 0.25


FOLLOW_GAIN = 25.0
"""A force-displacement record's force follows its displacement (:func:`check_force_follows`)
where a spring, a damper and a friction force explain more than this many times its white
noise's variance: white noise explains about 3 of them; a link the fit keeps explains at
least :data:`~motionhyst.identify.io_checks.NO_HYSTERESIS_GAIN` beyond a spring, most of it
through those three."""


class ForceFalls(ValueError):
    """A force-displacement record whose force falls as its displacement rises
    (:func:`check_force_follows`): a sensor's sign reversed, or a force that drives a mass
    (a stage's input-output record: above its resonance the position lags the force by
    nearly 180 degrees), which the caller tells by the record's inertia.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 1000.0
    >>> x = 1e-3 * np.sin(2 * np.pi * 3.0 * t)
    >>> try:
    ...     check_force_follows(x, -2000.0 * x, t)
    ... except ForceFalls as exc:
    ...     print(str(exc)[:62])
    no hysteresis found: the force falls as the displacement rises
    """


def check_force_follows(x: ArrayLike, w: ArrayLike, t: ArrayLike) -> None:
    """Refuse, before any fit, a force-displacement record whose force does not follow its
    displacement: it falls as the displacement rises (their correlation below -0.5: a
    sensor's sign reversed, which no link of positive stiffness describes; the fit's first
    stage refused it after the mass check, 1.4 s of CPU for 60000 samples), or a spring
    ``x``, a damper ``x'`` and a friction force ``sign(x')`` explain at most
    :data:`FOLLOW_GAIN` times the variance of the force's white noise (the residual's
    differences, as :func:`~motionhyst.identify.io_checks.hysteresis_gain` has it): noise,
    which no link's force is (the fit refused it as "no hysteresis" after its work, 1.3 s).

    Parameters
    ----------
    x, w, t : array_like
        The record's displacement (as the fit takes it), force and time.

    Raises
    ------
    ValueError
        One line: what the force does, and what would help (:class:`ForceFalls` where it
        falls as the displacement rises).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(3000) / 1000.0
    >>> x = 1e-3 * np.sin(2 * np.pi * 2.0 * t)
    >>> check_force_follows(x, 20.0 * x + 0.01 * np.sign(np.cos(2 * np.pi * 2.0 * t)), t)
    >>> try:
    ...     check_force_follows(x, np.random.default_rng(0).standard_normal(t.size), t)
    ... except ValueError as exc:
    ...     print(str(exc)[:68])
    no hysteresis in the record: its force does not follow the displacem
    """
    x, w, t = (np.asarray(a, dtype=float) for a in (x, w, t))
    x0, w0 = x - np.mean(x), w - np.mean(w)
    xx, ww = float(x0 @ x0), float(w0 @ w0)
    if x.size < 8 or not (xx > 0 and ww > 0):
        return
    if float(x0 @ w0) < -0.5 * math.sqrt(xx * ww):
        raise ForceFalls("no hysteresis found: the force falls as the displacement rises (is "
                         "one sensor's sign reversed? --scale force=-1)")
    v = np.gradient(x, t)
    basis = np.column_stack([np.ones_like(x), x0, v, np.sign(v)])
    with few_blas_threads(*basis.shape):
        coef = np.linalg.lstsq(basis, w, rcond=None)[0]
    r = w - basis @ coef
    noise = float(np.mean(np.diff(r) ** 2)) / 2.0
    gain = (ww - float(r @ r)) / noise if noise > 0 else math.inf
    if gain <= FOLLOW_GAIN:
        raise ValueError(f"no hysteresis in the record: its force does not follow the "
                         f"displacement (a spring, a damper and a friction force explain "
                         f"{max(gain, 0.0):.2g} times its white noise's variance, at most "
                         f"{FOLLOW_GAIN:g}): it is noise, or the link is not loaded; nothing "
                         f"identified (a record whose displacement loads the link may be)")


def check_loops_open(x: ArrayLike, w: ArrayLike, t: ArrayLike | None = None) -> None:
    """Refuse, before any fit, a force-displacement record that no Maxwell-slip elements can
    describe because it has no hysteresis but is not a line, or (given its time `t`) because
    its loops are a damper's.

    Maxwell-slip elements (Jenkins elements in parallel, paper eq. 3) are one straight line
    until one of them slips, and a slipping element opens a loop: the force then depends
    on the way the displacement came.  A force that is a curve of the displacement alone
    (a saturating or stiffening spring) is neither: a straight line leaves a systematic
    error (:func:`~motionhyst.identify.io_checks.systematic_share`) of more than
    :data:`ELASTIC_CURVE_FACTOR` times what a fit may leave, while a curve in the
    displacement (a Chebyshev series of degree :data:`ELASTIC_CURVE_DEGREE`) leaves less
    than :data:`ELASTIC_CURVE_RATIO` of the line's.  The fit would end in the same refusal
    after its work (seconds); a record with loops (Maxwell-slip's own: the curve leaves
    about what the line does) is never refused here.

    Loops a spring and a damper in parallel (``w = w0 + k x + c dx/dt``) describe to within
    what a fit may leave, and to less than :data:`ELASTIC_CURVE_RATIO` of the line's error,
    are a damper's: their width grows with the speed, while elements that slip give loops
    of the path alone.  Hysteresis of every rate-independent kind leaves a damper at least
    a fifth of the line's error (Jenkins, Maxwell-slip and Iwan distributions, Dahl and
    Bouc-Wen links, under sines, amplitude sweeps, two tones and band-limited noise).  They
    are judged once the line leaves :data:`DAMPER_LINE_SHARE` of what a fit may leave (a
    damper too weak to bend the line further is the fit's to judge), the message every
    ``--model`` gives for such a record.

    Parameters
    ----------
    x, w : array_like
        The record's displacement and force (checked by :func:`check_signals`).
    t : array_like, optional
        The record's time [s]; without it the loops are not judged.

    Raises
    ------
    ValueError
        One line naming both shares.

    Examples
    --------
    >>> import numpy as np
    >>> x = 1e-3 * np.sin(np.linspace(0.0, 8 * np.pi, 2000))
    >>> check_loops_open(x, 20.0 * x)                      # a line: the fit decides
    >>> check_loops_open(x, np.clip(20.0 * x, -0.01, 0.01))
    Traceback (most recent call last):
    ...
    ValueError: the force is a curve of the displacement alone (a curve leaves 0.71 % of its \
RMS, a straight line 23 %): Maxwell-slip elements are a straight line until one slips and a \
slip opens a loop, so none describes it (a spring that saturates or stiffens, not \
hysteresis); nothing identified
    >>> t = np.linspace(0.0, 2.0, 2000)
    >>> x = 1e-3 * np.sin(2 * np.pi * 2.0 * t)
    >>> check_loops_open(x, 20.0 * x + 0.5 * np.gradient(x, t), t)
    Traceback (most recent call last):
    ...
    ValueError: no hysteresis in the record: the force is a spring's and a damper's (they leave \
0 % of its RMS, a straight line 30 %); its loops widen with the speed, while a slipping \
element's follow the path alone; nothing identified
    """
    from motionhyst.identify.io_checks import SYSTEMATIC_SHARE, systematic_share

    x, w = np.asarray(x, dtype=float), np.asarray(w, dtype=float)
    span = float(np.ptp(x))
    if x.size <= ELASTIC_CURVE_DEGREE + 1 or not span > 0:
        return
    u = 2.0 * (x - float(np.min(x))) / span - 1.0
    shares = []
    for basis in (np.column_stack([np.ones_like(u), u]),
                  np.polynomial.chebyshev.chebvander(u, ELASTIC_CURVE_DEGREE)):
        with few_blas_threads(*basis.shape):  # a small fit: its threads cost more
            coef = np.linalg.lstsq(basis, w, rcond=None)[0]
        shares.append(systematic_share(w - basis @ coef, w))
    line, curve = shares
    if line > ELASTIC_CURVE_FACTOR * SYSTEMATIC_SHARE and curve < ELASTIC_CURVE_RATIO * line:
        raise ValueError(f"the force is a curve of the displacement alone (a curve leaves "
                         f"{100 * curve:.2g} % of its RMS, a straight line {100 * line:.2g} %): "
                         f"Maxwell-slip elements are a straight line until one slips and a "
                         f"slip opens a loop, so none describes it (a spring that saturates "
                         f"or stiffens, not hysteresis); nothing identified")
    if t is None or not line > DAMPER_LINE_SHARE * SYSTEMATIC_SHARE:
        return
    v = np.gradient(x, np.asarray(t, dtype=float))
    basis = np.column_stack([np.ones_like(u), u, v / float(np.max(np.abs(v)))])
    with few_blas_threads(*basis.shape):
        coef = np.linalg.lstsq(basis, w, rcond=None)[0]
    damper = systematic_share(w - basis @ coef, w)
    if damper < min(ELASTIC_CURVE_RATIO * line, SYSTEMATIC_SHARE):
        raise ValueError(f"no hysteresis in the record: the force is a spring's and a "
                         f"damper's (they leave {round(100 * damper, 2):.2g} % of its RMS, a "
                         f"straight line {100 * line:.2g} %); its loops widen with the speed, "
                         f"while a slipping element's follow the path alone; nothing "
                         f"identified")


def _load(source: Source, names: tuple[str, str, str], xname: str, columns=None, scale=None):
    data = read_record(source, names, columns=columns, scale=scale)
    t, x, v = data[:, 0], data[:, 1], data[:, 2]
    try:
        check_signals(x, {names[2]: v}, t, xname=xname)
    except ValueError as exc:
        raise ValueError(f"{describe(source)}: {exc}") from None
    return t, x, v


def load_force_displacement_csv(source: Source, *, columns: dict[str, str] | None = None,
                                scale: dict[str, float] | None = None
                                ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                           NDArray[np.float64]]:
    """Read a force-displacement record from CSV or MATLAB ``.mat`` (or an array or DataFrame).

    The record has the columns ``time,displacement,force`` (s, m, N; other
    columns are ignored), under those names or under the file's own mapped by
    `columns`, scaled by `scale` (read by :func:`motionhyst.io.records.read_record`:
    CSV dialects, MATLAB levels 4 to 7.3).  A DataFrame has those columns by
    name, an array those three columns in order.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        The CSV file, or the columns themselves.
    columns : dict, optional
        Quantity (``"time"``, ``"displacement"``, ``"force"``) -> the file's name for it; a quantity
        not mapped is read under its own name.
    scale : dict, optional
        Quantity -> gain its column is multiplied by (to SI units).

    Returns
    -------
    t, x, w : ndarray
        Time [s], displacement [m], force [N].

    Raises
    ------
    ValueError
        With one line naming the file: unreadable, missing column, non-numeric
        or non-finite value, rows of inconsistent length, fewer than
        ``MIN_SAMPLES`` samples, time not strictly increasing, constant
        displacement or force, or no reversal of the displacement.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from motionhyst import Jenkins
    >>> from motionhyst.identify import load_force_displacement_csv
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> x = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    >>> path = Path(tempfile.mkdtemp()) / "record.csv"
    >>> np.savetxt(path, np.column_stack([t, x, Jenkins(k=20.0, fc=0.05).response(x)]),
    ...            delimiter=",", header="time,displacement,force", comments="")
    >>> t, x, w = load_force_displacement_csv(path)
    >>> t.size, float(w.max())
    (1001, 0.05)
    """
    t, x, w = _load(source, ("time", "displacement", "force"), "displacement", columns, scale)
    if not np.ptp(w) > 0:  # said before a fit is loaded, which would find no stop operator
        raise ValueError(f"{describe(source)}: no hysteresis found: the force is constant")
    return t, x, w


def load_closed_loop_csv(source: Source, *, columns: dict[str, str] | None = None,
                         scale: dict[str, float] | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                    NDArray[np.float64]]:
    """Read a closed-loop record: columns ``time,y1,u`` (s, m, N), CSV or MATLAB ``.mat``.

    The file's own names are mapped by `columns` and scaled by `scale` (as
    :func:`load_force_displacement_csv`); an array (those columns in order) or
    a DataFrame is accepted as well.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        The CSV file, or the columns themselves.
    columns : dict, optional
        Quantity (``"time"``, ``"y1"``, ``"u"``) -> the file's name for it; a quantity not mapped is
        read under its own name.
    scale : dict, optional
        Quantity -> gain its column is multiplied by (to SI units).

    Returns
    -------
    t, y1, u : ndarray
        Time [s], position of the actuated mass [m], actuator force [N].

    Raises
    ------
    ValueError
        As :func:`load_force_displacement_csv` (with ``y1`` in place of the
        displacement).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify import load_closed_loop_csv
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> record = np.column_stack([t, 0.01 * np.sin(2 * np.pi * 2.0 * t), np.cos(2 * np.pi * t)])
    >>> t, y1, u = load_closed_loop_csv(record)           # columns time, y1, u (or a CSV file)
    >>> y1.shape
    (1001,)
    """
    return _load(source, ("time", "y1", "u"), "y1", columns, scale)


SETTLE_PERIODS = 10.0
"""Start-up transient of the closed-loop prefilter, in units of ``1 / cutoff_hz``."""


DECIMATED_RATE = 40.0
"""Closed-loop fits run at no less than this multiple of the prefilter cut-off [-]."""


def fit_every(dt: float, cutoff_hz: float) -> int:
    """Samples between the rows of a closed-loop record's fit: its link force, prefiltered at
    `cutoff_hz`, is band-limited, and fitted at no less than :data:`DECIMATED_RATE` times
    the cut-off.

    Parameters
    ----------
    dt : float
        The record's sampling interval [s].
    cutoff_hz : float
        The prefilter's cut-off (:func:`prefilter_cutoff`) [Hz].

    Returns
    -------
    int
        At least 1.

    Examples
    --------
    >>> fit_every(2e-4, 41.0), fit_every(2e-4, 250.0)     # 5 kHz
    (3, 1)
    """
    return max(1, int(1.0 / (dt * DECIMATED_RATE * cutoff_hz)))


def prefilter_cutoff(t: ArrayLike, y1: ArrayLike,
                     cutoff_hz: float | None = None) -> tuple[float, int]:
    """The cut-off of a closed-loop record's prefilter and the sample at which it has settled.

    The default cut-off is 20 times the record's fundamental (from the reversals of
    `y1`), at most a twentieth of the sampling rate; a cut-off given must lie below half
    the sampling rate and leave :data:`MIN_SAMPLES` samples after the prefilter's
    start-up transient, :data:`SETTLE_PERIODS` periods of the cut-off.  Checked from the
    record alone, before the plant is loaded and the filters run
    (:func:`~motionhyst.identify.closed_loop.infer_link_force` applies it).

    Parameters
    ----------
    t : array_like
        The record's time stamps [s] (uniform).
    y1 : array_like
        Position of the actuated mass [m].
    cutoff_hz : float, optional
        The cut-off asked for (``--cutoff``) [Hz].

    Returns
    -------
    cutoff_hz : float
        The cut-off [Hz].
    settle : int
        Index of the first sample after the start-up transient.

    Raises
    ------
    ValueError
        A cut-off at or above half the sampling rate, not positive, or one whose
        transient leaves fewer than :data:`MIN_SAMPLES` samples.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4000) / 1000.0
    >>> cutoff, settle = prefilter_cutoff(t, np.sin(2 * np.pi * 2.0 * t))  # 2 Hz: 16 reversals
    >>> round(cutoff, 1), settle                  # 20 x (16 + 1) / (2 x 4 s), settled at 0.24 s
    (42.5, 236)
    >>> try:
    ...     prefilter_cutoff(t, np.sin(t), cutoff_hz=1e9)
    ... except ValueError as exc:
    ...     print(exc)
    cutoff_hz must be in (0, 500) Hz, below half the record's sampling rate (the prefilter's \
cut-off, --cutoff), got 1e+09
    """
    ts = np.asarray(t, dtype=float)
    fs = 1.0 / float(np.median(np.diff(ts)))
    if cutoff_hz is None:
        duration = float(ts[-1] - ts[0])
        f0 = (count_reversals(np.asarray(y1, dtype=float)) + 1) / (2.0 * duration)
        cutoff_hz = min(20.0 * f0, fs / 20.0)
    cutoff_hz = float(cutoff_hz)
    if not (np.isfinite(cutoff_hz) and 0 < cutoff_hz < fs / 2):
        raise ValueError(f"cutoff_hz must be in (0, {fs / 2:g}) Hz, below half the record's "
                         f"sampling rate (the prefilter's cut-off, --cutoff), got {cutoff_hz:g}")
    settle = int(np.searchsorted(ts - ts[0], SETTLE_PERIODS / cutoff_hz))
    if ts.size - settle < MIN_SAMPLES:
        raise ValueError(f"too short: the prefilter settles in {SETTLE_PERIODS / cutoff_hz:.3g} "
                         f"s, leaving {max(ts.size - settle, 0)} samples; record longer or "
                         "raise the prefilter's cut-off (cutoff_hz, --cutoff)")
    return cutoff_hz, settle


UNIFORM_RTOL = 0.01
"""Allowed relative deviation of a closed-loop record's sampling interval from its median,
and from a sampled controller's period."""


def check_controller_period(t: ArrayLike, period: float) -> None:
    """Refuse a closed-loop record that is not at the samples of its sampled controller.

    The force a sampled controller held is inferred at its samples (the record's rows);
    a record at another rate is refused from its time column alone, before the loop is
    built (:func:`~motionhyst.identify.closed_loop.infer_link_force` applies it too).

    Parameters
    ----------
    t : array_like
        The record's time stamps [s].
    period : float
        The controller's sampling period [s].

    Raises
    ------
    ValueError
        The record's median sampling interval differs from `period` by more than
        :data:`UNIFORM_RTOL` of it.

    Examples
    --------
    >>> import numpy as np
    >>> check_controller_period(np.arange(100) / 1e4, 1e-4)        # a 10 kHz loop's record
    >>> try:
    ...     check_controller_period(np.arange(100) / 1e3, 1e-4)
    ... except ValueError as exc:
    ...     print(exc)
    the record's sampling interval 0.001 s is not the controller's period 0.0001 s
    """
    dt = float(np.median(np.diff(np.asarray(t, dtype=float))))
    if abs(dt - period) > UNIFORM_RTOL * period:
        raise ValueError(f"the record's sampling interval {dt:g} s is not the controller's "
                         f"period {period:g} s")


SCALE_RATIO = 100.0
"""A closed-loop record is refused before its fit when the force its plant needs to move
``y1`` as recorded is this many times ``u`` in the prefilter's band
(:func:`check_force_scale`): the link would push the stage harder than its actuator a
hundredfold, cancelling the plant's own dynamics."""


def check_force_scale(t: ArrayLike, y1: ArrayLike, u: ArrayLike, mechanics,
                      cutoff_hz: float) -> None:
    """Refuse a closed-loop record whose position and force do not fit its plant's scales.

    The link force is inferred as ``w = u - P1^-1 y1``: where the plant's force for ``y1``,
    ``P1^-1 y1``, is :data:`SCALE_RATIO` times ``u`` or more (RMS over the frequencies up
    to the prefilter's cut-off, both windowed alike, ``y1``'s straight line removed: a
    constant speed needs no force), the inferred force is the plant's force alone: its
    spring-like part dwarfs any slip of a link, the fit finds a spring (a slip force it
    cannot determine) and is refused after its work.  So is ``y1`` in mm (1000 times the
    plant's force), ``u`` in kN, the columns swapped, or a plant not the record's; a stage
    with a link of its own (the record's ``u`` and the link's force comparable) is not.

    Parameters
    ----------
    t, y1, u : array_like
        The record (uniform time [s], position of the actuated mass [m], force [N]).
    mechanics : Mechanics
        The plant's lumped masses (:meth:`~motionhyst.plants.registry.Plant.mechanics`):
        ``P1`` is its force-to-position response at the link's coordinate.
    cutoff_hz : float
        The prefilter's cut-off [Hz] (:func:`prefilter_cutoff`).

    Raises
    ------
    ValueError
        One line naming the ratio and the likely causes.

    Examples
    --------
    >>> from motionhyst import TwoMassStage
    >>> mech = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7).mechanics()
    >>> t = np.arange(5000) / 1e3
    >>> y1 = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    >>> u = -22.5 * (2 * np.pi * 2.0) ** 2 * y1               # the stage's inertia: 22.5 kg
    >>> check_force_scale(t, y1, u, mech, 40.0)
    >>> try:
    ...     check_force_scale(t, 1000.0 * y1, u, mech, 40.0)     # y1 in mm
    ... except ValueError as exc:
    ...     print(exc)
    the plant's force for y1 as recorded is 1000 times u (RMS up to the prefilter's cut-off \
40 Hz): a link would push the stage harder than its actuator, cancelling the plant's own \
dynamics, and its slip force would be a guess (y1 not in metres? u not in newtons? u and y1 \
swapped? the plant not the record's?); nothing identified
    """
    ts = np.asarray(t, dtype=float)
    ys = np.asarray(y1, dtype=float)
    us = np.asarray(u, dtype=float)
    n = ts.size
    if n < 3 or not ts[-1] > ts[0]:
        return
    dt = (ts[-1] - ts[0]) / (n - 1)
    tau = (ts - ts[0]) / (ts[-1] - ts[0])
    slope, offset = np.polyfit(tau, ys, 1)
    window = np.hanning(n)
    f = np.fft.rfftfreq(n, dt)
    band = np.flatnonzero((f > 0) & (f <= cutoff_hz))
    if band.size == 0:
        return
    s = 2j * np.pi * f[band]
    impedance = (np.diag(mechanics.mass)[None] * s[:, None, None] ** 2
                 + mechanics.C[None] * s[:, None, None] + mechanics.K[None])
    unit = np.zeros((band.size, mechanics.n, 1), dtype=complex)
    unit[:, mechanics.link, 0] = 1.0
    try:
        p1 = np.linalg.solve(impedance, unit)[:, mechanics.link, 0]
    except np.linalg.LinAlgError:  # an undamped mode on a line of the record: the fit judges
        return
    need = np.fft.rfft((ys - slope * tau - offset) * window)[band] / p1
    given = np.fft.rfft((us - us.mean()) * window)[band]
    given_rms = float(np.sqrt(np.sum(np.abs(given) ** 2)))
    need_rms = float(np.sqrt(np.sum(np.abs(need) ** 2)))
    if need_rms >= SCALE_RATIO * given_rms:
        ratio = f"{float(f'{need_rms / given_rms:.2g}'):g}" if given_rms > 0 else "infinitely many"
        raise ValueError(f"the plant's force for y1 as recorded is {ratio} times u (RMS up to "
                         f"the prefilter's cut-off {cutoff_hz:.4g} Hz): a link would push the "
                         f"stage harder than its actuator, cancelling the plant's own "
                         f"dynamics, and its slip force would be a guess (y1 not in metres? "
                         f"u not in newtons? u and y1 swapped? the plant not the record's?); "
                         f"nothing identified")
