"""IOIdentification prints itself and draws, per record, the measured and predicted position."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from motionhyst import MotionhystWarning
from motionhyst.cli import main
from motionhyst.hysteresis import Jenkins
from motionhyst.identify import input_output
from motionhyst.identify.input_output import identify_io
from motionhyst.identify.io_records import IORecord
from motionhyst.plants import QuasiStatic
from motionhyst.time.quasi_static import displacement_from_force


@pytest.fixture(scope="module")
def fit():
    t = np.arange(1000) / 500.0
    records = []
    for i, amplitude in enumerate((300.0, 200.0)):
        u = amplitude * np.sin(2 * np.pi * 2 * t)
        y = displacement_from_force(QuasiStatic(k=1e5), Jenkins(k=3e5, fc=100.0), t, u)
        noise = 1e-7 * np.random.default_rng(i).standard_normal(t.size)
        records.append(IORecord(t, u, y + 2e-5 + noise, f"record {i}"))
    return identify_io(records, Jenkins, plant=QuasiStatic)


def test_the_figure_shows_what_the_fit_compared(fit):
    fig = fit.plot()
    assert len(fig.axes) == 4  # positions and residual, per record
    for rec, stats in zip(fit.data, fit.records, strict=True):
        t, measured, predicted = fig.motionhyst_data[rec.name]
        np.testing.assert_array_equal(t, rec.t)
        np.testing.assert_array_equal(measured, rec.y)
        # the record's fit RMS, as the identification reports it, is the plotted difference's
        assert np.sqrt(np.mean((predicted - measured) ** 2)) == pytest.approx(
            stats["fit_rms"], rel=1e-12)
        assert stats["fit_rms"] < 2e-7  # the noise, not the offset of 2e-5 m


def test_prints_its_estimates_and_records(fit):
    text = str(fit)
    assert text.splitlines()[0] == ("quasi-static stage and jenkins link from 2 input-output "
                                    "record(s) (from a start)")
    for name in fit.estimates:
        assert name in text
    assert "record 1" in text
    assert round(fit.estimates["link.fc"]) == 100


def test_the_library_warns_each_line_and_the_command_shows_it_once(fit, tmp_path, capsys,
                                                                   monkeypatch):
    lines = ["link.k = 3e+05 ran 1e+05 times above its start: the records do not hold it",
             "m = 1e-09 kg: the inertia is not visible in these records"]
    # the fit itself as computed, its plausibility checks saying these two lines
    monkeypatch.setattr(input_output, "_route",
                        lambda *args, **kw: dataclasses.replace(fit, warnings=list(lines)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        identify_io(fit.data, Jenkins, plant=QuasiStatic)
    assert [(w.category, str(w.message)) for w in caught] == [
        (MotionhystWarning, line) for line in lines]
    rec = fit.data[0]
    data = tmp_path / "rec.csv"
    np.savetxt(data, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",",
               header="time,force,displacement", comments="", fmt="%.17g")
    assert main(["identify", str(data), "--record", "input-output", "--model", "jenkins",
                 "--plant", "quasi-static", "--json"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert [e for e in err if "warning" in e] == [
        f"motionhyst: warning: identify: {line}" for line in lines]
