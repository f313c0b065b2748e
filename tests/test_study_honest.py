"""A study that answers only what its inputs determine (issue 26, review B19 F2, F7, F9, F14):
an identification that is no covariance, or of another stage, is refused in one line; a
distribution that puts its mass where the scenario refuses is refused before any point runs;
``--force`` replaces only the store's own entries.

The command-line cases run in a child process under an address-space limit
(:mod:`limited_process`) in a folder of the user's files, and assert exit code 2, one line on
stderr (no traceback), nothing on stdout, and every file there before byte-identical after.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.study import Study, StudyError
from motionhyst.study.identified import joint_from_identification

STAGE = '[stage]\ntype = "mass-damper"\nm = 10.0\nc = 20.0\n'
LINK = '[hysteresis]\nmodel = "jenkins"\nk = 2000.0\nfc = 2.0\n'
LOOP = (STAGE + "\n" + LINK + '\n[controller]\ntype = "pid"\nkp = 2e5\nki = 2e6\nkd = 2000.0\n'
        'derivative_filter_hz = 500.0\n\n[reference]\namplitude = 1e-3\nfrequencies = [5.0]\n')
"""A 10 kg mass-damper with Table I's link scaled to it, in a PID loop: the identified system."""

PARAMETERS = ["stage.m", "stage.c", "hysteresis.k", "hysteresis.fc"]
ESTIMATES = [10.000019830835344, 19.999853571462516, 1999.7570141694232, 2.000046906500395]
STD = [1.053330127908144e-05, 9.263367796655379e-05, 0.14162079797906132, 2.3699220872117845e-05]
CORRELATION = [[1.0, -0.310198981648, -0.816862210666, 0.487396001347],
               [-0.310198981648, 1.0, 0.051352043296, -0.938686314713],
               [-0.816862210666, 0.051352043296, 1.0, -0.23309814522],
               [0.487396001347, -0.938686314713, -0.23309814522, 1.0]]
"""What ``identify --record input-output --plant mass-damper --model jenkins --save`` wrote for
4000 samples of the 10 kg mass-damper with its link (review B19's id.toml)."""


def identification(estimates=ESTIMATES, correlation=CORRELATION, stage: str = STAGE) -> str:
    """A model file as ``identify --save`` writes it: the stage, the link, [identification]."""
    return (stage + "\n" + LINK + "\n[identification]\nrecord = \"input-output\"\n"
            f"parameters = {json.dumps(PARAMETERS)}\nestimates = {json.dumps(estimates)}\n"
            f"std = {json.dumps(STD)}\ncorrelation = {json.dumps(correlation)}\n")


def _not_psd() -> list[list[float]]:
    """The correlation with corr(stage.m, hysteresis.fc) = 0.99: eigenvalue -0.29."""
    r = [list(row) for row in CORRELATION]
    r[0][3] = r[3][0] = 0.99
    return r


def study_text(scenario: str, n: int = 4, extra: str = "") -> str:
    return (f'scenario = "{scenario}"\noutputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n'
            f"[samples]\nn = {n}\nseed = 0\n{extra}")


def refused(tmp_path: Path, files: dict, argv: list[str]) -> str:
    """Run `argv` in `tmp_path` holding `files`: exit 2, one line on stderr (returned), nothing
    on stdout, every file byte-identical and none added."""
    populate(tmp_path, files)
    before = snapshot(tmp_path)
    code, out, err = limited_process.run(argv, tmp_path, limited_process.REFUSAL_LIMIT)
    assert code == 2, err
    assert out == ""
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err
    assert snapshot(tmp_path) == before
    return err.strip()


