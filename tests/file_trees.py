"""A folder of files made from a dictionary, and a snapshot to tell whether a command changed it.

Shared by the bad-input tests: each writes its files, runs a command that must refuse, and
checks that nothing in the folder changed.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path


def populate(root: Path, files: dict) -> None:
    """Write `files` under `root`: ``{name: text or bytes}``, or a maker ``{name: make}`` that
    writes the file (``make(path)``); ``"@symlink:NAME": target`` makes a symbolic link,
    ``"@hard:NAME": existing name`` a hard link, ``"@fifo:NAME": None`` a named pipe."""
    for name, content in files.items():
        if name.startswith("@"):
            kind, link = name[1:].split(":")
            if kind == "symlink":
                (root / link).symlink_to(content)
            elif kind == "fifo":
                os.mkfifo(root / link)
            else:
                (root / link).hardlink_to(root / content)
            continue
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if callable(content):
            content(path)
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)


def snapshot(root: Path) -> dict[str, str]:
    """Every entry under `root`: links by target, files by hash, folders and pipes as such."""
    snap = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            path = Path(dirpath) / name
            rel = str(path.relative_to(root))
            if path.is_symlink():
                snap[rel] = "link:" + os.readlink(path)
            elif path.is_dir():
                snap[rel] = "dir"
            elif not path.is_file():  # a named pipe: reading it would block
                snap[rel] = "special"
            else:
                snap[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
    return snap
