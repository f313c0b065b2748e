"""Reference trajectories for time simulation: position and acceleration on any time grid.

The rigid-body feedforward needs the acceleration ``r''``; every reference
therefore gives both, exactly where it is known in closed form (sine,
point-to-point profile) and from a quintic interpolating spline for sampled
data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.io.csvdata import Source, describe
from motionhyst.io.records import check_unread, read_record

__all__ = ["SPLINE_KEPT_BYTES", "SPLINE_SAMPLE_BYTES", "PointToPoint", "SampledReference",
           "SineReference", "check_spline_memory", "load_reference_csv", "reference_bytes"]


@dataclass(frozen=True)
class SineReference:
    """``r = amplitude sin(2 pi frequency_hz t)``.

    Parameters
    ----------
    amplitude : float
        Amplitude ``A_r`` [m].
    frequency_hz : float
        Frequency [Hz].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import SineReference
    >>> ref = SineReference(0.01, 5.0)                     # 10 mm at 5 Hz
    >>> r, a = ref(np.array([0.05]))                       # a quarter period: the crest
    >>> print(r, a)                                        # a = -(2 pi 5)^2 r
    [0.01] [-9.8696044]
    """

    amplitude: float
    frequency_hz: float

    def __post_init__(self):
        for name in ("amplitude", "frequency_hz"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be finite and > 0, got {v!r}")

    @property
    def max_frequency_hz(self) -> float:
        """Highest frequency in the reference [Hz]."""
        return self.frequency_hz

    @property
    def initial_velocity(self) -> float:
        """Velocity at ``t = 0`` [m/s]: the reference starts from rest with this jump."""
        return math.tau * self.frequency_hz * self.amplitude

    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and acceleration [m/s^2] at times `t` [s]."""
        th = math.tau * self.frequency_hz * np.asarray(t, dtype=float)
        r = self.amplitude * np.sin(th)
        return r, -((math.tau * self.frequency_hz) ** 2) * r


