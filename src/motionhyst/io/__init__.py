"""Files in and out: measured records (CSV and MATLAB), CSV tables, safe file writing.
"""

__all__: list[str] = []  # the modules of this package hold its names
