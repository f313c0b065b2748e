"""What every result object keeps (issue 20): ``to_dict()`` as strict JSON, ``__str__`` and
``plot(ax=None)`` drawing into a new figure or into the axes given.

One result of each kind, computed small; a new result class joins :data:`RESULTS`.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.figure import Figure

from motionhyst import (
    Jenkins,
    MaxwellSlip,
    SineReference,
    TwoMassStage,
    analyze,
    compare_with_describing_function,
    default_scenario,
    describing_function,
    fit_frf,
    loop_margins,
    periodic_steady_state,
    simulate,
)
from motionhyst.analysis.digital import compare_digital
from motionhyst.core.jsonio import dumps
from motionhyst.identify import identify_maxwell_slip
from motionhyst.identify.input_output import identify_io
from motionhyst.identify.io_records import IORecord
from motionhyst.plants import QuasiStatic
from motionhyst.plants.frf_fit import ModalPlant
from motionhyst.scan.ilc import learn
from motionhyst.scan.profiles import point_to_point, scan
from motionhyst.scan.scanning import run_scan
from motionhyst.time.quasi_static import displacement_from_force


def _identification():
    t = np.linspace(0.0, 4.0, 4001)
    x = 0.01 * np.exp(-t / 2) * np.sin(2 * np.pi * 2.0 * t)
    w = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x)
    return identify_maxwell_slip(x, w, t=t)


def _frf_fit():
    exact = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    f = np.geomspace(1.0, 3000.0, 60)
    return fit_frf(f, *exact.response(2 * np.pi * f))


def _io_identification():
    t = np.arange(1000) / 500.0
    u = 300.0 * np.sin(2 * np.pi * 2 * t)
    y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
    return identify_io([IORecord(t, u, y, "sine")], Jenkins, plant=QuasiStatic)


def _ilc(loop):
    p = point_to_point(0.002, 0.05, 2.0, 50.0, 1e3, start=0.005)
    return learn(loop, p, p.end + 0.01, trials=2)


def _scan(loop):
    p = scan(0.005, speed=0.05, a_max=2.0, j_max=50.0, s_max=1e3, start=0.01)
    return run_scan(loop, p, window=0.05, tail=0.0)


# name -> (how to compute it from the paper's loop, number of axes its plot draws)
RESULTS = {
    "QuasiLinearAnalysis": (lambda loop: analyze(loop, 0.01, [5.0, 10.0]), 1),
    "SteadyState": (lambda loop: periodic_steady_state(loop, 0.01, 5.0), 1),
    "DescribingFunctionComparison": (
        lambda loop: compare_with_describing_function(loop, 0.01, [5.0, 10.0]), 2),
    "Simulation": (lambda loop: simulate(loop, SineReference(0.01, 5.0), 0.05), 2),
    "DescribingFunctionResult": (
        lambda loop: describing_function(Jenkins(k=20.0, fc=0.05), [0.005, 0.01, 0.1]), 2),
    "Identification": (lambda loop: _identification(), 1),
    "FrfFit": (lambda loop: _frf_fit(), 2),
    "ILCResult": (_ilc, 1),
    "ScanResult": (_scan, 3),
    "Profile": (lambda loop: point_to_point(0.002, 0.05, 2.0, 50.0, 1e3), 5),
    "LoopMargins": (lambda loop: loop_margins(loop.controller, loop.P2), 1),
    "DigitalComparison": (lambda loop: compare_digital(loop, 0.01, [10.0]), 1),
    "IOIdentification": (lambda loop: _io_identification(), 2),
}


@pytest.fixture(scope="module")
def results():
    loop = default_scenario().loop()
    return {name: make(loop) for name, (make, _) in RESULTS.items()}


@pytest.mark.parametrize("name", list(RESULTS))
def test_is_the_class_named(results, name):
    assert type(results[name]).__name__ == name


@pytest.mark.parametrize("name", list(RESULTS))
def test_to_dict_is_strict_json(results, name):
    d = results[name].to_dict()
    assert isinstance(d, dict) and d
    text = dumps(d)  # NaN and infinities become null; numpy values plain
    assert json.loads(text) == json.loads(dumps(json.loads(text)))


@pytest.mark.parametrize("name", list(RESULTS))
def test_prints_itself(results, name):
    text = str(results[name])
    assert text.strip() and not text.startswith(f"{name}(")  # a table, not the dataclass repr


@pytest.mark.parametrize("name", [n for n, (_, axes) in RESULTS.items() if axes])
def test_plot_makes_a_figure_carrying_its_data(results, name):
    fig = results[name].plot()
    assert isinstance(fig, Figure) and len(fig.axes) >= RESULTS[name][1]
    assert isinstance(getattr(fig, "motionhyst_data", {}), dict)


@pytest.mark.parametrize("name", [n for n, (_, axes) in RESULTS.items() if axes])
def test_plot_draws_into_the_axes_given(results, name):
    n = RESULTS[name][1]
    mine = Figure()
    axes = mine.subplots(n, 1, squeeze=False)[:, 0]
    fig = results[name].plot(ax=axes[0] if n == 1 else list(axes))
    assert fig is mine
    for ax in axes:
        assert ax.has_data(), f"{name}.plot(ax=...) left an axes empty"


@pytest.mark.parametrize("name", [n for n, (_, axes) in RESULTS.items() if axes > 1])
def test_plot_refuses_a_wrong_number_of_axes(results, name):
    with pytest.raises(ValueError, match="axes"):
        results[name].plot(ax=Figure().subplots(1, 1))
