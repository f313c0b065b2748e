"""Scanning with a hysteretic cable slab: MA and MSD, model-based feedforward against ILC.

End-to-end example of issue 14, on the paper's Table I loop with its Jenkins link
(``examples/scan.toml``: k_J = 20 N/m, f_c = 50 mN, and a hysteresis feedforward
whose model is 4 % off):

1. Setpoint: a fourth-order scan of 15 mm at 50 mm/s and back
   (:func:`motionhyst.scan.profiles.scan`); its acceleration covers 2.9 mm, more than
   the link's slip displacement f_c / k_J = 2.5 mm and less than the 5 mm the link
   takes to reverse, so the return scan starts with the link stuck.
2. Metrics: the error's moving average (MA) and moving standard deviation (MSD)
   over a 50 ms exposure window, maximal over the constant-velocity phases
   (:func:`motionhyst.scan.scanning.run_scan`), for three compensations: ``none``
   (rigid-body feedforward only), ``model`` (the 4 %-off link model driven by the
   setpoint) and ``ilc`` (10 trials of frequency-domain learning control).
3. Carry-over: the model and the learned force, unchanged, on the same scan at
   half the speed.

Run ``python examples/scan_compensation.py [OUT_DIR]`` (default ``out/scan``);
it takes a few seconds and writes ``scan.png`` (error, MA and MSD against time
with the phases shaded), ``ilc.png`` (the learning's trials) and ``summary.json``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO

import matplotlib

from motionhyst.core.jsonio import dumps
from motionhyst.scan.ilc import ILCFilters
from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import ScanResult, run_scan
from motionhyst.scenario import Scenario

SCENARIO = Path(__file__).resolve().parent / "scan.toml"
LENGTH = 0.015
"""Scan length at constant velocity [m]."""
SPEED = 0.05
"""Scan speed [m/s]."""
LIMITS = {"a_max": 2.0, "j_max": 50.0, "s_max": 1e3}
"""Acceleration, jerk and snap limits [m/s^2, m/s^3, m/s^4]."""
WINDOW = 0.05
"""Exposure window [s]: a 2.5 mm slit at 50 mm/s."""
TRIALS = 10
"""ILC trials."""


def _write_atomic(path: Path, write: Callable[[IO], None], mode: str = "w") -> None:
    """Write `path` through a temporary file in its folder, renamed into place."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, mode) as fh:
            write(fh)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def reductions(res: ScanResult) -> dict:
    """Max MA and max MSD without compensation over each compensation's [-]."""
    none = res.run("none")
    return {r.compensation: {"ma": none.ma_max / r.ma_max, "msd": none.msd_max / r.msd_max}
            for r in res.runs if r.compensation != "none"}


def main(out_dir: str | Path = "out/scan", trials: int = TRIALS, quiet: bool = False) -> dict:
    """Run the example and write its figures and summary to `out_dir`.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing).
    trials : int
        ILC trials.
    quiet : bool
        Print nothing.

    Returns
    -------
    dict
        :meth:`ScanResult.to_dict` plus ``reductions`` (on the scan) and
        ``carry_over_reductions`` (at half the speed), ``figure``, ``ilc_figure``
        and ``runtime_s``; also written to ``summary.json``.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    loop = Scenario.from_file(SCENARIO).loop()
    profile = scan(LENGTH, SPEED, back_and_forth=True, start=0.01, **LIMITS)
    other = scan(LENGTH, SPEED / 2, back_and_forth=True, start=0.01, **LIMITS)
    res = run_scan(loop, profile, WINDOW, ("none", "model", "ilc"), trials, ILCFilters(),
                   other_profile=other)
    figure, ilc_figure = out / "scan.png", out / "ilc.png"
    fig = res.plot()
    _write_atomic(figure, lambda fh: fig.savefig(fh, format="png", dpi=130), mode="wb")
    fig = res.ilc.plot()
    _write_atomic(ilc_figure, lambda fh: fig.savefig(fh, format="png", dpi=110), mode="wb")
    result = {**res.to_dict(), "reductions": reductions(res),
              "carry_over_reductions": reductions(res.carry_over),
              "figure": str(figure), "ilc_figure": str(ilc_figure),
              "runtime_s": time.perf_counter() - start}
    _write_atomic(out / "summary.json", lambda fh: fh.write(dumps(result) + "\n"))
    if not quiet:
        print(res)
        for what, red in (("scan", result["reductions"]),
                          ("half speed", result["carry_over_reductions"])):
            print(f"{what}: " + "; ".join(f"{c} cuts max MA {r['ma']:.3g}x, max MSD "
                                          f"{r['msd']:.3g}x" for c, r in red.items()))
        print(f"figures: {figure}, {ilc_figure} ({result['runtime_s']:.1f} s)")
    return result


if __name__ == "__main__":
    matplotlib.use("Agg")
    main(sys.argv[1] if len(sys.argv) > 1 else "out/scan")
