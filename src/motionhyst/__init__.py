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
import importlib.machinery
import sys
import types
import warnings

from motionhyst.core.exports import lazy_exports

TYPE_CHECKING = False  # typing's, without typing (see motionhyst.core.exports)

__version__ = "0.1.0"

_EXPORTS = {
    "motionhyst.plants.frf_fit": ("FrfFit", "ModalPlant", "fit_frf"),
    "motionhyst.analysis.comparison": ("DescribingFunctionComparison",
                                       "compare_with_describing_function"),
    "motionhyst.analysis.describing": ("DescribingFunctionResult", "describing_function"),
    "motionhyst.core.warnings": ("MotionhystWarning",),
    "motionhyst.hysteresis": ("BoucWen", "Dahl", "Hysteresis", "Jenkins", "LuGre", "MaxwellIwan",
                              "MaxwellSlip"),
    "motionhyst.analysis.margins": ("LoopMargins", "loop_margins"),
    "motionhyst.controllers.loop": ("Loop",),
    "motionhyst.analysis.quasilinear": ("QuasiLinearAnalysis", "analyze"),
    "motionhyst.time.references": ("PointToPoint", "SampledReference", "SineReference",
                              "load_reference_csv"),
    "motionhyst.scenario": ("Scenario", "ScenarioError", "default_scenario", "load_scenario"),
    "motionhyst.time.simulation": ("Simulation", "simulate"),
    "motionhyst.analysis.steady": ("SteadyState", "periodic_steady_state", "steady_state_sweep"),
    "motionhyst.analysis.stability": ("StabilityResult", "stability"),
    "motionhyst.controllers.leadlag": ("LeadLagLowpass",),
    "motionhyst.plants.measured": ("MeasuredPlant", "load_frd_plant"),
    "motionhyst.plants.two_mass": ("TwoMassStage",),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = [
    "BoucWen", "Dahl", "DescribingFunctionComparison", "DescribingFunctionResult", "FrfFit",
    "Hysteresis", "Jenkins", "LeadLagLowpass", "Loop", "LoopMargins", "LuGre", "MaxwellIwan",
    "MaxwellSlip", "MeasuredPlant", "ModalPlant", "MotionhystWarning", "PointToPoint",
    "QuasiLinearAnalysis", "SampledReference", "Scenario", "ScenarioError", "Simulation",
    "SineReference", "StabilityResult", "SteadyState", "TwoMassStage", "analyze",
    "compare_with_describing_function",
    "default_scenario", "describing_function", "fit_frf", "load_frd_plant", "load_reference_csv",
    "load_scenario", "loop_margins",
    "periodic_steady_state", "simulate", "stability", "steady_state_sweep",
]

if TYPE_CHECKING:
    from motionhyst.analysis.comparison import (
        DescribingFunctionComparison,
        compare_with_describing_function,
    )
    from motionhyst.analysis.describing import DescribingFunctionResult, describing_function
    from motionhyst.analysis.margins import LoopMargins, loop_margins
    from motionhyst.analysis.quasilinear import QuasiLinearAnalysis, analyze
    from motionhyst.analysis.stability import StabilityResult, stability
    from motionhyst.analysis.steady import SteadyState, periodic_steady_state, steady_state_sweep
    from motionhyst.controllers.leadlag import LeadLagLowpass
    from motionhyst.controllers.loop import Loop
    from motionhyst.core.warnings import MotionhystWarning
    from motionhyst.hysteresis import (
        BoucWen,
        Dahl,
        Hysteresis,
        Jenkins,
        LuGre,
        MaxwellIwan,
        MaxwellSlip,
    )
    from motionhyst.plants.frf_fit import FrfFit, ModalPlant, fit_frf
    from motionhyst.plants.measured import MeasuredPlant, load_frd_plant
    from motionhyst.plants.two_mass import TwoMassStage
    from motionhyst.scenario import Scenario, ScenarioError, default_scenario, load_scenario
    from motionhyst.time.references import (
        PointToPoint,
        SampledReference,
        SineReference,
        load_reference_csv,
    )
    from motionhyst.time.simulation import Simulation, simulate


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)


