"""Inputs and outputs: scenario files, CSV records, safe file writing.
"""
