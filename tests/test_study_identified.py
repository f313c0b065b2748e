"""Monte Carlo from an identification's covariance: what ``identify --json`` and ``--save``
carry, and the study's joint draws of the link's parameters (study/identified.py)."""

from __future__ import annotations

import json
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.hysteresis import Jenkins
from motionhyst.identify.input_output import IORecord, identify_io
from motionhyst.scenario import Scenario, default_scenario_path
from motionhyst.study import Study, StudyError, open_results, run_study
from motionhyst.study.identified import LOG_SPACE_CV, JointNormal, joint_from_identification
from motionhyst.time.openloop import MassSpringDamper, OpenLoop

N_DRAWS = 4000


def _force_displacement_record(path: Path, noise: float = 0.002, n: int = 4000) -> Path:
    """A Jenkins link (Table I's k_J = 20 N/m, f_c = 0.05 N) driven by a sine whose amplitude
    decays from 10 mm to 0.5 mm and grows back, its force with white noise [N]."""
    t = np.arange(n) / 1000.0
    env = np.concatenate([np.geomspace(0.01, 5e-4, n // 2), np.geomspace(5e-4, 0.01, n - n // 2)])
    x = env * np.sin(2 * np.pi * 2.0 * t)
    w = Jenkins(k=20.0, fc=0.05).response(x) + noise * np.random.default_rng(1).standard_normal(n)
    np.savetxt(path, np.column_stack([t, x, w]), delimiter=",", comments="", fmt="%.17g",
               header="time,displacement,force")
    return path


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> tuple[Path, dict]:
    """``identify --save`` and ``identify --json`` of one force-displacement record."""
    folder = tmp_path_factory.mktemp("identified")
    record = _force_displacement_record(folder / "link.csv")
    model = folder / "model.toml"
    assert main(["identify", str(record), "--elements", "1", "--save", str(model)]) == 0
    fit = folder / "fit.json"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["identify", str(record), "--elements", "1", "--json"]) == 0
    fit.write_text(buf.getvalue())
    shutil.copy(default_scenario_path(), folder / "paper.toml")
    return folder, json.loads(buf.getvalue())


def _study(folder: Path, source: str, extra: str = "", n: int = N_DRAWS, seed: int = 3) -> Path:
    path = folder / f"study_{seed}_{n}.toml"
    path.write_text(f'scenario = "paper.toml"\noutputs = ["mismatch"]\n[axes]\n'
                    f'frequency_hz = [5.0, 10.0]\n[samples]\nn = {n}\nseed = {seed}\n'
                    f'from_identification = "{source}"\n{extra}')
    return path


def test_json_and_save_carry_the_covariance_of_the_standard_errors(saved):
    folder, fit = saved
    cov = fit["covariance"]
    assert cov["parameters"] == ["k", "fc", "offset"]
    c = np.array(cov["matrix"])
    assert np.array_equal(c, c.T)
    e = fit["elements"][0]
    np.testing.assert_allclose(np.sqrt(np.diag(c))[:2], [e["k_std"], e["fc_std"]], rtol=1e-12)
    assert c[2, 2] > 0
    r = c[0, 1] / np.sqrt(c[0, 0] * c[1, 1])
    assert 0.3 < r < 0.95  # k and fc of one element are correlated: independent draws miss it
    text = (folder / "model.toml").read_text()
    ident = tomllib.loads(text)["identification"]
    assert ident["parameters"] == ["hysteresis.k", "hysteresis.fc"]
    assert ident["estimates"] == [e["k"], e["fc"]]
    np.testing.assert_allclose(ident["std"], [e["k_std"], e["fc_std"]], rtol=1e-12)
    assert ident["correlation"][0][1] == pytest.approx(r, abs=1e-12)
    # the saved file stays a scenario (predict reads it); the table changes nothing in it
    sc = Scenario.from_file(folder / "model.toml")
    assert sc.model.identification.parameters == ["hysteresis.k", "hysteresis.fc"]


def test_input_output_identification_carries_its_covariance():
    """The input-output route: every determined estimate in the covariance, whose diagonal
    is the squares of the standard errors; the saved scenario names them by their keys."""
    true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), Jenkins(k=5e4, fc=20.0))
    t = np.arange(1024) / 750
    u = 40 * np.sin(2 * np.pi * 8 * t) + 20 * np.sin(2 * np.pi * 31 * t)
    y = true.simulate(t, u).displacement
    y = y + 0.02 * np.std(y) * np.random.default_rng(0).standard_normal(y.size)
    fit = identify_io([IORecord(t, u, y)], model="jenkins")
    cov = fit.to_dict()["covariance"]
    determined = [n for n, s in fit.std.items() if s is not None]
    assert cov["parameters"] == determined
    assert {"m", "c", "k", "link.k", "link.fc"} <= set(determined)
    np.testing.assert_allclose(np.sqrt(np.diag(cov["matrix"])),
                               [fit.std[n] for n in determined], rtol=1e-9)
    ident = tomllib.loads(fit.scenario_text())["identification"]
    assert ident["parameters"] == ["stage.m", "stage.c", "stage.k", "hysteresis.k",
                                   "hysteresis.fc"]
    d = joint_from_identification(_write(fit.scenario_text()))
    assert d.keys == ("hysteresis.k", "hysteresis.fc")
    at = [determined.index("link.k"), determined.index("link.fc")]
    np.testing.assert_allclose(d.covariance, np.array(cov["matrix"])[np.ix_(at, at)],
                               rtol=1e-9)


