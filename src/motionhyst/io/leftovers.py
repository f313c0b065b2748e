"""What a killed process leaves behind, removed by the next: temporary files and scratch folders.

A writer (:mod:`motionhyst.io.outputs`) names its temporary file
``.NAME.motionhyst-PID-XXXX.part`` only for the instant before it replaces its target; a
store replaced with ``--force`` (:mod:`motionhyst.study`) is built beside it as
``.NAME.motionhyst-PID-new`` and the old one moved aside as ``.NAME.motionhyst-PID-old``
for the instant of the swap; a command that draws figures in worker processes does so in a
scratch folder ``PREFIX-PID-XXXX`` of the system's temporary folder.  A process killed
meanwhile (``SIGKILL``, a power cut) cannot remove them: the next writer in that folder, or
the next scratch folder of that prefix, removes those of processes that no longer run (an
old store whose replacement never took its name is put back in its place).

Examples
--------
>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> open(os.path.join(folder, ".run.csv.motionhyst-999999999-ab12.part"), "w").close()
>>> clean_stale(folder)
['.run.csv.motionhyst-999999999-ab12.part']
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile

__all__ = ["clean_stale", "scratch_folder"]

_STALE = re.compile(r"\..+\.motionhyst-(\d+)-[A-Za-z0-9_]+\.part")
_BESIDE = re.compile(r"\.(.+)\.motionhyst-(\d+)-(new|old)")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process, say: alive
        return True
    return True


def clean_stale(folder: str | os.PathLike) -> list[str]:
    """Remove the temporary files of writers in `folder` whose process no longer runs.

    Only names this module gives its temporary files
    (``.NAME.motionhyst-PID-XXXX.part``) and folders built beside their target
    (``.NAME.motionhyst-PID-new``, ``.NAME.motionhyst-PID-old``) whose process
    ``PID`` has ended: what a writer killed (``SIGKILL``, a power cut) between
    naming them and moving them into place left behind.  An ``-old`` folder
    (or link) whose ``NAME`` is missing is the one replaced when the writer was
    killed before the new one took its name: it is put back as ``NAME``.

    Parameters
    ----------
    folder : str or Path
        The folder.

    Returns
    -------
    list of str
        The names removed (or put back).

    Examples
    --------
    >>> import os, tempfile
    >>> folder = tempfile.mkdtemp()
    >>> open(os.path.join(folder, ".run.csv.motionhyst-999999999-ab12.part"), "w").close()
    >>> clean_stale(folder), os.listdir(folder)
    (['.run.csv.motionhyst-999999999-ab12.part'], [])
    """
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        m = _STALE.fullmatch(name)
        if m and int(m.group(1)) != os.getpid() and not _alive(int(m.group(1))):
            with contextlib.suppress(OSError):
                os.unlink(os.path.join(folder, name))
                removed.append(name)
        m = _BESIDE.fullmatch(name)
        if m and int(m.group(2)) != os.getpid() and not _alive(int(m.group(2))):
            path, target = (os.path.join(folder, n) for n in (name, m.group(1)))
            with contextlib.suppress(OSError):
                if m.group(3) == "old" and not os.path.lexists(target):
                    os.rename(path, target)  # its replacement never took the name
                elif os.path.islink(path) or not os.path.isdir(path):
                    os.unlink(path)  # a link replaced: never what it points to
                else:
                    shutil.rmtree(path)
                removed.append(name)
    return removed


def scratch_folder(prefix: str) -> tempfile.TemporaryDirectory:
    """A temporary folder ``PREFIX-PID-XXXX`` in the system's; those of ended processes removed.

    The folder is removed when the returned object is closed (or used as a
    context manager), as :class:`tempfile.TemporaryDirectory`; a process
    killed before that leaves it, and the next call with the same `prefix`
    removes it.

    Parameters
    ----------
    prefix : str
        The folder's name starts with it (``"motionhyst-figures"``).

    Returns
    -------
    tempfile.TemporaryDirectory
        The folder (its ``name``).

    Examples
    --------
    >>> import os
    >>> with scratch_folder("motionhyst-example") as name:
    ...     os.path.basename(name).startswith(f"motionhyst-example-{os.getpid()}-")
    True
    """
    parent = tempfile.gettempdir()
    pattern = re.compile(re.escape(prefix) + r"-(\d+)-[A-Za-z0-9_]+")
    with contextlib.suppress(OSError):
        for name in os.listdir(parent):
            m = pattern.fullmatch(name)
            if m and int(m.group(1)) != os.getpid() and not _alive(int(m.group(1))):
                shutil.rmtree(os.path.join(parent, name), ignore_errors=True)
    return tempfile.TemporaryDirectory(prefix=f"{prefix}-{os.getpid()}-")