# ----------------------------------------------------------- F14: a correlation that is none
def test_a_correlation_matrix_with_a_negative_eigenvalue_is_refused_whole(tmp_path):
    """corr(stage.m, hysteresis.fc) = 0.99 in the identification of the 10 kg stage: the 4 x 4
    matrix has the eigenvalue -0.290 (no estimates have it); only its (k, fc) block was drawn,
    which is a correlation, and the study ran (exit 0).  Now the whole matrix is checked."""
    bad = _not_psd()
    assert np.linalg.eigvalsh(np.array(bad))[0] == pytest.approx(-0.2904, abs=1e-4)
    path = tmp_path / "bad.toml"
    path.write_text(identification(correlation=bad))
    with pytest.raises(ValueError, match=r"bad\.toml: \[identification\]: correlation: the "
                                         r"correlation matrix of its 4 "
                                         r"parameters \(stage\.m, stage\.c, hysteresis\.k, "
                                         r"hysteresis\.fc\) is not positive semi-definite \(it "
                                         r"has the eigenvalue -0\.29\)"):
        joint_from_identification(path)
    # the same of `identify --json`: its covariance matrix
    fit = {"plant": {"type": "mass-damper", "m": 10.0, "c": 20.0},
           "hysteresis": {"model": "jenkins", "k": 2000.0, "fc": 2.0},
           "estimates": {"m": ESTIMATES[0], "c": ESTIMATES[1], "link.k": ESTIMATES[2],
                         "link.fc": ESTIMATES[3]},
           "covariance": {"parameters": ["m", "c", "link.k", "link.fc"],
                          "matrix": (np.array(bad) * np.outer(STD, STD)).tolist()}}
    (tmp_path / "bad.json").write_text(json.dumps(fit))
    with pytest.raises(ValueError, match=r"not positive semi-definite \(it has the eigenvalue "
                                         r"-0\.29\).*identify \.\.\. --json"):
        joint_from_identification(tmp_path / "bad.json")
    # a saved matrix's rounding (1e-12) is no refusal: the identification as written is drawn
    (tmp_path / "good.toml").write_text(identification())
    assert joint_from_identification(tmp_path / "good.toml").keys == tuple(PARAMETERS[2:])


def test_study_refuses_an_impossible_correlation_in_one_line(tmp_path):
    err = refused(tmp_path, {"loop.toml": LOOP, "st.toml": study_text("loop.toml"),
                             "bad.toml": identification(correlation=_not_psd())},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0",
                   "--from-identification", "bad.toml"])
    assert err.endswith(NOT_PSD.format("bad.toml")), err


NOT_PSD = ("{}: [identification]: correlation: the correlation matrix of its 4 parameters "
           "(stage.m, stage.c, hysteresis.k, hysteresis.fc) is not positive semi-definite (it "
           "has the eigenvalue -0.29): no estimates have it; write the identification again "
           "(`motionhyst identify ... --save`)")


@pytest.mark.parametrize("argv", [
    ["predict", "bad.toml", "force.csv", "--out", "p.csv"],
    ["steady", "loop.toml", "--frequency", "5", "--no-floquet"],
    ["analyze", "loop.toml"],
    ["stability", "loop.toml"],
    ["simulate", "loop.toml", "--frequency", "5", "--time-series", "ts.csv"],
    ["scan", "loop.toml", "--length", "0.005", "--speed", "0.05", "--a-max", "2", "--j-max",
     "50", "--s-max", "1000"],
    ["reproduce", "loop.toml", "--out", "figures"],
    ["study", "st.toml", "--out", "st.zarr", "--workers", "0"],
], ids=lambda argv: argv[0])
def test_every_command_refuses_an_impossible_correlation_where_it_reads_it(tmp_path, argv):
    """The correlation of [identification] was checked only by a study drawing from it:
    ``predict`` of that model file and every command of a scenario holding it ran (exit 0)
    with an identification no estimates have.  Now refused where the file is read, in one
    line naming the key, before any work."""
    loop = LOOP + "\n" + identification(correlation=_not_psd()).partition(LINK)[2]
    t = np.arange(2000) * 1e-3
    force = "time,force\n" + "".join(f"{a:.3f},{b:.6g}\n"
                                      for a, b in zip(t, 50.0 * np.sin(4 * np.pi * t),
                                                      strict=True))
    err = refused(tmp_path, {"bad.toml": identification(correlation=_not_psd()),
                             "loop.toml": loop, "force.csv": force,
                             "st.toml": study_text("loop.toml", n=1).split("[samples]")[0]},
                  argv)
    named = "st.toml: the scenario" if argv[0] == "study" else argv[1]
    assert err.endswith(NOT_PSD.format(named)), err


