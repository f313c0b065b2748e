"""The EMPS benchmark's parameters in the reference model's form: a model with friction by
direction or a drifting offset reported as the reference model's m, c, fc, OF (what the
benchmark publishes), with standard errors from its covariance, its own under model_parameters."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.identify.emps import run_emps
from motionhyst.identify.emps_reference import equivalent_offset, reference_form
from motionhyst.identify.input_output import IORecord
from motionhyst.identify.io_start import inverse_dynamics

PERIOD = 1000


def _record(n: int = 2001) -> IORecord:
    t = np.arange(n) / 1000.0
    return IORecord(t, np.zeros_like(t), 0.05 * np.sin(np.pi * t) + 0.01 * np.sin(7 * t), "r")


def test_standard_errors_are_those_of_the_map_sampled():
    """The delta method of the linear map against the spread of 200,000 draws of correlated
    estimates pushed through the same map: within 1 % (the sampling's own error is 0.2 %)."""
    rec = _record()
    own = {"m": 93.5, "c": 165.0, "fc": 20.4, "c_neg": 74.0, "offset": 0.1, "drift": -0.02,
           "k": 2e7}
    names = ["m", "c", "fc", "c_neg", "offset", "drift"]
    rng = np.random.default_rng(11)
    a = rng.standard_normal((6, 6)) * np.array([0.2, 2.0, 0.1, 3.0, 0.1, 0.005])
    cov = a @ a.T
    ref, ref_std = reference_form(own, rec, {n: float(np.sqrt(cov[i, i]))
                                             for i, n in enumerate(names)} | {"k": 1e5},
                                  {"parameters": names, "matrix": cov.tolist()})
    assert list(ref) == ["m", "c", "fc", "offset", "k"] and ref["k"] == 2e7
    draws = rng.multivariate_normal([own[n] for n in names], cov, 200_000)
    mapped = {"c": [], "offset": []}
    for row in draws[:2000]:  # the map is linear: its value on a few draws fixes it
        q, _ = reference_form(dict(zip(names, row, strict=True)), rec)
        mapped["c"].append(q["c"])
        mapped["offset"].append(q["offset"])
    basis = np.column_stack([draws[:2000], np.ones(2000)])
    for key in ("c", "offset"):
        coef = np.linalg.lstsq(basis, np.array(mapped[key]), rcond=None)[0]
        sampled = np.std(np.column_stack([draws, np.ones(len(draws))]) @ coef)
        assert ref_std[key] == pytest.approx(sampled, rel=0.01), key
    assert ref["c"] == pytest.approx(165.0 + 37.0)
    assert ref["offset"] == pytest.approx(equivalent_offset(own, rec))
    assert ref_std["m"] == pytest.approx(np.sqrt(cov[0, 0]))


def test_an_undetermined_parameter_leaves_what_it_enters_undetermined():
    rec = _record()
    own = {"m": 95.0, "c": 200.0, "fc": 20.0, "c_neg": 0.0, "offset": -3.0}
    std = {"m": 0.1, "c": 1.0, "fc": 0.1, "c_neg": None, "offset": 0.05}
    ref, ref_std = reference_form(own, rec, std)
    assert ref_std["m"] == 0.1 and ref_std["fc"] == 0.1
    assert ref_std["c"] is None and ref_std["offset"] is None  # c_neg enters both
    assert ref["c"] == 200.0 and ref["offset"] == -3.0


def test_a_maxwell_slip_links_slip_forces_together_are_its_coulomb_force():
    own = {"m": 94.0, "c": 200.0, "k[0]": 1e6, "k[1]": 3e6, "fc[0]": 12.0, "fc[1]": 9.0,
           "offset": -3.1}
    std = {"m": 0.1, "c": 1.0, "k[0]": 1e4, "k[1]": 3e4, "fc[0]": 0.3, "fc[1]": 0.4,
           "offset": 0.02}
    ref, ref_std = reference_form(own, _record(), std)
    assert ref == {"m": 94.0, "c": 200.0, "fc": 21.0, "offset": -3.1, "k[0]": 1e6, "k[1]": 3e6}
    assert ref_std["fc"] == pytest.approx(0.5) and ref_std["k[1]"] == 3e4


def test_benchmark_lists_an_asymmetric_model_as_the_reference_sees_it():
    """An axis whose viscous friction is larger backward, with no force offset (EMPS's, as
    the benchmark's eq. 12 describes it), moved alike both ways as a loop moves it: the
    Coulomb link with viscous friction by direction finds it (its own offset about 0, under
    model_parameters), and its `parameters` are what the symmetric reference model fitted
    to the same record holds (IDIM-LS: the direction-dependent viscous force as an offset),
    with standard errors."""
    t = np.arange(4 * PERIOD) / 1000.0
    y = 0.03 * np.sin(2 * np.pi * t) + 0.01 * np.sin(6 * np.pi * t)
    v = np.gradient(y, t, edge_order=2)
    a = np.gradient(v, t, edge_order=2)
    u = 95.0 * a + 160.0 * v + 80.0 * np.minimum(v, 0.0) + 20.0 * np.sign(v)
    rec = IORecord(t, u, y + 1e-6 * np.random.default_rng(5).standard_normal(t.size), "axis")
    res = run_emps(rec, models=("coulomb-asymmetric",), period=PERIOD)
    (model,) = res.models
    own, ref = model.model_parameters, model.parameters
    assert own["offset"] == pytest.approx(0.0, abs=0.3)
    assert own["c"] + own.get("c_pos", 0.0) == pytest.approx(160.0, rel=0.03)
    assert own["c"] + own.get("c_neg", 0.0) == pytest.approx(240.0, rel=0.03)
    symmetric = inverse_dynamics([res.estimation_record], floating=True)
    assert symmetric["u0"] < -2.0
    assert ref["offset"] == pytest.approx(symmetric["u0"], abs=0.3)
    assert ref["c"] == pytest.approx(symmetric["c"], rel=0.03)
    assert ref["m"] == pytest.approx(95.0, rel=0.02) and ref["fc"] == pytest.approx(20.0, rel=0.05)
    assert all(s is not None and 0 < s < 0.05 * abs(ref[k]) for k, s in model.std.items()
               if k != "offset")
    assert 0 < model.std["offset"] < 0.3
    out = model.to_dict()
    assert out["parameters"]["offset"] == out["equivalent_offset"] == ref["offset"]
    assert out["model_parameters"] == own and set(out["model_std"]) == set(own)
