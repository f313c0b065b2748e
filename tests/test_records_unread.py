"""Long records sized before they are read (issue 26): a record file of 8 MB or more
(:data:`motionhyst.io.records.SIZED_UNREAD_BYTES`) gives its samples first, a CSV file's
rows counted from its line ends (1 MB at a time), a MATLAB file's from the sizes its
variables declare, and the command's estimate from those samples refuses it unread: one line
naming the file, its samples and --max-memory.  (An estimate from the lengths of the first
and last lines was 2.9 times high for a record at rest at both ends: review A13a H1.)
Before, the record was read whole (its own budget, four times the file) and the same
estimate refused it after: 1e6 samples of CSV, 157 MB and 2.2 s of wall time against 39 MB
and 0.7 s."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.io import records
from motionhyst.io.csvdata import count_rows
from motionhyst.io.records import check_unread, record_samples

N = 300_000
"""Samples of the long records: 10-11 MB of CSV."""

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _write_csv(path: Path, header: str, n: int = N, fmt: str = "%.10g", sep: str = ",",
               newline: str = "\n") -> Path:
    """A record of `n` samples at 1 kHz: time and two sines with noise."""
    t = np.arange(n) / 1000.0
    rng = np.random.default_rng(n)
    a = 60.0 * np.sin(2 * np.pi * 1.3 * t) + rng.standard_normal(n)
    b = 0.01 * np.sin(2 * np.pi * 1.3 * t - 0.3) + 1e-7 * rng.standard_normal(n)
    with open(path, "w", newline="") as fh:
        fh.write(header.replace(",", sep) + newline)
        np.savetxt(fh, np.column_stack([t, a, b]), delimiter=sep, fmt=fmt, newline=newline)
    return path


@pytest.fixture
def unread(monkeypatch):
    """The record readers fail the test if they are called: a refusal comes before them."""
    def read(*args, **kwargs):
        raise AssertionError("the record was read")

    monkeypatch.setattr(records, "read_columns", read)
    monkeypatch.setattr(records, "_read_mat", read)


def _refused(argv: list[str], capsys) -> str:
    assert main(argv) == 2
    captured = capsys.readouterr()
    line = captured.err.strip()
    assert captured.out == "" and "\n" not in line and "Traceback" not in line, captured.err
    return line


def _samples(line: str) -> int:
    return int(re.search(r"\((\d+) samples, not read yet\)", line).group(1))


def test_an_input_output_csv_is_refused_unread(tmp_path, unread, capsys):
    """identify --record input-output of 3e5 samples (at least 210 MB for its least search)
    under --max-memory 100M: refused before pandas reads the file, with its samples within
    exact count, in the same line in a process limited to 1 GB."""
    import limited_process

    _write_csv(tmp_path / "io.csv", "time,force,displacement")
    argv = ["identify", "io.csv", "--record", "input-output", "--plant", "mass-damper",
            "--model", "jenkins", "--max-memory", "100M"]
    line = limited_process.refusal(argv, tmp_path)
    assert line.startswith(f"motionhyst: error: io.csv ({N} samples, not read yet)"), line
    assert _samples(line) == N, line
    assert f"identify's search of {_samples(line)} samples (at least 20 integration" in line
    assert "above the memory budget of 105 MB (--max-memory)" in line, line
    argv[1] = str(tmp_path / "io.csv")
    assert _refused(argv, capsys) == line.replace("io.csv", argv[1], 1)


@pytest.mark.parametrize("model", [None, "dahl"])
def test_a_force_displacement_csv_is_refused_unread(tmp_path, unread, capsys, model):
    """The Maxwell-slip fit (its bound and the check that the loops open) and a link by
    --model, from 3e5 samples under --max-memory 100M: refused unread, the file named once."""
    path = _write_csv(tmp_path / "fd.csv", "time,force,displacement")
    line = _refused(["identify", str(path), *(["--model", model] if model else []),
                     "--max-memory", "100M"], capsys)
    assert line.startswith(f"motionhyst: error: {path} ({N} samples, not read yet)"), line
    assert line.count(str(path)) == 1 and _samples(line) == N, line
    what = ("the Maxwell-slip fit of" if model is None
            else "identify's dahl fit of a force-displacement record (")
    assert f"{what}{' ' if model is None else ''}{_samples(line)} samples" in line, line
    assert "(--max-memory)" in line, line


def test_a_closed_loop_csv_is_refused_unread(tmp_path, unread, capsys):
    path = _write_csv(tmp_path / "cl.csv", "time,y1,u")
    line = _refused(["identify", str(path), "--scenario", str(EXAMPLES / "paper.toml"),
                     "--max-memory", "100M"], capsys)
    assert f"{path} ({N} samples" in line and _samples(line) == N, line
    assert f"a closed-loop record of {_samples(line)} samples" in line, line


def test_matlab_records_are_refused_unread_with_their_declared_samples(tmp_path, unread,
                                                                       capsys):
    """A MATLAB 5 file's structure fields (listed 1x1 by whosmat: their sizes walked in the
    file) and a MATLAB 7.3 file's datasets give their exact samples unread."""
    import h5py
    from scipy.io import savemat

    n = 400_000
    t = np.arange(n) / 1000.0
    savemat(tmp_path / "v5.mat", {"rec": {"t": t[:, None], "f": np.sin(t)[:, None],
                                          "q": np.cos(t)[:, None]}})
    with h5py.File(tmp_path / "v73.mat", "w", userblock_size=512) as fh:
        for name, value in (("t", t), ("f", np.sin(t)), ("q", np.cos(t))):
            fh[name] = value[None, :]  # MATLAB's n x 1, stored transposed
            fh[name].attrs["MATLAB_class"] = np.bytes_("double")
    with open(tmp_path / "v73.mat", "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file".ljust(128, b" "))
    for name, prefix in (("v5.mat", "rec."), ("v73.mat", "")):
        columns = f"time={prefix}t,force={prefix}f,displacement={prefix}q"
        assert record_samples(tmp_path / name, ("time", "force"),
                              {"time": f"{prefix}t", "force": f"{prefix}f"}) == (n, True)
        line = _refused(["identify", str(tmp_path / name), "--record", "input-output",
                         "--plant", "mass-damper", "--model", "jenkins", "--columns", columns,
                         "--max-memory", "100M"], capsys)
        assert f"{tmp_path / name} ({n} samples, not read yet): identify's search of {n} " \
               f"samples" in line, line


