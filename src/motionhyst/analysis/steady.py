"""Exact periodic steady state of the nonlinear loop for a sinusoidal reference.

For ``r = A sin(2 pi f t)`` the loop settles to a periodic solution with all
harmonics of ``f``.  It is computed by harmonic balance with the exact
element (alternating frequency-time): the linear loop's response to ``r`` is
known in closed form; only the hysteresis-driven part is iterated::

    y1 = y1_lin + T_{w->y1} w(y1),      e = e_lin + T_{w->e} w(y1)

with the harmonics of ``w(y1)`` from the element's exact periodic output.  In
a stiff loop ``y1`` follows ``r`` closely, so the fixed point converges in a
few iterations, and ``e`` (about 1e-8 m against positions of 1e-2 m) is never
formed by subtracting positions.  A link's force linear in its velocity at every
amplitude (LuGre's ``sigma2``) is solved with the loop, ``y1 = (y1_lin + T_{w->y1} (w(y1) -
L y1)) / (1 - T_{w->y1} L)`` with ``L = j n w c`` (a sampled loop: per alias class), where
the iteration would multiply a change by ``|T_{w->y1} L|`` each pass; passes that contract
slowly or grow at a few harmonics (LuGre's ``sigma1``, which acts while the link sticks) are
mixed with the ones before (Anderson acceleration), and every pass is judged at every
harmonic (:mod:`motionhyst.analysis._fixed_point`): no answer where it did not converge.
Where those passes are refused, a link that sticks has its spring and dampers while it sticks
solved with the loop the same way (LuGre's ``sigma0 + j n w (sigma1 + sigma2)``), from the loop
with the link stuck, and only its departure from them iterated.

Complex amplitudes are reported relative to ``sin(n omega t)``:
a signal is ``c_0 + sum_n |c_n| sin(n omega t + angle c_n)``.

With a sampled controller the loop is hybrid: the link and the plant move
continuously, the controller sees the samples ``y2(t_k)`` and acts through a
delayed hold.  When the reference period is a whole number ``N`` of samples
(``f = F / N``) the loop's steady state is periodic with the reference, and
it is computed exactly in the same way: the samples' spectrum at
``z_m = e^{j 2 pi m / N}`` gathers every harmonic ``n = m mod N`` of the plant's
output (aliasing), the controller acts on it, and the hold spreads its output
over all those harmonics again (``H(j n w)``); the plant's response to the held
force is summed in closed form (:class:`~motionhyst.core.sampling.ZohEquivalent`),
the link's force is kept to ``H`` harmonics as in the continuous loop.  For
another frequency the loop has no steady state of the reference's period, and
:func:`periodic_steady_state` names the nearest frequency that has one.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.analysis._fixed_point import (
    ContinuousPasses,
    FixedPointError,
    Mixing,
    NoFixedPoint,
    Passes,
    Progress,
    chord,
    not_converged,
    sticking,
    viscous_damping,
)
from motionhyst.analysis.equations import over_error_without_link
from motionhyst.controllers.loop import Loop
from motionhyst.core.compiled import njit
from motionhyst.core.lti import TWO_PI
from motionhyst.core.sampling import hold_response
from motionhyst.core.textfmt import g, table
from motionhyst.hysteresis.periodic import (
    sample_period,
    stop_harmonics_base,
    stop_harmonics_update,
    stop_twiddles,
)

__all__ = ["SteadyState", "check_steady_frequencies", "periodic_steady_state",
           "samples_per_period", "steady_state_sweep"]

MIN_HARMONICS = 32
MAX_HARMONICS = 4096
#: Accuracy of the binned sums of the fixed point's first iteration for a link of many stop
#: operators (relative to the sums of their weights).  It is the starting value: an error
#: ``d`` in it moves the answer by about ``rho^(K-1) d`` (``rho`` the contraction, ``K >=
#: 3`` the iterations), which the stopping rule bounds by ``1e-12 d / rho`` as well: at
#: most 1e-8 ``d`` whatever ``rho``, far below round-off.
FIRST_ITERATION_TOL = 1e-10


def _to_sin_amplitudes(X: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """``rfft / N`` harmonics to complex amplitudes relative to ``sin(n theta)`` (DC kept)."""
    c = 2j * np.asarray(X, dtype=complex)
    c[0] = X[0].real
    return c


def _from_sin_amplitudes(c: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """The inverse of :func:`_to_sin_amplitudes`."""
    X = np.asarray(c, dtype=complex) / 2j
    X[0] = c[0].real
    return X


def default_harmonics(loop: Loop, frequency_hz: float) -> int:
    """Number of harmonics that resolves the loop's dynamics at `frequency_hz`.

    Harmonics up to twice the fastest closed-loop pole (LTI loops) or the
    highest measured frequency (measured plants).  For Table I, doubling
    this changes the error's first harmonic by less than 1e-12.
    """
    if loop.is_lti:
        f_lim = 2.0 * np.max(np.abs(loop.closed_loop_poles())) / TWO_PI
    else:
        f_lim = loop.P2.omega.max() / TWO_PI
    return int(np.clip(np.ceil(f_lim / frequency_hz), MIN_HARMONICS, MAX_HARMONICS))


@dataclass
class SteadyState:
    """Periodic steady state of the nonlinear loop at one frequency.

    Attributes
    ----------
    frequency_hz, amplitude : float
        Reference ``r = amplitude sin(2 pi frequency_hz t)``.
    e, y1, w : ndarray of complex
        Harmonics ``n = 0 .. H`` of the tracking error [m], the link's
        displacement [m] and the hysteresis force [N], relative to
        ``sin(n omega t)`` (``[0]`` is the mean).
    e_linear : ndarray of complex
        Harmonics of the error without hysteresis (only ``n = 1`` is non-zero,
        and its images ``n = k N +- 1`` for a sampled controller).
    iterations : int
        Fixed-point iterations used.
    residual : float
        Relative change of the first harmonic of ``w`` in the last iteration.
    samples_per_period : int or None
        ``N`` for a sampled controller (``f = F / N``); None for a continuous one.

    Examples
    --------
    >>> from motionhyst import default_scenario, periodic_steady_state
    >>> ss = periodic_steady_state(default_scenario().loop(), amplitude=0.01, frequency_hz=5.0)
    >>> print(f"3rd harmonic of the error: {abs(ss.e[3]):.3e} m")
    3rd harmonic of the error: 2.574e-09 m
    >>> signals = ss.time_series(200)                      # one period, sampled
    >>> sorted(signals)
    ['e', 'e_linear', 'r', 't', 'w', 'y1']
    >>> round(ss.to_dict()["mismatch_simulated_abs"], 3)
    6.041
    """

    frequency_hz: float
    amplitude: float
    e: NDArray[np.complex128]
    y1: NDArray[np.complex128]
    w: NDArray[np.complex128]
    e_linear: NDArray[np.complex128]
    iterations: int
    residual: float
    samples_per_period: int | None = None

    @property
    def n_harmonics(self) -> int:
        """Highest harmonic kept."""
        return len(self.e) - 1

    @property
    def mismatch(self) -> complex:
        """Exact mismatch ``E_sim = e_1 / e_1,linear`` (compare eqs. 18, 20); nan (no
        warning) where the loop without the link has no error, ``e_1,linear = 0`` (a rigid
        plant under its rigid-body feedforward:
        :func:`~motionhyst.analysis.equations.over_error_without_link`).

        Examples
        --------
        >>> from motionhyst import default_scenario
        >>> round(abs(periodic_steady_state(default_scenario().loop(), 0.01, 5.0).mismatch), 2)
        6.04
        """
        return complex(over_error_without_link(self.e[1], self.e_linear[1]))

    @property
    def error_rms(self) -> float:
        """RMS of the error over a period [m] (Parseval)."""
        return float(np.sqrt(self.e[0].real ** 2 + 0.5 * np.sum(np.abs(self.e[1:]) ** 2)))

    @property
    def error_hysteresis_rms(self) -> float:
        """RMS over a period of the error minus the error without hysteresis [m]."""
        d = self.e - self.e_linear
        return float(np.sqrt(d[0].real ** 2 + 0.5 * np.sum(np.abs(d[1:]) ** 2)))

    @property
    def error_linear_rms(self) -> float:
        """RMS of the error without hysteresis [m]."""
        return float(abs(self.e_linear[1]) / np.sqrt(2.0))

    def time_series(self, n_samples: int | None = None) -> dict[str, NDArray[np.float64]]:
        """One period sampled: ``t`` [s], ``r``, ``e``, ``e_linear``, ``y1`` [m], ``w`` [N].

        Parameters
        ----------
        n_samples : int, optional
            Samples of the period (default: enough for the harmonics computed).
        """
        N = n_samples or max(4096, 8 * self.n_harmonics)
        t = np.arange(N) / (N * self.frequency_hz)

        def synth(c):  # sin-referenced amplitudes -> rfft scaling, below Nyquist
            X = np.asarray(c[: N // 2], dtype=complex) / 2j
            X[0] = c[0].real
            return sample_period(X, N)

        r = self.amplitude * np.sin(TWO_PI * self.frequency_hz * t)
        return {"t": t, "r": r, "e": synth(self.e), "e_linear": synth(self.e_linear),
                "y1": synth(self.y1), "w": synth(self.w)}

    @property
    def error_peak(self) -> float:
        """Largest ``|e|`` over a period [m] (finely sampled)."""
        return float(np.max(np.abs(self.time_series()["e"])))

    def __str__(self) -> str:
        rows = [[str(n), g(abs(self.e[n])), f"{np.degrees(np.angle(self.e[n])):.2f}",
                 g(abs(self.w[n]))] for n in range(1, min(self.n_harmonics, 5) + 1)]
        sampled = ("" if self.samples_per_period is None else
                   f", sampled: {self.samples_per_period} samples a period")
        return "\n".join([
            f"Periodic steady state, r = {g(self.amplitude)} m sin(2 pi {g(self.frequency_hz)} t)"
            f": {self.n_harmonics} harmonics, {self.iterations} iterations{sampled}",
            f"  |E| = |e1 / e1_linear| = {g(abs(self.mismatch))}, "
            f"angle {np.degrees(np.angle(self.mismatch)):.2f} deg" if self.e_linear[1] != 0 else
            "  |E| = |e1 / e1_linear|: not defined, the loop without the link has no error",
            f"  error RMS {g(self.error_rms)} m (without hysteresis {g(self.error_linear_rms)} m)",
            table(["n", "|e_n| [m]", "angle e_n [deg]", "|w_n| [N]"], rows)])

    def plot(self, ax=None):
        """One period of the error, with and without hysteresis
        (:func:`motionhyst.analysis.figures.plot_steady_state`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_steady_state

        return plot_steady_state(self, ax=ax)

    def to_dict(self, harmonics: tuple[int, ...] = (1, 3, 5),
                mismatch_df: complex | None = None,
                error_harmonics_df: ArrayLike | None = None) -> dict:
        """JSON-ready dictionary (one point of the ``simulate --json`` schema).

        Parameters
        ----------
        harmonics : tuple of int
            The error harmonics to list.
        mismatch_df : complex, optional
            Eq. (18) to report beside the exact mismatch.
        error_harmonics_df : array_like, optional
            Error harmonics predicted by the higher-order describing functions [m].
        """
        eh = [{"n": n, "abs": float(abs(self.e[n])),
               "phase_deg": float(np.degrees(np.angle(self.e[n])))}
              for n in harmonics if n <= self.n_harmonics]
        E = self.mismatch
        out = {
            "frequency_hz": self.frequency_hz,
            "amplitude": self.amplitude,
            "error_harmonics": eh,
            "error_linear_abs": float(abs(self.e_linear[1])),
            "mismatch_simulated_abs": abs(E),
            "mismatch_simulated_phase_deg": float(np.degrees(np.angle(E))),
        }
        if mismatch_df is not None:
            out["mismatch_df_abs"] = abs(mismatch_df)
            out["mismatch_df_phase_deg"] = float(np.degrees(np.angle(mismatch_df)))
        if error_harmonics_df is not None:
            edf = np.asarray(error_harmonics_df)
            out["error_harmonics_df"] = [
                {"n": n, "abs": float(abs(edf[n - 1])),
                 "phase_deg": float(np.degrees(np.angle(edf[n - 1])))}
                for n in harmonics if n <= len(edf)]
        out.update({
            "error_peak": self.error_peak,
            "error_rms": self.error_rms,
            "error_hysteresis_rms": self.error_hysteresis_rms,
            "y1_amplitude": float(abs(self.y1[1])),
            "harmonics_kept": self.n_harmonics,
            "iterations": self.iterations,
        })
        if self.samples_per_period is not None:
            out["samples_per_period"] = self.samples_per_period
        return out


def periodic_steady_state(loop: Loop, amplitude: float, frequency_hz: float,
                          n_harmonics: int | None = None, tol: float = 1e-12,
                          max_iter: int = 50) -> SteadyState:
    """Exact periodic steady state of the nonlinear loop for ``r = A sin(2 pi f t)``.

    Parameters
    ----------
    loop : Loop
        The loop (with or without hysteresis and hysteresis feedforward).  A link along
        the stroke (:class:`~motionhyst.hysteresis.along_stroke.AlongStroke`) is followed
        at the stage's position, the sine about the table's position 0 (its feedforward
        model at the setpoint's).
    amplitude : float
        Reference amplitude ``A`` [m], > 0.
    frequency_hz : float
        Reference frequency ``f`` [Hz], > 0.
    n_harmonics : int, optional
        Highest harmonic kept; by default enough to cover the loop's dynamics
        (:func:`default_harmonics`).
    tol : float
        Convergence tolerance on the relative change of the first harmonic of ``w``.
    max_iter : int
        Iteration limit.

    Returns
    -------
    SteadyState

    Raises
    ------
    ValueError
        For a non-positive or non-finite amplitude or frequency, or a raw
        measured plant (``[plant] use = "data"``): the steady state needs the
        plant at every harmonic ``n f``, which measured lines do not give.
    RuntimeError
        If the fixed point does not converge (a link too stiff for the loop, or passes too
        slow), or diverges at a harmonic, or leaves one unconverged when its first harmonic
        has settled (a link too damped for the loop: :mod:`motionhyst.analysis._fixed_point`;
        a damping at every amplitude, LuGre's ``sigma2``, is solved with the loop instead, and
        where the passes are refused, the link's spring and dampers while it sticks too).

    Examples
    --------
    The exact counterpart of the paper's eq. (18) for Table I at 5 Hz:

    >>> from motionhyst import default_scenario, periodic_steady_state
    >>> loop = default_scenario().loop()
    >>> ss = periodic_steady_state(loop, amplitude=0.01, frequency_hz=5.0)
    >>> print(f"|E_sim| = {abs(ss.mismatch):.3f}")          # eq. (18) gives 6.040
    |E_sim| = 6.041
    >>> print(f"{ss.error_rms:.3e} m RMS, {ss.error_linear_rms:.3e} m without the link")
    8.176e-09 m RMS, 1.314e-09 m without the link
    """
    for name, v in (("amplitude", amplitude), ("frequency", frequency_hz)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be finite and > 0, got {v!r}")
    if not loop.plant.is_lti:
        raise ValueError("the steady state needs the plant at every harmonic n f, which raw "
                         "measured lines do not give; fit the data ([plant] use = \"fit\")")
    if loop.sampled is not None:
        N = samples_per_period(loop.sampled.sample_rate_hz, frequency_hz)
        H = (int(n_harmonics) if n_harmonics is not None
             else max(default_harmonics(loop, frequency_hz), min(N + 1, MAX_HARMONICS)))
        if H < 1:
            raise ValueError("n_harmonics must be >= 1")
        return _sampled_steady_state(loop, float(amplitude), float(frequency_hz), N, H,
                                     tol, max_iter)
    H = int(n_harmonics) if n_harmonics is not None else _default_harmonics(loop, frequency_hz)
    if H < 1:
        raise ValueError("n_harmonics must be >= 1")
    omega = TWO_PI * frequency_hz
    T = _transfers(loop, float(frequency_hz), H)
    R = np.zeros(H + 1, dtype=complex)
    R[1] = -0.5j * amplitude  # r = A sin(theta)
    # the reference has one harmonic, so the linear loop answers with that one only
    e_lin = np.zeros(H + 1, dtype=complex)
    y1_lin = np.zeros(H + 1, dtype=complex)
    e_lin[1] = T.r_e * R[1]
    y1_lin[1] = T.r_y1 * R[1]
    hyst, hff = loop.hysteresis, loop.hysteresis_feedforward
    U_h = (np.zeros(H + 1, dtype=complex) if hff is None
           else hff.periodic_harmonics(R, H, omega))
    if loop.ff is not None and loop.ff.coulomb:
        # fc sign(r') = fc sign(cos theta): a square wave, odd harmonics 4 fc / (pi n) cos(n theta)
        n = np.arange(H + 1)
        odd = n % 2 == 1
        U_h = U_h.copy()
        U_h[odd] += loop.ff.coulomb * 2.0 / (np.pi * n[odd]) * (-1.0) ** ((n[odd] - 1) // 2)
        hff = hff if hff is not None else loop.ff
    if hyst is None and hff is None:
        z = np.zeros(H + 1, dtype=complex)
        return SteadyState(float(frequency_hz), float(amplitude), _to_sin_amplitudes(e_lin),
                           _to_sin_amplitudes(y1_lin), z, _to_sin_amplitudes(e_lin), 0, 0.0)
    G_1 = T.w_y1
    X = y1_lin - G_1 * U_h
    W = np.zeros(H + 1, dtype=complex)
    residual, it = np.inf, 0
    stops = None if hyst is None else hyst.periodic_stops()
    if stops is not None:
        weights, grid, first_weights, first_grid = _BINNED_TABLE[0]
        grid, first_grid = grid.copy(), first_grid.copy()  # set to the weights returned
        (e, y1, w, e_linear, it, residual, converged, weights, first_weights,
         dW) = _stop_steady_state(
            complex(R[1]), T.r_e, T.r_y1, G_1, T.w_e, U_h, stops[0], stops[1], float(tol),
            int(max_iter), stop_twiddles(H, H), weights, grid, first_weights, first_grid)
        _BINNED_TABLE[0] = (weights, grid, first_weights, first_grid)
        if not converged:
            raise not_converged(frequency_hz, max_iter, residual)
        Passes(frequency_hz, hyst).judge(_from_sin_amplitudes(e), T.w_e * dW, it)
        return SteadyState(float(frequency_hz), float(amplitude), e, y1, w, e_linear, it,
                           residual)
    if hyst is not None:
        # a damping at every amplitude is solved with the linear loop, the rest iterated
        linear = chord(G_1, frequency_hz, viscous_damping(hyst))
        fixed = ContinuousPasses(hyst, frequency_hz, H, y1_lin, e_lin, U_h, T, tol, max_iter)
        try:
            W, X, it, residual = fixed.passes(linear, X, W)
        except FixedPointError as refusal:
            # a link that sticks: its spring and damping solved with the loop too, from the
            # loop with the link stuck; where that does not converge either, the first refusal
            k, c = sticking(hyst)
            stuck = chord(G_1, frequency_hz, c, k) if c > viscous_damping(hyst) or k else None
            if stuck is None:
                raise
            X = (y1_lin - G_1 * U_h) * stuck[1]
            try:
                W, X, it, residual = fixed.passes(stuck, X, stuck[0] * X)
            except FixedPointError:
                raise refusal from None
    e = e_lin + T.w_e * (W - U_h)
    return SteadyState(float(frequency_hz), float(amplitude), _to_sin_amplitudes(e),
                       _to_sin_amplitudes(X), _to_sin_amplitudes(W),
                       _to_sin_amplitudes(e_lin), it, residual)


class _Transfers(NamedTuple):
    """The loop's transfers at the harmonics ``n omega``, ``n = 0 .. H``, of one frequency."""

    r_e: complex
    r_y1: complex
    w_y1: NDArray[np.complex128]
    w_e: NDArray[np.complex128]


#: Bytes of transfers kept: the frequencies of a study's points, whatever their order.
_TRANSFER_BYTES = 64 * 2**20
_TRANSFERS: OrderedDict = OrderedDict()   # (Loop.transfer_key(), f, H) -> _Transfers
_F_LIM: OrderedDict = OrderedDict()       # Loop.transfer_key() -> fastest pole's f [Hz]
_CACHE_LOCK = threading.Lock()
#: The weights of the binned jump sums of parallel stop operators and their grid ``[N, P]``
#: (:func:`motionhyst.hysteresis.periodic.stop_harmonics_kept`), kept for the next point:
#: those of the iterations from the second on, then those of the first (a sine's input).
_BINNED_TABLE: list = [(np.empty((0, 0)), np.zeros(2, dtype=np.int64), np.empty((0, 0)),
                        np.zeros(2, dtype=np.int64))]
_CACHED = {"bytes": 0}


def _default_harmonics(loop: Loop, frequency_hz: float) -> int:
    """:func:`default_harmonics` with the loop's limiting frequency computed once for all the
    loops with the same transfers (:meth:`~motionhyst.controllers.loop.Loop.transfer_key`)."""
    key = loop.transfer_key()
    if key is None:
        return default_harmonics(loop, frequency_hz)
    f_lim = _F_LIM.get(key)
    if f_lim is None:
        f_lim = float(2.0 * np.max(np.abs(loop.closed_loop_poles())) / TWO_PI)
        with _CACHE_LOCK:
            _F_LIM[key] = f_lim
            if len(_F_LIM) > 4096:
                _F_LIM.popitem(last=False)
    return min(max(math.ceil(f_lim / frequency_hz), MIN_HARMONICS), MAX_HARMONICS)


def _transfers(loop: Loop, frequency_hz: float, H: int) -> _Transfers:
    """The transfers of the continuous loop at `frequency_hz` and its harmonics up to `H`,
    computed once for all the points (amplitudes, links) of one frequency and loop."""
    key = loop.transfer_key()
    T = None if key is None else _TRANSFERS.get((key, frequency_hz, H))
    if T is None:
        wn = TWO_PI * frequency_hz * np.arange(H + 1)
        T = _Transfers(complex(loop.transfer("r->e", wn[1:2])[0]),
                       complex(loop.transfer("r->y1", wn[1:2])[0]),
                       loop.transfer("w->y1", wn), loop.transfer("w->e", wn))
        T.w_y1.flags.writeable = False
        T.w_e.flags.writeable = False
        if key is not None:
            with _CACHE_LOCK:
                _TRANSFERS[(key, frequency_hz, H)] = T
                _CACHED["bytes"] += T.w_y1.nbytes + T.w_e.nbytes
                while _CACHED["bytes"] > _TRANSFER_BYTES and len(_TRANSFERS) > 1:
                    old = _TRANSFERS.popitem(last=False)[1]  # the oldest go first
                    _CACHED["bytes"] -= old.w_y1.nbytes + old.w_e.nbytes
    return T


@njit(cache=True)
def _sin_amplitudes(X):  # pragma: no cover - compiled
    """:func:`_to_sin_amplitudes`, compiled."""
    c = 2j * X
    c[0] = X[0].real
    return c


@njit(cache=True)
def _stop_steady_state(R1, r_e, r_y1, G_1, G_e, U_h, k, fc, tol, max_iter, tw, weights, grid,
                       first_weights, first_grid):  # pragma: no cover - compiled
    """The fixed point of :func:`periodic_steady_state` for a link of parallel stop
    operators, compiled whole: the same iteration and stopping rule as its Python loop.

    `weights` and `grid` (`first_weights`, `first_grid` for the first iteration) are the
    binned jump sums' weights kept from the point before
    (:func:`motionhyst.hysteresis.periodic.stop_harmonics_kept`; the grids are updated in
    place).  An iteration whose ``y1`` is within 1e-10 of the last one computed in full
    (the fixed point contracts fast: the last iterations change ``y1`` by 1e-12 of itself)
    follows it to first order (:func:`motionhyst.hysteresis.periodic.stop_harmonics_update`)
    where that computation was a costly one.  Returns the harmonics of ``e``, ``y1``, ``w``
    and of the linear ``e`` (relative to ``sin(n theta)``), the iterations, the last
    relative change, whether it converged, the weights to keep, and the last iteration's
    change of ``w`` (``rfft / N`` scaling).
    """
    H = G_1.shape[0] - 1
    e_lin = np.zeros(H + 1, dtype=np.complex128)
    y1_lin = np.zeros(H + 1, dtype=np.complex128)
    e_lin[1] = r_e * R1
    y1_lin[1] = r_y1 * R1
    X = y1_lin - G_1 * U_h
    W = np.zeros(H + 1, dtype=np.complex128)
    residual = np.inf
    previous = np.inf
    it = 0
    converged = False
    # the last full evaluation, which a small change of y1 follows to first order
    base = False
    Wb = np.empty(0, dtype=np.complex128)
    Xb = np.empty(0, dtype=np.complex128)
    Sb = np.empty(0, dtype=np.complex128)
    zs = np.empty(0, dtype=np.complex128)
    t_b = np.empty(0)
    js = np.empty(0)
    x_top = 0.0
    moments = np.empty((0, 0))
    dW = np.zeros(H + 1, dtype=np.complex128)
    for it in range(1, max_iter + 1):
        updated = False
        W_new = Wb
        if base:
            updated, W_new = stop_harmonics_update(X, H, tw, Wb, Xb, Sb, zs, t_b, js,
                                                   x_top, moments, weights, grid)
        if not updated:
            if it == 1:  # the linear loop's y1, one harmonic: a grid of its own; the
                # starting value, whose error the contraction damps at each later iteration
                # (computed to 1e-10 only, on the other grid: never followed to first order)
                (W_new, first_weights, _, Xb, Sb, zs, t_b, js, x_top,
                 moments) = stop_harmonics_base(X, k, fc, H, tw, first_weights, first_grid, H,
                                                FIRST_ITERATION_TOL)
                base = False
            else:  # one grid for any number of harmonics of y1
                (W_new, weights, base, Xb, Sb, zs, t_b, js, x_top,
                 moments) = stop_harmonics_base(X, k, fc, H, tw, weights, grid, 2 * H, 1e-17)
            Wb = W_new
        change = 0.0
        for q in range(H + 1):
            change = max(change, abs(W_new[q] - W[q]))
        residual = abs(W_new[1] - W[1]) / max(abs(W_new[1]), 1e-300)
        dW = W_new - W
        W = W_new
        X = y1_lin + G_1 * (W - U_h)
        rho = residual / previous if it > 2 and previous > 0 else 1.0
        previous = residual
        if it > 1 and (change == 0.0 or (rho < 0.5 and residual * rho / (1 - rho) <= tol)):
            converged = True
            break
    e = e_lin + G_e * (W - U_h)
    return (_sin_amplitudes(e), _sin_amplitudes(X), _sin_amplitudes(W), _sin_amplitudes(e_lin),
            it, residual, converged, weights, first_weights, dW)


def check_steady_frequencies(loop: Loop, frequencies_hz: ArrayLike) -> None:
    """Refuse, before any work, the frequencies at which :func:`periodic_steady_state` of
    `loop` has no answer: a plant of raw measured lines (no harmonics), a sampled loop's
    frequency whose period is not a whole number of samples (:func:`samples_per_period`).

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    frequencies_hz : array_like
        The frequencies asked [Hz].

    Raises
    ------
    ValueError
        The message :func:`periodic_steady_state` would give at the first such frequency.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> from motionhyst.analysis.steady import check_steady_frequencies
    >>> sc = default_scenario(check=False)
    >>> sc.model.controller.sample_rate_hz = 10e3          # Table I's controller at 10 kHz
    >>> loop = sc.loop()
    >>> check_steady_frequencies(loop, [5.0, 10.0])
    >>> try:
    ...     check_steady_frequencies(loop, [5.0, 7.0])
    ... except ValueError as err:
    ...     print(err)
    the steady state of a loop sampled at 10000 Hz needs a whole number of samples per \
period: 7 Hz has 1428.57; the nearest frequency that has one is 6.997900629811 Hz (1429 samples)
    """
    if not loop.plant.is_lti:
        raise ValueError("the steady state needs the plant at every harmonic n f, which raw "
                         "measured lines do not give; fit the data ([plant] use = \"fit\")")
    if loop.sampled is not None:
        for f in np.atleast_1d(frequencies_hz):
            samples_per_period(loop.sampled.sample_rate_hz, float(f))


def samples_per_period(sample_rate_hz: float, frequency_hz: float) -> int:
    """``N = F / f`` when it is a whole number >= 3; else ValueError naming the nearest such f.

    Parameters
    ----------
    sample_rate_hz : float
        The controller's rate ``F`` [Hz].
    frequency_hz : float
        The reference's frequency ``f`` [Hz].

    Examples
    --------
    >>> from motionhyst.analysis.steady import samples_per_period
    >>> samples_per_period(10e3, 5.0)
    2000
    >>> try:
    ...     samples_per_period(10e3, 7.0)
    ... except ValueError as err:
    ...     print(err)
    the steady state of a loop sampled at 10000 Hz needs a whole number of samples per \
period: 7 Hz has 1428.57; the nearest frequency that has one is 6.997900629811 Hz (1429 samples)
    """
    ratio = float(sample_rate_hz) / float(frequency_hz)
    N = max(3, round(ratio))
    if abs(ratio - N) > 1e-9 * ratio:
        raise ValueError(
            f"the steady state of a loop sampled at {sample_rate_hz:g} Hz needs a whole number "
            f"of samples per period: {frequency_hz:g} Hz has {ratio:.6g}; the nearest frequency "
            f"that has one is {sample_rate_hz / N:.13g} Hz ({N} samples)")
    return int(N)


def _feedforward_samples(loop: Loop, amplitude: float, omega: float, N: int
                         ) -> NDArray[np.complex128]:
    """DFT / N of the feedforward's nonlinear terms at the samples (Coulomb, phi_hat(r)).

    ``phi_hat`` is evaluated on the setpoint's samples, as the controller does (it does
    not see the setpoint's reversals between samples).
    """
    T = loop.sampled.period
    a = 0.0 if loop.ff is None else loop.ff.advance_samples
    th = omega * (np.arange(N) + a) * T
    f = np.zeros(N)
    if loop.ff is not None and loop.ff.coulomb:
        f += loop.ff.coulomb_force(amplitude * omega * np.cos(th))
    hff = loop.hysteresis_feedforward
    if hff is not None:
        if not hff.rate_independent:
            raise ValueError("the sampled loop's steady state takes a rate-independent "
                             "hysteresis feedforward only")
        # evaluated on the setpoint's samples, as the controller does: three periods of
        # them, the last one kept (a rate-independent model forgets its start by then)
        r_k = amplitude * np.sin(th)
        f += hff.response(np.concatenate([r_k, r_k, r_k]))[2 * N:]
    return np.fft.fft(f) / N


def _sampled_steady_state(loop: Loop, amplitude: float, frequency_hz: float, N: int, H: int,
                          tol: float, max_iter: int) -> SteadyState:
    """The hybrid loop's periodic steady state (module docstring), ``f = F / N``."""
    c = loop.sampled
    T, d = c.period, c.delay_samples
    omega = TWO_PI * frequency_hz
    n = np.arange(-H, H + 1)                      # two-sided harmonics of the period
    wn = n * omega
    m_of_n = np.mod(n, N)
    wm = TWO_PI * np.arange(N) / (N * T)          # a representative frequency of each z_m
    parts = loop.sampled_parts
    integrating = parts.zoh.a2 != 0.0 or parts.zoh.a1 != 0.0
    w_dc = np.where(n == 0, 1.0, wn) if integrating else wn   # P(0) is not used then
    P1 = np.asarray(parts.P1(w_dc))
    P2 = np.asarray(parts.P2(w_dc))
    Hn = hold_response(wn, T, d)
    with np.errstate(divide="ignore", invalid="ignore"):   # an integrator's pole at z = 1
        Rm, Ym = c.response(wm)
    with np.errstate(divide="ignore", invalid="ignore"):
        Gm = parts.zoh(wm)
    den = 1.0 + Ym * Gm
    # the linear loop: the fundamental (its careful error) and its images k N +- 1
    R1 = -0.5j * amplitude
    ff = loop.ff
    F1 = 0.0 if ff is None else complex(ff.linear_response(omega)) * np.exp(
        1j * omega * T * ff.advance_samples)
    ud1 = (Rm[1] + F1) * R1 / den[1]
    E_lin = np.zeros(n.size, dtype=complex)
    Y1_lin = np.zeros(n.size, dtype=complex)
    for sign, ud in ((1, ud1), (-1, np.conj(ud1))):
        img = m_of_n == (sign % N)
        E_lin[img] = -P2[img] * Hn[img] * ud
        Y1_lin[img] = P1[img] * Hn[img] * ud
    i1 = H + 1
    E_lin[i1] = loop.transfer("r->e", np.array([omega]))[0] * R1
    E_lin[H - 1] = np.conj(E_lin[i1])
    FF = _feedforward_samples(loop, amplitude, omega, N)
    hyst = loop.hysteresis
    W = np.zeros(H + 1, dtype=complex)

    def respond(W_pos):
        """Y1 and E (two-sided) of the loop with the link's force W and the feedforward's."""
        Wn = np.concatenate([np.conj(W_pos[:0:-1]), W_pos])
        wd2 = np.zeros(N, dtype=complex)
        np.add.at(wd2, m_of_n, np.where(n == 0, 0.0, P2 * Wn))
        with np.errstate(divide="ignore", invalid="ignore"):
            ud = (FF + Ym * wd2) / den
        if integrating:
            ud[0] = Wn[H]                          # no net static force on a free plant
        else:
            ud[0] = (FF[0] + Ym[0] * (wd2[0] + P2[H] * Wn[H])) / den[0]
        U = Hn * ud[m_of_n]
        Y1 = Y1_lin + np.where(n == 0, 0.0, P1 * (U - Wn))
        E = E_lin - np.where(n == 0, 0.0, P2 * (U - Wn))
        # the mean: the controller's static balance at the samples
        static = np.nonzero((m_of_n == 0) & (n != 0))[0]
        y2_images = np.sum(P2[static] * (U[static] - Wn[static]))
        y0 = Ym[0]
        if integrating:
            y2d0 = (FF[0] - Wn[H]) / y0 if np.isfinite(y0) and y0 != 0 else 0.0
            E[H] = -(y2d0 - y2_images)
            Y1[H] = -E[H]     # no net static force: the plant is not deflected, y1 = y2 on mean
        else:
            E[H] = -P2[H] * (U[H] - Wn[H])
            Y1[H] = P1[H] * (U[H] - Wn[H])
        return Y1, E

    def damped(W_pos, Y1, L):
        """The link's force `W_pos` at `Y1` with its part ``L Y1`` (``L = k + j n w c``, 0 at
        ``n = 0``: the damping :func:`viscous_damping`, or the link's spring and dampers
        while it sticks) moved to where the loop's answer puts ``Y1``: the linear loop with
        them solved per alias class (the held force of class ``m`` is one number,
        ``ud[m]``)."""
        Wn = np.concatenate([np.conj(W_pos[:0:-1]), W_pos]) - L * Y1   # L = 0 at n = 0
        a = 1.0 / (1.0 + P1 * L)                   # the direct path with the damper
        free = np.where(n == 0, 0.0, a * (Y1_lin - P1 * Wn))
        gain = np.where(n == 0, 0.0, a * P1 * Hn)
        wd2, A, B = (np.zeros(N, dtype=complex) for _ in range(3))
        np.add.at(wd2, m_of_n, np.where(n == 0, 0.0, P2 * Wn))
        np.add.at(A, m_of_n, P2 * L * free)
        np.add.at(B, m_of_n, P2 * L * gain)
        if not integrating:
            wd2[0] += P2[H] * Wn[H]
        with np.errstate(divide="ignore", invalid="ignore"):
            ud = (FF + Ym * (wd2 + A)) / (den - Ym * B)
        if integrating:
            ud[0] = Wn[H]
        Y1_new = free + gain * ud[m_of_n]
        return (Wn + L * Y1_new)[H:]

    def linear(c, k=0.0):
        """``L = k + j n w c`` (0 at ``n = 0``), or None where it is 0 or makes the loop
        singular."""
        L = np.where(n == 0, 0.0, k + 1j * wn * c)
        if not np.any(L != 0):
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.zeros(H + 1, dtype=complex)
            return L if np.all(np.isfinite(damped(z, np.zeros(n.size), L))) else None

    def passes(L, W, Y1, E):
        """The fixed point from the force `W` (`Y1`, `E` the loop's answer to it), with the
        link's part ``L Y1`` solved with the loop (None: all of it iterated)."""
        previous, residual, it = np.inf, 0.0, 0
        judged = Passes(frequency_hz, hyst, solved=L is not None)
        mixing, limit = Mixing(), Progress(max_iter)
        W_in = W
        while True:
            it += 1
            W_new = hyst.periodic_harmonics(Y1[H:], H, omega)
            if L is not None:
                W_new = damped(W_new, Y1, L)
            change = float(np.max(np.abs(W_new - W)))
            residual = float(abs(W_new[1] - W[1]) / max(abs(W_new[1]), 1e-300))
            W = W_new
            E_old = E[H:]
            Y1, E = respond(W)
            judged.step(E[H:] - E_old, E[H:])
            rho = residual / previous if it > 2 and previous > 0 else 1.0
            previous = residual
            if it > 1 and (change == 0.0 or (rho < 0.5 and residual * rho / (1 - rho) <= tol)):
                break
            if not limit.more(it, residual):
                raise not_converged(frequency_hz, it, residual)
            W_next = mixing.next(W_in, W)
            if W_next is not W:  # a mixed pass: the link moves as the mixture's force says
                Y1 = respond(W_next)[0]
            W_in = W_next
        judged.judge(E[H:])
        return W, Y1, E, it, residual

    Y1, E = respond(W)
    residual, it = 0.0, 0
    if hyst is not None:
        try:
            W, Y1, E, it, residual = passes(linear(viscous_damping(hyst)), W, Y1, E)
        except NoFixedPoint as refusal:
            # a link that sticks: its spring and dampers solved with the loop too, from the
            # loop with the link stuck; where that does not converge either, the first
            # refusal.  Not after a refusal that names the link's damping: no Floquet
            # multipliers check a sampled loop's answer, and the paper's loop at 10 kHz with
            # LuGre sigma1 = 1e6 converged so to e1 = 0.01034 m where a run in time settles
            # on 0.01300 m
            k, c = sticking(hyst)
            L = linear(c, k) if c > viscous_damping(hyst) or k else None
            if L is None:
                raise
            W = damped(np.zeros(H + 1, dtype=complex), np.zeros(n.size), L)
            Y1, E = respond(W)
            try:
                W, Y1, E, it, residual = passes(L, W, Y1, E)
            except FixedPointError:
                raise refusal from None
    return SteadyState(frequency_hz, amplitude, _to_sin_amplitudes(E[H:]),
                       _to_sin_amplitudes(Y1[H:]), _to_sin_amplitudes(W),
                       _to_sin_amplitudes(E_lin[H:]), it, residual, samples_per_period=N)


def steady_state_sweep(loop: Loop, amplitude: float, frequencies_hz: ArrayLike,
                       **kwargs) -> list[SteadyState]:
    """:func:`periodic_steady_state` at each frequency [Hz].

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    amplitude : float
        Reference amplitude ``A_r`` [m].
    frequencies_hz : array_like
        Frequencies [Hz].

    Examples
    --------
    >>> from motionhyst import default_scenario, steady_state_sweep
    >>> states = steady_state_sweep(default_scenario().loop(), 0.01, [5.0, 10.0, 15.0])
    >>> [round(abs(s.mismatch), 3) for s in states]       # eq. (18): 6.040, 1.239, 1.043
    [6.041, 1.24, 1.043]
    """
    return [periodic_steady_state(loop, amplitude, float(f), **kwargs)
            for f in np.atleast_1d(frequencies_hz)]
