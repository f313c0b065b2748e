"""Files in and out: measured records (CSV and MATLAB), CSV tables, safe file writing.
"""
