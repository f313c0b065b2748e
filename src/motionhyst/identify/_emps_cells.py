"""The cells of the EMPS benchmark's table (:class:`~motionhyst.identify.emps.EMPSBenchmark`):
a model's parameters as the reference model writes them, and the rows of models that failed."""

from __future__ import annotations

from collections.abc import Sequence

from motionhyst.core.textfmt import g, table

__all__ = ["failed_table", "friction", "marked", "offset", "own", "viscous"]


def viscous(p: dict) -> str:
    """``c``, or ``c+/c-`` (forward/backward) for direction-dependent viscous friction."""
    c = p.get("c")
    if c is None and "c_pos" in p:  # the asymmetric reference model's own
        return f"{g(p['c_pos'], 4)}/{g(p['c_neg'], 4)}"
    if c is None or not {"c_pos", "c_neg", "c_skew"} & set(p):
        return g(c, 4)
    d = p.get("c_skew", 0.0)
    return f"{g(c + d + p.get('c_pos', 0.0), 4)}/{g(c - d + p.get('c_neg', 0.0), 4)}"


def offset(p: dict) -> str:
    """``OF``, or ``OF + rate t`` [N, N/s] for a drifting offset."""
    if "drift" not in p:
        return g(p.get("offset"), 3)
    return f"{g(p['offset'], 3)} {p['drift']:+.2g} t"


def friction(p: dict) -> str:
    """``fc``, or ``fc+/fc-`` for Coulomb friction by direction, or ``-``."""
    if "fc" in p:
        return g(p["fc"], 4)
    if "fc_pos" in p:
        return f"{g(p['fc_pos'], 4)}/{g(p['fc_neg'], 4)}"
    return "-"


def marked(cell: str, std: dict, *names: str) -> str:
    """`cell`, marked when the record does not determine a parameter it shows (its standard
    error None, as the JSON's ``std`` and ``model_std`` say)."""
    return f"{cell} (not determined)" if any(n in std and std[n] is None for n in names) \
        else cell


def own(validation: dict) -> str:
    """The own-offset diagnosis' cell: its RMSE [mm] and the offset [N], or ``-``."""
    found = validation.get("own_offset")
    return "-" if found is None else f"{found['rmse_mm']:.3g} ({found['offset']:.3g} N)"


def failed_table(head: Sequence[str], rows: Sequence[Sequence[str]],
                 failed: dict[int, str]) -> str:
    """:func:`~motionhyst.core.textfmt.table` of `rows`, the row of each index in `failed`
    written as its first cell and ``failed: REASON`` (one line: the numbers it has none of
    are not padded out, and the others' columns keep their widths)."""
    text = table(head, [r if i not in failed else [r[0]] + [""] * (len(r) - 1)
                        for i, r in enumerate(rows)])
    if not failed:
        return text
    width = max(len(head[0]), *(len(r[0]) for r in rows))
    lines = text.split("\n")
    for i, why in failed.items():
        lines[2 + i] = f"{rows[i][0].rjust(width)}  failed: {why}"
    return "\n".join(lines)
