"""Refusals that name the cause and a remedy the command has (issue 26: "every refusal names
the cause and a remedy the command has"; "misleading messages").

A library function's refusal names its own arguments (``shorten the duration``, ``use more
substeps``); a command reached through it names its options instead, or, where it has none,
the scenario's value to check.  A refusal caused by an implausible ``[stage]`` value names
the value, not the reference.  A record's value that is not finite is named by its column and
sample.

The command lines run in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files; a refusal is exit code 2 and
one line on stderr (no traceback), and every file is byte-identical afterwards.
"""

from __future__ import annotations

from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER_10KHZ = EXAMPLES / "paper_10khz.toml"
JENKINS = ('model = "jenkins"\nk = 20.0              # spring stiffness k_J [N/m]\n'
           'fc = 0.05             # slip force f_c [N]')
SCAN = ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
        "1000", "--s-max", "1e6", "--compensation", "none"]
SCAN_REMEDY = ("shorten the setpoint (--length, --dwell) or --tail, or raise its limits "
               "(--speed, --a-max, --j-max, --s-max)")
QUASI_STATIC = ('[stage]\ntype = "quasi-static"\nk = 10.0\n\n'
                '[hysteresis]\nmodel = "jenkins"\nk = 20.0\nfc = 0.05\n')


def _paper(old: str, new: str) -> str:
    """The paper's scenario with one value changed."""
    assert old in PAPER
    return PAPER.replace(old, new)


def _maxwell_slip(n: int) -> str:
    """The Table I scenario with a Maxwell-slip link of `n` equal elements."""
    return _paper(JENKINS, f'model = "maxwell-slip"\nk = [{", ".join(["20.0"] * n)}]\n'
                           f'fc = [{", ".join(["0.05"] * n)}]')


def _record(columns: dict[str, np.ndarray]) -> str:
    names = list(columns)
    rows = zip(*(columns[n] for n in names), strict=True)
    return ",".join(names) + "\n" + "".join(
        ",".join(repr(float(v)) for v in row) + "\n" for row in rows)


T = np.arange(100) / 100.0
WITH_NAN = 0.01 * np.sin(2 * np.pi * T)
WITH_NAN[50] = np.nan

