"""Two runs of one stage are two records, however small their noise; a copy is one record.

Review C20 L1: with a tolerance of 1e-5 of each value, two runs of a stage held 5 mm from
the position's zero (a 1 mm sine) with 1 nm of noise, under a commanded force that repeats,
were taken for one record given twice (3000 of 3000 samples alike).  A copy differs from
what it copies only by how it was written: by the last significant digit it was written with
(:func:`~motionhyst.identify.record_overlap.significant_digits`) or its fixed decimals
(:func:`~motionhyst.identify.record_overlap.decimal_step`), and two runs written with all
their digits differ by their noise.
"""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.identify.record_overlap import repeated_record, significant_digits

STEP = 1e-3


def _run(seed: int) -> list[np.ndarray]:
    """force, position: 3 s at 1 kHz, the position 5 mm + 1 mm sin(4 pi t) with 1 nm noise."""
    t = np.arange(3000) * STEP
    x = 5e-3 + 1e-3 * np.sin(2 * np.pi * 2 * t)
    f = 0.04 * np.sin(2 * np.pi * 2 * t + 0.3)
    return [f, x + 1e-9 * np.random.default_rng(seed).standard_normal(t.size)]


def test_two_runs_whose_noise_is_below_1e5_of_every_value_are_two_records():
    assert repeated_record([(STEP, _run(0)), (STEP, _run(1))]) is None


@pytest.mark.parametrize("fmt", ["%.6g", "%.7e", "%.8f", "%.10f", "%.6f"])
def test_a_copy_written_with_fewer_digits_is_the_same_record(fmt):
    run = _run(0)
    copy = [np.array([float(fmt % v) for v in column]) for column in run]
    assert repeated_record([(STEP, run), (STEP, _run(1)), (STEP, copy)]) == (0, 2, 3000)


def test_the_digits_a_column_was_written_with():
    run = _run(0)
    assert [significant_digits(np.array([float(f"%.{d}g" % v) for v in run[1]]))
            for d in (3, 6, 9)] == [3, 6, 9]
    assert significant_digits(run[1]) >= 15
