"""A command line run in a fresh interpreter that reports what it imported.

Shared by the start-up and refusal tests: a fresh interpreter (a subprocess) is the only way
to see which libraries a command loads before it answers.  A refusal that loads none of
:data:`HEAVY` cannot have started the work they do.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

HEAVY = ("control", "scipy", "matplotlib", "numba", "pandas")
"""python-control, scipy (scipy.signal, scipy.optimize, ...), matplotlib, numba and pandas: each
takes longer to import than a refusal or a help text may take."""

_PROBE = """
import contextlib, io, json, sys
from motionhyst.core.compiled import quiet_compilation
quiet_compilation()
from motionhyst.cli import main
err = io.StringIO()
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
    try:
        rc = main(sys.argv[1:])
    except SystemExit as exc:
        rc = exc.code
heavy = sorted({m for m in sys.modules for h in HEAVY if m == h or m.startswith(h + ".")})
packages = sorted({m.split(".")[0] for m in heavy})
print(json.dumps({"rc": rc, "heavy": heavy, "packages": packages, "err": err.getvalue()}))
""".replace("HEAVY", repr(HEAVY))


def probe(argv: Sequence[str], cwd: Path | None = None) -> dict:
    """``motionhyst argv`` in a fresh interpreter.

    Returns ``{"rc": exit code, "err": its stderr, "heavy": the modules of HEAVY it imported,
    "packages": the packages of HEAVY they belong to}`` (full module names and top-level names,
    sorted: ``"control"`` is among both whenever any part of it was imported).
    The one-line notice of a first compilation is left out of stderr, as in a test session:
    whether the kernel cache is warm is not the command's answer.
    """
    proc = subprocess.run([sys.executable, "-c", _PROBE, *argv], capture_output=True,
                          text=True, cwd=cwd, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)
