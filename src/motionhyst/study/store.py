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
import shutil
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from motionhyst.study.outputs import fields_of
from motionhyst.study.spec import Study, StudyError

__all__ = ["FAILED", "MISSING", "OK", "StudyStore", "field_names", "is_study_store", "open_results",
           "remove_store"]

MISSING, OK, FAILED = 0, 1, 2
"""Values of the ``status`` array."""

KIND = "motionhyst-study"
CHUNK_POINTS = 65536


def _chunks(study: Study) -> tuple[int, ...]:
    """Chunks of about CHUNK_POINTS points, whole along the fastest (reference) axes."""
    shape = study.shape
    chunks = [1] * len(shape)
    size = 1
    for i in sorted(range(len(shape)), key=lambda i: study.dims[i] not in ("amplitude",
                                                                          "frequency_hz")):
        n = max(1, min(shape[i], CHUNK_POINTS // size))
        chunks[i] = n
        size *= n
    return tuple(chunks)


class StudyStore:
    """A zarr store of one study's results (create with :meth:`create`, reopen with
    :meth:`open`).

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from pathlib import Path
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["error_rms"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> store = StudyStore.create(Path(tempfile.mkdtemp()) / "s.zarr", st)
    >>> store.write([1], np.array([OK], np.int8), {"error_rms": np.array([2.0e-9])})
    >>> store.missing().tolist()                           # flat indices still to compute
    [0]
    """

    def __init__(self, path: Path, group) -> None:
        self.path = Path(path)
        self.group = group
        self.shape = tuple(group["status"].shape)
        self.fields = json.loads(group.attrs["fields"])

    @classmethod
    def create(cls, path: str | Path, study: Study, version: str = "") -> StudyStore:
        """A new store for `study` at `path` (which must not exist)."""
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
        for key, values in study.axes.items():
            a = g.create_array(key, shape=values.shape, dtype="float64", dimension_names=(key,))
            a[:] = values
        if study.samples:
            s = g.create_array("sample", shape=(study.n_samples,), dtype="int64",
                               dimension_names=("sample",))
            s[:] = np.arange(study.n_samples)
            for j, key in enumerate(study.samples):
                a = g.create_array(key, shape=(study.n_samples,), dtype="float64",
                                   dimension_names=("sample",))
                a[:] = study.sample_values[:, j]
        g.attrs.update({
            "kind": KIND, "fingerprint": study.fingerprint(), "fields": json.dumps(fields),
            "study": study.source, "scenario": study.scenario_source,
            "scenario_json": json.dumps(study.scenario), "outputs": json.dumps(study.outputs),
            "samples": json.dumps({k: list(v) for k, v in study.samples.items()}),
            "n_samples": study.n_samples, "seed": study.seed, "version": version,
            "coordinates": " ".join(study.samples)})
        return cls(path, g)

    @classmethod
    def open(cls, path: str | Path) -> StudyStore:
        """An existing store; :class:`StudyError` if `path` is not a study's store."""
        import zarr

        path = Path(path)
        if not is_study_store(path):
            raise StudyError(f"{path}: not a store of motionhyst study")
        return cls(path, zarr.open_group(str(path), mode="r+", zarr_format=3))

    def matches(self, study: Study) -> bool:
        """Whether the store holds `study` (same scenario, axes, samples and outputs)."""
        return self.group.attrs.get("fingerprint") == study.fingerprint()

    @property
    def n_points(self) -> int:
        """Number of points of the study."""
        return math.prod(self.shape)

    def status(self) -> NDArray[np.int8]:
        """The status of every point, flat (C order)."""
        return np.asarray(self.group["status"][...]).ravel()

    def missing(self, order: NDArray[np.int64] | None = None) -> NDArray[np.int64]:
        """Flat indices of the points not computed yet, in `order` (default C order)."""
        st = self.status()
        if order is None:
            return np.flatnonzero(st == MISSING)
        return order[st[order] == MISSING]

    def write(self, indices, status: NDArray[np.int8], values: dict[str, NDArray]) -> None:
        """Write one batch: the fields of the points at the flat `indices`, then their status."""
        idx = np.unravel_index(np.asarray(indices, dtype=np.int64), self.shape)
        try:
            for name in self.fields:
                self.group[name].vindex[idx] = values[name]
            self.group["status"].vindex[idx] = np.asarray(status, dtype=np.int8)
        except KeyError as exc:
            raise StudyError(f"{self.path}: the store lost its array {exc} while the study ran "
                             f"(removed by another program?)") from None


def is_study_store(path: str | Path) -> bool:
    """Whether `path` is a folder holding a study's zarr store.

    Examples
    --------
    >>> import tempfile
    >>> is_study_store(tempfile.mkdtemp())
    False
    """
    meta = Path(path) / "zarr.json"
    try:
        return json.loads(meta.read_text()).get("attributes", {}).get("kind") == KIND
    except (OSError, ValueError, AttributeError):
        return False


def remove_store(path: str | Path) -> None:
    """Delete a study's store (refuses anything else).

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
    shutil.rmtree(path)


def field_names(ds) -> list[str]:
    """The output fields of a study's Dataset, in the order of the study's outputs.

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

    Examples
    --------
    >>> import tempfile, tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> from motionhyst.study import run_study
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> path = Path(tempfile.mkdtemp()) / "s.zarr"
    >>> _ = run_study(st, path, workers=0)
    >>> ds = open_results(path)
    >>> ds["e1"].dims, str(ds["e1"].dtype)
    (('frequency_hz', 'amplitude'), 'complex128')
    """
    import xarray as xr

    if not is_study_store(path):
        raise StudyError(f"{path}: not a store of motionhyst study")
    ds = xr.open_zarr(str(path), consolidated=False, mask_and_scale=False).load()
    return ds
