"""Bounded and honest on every input (issue 26): memory, links, temporary files, no answer
from nothing, no option ignored.

Every case runs the command line in a child process whose address space is
limited (``RLIMIT_AS``), in a folder holding the user's files and a folder
beside it that a symbolic link may point into.  It asserts the exit code, one
line on stderr for a refusal (plain text, no traceback), and that every file
that was there before is byte-identical afterwards, apart from the outputs the
command owns, with no file added (no temporary file, no half-written output).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot
from records_of_other_kinds import damper_record, piezo_record

from motionhyst.cli import main
from motionhyst.plants.frf_fit import ModalPlant
from motionhyst.plants.two_mass import TwoMassStage
from motionhyst.scenario import default_scenario_path

PAPER = default_scenario_path().read_text()
STUDY = ('scenario = "s.toml"\noutputs = ["e1"]\n\n[axes]\namplitude = [0.001, 0.01]\n'
         'frequency_hz = { geomspace = [1.0, 100.0, 50] }\n\n[samples]\nn = 100\nseed = 0\n'
         '"hysteresis.k" = { lognormal = [20.0, 0.1] }\n')
LIMIT = 3 << 30
"""Address space of a case's process [bytes]: an estimate that misses is a MemoryError (the
cases that run to their end, such as a 200000-line FRF, peak at 0.9 GB)."""


def _popen(argv, cwd) -> subprocess.Popen:
    return limited_process.popen(argv, cwd, limit=LIMIT)


def _frd(f, scale_f: float = 1.0, noise: float = 0.0, magphase: bool = False,
         lowpass_hz: float | None = None) -> str:
    """A measured two-mass stage (Table I) at `f` [Hz], written with `f` times `scale_f`
    (through a sensor's first-order low-pass at `lowpass_hz`, if given)."""
    stage = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    p1, p2 = stage.response(2 * np.pi * f)
    if lowpass_hz is not None:
        p1, p2 = (p / (1.0 + 1j * f / lowpass_hz) for p in (p1, p2))
    if noise:
        rng = np.random.default_rng(0)
        p1 = p1 * (1 + noise * rng.standard_normal(f.size))
        p2 = p2 * (1 + noise * rng.standard_normal(f.size))
    if magphase:
        cols = [f * scale_f, np.abs(p1), np.angle(p1, deg=True), np.abs(p2),
                np.angle(p2, deg=True)]
        head = "frequency_hz,p1_abs,p1_phase_deg,p2_abs,p2_phase_deg\n"
    else:
        cols = [f * scale_f, p1.real, p1.imag, p2.real, p2.imag]
        head = "frequency_hz,p1_re,p1_im,p2_re,p2_im\n"
    rows = np.column_stack(cols)
    return head + "\n".join(",".join(f"{v:.10e}" for v in row) for row in rows) + "\n"


def _with_plant(extra: str = "", text: str = PAPER) -> str:
    """The Table I scenario with a measured [plant] ``plant.csv`` in place of its [stage]."""
    return (text[:text.index("[stage]")] + f'[plant]\nfile = "plant.csv"\n{extra}\n'
            + text[text.index("[hysteresis]"):])


def _io_record(mass: float = 0.0) -> str:
    """A short input-output record (time,force,displacement) of a spring, or of a mass on it."""
    from motionhyst.time.openloop import MassSpringDamper, OpenLoop

    t = np.arange(600) / 750.0
    u = 50.0 * np.sin(2 * np.pi * 7.0 * t) + 20.0 * np.sin(2 * np.pi * 31.0 * t)
    y = (OpenLoop(MassSpringDamper(mass, 10.0, 5e4)).simulate(t, u).displacement if mass
         else u / 5e4)
    return "time,force,displacement\n" + "".join(
        f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), u.tolist(), y.tolist(),
                                                 strict=True))


def _from_rest() -> str:
    """Three periods of a sine force on a mass-spring-damper, from rest: not a steady state."""
    from motionhyst.time.openloop import MassSpringDamper, OpenLoop

    t = np.arange(750) / 750.0
    u = 50.0 * np.sin(2 * np.pi * 3.0 * t)
    y = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4)).simulate(t, u).displacement
    y = y + 1e-5 * np.random.default_rng(1).standard_normal(y.size)  # 1.4 % of its RMS
    return "time,force,displacement\n" + "".join(
        f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), u.tolist(), y.tolist(),
                                                 strict=True))


