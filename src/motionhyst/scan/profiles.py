"""Fourth-order (snap-limited) setpoint profiles, as wafer stages use them.

A move of length ``L`` is a step of height ``L`` smoothed by four moving
averages (boxcars of unit area) of durations ``T_s <= T_j <= T_a <= T_v``::

    r = L step * b(T_v) * b(T_a) * b(T_j) * b(T_s),   b(T) = rect(0, T) / T

Each boxcar bounds one derivative: ``|r'| <= L / T_v``, ``|r''| <= L / (T_v
T_a)``, ``|r'''| <= L / (T_v T_a T_j)`` and the snap ``r''''`` is piecewise
constant, ``+-S`` with ``S = L / (T_v T_a T_j T_s)``.  When the durations
grow at least as fast as their partial sums (``T_a >= T_s + T_j``, ``T_v >=
T_s + T_j + T_a``) the pulses do not overlap and every bound is reached
exactly: this is the time-optimal symmetric fourth-order profile of
Lambrechts, Boerlage and Steinbuch (Control Eng. Practice 13, 2005), whose
phases last ``T_s`` (snap), ``T_j - T_s`` (constant jerk), ``T_a - T_s - T_j``
(constant acceleration) and ``T_v - T_s - T_j - T_a`` (constant velocity).
The durations are chosen greedily, shortest first, each as long as the limits
allow.

The position and all its derivatives are evaluated exactly, piecewise
polynomially from the switching instants, so the rigid-body feedforward
``u_ff = M r''`` (``C_ff = P_r^-1 = M s^2``, paper Sec. II with ``P_r`` of
eq. 1) comes from the exact acceleration, not from differentiated samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import combinations, pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Profile", "check_window_samples", "point_to_point", "scan"]

#: Names of the derivatives returned by :meth:`Profile.derivatives`, in order.
DERIVATIVES = ("position", "velocity", "acceleration", "jerk", "snap")

#: Phase kinds of a profile (:meth:`Profile.phases`).
PHASE_KINDS = ("rest", "accelerate", "constant velocity", "decelerate")

_ROUND_TOL = 1e-9  # durations within this fraction of a sample count as whole samples


@dataclass(frozen=True)
class Phase:
    """One phase of a profile: `kind` (one of :data:`PHASE_KINDS`) from `start` to `end` [s]."""

    kind: str
    start: float
    end: float

    @property
    def duration(self) -> float:
        """Length of the phase [s]."""
        return self.end - self.start


@dataclass(frozen=True)
class Move:
    """One rest-to-rest move: ``length`` [m] (signed), from ``start`` [s], boxcar durations [s].

    ``durations = (T_s, T_j, T_a, T_v)``, superincreasing (each at least the
    sum of the shorter ones); see the module docstring.
    """

    start: float
    length: float
    durations: tuple[float, float, float, float]

    @property
    def end(self) -> float:
        """Time at which the move is at rest again [s]."""
        return self.start + sum(self.durations)

    @property
    def snap(self) -> float:
        """Snap of the pulses [m/s^4], ``|L| / (T_s T_j T_a T_v)``."""
        return abs(self.length) / math.prod(self.durations)

    def pulses(self) -> list[tuple[float, float]]:
        """Snap pulses ``(start time, signed snap)``, each lasting ``T_s``."""
        _ts, tj, ta, tv = self.durations
        s = math.copysign(self.snap, self.length)
        out = []
        for n in range(4):
            for sub in combinations((tj, ta, tv), n):
                out.append((self.start + sum(sub), s * (-1) ** n))
        return out

    def phases(self) -> list[Phase]:
        """Accelerate, constant velocity (if any) and decelerate."""
        ts, tj, ta, tv = self.durations
        ramp = ts + tj + ta
        out = [Phase("accelerate", self.start, self.start + ramp)]
        if tv > ramp:
            out.append(Phase("constant velocity", self.start + ramp, self.start + tv))
        out.append(Phase("decelerate", self.start + tv, self.start + tv + ramp))
        return out


def _increasing_root(f, lo: float, hi: float) -> float:
    """Largest ``x`` in ``[lo, hi]`` with ``f(x) <= 0`` for an increasing `f` (``f(lo) <= 0``)."""
    if f(hi) <= 0:
        return hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(mid) <= 0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    return lo


def _greedy_durations(v_max: float, a_max: float, j_max: float, s_max: float,
                      length: float | None) -> tuple[float, float, float, float | None]:
    """Shortest-first durations ``T_s, T_j, T_a`` and, for a given `length`, ``T_v``.

    Without `length` (a scan) the velocity ``v_max`` is reached exactly and
    ``T_v`` is left to the caller (``None``).
    """
    s = s_max
    bounds = [j_max / s, math.sqrt(a_max / s), (v_max / (2 * s)) ** (1 / 3)]
    if length is not None:
        bounds.append((length / (8 * s)) ** 0.25)
    ts = min(bounds)
    j = s * ts
    # T_j: acceleration j T_j <= a_max; velocity j T_j (T_s + T_j) <= v_max;
    # length 2 j T_j (T_s + T_j)^2 <= L (no constant-acceleration or -velocity phase)
    tj_bounds = [a_max / j, 0.5 * (-ts + math.sqrt(ts * ts + 4 * v_max / j))]
    if length is not None:
        tj_bounds.append(_increasing_root(lambda x: 2 * j * x * (ts + x) ** 2 - length, ts,
                                          max(tj_bounds)))
    tj = max(ts, min(tj_bounds))
    a = j * tj
    # T_a: velocity a T_a <= v_max; length a T_a (T_s + T_j + T_a) <= L
    ta_bounds = [v_max / a]
    if length is not None:
        c = ts + tj
        ta_bounds.append(0.5 * (-c + math.sqrt(c * c + 4 * length / a)))
    ta = max(ts + tj, min(ta_bounds))
    if length is None:
        return ts, tj, ta, None
    return ts, tj, ta, max(length / (a * ta), ts + tj + ta)


def _whole_samples(durations, period: float, scan_time: float | None = None):
    """Durations rounded up to whole sample periods, still superincreasing.

    With `scan_time` (a scan) ``T_v`` is the rounded ramp plus the scan time
    rounded up; otherwise ``T_v`` itself is rounded up.
    """
    def up(x: float) -> int:
        return max(1, math.ceil(x / period - _ROUND_TOL))

    ns = up(durations[0])
    nj = max(up(durations[1]), ns)
    na = max(up(durations[2]), ns + nj)
    nv = ns + nj + na + up(scan_time) if scan_time is not None else max(
        up(durations[3]), ns + nj + na)
    return ns * period, nj * period, na * period, nv * period


def check_window_samples(window: float, step: float, remedy: str = "give a longer window"
                         ) -> None:
    """Refuse an exposure `window` that holds one sample of a run of time step `step`.

    The window centred on a sample holds the samples with ``|t_k - t| <= W / 2``: below two
    steps only the sample itself, whose moving standard deviation is 0 and moving average
    the error itself, whatever the error does.  Nothing is measured over the window then.

    Parameters
    ----------
    window : float
        The exposure window ``W`` [s].
    step : float
        The run's time step [s].
    remedy : str
        What the caller can change, for the message.

    Raises
    ------
    ValueError
        One line: the window, the step and the shortest window that holds three samples.

    Examples
    --------
    >>> check_window_samples(0.01, 3.62e-5)
    >>> try:
    ...     check_window_samples(1e-9, 3.62e-5)
    ... except ValueError as exc:
    ...     print(exc)
    the exposure window 1e-09 s is shorter than two time steps of the run (3.62e-05 s): it \
