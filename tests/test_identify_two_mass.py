"""Grey-box identification of the open-loop two-mass stage (eqs. 1-2) and its link."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.hysteresis import BoucWen, Dahl, Jenkins
from motionhyst.identify.input_output import (
    IORecord,
    best_linear_approximation_two_mass,
    identify_io,
)
from motionhyst.identify.io_elements import _ElementProblem, _LinkLayout
from motionhyst.time.openloop import OpenLoop, TwoMass

FS = 750.0
SUBSTEPS = 20
STAGE = {"m1": 2.0, "m2": 3.0, "b": 20.0, "k": 2e5}  # internal mode at 65 Hz, in the band
LINK = {"alpha": 5e4, "beta*gamma": 800.0, "beta*delta": -1100.0}
BOUC_WEN = BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0)


def _multisine(n: int, seed: int, rms: float = 50.0, odd: bool = False) -> np.ndarray:
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (FS / n)), int(150 / (FS / n)) + 1)
    if odd:  # u(t + T/2) = -u(t): no link ratchets the floating stage
        lines = lines[lines % 2 == 1]
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


def _record(n: int, seed: int, output: str = "y2", noise: float = 0.0, periodic: bool = False,
            link=BOUC_WEN, substeps: int = SUBSTEPS, rms: float = 50.0) -> IORecord:
    u = _multisine(n, seed, rms, odd=periodic)
    t = np.arange(n) / FS
    system = OpenLoop(TwoMass(**STAGE, output=output), link)
    y = system.simulate(t, u, periodic=periodic, substeps=substeps).displacement
    y = y + noise * np.random.default_rng(seed + 100).standard_normal(n)
    return IORecord(t, u, y, f"record {seed}")


@pytest.mark.filterwarnings("error::motionhyst.core.warnings.MotionhystWarning")
@pytest.mark.parametrize("output", ["y2", "y1"])
def test_noise_free_records_give_the_parameters(output):
    fit = identify_io([_record(1536, 1, output)], plant="two-mass", output=output,
                      substeps=SUBSTEPS)
    for name, value in {**STAGE, **LINK}.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert list(fit.estimates)[:4] == ["m1", "m2", "b", "k"]
    assert fit.fit_rms < 1e-12
    # floating, y2 (or y1) measured: every parameter is determined, only beta is not
    assert set(fit.not_identifiable) == {"beta", "gamma", "delta"}
    assert all(fit.std[name] is not None for name in fit.estimates)
    assert fit.plant.output == output and fit.plant.to_dict()["type"] == "two-mass"


@pytest.mark.filterwarnings("error::motionhyst.core.warnings.MotionhystWarning")
def test_noisy_records_within_three_standard_errors():
    noise = 2e-5  # about 1 % of the output's RMS
    fit = identify_io([_record(1536, 2, noise=noise), _record(1536, 3, noise=noise)],
                      plant="two-mass", substeps=SUBSTEPS)
    for name, value in {**STAGE, **LINK}.items():
        std = fit.std[name]
        assert std is not None and 0 < std < 0.05 * abs(value), name
        assert abs(fit.estimates[name] - value) <= 3 * std, name
    assert fit.fit_rms == pytest.approx(noise, rel=0.1)


@pytest.mark.filterwarnings("error::motionhyst.core.warnings.MotionhystWarning")
def test_periodic_records_compared_without_their_mean():
    # 20 N RMS: at 50 N this one period of y2 leaves the search in a local minimum
    rec = _record(1024, 4, periodic=True, rms=20.0)
    rec = IORecord(rec.t, rec.u, rec.y + 3e-3, rec.name)  # a steady state at any offset
    fit = identify_io([rec], plant="two-mass", periodic=True, substeps=SUBSTEPS)
    for name, value in {**STAGE, **LINK}.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name


@pytest.mark.filterwarnings("error::motionhyst.core.warnings.MotionhystWarning")
@pytest.mark.parametrize("model, link, expected", [
    ("jenkins", Jenkins(k=5e4, fc=60.0), {"link.k": 5e4, "link.fc": 60.0}),
    ("dahl", Dahl(k=5e4, fc=20.0, alpha=1.5),
     {"link.k": 5e4, "link.fc": 20.0, "link.alpha": 1.5})])
def test_element_links_recovered_from_noise_free_records(model, link, expected):
    rec = _record(1536, 1, link=link, substeps=10)
    fit = identify_io([rec], model, plant="two-mass", substeps=10)
    for name, value in {**STAGE, **expected}.items():
        assert fit.estimates[name] == pytest.approx(value, rel=1e-6), name
    assert fit.hysteresis.to_dict()["model"] == model
    assert "(exact Jacobian" in fit.stopping  # the two-mass stage's element sensitivities


def test_the_exact_jacobian_of_a_periodic_floating_stage():
    """Element links on the two-mass stage's periodic steady state (defined up to a constant:
    the output, its sensitivities and the record compared without their means): residuals
    at the truth vanish, the exact Jacobian is the residuals' central differences."""
    # slipping at 20 N of a 20 N RMS force with odd harmonics: no drift, every column alive
    rec = _record(512, 4, periodic=True, rms=20.0, link=Jenkins(k=5e4, fc=20.0), substeps=10)
    rec = IORecord(rec.t, rec.u, rec.y + 3e-3, rec.name)  # the stage's offset is arbitrary
    layout = _LinkLayout.of(Jenkins, 1)
    values = np.array([*STAGE.values(), 5e4, 20.0])
    prob = _ElementProblem([rec], True, 10, layout, float(np.std(rec.y)), values,
                           plant=TwoMass(**STAGE))
    q = prob.variables(values)
    r = prob.residuals(q)
    J = prob.jacobian(q)
    assert prob.exact
    assert np.max(np.abs(r)) < 1e-9  # in units of the output's RMS
    for b in range(q.size):
        hi, lo = q.copy(), q.copy()
        hi[b] += 1e-5
        lo[b] -= 1e-5
        fd = (prob._run(hi) - prob._run(lo)) / 2e-5
        assert np.max(np.abs(J[:, b] - fd)) < 2e-6 * np.max(np.abs(fd)), b


