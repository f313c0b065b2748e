"""Scans: setpoint profiles, MA/MSD metrics, model feedforward and learning control.
"""
