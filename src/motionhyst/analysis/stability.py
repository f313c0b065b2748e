"""Limit cycles of the loop with its link: predicted by the describing function, then exact.

The link sees the rest of the loop as one linear system from its force ``w`` to
its displacement ``y1`` (:mod:`motionhyst.controllers.loop`, the setpoint held at 0)::

    y1 = -G w,    G = P1 / (1 + C P2)        (= -T_{w->y1})

the controller with its integral action inside ``G`` (for a sampled controller
the response of the fundamental, :meth:`~motionhyst.controllers.loop.Loop.transfer`).  A
self-sustained oscillation ``y1 = A sin(omega t)`` balances its first harmonic
when ``1 + G(j omega) N(A, omega) = 0`` with ``N`` the link's describing function
(paper eq. 7): the Nyquist curve of ``G`` meets the locus ``-1/N(A, omega)`` at
the same frequency (one locus per amplitude over frequency for a rate-dependent
link; one locus over amplitude for a rate-independent one).  Each such point is a
*predicted* limit cycle.  Its stability by the describing function is Loeb's
criterion: writing ``F = 1 + G N = U + j V``, the cycle is stable when

    dU/dA dV/domega - dU/domega dV/dA > 0

(a growing amplitude moves the loop's root into the left half plane).

The prediction is then checked exactly.  For a continuous loop and a link with a
smooth state equation (:meth:`~motionhyst.hysteresis.Hysteresis.state_equation`,
LuGre, Dahl, Bouc-Wen) the autonomous loop ``x' = A x - B w``, ``z' = f(z, v1)``,
``w = h(z, v1)`` (``y1 = C x``, ``v1 = C A x``: the link acts through the
plant's inertia) is solved for its periodic orbit by shooting with the period
unknown and the phase condition ``y1(0) = 0`` (an upward crossing fixes the time
origin), the flow and its variations integrated together by a stiff solver
(Radau), so the monodromy matrix ``M = dx(T) / dx(0)`` comes with the orbit.
Its eigenvalues are the Floquet multipliers: one is 1 (a shift along the orbit),
the others say whether a deviation dies out (``|mu| < 1``: stable) or grows.
Every predicted cycle is refined so; so are the cycles a simulation from kicked
rest states runs into (the describing function of the link can miss a cycle:
friction that sticks moves far from a sinusoid).

For a controller with integral action a second describing function is taken with the
loop cut at the integrator (:mod:`motionhyst.analysis.integral_cut`): there the signal
of a hunting loop is nearly a sinusoid.  Its predictions are marked
``method = "integral-cut"`` (those of the link ``"link"``); each is refined from a run
that starts at rest at the bottom of the predicted cycle.  Each exact cycle is confirmed
by a simulation that starts beside it along its least stable direction and measures
the deviation one period later.

Examples
--------
The paper's Table I loop with the Jenkins link: ``G`` is far smaller than the
link's ``-1/N``, so no limit cycle is predicted.

>>> from motionhyst import default_scenario
>>> res = stability(default_scenario().loop())
>>> res.to_dict()
{'predicted': [], 'exact': []}
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.analysis.floquet import LoopStateEquation, from_monodromy
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI
from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis import Hysteresis

__all__ = ["ExactCycle", "PredictedCycle", "StabilityResult", "intersections",
           "link_loop_response", "stability"]

#: Grid of the search for intersections: points per decade of amplitude and frequency for a
#: rate-dependent link (each point a periodic solution of the link), and for a
#: rate-independent one (a closed form).
GRID_RATE_DEPENDENT = (4, 8)
GRID_RATE_INDEPENDENT = (12, 40)

#: Points of the Nyquist curve drawn.
NYQUIST_POINTS = 2000

#: Relative and absolute (per state scale) tolerances of the orbit's integration.
RTOL = 1e-10

#: The orbit is closed when ``|x(T) - x(0)|`` is below this fraction of each state's scale.
CLOSURE = 1e-8

#: Length of the run from a kick to a cycle the cut at the integrator predicts, in its
#: predicted periods (a stick-slip cycle attracts within a few).
CUT_SETTLE_PERIODS = 8.0

#: Length of the search's simulations, in periods of the slowest closed-loop pole.
SEARCH_SLOW_PERIODS = 60.0


def link_loop_response(loop: Loop, omega: ArrayLike) -> NDArray[np.complex128]:
    """``G(j omega) = P1 / (1 + C P2)``: the loop seen by the link, force in, displacement out.

    ``y1 = -G w`` with the setpoint at 0 (:meth:`Loop.transfer` ``"w->y1"``, negated).

    Parameters
    ----------
    loop : Loop
        The loop.
    omega : array_like
        Angular frequencies [rad/s].

    Returns
    -------
    ndarray of complex

    Examples
    --------
    >>> import control
    >>> from motionhyst import Loop
    >>> from motionhyst.plants import MassDamper
    >>> loop = Loop(MassDamper(m=1.0, c=0.0), control.tf([6.0, 3.0, 4.0], [1.0, 0.0]),
    ...             feedforward=None)                  # PID (a pure derivative) around a mass
    >>> G = link_loop_response(loop, [2.0])             # s / (s^3 + 6 s^2 + 3 s + 4) at 2 rad/s
    >>> print(f"{complex(G[0]):.4f}")
    -0.0099-0.0990j
    """
    return -np.asarray(loop.transfer("w->y1", np.asarray(omega, dtype=float)))


# ------------------------------------------------------------------ results
@dataclass
class PredictedCycle:
    """A limit cycle a describing function predicts.

    Attributes
    ----------
    amplitude : float
        Amplitude of the link's displacement [m]: ``A`` of ``y1 = A sin(omega t)`` for
        the link's describing function, the first harmonic of ``y1`` for the cut at the
        integrator.
    frequency_hz : float
        Its frequency [Hz].
    stable : bool
        Loeb's criterion (module docstring).
    loeb : float
        ``(dU/dA dV/domega - dU/domega dV/dA) A omega``, dimensionless; > 0: stable.
    method : str
        ``"link"``: ``1 + G N = 0`` with ``N`` the link's describing function;
        ``"integral-cut"``: ``1 + (ki / s) N = 0`` with ``N`` that of the stage with its
        link and the rest of the controller, driven by the integral action's force
        (:mod:`motionhyst.analysis.integral_cut`).
    peak_to_peak : float or None
        The predicted peak-to-peak of ``y1`` [m]; None: ``2 A`` (a sinusoid).
    force_amplitude : float or None
        Amplitude of the integral action's force [N] (``"integral-cut"`` only).
    waveform : tuple of ndarray or None
        ``(t, y1)``: one period of the predicted displacement of the link
        (``"integral-cut"`` only; for ``"link"`` a sinusoid).

    Examples
    --------
    >>> d = PredictedCycle(1e-3, 2.0, True, 0.5).to_dict()
    >>> d["amplitude"], d["frequency_hz"], d["stable"], d["method"], d["peak_to_peak"]
    (0.001, 2.0, True, 'link', 0.002)
    """

    amplitude: float
    frequency_hz: float
    stable: bool
    loeb: float
    method: str = "link"
    peak_to_peak: float | None = None
    force_amplitude: float | None = None
    waveform: tuple[NDArray[np.float64], NDArray[np.float64]] | None = field(default=None,
                                                                              repr=False)

    def __post_init__(self) -> None:
        if self.peak_to_peak is None:
            self.peak_to_peak = 2.0 * self.amplitude

    def to_dict(self) -> dict:
        """JSON-ready dictionary (one entry of ``predicted`` in ``stability --json``)."""
        return {"amplitude": float(self.amplitude), "frequency_hz": float(self.frequency_hz),
                "stable": bool(self.stable), "method": self.method,
                "peak_to_peak": float(self.peak_to_peak)}


@dataclass
class ExactCycle:
    """An exact periodic orbit of the autonomous loop and its Floquet multipliers.

    Attributes
    ----------
    period_s : float
        Period ``T`` [s].
    peak_to_peak : float
        Peak-to-peak of the link's displacement ``y1`` over the orbit [m].
    multipliers : ndarray of complex
        The Floquet multipliers but the trivial one (eigenvalues of the monodromy).
    floquet_max : float
        Largest ``|mu|`` of them.
    stable : bool
        ``floquet_max < 1``.
    found_by : str
        ``"prediction"`` (refined from a predicted cycle) or ``"simulation"``.
    predicted : PredictedCycle or None
        The prediction it was refined from (None if found by simulation).
    simulated_ratio : float
        Deviation one period after a start beside the orbit along its least stable
        direction, over the deviation at the start (the simulation's ``|mu|``).
    t, y1 : ndarray
        One period of the link's displacement from the upward crossing of ``y1 = 0``.

    Examples
    --------
    >>> import numpy as np
    >>> c = ExactCycle(2.0, 0.1, np.array([0.5 + 0j]), 0.5, True, "simulation", None, 0.5,
    ...                np.zeros(1), np.zeros(1))
    >>> c.to_dict()
    {'period_s': 2.0, 'peak_to_peak': 0.1, 'floquet_max': 0.5, 'stable': True}
    """

    period_s: float
    peak_to_peak: float
    multipliers: NDArray[np.complex128]
    floquet_max: float
    stable: bool
    found_by: str
    predicted: PredictedCycle | None
    simulated_ratio: float
    t: NDArray[np.float64] = field(repr=False)
    y1: NDArray[np.float64] = field(repr=False)

    @property
    def confirmed(self) -> bool:
        """True if the simulated deviation shrank (stable) or grew (unstable) as predicted."""
        return bool((self.simulated_ratio < 1.0) == self.stable)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (one entry of ``exact`` in ``stability --json``)."""
        return {"period_s": float(self.period_s), "peak_to_peak": float(self.peak_to_peak),
                "floquet_max": float(self.floquet_max), "stable": bool(self.stable)}


@dataclass
class StabilityResult:
    """Result of :func:`stability`: the loop seen by the link, the loci, the cycles.

    Attributes
    ----------
    link : Hysteresis or None
        The loop's link.
    omega : ndarray
        Frequencies of the Nyquist curve [rad/s] (finely spaced).
    nyquist : ndarray of complex
        ``G(j omega)`` (:func:`link_loop_response`).
    locus_omega : ndarray
        Frequencies of the loci [rad/s] (the search's grid).
    amplitudes : ndarray
        Amplitudes of the loci [m].
    loci : ndarray of complex, shape (amplitudes, locus_omega)
        ``-1 / N(A, omega)``; for a rate-independent link every column is the same.
    predicted : list of PredictedCycle
        Intersections, by amplitude.
    exact : list of ExactCycle
        Exact orbits, by amplitude.
    notes : list of str
        What was not done and why (one line each).

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> res = stability(default_scenario().loop())
    >>> print(str(res).splitlines()[0])
    Limit cycles of the loop with the jenkins link (y1 = -G w, G = P1 / (1 + C P2))
    """

    link: Hysteresis | None
    omega: NDArray[np.float64]
    nyquist: NDArray[np.complex128]
    locus_omega: NDArray[np.float64]
    amplitudes: NDArray[np.float64]
    loci: NDArray[np.complex128]
    predicted: list[PredictedCycle] = field(default_factory=list)
    exact: list[ExactCycle] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``stability --json`` schema): ``predicted`` and
        ``exact``; amplitudes and peak-to-peak of the link's displacement."""
        return {"predicted": [p.to_dict() for p in self.predicted],
                "exact": [c.to_dict() for c in self.exact]}

    def __str__(self) -> str:
        name = "no" if self.link is None else f"the {self.link.name}"
        lines = [f"Limit cycles of the loop with {name} link (y1 = -G w, G = P1 / (1 + C P2))"]
        if self.predicted:
            rows = [[p.method, g(p.amplitude), g(p.peak_to_peak), g(p.frequency_hz),
                     g(1.0 / p.frequency_hz), "stable" if p.stable else "unstable", g(p.loeb)]
                    for p in self.predicted]
            lines += ["Predicted by describing functions (link: 1 + G N = 0; integral-cut: "
                      "1 + (ki/s) N = 0):",
                      table(["method", "A [m]", "y1 p-p [m]", "f [Hz]", "T [s]",
                             "DF criterion", "Loeb [-]"], rows)]
        else:
            lines.append("Predicted by describing functions: none (the Nyquist curve of G "
                         "does not meet -1/N, nor the cut at the integrator balances)")
        if self.exact:
            rows = [[g(c.period_s), g(c.peak_to_peak), g(c.floquet_max),
                     "stable" if c.stable else "unstable", g(c.simulated_ratio),
                     "yes" if c.confirmed else "NO", c.found_by] for c in self.exact]
            lines += ["Exact periodic orbits (Floquet multipliers from the monodromy):",
                      table(["T [s]", "y1 peak-to-peak [m]", "max |mu|", "", "simulated",
                             "confirmed", "found by"], rows)]
            for c in self.exact:
                if c.predicted is not None:
                    p = c.predicted
                    lines.append(
                        f"  DF error ({p.method}): period {_rel(1.0 / p.frequency_hz, c.period_s)}"
                        f", peak-to-peak {_rel(p.peak_to_peak, c.peak_to_peak)} "
                        f"(T = {g(c.period_s)} s)")
        else:
            lines.append("Exact periodic orbits: none found")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def plot(self, ax=None):
        """The Nyquist curve of ``G`` with the loci ``-1/N(A, omega)`` and the predicted
        cycles; below it, when there are cycles with a waveform, one period of the link's
        displacement of each (:func:`motionhyst.analysis.figures.plot_stability`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or sequence of two Axes, optional
            Axes to draw into (one: the Nyquist curve only); default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_stability

        return plot_stability(self, ax=ax)


def _rel(pred: float, exact: float) -> str:
    return f"{100.0 * (pred - exact) / exact:+.1f} %"


# ------------------------------------------------------------------ prediction
def _grid(loop: Loop, link: Hysteresis, amplitudes, frequencies_hz):
    """Frequencies [rad/s] and amplitudes [m] of the search."""
    per_a, per_w = GRID_RATE_INDEPENDENT if link.rate_independent else GRID_RATE_DEPENDENT
    if frequencies_hz is not None:
        omega = TWO_PI * np.asarray(frequencies_hz, dtype=float)
    else:
        if loop.sampled is not None:
            hi = 0.999 * TWO_PI * loop.sampled.nyquist_hz
            p = np.abs(loop.closed_loop_poles())
            p = p[np.isfinite(p) & (p > 0)]
            lo = (np.min(p) if p.size else hi * 1e-4) / 30.0
        else:
            p = np.abs(loop.closed_loop_poles())
            p = p[p > 0]
            lo, hi = np.min(p) / 30.0, np.max(p) * 3.0
        n = max(8, math.ceil(per_w * math.log10(hi / lo)))
        omega = np.geomspace(lo, hi, n)
    if amplitudes is not None:
        A = np.asarray(amplitudes, dtype=float)
    else:
        scale = link.time_stepping().scale if _steps(link) else 1.0
        a_ref = scale / link.initial_stiffness
        A = np.geomspace(a_ref * 1e-2, a_ref * 1e6, 8 * per_a + 1)
    if omega.ndim != 1 or omega.size < 2 or not np.all(np.isfinite(omega) & (omega > 0)):
        raise ValueError("frequencies must be at least two finite values > 0 [Hz]")
    if A.ndim != 1 or A.size < 2 or not np.all(np.isfinite(A) & (A > 0)):
        raise ValueError("amplitudes must be at least two finite values > 0 [m]")
    return np.sort(omega), np.sort(A)


def _steps(link: Hysteresis) -> bool:
    try:
        link.time_stepping()
    except ValueError:
        return False
    return True


def _df(link: Hysteresis, A: NDArray, omega: NDArray) -> NDArray[np.complex128]:
    """``N(A, omega)``, shape ``(A.size, omega.size)``."""
    if link.rate_independent:
        d = np.asarray(link.describing_function(A), dtype=complex).reshape(A.size, 1)
        return np.repeat(d, omega.size, axis=1)
    return np.stack([np.asarray(link.describing_function(A, w), dtype=complex).reshape(A.size)
                     for w in omega], axis=1)


def _winding(F: NDArray[np.complex128]) -> NDArray[np.int64]:
    """Winding number of ``F`` around 0 along each grid cell's boundary."""
    def step(a, b):
        return np.angle(b / a)

    a, b, c, d = F[:-1, :-1], F[1:, :-1], F[1:, 1:], F[:-1, 1:]
    total = step(a, b) + step(b, c) + step(c, d) + step(d, a)
    return np.rint(total / TWO_PI).astype(np.int64)


