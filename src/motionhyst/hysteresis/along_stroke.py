"""A link whose parameters vary along the stroke: a table of scales over the position.

A cable slab bends at another place as the stage moves, so its stiffness and
slip force change along a long stroke.  The link here is a base model (any
link with a time-domain update) whose parameters are scaled at the position
``x`` by factors interpolated linearly in a table ``(x_i, s_i)`` (held beyond
its ends)::

    p(x) = p_base s_p(x)

The elements keep their state (for a stop operator, its force) when the
parameters change: a Jenkins element follows the paper's eq. (3) with ``k_J(x)``,
``dw = k(x) dx`` while ``|w| < fc(x)``, and slips at ``w = +-fc(x)``.  The time runs
update the parameters between pieces of the run over which the position stays within
one :data:`STEPS_PER_INTERVAL`-th of the table's spacing, at the piece's mean position
(the setpoint's in a closed loop: the stage's within the tracking error).

A stop operator whose stiffness varies is a conservative spring while it sticks: its
force is ``w = w_s + K(x) - K(x_s)`` since it stuck at ``x_s`` with ``w_s``, where
``K(x) = integral of k(x) dx`` (:meth:`AlongStroke.stiffness_integral`; exact for the
table's piecewise-linear ``k``, held beyond its ends), whatever path ``x`` took.  A
stiffness held piece by piece (``dw = k dx`` with the piece's ``k``) instead gains or
loses a little at each pass over a piece's edge, and a stop that never slips kept it:
its force drifted period after period.  So:

- the open-loop runs (:meth:`AlongStroke.response`, :meth:`AlongStroke.periodic_harmonics`,
  hence the exact steady state) advance such a stop on ``K(x) / k(x_0)`` with its
  stiffness at the table's first position: exact, sticking and slipping alike;
- the closed loops' runs (continuous and sampled), whose compiled step cannot transform
  the stage's position, set each such stop's force at a piece's end to
  ``w_s + K(x_e) - K(x_s)`` where it stuck through the piece
  (:meth:`AlongStroke.conserve`): exact at the pieces' ends where it sticks, so a stop
  that never slips returns to its force at the same position; within a piece, and over
  a piece where it slipped, the piece's held ``k`` (an error of the order of ``k'
  dx^2`` over the piece's ``dx``, not carried on: a slip sets the force).

The other kinds keep the piece's parameters: Dahl, Bouc-Wen and Maxwell branches
forget their start (a run settles on one periodic force), LuGre's state is the
bristles' deflection, not a force.
"""

from __future__ import annotations

from functools import lru_cache
from itertools import pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.validation import check_omega
from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.stepping import GL_T, GL_W, STOP, Stepping, open_loop_calls

__all__ = ["EXTRAPOLATED_RTOL", "FEEDFORWARD_KEY", "FIXED_IN_OPEN_LOOP", "LINK_KEY", "MAX_PERIODS",
           "NO_DESCRIBING_FUNCTION",
           "PERIODIC_RTOL", "STALL_PERIODS", "STEPS_PER_INTERVAL", "STUCK_RTOL", "AlongStroke"]

#: Parameter updates of a time run per interval of the table (the parameters are held over
#: the samples within one such step of the position).
STEPS_PER_INTERVAL = 64
#: A periodic force (:meth:`AlongStroke.periodic_harmonics`) repeats the previous period's to
#: this fraction of its largest value (a period's run rounds its force to about 1e-14 of it) ...
PERIODIC_RTOL = 1e-12
#: ... within this many periods of the displacement, run from rest ...
MAX_PERIODS = 2000
#: ... and refused once its change has not shrunk for this many periods.
STALL_PERIODS = 10
#: A change that shrinks by a steady ratio ``q`` a period (a Dahl link at a small stroke
#: forgets its start slowly) is extrapolated to its limit, ``w + (w - w_prev) q / (1 - q)``, once
#: that step, ``|w - w_prev| q / (1 - q)``, is at most this fraction of the force (its error a
#: tenth of it at most: the ratios agree to a tenth of ``1 - q``); a change that stops
#: shrinking below it is the run's rounding, settled.
EXTRAPOLATED_RTOL = 1e-6
#: A stop operator stuck through a piece of a closed loop's run (:meth:`AlongStroke.conserve`):
#: its force at the piece's end is its start plus the piece's ``k`` times the displacement to
#: this fraction of the larger (the compiled step's rounding over a piece is ~1e-15 of it; a
#: slip smaller than this is taken as none, its error as small).
STUCK_RTOL = 1e-9
#: The refusal of an open-loop system's link along the stroke (its runs hold the parameters).
FIXED_IN_OPEN_LOOP = ("an open-loop system (predict, identify) runs its link with fixed "
                      "parameters: a link along the stroke ([hysteresis] along) is run in a "
                      "closed loop (simulate, scan)")