def _write(text: str) -> Path:
    import tempfile

    path = Path(tempfile.mkdtemp()) / "model.toml"
    path.write_text(text)
    return path


def _within_sampling_error(x: np.ndarray, mean, cov, n_sigma: float = 4.0) -> None:
    """Sample means and covariances of the rows of `x` against `mean` and `cov`: each within
    `n_sigma` of its standard error (normal draws: var(s_ij) = (c_ii c_jj + c_ij^2) / n)."""
    n = x.shape[0]
    mean, cov = np.asarray(mean), np.asarray(cov)
    assert np.all(np.abs(x.mean(axis=0) - mean) <= n_sigma * np.sqrt(np.diag(cov) / n))
    se = np.sqrt((np.outer(np.diag(cov), np.diag(cov)) + cov ** 2) / n)
    assert np.all(np.abs(np.cov(x.T) - cov) <= n_sigma * se)


@pytest.mark.parametrize("source", ["model.toml", "fit.json"])
def test_draws_have_the_saved_covariance_and_the_seed_gives_the_same_study(saved, source):
    folder, fit = saved
    st = Study.from_file(_study(folder, source))
    assert st.sampled_keys == ("hysteresis.k", "hysteresis.fc") and not st.samples
    e = fit["elements"][0]
    saved_cov = np.array(fit["covariance"]["matrix"])[:2, :2]
    assert not st.joint.log_space  # 0.1 % errors: the normal distribution itself
    _within_sampling_error(st.sample_values, [e["k"], e["fc"]], saved_cov)
    again = Study.from_file(_study(folder, source))
    assert np.array_equal(again.sample_values, st.sample_values)
    assert again.fingerprint() == st.fingerprint()
    other = Study.from_file(_study(folder, source, seed=4))
    assert not np.array_equal(other.sample_values, st.sample_values)


def test_the_same_seed_computes_the_same_study(saved, tmp_path):
    folder, _ = saved
    stores = []
    for name in ("a.zarr", "b.zarr"):
        st = Study.from_file(_study(folder, "model.toml", n=3))
        run_study(st, tmp_path / name, workers=0)
        stores.append(open_results(tmp_path / name))
    a, b = stores
    assert np.array_equal(a["mismatch"].values, b["mismatch"].values)
    assert np.all(np.isfinite(a["mismatch"].values))
    assert np.array_equal(a["hysteresis.k"].values, b["hysteresis.k"].values)
    assert json.loads(a.attrs["joint"])["keys"] == ["hysteresis.k", "hysteresis.fc"]
    from motionhyst.study.export import to_table

    # the table's columns of the draws in the order they are drawn
    assert to_table(a).startswith("frequency_hz,amplitude,sample,hysteresis.k,hysteresis.fc,")


