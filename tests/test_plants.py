"""The plant registry and the contract every registered plant keeps (as scikit-learn's
check_estimator does for estimators): a new plant registered is checked here without a new
test."""

import math

import numpy as np
import pytest

from motionhyst.plants.registry import PLANTS, Plant, PlantParameter, plant_class, stage_types

# a value inside each kind's range, chosen so that no two parameters are equal
_TYPICAL = {"positive": (3.0, 5.0, 7.0, 2.0e4, 11.0), "nonnegative": (0.7, 0.9, 1.3),
            "finite": (-0.4, 0.25, 0.15)}


def _kwargs(cls) -> dict:
    used = {kind: iter(values) for kind, values in _TYPICAL.items()}
    return {p.name: next(used[p.kind]) for p in cls.parameters}


def _from_data() -> dict:
    """The plants that are not built from parameters: a fit's model, measured data, systems."""
    import control

    from motionhyst.plants import MeasuredPlant, ModalPlant, Mode, TransferPlant, TwoMassStage

    stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    omega = 2 * np.pi * np.geomspace(1.0, 2000.0, 40)
    return {
        "modal": ModalPlant(22.5, [Mode(694.0, 0.003, 0.15, 1 / 22.5),
                                   Mode(1500.0, 0.01, 0.05, 0.01)]),
        "frd": MeasuredPlant(control.frd(stage.P1, omega), control.frd(stage.P2, omega), 22.5),
        "transfer-functions": TransferPlant(stage.P1, stage.P2, stage.M),
    }


def _examples():
    """One instance of every registered plant (built from its parameters, or from data)."""
    data = _from_data()
    out = {}
    for name in PLANTS:
        cls = plant_class(name)
        out[name] = cls(**_kwargs(cls)) if cls.parameters else data[name]
    return out


EXAMPLES = _examples()
F = np.array([0.5, 3.0, 40.0, 700.0])


def _freqresp(sys, f):
    from motionhyst.core.lti import freqresp

    return freqresp(sys, 2 * np.pi * np.asarray(f, dtype=float))


@pytest.mark.parametrize("name", list(PLANTS))
def test_follows_the_protocol(name):
    plant = EXAMPLES[name]
    assert isinstance(plant, Plant)
    assert type(plant).name == name and plant_class(name) is type(plant)
    names = [p.name for p in plant.parameters]
    assert len(set(names)) == len(names)
    assert all(isinstance(p, PlantParameter) for p in plant.parameters)
    assert set(plant.PARAMETERS) <= set(names)
    assert plant.output in plant.outputs
    assert plant.M > 0 or not plant.has_inertia
    assert math.isfinite(plant.force_offset)
    assert (plant.frequency_range_hz is None) == plant.is_lti


@pytest.mark.parametrize("name", [n for n in PLANTS if PLANTS[n].parameters])
def test_parameters_are_checked_and_round_trip(name):
    cls = PLANTS[name]
    kwargs = _kwargs(cls)
    plant = cls(**kwargs)
    table = plant.to_dict()
    assert table.get("type", "two-mass") == name       # the default [stage] type may be left out
    again = cls(**{k: v for k, v in table.items() if k != "type"})
    assert again.to_dict() == table
    for p in cls.parameters:
        if p.required:
            with pytest.raises(TypeError):
                cls(**{k: v for k, v in kwargs.items() if k != p.name})
        bad = {"positive": 0.0, "nonnegative": -1.0, "finite": math.nan}[p.kind]
        with pytest.raises(ValueError, match=rf"^{p.name} must be finite"):
            cls(**{**kwargs, p.name: bad})
        with pytest.raises(ValueError, match=rf"^{p.name} must be a number"):
            cls(**{**kwargs, p.name: "1"})
    assert plant.with_parameters(plant.values()).to_dict() == table
    assert plant.force_offset == kwargs["force_offset"]


