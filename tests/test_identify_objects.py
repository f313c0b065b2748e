"""identify_io takes the link and the stage as objects; registered names are converted once."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import Jenkins, MaxwellIwan
from motionhyst.identify.input_output import identify_io
from motionhyst.identify.io_records import IORecord
from motionhyst.plants import MassDamper, ModalPlant, Mode, QuasiStatic, TwoMassStage
from motionhyst.time.quasi_static import displacement_from_force


def _record() -> IORecord:
    """A spring and a Jenkins link driven by a force, measured with a position offset."""
    t = np.arange(2000) / 1000.0
    u = 300.0 * np.sin(2 * np.pi * 2 * t) * np.minimum(1.0, t)
    y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
    return IORecord(t, u, y + 1e-4)


def test_a_class_an_instance_and_a_name_give_the_same_fit():
    rec = _record()
    by_name = identify_io([rec], "jenkins", plant="quasi-static")
    for link, plant in ((Jenkins, QuasiStatic), (Jenkins(k=1.0, fc=1.0), QuasiStatic(k=5.0))):
        fit = identify_io([rec], link, plant=plant)
        assert fit.estimates == by_name.estimates
        assert fit.fit_rms == by_name.fit_rms
    assert by_name.estimates["link.fc"] == pytest.approx(100.0, rel=1e-6)


def test_objects_the_records_cannot_fit_are_refused_in_one_line():
    rec = _record()
    with pytest.raises(ValueError, match=r"^input-output records fit a link model of bouc-wen, "):
        identify_io([rec], MaxwellIwan)
    with pytest.raises(ValueError, match=r"^input-output records fit a link model of "):
        identify_io([rec], dict)
    modal = ModalPlant(22.5, [Mode(694.27, 0.00265, 17.5 / (22.5 * 5.0), 1 / 22.5)])
    with pytest.raises(ValueError, match=r"^input-output records identify a mass-spring-damper, "):
        identify_io([rec], Jenkins, plant=modal)
    with pytest.raises(ValueError, match=r"^output 'y2': a mass-damper stage has one position$"):
        identify_io([rec], Jenkins, plant=MassDamper, output="y2")
    with pytest.raises(ValueError, match=r"^output 'y2' differs from the plant's own 'y1'$"):
        identify_io([rec], Jenkins, plant=TwoMassStage(1, 1, 0, 1, output="y1"), output="y2")
    with pytest.raises(ValueError, match=r"^unknown output 'y3'; expected y2 or y1$"):
        identify_io([rec], Jenkins, plant=TwoMassStage, output="y3")