#: The refusal of a computation that needs the link's describing function (or its HOSIDF),
#: its ``{key}`` the scenario's key of the table.
NO_DESCRIBING_FUNCTION = ("a link along the stroke ({key}) has no describing "
                          "function: run it in time (simulate --time-series, scan), or compute "
                          "its exact steady state in a study (outputs e1, harmonics, "
                          "error_rms)")
#: The scenario's key of a link along the stroke (``key`` of :class:`AlongStroke`) ...
LINK_KEY = "[hysteresis] along"
#: ... and of the feedforward's model of it.
FEEDFORWARD_KEY = "[feedforward] hysteresis.along"


class AlongStroke(Hysteresis):
    """The link `base` with its parameters scaled along the stroke.

    Parameters
    ----------
    base : Hysteresis
        The link at scale 1 (a model with a time-domain update).
    position : array_like
        Increasing positions ``x_i`` of the table [m], at least two.
    scales : dict
        For each parameter of `base` that varies, its scale at each position
        (positive; a parameter not named keeps scale 1).
    key : str
        The scenario's key that gives the table, named in refusals (:data:`LINK_KEY`, or
        :data:`FEEDFORWARD_KEY` for the feedforward's model).

    Examples
    --------
    A Jenkins link whose slip force falls from 60 to 40 mN over 0.1 m:

    >>> from motionhyst import Jenkins
    >>> link = AlongStroke(Jenkins(20.0, 0.05), [0.0, 0.1], {"fc": [1.2, 0.8]})
    >>> round(link.at(0.05).fc, 6), round(link.at(0.2).fc, 6)
    (0.05, 0.04)
    >>> w = link.response(np.linspace(0.0, 0.1, 1001))          # slipping forward
    >>> round(float(w[-1]), 6)
    0.04
    """

    name = "along-stroke"

    def __init__(self, base: Hysteresis, position: ArrayLike, scales: dict,
                 key: str = LINK_KEY) -> None:
        if isinstance(base, AlongStroke):
            raise ValueError("the base of a link along the stroke is a link model")
        self.base = base
        self.key = key
        self.position = np.asarray(position, dtype=float)
        x = self.position
        if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)) or np.any(np.diff(x) <= 0):
            raise ValueError("the positions along the stroke must be at least two finite, "
                             "increasing values")
        names = [p.name for p in base.parameters]
        self.scales: dict[str, NDArray[np.float64]] = {}
        for name, values in scales.items():
            if name not in names:
                raise ValueError(f"{name!r} is not a parameter of the {base.name} model "
                                 f"({', '.join(names)})")
            v = np.asarray(values, dtype=float)
            if v.shape != x.shape or not np.all(np.isfinite(v)) or np.any(v <= 0):
                raise ValueError(f"the scales of {name} must be {x.size} positive values, one "
                                 "per position")
            self.scales[name] = v
        self.rate_independent = base.rate_independent
        self.parameters = base.parameters
        base.time_stepping()  # a model without a time-domain update is refused here
        codes = self.time_stepping().codes
        # the stop operators whose stiffness varies: k at the table's positions, and its
        # integral from the first one (trapezoids: exact for the linear interpolation)
        k = np.array([self.stepping_params(xi)[:, 0] for xi in x])
        self._stops = np.flatnonzero((codes == STOP) & (np.ptp(k, axis=0) > 0))
        self._k = k[:, self._stops]
        self._K = np.vstack([np.zeros((1, self._stops.size)),
                             np.cumsum(0.5 * (self._k[1:] + self._k[:-1]) * np.diff(x)[:, None],
                                       axis=0)])

    def __repr__(self) -> str:
        return (f"AlongStroke({self.base!r}, position={self.position.tolist()}, "
                f"scales={ {k: v.tolist() for k, v in self.scales.items()} })")

    def scale_at(self, x: float) -> dict[str, float]:
        """Each varying parameter's scale at position `x` (held beyond the table).

        Parameters
        ----------
        x : float
            Position [m].
        """
        return {k: float(np.interp(x, self.position, v)) for k, v in self.scales.items()}

    def at(self, x: float) -> Hysteresis:
        """The base model with its parameters at position `x`.

        Parameters
        ----------
        x : float
            Position [m].
        """
        return _scaled(self.base, tuple(sorted(self.scale_at(x).items())))

    def with_base(self, base: Hysteresis) -> AlongStroke:
        """The same table of scales around another base model.

        Parameters
        ----------
        base : Hysteresis
            The new base (same model).
        """
        return AlongStroke(base, self.position, self.scales, self.key)

    def shifted(self, x0: float) -> AlongStroke:
        """The link seen from a stroke position `x0`: position 0 here is `x0` on the table.

        Parameters
        ----------
        x0 : float
            Where on the stroke the motion starts [m].
        """
        return AlongStroke(self.base, self.position - float(x0), self.scales, self.key)

    @property
    def initial_stiffness(self) -> float:
        """The largest initial stiffness along the table [N/m]."""
        return self._largest("initial_stiffness")

    @property
    def bristle_damping(self) -> float:
        """The largest :attr:`~motionhyst.hysteresis.base.Hysteresis.bristle_damping` along
        the table [N s/m] (the base model's, LuGre's ``sigma1``, scaled).

        Examples
        --------
        >>> from motionhyst import LuGre
        >>> lugre = LuGre(sigma0=1e5, sigma1=316.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
        >>> AlongStroke(lugre, [0.0, 0.1], {"fc": [1.0, 2.0]}).bristle_damping
        316.0
        """
        return self._largest("bristle_damping")

    @property
    def viscous_damping(self) -> float:
        """The largest :attr:`~motionhyst.hysteresis.base.Hysteresis.viscous_damping` along
        the table [N s/m] (the base model's, scaled).

        Examples
        --------
        >>> from motionhyst import LuGre
        >>> lugre = LuGre(sigma0=1e5, sigma1=316.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
        >>> AlongStroke(lugre, [0.0, 0.1], {"sigma2": [1.0, 0.5]}).viscous_damping
        0.4
        """
        return self._largest("viscous_damping")

    def _largest(self, attribute: str) -> float:
        """The largest value of the base model's `attribute` at the table's positions."""
        return max(float(getattr(self.at(x), attribute)) for x in self.position)

    def describing_function(self, A, omega=None):
        """Not defined: the link's parameters change with the position.

        Parameters
        ----------
        A, omega : array_like
            Amplitude and frequency (unused).

        Raises
        ------
        ValueError
            Always (:data:`NO_DESCRIBING_FUNCTION`).
        """
        raise ValueError(NO_DESCRIBING_FUNCTION.format(key=self.key))

    def hosidf(self, A, n_max, omega=None):
        """Not defined, as :meth:`describing_function` (its first harmonic).

        Parameters
        ----------
        A, n_max, omega
            As :meth:`Hysteresis.hosidf` (unused).

        Raises
        ------
        ValueError
            Always (:data:`NO_DESCRIBING_FUNCTION`).
        """
        raise ValueError(NO_DESCRIBING_FUNCTION.format(key=self.key))

    def time_stepping(self) -> Stepping:
        """The elements at the start of the table's first position (the runs update them)."""
        return self.at(self.position[0]).time_stepping()

    def stepping_params(self, x: float) -> NDArray[np.float64]:
        """The elements' parameter rows at position `x` (:class:`~.stepping.Stepping`).

        Parameters
        ----------
        x : float
            Position [m].
        """
        return self.at(x).time_stepping().params

    @property
    def varying_stops(self) -> NDArray[np.int64]:
        """The rows of the elements (:meth:`time_stepping`) that are stop operators whose
        stiffness varies along the table (advanced by :meth:`stiffness_integral`)."""
        return self._stops

    def stiffness_integral(self, x: ArrayLike) -> NDArray[np.float64]:
        """``K(x) = integral of k(u) du`` from the table's first position to `x`, for each
        of the :attr:`varying_stops`: the force a stop operator stuck at ``x_s`` gains moving
        to `x` is ``K(x) - K(x_s)`` (the paper's eq. (3), ``dw = k_J(x) dx``, integrated).

        Exact for the table's ``k``, linear between its positions and held beyond its ends.

        Parameters
        ----------
        x : array_like
            Positions [m].

        Returns
        -------
        ndarray, shape ``x.shape + (len(varying_stops),)``
            [N].

        Examples
        --------
        A Jenkins element whose stiffness doubles from 10 to 20 N/m over 0.1 m:

        >>> from motionhyst import Jenkins
        >>> link = AlongStroke(Jenkins(10.0, 5.0), [0.0, 0.1], {"k": [1.0, 2.0]})
        >>> K = link.stiffness_integral([0.0, 0.1, 0.2])[:, 0]
        >>> [round(float(v), 12) for v in K]           # 1.5 N over the table, then 20 N/m
        [0.0, 1.5, 3.5]
        """
        return self._integral(np.asarray(x, dtype=float), slice(None))

    def _integral(self, x: NDArray[np.float64], columns) -> NDArray[np.float64]:
        """:meth:`stiffness_integral` of the :attr:`varying_stops` `columns` selects."""
        xp, k, K = self.position, self._k[:, columns], self._K[:, columns]
        i = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, xp.size - 2)
        u = (np.clip(x, xp[0], xp[-1]) - xp[i])[..., None]
        slope = (k[i + 1] - k[i]) / (xp[i + 1] - xp[i])[..., None]
        out = K[i] + u * (k[i] + 0.5 * slope * u)
        out += k[0] * np.minimum(x - xp[0], 0.0)[..., None]
        out += k[-1] * np.maximum(x - xp[-1], 0.0)[..., None]
        return out

    def conserve(self, s: NDArray[np.float64], s_start: NDArray[np.float64], y_start: float,
                 y_end: float, params: NDArray[np.float64]) -> float:
        """Set, in place, the force `s` at a piece's end of each of the :attr:`varying_stops`
        that stuck through the piece to ``w_s + K(y_end) - K(y_start)``
        (:meth:`stiffness_integral`), the piece having advanced it with its held ``k``.

        A stop stuck through the piece where its force at the end is ``w_s + k (y_end -
        y_start)`` to :data:`STUCK_RTOL` (a slip would have taken some of that off); the
        conserved force is held within its slip force.

        Parameters
        ----------
        s : ndarray
            The elements' states at the piece's end (updated).
        s_start : ndarray
            Their states at its start.
        y_start, y_end : float
            The link's displacement at the piece's start and end (positions on the table) [m].
        params : ndarray
            The elements' parameter rows the piece was run with.

        Returns
        -------
        float
            The change of the link's force [N].

        Examples
        --------
        A stop stuck at 0 N moved from 0 to 0.1 m with the piece's k = 15 N/m:

        >>> from motionhyst import Jenkins
        >>> link = AlongStroke(Jenkins(10.0, 5.0), [0.0, 0.1], {"k": [1.0, 2.0]})
        >>> s = np.array([1.5 + 0.02])                 # as a piece with k = 15.2 N/m left it
        >>> link.conserve(s, np.zeros(1), 0.0, 0.1, np.array([[15.2, 5.0, 0, 0, 0, 0]]))
        -0.02...
        >>> round(float(s[0]), 12)
        1.5
        """
        rows = self._stops
        if rows.size == 0 or y_end == y_start:
            return 0.0
        k, fc = params[rows, 0], params[rows, 1]
        w0, w1 = s_start[rows], s[rows]
        held = w0 + k * (y_end - y_start)
        stuck = np.abs(w1 - held) <= STUCK_RTOL * np.maximum(np.abs(held), np.abs(w1))
        if not np.any(stuck):
            return 0.0
        K = self.stiffness_integral(np.array([y_start, y_end]))
        w = np.where(stuck, np.clip(w0 + (K[1] - K[0]), -fc, fc), w1)
        s[rows] = w
        return float(np.sum(w - w1))

    def pieces(self, x: ArrayLike) -> list[tuple[int, int]]:
        """Index ranges ``[i0, i1)`` of `x` within one :data:`STEPS_PER_INTERVAL`-th of the
        table's smallest spacing: a time run holds the parameters over each.

        Parameters
        ----------
        x : array_like
            Positions [m].
        """
        x = np.asarray(x, dtype=float)
        if x.size == 0:
            return []
        dx = float(np.min(np.diff(self.position))) / STEPS_PER_INTERVAL
        cell = np.floor((x - self.position[0]) / dx)
        breaks = np.flatnonzero(np.diff(cell)) + 1
        edges = [0, *breaks.tolist(), x.size]
        return list(pairwise(edges))

    def response(self, x: ArrayLike, w0: float = 0.0, t: ArrayLike | None = None
                 ) -> NDArray[np.float64]:
        """Force for the displacement samples `x` from rest, the parameters updated between
        :meth:`pieces` at each one's mean position, the :attr:`varying_stops` advanced on
        :meth:`stiffness_integral` (exact: the module docstring).

        Parameters
        ----------
        x : array_like
            Displacement samples [m] (positions on the table).
        w0 : float
            Must be 0: the link starts at rest.
        t : array_like, optional
            Sample times [s], uniformly spaced, same length as `x`: required for a
            rate-dependent base (LuGre), whose force depends on the velocity.
        """
        if w0 != 0.0:
            raise ValueError("a link along the stroke starts at rest (w0 = 0)")
        x = np.ascontiguousarray(x, dtype=float)
        run = self._runner(float(x[0]) if x.size else 0.0, self._step(x, t))
        return run(x, 0)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Harmonics of the periodic force for a periodic displacement, the table followed.

        The period is sampled as :meth:`Hysteresis.periodic_harmonics` samples it and
        run from rest, period after period, the parameters updated between
        :meth:`pieces` as in a time run (the :attr:`varying_stops` on
        :meth:`stiffness_integral`: a stop that never slips repeats its force exactly), until
        a period's force repeats the previous one to :data:`PERIODIC_RTOL` of its largest
        value.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement (positions on the table) over one
            period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency [rad/s]; required for a rate-dependent base (LuGre).

        Returns
        -------
        ndarray of complex, shape (H + 1,)

        Raises
        ------
        RuntimeError
            If the force does not repeat within :data:`MAX_PERIODS` periods (nor extrapolates
            to its limit, :data:`EXTRAPOLATED_RTOL`), or its change has not shrunk for
            :data:`STALL_PERIODS` periods.

        Examples
        --------
        With unit scales, the base link's own (exact) harmonics:

        >>> from motionhyst import Jenkins
        >>> base = Jenkins(20.0, 0.05)
        >>> link = AlongStroke(base, [-0.01, 0.01], {"fc": [1.0, 1.0]})
        >>> X = np.array([0.0, 0.01 / 2j])
        >>> bool(np.allclose(link.periodic_harmonics(X, 5), base.periodic_harmonics(X, 5),
        ...                  rtol=0, atol=1e-6 * 0.05))
        True
        """
        from motionhyst.hysteresis.periodic import sample_period

        H = int(n_harmonics)
        N = max(8 * H, 8 * (len(X) - 1), 8192)
        x = np.ascontiguousarray(sample_period(X, N))
        h = 0.0
        if not self.rate_independent:
            h = 2.0 * np.pi / (check_omega(omega, self.base.name) * N)
        run = self._runner(float(x[0]), h)
        w = run(x, 0)
        smallest, since, changes = np.inf, 0, []
        for p in range(1, MAX_PERIODS):
            prev, w = w, run(x, p * N)
            change = float(np.max(np.abs(w - prev)))
            scale = max(float(np.max(np.abs(w))), 1e-300)
            if change <= PERIODIC_RTOL * scale:
                return (np.fft.rfft(w) / N)[: H + 1]
            changes.append(change)
            smallest, since = (change, 0) if change < smallest else (smallest, since + 1)
            if since >= STALL_PERIODS:
                if smallest <= EXTRAPOLATED_RTOL * scale:  # at the run's rounding, settled
                    return (np.fft.rfft(w) / N)[: H + 1]
                raise RuntimeError(
                    f"the {self.base.name} link along the stroke ({self.key}) has no "
                    f"periodic force: its change from period to period ({change:.2g} N) does "
                    "not shrink (its elements neither settle nor forget their start); "
                    "run it in time (simulate --time-series)")
            if len(changes) > 2 * STALL_PERIODS:
                rest = _geometric_rest(changes[-STALL_PERIODS - 1:])
                if change * rest <= EXTRAPOLATED_RTOL * scale:
                    return (np.fft.rfft(w + (w - prev) * rest) / N)[: H + 1]
        raise RuntimeError(
            f"the {self.base.name} link along the stroke ({self.key}) settles too "
            f"slowly: after {MAX_PERIODS} periods its force still changes by {change:.2g} N "
            "a period; run it in time (simulate --time-series)")

    def _step(self, x: NDArray[np.float64], t: ArrayLike | None) -> float:
        """The uniform step of the sample times `t` (0 for a rate-independent base, whose
        force does not depend on it)."""
        if self.rate_independent:
            return 0.0
        if t is None:
            raise ValueError(f"the {self.base.name} model is rate-dependent: response() of its "
                             "link along the stroke needs the sample times t [s]")
        ts = np.asarray(t, dtype=float)
        if ts.shape != x.shape or not np.all(np.isfinite(ts)):
            raise ValueError("x and t must be finite and of the same length")
        if ts.size < 2:
            return 0.0
        h = (ts[-1] - ts[0]) / (ts.size - 1)
        if not h > 0 or np.max(np.abs(np.diff(ts) - h)) > 1e-9 * h:
            raise ValueError("the sample times t of a link along the stroke must be "
                             "uniformly spaced and increasing")
        return float(h)

    def _groups(self) -> list[tuple[NDArray[np.int64], int]]:
        """The elements' rows run together by :meth:`_runner`: ``(rows, j)`` with ``j`` the
        column of :meth:`stiffness_integral` they run on (-1: on the position itself); the
        :attr:`varying_stops` grouped by the shape of their stiffness along the table."""
        n = self.time_stepping().codes.size
        rest = np.setdiff1d(np.arange(n), self._stops)
        groups = [(rest, -1)] if rest.size else []
        shape = self._k / self._k[0]
        left = list(range(self._stops.size))
        while left:
            j = left[0]
            same = [c for c in left if np.allclose(shape[:, c], shape[:, j], rtol=1e-12, atol=0)]
            groups.append((self._stops[same], j))
            left = [c for c in left if c not in same]
        return groups

    def _runner(self, x0: float, h: float):
        """``run(x, i0)``: the force of the samples `x` (indices from `i0`, step `h`), the
        elements' state carried from call to call, starting at rest at `x0`.

        The :attr:`varying_stops` run on ``K(x) / k(x_0)`` (:meth:`stiffness_integral`,
        ``x_0`` the table's first position) with their stiffness at ``x_0``: their force
        gains ``K(x_e) - K(x_s)`` while they stick (exact), the others' run on ``x``."""
        st = self.at(x0).time_stepping()
        state = []
        for rows, j in self._groups():
            s = np.ascontiguousarray(st.state0[rows], dtype=float).copy()
            state.append((rows, j, np.ascontiguousarray(st.codes[rows]), s, s.copy(),
                          np.zeros(2)))

        def run(x: NDArray[np.float64], i0: int) -> NDArray[np.float64]:
            out = np.zeros(x.size)
            for a, b in self.pieces(x):
                params = self.stepping_params(float(np.mean(x[a:b])))
                for rows, j, codes, s, s_prev, scalars in state:
                    p = np.ascontiguousarray(params[rows])
                    piece = x[a:b]
                    if j >= 0:  # the position stretched by the stiffness' scale
                        p[:, 0] = self._k[0, np.searchsorted(self._stops, rows)]
                        piece = self._integral(piece, slice(j, j + 1))[:, 0] / self._k[0, j]
                    out[a:b] += open_loop_calls(codes, p, s, s_prev, scalars, piece, h, i0 + a,
                                                GL_T, GL_W)
            return out

        return run

    def to_dict(self) -> dict:
        """The base model's parameters and the table (key ``along``)."""
        return {**self.base.to_dict(), "along": {"position": self.position.tolist(),
                                                 **{k: v.tolist() for k, v in
                                                    self.scales.items()}}}


def _geometric_rest(changes: list[float]) -> float:
    """``q / (1 - q)`` of changes that shrink by a steady ratio ``q`` a period (the sum of all
    later changes over the last), or infinity when they do not (a ratio of 1 or more, or
    ratios that vary by more than a tenth of ``1 - q``)."""
    c = np.asarray(changes, dtype=float)
    ratios = c[1:] / c[:-1]
    if not np.all((ratios > 0.0) & (ratios < 1.0)):
        return np.inf
    q = float(np.exp(np.mean(np.log(ratios))))
    if np.ptp(ratios) > 0.1 * (1.0 - q):
        return np.inf
    return q / (1.0 - q)


@lru_cache(maxsize=4096)
def _scaled_cached(cls, items: tuple, scales: tuple) -> Hysteresis:
    kw = dict(items)
    for name, s in scales:
        v = kw[name]
        kw[name] = tuple(x * s for x in v) if isinstance(v, tuple) else v * s
    return cls(**{k: list(v) if isinstance(v, tuple) else v for k, v in kw.items()})


def _scaled(base: Hysteresis, scales: tuple) -> Hysteresis:
    d = base.to_dict()
    items = tuple((p.name, tuple(d[p.name]) if isinstance(d[p.name], list) else d[p.name])
                  for p in base.parameters)
    return _scaled_cached(type(base), items, scales)