def intersections(response, link: Hysteresis, amplitudes: ArrayLike, omega: ArrayLike
                  ) -> list[PredictedCycle]:
    """Where ``1 + G(j omega) N(A, omega) = 0``: the describing function's limit cycles.

    Cells of the amplitude-frequency grid around which ``1 + G N`` winds once, each
    refined by Newton's method in ``(log A, log omega)``; stable or not by Loeb's criterion
    (module docstring).  What :func:`stability` predicts with, for any linear part.

    Parameters
    ----------
    response : python-control LTI system or callable
        ``G``: a system (its frequency response is taken), or a function of an array of
        angular frequencies [rad/s] returning ``G(j omega)``.
    link : Hysteresis
        The nonlinearity ``N`` (its :meth:`~motionhyst.hysteresis.Hysteresis.describing_function`).
    amplitudes : array_like
        Amplitudes of the grid [m], increasing.
    omega : array_like
        Angular frequencies of the grid [rad/s], increasing.

    Returns
    -------
    list of PredictedCycle
        By amplitude.

    Examples
    --------
    A Jenkins link in a loop with a third-order lag: one intersection, as python-control's
    :func:`control.describing_function_response` finds with the same link; stable: the
    loop with the link stuck is unstable, without it stable, so the oscillation grows to
    it from below and shrinks to it from above.

    >>> import numpy as np
    >>> import control
    >>> from motionhyst import Jenkins
    >>> H = control.tf([-2.0], [1.0, 3.0, 3.0, 1.0])            # -2 / (s + 1)^3
    >>> link = Jenkins(k=1.0, fc=0.1)
    >>> [c] = intersections(H, link, np.geomspace(0.1, 100, 50), np.geomspace(0.01, 10, 60))
    >>> print(f"A = {c.amplitude:.3f} m at {c.frequency_hz:.4f} Hz, stable: {c.stable}")
    A = 0.224 m at 0.0339 Hz, stable: True
    """
    from motionhyst.core.lti import freqresp

    A = np.asarray(amplitudes, dtype=float)
    w = np.asarray(omega, dtype=float)
    if hasattr(response, "poles"):
        sys = response
        response = lambda om: freqresp(sys, om)  # noqa: E731
    return _predict(response, link, A, w, _df(link, A, w), np.asarray(response(w)))


