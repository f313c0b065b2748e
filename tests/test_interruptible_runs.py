"""A signal ends a long run at once (issue 26: Ctrl-C or SIGTERM at any moment exits 130, the
old files intact): the compiled step loop runs in calls of bounded work, between which the
signal is taken, with the numbers of one call; and a signal that finds numba boxing a
kernel's results while an output file is written is raised once the kernel has returned
(main: the file writer's handler raised it there, and numba's broken tuple ended the run in a
segmentation fault, exit -11).
"""

from __future__ import annotations

import signal
import time
from pathlib import Path

import limited_process
import numpy as np
import pytest
from file_trees import populate, snapshot

from motionhyst.time import engine

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _sampled_run():
    """The paper's loop at 10 kHz (its force 1.5 samples late: periods of two step kinds)."""
    from motionhyst.scenario import load_scenario
    from motionhyst.time.references import SineReference
    from motionhyst.time.sampled import simulate_sampled

    loop = load_scenario(EXAMPLES / "paper_10khz.toml").loop()
    sim = simulate_sampled(loop, SineReference(0.01, 5.0), 0.05, linear=False)
    return sim.e, sim.u, sim.w, sim.y1


def _closed_loop_run():
    """Table I's continuous loop (the closed-loop convention, exogenous outputs)."""
    from motionhyst.scenario import default_scenario_path, load_scenario
    from motionhyst.time.references import SineReference
    from motionhyst.time.simulation import simulate

    loop = load_scenario(default_scenario_path()).loop()
    sim = simulate(loop, SineReference(0.01, 5.0), 0.1)
    return sim.e, sim.w, sim.u


def _sensitivities_run():
    """A Jenkins link on a mass-spring-damper with the sensitivities identify's search uses."""
    from motionhyst.hysteresis import Jenkins
    from motionhyst.hysteresis.stepping import N_PARAMS
    from motionhyst.time.openloop import MassSpringDamper, simulate_elements

    t = np.arange(1500) / 750.0
    u = 40 * np.sin(2 * np.pi * 8 * t)
    dparams = np.zeros((1, N_PARAMS, 2))
    dparams[0, 0, 0] = dparams[0, 1, 1] = 1.0
    return simulate_elements(MassSpringDamper(2.0, 10.0, 5e4).mechanics(),
                             Jenkins(k=2e4, fc=10.0).time_stepping(), u, 750.0, 40,
                             periodic=False, dparams=dparams)


def _calls(monkeypatch) -> list[int]:
    """The steps of each call of the compiled step loop from now on."""
    calls: list[int] = []
    kernel = engine.step_loop

    def counted(*args):
        calls.append(args[11].shape[0] - 1)  # the force nodes `a`: steps + 1
        return kernel(*args)

    monkeypatch.setattr(engine, "step_loop", counted)
    return calls


@pytest.mark.parametrize("run", [_sampled_run, _closed_loop_run, _sensitivities_run],
                         ids=["sampled", "closed-loop", "sensitivities"])
def test_a_run_in_calls_of_bounded_work_gives_the_numbers_of_one_call(monkeypatch, run):
    """Cut at every record and controller period it can be (main: the whole run in one call,
    20 s and more for a link of 100 elements, deaf to signals), the run gives one call's
    numbers bit for bit."""
    calls = _calls(monkeypatch)
    monkeypatch.setattr(engine, "CALL_SECONDS", 1e9)
    whole = run()
    assert calls and max(calls) > 1000  # the case has long calls to cut
    one_call = len(calls)
    monkeypatch.setattr(engine, "CALL_SECONDS", 1e-12)  # a call per record or period
    cut = run()
    assert len(calls) - one_call > 20 * one_call
    for a, b in zip(whole, cut, strict=True):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("elements", [0, 1, 100, 10_000])
@pytest.mark.parametrize("sensitivities", [0, 5])
@pytest.mark.parametrize("align", [1, 3, 40])
def test_a_call_runs_the_most_whole_periods_within_its_nominal_work(elements, sensitivities,
                                                                   align):
    """A call's steps are whole records and controller periods (`align`), as many as keep
    its nominal work within CALL_SECONDS (one period where a period is more)."""
    from motionhyst.time.steps import SECONDS_PER_ELEMENT_STEP, SECONDS_PER_STEP

    steps = engine.call_steps(elements, sensitivities, align)
    per_step = (SECONDS_PER_STEP + elements * SECONDS_PER_ELEMENT_STEP) * (1 + sensitivities)
    assert steps % align == 0 and steps >= align
    assert steps == align or steps * per_step <= engine.CALL_SECONDS
    assert (steps + align) * per_step > engine.CALL_SECONDS
    assert engine.CALL_SECONDS <= 0.1  # within the 2 s a signal may take on a loaded machine