@dataclass(frozen=True)
class PointToPoint:
    """Jerk-limited point-to-point move (third-order profile), a stage's usual set-point.

    Parameters
    ----------
    distance : float
        Length of the move [m] (sign gives direction).
    v_max, a_max, j_max : float
        Velocity [m/s], acceleration [m/s^2] and jerk [m/s^3] limits, > 0.
    start : float
        Time at which the move starts [s].

    Examples
    --------
    A 20 mm move at 0.5 m/s, 10 m/s^2, 1000 m/s^3; a reference gives position and
    acceleration (for the feedforward ``M r''``) at any times:

    >>> import numpy as np
    >>> from motionhyst import PointToPoint
    >>> move = PointToPoint(0.02, 0.5, 10.0, 1000.0)
    >>> print(f"{move.duration:.3f} s")
    0.100 s
    >>> r, a = move(np.array([0.0, move.duration / 2, move.duration + 0.1]))
    >>> print(r)
    [0.   0.01 0.02]
    """

    distance: float
    v_max: float
    a_max: float
    j_max: float
    start: float = 0.0

    def __post_init__(self):
        if not np.isfinite(self.distance) or self.distance == 0:
            raise ValueError("distance must be finite and non-zero")
        for name in ("v_max", "a_max", "j_max"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be finite and > 0, got {v!r}")
        if not (np.isfinite(self.start) and self.start >= 0):
            raise ValueError("start must be finite and >= 0")

    def _phases(self) -> tuple[float, float, float]:
        """Durations of the jerk phase, the constant-acceleration phase and the cruise."""
        d, v, a, j = abs(self.distance), self.v_max, self.a_max, self.j_max
        tj = min(a / j, np.sqrt(v / j))
        ta = max(v / (j * tj) - tj, 0.0) if tj > 0 else 0.0
        # distance covered while accelerating to the peak speed and back to rest
        vp = j * tj * (tj + ta)
        d_acc = vp * (2 * tj + ta)
        if d_acc <= d:
            return tj, ta, (d - d_acc) / vp
        # too short to reach v_max: shrink the peak speed (bisection on the profile length)
        lo, hi = 0.0, vp
        for _ in range(200):
            vm = 0.5 * (lo + hi)
            tj = min(a / j, np.sqrt(vm / j))
            ta = max(vm / (j * tj) - tj, 0.0)
            if vm * (2 * tj + ta) > d:
                hi = vm
            else:
                lo = vm
        tj = min(a / j, np.sqrt(lo / j))
        ta = max(lo / (j * tj) - tj, 0.0)
        return tj, ta, 0.0

    @property
    def duration(self) -> float:
        """Duration of the move [s]."""
        tj, ta, tv = self._phases()
        return 2 * (2 * tj + ta) + tv

    @property
    def max_frequency_hz(self) -> float:
        """A frequency that the profile's jerk switching resolves to [Hz]."""
        tj, ta, _ = self._phases()
        return 1.0 / max(min(tj, ta) if ta > 0 else tj, 1e-9)

    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and acceleration [m/s^2] at times `t` [s]."""
        tj, ta, tv = self._phases()
        jerks = np.array([1, 0, -1, 0, -1, 0, 1], dtype=float) * self.j_max
        durs = np.array([tj, ta, tj, tv, tj, ta, tj])
        edges = np.concatenate([[0.0], np.cumsum(durs)])
        # state (position, velocity, acceleration) at each edge
        p, v, a = [0.0], [0.0], [0.0]
        for jk, d in zip(jerks, durs, strict=True):
            p.append(p[-1] + v[-1] * d + a[-1] * d**2 / 2 + jk * d**3 / 6)
            v.append(v[-1] + a[-1] * d + jk * d**2 / 2)
            a.append(a[-1] + jk * d)
        tt = np.asarray(t, dtype=float) - self.start
        idx = np.clip(np.searchsorted(edges, tt, side="right") - 1, 0, 6)
        tau = np.clip(tt - edges[idx], 0.0, None)
        tau = np.where(tt >= edges[-1], 0.0, tau)
        idx = np.where(tt >= edges[-1], 6, idx)
        p0, v0, a0 = np.array(p)[idx], np.array(v)[idx], np.array(a)[idx]
        jk = jerks[idx]
        pos = p0 + v0 * tau + a0 * tau**2 / 2 + jk * tau**3 / 6
        acc = a0 + jk * tau
        pos = np.where(tt >= edges[-1], p[-1], np.where(tt < 0, 0.0, pos))
        acc = np.where((tt >= edges[-1]) | (tt < 0), 0.0, acc)
        sgn = np.sign(self.distance)
        return sgn * pos, sgn * acc


@dataclass(frozen=True)
class SampledReference:
    """A reference given by samples, interpolated by a quintic spline (acceleration from it).

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing.
    r : array_like
        Reference position at those times [m].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import SampledReference
    >>> t = np.linspace(0.0, 0.5, 501)
    >>> ref = SampledReference(t, 0.01 * np.sin(2 * np.pi * 4.0 * t))
    >>> ref.duration
    0.5
    >>> r, a = ref(np.array([1 / 16]))                     # the crest of the 4 Hz sine
    >>> print(f"r = {r[0]:.6f} m, a = {a[0]:.3f} m/s^2")   # exact: 0.01, -6.317
    r = 0.010000 m, a = -6.317 m/s^2
    """

    t: NDArray[np.float64]
    r: NDArray[np.float64]

    def __post_init__(self):
        t, r = np.asarray(self.t, float), np.asarray(self.r, float)
        if t.ndim != 1 or t.shape != r.shape:
            raise ValueError("time and position must be one-dimensional and of equal length")
        if t.size < 6:
            raise ValueError("a sampled reference needs at least 6 samples")
        for name, v in (("time", t), ("position", r)):
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:  # the column and the first sample named
                more = f", and {bad.size - 1} more" if bad.size > 1 else ""
                raise ValueError(f"the reference's {name} must be finite: sample "
                                 f"{int(bad[0]) + 1} is {v[bad[0]]}{more}")
        if np.any(np.diff(t) <= 0):
            raise ValueError("reference time must be strictly increasing")
        from scipy.interpolate import make_interp_spline  # a file's reference only

        check_spline_memory([t.size])

        object.__setattr__(self, "_spline", make_interp_spline(t, r, k=5))

    @property
    def initial_velocity(self) -> float:
        """Velocity of the first sample [m/s], a jump when the loop starts from rest."""
        return float(self._spline(self.t[0], 1))

    @property
    def max_frequency_hz(self) -> float:
        """Nyquist frequency of the samples [Hz]."""
        return 0.5 / float(np.min(np.diff(self.t)))

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return float(self.t[-1])

    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and acceleration [m/s^2]; held constant outside the samples."""
        tt = np.clip(np.asarray(t, dtype=float), self.t[0], self.t[-1])
        inside = (np.asarray(t) >= self.t[0]) & (np.asarray(t) <= self.t[-1])
        return self._spline(tt), np.where(inside, self._spline(tt, 2), 0.0)


SPLINE_SAMPLE_BYTES = 240
"""Memory a sampled reference takes per sample while its quintic spline is made [bytes]
(the spline keeps 56).  Measured, 1e6 samples read from a CSV file: 216 MB traced, 271 MB of
address space above a warmed process, the reading's 46 MB included."""


SPLINE_KEPT_BYTES = 56
"""Memory a sampled reference keeps per sample once its spline is made, for as long as a run
uses it [bytes]: its time and position, the spline's knots and coefficients (measured, 1e6
samples read from a CSV file by :func:`load_reference_csv`: 56.2 traced)."""


def reference_bytes(reference) -> float:
    """Memory a run's `reference` holds while the run goes [bytes]: a sampled reference's
    :data:`SPLINE_KEPT_BYTES` a sample, none for a built-in one.

    Parameters
    ----------
    reference : object
        The run's reference.

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(10_000) / 1e3
    >>> reference_bytes(SampledReference(t, 1e-3 * np.sin(t))), reference_bytes(None)
    (560000.0, 0.0)
    """
    return SPLINE_KEPT_BYTES * float(reference.t.size) \
        if isinstance(reference, SampledReference) else 0.0


def check_spline_memory(samples: list[int]) -> None:
    """Refuse a sampled reference whose spline (:data:`SPLINE_SAMPLE_BYTES` a sample) does not
    fit the memory budget (a file's, before it is read: ``samples`` from its size).

    Parameters
    ----------
    samples : list of int
        The reference's samples (one item).

    Raises
    ------
    motionhyst.core.budget.BudgetError
        One line: the samples, the memory they need, the budget and the remedy.

    Examples
    --------
    >>> check_spline_memory([10_000])                         # 2.4 MB
    """
    from motionhyst.core.budget import check_memory

    check_memory(SPLINE_SAMPLE_BYTES * float(samples[0]), f"the reference's spline through "
                 f"{samples[0]} samples", "give fewer samples (a coarser or shorter reference)")


def load_reference_csv(source: Source, *, columns: dict[str, str] | None = None,
                       scale: dict[str, float] | None = None) -> SampledReference:
    """Read a reference: columns ``time,position`` (SI units) of a CSV or MATLAB ``.mat`` file.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        A CSV file (BOM, comma or semicolon, names in any case) or a MATLAB
        file (levels 4 to 7.3), read by :func:`motionhyst.io.records.read_record`;
        a DataFrame with those columns, or an array of shape ``(n, 2)``.
    columns : dict, optional
        The file's names of ``time`` and ``position`` (the EMPS benchmark's
        reference: ``{"time": "t", "position": "qg"}``).
    scale : dict, optional
        Gains the columns are multiplied by (``{"position": 1e-3}`` for mm).

    Returns
    -------
    SampledReference

    Raises
    ------
    ValueError
        One line naming the source.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 0.5, 6)
    >>> load_reference_csv(np.column_stack([t, 1e-3 * t])).duration
    0.5

    From a file:

    >>> import tempfile
    >>> from pathlib import Path
    >>> t = np.linspace(0.0, 0.5, 501)
    >>> path = Path(tempfile.mkdtemp()) / "setpoint.csv"
    >>> np.savetxt(path, np.column_stack([t, 0.01 * np.sin(2 * np.pi * 4.0 * t)]),
    ...            delimiter=",", header="time,position", comments="")
    >>> ref = load_reference_csv(path)
    >>> ref.duration, round(ref.max_frequency_hz)
    (0.5, 500)
    """
    check_unread([source], ("time", "position"), check_spline_memory, columns=columns)
    data = read_record(source, ("time", "position"), columns=columns, scale=scale)
    t, r = data[:, 0], data[:, 1]
    try:
        return SampledReference(t, r)
    except ValueError as exc:
        raise ValueError(f"{describe(source)}: {exc}") from None
