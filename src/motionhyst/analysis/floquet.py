"""Floquet multipliers of a periodic solution of the loop with its link, from the exact monodromy.

A periodic solution is stable when every deviation from it dies out.  Over one period
``T`` a small deviation ``dX`` of the loop's state (the linear part's and the link's) is
mapped by the monodromy matrix ``M = dX(T) / dX(0)``; its eigenvalues are the Floquet
multipliers, and the solution is stable when all lie inside the unit circle (for an
autonomous cycle one of them is 1, a shift along the orbit, and is left out).

The linear part is the loop seen by the link, ``y1 = -G w`` with ``G = P1 / (1 + C P2)``
(:class:`LoopStateEquation`: ``x' = A x - B w``, ``y1 = C x``, ``v1 = C A x``); the
reference drives the solution but not its deviations.  The link's deviations follow its
own linearisation along the solution:

* a link with a smooth state equation (LuGre, Dahl, Bouc-Wen,
  :meth:`~motionhyst.hysteresis.Hysteresis.state_equation`): ``z' = f(z, v1)``,
  ``w = h(z, v1)``; the Jacobian along the solution at the midpoints of fine steps, the
  monodromy the product of their exponentials;
* stop elements (Jenkins, Maxwell-slip): a stuck element is a spring ``k`` (``dw' = k dv1``),
  a slipping one holds its force (``dw' = 0``); at the onset of slip the vector field
  jumps and the saltation matrix sets the element's ``dw`` to 0, at a reversal it is
  continuous.  The monodromy is then a product of matrix exponentials over the intervals
  of one set of stuck elements, with those resets.

Examples
--------
The paper's Table I at 5 Hz: a deviation shrinks to a tenth within a period (its slowest
closed-loop mode decays at 11.6 /s).

>>> from motionhyst import default_scenario, periodic_steady_state
>>> loop = default_scenario().loop()
>>> fl = steady_state_floquet(loop, periodic_steady_state(loop, 0.01, 5.0))
>>> round(fl.floquet_max, 4), fl.stable       # the stage's resonance, b (1/m1 + 1/m2) / 2
(0.0988, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.analysis.steady import MAX_HARMONICS, MIN_HARMONICS, SteadyState
from motionhyst.controllers.loop import Loop
from motionhyst.core.budget import check_memory, check_work
from motionhyst.core.lti import TWO_PI
from motionhyst.core.textfmt import g
from motionhyst.hysteresis import Hysteresis
from motionhyst.hysteresis.along_stroke import AlongStroke
from motionhyst.hysteresis.stepping import STOP

__all__ = ["MAX_TIME_SCALE_RATIO", "SECONDS_PER_ELEMENT_STEP", "SECONDS_PER_STATE_CUBED",
           "SECONDS_PER_STEP", "FloquetResult", "LoopStateEquation", "check_floquet_budget",
           "steady_state_floquet", "unresolved_time_scales"]

MAX_TIME_SCALE_RATIO = 1e6
"""Largest ratio of the loop's fastest to slowest closed-loop pole whose monodromy, a product
of matrix exponentials in double precision, is resolved (Table I: 6.5; a stage stiffness of
1e20 N/m: 7.7e6, and multipliers of 1e239 that mean nothing)."""

SECONDS_PER_STEP = 20e-6
"""Nominal cost of the monodromy per step of the period [s] (one core of a quiet machine:
the stop elements' intervals, a smooth link's exponentials)."""

SECONDS_PER_ELEMENT_STEP = 10e-9
"""Nominal cost of the monodromy per step of the period and stop element [s]."""

SECONDS_PER_STATE_CUBED = 1e-8
"""Nominal cost of the multipliers per cube of the monodromy's states [s] (its eigenvalues)."""