holds one sample, whose moving standard deviation is 0 and moving average the error itself; \
give a longer window (at least 7.24e-05 s)
    """
    if window < 2.0 * step * (1.0 - 1e-9):
        least = 2.0 * step  # said rounded up: the figure given is then not refused
        scale = 10.0 ** (math.floor(math.log10(least)) - 2)
        raise ValueError(f"the exposure window {window:.3g} s is shorter than two time steps "
                         f"of the run ({step:.3g} s): it holds one sample, whose moving "
                         f"standard deviation is 0 and moving average the error itself; "
                         f"{remedy} (at least {math.ceil(least / scale) * scale:.3g} s)")


def _check_positive(**values: float) -> None:
    for name, v in values.items():
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be finite and > 0, got {v!r}")


@dataclass(frozen=True)
class Profile:
    """A fourth-order setpoint: rest-to-rest moves, evaluated exactly.

    Build one with :func:`point_to_point` or :func:`scan`.  Calling it gives
    position and acceleration, the interface of :mod:`motionhyst.time.references`
    (and of :func:`motionhyst.time.simulation.simulate`).

    Attributes
    ----------
    kind : {"point-to-point", "scan"}
        How the profile was specified.
    moves : tuple of Move
        The moves, in time order, not overlapping.
    limits : dict
        The limits asked for: ``v_max, a_max, j_max, s_max`` [m/s .. m/s^4].
    length : float
        The move length (point-to-point) or scan length at constant velocity
        (scan) [m], as realised (a scan rounded to whole samples may be longer).
    rate_hz : float or None
        Controller rate to whose samples the switching instants are rounded.
    back_and_forth : bool
        A scan followed by the same scan back to the start.
    dwell : float
        Rest between the scan and its return [s].

    Examples
    --------
    >>> p = point_to_point(0.1, v_max=0.5, a_max=10.0, j_max=500.0, s_max=5e4)
    >>> round(p.duration, 6)
    0.28
    >>> r, a = p([0.0, p.duration])
    >>> float(r[1]), float(a[1])
    (0.1, 0.0)
    """

    kind: str
    moves: tuple[Move, ...]
    limits: dict
    length: float
    rate_hz: float | None = None
    back_and_forth: bool = False
    dwell: float = 0.0
    _table: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        breaks, states = [], []
        p0 = 0.0
        for mv in self.moves:
            pulses = mv.pulses()
            ts = mv.durations[0]
            edges = sorted({t for t, _ in pulses} | {t + ts for t, _ in pulses})
            ramp_end = mv.start + sum(mv.durations[:3])
            state = np.array([p0, 0.0, 0.0, 0.0])
            for t0, t1 in pairwise(edges):
                mid = 0.5 * (t0 + t1)
                snap = sum(s for t, s in pulses if t <= mid < t + ts)
                breaks.append(t0)
                states.append((*state, snap))
                state = _propagate(state, snap, t1 - t0)
                if abs(t1 - ramp_end) <= 1e-12 * max(1.0, t1):
                    # constant velocity: exactly, not to the round-off of the ramp
                    state[1:] = (mv.length / mv.durations[3], 0.0, 0.0)
            p0 = p0 + mv.length  # exactly at rest at the end of the move
            breaks.append(edges[-1])
            states.append((p0, 0.0, 0.0, 0.0, 0.0))
        object.__setattr__(self, "_table", (np.array(breaks, float),
                                            np.array(states, float).reshape(-1, 5)))

    # ------------------------------------------------------------------ timing
    @property
    def start(self) -> float:
        """Time at which the first move starts [s]."""
        return self.moves[0].start

    @property
    def end(self) -> float:
        """Time at which the last move is at rest [s]."""
        return self.moves[-1].end

    @property
    def duration(self) -> float:
        """Time from the start of the first move to the end of the last [s]."""
        return self.end - self.start

    @property
    def durations(self) -> tuple[float, float, float, float]:
        """Boxcar durations ``(T_s, T_j, T_a, T_v)`` of the (first) move [s]."""
        return self.moves[0].durations

    @property
    def initial_velocity(self) -> float:
        """Velocity at ``t = 0`` [m/s]: 0, the profile starts from rest."""
        return 0.0

    @property
    def max_frequency_hz(self) -> float:
        """``1 / (40 T_s)`` [Hz]: the default simulation step resolves a snap pulse in 10."""
        return 1.0 / (40.0 * min(mv.durations[0] for mv in self.moves))

    def reached(self) -> dict:
        """Peak speed, acceleration, jerk and snap of the profile [m/s .. m/s^4]."""
        ts, tj, ta, tv = self.durations
        v = abs(self.moves[0].length) / tv
        return {"speed": v, "acceleration": v / ta, "jerk": v / (ta * tj),
                "snap": v / (ta * tj * ts)}

    def phases(self) -> list[Phase]:
        """The profile's phases in time order, with rest between and after the moves."""
        out: list[Phase] = []
        t = 0.0
        for mv in self.moves:
            if mv.start > t:
                out.append(Phase("rest", t, mv.start))
            out += mv.phases()
            t = mv.end
        return out

    def constant_velocity_phases(self) -> list[Phase]:
        """The constant-velocity phases: for a scan, the scans themselves."""
        return [p for p in self.phases() if p.kind == "constant velocity"]

    def check_window(self, window: float) -> None:
        """Refuse an exposure `window` [s] longer than every scan at constant velocity.

        The moving average and standard deviation of the error over the window
        (:mod:`motionhyst.scan.scanning`) need a scan at least that long; a
        point-to-point move has no such condition.

        Parameters
        ----------
        window : float
            The exposure window [s].

        Raises
        ------
        ValueError
            One line: the window and the scan's time at constant velocity.

        Examples
        --------
        >>> p = scan(0.01, speed=0.1, a_max=10.0, j_max=1000.0, s_max=1e6)
        >>> p.check_window(0.01)
        >>> p.check_window(1.0)
        Traceback (most recent call last):
        ...
        ValueError: the exposure window (1 s) is longer than the scan (0.1 s at constant velocity)
        """
        if self.kind == "scan" and not any(ph.duration >= window
                                           for ph in self.constant_velocity_phases()):
            raise ValueError(f"the exposure window ({window:g} s) is longer than the scan "
                             f"({self.constant_velocity_phases()[0].duration:g} s at constant "
                             "velocity)")

    # -------------------------------------------------------------- evaluation
    def derivatives(self, t: ArrayLike) -> NDArray[np.float64]:
        """Position, velocity, acceleration, jerk and snap at times `t`, shape ``(5, *t.shape)``.

        Exact (piecewise polynomial from the switching instants); at rest
        before the first move and after the last.

        Parameters
        ----------
        t : array_like
            Times [s].

        Examples
        --------
        >>> p = scan(0.05, speed=0.25, a_max=10.0, j_max=1000.0, s_max=1e6)
        >>> d = p.derivatives(p.constant_velocity_phases()[0].start + 0.01)
        >>> [round(float(x), 12) for x in d[1:]]
        [0.25, 0.0, 0.0, 0.0]
        """
        tt = np.asarray(t, dtype=float)
        breaks, states = self._table
        idx = np.searchsorted(breaks, tt, side="right") - 1
        before = idx < 0
        idx = np.clip(idx, 0, len(breaks) - 1)
        tau = np.where(before, 0.0, tt - breaks[idx])
        p0, v0, a0, j0, s = (np.where(before, 0.0, states[idx, k]) for k in range(5))
        out = np.empty((5, *tt.shape))
        out[0] = p0 + tau * (v0 + tau * (a0 / 2 + tau * (j0 / 6 + tau * s / 24)))
        out[1] = v0 + tau * (a0 + tau * (j0 / 2 + tau * s / 6))
        out[2] = a0 + tau * (j0 + tau * s / 2)
        out[3] = j0 + tau * s
        out[4] = s
        return out

    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and acceleration [m/s^2] at times `t` [s]."""
        d = self.derivatives(t)
        return d[0], d[2]

    def feedforward(self, t: ArrayLike, mass: float) -> NDArray[np.float64]:
        """Rigid-body feedforward force ``M r''`` [N] (``C_ff = M s^2``, paper Sec. II, eq. 1).

        Parameters
        ----------
        t : array_like
            Times [s].
        mass : float
            Rigid-body mass ``M`` [kg].

        Examples
        --------
        >>> p = point_to_point(0.01, v_max=0.2, a_max=5.0, j_max=500.0, s_max=1e5)
        >>> accelerate = p.phases()[0]
        >>> round(float(p.feedforward(accelerate.start + accelerate.duration / 2, 22.5)), 9)
        112.5
        """
        return float(mass) * self.derivatives(t)[2]

    def sample(self, rate_hz: float | None = None,
               after: float = 0.0) -> dict[str, NDArray[np.float64]]:
        """The profile at a controller's samples: ``time`` and each of :data:`DERIVATIVES`.

        Parameters
        ----------
        rate_hz : float, optional
            Sample rate [Hz]; by default the profile's own ``rate_hz``.
        after : float
            Time to sample after the end of the last move [s].

        Examples
        --------
        >>> p = point_to_point(0.01, 0.2, 5.0, 500.0, 1e5, rate_hz=10_000.0)
        >>> s = p.sample()
        >>> float(s["time"][1]), float(s["position"][-1])
        (0.0001, 0.01)
        """
        rate = self.rate_hz if rate_hz is None else rate_hz
        if rate is None:
            raise ValueError("give rate_hz: the profile has no controller rate")
        _check_positive(rate_hz=rate)
        n = math.floor((self.end + after) * rate + _ROUND_TOL) + 1
        t = np.arange(n) / rate
        return {"time": t, **dict(zip(DERIVATIVES, self.derivatives(t), strict=True))}

    # ----------------------------------------------------------------- outputs
    def to_dict(self) -> dict:
        """The profile's specification, durations and phases (JSON keys spelled here)."""
        ts, tj, ta, tv = self.durations
        d = {"kind": self.kind, "length": self.length, **self.limits,
             "back_and_forth": self.back_and_forth, "dwell_s": self.dwell,
             "rate_hz": self.rate_hz, "duration_s": self.duration,
             "durations_s": {"snap": ts, "jerk": tj, "acceleration": ta, "velocity": tv},
             "reached": self.reached(),
             "phases": [{"kind": p.kind, "start_s": p.start, "end_s": p.end}
                        for p in self.phases()]}
        return d

    def __str__(self) -> str:
        r = self.reached()
        what = (f"scan of {self.length:g} m at {r['speed']:g} m/s"
                + (" and back" if self.back_and_forth else "")
                if self.kind == "scan" else f"point-to-point move of {self.length:g} m")
        return (f"{what}: {self.duration:.4g} s; peak acceleration {r['acceleration']:.4g} "
                f"m/s^2, jerk {r['jerk']:.4g} m/s^3, snap {r['snap']:.4g} m/s^4")

    def plot(self, after: float = 0.0, ax=None):
        """Figure of position, velocity, acceleration, jerk and snap with the phases shaded.

        Parameters
        ----------
        after : float
            Time shown after the move ends [s].
        ax : sequence of 5 matplotlib.axes.Axes, optional
            Axes to draw into (position to snap); default: a new figure.
        """
        from matplotlib.figure import Figure

        t = np.linspace(0.0, self.end + after, 4001)
        d = self.derivatives(t)
        if ax is None:
            fig = Figure(figsize=(6.4, 6.4), layout="constrained")
            axes = fig.subplots(5, 1, sharex=True)
        else:
            axes = list(ax) if hasattr(ax, "__len__") else [ax]
            if len(axes) != 5:
                raise ValueError(f"this plot draws 5 axes; ax= gives {len(axes)}")
            fig = axes[0].figure
        units = ("m", "m/s", "m/s$^2$", "m/s$^3$", "m/s$^4$")
        for ax, name, unit, y in zip(axes, DERIVATIVES, units, d, strict=True):
            ax.plot(t, y, color="0.15", lw=1.2)
            ax.set_ylabel(f"{name}\n[{unit}]")
            ax.grid(True, alpha=0.3)
            shade_phases(ax, self)
        axes[-1].set_xlabel("time [s]")
        axes[0].set_title(str(self).replace(": ", ":\n", 1), fontsize=9)
        return fig


