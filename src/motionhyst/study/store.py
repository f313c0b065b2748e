"""The results of a study in a zarr store, written batch by batch and read as an xarray Dataset.

One array per output field over the study's dimensions (complex fields complex), a
``status`` array (0: not computed yet, 1: computed, 2: failed: the point did not converge or
its loop could not be built), the axes as coordinates and the Monte-Carlo samples as
coordinates along ``sample``.  The attributes name the study file, the scenario, the
version, the seed and a fingerprint of the study: the same command on the same store
computes only the points whose status is 0.  Each chunk is written atomically by zarr, values
before status, so a process killed at any moment leaves a store to resume.
"""

from __future__ import annotations

import json
import math
import re
import shutil
import time
import warnings
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from motionhyst.study.outputs import fields_of
from motionhyst.study.spec import REFERENCE_AXES, StudyDefinition, StudyError

__all__ = ["FAILED", "FLUSH_SECONDS", "MISSING", "OK", "REASONS", "ChunkWriter", "StudyStore",
           "field_names", "foreign_entries", "is_os_metadata", "is_study_store", "listed",
           "open_results", "remove_store"]

MISSING, OK, FAILED = 0, 1, 2
"""Values of the ``status`` array."""

REASONS = {
    0: "none",
    1: "the loop at the point's keys could not be built (refused by the scenario, or unstable)",
    2: "the steady state did not converge",
    3: "an output could not be computed at the point",
    4: "a numerical error (overflow, a singular matrix)",
}
"""Values of the ``reason`` array: why a point failed (0 for a point that did not fail)."""

OS_METADATA = {
    ".ds_store": b"\x00\x00\x00\x01Bud1",                    # macOS Finder: a folder's view
    "thumbs.db": b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1",      # Windows Explorer: thumbnails
    "ehthumbs.db": b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1",    # (an OLE compound file each)
    "desktop.ini": b"[",                                       # Windows: a folder's settings
}
"""The files an operating system's file manager writes into a folder it shows, by lower-case
name, each with the first bytes it writes (``desktop.ini``: its first section, after blank
lines and a byte-order mark).  Files named ``._<name>`` are macOS's AppleDouble files
(:data:`APPLE_DOUBLE` first)."""

_NOT_ZARR = re.compile(r"Object at (.+) is not recognized as a component of a Zarr hierarchy\.")
"""zarr's warning on an entry of a group that is neither an array nor a group."""

APPLE_DOUBLE = b"\x00\x05\x16\x07"
"""The first bytes of an AppleDouble file (macOS's resource fork of ``<name>`` as ``._<name>``
on a volume that has none)."""

FLUSH_SECONDS = 2.0
"""Least time between two writes of the chunks a run holds open [s] (the first batch is
written at once, a completed chunk when it completes)."""

KIND = "motionhyst-study"
CHUNK_POINTS = 65536


