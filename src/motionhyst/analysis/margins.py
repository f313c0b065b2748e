"""Stability margins of the linear loop ``L = C P2`` (without the dynamic link).

The classical margins of the open loop ``L(j omega) = C(j omega) P2(j omega)``
of the paper's Fig. 3 with ``phi = 0``, with the definitions of
:func:`control.stability_margins`:

- gain margin ``1 / |L|`` where ``L`` crosses the negative real axis (phase
  -180 deg mod 360); of several crossings the one nearest 0 dB;
- phase margin ``angle L + 180 deg`` where ``|L| = 1``; of several the
  smallest in magnitude;
- modulus margin ``min |1 + L| = 1 / max |S|``, ``S = 1 / (1 + L)``, the
  distance of the Nyquist curve to -1.

The bandwidth is the crossover frequency: the first (lowest) frequency where
``|L|`` falls through 1 (0 dB), as the paper's ``f_bw = 120 Hz`` for Table I.

With a sampled controller (:class:`~motionhyst.controllers.sampled.SampledController`)
the loop is ``L = Y(z) G_d(z)`` at ``z = e^{j w T}``, ``Y`` the feedback path and
``G_d`` the plant behind the delayed hold (:class:`~motionhyst.core.sampling.ZohEquivalent`),
scanned up to the Nyquist frequency: for a whole number ``d`` of samples of delay
the margins are those :func:`control.stability_margins` gives for
``c2d(P2, T, "zoh") C_d(z) z^-d``.  The delay margin is the extra delay that
brings the loop to the edge of stability, ``PM / w_c`` at each gain crossover
(the smallest), in seconds and, for a sampled loop, in samples.

For LTI systems ``L`` is scanned on a dense logarithmic grid, made denser
around every lightly damped pole and zero of ``C`` and ``P2`` (a resonance
narrower than the grid's spacing, such as the stage's 694 Hz mode with a
damping ratio of 0.0027, would otherwise fall between two points), and each
crossing and the lowest local minima of ``|1 + L|`` are refined by root finding,
so a margin is found wherever the grid brackets it.  For measured data only the
measured lines are evaluated: crossings are interpolated linearly in
``log f`` between the two lines that bracket them and the modulus margin is
the smallest ``|1 + L|`` on the lines (an upper bound of the true one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import control
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq, minimize_scalar

from motionhyst.controllers.sampled import SampledController
from motionhyst.core.lti import TWO_PI, freqresp, tf_poly, trim
from motionhyst.core.sampling import ZohEquivalent

__all__ = ["LoopMargins", "loop_margins"]

BANDWIDTH_DEFINITION = ("crossover frequency: the lowest frequency where |L| = |C P2| falls "
                        "through 1 (0 dB)")
#: Grid density of the scan of an LTI loop [points per decade].
POINTS_PER_DECADE = 400
#: The local minima of ``|1 + L|`` on the grid refined for the modulus margin, lowest first.
REFINED_DIPS = 8
#: Poles and zeros of damping ratio below this get points of their own.
LIGHTLY_DAMPED = 0.1
#: Those points lie either side of ``f_n`` at detunings from 0.01 to ``RESONANCE_SPAN`` damping
#: widths ``zeta f_n`` (at most half of ``f_n``), spaced geometrically, ...
RESONANCE_SPAN = 1e4
#: ... this many a side.
RESONANCE_POINTS = 300


@dataclass(frozen=True)
class LoopMargins:
    """Margins of ``L = C P2`` (see the module docstring for the definitions).

    Attributes
    ----------
    gain_margin : float
        ``1 / |L|`` at the phase crossover [-] (inf without a crossing).
    gain_margin_hz : float
        Its frequency [Hz] (nan without a crossing).
    phase_margin_deg : float
        ``angle L + 180`` at the gain crossover [deg] (inf without a crossing).
    phase_margin_hz : float
        Its frequency [Hz].
    modulus_margin : float
        ``min |1 + L| = 1 / max |S|`` [-].
    modulus_margin_hz : float
        Frequency of ``max |S|`` [Hz].
    bandwidth_hz : float
        Lowest frequency where ``|L|`` falls through 1 [Hz].
    evaluated_on : str
        ``"model"`` (dense grid, refined) or ``"measured lines"``.
    delay_margin_s : float
        Smallest ``PM / w_c`` over the gain crossovers [s] (inf without one).
    sample_rate_hz : float or None
        The sampled controller's rate; None for a continuous loop.
    frequency_hz, open_loop : ndarray or None
        The frequencies [Hz] the margins were searched on and ``L`` there (what
        :meth:`plot` draws); not part of :meth:`to_dict`.

    Examples
    --------
    >>> from motionhyst import LeadLagLowpass, TwoMassStage, loop_margins
    >>> m = loop_margins(LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6),
    ...                  TwoMassStage(5.0, 17.5, 90.0, 7.4e7).P2)
    >>> round(m.gain_margin_db, 2), round(m.gain_margin_hz, 1)
    (9.07, 273.0)
    >>> print(str(m).splitlines()[1])
      phase margin                   24.83 deg at 120.6 Hz
    """

    gain_margin: float
    gain_margin_hz: float
    phase_margin_deg: float
    phase_margin_hz: float
    modulus_margin: float
    modulus_margin_hz: float
    bandwidth_hz: float
    evaluated_on: str = "model"
    delay_margin_s: float = math.inf
    sample_rate_hz: float | None = None
    frequency_hz: NDArray[np.float64] | None = field(default=None, repr=False, compare=False)
    open_loop: NDArray[np.complex128] | None = field(default=None, repr=False, compare=False)

    @property
    def delay_margin_samples(self) -> float | None:
        """The delay margin in samples of a sampled controller (None for a continuous one)."""
        return None if self.sample_rate_hz is None else self.delay_margin_s * self.sample_rate_hz

    @property
    def gain_margin_db(self) -> float:
        """Gain margin in dB, ``20 log10(gain_margin)``."""
        return 20.0 * math.log10(self.gain_margin) if self.gain_margin > 0 else -math.inf

    def to_dict(self) -> dict:
        """JSON-ready dictionary (keys of ``analyze --json``)."""
        return {"gain_margin_db": self.gain_margin_db, "gain_margin_hz": self.gain_margin_hz,
                "phase_margin_deg": self.phase_margin_deg,
                "phase_margin_hz": self.phase_margin_hz,
                "modulus_margin": self.modulus_margin,
                "modulus_margin_hz": self.modulus_margin_hz,
                "bandwidth_hz": self.bandwidth_hz,
                "bandwidth_definition": BANDWIDTH_DEFINITION,
                "margins_evaluated_on": self.evaluated_on,
                "delay_margin_s": self.delay_margin_s,
                **({} if self.sample_rate_hz is None else
                   {"sample_rate_hz": self.sample_rate_hz,
                    "delay_margin_samples": self.delay_margin_samples})}

    def __str__(self) -> str:
        def at(f):
            return "" if not math.isfinite(f) else f" at {f:.4g} Hz"

        def value(x, unit, none):  # never "inf" or "nan" as an answer: what it means instead
            return f"{x:.4g} {unit}" if math.isfinite(x) else none

        gm = self.gain_margin_db
        no_crossover = "unbounded (|C P2| never reaches 1: no gain crossover)"
        return "\n".join([
            f"  gain margin                    "
            f"{value(gm, 'dB', 'unbounded (the phase of C P2 never crosses -180 deg)')}"
            f"{at(self.gain_margin_hz)}",
            f"  phase margin                   {value(self.phase_margin_deg, 'deg', no_crossover)}"
            f"{at(self.phase_margin_hz)}",
            f"  modulus margin 1/max|S|        {self.modulus_margin:.4g}"
            f"{at(self.modulus_margin_hz)}"
            f" (max|S| = {20 * math.log10(1 / self.modulus_margin):.4g} dB)",
            f"  delay margin                   {value(self.delay_margin_s, 's', no_crossover)}"
            + ("" if self.sample_rate_hz is None or not math.isfinite(self.delay_margin_s) else
               f" ({self.delay_margin_samples:.4g} samples at {self.sample_rate_hz:g} Hz)"),
            f"  bandwidth                      "
            f"{value(self.bandwidth_hz, 'Hz', 'none (|C P2| does not fall through 1)')}"
            f" ({BANDWIDTH_DEFINITION})"
            + ("" if self.evaluated_on == "model" else
               f"; evaluated on the {self.evaluated_on} only")])

    def plot(self, ax=None):
        """``|L|`` and ``|S| = 1 / |1 + L|`` against frequency, the bandwidth and the
        modulus margin marked (:func:`motionhyst.analysis.figures.plot_margins`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_margins

        return plot_margins(self, ax=ax)


def _grid_hz(controller, plant) -> NDArray[np.float64]:
    """Frequencies spanning every pole and zero of ``C`` and ``P2`` by two decades."""
    corners = []
    for sys in (controller, plant):
        if sys is None:
            continue
        for poly in tf_poly(sys):
            r = np.abs(np.roots(trim(poly)))
            corners += list(r[r > 0] / TWO_PI)
    lo = min([*corners, 1.0]) / 100.0
    hi = max([*corners, 1.0]) * 100.0
    n = int(np.ceil(POINTS_PER_DECADE * np.log10(hi / lo))) + 1
    return np.geomspace(lo, hi, n)


def _resonances_hz(roots_s: NDArray[np.complex128], nyquist_hz: float | None = None
                   ) -> NDArray[np.float64]:
    """Points around each lightly damped root ``s`` (pole or zero) of the loop.

    ``RESONANCE_POINTS`` a side at detunings from 0.01 to ``RESONANCE_SPAN`` damping widths
    from its natural frequency, geometrically spaced: the Nyquist curve's loop around a light
    resonance passes -1 where the resonance's own term has fallen to about the rest of ``L``,
    which can be many widths away. With a sampling rate, folded into ``(0, nyquist_hz)`` as
    ``z = e^{sT}`` does.
    """
    out = []
    for r in np.asarray(roots_s, dtype=complex):
        wn = abs(r)
        if not np.isfinite(wn) or wn == 0.0:
            continue
        zeta = abs(r.real) / wn
        if zeta >= LIGHTLY_DAMPED:
            continue
        fn = wn / TWO_PI
        z = max(zeta, 1e-9)
        detune = z * np.geomspace(1e-2, min(RESONANCE_SPAN, 0.5 / z), RESONANCE_POINTS)
        pts = fn * np.concatenate([1.0 - detune, [1.0], 1.0 + detune])
        if nyquist_hz is not None:
            pts = np.abs(np.remainder(pts + nyquist_hz, 2.0 * nyquist_hz) - nyquist_hz)
            pts = pts[pts < nyquist_hz * (1.0 - 1e-12)]
        out.append(pts[pts > 0.0])
    return np.concatenate(out) if out else np.empty(0)


def _roots_s(sys) -> NDArray[np.complex128]:
    """Poles and zeros of a python-control SISO system, in ``s`` (a discrete one's through
    ``s = ln(z) / T``)."""
    num, den = tf_poly(sys)
    roots = np.concatenate([np.roots(trim(num)), np.roots(trim(den))]).astype(complex)
    dt = getattr(sys, "dt", 0)
    if dt not in (0, None, True):
        roots = np.log(roots[roots != 0.0]) / float(dt)
    return roots


def loop_margins(controller, plant, zoh: ZohEquivalent | None = None) -> LoopMargins:
    """Gain, phase and modulus margins and the bandwidth of ``L = C P2``.

    Parameters
    ----------
    controller : python-control LTI system or SampledController
        Feedback controller ``C`` (a sampled one: its feedback path ``Y(z)``,
        behind its hold and delay).
    plant : python-control LTI system or FrequencyResponseData
        Non-collocated plant ``P2``; measured data are evaluated at the
        measured lines only (not with a sampled controller).
    zoh : ZohEquivalent, optional
        ``G_d`` of `plant` behind a sampled controller's hold, when already built.

    Returns
    -------
    LoopMargins

    Examples
    --------
    >>> from motionhyst.analysis.margins import loop_margins
    >>> from motionhyst.controllers.leadlag import LeadLagLowpass
    >>> from motionhyst.plants.two_mass import TwoMassStage
    >>> m = loop_margins(LeadLagLowpass(6.2e6, 60.0, 240.0, 700.0, 0.6),
    ...                  TwoMassStage(5.0, 17.5, 90.0, 7.4e7).P2)
    >>> round(m.bandwidth_hz, 1), round(m.phase_margin_deg, 1), round(m.modulus_margin, 3)
    (120.6, 24.8, 0.396)
    """
    data = isinstance(plant, control.FrequencyResponseData)
    sampled = isinstance(controller, SampledController)
    if sampled:
        G = zoh or ZohEquivalent(plant, controller.period, controller.delay_samples)
        nyq = controller.nyquist_hz
        corners = [x for x in _grid_hz(None, plant)[[0, -1]]]
        lo = min(corners[0], nyq * 1e-6)
        n = int(np.ceil(POINTS_PER_DECADE * np.log10(nyq / lo))) + 1
        f = np.geomspace(lo, nyq, n)
        f[-1] = nyq * (1.0 - 1e-12)   # z = -1 itself: L is real there, its phase ambiguous
        roots = np.concatenate([_roots_s(plant), _roots_s(controller.tf())])
        f = np.union1d(f, _resonances_hz(roots, nyq))
        f = f[(f >= lo) & (f <= f[-1])]

        def response(x):
            w = TWO_PI * np.asarray(x, dtype=float)
            return controller.feedback_response(w) * G(w)

        L = response(f)
    elif data:
        w = np.asarray(plant.omega, dtype=float)
        f = w / TWO_PI
        L = freqresp(controller, w) * np.asarray(plant.frdata, dtype=complex).ravel()
    else:
        f = _grid_hz(controller, plant)
        extra = _resonances_hz(np.concatenate([_roots_s(controller), _roots_s(plant)]))
        f = np.union1d(f, extra[(extra > f[0]) & (extra < f[-1])])
        L = freqresp(controller, TWO_PI * f) * freqresp(plant, TWO_PI * f)

    def loop_at(x: float) -> complex:
        if sampled:
            return complex(response(np.array([x]))[0])
        w1 = np.array([TWO_PI * x])
        return complex(freqresp(controller, w1)[0] * freqresp(plant, w1)[0])

    def refine(fun, i: int) -> float:
        """Root of `fun` between grid points i and i + 1 (log-linear for data)."""
        a, b = fun(f[i]), fun(f[i + 1])
        if data:
            t = a / (a - b)
            return float(np.exp(np.log(f[i]) + t * np.log(f[i + 1] / f[i])))
        return float(brentq(fun, f[i], f[i + 1], xtol=1e-13 * f[i], rtol=1e-14))

    def at_lines(values):
        table = dict(zip(f.tolist(), values, strict=True))
        return lambda x: table[x]

    # phase crossovers: Im L changes sign where Re L < 0
    im = L.imag
    im_fun = at_lines(im) if data else (lambda x: loop_at(x).imag)
    idx = np.nonzero((np.sign(im[:-1]) != np.sign(im[1:])) & (L.real[:-1] + L.real[1:] < 0))[0]
    f180 = [refine(im_fun, i) for i in idx]
    if data:
        mag180 = [float(np.exp(np.interp(np.log(x), np.log(f), np.log(np.abs(L)))))
                  for x in f180]
    else:
        mag180 = [abs(loop_at(x)) for x in f180]
    gms = [(1.0 / m, x) for m, x in zip(mag180, f180, strict=True) if m > 0]
    gm, f_gm = (min(gms, key=lambda v: abs(math.log(v[0]))) if gms
                else (math.inf, math.nan))

    # gain crossovers: log|L| changes sign
    lm = np.log(np.abs(L))
    lm_fun = at_lines(lm) if data else (lambda x: math.log(abs(loop_at(x))))
    idx = np.nonzero(np.sign(lm[:-1]) != np.sign(lm[1:]))[0]
    fc = [refine(lm_fun, i) for i in idx]
    if data:
        ph = np.unwrap(np.angle(L))
        pms = [(float(np.remainder(np.degrees(np.interp(np.log(x), np.log(f), ph)), 360.0)
                      - 180.0), x) for x in fc]
    else:
        pms = [(float(np.remainder(np.degrees(np.angle(loop_at(x))), 360.0) - 180.0), x)
               for x in fc]
    pm, f_pm = min(pms, key=lambda v: abs(v[0])) if pms else (math.inf, math.nan)
    # delay margin: the extra delay that turns a gain crossover's phase margin to zero
    dms = [float(np.remainder(p, 360.0)) / 360.0 / x for p, x in pms if x > 0]
    dm = min(dms) if dms else math.inf
    falling = [x for i, x in zip(idx, fc, strict=True) if lm[i] > 0]
    bw = min(falling) if falling else math.nan

    # modulus margin: min |1 + L|, the lowest local minima on the grid refined (far above
    # the loop's dips, where L is small, |1 + L| has minima of rounding by the hundred)
    d = np.abs(1.0 + L)
    i = int(np.argmin(d))
    mm, f_mm = float(d[i]), float(f[i])
    if not data:
        dips = np.flatnonzero((d[1:-1] <= d[:-2]) & (d[1:-1] <= d[2:])) + 1
        for j in dips[np.argsort(d[dips])][:REFINED_DIPS]:
            res = minimize_scalar(lambda x: abs(1.0 + loop_at(x)), bounds=(f[j - 1], f[j + 1]),
                                  method="bounded", options={"xatol": 1e-10 * f[j]})
            if res.fun < mm:
                mm, f_mm = float(res.fun), float(res.x)
    return LoopMargins(gain_margin=float(gm), gain_margin_hz=float(f_gm),
                       phase_margin_deg=float(pm), phase_margin_hz=float(f_pm),
                       modulus_margin=mm, modulus_margin_hz=f_mm, bandwidth_hz=float(bw),
                       evaluated_on="measured lines" if data else "model",
                       delay_margin_s=float(dm),
                       sample_rate_hz=controller.sample_rate_hz if sampled else None,
                       frequency_hz=f, open_loop=L)
