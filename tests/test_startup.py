"""Start-up and compilation: what the commands import, and where compiled kernels go.

Each case runs in a fresh interpreter (a subprocess), the only way to see
what a command imports and what the first compilation does.  Nothing here
is timed (start-up times are measured by ``make bench``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_probe import probe

import motionhyst

PACKAGE = Path(motionhyst.__file__).parent

def _run(code: str, *args: str, env: dict | None = None, cwd: Path | None = None
         ) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=600, check=False)


@pytest.mark.parametrize("argv, rc", [
    (["--help"], 0),
    (["df", "--help"], 0),
    (["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"], 0),
    (["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "0.02", "--json"], 0),
    (["df", "--model", "maxwell-slip", "--k", "20", "10", "--fc", "0.05", "0.02",
      "--amplitude", "0.01"], 0),
    (["df", "--model", "lugre", "--sigma0", "1", "--amplitude", "0.01"], 2),  # missing --fc
    (["df", "--model", "dahl", "--k", "20", "--fc", "-1", "--amplitude", "0.01"], 2),
    (["df", "--k", "20", "--fc", "0.05"], 2),                                  # no --amplitude
    (["analyze", "--frequency", "ten"], 2),
    (["simulate", "--amplitude", "-1"], 2),
    (["identify"], 2),
    (["identify", "r.csv", "--force"], 2),                                    # no --save
    (["identify", "r.csv", "--record", "input-output", "--model", "jenkins", "--periodic",
      "--from-rest"], 2),
    (["stability", "--force"], 2),                                            # no --figure
    (["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
      "--s-max", "1e6", "--dwell", "1"], 2),                                  # no return
    (["reproduce", "--bogus"], 2),
    (["no-such-command"], 2),
])
def test_help_df_and_argument_errors_import_nothing_heavy(argv, rc):
    out = probe(argv)
    assert out["rc"] == rc, out["err"]
    assert out["heavy"] == [], f"motionhyst {' '.join(argv)} imported {out['heavy']}"
    if rc == 2:
        assert out["err"].count("\n") == 1 and "error" in out["err"]


def _rows(header: str, *columns: np.ndarray) -> str:
    return header + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                    for row in np.column_stack(columns))


def _bad_records() -> dict[str, str]:
    """Records of 200 samples at 750 Hz, each with one defect a reader refuses."""
    t = np.arange(200) / 750
    u = np.sin(np.arange(200) / 10)
    y = 1e-3 * np.cos(np.arange(200) / 10)
    swapped = t.copy()
    swapped[[50, 51]] = swapped[[51, 50]]  # time goes back once
    y_hole, u_hole = y.copy(), u.copy()
    y_hole[7] = u_hole[7] = np.nan
    return {
        "io-missing.csv": _rows("time,force", t, u),
        "io-nan.csv": _rows("time,force,displacement", t, u, y_hole),
        "io-back.csv": _rows("time,force,displacement", swapped, u, y),
        "io-spring.csv": _rows("time,force,displacement", t, u, u / 5e4),  # no inertia
        "fd-nan.csv": _rows("time,displacement,force", t, y, u_hole),
        "fd-back.csv": _rows("time,displacement,force", swapped, y, u),
        "fd-zero.csv": _rows("time,displacement,force", t, y, 0.0 * u),
        "fd-clip.csv": _rows("time,displacement,force", t, y, np.clip(2e3 * y, -1.0, 1.0)),
        "fd-damper.csv": _rows("time,displacement,force", t, y, 2e3 * y + 30.0 * np.gradient(y, t)),
        "cl-nan.csv": _rows("time,y1,u", t, y_hole, u),
        "f-missing.csv": _rows("time,position", t, y),
        "f-nan.csv": _rows("time,force", t, u_hole),
        "f-back.csv": _rows("time,force", swapped, u),
        "stage.toml": ('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
                       '[hysteresis]\nmodel = "jenkins"\nk = 100.0\nfc = 1.0\n'),
    }


# python-control, matplotlib and scipy.optimize come with the fits and the simulation, not
# with reading a record (pandas does: it parses the CSV)
FIT_LIBRARIES = ("control", "matplotlib", "scipy.optimize", "scipy.signal", "numba")


def _assert_refused_without_fit_libraries(argv: list[str], error: str, cwd: Path) -> None:
    """`motionhyst ARGV` run in `cwd` exits 2 with one line holding `error`, having imported
    none of :data:`FIT_LIBRARIES`."""
    out = probe(argv, cwd=cwd)
    assert out["rc"] == 2, out["err"]
    assert out["err"].count("\n") == 1 and error in out["err"], out["err"]
    loaded = [m for m in out["heavy"] if m.startswith(FIT_LIBRARIES)]
    assert loaded == [], f"motionhyst {' '.join(argv)} imported {loaded}"


@pytest.mark.parametrize("argv, error", [
    (["identify", "io-missing.csv", "--record", "input-output"], "missing column(s) displacement"),
    (["identify", "io-nan.csv", "--record", "input-output"],
     "io-nan.csv: displacement must be finite: sample 8"),
    (["identify", "io-back.csv", "--record", "input-output"], "time must increase"),
    (["identify", "io-spring.csv", "--record", "input-output"], "no inertia in the force"),
    (["identify", "fd-zero.csv"], "no hysteresis found: the force is constant"),
    (["identify", "fd-clip.csv"], "the force is a curve of the displacement alone"),
    (["identify", "fd-damper.csv"], "no hysteresis in the record: the force is a spring's"),
    (["identify", "fd-nan.csv"], "non-finite value in force"),
    (["identify", "fd-back.csv"], "strictly increasing"),
    (["identify", "cl-nan.csv", "--scenario", "stage.toml"], "non-finite value in y1"),
    (["predict", "stage.toml", "f-missing.csv", "--out", "p.csv"], "missing column(s) force"),
    (["predict", "stage.toml", "f-nan.csv", "--out", "p.csv"],
     "f-nan.csv: force must be finite: sample 8"),
    (["predict", "stage.toml", "f-back.csv", "--out", "p.csv"], "f-back.csv: time must increase"),
])
def test_a_bad_record_is_refused_before_the_fit_libraries_are_imported(tmp_path, argv, error):
    for name, text in _bad_records().items():
        (tmp_path / name).write_text(text)
    _assert_refused_without_fit_libraries(argv, error, tmp_path)
    assert not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize("argv, error", [
    (["benchmark", "emps"], "give --data DIR, the folder with DATA_EMPS.mat"),
    (["benchmark", "bouc-wen"], "give --data DIR, the folder with uval_multisine.mat"),
    (["benchmark", "emps", "--data", "none"], "--data none: no such folder"),
    (["benchmark", "bouc-wen", "--data", "text/DATA_EMPS.mat"], "DATA_EMPS.mat: not a folder"),
    (["benchmark", "emps", "--data", "."], "has no DATA_EMPS.mat"),
    (["benchmark", "emps", "--data", "text"], "not a MATLAB .mat file (a text file)"),
    (["benchmark", "emps", "--data", "short"], "no variable 'vir' (the file has: t, qm)"),
    (["benchmark", "emps", "--data", "short", "--models", "coulomb,coulomb"], "distinct names"),
    (["benchmark", "emps", "--data", "short", "--seed", "1"], "--seed applies to bouc-wen"),
])
def test_a_benchmark_refusal_comes_before_the_fit_libraries(tmp_path, argv, error):
    """The data folder, its records and the options are checked before the optimisers load."""
    from scipy.io import savemat

    (tmp_path / "text").mkdir()
    (tmp_path / "text" / "DATA_EMPS.mat").write_text("t,vir,qm\n0,0,0\n")
    (tmp_path / "short").mkdir()
    savemat(tmp_path / "short" / "DATA_EMPS.mat", {"t": np.arange(10.0), "qm": np.zeros(10)})
    _assert_refused_without_fit_libraries(argv, error, tmp_path)


def _refused_scenarios() -> dict[str, str]:
    """Scenarios a command refuses before it builds their loop, and the files they name."""
    from motionhyst.scenario import default_scenario_path

    paper = default_scenario_path().read_text()
    head, tail = paper[:paper.index("[stage]")], paper[paper.index("[hysteresis]"):]
    return {
        "paper.toml": paper,
        "unstable.toml": paper.replace("flp = 700.0", "flp = 1e12"),
        # sampled at 10 kHz with 8 samples of delay; a tf-z controller; a PID
        "unstable-10k.toml": paper.replace("beta = 0.6 ", "beta = 0.6\nsample_rate_hz = 1e4\n"
                                           "delay_samples = 8.0 "),
        "sampled-10k.toml": paper.replace("beta = 0.6 ", "beta = 0.6\nsample_rate_hz = 1e4 "),
        "unstable-tfz.toml": paper[:paper.index("[controller]")] + (
            '[controller]\ntype = "tf-z"\nnum = [2e7, -1.9e7]\nden = [1.0, -0.5]\n'
            "sample_rate_hz = 1e4\n\n") + paper[paper.index("[feedforward]"):],
        "unstable-pid.toml": paper[:paper.index("[controller]")] + (
            '[controller]\ntype = "pid"\nkp = 6e6\nki = 1e10\nkd = 2e4\n'
            "derivative_filter_hz = 1500.0\n\n") + paper[paper.index("[feedforward]"):],
        "slip.toml": paper.replace('model = "jenkins"', 'model = "maxwell-slip"').replace(
            "k = 20.0 ", "k = [" + "1.0," * 100_001 + "] ").replace(
            "fc = 0.05 ", "fc = [" + "0.01," * 100_001 + "] "),
        "slip-3000.toml": paper.replace('model = "jenkins"', 'model = "maxwell-slip"').replace(
            "k = 20.0 ", "k = [" + "20.0," * 3000 + "] ").replace(
            "fc = 0.05 ", "fc = [" + "0.05," * 3000 + "] "),
        "open.toml": _bad_records()["stage.toml"],
        "plant-dir.toml": head + '[plant]\nfile = "pl"\n' + tail,
        "plant-text.toml": head + '[plant]\nfile = "plant.mat"\n' + tail,
        "plant-columns.toml": head + '[plant]\nfile = "plant.csv"\n' + tail,
        "plant.mat": "not a MATLAB file\n",
        "plant.csv": "frequency_hz,p1\n1,2\n",
        "f.csv": _rows("time,force", np.arange(20) / 750, np.sin(np.arange(20) / 3)),
    }


SCAN = ["scan", "paper.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max",
        "1000", "--s-max", "1e6"]


@pytest.mark.parametrize("argv, error", [
    ([*SCAN, "--ilc-gain", "2"], "--ilc-gain must be in (0, 2)"),
    ([*SCAN, "--compensation", "none", "--ilc-gain", "0.5"], "--ilc-gain has no effect"),
    ([*SCAN, "--at", "nan"], "--at must be finite"),
    ([*SCAN, "--at", "0.1"], "--at: a scan's place on the stroke needs a link that varies"),
    ([*SCAN[:1], "slip-3000.toml", *SCAN[2:], "--compensation", "none", "--max-seconds", "1"],
     "time steps of a link of 3000 elements would take about"),
    ([*SCAN, "--compensation", "model"], "--compensation model needs a [feedforward]"),
    ([*SCAN, "--feedforward", "hysteresis"], "--feedforward hysteresis needs a [feedforward]"),
    ([*SCAN, "--window", "1"], "exposure window (1 s) is longer than the scan"),
    ([*SCAN, "--time-series", "paper.toml"], "it is an input of this command"),
    (["scan", "paper.toml", "--length", "1e6", "--speed", "0.1", "--a-max", "10", "--j-max",
      "1000", "--s-max", "1e6"], "time steps of 3.62e-05 s: too many"),
    (["simulate", "paper.toml", "--time-series", "o.csv", "--frequency", "5", "--duration",
      "1e9"], "too many time steps"),
    (["simulate", "paper.toml", "--time-series", "o.csv", "--profile", "point-to-point",
      "--v-max", "1e-9"], "too many time steps"),
    (["simulate", "paper.toml", "--time-series", "o.csv", "--frequency", "5", "--output-rate",
      "1e-9"], "longer than the duration"),
    (["analyze", "plant-dir.toml"], "[plant] file: cannot read pl: it is a folder"),
    (["analyze", "plant-text.toml"], "not a MATLAB .mat file (a text file)"),
    (["analyze", "plant-columns.toml"], "need columns"),
    (["steady", "unstable.toml"], "does not stabilise the loop (closed-loop pole at 22.94"),
    (["stability", "unstable.toml"], "does not stabilise the loop"),
    (["steady", "unstable-10k.toml"], "the sampled controller does not stabilise the loop "
                                      "(closed-loop pole at z = 1.00"),
    (["analyze", "unstable-tfz.toml"], "the sampled controller does not stabilise the loop"),
    (["steady", "unstable-pid.toml"], "does not stabilise the loop (closed-loop pole at 380+4218j"),
    ([*SCAN[:1], "unstable-10k.toml", *SCAN[2:]], "the sampled controller does not stabilise"),
    (["simulate", "unstable-10k.toml", "--time-series", "o.csv", "--frequency", "5"],
     "the sampled controller does not stabilise"),
    ([*SCAN, "--tail", "1e4"], "276556451 time steps of 3.62e-05 s: too many"),  # the poles'
    ([*SCAN, "--rate", "1e-3"], "--rate 0.001 Hz cannot resolve the setpoint: its switching "
                                "instants on the samples make another move (0.142 s -> 9e+03 s"),
    ([*SCAN, "--window", "1e-9"], "the exposure window 1e-09 s is shorter than two time steps "
                                  "of the run (3.62e-05 s)"),
    (["steady", "slip.toml"], "[hysteresis] k: 100001 values, more than the 100000"),
    (["stability", "open.toml"], "needs a closed loop"),
    (["analyze", "open.toml"], "needs a closed loop"),
    (["steady", "open.toml"], "needs a closed loop"),
    (["predict", "paper.toml", "f.csv", "--out", "p.csv"], "an open-loop system needs"),
    (["steady", "paper.toml", "--frequency", "5", "1e9"],
     "--frequency 1e+09 Hz is more than 2 decades above the loop's fastest closed-loop pole"),
    (["steady", "sampled-10k.toml", "--frequency", "2e6"],
     "decades above the loop's sampling rate (10000 Hz)"),
])
def test_a_refusal_that_needs_no_loop_comes_before_the_fit_libraries(tmp_path, argv, error):
    """Options, outputs, files and sizes known from the command line and the scenario (an
    unstable loop, a step its poles set: from its coefficients) are refused before the loop
    is built (python-control) or anything is fitted."""
    (tmp_path / "pl").mkdir()
    for name, text in _refused_scenarios().items():
        (tmp_path / name).write_text(text)
    _assert_refused_without_fit_libraries(argv, error, tmp_path)
    assert not (tmp_path / "o.csv").exists() and not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize("argv, error", [
    (["identify", "d.csv"], "it is a folder"),
    (["predict", "open.toml", "f.mat", "--out", "p.csv"], "not a MATLAB .mat file (a text file)"),
    (["analyze", "plant-dir.toml"], "it is a folder"),
    (["simulate", "paper.toml", "--time-series", "o.csv", "--frequency", "5", "--duration",
      "1e9"], "too many time steps"),
    ([*SCAN, "--window", "1"], "longer than the scan"),
    (["study", "--summary", "pl"], "pl: not a store of motionhyst study"),  # zarr, xarray
    # a CSV header is read as pandas reads it, without pandas: a header refused does not wait
    (["identify", "notes.csv"], "unknown record header 'my notes'"),
    (["identify", "twice.csv"], "column 'displacement' appears twice in the header"),
    (["identify", "io.csv", "--record", "input-output"], "missing column(s) displacement"),
    (["predict", "open.toml", "notes.csv", "--out", "p.csv"], "missing column(s) time"),
])
def test_a_file_or_a_size_is_refused_before_any_heavy_library(tmp_path, argv, error):
    """Neither pandas (it parses a CSV; these are refused before) nor anything else heavy."""
    (tmp_path / "pl").mkdir()
    (tmp_path / "d.csv").mkdir()
    files = {"f.mat": "time,force\n0,1\n", "notes.csv": "my notes\n1\n",
             "twice.csv": 'time; Displacement ;force;"displacement"\n0;0;0;1\n',
             "io.csv": "\ufeff Time ,\tForce\r\n0,1\r\n"}
    for name, text in {**_refused_scenarios(), **files}.items():
        (tmp_path / name).write_text(text)
    out = probe(argv, cwd=tmp_path)
    assert out["rc"] == 2 and error in out["err"], out["err"]
    assert out["heavy"] == [], f"motionhyst {' '.join(argv)} imported {out['heavy']}"


# python-control's plots and scipy.signal's statistics and image filters: what its import
# would load for a computation that never uses them (motionhyst.core.deferred)
CONTROL_EXTRAS = ("matplotlib", "mpl_toolkits", "scipy.stats", "scipy.ndimage")


@pytest.mark.parametrize("argv", [
    ["analyze", "--frequency", "5"],
    ["steady", "--frequency", "5", "--no-floquet"],
    ["stability"],
])
def test_a_command_that_builds_its_loop_imports_python_control_without_its_plots(argv):
    out = probe(argv)
    assert out["rc"] == 0, out["err"]
    assert "control" in out["packages"]
    loaded = [m for m in out["heavy"] if m.startswith(CONTROL_EXTRAS)]
    assert loaded == [], f"motionhyst {' '.join(argv)} imported {loaded[:5]}"


_DEFERRED_USED = """
import json, sys
import numpy as np
if sys.argv[1] == "deferred":
    from motionhyst.core.deferred import defer_control_extras
    defer_control_extras()