def test_a_key_the_study_gives_keeps_its_distribution_and_the_rest_their_marginal(saved):
    folder, fit = saved
    st = Study.from_file(_study(folder, "model.toml",
                                '"hysteresis.k" = { lognormal = [20.0, 0.1] }\n'))
    assert st.samples == {"hysteresis.k": ("lognormal", 20.0, 0.1)}
    assert st.joint.keys == ("hysteresis.fc",)
    assert st.joint.covariance[0][0] == pytest.approx(fit["covariance"]["matrix"][1][1],
                                                      rel=1e-9)
    assert st.sampled_keys == ("hysteresis.k", "hysteresis.fc")


def test_large_errors_are_drawn_lognormal_with_the_same_moments():
    """Above LOG_SPACE_CV a normal draw could reach 0: the lognormal draws keep every value
    positive and have the stated means and covariance."""
    m = np.array([20.0, 0.05])
    s = np.array([0.4, 0.4]) * m
    cov = np.outer(s, s) * np.array([[1.0, 0.6], [0.6, 1.0]])
    d = JointNormal(("hysteresis.k", "hysteresis.fc"), tuple(m), tuple(map(tuple, cov)))
    assert d.log_space and 0.4 > LOG_SPACE_CV
    x = d.draw(np.random.default_rng(5), 200_000)
    assert np.all(x > 0)
    np.testing.assert_allclose(x.mean(axis=0), m, rtol=0.005)
    np.testing.assert_allclose(np.cov(x.T), cov, rtol=0.03)
    normal = JointNormal(d.keys, tuple(m), tuple(map(tuple, cov / 16)))  # 10 %: normal
    assert not normal.log_space
    y = normal.draw(np.random.default_rng(5), 200_000)
    assert np.all(y > 0)
    # the normal distribution's third moment is 0; the lognormal's is not
    z = (y - m) / np.sqrt(np.diag(cov / 16))
    assert abs(np.mean(z ** 3)) < 0.02


def test_bad_identifications_are_one_line(saved):
    folder, fit = saved
    with pytest.raises(StudyError, match=r"no \[identification\] table"):
        Study.from_file(_study(folder, "paper.toml"))
    two = {k: v for k, v in fit.items() if k != "covariance"}  # an older identify --json
    two["elements"] = fit["elements"] * 2
    (folder / "two.json").write_text(json.dumps(two))
    with pytest.raises(StudyError, match="2 Jenkins elements"):
        Study.from_file(_study(folder, "two.json"))
    undetermined = dict(fit, covariance={"parameters": ["k", "offset"], "matrix": [[1.0, 0.0],
                                                                                  [0.0, 1.0]]})
    (folder / "undetermined.json").write_text(json.dumps(undetermined))
    with pytest.raises(StudyError, match="fc: its standard error is not determined"):
        Study.from_file(_study(folder, "undetermined.json"))
    r = tomllib.loads((folder / "model.toml").read_text())["identification"]["correlation"]
    (folder / "asym.toml").write_text((folder / "model.toml").read_text().replace(
        f"[{r[1][0]!r}, 1.0]", "[0.1, 1.0]"))
    with pytest.raises(StudyError, match=r"\[identification\].*symmetric"):
        Study.from_file(_study(folder, "asym.toml"))
    (folder / "negative.toml").write_text('[identification]\nparameters = ["hysteresis.k"]\n'
                                          'estimates = [-1.0]\nstd = [0.1]\n'
                                          'correlation = [[1.0]]\n')
    with pytest.raises(StudyError, match=r"from_identification .*negative.toml: hysteresis.k = "
                                         r"-1: a parameter to draw must be a positive number"):
        Study.from_file(_study(folder, "negative.toml"))
    with pytest.raises(StudyError, match=r"'hysteresis.k' \(from_identification\): already "
                                         r"an axis"):
        Study.from_dict({"scenario": "paper.toml", "outputs": ["e1"],
                         "axes": {"hysteresis.k": [19.0, 21.0]},
                         "samples": {"n": 2, "seed": 0, "from_identification": "model.toml"}},
                        base_dir=folder)


