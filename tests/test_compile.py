"""Each compiled kernel is compiled for one signature.

A numba kernel is compiled once per combination of argument types it is
called with, and a constant argument of a call between kernels counts as a
type of its own (``f(x, True)`` compiles ``f`` for ``Literal[bool](True)``
besides ``bool``).  Each extra version costs its whole compilation again on
a user's first run (``advance``, called with a literal ``True`` on a
simulation's first sample, was compiled twice before it was declared with
its one signature).  The test runs the periodic steady state with every link
model, time simulations with the time-stepped ones and the sampled
responses, then reads the signatures cached for every kernel: the cache
folder is keyed by the package's sources, so its index holds every version
compiled for these sources (in a ``make test`` session, those of every test;
a kernel loaded from the cache is not compiled again in the process, so the
dispatchers alone would miss callees).
"""

from __future__ import annotations

import gc

import numpy as np
import pytest

from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.loop import Loop
from motionhyst.core.compiled import Kernel, compiled_in_memory
from motionhyst.hysteresis import BoucWen, Dahl, Jenkins, LuGre, MaxwellIwan, MaxwellSlip
from motionhyst.scenario import default_scenario
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import simulate

LINKS = [Jenkins(20.0, 0.05), MaxwellSlip([12.0, 5.0, 3.0], [0.02, 0.02, 0.01]),
         BoucWen(k=20.0, fc=0.05, n=2.0, beta=0.7, gamma=0.3),
         BoucWen(k=20.0, fc=0.05, n=1.5, beta=0.7, gamma=0.3), Dahl(20.0, 0.05),
         LuGre(sigma0=20.0, sigma1=0.01, sigma2=0.001, fc=0.05, fs=0.06, vs=0.01),
         MaxwellIwan(k0=5.0, kv=[8.0, 3.0], cv=[0.4, 0.02], ki=30.0, d_min=1e-4,
                     d_max=4e-3)]


# kernels specialised on purpose, one version per kind of call
SPECIALISED = {
    # per plant size (the masses as a tuple) and with or without the sensitivities (None)
    "motionhyst.time.bouc_wen_rk4._rk4_run",
}


def cached_signatures(kernel: Kernel) -> list:
    """The signatures in the cache index of `kernel` (numba's own reader)."""
    from numba.core.caching import FunctionCache

    return [key[0] for key in FunctionCache(kernel.py_func)._cache_file._load_index()]


def test_each_kernel_is_compiled_for_one_signature():
    base = default_scenario().loop()
    for link in LINKS:
        loop = Loop(base.plant, base.controller, link)
        assert periodic_steady_state(loop, 0.01, 10.0).iterations >= 1
        if not isinstance(link, MaxwellIwan):
            sim = simulate(loop, SineReference(0.01, 10.0), 0.05)
            assert np.all(np.isfinite(sim.e))
    t = np.linspace(0.0, 0.1, 201)
    x = 0.01 * np.sin(2 * np.pi * 10.0 * t)
    for link in LINKS:
        w = link.response(x, t=t) if isinstance(link, LuGre | MaxwellIwan) else link.response(x)
        assert np.all(np.isfinite(w))
    if compiled_in_memory():
        pytest.skip("no writable cache folder: the compiled versions are not recorded")
    kernels = [k for k in gc.get_objects() if isinstance(k, Kernel)]
    cached = {f"{k.__module__}.{k.__qualname__}": cached_signatures(k) for k in kernels}
    assert sum(1 for v in cached.values() if v) >= 30  # the paths above compiled many kernels
    several = {name: sigs for name, sigs in cached.items()
               if len(sigs) > 1 and name not in SPECIALISED}
    assert not several, several


def test_first_kernel_call_prunes_cache_folders_of_other_sources(tmp_path):
    """The cache folders of other sources (one per edit or upgrade) do not pile up: at a
    process's first kernel call those no process used for a day go, and past the most
    recently used few those unused for an hour; a folder a running process marked, however
    old, and other names stay."""
    import os
    import subprocess
    import sys
    import time

    from motionhyst.core.compiled import BUSY_SECONDS, KEEP_RECENT, PRUNE_SECONDS, _marker_name

    parent = tmp_path / "motionhyst"
    now = time.time()
    ago = {f"numba-{'a' * 16}": 2 * PRUNE_SECONDS,          # unused for two days
           f"numba-{'b' * 16}": 60.0,                       # in use a minute ago
           f"numba-{'c' * 16}.removed-7": 0.0,              # a pruning process died mid-way
           "numba-notes": 2 * PRUNE_SECONDS}                # not a cache folder's name
    hours = [f"numba-{c * 16}" for c in "123456"]           # unused for 2, 3, ... 7 hours
    ago.update({name: (2 + i) * BUSY_SECONDS for i, name in enumerate(hours)})
    running, ended = f"numba-{'d' * 16}", f"numba-{'e' * 16}"
    elsewhere, long_ago = f"numba-{'f' * 16}", f"numba-{'9' * 16}"
    ago.update({running: 2 * PRUNE_SECONDS, ended: 2 * PRUNE_SECONDS,
                elsewhere: 2 * PRUNE_SECONDS, long_ago: 2 * PRUNE_SECONDS})
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    for name in ago:
        (parent / name / "sub").mkdir(parents=True)
        (parent / name / "sub" / "f.nbi").write_bytes(b"x")
    # a process still running (this one) started from `running`'s sources two days ago; one
    # that used `ended` was killed without removing its marker
    (parent / running / _marker_name()).write_text("")
    (parent / ended / _marker_name(int(gone.stdout))).write_text("")
    # a cache folder shared with another machine (a home on a network): its processes cannot
    # be seen from here, so its marker keeps the folder for a day
    (parent / elsewhere / ".in-use-othermachine-1").write_text("")
    (parent / long_ago / ".in-use-othermachine-2").write_text("")
    old = now - 2 * PRUNE_SECONDS
    os.utime(parent / long_ago / ".in-use-othermachine-2", (old, old))
    for name, seconds in ago.items():
        os.utime(parent / name, (now - seconds, now - seconds))
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    code = ("from motionhyst.core.compiled import njit, _cache_folder\n"
            "print(njit(lambda x: x + 1)(1), _cache_folder().name)")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    value, name = out.stdout.split()
    assert value == "2"
    kept = [f"numba-{'b' * 16}", *hours[:KEEP_RECENT - 1]]  # the most recently used others
    assert sorted(p.name for p in parent.iterdir()) == sorted(
        [*kept, running, elsewhere, "numba-notes", name])
    assert time.time() - (parent / name).stat().st_mtime < BUSY_SECONDS   # marked used
    # its own marker went with the process
    assert not [f for f in (parent / name).iterdir() if f.name.startswith(".in-use-")]