# (id, the user's files, argv, words of the one line on stderr, words it must not have)
CASES = [
    # ------------------- a run's size: the command's options, not the library's arguments
    ("scan-link-of-3000-elements-over-the-work-budget", {"s.toml": _maxwell_slip(3000)},
     [*SCAN, "--max-seconds", "1"],
     ["a run of 5.59e+03 time steps of a link of 3000 elements would take about",
      "(--max-seconds); " + SCAN_REMEDY + ", or give the link fewer elements ([hysteresis])"],
     ["lower its frequencies", "duration"]),
    ("simulate-link-of-100000-elements-over-the-work-budget",
     {"s.toml": _maxwell_slip(100_000)},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "20", "--duration", "20"],
     ["a run of 6e+05 time steps of a link of 100000 elements, 2e+05 rows written would take "
      "about",
      "(--max-seconds); shorten --duration, or give the link fewer elements ([hysteresis])"],
     ["lower its frequencies"]),
    ("simulate-sampled-loop-of-too-many-controller-samples", {"s.toml": PAPER_10KHZ.read_text()},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration",
      "6000"],
     ["60000001 controller samples at 10000 Hz: too many (at most 5e+07); shorten --duration"],
     ["lower --frequency", "shorten the duration"]),
    ("simulate-sine-of-1MHz", {"s.toml": PAPER},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "1e6"],
     ["too many time steps (a step of 2.5e-09 s: the reference's 1e+06 Hz, resolved in 400 "
      "steps a period)", "; shorten --duration or lower --frequency"], ["output rate"]),
    ("steady-floquet-of-100000-frequencies", {"s.toml": PAPER},
     ["steady", "s.toml", "--frequency", *[f"{1 + i * 1e-3:.3f}" for i in range(100_000)]],
     ["the Floquet multipliers at 100000 frequencies would take about",
      "; give fewer frequencies (--frequency) or leave the multipliers out (--no-floquet)"],
     ["floquet=False"]),
    # ---------- an implausible [stage] value sets the step: named, not the reference's
    ("simulate-actuated-mass-of-a-nanogram", {"s.toml": _paper("m1 = 5.0", "m1 = 1e-9")},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration",
      "0.05"],
     ["too many time steps (a step of 1.75e-12 s: the loop's fastest closed-loop pole, "
      "1.432e+10 Hz, resolved in 40 steps, beyond a motion stage's 1e+05 Hz: s.toml: [stage] "
      "m1 = 1e-09 kg, a factor 1e+06 below the 0.001-10000 kg of motion stages: is it in kg?)",
      "; shorten --duration"], ["reference's frequency", "lower --frequency"]),
    ("simulate-stage-damping-off-by-1e9", {"s.toml": _paper("b = 90.0", "b = 9e10")},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration",
      "0.05"],
     ["s.toml: [stage] b = 9e+10 N s/m gives the stage a pole at 3.7e+09 Hz, beyond the "
      "1e+05 Hz of motion stages: is it in N s/m?"], ["reference's frequency"]),
    ("scan-stage-stiffness-off-by-1e9", {"s.toml": _paper("k = 7.4e7", "k = 7.4e16")}, SCAN,
     ["the step resolves the loop's fastest closed-loop pole, 2.195e+07 Hz (beyond a motion "
      "stage's 1e+05 Hz: s.toml: [stage] k = 7.4e+16 N/m gives the stage a mode at 2.2e+07 "
      "Hz, beyond the 1e+05 Hz of motion stages: is it in N/m?); " + SCAN_REMEDY], []),
    ("scan-acceleration-limit-of-1e-9", {"s.toml": PAPER},
     ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "1e-9", "--j-max",
      "1000", "--s-max", "1e6", "--compensation", "none"],
     ["time steps of 3.16e-09 s: too many; " + SCAN_REMEDY], []),
    # --------------------------------------------- a sampled controller's keys and options
    ("sampled-delay-of-1e9-samples",
     {"s.toml": PAPER_10KHZ.read_text().replace("delay_samples = 1.5", "delay_samples = 1e9")},
     ["analyze", "s.toml"],
     ["s.toml: [controller]: delay_samples = 1e+09 is more than 1000 samples (1e+05 s at "
      "10000 Hz): is it in samples?"], ["memory"]),
    ("scan-rate-between-the-controller-s-samples", {"s.toml": PAPER_10KHZ.read_text()},
     [*SCAN, "--rate", "3000"],
     ["scan: --rate 3000 Hz: s.toml's controller samples at 10000 Hz, which is no whole "
      "multiple of it"], []),
    # ----------------------------- a value that is not finite: its column and sample named
    ("predict-force-of-a-displacement-with-a-nan", {"m.toml": QUASI_STATIC,
                                                    "d.csv": _record({"time": T,
                                                                      "displacement": WITH_NAN})},
     ["predict", "m.toml", "d.csv", "--out", "p.csv"],
     ["d.csv: displacement must be finite: sample 51 (t = 0.5 s) is nan"], ["force"]),
    ("simulate-reference-with-a-nan", {"s.toml": PAPER,
                                       "r.csv": _record({"time": T, "position": WITH_NAN})},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--reference-csv", "r.csv"],
     ["r.csv: the reference's position must be finite: sample 51 is nan"], []),
]


@pytest.mark.parametrize(("files", "argv", "words", "not_words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_refusal_names_the_cause_and_a_remedy_the_command_has(tmp_path, files, argv, words,
                                                                not_words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**files, "notes.txt": "my notes"})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    for word in not_words:
        assert word not in line, (word, line)
    assert snapshot(root) == before


def test_simulate_s_old_spelling_names_steady_s_option(tmp_path):
    """``simulate`` without ``--time-series`` is the old spelling of ``steady``: a refusal of
    its Floquet multipliers names ``steady --no-floquet`` (``simulate`` has no such option),
    in one line, which ends with the spelling's new name (the notice stands alone only before
    an answer)."""
    populate(tmp_path, {"s.toml": _paper("frequencies = [5.0, 10.0, 15.0]", "frequencies = ["
                                         + ", ".join(f"{1 + i * 1e-3:.3f}"
                                                     for i in range(100_000)) + "]")})
    before = snapshot(tmp_path)
    code, out, err = limited_process.run(["simulate", "s.toml"], tmp_path)
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1, err
    assert lines[0].endswith("give fewer frequencies (s.toml's [reference] frequencies) or "
                             "leave the multipliers out (motionhyst steady --no-floquet) "
                             "(`motionhyst simulate` without --time-series is now `motionhyst "
                             "steady`)"), err
    assert snapshot(tmp_path) == before


