"""Controllers of the loop (the paper's eq. (23) lead-lag with low-pass).
"""

__all__: list[str] = []  # the modules of this package hold its names
