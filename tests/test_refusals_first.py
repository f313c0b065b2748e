"""Refusals decided before the expensive work (issue 26: every refusal within 2 s of start).

Each case shows that the work a refusal used to wait for never starts: a fresh interpreter
(a subprocess) runs the command and reports the modules it imported, or the work is replaced
by one that fails the test if called.  Nothing here is timed (``benchmarks/refusals.py``
measures how soon each refusal comes, as ratios to the command's start).
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from cli_probe import probe


def _csv(columns: dict[str, np.ndarray]) -> str:
    """A CSV record with a header of the `columns`' names."""
    rows = np.column_stack(list(columns.values()))
    return ",".join(columns) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                              for row in rows)


def _axis(n: int = 600, fs: float = 1000.0) -> str:
    """An input-output record of a 2 kg positioning axis (no spring)."""
    t = np.arange(n) / fs
    force = 30 * np.sin(2 * np.pi * 0.5 * t) + 12 * np.sin(2 * np.pi * 2.3 * t + 0.4)
    y = np.cumsum(np.cumsum(force - force.mean())) / (2 * fs**2)
    return _csv({"time": t, "force": force, "displacement": y})


def test_a_link_model_input_output_records_cannot_fit_is_refused_before_they_are_read(
        tmp_path):
    """``--model maxwell-iwan --record input-output`` was refused after the records were
    read and checked (scipy loaded, the positioning axis's warning printed first: two
    lines).  The model's name alone decides it: one line, the record never opened."""
    (tmp_path / "a.csv").write_text(_axis())
    for record in ("a.csv", "missing.csv"):
        out = probe(["identify", record, "--record", "input-output", "--model",
                      "maxwell-iwan"], tmp_path)
        assert out["rc"] == 2, out["err"]
        assert out["err"].count("\n") == 1, out["err"]
        assert ("--model maxwell-iwan is not available for input-output records; use "
                "bouc-wen, jenkins, maxwell-slip, dahl, lugre, coulomb") in out["err"]
        assert out["packages"] == [], out["packages"]


def _spin(seconds: float) -> None:
    """Use `seconds` of this process's CPU time."""
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass


def test_a_work_budget_that_runs_out_in_a_c_callback_stops_the_work_without_a_traceback(
        capfd):
    """The CPU-time alarm raised where the interpreter was: in a callback from C (llvmlite's
    cache notice while numba compiled a kernel, on a cold cache) ctypes printed the
    exception with a traceback on stderr, ignored it, and the work went on past its budget
    to exit 0.  The alarm comes again until the work stops, its exception unseen."""
    import ctypes
    import ctypes.util

    from motionhyst.core.budget import BudgetError, cpu_time_limit

    libc = ctypes.CDLL(ctypes.util.find_library("c"))
    compare = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p)

    def slow_compare(a, b) -> int:  # the alarm comes in here, a callback from C
        _spin(0.3)
        return 0

    values = (ctypes.c_int * 2)(2, 1)
    after = []
    with pytest.raises(BudgetError, match=r"did not finish within the work budget of 0\.05 s"):
        with cpu_time_limit(0.05, "a sort"):
            libc.qsort(values, 2, ctypes.sizeof(ctypes.c_int), compare(slow_compare))
            after.append(time.process_time())
            _spin(5.0)  # the old alarm never came back: the work ran on to its end
            after.append("ended")
    assert after and after[-1] != "ended"
    err = capfd.readouterr().err
    assert "Traceback" not in err and "_TimeUp" not in err and "ignored" not in err, err


def test_a_work_budget_that_runs_out_while_the_compiler_runs_stops_once_it_returns():
    """In numba's own code (compiling a kernel, boxing its results) the alarm's exception
    would leave the compiler's state broken: it is raised once that code has returned."""
    from motionhyst.core.budget import BudgetError, cpu_time_limit

    compiler = {"__name__": "numba.core.compiler", "clock": time.process_time}
    exec("def compile_kernel():\n"  # its own loop: the alarm comes in the compiler's frame
         "    start = clock()\n"
         "    while clock() - start < 0.3:\n"
         "        pass\n"
         "    return 'compiled'\n", compiler)
    done = []
    with pytest.raises(BudgetError):
        with cpu_time_limit(0.05, "a compilation"):
            done.append(compiler["compile_kernel"]())  # not interrupted inside
            _spin(5.0)
            done.append("ended")
    assert done == ["compiled"]


