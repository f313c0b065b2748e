"""The ``motionhyst`` command with hysteresis models: ``df --model``, ``--harmonics``, and the
describing-function error harmonics of ``simulate --json``."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.hysteresis import BoucWen, Dahl, Jenkins, LuGre, MaxwellSlip
from motionhyst.scenario import default_scenario_path

HARMONIC_KEYS = {"n", "re", "im", "abs_over_amplitude", "phase_deg"}


def _reject_constant(name: str):
    raise AssertionError(f"non-standard JSON token {name}")


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def run_json(capsys, *args: str):
    rc, out, err = run(capsys, *args)
    assert rc == 0, err
    assert err == ""
    return json.loads(out, parse_constant=_reject_constant)


MAXWELL_ARGS = ("df", "--model", "maxwell-slip", "--k", "1", "2", "--fc", "1", "0.5")


# ----------------------------------------------------------------------------- df
def test_df_maxwell_slip_json_schema_and_values(capsys):
    d = run_json(capsys, *MAXWELL_ARGS, "--amplitude", "3", "--json")
    assert set(d) == {"model", "k", "fc", "points"}
    assert d["model"] == "maxwell-slip"
    assert d["k"] == [1, 2] and d["fc"] == [1, 0.5]
    assert len(d["points"]) == 1
    p = d["points"][0]
    assert p["amplitude"] == 3.0
    assert p["zeta"] is None  # no single zeta for several elements (strict JSON: no NaN)
    expected = (Jenkins(1.0, 1.0).describing_function(3.0)
                + Jenkins(2.0, 0.5).describing_function(3.0))
    D = complex(p["re"], p["im"])
    assert abs(D - expected) <= 1e-14 * abs(expected)
    assert p["abs"] == pytest.approx(abs(expected), rel=1e-14)
    assert p["phase_deg"] == pytest.approx(np.degrees(np.angle(expected)), abs=1e-10)
    assert "harmonics" not in p


def test_df_maxwell_slip_several_amplitudes(capsys):
    amps = [0.0, 0.1, 0.5, 3.0, 30.0]
    d = run_json(capsys, *MAXWELL_ARGS, "--amplitude", *map(str, amps), "--json")
    ms = MaxwellSlip([1.0, 2.0], [1.0, 0.5])
    assert [p["amplitude"] for p in d["points"]] == amps
    for p, a in zip(d["points"], amps, strict=True):
        assert complex(p["re"], p["im"]) == pytest.approx(ms.describing_function(a), rel=1e-14)
    assert d["points"][0]["re"] == 3.0 and d["points"][0]["im"] == 0.0  # stuck: sum of k


def test_df_harmonics_json(capsys):
    d = run_json(capsys, *MAXWELL_ARGS, "--amplitude", "3", "0.5", "--harmonics", "5",
                 "--json")
    j1, j2 = Jenkins(1.0, 1.0), Jenkins(2.0, 0.5)
    for p in d["points"]:
        hs = p["harmonics"]
        assert [h["n"] for h in hs] == [1, 2, 3, 4, 5]
        assert all(set(h) == HARMONIC_KEYS for h in hs)
        for h in hs[1::2]:
            assert h["re"] == 0.0 and h["im"] == 0.0 and h["abs_over_amplitude"] == 0.0
        D = complex(p["re"], p["im"])
        h1 = complex(hs[0]["re"], hs[0]["im"])
        assert abs(h1 - D) <= 1e-12 * abs(D)
        assert hs[0]["abs_over_amplitude"] == pytest.approx(p["abs"], rel=1e-12)
        closed = (j1.hosidf_closed_form(p["amplitude"], 5)
                  + j2.hosidf_closed_form(p["amplitude"], 5))
        for h, c in zip(hs, closed, strict=True):
            assert abs(complex(h["re"], h["im"]) - c) <= 1e-12 * abs(D)
            if abs(c) > 1e-10 * abs(D):  # odd harmonics; the even ones are round-off
                assert h["abs_over_amplitude"] == pytest.approx(abs(c), rel=1e-10)
                assert h["phase_deg"] == pytest.approx(np.degrees(np.angle(c)), abs=1e-8)
    # A = 0.5: only the second element (slip displacement fc/k = 0.25, the first's is 1) slips
    h3 = d["points"][1]["harmonics"][2]
    assert complex(h3["re"], h3["im"]) == pytest.approx(
        Jenkins(2.0, 0.5).hosidf_closed_form(0.5, 3)[2], rel=1e-10)
    assert h3["abs_over_amplitude"] > 0.01


def test_df_jenkins_harmonics_json(capsys):
    d = run_json(capsys, "df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01",
                 "--harmonics", "3", "--json")
    assert d["model"] == "jenkins" and d["k"] == 20 and d["fc"] == 0.05
    p = d["points"][0]
    assert p["zeta"] == pytest.approx(0.25)
    h = Jenkins(20.0, 0.05).hosidf_closed_form(0.01, 3)
    got = [complex(x["re"], x["im"]) for x in p["harmonics"]]
    np.testing.assert_allclose(got, h, rtol=0, atol=1e-12 * abs(h[0]))


def test_df_text_output_with_harmonics_has_second_table(capsys):
    rc, out, err = run(capsys, *MAXWELL_ARGS, "--amplitude", "3", "0.2", "--harmonics", "3")
    assert rc == 0 and err == ""
    assert "maxwell-slip" in out
    first, second = out.split("Higher-order describing functions")
    assert "|D| [N/m]" in first
    lines = [ln for ln in second.splitlines() if ln.strip()]
    header, rule, *rows = lines[1:]
    assert "n" in header.split() and "|H_n|" in header
    assert set(rule.replace(" ", "")) == {"-"}
    assert len(rows) == 2 * 3
    assert [row.split()[1] for row in rows] == ["1", "2", "3"] * 2


def test_df_text_output_without_harmonics_has_one_table(capsys):
    rc, out, _ = run(capsys, *MAXWELL_ARGS, "--amplitude", "3")
    assert rc == 0
    assert "Higher-order" not in out


@pytest.mark.parametrize(("args", "element"), [
    (("--model", "bouc-wen", "--k", "20", "--fc", "0.05", "--n", "2", "--beta", "0.7",
      "--gamma", "0.3"), BoucWen(20.0, 0.05, n=2.0, beta=0.7, gamma=0.3)),
    (("--model", "bouc-wen", "--k", "20", "--fc", "0.05"), BoucWen(20.0, 0.05)),
    (("--model", "dahl", "--k", "20", "--fc", "0.05", "--alpha", "2"),
     Dahl(20.0, 0.05, alpha=2.0)),
], ids=["bouc-wen", "bouc-wen-defaults", "dahl"])
def test_df_rate_independent_models_json(capsys, args, element):
    amps = [0.0, 0.001, 0.01]
    d = run_json(capsys, "df", *args, "--amplitude", *map(str, amps), "--harmonics", "3",
                 "--json")
    assert d == {**element.to_dict(), "points": d["points"]}
    assert [p["amplitude"] for p in d["points"]] == amps
    assert all("frequency_hz" not in p for p in d["points"])
    H = element.hosidf(np.array(amps), 3)
    for p, a, h in zip(d["points"], amps, H, strict=True):
        D = complex(element.describing_function(a))
        assert complex(p["re"], p["im"]) == pytest.approx(D, rel=1e-12)
        got = [complex(x["re"], x["im"]) for x in p["harmonics"]]
        np.testing.assert_allclose(got, h, rtol=0, atol=1e-12 * abs(D))
    assert d["points"][0]["re"] == pytest.approx(20.0, rel=1e-12)  # A = 0: stuck, k


def test_df_lugre_needs_frequency_and_gives_every_pair(capsys):
    args = ("df", "--model", "lugre", "--sigma0", "20", "--sigma1", "0.1", "--sigma2", "0.01",
            "--fc", "0.05", "--fs", "0.06", "--vs", "0.01", "--amplitude", "0.001", "0.01")
    d = run_json(capsys, *args, "--frequency", "1", "10", "--json")
    el = LuGre(20.0, 0.1, 0.01, 0.05, 0.06, 0.01)
    assert d == {**el.to_dict(), "points": d["points"]}
    pairs = [(p["amplitude"], p["frequency_hz"]) for p in d["points"]]
    assert pairs == [(0.001, 1.0), (0.01, 1.0), (0.001, 10.0), (0.01, 10.0)]
    for p in d["points"]:
        D = el.describing_function(p["amplitude"], 2 * np.pi * p["frequency_hz"])
        assert complex(p["re"], p["im"]) == pytest.approx(D, rel=1e-12)
    # rate-dependent: the same amplitude at another frequency gives another D
    assert abs(d["points"][0]["im"] - d["points"][2]["im"]) > 0.1 * abs(d["points"][0]["im"])
    rc, out, _ = run(capsys, *args, "--frequency", "1")
    assert rc == 0 and "f [Hz]" in out and "sigma1 = 0.1 N s/m" in out


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (("df", "--k", "1", "2", "--fc", "1", "--amplitude", "3"),
         ("--k", "one value", "jenkins")),
        (("df", "--model", "jenkins", "--k", "1", "--fc", "1", "2", "--amplitude", "3"),
         ("--fc", "one value")),
        (("df", "--model", "maxwell-slip", "--k", "1", "2", "--fc", "1", "--amplitude", "3"),
         ("same length", "2 != 1")),
        (("df", "--model", "maxwell-slip", "--fc", "1", "--amplitude", "3"),
         ("--k", "required")),
        (("df", "--k", "1", "--amplitude", "3"), ("--fc", "required")),
        (("df", "--k", "1", "--fc", "1", "--amplitude", "3", "--harmonics", "0"),
         ("--harmonics", "'0'")),
        (("df", "--k", "1", "--fc", "1", "--amplitude", "3", "--harmonics", "x"),
         ("--harmonics", "'x'")),
        (("df", "--k", "1", "--fc", "1", "--amplitude", "3", "--harmonics", "-2"),
         ("--harmonics",)),
        (("df", "--model", "preisach", "--k", "1", "--fc", "1", "--amplitude", "3"),
         ("--model", "preisach")),
        (("df", "--model", "maxwell-slip", "--k", "1", "-2", "--fc", "1", "1",
          "--amplitude", "3"), ("--k",)),
        (("df", "--model", "lugre", "--sigma0", "20", "--fc", "0.05", "--fs", "0.06",
          "--vs", "0.01", "--amplitude", "3"), ("--frequency", "required", "lugre")),
        (("df", "--model", "lugre", "--sigma0", "20", "--fc", "0.05", "--vs", "0.01",
          "--amplitude", "3", "--frequency", "1"), ("--fs", "required")),
        (("df", "--model", "dahl", "--k", "1", "--fc", "1", "--amplitude", "3",
          "--frequency", "1"), ("--frequency", "rate-independent")),
        (("df", "--model", "dahl", "--k", "1", "--fc", "1", "--beta", "1", "--amplitude", "3"),
         ("--beta", "does not apply", "dahl")),
        (("df", "--k", "1", "--fc", "1", "--sigma0", "1", "--amplitude", "3"),
         ("--sigma0", "does not apply", "jenkins")),
        (("df", "--model", "bouc-wen", "--k", "1", "--fc", "1", "--beta", "0.1", "--gamma",
          "0.3", "--amplitude", "3"), ("beta", "gamma")),
        (("df", "--model", "bouc-wen", "--k", "1", "--fc", "1", "--n", "0.5",
          "--amplitude", "3"), ("n must be >= 1, got 0.5",)),
        (("df", "--model", "bouc-wen", "--k", "1", "--fc", "1", "--beta", "nan",
          "--amplitude", "3"), ("--beta", "finite")),
        (("df", "--model", "dahl", "--k", "1", "--fc", "1", "--alpha", "0",
          "--amplitude", "3"), ("--alpha", "> 0")),
        (("df", "--model", "lugre", "--sigma0", "20", "--sigma1", "-1", "--fc", "0.05",
          "--fs", "0.06", "--vs", "0.01", "--amplitude", "3", "--frequency", "1"),
         ("--sigma1",)),
        (("df", "--model", "dahl", "--k", "1", "2", "--fc", "1", "--amplitude", "3"),
         ("--k", "one value")),
    ],
)
def test_df_usage_errors_are_one_line(capsys, args, fragments):
    rc, out, err = run(capsys, *args)
    assert rc == 2
    assert out == ""
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert err.startswith("motionhyst: error: df: ")
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in err, (fragment, err)


# ----------------------------------------------------------------------- simulate
@pytest.fixture(scope="module")
def simulate_points():
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["steady", "--json"])
    assert rc == 0
    return json.loads(buf.getvalue(), parse_constant=_reject_constant)["points"]


def test_simulate_json_has_error_harmonics_df(simulate_points):
    assert [p["frequency_hz"] for p in simulate_points] == [5.0, 10.0, 15.0]
    for p in simulate_points:
        exact = {h["n"]: h for h in p["error_harmonics"]}
        df = {h["n"]: h for h in p["error_harmonics_df"]}
        assert sorted(df) == [1, 3, 5]
        assert all(set(h) == {"n", "abs", "phase_deg"} for h in df.values())
        assert df[1]["abs"] == pytest.approx(exact[1]["abs"], rel=0.01)
        for n in (3, 5):
            assert df[n]["abs"] == pytest.approx(exact[n]["abs"], rel=0.02)
            assert abs(df[n]["phase_deg"] - exact[n]["phase_deg"]) < 3.0
        # the first DF harmonic is eq. (18) times the linear error
        assert df[1]["abs"] == pytest.approx(p["mismatch_df_abs"] * p["error_linear_abs"],
                                             rel=1e-9)


def test_simulate_without_time_series_is_steady_and_says_so(capsys):
    rc, out, err = run(capsys, "simulate", "--frequency", "5", "--json")
    rc2, out2, err2 = run(capsys, "steady", "--frequency", "5", "--json")
    assert rc == rc2 == 0 and out == out2 and err2 == ""
    assert err.count("\n") == 1 and "motionhyst steady" in err


def test_steady_text_shows_hosidf_columns(capsys):
    rc, out, err = run(capsys, "steady", "--frequency", "5")
    assert rc == 0 and err == ""
    assert "|e3| HOSIDF" in out and "|e5| HOSIDF" in out


def test_simulate_maxwell_scenario_with_feedforward(capsys, tmp_path):
    text = default_scenario_path().read_text()
    text = (text.replace('model = "jenkins"', 'model = "maxwell-slip"')
            .replace("k = 20.0 ", "k = [8.0, 6.0, 4.0] ")
            .replace("fc = 0.05 ", "fc = [0.01, 0.03, 0.06] ")
            .replace("[reference]", 'hysteresis = { model = "maxwell-slip", k = [8, 6, 4], '
                                    'fc = [0.01, 0.03, 0.06] }\n\n[reference]'))
    path = tmp_path / "maxwell_ff.toml"
    path.write_text(text)
    with_ff = run_json(capsys, "steady", str(path), "--frequency", "5", "--json")["points"][0]
    path.write_text(text.replace('hysteresis = { model = "maxwell-slip", k = [8, 6, 4], '
                                 'fc = [0.01, 0.03, 0.06] }', ""))
    without = run_json(capsys, "steady", str(path), "--frequency", "5", "--json")["points"][0]
    assert without["error_hysteresis_rms"] / with_ff["error_hysteresis_rms"] > 1000
    assert with_ff["mismatch_simulated_abs"] == pytest.approx(1.0, abs=2e-3)
    assert with_ff["mismatch_df_abs"] == pytest.approx(1.0, abs=5e-3)
    assert without["mismatch_df_abs"] > 2
    # analyze takes the same scenario
    a = run_json(capsys, "analyze", str(path), "--frequency", "5", "--json")
    assert a["zeta"] is None
    assert a["mismatch"][0]["abs"] == pytest.approx(without["mismatch_df_abs"], rel=1e-12)


# ------------------------------------------------------- scenarios with other link models
LINKS = {
    "bouc-wen": 'model = "bouc-wen"\nk = 20.0\nfc = 0.05\nn = 2.0\n',
    "dahl": 'model = "dahl"\nk = 20.0\nfc = 0.05\n',
    "lugre": 'model = "lugre"\nsigma0 = 20.0\nsigma1 = 0.01\nfc = 0.05\nfs = 0.06\nvs = 0.01\n',
}


def _scenario_with_link(tmp_path, name: str):
    text = default_scenario_path().read_text()
    head, rest = text.split("[hysteresis]", 1)
    tail = rest[rest.index("\n["):]
    path = tmp_path / f"{name}.toml"
    path.write_text(f"{head}[hysteresis]\n{LINKS[name]}{tail}")
    return path


@pytest.mark.parametrize("name", list(LINKS))
def test_analyze_and_simulate_accept_every_link_model(capsys, tmp_path, name):
    path = _scenario_with_link(tmp_path, name)
    a = run_json(capsys, "analyze", str(path), "--frequency", "5", "10", "--json")
    assert a["df_frequency_hz"] == (5.0 if name == "lugre" else None)
    # the link has the Table I stiffness and slip force, so eq. (21) stays near 7.6 Hz
    assert 7.0 < a["mismatch_crossover_hz"] < 8.2
    assert a["mismatch_crossover_exact_hz"] == pytest.approx(a["mismatch_crossover_hz"],
                                                             rel=0.01)
    s = run_json(capsys, "steady", str(path), "--frequency", "5", "10", "--json")
    for p, q in zip(s["points"], a["mismatch"], strict=True):
        # the describing function's claim (paper section V) holds for these links too
        assert p["mismatch_simulated_abs"] == pytest.approx(p["mismatch_df_abs"], rel=0.01)
        assert p["mismatch_df_abs"] == pytest.approx(q["abs"], rel=1e-9)
