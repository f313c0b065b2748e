"""Benchmark: the time engine's three runs, per step, in one run.

For the paper's Table I loop (Jenkins link ``k = 20 N/m``, ``fc = 0.05 N``) and the
reference ``r = 0.01 sin(2 pi 10 t)`` over ``DURATION`` s, one run measures
(``time.process_time``, the least of ``REPEATS`` runs after one to compile):

1. ``simulate``: the continuous closed loop, per integration step;
2. ``run_sampled``: the controller discretised (Tustin) at 10 kHz with 1.5
   samples of delay, the plant and the link integrated exactly between updates,
   per controller sample (issue 22's target: no more than the continuous loop
   per step);
3. ``simulate_elements``: the open loop of a mass-spring-damper with a Jenkins
   link, per fine step, without and with the forward sensitivities.

Run with ``make bench`` or ``python benchmarks/engine.py``.
"""

from __future__ import annotations

import sys
import time

import control
import numpy as np

from motionhyst.controllers.loop import Loop
from motionhyst.hysteresis import Jenkins
from motionhyst.hysteresis.stepping import N_PARAMS
from motionhyst.scenario import default_scenario
from motionhyst.time.engine import DiscreteController, run_sampled
from motionhyst.time.openloop import MassSpringDamper, TwoMass, simulate_elements
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

DURATION = 0.5  # s
REPEATS = 7
SAMPLE_RATE = 1e4  # Hz
DELAY = 1.5  # samples


def least_time(fn) -> float:
    """The least process time of `fn` over REPEATS calls, after one call to compile [s]."""
    fn()
    best = np.inf
    for _ in range(REPEATS):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def main() -> int:
    base = default_scenario().loop()
    link = Jenkins(20.0, 0.05)
    loop = Loop(base.plant, base.controller, link)
    ref = SineReference(0.01, 10.0)
    n_steps = simulate(loop, ref, DURATION).t.size
    t_cont = least_time(lambda: simulate(loop, ref, DURATION))

    T = 1.0 / SAMPLE_RATE
    Cz = control.ss(control.c2d(control.ss(base.controller), T, "tustin"))
    ctrl = DiscreteController(Cz.A, np.hstack([Cz.B, -Cz.B]), Cz.C,
                              [Cz.D[0, 0], -Cz.D[0, 0]], T)
    n_k = round(DURATION / T)
    tk = np.arange(n_k) * T
    r, a = ref(tk)
    plant = TwoMass(5.0, 17.5, 90.0, 7.4e7)
    t_samp = least_time(lambda: run_sampled(plant, link, ctrl, r, ff=base.M * a,
                                            delay_samples=DELAY))

    msd = MassSpringDamper(2.0, 10.0, 5e4)
    ol_link = Jenkins(2e4, 10.0)
    fs, substeps = 750.0, 20
    u = 30 * np.sin(2 * np.pi * 5 * np.arange(3000) / fs)
    dparams = np.zeros((1, N_PARAMS, 2))
    dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0
    n_fine = (u.size - 1) * substeps

    def open_loop(dp):
        return simulate_elements(msd.mechanics(), ol_link.time_stepping(), u, fs, substeps,
                                 periodic=False, dparams=dp)

    t_open = least_time(lambda: open_loop(None))
    t_sens = least_time(lambda: open_loop(dparams))

    per_step = t_cont / n_steps
    per_sample = t_samp / n_k
    rows = [("simulate (continuous), per step", per_step),
            (f"run_sampled ({SAMPLE_RATE / 1e3:g} kHz, d = {DELAY:g}), per controller sample",
             per_sample),
            ("open loop, per fine step", t_open / n_fine),
            ("open loop with 5 sensitivities, per fine step", t_sens / n_fine)]
    print(f"Time engine, Table I loop with a Jenkins link, {DURATION:g} s "
          f"(least of {REPEATS} runs, process time)")
    for label, value in rows:
        print(f"  {label:<58s} {value * 1e6:8.3f} us")
    ratio = per_sample / per_step
    print(f"  sampled per controller sample / continuous per step: {ratio:.2f} "
          f"(target <= 1: {'met' if ratio <= 1.0 else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