import control
extras = sorted({m.split(".")[0] + "." + m.split(".")[1] if m.startswith("scipy.") else
                 m.split(".")[0] for m in sys.modules if m.startswith(CONTROL_EXTRAS)})
import matplotlib
matplotlib.use("Agg")
from scipy.signal import find_peaks_cwt, medfilt, savgol_filter
x = np.sin(np.linspace(0.0, 20.0, 200)) + 0.1 * np.cos(np.linspace(0.0, 170.0, 200))
sys_ = control.tf([1.0], [1.0, 0.4, 1.0])
cplt = control.pole_zero_plot(sys_, grid=True)   # control.grid, axisartist
nichols = control.nichols_plot(sys_)             # matplotlib.transforms
bode = control.bode_plot(sys_)                   # pyplot
print(json.dumps({
    "extras": extras,
    "peaks": find_peaks_cwt(x, [5]).tolist(),                   # scipy.stats
    "savgol": savgol_filter(x, 7, 2, mode="nearest").tolist(),  # scipy.ndimage
    "median": medfilt(x, 5).tolist(),
    "lines": [len(a.get_lines()) for a in bode.axes.ravel()],
    "nichols": [len(a.get_lines()) for a in nichols.axes.ravel()],
    "grid": type(cplt.axes.ravel()[0]).__name__,
}))
""".replace("CONTROL_EXTRAS", repr(CONTROL_EXTRAS))


def test_python_control_s_deferred_plots_and_statistics_work_when_used(tmp_path):
    """The stand-ins import the real modules at their first use: python-control's plots
    (pyplot, a pole-zero map's grid, a Nichols chart's transforms) and scipy.signal's peak
    search, filters and median give what the plain import gives."""
    plain, deferred = (_run(_DEFERRED_USED, how, cwd=tmp_path) for how in ("plain", "deferred"))
    assert plain.returncode == 0 and deferred.returncode == 0, plain.stderr + deferred.stderr
    plain, deferred = json.loads(plain.stdout), json.loads(deferred.stdout)
    assert plain.pop("extras") == ["matplotlib", "mpl_toolkits", "scipy.ndimage", "scipy.stats"]
    assert deferred.pop("extras") == []
    assert deferred == plain


def test_a_name_a_stand_in_does_not_forward_imports_the_real_module():
    """Another version of python-control or scipy that imports more than the names forwarded
    gets the real module (a slower import, never a wrong one)."""
    code = ("import json, sys\n"
            "from motionhyst.core.deferred import Deferred\n"
            "sys.modules['fractions'] = stand_in = Deferred('fractions', ('gcd_unused',))\n"
            "forward = stand_in.gcd_unused\n"
            "before = 'fractions' in sys.modules and sys.modules['fractions'] is stand_in\n"
            "Fraction = stand_in.Fraction\n"
            "import fractions\n"
            "print(json.dumps([before, fractions is not stand_in, Fraction is fractions.Fraction,"
            " str(Fraction(1, 3) + Fraction(1, 6))]))\n")
    proc = _run(code)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [True, True, True, "1/2"]


def test_import_motionhyst_is_light_and_exports_every_name():
    code = """
