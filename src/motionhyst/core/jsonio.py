"""JSON output: results as strict JSON (no NaN or Infinity tokens)."""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["dumps", "jsonable"]


def jsonable(obj):
    """`obj` with numpy scalars made plain and non-finite floats replaced by None.

    Parameters
    ----------
    obj : object
        Dictionaries, lists, numbers and strings.

    Examples
    --------
    >>> import numpy as np
    >>> jsonable({"a": np.float64(1.5), "b": float("nan"), "c": [np.int64(2)]})
    {'a': 1.5, 'b': None, 'c': [2]}
    """
    if isinstance(obj, dict):
        return {k: jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, float | np.floating):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def dumps(obj) -> str:
    """Strict JSON text of `obj`, indented.

    Parameters
    ----------
    obj : object
        Dictionaries, lists, numbers and strings.

    Examples
    --------
    >>> print(dumps({"x": float("inf")}))
    {
      "x": null
    }
    """
    return json.dumps(jsonable(obj), indent=2, allow_nan=False)