def _predict(response, link: Hysteresis, A: NDArray, omega: NDArray,
             N: NDArray[np.complex128], G: NDArray[np.complex128]) -> list[PredictedCycle]:
    """:func:`intersections` with ``N`` and ``G`` on the grid already computed."""
    from scipy.optimize import root

    F = 1.0 + G[None, :] * N
    cells = np.argwhere(_winding(F) != 0)

    def residual(p):
        a, w = math.exp(p[0]), math.exp(p[1])
        n = complex(np.ravel(link.describing_function(a, None if link.rate_independent
                                                       else w))[0])
        f = 1.0 + complex(np.ravel(response(np.array([w])))[0]) * n
        return np.array([f.real, f.imag])

    found: list[PredictedCycle] = []
    for i, j in cells:
        p0 = np.array([0.5 * (math.log(A[i]) + math.log(A[i + 1])),
                       0.5 * (math.log(omega[j]) + math.log(omega[j + 1]))])
        sol = root(residual, p0, method="hybr", options={"xtol": 1e-12})
        if not sol.success or np.max(np.abs(residual(sol.x))) > 1e-8:
            continue
        a, w = math.exp(sol.x[0]), math.exp(sol.x[1])
        if any(abs(a / c.amplitude - 1) < 1e-6 and abs(w / (TWO_PI * c.frequency_hz) - 1) < 1e-6
               for c in found):
            continue
        # Loeb's criterion in (log A, log omega): the same sign, dimensionless
        hA, hw = np.array([1e-5, 0.0]), np.array([0.0, 1e-5])
        dA = (residual(sol.x + hA) - residual(sol.x - hA)) / 2e-5
        dw = (residual(sol.x + hw) - residual(sol.x - hw)) / 2e-5
        loeb = float(dA[0] * dw[1] - dw[0] * dA[1])
        found.append(PredictedCycle(a, w / TWO_PI, loeb > 0.0, loeb))
    return sorted(found, key=lambda c: c.amplitude)


