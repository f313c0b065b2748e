"""A worker started with dask's trim threshold (``MALLOC_TRIM_THRESHOLD_=65536``, set by the
nanny) keeps its heap while batches run, and returns it as configured afterwards."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(
    platform.system() != "Linux" or platform.libc_ver()[0] != "glibc",
    reason="the trim threshold is glibc's")

# 64 blocks of 100 kB (below the mmap threshold: from the top of the heap) allocated and freed
# 50 times: each round grows the heap by 6.4 MB, which a trim threshold of 64 kB gives back
SCRIPT = """
import resource
from motionhyst.study.heap import heap_kept

def faults():
    r0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(50):
        blocks = [bytearray(100_000) for _ in range(64)]
        del blocks
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - r0

before = faults()
with heap_kept():
    with heap_kept():           # a second thread's batch: the first to end does not restore
        pass
    kept = faults()
after = faults()
print(before, kept, after)
"""


def _faults(env: dict) -> tuple[int, int, int]:
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, check=True, timeout=120)
    before, kept, after = map(int, out.stdout.split())
    return before, kept, after


def test_heap_kept_under_a_nanny_trim_threshold():
    before, kept, after = _faults({**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"})
    pages = 50 * 64 * 100_000 // 4096
    assert before > pages // 2          # every round faults the grown heap in again
    assert kept < before / 10           # kept: faulted in once
    assert after > pages // 2           # the configured threshold is back


def test_heap_untouched_without_a_configured_threshold():
    env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
    before, kept, after = _faults(env)
    # glibc's own threshold decides, the same in and out of the block
    assert abs(kept - before) < before / 10 + 100
    assert abs(after - before) < before / 10 + 100
