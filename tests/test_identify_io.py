"""Grey-box identification from input-output records (identify.input_output) and its CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.hysteresis import BoucWen
from motionhyst.identify.input_output import IORecord, best_linear_approximation, identify_io
from motionhyst.time.openloop import MassSpringDamper, OpenLoop

FS = 750.0
TRUE = {"m": 2.0, "c": 10.0, "k": 5e4, "alpha": 5e4, "beta*gamma": 800.0,
        "beta*delta": -1100.0}
SYSTEM = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                  BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0))
SUBSTEPS = 20


def _multisine(n: int, seed: int, rms: float = 50.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (FS / n)), int(150 / (FS / n)) + 1)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


def _record(n: int, seed: int, noise: float = 0.0, periodic: bool = False) -> IORecord:
    u = _multisine(n, seed)
    t = np.arange(n) / FS
    y = SYSTEM.simulate(t, u, periodic=periodic, substeps=SUBSTEPS).displacement
    y = y + noise * np.random.default_rng(seed + 100).standard_normal(n)
    return IORecord(t, u, y, f"record {seed}")


@pytest.fixture(scope="module")
def exact_fit():
    return identify_io([_record(1536, 1)], substeps=SUBSTEPS)


def test_noise_free_records_give_the_parameters(exact_fit):
    for name, value in TRUE.items():
        assert exact_fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert exact_fit.fit_rms < 1e-12
    # beta alone is not identifiable; the identifiable products are the estimates
    assert "beta" in exact_fit.not_identifiable
    g = exact_fit.hysteresis.general
    assert abs(g["gamma"]) + abs(g["delta"]) == pytest.approx(1.0)
    assert g["beta"] * g["gamma"] == pytest.approx(800.0, rel=1e-6)
    d = exact_fit.to_dict()
    assert {"plant", "hysteresis", "std", "fit_rms", "records", "seconds"} <= set(d)
    assert d["plant"] == {"type": "mass-spring-damper", "m": pytest.approx(2.0, rel=1e-6),
                          "c": pytest.approx(10.0, rel=1e-6), "k": pytest.approx(5e4, rel=1e-6)}


def test_noisy_records_within_three_standard_errors():
    noise = 8e-6  # the benchmark's noise, about 1 % of the output RMS
    fit = identify_io([_record(1536, 2, noise), _record(1536, 3, noise)], substeps=SUBSTEPS)
    for name, value in TRUE.items():
        std = fit.std[name]
        assert std is not None and 0 < std < 0.01 * abs(value), name
        assert abs(fit.estimates[name] - value) <= 3 * std, name
    assert fit.fit_rms == pytest.approx(noise, rel=0.1)


def test_periodic_records():
    fit = identify_io([_record(1024, 4, periodic=True)], periodic=True, substeps=SUBSTEPS)
    for name, value in TRUE.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name


def test_best_linear_approximation_of_a_linear_stage():
    t = np.arange(2048) / FS
    u = _multisine(2048, 5)
    plant = MassSpringDamper(1.5, 4.0, 2e4)
    y = OpenLoop(plant).simulate(t, u, periodic=True).displacement
    bla = best_linear_approximation([IORecord(t, u, y)])
    assert (bla.m, bla.c, bla.k) == (pytest.approx(1.5, rel=1e-6), pytest.approx(4.0, rel=1e-5),
                                     pytest.approx(2e4, rel=1e-6))


def test_record_errors():
    t = np.arange(200) / FS
    u = np.sin(2 * np.pi * 10 * t)
    with pytest.raises(ValueError, match="too short"):
        identify_io([IORecord(t[:10], u[:10], u[:10], "a.csv")])
    with pytest.raises(ValueError, match=r"a\.csv: displacement must be finite: sample "):
        identify_io([IORecord(t, u, np.where(t > 0.1, np.nan, 0.0), "a.csv")])
    with pytest.raises(ValueError, match=r"a\.csv: the force is constant"):
        identify_io([IORecord(t, np.ones_like(t), u, "a.csv")])
    with pytest.raises(ValueError, match=r"b\.csv: sampled at 375 Hz"):
        identify_io([IORecord(t, u, u, "a.csv"), IORecord(2 * t, u, u, "b.csv")])
    with pytest.raises(ValueError, match="differ in length"):
        identify_io([IORecord(t, u, u[:-1], "a.csv")])
    with pytest.raises(ValueError, match="unknown link model"):
        identify_io([IORecord(t, u, u)], "preisach")


def _write_csv(path, rec: IORecord) -> None:
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")


def test_cli_identify_save_and_predict(tmp_path, capsys):
    rec = _record(1536, 1)
    data = tmp_path / "rec.csv"
    _write_csv(data, rec)
    model = tmp_path / "model.toml"
    assert main(["identify", str(data), "--record", "input-output", "--save", str(model),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"plant", "hysteresis", "std", "fit_rms", "records", "seconds"} <= set(out)
    assert out["hysteresis"]["model"] == "bouc-wen"
    assert out["plant"]["m"] == pytest.approx(2.0, rel=1e-4)
    # predict reads the saved scenario; the periodic prediction of one period is the
    # model's steady state
    t = np.arange(512) / FS
    u = _multisine(512, 9)
    inp = tmp_path / "force.csv"
    np.savetxt(inp, np.column_stack([t, u]), delimiter=",", header="time,force", comments="",
               fmt="%.17g")
    pred = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(inp), "--periodic", "--out", str(pred)]) == 0
    got = np.loadtxt(pred, delimiter=",", skiprows=1)
    np.testing.assert_allclose(got[:, 0], t, rtol=0, atol=1e-15)
    ref = SYSTEM.simulate(t, u, periodic=True).displacement
    assert np.max(np.abs(got[:, 1] - ref)) < 1e-4 * np.max(np.abs(ref))
    # existing output: refused without --force, replaced with it; an input is never replaced
    assert main(["predict", str(model), str(inp), "--out", str(pred)]) == 2
    assert "exists; give --force" in capsys.readouterr().err
    assert main(["predict", str(model), str(inp), "--out", str(pred), "--force"]) == 0
    assert main(["predict", str(model), str(inp), "--out", str(inp), "--force"]) == 2
    assert "input" in capsys.readouterr().err
    assert np.loadtxt(inp, delimiter=",", skiprows=1).shape == (512, 2)


def test_cli_errors(tmp_path, capsys):
    t = np.arange(100) / FS
    bad = tmp_path / "const.csv"
    _write_csv(bad, IORecord(t, np.ones_like(t), np.sin(t), ""))
    assert main(["identify", str(bad), "--record", "input-output"]) == 2
    err = capsys.readouterr().err
    assert "const.csv: the force is constant" in err and len(err.strip().splitlines()) == 1
    # read as a force-displacement record (its header has both): --model fits its link's
    # force, and this displacement never reverses
    assert main(["identify", str(bad), "--model", "bouc-wen"]) == 2
    assert "const.csv: no reversal" in capsys.readouterr().err
    assert main(["identify", str(bad), "--record", "input-output", "--output", "y1"]) == 2
    assert "--output applies to --plant two-mass only" in capsys.readouterr().err
    assert main(["identify", str(bad), "--output", "y1"]) == 2
    assert "--output applies to --record input-output only" in capsys.readouterr().err
    closed = tmp_path / "closed.toml"
    closed.write_text('[stage]\nm1 = 5.0\nm2 = 17.5\nb = 90.0\nk = 7.4e7\n'
                      '[hysteresis]\nmodel = "jenkins"\nk = 20.0\nfc = 0.05\n'
                      '[controller]\ntype = "tf"\nnum = [1e6, 1e8]\nden = [1.0, 1e3]\n'
                      '[reference]\namplitude = 0.01\nfrequencies = [1.0]\n')
    assert main(["predict", str(closed), str(bad), "--out", str(tmp_path / "o.csv")]) == 2
    assert "not a mass-spring-damper" in capsys.readouterr().err


def test_maxwell_slip_link_recovered_from_noise_free_records():
    from motionhyst.hysteresis import MaxwellSlip

    true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), MaxwellSlip(k=[2e4, 3e4], fc=[4.0, 15.0]))
    n = 1536
    u = _multisine(n, 1)
    t = np.arange(n) / FS
    y = true.simulate(t, u, substeps=10).displacement
    fit = identify_io([IORecord(t, u, y)], "maxwell-slip", n_elements=2, substeps=10)
    expected = {"m": 2.0, "c": 10.0, "k": 5e4, "link.k[0]": 2e4, "link.k[1]": 3e4,
                "link.fc[0]": 4.0, "link.fc[1]": 15.0}
    for name, value in expected.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert fit.hysteresis.to_dict()["model"] == "maxwell-slip"


def test_link_that_saturates_early_is_recovered():
    """A link whose ultimate force (0.53 N) is a tenth of the force's RMS hardly shows in the
    linear model's stiffness: the starts that split that stiffness alone led the search
    outside the model's accepted set."""
    fs = 500.0
    system = OpenLoop(MassSpringDamper(0.5, 4.0, 2e3),
                      BoucWen.from_general(800.0, 3e3, 0.7, -0.2, 1.0))
    rng = np.random.default_rng(3)
    records = []
    for i in range(2):
        spec = np.zeros(2001, dtype=complex)
        spec[2:300] = np.exp(2j * np.pi * rng.random(298))
        u = np.fft.irfft(spec, 4000)
        u *= 5.0 / np.std(u)
        t = np.arange(4000) / fs
        records.append(IORecord(t, u, system.simulate(t, u, substeps=SUBSTEPS).displacement,
                                f"record {i}"))
    fit = identify_io(records, substeps=SUBSTEPS)
    true = {"m": 0.5, "c": 4.0, "k": 2e3, "alpha": 800.0, "beta*gamma": 2100.0,
            "beta*delta": -600.0}
    for name, value in true.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name


