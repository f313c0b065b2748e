"""Plausibility warnings (issue 10): one stderr line each, the result still printed, exit 0."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path


def _measured(tmp_path):
    f = np.geomspace(1.0, 1000.0, 40)
    p = (-1.0 / (22.5 * (2 * np.pi * f) ** 2)).tolist()
    (tmp_path / "plant.csv").write_text("frequency_hz,p1_re,p1_im,p2_re,p2_im\n" + "".join(
        f"{a!r},{b!r},0,{b!r},0\n" for a, b in zip(f.tolist(), p, strict=True)))
    text = default_scenario_path().read_text()
    text = (text[:text.index("[stage]")] + '[plant]\nfile = "plant.csv"\nuse = "data"\n'
            "mass = 22.5\n\n" + text[text.index("[hysteresis]"):])
    (tmp_path / "m.toml").write_text(text)
    return str(tmp_path / "m.toml")


@pytest.mark.parametrize(("argv", "warnings"), [
    (["analyze", "--frequency", "0.05", "5"], ["0.05 Hz below f* = 0.15 Hz"]),
    (["steady", "--amplitude", "0.002", "--frequency", "5"],
     ["never slips (zeta = fc / (k A) = 1.25 >= 1)"]),
    (["analyze", "--amplitude", "0.001", "--frequency", "0.1", "5"],
     ["0.1 Hz below f*", "never slips"]),
    (["simulate", "--time-series", "{tmp}/run.csv", "--frequency", "2", "--duration", "0.1",
      "--output-rate", "1000"], ["exceeds --duration 0.1 s: no full period"]),
    (["analyze", "{measured}", "--frequency", "0.5", "5", "2000"],
     ["0.5, 2000 Hz outside the measured plant's data (1-1000 Hz)"]),
])
def test_warnings_are_stderr_lines_and_exit_0(tmp_path, capsys, argv, warnings):
    measured = _measured(tmp_path) if "{measured}" in argv else ""
    argv = [a.format(tmp=tmp_path, measured=measured) for a in argv]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert out.strip()  # the result is printed as usual
    lines = [ln for ln in err.splitlines() if ln.startswith("motionhyst: warning: ")]
    assert len(lines) == len(warnings), err
    for line, word in zip(lines, warnings, strict=True):
        assert word in line, (word, line)


def test_no_warning_where_the_model_holds(capsys):
    assert main(["analyze", "--frequency", "5", "10"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_loop_without_bandwidth_says_so_and_warns_naming_the_mass(tmp_path, capsys):
    """m1 = 1e20 kg: |C P2| never reaches 1; no 'nan Hz' or 'inf deg' (issue 26)."""
    text = default_scenario_path().read_text()
    assert "m1 = 5.0 " in text
    (tmp_path / "heavy.toml").write_text(text.replace("m1 = 5.0 ", "m1 = 1e20 "))
    assert main(["analyze", str(tmp_path / "heavy.toml")]) == 0
    out, err = capsys.readouterr()
    assert "none (|C P2| does not fall through 1 in the range searched)" in out
    assert "unbounded (|C P2| never reaches 1: no gain crossover)" in out
    assert not {"nan", "inf"} & set(out.replace("(", " ").split()), out
    lines = [ln for ln in err.splitlines() if ln.startswith("motionhyst: warning: ")]
    assert len(lines) == 2 and "the loop has no bandwidth" in lines[1], err
    assert "M = 1e+20 kg" in lines[1]
    assert "[stage] m1 = 1e+20 kg, a factor 1e+16 above" in lines[0]  # the key to check


def test_another_librarys_warning_is_one_line_without_a_source_path(capsys, monkeypatch):
    import warnings

    from motionhyst.cli._common import warnings_on_stderr

    monkeypatch.delenv("MOTIONHYST_TRACEBACK", raising=False)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        with warnings_on_stderr("steady"):
            warnings.warn("invalid value encountered in cast", RuntimeWarning, stacklevel=1)
    err = capsys.readouterr().err
    assert err == "motionhyst: warning: steady: RuntimeWarning: invalid value encountered in cast\n"
