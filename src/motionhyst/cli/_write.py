"""Writing a result file for a command: atomic, asked for with --force, never an input."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path


def write_text(path: str | os.PathLike, text: str, *, force: bool,
               inputs: Iterable[str | os.PathLike] = (), option: str = "--out") -> None:
    """Write `text` to `path` through a temporary file in its folder and :func:`os.replace`.

    Raises ``ValueError`` (one line naming the option and the path) if `path`
    is one of `inputs`, a folder, or exists without `force`.
    """
    target = Path(path)
    for inp in inputs:
        if target.exists() and Path(inp).exists() and os.path.samefile(target, inp):
            raise ValueError(f"{option} {target}: is an input of this command; refusing to "
                             f"overwrite it")
    if target.is_dir():
        raise ValueError(f"{option} {target}: is a folder; give a file name")
    if target.exists() and not force:
        raise ValueError(f"{option} {target} exists; give --force to replace it")
    if not target.parent.is_dir():
        raise ValueError(f"{option} {target}: folder {target.parent} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
