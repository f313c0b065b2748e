"""The hostile corpus over records as engineers have them (issue 26): MATLAB files of every
level and type, time columns, ``--columns``/``--scale`` misuse, options given twice, and
records that determine nothing.

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

from motionhyst.scenario import default_scenario_path

FS = 1000.0
AXIS = ('[stage]\ntype = "mass-damper"\nm = 2.0\nc = 10.0\n\n'
        '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 4.0\n')


def _record(n: int = 600) -> dict[str, np.ndarray]:
    """A 2 kg axis's record (made-up values: the cases are refused before any model runs)."""
    t = np.arange(n) / FS
    force = 30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
    return {"t": t, "u": force, "y": np.cumsum(np.cumsum(force - force.mean())) / (2 * FS**2)}


def _mat(**variables):
    """A maker of a MATLAB v5 file: the record's ``t``, ``u``, ``y`` as n x 1 columns, with
    `variables` added or replacing them."""
    def make(path) -> None:
        from scipy.io import savemat

        savemat(path, {**{k: v[:, None] for k, v in _record().items()}, **variables})
    return make


def _frd(f, phase_unit: str = "deg") -> str:
    """A measured Table I stage at the frequencies `f` [Hz], in their order, as magnitude and
    phase (the phase column in degrees, or `phase_unit` "rad" under the same name)."""
    from motionhyst.plants.frf_fit import ModalPlant
    from motionhyst.plants.two_mass import TwoMassStage

    stage = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    p1, p2 = stage.response(2 * np.pi * np.asarray(f))
    deg = phase_unit == "deg"
    rows = np.column_stack([f, np.abs(p1), np.angle(p1, deg=deg), np.abs(p2),
                            np.angle(p2, deg=deg)])
    return "frequency_hz,p1_abs,p1_phase_deg,p2_abs,p2_phase_deg\n" + "".join(
        ",".join(f"{v:.10e}" for v in row) + "\n" for row in rows)


PAPER = default_scenario_path().read_text()
MEASURED = (PAPER[:PAPER.index("[stage]")] + '[plant]\nfile = "plant.csv"\n\n'
            + PAPER[PAPER.index("[hysteresis]"):])
LOG = np.geomspace(1.0, 3000.0, 200)
def _zlib_bomb(path) -> None:
    """A MATLAB v5 file of a few kB whose compressed variables ``t`` and ``u`` declare 2e9
    values each (32 GB as read), as a file of zeros compressed a thousandfold does."""
    import io
    import struct
    import zlib

    from scipy.io import savemat

    buf = io.BytesIO()
    savemat(buf, {"t": np.zeros((1000, 1)), "u": np.zeros((1000, 1))}, do_compression=True)
    raw, pos = buf.getvalue(), 128
    out = [raw[:pos]]
    while pos < len(raw):  # each variable: a compressed element whose dimensions are patched
        kind, size = struct.unpack("<ii", raw[pos:pos + 8])
        body = zlib.decompress(raw[pos + 8:pos + 8 + size]).replace(
            struct.pack("<iiii", 5, 8, 1000, 1), struct.pack("<iiii", 5, 8, 2_000_000_000, 1), 1)
        packed = zlib.compress(body)
        out.append(struct.pack("<ii", kind, len(packed)) + packed)
        pos += 8 + size
    path.write_bytes(b"".join(out))


BASE = {"axis.toml": AXIS, "notes.txt": "my notes", "p.toml": MEASURED}
PREDICT = ["predict", "axis.toml", "r.mat", "--out", "p.csv"]
MAP = ["--columns", "time=t,force=u"]

