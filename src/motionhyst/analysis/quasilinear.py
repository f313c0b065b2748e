"""Quasi-linear (describing-function) analysis of the loop, paper sections III-C and IV.

The hysteresis ``phi`` is replaced by its describing function ``D`` (eq. 10),
which turns the loop into a linear one whose frequency responses show where
the dynamic link spoils tracking: the quasi-linear plant ``P^phi`` (eq. 12),
the sensitivity ``S1^phi`` (eq. 15), the feedforward mismatch ``E`` (eq. 18)
and its low-frequency asymptote (eq. 20), with the characteristic frequencies
``f*`` (eq. 13) and the crossover of eq. (21).

With a sampled controller the analysis is that of the sampled-data loop:
the controller and the hold are evaluated at ``z = e^{j w T}``, the plant and the
link act in continuous time, and eq. (18) is the ratio of the fundamentals of
the error with and without the link (:meth:`motionhyst.controllers.loop.Loop.transfer`).
What is approximated, besides the describing function itself: the link
acts on the fundamental of ``y1`` only.  The held force also has images at
``w + k F`` (``k != 0``, all above the Nyquist frequency ``F / 2`` for ``f < F / 2``);
they move ``y1`` by ``|P1 H|`` at those frequencies and the link's response to
them is left out, as are the harmonics it generates.  Their aliases at the
samples are kept exactly (``G_d`` sums them in closed form).  For ``f`` above the
Nyquist frequency the same holds (the fundamental is exact for the linear loop),
except at multiples of ``F / 2``, where a sinusoid and its image coincide at the
samples: there the analysis refuses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from motionhyst.analysis.equations import (
    f_star,
    mismatch,
    mismatch_asymptote,
    mismatch_crossover,
    over_error_without_link,
)
from motionhyst.analysis.equations import quasi_linear_plant as quasi_linear_plant
from motionhyst.analysis.equations import sensitivity_s1 as sensitivity_s1
from motionhyst.analysis.margins import LoopMargins, loop_margins
from motionhyst.analysis.plausibility import check_frequency_range, check_plausible
from motionhyst.controllers.loop import Loop
from motionhyst.core.lti import TWO_PI, freqresp
from motionhyst.core.textfmt import g, table
from motionhyst.core.warnings import warn

if TYPE_CHECKING:
    from motionhyst.plants.measured import MeasuredPlant

__all__ = ["MismatchPoint", "QuasiLinearAnalysis", "analyze", "error_harmonics_df",
           "loop_mismatch", "mismatch_crossover_exact"]


@dataclass
class MismatchPoint:
    """The mismatch at one frequency.

    Parameters
    ----------
    frequency_hz : float
        Frequency [Hz].
    value : complex
        The mismatch ``E`` of eq. (18).
    asymptote : complex
        Its asymptote ``E~`` of eq. (20).
    zeta : float
        ``fc / (k A_y1)`` (eq. 4).
    y1_amplitude : float
        Amplitude of ``y1`` the describing function is taken at [m].
    D : complex
        The describing function there [N/m].

    Examples
    --------
    >>> from motionhyst import analyze, default_scenario
    >>> p = analyze(default_scenario().loop(), 0.01, [5.0]).points[0]
    >>> round(abs(p.value), 2), p.zeta                      # |E| of eq. (18), eq. (4)
    (6.04, 0.25)
    """

    frequency_hz: float
    value: complex
    asymptote: complex
    zeta: float
    y1_amplitude: float
    D: complex = complex("nan")

    def to_dict(self) -> dict:
        """JSON-ready dictionary (magnitudes and phases in degrees)."""
        return {"frequency_hz": self.frequency_hz, "abs": abs(self.value),
                "phase_deg": float(np.degrees(np.angle(self.value))),
                "asymptote_abs": abs(self.asymptote), "zeta": self.zeta,
                "y1_amplitude": self.y1_amplitude, "df_re": self.D.real, "df_im": self.D.imag}


@dataclass
class QuasiLinearAnalysis:
    """Result of :func:`analyze`: the paper's quasi-linear numbers for one scenario.

    Attributes
    ----------
    amplitude : float
        Reference amplitude ``A_r`` [m].
    zeta : float
        ``fc / (k A_r)`` (eq. 4), with ``A_y1 = A_r`` as in the paper.
    D : complex
        Describing function at ``A_r`` [N/m] (eq. 10); for a rate-dependent
        element, at the lowest requested frequency (`df_frequency_hz`).
    k_link : float
        Initial stiffness of the dynamic link [N/m].
    f_star_hz : float
        Eq. (13) [Hz].
    bandwidth_hz : float
        First 0 dB crossing of ``C P2`` [Hz].
    mismatch_crossover_hz : float
        Eq. (21) [Hz] (nan without a two-mass model).
    mismatch_crossover_exact_hz : float
        Lowest frequency where ``|E - 1|`` of eq. (18) falls to 1 [Hz]
        (see :func:`mismatch_crossover_exact`).
    points : list of MismatchPoint
        The mismatch at the requested frequencies.
    amplitude_mode : str
        ``"reference"`` or ``"self-consistent"``.
    df_frequency_hz : float or None
        Frequency at which `D` is evaluated [Hz]; None for a rate-independent element.
    margins : LoopMargins or None
        Gain, phase and modulus margins of the linear loop ``C P2``
        (:func:`motionhyst.analysis.margins.loop_margins`).
    unresolved : list of str
        The quantities that are nan and why.  For raw measured data (``use = "data"``):
        frequencies that are not measured lines, lines where ``Pf2 = Pr - P2`` is below
        the data's resolution, eq. (21).  For a model: eq. (21) without a flexible mode,
        and ``E`` of a rigid plant (:data:`NO_ERROR_WITHOUT_LINK`).
    measured : bool
        The plant is raw measured data.
    sampling : str or None
        For a sampled controller: its rate, delay and feedforward advance, and
        what the analysis approximates above the Nyquist frequency.

    Examples
    --------
    >>> from motionhyst import analyze, default_scenario
    >>> res = analyze(default_scenario().loop(), amplitude=0.01, frequencies_hz=[5, 10])
    >>> res.amplitude_mode, len(res.points)
    ('reference', 2)
    >>> d = res.to_dict()                                  # the ``analyze --json`` schema
    >>> round(d["df_phase_deg"], 2)
    50.69
    >>> print(res)                                         # doctest: +ELLIPSIS
      reference amplitude A_r        0.01 m
      zeta = fc/(k A)  (eq. 4)       0.25
    ...
    """

    amplitude: float
    zeta: float
    D: complex
    k_link: float
    f_star_hz: float
    bandwidth_hz: float
    mismatch_crossover_hz: float
    mismatch_crossover_exact_hz: float
    points: list[MismatchPoint] = field(default_factory=list)
    amplitude_mode: str = "reference"
    df_frequency_hz: float | None = None
    margins: LoopMargins | None = None
    unresolved: list[str] = field(default_factory=list)
    sampling: str | None = None
    measured: bool = False

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``analyze --json`` schema)."""
        return {
            "amplitude": self.amplitude,
            "amplitude_mode": self.amplitude_mode,
            "zeta": self.zeta,
            "df_re": self.D.real,
            "df_im": self.D.imag,
            "df_abs_over_k": abs(self.D) / self.k_link,
            "df_phase_deg": float(np.degrees(np.angle(self.D))),
            "df_frequency_hz": self.df_frequency_hz,
            "f_star_hz": self.f_star_hz,
            "bandwidth_hz": self.bandwidth_hz,
            **({} if self.margins is None else
               {k: v for k, v in self.margins.to_dict().items() if k != "bandwidth_hz"}),
            "mismatch_crossover_hz": self.mismatch_crossover_hz,
            "mismatch_crossover_exact_hz": self.mismatch_crossover_exact_hz,
            "mismatch": [p.to_dict() for p in self.points],
            "unresolved": list(self.unresolved),
            **({} if self.sampling is None else {"sampling": self.sampling}),
        }

    def __str__(self) -> str:
        d = self.to_dict()
        has_zeta = self.zeta is not None and math.isfinite(self.zeta)

        def hz(f: float, why: str) -> str:
            return _hz(f, why, bool(self.unresolved))

        lines = [f"  reference amplitude A_r        {g(self.amplitude)} m"]
        if self.sampling is not None:
            lines.insert(0, f"  {self.sampling}")
        if has_zeta:
            lines.append(f"  zeta = fc/(k A)  (eq. 4)       {g(self.zeta)}")
        at = "" if self.df_frequency_hz is None else f" at {g(self.df_frequency_hz)} Hz"
        label = f"|D|/k, angle D  ({'eq. 10' if has_zeta else 'eq. 7'})"
        lines += [f"  {label:<31}{g(d['df_abs_over_k'])}, {d['df_phase_deg']:.2f} deg{at}",
                  f"  f*  (eq. 13)                   {g(self.f_star_hz)} Hz",
                  f"  bandwidth (first |C P2| = 1)   "
                  f"{hz(self.bandwidth_hz, '|C P2| does not fall through 1')} (the crossover "
                  "frequency, where |C P2| falls through 0 dB)",
                  *([] if self.margins is None else str(self.margins).splitlines()[
                      :3 if self.sampling is None else 4]),
                  f"  mismatch crossover (eq. 21)    "
                  f"{hz(self.mismatch_crossover_hz, 'eq. 21 does not give one')}",
                  f"  exact crossover |E - 1| = 1    "
                  f"{hz(self.mismatch_crossover_exact_hz, '|E - 1| does not fall to 1')} "
                  "(eq. 18: where the error the link adds equals the error without it; "
                  "eq. 21 estimates it from the asymptote, eq. 20)",
                  ""]
        rows = [[g(p["frequency_hz"]), g(p["abs"]), f"{20 * math.log10(p['abs']):.2f}",
                 f"{p['phase_deg']:.2f}", g(p["asymptote_abs"]), g(p["y1_amplitude"])]
                for p in d["mismatch"]]
        lines.append(table(["f [Hz]", "|E| [-]", "|E| [dB]", "angle E [deg]", "|E~| (eq. 20)",
                            "A_y1 [m]"], rows))
        if self.unresolved:
            lines += ["", "Not resolved from the raw measured data (nan above; fit the data "
                      'with [plant] use = "fit" to get them):' if self.measured else
                      "Not resolved (nan above):"]
            lines += [f"  - {u}" for u in self.unresolved]
        return "\n".join(lines)

    def plot(self, ax=None):
        """The mismatch ``|E|`` (eq. 18) and its asymptote (eq. 20) at the analysed
        frequencies, with the crossovers (:func:`motionhyst.analysis.figures.plot_analysis`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_analysis

        return plot_analysis(self, ax=ax)


def _hz(f: float, why: str, unresolved: bool) -> str:
    """A frequency for the text, or why there is none (never ``nan Hz``)."""
    if math.isfinite(f):
        return f"{g(f)} Hz"
    return "not resolved (below)" if unresolved else f"none ({why} in the range searched)"


def _parts(loop: Loop, omega: NDArray[np.float64]):
    """Frequency responses C, P1, P2, Pr, Pf2 of the loop at `omega` (C: ``Y(z)`` if sampled)."""
    C = (freqresp(loop.controller, omega) if loop.sampled is None
         else loop.sampled.feedback_response(omega))
    P1 = freqresp(loop.P1, omega)
    P2 = freqresp(loop.P2, omega)
    Pr = 1.0 / (loop.M * (1j * omega) ** 2)
    if loop.plant.Pf2 is not None:  # a model: Pf2 from its own terms, not Pr - P2
        Pf2 = freqresp(loop.plant.Pf2, omega)
    else:
        Pf2 = Pr - P2
    return C, P1, P2, Pr, Pf2


def loop_mismatch(loop: Loop, frequency_hz: ArrayLike, amplitude: float | ArrayLike,
                  reference_amplitude: float | None = None,
                  describing_function: ArrayLike | None = None) -> NDArray[np.complex128]:
    """Mismatch ``E`` of eq. (18) for `loop` at the given frequencies [Hz].

    `amplitude` is the amplitude of ``y1`` that sets ``D``: a scalar, or one
    per frequency.  Rate-dependent elements get ``D(A, omega)``; a `describing_function`
    given (one value per frequency, already computed) is used instead.  With
    hysteresis feedforward the residual mismatch is returned, its model driven
    by the reference of amplitude `reference_amplitude` (default `amplitude`).

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    frequency_hz : array_like
        Frequencies [Hz].
    amplitude : float or array_like
        Amplitude of ``y1`` [m], one or one per frequency.
    reference_amplitude : float, optional
        Amplitude of the reference the feedforward model is driven by [m].
    describing_function : array_like, optional
        ``D`` per frequency, already computed [N/m].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import default_scenario
    >>> np.abs(loop_mismatch(default_scenario().loop(), [5.0, 10.0], 0.01)).round(3).tolist()
    [6.04, 1.239]
    """
    f = np.atleast_1d(np.asarray(frequency_hz, dtype=float))
    omega = TWO_PI * f
    if describing_function is not None:
        D = np.broadcast_to(np.asarray(describing_function, dtype=complex), f.shape)
    else:
        D = loop.hysteresis.describing_function(np.broadcast_to(amplitude, f.shape), omega)
    a_ref = amplitude if reference_amplitude is None else reference_amplitude
    if _paper_loop(loop):
        return mismatch(*_parts(loop, omega), D)
    return residual_mismatch(loop, omega, D, _feedforward_df(loop, a_ref, omega))


def _paper_loop(loop: Loop) -> bool:
    """A continuous loop with the paper's feedforward ``M s^2`` alone: eq. (18) as written."""
    ff = loop.ff
    return (loop.sampled is None and loop.hysteresis_feedforward is None and ff is not None
            and ff.mass == loop.M and not ff.viscous and not ff.coulomb and not ff.jerk
            and not ff.snap)


