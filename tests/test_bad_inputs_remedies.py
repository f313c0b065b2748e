"""Refusals that name the cause and a remedy the command has (issue 26: "every refusal names
the cause and a remedy the command has"; "misleading messages").

A library function's refusal names its own arguments (``shorten the duration``, ``use more
substeps``); a command reached through it names its options instead, or, where it has none,
the scenario's value to check.  A refusal caused by an implausible ``[stage]`` value names
the value, not the reference.  A record's value that is not finite is named by its column and
sample.

The command lines run in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files; a refusal is exit code 2 and
one line on stderr (no traceback), and every file is byte-identical afterwards.
"""

from __future__ import annotations

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
QUASI_STATIC = ('[stage]\ntype = "quasi-static"\nk = 10.0\n\n'
                '[hysteresis]\nmodel = "jenkins"\nk = 20.0\nfc = 0.05\n')


def _record(columns: dict[str, np.ndarray]) -> str:
    names = list(columns)
    rows = zip(*(columns[n] for n in names), strict=True)
    return ",".join(names) + "\n" + "".join(
        ",".join(repr(float(v)) for v in row) + "\n" for row in rows)


T = np.arange(100) / 100.0
WITH_NAN = 0.01 * np.sin(2 * np.pi * T)
WITH_NAN[50] = np.nan

# (id, the user's files, argv, words of the one line on stderr, words it must not have)
CASES = [
    # ----------------------------- a value that is not finite: its column and sample named
    ("predict-force-of-a-displacement-with-a-nan", {"m.toml": QUASI_STATIC,
                                                    "d.csv": _record({"time": T,
                                                                      "displacement": WITH_NAN})},
     ["predict", "m.toml", "d.csv", "--out", "p.csv"],
     ["d.csv: displacement must be finite: sample 51 (t = 0.5 s) is nan"], ["force"]),
    ("simulate-reference-with-a-nan", {"s.toml": PAPER,
                                       "r.csv": _record({"time": T, "position": WITH_NAN})},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--reference-csv", "r.csv"],
     ["r.csv: the reference's position must be finite: sample 51 is nan"], []),
]


@pytest.mark.parametrize(("files", "argv", "words", "not_words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_refusal_names_the_cause_and_a_remedy_the_command_has(tmp_path, files, argv, words,
                                                                not_words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**files, "notes.txt": "my notes"})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    for word in not_words:
        assert word not in line, (word, line)
    assert snapshot(root) == before