def test_cli_runs_a_study_from_a_saved_identification(saved, tmp_path, capsys):
    folder, _ = saved
    bare = folder / "bare.toml"
    bare.write_text('scenario = "paper.toml"\noutputs = ["mismatch"]\n[axes]\n'
                    'frequency_hz = [5.0]\n')
    out = tmp_path / "s.zarr"
    assert main(["study", str(bare), "--from-identification", str(folder / "model.toml"),
                 "--out", str(out), "--workers", "0", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["points"] == 100 and report["failed"] == 0
    ds = open_results(out)
    assert ds["hysteresis.k"].dims == ds["hysteresis.fc"].dims == ("sample",)
    assert abs(np.median(ds["hysteresis.k"].values) - 20.0) < 0.1
    assert main(["study", "--summary", str(out)]) == 0
    assert ("100 samples of hysteresis.k, hysteresis.fc drawn jointly from "
            f"{folder / 'model.toml'} (normal, its covariance)") in capsys.readouterr().out


def test_the_example_study_draws_from_an_identification(saved):
    folder, _ = saved
    example = Path(__file__).resolve().parent.parent / "examples" / "study_identified.toml"
    st = Study.from_file(example, from_identification=folder / "model.toml")
    assert (st.n_samples, st.seed, st.n_points) == (100, 0, 3200)
    assert st.sampled_keys == ("hysteresis.k", "hysteresis.fc")


def test_a_maxwell_slip_link_is_drawn_element_by_element(tmp_path):
    """Several elements: their k and fc under the keys hysteresis.k[0], ..., the joint draws
    with the covariance of the identification (JSON and saved TOML alike)."""
    from motionhyst.hysteresis import MaxwellSlip
    from motionhyst.identify import identify_maxwell_slip

    t = np.arange(3000) / 1000.0
    env = np.concatenate([np.geomspace(0.012, 3e-4, 1500), np.geomspace(3e-4, 0.012, 1500)])
    x = env * np.sin(2 * np.pi * 3.0 * t)
    w = (MaxwellSlip(k=[10.0, 6.0, 4.0], fc=[0.01, 0.02, 0.03]).response(x)
         + 0.002 * np.random.default_rng(2).standard_normal(t.size))
    fit = identify_maxwell_slip(x, w, t=t, n_elements=3)
    (tmp_path / "ms.toml").write_text(fit.scenario_text())
    (tmp_path / "ms.json").write_text(json.dumps(fit.to_dict()))
    keys = tuple(f"hysteresis.{p}[{i}]" for p in ("k", "fc") for i in range(3))
    c = np.array(fit.covariance["matrix"])[:6, :6]
    for name in ("ms.toml", "ms.json"):
        d = joint_from_identification(tmp_path / name)
        assert d.keys == keys
        np.testing.assert_allclose(d.covariance, c, rtol=1e-9, atol=1e-9 * np.abs(c).max())
    shutil.copy(default_scenario_path(), tmp_path / "paper.toml")
    base = tomllib.loads((tmp_path / "paper.toml").read_text())
    base["hysteresis"] = {"model": "maxwell-slip", "k": [10.0, 6.0, 4.0],
                          "fc": [0.01, 0.02, 0.03]}
    st = Study.from_dict({"outputs": ["mismatch"], "axes": {"frequency_hz": [5.0]},
                          "samples": {"n": N_DRAWS, "seed": 1,
                                      "from_identification": "ms.toml"}},
                         base_dir=tmp_path, scenario=base)
    assert st.sampled_keys == keys
    _within_sampling_error(st.sample_values, [e[p] for p in ("k", "fc")
                                              for e in fit.elements], c)
    at = st.scenario_at(st.point(5))["hysteresis"]
    assert at["k"][2] == st.point(5)["hysteresis.k[2]"]
    with pytest.raises(StudyError, match=r"'hysteresis.k\[3\]'.*\[hysteresis\] k has 3 values"):
        Study.from_dict({"outputs": ["mismatch"], "axes": {"hysteresis.k[3]": [1.0]}},
                        scenario=base)


def test_the_local_pool_draws_and_computes_as_this_process(saved, tmp_path):
    """The pool's workers rebuild the study from its plain parameters (the joint distribution
    among them): the same draws and the same numbers as in this process, bit for bit."""
    folder, _ = saved
    st = Study.from_file(_study(folder, "model.toml", n=4))
    run_study(st, tmp_path / "here.zarr", workers=0)
    run_study(Study.from_file(_study(folder, "model.toml", n=4)), tmp_path / "pool.zarr",
              workers=2)
    here, pool = open_results(tmp_path / "here.zarr"), open_results(tmp_path / "pool.zarr")
    for name in ("mismatch", "status", "hysteresis.k", "hysteresis.fc"):
        np.testing.assert_array_equal(here[name].values, pool[name].values, err_msg=name)


def _bouc_wen_fit():
    """A Bouc-Wen link on a mass-spring-damper (alpha = 5e4 N/m, beta*gamma = 800,
    beta*delta = -1100 1/m, nu = 1) identified from a multisine record with 8 um of noise."""
    from motionhyst.hysteresis import BoucWen

    fs, n = 750.0, 1024
    rng = np.random.default_rng(2)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (fs / n)), int(150 / (fs / n)) + 1)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    u *= 50.0 / np.std(u)
    t = np.arange(n) / fs
    system = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4),
                      BoucWen.from_general(5e4, 1e3, 0.8, -1.1, 1.0))
    y = system.simulate(t, u, substeps=20).displacement + 8e-6 * rng.standard_normal(n)
    return identify_io([IORecord(t, u, y)], substeps=20)


