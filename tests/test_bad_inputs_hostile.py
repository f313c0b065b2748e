"""The hostile corpus (issue 26, the further cases): output names, empty values, signals.

Each refusal runs the command line in a child process whose address space is
limited (``RLIMIT_AS``, :mod:`limited_process`), in a folder holding the
user's files, and asserts exit code 2, one line on stderr without a
traceback, nothing on stdout, and that every file that was there before is
byte-identical afterwards, with no file added.  The signal cases send SIGTERM
as a service manager or ``kill`` would: exit 130, one line, the old files
intact and no temporary file left.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
STUDY = ('scenario = "s.toml"\noutputs = ["e1"]\n\n[axes]\namplitude = [0.001, 0.01]\n'
         'frequency_hz = [1.0, 2.0]\n')
MODEL = ('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
         '[hysteresis]\nmodel = "jenkins"\nk = 100.0\nfc = 1.0\n')


def _force(n: int = 300) -> str:
    t = np.arange(n) / 750.0
    return "time,force\n" + "".join(f"{a!r},{np.sin(i / 10):.6f}\n"
                                     for i, a in enumerate(t.tolist()))


def _one_period(n: int) -> str:
    """A force record of one period of a sine, `n` samples (a --periodic input)."""
    return "time,force\n" + "".join(f"{i / 750!r},{np.sin(2 * np.pi * i / n):.6f}\n"
                                     for i in range(n))


def _link(force: str = "jenkins") -> str:
    """A force-displacement record (time,displacement,force) of a Jenkins element, of a
    spring (`force` "spring": it never slips) or of sensor noise alone ("noise")."""
    from motionhyst.hysteresis import Jenkins

    t = np.arange(500) / 250.0
    envelope = np.concatenate([np.geomspace(0.01, 5e-4, 250), np.geomspace(5e-4, 0.01, 250)])
    x = envelope * np.sin(2 * np.pi * 2.0 * t)
    f = {"jenkins": lambda: Jenkins(k=20.0, fc=0.05).response(x), "spring": lambda: 20.0 * x,
         "noise": lambda: 0.02 * np.random.default_rng(0).standard_normal(t.size)}[force]()
    return "time,displacement,force\n" + "".join(
        f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), x.tolist(), f.tolist(),
                                                 strict=True))


def _io_record() -> str:
    """A record of a mass-spring-damper under a two-sine force (time,force,displacement)."""
    from motionhyst.time.openloop import MassSpringDamper, OpenLoop

    t = np.arange(600) / 750.0
    u = 50.0 * np.sin(2 * np.pi * 7.0 * t) + 20.0 * np.sin(2 * np.pi * 31.0 * t)
    y = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4)).simulate(t, u).displacement
    return "time,force,displacement\n" + "".join(
        f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), u.tolist(), y.tolist(),
                                                 strict=True))


BASE = {"s.toml": PAPER, "st.toml": STUDY, "model.toml": MODEL, "f.csv": _force(),
        "rec.csv": _link(), "notes.txt": "my notes", "old.csv": "time,error\n0,0\n"}

SCAN = ["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
        "--s-max", "1e6"]
WRITERS = {  # a command that writes a file, up to the output's name
    "simulate": ["simulate", "--frequency", "5", "--time-series"],
    "scan": [*SCAN, "--time-series"],
    "identify": ["identify", "rec.csv", "--elements", "1", "--save"],
    "predict": ["predict", "model.toml", "f.csv", "--out"],
    "stability": ["stability", "--figure"],
    "study": ["study", "st.toml", "--workers", "1", "--table"],
    "reproduce": ["reproduce", "--out"],
}
FILE = {"simulate": "o.csv", "scan": "o.csv", "identify": "m.toml", "predict": "p.csv",
        "stability": "f.png", "study": "t.csv", "reproduce": "out"}

# (id, extra files, argv, words the message must contain)
CASES = []
for _name, _argv in WRITERS.items():
    CASES += [
        # an empty value (an unset shell variable) is no value: the option is not dropped
        (f"{_name}-empty-name", {}, [*_argv, ""], ["is empty"]),
        # the standard output's usual name is not made a file named '-'
        (f"{_name}-dash", {}, [*_argv, "-"], ["-"]),
        # a folder that even root cannot create a file in: refused before the work
        (f"{_name}-proc", {}, [*_argv, f"/proc/{FILE[_name]}", "--force"], ["/proc"]),
    ]
    if _name != "reproduce":  # reproduce's --out is a folder
        CASES.append((f"{_name}-trailing-slash", {}, [*_argv, f"{FILE[_name]}/"], ["ends in /"]))
        # a text file named .mat would be read back as MATLAB (and fail) by every reader
        CASES.append((f"{_name}-named-mat", {}, [*_argv, "o.MAT"], ["writes no MATLAB file"]))
CASES += [
    # a header naming a column twice: pandas would read the first and rename the second
    ("reference-column-twice", {"r.csv": "time,position,Position\n" + "".join(
        f"{i / 1000},{i * 1e-5},{-i * 1e-5}\n" for i in range(20))},
     ["simulate", "--reference-csv", "r.csv", "--time-series", "o.csv"], ["twice"]),
    ("record-column-twice", {"r.csv": "time;displacement;force;displacement\n0;0;0;1\n"},
     ["identify", "r.csv"], ["twice"]),
    # a force-displacement record that cannot tell a slip force: no answer
    ("link-force-is-noise", {"r.csv": _link(force="noise")}, ["identify", "r.csv"],
     ["no hysteresis"]),
    ("link-force-of-a-spring", {"r.csv": _link(force="spring")}, ["identify", "r.csv"],
     ["no hysteresis"]),
    ("max-memory-beyond-floats", {}, ["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01",
                                      "--max-memory", "1e400"], ["not a size"]),
    ("scenario-empty-name", {}, ["analyze", ""], ["is empty"]),
    ("columns-empty", {}, ["identify", "rec.csv", "--columns="], ["--columns"]),
    ("scenario-option-empty", {}, ["identify", "rec.csv", "--scenario", ""], ["is empty"]),
    # a study's store: made by the command itself, checked as every output is, before the work
    ("study-out-dash", {}, ["study", "st.toml", "--out", "-"], ["--out -: not a folder name"]),
    ("study-out-proc", {}, ["study", "st.toml", "--out", "/proc/o.zarr"],
     ["cannot create a file in /proc"]),
    ("study-out-symbolic-link", {"mine/notes.txt": "mine", "@symlink:o.zarr": "mine"},
     ["study", "st.toml", "--out", "o.zarr"], ["o.zarr is a symbolic link", "--force"]),
    # the record that sets predict's initial state is an input too: never its output
    ("predict-out-is-init-from", {"io.csv": _io_record()},
     ["predict", "model.toml", "f.csv", "--out", "io.csv", "--init-from", "io.csv", "--force"],
     ["--out io.csv: it is an input of this command"]),
    # options an estimate would ignore (it computes and writes nothing)
    *[(f"study-estimate-{opt.lstrip('-')}", {}, ["study", "st.toml", "--estimate", opt, *value],
       [f"--estimate: {opt} has no effect"])
      for opt, value in (("--table", ["t.csv"]), ("--netcdf", ["t.nc"]),
                         ("--figure", ["f.png"]), ("--force", []),
                         ("--scheduler", ["tcp://127.0.0.1:8786"]))],
    # two outputs of one study naming one file: the second replaced the first after the work
    ("study-table-and-netcdf-one-file", {},
     ["study", "st.toml", "--out", "o.zarr", "--table", "x.csv", "--netcdf", "./x.csv"],
     ["--netcdf ./x.csv: also the --table file"]),
    ("study-figure-is-the-table", {"old.png": "old"},
     ["study", "st.toml", "--out", "o.zarr", "--table", "old.png", "--figure", "old.png",
      "--force"], ["--figure old.png: also the --table file"]),
    # a file written into the store is not the study's (the store is replaced as a whole)
    ("study-workers-with-a-scheduler", {},
     ["study", "st.toml", "--out", "o.zarr", "--workers", "2", "--scheduler",
      "tcp://127.0.0.1:8786"], ["--workers has no effect with --scheduler"]),
    ("study-summary-force-without-a-file", {}, ["study", "--summary", "o.zarr", "--force"],
     ["--force has no effect without --table, --netcdf or --figure"]),
    # the criterion chooses the number of elements: with --elements it chose nothing
    ("identify-criterion-with-elements", {},
     ["identify", "rec.csv", "--elements", "2", "--criterion", "bic"],
     ["--criterion has no effect with --elements"]),
    ("study-table-inside-the-store", {},
     ["study", "st.toml", "--out", "o.zarr", "--table", "o.zarr/t.csv"],
     ["--table o.zarr/t.csv: inside the store o.zarr"]),
]


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES) >= 30


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_hostile_input_is_exit_2_one_line_and_touches_nothing(tmp_path, files, argv, words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**BASE, **files})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before  # nothing changed, nothing added
    assert [p.name for p in tmp_path.iterdir()] == ["user"]


@pytest.mark.parametrize(("budget", "words"), [
    (None, ["needs 6.4 GB, above the memory budget of", "fewer samples or substeps"]),
    ("64G", ["out of memory"]),
], ids=["own-budget", "budget-past-the-limit"])
def test_the_memory_limit_bites_on_a_case_that_needs_more(tmp_path, budget, words):
    """The limit of these tests means something: a periodic prediction of 20000 samples of
    10000 integration steps each (6.4 GB: the period upsampled at once; a run from rest goes
    in blocks) is refused by its own budget, which follows the limit; with its budget raised
    past the limit it meets the limit itself: a MemoryError, still one line and exit 2, and
    nothing written."""
    populate(tmp_path, {"model.toml": MODEL, "f.csv": _one_period(20_000)})
    before = snapshot(tmp_path)
    argv = ["predict", "model.toml", "f.csv", "--out", "p.csv", "--substeps", "10000",
            "--periodic"]
    line = limited_process.refusal(argv + (["--max-memory", budget] if budget else []),
                                   tmp_path)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(tmp_path) == before


def test_a_folder_that_takes_no_file_is_refused_by_trying_one(tmp_path):
    """The check creates a file (unnamed, or named and removed at once) and leaves nothing."""
    from motionhyst.io.outputs import OutputError, OutputFile, OutputFolder

    OutputFile(tmp_path / "o.csv")
    OutputFolder(tmp_path / "out", ["report.md"])
    assert list(tmp_path.iterdir()) == []
    for make in (lambda: OutputFile("/proc/o.csv"), lambda: OutputFolder("/proc/out", ["a"])):
        with pytest.raises(OutputError, match="/proc"):
            make()


def _started(proc: subprocess.Popen, module: str, timeout: float = 120.0) -> None:
    """Wait until `proc` has loaded `module` (its work has begun), or fail."""
    deadline = time.monotonic() + timeout
    maps = Path(f"/proc/{proc.pid}/maps")
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"ended early: {proc.stderr.read().decode(errors='replace')}")
        try:
            if module in maps.read_text():
                return
        except OSError:
            pass
        time.sleep(0.05)
    pytest.fail(f"{module} was never loaded")


@pytest.mark.skipif(not Path("/proc/self/maps").is_file(), reason="needs /proc")
@pytest.mark.parametrize("argv", [
    ["simulate", "--time-series", "old.csv", "--frequency", "5", "--duration", "60", "--force"],
    ["steady", "s.toml", "--frequency", "0.2", "0.5", "1", "2", "3", "4"],
], ids=["simulate", "steady"])
def test_sigterm_before_any_file_is_written_is_exit_130_and_touches_nothing(tmp_path, argv):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, BASE)
    before = snapshot(tmp_path)
    proc = limited_process.popen(argv, root)
    _started(proc, "_multiarray_umath")  # numpy loaded: the command is under way
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.decode().strip().splitlines()[-1:] == ["motionhyst: interrupted"]
    assert "Traceback" not in err.decode() and "Fatal Python" not in err.decode()
    assert snapshot(tmp_path) == before


def test_sigterm_in_a_process_forked_by_a_command_ends_it_by_default(tmp_path):
    """A command's SIGTERM handler raises in the command only: a forked worker that gets
    SIGTERM (a pool shutting down) ends by the signal, without a traceback."""
    code = ("import os, signal, sys\n"
            "from motionhyst.cli import _Interrupts\n"
            "_Interrupts()\n"
            "pid = os.fork()\n"
            "if pid == 0:\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n"
            "    os._exit(0)\n"
            "_, status = os.waitpid(pid, 0)\n"
            "print(os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, cwd=tmp_path)
    assert done.stdout.strip() == "True", done.stderr
    assert done.stderr == ""


def test_main_leaves_the_signal_handlers_as_it_found_them(capsys):
    before = [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)]
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 0
    assert [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)] == before


def test_minus_zero_is_zero(capsys):
    """``--amplitude -0`` passed the >= 0 check and gave the describing function 0 (its limit
    at A -> 0 is the initial stiffness)."""
    argv = ["df", "--k", "20", "--fc", "0.05", "--amplitude", "-0", "--json"]
    assert main(argv) == 0
    minus = capsys.readouterr().out
    assert main([*argv[:-2], "0", "--json"]) == 0
    assert minus == capsys.readouterr().out
    assert '"abs": 20.0' in minus


def test_identify_stops_at_its_cpu_time_budget_and_saves_nothing(tmp_path, monkeypatch,
                                                                 capsys):
    """A search has no estimate before it runs: it is stopped at --max-seconds of CPU time."""
    populate(tmp_path, {"io.csv": _io_record()})
    monkeypatch.chdir(tmp_path)
    before = snapshot(tmp_path)
    code = main(["identify", "io.csv", "--record", "input-output", "--model", "jenkins",
                 "--plant", "mass-spring-damper", "--save", "m.toml", "--max-seconds", "0.05"])
    out, err = capsys.readouterr()
    assert code == 2, err
    assert out == ""
    line = err.strip().splitlines()[-1]
    assert "did not finish within the work budget" in line and "--max-seconds" in line
    assert "Traceback" not in err
    assert snapshot(tmp_path) == before
    assert signal.getsignal(signal.SIGPROF) in (signal.SIG_DFL, None)


def test_a_signal_swallowed_during_a_write_still_stops_it(tmp_path):
    """A KeyboardInterrupt raised inside a C callback (numba's compiler caching a kernel) is
    swallowed there and the writer goes on: the signal is remembered, the old file kept."""
    from motionhyst.io.outputs import OutputFile

    target = tmp_path / "o.csv"
    target.write_text("old\n")
    with pytest.raises(KeyboardInterrupt), OutputFile(target, force=True).open() as fh:
        fh.write("new\n")
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)  # the handler raises at once
        except KeyboardInterrupt:
            pass  # swallowed, as a C callback does
    assert target.read_text() == "old\n"
    assert list(tmp_path.iterdir()) == [target]


def test_an_interrupt_swallowed_by_a_c_callback_ends_the_command_130(monkeypatch, capsys):
    """Python reports an exception it cannot raise (in a C callback) to sys.unraisablehook,
    with a traceback on stderr, and goes on; the command notes it and ends interrupted."""
    import motionhyst.cli.df as df

    def run(args):
        exc = KeyboardInterrupt("SIGINT")
        sys.unraisablehook(types.SimpleNamespace(exc_type=KeyboardInterrupt, exc_value=exc,
                                                 exc_traceback=None, err_msg=None,
                                                 object=None))
        return 0

    monkeypatch.setattr(df, "run", run)
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 130
    assert capsys.readouterr().err.strip() == "motionhyst: interrupted"
    assert sys.unraisablehook is not None and "_Interrupts" not in repr(sys.unraisablehook)


# ------------------------------------------------------------------ CSV dialects and .mat kinds
def _columns() -> list[np.ndarray]:
    t = np.arange(120) / 1000.0
    return [t, 1e-3 * np.sin(2 * np.pi * 5.0 * t), -2.5 * np.cos(2 * np.pi * 5.0 * t)]


def _csv(sep: str = ",", eol: str = "\n", cell=repr, head=("time", "force", "displacement"),
         rows: int | None = None) -> str:
    cols = [c[:rows] for c in _columns()]
    return sep.join(head) + eol + "".join(sep.join(cell(v) for v in r) + eol
                                         for r in zip(*[c.tolist() for c in cols], strict=True))


DIALECTS = {  # a logger's or a spreadsheet's way of writing the same record
    "tab": _csv(sep="\t"),
    "semicolon": _csv(sep=";"),
    "semicolon-decimal-comma": _csv(sep=";", cell=lambda v: repr(v).replace(".", ",")),
    "bom": "\ufeff" + _csv(),
    "crlf": _csv(eol="\r\n"),
    "bom-crlf": "\ufeff" + _csv(eol="\r\n"),
    "cr": _csv(eol="\r"),
    "quoted": _csv(cell=lambda v: f'"{v!r}"', head=('"time"', '"force"', '"displacement"')),
    "spaces": _csv(sep=" , "),
    "trailing-separator": _csv().replace("\n", ",\n"),
    "blank-lines": _csv().replace("\n", "\n\n", 3) + "\n\n",
    "upper-case-header": _csv(head=("TIME", "Force", "Displacement")),
    "plus-signs": _csv(cell=lambda v: ("+" if v >= 0 else "") + repr(v)),
    "utf-16": _csv().encode("utf-16"),
}


@pytest.mark.parametrize("text", DIALECTS.values(), ids=DIALECTS.keys())
def test_a_csv_dialect_gives_the_same_numbers(tmp_path, text):
    from motionhyst.io.records import read_record

    path = tmp_path / "r.csv"
    (path.write_bytes if isinstance(text, bytes) else path.write_text)(text)
    data = read_record(path, ("time", "force", "displacement"))
    np.testing.assert_array_equal(data, np.column_stack(_columns()))


BAD_CSV = {  # what no dialect reads as the numbers meant: one line naming the place
    "decimal-comma-quoted": (_csv(cell=lambda v: '"' + repr(v).replace(".", ",") + '"'),
                             "non-numeric"),
    "hex-floats": (_csv(cell=float.hex), "non-numeric"),
    "thousands-separators": (_csv(cell=lambda v: f'"{1e4 * v:,.3f}"'), "non-numeric"),
    "units-in-header": (_csv(head=("time [s]", "force [N]", "displacement [m]")), "missing"),
    "comment-line-first": ("# exported by a logger\n" + _csv(), "missing"),
    "nul-bytes": (_csv().replace("\n", "\x00\n", 3), "not a CSV file"),
    "one-row": (_csv(rows=1), "r.csv"),
    "header-only": ("time,force,displacement\n", "no data rows"),
    "repeated-rows": (_csv() + _csv().split("\n", 1)[1], "time must increase"),
    "time-twice": (_csv().replace("\n0.06,", "\n0.059,", 1), "r.csv"),
}


@pytest.mark.parametrize(("text", "word"), BAD_CSV.values(), ids=BAD_CSV.keys())
def test_a_record_no_dialect_reads_is_refused_in_one_line(tmp_path, text, word):
    populate(tmp_path, {"r.csv": text, "model.toml": MODEL})
    before = snapshot(tmp_path)
    line = limited_process.refusal(["predict", "model.toml", "r.csv", "--out", "p.csv"],
                                   tmp_path)
    assert word in line, (word, line)
    assert snapshot(tmp_path) == before


def _mat(kind: str, path: Path) -> None:
    """A MATLAB file holding time, force and displacement, one of them of an odd kind."""
    from scipy.io import savemat
    from scipy.sparse import csr_matrix

    t, f, x = _columns()
    odd = {"int16": {"displacement": (x * 1e4).astype(np.int16)},
           "float32": {"force": f.astype(np.float32)},
           "bool": {"force": f > 0},
           "3-d": {"force": f.reshape(-1, 1, 1)},
           "complex": {"force": f + 0j},
           "sparse": {"force": csr_matrix(f)},
           "int64-time": {"time": np.arange(t.size, dtype=np.int64) * 256},
           "uint8-time": {"time": np.arange(t.size).astype(np.uint8) * 3},
           "empty": {"force": np.zeros((0, 0))}}[kind]
    savemat(path, {"time": t, "force": f, "displacement": x, **odd})


MATS = {"int16": None, "float32": None, "bool": None, "3-d": None, "int64-time": None,
        "complex": "complex", "sparse": "sparse", "empty": "empty",
        "uint8-time": "increasing"}


@pytest.mark.parametrize(("kind", "word"), MATS.items(), ids=MATS.keys())
def test_a_mat_variable_of_another_type_is_read_as_its_values_or_refused(tmp_path, kind, word):
    from motionhyst.identify.records import load_force_displacement_csv
    from motionhyst.io.records import RecordError, read_record

    path = tmp_path / "r.mat"
    _mat(kind, path)
    if word is None:  # integers, singles, logicals, a trailing singleton dimension: values
        data = read_record(path, ("time", "force", "displacement"))
        assert data.dtype == np.float64 and data.shape == (120, 3)
        assert np.isfinite(data).all()
    else:
        with pytest.raises((RecordError, ValueError), match=word):
            load_force_displacement_csv(path)


@pytest.mark.parametrize("variable", ["MOTIONHYST_MAX_MEMORY", "MOTIONHYST_MAX_SECONDS"])
@pytest.mark.parametrize("value", ["garbage", "nan", "-1", "1e400"])
def test_a_budget_variable_that_is_no_size_is_refused_by_every_command(tmp_path, variable,
                                                                       value):
    """Not only by the commands whose computation consults the budget (df never does)."""
    code, out, err = limited_process.run(["df", "--k", "20", "--fc", "0.05", "--amplitude",
                                          "0.01"], tmp_path,
                                         env=limited_process.environment(**{variable: value}))
    assert code == 2
    assert out == "" and err.strip() == err.strip().splitlines()[0]
    assert variable in err


def test_a_refusal_keeps_its_exit_code_when_stderr_cannot_be_written(monkeypatch):
    closed = open(os.devnull, "w")
    closed.close()
    monkeypatch.setattr(sys, "stderr", closed)
    assert main(["df", "--k", "-20", "--fc", "0.05", "--amplitude", "0.01"]) == 2


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_output_to_a_full_disk_is_exit_2_in_plain_words(tmp_path):
    with open("/dev/full", "w") as full:
        code, _, err = limited_process.run(["df", "--k", "20", "--fc", "0.05", "--amplitude",
                                            "0.01"], tmp_path, stdout=full, timeout=120)
    assert code == 2
    assert err.strip() == "motionhyst: error: standard output: No space left on device"


def test_a_work_budget_beyond_a_timer_is_no_limit(tmp_path, monkeypatch, capsys):
    """--max-seconds 1e10 (more than setitimer holds) ended in an OverflowError, exit 1."""
    populate(tmp_path, {"rec.csv": _link()})
    monkeypatch.chdir(tmp_path)
    assert main(["identify", "rec.csv", "--elements", "1", "--max-seconds", "1e10"]) == 0
    assert "k [N/m]" in capsys.readouterr().out


def test_main_in_another_thread_leaves_signals_and_hooks_alone(monkeypatch, capsys):
    import threading

    import motionhyst.cli.df as df

    seen = []
    monkeypatch.setattr(df, "run", lambda args: seen.append(sys.unraisablehook) or 0)
    hook = sys.unraisablehook
    codes = []
    thread = threading.Thread(target=lambda: codes.append(
        main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"])))
    thread.start()
    thread.join()
    assert codes == [0] and seen == [hook] and sys.unraisablehook is hook


def test_font_fallbacks_are_not_reported_on_stderr():
    """A font cache without matplotlib's STIX fonts made every figure command print a
    'findfont: ... not found' line per math font family (21 for reproduce)."""
    import logging

    import motionhyst.core.plotting  # noqa: F401

    assert logging.getLogger("matplotlib.font_manager").getEffectiveLevel() >= logging.ERROR


# ------------------------------------------------------------------ a study's store, damaged
def _store(root: Path) -> Path:
    """The store of BASE's study, two of its four points written (as an interrupted run
    leaves it)."""
    from motionhyst.study import Study
    from motionhyst.study.store import OK, StudyStore

    study = Study.from_file(root / "st.toml")
    store = StudyStore.create(root / "o.zarr", study)
    store.write([0, 1], np.array([OK, OK], np.int8), {"e1": np.array([1e-9 + 0j, 2e-9 + 0j])})
    return root / "o.zarr"


def _edit_json(path: Path, change) -> None:
    import json

    meta = json.loads(path.read_text())
    change(meta)
    path.write_text(json.dumps(meta))


def _remove_status(store: Path) -> None:
    import shutil

    shutil.rmtree(store / "status")


def _unknown_status(store: Path) -> None:
    import zarr

    zarr.open_group(str(store), mode="r+")["status"].set_basic_selection((0, 0), 7)


DAMAGES = {  # how a store comes apart (a copy cut short, a disk error, another program), and
    # the words that name it
    "status-removed": (_remove_status, "no array 'status'"),
    "fields-attribute-removed": (lambda s: _edit_json(
        s / "zarr.json", lambda m: m["attributes"].pop("fields")), "no 'fields' attribute"),
    "fields-attribute-garbage": (lambda s: _edit_json(
        s / "zarr.json", lambda m: m["attributes"].update(fields="{x")), "not JSON"),
    "status-chunk-cut-short": (lambda s: (s / "status/c/0/0").write_bytes(b"\x28\xb5"),
                               "its status cannot be read"),
    "status-shape-changed": (lambda s: _edit_json(
        s / "status/zarr.json", lambda m: m.update(shape=[2, 3])), "has shape (2, 3)"),
    "status-type-changed": (lambda s: _edit_json(
        s / "status/zarr.json", lambda m: m.update(data_type="float64")), "holds float64"),
    "axes-past-their-values": (lambda s: [_edit_json(
        s / f"{name}/zarr.json", lambda m: m.update(shape=[10**5, 10**5])) for name in (
        "e1", "status", "reason")], "does not have the 100000 values"),
    "status-value-unknown": (_unknown_status, "status 7 at point 0"),
}


@pytest.mark.parametrize("command", ["summary", "resume", "table"])
@pytest.mark.parametrize(("damage", "words"), DAMAGES.values(), ids=DAMAGES.keys())
def test_a_damaged_store_is_named_as_such_and_left_alone(tmp_path, damage, words, command):
    """A store whose arrays or attributes are missing, cut short or changed: one line naming
    it a damaged study store (was: 'internal error: KeyError' or a codec's message), exit 2,
    nothing changed; a resume says how to replace it."""
    root = tmp_path / "user"
    root.mkdir()
    populate(root, BASE)
    damage(_store(root))
    before = snapshot(root)
    run = ["study", "st.toml", "--out", "o.zarr", "--workers", "0"]
    argv = {"summary": ["study", "--summary", "o.zarr"], "resume": run,
            "table": [*run, "--table", "t.csv"]}[command]
    line = limited_process.refusal(argv, root)
    assert "o.zarr: a damaged study store" in line and words in line, line
    if command != "summary":
        assert line.endswith("give --force to replace it"), line
    assert snapshot(root) == before


def test_force_replaces_a_damaged_store(tmp_path):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, BASE)
    (_store(root) / "status/c/0/0").write_bytes(b"\x28\xb5")
    limit = limited_process.RUN_LIMIT
    code, out, err = limited_process.run(["study", "st.toml", "--out", "o.zarr", "--workers",
                                          "0", "--force"], root, limit)
    assert code == 0, err
    assert out.startswith("4 points: 4 computed"), out
    code, out, err = limited_process.run(["study", "--summary", "o.zarr", "--json"], root, limit)
    assert code == 0, err


def test_an_error_on_the_way_to_the_chunks_is_not_called_damage(tmp_path, monkeypatch):
    """Under a memory limit zarr may find no thread to start: 'can't start new thread' is
    not the store's fault, and 'remove it' would be the wrong advice."""
    from motionhyst.study.store import StudyStore

    populate(tmp_path, BASE)
    store = StudyStore.open(_store(tmp_path))

    class NoThread:
        def __getitem__(self, key):
            raise RuntimeError("can't start new thread")

    monkeypatch.setattr(store, "group", {"status": NoThread()})
    with pytest.raises(RuntimeError, match="can't start new thread"):
        store.status()


def test_a_store_of_another_version_is_resumed_with_a_word(tmp_path):
    """Its points stay as that version computed them: said, not refused (the layout is
    checked; a version's numbers may differ in their last digits)."""
    from motionhyst import __version__
    from motionhyst.study.store import OK, StudyStore

    populate(tmp_path, BASE)
    path = _store(tmp_path)
    store = StudyStore.open(path)
    store.write([2, 3], np.array([OK, OK], np.int8), {"e1": np.array([3e-9 + 0j, 4e-9 + 0j])})
    store.group.attrs["version"] = "99.0"
    code, out, err = limited_process.run(["study", "st.toml", "--out", "o.zarr", "--workers",
                                          "0"], tmp_path, limited_process.RUN_LIMIT)
    assert code == 0, err
    assert out.startswith("4 points: 0 computed"), out
    assert err.strip().splitlines() == [
        "motionhyst: warning: study: o.zarr: a store of motionhyst 99.0, resumed by "
        f"{__version__}: the points it holds stay as that version "
        "computed them"]


def test_df_of_coulomb_friction_is_printed_without_a_ratio_to_its_zero_stiffness(capsys):
    """Coulomb friction has no elastic range (k_init 0): the table divided by it (internal
    error, exit 1)."""
    assert main(["df", "--model", "coulomb", "--fc", "0.05", "--amplitude", "0.01",
                 "--frequency", "5"]) == 0
    out = capsys.readouterr().out
    assert "k_init [-]" not in out and "no elastic range" in out
    row = out.splitlines()[3].split()
    assert [float(v) for v in row[:5]] == pytest.approx([0.01, 5, 0, 4 * 0.05 / (np.pi * 0.01),
                                                         4 * 0.05 / (np.pi * 0.01)], rel=1e-3)


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("answer", [None, b"HTTP/1.1 400 Bad Request\r\n\r\n" * 8],
                         ids=["nothing-listens", "another-service"])
def test_a_scheduler_address_without_a_dask_scheduler_is_refused_in_one_line(tmp_path, answer):
    """Nothing listening: refused at once, by the system's answer (dask tried for 10 s, "Timed
    out"); another service (an HTTP server): dask read a frame length of 3 EiB from its reply
    ("out of memory")."""
    import socket
    import threading

    root = tmp_path / "user"
    root.mkdir()
    populate(root, BASE)
    port = _free_port()
    server = None
    if answer is not None:
        server = socket.create_server(("127.0.0.1", 0))
        port = server.getsockname()[1]

        def serve():
            with contextlib.suppress(OSError):
                while True:
                    conn, _ = server.accept()
                    with conn:
                        conn.sendall(answer)
                        time.sleep(0.2)

        threading.Thread(target=serve, daemon=True).start()
    try:
        line = limited_process.refusal(["study", "st.toml", "--out", "o.zarr", "--scheduler",
                                        f"tcp://127.0.0.1:{port}"], root)
    finally:
        if server is not None:
            server.close()
    assert f"--scheduler tcp://127.0.0.1:{port}" in line
    assert ("Connection refused" if answer is None else "not a dask scheduler") in line, line
    assert not (root / "o.zarr").exists()