@dataclass
class FloquetResult:
    """Floquet multipliers of a periodic solution.

    Attributes
    ----------
    period_s : float
        The period ``T`` [s].
    multipliers : ndarray of complex
        The multipliers, largest first (for an autonomous cycle without the trivial 1).
    floquet_max : float
        The largest ``|mu|``.
    stable : bool
        ``floquet_max < 1``.

    Examples
    --------
    >>> import numpy as np
    >>> r = FloquetResult(0.2, np.array([0.5, 0.1j]), 0.5, True)
    >>> r.to_dict()
    {'floquet_max': 0.5, 'stable': True}
    """

    period_s: float
    multipliers: NDArray[np.complex128]
    floquet_max: float
    stable: bool

    def to_dict(self) -> dict:
        """JSON-ready dictionary: ``floquet_max`` and ``stable`` (keys of ``steady --json``)."""
        return {"floquet_max": float(self.floquet_max), "stable": bool(self.stable)}

    def __str__(self) -> str:
        mus = ", ".join(g(abs(m)) for m in self.multipliers[:4])
        return (f"Floquet multipliers over T = {g(self.period_s)} s: |mu| = {mus}"
                f"{', ...' if self.multipliers.size > 4 else ''}: "
                f"{'stable' if self.stable else 'UNSTABLE'}")

    def plot(self, ax=None):
        """The multipliers in the complex plane with the unit circle.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_multipliers

        return plot_multipliers(self, ax=ax)


def from_monodromy(M: NDArray, T: float, autonomous: bool = False, neutral: int = 0
                   ) -> FloquetResult:
    """:class:`FloquetResult` of a monodromy matrix, the trivial multipliers 1 left out.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        The monodromy matrix.
    T : float
        The period [s].
    autonomous : bool
        Leave out the multiplier nearest 1 (a shift along an autonomous orbit).
    neutral : int
        Leave out as many more multipliers equal to 1 (to 1e-9): the preloads of stop
        elements that never slip (any force they hold is a steady state as well).

    Returns
    -------
    FloquetResult

    Examples
    --------
    >>> import numpy as np
    >>> from_monodromy(np.diag([1.0, 0.25]), 2.0, autonomous=True).floquet_max
    0.25
    """
    mu = np.linalg.eigvals(np.asarray(M, dtype=float))
    if autonomous and mu.size:
        mu = np.delete(mu, int(np.argmin(np.abs(mu - 1.0))))
    for _ in range(neutral):
        i = int(np.argmin(np.abs(mu - 1.0)))
        if mu.size and abs(mu[i] - 1.0) < 1e-9:
            mu = np.delete(mu, i)
    mu = mu[np.argsort(-np.abs(mu))]
    fmax = float(np.abs(mu[0])) if mu.size else 0.0
    return FloquetResult(float(T), mu, fmax, fmax < 1.0)


class LoopStateEquation:
    """The loop seen by the link as a state equation, the setpoint at 0.

    ``x' = A x - B w``, ``y1 = C x``, ``v1 = C A x`` (``G = P1 / (1 + C P2)`` of
    relative degree >= 2, balanced), and the link's states ``z`` after ``x`` in the state
    ``X = (x, z)`` for a link with a smooth state equation.

    Parameters
    ----------
    loop : Loop
        A continuous LTI loop with a link.

    Raises
    ------
    ValueError
        If ``G`` has relative degree < 2 (the link's velocity is not a state).

    Examples
    --------
    >>> import control
    >>> from motionhyst import Loop, LuGre
    >>> from motionhyst.plants import MassDamper
    >>> link = LuGre(sigma0=1e5, sigma1=300.0, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
    >>> pid = control.tf([6.0, 3.0, 4.0], [1.0, 0.0])
    >>> sys = LoopStateEquation(Loop(MassDamper(1.0, 0.0), pid, link, feedforward=None))
    >>> sys.n, sys.N                   # s / (s^3 + 6 s^2 + 3 s + 4): three states, and z
    (3, 4)
    """

    def __init__(self, loop: Loop) -> None:
        import control
        from scipy.linalg import matrix_balance

        tf = loop.transfer_tf("w->y1")
        num = -np.trim_zeros(np.asarray(tf.num[0][0], dtype=float), "f")
        den = np.trim_zeros(np.asarray(tf.den[0][0], dtype=float), "f")
        if len(den) - len(num) < 2:
            raise ValueError("the link's velocity must be a state of the loop (G = P1 / (1 + "
                             "C P2) of relative degree >= 2)")
        ss = control.tf2ss(num / den[0], den / den[0])
        # scipy casts every balancing factor to an integer to read the permutation out of
        # it; factors past 2**63 (a stage with several modes in companion form) warn in
        # that cast, which only the permutation entries (none here) would use
        with np.errstate(invalid="ignore"):
            A, T = matrix_balance(np.asarray(ss.A, dtype=float))
        self.A = A
        self.B = np.linalg.solve(T, np.asarray(ss.B, dtype=float)).ravel()
        self.C = (np.asarray(ss.C, dtype=float) @ T).ravel()
        self.CA = self.C @ self.A
        self.link: Hysteresis = loop.hysteresis
        self.n = self.A.shape[0]
        self.ns = self.link.n_states
        self.N = self.n + self.ns

    def rhs(self, t: float, X: NDArray) -> NDArray:
        """``X'`` of the autonomous loop.

        Parameters
        ----------
        t : float
            Time [s] (unused: autonomous).
        X : ndarray
            The state ``(x, z)``.
        """
        x, z = X[:self.n], X[self.n:]
        v = float(self.CA @ x)
        zdot, w, *_ = self.link.state_equation(z, v)
        return np.concatenate([self.A @ x - self.B * w, zdot])

    def linearised(self, z: NDArray, v: float) -> NDArray:
        """The Jacobian of :meth:`rhs` at the link's state `z` and velocity `v`.

        Parameters
        ----------
        z : ndarray
            The link's states.
        v : float
            The link's velocity [m/s].
        """
        n = self.n
        _, _, dzz, dzv, dwz, dwv = self.link.state_equation(z, v)
        J = np.empty((self.N, self.N))
        J[:n, :n] = self.A - np.outer(self.B, dwv * self.CA)
        J[:n, n:] = -np.outer(self.B, dwz)
        J[n:, :n] = np.outer(dzv, self.CA)
        J[n:, n:] = dzz
        return J

    def jac(self, t: float, X: NDArray) -> NDArray:
        """The Jacobian of :meth:`rhs` at `X`.

        Parameters
        ----------
        t : float
            Time [s] (unused).
        X : ndarray
            The state ``(x, z)``.
        """
        return self.linearised(X[self.n:], float(self.CA @ X[:self.n]))


# ------------------------------------------------------------------ forced steady states
class _Harmonics:
    """``y1(t)`` and ``v1(t)`` of a steady state from its harmonics (sin-referenced)."""

    def __init__(self, ss: SteadyState) -> None:
        self.ss = ss
        self.omega = TWO_PI * ss.frequency_hz
        c = np.asarray(ss.y1, dtype=complex)
        self.mean = float(c[0].real)
        self.c = c[1:]
        self.n = np.arange(1, c.size)

    def samples(self, n: int) -> NDArray:
        """``y1`` on ``t = i T / n`` (an inverse FFT)."""
        return self.ss.time_series(n)["y1"]

    def y(self, t):
        ph = np.multiply.outer(np.atleast_1d(t), self.n * self.omega)
        return self.mean + np.sum(np.abs(self.c) * np.sin(ph + np.angle(self.c)), axis=-1)

    def v(self, t):
        ph = np.multiply.outer(np.atleast_1d(t), self.n * self.omega)
        return np.sum(np.abs(self.c) * self.n * self.omega * np.cos(ph + np.angle(self.c)),
                      axis=-1)


def _smooth_monodromy(sys: LoopStateEquation, h: _Harmonics, T: float, samples: int
                      ) -> NDArray:
    """The variations along the steady state of a link with a smooth state equation.

    The Jacobian along the solution taken at the midpoints of `samples` steps, the
    monodromy the product of their exponentials (second order in the step; each step's
    stiff link relaxation is exact in it).
    """
    from scipy.integrate import solve_ivp

    from motionhyst.core.lti import expm_small

    link, ns = sys.link, sys.ns

    def fz(t, z):
        return link.state_equation(z, float(h.v(t)[0]))[0]

    # the link's periodic state along the solution: two periods to settle, the third kept
    z0 = solve_ivp(fz, (0.0, 2 * T), np.zeros(ns), method="LSODA", rtol=1e-11,
                   atol=1e-18).y[:, -1]
    dt = T / samples
    mid = (np.arange(samples) + 0.5) * dt
    sol = solve_ivp(fz, (0.0, T), z0, method="LSODA", rtol=1e-11, atol=1e-18, t_eval=mid)
    if not sol.success:
        raise RuntimeError(f"the link's state could not be integrated: {sol.message}")
    v = h.v(mid)
    M = np.eye(sys.N)
    for j in range(samples):
        M = expm_small(sys.linearised(sol.y[:, j], float(v[j])) * dt) @ M
    return M


def _stop_monodromy(sys: LoopStateEquation, h: _Harmonics, T: float, k: NDArray,
                    fc: NDArray, samples: int) -> tuple[NDArray, int]:
    """The product of exponentials over the stuck/slipping intervals of stop elements, and
    the number of elements that never slip."""
    from scipy.linalg import expm

    n, m = sys.n, k.size
    N = n + m
    y = np.tile(h.samples(samples), 2)
    dy = np.diff(np.append(y, y[0]))
    # the stop operators over two periods from rest; the second is periodic
    w = np.zeros(m)
    stuck = np.ones((samples, m), dtype=bool)
    onset = np.full((samples, m), np.nan)          # fraction of the step where slip begins
    for j in range(2 * samples):
        free = w + k * dy[j]
        lim = np.clip(free, -fc, fc)
        slipping = lim != free
        if j >= samples:
            jj = j - samples
            stuck[jj] = ~slipping
            was_stuck = np.abs(w) < fc
            start = slipping & was_stuck
            with np.errstate(divide="ignore", invalid="ignore"):
                frac = (np.sign(dy[j]) * fc - w) / (k * dy[j])
            onset[jj] = np.where(start, np.clip(frac, 0.0, 1.0), np.nan)
        w = lim

    def block(st):
        J = np.zeros((N, N))
        J[:n, :n] = sys.A
        J[:n, n:] = -np.outer(sys.B, np.ones(m))
        J[n:, :n] = np.outer(k * st, sys.CA)
        return J

    M = np.eye(N)
    dt = T / samples
    j = 0
    while j < samples:
        st = stuck[j]
        if np.any(~np.isnan(onset[j])):
            # the step splits: stuck until the onset, the elements' dw reset, slipping after
            before = st | ~np.isnan(onset[j])
            frac = float(np.nanmin(onset[j]))
            M = expm(block(before) * frac * dt) @ M
            reset = np.ones(N)
            reset[n:][~np.isnan(onset[j])] = 0.0
            M = reset[:, None] * M
            M = expm(block(st) * (1.0 - frac) * dt) @ M
            j += 1
            continue
        j2 = j + 1
        while (j2 < samples and np.array_equal(stuck[j2], st)
               and np.all(np.isnan(onset[j2]))):
            j2 += 1
        M = expm(block(st) * (j2 - j) * dt) @ M
        j = j2
    return M, int(np.sum(np.all(stuck, axis=0)))


def _floquet_size(loop: Loop, frequencies_hz: NDArray, samples: int | None
                  ) -> tuple[float, float, int]:
    """Bytes of one point (the largest), seconds of all and the link's states of the
    multipliers at these frequencies; zeros where the loop has none."""
    link = loop.hysteresis
    if link is None or loop.sampled is not None or not loop.is_lti or frequencies_hz.size == 0:
        return 0.0, 0.0, 0
    m = int(link.n_states)
    if not m:
        try:
            st = link.time_stepping()
        except ValueError:
            return 0.0, 0.0, 0
        if st is None or not np.all(st.codes == STOP):
            return 0.0, 0.0, 0
        m = int(st.codes.size)
    n = int(loop.closed_loop_poles().size) + m
    # the harmonics of each point as default_harmonics gives them, for all points at once
    f_lim = 2.0 * float(np.max(np.abs(loop.closed_loop_poles()))) / TWO_PI
    H = np.clip(np.ceil(f_lim / frequencies_hz), MIN_HARMONICS, MAX_HARMONICS)
    steps = np.full(H.shape, float(samples)) if samples else np.maximum(8192.0, 16.0 * H)
    step_bytes = 9.0 * m if not link.n_states else 24.0 * float(H.max())  # stuck, onset / v(t)
    nbytes = float(steps.max()) * step_bytes + 8.0 * 8.0 * n * n
    per_step = SECONDS_PER_STEP + (0.0 if link.n_states else m * SECONDS_PER_ELEMENT_STEP)
    seconds = float(np.sum(steps)) * per_step + H.size * SECONDS_PER_STATE_CUBED * float(n) ** 3
    return nbytes, seconds, m


def check_floquet_budget(loop: Loop, frequencies_hz: ArrayLike, samples: int | None = None,
                         remedy: str = "give fewer frequencies or a link of fewer elements"
                         ) -> None:
    """Refuse the Floquet multipliers of `loop` at these frequencies above the memory or work
    budget (:mod:`motionhyst.core.budget`), before any is computed.

    The monodromy of a link of ``m`` stop elements has ``n + m`` states: its memory grows
    as their square, its eigenvalues' work as their cube, and its intervals' work as the
    steps of the period times ``m`` (nominal costs :data:`SECONDS_PER_STEP`,
    :data:`SECONDS_PER_STATE_CUBED`).

    Parameters
    ----------
    loop : Loop
        The loop.
    frequencies_hz : array_like
        The frequencies of its steady states [Hz].
    samples : int, optional
        Steps of the period, as :func:`steady_state_floquet` takes them.
    remedy : str
        What the user can change, for the message.

    Raises
    ------
    motionhyst.core.budget.BudgetError
        One line naming the size and `remedy`.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.core.budget import BudgetError, set_max_seconds
    >>> loop = default_scenario().loop()
    >>> check_floquet_budget(loop, [5.0, 10.0])          # seconds: within the default hour
    >>> set_max_seconds(60.0)
    >>> try:
    ...     check_floquet_budget(loop, np.linspace(1.0, 100.0, 100_000))
    ... except BudgetError as exc:
    ...     print(exc)
    the Floquet multipliers at 100000 frequencies would take about 4.6 h, above the work budget \
of 1 min (--max-seconds); give fewer frequencies or a link of fewer elements
    >>> set_max_seconds(None)
    """
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    nbytes, seconds, m = _floquet_size(loop, f, samples)
    if not m:
        return
    link = (f" of {m} stop elements" if not loop.hysteresis.n_states
            else f" of a link of {m} states") if m > 1 else ""
    check_memory(nbytes, f"the monodromy{link}", remedy)
    where = f"{f.size} frequencies" if f.size > 1 else f"{g(f[0])} Hz"
    check_work(seconds, f"the Floquet multipliers{link} at {where}", remedy)


def unresolved_time_scales(loop: Loop) -> str | None:
    """Why the monodromy of `loop` cannot be resolved, or None: its closed-loop poles span
    more than :data:`MAX_TIME_SCALE_RATIO` (a plant or gain off by orders of magnitude).

    Parameters
    ----------
    loop : Loop
        A continuous LTI loop.

    Returns
    -------
    str or None
        The reason, naming the poles.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> unresolved_time_scales(default_scenario().loop()) is None
    True
    """
    p = np.abs(loop.closed_loop_poles())
    p = p[p > 0]
    if p.size and p.max() > MAX_TIME_SCALE_RATIO * p.min():
        return (f"the loop's closed-loop poles span {g(p.min())} to {g(p.max())} rad/s, a ratio "
                f"above {MAX_TIME_SCALE_RATIO:.0e}: its monodromy is not resolved in double "
                f"precision (is a mass, stiffness or gain off by orders of magnitude?)")
    return None


def steady_state_floquet(loop: Loop, ss: SteadyState, samples: int | None = None
                         ) -> FloquetResult:
    """Floquet multipliers of the periodic steady state `ss` of `loop` (exact monodromy).

    Parameters
    ----------
    loop : Loop
        The loop `ss` belongs to: continuous, LTI, with a link made of stop elements
        (Jenkins, Maxwell-slip) or with a smooth state equation (LuGre, Dahl, Bouc-Wen).
    ss : SteadyState
        Its periodic steady state (:func:`~motionhyst.analysis.steady.periodic_steady_state`).
    samples : int, optional
        Steps of the period: stop elements' intervals are found on them, a smooth link's
        Jacobian is taken at their midpoints (default: 16 per harmonic kept, at least 8192).

    Returns
    -------
    FloquetResult

    Raises
    ------
    ValueError
        For a sampled controller, a measured plant, no link, a link of another kind (one
        along the stroke), or time scales the monodromy does not resolve
        (:func:`unresolved_time_scales`).
    motionhyst.core.budget.BudgetError
        Above the memory or work budget (:func:`check_floquet_budget`), before the work.

    Examples
    --------
    >>> from motionhyst import default_scenario, periodic_steady_state
    >>> loop = default_scenario().loop()
    >>> fl = steady_state_floquet(loop, periodic_steady_state(loop, 0.01, 5.0))
    >>> fl.to_dict()["stable"]
    True
    """
    link = loop.hysteresis
    if link is None:
        raise ValueError("the loop has no link")
    if loop.sampled is not None or not loop.is_lti:
        raise ValueError("Floquet multipliers need a continuous loop with a plant model")
    if isinstance(link, AlongStroke):
        raise ValueError("Floquet multipliers need the link's parameters fixed; a link along the "
                         "stroke ([hysteresis] along) changes them with the position")
    why = unresolved_time_scales(loop)
    if why:
        raise ValueError(f"Floquet multipliers not computed: {why}")
    check_floquet_budget(loop, [ss.frequency_hz], samples)
    sys = LoopStateEquation(loop)
    T = 1.0 / ss.frequency_hz
    h = _Harmonics(ss)
    n_samp = int(samples or max(8192, 16 * ss.n_harmonics))
    if link.n_states:
        return from_monodromy(_smooth_monodromy(sys, h, T, n_samp), T)
    try:
        st = link.time_stepping()
    except ValueError:
        st = None
    if st is None or not np.all(st.codes == STOP):
        raise ValueError(f"Floquet multipliers need stop elements or a smooth state "
                         f"equation; the {link.name} link has neither")
    k, fc = st.params[:, 0].copy(), st.params[:, 1].copy()
    sys.ns, sys.N = k.size, sys.n + k.size
    M, never = _stop_monodromy(sys, h, T, k, fc, n_samp)
    return from_monodromy(M, T, neutral=never)
