"""A closed-loop record of a sampled controller given with a continuous one (issue 26).

The paper's loop with its controller sampled at 5 kHz (one sample late), logged at 10 kHz: u
holds each of the controller's values over two rows.  Given with the paper's continuous
scenario, the force inferred through the plant read that staircase as ramps, late by half the
controller's period and more, and was refused as "creating energy", asking about u's sign or a
time offset of three samples.  The staircase itself says what the record is: refused before
the inference, naming the controller's rate (``sample_rate_hz``) and the rows at its samples;
with them the record is identified.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from closed_loop_files import closed_loop_files, record_csv

from motionhyst import Jenkins, Loop, SineReference
from motionhyst.identify import identify_closed_loop
from motionhyst.scenario import Scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CONTROLLER_RATE = 5000.0
LOGGER_RATE = 10_000.0


def _sampled_scenario() -> str:
    text = (EXAMPLES / "paper_10khz.toml").read_text()
    assert "sample_rate_hz = 10000.0" in text and "delay_samples = 1.5" in text
    return text.replace("sample_rate_hz = 10000.0", "sample_rate_hz = 5000.0").replace(
        "delay_samples = 1.5", "delay_samples = 1.0")


@pytest.fixture(scope="module")
def held_record():
    """1 s of a 5 Hz, 10 mm sine: the sampled loop gives u_k; the stage and its link, driven
    by the held force one sample late (at 100 kHz, each step's sample at its mean so that the
    interpolated force carries the held one's impulse), give y1 at the logger's rows (3.7 nm
    from the sampled run's at its samples)."""
    from motionhyst.plants import TwoMassStage
    from motionhyst.time.openloop import OpenLoop
    from motionhyst.time.sampled import simulate_sampled

    sc = Scenario.from_dict(tomllib.loads(_sampled_scenario()), "s")
    link = Jenkins(k=20.0, fc=0.05)
    sim = simulate_sampled(Loop(sc.plant(), sc.controller(), link), SineReference(0.01, 5.0),
                           1.0)
    T, fine = 1.0 / CONTROLLER_RATE, 100_000.0
    tf = np.arange(100_001) / fine
    k = np.floor(tf / T - 1.0 + 1e-9).astype(int)  # the u_k acting at tf, a sample late

    def acting(j):
        return np.where(j >= 0, sim.u[np.clip(j, 0, sim.u.size - 1)], 0.0)

    at_step = np.abs(tf / T - np.round(tf / T)) < 1e-6
    force = np.where(at_step, 0.5 * (acting(k) + acting(k - 1)), acting(k))
    y1 = OpenLoop(TwoMassStage(5.0, 17.5, 90.0, 7.4e7, output="y1"), link).simulate(
        tf, force, substeps=4).displacement
    rows = slice(None, None, int(fine / LOGGER_RATE))
    t = tf[rows]
    u = sim.u[np.floor(t / T + 1e-9).astype(int)]  # logged as computed, held between samples
    assert np.max(np.abs(y1[rows][::2] - sim.y1)) < 1e-8
    return t, y1[rows], u


def test_a_held_record_with_a_continuous_controller_is_refused_naming_its_rate(held_record,
                                                                              tmp_path):
    import limited_process
    from file_trees import populate, snapshot

    populate(tmp_path, closed_loop_files(*held_record))
    before = snapshot(tmp_path)
    line = limited_process.refusal(["identify", "rec.csv", "--scenario", "s.toml"], tmp_path)
    assert line == ("motionhyst: error: rec.csv: u is held over 2 rows (it takes a new value "
                    "every 2 rows, from row 1): the force of a controller sampled at about "
                    "5000 Hz, which a continuous controller reads as ramps, late by half its "
                    "period and more; give s.toml's [controller] its sample_rate_hz = 5000 "
                    "(and delay_samples), and the record at its samples (one row in 2, from "
                    "row 1); nothing identified"), line
    assert snapshot(tmp_path) == before


def test_the_record_as_the_refusal_says_is_identified(held_record, tmp_path):
    """The scenario given the controller's rate: the record at 10 kHz is refused naming the
    rows to take; those rows are identified (k 20 N/m, fc 0.05 N within 1 %)."""
    import json

    import limited_process
    from file_trees import populate

    t, y1, u = held_record
    populate(tmp_path, closed_loop_files(t, y1, u, _sampled_scenario()))
    line = limited_process.refusal(["identify", "rec.csv", "--scenario", "s.toml"], tmp_path)
    assert line.endswith("the record's sampling interval 0.0001 s is not the controller's "
                         "period 0.0002 s (u is held over 2 rows: take one row in 2, from row "
                         "1)"), line
    (tmp_path / "rec.csv").write_text(record_csv(t[::2], y1[::2], u[::2]))
    code, out, err = limited_process.run(["identify", "rec.csv", "--scenario", "s.toml",
                                          "--json"], tmp_path)
    assert code == 0, err
    element, = json.loads(out)["elements"]
    assert element["k"] == pytest.approx(20.0, rel=0.01)
    assert element["fc"] == pytest.approx(0.05, rel=0.01)


def test_the_library_refuses_a_held_record_without_its_controller(held_record):
    from motionhyst import default_scenario

    with pytest.raises(ValueError, match=r"^u is held over 2 rows .* give the "
                                         r"SampledController \(controller=\) its "
                                         r"sample_rate_hz = 5000"):
        identify_closed_loop(*held_record, default_scenario().plant(), n_elements=1)


@pytest.mark.parametrize("quantum", [0.0, 1e-4, 1e-2, 1.0, "float32"])
@pytest.mark.parametrize("frequency_hz", [0.2, 5.0])
def test_a_continuous_loop_s_u_is_not_held_even_quantised(frequency_hz, quantum):
    """A continuous loop's u, rounded to a DAC's steps (0.1 mN to 1 N) or to float32, stays
    at the same value for irregular runs of rows: no staircase (0 of 133 such records in the
    measurement)."""
    from motionhyst import default_scenario, simulate
    from motionhyst.identify.link_checks import held_rows

    sc = default_scenario()
    u = simulate(Loop(sc.plant(), sc.controller(), Jenkins(k=20.0, fc=0.05)),
                 SineReference(0.01, frequency_hz), 1.0, dt=1e-4).u
    if quantum == "float32":
        u = u.astype(np.float32).astype(float)
    elif quantum:
        u = np.round(u / quantum) * quantum
    assert held_rows(u) == (1, 0)
