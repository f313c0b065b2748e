"""The loop in time: simulation, open-loop systems, long time series, references.
"""

__all__: list[str] = []  # the modules of this package hold its names