def _paper_with(link: str, *changes: tuple[str, str]) -> str:
    """The paper's scenario with its Jenkins link replaced by `link` (and `changes`)."""
    from motionhyst.scenario import default_scenario_path

    text = default_scenario_path().read_text()
    jenkins = ('model = "jenkins"\nk = 20.0              # spring stiffness k_J [N/m]\n'
               'fc = 0.05             # slip force f_c [N]')
    assert jenkins in text
    text = text.replace(jenkins, link)
    for old, new in changes:
        assert old in text
        text = text.replace(old, new)
    return text


def _lugre(sigma1: float) -> str:
    return f'model = "lugre"\nsigma0 = 20.0\nsigma1 = {sigma1!r}\nfc = 0.05\nfs = 0.07\nvs = 0.1'


@pytest.mark.parametrize("argv", [
    ["scan", "s.toml", "--length", "0.01", "--speed", "0.1", "--a-max", "10", "--j-max", "1000",
     "--s-max", "1e6", "--compensation", "none"],
    ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--duration", "0.2"],
])
def test_a_link_too_damped_for_the_step_is_refused_before_the_loop_is_built(tmp_path, argv):
    """A LuGre link of sigma1 = 1e7 N s/m on the paper's stage was refused when the run's
    implicit step failed at the stage's first motion, after python-control built the loop
    and numba loaded the kernels.  The scenario and the step, known before, decide it."""
    (tmp_path / "s.toml").write_text(_paper_with(_lugre(1e7)))
    out = probe(argv, tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert "s.toml: [hysteresis]: the link's damping for small motions, 1e+07 N s/m" in out["err"]
    assert out["packages"] == [], out["packages"]
    assert not (tmp_path / "ts.csv").exists()


@pytest.mark.parametrize(("m1", "frequency_hz"), [(5.0, 5.0), (2.0, 5.0), (20.0, 50.0)])
def test_a_link_refused_for_its_damping_is_one_whose_run_fails(tmp_path, m1, frequency_hz):
    """The nearest damping :func:`check_link_damping` refuses (its factor 5 % above the
    margin) is one whose run's implicit step does fail: the check refuses no run that would
    converge; just below the margin it leaves the run to judge (which, measured, fails from
    a factor of 0.6 on)."""
    from motionhyst import Loop, SineReference, simulate
    from motionhyst.hysteresis import LuGre
    from motionhyst.scenario import load_scenario
    from motionhyst.time.kernel import StepNotConverged
    from motionhyst.time.steps import IMPLICIT_STEP_MARGIN, check_link_damping, pole_step

    (tmp_path / "s.toml").write_text(_paper_with(_lugre(1.0), ("m1 = 5.0", f"m1 = {m1}")))
    sc = load_scenario(tmp_path / "s.toml")
    step = pole_step(sc.fastest_pole(), frequency_hz)
    at_margin = IMPLICIT_STEP_MARGIN * 4 * m1 / step  # c step / (4 m) = the margin

    def lugre(c: float) -> LuGre:
        return LuGre(sigma0=20.0, sigma1=c, sigma2=0.0, fc=0.05, fs=0.07, vs=0.1)

    check_link_damping(lugre(0.95 * at_margin), sc.plant(), step)
    with pytest.raises(ValueError, match="is too strong for the time step"):
        check_link_damping(lugre(1.05 * at_margin), sc.plant(), step)
    loop = Loop(sc.plant(), sc.controller(), lugre(1.05 * at_margin))
    with pytest.raises(StepNotConverged):
        simulate(loop, SineReference(0.01, frequency_hz), 0.02, dt=step)


@pytest.fixture(scope="module")
def loop_record() -> dict[str, np.ndarray]:
    """A closed-loop record of the paper's loop with a two-element link (3 s of a 2 Hz
    sine, 5 kHz)."""
    from motionhyst import Loop, MaxwellSlip, SineReference, default_scenario, simulate

    sc = default_scenario()
    loop = Loop(sc.plant(), sc.controller(), MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]))
    sim = simulate(loop, SineReference(0.01, 2.0), 3.0, dt=2e-4)
    return {"time": sim.t, "y1": sim.y1, "u": sim.u}


@pytest.mark.parametrize(("mistake", "ratio"), [("y1 in mm", "1000"), ("u in kN", "1000"),
                                                ("columns swapped", "1.3e+07")])
