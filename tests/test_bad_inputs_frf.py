"""A measured plant's response that cannot give the plant asked for (issue 26, no answer from
nothing): each refused with one line that names the cause, before the fit where the lines
decide it, and a loop unstable with a fitted plant blamed on the plant.

The data are Table I's stage (eq. 2, mode at 694 Hz) at 60 log-spaced lines from 1 to
3000 Hz with 0.5 % complex noise, as ``examples/measured_plant.py`` writes them, then
spoiled one way per case.  Each case runs ``motionhyst analyze`` in a child process under an
address-space limit and asserts the exit code, one plain line on stderr, nothing on stdout,
and every file of the folder byte-identical; the refusals decided before the fit also
leave python-control unimported (its import is most of a refusal's second).
"""

from __future__ import annotations

import subprocess
import sys

import limited_process
import numpy as np
from file_trees import populate

from motionhyst import TwoMassStage
from motionhyst.plants.frf_fit import ModalPlant
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
LINES = np.geomspace(1.0, 3000.0, 60)
STAGE = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))


def _measured(delay: float = 0.0, seed: int = 0):
    """Table I's ``P1``, ``P2`` at :data:`LINES`, delayed by `delay` [s], 0.5 % noise."""
    p1, p2 = STAGE.response(2 * np.pi * LINES)
    rng = np.random.default_rng(seed)
    lag = np.exp(-2j * np.pi * LINES * delay)
    noise = rng.standard_normal((2, 2, LINES.size))
    return tuple(p * lag * (1 + 0.005 * (n[0] + 1j * n[1]) / np.sqrt(2))
                 for p, n in zip((p1, p2), noise, strict=True))


def _csv(f=LINES, p1=None, p2=None, reim: bool = False, both_scale: float | None = None) -> str:
    """The response as an analyser exports it: magnitude and phase (or re, im; or both sets,
    the magnitudes of the abs, phase set times `both_scale`)."""
    if p1 is None:
        p1, p2 = _measured()
    cols, head = [f], ["frequency_hz"]
    if reim or both_scale is not None:
        cols += [p1.real, p1.imag, p2.real, p2.imag]
        head += ["p1_re", "p1_im", "p2_re", "p2_im"]
    if not reim:
        k = 1.0 if both_scale is None else both_scale
        cols += [k * np.abs(p1), np.angle(p1, deg=True), k * np.abs(p2), np.angle(p2, deg=True)]
        head += ["p1_abs", "p1_phase_deg", "p2_abs", "p2_phase_deg"]
    rows = np.column_stack(cols)
    return ",".join(head) + "\n" + "\n".join(",".join(f"{v:.10e}" for v in r)
                                             for r in rows) + "\n"


def _scenario(extra: str = "") -> str:
    """Table I's scenario with ``[plant] file = "frf.csv"`` (and `extra`) for its [stage]."""
    return (PAPER[:PAPER.index("[stage]")] + f'[plant]\nfile = "frf.csv"\n{extra}\n'
            + PAPER[PAPER.index("[hysteresis]"):])


P1, P2 = _measured()
CASES = [
    # (id, scenario's extra, frf.csv, words of the one line, decided before the fit)
]
def test_a_fit_refusal_comes_before_python_control_loads(tmp_path):
    """Three lines below the mode determine none (the fit's refusal): python-control, which a
    loop needs, is not imported for it."""
    f = LINES[:3]
    populate(tmp_path, {"s.toml": _scenario(), "frf.csv": _csv(f, P1[:3], P2[:3])})
    code = ("import sys\nfrom motionhyst.cli import main\n"
            "code = main(['analyze', 's.toml', '--frequency', '1'])\n"
            "print(code, 'control' in sys.modules)\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, env=limited_process.environment())
    assert proc.stdout.splitlines()[-1] == "2 False", proc.stdout + proc.stderr
    assert "determine none of the 1 mode(s)" in proc.stderr