def _many_elements(path: Path) -> None:
    """The paper's loop at 10 kHz with a Maxwell-slip link of 100 elements (each step 7 times
    dearer than Jenkins's): a run of 30 s takes about 15 s of CPU in the step loop."""
    text = (EXAMPLES / "paper_10khz.toml").read_text()
    jenkins = 'model = "jenkins"\nk = 20.0\nfc = 0.05'
    assert jenkins in text
    link = (f'model = "maxwell-slip"\nk = [{", ".join(["0.2"] * 100)}]\n'
            f'fc = [{", ".join(["0.0005"] * 100)}]')
    path.write_text(text.replace(jenkins, link))


def _cpu_seconds(pid: int) -> float:
    """User and system CPU time [s] process `pid` has used."""
    import os

    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
@pytest.mark.parametrize("name", ["SIGTERM", "SIGINT"])
def test_a_signal_during_a_sampled_time_series_is_exit_130_the_old_file_intact(tmp_path, name):
    """simulate --time-series of a sampled loop, signalled once its run is in the step loop
    (4 s of CPU after a run that compiled its kernels): main crashed (exit -11, 'Segmentation
    fault', by the file writer's handler raising inside numba's boxing of the results); now
    'motionhyst: interrupted', exit 130, the old file as it was and nothing else left."""
    populate(tmp_path, {"loop.toml": _many_elements, "o.csv": "old\n"})
    argv = ["simulate", "loop.toml", "--frequency", "5", "--time-series", "o.csv", "--force"]
    warm = limited_process.run(["simulate", "loop.toml", "--frequency", "5", "--duration",
                                "0.01", "--time-series", "w.csv"], tmp_path,
                               limit=limited_process.RUN_LIMIT)
    assert warm[0] == 0, warm
    (tmp_path / "w.csv").unlink()
    before = snapshot(tmp_path)
    with limited_process.ended(limited_process.popen(
            [*argv, "--duration", "30"], tmp_path, limit=limited_process.RUN_LIMIT)) as proc:
        while proc.poll() is None and _cpu_seconds(proc.pid) < 4.0:
            time.sleep(0.1)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(getattr(signal, name))
        out, err = proc.communicate(timeout=300)
    assert proc.returncode == 130, (proc.returncode, err[-2000:])
    assert err.decode() == "motionhyst: interrupted\n" and out == b""
    assert snapshot(tmp_path) == before



@pytest.mark.parametrize("link", ["maxwell-slip", "lugre"])
def test_a_link_s_force_record_in_calls_of_bounded_work_is_one_call_s(monkeypatch, link):
    """The link's force from a displacement record (predict's quasi-static runs, a loop's
    hysteresis feedforward) in calls of open_loop_chunk of at most CALL_ELEMENT_STEPS element
    steps (main: one call for the whole record, 17 s for 2e6 samples through 50 elements):
    the numbers of one call bit for bit, rate-dependent elements' first step included."""
    from motionhyst.hysteresis import LuGre, MaxwellSlip, stepping
    from motionhyst.plants import QuasiStatic
    from motionhyst.time import quasi_static

    model = (MaxwellSlip(k=[100.0] * 5, fc=[0.1, 0.2, 0.3, 0.4, 0.5]) if link == "maxwell-slip"
             else LuGre(sigma0=1e5, sigma1=300.0, sigma2=5.0, fc=1.0, fs=1.5, vs=0.01))
    t = np.arange(20_000) * 1e-4
    x = 0.01 * np.sin(2 * np.pi * 5 * t) + 0.002 * np.sin(2 * np.pi * 37 * t)
    calls: list[int] = []
    kernel = quasi_static.open_loop_calls.__globals__["open_loop_chunk"]

    def counted(*args):
        calls.append(args[5].size)
        return kernel(*args)

    monkeypatch.setattr(stepping, "open_loop_chunk", counted)
    monkeypatch.setattr(stepping, "CALL_ELEMENT_STEPS", 10**12)
    whole = quasi_static.force_from_displacement(QuasiStatic(k=1e3), model, t, x)
    assert calls == [t.size]
    monkeypatch.setattr(stepping, "CALL_ELEMENT_STEPS", 1_000)
    cut = quasi_static.force_from_displacement(QuasiStatic(k=1e3), model, t, x)
    m = len(model.time_stepping().codes)
    assert len(calls) > 10 and max(calls[1:]) == max(1, 1_000 // m)
    assert np.array_equal(whole, cut)