def _chunks(study: StudyDefinition) -> tuple[int, ...]:
    """Chunks of about CHUNK_POINTS points, each a contiguous run of the computing order.

    The extents are given from the axis that varies fastest in :meth:`StudyDefinition.order` (the
    reference axes, the last first, then the other axes, the last first) to the slowest: a
    chunk is whole along every axis faster than the one where it stops, so consecutive
    batches fill one chunk after another and a run holds few chunks open at a time.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [1.0, 2.0, 3.0],
    ...                       "controller.K": [6e6, 7e6]}}, scenario=base)
    >>> st.dims, _chunks(st)
    (('frequency_hz', 'controller.K', 'amplitude'), (3, 2, 1))
    """
    shape = study.shape
    dims = study.dims
    inner = [i for i, d in enumerate(dims) if d in REFERENCE_AXES]
    outer = [i for i, d in enumerate(dims) if d not in REFERENCE_AXES]
    chunks = [1] * len(shape)
    size = 1
    for i in inner[::-1] + outer[::-1]:
        n = max(1, min(shape[i], CHUNK_POINTS // size))
        chunks[i] = n
        size *= n
        if n < shape[i]:
            break
    return tuple(chunks)


class StudyStore:
    """A zarr store of one study's results (create with :meth:`create`, reopen with
    :meth:`open`).

    Parameters
    ----------
    path : Path
        The store's folder.
    group : zarr.Group
        The opened store.

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from pathlib import Path
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict(
    ...     {"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> store = StudyStore.create(Path(tempfile.mkdtemp()) / "s.zarr", st)
    >>> store.write([1], np.array([OK], np.int8), {"error_rms": np.array([2.0e-9])})
    >>> store.missing().tolist()                           # flat indices still to compute
    [0]
    """

    def __init__(self, path: Path, group) -> None:
        self.path = Path(path)
        self.group = group
        self.fields = _check_layout(path, group)
        self.shape = tuple(group["status"].shape)

    @classmethod
    def create(cls, path: str | Path, study: StudyDefinition, version: str = "") -> StudyStore:
        """A new store for `study` at `path` (which must not exist).

        Parameters
        ----------
        path : str or Path
            Where to create it.
        study : Study
            The study whose results it holds.
        version : str
            The package version, kept as an attribute.
        """
        import zarr

        path = Path(path)
        g = zarr.open_group(str(path), mode="w-", zarr_format=3)
        dims = study.dims
        chunks = _chunks(study)
        fields = fields_of(study.outputs)
        for name, kind in fields.items():
            dtype, fill = (("complex128", complex(np.nan, np.nan)) if kind == "complex"
                           else ("float64", np.nan))
            g.create_array(name, shape=study.shape, chunks=chunks, dtype=dtype,
                           fill_value=fill, dimension_names=dims)
        g.create_array("status", shape=study.shape, chunks=chunks, dtype="int8",
                       fill_value=MISSING, dimension_names=dims)
        g["status"].attrs["flag_values"] = [MISSING, OK, FAILED]
        g["status"].attrs["flag_meanings"] = "missing computed failed"
        g.create_array("reason", shape=study.shape, chunks=chunks, dtype="int8",
                       fill_value=0, dimension_names=dims)
        g["reason"].attrs["flag_values"] = list(REASONS)
        g["reason"].attrs["flag_meanings"] = json.dumps(REASONS)
        for key, values in study.axes.items():  # the numbers' or, scan.compensation, the names
            a = g.create_array(key, shape=values.shape, dimension_names=(key,),
                               dtype=str if values.dtype.kind == "U" else "float64")
            a[:] = values
        if study.sampled_keys:
            s = g.create_array("sample", shape=(study.n_samples,), dtype="int64",
                               dimension_names=("sample",))
            s[:] = np.arange(study.n_samples)
            for j, key in enumerate(study.sampled_keys):
                a = g.create_array(key, shape=(study.n_samples,), dtype="float64",
                                   dimension_names=("sample",))
                a[:] = study.sample_values[:, j]
        g.attrs.update({
            "kind": KIND, "fingerprint": study.fingerprint(), "fields": json.dumps(fields),
            "study": study.source, "scenario": study.scenario_source,
            "scenario_json": json.dumps(study.scenario), "outputs": json.dumps(study.outputs),
            "samples": json.dumps({k: list(v) for k, v in study.samples.items()}),
            "joint": json.dumps(None if study.joint is None else study.joint.to_dict()),
            "n_samples": study.n_samples, "seed": study.seed, "version": version,
            "coordinates": " ".join(study.sampled_keys), "failures": "{}"})
        return cls(path, g)

    @classmethod
    def open(cls, path: str | Path) -> StudyStore:
        """An existing store; :class:`StudyError` if `path` is not a study's store.

        Parameters
        ----------
        path : str or Path
            The store's folder.
        """
        path = Path(path)
        if not is_study_store(path):  # decided before zarr loads
            raise StudyError(f"{path}: not a store of motionhyst study")
        import zarr

        try:
            group = zarr.open_group(str(path), mode="r+", zarr_format=3)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise _damaged(path, f"{type(exc).__name__}: {exc}") from None
        return cls(path, group)

    def matches(self, study: StudyDefinition) -> bool:
        """Whether the store holds `study` (same scenario, axes, samples and outputs).

        Parameters
        ----------
        study : Study
            The study to compare with.
        """
        return self.group.attrs.get("fingerprint") == study.fingerprint()

    @property
    def n_points(self) -> int:
        """Number of points of the study."""
        return math.prod(self.shape)

    def status(self) -> NDArray[np.int8]:
        """The status of every point, flat (C order); :class:`StudyError` if the store's
        chunks cannot be read or hold another value than :data:`MISSING`, :data:`OK` or
        :data:`FAILED`."""
        try:
            st = np.asarray(self.group["status"][...]).ravel()
        except (RuntimeError, ValueError) as exc:
            if not _in_codec(exc):  # not the data (no thread to be had, ...): as it is
                raise
            raise _damaged(self.path, f"its status cannot be read: {exc}") from None
        odd = np.flatnonzero((st != MISSING) & (st != OK) & (st != FAILED))
        if odd.size:
            raise _damaged(self.path, f"status {int(st[odd[0]])} at point {int(odd[0])}")
        return st

    def missing(self, order: NDArray[np.int64] | None = None) -> NDArray[np.int64]:
        """Flat indices of the points not computed yet, in `order` (default C order).

        Parameters
        ----------
        order : ndarray of int, optional
            The order to return them in (default C order).
        """
        st = self.status()
        if order is None:
            return np.flatnonzero(st == MISSING)
        return order[st[order] == MISSING]

    @property
    def arrays(self) -> list[str]:
        """The store's arrays over the study's dimensions, in the order a write goes: the
        output fields, ``reason`` (stores of older versions lack it), then ``status``."""
        names = list(self.fields)
        if "reason" in self.group:
            names.append("reason")
        return [*names, "status"]

    def write(self, indices, status: NDArray[np.int8], values: dict[str, NDArray],
              reason: NDArray[np.int8] | None = None) -> None:
        """Write one batch at once: the fields of the points at the flat `indices`, the
        reasons of those that failed, then their status (a run writes through
        :meth:`writer`, which gathers batches into whole chunks).

        Parameters
        ----------
        indices : array_like of int
            Flat (C-order) indices of the points.
        status : ndarray of int8
            :data:`OK` or :data:`FAILED` per point.
        values : dict of str to ndarray
            Each output field per point.
        reason : ndarray of int8, optional
            Why a point failed (:data:`REASONS`); default none.
        """
        idx = np.unravel_index(np.asarray(indices, dtype=np.int64), self.shape)
        given = {**values, "status": np.asarray(status, dtype=np.int8),
                 "reason": (np.zeros(len(idx[0]), np.int8) if reason is None
                            else np.asarray(reason, dtype=np.int8))}
        try:
            for name in self.arrays:
                self.group[name].vindex[idx] = given[name]
        except KeyError as exc:
            raise StudyError(f"{self.path}: the store lost its array {exc} while the study ran "
                             f"(removed by another program?)") from None

    def writer(self, flush_seconds: float = FLUSH_SECONDS) -> ChunkWriter:
        """A :class:`ChunkWriter` of this store (use it as a context manager).

        Parameters
        ----------
        flush_seconds : float
            Least time between two writes of the chunks it holds open [s].
        """
        return ChunkWriter(self, flush_seconds)

    def failures(self) -> dict[int, str]:
        """The message of the first failed point of each reason (:data:`REASONS`)."""
        return {int(k): v for k, v in json.loads(self.group.attrs.get("failures", "{}")).items()}


class ChunkWriter:
    """Gathers batches of results into whole chunks of the store and writes each chunk at
    once: when it is complete, and the chunks still open at most every `flush_seconds`
    (the first batch at once), and when the writer closes (also on Ctrl-C).

    A chunk is read once when a batch first reaches it (a resumed store keeps its points),
    then written whole, each array in one call, values before ``reason`` and ``status``: a
    process killed at any moment leaves every chunk either old or new, and loses at most the
    results of the last `flush_seconds`.  The writer holds only the chunks still open; with
    the store's chunks in the computing order (:func:`_chunks`) that is one or two, whatever
    the size of the study.

    Parameters
    ----------
    store : StudyStore
        The store to write.
    flush_seconds : float
        Least time between two writes of the open chunks [s]; the time is raised to 20 times
        the last write's, so writing never takes more than 5 % of a run.

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict(
    ...     {"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> store = StudyStore.create(Path(tempfile.mkdtemp()) / "s.zarr", st)
    >>> with store.writer() as w:
    ...     w.add([1], np.array([OK], np.int8), {"error_rms": np.array([2.0e-9])})
    ...     w.open_chunks
    1
    >>> store.missing().tolist()
    [0]
    """

    def __init__(self, store: StudyStore, flush_seconds: float = FLUSH_SECONDS) -> None:
        self.store = store
        self.flush_seconds = float(flush_seconds)
        self.chunks = tuple(store.group["status"].chunks)
        self.grid = tuple(math.ceil(n / c) for n, c in zip(store.shape, self.chunks,
                                                            strict=True))
        self.names = store.arrays
        self._open: dict[int, dict[str, NDArray]] = {}
        self._dirty: set[int] = set()
        self._failures = store.failures()
        self._new_failure = False
        self._last: float | None = None
        self._interval = self.flush_seconds
        self.most_open = 0

    @property
    def open_chunks(self) -> int:
        """Chunks held in memory (:attr:`most_open`: the most at once so far)."""
        return len(self._open)

    def _region(self, key: int) -> tuple[slice, ...]:
        pos = np.unravel_index(key, self.grid)
        return tuple(slice(p * c, min((p + 1) * c, n))
                     for p, c, n in zip(pos, self.chunks, self.store.shape, strict=True))

    def _block(self, key: int) -> dict[str, NDArray]:
        block = self._open.get(key)
        if block is None:
            region = self._region(key)
            block = {name: np.array(self.store.group[name][region]) for name in self.names}
            self._open[key] = block
            self.most_open = max(self.most_open, len(self._open))
        return block

    def add(self, indices, status: NDArray[np.int8], values: dict[str, NDArray],
            reason: NDArray[np.int8] | None = None, failures: dict[int, str] | None = None
            ) -> None:
        """Take one batch; write the chunks it completes, and the open ones when due.

        Parameters
        ----------
        indices, status, values, reason
            The batch, as :meth:`StudyStore.write` takes it.
        failures : dict of int to str, optional
            A reason to the message of a point that failed for it (the store keeps the first
            of each reason).
        """
        idx = np.unravel_index(np.asarray(indices, dtype=np.int64), self.store.shape)
        keys = np.ravel_multi_index(tuple(i // c for i, c in zip(idx, self.chunks,
                                                                  strict=True)), self.grid)
        given = {**values, "status": np.asarray(status, dtype=np.int8),
                 "reason": (np.zeros(len(keys), np.int8) if reason is None
                            else np.asarray(reason, dtype=np.int8))}
        for key in np.unique(keys):
            key = int(key)
            sel = keys == key
            block = self._block(key)
            local = tuple(i[sel] - r.start for i, r in zip(idx, self._region(key),
                                                             strict=True))
            for name in self.names:
                block[name][local] = given[name][sel]
            if not np.any(block["status"] == MISSING):
                self._write(key)
                del self._open[key]
                self._dirty.discard(key)
            else:
                self._dirty.add(key)
        for code, message in (failures or {}).items():
            if code not in self._failures:
                self._failures[int(code)] = message
                self._new_failure = True
        now = time.monotonic()
        if self._last is None or now - self._last >= self._interval:
            self.flush()

    def _write(self, key: int) -> None:
        region = self._region(key)
        block = self._open[key]
        try:
            for name in self.names:
                self.store.group[name][region] = block[name]
        except KeyError as exc:
            raise StudyError(f"{self.store.path}: the store lost its array {exc} while the "
                             f"study ran (removed by another program?)") from None

    def flush(self) -> None:
        """Write the chunks changed since the last write."""
        t0 = time.monotonic()
        for key in sorted(self._dirty):
            self._write(key)
        self._dirty.clear()
        if self._new_failure:
            self.store.group.attrs["failures"] = json.dumps(
                {str(k): v for k, v in sorted(self._failures.items())})
            self._new_failure = False
        self._last = time.monotonic()
        self._interval = max(self.flush_seconds, 20.0 * (self._last - t0))

    def __enter__(self) -> ChunkWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.flush()


def _in_codec(exc: BaseException) -> bool:
    """Whether `exc` was raised while a chunk was decoded (its bytes are not what its array's
    codecs wrote: a chunk cut short or replaced), not by anything else on the way."""
    tb = exc.__traceback__
    while tb is not None:
        name = tb.tb_frame.f_code.co_filename.replace("\\", "/")
        if "/numcodecs/" in name or "/zarr/codecs/" in name:
            return True
        tb = tb.tb_next
    return False


def _damaged(path: str | Path, what: str) -> StudyError:
    """The error for a store that is a study's but cannot be used as one (`what` is wrong)."""
    return StudyError(f"{path}: a damaged study store ({what})")


def _check_layout(path: str | Path, group) -> dict[str, str]:
    """The output fields of the study store `group` at `path` (name: kind), checked against its
    arrays: each field and ``status`` there, of one shape and of their type; else
    :class:`StudyError` (:func:`_damaged`) before anything reads or writes them.

    Parameters
    ----------
    path : str or Path
        The store's folder, for the message.
    group : zarr.Group
        The opened store.
    """
    try:
        fields = json.loads(group.attrs["fields"])
    except KeyError:
        raise _damaged(path, "no 'fields' attribute") from None
    except (TypeError, ValueError):
        raise _damaged(path, "its 'fields' attribute is not JSON") from None
    if not isinstance(fields, dict) or not fields or not all(
            isinstance(k, str) and v in ("real", "complex") for k, v in fields.items()):
        raise _damaged(path, "its 'fields' attribute names no output fields")
    want = {**{name: "complex128" if kind == "complex" else "float64"
               for name, kind in fields.items()}, "status": "int8"}
    shape, first = None, ""
    for name, dtype in want.items():
        try:
            array = group[name]
            got, here = str(array.dtype), tuple(array.shape)
        except (KeyError, AttributeError, TypeError, ValueError):
            raise _damaged(path, f"no array {name!r}") from None
        if got != dtype:
            raise _damaged(path, f"array {name!r} holds {got}, not {dtype}")
        if shape is not None and here != shape:
            raise _damaged(path, f"array {name!r} has shape {here}, {first!r} {shape}")
        shape, first = (here, name) if shape is None else (shape, first)
    dims = getattr(group["status"].metadata, "dimension_names", None) or ()
    for dim, n in zip(dims, shape, strict=False):  # the axes' values, one per point along each
        axis = group.get(dim) if dim is not None else None
        if axis is None or tuple(axis.shape) != (n,):
            raise _damaged(path, f"the axis {dim!r} does not have the {n} values of status")
    return fields


def is_study_store(path: str | Path) -> bool:
    """Whether `path` is a folder holding a study's zarr store.

    Parameters
    ----------
    path : str or Path
        The folder.

    Examples
    --------
    >>> import tempfile
    >>> is_study_store(tempfile.mkdtemp())
    False
    """
    meta = Path(path) / "zarr.json"
    try:
        return json.loads(meta.read_text()).get("attributes", {}).get("kind") == KIND
    except (OSError, ValueError, AttributeError, RecursionError):  # RecursionError: nested
        return False                                                # thousands of levels deep


def is_os_metadata(entry: Path) -> bool:
    """Whether `entry` is a file an operating system wrote into a folder it showed: a regular
    file (not a link) named as one of :data:`OS_METADATA` or ``._<name>`` whose first bytes are
    those the system writes.  A user's file of that name holding anything else is not one.

    Parameters
    ----------
    entry : Path
        A folder's entry.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / ".DS_Store").write_bytes(OS_METADATA[".ds_store"] + bytes(8))
    >>> _ = (folder / "Thumbs.db").write_text("my notes")
    >>> is_os_metadata(folder / ".DS_Store"), is_os_metadata(folder / "Thumbs.db")
    (True, False)
    """
    name = entry.name.lower()
    if name.startswith("._"):
        magic = APPLE_DOUBLE
    elif name in OS_METADATA:
        magic = OS_METADATA[name]
    else:
        return False
    if entry.is_symlink() or not entry.is_file():  # never open a FIFO, a device or a link
        return False
    try:
        with entry.open("rb") as f:
            head = f.read(512)
    except OSError:
        return False
    if name == "desktop.ini":  # text, often UTF-16 with a byte-order mark, blank lines first
        for bom, codec in ((b"\xff\xfe", "utf-16-le"), (b"\xef\xbb\xbf", "utf-8")):
            if head.startswith(bom):
                head = head[len(bom):].decode(codec, errors="replace").encode()
                break
        head = head.lstrip(b"\r\n\t \x00")
    return head.startswith(magic)


def foreign_entries(path: str | Path) -> list[str]:
    """The entries of the store folder `path` that are not the store's: anything beside its
    ``zarr.json`` and its arrays' folders (each a ``zarr.json`` and its chunks ``c``), such
    as a user's notes put there.  A store replaced with ``--force`` would take them with it.
    The files a file manager writes into a folder it shows (:func:`is_os_metadata`: macOS's
    ``.DS_Store`` and ``._*``, Windows's ``Thumbs.db`` and ``desktop.ini``) are not the user's:
    they go with the store.

    Parameters
    ----------
    path : str or Path
        A study's store folder.

    Returns
    -------
    list of str
        Their names relative to `path`, sorted (empty for a store as a study wrote it).

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "zarr.json").write_text("{}")
    >>> (folder / "e1" / "c").mkdir(parents=True)
    >>> _ = (folder / "e1" / "zarr.json").write_text("{}")
    >>> _ = (folder / "notes.txt").write_text("my notes")
    >>> foreign_entries(folder)
    ['notes.txt']
    """
    path = Path(path)
    out = []
    for entry in sorted(path.iterdir()):
        if ((entry.name == "zarr.json" and entry.is_file() and not entry.is_symlink())
                or is_os_metadata(entry)):
            continue
        if not (entry.is_dir() and not entry.is_symlink() and (entry / "zarr.json").is_file()):
            out.append(entry.name)
            continue
        out.extend(f"{entry.name}/{inner.name}" for inner in sorted(entry.iterdir())
                   if not ((inner.name in ("zarr.json", "c") and not inner.is_symlink()
                           and (inner.is_file() if inner.name == "zarr.json"
                                else inner.is_dir())) or is_os_metadata(inner)))
    return out


def remove_store(path: str | Path) -> None:
    """Delete a study's store (refuses anything else).

    Parameters
    ----------
    path : str or Path
        The store's folder.

    Examples
    --------
    >>> import tempfile
    >>> try:
    ...     remove_store(tempfile.mkdtemp())
    ... except StudyError as exc:
    ...     print(str(exc).endswith("not a store of motionhyst study; refusing to delete it"))
    True
    """
    if not is_study_store(path):
        raise StudyError(f"{path}: not a store of motionhyst study; refusing to delete it")
    foreign = foreign_entries(path)
    if foreign:
        raise StudyError(f"{path}: holds {listed(foreign)}, not the store's; refusing to "
                         f"delete it")
    shutil.rmtree(path)


def listed(names: list[str]) -> str:
    """The first of `names` and how many more (for a message of one line).

    Parameters
    ----------
    names : list of str
        At least one name.

    Examples
    --------
    >>> listed(["notes.txt"]), listed(["a.txt", "e1/b.txt", "c.txt"])
    ('notes.txt', 'a.txt and 2 more')
    """
    return names[0] + (f" and {len(names) - 1} more" if len(names) > 1 else "")


def field_names(ds) -> list[str]:
    """The output fields of a study's Dataset, in the order of the study's outputs.

    Parameters
    ----------
    ds : xarray.Dataset
        The results (:func:`open_results`).

    Examples
    --------
    >>> import xarray as xr
    >>> field_names(xr.Dataset(attrs={"fields": '{"e1": "complex", "error_rms": "real"}'}))
    ['e1', 'error_rms']
    """
    if "fields" in ds.attrs:
        return list(json.loads(ds.attrs["fields"]))
    return [str(n) for n in ds.data_vars if n != "status"]


def open_results(path: str | Path):
    """The results of a study store as an :class:`xarray.Dataset` (loaded in memory).

    Points not computed yet and points that failed are NaN; ``status`` says which.

    Parameters
    ----------
    path : str or Path
        The store's folder.

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> from motionhyst.study import run_study
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = StudyDefinition.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> path = Path(tempfile.mkdtemp()) / "s.zarr"
    >>> _ = run_study(st, path, workers=0)
    >>> ds = open_results(path)
    >>> ds["e1"].dims, str(ds["e1"].dtype)
    (('frequency_hz', 'amplitude'), 'complex128')
    """
    StudyStore.open(path).status()  # a damaged store is named as such, not by xarray
    import xarray as xr  # loaded once the store is one (pandas with it)

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ds = xr.open_zarr(str(path), consolidated=False, mask_and_scale=False).load()
    except (RuntimeError, ValueError) as exc:
        if not _in_codec(exc):
            raise
        raise StudyError(f"{_damaged(path, f'its values cannot be read: {exc}')}; remove it (a "
                         f"study run again computes every point)") from None
    for w in caught:  # zarr's word on a file manager's .DS_Store beside the arrays is dropped
        name = _NOT_ZARR.fullmatch(str(w.message))
        if not (name and is_os_metadata(Path(path) / name[1])):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return ds
