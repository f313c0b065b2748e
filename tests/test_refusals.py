"""Refusals of what a command cannot work with: a closed output, input files nested too deeply.

Each is one line on stderr and exit code 2, before any work (issue 26).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from motionhyst.cli import main

_MAIN = "import sys; from motionhyst.cli import main; sys.exit(main(sys.argv[1:]))"


def _closed_stdout(argv: list[str], cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _MAIN, *argv], stderr=subprocess.PIPE,
                          text=True, cwd=cwd, timeout=600, preexec_fn=lambda: os.close(1))


def test_a_closed_standard_output_is_refused_not_answered_into_nothing(tmp_path):
    """``motionhyst df ... >&-``: Python gives a closed stdout as None and print() then
    writes nothing, so the command exited 0 with its answer lost."""
    proc = _closed_stdout(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"], tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "standard output is closed" in proc.stderr
    assert "writes no file" in proc.stderr


def test_a_standard_output_opened_for_reading_is_named(tmp_path):
    """``motionhyst df ... 1</dev/null``: every write failed with "Bad file descriptor",
    naming nothing."""
    def read_only():
        fd = os.open(os.devnull, os.O_RDONLY)
        os.dup2(fd, 1)
        os.close(fd)

    argv = [sys.executable, "-c", _MAIN, "df", "--k", "20", "--fc", "0.05", "--amplitude",
            "0.01"]
    proc = subprocess.run(argv, stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=600,
                          preexec_fn=read_only)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "standard output is not open for writing" in proc.stderr


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full here")
@pytest.mark.parametrize("argv", [
    ["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"],           # a table
    ["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "--json"],  # a short JSON
])
def test_a_full_standard_output_is_named(tmp_path, argv):
    """``motionhyst df ... > /dev/full`` said "No space left on device", naming nothing."""
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-c", _MAIN, *argv], stdout=full,
                              stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=600)
    assert proc.returncode == 2
    assert proc.stderr == ("motionhyst: error: standard output: No space left on device\n")


def test_a_broken_pipe_is_still_no_error(tmp_path):
    """Output piped into ``head``: the reader gone is the end of the output, exit 0."""
    proc = subprocess.Popen([sys.executable, "-c", _MAIN, "df", "--k", "20", "--fc", "0.05",
                             "--amplitude", *[str(a) for a in np.geomspace(1e-3, 1, 2000)]],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path)
    proc.stdout.readline()
    proc.stdout.close()
    assert proc.wait(timeout=600) == 0
    assert proc.stderr.read() == b""


def test_a_command_writing_its_results_to_a_file_runs_with_stdout_closed(tmp_path):
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "s.toml").write_text(default_scenario_path().read_text())
    proc = _closed_stdout(["stability", "s.toml", "--figure", "n.png"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "n.png").stat().st_size > 0
    assert "Traceback" not in proc.stderr


def test_an_output_of_none_is_refused_in_process(monkeypatch, capsys):
    monkeypatch.setattr(sys, "stdout", None)
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "standard output is closed" in err


@pytest.mark.parametrize("text", [
    "a = " + "[" * 5000 + "]" * 5000,                        # arrays within arrays
    "a = " + "{b = " * 3000 + "1" + "}" * 3000,              # inline tables within tables
])
@pytest.mark.parametrize("command", [["analyze"], ["steady"], ["study"]])
def test_a_toml_file_nested_too_deeply_is_refused_naming_it(tmp_path, monkeypatch, capsys,
                                                            text, command):
    """It was "maximum recursion depth exceeded", naming neither the file nor the cause."""
    (tmp_path / "deep.toml").write_text(text + "\n")
    monkeypatch.chdir(tmp_path)
    assert main([*command, "deep.toml"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert "deep.toml: TOML nested too deeply" in err


def test_an_identification_nested_too_deeply_is_refused_naming_it(tmp_path, monkeypatch,
                                                                   capsys):
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "s.toml").write_text('scenario = "paper.toml"\noutputs = ["mismatch"]\n\n'
                                     '[axes]\namplitude = [0.01]\nfrequency_hz = [5.0]\n')
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    monkeypatch.chdir(tmp_path)
    assert main(["study", "s.toml", "--from-identification", "deep.json", "--out",
                 "o.zarr"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "deep.json: JSON nested too deeply" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deep.json", "paper.toml", "s.toml"]


@pytest.mark.parametrize("suffix", ["toml", "json"])
def test_an_identification_larger_than_any_is_refused_before_it_is_parsed(
        tmp_path, monkeypatch, capsys, suffix):
    """A 64 MB TOML took 7.8 s of CPU to parse before any check: its size is refused first;
    what ``identify --save`` writes (a few kB) and a 200-element one (0.8 MB) are read."""
    import motionhyst.study.identified as identified
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "s.toml").write_text('scenario = "paper.toml"\noutputs = ["mismatch"]\n\n'
                                     '[axes]\namplitude = [0.01]\nfrequency_hz = [5.0]\n')
    big = tmp_path / f"big.{suffix}"
    last = "{}" if suffix == "json" else "#"  # after blank lines: valid, past the limit by 1
    big.write_text("\n" * (identified.MAX_IDENTIFICATION_BYTES + 1 - len(last)) + last)
    assert big.stat().st_size == identified.MAX_IDENTIFICATION_BYTES + 1

    def parsed(*args, **kwargs):
        raise AssertionError("the file was parsed")

    monkeypatch.setattr(identified, "read_toml", parsed)
    monkeypatch.setattr(identified, "read_text", parsed)
    monkeypatch.chdir(tmp_path)
    assert main(["study", "s.toml", "--from-identification", big.name, "--out", "o.zarr"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"big.{suffix}: 4 MB, too large for an identification" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [big.name, "paper.toml", "s.toml"]


@pytest.mark.parametrize("points_to", ["a folder", "a store", "nothing"])
def test_a_store_named_by_a_link_replaces_the_link_with_force_never_its_target(
        tmp_path, monkeypatch, capsys, points_to):
    """One rule for every writer: a symbolic link is refused without --force; with it the
    link itself is replaced (here by a new store), what it points to left as it was (a
    store holding the same study is not resumed through the link)."""
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import is_study_store

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "s.toml").write_text('scenario = "paper.toml"\noutputs = ["mismatch"]\n\n'
                                     '[axes]\namplitude = [0.01]\nfrequency_hz = [5.0]\n')
    monkeypatch.chdir(tmp_path)
    if points_to == "a folder":
        (tmp_path / "mine").mkdir()
        (tmp_path / "mine" / "notes.txt").write_text("mine")
    elif points_to == "a store":
        assert main(["study", "s.toml", "--out", "mine", "--workers", "0"]) == 0
    target = tmp_path / ("mine" if points_to != "nothing" else "gone")
    before = {p: p.read_bytes() for p in target.rglob("*") if p.is_file()}
    (tmp_path / "o.zarr").symlink_to(target.name)
    capsys.readouterr()
    assert main(["study", "s.toml", "--out", "o.zarr", "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "o.zarr is a symbolic link" in err and "--force" in err
    assert (tmp_path / "o.zarr").is_symlink()
    assert main(["study", "s.toml", "--out", "o.zarr", "--workers", "0", "--force"]) == 0
    assert not (tmp_path / "o.zarr").is_symlink() and is_study_store(tmp_path / "o.zarr")
    assert {p: p.read_bytes() for p in target.rglob("*") if p.is_file()} == before
    assert target.exists() == (points_to != "nothing")


@pytest.mark.parametrize("there", ["a link", "another study's store"])
def test_a_store_replaced_with_force_stays_until_the_new_one_is_made(tmp_path, monkeypatch,
                                                                      capsys, there):
    """The new store is made beside what it replaces and renamed into its place: a failure
    while it is made (a full disk) leaves the link or the other study's store as it was,
    and nothing else."""
    import motionhyst.study.runner as runner
    from motionhyst.scenario import default_scenario_path
    from motionhyst.study.store import StudyStore, is_study_store

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    study = 'scenario = "paper.toml"\noutputs = ["mismatch"]\n\n[axes]\namplitude = [0.01]\n'
    (tmp_path / "s.toml").write_text(study + "frequency_hz = [5.0]\n")
    monkeypatch.chdir(tmp_path)
    if there == "a link":
        (tmp_path / "mine").mkdir()
        (tmp_path / "o.zarr").symlink_to("mine")
    else:
        assert main(["study", "s.toml", "--out", "o.zarr", "--workers", "0"]) == 0
        (tmp_path / "s.toml").write_text(study + "frequency_hz = [6.0]\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    fingerprint = None if there == "a link" else (tmp_path / "o.zarr" / "zarr.json").read_bytes()
    created = StudyStore.create

    def full_disk(path, *args, **kwargs):
        created(path, *args, **kwargs)  # part of it written, then the disk is full
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(runner.StudyStore, "create", full_disk)
    capsys.readouterr()
    assert main(["study", "s.toml", "--out", "o.zarr", "--workers", "0", "--force"]) == 2
    assert capsys.readouterr().err == "motionhyst: error: o.zarr: No space left on device\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    if there == "a link":
        assert (tmp_path / "o.zarr").is_symlink() and os.readlink(tmp_path / "o.zarr") == "mine"
    else:
        assert (tmp_path / "o.zarr" / "zarr.json").read_bytes() == fingerprint
    monkeypatch.setattr(runner.StudyStore, "create", created)
    assert main(["study", "s.toml", "--out", "o.zarr", "--workers", "0", "--force"]) == 0
    assert not (tmp_path / "o.zarr").is_symlink() and is_study_store(tmp_path / "o.zarr")
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("points_to", ["folder", "file", "nothing"])
def test_a_results_folder_named_by_a_link_replaces_the_link_with_force(tmp_path, points_to):
    """``reproduce --out LINK --force``, the rule of every writer: the link itself is replaced
    (by a new folder, when the first file is written), never what it points to; a run
    abandoned puts the link back as it was."""
    from motionhyst.io.outputs import MANIFEST, OutputError, OutputFolder

    (tmp_path / "folder").mkdir()
    (tmp_path / "folder" / "report.md").write_text("mine")
    (tmp_path / "file").write_text("mine")
    link = tmp_path / "out"
    link.symlink_to(points_to)
    listing = {p: p.read_bytes() for p in tmp_path.rglob("*")
               if p.is_file() and not p.is_symlink()}  # not through the link
    with pytest.raises(OutputError, match=r"out is a symbolic link; .* or --force to replace "
                                          r"the link itself"):
        OutputFolder(link, ["report.md"])
    with pytest.raises(RuntimeError, match="a failure"), \
            OutputFolder(link, ["report.md"], force=True) as out:
        out.write_text("report.md", "new")
        raise RuntimeError("a failure")
    assert link.is_symlink() and os.readlink(link) == points_to  # put back as it was
    with OutputFolder(link, ["report.md"], force=True) as out:
        out.write_text("report.md", "new")
    assert not link.is_symlink() and sorted(os.listdir(link)) == [MANIFEST, "report.md"]
    assert (link / "report.md").read_text() == "new"
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()
            and p.parent != link} == listing


def test_a_dahl_shape_exponent_past_its_range_is_refused_by_df(capsys):
    """``df --model dahl --alpha 1e25`` printed a describing function of 2e-20 N/m with a
    negative imaginary part: past about 1e15 the closed form has no digit left."""
    args = ["df", "--model", "dahl", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]
    assert main([*args, "--alpha", "1e25"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert "--alpha" in err and "less than or equal to 100" in err
    assert main([*args, "--alpha", "100", "--json"]) == 0      # the bound itself is taken
    assert '"alpha": 100.0' in capsys.readouterr().out


def test_a_dahl_shape_exponent_past_its_range_is_refused_by_a_scenario():
    import tomllib

    from motionhyst import Dahl, Scenario, ScenarioError
    from motionhyst.scenario import default_scenario_path

    data = tomllib.loads(default_scenario_path().read_text())
    data["hysteresis"] = {"model": "dahl", "k": 20.0, "fc": 0.05, "alpha": 1e3}
    with pytest.raises(ScenarioError, match=r"\[hysteresis\] alpha: Input should be less "
                                            r"than or equal to 100"):
        Scenario.from_dict(data, "s.toml", check=False)
    # Bouc-Wen's alpha (its general form's stiffness) is another parameter: not bound
    data["hysteresis"] = {"model": "bouc-wen", "alpha": 5e4, "beta": 1e3, "gamma": 0.8,
                          "delta": -1.1, "nu": 1.0}
    Scenario.from_dict(data, "s.toml", check=False)
    # the class itself takes it (an identification's search is not bound)
    assert Dahl(k=20.0, fc=0.05, alpha=1e3).alpha == 1e3


DEEP_JSON = "[" * 100_000 + "]" * 100_000


def test_a_manifest_nested_too_deeply_is_not_ours(tmp_path):
    """reproduce --out DIR whose motionhyst-manifest.json is arrays thousands of levels deep
    ended in "maximum recursion depth exceeded" naming nothing: it is no manifest of ours."""
    from motionhyst.io.outputs import MANIFEST, OutputFolder

    (tmp_path / MANIFEST).write_text(DEEP_JSON)
    (tmp_path / "report.md").write_text("mine")
    with pytest.raises(ValueError, match=r"report\.md exists and was not written by"):
        OutputFolder(tmp_path, ["report.md"])              # it authorises nothing
    with OutputFolder(tmp_path, ["other.md"]) as out:
        out.write_text("other.md", "# report")
    assert (tmp_path / "report.md").read_text() == "mine"


def test_a_store_nested_too_deeply_is_no_study_store(tmp_path, monkeypatch, capsys):
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    (tmp_path / "s.toml").write_text('scenario = "paper.toml"\noutputs = ["mismatch"]\n\n'
                                     '[axes]\namplitude = [0.01]\nfrequency_hz = [5.0]\n')
    (tmp_path / "o.zarr").mkdir()
    (tmp_path / "o.zarr" / "zarr.json").write_text(DEEP_JSON)
    monkeypatch.chdir(tmp_path)
    assert main(["study", "s.toml", "--out", "o.zarr"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out o.zarr: exists and is not a study's store" in err
    assert (tmp_path / "o.zarr" / "zarr.json").read_text() == DEEP_JSON


def _run(argv: list[str], cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _MAIN, *argv], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


@pytest.mark.parametrize("argv, says", [
    # 17 s of CPU, exit 0, |E| = 1: the reference a million times faster than the loop
    (["steady", "--frequency", "5", "1e9"],
     "--frequency 1e+09 Hz is more than 2 decades above the loop's fastest closed-loop pole "
     "(691 Hz)"),
    (["analyze", "sampled.toml", "--frequency", "2e6"],
     "--frequency 2e+06 Hz is more than 2 decades above the loop's sampling rate (10000 Hz)"),
    (["steady", "high.toml"], "high.toml: [reference] frequencies: 100000 Hz is more than 2 "
                              "decades above"),
])
def test_a_frequency_the_loop_cannot_mean_is_refused_before_the_work(tmp_path, argv, says):
    from motionhyst.scenario import default_scenario_path

    paper = default_scenario_path().read_text()
    (tmp_path / "sampled.toml").write_text(paper.replace("beta = 0.6 ", "beta = 0.6\n"
                                                         "sample_rate_hz = 1e4 "))
    (tmp_path / "high.toml").write_text(paper.replace("frequencies = [5.0, 10.0, 15.0]",
                                                      "frequencies = [5.0, 1e5]"))
    proc = _run(argv, tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert says in proc.stderr


@pytest.mark.parametrize("k, frequency", [(20.0, "1e-30"), (1e6, "0.01"), (1e7, "0.1")])
def test_a_frequency_below_f_star_is_answered_with_the_warning(tmp_path, k, frequency):
    """Below f* (eq. 13) the link shapes the plant: said, not refused (a stiff link's f* is
    tens of hertz, and its analysis there is what a user asks for)."""
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "s.toml").write_text(default_scenario_path().read_text().replace(
        "k = 20.0 ", f"k = {k!r} "))
    proc = _run(["analyze", "s.toml", "--frequency", frequency, "--json"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert f"{float(frequency):g} Hz below f*" in proc.stderr and "Traceback" not in proc.stderr
    assert len(json.loads(proc.stdout)["mismatch"]) == 1


def test_the_frequency_bound_is_taken_and_the_library_refuses_too():
    from motionhyst import compare_with_describing_function, default_scenario
    from motionhyst.analysis.plausibility import check_frequencies

    loop = default_scenario().loop()
    fastest = max(abs(loop.closed_loop_poles())) / (2 * np.pi)
    check_frequencies([100 * fastest, 1e-30], fastest_pole_hz=fastest)  # the bound itself
    with pytest.raises(ValueError, match="decades above the loop's fastest"):
        compare_with_describing_function(loop, 0.01, [1e5])


def test_a_force_without_loops_that_no_line_describes_is_refused_before_the_fit(tmp_path):
    """A saturating spring (no hysteresis, not a line): Maxwell-slip elements cannot describe
    it, which the fit found after its work (1.4 s of CPU); the record shows it at once.
    With --elements and no --save the fit is reported, its error with it, as before."""
    t = np.arange(600) / 750
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    w = np.clip(20.0 * x, -0.01, 0.01)
    np.savetxt(tmp_path / "clip.csv", np.column_stack([t, x, w]), delimiter=",",
               header="time,displacement,force", comments="")
    proc = _run(["identify", "clip.csv", "--save", "m.toml"], tmp_path)
    assert proc.returncode == 2 and proc.stdout == "" and "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") == 1
    assert "clip.csv: the force is a curve of the displacement alone" in proc.stderr
    assert "Maxwell-slip elements are a straight line until one slips" in proc.stderr
    assert not (tmp_path / "m.toml").exists()
    proc = _run(["identify", "clip.csv", "--elements", "2"], tmp_path)
    assert proc.returncode == 0 and "22.3 % of the force RMS" in proc.stdout


def test_loops_of_a_damper_are_refused_before_the_fit(tmp_path):
    """A spring and a damper in parallel (loops that widen with the speed): the fit found
    after its work (1.3-1.9 s of CPU) that no Maxwell-slip elements leave less than 2 %; the
    record shows it at once.  With --elements and no --save the fit is reported, as before."""
    t = np.arange(600) / 750
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    w = 20.0 * x + np.gradient(x, t) + 1e-4 * np.random.default_rng(2).standard_normal(t.size)
    np.savetxt(tmp_path / "damper.csv", np.column_stack([t, x, w]), delimiter=",",
               header="time,displacement,force", comments="")
    for argv in (["identify", "damper.csv"], ["identify", "damper.csv", "--save", "m.toml"]):
        proc = _run(argv, tmp_path)
        assert proc.returncode == 2 and proc.stdout == "" and "Traceback" not in proc.stderr
        assert proc.stderr.count("\n") == 1
        assert "damper.csv: no hysteresis in the record: the force is a spring's and a " \
               "damper's (they leave 0 % of its RMS, a straight line 55 %)" in proc.stderr
        assert not (tmp_path / "m.toml").exists()
    proc = _run(["identify", "damper.csv", "--elements", "2"], tmp_path)
    assert proc.returncode == 0 and "% of the force RMS" in proc.stdout


@pytest.mark.parametrize("noise", [0.0, 0.02])
def test_records_with_loops_are_never_refused_as_curves(noise):
    """Maxwell-slip's own records (a Jenkins element slipping a little or much, three
    elements under a decaying amplitude, Iwan distributions of twenty), Dahl's, Bouc-Wen's
    (with a spring beside it), and a stiffening spring within what a fit may leave: each goes
    to its fit, neither a curve nor a damper's loops."""
    from motionhyst.hysteresis import BoucWen, Dahl, Jenkins, MaxwellSlip
    from motionhyst.identify.records import check_loops_open

    rng = np.random.default_rng(1)
    t = np.arange(3000) / 750
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    env = np.concatenate([np.geomspace(1e-4, 1e-3, 1500), np.geomspace(1e-3, 1e-4, 1500)])
    cases = [(x, Jenkins(k=20.0, fc=z * 0.02).response(x)) for z in (0.99, 0.9, 0.5, 0.1)]
    cases += [(env * np.sin(2 * np.pi * 3 * t),
               MaxwellSlip(k=[10.0, 6.0, 4.0], fc=[0.002, 0.005, 0.01]).response(
                   env * np.sin(2 * np.pi * 3 * t))),
              (x, Dahl(k=20.0, fc=0.01).response(x)),
              (x, 20.0 * x + 3e6 * x ** 3)]                  # 3.4 % from a line: the fit's
    for slip in (0.1, 1.0, 3.0):  # the largest slip displacement over the amplitude
        fc = 1e-3 * slip * np.linspace(0.05, 1.0, 20)
        cases += [(x, MaxwellSlip(k=[1.0] * 20, fc=fc).response(x)),
                  (x, MaxwellSlip(k=[1.0] * 20, fc=fc ** 2 / fc[-1]).response(x)),
                  (x, BoucWen(k=20.0, fc=0.02 * slip, n=2.0).response(x) + 5.0 * x)]
    for xx, w in cases:
        check_loops_open(xx, w + noise * np.std(w) * rng.standard_normal(w.size), t)
