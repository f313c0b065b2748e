"""Compiled kernels (numba), set up at their first call.

Every compiled loop of :mod:`motionhyst` is declared with :func:`njit` from
this module instead of numba's.  The kernel stays a plain Python object until
it is first called, so importing :mod:`motionhyst` (and commands that never
run a kernel, such as ``motionhyst --help`` or ``motionhyst df`` for a
Jenkins element) does not import numba.  At the first call, once per process:

* numba is imported and the cache is chosen: compiled machine code is kept
  beside the package (``__pycache__/numba-<key>``), or, where the package is
  read-only, in the user's cache folder (``$XDG_CACHE_HOME/motionhyst`` or
  ``~/.cache/motionhyst``; ``NUMBA_CACHE_DIR`` when set); where neither is
  writable the kernels are compiled in memory for the process instead of
  failing.  ``<key>`` is a hash of the package's sources: numba checks a
  cached kernel only against its own file, so a kernel whose callee in another
  file changed (an upgrade, an edit) would otherwise run stale machine code;
  the folders of other sources beside it that no process used for
  :data:`PRUNE_SECONDS`, or for :data:`BUSY_SECONDS` past the
  :data:`KEEP_RECENT` most recently used, are removed (:func:`prune_caches`),
  so that they do not pile up, one per edit or upgrade;
* the first compilation announces itself with one line on stderr when stderr is a
  terminal (it takes seconds; later runs load the cache); what a command held back to
  that moment (its warnings, while it checks its input) is shown just before
  (:func:`before_notice`), not after the compilation.  Where stderr is not a terminal (a
  script, a pipe, a file) nothing is announced and the warnings stay held as usual, so
  that a refusal after a first compilation is still its one line.

Kernels calling other kernels work as in numba: a kernel passes for its numba
dispatcher inside compiled code.  A kernel declared with a signature
(``@njit("(float64, int64)")``) is compiled for that one signature when first
needed, and arguments of other types are converted to it: a kernel that
would otherwise be compiled once more for a constant argument (numba types
``f(x, 1)`` with the literal ``1``) or another dtype costs one compilation.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tempfile
import threading
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

from motionhyst.core.interrupts import DEFERRED, raise_deferred

_LOCK = threading.RLock()
_STATE: dict[str, Any] = {"cache": None, "announced": False, "numba": None,
                          "before_notice": None}
_PACKAGE = __name__.partition(".")[0]


PRUNE_SECONDS = 86400.0
"""A cache folder of other sources that no process used for this long [s] is removed (a
day: versions used in turn keep theirs; a process older than that which compiles anew makes
its folder again, as numba does when it saves a kernel)."""

KEEP_RECENT = 4
"""Cache folders of other sources kept beside the running one whatever their number (the
most recently used); the others go once no process used them for :data:`BUSY_SECONDS`."""

BUSY_SECONDS = 3600.0
"""A cache folder used within this time [s] is kept (a process of its sources may run)."""

# the cache folders' names (numba-<key>), and those of folders being removed
_CACHE_NAME = re.compile(r"numba-[0-9a-f]{16}(\.removed-[0-9]+)?")


def _probe() -> None:
    """A function of this package's files: where numba would cache it decides for all."""