PHASE_COLORS = {"accelerate": "tab:orange", "constant velocity": "tab:green",
                "decelerate": "tab:purple"}


def shade_phases(ax, profile: Profile) -> None:
    """Shade the moving phases of `profile` on the axes `ax` (time on x)."""
    for p in profile.phases():
        if p.kind in PHASE_COLORS:
            ax.axvspan(p.start, p.end, color=PHASE_COLORS[p.kind], alpha=0.08, lw=0)


def _propagate(state, snap: float, h: float):
    p, v, a, j = state
    return np.array([p + h * (v + h * (a / 2 + h * (j / 6 + h * snap / 24))),
                     v + h * (a + h * (j / 2 + h * snap / 6)),
                     a + h * (j + h * snap / 2), j + h * snap])


def _limits(v_max, a_max, j_max, s_max) -> dict:
    _check_positive(v_max=v_max, a_max=a_max, j_max=j_max, s_max=s_max)
    return {"v_max": float(v_max), "a_max": float(a_max), "j_max": float(j_max),
            "s_max": float(s_max)}


def _check_rate_start(rate_hz, start) -> None:
    if rate_hz is not None:
        _check_positive(rate_hz=rate_hz)
    if not (math.isfinite(start) and start >= 0):
        raise ValueError(f"start must be finite and >= 0, got {start!r}")