# ------------------------------------------- F2: a user's file in the store folder is kept
PAPER_STUDY = ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\namplitude = [0.01]\n'
               'frequency_hz = [{}]\n')


@pytest.mark.parametrize("where", ["notes.txt", "e1/notes.txt"])
def test_force_onto_a_store_holding_a_users_file_is_refused(tmp_path, where):
    """``study --force`` onto another study's store replaced the whole folder: a file the user
    had put in it (notes.txt) was deleted with it (exit 0).  Now refused in one line naming
    it, before any point is computed; the store and the file stay as they were."""
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import StudyStore

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "old.toml").write_text(PAPER_STUDY.format("5.0"))
    StudyStore.create(tmp_path / "st.zarr", Study.from_file(tmp_path / "old.toml"))
    err = refused(tmp_path, {"new.toml": PAPER_STUDY.format("6.0"),
                             f"st.zarr/{where}": "my notes\n"},
                  ["study", "new.toml", "--out", "st.zarr", "--workers", "0", "--force"])
    assert err.endswith(f"--out st.zarr: holds {where}, not the study's; --force replaces the "
                        f"store with all in its folder: move them out of it, or give another "
                        f"--out"), err


def test_a_store_is_deleted_only_when_all_in_its_folder_is_its_own(tmp_path):
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import StudyStore, foreign_entries, remove_store

    study = Study.from_dict(tomllib.loads(PAPER_STUDY.format("5.0")),
                            scenario=tomllib.loads(default_scenario_path().read_text()))
    StudyStore.create(tmp_path / "s.zarr", study)
    assert foreign_entries(tmp_path / "s.zarr") == []
    (tmp_path / "s.zarr" / "mine").mkdir()
    (tmp_path / "s.zarr" / "status" / "x.txt").write_text("x")
    assert foreign_entries(tmp_path / "s.zarr") == ["mine", "status/x.txt"]
    with pytest.raises(StudyError, match=r"s\.zarr: holds mine and 1 more, not the store's; "
                                         r"refusing to delete it"):
        remove_store(tmp_path / "s.zarr")
    assert (tmp_path / "s.zarr" / "status" / "x.txt").read_text() == "x"


DS_STORE = b"\x00\x00\x00\x01Bud1" + bytes(24)
"""The first bytes of a .DS_Store as macOS's Finder writes it (a 'Bud1' buddy allocator)."""


def _os_metadata(folder: Path) -> None:
    """What macOS and Windows write into a store folder shown in a file manager."""
    (folder / ".DS_Store").write_bytes(DS_STORE)
    (folder / "e1" / ".DS_Store").write_bytes(DS_STORE)
    (folder / "e1" / "._zarr.json").write_bytes(b"\x00\x05\x16\x07\x00\x02\x00\x00")
    (folder / "Thumbs.db").write_bytes(b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(504))
    (folder / "desktop.ini").write_bytes(b"\xff\xfe" + "\r\n[.ShellClassInfo]\r\n"
                                         .encode("utf-16-le"))


