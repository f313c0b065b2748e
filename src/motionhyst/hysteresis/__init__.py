"""Hysteresis models of dynamic links (displacement in, force out).

Every model is registered in :data:`motionhyst.hysteresis.registry.MODELS`
when this package is imported.
"""

from motionhyst.hysteresis.base import Hysteresis

# isort: off
# The import order is the registration order: the order in which scenarios'
# error messages, `motionhyst df --model` and the documentation list the models.
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function
from motionhyst.hysteresis.maxwell import MaxwellSlip
from motionhyst.hysteresis.bouc_wen import BoucWen
from motionhyst.hysteresis.dahl import Dahl
from motionhyst.hysteresis.lugre import LuGre
from motionhyst.hysteresis.maxwell_iwan import MaxwellIwan
from motionhyst.hysteresis.coulomb import Coulomb
# isort: on
from motionhyst.hysteresis.registry import MODELS, Parameter, model_class, register

__all__ = ["MODELS", "BoucWen", "Coulomb", "Dahl", "Hysteresis", "Jenkins", "LuGre", "MaxwellIwan",
           "MaxwellSlip", "Parameter", "jenkins_describing_function", "model_class", "register"]