def point_to_point(length: float, v_max: float, a_max: float, j_max: float, s_max: float,
                   rate_hz: float | None = None, start: float = 0.0) -> Profile:
    """Time-optimal snap-limited move of `length` [m] within the limits.

    Parameters
    ----------
    length : float
        Move length [m], non-zero; the sign gives the direction.
    v_max, a_max, j_max, s_max : float
        Velocity, acceleration, jerk and snap limits [m/s, m/s^2, m/s^3, m/s^4], > 0.
    rate_hz : float, optional
        Controller rate [Hz]: the switching instants are rounded up to its
        samples and the snap lowered so that the length stays exact.
    start : float
        Time at which the move starts [s].

    Returns
    -------
    Profile

    Examples
    --------
    >>> p = point_to_point(0.1, v_max=0.5, a_max=10.0, j_max=500.0, s_max=5e4)
    >>> [round(x, 6) for x in p.durations]   # T_s, T_j, T_a, T_v
    [0.01, 0.02, 0.05, 0.2]
    >>> {k: round(v, 6) for k, v in p.reached().items()}
    {'speed': 0.5, 'acceleration': 10.0, 'jerk': 500.0, 'snap': 50000.0}
    """
    if not (isinstance(length, int | float) and math.isfinite(length) and length != 0):
        raise ValueError(f"length must be finite and non-zero, got {length!r}")
    limits = _limits(v_max, a_max, j_max, s_max)
    _check_rate_start(rate_hz, start)
    durs = _greedy_durations(v_max, a_max, j_max, s_max, abs(length))
    if rate_hz is not None:
        durs = _whole_samples(durs, 1.0 / rate_hz)
    return Profile("point-to-point", (Move(float(start), float(length), durs),), limits,
                   float(length), rate_hz)


