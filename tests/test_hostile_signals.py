"""Ctrl-C and SIGTERM at any moment of a command (issue 26): exit 130, the old files intact.

The signals grid of the campaign found a command ended by a segmentation fault instead:
a signal that came while a compiled kernel ran was raised by the command's handler as
numba boxed the kernel's results (numba runs Python code there), and numba handed back a
tuple with an item missing.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

KERNEL_INTERRUPTED = """
import os, signal, threading
import numpy as np
from motionhyst.cli import _Interrupts
from motionhyst.core.compiled import njit

@njit
def two(n):  # a kernel returning two arrays: numba boxes the second through Python code
    a = np.zeros(3)
    b = np.zeros(4)
    s = 0.0
    for i in range(n):
        s += np.sin(i * 1e-3)
    a[0] = s
    return a, b

two(10)
_Interrupts()
threading.Timer(0.3, os.kill, (os.getpid(), signal.SIG{name})).start()
try:
    for _ in range(2000):  # about 20 ms a call: the signal comes while the kernel runs
        x, y = two(2_000_000)
    print("not interrupted")
except KeyboardInterrupt as exc:
    print("interrupted", exc)
except BaseException as exc:
    print(type(exc).__name__, exc)
"""


@pytest.mark.parametrize("name", ["INT", "TERM"])
def test_a_signal_while_a_kernel_returns_arrays_is_an_interrupt_not_a_crash(name):
    done = subprocess.run([sys.executable, "-c", KERNEL_INTERRUPTED.replace("{name}", name)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    assert done.stdout.strip() == f"interrupted SIG{name}", done.stderr[-2000:]


def test_a_noted_signal_is_raised_by_the_next_kernel_call_and_only_once():
    import numpy as np

    from motionhyst.core.compiled import njit
    from motionhyst.core.interrupts import DEFERRED, defer

    @njit
    def total(x):
        return x.sum()

    assert total(np.ones(3)) == 3.0
    defer("SIGTERM")
    with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
        total(np.ones(3))
    assert DEFERRED == []
    assert total(np.ones(3)) == 3.0
