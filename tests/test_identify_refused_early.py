"""identify's refusals come before its search, as one line (issue 26: every refusal within
2 s of start, a refusal is one line): a budget of model evaluations below the least the
search needs is refused without the warnings the checks of the records held (a time column
in ms), which the search shows as it starts; an axis whose link never slips in its records
is refused before the search (:mod:`motionhyst.identify.link_slips`), not after it.

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`) and asserts exit code 2, one line on stderr and nothing on stdout.
"""

from __future__ import annotations

import limited_process
import numpy as np
import pytest
from file_trees import populate
from test_bad_inputs_late import _stage
from test_identify_undetermined import LINK_FC, LINK_K, axis_record, run, write_csv

from motionhyst.hysteresis import Jenkins
from motionhyst.identify.io_records import IORecord
from motionhyst.identify.link_slips import check_link_slips, linear_stage_error
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop


def test_a_budget_below_the_search_s_least_is_one_line_before_the_warnings(tmp_path):
    """A time column in ms (a warning of the checks) and --max-evaluations 20, below the 29
    the positioning axis's search needs at least (3 for each of its 3 starts, 9 for each of
    two steps, 2 to choose): the refusal alone, one line (it followed the two warnings)."""
    populate(tmp_path, {"ms.csv": _stage(time_unit=1000.0)})
    code, out, err = limited_process.run(["identify", "ms.csv", "--record", "input-output",
                                          "--max-evaluations", "20"], tmp_path)
    assert out == "" and code == 2 and len(err.strip().splitlines()) == 1, err
    assert err.startswith("motionhyst: error: a budget of 20 model evaluations is below the "
                          "least this search needs, 29:"), err


def test_a_link_that_never_slips_is_refused_before_the_search(capsys, tmp_path, monkeypatch):
    """An axis whose Jenkins link never slips (1.2 N against 2 N) was refused only after the
    search (20-43 s of CPU, its slip force run away to 2.5e6 N): a mass-spring-damper of
    the link's stiffness explains the records within their noise, refused in one line
    before any search runs (a search here would fail the test), nothing saved."""
    import motionhyst.identify.input_output as io

    def no_search(*args, **kwargs):
        raise AssertionError("the search ran")

    monkeypatch.setattr(io, "identify_elements_io", no_search)
    record = write_csv(tmp_path / "stuck.csv", axis_record())
    saved = tmp_path / "m.toml"
    rc, out, err = run(capsys, "identify", str(record), "--record", "input-output", "--plant",
                       "mass-damper", "--model", "jenkins", "--save", str(saved))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert "the link never slips in these records (a mass-spring-damper of m 9.999 kg" in err
    spring = float(err.split("it acts as a spring of ")[1].split(" N/m")[0])
    assert spring == pytest.approx(LINK_K, rel=1e-3) and not saved.exists()


@pytest.mark.parametrize("force", [1.9, 3.0])
def test_a_link_that_slips_is_left_to_the_search(force):
    """The same axis driven 1.9 times harder: the link slips at the peaks (2.1 N against
    2 N), a linear stage leaves 800 times the records' noise; not refused (nor at 3 times)."""
    t, u, _ = axis_record()
    y = OpenLoop(MassDamper(10.0, 20.0), Jenkins(k=LINK_K, fc=LINK_FC)).simulate(
        t, force * u).displacement
    y = y + 1e-7 * np.random.default_rng(0).standard_normal(t.size)
    check_link_slips([IORecord(t, force * u, y)], "jenkins", stage_k=False)


def test_a_linear_stage_is_found_by_its_simulation_error():
    """The probe's linear fit: a 10 kg mass on 20 N s/m and 2000 N/m (the stuck axis) from a
    start a factor of 2-3 off, within 1e-3 (noise of 0.1 um)."""
    t, u, y = axis_record()
    (m, c, k), rms = linear_stage_error([IORecord(t, u, y)], (4.0, 50.0, 800.0))
    assert (m, c, k) == pytest.approx((10.0, 20.0, LINK_K), rel=1e-3)
    assert rms == pytest.approx(1e-7, rel=0.1)
