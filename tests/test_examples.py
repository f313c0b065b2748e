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
    # the training record it wrote gives the same model on the command line
    assert cli_main(["identify", str(folder / "train.csv"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    for cli_el, ex_el in zip(d["elements"], result["identified"]["elements"], strict=True):
        assert cli_el["k"] == pytest.approx(ex_el["k"], rel=1e-6)
        assert cli_el["fc"] == pytest.approx(ex_el["fc"], rel=1e-6)


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
