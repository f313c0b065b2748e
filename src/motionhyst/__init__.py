"""motionhyst: hysteresis of dynamic links in high-precision motion control.

Model the hysteresis (:class:`Jenkins`, :class:`MaxwellSlip`, :class:`BoucWen`,
:class:`Dahl`, :class:`LuGre`), predict its effect on tracking with
describing functions (:func:`analyze`), and check the prediction against the
exact periodic steady state of the nonlinear loop (:func:`periodic_steady_state`).
"""

from motionhyst.hysteresis import BoucWen, Dahl, Hysteresis, Jenkins, LuGre, MaxwellSlip
from motionhyst.loop import Loop
from motionhyst.quasilinear import QuasiLinearAnalysis, analyze
from motionhyst.references import PointToPoint, SampledReference, SineReference, load_reference_csv
from motionhyst.scenario import Scenario, ScenarioError, default_scenario, load_scenario

# Importing the submodule sets the package attribute `simulate` to the module; this
# import then rebinds it to the function, so `from motionhyst import simulate` gives the
# function (tests/test_docs.py checks every import order).
from motionhyst.simulate import Simulation, simulate
from motionhyst.steady import SteadyState, periodic_steady_state, steady_state_sweep
from motionhyst.systems import LeadLagLowpass, MeasuredPlant, TwoMassStage, load_frd_plant

__version__ = "0.1.0"

__all__ = [
    "BoucWen", "Dahl", "Hysteresis", "Jenkins", "LeadLagLowpass", "Loop", "LuGre", "MaxwellSlip",
    "MeasuredPlant", "PointToPoint",
    "QuasiLinearAnalysis", "SampledReference", "Scenario", "ScenarioError", "Simulation",
    "SineReference", "SteadyState", "TwoMassStage", "analyze",
    "default_scenario", "load_frd_plant", "load_reference_csv", "load_scenario",
    "periodic_steady_state", "simulate", "steady_state_sweep",
]
