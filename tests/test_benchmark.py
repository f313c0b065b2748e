"""The Bouc-Wen benchmark's data generator (motionhyst.identify.benchmark) and its test sets."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from motionhyst.identify.benchmark import (
    FS,
    TRUE_PARAMETERS,
    UPSAMPLE,
    benchmark_output,
    decimate_fir,
    load_test_set,
    multisine,
    newmark_bouc_wen,
    training_record,
)


def _shared_benchmark() -> Path | None:
    """The benchmark's folder ``shared/benchmarks/bouc-wen`` next to the repository, if any."""
    for parent in Path(__file__).resolve().parents:
        d = parent / "shared" / "benchmarks" / "bouc-wen"
        if (d / "uval_multisine.mat").is_file():
            return d
    return None


SHARED = _shared_benchmark()
needs_shared = pytest.mark.skipif(SHARED is None, reason="needs ../shared/benchmarks/bouc-wen "
                                  "(the benchmark's official test sets)")


def _upsample_period(u: np.ndarray, r: int) -> np.ndarray:
    """Band-limited upsampling of one period (zero-padded spectrum)."""
    n = u.size
    spec = np.zeros(n * r // 2 + 1, dtype=complex)
    spec[: n // 2] = np.fft.rfft(u)[: n // 2]
    return np.fft.irfft(spec, n * r) * r


@needs_shared
def test_generator_reproduces_the_official_multisine_output():
    # the test INPUT is used here only to check the generator against the test OUTPUT
    test = load_test_set(SHARED, "multisine")
    n = test.u.size
    u_fine = _upsample_period(test.u, UPSAMPLE)
    assert np.max(np.abs(u_fine[::UPSAMPLE] - test.u)) < 1e-12 * np.max(np.abs(test.u))
    y = benchmark_output(np.tile(u_fine, 3))  # from rest; the second period is steady
    rms_test = np.sqrt(np.mean(test.y ** 2))
    err = np.sqrt(np.mean((y[n:2 * n] - test.y) ** 2))
    assert err < 1e-12 * rms_test  # measured 2.4e-16 m on 6.7e-4 m
    # one sample of misalignment would be 0.3 of the signal: the match is not a coincidence
    assert np.sqrt(np.mean((np.roll(y[n:2 * n], 1) - test.y) ** 2)) > 0.1 * rms_test


@needs_shared
def test_test_sets_load():
    for name, n in (("multisine", 8192), ("sinesweep", 153000)):
        rec = load_test_set(SHARED, name)
        assert rec.u.shape == rec.y.shape == (n,)
        assert rec.t[1] == pytest.approx(1 / FS)


def test_missing_test_set_is_a_one_line_error(tmp_path):
    with pytest.raises(ValueError, match=r"uval_multisine\.mat: no such file"):
        load_test_set(tmp_path, "multisine")
    (tmp_path / "uval_multisine.mat").write_text("not a MATLAB file")
    with pytest.raises(ValueError, match=r"uval_multisine\.mat: cannot read"):
        load_test_set(tmp_path, "multisine")
    with pytest.raises(ValueError, match="unknown test set"):
        load_test_set(tmp_path, "chirp")


def test_multisine_lines_and_level():
    rng = np.random.default_rng(3)
    u = multisine(2, rng, period=1024)
    assert u.size == 2 * 1024 * UPSAMPLE
    np.testing.assert_allclose(u[: u.size // 2], u[u.size // 2:], atol=0)
    spec = np.abs(np.fft.rfft(u[: u.size // 2]))
    lines = np.nonzero(spec > 1e-8 * spec.max())[0]
    f_res = FS / 1024
    assert lines[0] == int(np.floor(5 / f_res)) and lines[-1] == int(np.ceil(150 / f_res))
    assert lines.size == lines[-1] - lines[0] + 1  # every line in the band
    np.testing.assert_allclose(spec[lines], spec[lines[0]], rtol=1e-9)  # flat amplitude
    assert np.std(u, ddof=1) == pytest.approx(50.0, rel=1e-3)


def test_newmark_second_order_and_linear_limit():
    # without hysteresis (alpha = 0) the scheme is the trapezoidal rule: second order,
    # error against the exact response of the spring-mass-damper to a step
    p = {"alpha": 0.0, "beta": 0.0}
    m, c, k = TRUE_PARAMETERS["m"], TRUE_PARAMETERS["c"], TRUE_PARAMETERS["k"]
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - zeta ** 2)
    errs = []
    for h in (1e-4, 5e-5):
        n = round(0.05 / h) + 1
        t = np.arange(n) * h
        y = newmark_bouc_wen(np.ones(n), h, p)
        exact = (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd
                                               * np.sin(wd * t))) / k
        errs.append(np.max(np.abs(y - exact)))
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.05)


def test_newmark_hysteresis_static_equilibrium():
    # a slow ramp to 10 N: k y + z = u with z on the virgin curve dz/dy = alpha + 300 z
    # (gamma + delta = -0.3 for y' > 0, z > 0), i.e. z = alpha / 300 (exp(300 y) - 1)
    h = 1 / 15000
    n = 15000 * 20
    u = np.linspace(0, 10.0, n)
    y = newmark_bouc_wen(u, h)
    a, lam = TRUE_PARAMETERS["alpha"], -TRUE_PARAMETERS["beta"] * (
        TRUE_PARAMETERS["gamma"] + TRUE_PARAMETERS["delta"])
    z = a / lam * np.expm1(lam * y[-1])
    assert TRUE_PARAMETERS["k"] * y[-1] + z == pytest.approx(10.0, rel=1e-4)


def test_decimate_fir_aligns_and_passes_the_band():
    t = np.arange(4000) / 4000.0
    x = np.sin(2 * np.pi * 20 * t) + 0.5 * np.cos(2 * np.pi * 70 * t)
    out = decimate_fir(x, 5)
    assert out.size == 800
    # zero phase: aligned with x[::5]; the Hamming FIR's gain at 0.035 fs is 1 within 1e-3
    np.testing.assert_allclose(out[50:-50], x[::5][50:-50], atol=2e-3)
    with pytest.raises(ValueError, match="more than 31 samples"):
        decimate_fir(x[:20], 2)


def test_training_record_is_periodic_after_the_transient():
    rec = training_record(np.random.default_rng(4), 3, period=2048, noise_rms=0.0)
    n = 2048
    assert rec.y.size == 3 * n
    np.testing.assert_allclose(rec.u[:n], rec.u[n:2 * n], atol=0)
    # the 1.1 % damped mode forgets the start within a period of 2.7 s (decay exp(-6.7))
    assert np.max(np.abs(rec.y[2 * n:] - rec.y[n:2 * n])) < 2e-3 * np.max(np.abs(rec.y))
    noisy = training_record(np.random.default_rng(4), 3, period=2048)
    assert np.std(noisy.y - rec.y) == pytest.approx(8e-6, rel=0.05)


@needs_shared
def test_benchmark_on_one_training_period_meets_the_multisine_target():
    from motionhyst.identify.benchmark import run_benchmark

    res = run_benchmark(SHARED, n_experiments=1, n_periods=1, models=("bouc-wen",))
    row = res["models"][0]
    assert row["multisine_rmse"] <= 1e-6  # the target, from 8192 noisy samples only
    assert row["sinesweep_rmse"] <= 5e-6
    assert res["generator_check_rms"] < 1e-12


def test_benchmark_command_without_test_sets(tmp_path, capsys, monkeypatch):
    from motionhyst.cli import main

    for name in ("bouc-wen", "emps"):  # the benchmarks' folders beside the working folder
        (tmp_path / "shared" / "benchmarks" / name).mkdir(parents=True)
    (tmp_path / "repo").mkdir()
    monkeypatch.chdir(tmp_path / "repo")
    for name in ("bouc-wen", "emps"):  # never looked for in ../shared: --data is required
        assert main(["benchmark", name]) == 2
        err = capsys.readouterr().err
        assert "give --data DIR" in err and "nonlinearbenchmark.org" in err
        assert err.count("\n") == 1
    assert main(["benchmark", "bouc-wen", "--data", str(tmp_path)]) == 2
    assert "uval_multisine.mat: no such file" in capsys.readouterr().err
