"""The hostile corpus over answers from nothing and the readers' leftovers (issue 26): one
record given twice, records that determine nothing, files read by what they hold.

Each case runs the command line in a child process under an address-space limit
(:mod:`limited_process`), in a folder holding the user's files, and asserts exit code 2, one
line on stderr naming the cause (no traceback), nothing on stdout, and every file there
before byte-identical afterwards, with no file added.
"""

from __future__ import annotations

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

FS = 1000.0


def _csv(columns: dict[str, np.ndarray]) -> str:
    """A CSV record with a header of the `columns`' names."""
    rows = np.column_stack(list(columns.values()))
    return ",".join(columns) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                              for row in rows)


def _axis(n: int = 600) -> str:
    """An input-output record of a 2 kg axis (made up: the cases are refused before any fit)."""
    t = np.arange(n) / FS
    force = 30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
    y = np.cumsum(np.cumsum(force - force.mean())) / (2 * FS**2)
    return _csv({"time": t, "force": force, "displacement": y})


def _declaring(n: int, **variables):
    """A maker of a MATLAB v5 file of a few kB whose `variables` (a structure's or a cell's
    arrays of 1000 zeros) declare `n` values each, as a file of zeros compressed a
    thousandfold does (its data is cut short: the declaration alone must refuse it)."""
    def make(path) -> None:
        import io
        import struct
        import zlib

        from scipy.io import savemat

        buf = io.BytesIO()
        savemat(buf, variables, do_compression=True)
        raw, pos = buf.getvalue(), 128
        out = [raw[:pos]]
        while pos < len(raw):  # each variable: a compressed element whose arrays are patched
            kind, size = struct.unpack("<ii", raw[pos:pos + 8])
            body = zlib.decompress(raw[pos + 8:pos + 8 + size]).replace(
                struct.pack("<iiii", 5, 8, 1000, 1), struct.pack("<iiii", 5, 8, n, 1))
            packed = zlib.compress(body)
            out.append(struct.pack("<ii", kind, len(packed)) + packed)
            pos += 8 + size
        path.write_bytes(b"".join(out))
    return make


def _paper(old: str, new: str) -> str:
    """The paper's scenario with one value changed."""
    from motionhyst.scenario import default_scenario_path

    text = default_scenario_path().read_text()
    assert old in text
    return text.replace(old, new)


def _force_noise(n: int = 6000) -> str:
    """A force-displacement record whose force is white noise under a sine displacement."""
    t = np.arange(n) / FS
    force = np.random.default_rng(5).standard_normal(n)
    return _csv({"time": t, "displacement": 0.01 * np.sin(5 * t), "force": force})


IO = ["--record", "input-output"]
DAMPED_LINK = _paper('model = "jenkins"\nk = 20.0              # spring stiffness k_J [N/m]\n'
                     'fc = 0.05             # slip force f_c [N]',
                     'model = "lugre"\nsigma0 = 20.0\nsigma1 = 1e7\nfc = 0.05\nfs = 0.07\n'
                     'vs = 0.1')
TOO_DAMPED = ["s.toml: [hysteresis]: the link's damping for small motions, 1e+07 N s/m on "
              "the 5 kg it moves, is too strong for the time step of",
              "the run would stop at the stage's first motion or end in a motion that is no "
              "solution; the step is the command's, set "
              "from the loop's poles and the reference: is the link's damping meant (in SI "
              "units)?"]
PREDICT = ["predict", "axis.toml", "r.mat", "--out", "p.csv"]
ZEROS = np.zeros((1000, 1))
CELL = np.empty((1, 1), dtype=object)
CELL[0, 0] = ZEROS
AXIS = ('[stage]\ntype = "mass-damper"\nm = 2.0\nc = 10.0\n\n'
        '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 4.0\n')
TWICE = "a record given twice counts its samples twice (standard errors too small)"