def test_free_exponent_of_the_benchmark_link_is_fixed_at_one():
    # no ultimate force (beta*(gamma + delta) < 0) is admitted for nu = 1 only; the data
    # cannot tell nu from 1, so it is fixed there and the rest refined again
    fit = identify_io([_record(1536, 1)], nu=None, substeps=SUBSTEPS)
    assert "nu" not in fit.estimates and fit.hysteresis.general["nu"] == 1.0
    assert fit.not_identifiable["nu"].startswith("not distinguishable from 1")
    for name, value in TRUE.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name


def test_inseparable_parameters_are_reported_not_given_huge_errors():
    from motionhyst.identify.io_uncertainty import standard_errors, undetermined_notes

    rng = np.random.default_rng(8)
    a, b = rng.standard_normal(200), rng.standard_normal(200)
    J = np.column_stack([a, b, 3.0 * b, np.zeros(200)])  # b, 3b: only b + 3c counts
    std, groups = standard_errors(J, rss=2.0, n_rows=200)
    assert sorted(map(sorted, groups)) == [[1, 2], [3]]
    assert np.isfinite(std[0]) and np.all(np.isnan(std[1:]))
    notes = undetermined_notes(["m", "k", "link.k", "fc"], groups, 1e-8)
    assert notes["k"].startswith("not determined by these records: only a combination with "
                                 "link.k is")
    assert "no effect on the output" in notes["fc"]
    assert "m" not in notes


