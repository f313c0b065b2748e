"""A link's force-displacement record too short or too poor for the model is no result
(issue 26: no answer from nothing).

64 samples of the test stand (a spring of 100 N/m and a damper of 0.5 N s/m beside a Jenkins
link of 2000 N/m slipping at 2 N, driven to 2 mm; the record of
:mod:`test_identify_undetermined` at every 62nd sample): the LuGre link's fit exited 0 with
``fs = 4.2e10 +- 4.1e10 N`` (forces of 2 N), the Dahl link's with ``alpha = 0.0088 +-
0.0075``.  Now the LuGre link's 8 parameters are refused before the search (fewer than 10
samples each), the Dahl link's exponent after it (not two standard errors from 0); nothing is
saved.  The Jenkins link's fit of the same samples determines its parameters and is kept.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_identify_undetermined import LINK_FC, LINK_K, run, stand_record


def _short(tmp_path):
    """The stand's record at every 62nd sample: 64 samples over 3.9 s."""
    whole = stand_record(tmp_path / "whole.csv", 2e-3)
    data = np.loadtxt(whole, delimiter=",", skiprows=1)[::62][:64]
    path = tmp_path / "short.csv"
    np.savetxt(path, data, delimiter=",", header="time,displacement,force", comments="")
    return path


@pytest.mark.parametrize(("model", "words"), [
    ("lugre", "the records hold 64 samples for the 8 parameters of the lugre link's fit, "
              "fewer than 10 for each (80): they cannot determine them"),
    ("dahl", "the fit failed: the records do not determine link.alpha = "),
])
def test_a_record_too_short_for_the_model_is_refused(capsys, tmp_path, model, words):
    record = _short(tmp_path)
    saved = tmp_path / "m.toml"
    rc, out, err = run(capsys, "identify", str(record), "--model", model, "--save", str(saved))
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert f"{record}: {words}" in err, err
    assert "Traceback" not in err and not saved.exists()


def test_a_model_the_short_record_determines_is_identified(capsys, tmp_path):
    """The Jenkins link (5 parameters) on the same 64 samples: its stiffness and slip force
    within three standard errors of the stand's."""
    rc, out, err = run(capsys, "identify", str(_short(tmp_path)), "--model", "jenkins",
                       "--json")
    assert rc == 0, err
    fit = json.loads(out)
    est, std = fit["estimates"], fit["std"]
    assert abs(est["link.k"] - LINK_K) < 3 * std["link.k"]
    assert abs(est["link.fc"] - LINK_FC) < 3 * std["link.fc"]