BOUC_WEN_KEYS = ("hysteresis.alpha", "hysteresis.beta*gamma", "hysteresis.beta*delta")


@pytest.fixture(scope="module")
def bouc_wen(tmp_path_factory):
    """The Bouc-Wen identification, saved (model.toml), printed (fit.json), and its system
    in a loop (loop.toml: a PID around the identified stage)."""
    folder = tmp_path_factory.mktemp("bouc_wen")
    fit = _bouc_wen_fit()
    text = fit.scenario_text()
    (folder / "model.toml").write_text(text)
    (folder / "fit.json").write_text(json.dumps(fit.to_dict()))
    (folder / "loop.toml").write_text(
        text.split("[identification]")[0]
        + '[controller]\ntype = "pid"\nkp = 2e5\nki = 2e6\nkd = 600.0\n'
          'derivative_filter_hz = 500.0\n[reference]\namplitude = 1e-4\nfrequencies = [5.0]\n')
    return folder, fit


def _loop_study(folder: Path, n: int, **samples) -> Study:
    return Study.from_dict({"outputs": ["mismatch"], "axes": {"frequency_hz": [5.0]},
                            "samples": {"n": n, "seed": 1, "from_identification": "model.toml",
                                        **samples}},
                           base_dir=folder,
                           scenario=tomllib.loads((folder / "loop.toml").read_text()))


def test_a_bouc_wen_link_is_drawn_from_its_identified_products(bouc_wen):
    """beta alone is not identified: the covariance is of alpha and the products
    beta*gamma, beta*delta (of either sign), saved under hysteresis.beta*gamma, ...; a study
    draws them jointly and sets beta, gamma and delta of the link (|gamma| + |delta| = 1)
    whose products they are."""
    tmp_path, fit = bouc_wen
    cov = fit.to_dict()["covariance"]
    determined = [n for n, s in fit.std.items() if s is not None]
    assert cov["parameters"] == determined == ["m", "c", "k", "alpha", "beta*gamma",
                                               "beta*delta"]
    np.testing.assert_allclose(np.sqrt(np.diag(cov["matrix"])),
                               [fit.std[n] for n in determined], rtol=1e-9)
    text = fit.scenario_text()
    ident = tomllib.loads(text)["identification"]
    assert ident["parameters"] == ["stage.m", "stage.c", "stage.k", *BOUC_WEN_KEYS]
    c = np.array(cov["matrix"])[3:, 3:]
    mean = [fit.estimates[n] for n in ("alpha", "beta*gamma", "beta*delta")]
    assert mean[2] < 0
    for name in ("model.toml", "fit.json"):
        d = joint_from_identification(tmp_path / name)
        assert d.keys == BOUC_WEN_KEYS and not d.log_space
        np.testing.assert_allclose(d.covariance, c, rtol=1e-9, atol=1e-9 * np.abs(c).max())

    # the identified system in a loop: the study's scenario (the link alone drawn, as asked;
    # by default its stage's estimates are drawn with it: tests/test_study_honest.py)
    link_only = {"from_identification_tables": ["hysteresis"]}
    st = _loop_study(tmp_path, N_DRAWS, **link_only)
    assert st.sampled_keys == BOUC_WEN_KEYS
    _within_sampling_error(st.sample_values, mean, c)
    for i in (0, 7, 99):
        drawn = st.point(i)
        link = st.scenario_at(drawn)["hysteresis"]
        assert abs(link["gamma"]) + abs(link["delta"]) == pytest.approx(1.0, rel=1e-15)
        assert link["beta"] * link["gamma"] == pytest.approx(drawn["hysteresis.beta*gamma"],
                                                             rel=1e-14)
        assert link["beta"] * link["delta"] == pytest.approx(drawn["hysteresis.beta*delta"],
                                                             rel=1e-14)
        assert link["alpha"] == drawn["hysteresis.alpha"]
    # two machines of the fleet computed: their loops are built from the drawn links
    small = _loop_study(tmp_path, 2, **link_only)
    report = run_study(small, tmp_path / "bw.zarr", workers=0)
    assert (report.computed, report.failed) == (2, 0)
    ds = open_results(tmp_path / "bw.zarr")
    np.testing.assert_array_equal(ds["hysteresis.beta*delta"].values, small.sample_values[:, 2])
    m = ds["mismatch"].values.ravel()
    assert np.all(np.isfinite(m)) and m[0] != m[1]