def _feedforward_df(loop: Loop, amplitude, omega) -> NDArray[np.complex128] | float:
    """The feedforward's nonlinear force per unit reference: ``phi_hat``'s DF and Coulomb's."""
    out = 0.0
    hff = loop.hysteresis_feedforward
    if hff is not None:
        out = out + np.asarray(hff.describing_function(
            np.broadcast_to(amplitude, np.shape(omega)), omega))
    if loop.ff is not None and loop.ff.coulomb:   # eq. (10)'s counterpart: 4j fc / (pi A)
        out = out + 4j * loop.ff.coulomb / (np.pi * np.asarray(amplitude, dtype=float))
    return out


def residual_mismatch(loop: Loop, omega: ArrayLike, D: ArrayLike, D_ff: ArrayLike
                      ) -> NDArray[np.complex128]:
    """Mismatch ``e / e_hat`` left with hysteresis feedforward ``u_ff = M r'' + phi_hat(r)``.

    Quasi-linear: ``w = D y1`` and ``phi_hat(r) = D_ff r``, so
    ``y1 = (T_ry1 + T_fy1 D_ff) / (1 - T_wy1 D) r`` and
    ``e = T_re r + T_we D y1 + T_fe D_ff r``; ``e_hat = T_re r`` is the error
    without hysteresis and without its feedforward.  ``T_f`` is the path of a
    force added to the controller's output (``T_f = -T_w`` for a continuous
    controller; sampled, advanced and held with it for a sampled one).  With
    ``D_ff = 0`` this is eq. (18).
    """
    w = np.asarray(omega, dtype=float)
    t_re, t_ry1 = loop.transfer("r->e", w), loop.transfer("r->y1", w)
    t_we, t_wy1 = loop.transfer("w->e", w), loop.transfer("w->y1", w)
    D, D_ff = np.asarray(D), np.asarray(D_ff)
    if loop.sampled is None:
        y1 = (t_ry1 - t_wy1 * D_ff) / (1.0 - t_wy1 * D)
        return 1.0 + over_error_without_link(t_we * (D * y1 - D_ff), t_re)
    t_fe, t_fy1 = loop.transfer("f->e", w), loop.transfer("f->y1", w)
    y1 = (t_ry1 + t_fy1 * D_ff) / (1.0 - t_wy1 * D)
    return 1.0 + over_error_without_link(t_we * D * y1 + t_fe * D_ff, t_re)