def test_an_operating_systems_files_in_a_store_are_not_the_users(tmp_path):
    """Review C20 L6: a .DS_Store (Finder), ._* (AppleDouble), Thumbs.db or desktop.ini
    (Explorer) in the store's folders made ``--force`` refuse the store as holding the user's
    files.  They are the system's by their name and first bytes: they go with the store.  A
    file of such a name holding anything else, a link or a folder of that name, stays the
    user's."""
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import StudyStore, foreign_entries, remove_store

    study = Study.from_dict(tomllib.loads(PAPER_STUDY.format("5.0")),
                            scenario=tomllib.loads(default_scenario_path().read_text()))
    store = tmp_path / "s.zarr"
    StudyStore.create(store, study)
    _os_metadata(store)
    assert foreign_entries(store) == []
    (store / "status" / "._c").write_text("my notes")  # a user's, not AppleDouble
    (store / "desktop.ini").unlink()
    (store / "Desktop.ini").write_text("my notes")
    (store / "Thumbs.db").unlink()
    (store / "thumbs.db").mkdir()
    (tmp_path / "target").write_bytes(DS_STORE)
    (store / "e1" / ".DS_Store").unlink()
    (store / "e1" / ".DS_Store").symlink_to(tmp_path / "target")
    mine = ["Desktop.ini", "e1/.DS_Store", "status/._c", "thumbs.db"]
    assert foreign_entries(store) == mine
    for name in mine:
        p = store / name
        p.rmdir() if p.is_dir() and not p.is_symlink() else p.unlink()
    remove_store(store)
    assert not store.exists()
    assert (tmp_path / "target").read_bytes() == DS_STORE


def test_force_replaces_a_store_a_file_manager_has_shown(tmp_path):
    """The command of review C20 L6: ``study --force`` onto another study's store that Finder
    and Explorer have shown is exit 0, the new study in the store; the same study again reads
    the store without zarr's warning on the .DS_Store beside its arrays."""
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import StudyStore

    populate(tmp_path, {"paper.toml": default_scenario_path().read_text(),
                        "old.toml": PAPER_STUDY.format("5.0"),
                        "new.toml": PAPER_STUDY.format("6.0")})
    StudyStore.create(tmp_path / "st.zarr", Study.from_file(tmp_path / "old.toml"))
    _os_metadata(tmp_path / "st.zarr")
    argv = ["study", "new.toml", "--out", "st.zarr", "--workers", "0"]
    code, out, err = limited_process.run([*argv, "--force"], tmp_path,
                                         limited_process.RUN_LIMIT)
    assert code == 0, err
    assert "1 points: 1 computed" in out
    assert StudyStore.open(tmp_path / "st.zarr").matches(Study.from_file(tmp_path / "new.toml"))
    assert not (tmp_path / "st.zarr" / "Thumbs.db").exists()
    (tmp_path / "st.zarr" / ".DS_Store").write_bytes(DS_STORE)
    code, out, err = limited_process.run(argv, tmp_path, limited_process.RUN_LIMIT)
    assert code == 0, err
    assert "1 points: 0 computed" in out
    assert "warning" not in err.lower() and "zarr" not in err.lower(), err


def test_the_rate_of_a_slow_study_keeps_its_digits():
    """'2 points: 2 computed in 8.7 s (0 points/s)': the rate rounded to 0."""
    from motionhyst.study.runner import RunReport

    assert "(0.23 points/s)" in str(RunReport(points=2, computed=2, failed=0, seconds=8.7))
    assert "(7.14 points/s)" in str(RunReport(points=50, computed=50, failed=0, seconds=7.0))
    assert "(2400 points/s)" in str(RunReport(points=2400, computed=2400, failed=0,
                                              seconds=1.0))


# ------------------------------- F7: a distribution the scenario refuses; bands of survivors
NORMAL_FC = ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n'
             '[samples]\nn = 4\nseed = 0\n"hysteresis.fc" = {{ {} = [{}, {}] }}\n')


def _paper_folder(tmp_path: Path) -> dict:
    from motionhyst.scenario import default_scenario_path

    return {"paper.toml": default_scenario_path().read_text()}