LOG = np.geomspace(1.0, 3000.0, 200)
JENKINS = ('model = "jenkins"\nk = 20.0              # spring stiffness k_J [N/m]\n'
           'fc = 0.05             # slip force f_c [N]\n')


def _maxwell_slip(n: int) -> str:
    """The Table I scenario with a Maxwell-slip link of `n` equal elements."""
    return PAPER.replace(JENKINS, f'model = "maxwell-slip"\nk = [{", ".join(["1.0"] * n)}]\n'
                                  f'fc = [{", ".join(["0.01"] * n)}]\n')


def _frequencies(n: int) -> str:
    """The Table I scenario at `n` frequencies from 1 Hz on, 1 mHz apart."""
    return PAPER.replace("frequencies = [5.0, 10.0, 15.0]",
                         f"frequencies = [{', '.join(f'{1 + i * 1e-3:.3f}' for i in range(n))}]")
MODEL = ('[stage]\ntype = "mass-spring-damper"\nm = 2.0\nc = 10.0\nk = 5e4\n\n'
         '[hysteresis]\nmodel = "jenkins"\nk = 100.0\nfc = 1.0\n')


def _force(n: int) -> str:
    """A force record time,force of `n` samples at 750 Hz."""
    return "time,force\n" + "".join(f"{i / 750!r},{np.sin(i / 10):.6f}\n" for i in range(n))


def _one_period(n: int) -> str:
    """A force record of one period of a sine, `n` samples at 750 Hz (a --periodic input)."""
    return "time,force\n" + "".join(f"{i / 750!r},{np.sin(2 * np.pi * i / n):.6f}\n"
                                     for i in range(n))


def _negative_magnitude() -> str:
    """Magnitude and phase, the first line's ``p1_abs`` negative (a sign slipped in)."""
    rows = _frd(LOG, magphase=True).splitlines()
    cells = rows[1].split(",")
    cells[1] = "-" + cells[1]
    return "\n".join([rows[0], ",".join(cells), *rows[2:]]) + "\n"
def _table(record, columns: tuple[str, ...]) -> str:
    """A generated record (:mod:`records_of_other_kinds`) as CSV text with these columns."""
    data = {"time": record.t, "force": record.force, "displacement": record.displacement}
    return ",".join(columns) + "\n" + "".join(
        ",".join(repr(float(data[c][i])) for c in columns) + "\n" for i in range(record.t.size))


PIEZO = _table(piezo_record(seconds=0.5), ("time", "force", "displacement"))
DAMPER = _table(damper_record(seconds=10.0), ("time", "displacement", "force"))
SCAN = ["scan", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
        "--s-max", "1e6"]

BASE = {"s.toml": PAPER, "notes.txt": "my notes", "old.csv": "time,error\n0,0\n",
        "io.csv": _io_record(), "../outside/target.csv": "not yours\n"}

