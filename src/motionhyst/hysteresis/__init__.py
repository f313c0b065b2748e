"""Hysteresis models of dynamic links (displacement in, force out)."""

from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.bouc_wen import BoucWen
from motionhyst.hysteresis.dahl import Dahl
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function
from motionhyst.hysteresis.lugre import LuGre
from motionhyst.hysteresis.maxwell import MaxwellSlip

__all__ = ["BoucWen", "Dahl", "Hysteresis", "Jenkins", "LuGre", "MaxwellSlip",
           "jenkins_describing_function"]
