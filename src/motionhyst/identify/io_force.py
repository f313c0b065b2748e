"""A record's force as an input-output search runs it: upsampled once, offsets applied per block.

Each evaluation of a search runs every record on its upsampled force
(:func:`~motionhyst.time.resample.fine_input`, ``r`` fine nodes a sample) less the force
offset ``u0`` and a drifting offset's rate times the fine nodes' times.  The upsampling is
done once (it is linear: the offset's part is ``u0`` times the upsampled constant 1, which
repeats with the fine step's phase and is kept as those ``r`` values); the subtraction is
done one block at a time as the run goes through the record
(:func:`~motionhyst.time.openloop.simulate_elements` with an iterator of blocks), so that no
evaluation holds a second copy of the record's fine force.

Examples
--------
>>> import numpy as np
>>> from motionhyst.identify.io_records import IORecord
>>> t = np.arange(3000) / 1000.0
>>> rec = IORecord(t, np.sin(2 * np.pi * 3.3 * t), np.zeros(3000))
>>> force = RecordForce(rec, 20, periodic=False, offset=True)
>>> whole = force.whole(0.5)
>>> blocks = list(force.blocks(0.5, nodes=20 * 1000))
>>> [b.size for b in blocks], whole.size
([20001, 20001, 19981], 59981)
>>> bool(np.array_equal(np.concatenate([blocks[0], *(b[1:] for b in blocks[1:])]), whole))
True
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from motionhyst.time.resample import block_samples, fine_blocks, fine_input

__all__ = ["RecordForce"]


class RecordForce:
    """The fine force of one record for a search's runs, less an offset (and its drift).

    Parameters
    ----------
    rec : IORecord
        The record (its ``u`` and ``t``).
    factor : int
        Fine nodes per sample (the search's substeps).
    periodic : bool
        The record is whole periods of a periodic steady state (its runs take the period's
        fine force whole) or a run from a start (in blocks).
    offset : bool
        Runs subtract a force offset (``u0`` times the upsampled constant 1).
    drift : bool
        Runs subtract a drifting offset (its rate times the upsampled time stamps).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify.io_records import IORecord
    >>> rec = IORecord(np.arange(10) / 10.0, np.full(10, 5.0), np.zeros(10))
    >>> force = RecordForce(rec, 4, periodic=False, offset=True)   # 5 N, less 2 N
    >>> force.whole(2.0).size, force.whole(2.0)[:3].round(6).tolist()
    (37, [3.0, 3.0, 3.0])
    """

    def __init__(self, rec, factor: int, periodic: bool, offset: bool = False,
                 drift: bool = False) -> None:
        self.factor = int(factor)
        self.periodic = periodic
        self.fine = fine_input(rec.u, self.factor, periodic)
        self._one_phase: NDArray[np.float64] | None = None
        self._one: NDArray[np.float64] | None = None
        if offset:
            self._one_phase, self._one = _upsampled_one(rec.u.size, self.factor, periodic)
        # a drifting offset's times: not periodic in the fine step; kept whole (--drift only)
        self._t = fine_input(rec.t, self.factor, periodic) if drift else None

    @property
    def nbytes(self) -> int:
        """Bytes held (the fine force, and the upsampled time stamps of a drift)."""
        return sum(a.nbytes for a in (self.fine, self._one, self._t) if a is not None)

    def whole(self, u0: float = 0.0, drift: float = 0.0) -> NDArray[np.float64]:
        """The fine force less the offsets, whole (the record's own array if there are none).

        Parameters
        ----------
        u0 : float
            The force offset [N].
        drift : float
            Its rate [N/s].

        Returns
        -------
        ndarray
            The fine nodes.
        """
        return self._part(0, self.fine.size, u0, drift)

    def blocks(self, u0: float = 0.0, drift: float = 0.0, nodes: int | None = None
               ) -> Iterator[NDArray[np.float64]]:
        """The fine force less the offsets in consecutive blocks that share their end nodes,
        as :func:`~motionhyst.time.resample.fine_blocks` gives them (the same nodes, bit for
        bit, as :meth:`whole`).

        Parameters
        ----------
        u0, drift : float
            As for :meth:`whole`.
        nodes : int, optional
            As for :func:`~motionhyst.time.resample.block_samples`.

        Yields
        ------
        ndarray
            A block's fine nodes.
        """
        step = block_samples(self.factor, nodes) * self.factor
        last = self.fine.size - 1
        if last <= step:
            yield self.whole(u0, drift)
            return
        for a in range(0, last, step):
            yield self._part(a, min(a + step, last) + 1, u0, drift)

    def _part(self, a: int, b: int, u0: float, drift: float) -> NDArray[np.float64]:
        # the operations of `fine - u0 * one - drift * t` on the whole arrays, node by node
        fine = self.fine[a:b]
        if self._one is not None:
            fine = fine - u0 * self._one[a:b]
        elif self._one_phase is not None:
            fine = fine - u0 * _tiled(self._one_phase, a, b)
        if self._t is not None:
            fine = fine - drift * self._t[a:b]
        return fine


def _tiled(phase: NDArray[np.float64], a: int, b: int) -> NDArray[np.float64]:
    """Nodes `a` to `b` of the fine constant 1 that repeats `phase` from node 0."""
    r = phase.size
    first = a // r
    reps = -(-b // r) - first
    return np.tile(phase, reps)[a - first * r: b - first * r]


def _upsampled_one(n: int, factor: int, periodic: bool
                   ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """The upsampled constant 1 of a record of `n` samples: as the ``factor`` values it
    repeats (from the first block of its upsampling, checked on every block; its nodes
    those of ``fine_input(ones, factor, periodic)``: bit for bit where that interpolates by
    the windowed sinc, to rounding (1e-16) where it zero-pads a spectrum), or, for one that
    does not repeat, whole (phase None)."""
    if periodic:
        one = fine_input(np.ones(n), factor, periodic)
        phase = one[:factor].copy()
        if _repeats(one, phase, 0):
            return phase, None
        return None, one
    phase = None
    at = 0
    for block in fine_blocks(np.ones(n), factor):
        if phase is None:
            phase = block[:factor].copy()
        if not _repeats(block, phase, at):
            return None, fine_input(np.ones(n), factor, periodic)
        at += block.size - 1
    return phase, None


def _repeats(block: NDArray[np.float64], phase: NDArray[np.float64], at: int) -> bool:
    return bool(np.array_equal(block, _tiled(phase, at, at + block.size)))