@pytest.mark.parametrize("name", list(PLANTS))
def test_transfers_agree(name):
    """Pf2 is Pr - P2; Pf2(0) is the static value eq. (21) uses (or None)."""
    plant = EXAMPLES[name]
    f = F if plant.frequency_range_hz is None else np.asarray(plant.P2.omega) / (2 * np.pi)
    P2 = _freqresp(plant.P2, f)
    if plant.Pf2 is not None:
        Pr = 1.0 / (plant.M * (2j * np.pi * f) ** 2)
        np.testing.assert_allclose(_freqresp(plant.Pf2, f), Pr - P2, rtol=1e-7,
                                   atol=1e-9 * np.max(np.abs(Pr)))
    if plant.pf2_static is not None:
        assert plant.pf2_static > 0
        low = _freqresp(plant.Pf2, [1e-6])[0]
        assert plant.pf2_static == pytest.approx(low.real, rel=1e-6)


@pytest.mark.parametrize("name", [n for n in PLANTS if PLANTS[n].PARAMETERS
                                  and PLANTS[n].has_inertia])
def test_state_space_realises_the_transfers(name):
    """mechanics() is the plant: its response is P1 (P2) for the output y1 (y2), the force
    offset rides along, and its derivatives are those of its matrices (they are linear in the
    parameters)."""
    plant = EXAMPLES[name]
    mech = plant.mechanics()
    assert mech.force_offset == plant.force_offset
    G = mech.frequency_response(F)
    np.testing.assert_allclose(plant.frequency_response(F), G, rtol=1e-9)
    P = plant.P1 if mech.output == mech.link else plant.P2
    np.testing.assert_allclose(_freqresp(P, F), G, rtol=1e-9)
    # with the link a spring and damper on its coordinate
    np.testing.assert_allclose(plant.frequency_response(F, 50.0, 0.3),
                               mech.frequency_response(F, 50.0, 0.3), rtol=1e-9)
    v = plant.values()
    assert mech.dmass.shape[0] == len(plant.PARAMETERS) == v.size
    for i in range(v.size):
        step = np.zeros(v.size)
        step[i] = 0.5 * v[i] + 1.0
        hi = plant.mechanics(v + step)
        np.testing.assert_allclose(hi.mass - mech.mass, mech.dmass[i] * step[i], atol=1e-12)
        np.testing.assert_allclose(hi.C - mech.C, mech.dC[i] * step[i], atol=1e-9)
        np.testing.assert_allclose(hi.K - mech.K, mech.dK[i] * step[i], rtol=1e-12,
                                   atol=1e-9)
    again = plant.with_parameters(v * 1.5).mechanics()
    np.testing.assert_allclose(again.K, plant.mechanics(v * 1.5).K)


def test_unknown_plant_is_one_line():
    with pytest.raises(ValueError, match=r"^unknown plant 'spring'; known: .*mass-damper"):
        plant_class("spring")


def test_stage_types_are_the_plants_built_from_parameters():
    assert "mass-damper" in stage_types()
    assert all(PLANTS[n].parameters for n in stage_types())


def test_mass_damper_is_a_floating_mass_with_viscous_friction():
    from motionhyst.plants.mass_damper import MassDamper

    axis = MassDamper(m=95.1, c=203.5)
    s = 2j * np.pi * F
    np.testing.assert_allclose(axis.frequency_response(F), 1 / (95.1 * s * s + 203.5 * s))
    mech = axis.mechanics()
    assert mech.floating and mech.n == 1
    A, B = mech.state_space()
    # the velocity's pole is -c/m, the position's 0: a constant force ends in v = F / c
    assert sorted(np.linalg.eigvals(A).real) == pytest.approx([-203.5 / 95.1, 0.0])
    assert B.tolist() == [0.0, 1 / 95.1]
    assert math.isinf(mech.decay_time())                  # the position never settles
    assert axis.pf2_static is None


def test_mass_damper_without_damping_is_a_free_mass():
    from motionhyst.plants.mass_damper import MassDamper

    free = MassDamper(m=2.0, c=0.0)
    assert free.corner_hz == 0.0
    np.testing.assert_allclose(free.frequency_response(F), -1 / (2.0 * (2 * np.pi * F) ** 2))