# (id, scenario, argv, the warning's words)
WARNED = [
    ("analyze-stage-stiffness-off-by-1e9", _paper("k = 7.4e7", "k = 7.4e16"),
     ["analyze", "s.toml", "--frequency", "5"],
     "s.toml: [stage] k = 7.4e+16 N/m gives the stage a mode at 2.2e+07 Hz, beyond the "
     "1e+05 Hz of motion stages: is it in N/m?"),
    ("analyze-amplitude-in-millimetres", _paper("amplitude = 0.01 ", "amplitude = 10.0 "),
     ["analyze", "s.toml", "--frequency", "5"],
     "amplitude 10 m, above the 2 m of a motion stage's half stroke: is it in m?"),
    ("simulate-move-in-millimetres", PAPER,
     ["simulate", "s.toml", "--time-series", "ts.csv", "--profile", "point-to-point",
      "--distance", "10", "--duration", "0.01"],
     "--distance 10 m, longer than the 4 m stroke of a motion stage: is it in m?"),
    ("stability-stage-damping-off-by-1e9", _paper("b = 90.0", "b = 9e10"),
     ["stability", "s.toml"],
     "s.toml: [stage] b = 9e+10 N s/m gives the stage a pole at 3.7e+09 Hz, beyond the "
     "1e+05 Hz of motion stages: is it in N s/m?"),
]


@pytest.mark.parametrize(("scenario", "argv", "words"), [c[1:] for c in WARNED],
                         ids=[c[0] for c in WARNED])
def test_a_stage_value_off_by_orders_of_magnitude_is_a_warning_naming_it(tmp_path, scenario,
                                                                         argv, words):
    populate(tmp_path, {"s.toml": scenario})
    code, out, err = limited_process.run(list(argv), tmp_path)
    assert code == 0 and out, err
    lines = err.strip().splitlines()
    assert all(line.startswith("motionhyst: warning: ") for line in lines), err
    assert sum(words in line for line in lines) == 1, err


def test_a_study_names_its_scenario_s_implausible_mass(tmp_path):
    """``study`` built its points' loops with their warnings silenced: a microgram's stage
    ran (73 s for two points, its pole at 1.4e10 Hz) without a word."""
    populate(tmp_path, {"s.toml": _paper("m1 = 5.0", "m1 = 1e-9"),
                        "st.toml": 'scenario = "s.toml"\noutputs = ["e1"]\n\n[axes]\n'
                                   'frequency_hz = [5.0, 10.0]\n'})
    code, out, err = limited_process.run(["study", "st.toml", "--estimate"], tmp_path)
    assert code == 0 and out, err
    assert ("motionhyst: warning: study: s.toml: [stage] m1 = 1e-09 kg, a factor 1e+06 below "
            "the 0.001-10000 kg of motion stages: is it in kg?") in err.splitlines(), err


def test_a_plausible_stage_of_every_example_says_nothing():
    """The stages of the examples (Table I, the hunting loop, the EMPS axis's) are motion
    stages: no warning."""
    from motionhyst.scenario import load_scenario
    from motionhyst.scenario.schema import implausible_stage

    paths = sorted(EXAMPLES.glob("*.toml"))
    for path in [None, *paths]:
        try:
            sc = load_scenario(path, check=False)
        except Exception:  # a study file, not a scenario
            continue
        assert implausible_stage(sc) == [], path


def test_predict_s_implicit_step_names_its_substeps_option(tmp_path, monkeypatch, capsys):
    """The open-loop run's implicit step that does not converge says the library's remedy
    ("use more substeps", an argument of ``OpenLoop.simulate``); ``predict`` names its
    ``--substeps``.  The run is made to fail (no record of a real axis fails it at the
    default substeps)."""
    from motionhyst.cli import main
    from motionhyst.time import openloop

    def not_converged(*args, **kwargs):
        openloop._check_converged(10**6)

    monkeypatch.setattr(openloop, "simulate_elements", not_converged)
    populate(tmp_path, {"m.toml": '[stage]\ntype = "mass-damper"\nm = 2.0\nc = 10.0\n\n'
                                  '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 4.0\n',
                        "f.csv": _record({"time": T, "force": 50 * np.sin(2 * np.pi * T)})})
    monkeypatch.chdir(tmp_path)
    assert main(["predict", "m.toml", "f.csv", "--out", "p.csv"]) == 2
    err = capsys.readouterr().err
    assert err.strip().endswith("the link is too stiff (or too strongly damped) for the "
                                "integration step; give more --substeps"), err
    assert "use more substeps" not in err and not (tmp_path / "p.csv").exists()