def error_harmonics_df(loop: Loop, amplitude: float, frequency_hz: float, n_max: int = 5,
                       amplitude_mode: str = "reference") -> NDArray[np.complex128]:
    """Quasi-linear prediction of the error's harmonics 1 .. n_max [m], relative to sin(n w t).

    The first harmonic is ``E e_hat`` (eq. 18 times the linear error); harmonic
    ``n >= 2`` is the n-th harmonic of the hysteresis force for
    ``y1 = A_y1 sin(omega t + phi)``, from the higher-order describing function
    ``H_n(A_y1)``, passed through ``P2 / (1 + C P2)`` at ``n omega``.  ``phi`` is
    the phase of the linear loop's ``y1``; ``A_y1 = A_r`` (``"reference"``) or
    the quasi-linear loop's solution (``"self-consistent"``).

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    amplitude : float
        Reference amplitude ``A_r`` [m].
    frequency_hz : float
        Frequency [Hz].
    n_max : int
        Highest harmonic.
    amplitude_mode : {"reference", "self-consistent"}
        How ``A_y1`` is taken (see above).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import default_scenario
    >>> h = error_harmonics_df(default_scenario().loop(), 0.01, 5.0)
    >>> (np.abs(h[:3]) * 1e9).round(3).tolist()            # |e_1|, |e_2|, |e_3| [nm]
    [11.224, 0.0, 2.575]
    """
    omega = TWO_PI * float(frequency_hz)
    n = np.arange(1, int(n_max) + 1)
    t_ry1 = complex(loop.transfer("r->y1", np.array([omega]))[0])
    a_y1 = (amplitude if amplitude_mode == "reference"
            else self_consistent_amplitude(loop, frequency_hz, amplitude))
    phi = np.angle(t_ry1)
    H = np.asarray(loop.hysteresis.hosidf(a_y1, int(n_max), omega)).ravel()
    w_n = H * a_y1 * np.exp(1j * n * phi)
    hff = loop.hysteresis_feedforward
    if hff is not None:  # phi_hat(r), r = A_r sin(omega t)
        w_n = w_n - np.asarray(hff.hosidf(amplitude, int(n_max), omega)).ravel() * amplitude
    e = loop.transfer("w->e", n * omega) * w_n
    e_hat = complex(loop.transfer("r->e", np.array([omega]))[0]) * amplitude
    e[0] = complex(loop_mismatch(loop, [frequency_hz], a_y1, amplitude)[0]) * e_hat
    return e


