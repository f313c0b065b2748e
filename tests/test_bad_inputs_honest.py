"""The hostile corpus over answers from nothing and the readers' leftovers (issue 26): one
record given twice, records that determine nothing, files read by what they hold.

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2, one
line on stderr naming the cause (no traceback), nothing on stdout, and every file there
before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

FS = 1000.0


def _csv(columns: dict[str, np.ndarray]) -> str:
    """A CSV record with a header of the `columns`' names."""
    rows = np.column_stack(list(columns.values()))
    return ",".join(columns) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                              for row in rows)


def _axis(n: int = 600) -> str:
    """An input-output record of a 2 kg axis (made up: the cases are refused before any fit)."""
    t = np.arange(n) / FS
    force = 30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
    y = np.cumsum(np.cumsum(force - force.mean())) / (2 * FS**2)
    return _csv({"time": t, "force": force, "displacement": y})


def _link(path) -> None:
    """A symbolic link ``l.csv`` beside `path` pointing to ``a.csv``."""
    path.symlink_to("a.csv")


IO = ["--record", "input-output"]
TWICE = "a record given twice counts its samples twice (standard errors too small)"

# (id, extra files, argv, words of the one line on stderr); a file given as a callable is
# made by it (path) -> None
CASES = [
    # ------------------------ one record given twice: its standard errors sqrt(2) too small
    ("record-given-twice", {}, ["identify", "a.csv", "a.csv", *IO],
     ["identify: a.csv is given twice: " + TWICE]),
    ("record-twice-through-a-link", {"l.csv": _link}, ["identify", "a.csv", "l.csv", *IO],
     ["identify: a.csv and l.csv are the same file: " + TWICE]),
    ("record-copied", {"b.csv": _axis()}, ["identify", "a.csv", "b.csv", *IO],
     ["identify: a.csv and b.csv hold the same record byte for byte: " + TWICE]),
    ("record-copied-force-displacement", {"b.csv": _axis()},
     ["identify", "a.csv", "b.csv", "--model", "dahl"], ["a.csv and b.csv hold the same"]),
]
BASE = {"a.csv": _axis(), "notes.txt": "my notes"}


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv, words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**BASE, **{k: v for k, v in files.items() if not callable(v)}})
    for name, make in files.items():
        if callable(make):
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            make(root / name)
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before
    assert [p.name for p in tmp_path.iterdir()] == ["user"]
