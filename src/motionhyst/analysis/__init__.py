"""Frequency-domain and periodic analyses of the loop: quasi-linear analysis, margins, exact
periodic steady state, their comparison.
"""

__all__: list[str] = []  # the modules of this package hold its names
