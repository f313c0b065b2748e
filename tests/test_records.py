"""The record reader: CSV and MATLAB .mat files (scipy and h5py layouts), column maps, scales,
time jitter and the failure paths (one line naming the file)."""

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.io import loadmat, savemat

from motionhyst.io.records import (
    RecordError,
    is_mat_file,
    parse_columns,
    parse_scale,
    read_record,
    record_columns,
)
from motionhyst.time.openloop import STAMP_TOLERANCE, check_record, sampling_rate

EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"
NAMES = ("time", "force", "displacement")
EMPS_COLUMNS = {"time": "t", "force": "vir", "displacement": "qm"}
GAIN = 35.15065


def _signals(n=200, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 1e-3
    return t, rng.standard_normal(n), 1e-3 * np.sin(2 * np.pi * 3.0 * t)


def write_v73(path: Path, variables: dict) -> None:
    """A MATLAB 7.3 file as MATLAB writes one: HDF5 after a 512-byte header, arrays transposed,
    each dataset with its MATLAB_class, a structure as a group."""
    def put(group, name, value):
        if isinstance(value, dict):
            sub = group.create_group(name)
            sub.attrs["MATLAB_class"] = np.bytes_("struct")
            for field, v in value.items():
                put(sub, field, v)
            return
        if isinstance(value, str):
            ds = group.create_dataset(name, data=np.array([[ord(c)] for c in value],
                                                          dtype=np.uint16))
            ds.attrs["MATLAB_class"] = np.bytes_("char")
            return
        arr = np.asarray(value)
        ds = group.create_dataset(name, data=arr.T if arr.ndim == 2 else arr.reshape(1, -1))
        ds.attrs["MATLAB_class"] = np.bytes_("double")

    with h5py.File(path, "w", userblock_size=512) as fh:
        for name, value in variables.items():
            put(fh, name, value)
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Wed Nov 25 12:00:00 2026 HDF5"
    header = text.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM"
    with path.open("r+b") as fh:
        fh.write(header)


# ------------------------------------------------------------------ reading
@pytest.mark.parametrize("fmt", ["5", "4"])
def test_mat_v5_and_v4_with_column_map_and_scale(tmp_path, fmt):
    t, v, q = _signals()
    path = tmp_path / "axis.mat"
    savemat(path, {"t": t[:, None], "vir": v[:, None], "qm": q[None, :], "gtau": GAIN},
            format=fmt)
    data = read_record(path, NAMES, columns=EMPS_COLUMNS, scale={"force": GAIN})
    assert data.shape == (t.size, 3) and data.flags.c_contiguous
    np.testing.assert_array_equal(data[:, 0], t)
    np.testing.assert_allclose(data[:, 1], GAIN * v, rtol=1e-15)
    np.testing.assert_array_equal(data[:, 2], q)


def test_mat_v73_written_by_h5py(tmp_path):
    t, v, q = _signals(seed=1)
    path = tmp_path / "axis73.mat"
    write_v73(path, {"t": t[:, None], "vir": v[:, None], "qm": q[:, None], "note": "run 3"})
    assert h5py.is_hdf5(path)
    with pytest.raises(NotImplementedError):  # what scipy alone says: h5py is needed
        loadmat(path)
    data = read_record(path, NAMES, columns=EMPS_COLUMNS, scale={"force": -2.0})
    np.testing.assert_array_equal(data[:, 0], t)
    np.testing.assert_array_equal(data[:, 1], -2.0 * v)
    np.testing.assert_array_equal(data[:, 2], q)
    assert record_columns(path, {"time": "t"}) == ["note", "qm", "time", "vir"]


def test_structure_fields_and_names_ignoring_case(tmp_path):
    t, v, q = _signals(seed=2)
    for path, write in ((tmp_path / "s5.mat", lambda p, d: savemat(p, d)),
                        (tmp_path / "s73.mat", write_v73)):
        write(path, {"Run": {"Time": t, "F": v, "Y": q}})
        data = read_record(path, NAMES, columns={"time": "run.time", "force": "Run.F",
                                                 "displacement": "run.y"})
        np.testing.assert_array_equal(data, np.column_stack([t, v, q]))


def test_kind_from_content_not_name(tmp_path):
    t, v, q = _signals(seed=3)
    path = tmp_path / "record.dat"
    savemat(path, {"time": t, "force": v, "displacement": q})
    assert is_mat_file(path)
    np.testing.assert_array_equal(read_record(path, NAMES)[:, 1], v)
    csv = tmp_path / "record.csv"
    np.savetxt(csv, np.column_stack([t, v, q]), delimiter=",", header="T,Vir,QM", comments="")
    assert not is_mat_file(csv)
    data = read_record(csv, NAMES, columns=EMPS_COLUMNS, scale={"force": GAIN})
    np.testing.assert_allclose(data[:, 1], GAIN * v, rtol=1e-15)
    assert record_columns(csv, EMPS_COLUMNS) == ["time", "force", "displacement"]


# ------------------------------------------------------------------ options
def test_parse_options():
    assert parse_columns(" Time = t , force=vir ") == {"time": "t", "force": "vir"}
    assert parse_scale("force=-2.5e1,time=1e-3") == {"force": -25.0, "time": 1e-3}
    for text, fragment in (("time", "is not NAME=COLUMN"), ("time=", "is not NAME=COLUMN"),
                           ("time=t,TIME=s", "'time' is given twice"), (",", "empty")):
        with pytest.raises(RecordError, match=fragment):
            parse_columns(text)
    for text, fragment in (("force=abc", "must be a number"), ("force=0", "non-zero"),
                           ("force=inf", "finite"), ("force", "is not NAME=GAIN")):
        with pytest.raises(RecordError, match=fragment):
            parse_scale(text)


# ------------------------------------------------------------------ time stamps
def test_logger_jitter_within_the_stated_tolerance(tmp_path):
    n = 5000
    t = np.arange(n) * 1e-3
    jitter = 2e-5 * 1e-3 * np.random.default_rng(4).uniform(-1.0, 1.0, n)  # as EMPS's logger
    path = tmp_path / "jitter.mat"
    savemat(path, {"t": t + jitter, "vir": np.sin(t), "qm": np.cos(t)})
    data = read_record(path, NAMES, columns=EMPS_COLUMNS)
    tt, _ = check_record(data[:, 0], data[:, 1])
    assert sampling_rate(tt) == pytest.approx(1000.0, rel=1e-7)
    late = t.copy()
    late[1234] += 2 * STAMP_TOLERANCE * 1e-3  # twice the tolerance off the grid
    with pytest.raises(ValueError, match=r"stamp 1\.234\d* s is 0\.1 sampling intervals off"):
        check_record(late, np.zeros(n))


# ------------------------------------------------------------------ failure paths
def _error(path, **kw) -> str:
    with pytest.raises(RecordError) as info:
        read_record(path, NAMES, **kw)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith((str(path), f"cannot read {path}"))
    return msg


def test_bad_mat_files(tmp_path):
    t, v, q = _signals(seed=5)
    text = tmp_path / "text.mat"
    text.write_text("time,force,displacement\n" + "0,1,2\n" * 50)
    assert "not a MATLAB .mat file (a text file)" in _error(text)
    empty = tmp_path / "empty.mat"
    empty.write_bytes(b"")
    assert "empty file" in _error(empty)
    cut = tmp_path / "cut.mat"
    savemat(cut, {"time": t, "force": v, "displacement": q})
    cut.write_bytes(cut.read_bytes()[:300])
    assert "cannot read as a MATLAB file" in _error(cut)
    assert "no such file" in _error(tmp_path / "missing.mat")

    ok = tmp_path / "ok.mat"
    savemat(ok, {"t": t, "vir": v, "qm": q, "gtau": GAIN, "M": np.ones((t.size, 2)),
                 "label": "axis 1", "c": [[1.0j] * t.size], "cell": np.array([[t, q]],
                                                                               dtype=object),
                 "s": {"a": t}, "short": t[:-1]})
    msg = _error(ok)
    assert "no variable 'time' (the file has: " in msg and "--columns time=NAME" in msg
    cases = {"M": "is a 200x2 matrix", "label": "is text", "c": "complex",
             "cell": "cell array", "s": "is a structure; name one of its fields (a)",
             "short": "differ in length (t 200, short 199, qm 200)",
             "gtau": "differ in length", "t.x": "'t' is not a structure"}
    for name, fragment in cases.items():
        assert fragment in _error(ok, columns={**EMPS_COLUMNS, "force": name}), name
    assert "--scale names 'velocity'" in _error(ok, columns=EMPS_COLUMNS,
                                                   scale={"velocity": 2.0})
    assert "one column as two" in _error(ok, columns={**EMPS_COLUMNS, "force": "T"})


def test_bad_v73_files(tmp_path):
    t, v, _ = _signals(seed=6)
    path = tmp_path / "bad73.mat"
    write_v73(path, {"t": t, "vir": v, "qm": np.ones((t.size, 3)), "label": "axis",
                     "s": {"a": t}})
    assert "is a 200x3 matrix" in _error(path, columns=EMPS_COLUMNS)
    assert "is text (char)" in _error(path, columns={**EMPS_COLUMNS, "displacement": "label"})
    assert "name one of its fields (a)" in _error(path, columns={**EMPS_COLUMNS,
                                                                 "displacement": "s"})
    assert "no field of 's': 'b'" in _error(path, columns={**EMPS_COLUMNS,
                                                            "displacement": "s.b"})
    assert "no variable 'x' (the file has: label, qm, s, t, vir)" in _error(
        path, columns={**EMPS_COLUMNS, "time": "x"})
    broken = tmp_path / "broken73.mat"
    broken.write_bytes(path.read_bytes()[:700])
    assert "cannot read as a MATLAB 7.3 file" in _error(broken)


def test_array_has_no_names():
    with pytest.raises(RecordError, match="an array has none"):
        read_record(np.zeros((10, 3)), NAMES, columns={"time": "t"})


# ------------------------------------------------------------------ the EMPS record
@pytest.mark.skipif(not EMPS.is_file(), reason="the EMPS benchmark's files are not beside the "
                    "repository")
def test_emps_record_as_published():
    data = read_record(EMPS, NAMES, columns=EMPS_COLUMNS, scale={"force": GAIN})
    raw = loadmat(EMPS)
    assert data.shape == (24841, 3)
    np.testing.assert_array_equal(data[:, 2], raw["qm"].ravel())
    np.testing.assert_allclose(data[:, 1], GAIN * raw["vir"].ravel(), rtol=1e-15)
    tt, _ = check_record(data[:, 0], data[:, 1])  # its logger's jitter is accepted
    assert sampling_rate(tt) == pytest.approx(1000.0, rel=1e-6)


# ------------------------------------------------------------------ every command reads .mat
def test_commands_read_mat_files_with_mapped_scaled_columns(tmp_path, capsys):
    """identify, predict, a reference and a measured plant: a .mat record (scipy or h5py
    layout) with the file's own names gives what the same record as CSV gives."""
    from motionhyst.cli import main
    from motionhyst.hysteresis import MaxwellSlip
    from motionhyst.plants.measured import load_frd_plant
    from motionhyst.plants.two_mass import TwoMassStage
    from motionhyst.time.references import load_reference_csv

    n = 800
    t = np.arange(n) * 1e-3
    x = 0.01 * np.sin(2 * np.pi * 5.0 * t) * np.linspace(1.0, 0.2, n)
    w = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).response(x)
    csv = tmp_path / "fd.csv"
    np.savetxt(csv, np.column_stack([t, x, w]), delimiter=",", header="time,displacement,force",
               comments="", fmt="%.17g")
    v5, v73 = tmp_path / "fd.mat", tmp_path / "fd73.mat"
    savemat(v5, {"T": t[:, None], "X": 1e3 * x[:, None], "V": w[:, None] / 2.0})
    write_v73(v73, {"T": t[:, None], "X": 1e3 * x[:, None], "V": w[:, None] / 2.0})
    mapped = ["--columns", "time=T,displacement=X,force=V", "--scale", "displacement=1e-3,force=2"]
    assert main(["identify", str(csv), "--elements", "2", "--json"]) == 0
    want = json.loads(capsys.readouterr().out)
    for path in (v5, v73):
        assert main(["identify", str(path), "--elements", "2", "--json", *mapped]) == 0
        got = json.loads(capsys.readouterr().out)
        for a, b in zip(got["elements"], want["elements"], strict=True):
            assert a["k"] == pytest.approx(b["k"], rel=1e-9)
            assert a["fc"] == pytest.approx(b["fc"], rel=1e-9)

    scenario = tmp_path / "model.toml"
    scenario.write_text('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n'
                        '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 10.0\n')
    u = 30.0 * np.sin(2 * np.pi * 8.0 * t)
    np.savetxt(csv, np.column_stack([t, u]), delimiter=",", header="time,force", comments="",
               fmt="%.17g")
    savemat(v5, {"t": t, "vir": u / GAIN})
    outs = []
    for args in ([str(csv)], [str(v5), "--columns", "time=t,force=vir", "--scale",
                              f"force={GAIN!r}"]):
        out = tmp_path / f"y{len(outs)}.csv"
        assert main(["predict", str(scenario), *args, "--out", str(out)]) == 0
        outs.append(np.loadtxt(out, delimiter=",", skiprows=1))
    np.testing.assert_allclose(outs[1], outs[0], rtol=0, atol=1e-12 * np.ptp(outs[0][:, 1]))

    savemat(v5, {"t": t, "qg": 1e3 * x})
    ref = load_reference_csv(v5, columns={"time": "t", "position": "qg"},
                             scale={"position": 1e-3})
    np.testing.assert_allclose(ref(t[::7])[0], x[::7], rtol=0, atol=1e-15)

    stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    f = np.geomspace(1.0, 2000.0, 300)
    p1, p2 = stage.P1(2j * np.pi * f), stage.P2(2j * np.pi * f)
    write_v73(v73, {"frequency_hz": f, "p1_re": p1.real, "p1_im": p1.imag, "p2_re": p2.real,
                    "p2_im": p2.imag})
    assert load_frd_plant(v73).M == pytest.approx(22.5, rel=1e-3)


