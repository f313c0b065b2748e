"""``predict`` of a model without inertia from a force record that starts under load: the
warning says where the record starts and where the model rests, its force offset included,
and judges the start from its first samples, not from one (review C13 L1: main said "where the
model rests at 0 N" beside an offset of 12 N, and a spike in the first sample warned)."""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.cli import main

PIEZO = ('[stage]\ntype = "quasi-static"\nk = 4e6\nc = 400.0\nforce_offset = {offset}\n'
         '[hysteresis]\nmodel = "jenkins"\nk = 2e6\nfc = 8.0\n')


def _predict(tmp_path, capsys, force: np.ndarray, offset: float) -> str:
    t = np.arange(force.size) / 20000.0
    (tmp_path / "piezo.toml").write_text(PIEZO.format(offset=offset))
    np.savetxt(tmp_path / "later.csv", np.column_stack([t, force]), delimiter=",",
               header="time,force", comments="")
    code = main(["predict", str(tmp_path / "piezo.toml"), str(tmp_path / "later.csv"),
                 "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 0 and (tmp_path / "x.csv").exists(), err
    return err


def _sines(start: float) -> np.ndarray:
    """Sines of 40 N at 25 Hz from `start` [N], held there for the first millisecond."""
    t = np.arange(4000) / 20000.0
    return start - 40.0 * np.sin(2 * np.pi * 25.0 * np.maximum(t - 1e-3, 0.0))


def test_the_warning_names_the_model_s_rest_with_its_force_offset(tmp_path, capsys):
    """The record starts at 48 N; the model (``u + 12 = w + k y + c y'``) rests at -12 N:
    60 N from it, 75 % of the force's range of 80 N."""
    err = _predict(tmp_path, capsys, _sines(48.0), offset=12.0)
    assert err.startswith("motionhyst: warning: predict: "), err
    assert ("later.csv starts under load, at 48 N, 60 N (75 % of its force's range) from where "
            "the model rests (-12 N, its force offset): a model without inertia starts its "
            "link relaxed") in err, err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("offset", [0.0, 12.0])
def test_a_record_that_starts_where_the_model_rests_is_not_warned(tmp_path, capsys, offset):
    """The same sines about the model's rest (0 N, or -12 N with the offset), the first
    sample a spike of 50 N: no warning (main warned of a load of 50 N from the spike)."""
    force = _sines(-offset)
    force[0] += 50.0
    assert _predict(tmp_path, capsys, force, offset) == ""


def test_a_record_without_offset_says_its_share_of_the_range(tmp_path, capsys):
    err = _predict(tmp_path, capsys, _sines(60.0), offset=0.0)
    assert ("later.csv starts under load, at 60 N (75 % of its force's range from where the "
            "model rests, 0 N)") in err, err
