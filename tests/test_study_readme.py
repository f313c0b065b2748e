"""The README's Monte-Carlo figures ("Studies") are what its commands give.

The commands are run as the README states them (the generated link record, its
identification, the study drawn from the identification's covariance, the fleet of
``examples/study.toml``), and every figure the README quotes from them is read from its text
and compared with the results to the digits it prints: a change of the code or of the text
that parts them fails here.
"""

from __future__ import annotations

import importlib.util
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from motionhyst import analyze, default_scenario
from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results
from motionhyst.study.summary import BAND, summarize

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
RAW = (ROOT / "README.md").read_text()
README = " ".join(RAW.split())   # one line, single spaces


def _readme(pattern: str) -> tuple[str, ...]:
    """The groups of `pattern` in the README (whitespace normalised); fails if absent."""
    m = re.search(pattern, README)
    assert m, f"the README no longer says: {pattern}"
    return m.groups()


def _agrees(text: str, value: float) -> bool:
    """`value` rounds to `text` at the digits `text` prints."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    return abs(value - float(text)) <= 0.5 * 10.0 ** -decimals * (1 + 1e-9)


def _assert_agrees(text: str, value: float, what: str) -> None:
    assert _agrees(text, value), f"README {what}: {text}, computed {value:.6g}"


@pytest.fixture(scope="module")
def identified(tmp_path_factory) -> dict:
    """The README's commands from the generated record to the study's store."""
    out = tmp_path_factory.mktemp("fleet")
    for command in ("python examples/link_record.py out/fleet",
                    "motionhyst identify out/fleet/link.csv --elements 1 --save "
                    "out/fleet/link.toml",
                    "motionhyst study examples/study_identified.toml --from-identification "
                    "out/fleet/link.toml \\ --out out/fleet/fleet.zarr"):
        assert command in README, command
    spec = importlib.util.spec_from_file_location("link_record", EXAMPLES / "link_record.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    csv = module.main(out)
    assert main(["identify", str(csv), "--elements", "1", "--save", str(out / "link.toml")]) == 0
    assert main(["study", str(EXAMPLES / "study_identified.toml"), "--from-identification",
                 str(out / "link.toml"), "--out", str(out / "fleet.zarr")]) == 0
    return {"toml": tomllib.loads((out / "link.toml").read_text()),
            "ds": open_results(out / "fleet.zarr")}


def test_identification_figures(identified):
    ident = identified["toml"]["identification"]
    assert ident["parameters"] == ["hysteresis.k", "hysteresis.fc"]
    (k, fc), (k_std, fc_std) = ident["estimates"], ident["std"]
    corr = ident["correlation"][0][1]
    k_t, k_std_t, fc_t, fc_std_t, rel_t, corr_t = _readme(
        r"gives `k = ([\d.]+) \+- ([\d.]+) N/m` and `fc = ([\d.]+) \+- ([\d.]+) N` "
        r"\(([\d.]+) % each, correlation \+([\d.]+)")
    _assert_agrees(k_t, k, "k")
    _assert_agrees(k_std_t, k_std, "std of k")
    _assert_agrees(fc_t, fc, "fc")
    _assert_agrees(fc_std_t, fc_std, "std of fc")
    _assert_agrees(rel_t, 100 * k_std / k, "relative std of k")
    _assert_agrees(rel_t, 100 * fc_std / fc, "relative std of fc")
    _assert_agrees(corr_t, corr, "correlation")
    # the table the README shows `link.toml` ending with
    blocks = re.findall(r"^```\n(\[identification\]\n.*?)^```", RAW, re.M | re.S)
    assert len(blocks) == 1, "the README shows link.toml's [identification] table once"
    shown = tomllib.loads(blocks[0])["identification"]
    assert shown["parameters"] == ident["parameters"]
    for key in ("estimates", "std", "correlation"):
        np.testing.assert_allclose(shown[key], ident[key], rtol=1e-9, err_msg=key)


def test_study_figures(identified):
    ds = identified["ds"]
    mismatch = ds["mismatch"]
    assert dict(mismatch.sizes) == {"amplitude": 2, "frequency_hz": 16, "sample": 100}
    lo_t, hi_t, med_t = _readme(r"at 10 mm and 1 Hz `\|E_sim\|` spreads from (\d+) \(5 %\) to "
                                r"(\d+) \(95 %\) over the draws, median (\d+)")
    at = np.abs(mismatch.sel(amplitude=0.01, frequency_hz=1.0).values)
    for text, p in zip((lo_t, med_t, hi_t), BAND, strict=True):
        _assert_agrees(text, float(np.percentile(at, p)), f"|E_sim| {p:g} %")
    # the summary's widest band is the same one
    widest = summarize(ds).widest["mismatch"]
    assert widest["at"] == {"amplitude": 0.01, "frequency_hz": 1.0}
    _assert_agrees(med_t, widest["50"], "the summary's median")

    top_t, more_t, n_t, low_t, eq21_t = _readme(
        r"up to ([\d.]+) Hz of these frequencies at 10 mm \(([\d.]+) Hz for (\d+) of the 100 "
        r"draws\) and ([\d.]+) Hz at 1 mm \(eq. 21's crossover, from the quasi-linear "
        r"asymptote: ([\d.]+) Hz\)")
    f = ds["frequency_hz"].values

    def crossovers(amplitude: float) -> np.ndarray:
        """Per draw, the highest frequency where the link dominates (|E_sim - 1| > 1)."""
        over = np.abs(mismatch.sel(amplitude=amplitude).transpose("sample", "frequency_hz")
                      .values - 1.0) > 1.0
        assert over.any(axis=1).all()
        return np.array([f[np.flatnonzero(row).max()] for row in over])

    big, small = crossovers(0.01), crossovers(0.001)
    values, counts = np.unique(big, return_counts=True)
    assert len(values) == 2, dict(zip(values, counts, strict=True))
    _assert_agrees(top_t, values[0], "crossover at 10 mm")
    _assert_agrees(more_t, values[1], "crossover at 10 mm of a few draws")
    assert counts[1] == int(n_t)
    assert np.unique(small).size == 1
    _assert_agrees(low_t, small[0], "crossover at 1 mm")
    # the study's scenario is Table I's loop (the paper's file beside the study file)
    assert Study.from_file(EXAMPLES / "study_identified.toml").scenario == tomllib.loads(
        default_scenario_path().read_text())
    res = analyze(default_scenario().loop(), amplitude=0.01, frequencies_hz=[5.0])
    _assert_agrees(eq21_t, res.mismatch_crossover_hz, "eq. 21's crossover")


def test_fleet_summary_figure(tmp_path):
    """``examples/study.toml``: |E| at 1 Hz and 10 mm over its 100 machines."""
    assert "motionhyst study examples/study.toml --out fleet.zarr" in README
    store = tmp_path / "fleet.zarr"
    assert main(["study", str(EXAMPLES / "study.toml"), "--out", str(store)]) == 0
    ds = open_results(store)
    assert ds["status"].size == 10_000
    lo_t, hi_t, med_t = _readme(r"`\|E\|` at 1 Hz and 10 mm spreads from (\d+) \(5 %\) to "
                                r"(\d+) \(95 %\) over the machines, median (\d+)")
    at = np.abs(ds["E"].sel(amplitude=0.01, frequency_hz=1.0).values)
    assert at.size == 100
    for text, p in zip((lo_t, med_t, hi_t), BAND, strict=True):
        _assert_agrees(text, float(np.percentile(at, p)), f"|E| {p:g} %")


def test_the_dask_settings_for_studies_are_the_engines():
    """The environment the README and the guide start a cluster for studies with is
    ``dask_environment()``, line for line: one edited alone fails here."""
    from motionhyst.study.engine import dask_environment

    want = [f"export {name}={value}" for name, value in dask_environment().items()]
    for text in (RAW, (ROOT / "docs" / "guide" / "studies.rst").read_text()):
        got = [line.strip() for line in text.splitlines()
               if line.strip().startswith("export DASK_")]
        assert got == want
