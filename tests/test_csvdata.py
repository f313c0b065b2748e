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