# (id, extra files, argv, exit code, words of the one line on stderr (None: stderr free),
#  outputs the command owns (created or replaced))
CASES = [
    # ------------------------------------------------------------------------ memory and work
    ("simulate-1MHz-sine", {}, ["simulate", "s.toml", "--time-series", "t.csv", "--frequency",
                                "1e6"], 2, ["too many time steps", "lower --frequency"], []),
    ("scan-long-tail", {}, [*SCAN, "--tail", "1e5"], 2, ["too many", "tail"], []),
    ("scan-above-max-memory", {}, [*SCAN, "--tail", "10", "--max-memory", "50M"], 2,
     ["memory budget of 52.4 MB", "--max-memory"], []),
    ("frf-fit-above-max-memory", {"p.toml": _with_plant(), "plant.csv": _frd(LOG)},
     ["analyze", "p.toml", "--max-memory", "10M"], 2, ["candidate modes", "memory budget"],
     []),
    ("max-memory-not-a-size", {}, ["analyze", "--max-memory", "lots"], 2,
     ["--max-memory", "not a size"], []),
    ("steady-100k-frequencies", {"f.toml": _frequencies(100_000)}, ["steady", "f.toml"], 2,
     ["^the Floquet multipliers at 100000 frequencies would take about", "work budget of 1 h",
      "--max-seconds", "--no-floquet"], []),
    ("steady-above-max-seconds", {}, ["steady", "--frequency", "5", "10", "--max-seconds",
                                      "0.1"], 2, ["work budget of 0.1 s (--max-seconds)"], []),
    ("steady-maxwell-100k-elements", {"m.toml": _maxwell_slip(100_000)},
     ["steady", "m.toml", "--frequency", "10"], 2,
     ["^the monodromy of 100000 stop elements needs", "memory budget", "--no-floquet"], []),
    ("simulate-maxwell-100k-elements", {"m.toml": _maxwell_slip(100_000)},
     ["simulate", "m.toml", "--time-series", "t.csv", "--frequency", "20", "--duration", "20"],
     2, ["time steps of a link of 100000 elements, 2e+05 rows written would take about",
         "(--max-seconds)",
         "fewer elements"], []),
    ("max-seconds-not-positive", {}, ["steady", "--max-seconds", "0"], 2,
     ["--max-seconds", "must be"], []),
    ("frf-dense-200k-lines", {"p.toml": _with_plant(),
                              "plant.csv": _frd(np.linspace(1.0, 3000.0, 200_000),
                                                noise=0.01)},
     ["analyze", "p.toml"], 0, None, []),
    ("predict-too-many-substeps", {"model.toml": MODEL, "f.csv": _one_period(20_000)},
     ["predict", "model.toml", "f.csv", "--out", "pred.csv", "--substeps", "10000",
      "--periodic"], 2,
     ["20000 samples of 10000 integration steps", "memory budget"], []),
    ("io-two-mass-on-one-mass", {"mass.csv": _io_record(mass=2.0)},
     ["identify", "mass.csv", "--record", "input-output", "--plant", "two-mass",
      "--max-memory", "1G"], 2,
     ["the records show one mass, not two", "--plant mass-spring-damper"], []),
    ("benchmark-mat-header-damaged", {f"bw/{n}.mat": b"MATLAB 5.0 MAT-file\x00\x01\x02"
                                      for n in ("uval_multisine", "yval_multisine",
                                                "uval_sinesweep", "yval_sinesweep")},
     ["benchmark", "bouc-wen", "--data", "bw"], 2, ["uval_multisine.mat: cannot read"], []),
    # ----------------------------------------------------------- inputs that are not files
    ("scenario-is-a-device", {}, ["analyze", "/dev/zero"], 2,
     ["^/dev/zero: cannot read (not a regular file: a device, a pipe or a socket)"], []),
    ("scenario-is-a-pipe", {"@fifo:p.toml": None}, ["steady", "p.toml"], 2,
     ["^p.toml: cannot read (not a regular file"], []),
    ("plant-file-is-a-device", {"p.toml": _with_plant().replace('"plant.csv"', '"/dev/zero"')},
     ["analyze", "p.toml"], 2, ["[plant] file: cannot read /dev/zero: not a regular file"], []),
    ("record-is-a-pipe", {"@fifo:r.csv": None}, ["identify", "r.csv"], 2,
     ["cannot read r.csv: not a regular file"], []),
    ("io-record-is-a-device", {}, ["identify", "/dev/urandom", "--record", "input-output"], 2,
     ["cannot read /dev/urandom: not a regular file"], []),
    ("predict-input-is-a-pipe", {"model.toml": MODEL, "@fifo:f.csv": None},
     ["predict", "model.toml", "f.csv", "--out", "pred.csv"], 2,
     ["cannot read f.csv: not a regular file"], []),
    ("study-is-a-pipe", {"@fifo:st.toml": None}, ["study", "st.toml", "--out", "o.zarr"], 2,
     ["st.toml: cannot read (not a regular file"], []),
    ("record-above-max-memory", {"big.csv": _io_record()},
     ["identify", "big.csv", "--max-memory", "20K"], 2,
     ["big.csv (600 rows, not read yet): reading its 3 columns needs 480 kB, above the memory "
      "budget of 20.5 kB", "give a smaller file"], []),
    ("record-line-of-2e6-fields", {"r.csv": "time,displacement,force\n0,0,0\n" + "0," * 2_000_000
                                   + "0\n"}, ["identify", "r.csv"], 2,
     ["^r.csv: inconsistent lengths: line 3 has 2000001 fields, the header 3"], []),
    ("record-column-1e300", {"r.csv": "time,displacement,force\n" + "".join(
        f"{i / 100!r},{1e300 * np.sin(i / 10):.17g},{np.sin(i / 10):.17g}\n" for i in range(400))},
     ["identify", "r.csv"], 2, ["^r.csv: displacement reaches", "outside the magnitudes"], []),
    ("record-time-step-1e-300", {"r.csv": "time,force\n" + "".join(
        f"{i * 1e-300!r},{np.sin(i / 10):.6f}\n" for i in range(300)), "model.toml": MODEL},
     ["predict", "model.toml", "r.csv", "--out", "p.csv"], 2,
     ["^r.csv: time reaches 2.99e-298: outside the magnitudes"], []),
    ("study-axis-of-1e9-values", {"st.toml": STUDY.replace("[1.0, 100.0, 50]",
                                                           "[1.0, 100.0, 1000000000]")},
     ["study", "st.toml", "--out", "o.zarr"], 2,
     ["'frequency_hz': 1000000000 values, more than the 100000000 points"], []),
    ("study-1e12-samples", {"st.toml": STUDY.replace("n = 100", "n = 1000000000000")},
     ["study", "st.toml", "--out", "o.zarr"], 2,
     ["[samples] 'n': 1000000000000 samples, more than the 100000000 points"], []),
    # ----------------------------------------------------------------- no answer from nothing
    ("io-piezo-without-inertia", {"piezo.csv": PIEZO},
     ["identify", "piezo.csv", "--record", "input-output", "--model", "jenkins"], 2,
     ["^piezo.csv: no inertia in the force", "not positive", "--plant quasi-static"], []),
    ("io-spring-without-inertia", {}, ["identify", "io.csv", "--record", "input-output"], 2,
     ["^io.csv: no inertia in the force", "--plant quasi-static"], []),
    ("io-force-displacement-record", {"damper.csv": DAMPER},
     ["identify", "damper.csv", "--record", "input-output", "--plant", "mass-damper",
      "--model", "coulomb"], 2,
     ["^damper.csv: no inertia in the force", "without --record input-output"], []),
    ("frf-two-lines", {"p.toml": _with_plant(), "plant.csv": _frd(np.array([10.0, 100.0]))},
     ["analyze", "p.toml"], 2, ["^p.toml: [plant] file: plant.csv: 2 measured lines cannot "
                                "determine a mode", "Pf2 = 0"], []),
    ("frf-modes-0", {"p.toml": _with_plant("modes = 0"), "plant.csv": _frd(LOG)},
     ["steady", "p.toml"], 2, ["^p.toml: [plant]: modes = 0", "Pf2 = 0"], []),
    ("frf-negative-magnitude", {"p.toml": _with_plant(), "plant.csv": _negative_magnitude()},
     ["analyze", "p.toml"], 2, ["p1_abs must be > 0", "phase", "at 1 Hz"], []),
    ("frf-in-khz", {"p.toml": _with_plant(), "plant.csv": _frd(LOG, scale_f=1e-3)},
     ["analyze", "p.toml"], 0, ["warning", "M = 2.25e+07 kg", "kHz"], []),
    # 1 % noise: the BIC's second 'mode' (r1 within its std of zero) made the loop unstable,
    # refused as a fit in doubt; it is dropped now, and the one-mode fit (M 22.51 kg, 694 Hz,
    # its error the noise) analysed without a word
    ("frf-noisy-fit-keeps-the-mode-it-determines", {"p.toml": _with_plant(),
                                                     "plant.csv": _frd(LOG, noise=0.01)},
     ["analyze", "p.toml"], 0, None, []),
    ("frf-fit-above-its-noise", {"p.toml": _with_plant("modes = 1"),
                                 "plant.csv": _frd(LOG, noise=0.005, lowpass_hz=2000.0)},
     ["analyze", "p.toml"], 2, ["^p.toml: [plant] file: plant.csv: cannot fit a rigid body "
                                "plus modes: fit errors far above the data's noise",
                                "give [plant] modes"], []),
    ("predict-periodic-ends-do-not-join", {"model.toml": MODEL, "f.csv": _force(300)},
     ["predict", "model.toml", "f.csv", "--out", "p.csv", "--periodic"], 2,
     ["^f.csv: not whole periods of a periodic signal: its ends do not join"], []),
    ("periodic-record-from-rest", {"rest.csv": _from_rest()},
     ["identify", "rest.csv", "--record", "input-output", "--periodic"], 2,
     ["rest.csv: not a periodic steady state", "without --periodic"], []),
    ("scenario-duplicate-frequency", {"d.toml": PAPER.replace(
        "frequencies = [5.0, 10.0, 15.0]", "frequencies = [5.0, 10.0, 5.0]")},
     ["analyze", "d.toml"], 2, ["frequencies: 5 is given twice"], []),
    ("scenario-mass-1e300", {"h.toml": PAPER.replace("m2 = 17.5 ", "m2 = 1e300 ")},
     ["analyze", "h.toml"], 2, ["^h.toml: [stage] m2 = 1e+300: outside the magnitudes"], []),
    ("scenario-mass-1e20-no-numpy-warning", {"h.toml": PAPER.replace("m1 = 5.0 ", "m1 = 1e20 ")},
     ["analyze", "h.toml"], 0, ["motionhyst: warning: analyze: h.toml: [stage] m1 = 1e+20 kg, "
                                "a factor 1e+16 above the 0.001-10000 kg of motion stages",
                                "motionhyst: warning: analyze: |C P2| does not fall through 1",
                                "no bandwidth", "M = 1e+20 kg"], []),  # its own warnings only
    ("scenario-mass-1e-300", {"h.toml": PAPER.replace("m2 = 17.5 ", "m2 = 1e-300 ")},
     ["steady", "h.toml"], 2, ["^h.toml: [stage] m2 = 1e-300: outside the magnitudes"], []),
    ("scenario-slip-force-list-1e-300", {"h.toml": PAPER.replace(
        'model = "jenkins"\nk = 20.0', 'model = "maxwell-slip"\nk = [20.0, 10.0]').replace(
        "fc = 0.05 ", "fc = [0.05, 1e-300] ")},
     ["analyze", "h.toml"], 2, ["^h.toml: [hysteresis] fc[1] = 1e-300"], []),
    ("option-stiffness-1e300", {}, ["df", "--k", "1e300", "--fc", "0.05", "--amplitude",
                                    "0.01"], 2, ["--k: 1e300 is outside the magnitudes"], []),
    ("option-frequency-1e-300", {}, ["steady", "--frequency", "1e-300"], 2,
     ["--frequency: 1e-300 is outside the magnitudes"], []),
    # ------------------------------------------------------------------- options not ignored
    ("criterion-with-input-output", {}, ["identify", "io.csv", "--record", "input-output",
                                         "--criterion", "bic"], 2,
     ["--criterion", "input-output"], []),
    ("scan-ilc-trials-without-ilc", {}, [*SCAN, "--compensation", "none", "--ilc-trials", "3"],
     2, ["--ilc-trials has no effect without --compensation ilc"], []),
    ("scan-other-speed-without-ilc", {}, [*SCAN, "--compensation", "none", "--other-speed",
                                          "0.2"], 2, ["--other-speed has no effect"], []),
    # --------------------------------------------------------------------- outputs and links
    ("time-series-link-out-of-folder", {"@symlink:link.csv": "../outside/target.csv"},
     ["simulate", "--time-series", "link.csv", "--frequency", "5", "--duration", "0.05"], 2,
     ["link.csv: a symbolic link", "--force", "never the file it points to"], []),
    ("time-series-link-forced", {"@symlink:link.csv": "../outside/target.csv"},
     ["simulate", "--time-series", "link.csv", "--frequency", "5", "--duration", "0.3",
      "--force"], 0, None, ["link.csv"]),
    ("predict-out-link-forced", {"@symlink:pred.csv": "../outside/target.csv",
                                 "model.toml": MODEL, "f.csv": _force(300)},
     ["predict", "model.toml", "f.csv", "--out", "pred.csv", "--force"], 0, None,
     ["pred.csv"]),
    ("reproduce-out-link-to-folder", {"@symlink:out": "../outside"},
     ["reproduce", "--out", "out"], 2, ["symbolic link", "--force"], []),
]


