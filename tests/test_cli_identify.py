"""``motionhyst identify``: force-displacement and closed-loop records, JSON, text, errors."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import feedforward_fragment, main, record_kind
from motionhyst.hysteresis import Jenkins, MaxwellSlip
from motionhyst.identify import identify_maxwell_slip, load_force_displacement_csv
from motionhyst.scenario import Scenario, default_scenario, default_scenario_path

K_TRUE = np.array([10.0, 6.0, 4.0])  # N/m, total 20 N/m as Table I's k_J
FC_TRUE = np.array([0.01, 0.02, 0.03])  # N; slip displacements 1, 3.3 and 7.5 mm
NOISE = 0.01  # force noise relative to the force RMS
N_SAMPLES = 2000
IDENTIFY_KEYS = {"model", "elements", "fit_rms", "fit_nrms", "r2", "n_samples", "offset",
                 "offset_std", "criterion", "signal", "candidates", "record", "data",
                 "covariance"}
ELEMENT_KEYS = {"k", "fc", "k_std", "fc_std"}


def _reject_constant(name: str):
    raise AssertionError(f"non-standard JSON token {name}")


def strict_json(text: str):
    """Parse JSON, refusing NaN, Infinity and -Infinity."""
    return json.loads(text, parse_constant=_reject_constant)


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def run_json(capsys, *args: str) -> dict:
    rc, out, err = run(capsys, *args, "--json")
    assert rc == 0, err
    assert err == ""
    return strict_json(out)


def sweep(n: int = N_SAMPLES, cycles: int = 20, a_max: float = 0.012,
          a_min: float = 3e-4) -> np.ndarray:
    """Sine whose amplitude decays from `a_max` to `a_min` and grows back [m]."""
    theta = np.linspace(0.0, 2 * np.pi * cycles, n)
    env = np.concatenate([np.geomspace(a_max, a_min, n // 2),
                          np.geomspace(a_min, a_max, n - n // 2)])
    return env * np.sin(theta)


def write_csv(path: Path, header: str, columns) -> Path:
    rows = "\n".join(",".join(repr(float(v)) for v in row) for row in zip(*columns, strict=True))
    path.write_text(header + "\n" + rows + "\n")
    return path


@pytest.fixture(scope="module")
def record(tmp_path_factory) -> Path:
    """A noisy force-displacement record of a three-element Maxwell-slip link."""
    rng = np.random.default_rng(6)
    x = sweep()
    w = MaxwellSlip(K_TRUE, FC_TRUE).response(x)
    w = w + NOISE * np.sqrt(np.mean(w**2)) * rng.standard_normal(x.size)
    t = np.arange(x.size) * 1e-2
    return write_csv(tmp_path_factory.mktemp("fd") / "record.csv", "time,displacement,force",
                     (t, x, w))


@pytest.fixture(scope="module")
def identified(record) -> dict:
    """``identify --json`` of the record (run once; capsys is function-scoped)."""
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["identify", str(record), "--json"])
    assert rc == 0
    return strict_json(buf.getvalue())


# --------------------------------------------------------------------------- force-displacement


def test_json_schema(identified, record):
    # a force-displacement record's displacement: its noise found, and whether it was removed
    assert set(identified) == IDENTIFY_KEYS | {"displacement_noise"}
    assert set(identified["displacement_noise"]) == {"sigma", "filtered", "cutoff_hz", "reason"}
    assert identified["model"] == "maxwell-slip"
    assert identified["record"] == "force-displacement"
    assert identified["data"] == str(record)
    assert identified["signal"] == "force"
    assert identified["n_samples"] == N_SAMPLES
    assert [set(e) for e in identified["elements"]] == [ELEMENT_KEYS] * 3
    assert {c["n_elements"] for c in identified["candidates"]} >= {1, 2, 3, 4}


def test_json_values_recover_the_link(identified):
    assert identified["criterion"].startswith("rms")
    k = np.array([e["k"] for e in identified["elements"]])
    fc = np.array([e["fc"] for e in identified["elements"]])
    # 1 % noise on 2000 samples: measured errors below 0.22 % (k) and 0.18 % (fc)
    np.testing.assert_allclose(k, K_TRUE, rtol=0.01)
    np.testing.assert_allclose(fc, FC_TRUE, rtol=0.01)
    for e, kt, fct in zip(identified["elements"], K_TRUE, FC_TRUE, strict=True):
        assert 0 < e["k_std"] < 0.01 * kt
        assert 0 < e["fc_std"] < 0.01 * fct
        assert abs(e["k"] - kt) < 4 * e["k_std"]
        assert abs(e["fc"] - fct) < 4 * e["fc_std"]
    # the residual is the added noise: 1 % of the force RMS
    assert identified["fit_nrms"] == pytest.approx(NOISE, rel=0.1)
    assert identified["r2"] == pytest.approx(1 - identified["fit_nrms"] ** 2, abs=1e-9)
    assert abs(identified["offset"]) < 1e-3


def test_json_agrees_with_the_library(identified, record):
    t, x, w = load_force_displacement_csv(record)
    lib = identify_maxwell_slip(x, w, t=t).to_dict()
    for cli_el, lib_el in zip(identified["elements"], lib["elements"], strict=True):
        for key in ELEMENT_KEYS:
            assert cli_el[key] == pytest.approx(lib_el[key], rel=1e-12)
    assert identified["fit_rms"] == pytest.approx(lib["fit_rms"], rel=1e-12)


def fragment_of(text: str) -> str:
    """The TOML the text summary offers to paste (its comment lines to the end)."""
    return text[text.index("# hysteresis feedforward"):]


def test_text_summary_and_fragment_ready_to_paste(capsys, record, identified):
    rc, out, err = run(capsys, "identify", str(record))
    assert rc == 0 and err == ""
    assert f"{record}" in out and "force-displacement record" in out
    assert "elements: 3" in out
    assert "k [N/m]" in out and "fc [N]" in out and "std k [N/m]" in out
    section = tomllib.loads(fragment_of(out))["feedforward"]
    assert section["type"] == "rigid-body"
    assert section["hysteresis"]["model"] == "maxwell-slip"
    # pasted into Table I, the scenario compensates with the identified model
    data = default_scenario().to_dict()
    data["feedforward"] = section
    hff = Scenario.from_dict(data, "pasted").loop().hysteresis_feedforward
    assert isinstance(hff, MaxwellSlip)
    np.testing.assert_allclose(hff.k, [e["k"] for e in identified["elements"]], rtol=1e-6)
    np.testing.assert_allclose(hff.fc, [e["fc"] for e in identified["elements"]], rtol=1e-6)


def test_fixed_number_of_elements(capsys, record):
    d = run_json(capsys, "identify", str(record), "--elements", "2")
    assert len(d["elements"]) == 2
    assert d["criterion"].startswith("fixed")
    assert d["fit_nrms"] > 5 * NOISE  # two elements cannot describe three


def test_one_element_is_written_as_jenkins(capsys, record):
    rc, out, err = run(capsys, "identify", str(record), "--elements", "1")
    assert rc == 0, err
    hyst = tomllib.loads(fragment_of(out))["feedforward"]["hysteresis"]
    assert hyst["model"] == "jenkins"
    assert isinstance(hyst["k"], float) and isinstance(hyst["fc"], float)
    data = default_scenario().to_dict()
    data["feedforward"]["hysteresis"] = hyst
    assert isinstance(Scenario.from_dict(data).loop().hysteresis_feedforward, Jenkins)


def test_bic_criterion(capsys, record):
    d = run_json(capsys, "identify", str(record), "--criterion", "bic")
    assert d["criterion"].startswith("bic")
    assert len(d["elements"]) == 3


def test_feedforward_fragment_literals():
    text = feedforward_fragment([20.0, 1e-7], [0.05, 3.0])
    hyst = tomllib.loads(text)["feedforward"]["hysteresis"]
    assert hyst == {"model": "maxwell-slip", "k": [20.0, 1e-7], "fc": [0.05, 3.0]}
    assert all(isinstance(v, float) for v in hyst["k"] + hyst["fc"])


# --------------------------------------------------------------------------- closed loop


@pytest.fixture(scope="module")
def closed_loop_case(tmp_path_factory) -> tuple[Path, Path]:
    """A scenario with the three-element link and a transient run of it (``time,...,y1,u``)."""
    folder = tmp_path_factory.mktemp("cl")
    text = default_scenario_path().read_text()
    text = (text.replace('model = "jenkins"', 'model = "maxwell-slip"')
            .replace("k = 20.0 ", "k = [10.0, 6.0, 4.0] ")
            .replace("fc = 0.05 ", "fc = [0.01, 0.02, 0.03] "))
    scenario = folder / "cable.toml"
    scenario.write_text(text)
    assert isinstance(Scenario.from_file(scenario).hysteresis(), MaxwellSlip)
    csv = folder / "run.csv"
    assert main(["simulate", str(scenario), "--time-series", str(csv), "--frequency", "2",
                 "--duration", "1.0", "--json"]) == 0
    return scenario, csv


def _closed_loop_json(capsys, *args: str) -> dict:
    """The JSON of an identification of the noise-free closed-loop record: the fit leaves
    its prefilter's and sampling's error (3e-4 of the force), many times the records'
    rounding noise, so its standard errors are lower bounds (main took 40 times that noise
    from the filters' response to an impulse on the first sample and said nothing), and an
    offset of 0 inside its widened standard error may be said in one warning line."""
    rc, out, err = run(capsys, *args, "--json")
    assert rc == 0, err
    d = strict_json(out)
    assert d["std_lower_bound"] is True and d["std_note"].startswith(
        "standard errors are lower bounds: the fit leaves ")
    assert err == "" or (err.count("\n") == 1 and err.startswith(
        "motionhyst: warning: identify: with residuals beyond white noise (model error or "
        "coloured noise), offset (") and "is not distinguishable from 0" in err), err
    return d


def test_closed_loop_record(capsys, closed_loop_case):
    scenario, csv = closed_loop_case
    capsys.readouterr()
    assert record_kind(csv) == "closed-loop"
    d = _closed_loop_json(capsys, "identify", str(csv), "--scenario", str(scenario))
    assert d["record"] == "closed-loop"
    assert d["scenario"] == str(scenario)
    assert d["signal"] == "prefiltered force"
    assert set(d) == IDENTIFY_KEYS | {"scenario", "cutoff_hz", "std_lower_bound", "std_note"}
    # 20 times the fundamental as estimated from the reversals: (4 + 1) / (2 * 1 s) = 2.5 Hz
    assert d["cutoff_hz"] == pytest.approx(50.0, rel=1e-3)
    assert len(d["elements"]) == 3
    # noise-free simulation: measured errors at most 3.1e-4 (prefilter, sampling)
    np.testing.assert_allclose([e["k"] for e in d["elements"]], K_TRUE, rtol=2e-3)
    np.testing.assert_allclose([e["fc"] for e in d["elements"]], FC_TRUE, rtol=2e-3)
    assert d["fit_nrms"] < 1e-3
    # no silent default plant: the paper's Table I stage is not the stage of a measured loop
    rc, out, err = run(capsys, "identify", str(csv))
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and "--scenario" in err


def test_closed_loop_prefilter_cutoff(capsys, closed_loop_case):
    scenario, csv = closed_loop_case
    capsys.readouterr()
    d = _closed_loop_json(capsys, "identify", str(csv), "--scenario", str(scenario),
                          "--cutoff", "25")
    assert d["cutoff_hz"] == 25.0
    # the model is fitted through the same prefilter, so a lower cut-off costs no bias
    np.testing.assert_allclose([e["k"] for e in d["elements"]], K_TRUE, rtol=2e-3)
    np.testing.assert_allclose([e["fc"] for e in d["elements"]], FC_TRUE, rtol=2e-3)
    rc, out, err = run(capsys, "identify", str(csv), "--scenario", str(scenario), "--cutoff",
                       "1e6")
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert "cutoff_hz must be in (0, " in err and str(csv) in err


def test_closed_loop_offset_option(capsys, closed_loop_case):
    """--offset on a closed-loop record as on input-output ones: none fixes the force
    offset at 0; a position offset is refused; a force-displacement record takes none."""
    scenario, csv = closed_loop_case
    capsys.readouterr()
    d = run_json(capsys, "identify", str(csv), "--scenario", str(scenario), "--offset", "none")
    assert d["offset"] == 0.0 and d["offset_std"] == 0.0
    np.testing.assert_allclose([e["k"] for e in d["elements"]], K_TRUE, rtol=2e-3)
    rc, out, err = run(capsys, "identify", str(csv), "--scenario", str(scenario), "--offset",
                       "output")
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert "position offset does not enter" in err


def test_closed_loop_needs_a_stage_model(capsys, tmp_path, closed_loop_case):
    from motionhyst.core.lti import freqresp
    from motionhyst.plants.two_mass import TwoMassStage

    _, csv = closed_loop_case
    stage = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)
    f = np.geomspace(0.05, 5000.0, 100)
    p1, p2 = freqresp(stage.P1, 2 * np.pi * f), freqresp(stage.P2, 2 * np.pi * f)
    write_csv(tmp_path / "p.csv", "frequency_hz,p1_re,p1_im,p2_re,p2_im",
              (f, p1.real, p1.imag, p2.real, p2.imag))
    text = default_scenario_path().read_text()
    text = (text[:text.index("[stage]")] + '[plant]\nfile = "p.csv"\nmass = 22.5\n'
            'use = "data"\n\n' + text[text.index("[hysteresis]"):])
    (tmp_path / "frd.toml").write_text(text)
    rc, out, err = run(capsys, "identify", str(csv), "--scenario", str(tmp_path / "frd.toml"))
    assert rc == 2 and out == ""
    assert "measured [plant]" in err and err.count("\n") == 1


# --------------------------------------------------------------------------- errors


def _record_text(kind: str) -> str:
    n = 200
    t = np.arange(n) * 1e-3
    x = 0.01 * np.sin(2 * np.pi * 20 * t)
    w = 5.0 * x
    if kind == "short":
        t, x, w = t[:20], x[:20], w[:20]
    elif kind == "constant":
        x = np.full(n, 0.002)
    lines = ["time,displacement,force"] + [
        f"{a!r},{b!r},{c!r}" for a, b, c in zip(t.tolist(), x.tolist(), w.tolist(), strict=True)]
    if kind == "nan":
        lines[10] = "0.009,nan,0.0"
    elif kind == "inf":
        lines[10] = "0.009,0.001,inf"
    elif kind == "header":
        lines[0] = "time,position,force"
    elif kind == "lengths":
        lines[10] = "0.009,0.001"
    elif kind == "empty":
        lines = []
    elif kind == "both":
        lines = [lines[0] + ",y1,u"] + [ln + ",0.0,0.0" for ln in lines[1:]]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(("kind", "args", "match"), [
    ("missing", [], "cannot read"),
    ("header", [], "unknown record header 'time,position,force'; expected "
                   "time,displacement,force (force-displacement) or time,y1,u (closed-loop)"),
    ("empty", [], "empty file"),
    ("short", [], "too short: 20 samples"),
    ("constant", [], "constant displacement"),
    ("nan", [], "non-finite value in displacement"),
    ("inf", [], "non-finite value in force"),
    ("lengths", [], "inconsistent lengths"),
    ("ok", ["--elements", "0"], "--elements: must be from 1 to 20, got '0'"),
    ("ok", ["--elements", "2.5"], "--elements: must be a whole number"),
    ("ok", ["--criterion", "aic"], "--criterion: invalid choice"),
    ("ok", ["--scenario", "x.toml"], "--scenario applies to closed-loop records"),
    ("ok", ["--cutoff", "10"], "--cutoff applies to closed-loop records"),
    ("ok", ["--cutoff", "-1"], "--cutoff: value must be > 0"),
    ("both", [], "columns of both a force-displacement and a closed-loop record; choose one "
                 "with --record"),
    ("ok", ["--record", "closed-loop"], "a closed-loop record needs the columns time,y1,u; "
                                        "the header is 'time,displacement,force'"),
    ("ok", ["--record", "hysteresis"], "--record: invalid choice"),
])
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, kind, args, match):
    path = tmp_path / "rec.csv"
    if kind != "missing":
        path.write_text(_record_text(kind))
    rc, out, err = run(capsys, "identify", str(path), *args, "--json")
    assert rc == 2
    assert out == ""
    assert match in err
    assert err.count("\n") == 1 and "Traceback" not in err
    if kind not in ("ok",):
        assert "rec.csv" in err


def test_record_kind_chosen_where_the_header_has_both(capsys, tmp_path, record, identified):
    lines = record.read_text().splitlines()
    both = tmp_path / "both.csv"
    both.write_text("\n".join([lines[0] + ",y1,u"] + [ln + ",0,0" for ln in lines[1:]]) + "\n")
    d = run_json(capsys, "identify", str(both), "--record", "force-displacement")
    assert d["record"] == "force-displacement"
    assert d["elements"] == identified["elements"]


def test_missing_argument(capsys):
    rc, out, err = run(capsys, "identify")
    assert rc == 2 and out == ""
    assert "DATA.csv" in err and err.count("\n") == 1
