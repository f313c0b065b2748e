"""A folder of results shared with the user's own files (``motionhyst reproduce --out DIR``):
:class:`OutputFolder` and its manifest :data:`MANIFEST` (the rules: :mod:`motionhyst.io.outputs`).
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterable
from pathlib import Path

from motionhyst.io.leftovers import clean_stale
from motionhyst.io.output_file import (
    OutputError,
    OutputFile,
    Temporary,
    check_name,
    check_not_input,
    check_parents,
    fsync_dir,
    input_paths,
    missing_parents,
    replaceable_link,
    signals_raise,
    stop_if,
)

MANIFEST = "motionhyst-manifest.json"
"""Name of the manifest :class:`OutputFolder` writes into a results folder."""

_MANIFEST_KIND = "motionhyst output folder"


class OutputFolder:
    """A results folder (``reproduce --out DIR``) shared with the user's own files.

    The folder may hold anything; the tool writes only the names it is asked
    to write, records them in :data:`MANIFEST`, and on a later run replaces
    only files that manifest lists (others of the same name need `force`).
    Files of an earlier run that this run does not write again are removed
    only if the manifest lists them.  Files are first staged as temporary
    files in the folder (:meth:`write_bytes`), then moved into place together
    (:meth:`finish`): a failure while writing leaves the earlier files as they
    were and no temporary file.  Used as a context manager, it finishes at the
    end of the block, abandons on an exception, and turns SIGINT and SIGTERM
    into ``KeyboardInterrupt`` meanwhile.

    Parameters
    ----------
    path : str or Path
        The folder; created (with missing parents) if absent.  ``"."`` is fine.
    names : iterable of str
        Every file name this run may write (plain names, no folders).
    force : bool
        Also replace files of those names that the tool did not write, and a symbolic link
        named `path` (the link itself, by a new folder, when the first file is written; put
        back if the run is abandoned; what it points to is never written).
    inputs : iterable of paths
        Files the command reads (never replaced).
    option : str
        The option naming the folder, for messages.

    Raises
    ------
    OutputError
        The path is a regular file or not a folder, a symbolic link and `force` is false, or
        a file to be written exists, was not written by the tool and `force` is false.

    Examples
    --------
    >>> import os, tempfile
    >>> folder = tempfile.mkdtemp()
    >>> open(os.path.join(folder, "notes.txt"), "w").write("mine")
    4
    >>> with OutputFolder(folder, ["report.md"]) as out:
    ...     out.write_text("report.md", "# report")
    >>> sorted(os.listdir(folder))
    ['motionhyst-manifest.json', 'notes.txt', 'report.md']
    """

    def __init__(self, path: str | os.PathLike, names: Iterable[str], force: bool = False,
                 inputs: Iterable[str | os.PathLike | None] = (), option: str = "--out"):
        self.path = Path(path)
        self.option = option
        self.force = force
        self.inputs = input_paths(inputs)
        self.names = list(dict.fromkeys(names))
        label = f"{option} {self.path}"
        if str(path) in ("", "-"):
            raise OutputError(f"{label}: not a folder name")
        check_name(self.path, label)
        for name in self.names:
            if Path(name).name != name or name in ("", ".", "..", MANIFEST):
                raise ValueError(f"not a plain file name: {name!r}")
        # a symbolic link replaced with force: what it held (a new folder in its place)
        self._link = os.readlink(self.path) if replaceable_link(self.path, label, force) \
            else None
        self._link_removed = False
        if self._link is None and self.path.exists() and not self.path.is_dir():
            kind = "a file" if self.path.is_file() else "not a folder"
            raise OutputError(f"{label} is {kind}; give a folder (it is left untouched)")
        check_parents(self.path, label)
        if self._link is None and self.path.is_dir() and not os.access(self.path,
                                                                       os.W_OK | os.X_OK):
            raise OutputError(f"{label}: no permission to write in {self.path}")
        self.previous = self._read_manifest() if self._link is None else set()
        for name in self.names if self._link is None else ():
            target = self.path / name
            if target.is_symlink() or target.exists():
                if target.is_dir() and not target.is_symlink():
                    raise OutputError(f"{label}: {target} is a folder; the tool writes a file "
                                      f"of that name (move it away)")
                if name not in self.previous and not force:
                    raise OutputError(f"{label}: {target} exists and was not written by "
                                      f"motionhyst (not in {MANIFEST}); give --force to "
                                      f"replace it")
            check_not_input(target, self.inputs, option)
        self._staged: list[tuple[str, Temporary]] = []
        self._done: list[str] = []
        self._created: list[Path] = []

    def _read_manifest(self) -> set[str]:
        """Names an earlier run recorded; a manifest that is not ours is ignored."""
        path = self.path / MANIFEST
        if not path.is_file() or path.is_symlink():
            return set()
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError):  # arrays thousands of levels deep
            return set()
        if not isinstance(data, dict) or data.get("kind") != _MANIFEST_KIND:
            return set()
        files = data.get("files", [])
        if not isinstance(files, list):
            return set()
        # only plain names: a manifest never authorises a path outside the folder
        return {f for f in files if isinstance(f, str) and Path(f).name == f
                and f not in ("", ".", "..", MANIFEST)}

    def _ensure_folder(self) -> None:
        if self._link is not None and not self._link_removed:  # replaced, never followed
            try:
                self.path.unlink()
            except OSError as exc:
                raise OutputError(f"cannot replace the link {self.option} {self.path}: "
                                  f"{exc.strerror}") from None
            self._link_removed = True
        if not self.path.exists():
            for folder in missing_parents(self.path):
                try:
                    folder.mkdir()
                except OSError as exc:
                    raise OutputError(f"cannot create {self.option} {folder}: "
                                      f"{exc.strerror}") from None
                self._created.append(folder)

    def _manifest(self, names: Iterable[str]) -> None:
        text = json.dumps({"kind": _MANIFEST_KIND,
                           "note": "files written by motionhyst; a later run replaces "
                                   "these and nothing else in this folder",
                           "files": sorted(set(names))}, indent=2) + "\n"
        OutputFile(self.path / MANIFEST, force=True).write_text(text)

    def write_bytes(self, name: str, data: bytes) -> None:
        """Stage the file `name`: a temporary file in the folder, moved by :meth:`finish`.

        Parameters
        ----------
        name : str
            One of the names the folder was made with.
        data : bytes
            The whole content of the file.
        """
        if name not in self.names:
            raise ValueError(f"{name!r} is not among the names given to OutputFolder")
        self._ensure_folder()
        target = self.path / name
        mode = OutputFile(target, force=True)._mode()
        try:
            if not self._staged:
                clean_stale(self.path)
            tmp = Temporary(self.path, name, mode)
        except OSError as exc:
            raise OutputError(f"cannot write {target}: {exc.strerror}") from None
        self._staged.append((name, tmp))
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(tmp.fd, view):]
            os.fsync(tmp.fd)
        except OSError as exc:
            raise OutputError(f"cannot write {target}: {exc.strerror}") from None

    def write_text(self, name: str, text: str) -> None:
        """Stage the text file `name` (UTF-8), as :meth:`write_bytes`.

        Parameters
        ----------
        name : str
            One of the names the folder was made with.
        text : str
            The whole content of the file.
        """
        self.write_bytes(name, text.encode("utf-8"))

    @property
    def written(self) -> list[str]:
        """Names staged so far."""
        return [name for name, _ in self._staged]

    def finish(self) -> list[str]:
        """Move the staged files into place, record them, remove this tool's stale files.

        The manifest first lists the earlier and the new names (so a run cut
        short between the moves leaves only files the tool knows as its own),
        then the staged files replace their targets, files of the earlier run
        not written again are removed, and the manifest is rewritten with the
        names of this run.

        Returns
        -------
        list of str
            Names of the removed files.
        """
        self._ensure_folder()
        with signals_raise():
            try:
                stop_if(getattr(self, "_received", []))
                self._manifest(self.previous | set(self.written))
                while self._staged:
                    name, tmp = self._staged[0]
                    try:
                        tmp.commit(self.path / name)
                    except OSError as exc:
                        raise OutputError(f"cannot write {self.path / name}: "
                                          f"{exc.strerror}") from None
                    tmp.discard()
                    self._done.append(name)
                    self._staged.pop(0)
            except BaseException:
                self.abandon()
                raise
        fsync_dir(self.path)
        removed = []
        for name in sorted(self.previous - set(self._done)):
            target = self.path / name
            if target.is_file() and not target.is_symlink():
                with contextlib.suppress(OSError):
                    target.unlink()
                    removed.append(name)
        self._manifest(self._done)
        return removed

    def abandon(self) -> None:
        """After a failure: remove the staged files, and folders this run created if empty."""
        for _, tmp in self._staged:
            tmp.discard()
        self._staged.clear()
        for folder in reversed(self._created):
            with contextlib.suppress(OSError):
                if {p.name for p in folder.iterdir()} <= {MANIFEST}:
                    (folder / MANIFEST).unlink(missing_ok=True)
                folder.rmdir()
        if self._link_removed and not (self.path.exists() or self.path.is_symlink()):
            with contextlib.suppress(OSError):  # the link the user had, as it was
                os.symlink(self._link, self.path)
                self._link_removed = False

    def __enter__(self) -> OutputFolder:
        self._signals = signals_raise()
        self._received = self._signals.__enter__()
        try:
            # before the work: a folder that cannot be made fails now, not after it (a
            # folder made here and left empty is removed again)
            self._ensure_folder()
        except BaseException:
            self._signals.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, kind, value, tb) -> None:
        try:
            if kind is None:
                self.finish()
            else:
                self.abandon()
        finally:
            self._signals.__exit__(None, None, None)


__all__ = ["MANIFEST", "OutputFolder"]
