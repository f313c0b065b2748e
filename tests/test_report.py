"""Tests of ``motionhyst reproduce`` (report.py) and the paper's figures (plots.py)."""

from __future__ import annotations

import json
import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure
from numpy.testing import assert_allclose

from motionhyst.analysis.quasilinear import analyze, loop_mismatch, mismatch_asymptote
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.core.lti import freqresp
from motionhyst.hysteresis import BoucWen, Dahl, LuGre, MaxwellSlip
from motionhyst.io.outputs import MANIFEST
from motionhyst.present import plots, report
from motionhyst.scenario import Scenario, default_scenario, default_scenario_path

FIGURES = [f"fig{i}" for i in range(5, 12)]
A_REF = 0.01
FREQS = [5.0, 10.0, 15.0]


@pytest.fixture(scope="module")
def scenario():
    return default_scenario()


@pytest.fixture(scope="module")
def loop(scenario):
    return scenario.loop()


@pytest.fixture(scope="module")
def el(loop):
    return loop.hysteresis


@pytest.fixture(scope="module")
def states(loop):
    return [periodic_steady_state(loop, A_REF, f) for f in FREQS]


@pytest.fixture(scope="module")
def analysis(loop):
    return analyze(loop, A_REF, FREQS)


@pytest.fixture(scope="module")
def reproduced(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce") / "out"
    out.mkdir()
    (out / "notes.txt").write_text("the user's own file")  # never touched (issue 10)
    summary = report.reproduce(default_scenario(), out, quiet=True, is_paper=True)
    return out, summary


# ------------------------------------------------------------------------------ reproduce


def test_reproduce_writes_all_files(reproduced):
    out, _ = reproduced
    expected = {f"{n}.{ext}" for n in FIGURES for ext in ("png", "pdf")}
    expected |= {"summary.json", "report.md"}
    assert {p.name for p in out.iterdir()} == expected | {"notes.txt", MANIFEST}
    assert set(json.loads((out / MANIFEST).read_text())["files"]) == expected
    for name in expected:
        assert (out / name).stat().st_size > 0
    for n in FIGURES:
        assert (out / f"{n}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (out / f"{n}.pdf").read_bytes()[:5] == b"%PDF-"
    # nothing left behind next to the output
    assert [p.name for p in out.parent.iterdir()] == ["out"]


def test_summary_json(reproduced, loop, states):
    out, summary = reproduced
    data = json.loads((out / "summary.json").read_text())
    assert set(data) >= {"scenario", "analyze", "simulate"}
    assert data == json.loads(json.dumps(summary))
    a = data["analyze"]
    assert a["zeta"] == pytest.approx(0.25, rel=1e-12)
    assert a["df_abs_over_k"] == pytest.approx(0.3086, abs=5e-5)
    assert a["df_phase_deg"] == pytest.approx(50.69, abs=0.01)
    assert a["f_star_hz"] == pytest.approx(0.150, abs=5e-4)
    assert a["mismatch_crossover_hz"] == pytest.approx(7.6, abs=0.01)
    assert a["bandwidth_hz"] == pytest.approx(120.0, rel=0.01)
    assert [m["frequency_hz"] for m in a["mismatch"]] == FREQS
    points = data["simulate"]["points"]
    assert [p["frequency_hz"] for p in points] == FREQS
    E_df = loop_mismatch(loop, FREQS, A_REF)
    for p, ss, e in zip(points, states, E_df, strict=True):
        assert p["mismatch_df_abs"] == pytest.approx(abs(e), rel=1e-12)
        assert p["mismatch_df_phase_deg"] == pytest.approx(np.degrees(np.angle(e)), abs=1e-9)
        assert p["mismatch_simulated_abs"] == pytest.approx(abs(ss.mismatch), rel=1e-10)
        # the paper's claim: describing function within 1 % and 1 deg of the exact result
        assert p["mismatch_simulated_abs"] == pytest.approx(p["mismatch_df_abs"], rel=0.01)
        assert p["mismatch_simulated_phase_deg"] == pytest.approx(p["mismatch_df_phase_deg"],
                                                                  abs=1.0)
        assert p["error_harmonics"][0]["abs"] == pytest.approx(abs(ss.e[1]), rel=1e-10)
        assert p["error_rms"] == pytest.approx(ss.error_rms, rel=1e-10)
        assert p["y1_amplitude"] == pytest.approx(abs(ss.y1[1]), rel=1e-10)


def test_report_markdown(reproduced):
    out, _ = reproduced
    text = (out / "report.md").read_text()
    assert "## Paper vs computed" in text
    lines = text.splitlines()
    zeta_row = next(ln for ln in lines if ln.startswith("| zeta |"))
    assert zeta_row.split("|")[2:4] == [" 0.25 ", " 0.25 "]
    cross_row = next(ln for ln in lines if ln.startswith("| crossover (eq. 21) |"))
    assert "7.6 Hz" in cross_row and "7.607 Hz" in cross_row
    assert "| 0.3086 |" in text
    for n in FIGURES:
        assert f"![{n}]({n}.png)" in text
    # one row per reference frequency in the mismatch table
    assert sum(ln.startswith(("| 5 |", "| 10 |", "| 15 |")) for ln in lines) == 3


def test_reproduce_keeps_the_users_files(reproduced):
    out, _ = reproduced
    assert (out / "notes.txt").read_text() == "the user's own file"


def test_report_without_paper_column(scenario, el, analysis, states):
    E_df = [p.value for p in analysis.points]
    text = report._report_text(scenario, el, analysis, states, E_df, None, ["fig5"],
                               is_paper=False, notes=["a note"])
    assert "## Key numbers" in text and "Paper vs computed" not in text
    assert "| quantity | computed |" in text
    assert "- a note" in text
    # the mismatch rows carry the results' own numbers: eq. (18) and the exact steady state
    for f, E, st in zip(FREQS, E_df, states, strict=True):
        row = next(ln for ln in text.splitlines() if ln.startswith(f"| {f:g} |"))
        assert row.split("|")[2:6] == [f" {abs(E):.4g} ", f" {np.degrees(np.angle(E)):.2f} ",
                                       f" {abs(st.mismatch):.4g} ",
                                       f" {np.degrees(np.angle(st.mismatch)):.2f} "]


def test_reproduce_failure_leaves_previous_output(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "marker.txt").write_text("previous run")

    def broken(*args, **kwargs):
        raise RuntimeError("fig9 failed")

    monkeypatch.setattr(plots, "fig9_quasilinear_plant", broken)
    sc = default_scenario()
    sc.model.reference.frequencies = [10.0]
    with pytest.raises(RuntimeError, match="fig9 failed"):
        report.reproduce(sc, out, quiet=True)
    assert [p.name for p in out.iterdir()] == ["marker.txt"]
    assert (out / "marker.txt").read_text() == "previous run"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no temporary folders remain


def test_reproduce_of_an_unstable_scenario_writes_nothing(tmp_path, capsys):
    # the loop is built and checked inside the command, while the link's figures are drawn
    from motionhyst.cli import main

    text = default_scenario_path().read_text()
    assert "\nK = 6.2e6 " in text
    scenario = tmp_path / "unstable.toml"
    scenario.write_text(text.replace("\nK = 6.2e6 ", "\nK = 6.2e9 "))  # 1000 x: unstable
    out = tmp_path / "out"
    out.mkdir()
    (out / "marker.txt").write_text("previous run")
    assert main(["reproduce", str(scenario), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "[controller]" in err and "stabilise" in err
    assert [p.name for p in out.iterdir()] == ["marker.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "unstable.toml"]
    assert multiprocessing.active_children() == []  # the figure workers were stopped


def test_reproduce_failure_in_final_move_leaves_previous_output(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "marker.txt").write_text("previous run")
    for name in FIGURES:  # figures are not the point here: draw empty ones
        attr = next(a for a in dir(plots) if a.startswith(f"{name}_"))
        monkeypatch.setattr(plots, attr, lambda *args, **kwargs: Figure())
    sc = default_scenario()
    sc.model.reference.frequencies = [10.0]
    report.reproduce(sc, out, quiet=True)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    replace = os.replace

    def failing_replace(src, dst):
        # the move of a staged figure fails, after others have been moved
        if Path(dst).name == "fig9.png":
            raise OSError(28, "No space left on device")
        return replace(src, dst)

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(ValueError, match=r"cannot write .*fig9\.png: No space"):
        report.reproduce(sc, out, quiet=True)
    monkeypatch.undo()
    assert (out / "marker.txt").read_text() == "previous run"
    after = {p.name: p.read_bytes() for p in out.iterdir()}
    assert set(after) == set(before)  # no temporary file is left
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


# -------------------------------------------------------------------------------- figures


def test_fig5_loops_bounded_by_fc(el):
    fig = plots.fig5_loops(el)
    assert isinstance(fig, Figure)
    data = fig.motionhyst_data
    assert set(data) == {"zeta=0.25", "zeta=0.5", "zeta=0.75", "zeta=1.25"}
    for key, xw in data.items():
        zeta = float(key.split("=")[1])
        x, w = xw
        assert np.max(np.abs(w)) <= el.fc
        assert np.max(np.abs(x)) == pytest.approx(el.fc / (el.k * zeta), rel=1e-6)
        if zeta < 1:
            assert np.max(np.abs(w)) == pytest.approx(el.fc)  # slips
        else:
            assert_allclose(w, el.k * x, rtol=0, atol=1e-15)  # a spring, never slips


def test_fig6_modes(el):
    data = plots.fig6_modes(el).motionhyst_data
    # stick-to-slip onsets: x w <= 0 in mode 2, x w > 0 in mode 3 (paper section III-A)
    x2, w2 = data["mode2_onsets"]
    x3, w3 = data["mode3_onsets"]
    assert len(x2) == len(x3) == 2
    assert np.all(x2 * w2 <= 0)
    assert np.all(x3 * w3 > 0)
    assert_allclose(np.abs(w2), el.fc)


def test_fig7_first_harmonic(el):
    fig = plots.fig7_time(el, A_REF, 5.0)
    data = fig.motionhyst_data
    t, w, w1 = data["t"], data["w"], data["w_first_harmonic"]
    assert t[-1] == pytest.approx(0.2)
    D = el.describing_function(A_REF)
    assert np.max(np.abs(w1)) == pytest.approx(A_REF * abs(D), rel=1e-5)
    # w1 is the first Fourier harmonic of w (one period, endpoint repeated)
    n = len(t) - 1
    c1 = 2 * np.fft.rfft(w[:-1])[1] / n
    assert abs(1j * c1) == pytest.approx(A_REF * abs(D), rel=1e-3)
    assert np.all(np.abs(w[data["slip"]]) == pytest.approx(el.fc))


def test_fig8_describing_function(el):
    data = plots.fig8_describing_function(el).motionhyst_data
    z = data["zeta"]
    assert z[0] == pytest.approx(1e-3) and z[-1] == pytest.approx(10.0)
    assert np.interp(np.log(0.25), np.log(z), data["abs_over_k"]) == pytest.approx(0.3086,
                                                                                   abs=2e-4)
    assert np.interp(np.log(0.25), np.log(z), data["phase_deg"]) == pytest.approx(50.69,
                                                                                  abs=0.05)
    # exact values on a grid through zeta = 0.25
    exact = plots.fig8_describing_function(el, zeta_range=(0.25, 4.0)).motionhyst_data
    assert exact["zeta"][0] == 0.25
    assert exact["abs_over_k"][0] == pytest.approx(0.30857, abs=1e-5)
    assert np.all(data["abs_over_k"] <= 1 + 1e-15)  # |D| <= k
    assert_allclose(data["abs_over_k"][z >= 1], 1.0, rtol=1e-15)
    assert_allclose(data["phase_deg"][z >= 1], 0.0, atol=1e-12)
    # eq. (11): the phase tends to 90 deg; for small zeta Re D / Im D = (4 / 3) sqrt(zeta)
    assert data["phase_deg"][0] == pytest.approx(
        90.0 - np.degrees(np.arctan(4 / 3 * np.sqrt(1e-3))), abs=0.01)


def test_fig9_quasilinear_plant(loop, el):
    fig = plots.fig9_quasilinear_plant(loop, f_star_hz=0.15)
    data = fig.motionhyst_data
    f = data["f"]
    w = 2 * np.pi * f
    P1, P2 = freqresp(loop.P1, w), freqresp(loop.P2, w)
    assert_allclose(data["P2"], P2, rtol=1e-12)
    for z in (0.01, 0.25, 1.0):
        D = el.describing_function(el.fc / (el.k * z))
        assert_allclose(data[f"zeta={z:g}"], P2 / (1 + D * P1), rtol=1e-12)
    # above f* the quasi-linear plant is the floating mass P2 (Remark 1)
    hi = f > 10 * 0.15
    assert_allclose(np.abs(data["zeta=1"][hi]), np.abs(P2[hi]), rtol=0.02)


def test_fig10_mismatch(loop, analysis, states):
    fig = plots.fig10_mismatch(loop, analysis, states)
    data = fig.motionhyst_data
    f = data["f"]
    assert_allclose(data["E"], loop_mismatch(loop, f, A_REF), rtol=1e-12)
    w = 2 * np.pi * f
    Pr = 1.0 / (loop.M * (1j * w) ** 2)
    Et = mismatch_asymptote(Pr, freqresp(loop.plant.Pf2, w), analysis.D)
    assert_allclose(data["asymptote"], Et, rtol=1e-12)
    assert_allclose(data["f_exact"], FREQS)
    assert_allclose(data["E_exact"], [abs(s.mismatch) for s in states], rtol=1e-14)
    # the asymptote crosses 1 at eq. (21)
    i = np.argmin(np.abs(np.log(np.abs(Et))))
    assert f[i] == pytest.approx(analysis.mismatch_crossover_hz, rel=0.01)
    # without exact points no markers
    assert "E_exact" not in plots.fig10_mismatch(loop, analysis).motionhyst_data


def test_fig11_errors(loop, states):
    E_df = loop_mismatch(loop, FREQS, A_REF)
    fig = plots.fig11_errors(states, E_df)
    assert len(fig.axes) == len(states)
    data = fig.motionhyst_data
    for ss, E in zip(states, E_df, strict=True):
        t, e, e_lin, e_df = data[f"f={ss.frequency_hz:g}"]
        ts = ss.time_series()
        assert_allclose(t, ts["t"], rtol=0, atol=0)
        assert_allclose(e, ts["e"], rtol=0, atol=0)
        assert_allclose(e_lin, ts["e_linear"], rtol=0, atol=0)
        e1 = E * ss.e_linear[1]
        assert_allclose(e_df, abs(e1) * np.sin(2 * np.pi * ss.frequency_hz * t + np.angle(e1)),
                        rtol=0, atol=1e-12 * abs(e1))
        # the describing-function estimate is close to the exact first harmonic
        assert abs(e1 - ss.e[1]) < 0.01 * abs(ss.e[1])


def test_figures_from_reproduce_match_functions(reproduced, loop, el, analysis, states):
    """reproduce draws each figure once: the functions it calls return Figures."""
    makers = [plots.fig5_loops(el), plots.fig6_modes(el), plots.fig7_time(el, A_REF, 5.0),
              plots.fig8_describing_function(el), plots.fig9_quasilinear_plant(loop),
              plots.fig10_mismatch(loop, analysis, states),
              plots.fig11_errors(states, loop_mismatch(loop, FREQS, A_REF))]
    for fig in makers:
        assert isinstance(fig, Figure)
        assert fig.motionhyst_data


# ------------------------------------------------------------------ other link models
@pytest.mark.parametrize("other", [
    BoucWen(20.0, 0.05, n=2.0), Dahl(20.0, 0.05), MaxwellSlip([12.0, 8.0], [0.02, 0.03])],
    ids=["bouc-wen", "dahl", "maxwell-slip"])
def test_fig5_and_fig8_of_other_models_show_their_periodic_loops(other):
    fc = float(np.sum(other.fc))
    fig = plots.fig5_loops(other, zetas=(0.25, 2.0))
    title = fig.axes[0].get_title()
    assert all(f"{key} = " in title for key in other.to_dict() if key != "model")
    if isinstance(other, MaxwellSlip):
        assert "k = [12, 8], fc = [0.02, 0.03]" in title
    data = fig.motionhyst_data
    for zeta in (0.25, 2.0):
        x, w = data[f"zeta={zeta:g}"]
        A = fc / (other.initial_stiffness * zeta)
        assert np.max(np.abs(x)) == pytest.approx(A, rel=1e-6)
        assert np.max(np.abs(w)) <= fc * (1 + 1e-12)
        # the periodic loop: closed, and odd symmetric (w(-x) = -w(x) half a period on)
        assert (x[0], w[0]) == pytest.approx((x[-1], w[-1]), abs=1e-12 * fc)
        assert np.max(w) == pytest.approx(-np.min(w), rel=1e-6)
        # its area is the energy per cycle, pi A^2 Im D (paper eq. 7)
        area = abs(np.sum(0.5 * (w[1:] + w[:-1]) * np.diff(x)))
        assert area == pytest.approx(np.pi * A**2 * other.describing_function(A).imag,
                                     rel=1e-3)
    d8 = plots.fig8_describing_function(other, zeta_range=(0.1, 10.0)).motionhyst_data
    A = fc / (other.initial_stiffness * d8["zeta"])
    D = other.describing_function(A)
    assert_allclose(d8["abs_over_k"], np.abs(D) / other.initial_stiffness, rtol=1e-14)
    assert_allclose(d8["phase_deg"], np.degrees(np.angle(D)), rtol=1e-14)


def test_rate_dependent_figures_need_a_frequency():
    lugre = LuGre(20.0, 0.0, 0.0, 0.05, 0.05, 0.01)
    with pytest.raises(ValueError, match="frequency_hz"):
        plots.fig5_loops(lugre)
    data = plots.fig8_describing_function(lugre, zeta_range=(0.5, 2.0), frequency_hz=5.0)
    z = data.motionhyst_data["zeta"]
    D = lugre.describing_function(0.05 / (20.0 * z), 2 * np.pi * 5.0)
    assert_allclose(data.motionhyst_data["abs_over_k"], np.abs(D) / 20.0, rtol=1e-14)


LUGRE = LuGre(sigma0=20.0, sigma1=0.1, sigma2=0.01, fc=0.05, fs=0.06, vs=0.01)


class _Counted:
    """A link whose describing function counts the frequencies it is computed at."""

    def __init__(self, el):
        self.el, self.rate_independent, self.computed = el, el.rate_independent, 0

    def describing_function(self, A, omega=None):
        self.computed += np.size(omega)
        return self.el.describing_function(A, omega)


@pytest.mark.parametrize("A", [2.5e-1, 1e-2, 2.5e-3, 1e-5])  # zeta 0.01 to 1, and far below
def test_describing_function_curve_of_lugre_is_exact_from_a_sixth_of_the_points(A):
    w = 2 * np.pi * np.geomspace(0.01, 100.0, 600)  # Fig. 9's grid
    counted = _Counted(LUGRE)
    D = plots.describing_function_curve(counted, A, w)
    exact = LUGRE.describing_function(A, w)
    assert np.max(np.abs(D - exact) / np.abs(exact)) < 1e-5
    assert counted.computed <= 600 // 6 + 2


class _Notch:
    """A rate-dependent describing function with a notch narrower than the coarse grid."""

    rate_independent = False

    def __init__(self, omega0):
        self.omega0 = omega0

    def describing_function(self, A, omega=None):
        u = np.log(np.asarray(omega) / self.omega0) / 2e-3
        return (1.0 + 0.5j) * (1.0 - 0.5 / (1.0 + u**2)) * np.ones_like(u)


def test_describing_function_curve_computes_each_point_where_the_spline_misses():
    w = 2 * np.pi * np.geomspace(0.01, 100.0, 600)
    notch = _Notch(w[305])  # between two points of the coarse grid (every 12th)
    D = plots.describing_function_curve(notch, 0.01, w)
    assert_allclose(D, notch.describing_function(0.01, w), rtol=1e-4)


def test_figures_of_a_lugre_loop_draw_its_exact_curves(loop):
    from motionhyst.controllers.loop import Loop

    lugre_loop = Loop(loop.plant, loop.controller, LUGRE, feedforward="rigid-body")
    f = np.geomspace(0.01, 100.0, 600)
    w = 2 * np.pi * f
    data = plots.fig9_quasilinear_plant(lugre_loop, paper=False).motionhyst_data
    P1, P2 = freqresp(lugre_loop.P1, w), freqresp(lugre_loop.P2, w)
    A = 0.05 / (20.0 * 0.25)
    exact = P2 / (1 + LUGRE.describing_function(A, w) * P1)
    assert_allclose(data["zeta=0.25"], exact, rtol=1e-5)
    analysis = analyze(lugre_loop, 0.01, [5.0])
    d10 = plots.fig10_mismatch(lugre_loop, analysis).motionhyst_data
    assert_allclose(d10["E"], loop_mismatch(lugre_loop, d10["f"], 0.01), rtol=1e-5)


def test_fig9_wraps_a_long_parameter_list_between_parameters(loop):
    from motionhyst.controllers.loop import Loop

    lugre_loop = Loop(loop.plant, loop.controller, LUGRE, feedforward="rigid-body")
    title = plots.fig9_quasilinear_plant(lugre_loop).axes[1].get_title()
    lines = title.split("\n")
    assert len(lines) == 2 and all(len(line) <= 70 for line in lines)
    # every parameter whole on one line, as the model states it
    for key, value in LUGRE.to_dict().items():
        if key != "model":
            assert any(f"{key} = {value:g}" in line for line in lines), key


def test_reproduce_with_another_model_draws_its_figures(tmp_path):
    sc = default_scenario()
    data = sc.to_dict()
    data["hysteresis"] = {"model": "dahl", "k": 20.0, "fc": 0.05}
    other = Scenario.from_dict(data, source="dahl.toml")
    out = tmp_path / "out"
    summary = report.reproduce(other, out, quiet=True)
    written = sorted(p.stem for p in out.glob("*.png"))
    assert written == ["fig10", "fig11", "fig5", "fig8", "fig9"]
    text = (out / "report.md").read_text()
    assert "dahl model" in text and "Jenkins element for sinusoids" not in text
    assert summary["scenario"]["hysteresis"]["model"] == "dahl"
    # the mismatch of a Dahl link at 5 Hz: exact steady state against eq. (18) within 1 %
    p = summary["simulate"]["points"][0]
    assert p["mismatch_simulated_abs"] == pytest.approx(p["mismatch_df_abs"], rel=0.01)


# ------------------------------------------------ figures as printed (issue 13)
def test_fig7_input_and_switching_instants(el):
    data = plots.fig7_time(el, A_REF, 5.0).motionhyst_data
    t, x = data["t"], data["x"]
    assert np.max(x) == pytest.approx(A_REF, rel=1e-6)  # A
    assert t[-1] == pytest.approx(1 / 5.0)  # f
    # eq. (6): gamma = arcsin(2 zeta - 1); stick at x reversals, slip at pi + gamma, 2 pi + gamma
    gamma = np.arcsin(2 * 0.25 - 1)
    expected = np.sort(np.remainder([np.pi / 2, np.pi + gamma, 3 * np.pi / 2, 2 * np.pi + gamma],
                                    2 * np.pi)) / (2 * np.pi * 5.0)
    assert_allclose(data["tau"], expected, rtol=1e-12)
    # the switching instants are where the sampled force changes between slipping and sticking
    slip = data["slip"]
    changes = t[1:][slip[1:] != slip[:-1]]
    for tau in data["tau"]:
        assert np.min(np.abs(changes - tau)) < 2 * (t[1] - t[0])
    # no switching without slip (zeta >= 1)
    assert plots.switching_instants(el, el.fc / el.k, 5.0).size == 0


def test_fig8_marks_the_operating_point(el):
    data = plots.fig8_describing_function(el, zeta_op=0.25).motionhyst_data
    assert data["zeta_op"] == 0.25
    D = data["D_op"]
    assert abs(D) / el.k == pytest.approx(0.3086, abs=5e-5)  # the paper: ~0.3 k
    assert np.degrees(np.angle(D)) == pytest.approx(50.69, abs=0.01)  # the paper: ~50 deg


def test_fig9_paper_parameters_beside_the_scenario(loop):
    from motionhyst.hysteresis import Jenkins

    fig = plots.fig9_quasilinear_plant(loop, f_star_hz=0.15)
    data = fig.motionhyst_data
    paper = Jenkins(k=1e4, fc=100.0)  # the paper's section III-C for Fig. 9
    f = data["paper_f"]
    w = 2 * np.pi * f
    stage = loop.plant
    P1, P2 = freqresp(stage.P1, w), freqresp(stage.P2, w)
    for z in (0.01, 0.25, 1.0):
        D = paper.describing_function(paper.fc / (paper.k * z))
        assert_allclose(data[f"paper_zeta={z:g}"], P2 / (1 + D * P1), rtol=1e-12)
    # f* = sqrt(kJ / M) / (2 pi) = 3.36 Hz: above it the paper's curves are P2 (Remark 1)
    hi = f > 10 * np.sqrt(1e4 / 22.5) / (2 * np.pi)
    assert_allclose(np.abs(data["paper_zeta=1"][hi]), np.abs(P2[hi]), rtol=0.02)
    titles = " ".join(ax.get_title() for ax in fig.axes)
    assert "kJ = 1e4 N/m, fc = 100 N" in titles and "this scenario" in titles
    assert len(fig.axes) == 4


def test_report_defines_margins_and_exact_crossover(reproduced):
    out, summary = reproduced
    text = (out / "report.md").read_text()
    a = summary["analyze"]
    for label in ("| gain margin |", "| phase margin |", "| modulus margin 1 / max \\|S\\| |"):
        assert label in text
    assert "not a quantity of the paper" in text and "crossover frequency" in text
    assert a["phase_margin_deg"] == pytest.approx(24.83, abs=0.01)
    for name in ("fig7", "fig9", "fig10"):
        assert name in text
    assert "tau_i" in report.FIGURE_NOTES["fig7"]
    assert "kJ = 1e4 N/m, fc = 100 N" in report.FIGURE_NOTES["fig9"]
    for line in ("Black", "Dashed red", "Circles", "Grey", "Dotted green", "Dash-dotted green"):
        assert line in report.FIGURE_NOTES["fig10"]


def test_report_of_a_fitted_measured_plant(tmp_path):
    from motionhyst.plants.frf_fit import ModalPlant
    from motionhyst.plants.two_mass import TwoMassStage
    from motionhyst.scenario import Scenario, default_scenario_path

    exact = ModalPlant.from_two_mass(TwoMassStage(5.0, 17.5, 90.0, 7.4e7))
    f = np.geomspace(1.0, 3000.0, 60)
    p1, p2 = exact.response(2 * np.pi * f)
    rows = [",".join(f"{v:.17g}" for v in (fi, a.real, a.imag, b.real, b.imag))
            for fi, a, b in zip(f, p1, p2, strict=True)]
    (tmp_path / "p.csv").write_text("frequency_hz,p1_re,p1_im,p2_re,p2_im\n" + "\n".join(rows))
    text = default_scenario_path().read_text()
    text = (text[:text.index("[stage]")] + '[plant]\nfile = "p.csv"\n\n'
            + text[text.index("[hysteresis]"):].replace("[5.0, 10.0, 15.0]", "[5.0]"))
    (tmp_path / "s.toml").write_text(text)
    sc = Scenario.from_file(tmp_path / "s.toml")
    summary = report.reproduce(sc, tmp_path / "out", quiet=True)
    md = (tmp_path / "out" / "report.md").read_text()
    assert "## Measured plant" in md and "rigid body + 1 mode(s)" in md
    assert "![plant_fit](plant_fit.png)" in md
    assert (tmp_path / "out" / "plant_fit.png").stat().st_size > 0
    assert summary["plant_fit"]["modes"][0]["frequency_hz"] == pytest.approx(694.26, abs=0.01)
    assert summary["analyze"]["mismatch_crossover_hz"] == pytest.approx(7.607, abs=0.001)