@pytest.mark.parametrize(("kind", "a", "b", "share"), [
    ("normal", 0.05, 0.1, "30.9 %"),     # P(fc <= 0) = Phi(-0.5) = 0.3085
    ("uniform", -0.01, 0.09, "10 %"),    # 0.01 of 0.1 below 0
    ("normal", 0.05, 0.02, None),        # Phi(-2.5) = 0.62 %: within the 1 % admitted
])
def test_a_distribution_whose_mass_the_scenario_refuses_is_refused_up_front(
        tmp_path, kind, a, b, share):
    """fc normal [0.05, 0.1] on the paper's loop: 28 % of 50 draws failed (fc <= 0) and the
    summary's band was over the 36 left, exit 0.  The share refused is found from the
    distribution's quantiles and the scenario alone, before any point runs."""
    text = NORMAL_FC.format(kind, a, b)
    if share is None:
        study = Study.from_dict(tomllib.loads(text), base_dir=_write_paper(tmp_path))
        assert study.samples["hysteresis.fc"] == (kind, a, b)
        return
    err = refused(tmp_path, {**_paper_folder(tmp_path), "st.toml": text},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0"])
    assert (f"st.toml: [samples] 'hysteresis.fc': {kind} [{a:g}, {b:g}] puts {share} of its "
            f"draws where the scenario refuses them (paper.toml: [hysteresis] fc: Input should "
            f"be greater than 0 (got -") in err, err
    assert err.endswith("more than the 1 % a study admits (its bands would be of the draws "
                        "left); give a lognormal distribution (positive by construction) or one "
                        "within the admitted values"), err


def test_the_shares_refused_at_both_ends_are_added(tmp_path):
    """Dahl's alpha lies in (0, 100]: uniform [-0.9, 100.9] puts 0.88 % of its draws below
    and 0.88 % above, 1.77 % in all, more than the 1 % admitted (each end alone is not)."""
    paper = _paper_folder(tmp_path)["paper.toml"]
    dahl = paper.replace('model = "jenkins"', 'model = "dahl"\nalpha = 50.0')
    assert dahl != paper
    text = ('scenario = "dahl.toml"\noutputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n'
            '[samples]\nn = 4\nseed = 0\n"hysteresis.alpha" = { uniform = [-0.9, 100.9] }\n')
    err = refused(tmp_path, {"dahl.toml": dahl, "st.toml": text},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0"])
    assert "[samples] 'hysteresis.alpha': uniform [-0.9, 100.9] puts 1.77 % of its draws " \
           "where the scenario refuses them" in err, err


def _write_paper(folder: Path) -> Path:
    populate(folder, _paper_folder(folder))
    return folder


def test_a_band_over_fewer_samples_than_drawn_says_of_how_many(tmp_path):
    """Two of five samples failed: the band is the percentiles of the other three's worst
    cases (numpy's, independently), and the summary says 'of 3/5 samples'."""
    from motionhyst.study import open_results
    from motionhyst.study.store import FAILED, OK, StudyStore
    from motionhyst.study.summary import summarize

    text = NORMAL_FC.format("lognormal", 0.05, 0.1).replace("n = 4", "n = 5").replace(
        "[5.0]", "[5.0, 10.0]")
    study = Study.from_dict(tomllib.loads(text), base_dir=_write_paper(tmp_path))
    store = StudyStore.create(tmp_path / "s.zarr", study)
    e1 = np.array([1.0, 4.0, 2.0, 3.0, 5.0, 7.0]) * 1e-8  # samples 0, 2, 4 at 5 and 10 Hz
    status = np.array([OK, FAILED, OK, FAILED, OK] * 2, np.int8)
    indices = np.arange(10)  # frequency_hz, amplitude, sample (C order)
    values = np.full(10, np.nan)
    values[[0, 2, 4, 5, 7, 9]] = e1
    store.write(indices, status, {"e1": values},
                np.where(status == FAILED, 1, 0).astype(np.int8))
    s = summarize(open_results(tmp_path / "s.zarr"))
    worst = np.maximum(e1[:3], e1[3:])  # each computed sample's worst over the frequencies
    np.testing.assert_allclose(list(s.band["e1"].values()), np.percentile(worst, [5, 50, 95]),
                               rtol=1e-12)
    assert s.band_samples["e1"] == {"band": 3, "widest": 3, "of": 5}
    text = str(s)
    assert "Monte Carlo, each sample's worst case, of 3/5 samples: 5 % " in text, text
    assert ", of 3/5 samples: 5 % " in text.split("widest band at")[1], text
    # all samples computed: no count
    store.write([1, 3, 6, 8], np.full(4, OK, np.int8), {"e1": np.full(4, 1e-8)})
    assert "samples:" not in str(summarize(open_results(tmp_path / "s.zarr")))


def test_a_point_refused_by_the_scenario_is_named_by_its_file(tmp_path):
    """The failure line said '<dict>: [hysteresis] fc: ...' (an internal name): now the
    scenario's file."""
    from motionhyst.study.engine import Evaluator
    from motionhyst.study.store import FAILED

    study = Study.from_dict(tomllib.loads(NORMAL_FC.format("lognormal", 0.05, 0.1)),
                            base_dir=_write_paper(tmp_path))
    study.scenario_source = "paper.toml"
    study.sample_values[0, 0] = -0.01  # a draw the scenario refuses
    batch = Evaluator(study).batch([0])
    assert batch.status.tolist() == [FAILED]
    (message,) = batch.failures.values()
    assert message == ("point 0 (frequency_hz = 5, amplitude = 0.01, hysteresis.fc = -0.01): "
                       "paper.toml: [hysteresis] fc: Input should be greater than 0 (got -0.01)")


@pytest.mark.parametrize(("names", "words"), [
    ("self.toml", "'scenario': self.toml is this study file; give the scenario it studies"),
    ("other.toml", "'scenario': other.toml is a study file (it names a scenario and "
                   "outputs); give the scenario it studies"),
])
def test_a_study_file_given_as_the_scenario_is_named_so(tmp_path, names, words):
    """A study naming itself as its scenario said '[scenario]: unknown section'."""
    err = refused(tmp_path, {"self.toml": f'scenario = "{names}"\noutputs = ["e1"]\n[axes]\n'
                                          'frequency_hz = [5.0]\n',
                             "other.toml": 'scenario = "paper.toml"\noutputs = ["e1"]\n'},
                  ["study", "self.toml", "--out", "st.zarr", "--workers", "0"])
    assert err.endswith(f"study: self.toml: {words} (the file of [stage], [controller], ...)"), err


# ------------------------- F9: an identification's stage is the scenario's, or it is refused
TWO_MASS_STUDY = ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\nfrequency_hz = [5.0]\n'
                  '[samples]\nn = 4\nseed = 0\n')


def test_a_link_identified_on_another_stage_is_refused(tmp_path):
    """The mass-damper identification (stage.m 10 kg, stage.c 20 N s/m, correlated with the
    link's k by -0.82) on the paper's two-mass stage: the stage's estimates were dropped
    without a word and the link put on the 22.5 kg stage, exit 0."""
    err = refused(tmp_path, {**_paper_folder(tmp_path), "st.toml": TWO_MASS_STUDY,
                             "id.toml": identification()},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0",
                   "--from-identification", "id.toml"])
    assert "id.toml: its link was identified on a stage (stage.m = 10, stage.c = 19.9999, " \
           "estimated jointly with it) and the scenario's [stage] (m1, m2, b, k) does not " \
           "have m, c; give a scenario of the identified stage, or " \
           "from_identification_tables = [\"hysteresis\"] in [samples] to put the link alone " \
           "on the scenario's stage" in err, err


