"""The dask engine of studies on a real cluster: a scheduler and two workers started as
separate processes on localhost, the same numbers as the local pool, a worker killed
mid-study."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path
from motionhyst.study import Study, open_results, run_study
from motionhyst.study.engine import DASK_CLUSTER_CONFIG, dask_environment

distributed = pytest.importorskip("distributed")

STUDY_TOML = """\
scenario = "paper.toml"
outputs = ["e1", "error_peak"]
[axes]
amplitude = [0.001, 0.01]
frequency_hz = { geomspace = [2.0, 50.0, 20] }
[samples]
n = 6
seed = 3
"hysteresis.k" = { lognormal = [20.0, 0.1] }
"hysteresis.fc" = { uniform = [0.03, 0.05] }
"""
POINTS = 240


def _start(args: list[str], log: Path, env: dict[str, str]) -> subprocess.Popen:
    with open(log, "w") as fh:
        return subprocess.Popen([sys.executable, "-m", "dask", *args], stdout=fh,
                                stderr=subprocess.STDOUT, start_new_session=True, env=env)


@contextlib.contextmanager
def _cluster(folder: Path, settings: dict[str, str]):
    """``dask scheduler`` and two ``dask worker`` processes (one thread each, no nanny: a
    killed worker stays dead) on 127.0.0.1, dask's configuration `settings` in their
    environment; the client and the workers' processes."""
    env = {**{k: v for k, v in os.environ.items() if not k.startswith("DASK_")}, **settings}
    sched_file = folder / "scheduler.json"
    procs = [_start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                     "--scheduler-file", str(sched_file)], folder / "scheduler.log", env)]
    try:
        deadline = time.monotonic() + 120
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert sched_file.exists(), (folder / "scheduler.log").read_text()
        for i in range(2):
            procs.append(_start(["worker", "--scheduler-file", str(sched_file), "--nthreads",
                                 "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1",
                                 "--local-directory", str(folder / f"worker{i}")],
                                folder / f"worker{i}.log", env))
        client = distributed.Client(scheduler_file=str(sched_file), timeout="60s")
        try:
            client.wait_for_workers(2, timeout=120)
            yield client, procs[1:]
        finally:
            client.close()
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


@pytest.fixture
def cluster(tmp_path):
    """A cluster with dask's defaults (as ``dask scheduler`` and ``dask worker`` start)."""
    with _cluster(tmp_path, {}) as out:
        yield out


@pytest.fixture
def study_cluster(tmp_path):
    """A cluster started with the settings for studies (the README's and the guide's)."""
    with _cluster(tmp_path, dask_environment()) as out:
        yield out


@pytest.fixture
def study_file(tmp_path: Path) -> Path:
    shutil.copy(default_scenario_path(), tmp_path / "paper.toml")
    path = tmp_path / "study.toml"
    path.write_text(STUDY_TOML)
    return path


def _killing_first_holder(run_batches, client, workers: list[subprocess.Popen], killed: dict):
    """`run_batches` that, when the first batch has come back and before the runner sees it,
    SIGKILLs the worker holding the most of the study's batches (computed and not yet
    collected, or being computed, as the scheduler sees them): the study is mid-way by
    construction, whatever the load; `killed` says how many it held and how it ended."""
    pids = {p.pid: p for p in workers}

    def wrapped(*args, **kwargs):
        results = run_batches(*args, **kwargs)
        try:
            first = next(results)
            held = {addr: len(keys) for addr, keys in client.has_what().items()}
            for addr, keys in client.processing().items():
                held[addr] = held.get(addr, 0) + len(keys)
            addr = max(held, key=held.get)
            proc = pids[client.run(os.getpid, workers=[addr])[addr]]
            os.kill(proc.pid, signal.SIGKILL)
            killed.update(held=held[addr], code=proc.wait(timeout=30), left=len(held) - 1)
            yield first
            yield from results
        finally:
            results.close()

    return wrapped


