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

from motionhyst.io.leftovers import clean_stale, scratch_folder
from motionhyst.io.output_file import (
    OutputError,
    OutputFile,
    check_not_input,
    check_output_folder,
    umask,
)
from motionhyst.io.output_folder import MANIFEST, OutputFolder

__all__ = ["MANIFEST", "OutputError", "OutputFile", "OutputFolder", "check_not_input",
           "check_output_folder", "clean_stale", "scratch_folder", "umask"]
