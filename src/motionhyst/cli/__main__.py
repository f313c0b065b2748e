"""``python -m motionhyst.cli``: the ``motionhyst`` command.

Python imports the package and this one (``motionhyst.cli``, 0.1 s and more on a loaded
machine) before this module runs: a Ctrl-C or SIGTERM meanwhile ends the process by Python's
default (a traceback, or the signal's own end), not in ``motionhyst: interrupted``.  From here
on it is the console script (:func:`_motionhyst_entry.main`); ``python -m _motionhyst_entry``
is the console script's route from its first line, before the package loads.
"""

import sys

from _motionhyst_entry import main

sys.exit(main())
