"""The one CSV reader: spreadsheet dialects, errors by line and column, tables in memory."""

from __future__ import annotations

import codecs

import numpy as np
import pandas as pd
import pytest

from motionhyst.identify import load_force_displacement_csv
from motionhyst.io.csvdata import CSVError, read_columns, read_header
from motionhyst.plants.measured import load_frd_plant
from motionhyst.time.references import load_reference_csv

T = np.linspace(0.0, 0.5, 6)
R = np.array([0.0, 1.5e-3, 2.25e-3, -3.125e-4, 4e-3, 5.5e-3])
EXPECTED = np.column_stack([T, R])


def _rows(sep: str, decimal: str = ".") -> list[str]:
    return [f"{t!r}{sep}{r!r}".replace(".", decimal) if decimal != "." else f"{t!r}{sep}{r!r}"
            for t, r in EXPECTED.tolist()]


def _write(path, text: str, encoding: str = "utf-8", bom: bytes = b""):
    path.write_bytes(bom + text.encode(encoding))
    return path


@pytest.mark.parametrize(("name", "text", "encoding", "bom"), [
    ("plain", "time,position\n" + "\n".join(_rows(",")) + "\n", "utf-8", b""),
    ("excel-bom-crlf", "time,position\r\n" + "\r\n".join(_rows(",")) + "\r\n", "utf-8",
     codecs.BOM_UTF8),
    ("semicolon-spaces-case", " Time ; POSITION \r\n" + "\r\n".join(_rows("; ")) + "\r\n",
     "utf-8", codecs.BOM_UTF8),
    ("semicolon-decimal-comma", "time;position\n" + "\n".join(_rows(";", ",")) + "\n",
     "utf-8", b""),
    ("tab-utf16", "time\tposition\r\n" + "\r\n".join(_rows("\t")) + "\r\n", "utf-16-le",
     codecs.BOM_UTF16_LE),
    ("quoted-extra-columns-trailing-sep",
     '"Index","Time","Position",\n' + "\n".join(f"{i},{row}," for i, row in
                                                  enumerate(_rows(","))) + "\n",
     "utf-8", b""),
    ("blank-lines-no-final-newline", "\n\ntime,position\n\n" + "\n".join(_rows(", ")),
     "utf-8", b""),
])
def test_dialects_read_the_same_numbers(tmp_path, name, text, encoding, bom):
    path = _write(tmp_path / f"{name}.csv", text, encoding, bom)
    data = read_columns(path, ("time", "position"))
    np.testing.assert_array_equal(data, EXPECTED)
    assert data.dtype == np.float64 and data.flags.c_contiguous
    ref = load_reference_csv(path)  # and through a loader of the package
    np.testing.assert_array_equal(ref.r, R)


def test_floats_are_parsed_exactly(tmp_path):
    rng = np.random.default_rng(1)
    x = rng.standard_normal(20_000) * 10.0 ** rng.integers(-15, 8, 20_000)
    path = tmp_path / "x.csv"
    path.write_text("time,position\n" + "".join(f"{i},{float(v)!r}\n" for i, v in enumerate(x)))
    np.testing.assert_array_equal(read_columns(path, ("time", "position"))[:, 1], x)


def test_nan_and_inf_written_out_are_kept_for_the_caller(tmp_path):
    path = _write(tmp_path / "r.csv", "time,position\n0,nan\n1,inf\n2,-inf\n")
    data = read_columns(path, ("time", "position"))
    assert np.isnan(data[0, 1]) and data[1, 1] == np.inf and data[2, 1] == -np.inf


@pytest.mark.parametrize(("text", "fragments"), [
    ("time,position\n0,0\n0.1,1e-3\n0.2,abc\n", ["non-numeric value 'abc'", "line 4",
                                                  "column 'position'"]),
    ("time;position\n0;0\n\n0.1;1e-3\n0,2x;2e-3\n", ["non-numeric value '0,2x'", "line 5",
                                                     "column 'time'"]),
    ("time,position\n0,0\n0.1,\n", ["an empty cell", "line 3", "column 'position'"]),
    ("time,position\n0,0\n0.1\n0.2,1\n", ["inconsistent lengths: line 3 has 1 fields, "
                                          "the header 2"]),
    ("time,position\n0,0\n0.1,1,7\n", ["inconsistent lengths: line 3 has 3 fields"]),
    ("time,position\n0,0,1\n0.1,1,7\n", ["inconsistent lengths: line 2 has 3 fields, "
                                         "the header 2"]),
    ("time,position\n0,0\n" + "0," * 70_000 + "0\n0.2,1\n",  # refused before pandas reads it
     ["inconsistent lengths: line 3 has 70001 fields, the header 2 (refused unread)"]),
    ("time,position\n0,0\n\n0.1," + "7" * 200_000,
     ["line 4 is 200 kB long: not a row of 2 numbers"]),
    ("t,pos\n0,0\n", ["missing column(s) time, position", "need a header with time,position",
                      "found t,pos"]),
    ("time,Time\n0,0\n", ["column 'time' appears twice"]),
    ("time,position\n", ["no data rows"]),
    ("", ["empty file"]),
    ("\n \n", ["empty file"]),
])
def test_errors_are_one_line_naming_file_line_and_column(tmp_path, text, fragments):
    path = _write(tmp_path / "bad.csv", text)
    with pytest.raises(CSVError) as info:
        read_columns(path, ("time", "position"))
    msg = str(info.value)
    assert "\n" not in msg and str(path) in msg
    for fragment in fragments:
        assert fragment in msg, (fragment, msg)