def self_consistent_amplitude(loop: Loop, frequency_hz: float, amplitude: float,
                              tol: float = 1e-12, max_iter: int = 200) -> float:
    """Amplitude of ``y1`` in the quasi-linear loop, solved with ``w = D(A_y1) y1``.

    ``y1 = (T_ry1 + T_fy1 D_ff) / (1 - T_wy1 D) r`` (``D_ff`` of a hysteresis or
    Coulomb feedforward, else 0; ``T_fy1 = -T_wy1`` for a continuous controller);
    iterated on ``A_y1`` starting at ``A_r``.
    """
    omega = TWO_PI * float(frequency_hz)
    t_r = complex(loop.transfer("r->y1", np.array([omega]))[0])
    t_w = complex(loop.transfer("w->y1", np.array([omega]))[0])
    t_f = complex(loop.transfer("f->y1", np.array([omega]))[0])
    D_ff = complex(np.asarray(_feedforward_df(loop, amplitude, omega)).ravel()[0])
    a = amplitude
    for _ in range(max_iter):
        D = complex(np.asarray(loop.hysteresis.describing_function(a, omega)).ravel()[0])
        a_new = abs((t_r + t_f * D_ff) / (1.0 - t_w * D)) * amplitude
        if abs(a_new - a) <= tol * a_new:
            return float(a_new)
        a = a_new
    raise RuntimeError(f"self-consistent amplitude did not converge at {frequency_hz} Hz")