# ------------------------------------------------------------------ the autonomous loop
class _Autonomous(LoopStateEquation):
    """The loop with the setpoint at 0 as one state equation, with its flow and shooting."""

    def rhs_var(self, t, Y):
        N = self.N
        X = Y[:N]
        J = self.jac(t, X)
        return np.concatenate([self.rhs(t, X), (J @ Y[N:].reshape(N, N)).ravel()])

    def jac_var(self, t, Y):
        N = self.N
        J = self.jac(t, Y[:N])
        out = np.zeros((N + N * N, N + N * N))
        out[:N, :N] = J
        out[N:, N:] = np.kron(J, np.eye(N))
        return out

    def atol(self, scale: NDArray) -> NDArray:
        return RTOL * np.maximum(np.abs(scale), 1e-300)

    def flow(self, X0: NDArray, T: float, scale: NDArray, monodromy: bool = True):
        """``X(T)`` and the monodromy ``dX(T) / dX(0)`` (None without `monodromy`)."""
        from scipy.integrate import solve_ivp

        N = self.N
        if monodromy:
            Y0 = np.concatenate([X0, np.eye(N).ravel()])
            atol = np.concatenate([self.atol(scale), np.full(N * N, RTOL)])
            sol = solve_ivp(self.rhs_var, (0.0, T), Y0, method="LSODA", jac=self.jac_var,
                            rtol=RTOL, atol=atol)
        else:
            sol = solve_ivp(self.rhs, (0.0, T), X0, method="LSODA", jac=self.jac,
                            rtol=RTOL, atol=self.atol(scale))
        if not sol.success:
            raise RuntimeError(f"the loop's orbit could not be integrated: {sol.message}")
        Y = sol.y[:, -1]
        return Y[:N], (Y[N:].reshape(N, N) if monodromy else None)

    def run(self, X0: NDArray, t_end: float, scale: NDArray, rtol: float = 1e-8,
            method: str = "Radau", **kw):
        """A simulation from `X0`, with its dense output and, as ``t_events[0]`` and
        ``y_events[0]``, its upward crossings of ``y1 = 0``.

        The crossings are bracketed by the steps' own values and located on the solver's
        interpolant (scipy's event search can stop with an error when LSODA's interpolant
        and its steps disagree on a sign); where the interpolant does not bracket one, it
        is placed by linear interpolation between the steps.
        """
        from scipy.integrate import solve_ivp
        from scipy.optimize import brentq

        kw.pop("dense_output", None)
        sol = solve_ivp(self.rhs, (0.0, t_end), X0, method=method, jac=self.jac, rtol=rtol,
                        atol=rtol * 1e-2 * np.maximum(np.abs(scale), 1e-300),
                        dense_output=True, **kw)
        C, n = self.C, self.n

        def y1(t):
            return float(C @ sol.sol(t)[:n])

        y = C @ sol.y[:n]
        te = []
        for i in np.nonzero((y[:-1] < 0.0) & (y[1:] >= 0.0))[0]:
            a, b = float(sol.t[i]), float(sol.t[i + 1])
            if y1(a) < 0.0 <= y1(b):
                te.append(a if y1(a) == 0.0 else brentq(y1, a, b, xtol=1e-15, rtol=1e-15))
            else:
                te.append(a + (b - a) * float(-y[i] / (y[i + 1] - y[i])))
        sol.t_events = [np.array(te)]
        sol.y_events = [np.array([sol.sol(t) for t in te]).reshape(len(te), sol.y.shape[0])]
        return sol

    def shoot(self, X0: NDArray, T: float, scale: NDArray, max_iter: int = 12):
        """Newton on ``X(T) = X0``, ``y1(0) = 0``; returns ``X0, T, M``.

        Converged when the orbit closes to :data:`CLOSURE` of each state's scale (the
        integration's own accuracy is about ``1e-9`` of it).
        """
        N = self.N
        e = np.concatenate([self.C, np.zeros(self.ns)])
        X0 = X0 - e * (e @ X0) / (e @ e)            # onto the section y1 = 0
        sc = scale_col(scale, T)
        for _ in range(max_iter):
            XT, M = self.flow(X0, T, scale)
            r = np.concatenate([XT - X0, [e @ X0]])
            if np.max(np.abs(r[:N]) / scale) < CLOSURE:
                return X0, T, M
            J = np.zeros((N + 1, N + 1))
            J[:N, :N] = M - np.eye(N)
            J[:N, N] = self.rhs(T, XT)
            J[N, :N] = e
            try:
                d = np.linalg.solve(J * sc[None, :], -r) * sc
            except np.linalg.LinAlgError:
                raise RuntimeError("the shooting's Jacobian is singular") from None
            step = 1.0
            while T + step * d[N] <= 0.2 * T:
                step *= 0.5
            X0 = X0 + step * d[:N]
            T = T + step * d[N]
        raise RuntimeError("the shooting for the periodic orbit did not converge")


