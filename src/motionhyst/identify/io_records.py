"""Input-output records: force in, displacement out, one sampling rate.

What :func:`motionhyst.identify.input_output.identify_io` takes: an
:class:`IORecord` per experiment (read from CSV by :func:`load_io_csv`), checked
by :func:`check_records`; the refinements' starts are tried on the short part
of the records :func:`short_records` cuts.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from motionhyst.time.resample import check_record, sampling_rate

__all__ = ["IORecord", "load_io_csv"]

MIN_SAMPLES = 64
#: Samples of each segment a rigid slider's search first cuts the records into
#: (:func:`segment_records`)
SEGMENT = 500
#: The most segments (of the records' first samples; bounds their search's Jacobian)
MAX_SEGMENTS = 32


@dataclass
class IORecord:
    """One input-output record: time [s], force [N], displacement [m] and a name.

    Attributes
    ----------
    t : ndarray
        Sample times [s], uniformly spaced.
    u : ndarray
        Force on the stage [N].
    y : ndarray
        Measured displacement [m].
    name : str
        Where the record comes from (its file), for messages.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.identify.io_records import IORecord
    >>> t = np.arange(1000) / 500.0
    >>> rec = IORecord(t, np.sin(2 * np.pi * 5 * t), 1e-3 * np.sin(2 * np.pi * 5 * t), "sine")
    >>> round(rec.fs, 9)                                   # sampling frequency [Hz]
    500.0
    """

    t: NDArray[np.float64]
    u: NDArray[np.float64]
    y: NDArray[np.float64]
    name: str = "record"

    @property
    def fs(self) -> float:
        """Sampling frequency [Hz]."""
        return sampling_rate(self.t)


def load_io_csv(path: str | Path, *, columns: dict[str, str] | None = None,
                scale: dict[str, float] | None = None) -> IORecord:
    """Read a record with columns ``time,force,displacement``, CSV or MATLAB ``.mat``.

    The file's own names are mapped by `columns` and scaled by `scale`
    (:func:`motionhyst.io.records.read_record`); errors are one-line ``ValueError``.

    Parameters
    ----------
    path : str or Path
        CSV file with a header naming the columns, or a MATLAB ``.mat`` file.
    columns : dict, optional
        Quantity (``"time"``, ``"force"``, ``"displacement"``) -> the file's name for it;
        a quantity not mapped is read under its own name.
    scale : dict, optional
        Quantity -> gain its column is multiplied by (to SI units).

    Returns
    -------
    IORecord
        Named after `path`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "run.csv"
    >>> _ = path.write_text("time,force,displacement\\n0,0,0\\n0.001,1.5,2e-6\\n")
    >>> load_io_csv(path).u.tolist()
    [0.0, 1.5]
    """
    from motionhyst.io.records import read_record

    data = read_record(path, ("time", "force", "displacement"), columns=columns, scale=scale)
    return IORecord(data[:, 0], data[:, 1], data[:, 2], str(path))


def check_records(records: list[IORecord], periodic: bool) -> list[IORecord]:
    """Validate records; raises ``ValueError`` with one line naming the record."""
    if not records:
        raise ValueError("no records")
    out = []
    for rec in records:
        t = np.asarray(rec.t, dtype=float)
        u = np.asarray(rec.u, dtype=float)
        y = np.asarray(rec.y, dtype=float)
        if not (t.shape == u.shape == y.shape) or t.ndim != 1:
            raise ValueError(f"{rec.name}: time, force and displacement differ in length")
        if t.size < MIN_SAMPLES:
            raise ValueError(f"{rec.name}: too short ({t.size} samples; need at least "
                             f"{MIN_SAMPLES})")
        try:
            check_record(t, y, what="displacement")
            check_record(t, u)
        except ValueError as exc:
            raise ValueError(f"{rec.name}: {exc}") from None
        if np.ptp(u) <= 1e-12 * max(1.0, float(np.max(np.abs(u)))):
            raise ValueError(f"{rec.name}: the force is constant; it excites nothing")
        if np.ptp(y) == 0.0:
            raise ValueError(f"{rec.name}: the displacement is constant")
        out.append(IORecord(t, u, y, rec.name))
    fs = out[0].fs
    for rec in out[1:]:
        if abs(rec.fs - fs) > 1e-9 * fs:
            raise ValueError(f"{rec.name}: sampled at {rec.fs:.6g} Hz, {out[0].name} at "
                             f"{fs:.6g} Hz; records must share one sampling rate")
    return out



def short_records(records: list[IORecord], periodic: bool, n_max: int = 4096
                  ) -> list[IORecord]:
    """The first record, or its first `n_max` samples from rest (whole for periodic records)."""
    rec = records[0]
    if periodic or rec.y.size <= n_max:
        return [rec]
    return [IORecord(rec.t[:n_max], rec.u[:n_max], rec.y[:n_max], rec.name)]


def segment_records(records: list[IORecord]) -> list[tuple[int, IORecord]]:
    """The records cut into segments of :data:`SEGMENT` samples from each record's start
    on: every sample of a record in one (a shorter tail joins the segment before it, a record
    shorter than a segment is one) until the record's share of the :data:`MAX_SEGMENTS`
    runs out (views of the records' arrays).

    The segments are shared by the records' lengths (largest remainders; every record one at
    least, while there are enough): two long records get half each, not all to the first.

    Parameters
    ----------
    records : list of IORecord
        The records.

    Returns
    -------
    list of (int, IORecord)
        Each segment with the index of its record, in the records' order.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1800) / 1e3
    >>> [(i, s.y.size) for i, s in segment_records([IORecord(t, np.sin(t), np.cos(t))])]
    [(0, 500), (0, 500), (0, 800)]
    >>> parts = segment_records([IORecord(t[:1000], t[:1000], t[:1000]),
    ...                          IORecord(t[:300], t[:300], t[:300])])
    >>> [(i, s.y.size) for i, s in parts]
    [(0, 500), (0, 500), (1, 300)]
    >>> n = 100_000
    >>> rec = IORecord(np.arange(n) / 1e3, np.zeros(n), np.zeros(n))
    >>> parts = segment_records([rec, rec])
    >>> len(parts), [sum(i == j for i, _ in parts) for j in (0, 1)]
    (32, [16, 16])
    """
    shares = _segment_shares([max(rec.y.size // SEGMENT, 1) for rec in records])
    parts: list[tuple[int, IORecord]] = []
    for i, (rec, share) in enumerate(zip(records, shares, strict=True)):
        n = rec.y.size
        for a in list(range(0, max(n - SEGMENT, 0) + 1, SEGMENT))[:share]:
            b = n if a + 2 * SEGMENT > n else a + SEGMENT
            parts.append((i, IORecord(rec.t[a:b], rec.u[a:b], rec.y[a:b], rec.name)))
    return parts


def _segment_shares(counts: list[int]) -> list[int]:
    """How many of the :data:`MAX_SEGMENTS` segments each record gives, of the `counts` it
    holds: all where they fit, else in proportion to them (largest remainders), every record
    one at least while there are enough, the first records' where there are not."""
    total = sum(counts)
    if total <= MAX_SEGMENTS:
        return list(counts)
    if len(counts) >= MAX_SEGMENTS:
        return [1 if i < MAX_SEGMENTS else 0 for i in range(len(counts))]
    spare = MAX_SEGMENTS - len(counts)  # one each, the rest by what is left of each count
    ideal = [spare * (c - 1) / (total - len(counts)) for c in counts]
    shares = [1 + int(x) for x in ideal]
    by_remainder = sorted(range(len(counts)), key=lambda i: (int(ideal[i]) - ideal[i], i))
    for i in by_remainder[:MAX_SEGMENTS - sum(shares)]:
        shares[i] += 1
    return shares
