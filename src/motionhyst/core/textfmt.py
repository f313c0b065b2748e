"""Plain-text tables and numbers: how results print themselves (``str(result)``).

Examples
--------
>>> print(table(["f [Hz]", "|E| [-]"], [[g(5.0), g(6.04123)]]))
f [Hz]  |E| [-]
------  -------
     5    6.041
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["g", "table"]


def table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A plain-text table: right-aligned columns under a ruled header.

    Parameters
    ----------
    headers : sequence of str
        Column titles.
    rows : sequence of sequence of str
        The cells, already formatted.

    Examples
    --------
    >>> print(table(["f [Hz]", "|E| [-]"], [["5", "6.041"], ["10", "1.239"]]))
    f [Hz]  |E| [-]
    ------  -------
         5    6.041
        10    1.239
    """
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(headers)]
    line = "  ".join(h.rjust(w) for h, w in zip(headers, widths, strict=True))
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in rows]
    return "\n".join(out)


def g(x: float, digits: int = 4) -> str:
    """`x` with `digits` significant digits; ``nan`` for None or NaN.

    Parameters
    ----------
    x : float or None
        The number.
    digits : int
        Significant digits.

    Examples
    --------
    >>> g(3.14159), g(1234567.0), g(float("nan"))
    ('3.142', '1.235e+06', 'nan')
    """
    return "nan" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}g}"

