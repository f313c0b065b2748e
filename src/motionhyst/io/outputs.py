"""Every file the command line writes goes through here: atomic, asked for, never an input.

Rules (issue 10, checked by tests/test_outputs.py and tests/test_bad_inputs.py):

- A file is written to a temporary file in the target's own folder, flushed and
  ``fsync``-ed, then moved over the target with :func:`os.replace`: a reader sees the old
  file or the new one, never half of one.
- An existing target is replaced only when the user asked (``force=True``, the ``--force``
  option); otherwise :class:`OutputError` names it.  A target that is an input of the same
  command (the same file by :func:`os.path.samefile`, hard links and symbolic links
  included) is refused even with ``force``.
- A replaced file keeps its permission bits; a new file gets ``0666`` and a new folder
  ``0777``, both less the process umask (``0644`` / ``0755`` under ``022``), as ``open``
  and ``mkdir`` would give them.
- A target that is a symbolic link is refused without ``force``; with it, the link itself is
  replaced by the new file and the file it points to is left as it was (a link never makes
  the tool write outside the folder named).
- The temporary file has no name while it is written (``O_TMPFILE``, where the system has
  it): a process killed meanwhile leaves nothing behind.  It gets a name,
  ``.NAME.motionhyst-PID-XXXXXXXX.part``, only for the instant before it replaces the target
  (and throughout, where ``O_TMPFILE`` is missing); such a file of a process that no longer
  runs is removed by the next writer in that folder (:func:`~motionhyst.io.leftovers.clean_stale`).
- SIGINT or SIGTERM while a file is written leave the old file as it was and remove the
  temporary file; the process then ends with the usual ``KeyboardInterrupt``.  Messages name
  the target, never a temporary path.

:class:`OutputFolder` applies the same rules to a folder of results (``motionhyst reproduce
--out DIR``): it writes a manifest, :data:`MANIFEST`, listing the files the tool wrote there;
a later run replaces those files and no others, and never deletes anything it did not write.

Examples
--------
>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> target = OutputFile(os.path.join(folder, "run.csv"))
>>> with target.open() as fh:
...     _ = fh.write("time,error\\n0,0\\n")
>>> open(target.path).read()
'time,error\\n0,0\\n'
>>> try:
...     OutputFile(target.path)
... except OutputError as exc:
...     print(str(exc).endswith("run.csv exists; give --force to replace it"))
True
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import signal
import stat
import tempfile
import threading
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import ArrayLike

from motionhyst.core.interrupts import raise_or_defer
from motionhyst.core.textfiles import CSV_FORMAT, csv_header, csv_rows
from motionhyst.io.leftovers import clean_stale as clean_stale
from motionhyst.io.leftovers import scratch_folder as scratch_folder

MANIFEST = "motionhyst-manifest.json"
"""Name of the manifest :class:`OutputFolder` writes into a results folder."""

_MANIFEST_KIND = "motionhyst output folder"


class OutputError(ValueError):
    """An output that must not be written as asked: one line naming the path (exit 2).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst.io.outputs import OutputError, OutputFile
    >>> path = Path(tempfile.mkdtemp()) / "run.csv"
    >>> _ = path.write_text("time\\n")
    >>> try:
    ...     OutputFile(path)                               # exists, and no force=True
    ... except OutputError as err:
    ...     print(str(err).replace(str(path.parent), "DIR"))
    DIR/run.csv exists; give --force to replace it
    """


def umask() -> int:
    """The process umask (read without changing it for longer than one call).

    Examples
    --------
    >>> 0 <= umask() <= 0o777
    True
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    old = os.umask(0o022)
    os.umask(old)
    return old


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def _inputs(inputs) -> list[Path]:
    """The input paths: one path or an iterable of paths (None entries skipped)."""
    if inputs is None:
        return []
    if isinstance(inputs, str | os.PathLike):
        inputs = [inputs]
    return [Path(p) for p in inputs if p is not None and isinstance(p, str | os.PathLike)]


