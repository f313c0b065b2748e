"""The run of ``simulate --time-series`` sized before it starts (issue 26): a loop with a
sampled controller holds its whole run (:data:`~motionhyst.time.steps.SAMPLED_SAMPLE_BYTES`
a controller sample) and is refused in one line before its loop is built where the budget
does not hold it; a continuous one holds a chunk of it
(:data:`~motionhyst.time.timeseries.CHUNK_SAMPLE_BYTES` a sample), made smaller where the
budget holds less than :data:`~motionhyst.time.timeseries.MAX_CHUNK` samples; each estimate
an upper bound of the run's address space within its margin of the traced peak.  Before, a
reference file's run was not sized at all (mem15: 100 s of Table I at ``--max-memory 60M``
ran to its end at 430 MB), and a reference logged in milliseconds was refused for its steps
without a word of its unit (review A15b M5)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.core.budget import set_max_memory

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _reference(path: Path, seconds: float, rate: float, time_gain: float = 1.0) -> Path:
    """A 0.5 Hz sine setpoint of 5 mm for `seconds` sampled at `rate`, its time multiplied by
    `time_gain` (1000: logged in ms)."""
    t = np.arange(int(seconds * rate) + 1) / rate
    np.savetxt(path, np.column_stack([t * time_gain, 5e-3 * np.sin(np.pi * t)]), delimiter=",",
               fmt="%.10g", header="time,position", comments="")
    return path


@pytest.fixture
def budget():
    yield set_max_memory
    set_max_memory(None)


@pytest.fixture
def no_loop(monkeypatch):
    """The scenario's loop (python-control, the run) fails the test if it is built: the
    refusal comes before it."""
    from motionhyst.scenario import Scenario

    def loop(self, *args, **kwargs):
        raise AssertionError("the loop was built")

    monkeypatch.setattr(Scenario, "loop", loop)


def _refused(argv: list[str], capsys) -> str:
    assert main(argv) == 2
    captured = capsys.readouterr()
    line = captured.err.strip()
    assert captured.out == "" and "\n" not in line and "Traceback" not in line, captured.err
    return line


def test_a_sampled_loops_run_of_a_reference_file_is_refused_for_its_memory(
        tmp_path, capsys, no_loop):
    """100 s of a reference logged at 100 Hz (10001 samples: its spline 2.4 MB) run by the
    paper's loop at 10 kHz: 1000001 controller samples held whole, 200 MB, refused at
    ``--max-memory 100M`` before the loop is built, nothing written (main ran it: 230 MB
    above the process's own)."""
    ref = _reference(tmp_path / "r.csv", 100.0, 100.0)
    line = _refused(["simulate", str(EXAMPLES / "paper_10khz.toml"), "--reference-csv",
                     str(ref), "--time-series", str(tmp_path / "o.csv"), "--max-memory",
                     "100M"], capsys)
    assert line == ("motionhyst: error: a run of 1000001 controller samples (held whole) "
                    "needs 201 MB, above the memory budget of 105 MB (--max-memory); shorten "
                    "--duration (or the file)"), line  # 200 MB before its reference's 0.56
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]


def test_a_continuous_loops_run_is_written_in_chunks_the_budget_holds(tmp_path, capsys,
                                                                      monkeypatch):
    """Table I's loop computes a run a chunk at a time: 10 s of a 100 Hz reference (277001
    steps, 277 a row) at ``--max-memory 20M`` runs in chunks of 83661 steps (20 MB at 250
    bytes a step beside the reference's 56 kB) instead of 262144 (65.5 MB): not refused, nor
    above the budget (fe53321's parent refused it: "a run of 277001 time steps (262144 at a
    time) needs 65.5 MB")."""
    from motionhyst.time import simulation

    seen = []
    chunks = simulation.simulate_chunks

    def recorded(*args, **kwargs):
        seen.append(kwargs["chunk"])
        return chunks(*args, **kwargs)

    monkeypatch.setattr(simulation, "simulate_chunks", recorded)
    ref = _reference(tmp_path / "r.csv", 10.0, 100.0)
    assert main(["simulate", "--reference-csv", str(ref), "--time-series",
                 str(tmp_path / "o.csv"), "--max-memory", "20M"]) == 0, capsys.readouterr().err
    assert seen == [83661]  # 83886 before the reference's 1001 samples (56 kB) were counted
    assert len((tmp_path / "o.csv").read_text().splitlines()) == 1002  # 10 s at 100 Hz


