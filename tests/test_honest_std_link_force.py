"""Standard errors of a force-displacement Maxwell-slip fit that a user can trust (issue 21).

A two-element link (k 2e4 and 8e3 N/m, fc 2 and 6 N, a 1 N force offset) under a 1 mm
displacement of three sines, 6000 samples at 1 kHz.  With the force sensor's noise through a
first-order low-pass (rho 0.95), the standard errors computed as for white residuals put the
truth within 3 of them for 25-58 % of 12 records (13.7 of them away at worst), none said to be
lower bounds; they now take the residuals' autocorrelation (fit.correlated_std, as the
input-output routes do): 100 % (2.79 at worst), each such fit saying its standard errors are
lower bounds.  White noise keeps its standard errors (the same 12 records' |z| 2.29 at worst,
before and after)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from motionhyst import MaxwellSlip
from motionhyst.cli import main
from motionhyst.identify import identify_maxwell_slip

K, FC, OFFSET = [2e4, 8e3], [2.0, 6.0], 1.0
RHO = 0.95


def _record(seed: int, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(6000) / 1000.0
    ph = rng.uniform(0, 6, 3)
    x = 1e-3 * (np.sin(2 * np.pi * 0.5 * t + ph[0]) + 0.4 * np.sin(2 * np.pi * 1.3 * t + ph[1])
                + 0.2 * np.sin(2 * np.pi * 3.1 * t + ph[2]))
    e = 0.05 * rng.standard_normal(t.size)
    noise = e if kind == "white" else lfilter([1 - RHO], [1, -RHO],
                                              e * np.sqrt((1 + RHO) / (1 - RHO)))
    return t, x, MaxwellSlip(k=K, fc=FC).response(x) + noise + OFFSET


def _z(ident) -> list[float]:
    z = [(e["k"] - K[i]) / e["k_std"] for i, e in enumerate(ident.elements)]
    z += [(e["fc"] - FC[i]) / e["fc_std"] for i, e in enumerate(ident.elements)]
    return [*z, (ident.offset - OFFSET) / ident.offset_std]


@pytest.mark.parametrize("seed", [1, 2, 5, 7])
def test_coloured_force_noise_widens_the_standard_errors_to_hold_the_truth(seed):
    """Seeds whose white standard errors put the truth 4.5-11.9 of them away (main): now
    within 3 (measured at most 2.8), widened 3-6 times, the white ones kept as judged_std,
    the fit saying its standard errors are lower bounds."""
    t, x, w = _record(seed, "coloured")
    ident = identify_maxwell_slip(x, w, 2, t=t)
    assert max(abs(z) for z in _z(ident)) <= 3.0
    for i, e in enumerate(ident.elements):
        assert 2.0 < e["fc_std"] / ident.judged_std[f"fc[{i}]"] < 10.0
    assert ident.std_lower_bound.startswith("standard errors are lower bounds: the fit leaves")
    assert "Newey-West" in ident.std_lower_bound
    cov = ident.covariance
    std = dict(zip(cov["parameters"], np.sqrt(np.diag(cov["matrix"])), strict=True))
    assert std["fc[0]"] == pytest.approx(ident.elements[0]["fc_std"], rel=1e-9)
    assert std["offset"] == pytest.approx(ident.offset_std, rel=1e-9)


@pytest.mark.parametrize("seed", [0, 3])
def test_white_force_noise_keeps_its_standard_errors(seed):
    """White noise: within 10 % of the white residuals' standard errors (measured 0-5 %),
    the truth within 3 of them, nothing said."""
    t, x, w = _record(seed, "white")
    ident = identify_maxwell_slip(x, w, 2, t=t)
    assert max(abs(z) for z in _z(ident)) <= 3.0
    for i, e in enumerate(ident.elements):
        assert e["fc_std"] == pytest.approx(ident.judged_std[f"fc[{i}]"], rel=0.1)
        assert e["k_std"] == pytest.approx(ident.judged_std[f"k[{i}]"], rel=0.1)
    assert ident.std_lower_bound is None


def test_the_command_says_so(tmp_path, capsys):
    """``identify`` on such a record: the table marks the standard errors '>=', the line
    under it says why, --json has std_lower_bound."""
    t, x, w = _record(1, "coloured")
    path = tmp_path / "link.csv"
    np.savetxt(path, np.c_[t, x, w], delimiter=",", header="time,displacement,force",
               comments="")
    assert main(["identify", str(path), "--elements", "2"]) == 0
    out = capsys.readouterr().out
    assert ">= " in out and "standard errors are lower bounds: the fit leaves" in out
    assert main(["identify", str(path), "--elements", "2", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["std_lower_bound"] is True and "Newey-West" in got["std_note"]
