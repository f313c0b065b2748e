"""Exports of a study's results: a CSV table (one row a point) and netCDF.

In the table, a complex field ``e1`` becomes ``e1_abs`` and ``e1_deg``; in netCDF (version 3,
which has no complex numbers) ``e1_real`` and ``e1_imag``.
"""

from __future__ import annotations

import io
import json

import numpy as np

from motionhyst.core.textfiles import csv_header, csv_rows
from motionhyst.study.store import field_names

__all__ = ["to_netcdf_bytes", "to_table"]


def to_table(ds) -> str:
    """CSV text: the axes' values under their keys (and the sampled keys), each output, status.

    Parameters
    ----------
    ds : xarray.Dataset
        The results (:func:`motionhyst.study.open_results`).

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"e1": (("frequency_hz",), np.array([1 + 1j, 2j])),
    ...                  "status": (("frequency_hz",), np.array([1, 1], np.int8))},
    ...                 coords={"frequency_hz": [5.0, 10.0]})
    >>> print(to_table(ds), end="")
    frequency_hz,e1_abs,e1_deg,status
    5,1.4142135623730951,45,1
    10,2,90,1
    """
    dims = list(ds["status"].dims)
    grids = np.meshgrid(*[ds[d].values for d in dims], indexing="ij")
    cols: dict[str, np.ndarray] = {d: gr.ravel() for d, gr in zip(dims, grids, strict=True)}
    if "sample" in dims:
        k = dims.index("sample")
        sidx = np.meshgrid(*[np.arange(ds.sizes[d]) for d in dims], indexing="ij")[k].ravel()
        drawn = [str(n) for n, c in ds.coords.items() if c.dims == ("sample",) and n != "sample"]
        joint = json.loads(ds.attrs.get("joint", "null")) or {}
        order = [*json.loads(ds.attrs.get("samples", "{}")), *joint.get("keys", [])]
        for name in sorted(drawn, key=lambda n: order.index(n) if n in order else len(order)):
            cols[name] = ds[name].values[sidx]  # in the order they are drawn
    for name in field_names(ds):
        v = ds[name].values.ravel()
        if np.iscomplexobj(v):
            cols[f"{name}_abs"] = np.abs(v)
            cols[f"{name}_deg"] = np.degrees(np.angle(v))
        else:
            cols[str(name)] = v
    cols["status"] = ds["status"].values.ravel()
    buf = io.StringIO()
    csv_header(buf, list(cols))
    names = {k: c for k, c in cols.items() if np.asarray(c).dtype.kind in "UTO"}  # compensation
    if not names:
        csv_rows(buf, np.column_stack([np.asarray(c, dtype=float) for c in cols.values()]),
                 fmt=None)
        return buf.getvalue()
    numbers = io.StringIO()
    csv_rows(numbers, np.column_stack([np.asarray(c, dtype=float) if k not in names
                                       else np.zeros(len(c)) for k, c in cols.items()]),
             fmt=None)
    at = [list(cols).index(k) for k in names]
    for row, line in enumerate(numbers.getvalue().splitlines()):
        cells = line.split(",")
        for j, k in zip(at, names, strict=True):
            cells[j] = str(names[k][row])
        buf.write(",".join(cells) + "\n")
    return buf.getvalue()


def to_netcdf_bytes(ds) -> bytes:
    """The results as a netCDF-3 file's bytes (complex fields split into real and imaginary).

    Parameters
    ----------
    ds : xarray.Dataset
        The results (:func:`motionhyst.study.open_results`).

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"e1": (("frequency_hz",), np.array([1 + 1j, 2j])),
    ...                  "status": (("frequency_hz",), np.array([1, 1], np.int8))},
    ...                 coords={"frequency_hz": [5.0, 10.0]})
    >>> to_netcdf_bytes(ds)[:3]
    b'CDF'
    """
    out = ds.copy()
    for name in list(out.data_vars):
        if np.iscomplexobj(out[name].values):
            v = out[name]
            out[f"{name}_real"] = v.real
            out[f"{name}_imag"] = v.imag
            out = out.drop_vars(name)
    for name in list(out.variables):
        out[name].encoding = {}
    return bytes(out.to_netcdf(engine="scipy"))
