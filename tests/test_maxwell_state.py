"""The state of a Maxwell-slip link stepped sample by sample (python-control's interface):
held as arrays of element forces, or by its Jenkins elements once they are asked for."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import Jenkins, MaxwellSlip

K, FC = [10.0, 6.0, 2.0], [0.01, 0.03, 0.05]


def _path() -> list[float]:
    return np.cumsum(np.random.default_rng(0).normal(0.0, 0.004, 200)).tolist()


def _separate(w0: float = 0.0) -> list[float]:
    """The same link as separate Jenkins elements, summed in their order."""
    share = np.asarray(FC) / np.sum(FC)
    els = [Jenkins(k, fc) for k, fc in zip(K, FC, strict=True)]
    for el, s in zip(els, share, strict=True):
        el.reset(w0 * s)
    return [float(sum(el(x) for el in els)) for x in _path()]


@pytest.mark.parametrize("w0", [0.0, 0.04])
def test_the_link_steps_as_its_elements_do(w0):
    link = MaxwellSlip(K, FC)
    link.reset(w0)
    assert [link(x) for x in _path()] == _separate(w0)  # to the last digit


def test_the_elements_are_made_once_and_then_hold_the_state():
    link = MaxwellSlip(K, FC)
    path = _path()
    first = [link(x) for x in path[:50]]
    elements = link.elements  # made now, in the link's state
    assert link.elements is elements
    rest = [link(x) for x in path[50:]]
    assert first + rest == _separate()
    elements[0].reset(0.005)  # the link's state: what the old attribute was
    link(path[-1])
    assert elements[0](path[-1]) == 0.005
    link.reset(0.0)
    assert [e(0.0) for e in elements] == [0.0, 0.0, 0.0]
