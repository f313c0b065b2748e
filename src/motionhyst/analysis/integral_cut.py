"""Hunting predicted by the describing function of the loop cut at the controller's integrator.

The describing function of the link alone (:mod:`motionhyst.analysis.stability`) drives
the link with a sinusoidal displacement; in hunting the link's displacement is far from a
sinusoid: the stage sticks for most of the period and jumps.  The signal of the hunting
loop that *is* nearly sinusoidal is the integral action's force: the integral of a
stuck-and-jumping position is a ramp up and a ramp down, a triangle whose third harmonic
is 1/9 of its first.  The classical harmonic balance is therefore taken with the loop cut
there (the "describing function of the plant with its friction", as Olsson and Astrom and
Armstrong-Helouvry call combining part of the loop with the friction).  The controller is
split into its integral action and the rest,

    C(s) = ki / s + C0(s),    ki = lim_{s -> 0} s C(s),

and the loop into the linear part ``L(s) = ki / s`` and a nonlinear block: the stage with
its link, closed by ``C0`` (the proportional and derivative action), driven by the
integral action's force ``u_I``.  With ``u_I = -U cos(omega t)`` the block's periodic
response is computed exactly (the stage's, the link's and ``C0``'s state equation, the
half-wave symmetric periodic solution ``X(T/2) = -X(0)`` by shooting), and its
describing function is the first harmonic of the measured position over that of the
force, ``N(U, omega) = Y2 / U_I``.  A limit cycle balances the first harmonic where

    1 + L(j omega) N(U, omega) = 0,

solved by Newton's method in ``(log U, log omega)``; stable or not by Loeb's criterion
as for the link's describing function.  The block's response at the solution is the
prediction: its frequency, and the peak-to-peak and first harmonic of the link's
displacement ``y1`` (not a sinusoid: the describing function assumes only the *force*
to be one).

Assumptions: a continuous loop whose controller has a simple integrator (a pole at
``s = 0``), a link with a smooth state equation
(:meth:`~motionhyst.hysteresis.Hysteresis.state_equation`, LuGre), the force of the
integral action close to a sinusoid (it is a triangle when the stage sticks), a
half-wave symmetric cycle (no bias: the setpoint at 0, the link symmetric).  The
search starts at the link's break-away force (its force scale) and at the frequency
where ``|L N| = 1`` there; a cycle far from it may be missed.

Examples
--------
The Olsson-Astrom hunting loop: a 1 kg mass with LuGre friction (``fs = 1.5``,
``fc = 1``), ``C = 3 + 4 / s + 6 s``.

>>> import math, control
>>> from motionhyst import Loop, LuGre
>>> from motionhyst.plants import MassDamper
>>> link = LuGre(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
>>> pid = control.tf([6.0, 3.0, 4.0], [1.0, 0.0])
>>> cut = IntegralCut(Loop(MassDamper(1.0, 0.0), pid, link, feedforward=None))
>>> [(round(c.period_s, 1), round(c.response.peak_to_peak, 3)) for c in cut.cycles()]
[(25.6, 0.133)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from motionhyst.analysis.floquet import LoopStateEquation
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI, tf_poly, trim

__all__ = ["CutCycle", "CutResponse", "IntegralCut", "split_integral"]

#: Relative tolerance of the block's integration.
RTOL = 1e-8

#: The block's periodic solution is accepted when ``|X(T/2) + X(0)|`` is below this
#: fraction of each state's scale.
CLOSURE = 1e-7

#: A shooting step this small (per state's scale) leaves an error of about its square:
#: the periodic solution is taken without one more integration to check it.
STEP_DONE = 1e-4

#: Samples of one period for the harmonics and the peak-to-peak.
SAMPLES = 4096

#: Newton's method on the balance: converged when ``|1 + L N|`` is below this.
BALANCE_TOL = 1e-6

#: Newton's iterations at most.
NEWTON_ITERATIONS = 10

#: Step of the finite differences in ``(log U, log omega)``.
FD_STEP = 1e-4


def split_integral(controller) -> tuple[float, object]:
    """``C(s) = ki / s + C0(s)``: the integral action and the rest of a controller.

    Parameters
    ----------
    controller : python-control LTI system
        A continuous controller with one pole at ``s = 0``.

    Returns
    -------
    ki : float
        ``lim_{s -> 0} s C(s)`` [N/(m s)].
    C0 : control.TransferFunction
        The rest, without the pole at 0 (it may be improper, as a pure derivative).

    Raises
    ------
    ValueError
        If `controller` has no pole at ``s = 0`` or more than one.

    Examples
    --------
    >>> import control
    >>> ki, C0 = split_integral(control.tf([6.0, 3.0, 4.0], [1.0, 0.0]))   # 3 + 4/s + 6 s
    >>> ki, C0.num[0][0].tolist(), C0.den[0][0].tolist()
    (4.0, [6.0, 3.0], [1.0])
    """
    import control

    num, den = (trim(p) for p in tf_poly(controller, "the controller"))
    if den.size < 2 or den[-1] != 0.0:
        raise ValueError("the controller has no integral action (no pole at s = 0)")
    d1 = den[:-1]                                   # den = s d1
    if d1[-1] == 0.0:
        raise ValueError("the controller has more than one integrator; the cut takes one")
    ki = float(num[-1] / d1[-1])
    rest = np.polysub(num, ki * d1)                 # vanishes at s = 0: divide by s
    rest = trim(rest[:-1]) if rest.size > 1 else np.zeros(1)
    return ki, control.tf(rest if rest.size else [0.0], d1)


@dataclass
class CutResponse:
    """The block's periodic response to the integral action's force ``u_I = -U cos(w t)``.

    Attributes
    ----------
    force_amplitude : float
        ``U`` [N].
    frequency_hz : float
        ``omega / 2 pi`` [Hz].
    describing_function : complex
        ``N = Y2 / U_I``, first harmonics of the measured position and the force [m/N].
    y1_harmonic : complex
        First harmonic of the link's displacement (``y1 = Re(Y1 e^{j w t})``) [m].
    t, y1 : ndarray
        One period of the link's displacement, from the force's minimum.
    slipped : bool
        True if the link slipped (False: the block held still, ``N`` is the link's
        presliding stiffness only).
    start : tuple or None
        ``(X0, scale)``: the block's state at ``t = 0`` and its states' scales, from
        which the shooting for a nearby force starts.

    Examples
    --------
    >>> import numpy as np
    >>> r = CutResponse(1.0, 0.1, -0.05j, 0.05 + 0j, np.linspace(0, 10, 5),
    ...                 np.array([0.0, 0.05, 0.0, -0.05, 0.0]), True)
    >>> r.peak_to_peak, r.amplitude
    (0.1, 0.05)
    """

    force_amplitude: float
    frequency_hz: float
    describing_function: complex
    y1_harmonic: complex
    t: NDArray[np.float64] = field(repr=False)
    y1: NDArray[np.float64] = field(repr=False)
    slipped: bool
    start: tuple | None = field(default=None, repr=False, compare=False)

    @property
    def peak_to_peak(self) -> float:
        """Peak-to-peak of the link's displacement over the period [m]."""
        return float(np.max(self.y1) - np.min(self.y1))

    @property
    def amplitude(self) -> float:
        """Amplitude of the first harmonic of the link's displacement [m]."""
        return float(abs(self.y1_harmonic))