def mismatch_crossover_exact(loop: Loop, amplitude: float, f_min: float = 1e-2,
                       f_max: float = 1e4) -> float:
    """Exact counterpart of the crossover of eq. (21) [Hz]: lowest f where ``|E - 1| = 1``.

    ``E - 1 = (e - e_hat) / e_hat`` is the error that the hysteresis adds,
    relative to the error without it; eq. (20) is its low-frequency
    asymptote, and eq. (21) solves ``|E~| = 1``.  This solves the same
    condition on eq. (18) itself, with ``D`` at the given amplitude.  (``|E|``
    itself tends to 1 from above as frequency grows and does not cross 1 in
    any meaningful place.)  Returns nan if there is no crossing in the range.

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    amplitude : float
        Reference amplitude ``A_r`` [m].
    f_min : float
        Lower end of the search [Hz].
    f_max : float
        Upper end of the search [Hz].

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> round(mismatch_crossover_exact(default_scenario().loop(), 0.01), 3)  # eq. (21): 7.61 Hz
    7.606
    """
    lo, hi = loop.plant.frequency_range_hz or (f_min, f_max)
    f_min, f_max = max(f_min, lo), min(f_max, hi)
    if loop.sampled is not None:  # below the Nyquist frequency (the sampled loop repeats above)
        f_max = min(f_max, loop.sampled.nyquist_hz * (1.0 - 1e-9))
    # a fine grid for closed-form D; a coarser one where each D is a periodic solve,
    # scanned upwards so that frequencies above the first crossing are never evaluated
    per_decade = 500 if loop.hysteresis.rate_independent else 40
    n = max(2, int(np.ceil(per_decade * np.log10(f_max / f_min))) + 1)
    f = np.geomspace(f_min, f_max, n)

    def g(x):  # -inf where the link changes nothing (E = 1 to the last bit): no crossing
        with np.errstate(divide="ignore"):
            return np.log(np.abs(loop_mismatch(loop, x, amplitude) - 1.0))

    chunk = 64
    for start in range(0, n - 1, chunk):
        fs = f[start:start + chunk + 1]
        v = g(fs)
        idx = np.nonzero((v[:-1] > 0) & (v[1:] <= 0))[0]
        if idx.size:
            i = idx[0]
            return float(brentq(lambda x: float(g(np.array([x]))[0]), fs[i], fs[i + 1],
                                xtol=1e-12))
    return float("nan")


