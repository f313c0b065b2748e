"""A prediction from a window's state (``predict --init-from``,
:func:`~motionhyst.identify.io_predict.predict_from_window`) sized at what it takes (issue 26):
the larger of its samples' memory (:data:`~motionhyst.identify.io_predict.WINDOW_SAMPLE_BYTES`
a sample) and its blocks' (:data:`~motionhyst.identify.io_predict.WINDOW_NODE_BYTES` a fine node
held, a block's arrays of the compiled kernels included, which tracemalloc does not see).
Before, 48 bytes a node and 64 a sample (never measured): 1.5-2.1 times the peak where the
blocks decide, and below it where the samples do."""

from __future__ import annotations

import subprocess
import sys

import pytest

RUN = """
import resource, sys, tracemalloc, warnings
import numpy as np
warnings.simplefilter("ignore")
from motionhyst.core.budget import set_max_memory
set_max_memory(1 << 40)  # the address-space limit alone decides
from motionhyst.hysteresis import Jenkins
from motionhyst.plants.mass_spring_damper import MassSpringDamper
from motionhyst.identify.io_predict import predict_from_window
from motionhyst.time.openloop import OpenLoop
from motionhyst.time.resample import held_nodes

system = OpenLoop(MassSpringDamper(5.0, 50.0, 2e4), Jenkins(k=2e4, fc=20.0))
n, r = int(sys.argv[1]), int(sys.argv[2])

def record(n):
    t = np.arange(n) / 1000.0
    u = sum(40.0 * np.sin(2 * np.pi * f * t + f) for f in (3.1, 11.3, 23.7))
    y = system.simulate(t, u, substeps=r).displacement
    return t, u, y + 1e-9 * np.random.default_rng(0).standard_normal(n)

predict_from_window(system, *record(3000), window=20, substeps=r)  # compiled, warmed
t, u, y = record(n)
try:
    from motionhyst.identify.io_predict import window_memory
    estimate = window_memory(u, r)
except ImportError:  # main's: 48 bytes a node held and 64 a sample
    estimate = 48 * held_nodes(u, r) + 64 * u.size
with open("/proc/self/status") as f:
    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith("VmSize"))
resource.setrlimit(resource.RLIMIT_AS, (size + int(estimate), size + int(estimate)))
tracemalloc.start()
pred = predict_from_window(system, t, u, y, window=20, substeps=r)
with open("/proc/self/status") as f:
    peak = next(int(x.split()[1]) * 1024 for x in f if x.startswith("VmPeak")) - size
print(int(pred.rmse < 1e-7), int(estimate), tracemalloc.get_traced_memory()[1], peak)
"""


@pytest.mark.parametrize(("n", "r"), [
    (200_000, 10),   # its samples decide: 76.8 MB traced, 70.4 of address (main 160 MB)
    (20_000, 100),   # one block of 2e6 nodes: 33.0 traced, 64.0 address (main 97 MB)
    (20_000, 5),     # its samples: 7.7 MB traced (main 6.1 MB, below)
], ids=["samples", "blocks", "few-substeps"])
def test_a_prediction_from_a_window_is_estimated_within_its_margin(tmp_path, n, r):
    """The prediction under an address-space limit of its estimate above a warmed process
    (main's failed: a MemoryError at 2e4 samples of 5 steps), and the estimate at most 50 %
    above the larger of its traced peak and its address space's rise (measured 1.08-1.46 on
    two machines, whose address spaces rise by 70.4 and 104 MB at 2e5 samples; main
    1.52-2.1 where it ran)."""
    from limited_process import environment

    script = tmp_path / "run.py"
    script.write_text(RUN)
    proc = subprocess.run([sys.executable, str(script), str(n), str(r)],
                          capture_output=True, text=True, env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    good, estimate, traced, address = (int(x) for x in proc.stdout.split())
    assert good == 1
    assert max(traced, address) <= estimate <= 1.5 * max(traced, address), (estimate, traced,
                                                                             address)