import json, sys
import motionhyst
light = sorted(m for m in sys.modules if m.split(".")[0] in ("control", "scipy", "matplotlib",
                                                             "numba", "pydantic"))
from motionhyst import *  # noqa
from motionhyst import Loop, periodic_steady_state
import motionhyst.controllers.loop, motionhyst.analysis.steady
same = (Loop is motionhyst.controllers.loop.Loop
        and periodic_steady_state is motionhyst.analysis.steady.periodic_steady_state)
print(json.dumps({"light": light, "same": same, "all": sorted(motionhyst.__all__),
                  "dir": all(n in dir(motionhyst) for n in motionhyst.__all__),
                  "resolved": all(getattr(motionhyst, n) is not None for n in motionhyst.__all__)}))
"""
    proc = _run(code)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["light"] == []
    assert out["same"] and out["dir"] and out["resolved"]
    assert {"Loop", "analyze", "simulate", "periodic_steady_state"} <= set(out["all"])
    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        motionhyst.nothing_here  # noqa: B018


def _readonly_copy(tmp_path: Path) -> Path:
    """A copy of the package in which no ``__pycache__`` folder can be created."""
    root = tmp_path / "site"
    shutil.copytree(PACKAGE, root / "motionhyst",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for folder in [root / "motionhyst", *(p for p in (root / "motionhyst").rglob("*")
                                          if p.is_dir())]:
        (folder / "__pycache__").write_text("")  # a file where the cache folder would go
    for path in root.rglob("*"):
        path.chmod(0o444 if path.is_file() else 0o555)
    return root


_KERNEL = """
import json
import numpy as np
from motionhyst import Jenkins
from motionhyst.core.compiled import compiled_in_memory
w = Jenkins(k=20.0, fc=0.05).response(np.array([0.0, 0.01, -0.01, 0.0]))
print(json.dumps({"w": w.tolist(), "in_memory": compiled_in_memory()}))
"""


def _run_on_a_terminal(code: str, env: dict, cwd: Path) -> subprocess.CompletedProcess:
    """:func:`_run` with stderr a terminal (a pseudo-terminal read here), where the first
    compilation is announced."""
    import pty

    parent, child = pty.openpty()
    with subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                          stderr=child, env=env, cwd=cwd, text=True) as proc:
        os.close(child)
        chunks = []
        while True:
            try:
                chunk = os.read(parent, 4096)
            except OSError:  # the terminal's other end closed: the process ended
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(parent)
        out = proc.stdout.read()
        rc = proc.wait(timeout=600)
    err = b"".join(chunks).decode().replace("\r\n", "\n")
    return subprocess.CompletedProcess(proc.args, rc, out, err)


def _env(root: Path, cache_home: Path) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("HOME", "XDG_CACHE_HOME", "NUMBA_CACHE_DIR", "PYTHONPATH")}
    env.update(PYTHONPATH=str(root), XDG_CACHE_HOME=str(cache_home),
               PYTHONDONTWRITEBYTECODE="1")
    return env


def test_read_only_install_without_cache_folder_compiles_in_memory(tmp_path):
    root = _readonly_copy(tmp_path)
    blocked = tmp_path / "not-a-folder"
    blocked.write_text("")  # neither the user cache nor HOME can hold a folder
    env = _env(root, blocked)
    env["HOME"] = str(blocked)
    proc = _run_on_a_terminal(_KERNEL, env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out == {"w": [0.0, 0.05, -0.05, 0.05], "in_memory": True}
    assert proc.stderr.count("motionhyst: compiling") == 1
    assert "this run only" in proc.stderr
    assert "Traceback" not in proc.stderr
    piped = _run(_KERNEL, env=env, cwd=tmp_path)  # stderr not a terminal: nothing announced
    assert piped.returncode == 0 and json.loads(piped.stdout) == out and piped.stderr == ""


def test_read_only_install_caches_in_the_user_folder(tmp_path):
    root = _readonly_copy(tmp_path)
    cache = tmp_path / "cache"
    env = _env(root, cache)
    env.pop("HOME", None)
    first = _run_on_a_terminal(_KERNEL, env=env, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert json.loads(first.stdout) == {"w": [0.0, 0.05, -0.05, 0.05], "in_memory": False}
    assert first.stderr.count("motionhyst: compiling") == 1
    assert "cached for later runs" in first.stderr
    assert list(cache.rglob("*.nbi")), "no numba index in the user cache folder"
    second = _run_on_a_terminal(_KERNEL, env=env, cwd=tmp_path)
    assert second.returncode == 0, second.stderr
    assert second.stdout == first.stdout
    assert "compiling" not in second.stderr  # loaded from the cache, nothing announced


def test_cache_folder_is_keyed_by_the_sources(tmp_path):
    """numba checks a cached kernel against its own file only: after any source changes (an
    upgrade, an edit of a kernel another one calls), the cache folder must be a new one."""
    root = tmp_path / "src"
    shutil.copytree(Path(motionhyst.__file__).parent, root / "motionhyst",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    code = "from motionhyst.core.compiled import _cache_folder; print(_cache_folder().name)"

    def folder() -> str:
        out = subprocess.run([sys.executable, "-c", code], env=_env(root, tmp_path / "cache"),
                             capture_output=True, text=True, check=True)
        return out.stdout.strip()

    before = folder()
    assert before.startswith("numba-") and folder() == before  # stable while nothing changes
    kernels = root / "motionhyst" / "hysteresis" / "_kernels.py"
    kernels.write_text(kernels.read_text() + "\n# edited\n")
    assert folder() != before


_EARLY = """
import os, signal, sys
import motionhyst

