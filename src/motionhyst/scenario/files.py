"""The files a scenario or a study TOML reads: what no command may write over.

A scenario reads its own TOML and, for a measured plant, the FRF file ``[plant] file``; a
study reads its TOML, the scenario its ``scenario`` key names and that scenario's files.
Each writer lists these among its inputs (:func:`motionhyst.io.outputs.check_not_input`)
before it computes anything, so that ``--force`` replaces only the command's own output:
``scan --time-series frf.csv --force`` once replaced the measured FRF the scenario named.

The TOML is read leniently here: a file that does not parse lists itself alone, and its
errors are the scenario reader's to report (:func:`motionhyst.scenario.load_scenario`).

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> folder = Path(tempfile.mkdtemp())
>>> _ = (folder / "measured.toml").write_text('[plant]\\nfile = "frf.csv"\\n')
>>> _ = (folder / "study.toml").write_text('scenario = "measured.toml"\\n')
>>> [p.name for p in read_files(folder / "study.toml")]
['study.toml', 'measured.toml', 'frf.csv']
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

__all__ = ["read_files"]


def _table(path: Path) -> dict:
    """The TOML at `path` as a table, or an empty one where it cannot be read or parsed."""
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, ValueError):
        return {}


def _named(value, folder: Path) -> Path | None:
    """A file name written in a TOML, resolved against the TOML's folder (None: not a name)."""
    if not isinstance(value, str) or not value:
        return None
    path = Path(value)
    return path if path.is_absolute() else folder / path


def read_files(path: str | os.PathLike | None) -> list[Path]:
    """The files a scenario or study TOML at `path` reads: itself, a study's scenario, a
    scenario's measured plant (``[plant] file``), each resolved against its TOML's folder.

    Parameters
    ----------
    path : str, os.PathLike or None
        A scenario or study TOML (None: the built-in scenario, which reads no user file).

    Returns
    -------
    list of Path
        `path` first, then the files it names (whether or not they exist).
    """
    if path is None:
        return []
    first = Path(path)
    files, todo = [first], [first]
    while todo:
        toml = todo.pop()
        data = _table(toml)
        plant = data.get("plant")
        named = [_named(data.get("scenario"), toml.parent),
                 _named(plant.get("file"), toml.parent) if isinstance(plant, dict) else None]
        for f in named:
            if f is not None and f not in files:
                files.append(f)
                if f.suffix.lower() == ".toml":
                    todo.append(f)
    return files