def analyze(loop: Loop, amplitude: float, frequencies_hz: ArrayLike,
            amplitude_mode: str = "reference") -> QuasiLinearAnalysis:
    """The paper's quasi-linear analysis of `loop` for ``r = A sin(2 pi f t)``.

    Parameters
    ----------
    loop : Loop
        Loop with a hysteresis element and rigid-body feedforward.
    amplitude : float
        Reference amplitude ``A_r`` [m].
    frequencies_hz : array_like
        Frequencies at which to report the mismatch [Hz].
    amplitude_mode : {"reference", "self-consistent"}
        ``"reference"`` takes ``A_y1 = A_r`` as the paper does; ``"self-consistent"``
        solves the amplitude of ``y1`` in the quasi-linear loop per frequency.

    Returns
    -------
    QuasiLinearAnalysis

    Warns
    -----
    MotionhystWarning
        Where the paper's quasi-linear reading stops holding (a frequency below
        ``f*``, a link that never slips, a frequency outside measured data):
        :func:`~motionhyst.analysis.plausibility.check_plausible`.

    Examples
    --------
    Table I at 10 mm (the paper's section V):

    >>> from motionhyst import analyze, default_scenario
    >>> loop = default_scenario().loop()
    >>> res = analyze(loop, amplitude=0.01, frequencies_hz=[5, 10, 15])
    >>> res.zeta                                           # eq. (4)
    0.25
    >>> print(f"|D|/k = {abs(res.D) / res.k_link:.3f}, f* = {res.f_star_hz:.3f} Hz")
    |D|/k = 0.309, f* = 0.150 Hz
    >>> print(f"crossover {res.mismatch_crossover_hz:.2f} Hz")   # eq. (21); the paper: 7.6 Hz
    crossover 7.61 Hz
    >>> [round(abs(p.value), 3) for p in res.points]       # |E| of eq. (18) at 5, 10, 15 Hz
    [6.04, 1.239, 1.043]
    """
    if loop.hysteresis is None:
        raise ValueError("the loop has no hysteresis element")
    if loop.feedforward != "rigid-body":
        raise ValueError("the mismatch of eq. (18) is defined for rigid-body feedforward")
    if amplitude_mode not in ("reference", "self-consistent"):
        raise ValueError("amplitude_mode must be 'reference' or 'self-consistent'")
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise ValueError("amplitude must be finite and > 0")
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError("frequencies must be finite and > 0")

    check_frequency_range(loop, f)
    check_plausible(loop, amplitude, f)
    sampling = None if loop.sampled is None else _sampling_note(loop, f)
    hyst = loop.hysteresis
    k_link = hyst.initial_stiffness
    omega = TWO_PI * f
    if amplitude_mode == "reference":
        amps = np.full(f.shape, float(amplitude))
    else:
        amps = np.array([self_consistent_amplitude(loop, fi, amplitude) for fi in f])
    D_pts = np.asarray(hyst.describing_function(amps, omega), dtype=complex)
    C, P1, P2, Pr, Pf2 = _parts(loop, omega)
    # raw measured lines where Pf2 = Pr - P2 is 0 give no E: named as unresolved below
    with np.errstate(**({} if loop.plant.is_lti else {"divide": "ignore", "invalid": "ignore"})):
        if _paper_loop(loop):
            E = mismatch(C, P1, P2, Pr, Pf2, D_pts)
        else:
            E = residual_mismatch(loop, omega, D_pts, _feedforward_df(loop, amplitude, omega))
        Et = mismatch_asymptote(Pr, Pf2, D_pts)
    zetas = np.asarray(hyst.zeta(amps)) if hyst.defines_zeta else np.full(f.shape, np.nan)
    f_df = None if hyst.rate_independent else float(np.min(f))
    D_ref = complex(np.asarray(hyst.describing_function(
        amplitude, None if f_df is None else TWO_PI * f_df)).ravel()[0])
    zeta_ref = float(hyst.zeta(amplitude)) if hyst.defines_zeta else float("nan")
    q = _stiffness_over_masses(loop.plant)
    crossover = (float("nan") if q is None
                 else _crossover_estimate(q, hyst, amplitude, D_ref))
    margins = loop_margins(loop.controller, loop.P2,
                           None if loop.sampled is None else loop.sampled_parts.zoh)
    unresolved: list[str] = []
    if not loop.plant.is_lti:  # measured lines
        E, Et, amps = E.copy(), Et.copy(), amps.copy()
        unresolved = _measured_limits(loop.plant, f, P2, Pf2, E, Et, amps)
        crossover_exact, why = _crossover_exact_on_lines(loop, amplitude)
        unresolved += [why] if why else []
        unresolved.append("eq. (21): needs Pf2(0) from a model of the plant "
                          '([plant] use = "fit")')
        bandwidth_hz = margins.bandwidth_hz
    else:
        crossover_exact = mismatch_crossover_exact(loop, amplitude)
        bandwidth_hz = loop.bandwidth_hz()
        if not math.isfinite(bandwidth_hz):  # a plant or a gain off by orders of magnitude?
            warn(f"|C P2| does not fall through 1 in the range searched: the loop has no "
                 f"bandwidth; are the moving mass M = {g(loop.M)} kg and the controller's gain "
                 f"what was meant?")
        if np.any(np.asarray(Pf2) == 0):  # e_hat = 0: E is nan, not inf (eqs. 18, 20)
            unresolved.append(NO_ERROR_WITHOUT_LINK.format(plant=loop.plant.name))
        if q is None:  # eq. (21) does not apply: say so rather than print nan
            unresolved.append(f"eq. (21): needs a flexible mode with a static compliance "
                              f"Pf2(0) > 0 (the two-mass stage's m1 m2 / (k M^2)); the "
                              f"{loop.plant.name} plant has none")
    points = [MismatchPoint(float(fi), complex(e), complex(et), float(z), float(a), complex(d))
              for fi, e, et, z, a, d in zip(f, E, Et, np.broadcast_to(zetas, f.shape), amps,
                                            np.broadcast_to(D_pts, f.shape), strict=True)]
    return QuasiLinearAnalysis(
        amplitude=float(amplitude), zeta=zeta_ref, D=D_ref, k_link=k_link,
        f_star_hz=f_star(k_link, loop.M), bandwidth_hz=bandwidth_hz, margins=margins,
        mismatch_crossover_hz=crossover, mismatch_crossover_exact_hz=crossover_exact,
        points=points, amplitude_mode=amplitude_mode, df_frequency_hz=f_df,
        unresolved=unresolved, sampling=sampling, measured=not loop.plant.is_lti)