@pytest.mark.parametrize(("changed", "words"), [
    ("m = 10.5", "the scenario's [stage] m = 10.5 is not the identified stage.m = 10.00002 +- "
                 "1.05e-05 (off by 4.75e+04 standard errors, more than 3)"),
    ("c = 20.01", "the scenario's [stage] c = 20.01 is not the identified stage.c = 19.999854 "
                  "+- 9.26e-05 (off by 110 standard errors, more than 3)"),
])
def test_a_stage_whose_values_differ_from_the_identified_is_refused(tmp_path, changed, words):
    loop = LOOP.replace(changed.split(" = ")[0] + " = " + ("10.0" if changed[0] == "m"
                                                           else "20.0"), changed)
    assert loop != LOOP
    err = refused(tmp_path, {"loop.toml": loop, "st.toml": study_text("loop.toml"),
                             "id.toml": identification()},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0",
                   "--from-identification", "id.toml"])
    assert words in err, err


def test_the_stage_value_a_refusal_prints_is_accepted(tmp_path):
    """An estimate of 10.00004 +- 1.05e-5 kg (3.8 standard errors from 10): the refusal of
    m = 10 prints it with the digits its standard error needs (6 digits said "10"), and the
    scenario given that printed value is accepted (review C20 M1)."""
    estimates = [10.00004, *ESTIMATES[1:]]
    loop = LOOP.replace("m = 10.0", "m = 10")
    assert loop != LOOP
    err = refused(tmp_path, {"loop.toml": loop, "st.toml": study_text("loop.toml"),
                             "id.toml": identification(estimates)},
                  ["study", "st.toml", "--out", "st.zarr", "--workers", "0",
                   "--from-identification", "id.toml"])
    printed = err.split("the identified stage.m = ")[1].split(" +- ")[0]
    assert printed == "10.00004", err
    populate(tmp_path, {"loop.toml": LOOP.replace("m = 10.0", f"m = {printed}")})
    study = Study.from_dict({**tomllib.loads(study_text("loop.toml")),
                             "samples": {"n": 4, "seed": 0, "from_identification": "id.toml"}},
                            base_dir=tmp_path)
    assert study.sampled_keys == tuple(PARAMETERS)


