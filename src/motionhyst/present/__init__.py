"""Presentation of results: figures, plots, the report.
"""
