"""Library warnings: a result that is computed, but outside the range where the model holds.

A plausibility check (a frequency below ``f*`` of eq. 13, an amplitude at
which the link never slips, a frequency outside a measured plant's data)
does not stop a computation: it issues a :class:`MotionhystWarning` with
:func:`warnings.warn` and the result is returned as usual.  Python shows
such a warning once per place in the code by default; filter them as any
other warning (``warnings.simplefilter("error", MotionhystWarning)`` turns
them into errors, ``"ignore"`` silences them).  The ``motionhyst`` command
shows each one as a line ``motionhyst: warning: COMMAND: message`` on
stderr and still exits 0.

Examples
--------
>>> import warnings
>>> from motionhyst import MotionhystWarning
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     warn("5 Hz below f* = 7 Hz (eq. 13)")
>>> [(w.category.__name__, str(w.message)) for w in caught]
[('MotionhystWarning', '5 Hz below f* = 7 Hz (eq. 13)')]
"""

from __future__ import annotations

import warnings

__all__ = ["MotionhystWarning", "warn"]


class MotionhystWarning(UserWarning):
    """A result was computed where the model it rests on may not hold.

    The message is one sentence saying what was asked, where the model stops
    holding and what that means for the numbers (no prefix: the command line
    adds ``motionhyst: warning:`` and the command's name).

    Examples
    --------
    >>> import warnings
    >>> from motionhyst import MotionhystWarning
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", MotionhystWarning)
    ...     try:
    ...         warnings.warn("outside the data", MotionhystWarning)
    ...     except MotionhystWarning as exc:
    ...         print("raised:", exc)
    raised: outside the data
    """


def warn(message: str, stacklevel: int = 2) -> None:
    """Issue `message` as a :class:`MotionhystWarning`.

    Parameters
    ----------
    message : str
        One sentence, without a ``warning:`` prefix.
    stacklevel : int
        As for :func:`warnings.warn`, counted from the caller of this
        function: the default 2 names the line that called the function
        which calls :func:`warn`, i.e. the user's call into the library.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn("at amplitude 0.001 m the element never slips")
    >>> caught[0].category.__name__
    'MotionhystWarning'
    """
    warnings.warn(message, MotionhystWarning, stacklevel=stacklevel + 1)
