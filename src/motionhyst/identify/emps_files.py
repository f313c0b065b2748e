"""The EMPS benchmark's files: their names, their variables, the drive's gain and the period.

A. Janot, M. Gautier and M. Brunot, "Data Set and Reference Models of EMPS",
Workshop on Nonlinear System Identification Benchmarks, Eindhoven, 2019
(nonlinearbenchmark.org, "EMPS").  Kept apart from the identification
(:mod:`motionhyst.identify.emps`) so that a command checks a data folder and reads
its records without importing the optimisers: a refusal comes before them.

Examples
--------
>>> from motionhyst.identify.emps_files import COLUMNS, DRIVE_GAIN, ESTIMATION_FILE
>>> ESTIMATION_FILE, COLUMNS["force"], DRIVE_GAIN
('DATA_EMPS.mat', 'vir', 35.15065)
"""

from __future__ import annotations

__all__ = ["COLUMNS", "DRIVE_GAIN", "ESTIMATION_FILE", "PERIOD", "TEST_FILE"]

ESTIMATION_FILE = "DATA_EMPS.mat"
"""The benchmark's estimation record."""
TEST_FILE = "DATA_EMPS_PULSES.mat"
"""The benchmark's test record (the estimation reference with 5 V force pulses added)."""
COLUMNS = {"time": "t", "force": "vir", "displacement": "qm"}
"""The records' variables: time [s], controller output [V], measured position [m]."""
DRIVE_GAIN = 35.15065
"""The drive's gain ``gtau`` [N/V]: the force on the load is ``gtau * vir``."""
PERIOD = 6240
"""Samples per period of the estimation record's reference ``qg``."""
