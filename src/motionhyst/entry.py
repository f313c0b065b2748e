"""The console script's entry as installs before this release name it (``motionhyst.entry:main``).

The console script now runs :func:`_motionhyst_entry.main`, a module beside the package, so
that its Ctrl-C and SIGTERM handlers come before the package's ``__init__`` is imported; this
module gives the same function under its old name, for a console script written by an older
install and for callers that import it.

Examples
--------
>>> from motionhyst.entry import main
>>> main(["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"])   # one line on stderr
2
"""

from __future__ import annotations

from _motionhyst_entry import INTERRUPTED, main

__all__ = ["INTERRUPTED", "main"]