@pytest.mark.parametrize(("bad", "fragments"), [
    ("2500,abc", ["non-numeric value 'abc' at line 2502, column 'position'"]),
    ("2500,", ["an empty cell at line 2502, column 'position'"]),
    ("2500,1,7", ["inconsistent lengths: line 2502 has 3 fields"]),
    (None, []),
])
def test_a_file_read_in_chunks_gives_the_numbers_and_errors_of_one_read(tmp_path, monkeypatch,
                                                                         bad, fragments):
    """pandas reads a file :data:`~motionhyst.io.csvdata._CHUNK_ROWS` rows at a time: the
    numbers, a non-numeric or empty cell and a long row past the rows checked before pandas
    (2000) are those of one read, named by their line in the file, whatever the chunks."""
    from motionhyst.io import csvdata

    rows = [f"{i},{i * 1e-3!r}" for i in range(3000)]
    if bad is not None:
        rows[2500] = bad
    path = _write(tmp_path / "r.csv", "time,position\n" + "\n".join(rows) + "\n")
    results = []
    for chunk in (1 << 20, 1000, 7):
        monkeypatch.setattr(csvdata, "_CHUNK_ROWS", chunk)
        try:
            results.append(read_columns(path, ("time", "position")))
        except CSVError as exc:
            results.append(str(exc))
    if bad is None:
        assert results[0].shape == (3000, 2) and results[0][2999, 1] == 2999e-3
        for data in results[1:]:
            np.testing.assert_array_equal(data, results[0])
    else:
        assert results[1:] == results[:1] * 2, results
        for fragment in fragments:
            assert fragment in results[0], (fragment, results[0])


def test_a_million_rows_are_read_within_a_few_times_their_numbers(tmp_path):
    """1e6 rows of time,position (21 MB of CSV, 16 MB of floats) are read within three times
    their floats (48 MB) of address space above what the process held before (measured 38-42
    MB): read whole, pandas' C parser reserved 460 MB (23 times the file, most of it never
    touched) and, limited, needed 60-85 MB."""
    import subprocess
    import sys

    from limited_process import environment

    n = 1_000_000
    t = np.arange(n) / 1000.0
    np.savetxt(tmp_path / "r.csv", np.column_stack([t, np.sin(t)]), delimiter=",",
               fmt="%.10g", header="time,position", comments="")
    script = tmp_path / "read.py"
    script.write_text(
        "import resource, sys\n"
        "from motionhyst.core.budget import set_max_memory\n"
        "from motionhyst.io.csvdata import read_columns\n"
        "set_max_memory(1 << 30)\n"  # the address-space limit alone decides
        "read_columns(sys.argv[1], ('time', 'position'))\n"  # pandas loaded
        "with open('/proc/self/status') as f:\n"
        "    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith('VmSize'))\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + 3 * 16 * 10 ** 6,) * 2)\n"
        "data = read_columns(sys.argv[2], ('time', 'position'))\n"
        "print(data.shape[0], repr(float(data[-1, 0])))\n")
    (tmp_path / "small.csv").write_text("time,position\n0,1\n0.001,2\n")
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "small.csv"),
                           str(tmp_path / "r.csv")], capture_output=True, text=True,
                          env=environment(), timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == [str(n), "999.999"], proc.stdout


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(CSVError, match=r"cannot read .*nope\.csv"):
        read_columns(tmp_path / "nope.csv", ("time",))
    with pytest.raises(CSVError, match="it is a folder"):
        read_header(tmp_path)


def test_header_is_normalised(tmp_path):
    path = _write(tmp_path / "h.csv", "\ufeff Time ;\"Force\"; y1\r\n1;2;3\r\n")
    assert read_header(path) == ["time", "force", "y1"]


def test_dataframes_and_arrays_are_accepted_where_a_path_is():
    frame = pd.DataFrame({" Time": T, "POSITION": R, "other": 0.0})
    np.testing.assert_array_equal(read_columns(frame, ("time", "position")), EXPECTED)
    np.testing.assert_array_equal(read_columns({"time": T, "position": R},
                                               ("time", "position")), EXPECTED)
    np.testing.assert_array_equal(read_columns(EXPECTED, ("time", "position")), EXPECTED)
    assert load_reference_csv(frame).duration == pytest.approx(0.5)
    with pytest.raises(CSVError, match=r"the DataFrame: missing column.*position"):
        read_columns(frame[[" Time"]], ("time", "position"))
    with pytest.raises(CSVError, match=r"the array: need shape \(rows, 2\)"):
        read_columns(np.zeros((4, 3)), ("time", "position"))
    with pytest.raises(CSVError, match="the array: no data rows"):
        read_columns(np.zeros((0, 2)), ("time", "position"))
    with pytest.raises(CSVError, match="non-numeric value 'x' at row 2, column 'position'"):
        read_columns(pd.DataFrame({"time": [0, 1], "position": ["1", "x"]}),
                     ("time", "position"))


def test_loaders_take_frames():
    t = np.linspace(0.0, 1.0, 200)
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    w = np.clip(20 * x, -0.01, 0.01)
    frame = pd.DataFrame({"Time": t, "Displacement": x, "Force": w})
    got = load_force_displacement_csv(frame)
    np.testing.assert_array_equal(got[1], x)
    with pytest.raises(ValueError, match=r"the array: .*non-finite value in force"):
        load_force_displacement_csv(np.column_stack([t, x, np.where(t > 0.5, np.inf, w)]))
    f = np.geomspace(1.0, 100.0, 5)
    p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    plant = load_frd_plant(pd.DataFrame({"frequency_hz": f, "p1_re": p, "p1_im": 0.0,
                                         "p2_re": p, "p2_im": 0.0}))
    assert plant.M == pytest.approx(22.5)