# (id, extra files as file_trees.populate takes them, argv, words of the one line on stderr)
CASES = [
    # ------------------------ one record given twice: its standard errors sqrt(2) too small
    ("record-given-twice", {}, ["identify", "a.csv", "a.csv", *IO],
     ["identify: a.csv is given twice: " + TWICE]),
    ("record-twice-through-a-link", {"@symlink:l.csv": "a.csv"},
     ["identify", "a.csv", "l.csv", *IO],
     ["identify: a.csv and l.csv are the same file: " + TWICE]),
    ("record-copied", {"b.csv": _axis()}, ["identify", "a.csv", "b.csv", *IO],
     ["identify: a.csv and b.csv hold the same record byte for byte: " + TWICE]),
    ("record-copied-force-displacement", {"b.csv": _axis()},
     ["identify", "a.csv", "b.csv", "--model", "dahl"], ["a.csv and b.csv hold the same"]),
    # ------------- records that determine nothing: refused before any fit, not fitted to noise
    ("force-displacement-force-noise", {"f.csv": _force_noise()}, ["identify", "f.csv"],
     ["f.csv: no hysteresis in the record", "nothing identified"]),
    ("force-displacement-force-noise-model", {"f.csv": _force_noise()},
     ["identify", "f.csv", "--model", "dahl"],
     ["f.csv: no hysteresis in the record: its force does not follow the displacement",
      "nothing identified"]),
    # ---------------- a scenario's unit slip: the loop's pole, not the setpoint, sets the step
    ("scan-actuated-mass-of-a-nanogram", {"s.toml": _paper("m1 = 5.0", "m1 = 1e-9")},
     ["scan", "s.toml", "--length", "0.1", "--speed", "0.1", "--a-max", "10", "--j-max",
      "1000", "--s-max", "1e5", "--compensation", "none"],
     ["time steps of 1.75e-12 s: too many; the step resolves the loop's fastest closed-loop "
      "pole, 1.432e+10 Hz (beyond a motion stage's 1e+05 Hz: s.toml: [stage] m1 = 1e-09 kg, "
      "a factor 1e+06 below the 0.001-10000 kg of motion stages: is it in kg?); shorten the "
      "setpoint (--length, --dwell) or --tail, or raise its limits (--speed, --a-max, "
      "--j-max, --s-max)"]),
    # ---------- a link too damped for the step the command sets: no advice of an option it
    # lacks (the library's "use a smaller dt"), the scenario's section to check instead
    ("scan-link-too-damped-for-its-step", {"s.toml": DAMPED_LINK},
     ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
      "1000", "--s-max", "1e6", "--compensation", "none"], TOO_DAMPED),
    ("simulate-link-too-damped-for-its-step", {"s.toml": DAMPED_LINK},
     ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration",
      "0.2"], TOO_DAMPED),
    # --------------------- errors in a CSV's first data rows: decided before pandas loads
    ("csv-units-row", {"r.csv": "time,force\ns,N\n0,1\n0.001,2\n"},
     ["predict", "axis.toml", "r.csv", "--out", "p.csv"],
     ["r.csv: non-numeric value 's' at line 2, column 'time'"]),
    ("csv-empty-cell", {"r.csv": "time,force\n0,1\n\n0.001, \n"},
     ["predict", "axis.toml", "r.csv", "--out", "p.csv"],
     ["r.csv: an empty cell at line 4, column 'force'"]),
    ("csv-row-short-of-a-column", {"r.csv": "time,force,other\n0,1,2\n0.001\n"},
     ["predict", "axis.toml", "r.csv", "--out", "p.csv"],
     ["r.csv: inconsistent lengths: line 3 has 1 fields, the header 3"]),
    ("csv-row-too-long", {"r.csv": "time;force\n0;1\n0,001;2;5\n"},
     ["predict", "axis.toml", "r.csv", "--out", "p.csv"],
     ["r.csv: inconsistent lengths: line 3 has 3 fields, the header 2"]),
    # ------- a structure's or cell's arrays declaring more than memory (whosmat lists 1x1)
    ("mat-structure-declaring-32-GB",
     {"r.mat": _declaring(2_000_000_000, data={"t": ZEROS, "u": ZEROS})},
     [*PREDICT, "--columns", "time=data.t,force=data.u"],
     ["r.mat: cannot read variable 'data.t': reading its 2000000000 values needs 32 GB, above "
      "the memory budget", "give a smaller file"]),
    ("mat-nested-structure-declaring-4-GB",
     {"r.mat": _declaring(250_000_000, data={"t": ZEROS[:10], "run": {"u": ZEROS}})},
     [*PREDICT, "--columns", "time=data.t,force=data.run.u"],
     ["cannot read variable 'data.run.u': reading its 250000000 values needs 4 GB"]),
    ("mat-cell-in-a-structure-declaring-32-GB",
     {"r.mat": _declaring(2_000_000_000, data={"t": ZEROS[:10], "c": CELL})},
     [*PREDICT, "--columns", "time=data.t,force=data.c"],
     ["cannot read variable 'data.c{1}': reading its 2000000000 values needs 32 GB"]),
    ("mat-cell-wanted", {"r.mat": _declaring(2_000_000_000, c=CELL, t=ZEROS[:10])},
     [*PREDICT, "--columns", "time=t,force=c"],
     ["r.mat: variable 'c' is a cell array, not a numeric vector"]),
]
BASE = {"a.csv": _axis(), "axis.toml": AXIS, "notes.txt": "my notes"}


