"""Every record reader sized from its file before it reads it (issue 26): a CSV file's rows
counted (up to 64 MB) or estimated from lines sampled across it, and read a chunk of rows
at a time into one array, within :func:`~motionhyst.io.csvdata.reading_bytes` (8 bytes a
value and one more a row, and one chunk's parsing) instead of four times the file's bytes;
``predict``'s force record, ``simulate --reference-csv`` and a measured plant's response
refused before they are read, naming their samples.  Before, a file above four times the
budget was refused naming only its bytes, and one below it was read whole before its
command's estimate refused it (a measured response of 1e6 lines took 433 bytes a line of
address space, its reading 131)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.core.budget import BudgetError, set_max_memory
from motionhyst.io import csvdata, records
from motionhyst.io.csvdata import count_rows, data_rows, read_columns, reading_bytes

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _write(path: Path, header: str, columns: list[np.ndarray], fmt: str = "%.10g") -> Path:
    np.savetxt(path, np.column_stack(columns), delimiter=",", fmt=fmt, header=header,
               comments="")
    return path


@pytest.fixture
def unread(monkeypatch):
    """The record readers fail the test if they are called: a refusal comes before them."""
    def read(*args, **kwargs):
        raise AssertionError("the record was read")

    monkeypatch.setattr(records, "read_columns", read)
    monkeypatch.setattr(records, "_read_mat", read)


@pytest.fixture
def budget():
    yield set_max_memory
    set_max_memory(None)


def _refused(argv: list[str], capsys) -> str:
    assert main(argv) == 2
    captured = capsys.readouterr()
    line = captured.err.strip()
    assert captured.out == "" and "\n" not in line and "Traceback" not in line, captured.err
    return line


def test_a_file_above_four_times_the_budget_is_read_by_its_rows(tmp_path, budget):
    """3e5 rows of time,position (6.6 MB of text, 4.8 MB of floats) under a budget of 24 MB:
    main refused it for its bytes ("reading r.csv (6.6 MB) needs 26.4 MB"); read now, its
    numbers exact, within reading_bytes (40.7 MB with one chunk's 33.6)."""
    n = 300_000
    t = np.arange(n) / 1000.0
    path = _write(tmp_path / "r.csv", "time,position", [t, np.sin(t)])
    assert 4 * path.stat().st_size > 24 << 20
    budget(int(reading_bytes(n, 2)) + 1)
    data = read_columns(path, ("time", "position"))
    assert data.shape == (n, 2) and data.flags.c_contiguous
    np.testing.assert_allclose(data[:, 1], np.sin(t), rtol=0, atol=1e-10)
    budget(int(reading_bytes(n, 2)) - 1)
    with pytest.raises(BudgetError, match=r"r\.csv \(300000 rows, not read yet\): reading its "
                                          r"2 columns needs 40\.\d MB, above the memory"):
        read_columns(path, ("time", "position"))


def test_a_measured_response_of_a_million_lines_is_read_within_its_estimate(tmp_path):
    """1e6 lines of frequency_hz,p1_re,p1_im,p2_re,p2_im (115 MB of text, 40 MB of floats)
    read by read_record under an address-space limit of reading_bytes (81.6 MB) above a
    warmed process: measured 71 MB (main: 131 MB; 48 B a line, 9 a value, above a fixed
    part): a MemoryError on main."""
    from limited_process import environment

    n = 1_000_000
    f = np.geomspace(1.0, 2000.0, n)
    g = 1.0 / (2 * np.pi * f) ** 2
    _write(tmp_path / "frf.csv", "frequency_hz,p1_re,p1_im,p2_re,p2_im",
           [f, -g, 1e-3 * g, -g, -1e-3 * g], fmt="%.12g")
    warm = 300_000
    _write(tmp_path / "warm.csv", "frequency_hz,p1_re,p1_im,p2_re,p2_im",
           [np.arange(1, warm + 1.0)] * 5, fmt="%.6g")
    script = tmp_path / "read.py"
    script.write_text(
        "import resource, sys\n"
        "from motionhyst.core.budget import set_max_memory\n"
        "from motionhyst.io.csvdata import reading_bytes\n"
        "from motionhyst.io.records import read_record\n"
        "set_max_memory(1 << 32)\n"  # the address-space limit alone decides
        "names = ('frequency_hz', 'p1_re', 'p1_im', 'p2_re', 'p2_im')\n"
        "read_record(sys.argv[1], names)\n"  # pandas loaded, a chunk's buffers made
        "with open('/proc/self/status') as f:\n"
        "    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith('VmSize'))\n"
        f"limit = size + int(reading_bytes({n}, 5))\n"
        "resource.setrlimit(resource.RLIMIT_AS, (limit, limit))\n"
        "data = read_record(sys.argv[2], names)\n"
        "print(data.shape[0], repr(float(data[-1, 0])))\n")
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "warm.csv"),
                           str(tmp_path / "frf.csv")], capture_output=True, text=True,
                          env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == [str(n), "2000.0"], proc.stdout