# (id, extra files, argv, words of the one line on stderr); a file given as a callable is
# made by it (path) -> None
CASES = [
    # ------------------------------ --scale given twice: its first gain was silently replaced
    ("scale-given-twice", {"r.mat": _mat()},
     [*PREDICT, *MAP, "--scale", "force=2", "--scale", "force=3"],
     ["argument --scale: 'force' is given twice"]),
    ("columns-given-twice", {"r.mat": _mat()},
     [*PREDICT, "--columns", "time=t,force=u", "--columns", "force=y"],
     ["argument --columns: 'force' is given twice"]),
    # ------------------------------------ a compressed variable declaring more than memory
    ("mat-declaring-32-GB", {"r.mat": _zlib_bomb}, [*PREDICT, *MAP],
     ["r.mat: cannot read variable 't': reading its 2000000000 values needs 32 GB, above the "
      "memory budget", "give a smaller file"]),
    # ------------------------------ the Bouc-Wen benchmark's test sets as MATLAB users save them
    *[(f"bouc-wen-test-set-{kind}", {"bw/uval_multisine.mat": maker},
       ["benchmark", "bouc-wen", "--data", "bw"],
       [f"bw/uval_multisine.mat: cannot read: variable 'uval_multisine' is {words}"])
      for kind, maker, words in (
          ("complex", _mat(uval_multisine=np.ones((8192, 1)) + 1j), "complex"),  # was read
          # as its real part, a numpy warning on stderr
          ("cell", _mat(uval_multisine=np.array([np.ones(8192)], dtype=object)), "a cell array"),
          ("two-columns", _mat(uval_multisine=np.ones((8192, 2))), "a 8192x2 matrix"))],
    # ------------------------------------------------------- a time column not in seconds
    ("time-in-milliseconds", {"r.mat": _mat(t=1000 * _record()["t"][:, None])}, [*PREDICT, *MAP],
     ["integration steps per sample of r.mat", "sampling rate 1 Hz",
      "a time column not in seconds (--scale time=GAIN)"]),
    ("time-scaled-to-milliseconds", {"r.mat": _mat()}, [*PREDICT, *MAP, "--scale", "time=1000"],
     ["sampling rate 1 Hz", "--scale time=GAIN"]),
    # ------------------------------------------ frequency responses: the lines and their units
    ("frf-sweep-downwards", {"plant.csv": _frd(LOG[::-1])}, ["analyze", "p.toml"],
     ["plant.csv: frequency_hz must be positive and increasing: 2881.7 Hz follows 3000 Hz (line 2 "
      "of the data); sort the lines by frequency"]),
    ("frf-line-twice", {"plant.csv": _frd(np.sort(np.r_[LOG, LOG[50]]))}, ["analyze", "p.toml"],
     ["7.47564 Hz is given twice (lines 51 and 52 of the data); keep one line"]),
    ("frf-zero-hz", {"plant.csv": _frd(LOG).replace("1.0000000000e+00,", "0.0,", 1)},
     ["analyze", "p.toml"], ["positive and increasing: 0 Hz at line 1 of the data"]),
    ("frf-phase-in-radians", {"plant.csv": _frd(LOG, "rad")}, ["analyze", "p.toml"],
     ["cannot estimate the rigid-body mass", "is -22.5 kg, not a mass (phases in radians"]),
]


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "words"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_a_record_case_refuses_in_one_line_and_touches_nothing(tmp_path, files, argv, words):
    root = tmp_path / "user"
    root.mkdir()
    populate(root, {**BASE, **{k: v for k, v in files.items() if not callable(v)}})
    for name, make in files.items():
        if callable(make):
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            make(root / name)
    before = snapshot(root)
    line = limited_process.refusal(list(argv), root)
    for word in words:
        assert word in line, (word, line)
    assert snapshot(root) == before
    assert [p.name for p in tmp_path.iterdir()] == ["user"]


def test_a_scenario_saved_with_a_byte_order_mark_is_read_as_without(tmp_path):
    from motionhyst.scenario import Scenario

    path = tmp_path / "s.toml"
    path.write_text("\ufeff" + PAPER, encoding="utf-8")
    assert Scenario.from_file(path).to_dict() == Scenario.from_file(
        default_scenario_path()).to_dict()


