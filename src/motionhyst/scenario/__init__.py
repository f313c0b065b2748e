"""Scenario files: the TOML description of a loop or an open-loop system, read into model objects.

The reader and :class:`Scenario` are in :mod:`motionhyst.scenario.schema`, the tables' models
in :mod:`motionhyst.scenario.sections`; the paper's Table I is
``data/paper.toml`` here and the default everywhere (:func:`default_scenario`).
"""

from motionhyst.scenario.schema import (
    Scenario,
    ScenarioError,
    default_scenario,
    default_scenario_path,
    hysteresis_from_dict,
    load_scenario,
)

__all__ = [
    "Scenario",
    "ScenarioError",
    "default_scenario",
    "default_scenario_path",
    "hysteresis_from_dict",
    "load_scenario",
]