def test_no_advice_names_an_option_the_command_lacks(tmp_path):
    """scan and simulate set their own time step: the library's remedy (a smaller dt) is
    not theirs to give."""
    (tmp_path / "s.toml").write_text(DAMPED_LINK)
    for case in CASES:
        if case[0].endswith("link-too-damped-for-its-step"):
            line = limited_process.refusal(list(case[2]), tmp_path)
            assert "dt" not in line.split() and "smaller dt" not in line, line
            assert "substeps" not in line, line
    assert not (tmp_path / "ts.csv").exists()


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv, words):
    from motionhyst.scenario import default_scenario_path

    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**BASE, "paper.toml": default_scenario_path().read_text(), **files})
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before
    assert [p.name for p in tmp_path.iterdir()] == ["user"]


@pytest.mark.parametrize("compressed", [True, False])
def test_the_sizes_a_matlab_file_declares_are_its_arrays(tmp_path, compressed):
    """The walk of a level-5 file's headers finds every array of a structure (nested, an
    array of structures), a cell, complex and sparse values, with the sizes they hold."""
    import scipy.sparse
    from scipy.io import savemat

    from motionhyst.io._mat_sizes import declared_values

    variables = {
        "a": np.zeros((7, 1)),
        "s": {"t": np.zeros(5), "z": np.ones(3) + 1j, "in": {"deep": np.zeros((2, 4))},
              "text": "abc", "empty": np.zeros(0)},
        "arr": np.array([({"x": np.zeros(2)}), ({"x": np.zeros(9)})], dtype=object),
        "c": np.array([np.zeros(6), "ab"], dtype=object),
        "sp": scipy.sparse.csc_matrix(np.diag([1.0, 2.0, 0.0])),
    }
    savemat(tmp_path / "r.mat", variables, do_compression=compressed)
    found: list[tuple[str, int]] = []
    declared_values(tmp_path / "r.mat", ["s", "arr", "c", "sp", "a"],
                    lambda name, n: found.append((name, n)))
    assert found == [("a", 7), ("s.t", 5), ("s.z", 6), ("s.in.deep", 8), ("s.text", 3),
                     ("s.empty", 0), ("arr{1}.x", 2), ("arr{2}.x", 9), ("c{1}", 6),
                     ("c{2}", 2), ("sp", 2)]


def test_a_level_4_matlab_file_is_read_by_what_it_holds_not_its_name(tmp_path):
    """A MATLAB ``-v4`` file (no text header) named ``.dat`` or ``.csv`` predicts as the same
    file named ``.mat`` (it was refused as "not a MATLAB file")."""
    from scipy.io import savemat

    t = np.arange(400) / FS
    savemat(tmp_path / "r.mat", {"t": t[:, None], "u": np.sin(7 * t)[:, None]}, format="4")
    (tmp_path / "axis.toml").write_text(AXIS)
    outputs = []
    for name in ("r.mat", "r.dat", "r.csv"):
        if name != "r.mat":
            (tmp_path / name).write_bytes((tmp_path / "r.mat").read_bytes())
        code, _, err = limited_process.run(["predict", "axis.toml", name, "--out", f"{name}.out",
                                            "--columns", "time=t,force=u"], tmp_path)
        assert code == 0, err
        outputs.append((tmp_path / f"{name}.out").read_text())
    assert outputs[0] == outputs[1] == outputs[2]


