"""A force-displacement record of a spring and a damper: every route says the same thing.

The default route (Maxwell-slip elements, refused before the fit by
:func:`~motionhyst.identify.records.check_loops_open`) and each ``--model`` (refused after
its fit) answer "no hysteresis in the record(s)" in one line and save nothing, whether the
damper is weak (a straight line leaves 2.5 % of the force) or strong; a refusal never
recommends a model that refuses the same record.
"""

from __future__ import annotations

import numpy as np
import pytest
from records_of_other_kinds import Record, stepped_sines

from motionhyst.cli import main


def spring_and_damper(path, c: float, noise: float = 15.0):
    t = np.arange(4000) / 200.0
    x = stepped_sines(t, [(0.2, 0.02), (0.5, 0.008), (1.0, 0.014), (2.0, 0.003)])
    f = 5e4 * x + c * np.gradient(x, t) + 85.0
    f = f + noise * np.random.default_rng(0).standard_normal(t.size)
    return Record(t, f, x).write(path)


def refusal(capsys, *args: str) -> str:
    rc = main(list(args))
    out, err = capsys.readouterr()
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    return err


@pytest.mark.parametrize("c", [300.0, 2.0e4])
def test_every_route_says_no_hysteresis(capsys, tmp_path, c):
    path = spring_and_damper(tmp_path / "damper.csv", c)
    model = tmp_path / "m.toml"
    for extra in ((), ("--model", "jenkins"), ("--model", "dahl")):
        err = refusal(capsys, "identify", str(path), *extra, "--save", str(model))
        assert err.startswith(f"motionhyst: error: {path}: no hysteresis in the record")
        assert "--model" not in err and "the fit failed" not in err
        assert not model.exists()
