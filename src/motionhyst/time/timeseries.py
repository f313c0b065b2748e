"""Long transient runs written as they are computed, and summaries that separate the start-up.

:func:`run_time_series` drives :func:`motionhyst.time.simulation.simulate_chunks`:
the integration step follows the loop's dynamics (and a built-in reference's
own time scale), never the sample rate of a reference file; rows are written
at the output rate only, chunk by chunk, so memory stays bounded whatever the
duration.  The summary answers what the run is for:

- a sine: peak and RMS error over the last full period, with and without
  hysteresis (the start-up transient of a run from rest is excluded; the
  paper's steady-state comparison, section V);
- a point-to-point move: peak error while moving, settling time into a band
  after the move ends, and the final error, with and without hysteresis;
- any reference: the peak error over the whole run and the final error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.budget import check_memory, max_memory
from motionhyst.core.textfiles import csv_header, csv_rows
from motionhyst.time.references import (
    PointToPoint,
    SampledReference,
    SineReference,
    reference_bytes,
)
from motionhyst.time.steps import (
    RUN_REMEDY,
    SAMPLED_SAMPLE_BYTES,
    a_run,
    pole_step,
    step_set_by,
    time_series_grid,
)

if TYPE_CHECKING:  # the simulation (python-control, numba) loads when a run starts: the
    # command's checks of its run (time_series_grid) come before it
    from motionhyst.controllers.loop import Loop
    from motionhyst.time.simulation import Simulation

DEFAULT_OUTPUT_RATE_HZ = 10_000.0
"""Output rate of built-in references (sines, profiles) unless one is asked for [Hz]."""

DEFAULT_SETTLE_BAND = 10e-9
"""Half-width of the settling band of a point-to-point move [m] (10 nm)."""

ROWS_PER_CHUNK = 8192
"""Output rows computed and written at a time."""

MAX_CHUNK = 1 << 18
"""Most integration samples computed at a time (65.5 MB as sized, 52.5 traced), however many a
row holds."""

MIN_CHUNK = 4096
"""Fewest integration samples computed at a time where the memory budget holds no more."""

CHUNK_SAMPLE_BYTES = 250
"""Memory of :func:`run_time_series` (a continuous loop) per integration sample of a chunk: the
signals of the chunk written and of the next one computed, the loop's intermediate arrays
and the rows [bytes] (measured, Table I with a file's reference, runs of three chunks or more:
200-211 traced a sample of a chunk of 24576 and of 262144; 20 % above)."""

COLUMNS = ("time", "reference", "error", "y1", "y2", "u", "w", "error_linear")
"""Columns of the CSV, in order (as :meth:`motionhyst.time.simulation.Simulation.columns`)."""


def dynamics_step(loop: Loop, reference) -> float:
    """Integration step [s] from the loop's fastest pole and a built-in reference's time scale.

    A sampled reference (a file) is interpolated between its samples and does
    not set the step: a 10 kHz file does not force 400 steps per sample.  A
    loop with a sampled controller runs at the controller's period.

    Parameters
    ----------
    loop : Loop
        The loop with its link.
    reference : reference
        The reference run.

    Examples
    --------
    >>> from motionhyst.scenario import default_scenario
    >>> from motionhyst.time.references import SineReference
    >>> loop = default_scenario().loop()
    >>> h = dynamics_step(loop, SineReference(0.01, 5.0))
    >>> 1e-6 < h < 1e-4
    True
    """
    if loop.sampled is not None:
        return loop.sampled.period
    return pole_step(float(np.max(np.abs(loop.closed_loop_poles()))),
                     _reference_frequency(reference))


def _reference_frequency(reference) -> float:
    """The highest frequency of a built-in reference [Hz]; 0 for a file's (it does not set
    the step) or none."""
    return 0.0 if isinstance(reference, SampledReference) else float(
        getattr(reference, "max_frequency_hz", 0.0) or 0.0)


def reference_rate_hz(reference: SampledReference) -> float:
    """The sample rate of a sampled reference [Hz]: one over its median sample spacing.

    The output grid of :func:`run_time_series` is uniform at this rate, so a
    file sampled uniformly gets its own time stamps back.

    Parameters
    ----------
    reference : SampledReference
        A sampled reference.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(11) * 1e-4
    >>> round(reference_rate_hz(SampledReference(t, 1e-3 * t)))
    10000
    """
    return 1.0 / float(np.median(np.diff(reference.t)))


def time_series_chunk(steps: int, per_row: int, held: float = 0.0) -> int:
    """Integration samples :func:`run_time_series` computes at a time for a continuous loop:
    the samples of :data:`ROWS_PER_CHUNK` rows, at most :data:`MAX_CHUNK`, and no more than
    the memory budget holds beside `held` (:data:`CHUNK_SAMPLE_BYTES` a sample; at least
    :data:`MIN_CHUNK`), so that a long run is written in smaller pieces rather than refused.

    Parameters
    ----------
    steps : int
        Integration samples of the run.
    per_row : int
        Samples a row (:func:`~motionhyst.time.steps.time_series_grid`).
    held : float
        Bytes the run holds beside its chunks (a sampled reference:
        :func:`~motionhyst.time.references.reference_bytes`).

    Returns
    -------
    int

    Examples
    --------
    >>> from motionhyst.core.budget import set_max_memory
    >>> set_max_memory(1 << 30)
    >>> time_series_chunk(3_000_001, 3), time_series_chunk(3_000_001, 277)
    (24576, 262144)
    >>> set_max_memory(20 << 20)                     # 20 MB hold 83886 samples
    >>> time_series_chunk(3_000_001, 277)
    83886
    >>> set_max_memory(None)
    """
    fit = max(MIN_CHUNK, int(max(max_memory() - held, 0.0) // CHUNK_SAMPLE_BYTES))
    return max(1, min(int(steps), int(per_row) * ROWS_PER_CHUNK, MAX_CHUNK, fit))


def check_time_series_memory(steps: int, per_row: int, sampled: bool,
                             remedy: str = RUN_REMEDY, reference=None) -> None:
    """Refuse, before it starts, a run of :func:`run_time_series` whose memory is above the
    budget: a continuous loop's run is computed a chunk at a time
    (:func:`time_series_chunk`, :data:`CHUNK_SAMPLE_BYTES` a sample: refused only where
    the budget holds less than :data:`MIN_CHUNK` samples); a sampled controller's is held
    whole (:data:`~motionhyst.time.steps.SAMPLED_SAMPLE_BYTES` a controller sample); a
    sampled `reference` is held beside either
    (:func:`~motionhyst.time.references.reference_bytes`).

    Parameters
    ----------
    steps : int
        Integration samples of the run (controller samples of a sampled loop).
    per_row : int
        Samples a row (:func:`~motionhyst.time.steps.time_series_grid`).
    sampled : bool
        The loop's controller is sampled.
    remedy : str
        What the caller can change.
    reference : object, optional
        The run's reference (a sampled one's spline counts).

    Raises
    ------
    motionhyst.time.steps.RunTooLarge
        One line: the run's samples, its bytes, the budget and `remedy`.

    Examples
    --------
    >>> from motionhyst.core.budget import set_max_memory
    >>> set_max_memory(100 << 20)
    >>> check_time_series_memory(30_000_001, 277, sampled=False)   # in chunks of 65.5 MB
    >>> try:
    ...     check_time_series_memory(1_000_001, 1, sampled=True)
    ... except ValueError as exc:
    ...     print(exc)
    a run of 1000001 controller samples (held whole) needs 200 MB, above the memory budget \
