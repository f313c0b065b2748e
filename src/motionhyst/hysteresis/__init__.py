"""Hysteresis models of dynamic links (displacement in, force out)."""

from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function

__all__ = ["Hysteresis", "Jenkins", "jenkins_describing_function"]