def test_columns_and_scale_given_in_pieces_count_together(tmp_path):
    """Two --columns (or --scale) options: both maps read (the second replaced the first)."""
    _mat()(tmp_path / "r.mat")
    (tmp_path / "axis.toml").write_text(AXIS)
    outputs = []
    for i, maps in enumerate((["--columns", "time=t,force=u", "--scale", "force=2"],
                              ["--columns", "time=t", "--scale", "force=2", "--columns",
                               "force=u"])):
        code, _, err = limited_process.run([*PREDICT[:4], f"p{i}.csv", *maps], tmp_path)
        assert code == 0, err
        outputs.append((tmp_path / f"p{i}.csv").read_text())
    assert outputs[0] == outputs[1]


@pytest.mark.parametrize(("variables", "extra", "words"), [
    ({"t": (739000.0 + _record()["t"] / 86400.0)[:, None]}, [],
     "Hz sampling): if the time is not in seconds, scale it (--scale time=86400 for days)"),
    ({"y": 1000.0 * _record()["y"][:, None]}, ["--init-from", "r.mat"],
     "r.mat: displacement reaches 457 m, beyond the 100 m of a motion stage's stroke: if the "
     "positions are not in metres, scale them (--scale displacement=0.001 for mm"),
], ids=["time-in-days", "position-in-mm"])
def test_a_unit_slip_in_a_record_is_a_warning_naming_the_column(tmp_path, variables, extra,
                                                                 words):
    _mat(**variables)(tmp_path / "r.mat")
    (tmp_path / "axis.toml").write_text(AXIS)
    columns = "time=t,force=u,displacement=y" if extra else "time=t,force=u"
    code, _, err = limited_process.run([*PREDICT, "--columns", columns, *extra], tmp_path)
    assert code == 0, err
    assert "motionhyst: warning: predict: r.mat: " in err and words in err, err


@pytest.mark.parametrize("n", [50, 4000])
def test_the_robust_covariance_sums_every_lag_as_the_products_did(n):
    """Newey-West's weighted lag products, summed by one FFT convolution (a record of two
    million samples took 110 s of CPU in its 500 products), equal the products' sum."""
    from motionhyst.identify.residual_noise import bartlett_sum, bartlett_weights

    xe = np.random.default_rng(n).standard_normal((n, 6)).cumsum(axis=0)
    lags = min(n - 1, max(int(4 * n ** (1 / 3)), 7))
    expected = xe.T @ xe
    for lag in range(1, lags + 1):
        g = xe[lag:].T @ xe[:-lag]
        expected += (1.0 - lag / (lags + 1)) * (g + g.T)
    got = bartlett_sum(xe, bartlett_weights(lags))
    assert np.allclose(got, expected, rtol=0.0, atol=1e-12 * np.abs(expected).max())


def test_a_benchmark_test_set_saved_as_matlab_7_3_reads_as_version_5(tmp_path):
    """The Bouc-Wen benchmark's test sets through the records' reader: a file saved with
    ``-v7.3`` (HDF5) gives the same numbers (it was refused: scipy reads levels 4 and 5)."""
    import h5py
    from scipy.io import savemat

    from motionhyst.identify.benchmark import load_test_set

    u, y = (np.sin(np.arange(8192) / k) for k in (7.0, 11.0))
    v5, v73 = tmp_path / "v5", tmp_path / "v73"
    for folder in (v5, v73):
        folder.mkdir()
        savemat(folder / "yval_multisine.mat", {"yval_multisine": y[:, None]})
    savemat(v5 / "uval_multisine.mat", {"uval_multisine": u[:, None]})
    with h5py.File(v73 / "uval_multisine.mat", "w", userblock_size=512) as f:
        f.create_dataset("uval_multisine", data=u[None, :]).attrs["MATLAB_class"] = b"double"
    with open(v73 / "uval_multisine.mat", "r+b") as fh:  # the header MATLAB writes
        fh.write(b"MATLAB 7.3 MAT-file".ljust(116) + b"\x00" * 8 + b"\x00\x02IM")
    a, b = load_test_set(v5, "multisine"), load_test_set(v73, "multisine")
    assert np.array_equal(a.u, u) and np.array_equal(b.u, u) and np.array_equal(b.y, y)