def check_not_input(path: str | os.PathLike, inputs: Iterable[str | os.PathLike | None],
                    option: str | None = None) -> None:
    """Raise :class:`OutputError` if `path` is one of `inputs` (same file or same resolved path).

    Parameters
    ----------
    path : str or os.PathLike
        The output about to be written.
    inputs : iterable of str, os.PathLike or None
        The command's input files (None entries are skipped).
    option : str, optional
        The option that named `path`, put in front of it in the message.

    Examples
    --------
    >>> check_not_input("a.csv", ["b.toml"])
    >>> check_not_input("a.csv", ["./a.csv"], "--time-series")
    Traceback (most recent call last):
    ...
    motionhyst.io.outputs.OutputError: --time-series a.csv: it is an input of this command; \
choose another output file
    """
    path = Path(path)
    for src in _inputs(inputs):
        if _same_file(path, src):
            raise OutputError(f"{_label(path, option)}: it is an input of this command; "
                              f"choose another output file")


def _label(path: Path | str, option: str | None) -> str:
    return f"{option} {path}" if option else str(path)


def _check_name(path: str | os.PathLike, label: str, extra: int = 0) -> None:
    """Each part of `path` within the file system's longest name (its last with the `extra`
    bytes it gets while written), the path as given (as the system judges it) within its
    longest: else the system's "File name too long" names no option."""
    text = os.fspath(path)
    try:
        most = os.pathconf(os.path.dirname(text) or ".", "PC_NAME_MAX")
    except (OSError, ValueError):  # a folder still to be made: the usual limit
        most = 255
    longest, name = (max((len(os.fsencode(part)) for part in Path(text).parts), default=0),
                     len(os.fsencode(Path(text).name)))
    what = (f"a name of {longest} bytes, more than the {most} the file system allows"
            if longest > most else f"a name of {name} bytes, more than the {most - extra} it "
            f"may have (written under a name {extra} bytes longer)" if name + extra > most
            else "a path longer than the system allows (4096 bytes)"
            if len(os.fsencode(text)) + extra >= 4096 else "")
    if what:  # a path of kilobytes quoted whole would cut the line's end: its middle is left out
        label = label if len(label) <= 240 else f"{label[:120]}...{label[-80:]}"
        raise OutputError(f"{label}: {what}; give a shorter one")


def _check_parents(path: Path, label: str) -> None:
    """The nearest existing folder above `path` is a folder we may write in."""
    for parent in path.parents:
        if parent.exists() or parent.is_symlink():
            if not parent.is_dir():
                raise OutputError(f"{label}: {parent} is not a folder")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise OutputError(f"{label}: no permission to write in {parent}")
            problem = _cannot_create_in(parent)
            if problem is not None:
                raise OutputError(f"{label}: cannot create a file in {parent} ({problem})")
            return


_NO_TMPFILE = (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL)
"""Errors of ``O_TMPFILE`` that only say the file system lacks it."""


def _cannot_create_in(folder: Path) -> str | None:
    """Why no file can be created in `folder`, tried before the work; None if one can.

    ``os.access`` answers from the permission bits alone: for root every folder
    looks writable, also on a read-only file system, in ``/proc`` or ``/sys``.
    So a file is created: unnamed (``O_TMPFILE``) and closed at once, or,
    where the file system lacks that, named as a temporary file of this process
    (:func:`~motionhyst.io.leftovers.clean_stale`'s pattern) and removed at once.
    """
    try:
        fd = os.open(folder, os.O_TMPFILE | os.O_WRONLY | os.O_CLOEXEC, 0o600)
    except AttributeError:  # no O_TMPFILE on this system
        pass
    except OSError as exc:
        if exc.errno not in _NO_TMPFILE:
            return exc.strerror
    else:
        os.close(fd)
        return None
    try:
        fd, name = tempfile.mkstemp(prefix=f".probe.motionhyst-{os.getpid()}-", suffix=".part",
                                    dir=folder)
    except OSError as exc:
        return exc.strerror
    try:
        os.close(fd)
    finally:  # a Ctrl-C here still removes it
        with contextlib.suppress(OSError):
            os.unlink(name)
    return None


