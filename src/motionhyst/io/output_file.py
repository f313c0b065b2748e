"""One output file, written atomically, asked for and never an input: :class:`OutputFile`
and the checks of an output path before the work (the rules: :mod:`motionhyst.io.outputs`).

Examples
--------
>>> import os, tempfile
>>> target = OutputFile(os.path.join(tempfile.mkdtemp(), "run.csv"))
>>> with target.open() as fh:
...     _ = fh.write("time,error\\n0,0\\n")
>>> open(target.path).read()
'time,error\\n0,0\\n'
"""

from __future__ import annotations

import contextlib
import errno
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
from motionhyst.io.leftovers import clean_stale


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


def input_paths(inputs) -> list[Path]:
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
    motionhyst.io.output_file.OutputError: --time-series a.csv: it is an input of this command; \
choose another output file
    """
    path = Path(path)
    for src in input_paths(inputs):
        if _same_file(path, src):
            raise OutputError(f"{_label(path, option)}: it is an input of this command; "
                              f"choose another output file")


def _label(path: Path | str, option: str | None) -> str:
    return f"{option} {path}" if option else str(path)


def check_name(path: str | os.PathLike, label: str, extra: int = 0) -> None:
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


def check_parents(path: Path, label: str) -> None:
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


def replaceable_link(path: Path, label: str, force: bool) -> bool:
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
    motionhyst.io.output_file.OutputError: --out -: not a folder name
    """
    label = _label(path, option)
    if str(path) in ("", "-"):
        raise OutputError(f"{label}: not a folder name")
    check_name(path, label)
    path = Path(path)
    if replaceable_link(path, label, force):
        return
    problem = _cannot_create_in(path) if path.is_dir() else None
    if problem is not None:
        raise OutputError(f"{label}: cannot create a file in {path} ({problem})")
    if not path.is_dir():
        check_parents(path, label)


def missing_parents(folder: Path) -> list[Path]:
    """Folders that must be created for `folder` to exist, outermost first."""
    missing = []
    while not folder.exists() and not folder.is_symlink():
        missing.append(folder)
        if folder.parent == folder:
            break
        folder = folder.parent
    return missing[::-1]


class Temporary:
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
def signals_raise() -> Iterator[list[int]]:
    """SIGINT and SIGTERM raise ``KeyboardInterrupt`` inside the block (main thread only).

    Yields the signals received: one raised inside a C callback (numba's compiler
    caching a kernel, say) is swallowed there and the work goes on, so a writer checks
    the list before it replaces its target (:func:`stop_if`).
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


def stop_if(received: list[int]) -> None:
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
        check_name(self.path, label, extra=34)  # written as .NAME.motionhyst-PID-XXXXXXXX.part
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
        check_parents(self.target, label)

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
        with signals_raise() as received:
            try:
                for folder in missing_parents(self.target.parent):
                    folder.mkdir()
                    created.append(folder)
                if ((self.target.exists() or self.target.is_symlink())
                        and not self.force):  # appeared meanwhile
                    raise OutputError(f"{label} exists; give --force to replace it")
                clean_stale(self.target.parent)
                tmp = Temporary(self.target.parent, self.target.name, self._mode())
                kw = {} if mode == "wb" else {"encoding": encoding, "newline": newline}
                fh = os.fdopen(os.dup(tmp.fd), mode, **kw)
                try:
                    yield fh
                    fh.flush()
                    os.fsync(fh.fileno())
                finally:
                    fh.close()
                stop_if(received)
                tmp.commit(self.target)
                done = True
                fsync_dir(self.target.parent)
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


def fsync_dir(folder: Path) -> None:
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


__all__ = ["OutputError", "OutputFile", "check_not_input", "check_output_folder", "umask"]
