"""JSON output: results as strict JSON (no NaN or Infinity tokens)."""

from __future__ import annotations

import json
import math

import numpy as np


def jsonable(obj):
    """`obj` with numpy scalars made plain and non-finite floats replaced by None."""
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
    """Strict JSON text of `obj`, indented."""
    return json.dumps(jsonable(obj), indent=2, allow_nan=False)
