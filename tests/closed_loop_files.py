"""A closed-loop record and the paper's scenario as the files a command reads (issue 26).

The closed-loop tests that run ``identify rec.csv --scenario s.toml`` on a simulated record
write the same two files: :func:`closed_loop_files` gives them, for
:func:`file_trees.populate`.
"""

from __future__ import annotations

import numpy as np


def record_csv(t: np.ndarray, y1: np.ndarray, u: np.ndarray) -> str:
    """A closed-loop record's CSV text: the header ``time,y1,u`` and a row a sample, each
    value written exactly (``repr``)."""
    rows = np.column_stack([t, y1, u])
    return "time,y1,u\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                   for row in rows)


def closed_loop_files(t: np.ndarray, y1: np.ndarray, u: np.ndarray,
                      scenario: str | None = None) -> dict[str, str]:
    """``rec.csv`` (the record) and ``s.toml`` (`scenario`, default the paper's, Table I)."""
    if scenario is None:
        from motionhyst.scenario import default_scenario_path

        scenario = default_scenario_path().read_text()
    return {"s.toml": scenario, "rec.csv": record_csv(t, y1, u)}