LUGRE_STAGE = MassSpringDamper(2.0, 10.0, 5e4)
LUGRE_TRUE = {"m": 2.0, "c": 10.0, "k": 5e4, "link.sigma0": 2e4, "link.sigma1": 30.0,
              "link.fc": 5.0, "link.fs": 8.0, "link.vs": 0.02}


def _lugre_record(n: int, seed: int, rms: float, noise: float = 0.0) -> IORecord:
    from motionhyst.hysteresis import LuGre

    link = LuGre(sigma0=2e4, sigma1=30.0, sigma2=0.0, fc=5.0, fs=8.0, vs=0.02)
    u = _multisine(n, seed, rms)
    t = np.arange(n) / FS
    y = OpenLoop(LUGRE_STAGE, link).simulate(t, u, substeps=10).displacement
    y = y + noise * np.random.default_rng(seed + 100).standard_normal(n)
    return IORecord(t, u, y, f"lugre {seed}")


def test_lugre_link_recovered_from_noise_free_records():
    # 50 N RMS: the bristles slide (the link force reaches fc) and pass through the
    # Stribeck range; every parameter but sigma2 (a damper in parallel with c) is determined
    fit = identify_io([_lugre_record(1024, 1, 50.0)], "lugre", substeps=10)
    for name, value in LUGRE_TRUE.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert fit.fit_rms < 1e-12
    assert "link.sigma2" not in fit.estimates
    assert fit.not_identifiable["link.sigma2"].startswith("a damper in parallel")
    assert fit.hysteresis.to_dict() == {"model": "lugre", "sigma0": pytest.approx(2e4),
                                        "sigma1": pytest.approx(30.0), "sigma2": 0.0,
                                        "fc": pytest.approx(5.0), "fs": pytest.approx(8.0),
                                        "vs": pytest.approx(0.02)}