def scale_col(scale: NDArray, T: float) -> NDArray:
    """Column scaling of the shooting's unknowns (states, then the period)."""
    return np.concatenate([scale, [T]])


def _guess_from_prediction(sys: _Autonomous, p: PredictedCycle):
    """A state on ``y1 = A sin(omega t)`` at ``t = 0`` with the link's periodic state."""
    from scipy.integrate import solve_ivp

    w = TWO_PI * p.frequency_hz
    link = sys.link
    n = complex(np.ravel(link.describing_function(p.amplitude, None if link.rate_independent
                                                   else w))[0])
    Y1 = p.amplitude / 2j                                        # rfft scaling of A sin
    Xx = np.linalg.solve(1j * w * np.eye(sys.n) - sys.A, -sys.B * (n * Y1))
    x0 = 2.0 * Xx.real
    # the link's state on the sinusoid: run it three periods, keep the end (t = 0 mod T)

    def f(t, z):
        return link.state_equation(z, p.amplitude * w * math.cos(w * t))[0]

    z = solve_ivp(f, (0.0, 3 * TWO_PI / w), np.zeros(sys.ns), method="Radau", rtol=1e-8,
                  atol=1e-14).y[:, -1]
    return np.concatenate([x0, z]), TWO_PI / w


def _scale(sys: _Autonomous, X: NDArray) -> NDArray:
    """A magnitude per state, for tolerances (from a state on or near the orbit)."""
    s = np.abs(X).copy()
    s[:sys.n] = np.maximum(s[:sys.n], 1e-3 * np.max(s[:sys.n]))
    return np.maximum(s, 1e-300)