@dataclass
class CutCycle:
    """A limit cycle the cut's describing function predicts: ``1 + L N = 0``.

    Attributes
    ----------
    response : CutResponse
        The block's response at the balance (the predicted waveform of ``y1``).
    loeb : float
        Loeb's criterion in ``(log U, log omega)``; > 0: stable.

    Examples
    --------
    >>> import numpy as np
    >>> r = CutResponse(1.0, 0.04, -0.05j, 0.05 + 0j, np.zeros(2), np.zeros(2), True)
    >>> CutCycle(r, 0.3).period_s, CutCycle(r, 0.3).stable
    (25.0, True)
    """

    response: CutResponse
    loeb: float

    @property
    def period_s(self) -> float:
        """The predicted period [s]."""
        return 1.0 / self.response.frequency_hz

    @property
    def stable(self) -> bool:
        """Loeb's criterion: stable when :attr:`loeb` > 0."""
        return self.loeb > 0.0


class IntegralCut:
    """The loop cut at its integrator: ``L = ki / s`` and the block with the link.

    Parameters
    ----------
    loop : Loop
        A continuous loop whose controller has integral action, with a link that has a
        smooth state equation.

    Raises
    ------
    ValueError
        If the loop is sampled, its controller has no (simple) integrator, its link has
        no state equation, or the block's ``P1 / (1 + C0 P2)`` is not of relative
        degree >= 2.

    Examples
    --------
    >>> import math, control
    >>> from motionhyst import Loop, LuGre
    >>> from motionhyst.plants import MassDamper
    >>> link = LuGre(sigma0=1e5, sigma1=math.sqrt(1e5), sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)
    >>> cut = IntegralCut(Loop(MassDamper(1.0, 0.0), control.tf([6.0, 3.0, 4.0], [1.0, 0.0]),
    ...                        link, feedforward=None))
    >>> r = cut.response(1.5, 0.3)          # driven just above the break-away force
    >>> r.slipped, round(r.peak_to_peak, 3)
    (True, 0.214)
    >>> cut.response(0.5, 0.3).slipped      # held by the friction: no motion
    False
    """

    def __init__(self, loop: Loop) -> None:
        if loop.sampled is not None:
            raise ValueError("the controller is sampled (the cut needs a continuous one)")
        link = loop.hysteresis
        if link is None:
            raise ValueError("the loop has no link")
        if link.n_states == 0:
            raise ValueError(f"the {link.name} link has no smooth state equation (it switches "
                             f"between sticking and slipping)")
        self.ki, C0 = split_integral(loop.controller)
        if not self.ki > 0:
            raise ValueError("the controller's integral gain must be > 0")
        block = Loop(loop.plant, C0, link, feedforward=None)
        self.sys = LoopStateEquation(block)
        # y2 = P2 / P1 y1 (both driven by the same force)
        self._p2_over_p1 = lambda w: -block.transfer("w->e", w) / block.transfer("w->y1", w)
        self.link = link
        self.force_scale = float(link.time_stepping().scale)
        p = np.abs(loop.closed_loop_poles())
        p = p[p > 0]
        self._w_start = float(np.min(p)) / 3.0 if p.size else 1.0
        A = self.sys.A
        self._x_push = (np.linalg.solve(A, self.sys.B) if np.linalg.cond(A) < 1e12
                        else np.zeros(self.sys.n))

    def line(self, omega: float) -> complex:
        """``L(j omega) = ki / (j omega)``, the linear part of the cut.

        Parameters
        ----------
        omega : float
            Angular frequency [rad/s].
        """
        return self.ki / (1j * omega)

    # ---------------------------------------------------------------- the block
    def _rhs(self, U: float, w: float):
        sys = self.sys

        def rhs(t, X):
            d = sys.rhs(t, X)
            d[:sys.n] -= sys.B * (U * math.cos(w * t))
            return d

        return rhs

    def _flow(self, X0, U, w, t_end, scale, variations=False, dense=False):
        from scipy.integrate import solve_ivp

        sys, N, n = self.sys, self.sys.N, self.sys.n
        rhs = self._rhs(U, w)
        atol = RTOL * np.maximum(scale, 1e-300)
        if not variations:
            return solve_ivp(rhs, (0.0, t_end), X0, method="LSODA", jac=sys.jac, rtol=RTOL,
                             atol=atol, dense_output=dense)
        link, A, B, CA = sys.link, sys.A, sys.B, sys.CA
        J = np.empty((N, N))
        eye = np.eye(N)

        def rhs_var(t, Y):                  # the flow and its variations, one link call
            x, z = Y[:n], Y[n:N]
            v = float(CA @ x)
            zdot, f, dzz, dzv, dwz, dwv = link.state_equation(z, v)
            J[:n, :n] = A - np.outer(B, dwv * CA)
            J[:n, n:] = -np.outer(B, dwz)
            J[n:, :n] = np.outer(dzv, CA)
            J[n:, n:] = dzz
            d = np.concatenate([A @ x - B * (f + U * math.cos(w * t)), zdot])
            return np.concatenate([d, (J @ Y[N:].reshape(N, N)).ravel()])

        def jac_var(t, Y):
            Jx = sys.jac(t, Y[:N])
            out = np.zeros((N + N * N, N + N * N))
            out[:N, :N] = Jx
            out[N:, N:] = np.kron(Jx, eye)
            return out

        Y0 = np.concatenate([X0, eye.ravel()])
        return solve_ivp(rhs_var, (0.0, t_end), Y0, method="LSODA", jac=jac_var, rtol=RTOL,
                         atol=np.concatenate([atol, np.full(N * N, RTOL)]))

    def _periodic(self, U: float, w: float, start: NDArray | None):
        """The half-wave symmetric periodic state at ``t = 0`` and the state scales."""
        sys = self.sys
        T = TWO_PI / w
        if start is None:
            X = np.concatenate([self._x_push * U, np.zeros(sys.ns)])   # held at -U
            sol = self._flow(X, U, w, T, np.abs(X) + 1e-12)
            X = sol.y[:, -1]
            scale = np.max(np.abs(sol.y), axis=1)
        else:
            X, scale = start
        scale = np.maximum(scale, 1e-9 * np.max(scale[:sys.n]))
        for _ in range(10):
            sol = self._flow(X, U, w, T / 2, scale, variations=True)
            if not sol.success:
                raise RuntimeError(f"the block's response could not be integrated: "
                                   f"{sol.message}")
            Y = sol.y[:, -1]
            r = Y[:sys.N] + X
            if np.max(np.abs(r) / scale) < CLOSURE:
                return X, scale
            M = Y[sys.N:].reshape(sys.N, sys.N)
            dX = np.linalg.solve(M + np.eye(sys.N), r)
            X = X - dX
            if np.max(np.abs(dX) / scale) < STEP_DONE:   # Newton's next error ~ its square
                return X, scale
        raise RuntimeError("the block's periodic response did not converge")

    def response(self, U: float, omega: float, start=None) -> CutResponse:
        """The block's periodic response to ``u_I = -U cos(omega t)`` and its describing
        function.

        Parameters
        ----------
        U : float
            Amplitude of the integral action's force [N].
        omega : float
            Its angular frequency [rad/s].
        start : tuple, optional
            :attr:`CutResponse.start` of a nearby response, to start the shooting from.

        Returns
        -------
        CutResponse
        """
        sys = self.sys
        X, scale = self._periodic(U, omega, start)
        T = TWO_PI / omega
        sol = self._flow(X, U, omega, T / 2, scale, dense=True)
        half = sys.C @ sol.sol(np.linspace(0.0, T / 2, SAMPLES // 2, endpoint=False))[:sys.n]
        y1 = np.concatenate([half, -half])                  # half-wave symmetric
        c_y1 = 2.0 * np.fft.rfft(y1)[1] / y1.size
        Y2 = complex(np.ravel(self._p2_over_p1(np.array([omega])))[0]) * c_y1
        slipped = bool(np.ptp(y1) > 20.0 * U / self.link.initial_stiffness)
        return CutResponse(float(U), omega / TWO_PI, complex(Y2 / -U), complex(c_y1),
                           np.linspace(0.0, T, SAMPLES + 1), np.append(y1, y1[0]), slipped,
                           (X, scale))

    # ---------------------------------------------------------------- the balance
    def _balance(self, p: NDArray, start=None):
        U, w = math.exp(p[0]), math.exp(p[1])
        r = self.response(U, w, start)
        f = 1.0 + self.line(w) * r.describing_function
        return np.array([f.real, f.imag]), r

    def _start_frequency(self, U: float) -> float | None:
        """Where ``|L N(U, omega)| = 1`` (log-linear interpolation of a bracket), between
        1/10 and 10 times the start (a third of the slowest closed-loop pole)."""
        w, prev = self._w_start, None
        lo, hi = self._w_start / 10.0, self._w_start * 10.0
        while lo <= w <= hi:
            r = self.response(U, w)
            m = math.log(abs(self.line(w) * r.describing_function)) if r.slipped else -np.inf
            if prev is not None and (m > 0) != (prev[1] > 0) and np.isfinite(m + prev[1]):
                lw0, lw1 = math.log(prev[0]), math.log(w)
                return math.exp(lw0 + (lw1 - lw0) * prev[1] / (prev[1] - m))
            prev = (w, m)
            w = w * 2.0 if m > 0 else w / 2.0
        return None

    def cycles(self) -> list[CutCycle]:
        """The limit cycles of the cut's harmonic balance (at most one: Newton's method
        from the link's break-away force).

        Returns
        -------
        list of CutCycle
            Empty when the balance has no solution near the start or Newton's method
            does not converge.
        """
        for factor in (1.0, 1.25):
            U0 = self.force_scale * factor
            try:
                w0 = self._start_frequency(U0)
                if w0 is None:
                    continue
                found = self._newton(np.array([math.log(U0), math.log(w0)]))
            except (RuntimeError, np.linalg.LinAlgError):
                continue
            if found is not None:
                return [found]
        return []

    def _newton(self, p: NDArray) -> CutCycle | None:
        """Damped Newton's method on the balance; None if it stalls (the balance's least
        ``|1 + L N|`` at the end of the slipping branch, not a root) or diverges."""
        f, r = self._balance(p)
        stalled = 0
        for _ in range(NEWTON_ITERATIONS):
            if not r.slipped:
                return None
            J = np.empty((2, 2))
            for k in range(2):
                q = p.copy()
                q[k] += FD_STEP
                J[:, k] = (self._balance(q, r.start)[0] - f) / FD_STEP
            if np.max(np.abs(f)) < BALANCE_TOL:
                return CutCycle(r, float(J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]))
            d = np.linalg.solve(J, -f)
            d *= min(1.0, 0.5 / np.max(np.abs(d)))          # at most a factor e^0.5 a step
            for _ in range(4):
                try:
                    f1, r1 = self._balance(p + d, r.start)
                except RuntimeError:
                    f1, r1 = None, None
                if f1 is not None and r1.slipped and np.max(np.abs(f1)) < np.max(np.abs(f)):
                    break
                d *= 0.5
            else:
                return None
            stalled = stalled + 1 if np.max(np.abs(f1)) > 0.8 * np.max(np.abs(f)) else 0
            if stalled == 2:
                return None
            p, f, r = p + d, f1, r1
        return None
