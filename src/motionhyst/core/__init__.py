"""Foundations every other part uses: compiled kernels, checks of user numbers, linear-system
helpers, text and JSON formatting.
"""

__all__: list[str] = []  # the modules of this package hold its names