def _replaceable_link(path: Path, label: str, force: bool) -> bool:
    """Whether `path` is a symbolic link to replace (with `force`; without it refused)."""
    if not path.is_symlink():
        return False
    if not force:
        raise OutputError(f"{label} is a symbolic link; give the folder it points to, another "
                          f"name, or --force to replace the link itself (never what it points "
                          f"to)")
    if (problem := _cannot_create_in(path.parent)) is not None:
        raise OutputError(f"{label}: cannot replace the link in {path.parent} ({problem})")
    return True


def check_output_folder(path: str | os.PathLike, option: str, force: bool = False) -> None:
    """Raise :class:`OutputError` before the work if a folder a command fills itself (a study's
    store) cannot be: no name, ``-``, a symbolic link without `force` (with it, the link
    itself is to be replaced by the new folder, never what it points to), or no file can be
    created where it goes.

    Parameters
    ----------
    path : str or os.PathLike
        The folder, existing or to be made.
    option : str
        The option naming it, for messages.
    force : bool
        The user asked to replace what is there (``--force``).

    Examples
    --------
    >>> import tempfile
    >>> check_output_folder(tempfile.mkdtemp() + "/s.zarr", "--out")
    >>> check_output_folder("-", "--out")
    Traceback (most recent call last):
    ...
    motionhyst.io.outputs.OutputError: --out -: not a folder name
    """
    label = _label(path, option)
    if str(path) in ("", "-"):
        raise OutputError(f"{label}: not a folder name")
    _check_name(path, label)
    path = Path(path)
    if _replaceable_link(path, label, force):
        return
    problem = _cannot_create_in(path) if path.is_dir() else None
    if problem is not None:
        raise OutputError(f"{label}: cannot create a file in {path} ({problem})")
    if not path.is_dir():
        _check_parents(path, label)


def _missing_parents(folder: Path) -> list[Path]:
    """Folders that must be created for `folder` to exist, outermost first."""
    missing = []
    while not folder.exists() and not folder.is_symlink():
        missing.append(folder)
        if folder.parent == folder:
            break
        folder = folder.parent
    return missing[::-1]


class _Temporary:
    """A temporary file in `folder` for `name`: unnamed (``O_TMPFILE``) until :meth:`commit`."""

    def __init__(self, folder: Path, name: str, mode: int):
        self.folder, self.name, self.path, self.mode = folder, name, None, mode
        try:
            self.fd = os.open(folder, os.O_TMPFILE | os.O_RDWR | os.O_CLOEXEC, mode)
        except (AttributeError, OSError):  # no O_TMPFILE here: a named file from the start
            self.fd, self.path = self._named()
        os.fchmod(self.fd, mode)

    def _named(self) -> tuple[int, str]:
        fd, path = tempfile.mkstemp(prefix=f".{self.name}.motionhyst-{os.getpid()}-",
                                    suffix=".part", dir=self.folder)
        os.fchmod(fd, self.mode)
        return fd, path

    def commit(self, target: Path) -> None:
        """Move the (flushed) file over `target` atomically."""
        if self.path is None:
            for _ in range(100):
                path = self.folder / (f".{self.name}.motionhyst-{os.getpid()}-"
                                      f"{os.urandom(4).hex()}.part")
                try:  # linkat(AT_SYMLINK_FOLLOW) of the descriptor: a dir_fd makes it linkat
                    dir_fd = os.open(self.folder, os.O_RDONLY | os.O_DIRECTORY)
                    try:
                        os.link(f"/proc/self/fd/{self.fd}", path.name, dst_dir_fd=dir_fd,
                                follow_symlinks=True)
                    finally:
                        os.close(dir_fd)
                except FileExistsError:
                    continue
                except OSError:  # no /proc: copy into a named file
                    fd, name = self._named()
                    self.path = name
                    with open(fd, "wb", closefd=True) as out:
                        os.lseek(self.fd, 0, os.SEEK_SET)
                        while chunk := os.read(self.fd, 1 << 20):
                            out.write(chunk)
                        out.flush()
                        os.fsync(out.fileno())
                    break
                self.path = str(path)
                break
            else:  # pragma: no cover
                raise FileExistsError(f"no free temporary name for {target}")
        os.replace(self.path, target)
        self.path = None

    def discard(self) -> None:
        """Remove the file (a named one) and close it."""
        if self.path is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.path)
            self.path = None
        if self.fd is not None:
            with contextlib.suppress(OSError):
                os.close(self.fd)
            self.fd = None


