"""Hysteresis models of dynamic links (displacement in, force out)."""

from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function
from motionhyst.hysteresis.maxwell import MaxwellSlip

__all__ = ["Hysteresis", "Jenkins", "MaxwellSlip", "jenkins_describing_function"]
