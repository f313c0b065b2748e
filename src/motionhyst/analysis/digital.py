"""What the paper's analysis misjudges in a digital loop: a continuous loop beside its sampled twin.

The loop as analysed (continuous controller) against the same controller run
by a real-time computer: discretised (Tustin) at ``sample_rate_hz``, its output
``delay_samples`` late and held, once with the rigid-body feedforward sampled
and delayed with the feedback and once read ``delay + 1/2`` samples ahead (the
delay and the hold's half sample), as machines do.  For each: the margins
(gain, phase, modulus, delay), the mismatch of eq. (18) and, where the
reference's period is a whole number of samples, the exact periodic steady
state (:func:`motionhyst.analysis.steady.periodic_steady_state`): its ``|E|``, the
error's RMS without the link and the RMS the link adds.

Examples
--------
>>> from motionhyst import default_scenario
>>> from motionhyst.analysis.digital import compare_digital
>>> cmp = compare_digital(default_scenario().loop(), 0.01, [10.0])
>>> [round(v.margins.phase_margin_deg, 1) for v in cmp.variants]
[24.8, 16.1, 16.1]
>>> [f"{v.points[0].error_linear_rms:.1e}" for v in cmp.variants]   # 10 Hz: the feedforward's lag
['2.1e-08', '1.3e-06', '2.1e-08']
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from motionhyst.analysis.margins import LoopMargins, loop_margins
from motionhyst.analysis.quasilinear import loop_mismatch
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.loop import Loop
from motionhyst.controllers.sampled import SampledController
from motionhyst.core.jsonio import jsonable
from motionhyst.core.textfmt import g, table

__all__ = ["DigitalComparison", "DigitalPoint", "DigitalVariant", "compare_digital"]


@dataclass(frozen=True)
class DigitalPoint:
    """One reference frequency of one variant.

    Attributes
    ----------
    frequency_hz : float
        Reference frequency [Hz].
    mismatch_df : complex
        ``E`` of eq. (18) (the sampled loop's for a sampled variant).
    mismatch_exact : complex
        ``E`` of the exact periodic steady state (nan when the period is not a
        whole number of samples).
    error_linear_rms : float
        RMS of the error without the link [m] (nan as above).
    error_link_rms : float
        RMS of the error the link adds [m] (nan as above).

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> cmp = compare_digital(default_scenario().loop(), 0.01, [10.0])
    >>> cmp.variants[0].points[0].frequency_hz
    10.0
    """

    frequency_hz: float
    mismatch_df: complex
    mismatch_exact: complex
    error_linear_rms: float
    error_link_rms: float

    def to_dict(self) -> dict:
        """JSON-ready dictionary (None where there is no exact steady state)."""
        return jsonable({"frequency_hz": self.frequency_hz,
                         "mismatch_df_abs": abs(self.mismatch_df),
                         "mismatch_exact_abs": abs(self.mismatch_exact),
                         "error_linear_rms": self.error_linear_rms,
                         "error_link_rms": self.error_link_rms})


@dataclass(frozen=True)
class DigitalVariant:
    """The loop one way: continuous, or sampled with its feedforward's advance.

    Attributes
    ----------
    name : str
        ``"continuous"``, ``"sampled"`` or ``"sampled, feedforward advanced"``.
    margins : LoopMargins
        Gain, phase, modulus and delay margins.
    points : list of DigitalPoint
        One per reference frequency.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> cmp = compare_digital(default_scenario().loop(), 0.01, [10.0])
    >>> cmp.variants[1].name
    'sampled'
    """

    name: str
    margins: LoopMargins
    points: list[DigitalPoint] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {"name": self.name, "margins": jsonable(self.margins.to_dict()),
                "points": [p.to_dict() for p in self.points]}


@dataclass(frozen=True)
class DigitalComparison:
    """Result of :func:`compare_digital`.

    Attributes
    ----------
    sample_rate_hz, delay_samples, advance_samples : float
        The digital loop's rate [Hz], its delay and the feedforward's advance [samples].
    amplitude : float
        Reference amplitude [m].
    variants : list of DigitalVariant
        Continuous, sampled, sampled with the feedforward advanced.

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> cmp = compare_digital(default_scenario().loop(), 0.01, [10.0])   # 10 kHz, 1.5 samples late
    >>> [v.name for v in cmp.variants]
    ['continuous', 'sampled', 'sampled, feedforward advanced']
    >>> [round(v.margins.phase_margin_deg, 1) for v in cmp.variants[:2]]
    [24.8, 16.1]
    """

    sample_rate_hz: float
    delay_samples: float
    advance_samples: float
    amplitude: float
    variants: list[DigitalVariant]

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {"sample_rate_hz": self.sample_rate_hz, "delay_samples": self.delay_samples,
                "advance_samples": self.advance_samples, "amplitude": self.amplitude,
                "variants": [v.to_dict() for v in self.variants]}

    def rows(self) -> tuple[list[str], list[list[str]]]:
        """Header and rows of the comparison table (one column per variant)."""
        head = ["quantity", *(v.name for v in self.variants)]
        m = [v.margins for v in self.variants]
        rows = [["phase margin [deg]", *(f"{x.phase_margin_deg:.2f}" for x in m)],
                ["gain margin [dB]", *(f"{x.gain_margin_db:.3g}" for x in m)],
                ["modulus margin", *(f"{x.modulus_margin:.3g}" for x in m)],
                ["delay margin [ms]", *(f"{x.delay_margin_s * 1e3:.3g}" for x in m)]]
        for i, p in enumerate(self.variants[0].points):
            f = g(p.frequency_hz)
            pts = [v.points[i] for v in self.variants]
            rows += [[f"|E| eq. (18) at {f} Hz", *(g(abs(q.mismatch_df)) for q in pts)],
                     [f"|E| exact at {f} Hz", *(_num(abs(q.mismatch_exact)) for q in pts)],
                     [f"RMS error without link at {f} Hz [m]",
                      *(_num(q.error_linear_rms) for q in pts)],
                     [f"RMS error the link adds at {f} Hz [m]",
                      *(_num(q.error_link_rms) for q in pts)]]
        return head, rows

    def __str__(self) -> str:
        head, rows = self.rows()
        return "\n".join([
            f"Table I's loop continuous and run at {g(self.sample_rate_hz)} Hz with "
            f"{g(self.delay_samples)} samples of delay (Tustin), the feedforward advanced "
            f"{g(self.advance_samples)} samples in the last column; r = {g(self.amplitude)} m",
            table(head, rows)])

    def plot(self, ax=None):
        """``|E|`` of eq. (18) (lines) and exact (circles) of each variant
        (:func:`motionhyst.analysis.figures.plot_digital`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; a new figure when omitted.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from motionhyst.analysis.figures import plot_digital

        return plot_digital(self, ax=ax)


def _num(x: float) -> str:
    return "n/a" if not math.isfinite(x) else g(x)


def compare_digital(loop: Loop, amplitude: float, frequencies_hz, sample_rate_hz: float = 10e3,
                    delay_samples: float = 1.5) -> DigitalComparison:
    """The continuous `loop` beside its controller run at `sample_rate_hz`.

    Parameters
    ----------
    loop : Loop
        A loop with a continuous controller, a plant model and a link.
    amplitude : float
        Reference amplitude [m].
    frequencies_hz : array_like
        Reference frequencies [Hz].
    sample_rate_hz : float
        The digital controller's rate [Hz] (10 kHz).
    delay_samples : float
        Its output's delay [samples] (1.5).

    Returns
    -------
    DigitalComparison

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> cmp = compare_digital(default_scenario().loop(), 0.01, [10.0])   # 10 kHz, 1.5 samples late
    >>> [v.name for v in cmp.variants]
    ['continuous', 'sampled', 'sampled, feedforward advanced']
    >>> [round(v.margins.phase_margin_deg, 1) for v in cmp.variants[:2]]
    [24.8, 16.1]
    """
    if loop.sampled is not None:
        raise ValueError("the loop's controller is already sampled")
    advance = delay_samples + 0.5
    sampled = SampledController.discretize(loop.controller, sample_rate_hz,
                                           delay_samples=delay_samples)
    kwargs = {"hysteresis_feedforward": loop.hysteresis_feedforward, "mass": loop.M}
    ff = loop.ff if loop.ff is not None else None
    base = Feedforward() if ff is None else ff
    loops = [("continuous", loop),
             ("sampled", Loop(loop.plant, sampled, loop.hysteresis, feedforward=base, **kwargs)),
             ("sampled, feedforward advanced",
              Loop(loop.plant, sampled, loop.hysteresis,
                   feedforward=Feedforward(base.mass, base.viscous, base.coulomb, advance),
                   **kwargs))]
    f = [float(x) for x in np.atleast_1d(frequencies_hz)]
    variants = []
    for name, lp in loops:
        E = loop_mismatch(lp, f, amplitude)
        points = []
        for fi, Ei in zip(f, E, strict=True):
            try:
                ss = periodic_steady_state(lp, amplitude, fi)
            except ValueError:        # not a whole number of samples per period
                nan = float("nan")
                points.append(DigitalPoint(fi, complex(Ei), complex(nan, nan), nan, nan))
                continue
            points.append(DigitalPoint(fi, complex(Ei), ss.mismatch, ss.error_linear_rms,
                                       ss.error_hysteresis_rms))
        zoh = None if lp.sampled is None else lp.sampled_parts.zoh
        variants.append(DigitalVariant(name, loop_margins(lp.controller, lp.P2, zoh), points))
    return DigitalComparison(float(sample_rate_hz), float(delay_samples), float(advance),
                             float(amplitude), variants)
