"""No command writes over a file its scenario or study reads (issue 26: 0 files changed outside
what a command owns): the files a TOML names (a study's scenario, a scenario's measured plant
``[plant] file``, a study's ``--from-identification``) are inputs as the TOML itself is,
refused as an output even with ``--force``, before anything is read or computed.  Before,
``scan --time-series frf.csv --force`` replaced the measured FRF its scenario named,
``stability --figure`` a plant file named ``.png``, and ``study --table`` its scenario, its
FRF or its identification (exit 0, the user's file lost; review B19 F11, F12)."""

from __future__ import annotations

import os

import pytest

from motionhyst.cli import main
from motionhyst.scenario.files import read_files

SCENARIO = '[plant]\nfile = "{plant}"\n'
"""A scenario of a measured plant: it is not read, the refusal comes first."""


def _files(tmp_path, plant: str = "frf.csv") -> dict[str, bytes]:
    files = {"s.toml": SCENARIO.format(plant=plant).encode(),
             plant: b"frequency_hz,p1_abs\n1,1\n",
             "study.toml": b'scenario = "s.toml"\noutputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n',
             "idn.toml": b"[identification]\n",
             "force.csv": b"time,force\n0,0\n0.001,0\n"}
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    return files


def _refused(argv: list[str], tmp_path, monkeypatch, capsys, files: dict[str, bytes]) -> str:
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    captured = capsys.readouterr()
    line = captured.err.strip()
    assert captured.out == "" and line and "\n" not in line and "Traceback" not in line, (
        captured.err)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == files
    return line


SCAN = ["--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000", "--s-max",
        "1e5", "--compensation", "none"]


@pytest.mark.parametrize(("argv", "option", "target"), [
    (["scan", "s.toml", *SCAN, "--time-series", "frf.csv"], "--time-series", "frf.csv"),
    (["predict", "s.toml", "force.csv", "--out", "frf.csv"], "--out", "frf.csv"),
    (["study", "study.toml", "--out", "o.zarr", "--table", "s.toml"], "--table", "s.toml"),
    (["study", "study.toml", "--out", "o.zarr", "--netcdf", "frf.csv"], "--netcdf", "frf.csv"),
    (["study", "study.toml", "--out", "o.zarr", "--from-identification", "idn.toml",
      "--table", "idn.toml"], "--table", "idn.toml"),
], ids=["scan-frf", "predict-frf", "study-scenario", "study-frf", "study-identification"])
def test_a_file_the_toml_names_is_never_an_output(tmp_path, monkeypatch, capsys, argv, option,
                                                  target):
    files = _files(tmp_path)
    line = _refused([*argv, "--force"], tmp_path, monkeypatch, capsys, files)
    assert line.startswith(f"motionhyst: error: {option} {target}"), line
    assert line.endswith("it is an input of this command; choose another output file"), line


def test_a_plant_file_named_as_a_figure_is_not_replaced_by_it(tmp_path, monkeypatch, capsys):
    files = _files(tmp_path, plant="frf.png")
    line = _refused(["stability", "s.toml", "--figure", "frf.png", "--force"], tmp_path,
                    monkeypatch, capsys, files)
    assert line.endswith("it is an input of this command; choose another output file"), line


def test_the_files_a_toml_reads(tmp_path):
    """A study's scenario and its plant, resolved against each TOML's folder (the plant
    against the study's too, as the study reads it), a study's [samples]
    from_identification; a TOML that does not parse, or is a pipe, lists itself alone (its
    errors are the reader's)."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "s.toml").write_text('[plant]\nfile = "../frf.csv"\n')
    (tmp_path / "study.toml").write_text('scenario = "sub/s.toml"\n')
    (tmp_path / "bad.toml").write_text("scenario = \n")
    assert read_files(tmp_path / "study.toml") == [
        tmp_path / "study.toml", tmp_path / "sub" / "s.toml", tmp_path / "sub" / ".." / "frf.csv",
        tmp_path / ".." / "frf.csv"]  # the study reads it against its own folder
    (tmp_path / "mc.toml").write_text('scenario = "sub/s.toml"\n[samples]\n'
                                      'from_identification = "idn.toml"\n')
    assert tmp_path / "idn.toml" in read_files(tmp_path / "mc.toml")
    assert read_files(tmp_path / "bad.toml") == [tmp_path / "bad.toml"]
    os.mkfifo(tmp_path / "pipe.toml")  # not opened: it would wait for a writer
    (tmp_path / "p.toml").write_text('scenario = "pipe.toml"\n')
    assert read_files(tmp_path / "p.toml") == [tmp_path / "p.toml", tmp_path / "pipe.toml"]
    assert read_files(None) == []
