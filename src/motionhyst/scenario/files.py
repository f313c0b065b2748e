"""The files a scenario or a study TOML reads: what no command may write over.

A scenario reads its own TOML and, for a measured plant, the FRF file ``[plant] file``; a
study reads its TOML, the scenario its ``scenario`` key names and that scenario's files, and
the identification its ``[samples] from_identification`` names.
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
from pathlib import Path

from motionhyst.io.inputs import read_toml

__all__ = ["read_files"]


def _table(path: Path) -> dict:
    """The TOML at `path` as a table, or an empty one where it cannot be read or parsed (a
    pipe, a device or a folder is not opened: :func:`~motionhyst.io.inputs.read_toml`)."""
    try:
        return read_toml(path)
    except (OSError, ValueError):  # InputFileError, BudgetError: the reader's to report
        return {}


def _named(value, folder: Path) -> Path | None:
    """A file name written in a TOML, resolved against the TOML's folder (None: not a name)."""
    if not isinstance(value, str) or not value:
        return None
    path = Path(value)
    return path if path.is_absolute() else folder / path


def read_files(path: str | os.PathLike | None) -> list[Path]:
    """The files a scenario or study TOML at `path` reads: itself, a study's scenario and
    ``[samples] from_identification``, a scenario's measured plant (``[plant] file``), each
    resolved against its TOML's folder (a study's scenario's plant against the study's too).

    Parameters
    ----------
    path : str, os.PathLike or None
        A scenario or study TOML (None: the built-in scenario, which reads no user file).

    Returns
    -------
    list of Path
        `path` first, then the files it names (whether or not they exist).

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "s.toml").write_text('[plant]\\nfile = "frf.csv"\\n')
    >>> [p.name for p in read_files(folder / "s.toml")]
    ['s.toml', 'frf.csv']
    """
    if path is None:
        return []
    first = Path(path)
    files, todo = [first], [(first, first.parent)]
    while todo:
        toml, study_folder = todo.pop()
        data = _table(toml)
        plant, samples = data.get("plant"), data.get("samples")
        file = plant.get("file") if isinstance(plant, dict) else None
        scenario = _named(data.get("scenario"), toml.parent)
        # a study reads its scenario's plant file against the study's folder (its
        # base_dir); by itself the scenario reads it against its own: both are inputs
        named = [scenario, _named(file, toml.parent), _named(file, study_folder),
                 _named(samples.get("from_identification"), toml.parent)
                 if isinstance(samples, dict) else None]
        for f in named:
            if f is not None and f not in files:
                files.append(f)
                if f == scenario:
                    todo.append((f, study_folder))
    return files
