"""The EMPS benchmark's Jenkins link and its rigid limit: a stiffness whose stuck mode the
record cannot resolve (above a quarter of the sampling rate, or not determined) is reported
as the Coulomb link with the same options; a stiffness the record shows is kept."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import Coulomb, Jenkins
from motionhyst.identify.emps import run_emps
from motionhyst.identify.emps_models import unresolved_stiffness
from motionhyst.identify.input_output import IORecord
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

PERIOD = 1000


def _axis(link, n_periods: int = 2, c_skew: float = 0.0) -> IORecord:
    """A mass-damper with the link and a force offset, driven by a force, 1 kHz."""
    t = np.arange(n_periods * PERIOD) / 1000.0
    u = 150 * np.sin(2 * np.pi * t) + 60 * np.sin(6 * np.pi * t)
    axis = OpenLoop(MassDamper(95.0, 200.0, c_skew, force_offset=3.2), link)
    y = axis.simulate(t, u, substeps=40).displacement
    return IORecord(t, u, y + 1e-6 * np.random.default_rng(2).standard_normal(t.size), "axis")


def test_a_stiffness_the_record_cannot_resolve_is_the_rigid_limit():
    """A Coulomb axis: the Jenkins link's fitted stiffness is the search's (a stuck mode
    beyond 250 Hz at 1 kHz, or undetermined); reported as the Coulomb fit, which is reused."""
    res = run_emps(_axis(Coulomb(fc=20.0)), models=("coulomb", "jenkins"), periods=(1, 1),
                   period=PERIOD)
    coulomb, jenkins = res.models
    assert jenkins.limit == "coulomb" and coulomb.limit is None
    assert jenkins.parameters == coulomb.parameters
    assert jenkins.parameters["m"] == pytest.approx(95.0, rel=0.01)
    assert "rigid limit" in jenkins.warnings[0]
    assert "stuck mode" in jenkins.warnings[0] or "not determined" in jenkins.warnings[0]
    assert jenkins.to_dict()["warnings"] == jenkins.warnings  # the JSON says it too
    assert "warnings" not in coulomb.to_dict()


def test_a_stiffness_the_record_shows_is_kept():
    """A Jenkins axis whose stuck mode is at 23 Hz: the link keeps its stiffness."""
    res = run_emps(_axis(Jenkins(k=2e6, fc=20.0)), models=("jenkins",), periods=(1, 1),
                   period=PERIOD)
    (model,) = res.models
    assert model.limit is None
    assert model.model_parameters["k"] == pytest.approx(2e6, rel=0.1)
    assert model.parameters["k"] == model.model_parameters["k"]
    assert unresolved_stiffness("jenkins", model.model_parameters, model.model_std,
                                1000.0) is None


def test_the_rule_in_numbers():
    own = {"m": 95.0, "k": 95.0 * (2 * np.pi * 240.0) ** 2}  # stuck mode at 240 Hz: resolved
    assert unresolved_stiffness("jenkins", own, {"k": 1.0}, 1000.0) is None
    assert "260 Hz" in unresolved_stiffness("jenkins-drift", {"m": 95.0, "k": own["k"] * (
        260.0 / 240.0) ** 2}, {"k": 1.0}, 1000.0)
    assert unresolved_stiffness("jenkins", own, {"k": 1.0}, 900.0) is not None  # 225 Hz limit
    assert unresolved_stiffness("maxwell-slip", own, {"k": None}, 1000.0) is None  # not Jenkins
    assert unresolved_stiffness("coulomb", {"m": 95.0, "fc": 20.0}, {}, 1000.0) is None


def test_the_coulomb_fit_is_reused_as_the_friction_links_start():
    """A Jenkins fit started from a Coulomb fit made already (as the benchmark reuses its
    ``coulomb-asymmetric`` fit for ``jenkins-asymmetric``) finds exactly what it finds when it
    fits that start itself (the same fit: a cache, not another start), with fewer evaluations;
    a Coulomb fit of other options is refused."""
    from motionhyst.identify.input_output import identify_io

    rec = _axis(Jenkins(k=2e6, fc=20.0), c_skew=-35.0)  # EMPS: faster backward
    options = {"plant": "mass-damper", "init_window": 20, "asymmetric": True}
    coulomb = identify_io([rec], "coulomb", **options)
    alone = identify_io([rec], "jenkins", **options)
    reused = identify_io([rec], "jenkins", rigid=coulomb, **options)
    for name in ("m", "c", "c_skew", "link.k", "link.fc", "input_offset"):
        assert reused.estimates[name] == alone.estimates[name], name
    assert reused.n_evaluations < alone.n_evaluations
    with pytest.raises(ValueError, match="other options"):
        identify_io([rec], "jenkins", plant="mass-damper", init_window=20, asymmetric=False,
                    rigid=coulomb)


def test_the_rigid_limit_a_friction_link_starts_from_is_identify_ios_coulomb_fit():
    """The Coulomb fit a Jenkins link on a mass-damper starts from when none is given (with
    viscous friction by direction) is the fit ``identify_io(..., "coulomb")`` makes with the same
    options, bit for bit: the link's ``c_pos``/``c_neg`` on the stage's smaller ``c``, not the
    stage's ``c_skew`` (a Coulomb start spelled that way followed another search path, and the
    benchmark's ``jenkins-asymmetric`` depended on whether ``coulomb-asymmetric`` ran before)."""
    from motionhyst.identify.input_output import identify_io

    rec = _axis(Jenkins(k=2e6, fc=20.0), c_skew=-35.0)
    options = {"plant": "mass-damper", "init_window": 20, "asymmetric": True}
    coulomb = identify_io([rec], "coulomb", **options)
    seed = identify_io([rec], "jenkins", **options).rigid_limit
    assert seed is not None and seed.estimates == coulomb.estimates
    # more viscous friction backward (c_skew < 0): the link's c_neg holds the excess
    assert seed.hysteresis.c_neg == coulomb.hysteresis.c_neg > 0
    assert seed.hysteresis.c_pos == coulomb.hysteresis.c_pos == 0.0


def test_the_benchmarks_jenkins_fit_does_not_depend_on_the_models_listed():
    """``jenkins-asymmetric`` alone, or after ``coulomb-asymmetric`` (whose fit it reuses as its
    start), or after another Coulomb model: the same parameters and scores."""
    rec = _axis(Jenkins(k=2e6, fc=20.0), c_skew=-35.0)
    runs = [run_emps(rec, models=models, periods=(1, 1), period=PERIOD).models[-1]
            for models in (("jenkins-asymmetric",), ("coulomb-asymmetric", "jenkins-asymmetric"),
                           ("coulomb", "jenkins-asymmetric"))]
    for model in runs[1:]:
        assert model.model_parameters == runs[0].model_parameters
        assert model.validation["rmse_mm"] == runs[0].validation["rmse_mm"]