def _sampling_note(loop: Loop, f: NDArray[np.float64]) -> str:
    """What the analysis of a sampled loop is of, and what it approximates (module docstring)."""
    c = loop.sampled
    nyq = c.nyquist_hz
    k = f / nyq
    on = np.abs(k - np.round(k)) <= 1e-9 * np.maximum(k, 1.0)
    if np.any(on):
        raise ValueError(f"{f[on][0]:g} Hz is a multiple of the Nyquist frequency {nyq:g} Hz "
                         f"of the controller sampled at {c.sample_rate_hz:g} Hz: a sinusoid and "
                         "its image have the same samples there; take another frequency")
    adv = 0.0 if loop.ff is None else loop.ff.advance_samples
    above = ("" if np.all(f < nyq) else
             f"; {int(np.sum(f > nyq))} frequencies above the Nyquist frequency: their "
             "fundamental only")
    return (f"sampled at {c.sample_rate_hz:g} Hz, {c.delay_samples:g} samples of delay, "
            f"feedforward advanced {adv:g} samples: controller and hold at z = e^(jwT), plant and "
            f"link continuous; the link acts on the fundamental of y1 only (the held force's "
            f"images at f + k {c.sample_rate_hz:g} Hz reach the plant without it){above}")


#: Why ``E`` and ``E~`` (eqs. 18, 20) are nan for a rigid plant (its name for ``{plant}``).
NO_ERROR_WITHOUT_LINK = ("E and E~ (eqs. 18, 20): not defined: the {plant} plant has no "
                         "flexible part (Pf2 = Pr - P2 = 0), so its rigid-body feedforward "
                         "leaves no error without the link (e_hat = 0) to compare the link's "
                         "error with; the steady state's e1 is that error")
#: ``Pf2 = Pr - P2`` counts as resolved by data where ``|Pf2| / |P2|`` exceeds this many times
#: the data's relative scatter (three standard deviations).
RESOLUTION_FACTOR = 3.0


