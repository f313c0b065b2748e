"""What a Ctrl-C became: the interrupt behind another exception.

A ``KeyboardInterrupt`` raised inside an import of a compiled extension, a numba
compilation or a C callback comes out as another error (a SystemError, numpy's
ImportError) whose cause or context is the interrupt; the command line reports it as the
interruption it was (exit code 130), not as an error.

Examples
--------
>>> try:
...     try:
...         raise KeyboardInterrupt
...     except KeyboardInterrupt:
...         raise ImportError("numpy failed to import")
... except ImportError as exc:
...     interrupted(exc)
True
>>> interrupted(ValueError("a bad value"))
False
"""

from __future__ import annotations

__all__ = ["interrupted"]


def interrupted(exc: BaseException) -> bool:
    """Whether `exc` is, or was caused by, a ``KeyboardInterrupt`` (its cause or context,
    however deep).

    Parameters
    ----------
    exc : BaseException
        The exception that ended the work.

    Examples
    --------
    >>> interrupted(KeyboardInterrupt())
    True
    """
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False