def test_signed_products_and_the_bouc_wen_exponent_are_drawn_within_their_ranges():
    """A product keeps its sign freedom (normal, also beside lognormal positive keys, with
    the stated covariance); nu is drawn again below 1; a mean outside its range is refused."""
    m = np.array([5e4, -1100.0])
    s = np.array([0.4 * 5e4, 50.0])
    cov = np.outer(s, s) * np.array([[1.0, -0.5], [-0.5, 1.0]])
    d = JointNormal(("hysteresis.alpha", "hysteresis.beta*delta"), tuple(m),
                    tuple(map(tuple, cov)))
    assert d.log_space
    x = d.draw(np.random.default_rng(4), 200_000)
    assert np.all(x[:, 0] > 0)
    np.testing.assert_allclose(x.mean(axis=0), m, rtol=0.005)
    np.testing.assert_allclose(np.cov(x.T), cov, rtol=0.03)
    z = (x[:, 1] - m[1]) / s[1]
    assert abs(np.mean(z ** 3)) < 0.02        # the product stays normal
    nu = JointNormal(("hysteresis.nu",), (1.02,), ((0.02 ** 2,),))
    y = nu.draw(np.random.default_rng(0), 10_000)
    assert y.min() >= 1.0 and np.mean(y < 1.02) > 0.2
    with pytest.raises(ValueError, match=r"hysteresis.nu = 0.9: .* must be a number >= 1"):
        JointNormal(("hysteresis.nu",), (0.9,), ((0.01,),))
    with pytest.raises(ValueError, match=r"hysteresis.alpha = -1: .* must be a positive"):
        JointNormal(("hysteresis.alpha",), (-1.0,), ((0.01,),))


@pytest.mark.parametrize("source", ["model.toml", "fit.json"])
def test_the_identified_stage_is_drawn_with_its_link_when_asked(bouc_wen, source):
    """from_identification_tables = ["hysteresis", "stage"]: the study's scenario is the
    identified system, whose stage's estimates are drawn jointly with the link's."""
    folder, fit = bouc_wen
    st = _loop_study(folder, N_DRAWS, from_identification=source,
                     from_identification_tables=["hysteresis", "stage"])
    assert st.sampled_keys == ("stage.m", "stage.c", "stage.k", *BOUC_WEN_KEYS)
    names = ["m", "c", "k", "alpha", "beta*gamma", "beta*delta"]
    _within_sampling_error(st.sample_values, [fit.estimates[n] for n in names],
                           fit.to_dict()["covariance"]["matrix"])
    at = st.point(3)
    assert st.scenario_at(at)["stage"]["m"] == at["stage.m"]
    only = _loop_study(folder, 10, from_identification=source,
                       from_identification_tables=["stage"])
    assert only.sampled_keys == ("stage.m", "stage.c", "stage.k")
    for bad in (["controller"], [], "stage"):
        with pytest.raises(StudyError, match="'from_identification_tables': give a list"):
            _loop_study(folder, 10, from_identification_tables=bad)


