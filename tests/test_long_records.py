"""Long records from a start in bounded memory (issue 26): an open-loop run goes through the
record's upsampled force block by block (motionhyst.time.resample.fine_blocks), its state
carried on, with the numbers of one run over the whole upsampled record."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.core.budget import BudgetError, parse_size, set_max_memory
from motionhyst.hysteresis import BoucWen, Coulomb, Dahl, Jenkins, LuGre, MaxwellSlip
from motionhyst.identify.io_predict import predict_from_window
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.time import openloop, resample
from motionhyst.time.bouc_wen_rk4 import simulate_bouc_wen
from motionhyst.time.openloop import MassSpringDamper, OpenLoop, simulate_elements
from motionhyst.time.resample import block_samples, fine_blocks, fine_input, held_nodes

FS = 1000.0


def _force(n: int, seed: int = 0) -> np.ndarray:
    """A force that moves an axis back and forth, with noise [N]."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    return (60.0 * np.sin(2 * np.pi * 1.3 * t) + 25.0 * np.sin(2 * np.pi * 7.1 * t + 1.0)
            + rng.standard_normal(n))


def _joined(blocks: list[np.ndarray]) -> np.ndarray:
    return np.concatenate([blocks[0]] + [b[1:] for b in blocks[1:]])


@pytest.mark.parametrize("factor", [1, 3, 20])
@pytest.mark.parametrize("n", [2, 257, 5003])
def test_the_blocks_are_the_whole_records_fine_input_bit_for_bit(factor, n):
    u = np.cumsum(np.random.default_rng(n).standard_normal(n))
    blocks = list(fine_blocks(u, factor, nodes=300 * factor))
    assert len(blocks) == (1 if factor == 1 or n - 1 <= 300 else -(-(n - 1) // 300))
    assert all(b.size == 300 * factor + 1 for b in blocks[:-1])
    np.testing.assert_array_equal(_joined(blocks), fine_input(u, factor, periodic=False))


def test_a_record_of_whole_periods_is_interpolated_as_one():
    period = np.random.default_rng(1).standard_normal(250)
    u = np.tile(period, 40)  # 10000 samples: the spectrum of the whole record, zero-padded
    blocks = list(fine_blocks(u, 20, nodes=20 * 1000))
    assert len(blocks) == 10
    whole = fine_input(u, 20, periodic=False)
    assert np.max(np.abs(_joined(blocks) - whole)) <= 1e-13 * np.max(np.abs(whole))
    # what the memory check counts: a block and the upsampled period (with its index)
    assert held_nodes(u, 20, nodes=20 * 1000) == blocks[0].size + 2 * 250 * 20
    assert held_nodes(np.cumsum(u), 20, nodes=20 * 1000) == blocks[0].size
    u = np.tile(period[:143], 70)  # 10010 samples, 13 x 11 x 70: the windowed sinc, wrapped
    np.testing.assert_array_equal(_joined(list(fine_blocks(u, 20, nodes=20 * 1000))),
                                  fine_input(u, 20, periodic=False))


def test_a_block_holds_at_least_256_samples():
    assert block_samples(20) == resample.BLOCK_NODES // 20
    assert block_samples(10000) == block_samples(20, nodes=100) == 256


SYSTEMS = {
    "axis-jenkins-offset": OpenLoop(MassDamper(95.0, 200.0, force_offset=-3.0),
                                    Jenkins(k=1e6, fc=20.0)),
    "axis-coulomb-by-direction": OpenLoop(MassDamper(95.0, 200.0, c_skew=-20.0),
                                          Coulomb(fc=20.0)),
    "axis-bouc-wen": OpenLoop(MassDamper(95.0, 200.0), BoucWen(k=2e5, fc=20.0)),
    "spring-lugre": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                             LuGre(sigma0=2e4, sigma1=30.0, sigma2=0.0, fc=5.0, fs=8.0, vs=0.02)),
    "spring-dahl": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Dahl(k=2e4, fc=5.0)),
    "two-mass-maxwell-slip": OpenLoop(TwoMassStage(2.0, 3.0, 20.0, 2e5),
                                      MaxwellSlip(k=[1e4, 2e4], fc=[2.0, 4.0])),
    "spring-bouc-wen-rk4": OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=2e4, fc=5.0)),
    "axis-alone-rk4": OpenLoop(MassDamper(95.0, 200.0, force_offset=2.0)),
}


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_a_run_in_blocks_is_the_run_over_the_whole_record(monkeypatch, name):
    system = SYSTEMS[name]
    u = _force(3000)
    t = np.arange(u.size) / FS
    whole = system.simulate(t, u).displacement  # one block: 3000 samples
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    blocks = system.simulate(t, u).displacement
    assert np.all(np.isfinite(whole)) and np.ptp(whole) > 0
    np.testing.assert_array_equal(blocks, whole)