@contextlib.contextmanager
def _signals_raise() -> Iterator[list[int]]:
    """SIGINT and SIGTERM raise ``KeyboardInterrupt`` inside the block (main thread only).

    Yields the signals received: one raised inside a C callback (numba's compiler
    caching a kernel, say) is swallowed there and the work goes on, so a writer checks
    the list before it replaces its target (:func:`_stop_if`).
    """
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    pid = os.getpid()

    def handler(signum, frame):
        if os.getpid() != pid:  # a process forked inside the block: the signal is its own
            if signum == signal.SIGINT:
                signal.default_int_handler(signum, frame)
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        received.append(signum)
        raise_or_defer(signum, frame)  # not inside numba's boxing of a kernel's results

    saved = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            saved[sig] = signal.signal(sig, handler)
        except (ValueError, OSError):  # pragma: no cover - not the main interpreter
            pass
    try:
        yield received
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old)


def _stop_if(received: list[int]) -> None:
    """Raise ``KeyboardInterrupt`` if a signal came (and was swallowed) during a write."""
    if received:
        raise KeyboardInterrupt(signal.Signals(received[0]).name)


class OutputFile:
    """A file the CLI will write, checked when created (before any computation).

    Parameters
    ----------
    path : str or Path
        The target.  A symbolic link needs `force` and is then replaced
        itself: the file it points to is never written.
    force : bool
        Replace an existing file or symbolic link (``--force``).
    inputs : iterable of paths
        Files the command reads; the target may be none of them, even with `force`.
    option : str, optional
        The option that named the target (``"--time-series"``), for messages.

    Raises
    ------
    OutputError
        One line: the target exists and `force` is false, is an input, is a
        folder or not a regular file, or its folder is a file.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst.io.outputs import OutputFile
    >>> path = Path(tempfile.mkdtemp()) / "summary.txt"
    >>> OutputFile(path).write_text("written atomically\\n")
    >>> path.read_text()
    'written atomically\\n'
    >>> OutputFile(path, force=True).write_text("replaced\\n")   # an existing file needs force
    >>> path.read_text()
    'replaced\\n'
    """

    def __init__(self, path: str | os.PathLike, force: bool = False,
                 inputs: Iterable[str | os.PathLike | None] = (), option: str | None = None):
        self.path = Path(path)
        self.option = option
        self.force = force
        label = _label(self.path, option)
        if str(path) == "" or self.path.name in ("", ".", ".."):
            raise OutputError(f"{label}: not a file name")
        if str(path) == "-":  # elsewhere the standard output: a file named '-' surprises
            raise OutputError(f"{label}: the standard output is not written to; give a file "
                              f"name")
        if os.fspath(path).endswith(("/", os.sep)):  # Path() drops the slash: it names a folder
            raise OutputError(f"{_label(os.fspath(path), option)}: ends in {os.sep}, so names a "
                              f"folder; give a file name")
        if self.path.suffix.lower() == ".mat":  # every reader takes a .mat name for MATLAB
            raise OutputError(f"{label}: motionhyst writes no MATLAB file, and a .mat name is "
                              f"read back as one; give another name")
        _check_name(self.path, label, extra=34)  # written as .NAME.motionhyst-PID-XXXXXXXX.part
        check_not_input(self.path, inputs, option)
        self.target = self.path
        if self.path.is_symlink():
            if not force:
                what = "a symbolic link" if self.path.exists() else ("a symbolic link to a "
                                                                     "missing file")
                raise OutputError(f"{label}: {what}; give --force to replace the link itself "
                                  f"(never the file it points to) or choose another name")
        elif self.target.is_dir():
            raise OutputError(f"{label}: it is a folder; give a file name")
        elif self.target.exists():
            if not self.target.is_file():
                raise OutputError(f"{label}: not a regular file; refusing to replace it")
            if not force:
                raise OutputError(f"{label} exists; give --force to replace it")
        _check_parents(self.target, label)

    def _mode(self) -> int:
        try:
            st = os.lstat(self.target)
        except FileNotFoundError:
            return 0o666 & ~umask()
        return stat.S_IMODE(st.st_mode) if stat.S_ISREG(st.st_mode) else 0o666 & ~umask()

    @contextlib.contextmanager
    def open(self, mode: str = "w", encoding: str | None = "utf-8",
             newline: str | None = None) -> Iterator[IO]:
        """Write the file through a temporary file in its folder; replace the target at the end.

        Parameters
        ----------
        mode : {"w", "wb"}
            Text or binary.
        encoding, newline : str, optional
            As :func:`open` (text mode only).

        Yields
        ------
        file object
            Write to it; the target is replaced when the block ends without
            an exception (or interruption).  Otherwise the target is as it
            was and the temporary file is gone.
        """
        if mode not in ("w", "wb"):
            raise ValueError("mode must be 'w' or 'wb'")
        label = _label(self.path, self.option)
        created = []
        tmp = None
        done = False
        with _signals_raise() as received:
            try:
                for folder in _missing_parents(self.target.parent):
                    folder.mkdir()
                    created.append(folder)
                if ((self.target.exists() or self.target.is_symlink())
                        and not self.force):  # appeared meanwhile
                    raise OutputError(f"{label} exists; give --force to replace it")
                clean_stale(self.target.parent)
                tmp = _Temporary(self.target.parent, self.target.name, self._mode())
                kw = {} if mode == "wb" else {"encoding": encoding, "newline": newline}
                fh = os.fdopen(os.dup(tmp.fd), mode, **kw)
                try:
                    yield fh
                    fh.flush()
                    os.fsync(fh.fileno())
                finally:
                    fh.close()
                _stop_if(received)
                tmp.commit(self.target)
                done = True
                _fsync_dir(self.target.parent)
            except OSError as exc:
                raise OutputError(f"cannot write {label}: "
                                  f"{exc.strerror or exc.__class__.__name__}") from None
            finally:
                if tmp is not None:
                    tmp.discard()
                if not done:
                    for folder in reversed(created):
                        with contextlib.suppress(OSError):
                            folder.rmdir()

    def write_bytes(self, data: bytes) -> None:
        """Write `data` atomically (see :meth:`open`).

        Parameters
        ----------
        data : bytes
            The whole content of the file.
        """
        with self.open("wb") as fh:
            fh.write(data)

    def write_text(self, text: str) -> None:
        """Write `text` (UTF-8) atomically (see :meth:`open`).

        Parameters
        ----------
        text : str
            The whole content of the file.
        """
        with self.open("w") as fh:
            fh.write(text)

    def check_csv_size(self, rows: int, columns: int, fmt: str = CSV_FORMAT,
                       remedy: str = "") -> None:
        """Refuse, before the work, a CSV of `rows` rows of `columns` numbers in `fmt` that
        does not fit where it is written (:func:`~motionhyst.core.budget.check_disk`: the
        free disk space of its folder, the file size limit).

        A number takes at most the width `fmt` gives ``-1.2345678901234567e-100`` and a
        separator (``%.12e``: 21 bytes).

        Parameters
        ----------
        rows, columns : int
            The CSV's rows (after its header) and numbers a row.
        fmt : str
            printf format of a number.
        remedy : str
            What the user can change (the command's options), for the message.

        Raises
        ------
        motionhyst.core.budget.BudgetError
            One line: the file, its rows, their size and the space, and `remedy` (exit 2).

        Examples
        --------
        >>> import tempfile
        >>> from pathlib import Path
        >>> out = OutputFile(Path(tempfile.mkdtemp()) / "ts.csv", option="--time-series")
        >>> out.check_csv_size(1000, 8)                         # 168 kB: written
        >>> try:
        ...     out.check_csv_size(10 ** 12, 8, remedy="lower --output-rate")
        ... except ValueError as exc:
        ...     print(str(exc).split("ts.csv: ")[1].split(", above")[0])
        1e+12 rows of 8 numbers needs 168 TB
        """
        from motionhyst.core.budget import check_disk

        cell = len(fmt % -1.2345678901234567e-100) + 1
        nbytes = (rows + 1) * columns * cell
        check_disk(nbytes, self.target.parent,
                   f"{_label(self.path, self.option)}: {rows:.3g} rows of {columns} numbers",
                   remedy)

    def write_csv(self, columns: Mapping[str, ArrayLike], fmt: str = CSV_FORMAT) -> None:
        """Write named columns of equal length as a CSV file, atomically (see :meth:`open`).

        Parameters
        ----------
        columns : mapping of str to array_like
            The columns, in order: the header line, then one row per sample
            (:func:`motionhyst.core.textfiles.csv_rows`).
        fmt : str
            printf format of a number.

        Examples
        --------
        >>> import tempfile
        >>> from pathlib import Path
        >>> path = Path(tempfile.mkdtemp()) / "out.csv"
        >>> OutputFile(path).write_csv({"time": [0.0, 0.5], "force": [1.0, 2.0]}, fmt="%g")
        >>> print(path.read_text(), end="")
        time,force
        0,1
        0.5,2
        """
        with self.open("w") as fh:
            csv_header(fh, list(columns))
            csv_rows(fh, np.column_stack([np.asarray(c, dtype=float) for c in columns.values()]),
                     fmt)