@pytest.mark.parametrize(("command", "content", "fragment"), [
    ("identify", "text", "not a MATLAB .mat file (a text file)"),
    ("identify", "matrix", "is a 50x2 matrix"),
    ("identify", "missing", "needs the columns time,displacement,force; the header is"),
    ("predict", "text", "not a MATLAB .mat file (a text file)"),
    ("predict", "missing", "no variable 'force' (the file has: time, displacement); map"),
])
def test_bad_mat_files_through_the_commands(tmp_path, capsys, command, content, fragment):
    from motionhyst.cli import main

    path = tmp_path / "bad.mat"
    t = np.arange(50) * 1e-3
    if content == "text":
        path.write_text("time,force\n" + "0,0\n" * 50)
    elif content == "matrix":
        savemat(path, {"time": t, "displacement": np.ones((50, 2)), "force": t})
    else:
        savemat(path, {"time": t, "displacement": t})
    scenario = tmp_path / "model.toml"
    scenario.write_text('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n'
                        '[hysteresis]\nmodel = "jenkins"\nk = 2e4\nfc = 10.0\n')
    args = (["identify", str(path), "--record", "force-displacement"] if command == "identify"
            else ["predict", str(scenario), str(path), "--out", str(tmp_path / "y.csv")])
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
    assert not (tmp_path / "y.csv").exists()


def test_binary_file_named_csv_is_not_echoed(tmp_path):
    path = tmp_path / "record.csv"
    path.write_bytes(b"\x7fELF\x02\x01\x01\x00" + bytes(range(256)) * 4)
    for call in (lambda: read_record(path, NAMES), lambda: record_columns(path)):
        with pytest.raises(RecordError) as info:
            call()
        assert str(info.value) == (f"{path}: not a CSV file (binary data, and not a MATLAB "
                                   f".mat file)")


def test_a_structure_field_names_the_record_kind(tmp_path):
    """A MATLAB 5 structure's fields mapped by --columns give identify the record's kind."""
    from motionhyst.cli import record_kind

    t, v, q = _signals(seed=4)
    path = tmp_path / "test.mat"
    savemat(path, {"test": {"t": t, "d": q, "F": v}})
    columns = {"time": "test.t", "displacement": "test.d", "force": "test.F"}
    assert record_kind(path, columns=columns) == "force-displacement"
    np.testing.assert_array_equal(read_record(path, ("time", "displacement", "force"),
                                              columns=columns), np.column_stack([t, q, v]))