@pytest.mark.parametrize(("fmt", "sep", "newline"), [
    ("%.10g", ",", "\n"),        # time stamps that lengthen along the file
    ("%.6e", ",", "\n"),         # numbers of one width
    ("%.10g", ";", "\r\n"),      # a spreadsheet's export
    ("%.17g", "\t", "\n"),
])
def test_a_csv_s_rows_are_counted(tmp_path, fmt, sep, newline):
    path = _write_csv(tmp_path / "r.csv", "time,force,displacement", n=200_000, fmt=fmt,
                      sep=sep, newline=newline)
    assert count_rows(path) == 200_000
    with open(path, "a", newline="") as fh:  # blank lines, a last line without its end
        fh.write(newline * 3 + sep.join(["1", "2", "3"]))
    assert count_rows(path) == 200_001


def test_a_record_at_rest_at_both_ends_is_counted_not_guessed(tmp_path, capsys):
    """Review A13a H1: 4e5 rows whose first and last 64 kB are a stage at rest in the
    shortest form ("t,0,0") and whose middle moves at full precision: the estimate from the
    ends' lines said 1,164,318 samples and refused the record under --max-memory 500M (main
    read it); counted, it is 4e5 samples, and refused under 100M with that number."""
    n = 400_000
    path = tmp_path / "rest.csv"
    t = np.arange(n) / 1000.0
    moving = slice(10_000, n - 10_000)
    with open(path, "w") as fh:
        fh.write("time,force,displacement\n")
        fh.writelines(f"{t[i]:g},0,0\n" for i in range(moving.start))
        np.savetxt(fh, np.column_stack([t[moving], np.sin(t[moving]), 1e-3 * np.cos(t[moving])]),
                   delimiter=",", fmt="%.17g")
        fh.writelines(f"{t[i]:g},0,0\n" for i in range(moving.stop, n))
    assert count_rows(path) == n
    seen = []
    check_unread([path], ("time", "force", "displacement"), seen.append)
    assert seen == [[n]]
    line = _refused(["identify", str(path), "--record", "input-output", "--plant",
                     "mass-damper", "--model", "jenkins", "--max-memory", "100M"], capsys)
    assert f"{path} ({n} samples, not read yet): identify's search of {n} samples" in line


def test_records_within_the_budget_or_small_pass_unread_to_their_reading(tmp_path):
    """The command's estimate is given the samples and passes: nothing is refused; a file
    below 8 MB is left to the estimate after its reading (no sizing at all)."""
    path = _write_csv(tmp_path / "io.csv", "time,force,displacement")
    seen = []
    check_unread([path], ("time", "force", "displacement"), seen.append)
    assert seen == [[N]]
    small = _write_csv(tmp_path / "small.csv", "time,force,displacement", n=1000)
    check_unread([small, small], ("time", "force", "displacement"), seen.append)
    assert len(seen) == 1
    check_unread([path, path], ("time", "force", "displacement"), seen.append)
    assert seen[1] == [N, N]
    # a column not found: its reader says so, not the sizing
    check_unread([path], ("time", "position"), seen.append, columns={"position": "y"})
    check_unread([path], ("time", "y1", "u"), seen.append)
    assert len(seen) == 2
