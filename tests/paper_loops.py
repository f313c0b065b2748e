"""The paper's loop with another link, and the first harmonic of a run's last period: shared
by the tests of the steady state's fixed point against runs in time."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SAMPLED = (EXAMPLES / "paper_10khz.toml").read_text()


def paper_loop(link, sampled: bool = False):
    """Table I's loop (examples/paper_10khz.toml's, sampled at 10 kHz, for `sampled`) with
    `link`."""
    from motionhyst import Loop
    from motionhyst.scenario import Scenario, default_scenario

    sc = (Scenario.from_dict(tomllib.loads(SAMPLED), "s") if sampled else default_scenario())
    return Loop(sc.plant(), sc.controller(), link)


def last_period_e1(run, f: float = 5.0) -> float:
    """``|e_1|`` of the last period of a run in time at the reference's `f` [Hz]."""
    t, e = np.asarray(run.t), np.asarray(run.e)
    last = (t >= t[-1] - 1 / f - 1e-9) & (t < t[-1] - 1e-9)
    t, e = t[last], e[last]
    return float(2 * abs(np.mean(e * np.exp(-2j * np.pi * f * t))))
