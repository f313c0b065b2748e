"""Presentation of results: figures, plots, the report.
"""

__all__: list[str] = []  # the modules of this package hold its names
