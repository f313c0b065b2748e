"""The input-output search: its trials, its budget.

A trial the model refuses (a mass run to 0, an exponential overflowing) is the search's large
residual, with no numpy warning on the user's terminal; ``--max-evaluations N`` is the
search's whole budget (every start, profile point, rigid-limit fit and refinement counted).
"""

from __future__ import annotations

import limited_process
import numpy as np

from motionhyst.hysteresis import Jenkins
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.openloop import OpenLoop

FS = 1000.0


def _axis(n: int = 4000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A positioning axis (2 kg, 10 N s/m, a Jenkins link) driven by three sines, its position
    with 2 um of noise: time, force, position."""
    t = np.arange(n) / FS
    u = (30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
         + 5 * np.sin(2 * np.pi * 7 * t))
    y = OpenLoop(MassDamper(2.0, 10.0), Jenkins(k=2e4, fc=4.0)).simulate(t, u).displacement
    return t, u, y + 2e-6 * np.random.default_rng(0).standard_normal(n)


def _write(path, t, u, y) -> None:
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="time,force,displacement",
               comments="")


def test_refused_trials_of_an_inconsistent_record_print_no_numpy_warning(tmp_path):
    """A step force beside another record's position: the search tries masses near 0 and
    overflowing exponentials (numpy warned 'invalid value encountered in divide', 'overflow
    encountered in exp' on stderr); such a trial is a large residual, and stderr has only the
    command's own lines."""
    t, _, y = _axis()
    _write(tmp_path / "step.csv", t, np.where(t > 1.0, 30.0, 0.0), y)
    code, out, err = limited_process.run(
        ["identify", "step.csv", "--record", "input-output", "--plant", "mass-damper",
         "--model", "coulomb"], tmp_path)
    assert code == 0 and "fc = " in out, err  # the search ran to its end
    assert "RuntimeWarning" not in err and "encountered in" not in err, err
    assert all(line.startswith("motionhyst: ") for line in err.splitlines()), err