@pytest.mark.parametrize(("column", "values", "warned"), [
    ("time", np.arange(2000) / 20e6, False),                  # a 20 MHz capture
    ("time", 739000.0 + np.arange(2000) / 1000 / 86400, True),  # days at 1 kHz
    ("displacement", 0.08 * np.sin(np.arange(2000) / 100), False),
    ("displacement", 80.0 * np.sin(np.arange(2000) / 100), False),  # 80 mm read as m: not seen
    ("displacement", 150.0 * np.sin(np.arange(2000) / 100), True),
])
def test_the_unit_warnings_catch_what_they_say_and_no_more(tmp_path, column, values, warned):
    """Days at 1 kHz and strokes beyond 100 m are warned; a fast capture and a stroke that may
    be metres are not."""
    import warnings

    from motionhyst.core.warnings import MotionhystWarning
    from motionhyst.io.records import read_record

    other = "time" if column == "displacement" else "force"
    data = {column: values, other: np.arange(2000) / 1000 if other == "time" else values * 0}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_record(data, (column, other))
    assert [w.category for w in caught] == ([MotionhystWarning] if warned else [])


# ------------------------------------------------------------ MATLAB files by their format
def _v73(path, variables: dict[str, np.ndarray]) -> None:
    """A MATLAB 7.3 (HDF5) file of row vectors, as MATLAB writes them."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as fh:
        for name, v in variables.items():
            fh[name] = v[None, :]
            fh[name].attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file".ljust(116, b" ") + b"\0" * 8 + b"\x00\x02IM"
    with path.open("r+b") as fh:
        fh.write(header)


def _write(path, fmt: str, variables: dict[str, np.ndarray]) -> None:
    from scipy.io import savemat

    if fmt == "7.3":
        _v73(path, variables)
    else:
        savemat(path, {k: v[:, None] for k, v in variables.items()},
                do_compression=fmt == "7")


@pytest.mark.parametrize("fmt", ["5", "7", "7.3"])
def test_a_matlab_file_is_budgeted_by_the_variables_read_not_its_size(tmp_path, fmt):
    """A MATLAB file of 19 MB holding a long signal beside the record's two columns, read
    under a budget of 64 MB: its readers skip the other variables (peak resident memory
    the same for a file of 1 MB and of 200 MB, measured), so it is read; a text factor of 4
    on the file's size refused it (81 MB)."""
    n = 20_000
    t = np.arange(n) / 1000.0
    u = 50.0 * np.sin(2 * np.pi * 3 * t)
    other = np.random.default_rng(0).standard_normal(2_400_000)
    _write(tmp_path / "r.mat", fmt, {"t": t, "u": u, "camera": other})
    (tmp_path / "axis.toml").write_text(AXIS)
    assert (tmp_path / "r.mat").stat().st_size > 17e6
    before = (tmp_path / "r.mat").read_bytes()
    code, _, err = limited_process.run(["predict", "axis.toml", "r.mat", "--columns",
                                        "time=t,force=u", "--out", "p.csv",
                                        "--max-memory", "64M"], tmp_path)
    assert code == 0, err
    assert "budget" not in err
    p = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert p.shape[0] == n and np.all(np.isfinite(p))
    assert (tmp_path / "r.mat").read_bytes() == before


@pytest.mark.parametrize("fmt", ["5", "7.3"])
def test_a_matlab_variable_read_beyond_the_budget_is_still_refused(tmp_path, fmt):
    """The variables read count: 2 x 400000 values of 16 bytes as read are 12.8 MB, above a
    budget of 8 MB, whatever the file's size."""
    n = 400_000
    t = np.arange(n) / 1000.0
    _write(tmp_path / "r.mat", fmt, {"t": t, "u": np.sin(t)})
    (tmp_path / "axis.toml").write_text(AXIS)
    before = snapshot(tmp_path)
    line = limited_process.refusal(["predict", "axis.toml", "r.mat", "--columns",
                                    "time=t,force=u", "--out", "p.csv", "--max-memory",
                                    "8M"], tmp_path)
    assert "r.mat: cannot read variable 'u': reading its 400000 values needs" in line, line
    assert "above the memory budget" in line
    assert snapshot(tmp_path) == before
