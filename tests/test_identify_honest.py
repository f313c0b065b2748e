"""Honest answers of identify and predict: no model from a record without hysteresis, a mass
far from the records' own estimate said, errors that name the file at fault.
"""

from __future__ import annotations

import numpy as np
import scipy.io

from motionhyst.cli import main


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def test_an_init_from_record_without_a_column_is_named_once(capsys, tmp_path):
    """`predict --init-from REC.mat` whose file lacks the displacement: one line naming that
    file once (it said 'INPUT: REC: ...', the input's name in front of another file's
    error)."""
    model = tmp_path / "m.toml"
    model.write_text('[stage]\ntype = "quasi-static"\nk = 4e7\n[hysteresis]\nmodel = '
                     '"jenkins"\nk = 1e7\nfc = 100.0\n')
    t = np.arange(100) / 1000.0
    scipy.io.savemat(tmp_path / "in.mat", {"t": t[:, None], "vir": np.sin(t)[:, None]})
    scipy.io.savemat(tmp_path / "rec.mat", {"t": t[:, None], "vir": np.sin(t)[:, None]})
    out_csv = tmp_path / "x.csv"
    rc, out, err = run(capsys, "predict", str(model), str(tmp_path / "in.mat"), "--init-from",
                       str(tmp_path / "rec.mat"), "--columns", "time=t,force=vir", "--out",
                       str(out_csv))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.count("rec.mat") == 1 and "in.mat" not in err
    assert "no variable 'displacement'" in err and not out_csv.exists()
