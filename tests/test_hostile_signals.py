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


def test_an_interrupt_while_a_study_makes_its_exports_leaves_every_old_file(tmp_path,
                                                                             monkeypatch,
                                                                             capsys):
    """The table was written before the netCDF file was made: a Ctrl-C then gave exit 130
    with the table replaced. Every export is made first, then written."""
    import motionhyst.study.export as export
    from motionhyst.cli import main
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "s.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "st.toml").write_text('scenario = "s.toml"\noutputs = ["e1"]\n\n[axes]\n'
                                      'amplitude = [0.001, 0.01]\nfrequency_hz = [1.0, 2.0]\n')
    for name in ("t.csv", "t.nc"):
        (tmp_path / name).write_text("old\n")
    monkeypatch.chdir(tmp_path)

    def interrupted(ds):
        raise KeyboardInterrupt("SIGINT")

    monkeypatch.setattr(export, "to_netcdf_bytes", interrupted)
    code = main(["study", "st.toml", "--out", "s.zarr", "--workers", "0", "--table", "t.csv",
                 "--netcdf", "t.nc", "--force"])
    assert code == 130, capsys.readouterr().err
    assert capsys.readouterr().err.strip().splitlines()[-1] == "motionhyst: interrupted"
    assert (tmp_path / "t.csv").read_text() == "old\n"
    assert (tmp_path / "t.nc").read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "s.zarr", "st.toml",
                                                          "t.csv", "t.nc"]