def test_cluster_gives_the_local_pools_numbers_with_a_worker_killed(cluster, tmp_path,
                                                                    study_file, monkeypatch):
    from motionhyst.study import runner

    client, workers = cluster
    st = Study.from_file(study_file)
    assert st.n_points == POINTS
    run_study(st, tmp_path / "local.zarr", workers=2, batch=4)
    local = open_results(tmp_path / "local.zarr")

    # batches of one point; a worker killed (SIGKILL) from the runner's loop when the first
    # batch came back: what it held is lost and computed again by the other
    killed: dict = {}
    monkeypatch.setattr(runner, "run_batches",
                        _killing_first_holder(runner.run_batches, client, workers, killed))
    out = tmp_path / "dask.zarr"
    report = run_study(st, out, client=client, batch=1)
    monkeypatch.undo()
    assert killed["code"] == -signal.SIGKILL and killed["left"] == 1, killed
    # the first batch (collected) and at least one more, lost with the worker
    assert killed["held"] >= 2, killed
    assert len(client.scheduler_info()["workers"]) == 1
    assert (report.points, report.computed, report.failed) == (POINTS, POINTS, 0)
    remote = open_results(out)
    for name in ("e1", "error_peak", "status", "hysteresis.k", "hysteresis.fc"):
        np.testing.assert_array_equal(local[name].values, remote[name].values, err_msg=name)

    # the command line on the same (now one-worker) cluster, by its address
    address = client.scheduler.address
    store = tmp_path / "cli.zarr"
    assert main(["study", str(study_file), "--out", str(store), "--scheduler", address,
                 "--json"]) == 0
    cli = open_results(store)
    np.testing.assert_array_equal(local["e1"].values, cli["e1"].values)


def test_unreachable_scheduler_is_one_line(tmp_path, study_file, capsys):
    assert main(["study", str(study_file), "--out", str(tmp_path / "s.zarr"), "--scheduler",
                 "tcp://127.0.0.1:1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot connect" in err, err
    assert not (tmp_path / "s.zarr").exists()


def _settings(dask_worker) -> dict:
    """The settings of DASK_CLUSTER_CONFIG as this dask process runs with them, and what its
    timers do with them (``client.run`` and ``run_on_scheduler`` pass the process's server
    as `dask_worker`)."""
    import dask.config

    from motionhyst.study.engine import DASK_CLUSTER_CONFIG

    out = {key: dask.config.get(key) for key in DASK_CLUSTER_CONFIG}
    timers = dask_worker.periodic_callbacks
    return {**out, "profiler": "profile" in timers and timers["profile"].is_running(),
            **{f"{name}_ms": timers[name].callback_time for name in
               ("tick", "monitor", "memory_monitor") if name in timers}}


def _settings_of(client) -> list[dict]:
    """:func:`_settings` of the scheduler, then of each worker."""
    import cloudpickle

    # _settings goes by value: the workers cannot import this test module
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    try:
        return [client.run_on_scheduler(_settings), *client.run(_settings).values()]
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


def test_the_cluster_for_studies_runs_with_its_settings(study_cluster):
    """The environment of ``dask_environment()`` (the README's and the guide's) starts dask's
    processes with DASK_CLUSTER_CONFIG: a misspelt variable would leave dask's default."""
    client, _ = study_cluster
    everyone = _settings_of(client)
    assert len(everyone) == 3
    for got in everyone:
        assert got.pop("memory_monitor_ms", None) == (None if got is everyone[0] else 1000)
        assert got == {**DASK_CLUSTER_CONFIG, "profiler": False, "tick_ms": 1000,
                       "monitor_ms": 5000}


def test_a_study_quiets_a_default_clusters_diagnostics_while_it_runs(cluster):
    """On a cluster started with dask's defaults the study's run sets the timers of dask's
    diagnostics to the pace of DASK_CLUSTER_CONFIG (the workers' profiler stopped) and, when
    it ends, back to each process's configuration."""
    from motionhyst.study.engine import run_batches

    client, _ = cluster
    st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0, 20.0]}},
                         scenario=tomllib.loads(default_scenario_path().read_text()))
    defaults = {"distributed.admin.tick.interval": "20ms",
                "distributed.worker.profile.enabled": True,
                "distributed.worker.memory.monitor-interval": "100ms",
                "distributed.admin.system-monitor.interval": "500ms"}
    before = _settings_of(client)
    results = run_batches(st, [[0], [1], [2]], client=client)
    try:
        next(results)
        during = _settings_of(client)
    finally:
        results.close()
    after = _settings_of(client)
    assert before == after
    for when, got in ((before, {"tick_ms": 20, "monitor_ms": 500, "memory_monitor_ms": 100,
                                "profiler": True}),
                      (during, {"tick_ms": 1000, "monitor_ms": 5000, "memory_monitor_ms": 1000,
                                "profiler": False})):
        assert when[0] == {**defaults, "tick_ms": got["tick_ms"],
                           "monitor_ms": got["monitor_ms"], "profiler": False}
        for worker in when[1:]:
            assert worker == {**defaults, **got}