def test_a_runs_estimate_counts_its_reference_file(tmp_path, capsys, no_loop):
    """A sampled reference keeps 56 bytes a sample while the run uses it (its time, position,
    the spline's knots and coefficients; measured 56.2 traced for 1e6 samples), which the run's
    estimate left out: 10 s of a reference at 1 kHz (10001 samples) run by the paper's 10 kHz
    loop (100001 controller samples, 20.0 MB) at ``--max-memory 19.3M`` (20.2 MB) ran on
    main, though run and reference hold 20.6 MB; now refused in one line before the loop is
    built."""
    ref = _reference(tmp_path / "r.csv", 10.0, 1000.0)
    line = _refused(["simulate", str(EXAMPLES / "paper_10khz.toml"), "--reference-csv",
                     str(ref), "--time-series", str(tmp_path / "o.csv"), "--max-memory",
                     "19.3M"], capsys)
    assert line == ("motionhyst: error: a run of 100001 controller samples (held whole) needs "
                    "20.6 MB, above the memory budget of 20.2 MB (--max-memory); shorten "
                    "--duration (or the file)"), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]


def test_a_chunk_is_made_smaller_by_its_reference():
    """A continuous loop's chunk fits the budget beside its reference's bytes."""
    from motionhyst.time.timeseries import CHUNK_SAMPLE_BYTES, time_series_chunk

    set_max_memory(20 << 20)
    try:
        alone = time_series_chunk(3_000_001, 277)
        beside = time_series_chunk(3_000_001, 277, held=56 * 100_001)
    finally:
        set_max_memory(None)
    assert alone == 83886 and beside == (20 * 2**20 - 56 * 100_001) // CHUNK_SAMPLE_BYTES


def test_a_sampled_run_is_refused_by_the_library_too(budget):
    """simulate_sampled sizes its run before it allocates it (the library's remedy)."""
    from motionhyst.scenario import load_scenario
    from motionhyst.time.references import SineReference
    from motionhyst.time.sampled import simulate_sampled
    from motionhyst.time.steps import RunTooLarge

    loop = load_scenario(EXAMPLES / "paper_10khz.toml").loop()
    budget(50 << 20)
    with pytest.raises(RunTooLarge, match=r"^a run of 500001 controller samples at 10000 Hz "
                                          r"\(held whole\) needs 100 MB, above the memory "
                                          r"budget of 52\.4 MB \(--max-memory\); shorten the "
                                          r"duration$"):
        simulate_sampled(loop, SineReference(0.01, 2.0), 50.0)


RUN_SCRIPT = """
import os, resource, sys, tracemalloc, warnings
import numpy as np
warnings.simplefilter("ignore")
from motionhyst.core.budget import set_max_memory
set_max_memory(1 << 40)  # the address-space limit alone decides
from motionhyst.scenario import load_scenario
from motionhyst.time.references import SampledReference, SineReference
from motionhyst.time.steps import time_series_grid
from motionhyst.time.timeseries import CHUNK_SAMPLE_BYTES, time_series_chunk
from motionhyst.time.timeseries import dynamics_step, run_time_series
from motionhyst.time.steps import SAMPLED_SAMPLE_BYTES

loop = load_scenario(sys.argv[1]).loop()
seconds, rate = float(sys.argv[2]), float(sys.argv[3])
if len(sys.argv) > 4:
    set_max_memory(int(sys.argv[4]))  # a budget: smaller chunks
out = open(os.devnull, "w")
run_time_series(loop, SineReference(0.01, 2.0), 0.05, out)  # compiled, warmed
t = np.arange(int(seconds * rate) + 1) / rate
ref = SampledReference(t, 5e-3 * np.sin(np.pi * t))
sampled = loop.sampled is not None
rows, per_row, _ = time_series_grid(seconds, rate, dynamics_step(loop, ref),
                                    loop.sampled.sample_rate_hz if sampled else None)
steps = (rows - 1) * per_row + 1
estimate = (SAMPLED_SAMPLE_BYTES * steps if sampled
            else CHUNK_SAMPLE_BYTES * time_series_chunk(steps, per_row))
with open("/proc/self/status") as f:
    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith("VmSize"))
resource.setrlimit(resource.RLIMIT_AS, (size + estimate, size + estimate))
tracemalloc.start()
s = run_time_series(loop, ref, seconds, out, output_rate_hz=rate)
print(s["steps"], estimate, tracemalloc.get_traced_memory()[1])
"""