def test_lugre_noisy_records_within_three_standard_errors():
    noise = 1e-5  # about 0.5 % of the output RMS
    fit = identify_io([_lugre_record(1024, 2, 50.0, noise), _lugre_record(1024, 3, 50.0, noise)],
                      "lugre", substeps=10)
    for name, value in LUGRE_TRUE.items():
        std = fit.std[name]
        if name in ("link.fs", "link.vs"):  # the Stribeck dip is near the noise here
            assert (std is None and name in fit.not_identifiable) or std > 0, name
        else:
            assert std is not None and 0 < std < 0.02 * abs(value), name
        if std is not None:
            assert abs(fit.estimates[name] - value) <= 3 * std, name
    assert fit.fit_rms == pytest.approx(noise, rel=0.1)


def test_cli_lugre_below_sliding_reports_what_the_records_cannot_determine(tmp_path, capsys):
    # 0.5 N RMS: the link force stays far below fc and the velocities below vs, so the
    # Stribeck curve is seen at one level only: vs is not determined (its profile is flat),
    # the rest within three standard errors, the force at the level g(v) ~ fs of the records
    noise = 1.2e-7  # 1 % of the output RMS
    data = tmp_path / "small.csv"
    _write_csv(data, _lugre_record(1024, 2, 0.5, noise))
    model = tmp_path / "lugre.toml"
    assert main(["identify", str(data), "--record", "input-output", "--model", "lugre",
                 "--save", str(model), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["hysteresis"]["model"] == "lugre" and out["hysteresis"]["sigma2"] == 0.0
    assert out["std"]["link.vs"] is None
    assert out["not_identifiable"]["link.vs"].startswith("not determined by these records")
    assert "link.sigma2" in out["not_identifiable"]
    level = LUGRE_TRUE["link.fs"]
    for name, value in {**LUGRE_TRUE, "link.fc": level}.items():
        std = out["std"][name]
        if name not in out["not_identifiable"]:
            assert std is not None and abs(out["estimates"][name] - value) <= 3 * std, name
    assert out["fit_rms"] == pytest.approx(noise, rel=0.1)
    # the saved scenario is the identified system, read by predict
    inp = tmp_path / "force.csv"
    t = np.arange(256) / FS
    np.savetxt(inp, np.column_stack([t, _multisine(256, 9, 0.5)]), delimiter=",",
               header="time,force", comments="", fmt="%.17g")
    pred = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(inp), "--out", str(pred)]) == 0
    from motionhyst.hysteresis import LuGre

    h = out["hysteresis"]
    ref = OpenLoop(MassSpringDamper(out["plant"]["m"], out["plant"]["c"], out["plant"]["k"]),
                   LuGre(h["sigma0"], h["sigma1"], h["sigma2"], h["fc"], h["fs"], h["vs"])
                   ).simulate(t, _multisine(256, 9, 0.5)).displacement
    np.testing.assert_allclose(np.loadtxt(pred, delimiter=",", skiprows=1)[:, 1], ref,
                               rtol=0, atol=1e-12 * np.max(np.abs(ref)))