def test_best_linear_approximation_with_the_link_a_spring():
    spring = BoucWen.from_general(5e4, 1.0, 0.0, 0.0, 1.0)  # beta = 0: a linear spring
    for output in ("y2", "y1"):
        rec = _record(4096, 5, output, periodic=True, link=spring)
        plant, k_link, c_link = best_linear_approximation_two_mass([rec], output)
        for name, value in STAGE.items():
            assert getattr(plant, name) == pytest.approx(value, rel=1e-6), (output, name)
        assert k_link == pytest.approx(5e4, rel=1e-6)
        assert c_link < 1e-6 * np.sqrt(5e4 * 5.0)


def _write_csv(path, rec: IORecord) -> None:
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")


def test_cli_identify_two_mass_save_and_predict(tmp_path, capsys):
    data = tmp_path / "rec.csv"
    _write_csv(data, _record(1536, 1, "y1"))
    model = tmp_path / "model.toml"
    assert main(["identify", str(data), "--record", "input-output", "--plant", "two-mass",
                 "--output", "y1", "--save", str(model), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"plant", "hysteresis", "std", "fit_rms", "records", "seconds"} <= set(out)
    assert out["plant"]["type"] == "two-mass" and out["plant"]["output"] == "y1"
    assert out["plant"]["m2"] == pytest.approx(3.0, rel=1e-4)
    assert 'output = "y1"' in model.read_text()
    t = np.arange(512) / FS
    u = _multisine(512, 9, odd=True)
    inp = tmp_path / "force.csv"
    np.savetxt(inp, np.column_stack([t, u]), delimiter=",", header="time,force", comments="",
               fmt="%.17g")
    pred = tmp_path / "pred.csv"
    assert main(["predict", str(model), str(inp), "--periodic", "--out", str(pred)]) == 0
    got = np.loadtxt(pred, delimiter=",", skiprows=1)
    ref = OpenLoop(TwoMass(**STAGE, output="y1"), BOUC_WEN).simulate(t, u, periodic=True)
    assert np.max(np.abs(got[:, 1] - ref.displacement)) < 1e-4 * np.ptp(ref.displacement)
    capsys.readouterr()
    # the text report names the stage and what was measured
    assert main(["identify", str(data), "--record", "input-output", "--plant", "two-mass",
                 "--output", "y1"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("Two-mass stage (y1 measured) and bouc-wen link identified")
    assert 'type = "two-mass"' in text


def test_errors():
    rec = _record(256, 1)
    with pytest.raises(ValueError, match="unknown plant 'three-mass'"):
        identify_io([rec], plant="three-mass")
    with pytest.raises(ValueError, match="unknown output 'y3'"):
        identify_io([rec], plant="two-mass", output="y3")


def test_a_single_mass_record_is_refused_for_a_two_mass_stage(tmp_path, capsys):
    """A single mass's record fitted as a two-mass stage ran its whole search and exited 0
    with the link's products not identifiable: its masses move as one (the internal mode
    of the best linear fit far above the Nyquist frequency), refused in one line before
    the search."""
    from motionhyst.time.openloop import MassSpringDamper

    single = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=5e4, fc=20.0, beta=0.6,
                                                                 gamma=0.2))
    t = np.arange(1536) / FS
    u = _multisine(1536, 1)
    rec = IORecord(t, u, single.simulate(t, u).displacement, "single.csv")
    with pytest.raises(ValueError, match="the records show one mass, not two"):
        best_linear_approximation_two_mass([rec], "y2", periodic=False)
    data = tmp_path / "single.csv"
    _write_csv(data, rec)
    for model in ("bouc-wen", "jenkins"):
        assert main(["identify", str(data), "--record", "input-output", "--plant", "two-mass",
                     "--model", model]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and "--plant mass-spring-damper" in err


def test_a_light_carriage_whose_mode_the_records_excite_is_two_masses():
    """A 0.5 kg carriage on a 60 kg stage (0.8 % of it) whose internal mode, 101 Hz, lies in
    the records' band of 2-300 Hz: the records determine both masses (the link a spring,
    the linear fit exact); the base refused it as one mass for the ratio below 1 %."""
    n, fs = 3000, 1000.0
    t = np.arange(n) / fs
    rng = np.random.default_rng(0)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(6, 901)  # 2-300 Hz
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    u *= 200.0 / np.std(u)
    spring = BoucWen.from_general(5e4, 1.0, 0.0, 0.0, 1.0)  # beta = 0: a spring
    y = OpenLoop(TwoMass(0.5, 60.0, 20.0, 2e5), spring).simulate(t, u, substeps=20)
    p, kl, _ = best_linear_approximation_two_mass([IORecord(t, u, y.displacement)], "y2",
                                                  periodic=False)
    assert (p.m1, p.m2, p.k, kl) == pytest.approx((0.5, 60.0, 2e5, 5e4), rel=1e-3)
