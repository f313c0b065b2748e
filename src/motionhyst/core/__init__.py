"""Foundations every other part uses: compiled kernels, checks of user numbers, linear-system
helpers, text and JSON formatting.
"""
