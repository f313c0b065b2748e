"""The scripts under examples/, run on small data in a temporary folder."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from motionhyst.cli import main as cli_main

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
NRMS_BAR = 0.02  # issue 6: held-out normalised RMS force error
REDUCTION_BAR = 20.0  # issue 6: fall of the hysteresis-induced error at 5 Hz


def load_example(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def example() -> ModuleType:
    return load_example("identify_and_compensate")


@pytest.fixture(scope="module")
def result(example, tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("identify")
    return example.main(out, n_train=2000, n_heldout=1000, seed=3, quiet=True)


def test_identify_and_compensate_meets_the_bar(result):
    assert result["heldout_nrms"] <= NRMS_BAR
    assert result["reduction"] >= REDUCTION_BAR
    figure = Path(result["figure"])
    assert figure.is_file()
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_identify_and_compensate_numbers_are_sound(example, result):
    ident = result["identified"]
    assert len(ident["elements"]) == 3
    np.testing.assert_allclose([e["k"] for e in ident["elements"]], example.K_TRUE, rtol=0.02)
    np.testing.assert_allclose([e["fc"] for e in ident["elements"]], example.FC_TRUE, rtol=0.02)
    # against the noisy held-out force the error is the sensor noise (1 %, measured 1.0 %);
    # against the true force it is the model error (measured 0.09 %)
    assert result["heldout_nrms"] == pytest.approx(example.FORCE_NOISE, rel=0.15)
    assert result["heldout_nrms_true"] < 0.005
    # the link of about Table I's size causes nm errors at 5 Hz (measured 7.7 nm RMS);
    # the identified feedforward removes all but a few thousandths (measured 2400x)
    assert 1e-9 < result["error_hysteresis_rms_before"] < 1e-7
    assert result["error_hysteresis_rms_after"] < result["error_hysteresis_rms_before"] / 100
    assert result["frequency_hz"] == 5.0 and result["amplitude"] == 0.01


def test_identify_and_compensate_outputs(result, capsys):
    folder = Path(result["figure"]).parent
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["reduction"] == pytest.approx(result["reduction"])
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]  # no temporary files
    # the training record it wrote gives the same model on the command line, which estimates
    # the displacement without its sensor's 0.19 um of white noise first (the example fits it
    # as measured): the same to 1e-4 (measured 2e-5)
    assert cli_main(["identify", str(folder / "train.csv"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["displacement_noise"]["filtered"]
    for cli_el, ex_el in zip(d["elements"], result["identified"]["elements"], strict=True):
        assert cli_el["k"] == pytest.approx(ex_el["k"], rel=1e-4)
        assert cli_el["fc"] == pytest.approx(ex_el["fc"], rel=1e-4)


# ------------------------------------------------------------------- scan_compensation
SCAN_BAR = 10.0  # issue 14: both model and ilc cut the scan's max MA and max MSD 10x


@pytest.fixture(scope="module")
def scan_result(tmp_path_factory) -> dict:
    return load_example("scan_compensation").main(tmp_path_factory.mktemp("scan"), quiet=True)


def test_scan_compensation_meets_the_bar(scan_result):
    # Table I loop, link model 4 % off: measured model 24.9x (MA) and 21.1x (MSD),
    # ilc after 10 trials 1.2e5x and 1.8e3x
    for comp in ("model", "ilc"):
        red = scan_result["reductions"][comp]
        assert red["ma"] >= SCAN_BAR and red["msd"] >= SCAN_BAR, comp
    # the model leaves its own 4 % of the slipping link's error, fc / C(0) = 8.06 nm
    assert scan_result["reductions"]["model"]["ma"] == pytest.approx(25, rel=0.05)
    assert Path(scan_result["figure"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert Path(scan_result["ilc_figure"]).is_file()


def test_scan_compensation_model_carries_over_and_the_learned_force_does_not(scan_result):
    # at half the speed the model (a function of position) still cuts 10x; the force
    # learned in time for the other speed makes the scan worse than no compensation
    co = scan_result["carry_over_reductions"]
    assert co["model"]["ma"] >= SCAN_BAR and co["model"]["msd"] >= SCAN_BAR
    assert co["ilc"]["ma"] < 1 and co["ilc"]["msd"] < 1
    trials = scan_result["ilc"]["trials"]
    assert len(trials) == 10 and trials[-1] < trials[0] / 1000
    folder = Path(scan_result["figure"]).parent
    assert json.loads((folder / "summary.json").read_text())["window_s"] == 0.05
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]


# ---------------------------------------------------------------------- measured_plant
@pytest.fixture(scope="module")
def measured(tmp_path_factory) -> dict:
    return load_example("measured_plant").main(tmp_path_factory.mktemp("frf"), quiet=True)


def test_measured_plant_fit_recovers_table_I(measured):
    """60 noisy lines (0.5 %) of Table I: the one mode within its uncertainty, and the
    loop's numbers as for the exact stage (measured: |E| 3349 / 6.039 / 1.239 against
    3349 / 6.040 / 1.239, margins equal to 4 digits)."""
    fit = measured["fit"]
    (mode,) = fit["modes"]
    assert mode["frequency_hz"] == pytest.approx(694.26, abs=4 * mode["frequency_hz_std"])
    assert fit["M"] == pytest.approx(22.5, abs=4 * fit["M_std"])
    assert fit["rms_relative_error"] == pytest.approx(0.005, rel=0.2)  # the noise
    np.testing.assert_allclose(measured["mismatch_fit"], measured["mismatch_exact"], rtol=2e-3)
    for key, exact in measured["margins_exact"].items():
        assert measured["margins_fit"][key] == pytest.approx(exact, rel=5e-3), key


def test_measured_plant_through_a_delay_and_with_the_link_stuck(tmp_path):
    """--delay-us 50: the delay found (50.1 +- 0.07 us) and |E| as without it (measured:
    3349 / 6.039 / 1.239); --k-ground 20: the fit is |E| = 1.049 at 1 Hz and says it is
    wrong in one warning."""
    example = load_example("measured_plant")
    delayed = example.main(tmp_path / "delay", quiet=True, delay_s=50e-6)
    fit = delayed["fit"]
    assert abs(fit["delay_s"] - 50e-6) < 4 * fit["delay_std_s"] and len(fit["modes"]) == 1
    assert delayed["warnings"] == []
    np.testing.assert_allclose(delayed["mismatch_fit"], delayed["mismatch_exact"], rtol=2e-3)
    stuck = example.main(tmp_path / "stuck", quiet=True, k_ground=20.0)
    (warning,) = stuck["warnings"]
    assert "not a floating rigid body" in warning
    assert stuck["mismatch_fit"][0] < 0.01 * stuck["mismatch_exact"][0]


def test_measured_plant_files_give_the_same_fit_on_the_command_line(measured, capsys):
    csv_path, toml_path, figure = (Path(p) for p in measured["files"])
    assert csv_path.read_text().splitlines()[0] == \
        "frequency_hz,p1_abs,p1_phase_deg,p2_abs,p2_phase_deg"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli_main(["analyze", str(toml_path), "--frequency", "1", "5", "10", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["plant_fit"]["M"] == pytest.approx(measured["fit"]["M"], rel=1e-9)
    np.testing.assert_allclose([p["abs"] for p in d["mismatch"]], measured["mismatch_fit"],
                               rtol=1e-9)


# --------------------------------------------------------------- identify_input_output
@pytest.fixture(scope="module")
def io_result(tmp_path_factory) -> dict:
    return load_example("identify_input_output").main(tmp_path_factory.mktemp("io"),
                                                      quiet=True)


def test_identify_input_output_recovers_the_benchmark_system(io_result):
    """Two short benchmark experiments with 8e-6 m noise: the fit leaves the noise, every
    identifiable parameter lies within 4 standard errors of the truth (measured: within
    2.6), and the held-out prediction is far below the noise (measured 1.45e-7 m)."""
    from motionhyst.identify.benchmark import NOISE_RMS, TRUE_PARAMETERS

    p = TRUE_PARAMETERS
    ident = io_result["identified"]
    assert io_result["fit_rms"] == pytest.approx(NOISE_RMS, rel=0.05)
    true = {"m": p["m"], "c": p["c"], "k": p["k"], "alpha": p["alpha"],
            "beta*gamma": p["beta"] * p["gamma"], "beta*delta": p["beta"] * p["delta"]}
    assert set(ident["estimates"]) == set(true)
    for name, value in ident["estimates"].items():
        assert abs(value - true[name]) < 4 * ident["std"][name], name
    assert io_result["test_rmse"] < NOISE_RMS / 10
    assert io_result["test_output_rms"] > 1000 * io_result["test_rmse"]


def test_identify_input_output_model_predicts_the_same_on_the_command_line(io_result, capsys):
    files = {Path(f).name: Path(f) for f in io_result["files"]}
    folder = files["model.toml"].parent
    out = folder / "pred.csv"
    assert cli_main(["predict", str(files["model.toml"]), str(files["test_force.csv"]),
                     "--out", str(out)]) == 0
    pred = np.loadtxt(out, delimiter=",", skiprows=1)
    truth = np.loadtxt(files["test_displacement.csv"], delimiter=",", skiprows=1)
    rmse = float(np.sqrt(np.mean((pred[:, 1] - truth[:, 1]) ** 2)))
    assert rmse == pytest.approx(io_result["test_rmse"], rel=1e-6)
    assert files["prediction.png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]


# ------------------------------------------------------------------- scan_production
@pytest.fixture(scope="module")
def production(tmp_path_factory) -> dict:
    return load_example("scan_production").main(tmp_path_factory.mktemp("prod"), quiet=True)


def test_scan_production_meets_the_targets(production):
    # issue 24: 0.1 m at 0.5 m/s, the link model 4 % off: model (with the snap term) and
    # basis cut max MA and max MSD 10x; basis keeps 5x at half and double the speed, the
    # learned force does not (measured: model 68x / 1.6e3x, basis 2.5e3x / 1.7e3x; at half
    # the speed basis 2.5e3x, ilc 0.49x)
    for comp in ("model", "basis"):
        red = production["reductions"][comp]
        assert red["ma"] >= 10 and red["msd"] >= 10, comp
    for speed in ("half_speed", "double_speed"):
        red = production[speed]
        assert red["basis"]["ma"] >= 5 and red["basis"]["msd"] >= 5, speed
        assert red["ilc"]["ma"] < 5 or red["ilc"]["msd"] < 5, speed
    learned = production["basis"]["learned"]
    assert learned["snap"] == pytest.approx(5.0 * 17.5 / 7.4e7, rel=0.01)
    assert learned["link fc"] == pytest.approx(0.05, rel=0.01)
    assert Path(production["figure"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_scan_production_along_the_stroke_the_table_matters(production):
    # the link's fc and k vary along the stroke: a single-parameter model leaves the
    # variation everywhere; the model with the table leaves its 4 %
    for row in production["along_stroke"].values():
        assert row["table"]["model"]["ma"] > 3 * row["single"]["model"]["ma"]
        assert row["table"]["basis"]["ma"] > 10 * row["single"]["basis"]["ma"]


def test_link_record_identifies_with_correlated_errors(tmp_path):
    """examples/link_record.py: the generated record gives k and fc within three standard
    errors of Table I's, about 3 % each, positively correlated (README, "Studies")."""
    from motionhyst.identify import identify_maxwell_slip

    path = load_example("link_record").main(tmp_path)
    t, x, w = np.loadtxt(path, delimiter=",", skiprows=1).T
    fit = identify_maxwell_slip(x, w, t=t, n_elements=1)
    e = fit.elements[0]
    assert abs(e["k"] - 20.0) < 3 * e["k_std"] and abs(e["fc"] - 0.05) < 3 * e["fc_std"]
    assert 0.02 < e["k_std"] / e["k"] < 0.05 and 0.02 < e["fc_std"] / e["fc"] < 0.05
    c = np.array(fit.covariance["matrix"])
    assert 0.5 < c[0, 1] / np.sqrt(c[0, 0] * c[1, 1]) < 0.9
