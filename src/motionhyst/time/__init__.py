"""The loop in time: simulation, open-loop systems, long time series, references.
"""
