"""An ``simulate --output-rate`` far above what the loop needs (issue 26: 1e9 Hz against the
27.7 kHz Table I's loop steps at; on a disk with room the 8.4 GB run went ahead without a
word): 10 times is warned of, naming --output-rate and the rate the loop needs, 1000 times
refused in one line, the old time series byte-identical."""

from __future__ import annotations

import limited_process
import pytest
from file_trees import populate, snapshot

from motionhyst.cli import main
from motionhyst.scenario import default_scenario_path

SIMULATE = ["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5", "--force"]
NEEDED = ("the rate the loop needs (2.77e+04 Hz: the loop's fastest closed-loop pole, 691.4 "
          "Hz, resolved in 40 steps)")


def test_an_output_rate_a_thousand_times_the_loop_s_is_refused(tmp_path):
    """1e9 Hz for 10 us: 1e4 rows, 1.7 MB (main wrote them, exit 0)."""
    populate(tmp_path, {"s.toml": default_scenario_path().read_text(),
                        "ts.csv": "an old time series\n"})
    before = snapshot(tmp_path)
    line = limited_process.refusal([*SIMULATE, "--output-rate", "1e9", "--duration", "1e-5"],
                                   tmp_path, file_limit=10 << 20)
    assert line == (f"motionhyst: error: simulate: --output-rate 1e+09 Hz is 3.62e+04 times "
                    f"{NEEDED}: its rows would only make the run's step finer than the loop's "
                    f"dynamics need; give --output-rate 2.77e+04 (at most 1000 times it)"), line
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(("rate", "warned"), [("1e6", True), ("1e5", False), ("2.7e5", False)])
def test_an_output_rate_ten_times_the_loop_s_is_warned_of(tmp_path, monkeypatch, capsys, rate,
                                                          warned):
    """1 MHz, 36 times 27.7 kHz: the run goes on, with a warning (main: none); 100 kHz and
    270 kHz (3.6 and 9.8 times): no warning."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(default_scenario_path().read_text())
    assert main([*SIMULATE, "--output-rate", rate, "--duration", "0.001"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "--output-rate" in line]
    assert lines == ([f"motionhyst: warning: simulate: --output-rate 1e+06 Hz is 36.2 times "
                      f"{NEEDED}: its rows make the run's step and the file 36.2 times finer and "
                      f"longer than the loop's dynamics need; --output-rate 2.77e+04 resolves "
                      f"it"] if warned else []), lines
