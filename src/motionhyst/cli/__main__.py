"""``python -m motionhyst.cli``: the ``motionhyst`` command."""

import sys

from motionhyst.cli import main

sys.exit(main())