def _source_key() -> str:
    """A short hash of every source file of the package (the cache folder's name)."""
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha1()
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def _writable_folder(folder: Path) -> bool:
    """True if `folder` exists or can be made, and a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError:
        return False
    return True


def _cache_folder() -> Path | None:
    """The folder for compiled kernels, keyed by the sources; None if none is writable."""
    name = f"numba-{_source_key()}"
    user = os.environ.get("NUMBA_CACHE_DIR")
    if user:
        candidates = [Path(user) / "motionhyst" / name]
    else:
        xdg = os.environ.get("XDG_CACHE_HOME")
        home = os.environ.get("HOME")
        candidates = [Path(__file__).resolve().parent.parent / "__pycache__" / name]
        if xdg:
            candidates.append(Path(xdg) / "motionhyst" / name)
        elif home:
            candidates.append(Path(home) / ".cache" / "motionhyst" / name)
    return next((c for c in candidates if _writable_folder(c)), None)


def prune_caches(folder: str | Path, age: float = PRUNE_SECONDS, keep: int = KEEP_RECENT,
                 busy: float = BUSY_SECONDS) -> list[Path]:
    """Mark the cache folder `folder` used now and remove the cache folders of other sources
    beside it that no process used for `age` seconds, and those past the `keep` most
    recently used that no process used for `busy` seconds.

    A folder is used when a process chooses it: its time of modification is set then, and
    the process leaves a marker in it (``.in-use-<host>-<pid>``, removed when it exits); a
    folder with the marker of a process running on this machine is never removed, however
    old, nor one with another machine's marker younger than `age`.  A folder is first
    renamed, atomically, then removed, so that two processes pruning at once do not trip
    over each other and no process finds a half-removed folder under its name; a folder that
    a process marked between the look and the rename is renamed back.  Only folders named as
    the cache names them (``numba-<key>``) are touched; nothing that cannot be read or
    removed stops the caller.  A working tree whose sources are edited all day keeps the
    last hour's folders and the `keep` before them; versions used in turn keep theirs for a
    day.

    Parameters
    ----------
    folder : str or Path
        The cache folder of the running sources (``.../numba-<key>``).
    age : float
        Least time unused [s] of any folder removed.
    keep : int
        Folders of other sources kept, the most recently used, unless unused for `age`.
    busy : float
        Least time unused [s] of a folder removed past the `keep` most recent.

    Returns
    -------
    list of Path
        The folders removed.

    Examples
    --------
    >>> import os, tempfile, time
    >>> root = Path(tempfile.mkdtemp())
    >>> now = time.time()
    >>> unused = {"0": 0, "1": 2 * PRUNE_SECONDS, "2": 60, "3": 2 * BUSY_SECONDS,
    ...           "4": 3 * BUSY_SECONDS, "5": 4 * BUSY_SECONDS}
    >>> for key, ago in unused.items():
    ...     (root / f"numba-{key * 16}" / "sub").mkdir(parents=True)
    ...     os.utime(root / f"numba-{key * 16}", (now - ago, now - ago))
    >>> (root / "notes").mkdir()                                 # not a cache: kept
    >>> sorted(p.name[6:9] for p in prune_caches(root / ("numba-" + "0" * 16), keep=2))
    ['111', '444', '555']
    >>> sorted(p.name[:9] for p in root.iterdir())   # the 2 most recent of the others kept
    ['notes', 'numba-000', 'numba-222', 'numba-333']
    >>> _ = (root / ("numba-" + "3" * 16) / _marker_name()).write_text("")
    >>> [p.name[6:9] for p in prune_caches(root / ("numba-" + "0" * 16), keep=0, busy=0)]
    ['222']
    >>> sorted(p.name[:9] for p in root.iterdir())   # 333: in use by this process
    ['notes', 'numba-000', 'numba-333']
    """
    folder = Path(folder)
    removed: list[Path] = []
    try:
        os.utime(folder)
        _mark_in_use(folder)
        entries = list(folder.parent.iterdir())
    except OSError:
        return removed
    now = time.time()
    others: list[tuple[float, Path]] = []
    for f in entries:
        match = _CACHE_NAME.fullmatch(f.name)
        if f.name == folder.name or match is None:
            continue
        try:
            if f.is_symlink() or not f.is_dir():
                continue
            if match.group(1) is not None:  # left half-removed by another process: now
                shutil.rmtree(f, ignore_errors=True)
                removed.append(f)
            else:
                others.append((now - f.stat().st_mtime, f))
        except OSError:
            continue
    others.sort(key=lambda item: item[0])
    for rank, (unused, f) in enumerate(others):
        if (unused < age and (rank < keep or unused < busy)) or _in_use(f, age):
            continue
        target = f.with_name(f"{f.name}.removed-{os.getpid()}")
        try:
            os.rename(f, target)
            if _in_use(target, age):    # marked by a process starting meanwhile: give it back
                os.rename(target, f)
                continue
        except OSError:
            continue
        shutil.rmtree(target, ignore_errors=True)
        removed.append(f)
    return removed


def _pid_alive(pid: int) -> bool:
    """True if a process `pid` runs here (or may: one of another user's, or not to be told)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _host() -> str:
    """This machine's name as a marker holds it (a cache folder may be shared by machines)."""
    import socket

    return re.sub(r"[^A-Za-z0-9_.]", "_", socket.gethostname()) or "_"


def _marker_name(pid: int | None = None) -> str:
    """The name of the marker process `pid` (default: this one) leaves in its cache folder."""
    return f".in-use-{_host()}-{os.getpid() if pid is None else pid}"


def _in_use(folder: Path, age: float = PRUNE_SECONDS) -> bool:
    """True if a running process left its marker in the cache folder `folder`: one of this
    machine whose pid runs, or one of another machine (whose processes cannot be seen from
    here) younger than `age` seconds."""
    try:
        markers = [f for f in folder.iterdir() if f.name.startswith(".in-use-")]
    except OSError:
        return True
    host = _host()
    for f in markers:
        where, _, pid = f.name.removeprefix(".in-use-").rpartition("-")
        if not pid.isdigit():
            continue
        if where == host:
            if _pid_alive(int(pid)):
                return True
            continue
        try:
            if time.time() - f.stat().st_mtime < age:
                return True
        except OSError:
            continue
    return False


def _mark_in_use(folder: Path) -> None:
    """Leave this process's marker in `folder`, removed when the process exits (a marker a
    killed process leaves names a process that no longer runs: it keeps nothing)."""
    import atexit

    pid = os.getpid()
    marker = folder / _marker_name(pid)
    marker.touch()

    def _unmark() -> None:
        if os.getpid() == pid:          # not in a forked child
            marker.unlink(missing_ok=True)

    atexit.register(_unmark)


def _can_cache(py_func: Callable = _probe) -> bool:
    """True if numba finds a writable cache folder for `py_func`."""
    from numba.core.caching import FunctionCache

    try:
        FunctionCache(py_func)
    except RuntimeError:  # "cannot cache function ...: no locator available"
        return False
    return True


def _on_terminal(stream) -> bool:
    """True if `stream` is a terminal (a stream without ``isatty``, or a closed one, is not)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def _announce(dispatcher) -> None:
    """One line on stderr before the first compilation of a motionhyst kernel, when stderr
    is a terminal: a script's or a pipe's stderr gets only what the command says (a refusal
    stays its one line); the warnings held so far stay held as usual there."""
    if _STATE["announced"]:
        return
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
    if not module.startswith(_PACKAGE + "."):
        return
    _STATE["announced"] = True
    if not _on_terminal(sys.stderr):
        return
    hook = _STATE.get("before_notice")
    if hook is not None:
        hook()
    where = ("cached for later runs" if _STATE["cache"]
             else "no writable cache folder: compiled for this run only")
    print(f"motionhyst: compiling numerical kernels on first use ({where}) ...",
          file=sys.stderr, flush=True)


def _numba():
    """numba, imported and set up once (cache decision, compile announcement)."""
    numba = _STATE["numba"]
    if numba is None:
        import numba
        from numba.core import event

        class _Listener(event.Listener):
            def on_start(self, ev):
                _announce(ev.data.get("dispatcher"))

            def on_end(self, ev):
                pass

        event.register("numba:compile", _Listener())
        _STATE["numba"] = numba
    return numba


class Kernel:
    """A function compiled by numba at its first call (see the module docstring).

    Parameters
    ----------
    py_func : callable
        The Python function, in numba's nopython subset.
    options : dict
        Options for ``numba.njit`` other than ``cache``.
    signature : str, optional
        The one signature to compile (numba's syntax, e.g. ``"(float64, int64)"``);
        by default one per combination of argument types seen.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.core.compiled import njit
    >>> @njit
    ... def total(x):
    ...     s = 0.0
    ...     for v in x:
    ...         s += v
    ...     return s
    >>> total(np.arange(4.0))
    6.0
    >>> @njit("(float64, int64)")
    ... def scaled(x, n):
    ...     return x * n
    >>> scaled(1.5, 2), scaled(2, 3)   # one compiled version; 2 is converted to 2.0
    (3.0, 6.0)
    """

    def __init__(self, py_func: Callable, options: dict, signature: str | None = None) -> None:
        self.py_func = py_func
        self._options = options
        self._signature = signature
        self._dispatcher = None
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__module__ = py_func.__module__
        self.__doc__ = py_func.__doc__
        self.__wrapped__ = py_func

    def dispatcher(self):
        """The numba dispatcher (created at the first call)."""
        d = self._dispatcher
        if d is None:
            with _LOCK:
                d = self._dispatcher
                if d is None:
                    numba = _numba()
                    if _STATE["cache"] is None:
                        folder = _cache_folder()
                        if folder is not None:  # numba's locator for a user-given folder
                            numba.config.CACHE_DIR = str(folder)
                            prune_caches(folder)
                        _STATE["cache"] = folder is not None and _can_cache()
                    # a function without a source file (a doctest, the REPL) is never cached
                    cache = _STATE["cache"] and _can_cache(self.py_func)
                    _BUILDING.add(self)
                    try:
                        func = _with_callee_dispatchers(self)
                    finally:
                        _BUILDING.discard(self)
                    jit = (numba.njit(cache=cache, **self._options) if self._signature is None
                           else numba.njit(self._signature, cache=cache, **self._options))
                    d = jit(func)
                    self._dispatcher = d
        return d

    @property
    def _numba_type_(self):
        # how numba types a global holding this object inside another kernel
        return self.dispatcher()._numba_type_

    def __call__(self, *args):
        d = self._dispatcher
        if d is None:
            d = self.dispatcher()
        result = d(*args)
        if DEFERRED:  # a signal came while numba boxed the results: raised now
            raise_deferred()
        return result

    def __repr__(self) -> str:
        return f"<compiled kernel {self.__module__}.{self.__qualname__}>"


def _with_callee_dispatchers(kernel: Kernel) -> Callable:
    """`kernel`'s function, seeing the numba dispatchers of the kernels it calls by name.

    numba inlines a callee declared ``inline="always"`` only when the global it
    finds is the callee's dispatcher, not a :class:`Kernel` standing for it
    (a call it cannot inline costs the hot loops of :mod:`motionhyst.time.openloop`
    a factor 2 to 4).  The module keeps its :class:`Kernel` objects: the
    function is a copy whose globals hold the dispatchers (each callee does
    the same for its own callees; a kernel calling itself is left as it is).
    """
    f = kernel.py_func
    names = f.__globals__
    swap = {}
    for name in f.__code__.co_names:
        g = names.get(name)
        if isinstance(g, Kernel) and g is not kernel and g not in _BUILDING:
            swap[name] = g.dispatcher()
    if not swap:
        return f
    copy = types.FunctionType(f.__code__, {**names, **swap}, f.__name__, f.__defaults__,
                              f.__closure__)
    copy.__qualname__ = f.__qualname__
    copy.__module__ = f.__module__
    copy.__doc__ = f.__doc__
    copy.__kwdefaults__ = f.__kwdefaults__
    return copy


_BUILDING: set[Kernel] = set()


def njit(func: Callable | str | None = None, **options
         ) -> Kernel | Callable[[Callable], Kernel]:
    """Declare a numba kernel compiled at its first call (``@njit``, ``@njit(...)`` or
    ``@njit(signature, ...)`` with the one signature to compile, see :class:`Kernel`).

    ``cache`` is accepted for symmetry with numba and ignored: the cache is
    chosen once per process (see the module docstring).

    Parameters
    ----------
    func : callable or str, optional
        The function (``@njit``), or a numba signature to compile only that one.
    options
        Further numba options (``cache``, ``fastmath``, ...), as keywords.

    Examples
    --------
    >>> @njit("(float64, float64)")
    ... def clip_add(w, dx):
    ...     return min(max(w + dx, -1.0), 1.0)
    >>> clip_add(0.5, 0.75)
    1.0
    """
    options.pop("cache", None)
    if func is None or isinstance(func, str):
        return lambda f: Kernel(f, options, func)
    return Kernel(func, options)


def before_notice(hook: Callable[[], None] | None) -> Callable[[], None] | None:
    """Call `hook` just before the notice of the first compilation is printed (None: call
    nothing); the hook it replaces is returned.

    A command holds its warnings while it checks its input; a compilation on a cold cache
    among its checks takes seconds to minutes, which the user spends reading its notice:
    the warnings held so far are shown before it, not after.  A notice left out
    (:func:`quiet_compilation`, or stderr not a terminal) calls nothing.

    Parameters
    ----------
    hook : callable or None
        Called without arguments.

    Returns
    -------
    callable or None
        The hook set before.

    Examples
    --------
    >>> previous = before_notice(lambda: print("held lines"))
    >>> before_notice(previous) is not None
    True
    """
    replaced = _STATE.get("before_notice")
    _STATE["before_notice"] = hook
    return replaced


def quiet_compilation(quiet: bool = True) -> None:
    """Leave out (or restore) the one-line notice of the first compilation.

    For callers whose stderr must stay clean, e.g. a test session that checks
    the commands' error output.

    Parameters
    ----------
    quiet : bool
        True to leave the notice out, False to show it again.

    Examples
    --------
    >>> quiet_compilation()         # no notice before the next first compilation
    """
    _STATE["announced"] = bool(quiet)


def compiled_in_memory() -> bool | None:
    """Whether kernels are compiled without a disk cache (None before the first kernel call).

    Examples
    --------
    >>> compiled_in_memory() in (None, True, False)
    True
    """
    c = _STATE["cache"]
    return None if c is None else not c


__all__ = ["BUSY_SECONDS", "KEEP_RECENT", "PRUNE_SECONDS", "Kernel", "before_notice",
           "compiled_in_memory", "njit", "prune_caches", "quiet_compilation"]