def _fsync_dir(folder: Path) -> None:
    """Make a rename in `folder` durable (best effort)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover - e.g. platforms without directory fds
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


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
        self.inputs = _inputs(inputs)
        self.names = list(dict.fromkeys(names))
        label = f"{option} {self.path}"
        if str(path) in ("", "-"):
            raise OutputError(f"{label}: not a folder name")
        _check_name(self.path, label)
        for name in self.names:
            if Path(name).name != name or name in ("", ".", "..", MANIFEST):
                raise ValueError(f"not a plain file name: {name!r}")
        # a symbolic link replaced with force: what it held (a new folder in its place)
        self._link = os.readlink(self.path) if _replaceable_link(self.path, label, force) \
            else None
        self._link_removed = False
        if self._link is None and self.path.exists() and not self.path.is_dir():
            kind = "a file" if self.path.is_file() else "not a folder"
            raise OutputError(f"{label} is {kind}; give a folder (it is left untouched)")
        _check_parents(self.path, label)
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
        self._staged: list[tuple[str, _Temporary]] = []
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
            for folder in _missing_parents(self.path):
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
            tmp = _Temporary(self.path, name, mode)
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
        with _signals_raise():
            try:
                _stop_if(getattr(self, "_received", []))
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
        _fsync_dir(self.path)
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
        self._signals = _signals_raise()
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


__all__ = ["MANIFEST", "OutputError", "OutputFile", "OutputFolder", "check_not_input",
           "check_output_folder", "clean_stale", "scratch_folder", "umask"]