def test_mass_damper_runs_in_the_time_engine_with_its_force_offset():
    """From rest under a constant force F: y = F/c (t - m/c (1 - exp(-c t / m))); the force
    offset is that force."""
    from motionhyst.hysteresis import Jenkins
    from motionhyst.plants.mass_damper import MassDamper
    from motionhyst.time.openloop import OpenLoop

    m, c, F = 2.0, 10.0, 5.0
    t = np.arange(400) / 1000.0
    pushed = OpenLoop(MassDamper(m, c), None).simulate(t, np.full(t.size, F)).displacement
    exact = F / c * (t - m / c * (1 - np.exp(-c * t / m)))
    np.testing.assert_allclose(pushed, exact, rtol=1e-8, atol=1e-12)
    offset = OpenLoop(MassDamper(m, c, force_offset=F), None).simulate(t, np.zeros(t.size))
    np.testing.assert_allclose(offset.displacement, pushed, rtol=1e-12, atol=1e-15)
    # with a link (exact-update elements) the offset is the same as the force again
    link = Jenkins(k=50.0, fc=2.0)
    a = OpenLoop(MassDamper(m, c, force_offset=F), link).simulate(t, np.sin(20 * t))
    b = OpenLoop(MassDamper(m, c), link).simulate(t, np.sin(20 * t) + F)
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=1e-12, atol=1e-15)
    from motionhyst.hysteresis import BoucWen

    bw = BoucWen(k=50.0, fc=2.0, beta=0.6, gamma=0.2)
    a = OpenLoop(MassDamper(m, c, force_offset=F), bw).simulate(t, np.sin(20 * t))
    b = OpenLoop(MassDamper(m, c), bw).simulate(t, np.sin(20 * t) + F)
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=1e-9, atol=1e-15)


def test_a_scenario_may_describe_only_a_plant():
    from motionhyst.scenario import Scenario, ScenarioError

    two = Scenario.from_dict({"stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}})
    assert two.plant().to_dict() == {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7}
    assert two.hysteresis() is None and not two.is_open_loop
    with pytest.raises(ScenarioError, match=r"describes only a plant .*needs a closed loop"):
        two.loop()
    axis = Scenario.from_dict({"stage": {"type": "mass-damper", "m": 95.1, "c": 203.5,
                                         "force_offset": 3.16}})
    assert axis.is_open_loop and axis.open_loop().hysteresis is None
    assert axis.plant().force_offset == 3.16
    with pytest.raises(ScenarioError, match=r"\[hysteresis\]: missing"):
        Scenario.from_dict({"stage": {"m1": 5.0, "m2": 17.5, "b": 90.0, "k": 7.4e7},
                            "controller": {"type": "tf", "num": [1.0], "den": [1.0]},
                            "reference": {"amplitude": 0.01, "frequencies": [5.0]}})


@pytest.mark.parametrize("name", [n for n in PLANTS if PLANTS[n].parameters])
def test_every_stage_type_reads_from_a_scenario(name):
    """The [stage] table of every plant built from parameters is its to_dict()."""
    from motionhyst.scenario import Scenario, ScenarioError

    plant = PLANTS[name](**_kwargs(PLANTS[name]))
    sc = Scenario.from_dict({"stage": plant.to_dict()})
    assert sc.plant().to_dict() == plant.to_dict()
    with pytest.raises(ScenarioError, match=r"^<dict>: \[stage\] nonsense: unknown key$"):
        Scenario.from_dict({"stage": {**plant.to_dict(), "nonsense": 1.0}})


def test_eq21_says_why_it_does_not_apply_instead_of_nan():
    """A plant without a static flexible compliance (ground dampers, a single mass, bare
    transfer functions) has no eq. (21) estimate: the analysis says so by name."""
    from motionhyst import Jenkins, LeadLagLowpass, Loop, analyze
    from motionhyst.plants import MassDamper, TwoMassStage

    C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
    link = Jenkins(k=20.0, fc=0.05)
    paper = analyze(Loop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7), C, link), 0.01, [5.0])
    assert math.isfinite(paper.mismatch_crossover_hz)
    assert not any("eq. (21)" in u for u in paper.unresolved)
    stage = TwoMassStage(5.0, 17.5, 90.0, 7.4e7)
    for plant in (TwoMassStage(5.0, 17.5, 90.0, 7.4e7, c1=50.0), MassDamper(22.5, 50.0),
                  (stage.P1, stage.P2)):
        res = analyze(Loop(plant, C, link, mass=22.5), 0.01, [5.0])
        assert math.isnan(res.mismatch_crossover_hz)
        assert any(u.startswith("eq. (21): needs a flexible mode") for u in res.unresolved)
        assert math.isfinite(res.mismatch_crossover_exact_hz)  # eq. (18) itself still solves