def test_rows_of_a_large_file_are_estimated_from_lines_across_it(tmp_path, monkeypatch):
    """Beyond COUNTED_BYTES, the rows come from the file's size and lines sampled at 64
    places: a record at rest at both ends (short lines there, long ones while it moves: the
    first and last lines alone gave 2.9 times too many, review A13a H1) within 3 % (1.4)."""
    n = 200_000
    t = np.arange(n) / 1000.0
    x = np.where((t > 40) & (t < 160), 1e-3 * np.sin(2 * np.pi * 0.7 * t) * np.pi, 0.0)
    path = _write(tmp_path / "rest.csv", "time,displacement,force", [t, x, 3e4 * x])
    exact = count_rows(path)
    assert exact == n and data_rows(path) == (n, True)
    monkeypatch.setattr(csvdata, "COUNTED_BYTES", 1 << 20)
    rows, counted = data_rows(path)
    assert not counted and abs(rows / n - 1) < 0.03, rows
    data = read_columns(path, ("time", "force"))  # read all, beyond the estimate or short
    assert data.shape == (n, 2) and data[-1, 0] == t[-1]


def test_a_file_longer_than_its_estimate_is_read_whole(tmp_path, monkeypatch):
    """Long lines where the estimate samples them, short ones elsewhere: the array grows
    past the estimate (checked against the budget as it grows) and every row is read."""
    n = 50_000
    t = np.arange(n) / 1000.0
    path = tmp_path / "uneven.csv"
    with open(path, "w") as fh:
        fh.write("time,position\n")
        for i in range(n):
            fh.write(f"{t[i]:.17g},{np.pi * 1e-3:.17g}\n" if i < 2000 else f"{i},1\n")
    monkeypatch.setattr(csvdata, "COUNTED_BYTES", 1 << 10)
    monkeypatch.setattr(csvdata, "_PROBES", 1)  # the file's head alone: long lines
    rows, counted = data_rows(path)
    assert not counted and rows < n / 2, rows
    data = read_columns(path, ("time", "position"))
    assert data.shape == (n, 2) and data[-1, 0] == n - 1


def test_predict_refuses_a_long_force_record_unread(tmp_path, unread, capsys):
    """3e5 force samples (11 MB of CSV) predicted from rest under --max-memory 30M: the run
    needs at least a block of 20 steps a sample and the record (35.4 MB, the smaller of a
    run in blocks and in one block): refused
    before the file is read, with its samples (main refused its reading, naming its bytes and
    not its samples)."""
    n = 300_000
    t = np.arange(n) / 1000.0
    path = _write(tmp_path / "f.csv", "time,force", [t, 20 * np.sin(2 * np.pi * t)], "%.17g")
    assert path.stat().st_size > records.SIZED_UNREAD_BYTES
    model = tmp_path / "axis.toml"
    model.write_text('[stage]\ntype = "mass-damper"\nm = 95.0\nc = 200.0\n\n'
                     '[hysteresis]\nmodel = "jenkins"\nk = 1e6\nfc = 20.0\n')
    line = _refused(["predict", str(model), str(path), "--out", str(tmp_path / "o.csv"),
                     "--max-memory", "30M"], capsys)
    assert line.startswith(f"motionhyst: error: {path} ({n} samples, not read yet): "
                           f"predicting {n} samples from rest (at least 20 integration steps "
                           f"each) needs 35.4 MB, above the memory budget of 31.5 MB"), line
    assert line.endswith("fewer samples or --substeps"), line
    assert not (tmp_path / "o.csv").exists()


def test_a_long_reference_is_refused_unread(tmp_path, unread, capsys):
    """simulate --reference-csv of 3e5 samples under --max-memory 50M: its quintic spline
    needs 240 bytes a sample (72 MB): refused before the file is read."""
    n = 300_000
    t = np.arange(n) / 1e4
    path = _write(tmp_path / "ref.csv", "time,position", [t, 0.01 * np.sin(2 * np.pi * t)],
                  "%.17g")
    assert path.stat().st_size > records.SIZED_UNREAD_BYTES
    line = _refused(["simulate", "--reference-csv", str(path), "--time-series",
                     str(tmp_path / "ts.csv"), "--max-memory", "50M"], capsys)
    assert line == (f"motionhyst: error: {path} ({n} samples, not read yet): the reference's "
                    f"spline through {n} samples needs 72 MB, above the memory budget of 52.4 "
                    f"MB (--max-memory); give fewer samples (a coarser or shorter "
                    f"reference)"), line


