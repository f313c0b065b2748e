"""Tests of the old module paths: each module that moved still imports, warning that it moved."""

from __future__ import annotations

import importlib
import sys
import warnings

import pytest

import motionhyst
from motionhyst import TwoMassStage, simulate
from motionhyst.controllers.leadlag import bandwidth


@pytest.fixture(autouse=True)
def _forget_old_paths():
    """Each test imports old paths afresh, and leaves the package as it found it."""
    before = dict(vars(motionhyst))
    yield
    for old in motionhyst._MOVED:
        sys.modules.pop(old, None)
        last = old.rpartition(".")[2]
        if last in before:
            setattr(motionhyst, last, before[last])
        elif last in vars(motionhyst):
            delattr(motionhyst, last)


@pytest.mark.parametrize("old", sorted(motionhyst._MOVED))
def test_an_old_path_imports_with_a_deprecation_warning_and_gives_the_same_objects(old):
    sys.modules.pop(old, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = importlib.import_module(old)
    assert [w.category for w in caught] == [DeprecationWarning]
    assert old in str(caught[0].message)
    targets = [importlib.import_module(t) for t in motionhyst._MOVED[old]]
    names = [n for t in targets for n in getattr(t, "__all__", ())]
    for name in names:
        owner = next(t for t in targets if hasattr(t, name))
        assert getattr(module, name) is getattr(owner, name)
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        module.no_such_name  # noqa: B018


def test_the_split_systems_module_finds_each_name_in_its_new_home():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from motionhyst.systems import TwoMassStage as old_stage
        from motionhyst.systems import bandwidth as old_bandwidth
    assert old_stage is TwoMassStage and old_bandwidth is bandwidth


def test_the_package_simulate_is_the_function_not_a_module():
    import motionhyst.time.simulation as module

    assert motionhyst.simulate is simulate is module.simulate


def test_the_old_simulate_module_path_still_calls_the_function():
    from motionhyst import SineReference, default_scenario

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from motionhyst.simulate import Simulation
    loop = default_scenario().loop()
    sim = motionhyst.simulate(loop, SineReference(0.01, 5.0), 0.02)
    assert isinstance(sim, Simulation)
    assert sim.e.tolist() == simulate(loop, SineReference(0.01, 5.0), 0.02).e.tolist()
