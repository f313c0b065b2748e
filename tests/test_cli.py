"""The ``motionhyst`` command: df and analyze, JSON and text output, one-line usage errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

from motionhyst import entry
from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path

DF_KEYS = {"model", "k", "fc", "points"}
POINT_KEYS = {"amplitude", "zeta", "re", "im", "abs", "phase_deg"}
ANALYZE_KEYS = {"zeta", "df_re", "df_im", "df_abs_over_k", "df_phase_deg", "f_star_hz",
                "bandwidth_hz", "mismatch_crossover_hz", "mismatch_crossover_exact_hz",
                "mismatch"}
MISMATCH_KEYS = {"frequency_hz", "abs", "phase_deg", "asymptote_abs"}


def _reject_constant(name: str):
    raise AssertionError(f"non-standard JSON token {name}")


def strict_json(text: str):
    """Parse JSON, refusing NaN, Infinity and -Infinity."""
    return json.loads(text, parse_constant=_reject_constant)


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def run_json(capsys, *args: str):
    rc, out, err = run(capsys, *args, "--json")
    assert rc == 0, err
    assert err == ""
    return strict_json(out)


def write_scenario(path: Path, edits: dict[str, dict]) -> Path:
    """Copy of the packaged scenario with some values replaced (simple text edits)."""
    text = default_scenario_path().read_text()
    data = tomllib.loads(text)
    lines = []
    section = None
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("["):
            section = stripped[1:stripped.index("]")]
        elif "=" in stripped and not stripped.startswith("#"):
            key = stripped.split("=", 1)[0].strip()
            if key in edits.get(section, {}):
                line = f"{key} = {edits[section][key]}"
        lines.append(line)
    path.write_text("\n".join(lines) + "\n")
    changed = tomllib.loads(path.read_text())
    assert changed != data or not edits
    return path


# ------------------------------------------------------------------- df
def test_df_json_schema_and_values(capsys):
    d = run_json(capsys, "df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01")
    assert set(d) == DF_KEYS
    assert d["model"] == "jenkins"
    assert d["k"] == 20.0 and d["fc"] == 0.05
    assert len(d["points"]) == 1
    p = d["points"][0]
    assert set(p) == POINT_KEYS
    assert p["amplitude"] == 0.01
    assert p["zeta"] == pytest.approx(0.25)
    assert p["abs"] / d["k"] == pytest.approx(0.309, abs=5e-4)
    assert p["phase_deg"] == pytest.approx(50.7, abs=0.05)
    assert math.hypot(p["re"], p["im"]) == pytest.approx(p["abs"], rel=1e-12)
    assert math.degrees(math.atan2(p["im"], p["re"])) == pytest.approx(p["phase_deg"], rel=1e-12)
    assert p["re"] > 0 and p["im"] > 0


def test_df_multiple_amplitudes(capsys):
    amps = ["0.001", "0.0025", "0.01", "0.1", "1"]
    d = run_json(capsys, "df", "--k", "20", "--fc", "0.05", "--amplitude", *amps)
    pts = d["points"]
    assert [p["amplitude"] for p in pts] == [float(a) for a in amps]
    for p in pts:
        assert p["zeta"] == pytest.approx(0.05 / (20 * p["amplitude"]), rel=1e-12)
    # no slip below fc/k = 2.5 mm: the element is the spring k
    for p in pts[:2]:
        assert p["abs"] == pytest.approx(20.0) and p["phase_deg"] == pytest.approx(0.0, abs=1e-9)
    # slipping: |D| falls and the phase lead is positive
    slipping = pts[2:]
    assert slipping[0]["abs"] > slipping[1]["abs"] > slipping[2]["abs"]
    assert all(p["phase_deg"] > 0 for p in slipping)
    assert slipping[0] == pytest.approx(run_json(capsys, "df", "--k", "20", "--fc", "0.05",
                                                 "--amplitude", "0.01")["points"][0])


def test_df_amplitude_zero_gives_null_zeta(capsys):
    rc, out, err = run(capsys, "df", "--k", "20", "--fc", "0.05", "--amplitude", "0", "0.01",
                       "--json")
    assert rc == 0 and err == ""
    for token in ("NaN", "Infinity", "nan", "inf"):
        assert token not in out
    d = strict_json(out)
    p0, p1 = d["points"]
    assert p0["amplitude"] == 0.0
    assert p0["zeta"] is None
    assert p0["abs"] == 20.0
    assert p0["re"] == 20.0 and p0["im"] == 0.0
    assert p0["phase_deg"] == 0.0
    assert p1["zeta"] == pytest.approx(0.25)


def test_df_scales_with_k(capsys):
    d = run_json(capsys, "df", "--k", "40", "--fc", "0.1", "--amplitude", "0.01")
    p = d["points"][0]  # same zeta, so |D|/k and the phase are unchanged
    assert p["zeta"] == pytest.approx(0.25)
    assert p["abs"] / 40 == pytest.approx(0.3086, abs=1e-4)


def test_df_text_output(capsys):
    rc, out, err = run(capsys, "df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "0.1")
    assert rc == 0 and err == ""
    assert "N/m" in out and "[m]" in out and "[deg]" in out
    assert "k = 20 N/m" in out and "fc = 0.05 N" in out
    for number in ("0.01", "0.25", "3.91", "4.775", "6.171", "0.3086", "50.69", "0.025"):
        assert number in out, number
    with pytest.raises(json.JSONDecodeError):
        json.loads(out)


# -------------------------------------------------------------- analyze
@pytest.fixture
def analysis(capsys):
    return run_json(capsys, "analyze")


def test_analyze_json_schema(analysis):
    assert ANALYZE_KEYS <= set(analysis)
    assert isinstance(analysis["mismatch"], list)
    assert len(analysis["mismatch"]) == 3
    for p in analysis["mismatch"]:
        assert MISMATCH_KEYS <= set(p)
        assert all(isinstance(p[k], float) for k in MISMATCH_KEYS)


def test_analyze_json_values(analysis):
    a = analysis
    assert a["zeta"] == pytest.approx(0.25)
    assert a["df_abs_over_k"] == pytest.approx(0.309, abs=5e-4)
    assert a["df_phase_deg"] == pytest.approx(50.7, abs=0.05)
    assert math.hypot(a["df_re"], a["df_im"]) / 20 == pytest.approx(a["df_abs_over_k"])
    assert a["f_star_hz"] == pytest.approx(0.150, abs=5e-4)
    assert a["mismatch_crossover_hz"] == pytest.approx(7.6, abs=0.05)
    assert a["mismatch_crossover_exact_hz"] == pytest.approx(7.6, abs=0.05)
    assert a["bandwidth_hz"] == pytest.approx(120.6, abs=0.1)
    assert [p["frequency_hz"] for p in a["mismatch"]] == [5.0, 10.0, 15.0]
    mags = [p["abs"] for p in a["mismatch"]]
    assert mags[0] > mags[1] > mags[2] > 1.0  # the mismatch fades towards 1 above crossover
    assert mags[0] == pytest.approx(6.04, abs=0.01)
    asym = [p["asymptote_abs"] for p in a["mismatch"]]
    assert asym[0] > 1 > asym[1] > asym[2]  # eq. (20) crosses 1 near 7.6 Hz


def test_analyze_frequency_override(capsys, analysis):
    a = run_json(capsys, "analyze", "--frequency", "2", "3")
    assert [p["frequency_hz"] for p in a["mismatch"]] == [2.0, 3.0]
    for key in ("zeta", "f_star_hz", "bandwidth_hz", "mismatch_crossover_hz"):
        assert a[key] == analysis[key]
    # well below the crossover the mismatch follows its asymptote, eq. (20)
    for p in a["mismatch"]:
        assert p["abs"] == pytest.approx(p["asymptote_abs"], rel=0.02)
        assert p["abs"] > 10


def test_analyze_amplitude_override(capsys):
    a = run_json(capsys, "analyze", "--amplitude", "0.02")
    assert a["zeta"] == pytest.approx(0.125)


def test_analyze_self_consistent(capsys):
    a = run_json(capsys, "analyze", "--self-consistent")
    assert a["amplitude_mode"] == "self-consistent"
    for p in a["mismatch"]:
        assert p["y1_amplitude"] == pytest.approx(0.01, rel=1e-2)
        assert p["y1_amplitude"] != 0.01


def test_analyze_scenario_path(capsys, tmp_path):
    path = write_scenario(tmp_path / "mine.toml",
                          {"reference": {"amplitude": "0.02", "frequencies": "[4.0, 8.0]"}})
    a = run_json(capsys, "analyze", str(path))
    assert a["zeta"] == pytest.approx(0.125)
    assert [p["frequency_hz"] for p in a["mismatch"]] == [4.0, 8.0]
    rc, out, err = run(capsys, "analyze", str(path))
    assert rc == 0 and err == ""
    assert str(path) in out


def test_analyze_packaged_file_equals_default(capsys, analysis):
    assert run_json(capsys, "analyze", str(default_scenario_path())) == analysis


def test_analyze_text_output(capsys):
    rc, out, err = run(capsys, "analyze")
    assert rc == 0 and err == ""
    assert "Table I" in out
    assert "Hz" in out and " m" in out and "deg" in out
    for number in ("0.01", "0.25", "0.3086", "50.69", "0.1501", "120.6", "7.607", "6.04"):
        assert number in out, number
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in (["5"], ["10"],
                                                                                ["15"])]
    assert [r[0] for r in rows] == ["5", "10", "15"]


def test_analyze_measured_plant_gives_null_crossover(capsys, tmp_path):
    """eq. (21) is nan for a measured plant: it is printed as JSON null, never NaN."""
    import numpy as np

    from motionhyst.core.lti import freqresp
    from motionhyst.plants.two_mass import TwoMassStage

    stage = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)
    f = np.geomspace(0.05, 5000.0, 200)
    p1, p2 = freqresp(stage.P1, 2 * np.pi * f), freqresp(stage.P2, 2 * np.pi * f)
    rows = [",".join(repr(float(x)) for x in (fi, a.real, a.imag, b.real, b.imag))
            for fi, a, b in zip(f, p1, p2, strict=True)]
    (tmp_path / "p.csv").write_text("frequency_hz,p1_re,p1_im,p2_re,p2_im\n" + "\n".join(rows))
    text = default_scenario_path().read_text()
    text = (text[:text.index("[stage]")] + '[plant]\nfile = "p.csv"\nmass = 22.5\n'
            'use = "data"\n\n' + text[text.index("[hysteresis]"):])
    (tmp_path / "frd.toml").write_text(text)
    rc, out, err = run(capsys, "analyze", str(tmp_path / "frd.toml"), "--json")
    assert rc == 0, err
    assert "NaN" not in out
    a = strict_json(out)
    assert a["mismatch_crossover_hz"] is None
    assert a["bandwidth_hz"] == pytest.approx(120.6, abs=0.1)
    rc, out, err = run(capsys, "analyze", str(tmp_path / "frd.toml"))
    assert rc == 0 and err == ""
    # the text says why there is no number (issue 26: never "nan Hz" as an answer)
    assert "mismatch crossover (eq. 21)    not resolved (below)" in out
    assert "nan Hz" not in out


# ----------------------------------------------------------------- errors
def assert_usage_error(rc: int, out: str, err: str) -> str:
    assert rc == 2
    assert out == ""
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].strip()
    assert err.endswith("\n")
    return lines[0]


@pytest.mark.parametrize(("args", "fragment"), [
    pytest.param(["df", "--k", "20", "--fc", "-0.05", "--amplitude", "0.01"], "--fc",
                 id="negative-fc"),
    pytest.param(["df", "--k", "20", "--fc", "0", "--amplitude", "0.01"], "--fc", id="zero-fc"),
    pytest.param(["df", "--k", "20", "--fc", "nan", "--amplitude", "0.01"], "--fc",
                 id="nan-fc"),
    pytest.param(["df", "--k", "inf", "--fc", "0.05", "--amplitude", "0.01"], "--k",
                 id="inf-k"),
    pytest.param(["df", "--k", "20", "--fc", "0.05", "--amplitude", "-1"], "--amplitude",
                 id="negative-amplitude"),
    pytest.param(["df", "--k", "20", "--fc", "0.05", "--amplitude", "abc"], "--amplitude",
                 id="text-amplitude"),
    pytest.param(["df", "--fc", "0.05", "--amplitude", "0.01"], "--k", id="missing-k"),
    pytest.param(["df", "--k", "20", "--fc", "0.05"], "--amplitude", id="missing-amplitude"),
    pytest.param(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "--bogus"],
                 "--bogus", id="unknown-option"),
    pytest.param(["frobnicate"], "frobnicate", id="unknown-command"),
    pytest.param([], "command", id="no-command"),
    pytest.param(["analyze", "--frequency", "-2"], "--frequency", id="negative-frequency"),
    pytest.param(["analyze", "--amplitude", "0"], "--amplitude", id="zero-analyze-amplitude"),
])
def test_usage_errors(capsys, args, fragment):
    line = assert_usage_error(*run(capsys, *args))
    assert fragment in line


def test_missing_scenario_file(capsys, tmp_path):
    path = tmp_path / "missing.toml"
    line = assert_usage_error(*run(capsys, "analyze", str(path)))
    assert str(path) in line


def test_missing_scenario_file_with_json(capsys, tmp_path):
    path = tmp_path / "missing.toml"
    assert_usage_error(*run(capsys, "analyze", str(path), "--json"))


@pytest.mark.parametrize(("edits", "fragment"), [
    pytest.param({"stage": {"m1": "-5.0"}}, "m1", id="negative-mass"),
    pytest.param({"hysteresis": {"model": '"preisach"'}}, "preisach", id="unknown-model"),
    pytest.param({"controller": {"K": "6.2e9"}}, "stabilise", id="unstable"),
    pytest.param({"reference": {"frequencies": "[5.0, nan]"}}, "frequencies", id="nan-frequency"),
])
def test_invalid_scenario(capsys, tmp_path, edits, fragment):
    path = write_scenario(tmp_path / "bad.toml", edits)
    line = assert_usage_error(*run(capsys, "analyze", str(path), "--json"))
    assert str(path) in line
    assert fragment in line


def test_toml_syntax_error(capsys, tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[stage\nm1 = 5.0\n")
    line = assert_usage_error(*run(capsys, "analyze", str(path)))
    assert str(path) in line and "line" in line


@pytest.mark.parametrize("command, stops", [
    ("identify", "; its search, which no formula sizes, is stopped after S s of CPU time)"),
    ("reproduce", "; the report is stopped after S s of CPU time)"),
    ("benchmark", ")"), ("simulate", ")")])
def test_max_seconds_help_says_what_it_stops(capsys, command, stops):
    """--max-seconds refuses an estimated run before it starts, and stops identify's search and
    reproduce's report after that much CPU time: each command's help says what it does there
    (review A15b L6; benchmark's fits are not stopped, and its help does not say they are)."""
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "a longer one is refused before it starts" + stops in text


# ---------------------------------------------------------- entry point
def test_console_script_entry_point_is_main():
    """The console script runs :func:`motionhyst.cli.main` through :mod:`_motionhyst_entry`,
    which handles signals before the package and its command line interface are imported;
    :mod:`motionhyst.entry` (an older install's console script) is the same function."""
    import _motionhyst_entry

    with open(Path(__file__).parent.parent / "pyproject.toml", "rb") as f:
        assert tomllib.load(f)["project"]["scripts"] == {"motionhyst": "_motionhyst_entry:main"}
    eps = [ep for ep in metadata.entry_points(group="console_scripts") if ep.name == "motionhyst"]
    assert len(eps) == 1
    assert eps[0].load() is entry.main is _motionhyst_entry.main


def test_module_runs_as_script(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "motionhyst.cli", "df", "--k", "20", "--fc", "0.05",
         "--amplitude", "0.01", "0", "--json"],
        capture_output=True, text=True, cwd=tmp_path, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    d = strict_json(proc.stdout)
    assert d["points"][0]["zeta"] == pytest.approx(0.25)
    assert d["points"][1]["zeta"] is None


@pytest.mark.parametrize("module", ["_motionhyst_entry", "motionhyst.cli"])
def test_both_module_routes_run_the_command(tmp_path, module):
    """``python -m _motionhyst_entry`` is the console script's route, its handlers installed
    before the package loads (main 5c12916: it ran nothing, exit 0); ``python -m
    motionhyst.cli`` goes through the same entry once Python has loaded the package: a
    refusal is one line, exit 2."""
    proc = subprocess.run([sys.executable, "-m", module, "df", "--k", "-20", "--fc", "0.05",
                           "--amplitude", "0.01"], capture_output=True, text=True, cwd=tmp_path,
                          timeout=120, check=False)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert proc.stdout == "" and proc.stderr.startswith("motionhyst: error: ")
    assert proc.stderr.count("\n") == 1, proc.stderr
