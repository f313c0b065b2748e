"""Benchmark: the open loop's periodic steady state, with and without its two shortcuts.

A floating two-mass stage (``m1 = 2, m2 = 3 kg, b = 20 N s/m, k = 2e5 N/m``) on a
Jenkins link (``k = 5e4 N/m``, ``fc = 20 N``) that holds it, driven by a multisine of
1 N RMS (1560 samples at 750 Hz, lines up to 28 Hz): the stage's mode on the link's
spring is barely damped, so repeating the period forgets the start only slowly.  One
run measures (``time.process_time``, the least of ``REPEATS`` runs after one to compile)
the periodic steady state of

1. one period, the periods' start state extrapolated to the period map's fixed point
   (:class:`~motionhyst.time.periodic_runs.PeriodExtrapolation`), against the same run
   without (periods repeated until the output repeats);
2. a record of eight whole periods (12,480 samples) run as one period and repeated
   (:func:`~motionhyst.time.periodic_runs.whole_periods`), against the record run
   whole as its own period (both with the extrapolation).

The outputs agree to 1e-9 of their range.  Run with ``make bench`` or
``python benchmarks/periodic.py``.
"""

from __future__ import annotations

import sys
import time
from unittest import mock

import numpy as np

from motionhyst.hysteresis import Jenkins
from motionhyst.time import openloop
from motionhyst.time.openloop import OpenLoop, TwoMass
from motionhyst.time.periodic_runs import PeriodExtrapolation

REPEATS = 3
FS = 750.0
PERIOD = 1560
PERIODS = 8


class _Never(PeriodExtrapolation):
    """No extrapolation: the periods repeated until the output repeats."""

    def __call__(self, blocks):
        return None


def least_time(fn) -> tuple[float, np.ndarray]:
    """The least process time of `fn` over REPEATS calls, after one call to compile [s]."""
    out = fn()
    best = np.inf
    for _ in range(REPEATS):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def main() -> int:
    rng = np.random.default_rng(1)
    t = np.arange(PERIOD) / FS
    lines = np.arange(1, 60)
    u = sum(np.sin(2 * np.pi * k * FS / PERIOD * t + p)
            for k, p in zip(lines, rng.uniform(0, 2 * np.pi, lines.size), strict=True))
    u *= 1.0 / np.std(u)
    system = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5), Jenkins(k=5e4, fc=20.0))

    def one():
        return system.simulate(t, u, periodic=True).displacement

    t_fast, y_fast = least_time(one)
    with mock.patch.object(openloop, "PeriodExtrapolation", _Never):
        t_slow, y_slow = least_time(one)
    tt = np.arange(PERIODS * PERIOD) / FS
    uu = np.tile(u, PERIODS)

    def whole():
        return system.simulate(tt, uu, periodic=True).displacement

    t_tiled, y_tiled = least_time(whole)
    with mock.patch.object(openloop, "whole_periods", lambda _: 1):
        t_long, y_long = least_time(whole)
    span = float(np.ptp(y_fast))
    agree = max(float(np.max(np.abs(y_fast - y_slow))),
                float(np.max(np.abs(y_tiled - y_long)))) / span
    print(f"periodic steady state of a floating two-mass stage on a Jenkins link "
          f"({PERIOD} samples per period):")
    rows = [("one period, extrapolated", t_fast, ""),
            ("one period, repeated only", t_slow, f"({t_slow / t_fast:.1f}x)"),
            (f"{PERIODS} periods, run as one", t_tiled, ""),
            (f"{PERIODS} periods, run whole", t_long, f"({t_long / t_tiled:.1f}x)")]
    for label, seconds, ratio in rows:
        print(f"  {label:28s} {seconds:8.3f} s   {ratio}".rstrip())
    print(f"  outputs agree to {agree:.1e} of their range")
    return 0 if agree < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