@pytest.mark.parametrize("suffix", ["json", "toml"])
def test_an_identification_whose_names_the_scenario_lacks_is_refused_before_its_matrix(
        tmp_path, monkeypatch, suffix):
    """A 1000-element Maxwell-slip identification (2000 parameters, a 20 MB JSON) for the
    paper's Jenkins link was refused by the study's key check only after the covariance had
    been validated and factored (35-55 s): the names come first, the matrix is never read."""
    import motionhyst.study.identified as identified

    n = 200
    names = [f"{p}[{i}]" for p in ("k", "fc") for i in range(n)]
    if suffix == "json":
        text = json.dumps({"model": "maxwell-slip",
                           "elements": [{"k": 20.0, "fc": 0.05}] * n,
                           "covariance": {"parameters": names,
                                          "matrix": (1e-4 * np.eye(2 * n)).tolist()}})
    else:
        text = ("[identification]\nparameters = " + json.dumps([f"hysteresis.{m}"
                                                                for m in names])
                + "\nestimates = " + json.dumps([20.0] * n + [0.05] * n)
                + "\nstd = " + json.dumps([0.1] * (2 * n))
                + "\ncorrelation = " + json.dumps(np.eye(2 * n).tolist()) + "\n")
    (tmp_path / f"big.{suffix}").write_text(text)
    shutil.copy(default_scenario_path(), tmp_path / "paper.toml")

    def matrix_read(*args, **kwargs):
        raise AssertionError("the covariance was read before the names were checked")

    monkeypatch.setattr(identified, "JointNormal", matrix_read)
    study = {"scenario": "paper.toml", "outputs": ["mismatch"],
             "axes": {"frequency_hz": [5.0]},
             "samples": {"n": 10, "seed": 0, "from_identification": f"big.{suffix}"}}
    with pytest.raises(StudyError, match=r"\[samples\] 'hysteresis.k\[0\]': not a key of the "
                                         r"scenario .*\[hysteresis\] k has no list"):
        Study.from_dict(study, base_dir=tmp_path)
    # the study's own numbers come before the identification's matrix
    study["samples"]["seed"] = -1
    with pytest.raises(StudyError, match=r"\[samples\] 'seed': give a whole number >= 0"):
        Study.from_dict(study, base_dir=tmp_path)


def test_a_covariance_no_lognormal_has_is_refused_not_drawn_forever():
    """k 2000 +- 1e6 and fc 2 +- 10 with correlation -0.23 (an identification with standard
    errors far wider than its values, review B19 F15): ``log1p(C_kf / (m_k m_f))`` of a
    covariance below ``-m_k m_f`` is NaN, every draw was NaN and redrawn, and ``study
    --from-identification`` ran until killed (11 min); now one line saying why."""
    c = -2.33e6
    d = JointNormal(("hysteresis.k", "hysteresis.fc"), (2000.0, 2.0), ((1e12, c), (c, 100.0)),
                    "id.toml")
    assert d.log_space
    with pytest.raises(ValueError, match=r"^id\.toml: the covariance of hysteresis\.k and "
                                         r"hysteresis\.fc \(-2\.33e\+06\) is at or below minus "
                                         r"the product of their means \(2000 x 2\)"):
        d.draw(np.random.default_rng(0), 10)


def test_draws_outside_the_admitted_values_are_redrawn_a_bounded_number_of_times(monkeypatch):
    """A Bouc-Wen exponent nu = 1.05 +- 0.1 (normal draws: 0.095 relative) puts 31 % of its
    draws below its least value 1: redrawn until every draw is admitted, and refused once the
    rounds run out."""
    from motionhyst.study import identified

    d = JointNormal(("hysteresis.nu",), (1.05,), ((0.01,),))
    assert not d.log_space
    x = d.draw(np.random.default_rng(1), 20000)
    assert np.all(x >= 1.0)
    monkeypatch.setattr(identified, "MAX_REDRAWS", 0)
    with pytest.raises(ValueError, match=r"^\d+ of 20000 draws still have a parameter outside "
                                         r"its admitted values after 0 redraws"):
        d.draw(np.random.default_rng(1), 20000)
