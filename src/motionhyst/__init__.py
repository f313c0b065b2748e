"""motionhyst: hysteresis of dynamic links in high-precision motion control.

Model the hysteresis (:class:`Jenkins`, :class:`MaxwellSlip`, :class:`BoucWen`,
:class:`Dahl`, :class:`LuGre`, :class:`MaxwellIwan`), predict its effect on tracking with
describing functions (:func:`analyze`), and check the prediction against the
exact periodic steady state of the nonlinear loop (:func:`periodic_steady_state`).

The names below are imported from their modules on first use (PEP 562), so
``import motionhyst`` stays light and the command line starts quickly;
``from motionhyst import Loop`` works as usual.

Examples
--------
>>> import motionhyst
>>> motionhyst.Jenkins(k=20.0, fc=0.05).initial_stiffness
20.0
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING

__version__ = "0.1.0"

_EXPORTS = {
    "motionhyst.frf_fit": ("FrfFit", "ModalPlant", "fit_frf"),
    "motionhyst.comparison": ("DescribingFunctionComparison", "compare_with_describing_function"),
    "motionhyst.hysteresis": ("BoucWen", "Dahl", "Hysteresis", "Jenkins", "LuGre", "MaxwellIwan",
                              "MaxwellSlip"),
    "motionhyst.margins": ("LoopMargins", "loop_margins"),
    "motionhyst.loop": ("Loop",),
    "motionhyst.quasilinear": ("QuasiLinearAnalysis", "analyze"),
    "motionhyst.references": ("PointToPoint", "SampledReference", "SineReference",
                              "load_reference_csv"),
    "motionhyst.scenario": ("Scenario", "ScenarioError", "default_scenario", "load_scenario"),
    "motionhyst.simulate": ("Simulation", "simulate"),
    "motionhyst.steady": ("SteadyState", "periodic_steady_state", "steady_state_sweep"),
    "motionhyst.systems": ("LeadLagLowpass", "MeasuredPlant", "TwoMassStage", "load_frd_plant"),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = [
    "BoucWen", "Dahl", "DescribingFunctionComparison", "FrfFit", "Hysteresis", "Jenkins",
    "LeadLagLowpass", "Loop", "LoopMargins", "LuGre", "MaxwellIwan", "MaxwellSlip",
    "MeasuredPlant", "ModalPlant", "PointToPoint",
    "QuasiLinearAnalysis", "SampledReference", "Scenario", "ScenarioError", "Simulation",
    "SineReference", "SteadyState", "TwoMassStage", "analyze", "compare_with_describing_function",
    "default_scenario", "fit_frf", "load_frd_plant", "load_reference_csv", "load_scenario",
    "loop_margins",
    "periodic_steady_state", "simulate", "steady_state_sweep",
]

if TYPE_CHECKING:
    from motionhyst.comparison import DescribingFunctionComparison, compare_with_describing_function
    from motionhyst.frf_fit import FrfFit, ModalPlant, fit_frf
    from motionhyst.hysteresis import (
        BoucWen,
        Dahl,
        Hysteresis,
        Jenkins,
        LuGre,
        MaxwellIwan,
        MaxwellSlip,
    )
    from motionhyst.loop import Loop
    from motionhyst.margins import LoopMargins, loop_margins
    from motionhyst.quasilinear import QuasiLinearAnalysis, analyze
    from motionhyst.references import (
        PointToPoint,
        SampledReference,
        SineReference,
        load_reference_csv,
    )
    from motionhyst.scenario import Scenario, ScenarioError, default_scenario, load_scenario
    from motionhyst.simulate import Simulation, simulate
    from motionhyst.steady import SteadyState, periodic_steady_state, steady_state_sweep
    from motionhyst.systems import LeadLagLowpass, MeasuredPlant, TwoMassStage, load_frd_plant


def __getattr__(name: str):
    """Import an exported name from its module on first access (PEP 562)."""
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """The package's module type: an export named like its own submodule stays the export.

    Importing ``motionhyst.simulate`` (the module) sets the package attribute
    ``simulate``; here it is set to the function ``simulate.simulate`` the
    package exports instead, in whatever order the two are imported.
    """

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and _WHERE.get(name) == value.__name__:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