SIG = getattr(signal, sys.argv[1])

class SignalOnImport:  # the signal arrives while the command line interface is imported
    def find_spec(self, name, path=None, target=None):
        if name == "motionhyst.cli._common":
            os.kill(os.getpid(), SIG)
        return None

sys.meta_path.insert(0, SignalOnImport())
from motionhyst.entry import main
sys.argv[1:] = ["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]
sys.exit(main())
"""


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_before_the_command_handlers_ends_as_an_interruption(tmp_path, name):
    """The console script (motionhyst.entry) handles signals before argparse and the command
    line interface load: no traceback, no death by SIGTERM, exit 130, nothing on stdout."""
    proc = _run(_EARLY, name, cwd=tmp_path)
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr == "motionhyst: interrupted\n" and proc.stdout == ""


def test_import_motionhyst_before_the_entry_handles_signals_imports_little():
    """``import motionhyst`` (before its handlers when the command is started through the old
    entry, ``motionhyst.entry``) imports no more than a handful of small modules of the
    standard library."""
    code = ("import json, sys; before = set(sys.modules); import motionhyst; "
            "print(json.dumps(sorted(set(sys.modules) - before)))")
    proc = _run(code)
    assert proc.returncode == 0, proc.stderr
    new = {m for m in json.loads(proc.stdout) if not m.startswith("motionhyst")}
    assert new <= {"__future__", "importlib", "importlib._bootstrap",
                   "importlib._bootstrap_external", "importlib.machinery", "types", "warnings"}


def test_a_signal_ignored_by_the_parent_stays_ignored_before_the_handlers(tmp_path):
    """nohup (SIGINT and SIGTERM ignored): the entry installs nothing over them, and the
    command runs to its end."""
    import signal

    def ignore():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)

    proc = subprocess.run([sys.executable, "-c", _EARLY, "SIGTERM"], capture_output=True,
                          text=True, cwd=tmp_path, timeout=600, check=False, preexec_fn=ignore)
    assert proc.returncode == 0, proc.stderr
    assert "Describing function of the jenkins element" in proc.stdout


def test_the_entry_leaves_both_signals_ignored_to_the_exit_or_puts_them_back(tmp_path):
    """As the command (no arguments given) a signal after its work must neither interrupt
    the interpreter's exit nor turn the finished run into an interrupted one; called from
    Python, the handlers found are put back."""
    code = ("import signal, sys\n"
            "from motionhyst.entry import main\n"
            "found = [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)]\n"
            "a = main(['df', '--k', '20', '--fc', '0.05', '--amplitude', '0.01'])\n"
            "back = [signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)] == found\n"
            "sys.argv[1:] = ['df', '--k', '20', '--fc', '0.05', '--amplitude', '0.01']\n"
            "b = main()\n"
            "ignored = [signal.getsignal(s) is signal.SIG_IGN\n"
            "           for s in (signal.SIGINT, signal.SIGTERM)]\n"
            "print(a, back, b, ignored, file=sys.stderr)\n")
    proc = _run(code, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines()[-1] == "0 True 0 [True, True]", proc.stderr


def _entry_point() -> tuple[str, str]:
    """The module and function of the ``motionhyst`` console script, as pyproject.toml names
    them (the installed script may predate it)."""
    import tomllib

    with open(Path(__file__).parent.parent / "pyproject.toml", "rb") as f:
        value = tomllib.load(f)["project"]["scripts"]["motionhyst"]
    module, _, function = value.partition(":")
    return module, function


def test_the_console_script_imports_nothing_before_its_handlers():
    """The console script's entry is a module beside the package (not ``motionhyst.entry``,
    whose import runs the package's ``__init__`` first), and importing it loads no module the
    interpreter had not loaded before the script's first line (not even ``signal``)."""
    module, _ = _entry_point()
    proc = _run(f"import json, sys\nbefore = set(sys.modules)\nimport {module}\n"
                f"print(json.dumps(sorted(set(sys.modules) - before)))")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [module] and "." not in module


_HOOK = """import os, signal, weakref
class Thing:
    pass
def send(_=None):
    os.kill(os.getpid(), signal.{name})
class SignalOnImport:  # the signal arrives as the console script imports {module}
    def find_spec(self, name, path=None, target=None):
        if name == "{module}":
            if {in_callback}:  # where an exception cannot propagate: it is only reported
                thing = Thing()
                ref = weakref.ref(thing, send)
                del thing
            else:
                send()
        return None
sys.meta_path.insert(0, SignalOnImport())
"""


def _signalled_console_script(tmp_path: Path, name: str, module: str, in_callback: bool
                              ) -> subprocess.CompletedProcess:
    """The console script as pip writes it from pyproject.toml, signalled as it imports
    `module` (`in_callback`: from a weak reference's callback), run as ``motionhyst df``."""
    entry, function = _entry_point()
    hook = _HOOK.format(name=name, module=module, in_callback=in_callback)
    script = tmp_path / "motionhyst"
    script.write_text(f"import sys\n{hook}from {entry} import {function}\n"
                      f"if __name__ == '__main__':\n    sys.exit({function}())\n")
    return subprocess.run([sys.executable, str(script), "df", "--k", "20", "--fc", "0.05",
                           "--amplitude", "0.01"], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600, check=False)


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_as_the_console_script_imports_the_package_ends_as_an_interruption(
        tmp_path, name):
    """Ctrl-C or SIGTERM while the console script imports ``motionhyst`` (its ``__init__``
    and what that imports; then the ``signal`` module: 15 and 20 ms of the old window's 80
    under load): exit 130 and one line, as at any later moment (main f318d46: a traceback,
    or death by SIGTERM)."""
    proc = _signalled_console_script(tmp_path, name, "motionhyst", in_callback=False)
    assert (proc.returncode, proc.stderr, proc.stdout) == (130, "motionhyst: interrupted\n", "")


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_swallowed_by_a_callback_before_the_command_starts_ends_it(tmp_path, name):
    """A signal whose ``KeyboardInterrupt`` is raised in a callback of the import system (its
    module locks' weak references: 11 of 8240 signals 0-200 ms after start) is not lost: exit 130,
    one line, the command not run (main f318d46: 'Exception ignored ...' with a traceback,
    and the command ran to its end, exit 0)."""
    proc = _signalled_console_script(tmp_path, name, "motionhyst.cli", in_callback=True)
    assert (proc.returncode, proc.stderr, proc.stdout) == (130, "motionhyst: interrupted\n", "")
