"""Maxwell-slip elements fitted to a force-displacement record (the default route of
``identify``) that leave a systematic error above
:data:`~motionhyst.identify.io_checks.PREDICT_SHARE` (1.25 %) of the force's RMS: refused,
nothing saved, as on the link routes (on another record their error is a few times larger).
A number of elements the user fixed, shown without ``--save``, is a warning.  Before, that band
was saved: a Bouc-Wen damper (n = 4) fitted with six elements left 1.6 % and predicted its
held-out earthquake at 93.8 %, exit 0.
"""

from __future__ import annotations

import pytest
from records_of_other_kinds import damper_record, fit_percent

from motionhyst.cli import main
from motionhyst.hysteresis import BoucWen
from motionhyst.identify import identify_maxwell_slip
from motionhyst.scenario import Scenario
from motionhyst.time.quasi_static import force_from_displacement

#: A damper whose loops Maxwell-slip elements approach but do not follow: a Bouc-Wen link
#: whose exponent 4 makes its loops' corners sharper than Dahl's
SHARP = BoucWen(k=1.0e6, fc=3.0e3, n=4.0, beta=0.6, gamma=0.4)


@pytest.mark.parametrize(("link", "refused"), [(SHARP, True), (None, False)])
def test_elements_that_would_not_predict_another_record_are_not_saved(capsys, tmp_path, link,
                                                                     refused):
    train = damper_record("sines", seed=1, link=link).write(tmp_path / "sines.csv",
                                                             ("time", "displacement", "force"))
    model = tmp_path / "damper.toml"
    rc = main(["identify", str(train), "--elements", "6", "--save", str(model)])
    out, err = capsys.readouterr()
    held_out = damper_record("earthquake", seed=2, link=link)
    if refused:
        assert rc == 2 and not model.exists() and "wrote" not in out
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert err.startswith(f"motionhyst: error: {train}: the fit failed: 6 Maxwell-slip "
                              f"element(s) leave a systematic error of 1.6 % of the force's "
                              f"RMS (above 1.25 %"), err
        assert "below 95 %" in err and "more --elements than 6" in err
        assert err.rstrip().endswith("nothing saved")
        # what the refusal is about: the same six elements, written as --save would,
        # predict the held-out earthquake below 95 % (measured 93.8 %)
        rec = damper_record("sines", seed=1, link=link)
        ident = identify_maxwell_slip(rec.displacement, rec.force, 6, t=rec.t)
        model.write_text(ident.scenario_text(str(train)))
        # shown without --save: one warning line, exit 0
        assert main(["identify", str(train), "--elements", "6"]) == 0
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert err.startswith(f"motionhyst: warning: identify: {train}: the model leaves a "
                              f"systematic error of 1.6 % of the force's RMS"), err
    else:  # the damper of three Jenkins elements and a spring: silent, saved, and predicts
        assert rc == 0 and model.exists() and f"wrote {model}" in out
        assert err == ""
    system = Scenario.from_file(model).open_loop()
    predicted = force_from_displacement(system.plant, system.hysteresis, held_out.t,
                                        held_out.displacement)
    fit = fit_percent(held_out.force, predicted)
    assert fit < 95.0 if refused else fit > 99.0
