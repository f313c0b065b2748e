"""A command line run in a child process whose address space is limited (``RLIMIT_AS``).

Shared by the bad-input tests: a command that would allocate past the limit gets a
MemoryError (one line, exit 2) instead of growing until the kernel kills it, so a test that
passes under the limit shows the command's memory is bounded.  The child runs with one BLAS
and OpenMP thread and at most two malloc arenas, so that the limit measures the command and
not the machine's core count (each thread reserves a stack, buffers and an arena of 64 MB of
address space it hardly uses).
"""

from __future__ import annotations

import contextlib
import os
import resource
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

REFUSAL_LIMIT = 1 << 30
"""Address space [bytes] for a command that is refused or runs a small case: the commands of
the hostile corpus peak at 0.15-0.71 GB (VmPeak, numba compiling its kernels included)."""

RUN_LIMIT = 2 << 30
"""Address space [bytes] for a command that runs to its end with the study engine: a study of
six points peaks at 0.72 GB (VmPeak; 1.17 GB with an arena per thread; resident 0.33 GB)."""

MAIN = ("import sys\n"
        "from motionhyst.core.compiled import quiet_compilation\n"
        "quiet_compilation()\n"
        "from motionhyst.entry import main\n"
        "sys.exit(main())\n")
"""The console script (:func:`motionhyst.entry.main`, which keeps Ctrl-C and SIGTERM from the
interpreter's exit once the command has returned), without the notice of a first
compilation."""

ONE_THREAD = {**{name: "1" for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                        "MKL_NUM_THREADS")}, "MALLOC_ARENA_MAX": "2"}


def environment(**changes: str | None) -> dict[str, str]:
    """The test's environment without a memory budget of the caller's, one BLAS thread, and
    `changes` (a value None removes the variable)."""
    env = {k: v for k, v in os.environ.items() if k != "MOTIONHYST_MAX_MEMORY"}
    env.update(ONE_THREAD)
    for name, value in changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return env


def _limiter(limit: int, file_limit: int | None = None):
    def limit_address_space() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        if file_limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (file_limit, file_limit))
    return limit_address_space


def popen(argv: list[str], cwd: Path, limit: int = REFUSAL_LIMIT,
          env: dict[str, str] | None = None, file_limit: int | None = None,
          **kwargs) -> subprocess.Popen:
    """``motionhyst argv`` started in `cwd` under an address-space limit of `limit` bytes,
    and a file size limit of `file_limit` bytes if given (``ulimit -f``: a disk that holds
    no more), its stdout and stderr pipes unless `kwargs` say otherwise."""
    kwargs = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, **kwargs}
    return subprocess.Popen([sys.executable, "-c", MAIN, *argv], cwd=cwd,
                            env=environment() if env is None else env,
                            preexec_fn=_limiter(limit, file_limit), **kwargs)


@contextlib.contextmanager
def ended(proc: subprocess.Popen) -> Iterator[subprocess.Popen]:
    """`proc` inside the block, killed (and waited for) if it still runs when the block ends:
    a test that fails leaves no command running."""
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def run(argv: list[str], cwd: Path, limit: int = REFUSAL_LIMIT,
        env: dict[str, str] | None = None, timeout: float = 600.0,
        **kwargs) -> tuple[int, str, str]:
    """``motionhyst argv`` run to its end in `cwd` under `limit`: exit code, stdout, stderr."""
    proc = popen(argv, cwd, limit, env, **kwargs)
    try:
        out, err = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return (proc.returncode, (out or b"").decode("utf-8", errors="replace"),
            (err or b"").decode("utf-8", errors="replace"))


def refusal(argv: list[str], cwd: Path, limit: int = REFUSAL_LIMIT, **kwargs) -> str:
    """``motionhyst argv`` run in `cwd` under `limit`, which must refuse it: exit 2, nothing on
    stdout, one plain line on stderr (no traceback). The line, for the caller's words."""
    code, out, err = run(argv, cwd, limit, **kwargs)
    assert code == 2, (code, out, err)
    assert out == "", out
    line = err.strip()
    assert line and "\n" not in line and "Traceback" not in line, err
    return line