def scan(length: float, speed: float, a_max: float, j_max: float, s_max: float,
         back_and_forth: bool = False, dwell: float = 0.0, rate_hz: float | None = None,
         start: float = 0.0) -> Profile:
    """A scan: accelerate to `speed`, travel `length` at constant velocity, decelerate.

    Parameters
    ----------
    length : float
        Length of the constant-velocity phase [m], > 0.
    speed : float
        Scan speed [m/s], > 0, reached exactly.
    a_max, j_max, s_max : float
        Acceleration, jerk and snap limits, > 0.
    back_and_forth : bool
        Follow the scan, after `dwell`, by the same scan back to the start.
    dwell : float
        Rest between the scan and its return [s], >= 0.
    rate_hz : float, optional
        Controller rate [Hz]: the switching instants fall on its samples; the
        scan is lengthened to a whole number of samples and the snap lowered
        so that the speed stays exact.
    start : float
        Time at which the first move starts [s].

    Returns
    -------
    Profile

    Examples
    --------
    >>> p = scan(0.2, speed=0.25, a_max=20.0, j_max=2000.0, s_max=1e6, back_and_forth=True)
    >>> [(ph.kind, round(ph.duration, 4)) for ph in p.phases()][:3]
    [('accelerate', 0.0245), ('constant velocity', 0.8), ('decelerate', 0.0245)]
    >>> float(p(p.end)[0])   # back at the start
    0.0
    """
    _check_positive(length=length)
    limits = _limits(speed, a_max, j_max, s_max)
    _check_rate_start(rate_hz, start)
    if not (math.isfinite(dwell) and dwell >= 0):
        raise ValueError(f"dwell must be finite and >= 0, got {dwell!r}")
    ts, tj, ta, _ = _greedy_durations(speed, a_max, j_max, s_max, None)
    scan_time = length / speed
    if rate_hz is not None:
        ts, tj, ta, tv = _whole_samples((ts, tj, ta, 0.0), 1.0 / rate_hz, scan_time)
    else:
        tv = ts + tj + ta + scan_time
    durs = (ts, tj, ta, tv)
    ramp = ts + tj + ta
    total = speed * tv  # the move's length: scan plus the ramps' distances
    moves = [Move(float(start), total, durs)]
    if back_and_forth:
        moves.append(Move(moves[0].end + dwell, -total, durs))
    return Profile("scan", tuple(moves), limits, speed * (tv - ramp), rate_hz,
                   bool(back_and_forth), float(dwell))