def test_the_identified_stage_is_drawn_with_its_link_when_it_is_the_scenarios(tmp_path):
    """The scenario's [stage] is the identified one (10 kg, 20 N s/m, within 3 standard
    errors of the estimates 10.00002 and 19.99985): its estimates are drawn jointly with the
    link's, with the identification's covariance (k-m correlation -0.82)."""
    populate(tmp_path, {"loop.toml": LOOP, "id.toml": identification()})
    n = 4000
    study = Study.from_dict({**tomllib.loads(study_text("loop.toml", n)),
                             "samples": {"n": n, "seed": 0, "from_identification": "id.toml"}},
                            base_dir=tmp_path)
    assert study.sampled_keys == tuple(PARAMETERS)
    x = study.sample_values
    cov = np.array(CORRELATION) * np.outer(STD, STD)
    se = np.sqrt(np.diag(cov) / n)
    assert np.all(np.abs(x.mean(axis=0) - ESTIMATES) <= 4 * se)
    r = np.corrcoef(x.T)
    rho = np.array(CORRELATION)
    assert np.all(np.abs(r - rho) <= 4 * (1 - rho ** 2) / np.sqrt(n) + 1e-12), r  # its SE
    assert r[0, 2] < -0.78
    # the link alone on the scenario's stage, as the study file says
    alone = Study.from_dict({**tomllib.loads(study_text("loop.toml", 10)),
                             "samples": {"n": 10, "seed": 0, "from_identification": "id.toml",
                                         "from_identification_tables": ["hysteresis"]}},
                            base_dir=tmp_path)
    assert alone.sampled_keys == ("hysteresis.k", "hysteresis.fc")


def test_a_stage_estimate_without_a_standard_error_is_not_drawn(tmp_path):
    """An `identify --json` whose stage estimate has no standard error (not in its covariance,
    as `--save` leaves it out of [identification]) keeps the scenario's value: the stage is
    now read by default, and such an estimate must not refuse the study."""
    cov = (np.array(CORRELATION) * np.outer(STD, STD)).tolist()
    fit = {"plant": {"type": "mass-damper", "m": 10.0, "c": 20.0, "force_offset": 1e-6},
           "hysteresis": {"model": "jenkins", "k": 2000.0, "fc": 2.0},
           "estimates": {"m": ESTIMATES[0], "c": ESTIMATES[1], "link.k": ESTIMATES[2],
                         "link.fc": ESTIMATES[3], "force_offset": 1e-6},
           "covariance": {"parameters": ["m", "c", "link.k", "link.fc"], "matrix": cov}}
    (tmp_path / "fit.json").write_text(json.dumps(fit))
    d = joint_from_identification(tmp_path / "fit.json", ("hysteresis", "stage"))
    assert d.keys == tuple(PARAMETERS)
    np.testing.assert_allclose(d.covariance, cov, rtol=1e-12)
