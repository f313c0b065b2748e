"""The C heap of a worker kept while a batch runs, whatever the trim threshold it started with.

dask's nanny starts every worker with ``MALLOC_TRIM_THRESHOLD_=65536`` (its
``distributed.nanny.pre-spawn-environ``), so that glibc hands memory back to the system as soon
as 64 KB are free at the top of the heap.  A point allocates and frees its arrays by the
hundred: with that threshold the heap shrinks after nearly every point and the next point
faults the same pages in again (about ten page faults and 10 % of a point's CPU time on the
Table I loop).  :func:`heap_kept` raises the threshold while batches run and, when the
process's last batch ends, sets the configured one back and trims the heap once, so that the
worker still returns its memory as its environment asks.  Elsewhere (no such variable, or not
glibc) it does nothing: glibc's own threshold adapts to the program.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import os
import platform
import threading
from collections.abc import Iterator

__all__ = ["KEPT_BYTES", "configured_threshold", "heap_kept"]

KEPT_BYTES = 1 << 27
"""Trim threshold while batches run [bytes]: free memory at the top of the heap up to this
stays with the process (glibc's own threshold grows up to 64 MB)."""

_M_TRIM_THRESHOLD = -1      # glibc's mallopt parameter
_lock = threading.Lock()
_running = 0


@functools.cache
def _glibc() -> ctypes.CDLL | None:
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    try:
        return ctypes.CDLL(None)
    except OSError:
        return None


def configured_threshold() -> int | None:
    """The trim threshold this process's environment sets (``MALLOC_TRIM_THRESHOLD_``) [bytes],
    or None (not set, not a number, or not glibc: nothing to undo).

    Examples
    --------
    >>> import os
    >>> configured_threshold() == (int(os.environ["MALLOC_TRIM_THRESHOLD_"])
    ...                            if "MALLOC_TRIM_THRESHOLD_" in os.environ and _glibc()
    ...                            else None)
    True
    """
    text = os.environ.get("MALLOC_TRIM_THRESHOLD_", "").strip()
    if not text.isdigit() or _glibc() is None:
        return None
    return int(text)


@contextlib.contextmanager
def heap_kept() -> Iterator[None]:
    """Keep the freed heap in the process while the block runs (threads may nest it).

    Examples
    --------
    >>> with heap_kept():
    ...     chunks = [bytearray(100_000) for _ in range(3)]
    >>> len(chunks)
    3
    """
    global _running
    threshold = configured_threshold()
    libc = _glibc()
    if threshold is None or libc is None:
        yield
        return
    with _lock:
        if _running == 0:
            libc.mallopt(_M_TRIM_THRESHOLD, KEPT_BYTES)
        _running += 1
    try:
        yield
    finally:
        with _lock:
            _running -= 1
            if _running == 0:
                libc.mallopt(_M_TRIM_THRESHOLD, threshold)
                libc.malloc_trim(0)
