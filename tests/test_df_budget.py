"""``motionhyst df`` within its budgets (issue 26): the answer's values sized against
``--max-memory`` before any is computed, the computation stopped after ``--max-seconds`` of
CPU time; both options are in its help.  Before, ``df`` took neither: 2000 amplitudes x 1001
harmonics of a 2000-element Maxwell-slip link at ``--max-memory 10M`` ran 13.5 s of CPU to
1.16 GB resident and exit 0, and a longer list heads for the kernel's kill."""

from __future__ import annotations

import subprocess
import sys

import pytest

from motionhyst.cli import main
from motionhyst.cli.df import JSON_VALUE_BYTES, TEXT_VALUE_BYTES


def _values(n: int, scale: float) -> list[str]:
    return [f"{scale * (1 + i):g}" for i in range(n)]


def _refused(argv: list[str], capsys) -> str:
    assert main(argv) == 2
    captured = capsys.readouterr()
    line = captured.err.strip()
    assert captured.out == "" and line and "\n" not in line and "Traceback" not in line, (
        captured.err)
    return line


@pytest.fixture
def not_computed(monkeypatch):
    """The describing function fails the test if it is computed: the refusal comes first."""
    from motionhyst.analysis import describing

    def computed(*args, **kwargs):
        raise AssertionError("the describing function was computed")

    monkeypatch.setattr(describing, "describing_function", computed)


@pytest.mark.parametrize(("json", "per_value"), [(False, TEXT_VALUE_BYTES),
                                                 (True, JSON_VALUE_BYTES)])
def test_an_answer_above_the_memory_budget_is_refused_before_it_is_computed(
        capsys, not_computed, json, per_value):
    """2000 amplitudes x 1001 values of a 2000-element link: sized, refused in one line."""
    k = _values(2000, 1.0)
    line = _refused(["df", "--model", "maxwell-slip", "--k", *k, "--fc", *k, "--amplitude",
                     *_values(2000, 1e-4), "--harmonics", "1000", "--max-memory", "10M",
                     *(["--json"] if json else [])], capsys)
    size = f"{2000 * 1001 * per_value / 1e9:.2g} GB"
    assert line == ("motionhyst: error: the describing function at 2000 points of 1001 values "
                    f"each needs {size}, above the memory budget of 10.5 MB (--max-memory); "
                    "give fewer --amplitude or --frequency values, or fewer --harmonics"), line


def test_frequencies_count_in_the_size(capsys, not_computed):
    """A rate-dependent element: amplitudes x frequencies points (50 x 40 x 101 values)."""
    line = _refused(["df", "--model", "lugre", "--sigma0", "1e5", "--sigma1", "300", "--fc",
                     "1", "--fs", "1.5", "--vs", "1e-3", "--frequency", *_values(40, 1.0),
                     "--amplitude", *_values(50, 1e-4), "--harmonics", "100", "--max-memory",
                     "100M"], capsys)
    assert "at 2000 points of 101 values each needs 121 MB" in line, line


def test_a_computation_beyond_its_cpu_time_is_stopped_in_one_line(tmp_path):
    """LuGre integrated at 60 amplitudes x 10 frequencies (about 1 s of CPU) at
    ``--max-seconds 0.05``: stopped, nothing printed on stdout (in a process of its own: the
    limit may stop numba's import, which the command's exit ends)."""
    import limited_process

    line = limited_process.refusal(
        ["df", "--model", "lugre", "--sigma0", "1e5", "--sigma1", "300", "--fc", "1", "--fs",
         "1.5", "--vs", "1e-3", "--frequency", *_values(10, 1.0), "--amplitude",
         *_values(60, 1e-4), "--max-seconds", "0.05"], tmp_path)
    assert line == ("motionhyst: error: df did not finish within the work budget of 0.05 s of "
                    "CPU time (--max-seconds); give fewer --amplitude or --frequency values, or "
                    "fewer --harmonics, or a larger --max-seconds"), line


def test_an_answer_within_its_budgets_is_the_librarys(capsys):
    """Under both budgets the command prints the library's describing function (eq. 10)."""
    from motionhyst.analysis.describing import describing_function
    from motionhyst.hysteresis import Jenkins

    assert main(["df", "--k", "20", "--fc", "0.05", "--amplitude", "0.01", "0.02",
                 "--harmonics", "3", "--max-memory", "1M", "--max-seconds", "60"]) == 0
    printed = capsys.readouterr().out
    assert printed.strip() == str(describing_function(Jenkins(20.0, 0.05), [0.01, 0.02],
                                                      harmonics=3)).strip()


SIZED = """
import os, resource, sys
from motionhyst.cli import main
from motionhyst.cli.df import JSON_VALUE_BYTES, TEXT_VALUE_BYTES
sys.stdout = open(os.devnull, "w")
main(["df", "--amplitude", "0.01", "--k", "20", "--fc", "0.05", "--harmonics", "3"])
main(["df", "--amplitude", "0.01", "--k", "20", "--fc", "0.05", "--harmonics", "3", "--json"])
json = sys.argv[1] == "json"
estimate = (JSON_VALUE_BYTES if json else TEXT_VALUE_BYTES) * 400 * 401
with open("/proc/self/status") as f:
    size = next(int(x.split()[1]) * 1024 for x in f if x.startswith("VmSize"))
resource.setrlimit(resource.RLIMIT_AS, (size + estimate, size + estimate))
amplitudes = [f"{1e-4 * (1 + i):g}" for i in range(400)]
sys.exit(main(["df", "--k", "20", "--fc", "0.05", "--amplitude", *amplitudes,
               "--harmonics", "400", "--max-memory", "1T", *(["--json"] if json else [])]))
"""


@pytest.mark.parametrize("form", ["text", "json"])
def test_the_size_bounds_the_answers_memory(tmp_path, form):
    """400 amplitudes x 401 values run under an address-space limit of their estimate above
    the warmed process: the estimate holds the answer (a MemoryError would be exit 2)."""
    from limited_process import environment

    script = tmp_path / "sized.py"
    script.write_text(SIZED)
    proc = subprocess.run([sys.executable, str(script), form], capture_output=True, text=True,
                          env=environment(), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