def test_the_sensitivities_in_blocks_are_those_of_the_whole_record(monkeypatch):
    monkeypatch.setattr(resample, "BLOCK_NODES", 1)
    u = _force(1500)
    mech = MassSpringDamper(2.0, 10.0, 5e4).mechanics()
    dparams = np.zeros((1, 8, 2))
    dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0  # Jenkins (k, fc)
    link = Jenkins(k=2e4, fc=5.0).time_stepping()
    y, dy = simulate_elements(mech, link, u, FS, 10, periodic=False, dparams=dparams)
    y1, dy1 = simulate_elements(mech, link, u, FS, 10, periodic=False, dparams=dparams,
                                upsampled=fine_input(u, 10, periodic=False))
    np.testing.assert_array_equal(y, y1)
    np.testing.assert_array_equal(dy, dy1)
    assert dy.shape == (1500, 5) and np.ptp(dy[:, 3]) > 0
    p = np.array([2.0, 10.0, 5e4, 2e4, 800.0, -1100.0, 1.0])
    y, dy = simulate_bouc_wen(p, u, FS, 20, periodic=False, sensitivities=True)
    y1, dy1 = simulate_bouc_wen(p, u, FS, 20, periodic=False, sensitivities=True,
                                upsampled=fine_input(u, 40, periodic=False))
    np.testing.assert_array_equal(y, y1)
    np.testing.assert_array_equal(dy, dy1)


def test_a_prediction_from_a_window_in_blocks_is_the_same(monkeypatch):
    system = SYSTEMS["axis-jenkins-offset"]
    u = _force(3000)
    t = np.arange(u.size) / FS
    y = system.simulate(t, u).displacement + 0.01
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)  # the whole record as one block
    whole = predict_from_window(system, t, u, y)
    seen = []
    blocks_of = resample.fine_blocks

    def counted(*args, **kwargs):
        for b in blocks_of(*args, **kwargs):
            seen.append(b.size)
            yield b

    monkeypatch.setattr(resample, "BLOCK_NODES", 1)  # blocks of 256 samples
    monkeypatch.setattr(openloop, "fine_blocks", counted)
    blocks = predict_from_window(system, t, u, y)
    # the runs went through the record in blocks: the prediction's, and its run from a
    # velocity a step off (the window's noise floor, io_predict.window_noise_floor)
    assert len(seen) == 2 * -(-2999 // 256)
    np.testing.assert_array_equal(blocks.displacement, whole.displacement)
    assert whole.rmse < 1e-9
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)
    set_max_memory(parse_size("10M"))
    try:
        with pytest.raises(BudgetError, match="3000 samples of 200 integration steps each"):
            predict_from_window(system, t, u, y, substeps=200)  # 29 MB at once
        monkeypatch.setattr(resample, "BLOCK_NODES", 1)
        predict_from_window(system, t, u, y, substeps=200)  # 256-sample blocks: 2.7 MB
    finally:
        set_max_memory(None)


def test_predict_needs_the_record_and_one_block_not_the_whole_upsampled_record(tmp_path,
                                                                                monkeypatch,
                                                                                capsys):
    """8000 samples of 500 steps: 192 MB upsampled at once, above --max-memory 150M; in
    blocks of 4194 samples about 100 MB: predicted, the numbers of the whole record's run."""
    u = _force(8000)
    t = np.arange(u.size) / FS
    np.savetxt(tmp_path / "f.csv", np.column_stack([t, u]), delimiter=",", header="time,force",
               comments="")
    (tmp_path / "m.toml").write_text('[stage]\ntype = "mass-damper"\nm = 95.0\nc = 200.0\n\n'
                                     '[hysteresis]\nmodel = "jenkins"\nk = 1e6\nfc = 20.0\n')
    base = ["predict", str(tmp_path / "m.toml"), str(tmp_path / "f.csv"), "--substeps", "500"]
    assert main([*base, "--out", str(tmp_path / "p.csv"), "--max-memory", "150M"]) == 0
    monkeypatch.setattr(resample, "BLOCK_NODES", 1 << 40)  # the whole record as one block
    assert main([*base, "--out", str(tmp_path / "q.csv"), "--max-memory", "150M"]) == 2
    assert "8000 samples of 500 integration steps each needs 192 MB" in capsys.readouterr().err
    assert main([*base, "--out", str(tmp_path / "q.csv")]) == 0
    p = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert p.shape == (8000, 2) and np.ptp(p[:, 1]) > 1e-3
    np.testing.assert_array_equal(p, np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1))