def _populate(root: Path, files: dict) -> None:
    populate(root, {**BASE, **files})


def _one_line(err: bytes) -> str:
    text = err.decode("utf-8", errors="replace")
    lines = text.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in text, text
    assert lines[0].isprintable(), lines[0]
    return lines[0]


def _warnings(err: bytes, count: int) -> str:
    """The `count` warnings of a command that ran, joined: each line the product's own."""
    text = err.decode("utf-8", errors="replace")
    lines = text.strip().splitlines()
    assert len(lines) == count and "Traceback" not in text, text
    assert all(ln.startswith("motionhyst: warning: ") and ln.isprintable() for ln in lines), text
    return "\n".join(lines)


def test_the_cases_are_distinct():
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("files", "argv", "code", "words", "owned"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_bounded_honest_and_touching_nothing_it_does_not_own(tmp_path, files, argv, code,
                                                             words, owned):
    root = tmp_path / "user"
    root.mkdir()
    _populate(root, files)
    before = snapshot(tmp_path)
    start = time.monotonic()
    proc = _popen(argv, root)
    out, err = proc.communicate(timeout=600)
    took = time.monotonic() - start
    assert proc.returncode == code, (proc.returncode, err.decode(errors="replace")[-3000:])
    if words is None:
        assert err.decode(errors="replace").strip() == "", err
    else:  # one line, or as many warnings (each one line) as the case names
        warned = sum(word.startswith("motionhyst: warning: ") for word in words)
        line = _warnings(err, warned) if code == 0 and warned > 1 else _one_line(err)
        for word in words:  # "^..." : the message starts so
            if word.startswith("^"):
                assert line.startswith(f"motionhyst: error: {word[1:]}"), (word, line)
            else:
                assert word in line, (word, line)
        if code != 0:
            assert out == b""
            assert took < 60, took  # refused before the work, not after it
    after = snapshot(tmp_path)
    for name in owned:  # the command's own outputs: a regular file now, links replaced
        assert not (root / name).is_symlink() and (root / name).is_file()
        after.pop(f"user/{name}")
        before.pop(f"user/{name}", None)
    assert after == before  # nothing else changed, nothing added (no temporary file)


def test_a_dense_frf_is_fitted_to_a_thinned_set_of_its_lines():
    from motionhyst.plants.frf_fit import MAX_FIT_LINES, fit_frf

    f = np.linspace(1.0, 3000.0, 50_000)
    stage = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    fit = fit_frf(f, *stage.response(2 * np.pi * f))
    assert len(fit.frequency_hz) <= MAX_FIT_LINES
    assert "of the 50000 measured lines" in fit.criterion
    assert len(fit.plant.modes) == 1
    assert fit.plant.M == pytest.approx(22.5, rel=1e-6)
    assert fit.plant.modes[0].frequency_hz == pytest.approx(694.262, rel=1e-5)


def test_a_time_series_is_the_same_in_pieces_that_split_its_rows(monkeypatch):
    """A row of more integration steps than a piece holds: memory bounded, rows the same."""
    import io

    from motionhyst.scenario import default_scenario
    from motionhyst.time import timeseries
    from motionhyst.time.references import SineReference

    loop = default_scenario().loop()
    ref = SineReference(0.01, 50.0)

    def run():
        buf = io.StringIO()
        s = timeseries.run_time_series(loop, ref, 0.02, buf, output_rate_hz=500.0)
        return s, buf.getvalue()

    s_whole, whole = run()
    assert s_whole["steps"] // s_whole["samples"] > 7  # several steps per row
    monkeypatch.setattr(timeseries, "MAX_CHUNK", 7)  # pieces of 7 steps: rows split across
    _, split = run()
    assert split.splitlines()[0] == whole.splitlines()[0]
    a = np.loadtxt(whole.splitlines()[1:], delimiter=",")
    b = np.loadtxt(split.splitlines()[1:], delimiter=",")
    assert a.shape == b.shape == (s_whole["samples"], len(timeseries.COLUMNS))
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-15)