# Modules that moved in 0.2 (one subpackage per part of the architecture). Their old
# dotted paths still import, with a DeprecationWarning, until the next release.
_MOVED = {
    "motionhyst._jit": ("motionhyst.core.compiled",),
    "motionhyst.validation": ("motionhyst.core.validation",),
    "motionhyst.lti": ("motionhyst.core.lti",),
    "motionhyst.textfmt": ("motionhyst.core.textfmt",),
    "motionhyst.jsonio": ("motionhyst.core.jsonio",),
    "motionhyst.systems": ("motionhyst.plants.two_mass", "motionhyst.plants.measured",
                           "motionhyst.controllers.leadlag", "motionhyst.core.lti"),
    "motionhyst.frf_fit": ("motionhyst.plants.frf_fit",),
    "motionhyst.quasilinear": ("motionhyst.analysis.quasilinear",),
    "motionhyst.margins": ("motionhyst.analysis.margins",),
    "motionhyst.steady": ("motionhyst.analysis.steady",),
    "motionhyst.comparison": ("motionhyst.analysis.comparison",),
    "motionhyst.simulate": ("motionhyst.time.simulation",),
    "motionhyst.openloop": ("motionhyst.time.openloop",),
    "motionhyst.loop": ("motionhyst.controllers.loop",),
    "motionhyst.timeseries": ("motionhyst.time.timeseries",),
    "motionhyst.references": ("motionhyst.time.references",),
    "motionhyst.ilc": ("motionhyst.scan.ilc",),
    "motionhyst.profiles": ("motionhyst.scan.profiles",),
    "motionhyst.benchmark": ("motionhyst.identify.benchmark",),
    "motionhyst.csvdata": ("motionhyst.io.csvdata",),
    "motionhyst.outputs": ("motionhyst.io.outputs",),
    "motionhyst.figures": ("motionhyst.present.figures",),
    "motionhyst.figure_writer": ("motionhyst.present.figure_writer",),
    "motionhyst.plots": ("motionhyst.present.plots",),
    "motionhyst.report": ("motionhyst.present.report",),
}


class _MovedModule(types.ModuleType):
    """An old module path: its names are looked up in the module(s) it moved to."""

    def __getattr__(self, name: str):
        for target in _MOVED[self.__name__]:
            module = importlib.import_module(target)
            if hasattr(module, name):
                return getattr(module, name)
        raise AttributeError(f"module {self.__name__!r} has no attribute {name!r}")

    def __call__(self, *args, **kwargs):
        # importing an old path sets the package attribute of its name to the module: where
        # the package exports a function of that name (``simulate``), the call still works
        name = self.__name__.rpartition(".")[2]
        if name not in _WHERE:
            raise TypeError(f"module {self.__name__!r} is not callable")
        return getattr(importlib.import_module(_WHERE[name]), name)(*args, **kwargs)

    def __dir__(self) -> list[str]:
        return sorted({name for target in _MOVED[self.__name__]
                       for name in dir(importlib.import_module(target))})


class _MovedFinder:
    """Imports an old module path of :data:`_MOVED` with a DeprecationWarning (a finder and
    loader of ``sys.meta_path`` by its methods: ``importlib.abc`` would cost the command's
    start 50 ms)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in _MOVED:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec):
        new = _MOVED[spec.name]
        warnings.warn(f"{spec.name} moved to {' and '.join(new)}; the old path will be removed "
                      "in the next release", DeprecationWarning, stacklevel=4)
        return _MovedModule(spec.name)

    def exec_module(self, module) -> None:
        module.__all__ = [n for target in _MOVED[module.__name__]
                          for n in getattr(importlib.import_module(target), "__all__", ())]


if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
    sys.meta_path.append(_MovedFinder())
