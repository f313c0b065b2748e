"""The Coulomb link's search on an axis: its forward differences in one pool of threads, its
refinement on the records' segments, and the better end kept
(motionhyst.identify.io_differences, motionhyst.identify.io_refine)."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb
from motionhyst.identify import io_refine
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.identify.io_differences import REFUSED, forward_differences
from motionhyst.identify.io_offsets import Extras
from motionhyst.identify.io_records import MAX_SEGMENTS, segment_records
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

FS = 1000.0
EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"


class _Linear:
    """A search problem of two records (30 and 10 samples) whose residuals are linear in its
    six variables (two shared; each record's position offset and initial velocity, in
    :class:`Extras`' order), counting the runs of each record."""

    n_plant, n_link = 1, 1

    def __init__(self, refuse_above: float = np.inf):
        self.records = [IORecord(np.arange(n) / FS, np.zeros(n), np.zeros(n)) for n in (30, 10)]
        self.extras = Extras(False, True, ("v0",), 2)
        self.free = np.ones(2 + self.extras.size, bool)
        rng = np.random.default_rng(0)
        self.A = [rng.standard_normal((rec.y.size, 7)) for rec in self.records]
        self.A[0][:, [3, 5]] = 0.0  # record 1's own variables
        self.A[1][:, [2, 4]] = 0.0
        self.runs = [0, 0]
        self.charged = 0
        self.refuse_above = refuse_above

    def run_rows(self, q, only=None):
        if q[0] > self.refuse_above:  # values the model refuses
            return None
        which = range(2) if only is None else [only]
        for i in which:
            self.runs[i] += 1
        return np.concatenate([self.A[i] @ np.append(q, 1.0) for i in which])

    def charge(self, n):
        self.charged += n


def test_forward_differences_run_a_record_alone_for_its_own_offsets():
    """Each record's own position offset and initial velocity move its rows alone: their
    columns run that record only (the others' rows are zero, as whole runs give them), the
    shared variables run every record, and the budget is charged the runs' share of the
    samples: 2 + 2 evaluations for the six columns (each column ran every record before: 6)."""
    prob = _Linear()
    q = np.zeros(6)
    r0 = prob.run_rows(q)
    prob.runs = [0, 0]
    J = forward_differences(prob, q, r0, np.full(6, 1e-3))
    assert J == pytest.approx(np.vstack([a[:, :6] for a in prob.A]), rel=1e-9, abs=1e-9)
    assert prob.runs == [2 + 2, 2 + 2]  # the two shared columns, each record's own two
    assert prob.charged == 2 + 2


def test_a_column_the_model_refuses_is_refused_in_every_row():
    """A step to values the model refuses gives that column a refused run's residuals in
    every record's rows, as a run of all the records gives them."""
    prob = _Linear(refuse_above=1e-4)
    q = np.zeros(6)
    r0 = prob.run_rows(q)
    J = forward_differences(prob, q, r0, np.full(6, 1e-3))
    assert J[:, 0] == pytest.approx((REFUSED - r0) / 1e-3)
    assert J[:, 1:] == pytest.approx(np.vstack([a[:, 1:6] for a in prob.A]), abs=1e-9)


def _coulomb_axis(n: int, seed: int, offset: float = -3.0) -> IORecord:
    """A Coulomb axis (95 kg, 200 N s/m, fc 20 N, a force offset) driven by two sines and a
    random force, `n` samples, 1e-7 m of position noise."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    u = (60.0 * np.sin(2 * np.pi * 1.3 * t) + 25.0 * np.sin(2 * np.pi * 7.1 * t + 1.0)
         + rng.standard_normal(n))
    y = OpenLoop(MassDamper(95.0, 200.0, force_offset=offset), Coulomb(fc=20.0)).simulate(
        t, u).displacement
    return IORecord(t, u, y + 1e-7 * rng.standard_normal(n), f"axis{seed}")


def test_the_search_on_segments_starts_threads_from_one_level_only(monkeypatch):
    """The Coulomb search of two records on an axis (its segments' search of six records,
    and its secants' columns) starts every thread from the main thread: a column's runs of
    the records are tasks of the one pool, not a pool of their own (each thread's stack is
    address space the search's estimate does not hold; the nested pools ran out of it).
    Without a budget, so that the segments' search runs (a budget of 400 evaluations turned
    it off: it leaves less than RIGID_STEPS steps), and threads are started inside it."""
    starters: list[tuple[bool, bool]] = []  # (from the main thread, in the segments' search)
    segments: list[int] = []
    start, on_segments = threading.Thread.start, io_refine.on_segments

    def in_segments() -> bool:
        return bool(segments) and segments[-1] > 0

    def spy(self):
        starters.append((threading.current_thread() is threading.main_thread(), in_segments()))
        start(self)

    def spy_segments(prob, q, tol, max_nfev):
        segments.append(len(prob.records))
        try:
            end = on_segments(prob, q, tol, max_nfev)
        finally:
            segments[-1] = -segments[-1]  # done: threads after it are not its
        return end

    monkeypatch.setattr(threading.Thread, "start", spy)
    monkeypatch.setattr(io_refine, "on_segments", spy_segments)
    records = [_coulomb_axis(1500, 0), _coulomb_axis(1500, 1)]
    fit = identify_io(records, "coulomb", plant="mass-damper")
    assert segments == [-2], segments  # the segments' search ran once, on the two records
    assert any(inside for _, inside in starters), "no thread started in the segments' search"
    assert all(main for main, _ in starters), \
        f"{sum(not main for main, _ in starters)} threads started in a thread"
    assert fit.estimates["m"] == pytest.approx(95.0, rel=0.01)


def test_every_sample_of_a_record_is_in_a_segment():
    """A record's segments hold every one of its samples, its tail in the last (review C13
    M4: a record whose length was a multiple of 500 lost its last 500 samples, 6000 samples
    cut into 11 segments over 5500), a record shorter than a segment is one, and the
    segments stop at MAX_SEGMENTS (of the records' first samples)."""
    def sizes(*lengths):
        recs = [IORecord(np.arange(n) / FS, np.zeros(n), np.zeros(n)) for n in lengths]
        return [(i, s.y.size, float(s.t[-1])) for i, s in segment_records(recs)]

    assert sizes(6000) == [(0, 500, (500 * k + 499) / FS) for k in range(12)]
    assert sizes(1000, 300) == [(0, 500, 0.499), (0, 500, 0.999), (1, 300, 0.299)]
    assert sizes(1499) == [(0, 500, 0.499), (0, 999, 1.498)]
    assert [n for _, n, _ in sizes(500, 64)] == [500, 64]
    assert len(sizes(20000, 20000)) == MAX_SEGMENTS


def test_the_segments_are_shared_by_the_records_lengths():
    """Two long records share the MAX_SEGMENTS segments by their lengths (review A14b: two
    records of 20,000 samples gave all 32 to the first, none to the second); a short record
    keeps its one; more records than segments: one each of the first."""
    def counts(*lengths):
        recs = [IORecord(np.arange(n) / FS, np.zeros(n), np.zeros(n)) for n in lengths]
        got = [i for i, _ in segment_records(recs)]
        return [got.count(i) for i in range(len(lengths))]

    assert counts(20000, 20000) == [16, 16]
    assert counts(30000, 10000) == [24, 8]
    assert counts(20000, 300) == [31, 1]
    assert counts(*[600] * 40) == [1] * MAX_SEGMENTS + [0] * 8
    assert sum(counts(50000, 1700, 1700)) == MAX_SEGMENTS


@pytest.mark.skipif(not EMPS.is_file(),
                    reason="the EMPS benchmark's files are not beside the repository")
def test_the_segments_end_is_kept_only_where_it_ends_better():
    """On a window of the measured EMPS record (samples 6000-12000) the Coulomb fit's
    refinement from the segments' end ends worse than from the starts' best (the model does
    not fit the record to its noise); the ends are compared: the fit (viscous friction by
    direction, as identify chooses it for this record) is no worse than main's without
    segments (1.22254e-4 m; the segments' end kept unchecked: 1.23398e-4 m)."""
    from motionhyst.cli.benchmark import _emps_record

    rec = _emps_record(EMPS, "DATA_EMPS")
    part = slice(6000, 12000)
    window = IORecord(rec.t[part] - rec.t[part][0], rec.u[part], rec.y[part], "window")
    fit = identify_io([window], "coulomb", plant="mass-damper", asymmetric=True)
    assert fit.fit_rms <= 1.22254e-4 * (1 + 1e-5)


def test_a_stiff_jenkins_axis_is_fitted_to_its_noise():
    """A Jenkins axis (95 kg, 200 N s/m, k 1e8 N/m, fc 20 N, a 3 N force offset, 0.02 m/s at
    the start, 2 mm of position offset) under three sines and a random force, 4000 samples,
    1e-7 m of noise: main's search stopped at 174 times the noise with k 1.58e7 +- 1.3e5 N/m
    (659 standard errors off); refined from the segments' end too (its sticks mispredicted
    cost only their segment), it ends at the noise with every value within 3 standard
    errors."""
    from motionhyst.hysteresis import Jenkins
    from motionhyst.time.openloop import simulate_elements

    n, noise = 4000, 1e-7
    rng = np.random.default_rng(0)
    t = np.arange(n) / FS
    ph = rng.uniform(0, 2 * np.pi, 3)
    u = (30 + 90 * np.sin(2 * np.pi * 0.6 * t + ph[0]) + 40 * np.sin(2 * np.pi * 1.7 * t + ph[1])
         + 15 * np.sin(2 * np.pi * 4.1 * t + ph[2]) + 5 * rng.standard_normal(n))
    y, _ = simulate_elements(MassDamper(95.0, 200.0).mechanics(),
                             Jenkins(k=1e8, fc=20.0).time_stepping(), u + 3.0, FS, 20,
                             periodic=False, x0=np.array([0.0, 0.02]))
    rec = IORecord(t, u, y + 2e-3 + noise * rng.standard_normal(n))
    fit = identify_io([rec], "jenkins", plant="mass-damper", substeps=20)
    assert fit.fit_rms < 1.02 * noise
    for name, value in (("m", 95.0), ("c", 200.0), ("link.k", 1e8), ("link.fc", 20.0),
                        ("input_offset", -3.0)):
        assert abs(fit.estimates[name] - value) <= 3 * fit.std[name], name