def _bouc_wen_nu_system(nu: float) -> tuple[OpenLoop, dict[str, float]]:
    """The test stage with a Bouc-Wen link of exponent nu and a 30 N ultimate force."""
    alpha, gamma, delta = 5e4, 0.8, -0.3
    beta = alpha / 30.0 ** nu / (gamma + delta)
    true = {"m": 2.0, "c": 10.0, "k": 5e4, "alpha": alpha, "beta*gamma": beta * gamma,
            "beta*delta": beta * delta, "nu": nu}
    return OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                    BoucWen.from_general(alpha, beta, gamma, delta, nu)), true


@pytest.mark.parametrize("nu", [1.5, 2.0, 3.0])
def test_free_exponent_recovered_from_noise_free_records(nu):
    system, true = _bouc_wen_nu_system(nu)
    t = np.arange(1024) / FS
    u = _multisine(1024, 1)
    y = system.simulate(t, u, substeps=SUBSTEPS).displacement
    fit = identify_io([IORecord(t, u, y)], nu=None, substeps=SUBSTEPS)
    for name, value in true.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert fit.fit_rms < 1e-12
    assert fit.hysteresis.general["nu"] == pytest.approx(nu, rel=1e-6)


def test_free_exponent_noisy_records_within_three_standard_errors():
    system, true = _bouc_wen_nu_system(2.0)
    noise = 8e-6
    records = []
    for seed in (2, 3):
        t = np.arange(1536) / FS
        u = _multisine(1536, seed)
        y = system.simulate(t, u, substeps=SUBSTEPS).displacement
        records.append(IORecord(t, u, y + noise * np.random.default_rng(seed).standard_normal(
            t.size)))
    fit = identify_io(records, nu=None, substeps=SUBSTEPS)
    for name, value in true.items():
        std = fit.std[name]
        assert std is not None and 0 < std < 0.05 * abs(value), name
        assert abs(fit.estimates[name] - value) <= 3 * std, name


def test_cli_model_without_input_output_identification(tmp_path, capsys):
    data = tmp_path / "rec.csv"
    _write_csv(data, _record(256, 1))
    assert main(["identify", str(data), "--record", "input-output", "--model",
                 "maxwell-iwan"]) == 2
    err = capsys.readouterr().err
    assert "--model maxwell-iwan is not available for input-output records; use bouc-wen" in err
    assert len(err.strip().splitlines()) == 1


def test_lugre_link_recovered_from_a_periodic_record():
    # the periodic steady state and its sensitivities, carried from period to period
    from motionhyst.hysteresis import LuGre

    link = LuGre(sigma0=2e4, sigma1=30.0, sigma2=0.0, fc=5.0, fs=8.0, vs=0.02)
    t = np.arange(512) / FS
    u = _multisine(512, 4)
    y = OpenLoop(LUGRE_STAGE, link).simulate(t, u, periodic=True, substeps=10).displacement
    fit = identify_io([IORecord(t, u, y)], "lugre", periodic=True, substeps=10)
    for name, value in LUGRE_TRUE.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert fit.periodic and "exact Jacobian" in fit.stopping


def test_the_rates_of_a_record_are_scipys_savitzky_golay_to_round_off():
    """numpy alone (the inertia check loads no scipy.signal), the same filter."""
    from scipy.signal import savgol_filter

    from motionhyst.identify.io_rates import savgol_derivative

    rng = np.random.default_rng(7)
    for n, window, fs in ((7, 7, 750.0), (200, 5, 100.0), (1501, 9, 750.0), (3000, 21, 5e3)):
        y = 1e-3 * np.cumsum(rng.standard_normal(n))
        for deriv in (1, 2):
            ours = savgol_derivative(y, window, deriv, 1.0 / fs)
            theirs = savgol_filter(y, window, 3, deriv=deriv, delta=1.0 / fs)
            assert np.max(np.abs(ours - theirs)) <= 1e-12 * np.max(np.abs(theirs))