def _writing(proc: subprocess.Popen, path: Path, timeout: float = 60.0) -> None:
    """Wait until `proc` has started its run (its output file is open), or fail."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"ended early: {proc.stderr.read().decode(errors='replace')}")
        fds = Path(f"/proc/{proc.pid}/fd")
        try:
            if any("(deleted)" in os.readlink(fd) or str(path.parent) in os.readlink(fd)
                   for fd in fds.iterdir()):
                return
        except OSError:
            pass
        time.sleep(0.05)
    pytest.fail("the run did not start writing")


LONG_RUN = ["simulate", "--time-series", "old.csv", "--frequency", "5", "--duration", "60",
            "--force"]


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_interrupted_or_killed_mid_write_leaves_the_old_file_and_nothing_else(tmp_path, sig):
    root = tmp_path / "user"
    root.mkdir()
    _populate(root, {})
    before = snapshot(tmp_path)
    proc = _popen(LONG_RUN, root)
    _writing(proc, root / "old.csv")
    time.sleep(0.5)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    if sig == signal.SIGINT:
        assert proc.returncode == 130
        assert _one_line(err) == "motionhyst: interrupted"
    else:
        assert proc.returncode == -signal.SIGKILL
    assert snapshot(tmp_path) == before  # the old file, and no temporary file


@pytest.mark.parametrize("argv", [["analyze", "bad.toml"], ["steady", "huge.toml"],
                                  ["scan", "bad.toml", "--length", "0.01", "--speed", "0.1",
                                   "--a-max", "10", "--j-max", "1000", "--s-max", "1e6"],
                                  ["study", "bad.toml", "--out", "s.zarr"],
                                  ["reproduce", "huge.toml"]])
def test_a_refused_input_is_refused_before_the_analysis_loads(tmp_path, argv):
    """A scenario or study that cannot be read is refused before python-control, scipy.signal
    and numba are imported (they take seconds to load on a busy machine; the refusal does not
    wait for them)."""
    (tmp_path / "bad.toml").write_text("x\n")
    (tmp_path / "huge.toml").write_text(PAPER.replace("m2 = 17.5 ", "m2 = 1e300 "))
    code = ("import sys\nfrom motionhyst.cli import main\n"
            f"code = main({argv!r})\n"
            "print(code, sorted({'control', 'scipy.signal', 'numba'} & set(sys.modules)))\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert proc.stdout.splitlines()[-1] == "2 []", proc.stdout + proc.stderr


@pytest.mark.parametrize("became", [SystemError, ImportError, TypeError, ValueError])
def test_a_ctrl_c_that_became_another_error_is_still_an_interrupt(monkeypatch, capsys, became):
    """A Ctrl-C inside the import of a compiled extension, a numba compilation or a C callback
    comes out as another exception whose context is the KeyboardInterrupt (under load the
    interrupt of the test above landed in one: exit 1, "internal error"): exit 130."""
    from motionhyst.cli import df

    def run(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise became("initialization of _extension raised unreported exception") from None

    monkeypatch.setattr(df, "run", run)
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 130
    assert _one_line(capsys.readouterr().err.encode()) == "motionhyst: interrupted"


def test_an_error_without_a_ctrl_c_is_not_an_interrupt(monkeypatch, capsys):
    from motionhyst.cli import df

    def run(args):
        raise SystemError("a defect")

    monkeypatch.setattr(df, "run", run)
    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01"]) == 1
    assert "internal error: SystemError: a defect" in capsys.readouterr().err


def test_the_command_ignores_a_late_ctrl_c_so_that_its_exit_is_not_interrupted(tmp_path):
    """Once the work is done (files in place), a Ctrl-C during the interpreter's exit would
    print tracebacks of its finalisers after exit code 0: the command ignores it by then."""
    code = ("import signal, sys\n"
            "from motionhyst.cli import main\n"
            "sys.argv = ['motionhyst', 'df', '--k', '20', '--fc', '0.05', '--amplitude', "
            "'0.01']\n"
            "code = main()\n"
            "print(code, signal.getsignal(signal.SIGINT) is signal.SIG_IGN)\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert proc.stdout.splitlines()[-1] == "0 True", proc.stdout + proc.stderr


def test_a_scratch_folder_of_a_killed_process_is_removed_by_the_next(tmp_path, monkeypatch):
    import tempfile

    from motionhyst.io.outputs import scratch_folder

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    left = tmp_path / f"motionhyst-figures-{dead.pid}-ab_12"  # killed before its cleanup
    (left / "fig5.png").parent.mkdir()
    (left / "fig5.png").write_bytes(b"png")
    other = tmp_path / "motionhyst-figures-notes"  # not a name it gives: kept
    other.mkdir()
    with scratch_folder("motionhyst-figures") as name:
        assert Path(name).parent == tmp_path
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted([other.name,
                                                                     Path(name).name])
    assert [p.name for p in tmp_path.iterdir()] == [other.name]


def test_a_defect_is_one_line_and_exit_1_and_its_traceback_on_request(tmp_path, monkeypatch,
                                                                       capsys):
    """No input should raise a TypeError inside the tool; if one does, the user still gets
    one line (and the developer the traceback with MOTIONHYST_TRACEBACK=1)."""
    from motionhyst.cli import EXIT_INTERNAL, TRACEBACK_VARIABLE, analyze, main

    def broken(args):
        raise TypeError("unsupported operand type(s) for +: 'int' and 'str'")

    monkeypatch.setattr(analyze, "run", broken)
    monkeypatch.delenv(TRACEBACK_VARIABLE, raising=False)
    assert main(["analyze"]) == EXIT_INTERNAL == 1
    line = _one_line(capsys.readouterr().err.encode())
    assert line.startswith("motionhyst: internal error: TypeError: unsupported operand")
    assert TRACEBACK_VARIABLE in line
    monkeypatch.setenv(TRACEBACK_VARIABLE, "1")
    with pytest.raises(TypeError):
        main(["analyze"])


def test_records_without_inertia_are_refused_before_any_fit(tmp_path, monkeypatch, capsys):
    """The inertia check comes before the search: none of the fits is reached."""
    from motionhyst.identify import input_output

    def reached(*args, **kwargs):
        raise AssertionError("the search started")

    for name in ("identify_elements_io", "identify_bouc_wen_msd", "identify_bouc_wen_two_mass"):
        monkeypatch.setattr(input_output, name, reached)
    (tmp_path / "piezo.csv").write_text(PIEZO)
    for plant, model in (("mass-spring-damper", "bouc-wen"), ("mass-damper", "jenkins"),
                         ("two-mass", "bouc-wen")):
        code = main(["identify", str(tmp_path / "piezo.csv"), "--record", "input-output",
                     "--plant", plant, "--model", model])
        assert code == 2
        assert "no inertia in the force" in _one_line(capsys.readouterr().err.encode())


@pytest.mark.parametrize("mass", [2.0, 0.05])
@pytest.mark.parametrize("periodic", [False, True])
def test_records_of_a_stage_pass_the_inertia_check(mass, periodic):
    """A stage's mass, 2 kg or 0.05 kg (its mode at 225 Hz, in the band of a record at
    750 Hz: a 10 ms filter loses its acceleration; the 5-sample one keeps it), passes."""
    from motionhyst.hysteresis import BoucWen
    from motionhyst.identify.io_checks import check_inertia
    from motionhyst.identify.io_records import IORecord
    from motionhyst.time.openloop import MassSpringDamper, OpenLoop

    n = 256
    rng = np.random.default_rng(1)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(2, 52)  # 5.9 to 150 Hz
    lines = lines[lines % 2 == 1] if periodic else lines
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    u *= 50.0 / np.std(u)
    t = np.arange(n) / 750.0
    system = OpenLoop(MassSpringDamper(mass, 10.0, 5e4), BoucWen(k=5e4, fc=20.0, beta=0.6,
                                                                   gamma=0.2))
    y = system.simulate(t, u, periodic=periodic).displacement
    y += 0.01 * np.std(y) * rng.standard_normal(n)
    check_inertia([IORecord(t, u, y)])
    with pytest.raises(ValueError, match="no inertia in the force"):
        check_inertia([IORecord(t, u, u / 5e4)])  # the spring alone