@pytest.mark.parametrize(("scenario", "seconds", "rate", "budget"), [
    ("paper_10khz.toml", 20.0, 10_000.0, None),  # 200001 controller samples held whole: 40 MB
    ("paper.toml", 40.0, 100.0, None),           # 1108001 steps, chunks of 262144: 65.5 MB
    ("paper.toml", 40.0, 100.0, 20 << 20),       # chunks of 83886 steps: 21 MB
], ids=["sampled-whole", "continuous-chunk", "continuous-chunk-in-a-budget"])
def test_a_runs_estimate_bounds_its_memory_within_its_margin(tmp_path, scenario, seconds, rate,
                                                             budget):
    """The run under an address-space limit of its estimate above a warmed process (main's
    chunk estimate, 160 B a sample, was below the 200-211 traced), and the estimate at most
    40 % above the traced peak (measured 1.19 for the sampled run, 1.19-1.25 for a chunk)."""
    from limited_process import environment

    script = tmp_path / "run.py"
    script.write_text(RUN_SCRIPT)
    proc = subprocess.run([sys.executable, str(script), str(EXAMPLES / scenario), str(seconds),
                           str(rate), *([] if budget is None else [str(budget)])],
                          capture_output=True, text=True, env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    steps, estimate, traced = (int(x) for x in proc.stdout.split())
    assert steps == (200_001 if "10khz" in scenario else 1_108_001)
    assert traced <= estimate <= 1.4 * traced, (estimate, traced)


def test_a_size_refusal_of_a_reference_in_ms_names_its_unit(tmp_path, capsys, no_loop):
    """A 60 s, 1 kHz setpoint log with its time in ms (60000 s as read) is refused for its
    steps; the one line says first that its time looks like ms (main: "shorten --duration
    (or the file)" alone, review A15b M5), and no warning line besides it."""
    ref = _reference(tmp_path / "ms.csv", 60.0, 1000.0, time_gain=1e3)
    line = _refused(["simulate", "--reference-csv", str(ref), "--time-series",
                     str(tmp_path / "o.csv")], capsys)
    assert line.startswith("motionhyst: error: 60001 rows of 27656 steps each: too many time "
                           "steps"), line
    assert line.endswith("ms.csv: the reference is sampled at 1 Hz (60001 samples over 6e+04 "
                         "s): if its time is not in seconds, scale it (--scale time=0.001 for "
                         "ms); else shorten --duration (or the file)"), line


def test_a_memory_refusal_of_a_reference_in_ms_names_its_unit(tmp_path, capsys, no_loop):
    """The same hint on a refusal of the run's memory: 2 s logged at 100 Hz in ms, run by the
    sampled loop at 10 kHz, 2000 s as read (20000001 samples, 4 GB)."""
    ref = _reference(tmp_path / "ms.csv", 2.0, 100.0, time_gain=1e3)
    line = _refused(["simulate", str(EXAMPLES / "paper_10khz.toml"), "--reference-csv",
                     str(ref), "--time-series", str(tmp_path / "o.csv"), "--max-memory",
                     "1G"], capsys)
    assert line.startswith("motionhyst: error: a run of 20000001 controller samples (held "
                           "whole) needs 4 GB"), line
    assert "(--scale time=0.001 for ms); else shorten --duration (or the file)" in line, line
