"""Outputs of a study: named functions of one point, extendable with :func:`register_output`.

Each output gives one or more fields, each a real or a complex number.  A point is a
:class:`Point`: the loop at the point's scenario keys, the reference's amplitude and
frequency, and the exact periodic steady state (computed at the first output that needs it,
then shared).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used: reading a study file needs neither
    from motionhyst.analysis.steady import SteadyState
    from motionhyst.controllers.loop import Loop

__all__ = ["OUTPUTS", "Output", "Point", "register_output"]


@dataclass
class Point:
    """One point of a study: a loop and the reference ``r = amplitude sin(2 pi f t)``.

    Parameters
    ----------
    loop : Loop
        The loop of the point's scenario keys.
    amplitude : float
        Reference amplitude [m].
    frequency_hz : float
        Reference frequency [Hz].
    scan : dict, optional
        The settings of the point's scan (:mod:`motionhyst.study.scans`), for the output
        ``scan``.
    unset_terms : tuple of str
        The stage terms (``jerk``, ``snap``) the scenario's ``[feedforward]`` leaves unset
        (a scan's model feedforward takes the plant's).

    Examples
    --------
    >>> from motionhyst import default_scenario
    >>> p = Point(default_scenario().loop(), amplitude=0.01, frequency_hz=5.0)
    >>> print(f"|E_sim| = {abs(OUTPUTS['mismatch'].evaluate(p)['mismatch']):.3f}")
    |E_sim| = 6.041
    """

    loop: Loop
    amplitude: float
    frequency_hz: float
    scan: dict | None = None
    unset_terms: tuple[str, ...] = ()
    _steady: SteadyState | None = field(default=None, init=False, repr=False)

    @property
    def steady(self) -> SteadyState:
        """The exact periodic steady state (eq. 18's exact counterpart), computed once; a loop
        that hunts is refused saying so."""
        if self._steady is None:
            from motionhyst.analysis.hunting import steady_state_unless_hunting

            self._steady = steady_state_unless_hunting(self.loop, self.amplitude,
                                                       self.frequency_hz)
        return self._steady


@dataclass(frozen=True)
class Output:
    """A named function of one point.

    Attributes
    ----------
    name : str
        The name a study file lists.
    fields : dict of str to str
        The fields it gives and their kind, ``"complex"`` or ``"real"``.
    function : callable
        ``function(point) -> dict`` of field name to value.
    description : str
        One line, with its unit.

    Examples
    --------
    >>> OUTPUTS["e1"].fields
    {'e1': 'complex'}
    """

    name: str
    fields: dict[str, str]
    function: Callable[[Point], dict]
    description: str

    def evaluate(self, point: Point) -> dict:
        """The fields at `point`.

        Parameters
        ----------
        point : Point
            The point to evaluate.
        """
        return self.function(point)


OUTPUTS: dict[str, Output] = {}
"""The registry of outputs, by name."""


def register_output(name: str, fields: dict[str, str], description: str
                    ) -> Callable[[Callable[[Point], dict]], Callable[[Point], dict]]:
    """Register ``function(point) -> {field: value}`` as the output `name` (a decorator).

    Parameters
    ----------
    name : str
        The output's name (a study file's ``outputs`` entry).
    fields : dict of str to str
        Field name to its kind, ``"float"`` or ``"complex"``.
    description : str
        One line for the documentation and ``study --help``.

    Examples
    --------
    >>> @register_output("y1_amplitude", {"y1_amplitude": "real"},
    ...                  "first harmonic of the link's displacement [m]")
    ... def _y1(point):
    ...     return {"y1_amplitude": abs(point.steady.y1[1])}
    >>> "y1_amplitude" in OUTPUTS
    True
    >>> del OUTPUTS["y1_amplitude"]
    """
    bad = [k for k in fields.values() if k not in ("real", "complex")]
    if bad:
        raise ValueError(f"field kinds are 'real' or 'complex', got {bad[0]!r}")

    def wrap(function: Callable[[Point], dict]) -> Callable[[Point], dict]:
        OUTPUTS[name] = Output(name, dict(fields), function, description)
        return function

    return wrap


@register_output("e1", {"e1": "complex"},
                 "first harmonic of the tracking error, relative to sin(omega t) [m]")
def _e1(p: Point) -> dict:
    return {"e1": complex(p.steady.e[1])}


@register_output("harmonics", {"e2": "complex", "e3": "complex", "e5": "complex"},
                 "harmonics 2, 3 and 5 of the tracking error [m]")
def _harmonics(p: Point) -> dict:
    e = p.steady.e
    return {f"e{n}": complex(e[n]) if n < len(e) else 0j for n in (2, 3, 5)}


@register_output("mismatch", {"mismatch": "complex"},
                 "exact mismatch E_sim = e1 / e1_linear (compare eq. 18) [-]")
def _mismatch(p: Point) -> dict:
    return {"mismatch": p.steady.mismatch}  # nan where e1_linear = 0


@register_output("error_rms", {"error_rms": "real"}, "RMS of the error over a period [m]")
def _error_rms(p: Point) -> dict:
    return {"error_rms": p.steady.error_rms}


@register_output("error_peak", {"error_peak": "real"}, "largest |e| over a period [m]")
def _error_peak(p: Point) -> dict:
    return {"error_peak": p.steady.error_peak}


@register_output("E", {"E": "complex"},
                 "quasi-linear mismatch of eq. (18), D at the reference amplitude [-]")
def _quasi_linear(p: Point) -> dict:
    from motionhyst.analysis.quasilinear import loop_mismatch

    if p.loop.hysteresis is None:
        raise ValueError("the loop has no hysteresis element")
    return {"E": complex(loop_mismatch(p.loop, p.frequency_hz, p.amplitude)[0])}


@register_output("scan", {"ma_max": "real", "msd_max": "real", "peak_error": "real",
                          "settling_time_s": "real"},
                 "largest |MA| and MSD over the constant-velocity phases and the peak error [m], "
                 "settling time [s] of the study's scan ([scan], as motionhyst scan)")
def _scan(p: Point) -> dict:
    if p.scan is None:
        raise ValueError("the output 'scan' needs the study's [scan] settings")
    from motionhyst.study.scans import run_point_scan

    return run_point_scan(p.loop, p.scan, p.unset_terms)


_MARGINS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@register_output("margins", {"gain_margin_db": "real", "phase_margin_deg": "real",
                             "modulus_margin": "real", "bandwidth_hz": "real"},
                 "gain [dB], phase [deg] and modulus [-] margins and the bandwidth [Hz] of the "
                 "linear loop L = C P2 (the same at every amplitude and frequency)")
def _margins(p: Point) -> dict:
    # computed once a loop: the points of one loop (its amplitudes and frequencies) share it
    m = _MARGINS.get(p.loop)
    if m is None:
        from motionhyst.analysis.margins import loop_margins

        loop = p.loop
        m = loop_margins(loop.controller, loop.P2,
                         None if loop.sampled is None else loop.sampled_parts.zoh)
        _MARGINS[loop] = m
    return {"gain_margin_db": m.gain_margin_db, "phase_margin_deg": m.phase_margin_deg,
            "modulus_margin": m.modulus_margin, "bandwidth_hz": m.bandwidth_hz}


def fields_of(names: list[str]) -> dict[str, str]:
    """The fields of the outputs `names`, in order.

    Examples
    --------
    >>> fields_of(["e1", "error_rms"])
    {'e1': 'complex', 'error_rms': 'real'}
    """
    out: dict[str, str] = {}
    for n in names:
        out.update(OUTPUTS[n].fields)
    return out


def nan_of(kind: str):
    """The value of a field at a point that failed."""
    return complex(np.nan, np.nan) if kind == "complex" else np.nan
