"""identify's refusals come before its search, as one line (issue 26: every refusal within
2 s of start, a refusal is one line): a budget of model evaluations below the least the
search needs is refused without the warnings the checks of the records held (a time column
in ms), which the search shows as it starts.

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`) and asserts exit code 2, one line on stderr and nothing on stdout.
"""

from __future__ import annotations

import limited_process
from file_trees import populate
from test_bad_inputs_late import _stage


def test_a_budget_below_the_search_s_least_is_one_line_before_the_warnings(tmp_path):
    """A time column in ms (a warning of the checks) and --max-evaluations 20, below the 29
    the positioning axis's search needs at least (3 for each of its 3 starts, 9 for each of
    two steps, 2 to choose): the refusal alone, one line (it followed the two warnings)."""
    populate(tmp_path, {"ms.csv": _stage(time_unit=1000.0)})
    code, out, err = limited_process.run(["identify", "ms.csv", "--record", "input-output",
                                          "--max-evaluations", "20"], tmp_path)
    assert out == "" and code == 2 and len(err.strip().splitlines()) == 1, err
    assert err.startswith("motionhyst: error: a budget of 20 model evaluations is below the "
                          "least this search needs, 29:"), err