of 105 MB (--max-memory); shorten the duration or lower the reference's frequencies
    >>> set_max_memory(None)
    """
    held = reference_bytes(reference)
    if sampled:
        nbytes, what = SAMPLED_SAMPLE_BYTES * float(steps), f"{steps} controller samples " \
            "(held whole)"
    else:
        chunk = time_series_chunk(steps, per_row, held)
        nbytes, what = CHUNK_SAMPLE_BYTES * float(chunk), f"{steps} time steps ({chunk} at a time)"
    with a_run():
        check_memory(nbytes + held, f"a run of {what}", remedy)


@dataclass
class _Extreme:
    """Peak |x|, sum of squares and count of a signal over a window, accumulated by chunks."""

    peak: float = 0.0
    sum2: float = 0.0
    count: int = 0

    def add(self, x: NDArray[np.float64]) -> None:
        if x.size:
            self.peak = max(self.peak, float(np.max(np.abs(x))))
            self.sum2 += float(np.dot(x, x))
            self.count += int(x.size)

    @property
    def rms(self) -> float:
        return math.sqrt(self.sum2 / self.count) if self.count else math.nan


@dataclass
class _Settling:
    """Last time a signal was outside a band, accumulated by chunks."""

    band: float
    last_out: float = -math.inf
    final: float = math.nan

    def add(self, t: NDArray[np.float64], x: NDArray[np.float64]) -> None:
        if x.size:
            out = np.flatnonzero(np.abs(x) > self.band)
            if out.size:
                self.last_out = float(t[out[-1]])
            self.final = float(x[-1])


@dataclass
class _Signals:
    """The summaries of one error signal (with or without hysteresis)."""

    whole: _Extreme = field(default_factory=_Extreme)
    window: _Extreme = field(default_factory=_Extreme)
    settling: _Settling | None = None


def run_time_series(loop: Loop, reference, duration: float, out: IO[str] | None = None,
                    output_rate_hz: float | None = None,
                    settle_band: float = DEFAULT_SETTLE_BAND) -> dict:
    """Simulate from rest, write rows at the output rate to `out`, and summarise.

    Parameters
    ----------
    loop : Loop
        An LTI loop (see :func:`motionhyst.time.simulation.simulate`).
    reference : SineReference, PointToPoint, SampledReference or callable
        The reference; a sine or a point-to-point move gets its own summary.
    duration : float
        Simulated time [s], > 0.
    out : text file, optional
        Where the CSV rows go (header first); nothing is written if None.
    output_rate_hz : float, optional
        Rows per second.  Default: a sampled reference's own rate, else
        :data:`DEFAULT_OUTPUT_RATE_HZ`.  The integration step divides the
        output period, so every row is an integration sample.
    settle_band : float
        Half-width of the settling band of a point-to-point move [m].

    Returns
    -------
    dict
        ``samples`` (rows), ``steps`` (integration samples), ``dt_s``
        (integration step), ``output_rate_hz``, ``duration_s``,
        ``error_peak`` / ``error_linear_peak`` (whole run, start-up
        included), ``error_final`` / ``error_linear_final``, and per kind:
        ``last_period`` (sine: ``start_s``, ``end_s``, ``error_peak``,
        ``error_rms``, ``error_linear_peak``, ``error_linear_rms``; None if
        the run is shorter than a period) or ``move`` (point-to-point:
        ``start_s``, ``end_s``, ``error_peak``, ``error_linear_peak``,
        ``settle_band``, ``settling_time_s``, ``settling_time_linear_s``,
        None where the error is still outside the band at the end).

    Examples
    --------
    >>> import io
    >>> from motionhyst.scenario import default_scenario
    >>> from motionhyst.time.references import SineReference
    >>> buf = io.StringIO()
    >>> s = run_time_series(default_scenario().loop(), SineReference(0.01, 10.0), 0.2, buf,
    ...                     output_rate_hz=1000.0)
    >>> s["samples"], buf.getvalue().splitlines()[0]
    (201, 'time,reference,error,y1,y2,u,w,error_linear')
    >>> s["last_period"]["error_peak"] < s["error_peak"]  # the start-up is excluded
    True
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0, got {duration!r}")
    if output_rate_hz is None and loop.sampled is not None:   # the controller's samples
        output_rate_hz = loop.sampled.sample_rate_hz
    if output_rate_hz is None:
        output_rate_hz = (reference_rate_hz(reference) if isinstance(reference, SampledReference)
                          else DEFAULT_OUTPUT_RATE_HZ)
    if not (np.isfinite(output_rate_hz) and output_rate_hz > 0):
        raise ValueError(f"output rate must be finite and > 0, got {output_rate_hz!r}")
    if not (np.isfinite(settle_band) and settle_band > 0):
        raise ValueError(f"settle band must be finite and > 0, got {settle_band!r}")
    period_out = 1.0 / output_rate_hz
    why = "" if loop.sampled is not None else step_set_by(
        float(np.max(np.abs(loop.closed_loop_poles()))), _reference_frequency(reference))
    n_rows, per_row, step = time_series_grid(
        duration, output_rate_hz, dynamics_step(loop, reference),
        None if loop.sampled is None else loop.sampled.sample_rate_hz, set_by=why)
    check_time_series_memory((n_rows - 1) * per_row + 1, per_row, loop.sampled is not None,
                             reference=reference)
    end = (n_rows - 1) * period_out
    window = move = None
    if isinstance(reference, SineReference):
        period = 1.0 / reference.frequency_hz
        if period <= end:
            window = (end - period, end)
    elif isinstance(reference, PointToPoint):
        move = (reference.start, reference.start + reference.duration)
    sig = {name: _Signals(settling=_Settling(settle_band)) for name in ("e", "e_linear")}
    if out is not None:
        csv_header(out, COLUMNS)
    rows = 0
    steps = 0
    chunk = time_series_chunk((n_rows - 1) * per_row + 1, per_row,  # within the budget
                              reference_bytes(reference))
    from motionhyst.time.simulation import simulate_chunks

    for piece in simulate_chunks(loop, reference, end, dt=step, chunk=chunk):
        t = piece.t
        steps += len(t)
        for name, x in (("e", piece.e), ("e_linear", piece.e_linear)):
            s = sig[name]
            s.whole.add(x)
            s.settling.add(t, x)
            span = window or move
            if span is not None:
                inside = (t >= span[0] - 0.5 * step) & (t < span[1] - 0.5 * step) \
                    if window else (t >= span[0]) & (t <= span[1])
                s.window.add(x[inside])
        rows += _write_rows(out, piece, per_row, steps - len(t), period_out)
    summary: dict = {"samples": rows, "steps": steps, "dt_s": step,
                     "output_rate_hz": output_rate_hz, "duration_s": end,
                     "error_peak": sig["e"].whole.peak,
                     "error_linear_peak": sig["e_linear"].whole.peak,
                     "error_final": sig["e"].settling.final,
                     "error_linear_final": sig["e_linear"].settling.final}
    if isinstance(reference, SineReference):
        summary["last_period"] = None if window is None else {
            "start_s": window[0], "end_s": window[1],
            "error_peak": sig["e"].window.peak, "error_rms": sig["e"].window.rms,
            "error_linear_peak": sig["e_linear"].window.peak,
            "error_linear_rms": sig["e_linear"].window.rms}
    if move is not None:
        def settling(s: _Signals):
            if abs(s.settling.final) > settle_band:
                return None  # still outside the band at the end of the run
            return max(0.0, s.settling.last_out + step - move[1])

        summary["move"] = {"start_s": move[0], "end_s": move[1],
                           "error_peak": sig["e"].window.peak,
                           "error_linear_peak": sig["e_linear"].window.peak,
                           "settle_band": settle_band,
                           "settling_time_s": settling(sig["e"]),
                           "settling_time_linear_s": settling(sig["e_linear"])}
    return summary


def _write_rows(out: IO[str] | None, piece: Simulation, per_row: int, first_sample: int,
                period_out: float) -> int:
    """Write every `per_row`-th sample of `piece` as CSV rows; their number.

    The piece's first sample is sample `first_sample` of the run; rows are the
    samples whose index is a multiple of `per_row` (a piece may hold no row).
    The time column is the row's time ``row * period_out`` (the samples'
    times up to round-off), so a reference's own time stamps come back exactly.
    """
    cols = piece.columns()
    skip = -first_sample % per_row
    n = len(cols["time"][skip::per_row])
    first_row = (first_sample + skip) // per_row
    block = np.column_stack([(first_row + np.arange(n)) * period_out if c == "time"
                             else cols[c][skip::per_row] for c in COLUMNS])
    if out is not None and n:
        csv_rows(out, block)
    return n


__all__ = ["CHUNK_SAMPLE_BYTES", "COLUMNS", "DEFAULT_OUTPUT_RATE_HZ", "DEFAULT_SETTLE_BAND",
           "MIN_CHUNK", "check_time_series_memory", "dynamics_step", "reference_rate_hz",
           "run_time_series", "time_series_chunk"]
