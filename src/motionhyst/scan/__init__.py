"""Scans: setpoint profiles, MA/MSD metrics, model feedforward and learning control.
"""

__all__: list[str] = []  # the modules of this package hold its names