def resolved_lines(plant: MeasuredPlant, P2, Pf2) -> NDArray[np.bool_]:
    """Where ``|Pf2| / |P2|`` exceeds 3 x the data's resolution (everywhere if it is unknown)."""
    ratio = np.abs(Pf2) / np.abs(P2)
    if plant.resolution is None:
        return np.ones_like(ratio, bool)
    return ratio > RESOLUTION_FACTOR * plant.resolution


def _measured_limits(plant: MeasuredPlant, f, P2, Pf2, E, Et, amps) -> list[str]:
    """Blank (nan) the mismatch where raw data cannot give it; say why, per frequency."""
    out = []
    ok = resolved_lines(plant, P2, Pf2)
    lines = plant.frequency_hz
    for i, fi in enumerate(f):
        if plant.measured_line(fi) is None:
            near = lines[np.argmin(np.abs(lines - fi))]
            out.append(f"E and E~ at {fi:g} Hz: not a measured frequency (nearest line "
                       f"{near:.4g} Hz); raw data are evaluated at the measured lines only")
        elif not ok[i]:
            out.append(f"E and E~ at {fi:g} Hz: Pf2 = Pr - P2 is {abs(Pf2[i] / P2[i]):.2g} of "
                       f"P2, not above 3 x the data's resolution {plant.resolution:.2g}")
        else:
            continue
        E[i] = Et[i] = amps[i] = np.nan
    return out


def _crossover_exact_on_lines(loop: Loop, amplitude: float) -> tuple[float, str]:
    """``|E - 1| = 1`` from the measured lines (log-linear between the two that bracket it)."""
    plant = loop.plant
    f = plant.frequency_hz
    with np.errstate(divide="ignore", invalid="ignore"):  # lines where Pf2 = Pr - P2 is 0
        g = np.log(np.abs(loop_mismatch(loop, f, amplitude) - 1.0))
    idx = np.nonzero((g[:-1] > 0) & (g[1:] <= 0))[0]
    if idx.size == 0:
        return float("nan"), ""
    i = int(idx[0])
    _, _, P2, _, Pf2 = _parts(loop, TWO_PI * f[i:i + 2])
    if not np.all(resolved_lines(plant, P2, Pf2)):
        return float("nan"), (f"exact crossover |E - 1| = 1: between the lines {f[i]:.4g} and "
                              f"{f[i + 1]:.4g} Hz Pf2 = Pr - P2 is not above 3 x the data's "
                              f"resolution {plant.resolution:.2g}")
    t = g[i] / (g[i] - g[i + 1])
    return float(np.exp(np.log(f[i]) + t * np.log(f[i + 1] / f[i]))), ""


#: Fixed-point iterations of eq. (21) for a rate-dependent element (each one evaluation of D).
CROSSOVER_MAX_ITERATIONS = 50


def _stiffness_over_masses(plant) -> float | None:
    """``k / (m1 m2)`` of eq. (21), ``1 / (M^2 Pf2(0))``; None for a plant without a static
    flexible compliance ``Pf2(0) > 0`` (data, a single mass, ground dampers).

    Eq. (21) solves ``|Pr^2 D / Pf2| = 1`` with ``Pf2`` at its static value;
    for the two-mass stage ``M^2 Pf2(0) = m1 m2 / k``.
    """
    pf2 = plant.pf2_static
    if pf2 is None or not pf2 > 0:
        return None
    return 1.0 / (plant.M**2 * pf2)


def _crossover_estimate(q: float, hyst, amplitude: float, D: complex) -> float:
    """Eq. (21) with ``q = k / (m1 m2)``; rate-dependent elements take ``D`` at the crossover."""
    fc = mismatch_crossover(q, 1.0, 1.0, abs(D))
    if hyst.rate_independent:
        return fc
    for _ in range(CROSSOVER_MAX_ITERATIONS):
        D = complex(np.asarray(hyst.describing_function(amplitude, TWO_PI * fc)).ravel()[0])
        f_new = mismatch_crossover(q, 1.0, 1.0, abs(D))
        if abs(f_new - fc) <= 1e-12 * f_new:
            return f_new
        change, fc = abs(f_new - fc), f_new
    raise RuntimeError(f"eq. (21) with D(A, omega) at the crossover did not converge in "
                       f"{CROSSOVER_MAX_ITERATIONS} iterations: last estimate {fc:.6g} Hz, "
                       f"last change {change:.3g} Hz")