def test_the_open_loop_step_refusal_is_a_value_error_a_search_leaves():
    """A search takes a ``ValueError`` for parameters to leave: the refusal stays one, and
    says its cause apart from the library's remedy."""
    from motionhyst.time.kernel import StepNotConverged
    from motionhyst.time.openloop import _check_converged

    with pytest.raises(ValueError, match=r"use more substeps$") as caught:
        _check_converged(10**6)
    assert isinstance(caught.value, StepNotConverged)
    assert "substeps" not in caught.value.what


def test_the_top_parser_s_refusal_has_one_prefix(capsys):
    """A command that is none of motionhyst's was "motionhyst: error: motionhyst: argument
    command: ..."."""
    from motionhyst.cli import main

    assert main(["no-such-command"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("motionhyst: error: argument command: invalid choice: "
                          "'no-such-command'") and err.count("\n") == 1, err


def test_the_budget_options_before_the_command_set_the_budget(capsys):
    """``motionhyst --max-seconds S COMMAND`` (as the budget's documentation spelt it) was
    "invalid choice: '0.01'"; it sets the budget as the command's own option does.  Given
    both before the command and after it, one value was dropped without a word: refused."""
    from motionhyst.cli import main

    argv = ["steady", "--frequency", "5", "10"]
    assert main(["--max-seconds", "0.01", *argv]) == 2
    err = capsys.readouterr().err
    assert "above the work budget of 0.01 s (--max-seconds)" in err, err
    for option, value in (("--max-seconds", "0.02"), ("--max-memory", "2G")):
        assert main([option, value, *argv, option, value]) == 2
        assert capsys.readouterr().err == (f"motionhyst: error: steady: {option} is given twice "
                                           f"(before the command and after it); give it once\n")
    assert main(["--max-memory", "1K", *argv]) == 2
    assert "above the memory budget of 1.02 kB (--max-memory)" in capsys.readouterr().err


UNDETERMINED = {"m": 2.18, "c": 21.0, "link.sigma0": 1e5, "link.sigma1": 300.0,
                "link.fc": 0.98, "link.fs": 1.2, "link.vs": 0.01, "link.sigma2": 5.0}
"""A LuGre link's fit (a mass-damper's and the link's parameters) whose records determine the
mass alone."""


@pytest.mark.parametrize(("link", "remedy"), [
    ("lugre", "--model jenkins or coulomb"), ("dahl", "--model jenkins or coulomb"),
    ("bouc-wen", "--model jenkins or coulomb"), ("jenkins", "--model coulomb"),
    ("maxwell-slip", "fewer --elements"), ("coulomb", None)])
def test_an_undetermined_fit_s_remedy_names_what_simplifies_its_link(link, remedy):
    """A LuGre fit the records do not determine: main's remedy was 'a simpler link (fewer
    --elements)', an option of Maxwell-slip links only (refused with any other
    --model); now each link is told what simplifies it, and a Coulomb link, the simplest,
    only the record.  (The command, measured: identify short.csv --record input-output
    --model lugre on test_records_of_other_kinds' 64 samples of a mass-spring-damper, exit 2
    after 33 s: 'the records determine 2 of the model's 8 parameters ... give a longer or
    richer record, or a simpler link (--model jenkins or coulomb)'.)"""
    from motionhyst.identify.io_checks import FitFailed
    from motionhyst.identify.io_uncertainty import judge_determined

    std = dict.fromkeys(UNDETERMINED)
    std["m"] = 0.01
    with pytest.raises(FitFailed) as caught:
        judge_determined(UNDETERMINED, std, link=link)
    message = str(caught.value)
    assert message.startswith("the fit failed: the records determine 1 of the model's 8 ")
    assert ("--elements" in message) == (link == "maxwell-slip")
    if remedy is None:
        assert message.endswith("cannot predict; give a longer or richer record")
    else:
        assert message.endswith(f"give a longer or richer record, or a simpler link ({remedy})")
