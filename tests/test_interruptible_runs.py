"""A signal ends a long run as a signal (issue 26: Ctrl-C or SIGTERM at any moment exits 130,
the old files intact): one that finds numba boxing a kernel's results while an output file
is written is raised once the kernel has returned (main: the file writer's handler raised it
there, and numba's broken tuple ended the run in a segmentation fault, exit -11).
"""

from __future__ import annotations

import signal
import time
from pathlib import Path

import limited_process
import pytest
from file_trees import populate, snapshot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


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