def test_a_closed_loop_record_off_its_plant_s_scale_is_refused_before_the_loop_is_built(
        tmp_path, loop_record, mistake, ratio):
    """y1 in mm, u in kN or the two columns swapped: the plant's force for y1 is a
    thousandfold u or more.  Refused "no hysteresis" after the loop was built
    (python-control) and the fit ran (2.2-2.4 s of CPU); now from the scenario's plant
    before either."""
    from motionhyst.scenario import default_scenario_path

    record = dict(loop_record)
    if mistake == "y1 in mm":
        record["y1"] = 1000 * record["y1"]
    elif mistake == "u in kN":
        record["u"] = record["u"] / 1000
    else:
        record["y1"], record["u"] = record["u"], record["y1"]
    (tmp_path / "c.csv").write_text(_csv(record))
    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    out = probe(["identify", "c.csv", "--scenario", "paper.toml"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert f"c.csv: the plant's force for y1 as recorded is {ratio} times u" in out["err"]
    assert "control" not in out["packages"] and "matplotlib" not in out["packages"], out["packages"]


def test_the_force_scale_of_a_record_of_its_plant_is_near_one(loop_record):
    """The record the paper's loop makes, its link's force included: the plant's force for
    y1 is u's to 10 % (measured 1.029: refused with u a hundredth, not with u a 91st), a
    hundredth of the refusal's ratio, with or without noise of a micron on y1."""
    from motionhyst import default_scenario
    from motionhyst.identify.records import SCALE_RATIO, check_force_scale

    mech = default_scenario().plant().mechanics()
    t, y1, u = loop_record["time"], loop_record["y1"], loop_record["u"]
    noisy = y1 + 1e-6 * np.random.default_rng(3).standard_normal(y1.size)
    for y in (y1, noisy):
        check_force_scale(t, y, u, mech, 43.3)
        check_force_scale(t, y, u * 1.1 / SCALE_RATIO, mech, 43.3)  # the ratio below 1.1
        with pytest.raises(ValueError, match="is 100 times u"):    # and at least 1
            check_force_scale(t, y, u / SCALE_RATIO, mech, 43.3)


@pytest.mark.parametrize("rows", [6000, 200_000])
def test_a_small_regression_runs_on_one_blas_thread_a_large_one_on_the_machine_s(
        monkeypatch, rows):
    """The inertia check's regression (6000 x 36) ran on the machine's BLAS threads: on a
    loaded machine 0.94 s of wall time a call for 0.31 s of CPU (one thread: 0.07 s and
    0.03 s).  A small one now runs on one; a large one (200000 x 36) keeps the threads."""
    from threadpoolctl import threadpool_info

    from motionhyst.core.blas import SMALL_FLOPS
    from motionhyst.identify.io_checks import robust_least_squares

    def blas_threads() -> list[int]:
        return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]

    machine = blas_threads()
    seen = []
    lstsq = np.linalg.lstsq

    def counting(*args, **kwargs):
        seen.append(blas_threads())
        return lstsq(*args, **kwargs)

    monkeypatch.setattr(np.linalg, "lstsq", counting)
    A = np.random.default_rng(0).standard_normal((rows, 36))
    x, _ = robust_least_squares([A], [A @ np.arange(36.0)], 7)
    assert np.allclose(x, np.arange(36.0))
    small = rows * 36**2 <= SMALL_FLOPS
    assert seen == [[1] * len(machine) if small else machine], (seen, machine)
    assert blas_threads() == machine  # the limit was the regression's only


def test_a_measured_plant_s_fit_runs_on_one_blas_thread(monkeypatch):
    """A measured plant's fit (60 lines, a rigid body and a mode) spent its time in the
    SVDs of its small Jacobians on the machine's BLAS threads: ``analyze`` of a noisy
    FRF refused (the fitted loop unstable) after 11-15 s of wall time, 2.7-3.6 s of CPU
    (2 cores, load 19); 8-9 s and 1.7-1.9 s on one thread.  Each of its searches runs on
    one thread now, and the fit is the same."""
    from threadpoolctl import threadpool_info

    from motionhyst import ModalPlant, TwoMassStage
    from motionhyst.plants import frf_fit

    machine = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    seen = []
    least_squares = frf_fit.least_squares

    def counting(*args, **kwargs):
        seen.append([i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"])
        return least_squares(*args, **kwargs)

    monkeypatch.setattr(frf_fit, "least_squares", counting)
    exact = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    f = np.geomspace(1.0, 3000.0, 60)
    fit = frf_fit.fit_frf(f, *exact.response(2 * np.pi * f))
    assert len(fit.plant.modes) == 1 and abs(fit.plant.M - 22.5) < 1e-6
    assert abs(fit.plant.modes[0].frequency_hz - 694.262) < 1e-3
    assert seen and all(threads == [1] * len(machine) for threads in seen), (seen, machine)


def test_the_light_checks_of_a_force_displacement_record_run_on_one_blas_thread(monkeypatch):
    """check_loops_open's fits (60000 x 2 to 60000 x 5 for a long record) ran on the
    machine's BLAS threads: 0.70 s of wall time for its three at load 20."""
    from threadpoolctl import threadpool_info

    from motionhyst.identify.records import check_loops_open

    machine = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    seen = []
    lstsq = np.linalg.lstsq

    def counting(*args, **kwargs):
        seen.append([i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"])
        return lstsq(*args, **kwargs)

    monkeypatch.setattr(np.linalg, "lstsq", counting)
    t = np.arange(60_000) / 750
    x = 1e-3 * np.sin(2 * np.pi * 2 * t)
    with pytest.raises(ValueError, match="a spring's and a damper's"):
        check_loops_open(x, 20.0 * x + 0.5 * np.gradient(x, t), t)
    assert len(seen) == 3 and all(threads == [1] * len(machine) for threads in seen), seen


@pytest.mark.parametrize(("options", "words"), [
    # (its reading: 12 MB, csvdata.reading_bytes; under 8M that is refused first)
    (["--max-memory", "20M"], "c.csv: the Maxwell-slip fit of a closed-loop record of 15001 "
                              "samples needs"),
    (["--cutoff", "1e9"], "c.csv: cutoff_hz must be in (0, 2500) Hz"),
    (["--cutoff", "1e-3"], "c.csv: too short: the prefilter settles"),
])
def test_a_closed_loop_record_s_size_and_cut_off_are_judged_before_the_fit_loads(
        tmp_path, loop_record, options, words):
    """The memory check of a closed-loop fit read the fit's row limit from the fit module,
    which loads scipy.optimize and the link models (about 1 s of the 1.2 s of CPU of such a
    refusal): the size and the prefilter's cut-off are now judged with the record's reader
    alone (pandas, which parsed it)."""
    from motionhyst.scenario import default_scenario_path

    (tmp_path / "c.csv").write_text(_csv(loop_record))
    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    out = probe(["identify", "c.csv", "--scenario", "paper.toml", *options], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert words in out["err"], out["err"]
    assert out["packages"] == ["pandas"], out["packages"]


def test_a_closed_loop_record_off_its_plant_s_scale_is_refused_with_the_reader_alone(
        tmp_path, loop_record):
    """y1 in mm, its prefilter's cut-off from its reversals: the count of reversals was a
    compiled kernel (numba and its cache: 1.40 s of CPU for the refusal, with the fit
    module's scipy.optimize); now numpy and a walk over the turns (0.64 s): nothing heavy
    is loaded but the reader's pandas."""
    from motionhyst.scenario import default_scenario_path

    record = dict(loop_record)
    record["y1"] = 1000 * record["y1"]
    (tmp_path / "c.csv").write_text(_csv(record))
    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    out = probe(["identify", "c.csv", "--scenario", "paper.toml"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert "c.csv: the plant's force for y1 as recorded is 1000 times u" in out["err"]
    assert out["packages"] == ["pandas"], out["packages"]


@pytest.fixture(scope="module")
def loop_record_5hz() -> dict[str, np.ndarray]:
    """The paper's loop (Table I) recorded 1 s at 10 kHz on a 5 Hz sine of 10 mm."""
    from motionhyst import Jenkins, Loop, SineReference, default_scenario, simulate

    sc = default_scenario()
    sim = simulate(Loop(sc.plant(), sc.controller(), Jenkins(k=20.0, fc=0.05)),
                   SineReference(0.01, 5.0), 1.0, dt=1e-4)
    return {"time": sim.t, "y1": sim.y1, "u": sim.u}


@pytest.mark.parametrize(("mistake", "words"), [
    ("a spring and a damper", "c.csv: no hysteresis in the record: the link force inferred "
                              "through the plant is a spring's and a damper's"),
    ("u negated", "with u negated the record is a link's: --scale u=-1 reads it so"),
    ("y1 a sample ahead", "shifted by 1 sample (y1's row i beside u's row i + 1)"),
])
def test_a_closed_loop_record_that_is_no_link_s_is_refused_before_the_loop_is_built(
        tmp_path, loop_record_5hz, mistake, words):
    """A closed-loop record whose inferred force is no link's was refused once the loop was
    built (python-control, scipy.signal, the compiled filters: a made-up spring and damper
    2.0-2.3 s of CPU, the paper's loop with u negated 1.8-1.9 s); the same checks now run on
    the same force inferred with numpy from the plant's lumped masses, before the loop:
    none of the loop's or the fit's libraries is loaded (0.5-0.6 s of CPU)."""
    from motionhyst.scenario import default_scenario_path

    record = dict(loop_record_5hz)
    t = record["time"]
    if mistake == "a spring and a damper":
        record["y1"] = 0.01 * np.sin(2 * np.pi * 2.0 * t)
        record["u"] = 50.0 * np.sin(2 * np.pi * 2.0 * t + 0.2)
    elif mistake == "u negated":
        record["u"] = -record["u"]
    else:
        record = {"time": t[:-1], "y1": record["y1"][1:], "u": record["u"][:-1]}
    (tmp_path / "c.csv").write_text(_csv(record))
    (tmp_path / "paper.toml").write_text(default_scenario_path().read_text())
    out = probe(["identify", "c.csv", "--scenario", "paper.toml"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert words in out["err"], out["err"]
    loaded = [m for m in out["heavy"] if m.startswith(("control", "scipy.signal",
                                                          "scipy.optimize", "numba",
                                                          "matplotlib"))]
    assert loaded == [], loaded


def _damper(force_sign: float = 1.0, noise_only: bool = False) -> str:
    """A force-displacement record of 6000 samples at 1 kHz: a Jenkins element with a spring
    under a sine, its force reversed by `force_sign`, or white noise for a force."""
    from motionhyst.hysteresis import Jenkins

    t = np.arange(6000) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * 2.0 * t) * (0.6 + 0.4 * np.cos(2 * np.pi * 0.1 * t))
    w = (np.random.default_rng(5).standard_normal(t.size) if noise_only
         else force_sign * (Jenkins(k=40.0, fc=0.01).response(x) + 10.0 * x))
    return _csv({"time": t, "displacement": x, "force": w})


@pytest.mark.parametrize(("force_sign", "noise_only", "words"), [
    (-1.0, False, "rev.csv: no hysteresis found: the force falls as the displacement rises (is "
                  "one sensor's sign reversed? --scale force=-1)"),
    (1.0, True, "rev.csv: no hysteresis in the record: its force does not follow the "
                "displacement (a spring, a damper and a friction force explain ")],
    ids=["load-cell-reversed", "force-of-white-noise"])
def test_a_force_that_does_not_follow_the_displacement_is_refused_before_the_mass_check(
        tmp_path, force_sign, noise_only, words):
    """A force-displacement record with its load cell reversed, or whose force is white
    noise: refused after the mass check's stop operators (numba) and the fit's first stage
    (scipy), 1.3-1.6 s of CPU (review of issue 26); now from a least squares of the force on
    a spring, a damper and a friction force, before either loads.  The record itself
    (``--scale force=-1``) is identified."""
    (tmp_path / "rev.csv").write_text(_damper(force_sign, noise_only))
    out = probe(["identify", "rev.csv"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert out["err"].startswith(f"motionhyst: error: {words}"), out["err"]
    assert "numba" not in out["packages"] and "scipy" not in out["packages"], out["packages"]
    if not noise_only:
        fixed = probe(["identify", "rev.csv", "--scale", "force=-1"], tmp_path)
        assert fixed["rc"] == 0, fixed["err"]


@pytest.mark.parametrize("model", ["jenkins", "maxwell-slip", "bouc-wen", "dahl", "lugre",
                                   "maxwell-iwan", "coulomb"])
@pytest.mark.parametrize(("force_sign", "noise_only", "words"), [
    (-1.0, False, "rev.csv: no hysteresis found: the force falls as the displacement rises (is "
                  "one sensor's sign reversed? --scale force=-1)"),
    (1.0, True, "rev.csv: no hysteresis in the record: its force does not follow the "
                "displacement (a spring, a damper and a friction force explain ")],
    ids=["load-cell-reversed", "force-of-white-noise"])
def test_every_link_model_refuses_a_force_that_does_not_follow_before_its_fit(
        tmp_path, model, force_sign, noise_only, words):
    """The same records with ``--model``: the link's fit of a force of white noise refused
    after its start, "the records show no stiffness", and a reversed load cell as "the
    position falls as the force rises", after the fit's libraries loaded (scipy.optimize:
    0.8-1.1 s of CPU); now the check the elements' fit runs, before any of them."""
    (tmp_path / "rev.csv").write_text(_damper(force_sign, noise_only))
    out = probe(["identify", "rev.csv", "--model", model], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert out["err"].startswith(f"motionhyst: error: {words}"), out["err"]
    assert "numba" not in out["packages"] and "scipy" not in out["packages"], out["packages"]
