"""One BLAS thread for a small matrix: its threads cost more than its arithmetic.

numpy's BLAS (OpenBLAS, MKL, ...) runs a product or a factorisation on as many threads as
the machine has cores.  For a small matrix the work is milliseconds and the threads' start
and hand-over are most of it; on a loaded machine, where the threads wait for cores, they
are all of it: a least-squares fit of 6000 x 36 (the inertia check of a record) took
0.94 s of wall time and 0.31 s of CPU a call with the machine's threads, 0.07 s and 0.03 s
with one (2 cores, load 18).  :func:`few_blas_threads` runs a block with one thread where
its matrix is small (:data:`SMALL_FLOPS`), and leaves a large one its threads; the limit is
the block's only (:mod:`threadpoolctl` finds the loaded BLAS library, whichever it is).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["SMALL_FLOPS", "few_blas_threads"]

SMALL_FLOPS = 1e8
"""A matrix of ``rows x columns`` is small when ``rows * columns**2`` (the products of a
least-squares fit) is at most this: some tens of milliseconds on one core."""


@contextlib.contextmanager
def few_blas_threads(rows: int, columns: int) -> Iterator[None]:
    """Run the block on one BLAS thread if a ``rows x columns`` matrix is small.

    Parameters
    ----------
    rows, columns : int
        The shape of the block's largest matrix.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.random.default_rng(0).standard_normal((6000, 36))
    >>> with few_blas_threads(*A.shape):
    ...     x = np.linalg.lstsq(A, A[:, 0], rcond=None)[0]
    >>> round(float(x[0]), 6)
    1.0
    """
    if rows * columns * columns > SMALL_FLOPS:
        yield
        return
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