def test_a_long_measured_response_is_refused_unread(tmp_path, unread, budget):
    """A measured plant of 1e5 lines (12 MB) under a budget of 30 MB: the loader needs 400
    bytes a line (its responses and python-control's splines of them): refused unread."""
    from motionhyst import load_frd_plant

    n = 100_000
    f = np.geomspace(1.0, 2000.0, n)
    g = 1.0 / (2 * np.pi * f) ** 2
    path = _write(tmp_path / "frf.csv", "frequency_hz,p1_re,p1_im,p2_re,p2_im",
                  [f, -g, 1e-3 * g, -g, -1e-3 * g], fmt="%.12g")
    budget(30 << 20)
    with pytest.raises(BudgetError) as err:
        load_frd_plant(path)
    assert str(err.value) == (f"{path} ({n} samples, not read yet): a measured plant of {n} "
                              f"lines (its responses and their splines) needs 40 MB, above "
                              f"the memory budget of 31.5 MB (--max-memory); give fewer lines "
                              f"(a measurement thinned to the lines that resolve the plant: "
                              f"a few hundred log-spaced)")


def test_predict_refuses_a_long_displacement_record_unread(tmp_path, unread, capsys):
    """The force of a model without inertia for 3e5 displacement samples (11 MB of CSV) under
    --max-memory 25M: the record, its noise estimate and the link's run take 96 bytes a
    sample (28.8 MB; measured 28.2 MB of address space): refused unread (main sized this
    route by its reading alone, after the file was read: 78 MB at 1e6 samples, 125 on
    main, against an estimate of 58 and 102)."""
    n = 300_000
    t = np.arange(n) / 1000.0
    x = 0.003 * np.sin(np.pi * t) + 1e-5 * np.random.default_rng(0).standard_normal(n)
    path = _write(tmp_path / "d.csv", "time,displacement", [t, x], "%.17g")
    assert path.stat().st_size > records.SIZED_UNREAD_BYTES
    model = tmp_path / "link.toml"
    model.write_text('[stage]\ntype = "quasi-static"\nk = 5e4\n[hysteresis]\nmodel = "jenkins"\n'
                     'k = 1e6\nfc = 3e3\n')
    line = _refused(["predict", str(model), str(path), "--predict", "force", "--out",
                     str(tmp_path / "o.csv"), "--max-memory", "25M"], capsys)
    assert line == (f"motionhyst: error: {path} ({n} samples, not read yet): predicting the "
                    f"force of {n} displacement samples (the record, its noise estimate and "
                    f"the link's run) needs 28.8 MB, above the memory budget of 26.2 MB "
                    f"(--max-memory); give a shorter record"), line
    assert not (tmp_path / "o.csv").exists()


def test_a_model_without_inertia_is_not_sized_by_integration_steps(tmp_path, capsys):
    """The displacement of a model without inertia for 3e5 force samples (its balance solved
    at each sample: no integration steps) under --max-memory 40M: its least is the record and
    its outputs, 64 bytes a sample (19.2 MB), and it runs; sized with a block of 20 steps a
    sample, it was refused for 120 MB it never needs."""
    n = 300_000
    t = np.arange(n) / 1000.0
    path = _write(tmp_path / "f.csv", "time,force", [t, 2000 * np.sin(t)], "%.17g")
    assert path.stat().st_size > records.SIZED_UNREAD_BYTES
    model = tmp_path / "link.toml"
    model.write_text('[stage]\ntype = "quasi-static"\nk = 5e4\n[hysteresis]\nmodel = "jenkins"\n'
                     'k = 1e6\nfc = 3e3\n')
    argv = ["predict", str(model), str(path), "--predict", "displacement", "--out",
            str(tmp_path / "o.csv")]
    assert main([*argv, "--max-memory", "40M"]) == 0, capsys.readouterr().err
    out = read_columns(tmp_path / "o.csv", ("time", "displacement"))
    assert out.shape == (n, 2) and 1e-3 < np.max(np.abs(out[:, 1])) < 0.1
    capsys.readouterr()
    line = _refused([*argv, "--force", "--max-memory", "15M"], capsys)
    assert line == (f"motionhyst: error: {path} ({n} samples, not read yet): predicting {n} "
                    f"samples from rest needs 19.2 MB, above the memory budget of 15.7 MB "
                    f"(--max-memory); give a shorter record"), line