def _orbit_scale(sys: _Autonomous, X0: NDArray, T: float, scale: NDArray) -> NDArray:
    sol = sys.run(X0, T, scale, method="LSODA")
    s = np.max(np.abs(sol.y), axis=1)
    return _scale(sys, s)


def _exact(sys: _Autonomous, X0, T, found_by, predicted) -> ExactCycle:
    scale = _orbit_scale(sys, X0, T, _scale(sys, X0))
    X0, T, M = sys.shoot(X0, T, scale)
    scale = _orbit_scale(sys, X0, T, scale)
    mu, vec = np.linalg.eig(M)
    keep = np.arange(mu.size) != int(np.argmin(np.abs(mu - 1.0)))
    order = np.argsort(-np.abs(mu[keep]))
    floquet = from_monodromy(M, T, autonomous=True)
    rest, fmax = floquet.multipliers, floquet.floquet_max
    # one period of the orbit, finely, for its peak-to-peak and the figure
    sol = sys.run(X0, T, scale, rtol=RTOL, method="LSODA", dense_output=True)
    t = np.linspace(0.0, T, 20001)
    y1 = sys.C @ sol.sol(t)[:sys.n]
    p2p = _peak_to_peak(sys, sol, t, y1)
    # the simulation beside it: along the least stable direction, projected onto y1 = 0
    v = np.real(vec[:, np.arange(mu.size)[keep][order[0]]]) if rest.size else np.zeros(sys.N)
    e = np.concatenate([sys.C, np.zeros(sys.ns)])
    f0 = sys.rhs(0.0, X0)
    v = v - f0 * (e @ v) / (e @ f0)
    norm = np.max(np.abs(v) / scale)
    ratio = float("nan")
    if norm > 0:
        eps = 1e-4 / norm                 # small enough to be linear, large against the
        # integration error (1e-10 of the scale): the ratio is good to about 1e-6
        d0 = eps * v
        sim = sys.run(X0 + d0, 1.5 * T, scale, rtol=RTOL, method="LSODA")
        te, ye = sim.t_events[0], sim.y_events[0]
        k = np.nonzero(te > 0.5 * T)[0]
        if k.size:
            d1 = ye[k[0]] - X0
            ratio = float(np.max(np.abs(d1) / scale) / np.max(np.abs(d0) / scale))
    return ExactCycle(float(T), p2p, rest, fmax, fmax < 1.0, found_by, predicted, ratio, t, y1)