@pytest.mark.parametrize(("text", "refused"), [
    ("time,force\ns,N\n0,1\n", True),                    # a units row
    ("time,force\n0,1\n0.001,\n", True),                  # an empty cell
    ("time;force\n0;1\n0,001;2;3\n", True),               # a row longer than the header
    ("time,force,x\n0,1\n0.001,2,\n", False),             # a cell pandas reads as NaN
    ("time,force\n0,NA\n0.001,2\n", False),               # pandas' NaN: the caller's value
    ("time;force\n0;1,5\n0,001;-,5e3\n", False),           # decimal commas
    ("time,force\n0,1\n0.001,2,\n0.002,3\n", None),      # pandas' error: its message
    ('time,force\n0,"1\n"\n0.001,2\n', False),            # a quoted cell over two lines
])
def test_a_csv_whose_first_rows_are_refused_does_not_load_pandas(tmp_path, text, refused):
    """The first rows' errors are said without pandas (a second of loading on a busy
    machine); what the check cannot decide is read, or refused, by pandas as before."""
    import subprocess
    import sys

    (tmp_path / "r.csv").write_text(text)
    code = ("import sys\nfrom motionhyst.io.csvdata import CSVError, read_columns\n"
            "try:\n    print(read_columns(sys.argv[1], ('time', 'force')).tolist())\n"
            "except CSVError as e:\n    print(e)\nprint('pandas' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "r.csv")],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    assert out[-1] == str(not refused), out
    if refused is not False:
        assert "r.csv: " in out[0] and ("line 2" in out[0] or "line 3" in out[0]), out


STUDY = ('scenario = "paper.toml"\noutputs = ["e1"]\n[axes]\namplitude = [0.001]\n'
         'frequency_hz = [2.0, 5.0]\n')


def _dead_pid() -> int:
    """The id of a process that has ended."""
    import subprocess

    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


@pytest.mark.parametrize("killed", ["building", "swapping"])
@pytest.mark.parametrize("next_command", ["study", "predict"])
def test_what_a_killed_study_left_beside_its_store_is_cleaned_by_the_next_writer(
        tmp_path, killed, next_command):
    """``study --force`` builds the new store as ``.NAME.motionhyst-PID-new`` and moves the
    old aside as ``.NAME.motionhyst-PID-old`` for the swap: a SIGKILL in between left them
    (the next run did not see them).  The next command writing in that folder removes the new
    one and, if the store's name is missing, puts the old store back."""
    import shutil

    from motionhyst.scenario import default_scenario_path

    shutil.copy(default_scenario_path(), tmp_path / "paper.toml")
    (tmp_path / "study.toml").write_text(STUDY)
    (tmp_path / "axis.toml").write_text(AXIS)
    (tmp_path / "r.csv").write_text(_axis()[:2000].rsplit("\n", 1)[0] + "\n")
    run = ["study", "study.toml", "--out", "s.zarr", "--workers", "0"]
    code, _, err = limited_process.run(run, tmp_path, limited_process.RUN_LIMIT)
    assert code == 0, err
    store = snapshot(tmp_path / "s.zarr")
    pid = _dead_pid()
    new, old = (tmp_path / f".s.zarr.motionhyst-{pid}-{end}" for end in ("new", "old"))
    shutil.copytree(tmp_path / "s.zarr", new)  # a store half built
    if killed == "swapping":  # the old store moved aside, the new one not yet in its place
        (tmp_path / "s.zarr").rename(old)
    argv = run if next_command == "study" else ["predict", "axis.toml", "r.csv", "--out",
                                                "p.csv", "--columns", "time=time,force=force"]
    code, out, err = limited_process.run(argv, tmp_path, limited_process.RUN_LIMIT)
    assert code == 0, err
    assert not new.exists() and not old.exists()
    assert snapshot(tmp_path / "s.zarr") == store  # put back as it was (then resumed)
    if next_command == "study":
        assert "2 points: 0 computed" in out, out  # resumed: the old store's points stand


@pytest.fixture(scope="module")
def loop_record() -> dict[str, np.ndarray]:
    """A closed-loop record of the paper's loop with a two-element link (3 s of a 2 Hz
    sine, 5 kHz)."""
    from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate

    sc = default_scenario()
    loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    sim = simulate(loop, SineReference(0.01, 2.0), 3.0, dt=2e-4)
    return {"time": sim.t, "y1": sim.y1, "u": sim.u}


@pytest.mark.parametrize(("mistake", "words"), [
    ("none", None),
    ("y1-in-mm", "c.csv: the plant's force for y1 as recorded is 1000 times u"),
    ("columns-swapped", "c.csv: the plant's force for y1 as recorded is 1.3e+07 times u"),
])
def test_a_closed_loop_record_whose_link_shows_no_hysteresis_is_refused(tmp_path, loop_record,
                                                                        mistake, words):
    """y1 in mm, or u and y1 swapped (one loop's signals, each a column of the record) were
    fitted: a spring k = M w^2 (the sine's inertia) whose slip force was 2.2e5 +- 5e7 N
    or slipped only at the stroke's end; exit 0.  Then refused after the fit (no element
    that both slips and has a determined slip force); now before it, from the plant's force
    for y1 against u (:func:`~motionhyst.identify.records.check_force_scale`)."""
    from motionhyst.scenario import default_scenario_path

    record = dict(loop_record)
    if mistake == "y1-in-mm":
        record["y1"] = 1000 * record["y1"]
    elif mistake == "columns-swapped":
        record["y1"], record["u"] = record["u"], record["y1"]
    (tmp_path / "c.csv").write_text(_csv(record))
    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    argv = ["identify", "c.csv", "--scenario", "paper.toml"]
    if words is None:
        code, out, err = limited_process.run(argv, tmp_path)
        assert code == 0 and "elements: 2" in out, err
    else:
        line = limited_process.refusal(argv, tmp_path)
        assert words in line, line
        assert "(y1 not in metres? u not in newtons? u and y1 swapped? the plant not the " \
               "record's?); nothing identified" in line, line