def _peak_to_peak(sys: _Autonomous, sol, t, y1) -> float:
    """Peak-to-peak of ``y1``: its extremes refined where ``y1' = C A x`` vanishes."""
    from scipy.optimize import brentq

    v = sys.CA @ sol.sol(t)[:sys.n]
    ext = [y1.max(), y1.min()]
    for i in (int(np.argmax(y1)), int(np.argmin(y1))):
        lo, hi = max(i - 1, 0), min(i + 1, t.size - 1)
        if v[lo] * v[hi] < 0:
            tc = brentq(lambda s: float(sys.CA @ sol.sol(s)[:sys.n]), t[lo], t[hi], xtol=1e-14)
            y = float(sys.C @ sol.sol(tc)[:sys.n])
            ext.append(y)
    return float(max(ext) - min(ext))


def _search(sys: _Autonomous, loop: Loop, A: NDArray):
    """Simulations from kicked rest states: the cycles they settle on (state, period)."""
    p = np.abs(loop.closed_loop_poles())
    p = p[p > 0]
    t_slow = TWO_PI / np.min(p)
    w_mid = float(np.sqrt(np.min(p) * np.max(p)))
    cab = float(sys.CA @ sys.B)                     # the velocity per unit kick of the force
    out: list[tuple[NDArray, float]] = []
    # velocity kicks that would carry the link's displacement across the loci's amplitudes
    for a in (A[len(A) // 2], A[(3 * len(A)) // 4], A[-1]):
        X0 = np.zeros(sys.N)
        X0[:sys.n] = sys.B * (a * w_mid / cab)
        scale = np.empty(sys.N)
        scale[:sys.n] = np.abs(X0[:sys.n]) + 1e-3 * np.max(np.abs(X0[:sys.n]))
        scale[sys.n:] = a * 1e-3
        sim = sys.run(X0, SEARCH_SLOW_PERIODS * t_slow, scale, rtol=1e-8, method="LSODA")
        te, ye = sim.t_events[0], sim.y_events[0]
        if te.size < 4:
            continue
        mag = np.maximum(np.max(np.abs(ye[-3:]), axis=0), 1e-300)
        d = np.max(np.abs(ye[-1] - ye[-2]) / np.max(mag))
        periods = np.diff(te[-3:])
        if d < 1e-4 and abs(periods[1] / periods[0] - 1) < 1e-4:
            if not any(abs(T / periods[1] - 1) < 1e-3 and np.max(np.abs(X - ye[-1])) < 1e-3
                       * np.max(mag) for X, T in out):
                out.append((ye[-1].copy(), float(periods[1])))
    return out


def _cut_predictions(loop: Loop, notes: list[str]) -> list[PredictedCycle]:
    """The cycles of the describing function with the loop cut at its integrator."""
    from motionhyst.analysis.integral_cut import IntegralCut

    try:
        cut = IntegralCut(loop)
    except ValueError as exc:
        notes.append(f"the cut at the integrator does not apply: {exc}")
        return []
    return [PredictedCycle(c.response.amplitude, c.response.frequency_hz, c.stable, c.loeb,
                           "integral-cut", c.response.peak_to_peak, c.response.force_amplitude,
                           (c.response.t, c.response.y1))
            for c in cut.cycles()]


def _guess_from_cut(sys: _Autonomous, p: PredictedCycle):
    """A state on the cycle the cut predicts: the loop at rest with the link's displacement
    at the bottom of the predicted cycle, the link unloaded, run until it settles."""
    obs = np.array([sys.C @ np.linalg.matrix_power(sys.A, k) for k in range(sys.n)])
    X0 = np.zeros(sys.N)
    X0[:sys.n] = np.linalg.solve(obs, np.eye(sys.n)[0] * (-0.5 * p.peak_to_peak))
    scale = np.empty(sys.N)
    scale[:sys.n] = np.abs(X0[:sys.n]) + 1e-3 * np.max(np.abs(X0[:sys.n]))
    scale[sys.n:] = p.amplitude * 1e-3
    sim = sys.run(X0, CUT_SETTLE_PERIODS / p.frequency_hz, scale, rtol=1e-8, method="LSODA")
    te, ye = sim.t_events[0], sim.y_events[0]
    if te.size < 3:
        raise RuntimeError("a run from rest at its amplitude does not oscillate")
    return ye[-1].copy(), float(te[-1] - te[-2])


def stability(loop: Loop, amplitudes: ArrayLike | None = None,
              frequencies_hz: ArrayLike | None = None, exact: bool = True,
              search: bool = True, integral_cut: bool = True) -> StabilityResult:
    """Limit cycles of the loop with its link: predicted, refined to exact orbits, confirmed.

    Parameters
    ----------
    loop : Loop
        The loop with its link (the setpoint is held at 0; the scenario's reference
        plays no part).
    amplitudes : array_like, optional
        Amplitudes of the link's displacement [m] of the loci; by default 8 decades
        from 1e-2 times the link's slip displacement (force scale over initial stiffness).
    frequencies_hz : array_like, optional
        Frequencies [Hz] of the Nyquist curve and the loci; by default from 1/30 of the
        slowest to 3 times the fastest closed-loop pole.
    exact : bool
        Refine each predicted cycle to the exact orbit with its Floquet multipliers
        (continuous loops with a link that has a smooth state equation).
    search : bool
        Also simulate from kicked rest states and refine the cycles they settle on.
    integral_cut : bool
        Also predict by the describing function with the loop cut at the controller's
        integrator (:mod:`motionhyst.analysis.integral_cut`; a continuous controller with
        integral action and a link with a smooth state equation).

    Returns
    -------
    StabilityResult

    Raises
    ------
    ValueError
        For a loop without a link, or a measured plant without a model.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> res = stability(default_scenario().loop())
    >>> len(res.predicted), res.loci.shape[0] == res.amplitudes.size
    (0, True)
    >>> bool(abs(res.nyquist).max() < 1e-3 * abs(res.loci).min())   # G far inside -1/N
    True
    """
    link = loop.hysteresis
    if link is None:
        raise ValueError("the loop has no link: nothing can sustain a limit cycle")
    if not loop.is_lti:
        raise ValueError("the stability analysis needs a plant model; fit the measured data "
                         '([plant] use = "fit")')
    omega, A = _grid(loop, link, amplitudes, frequencies_hz)
    G = link_loop_response(loop, omega)
    N = _df(link, A, omega)
    with np.errstate(divide="ignore", invalid="ignore"):
        loci = -1.0 / N
    fine = np.geomspace(omega[0], omega[-1], NYQUIST_POINTS)
    res = StabilityResult(link, fine, link_loop_response(loop, fine), omega, A, loci)
    res.predicted = _predict(lambda w: link_loop_response(loop, w), link, A, omega, N, G)
    if integral_cut:
        res.predicted = sorted(res.predicted + _cut_predictions(loop, res.notes),
                               key=lambda c: c.amplitude)
    if not exact:
        return res
    if loop.sampled is not None:
        res.notes.append("exact orbits of a sampled loop are not computed (the hybrid loop "
                         "has no smooth state equation)")
        return res
    if link.n_states == 0:
        res.notes.append(f"exact orbits need a link with a smooth state equation; the "
                         f"{link.name} link switches between sticking and slipping")
        return res
    try:
        sys = _Autonomous(loop)
    except ValueError as exc:
        res.notes.append(f"exact orbits not computed: {exc}")
        return res
    candidates = []
    for p in res.predicted:
        if p.method == "link":
            X0, T = _guess_from_prediction(sys, p)
        else:
            try:
                X0, T = _guess_from_cut(sys, p)
            except RuntimeError as exc:
                res.notes.append(f"the cycle the cut predicts at {g(p.frequency_hz)} Hz was "
                                 f"not refined: {exc}")
                continue
        candidates.append((X0, T, "prediction", p))
    if search:
        candidates += [(X0, T, "simulation", None) for X0, T in _search(sys, loop, A)]
    for X0, T, how, p in candidates:
        try:
            c = _exact(sys, X0, T, how, p)
        except RuntimeError as exc:
            if p is not None:
                res.notes.append(f"the cycle predicted at A = {g(p.amplitude)} m, "
                                 f"{g(p.frequency_hz)} Hz was not refined: {exc}")
            continue
        same = [e for e in res.exact if abs(e.period_s / c.period_s - 1) < 1e-6
                and abs(e.peak_to_peak / c.peak_to_peak - 1) < 1e-6]
        if same:
            if same[0].predicted is None and p is not None:
                same[0].predicted, same[0].found_by = p, "prediction"
            continue
        res.exact.append(c)
    res.exact.sort(key=lambda c: c.peak_to_peak)
    return res
