"""Scanning at production speed: feedforward that inverts the stage, and learning that carries over.

End-to-end example of issue 24, on the paper's Table I loop with its Jenkins link
(``examples/scan_production.toml``: k_J = 20 N/m, f_c = 50 mN; the feedforward
inverts the stage up to the snap, ``M r'' + (m1 m2 / k) r''''``, and adds a link
model 4 % off):

1. Setpoint: a fourth-order scan of 0.1 m at 0.5 m/s (20 m/s^2, 2000 m/s^3,
   4e5 m/s^4) graded by MA and MSD over a 10 ms exposure window.
2. Compensations: ``none`` (``M r''`` only: the stage's flexible mode leaves
   ``(m1 m2 / k) / C(0)`` times the snap), ``model`` (the snap term and the link
   model), ``ilc`` (10 trials of learning a force) and ``basis`` (4 trials of
   learning the model's coefficients: mass, jerk, snap, the link's k and fc).
3. Carry-over: the model, the learned force and the learned coefficients,
   unchanged, at half and at double the speed.
4. Along the stroke: the link's slip force and stiffness vary over a 0.3 m stroke;
   scans at three places with a single-parameter link model and with the table.

Run ``python examples/scan_production.py [OUT_DIR]`` (default ``out/scan_production``);
it writes ``scan.png`` (the error, MA and MSD magnitudes against time, logarithmic) and
``summary.json``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

from motionhyst.core.jsonio import dumps
from motionhyst.scan.profiles import scan
from motionhyst.scan.scanning import ScanResult, loop_at, run_scan
from motionhyst.scenario import Scenario

SCENARIO = Path(__file__).resolve().parent / "scan_production.toml"
LENGTH, SPEED, WINDOW = 0.1, 0.5, 0.01
"""Scan length [m], speed [m/s] and exposure window [s]."""
LIMITS = {"a_max": 20.0, "j_max": 2000.0, "s_max": 4e5}
"""Acceleration, jerk and snap limits [m/s^2, m/s^3, m/s^4]."""
COMPENSATIONS = ("none", "model", "ilc", "basis")
TABLE = {"position": [0.0, 0.1, 0.2, 0.3], "fc": [1.2, 0.8, 1.0, 1.3], "k": [1.0, 1.0, 0.7, 1.0]}
"""The link along the stroke: scales of f_c and k at four positions [m]."""
PLACES = (0.0, 0.1, 0.2)
"""Where on the stroke the scans along it start [m]."""


def reductions(res: ScanResult) -> dict:
    """Max MA and max MSD without compensation over each compensation's [-]."""
    none = res.run("none")
    return {r.compensation: {"ma": none.ma_max / r.ma_max, "msd": none.msd_max / r.msd_max}
            for r in res.runs if r.compensation != "none"}


def along_stroke() -> dict:
    """Model and basis with a single-parameter link model and with the table, at each place."""
    data = Scenario.from_file(SCENARIO).to_dict()
    data["hysteresis"]["along"] = TABLE
    single = Scenario.from_dict(data, "along the stroke").loop()
    data["feedforward"]["hysteresis"]["along"] = TABLE
    table = Scenario.from_dict(data, "along the stroke, model with the table").loop()
    profile = scan(LENGTH, SPEED, start=0.01, **LIMITS)
    out = {}
    for x0 in PLACES:
        row = {}
        for name, loop in (("single", single), ("table", table)):
            res = run_scan(loop_at(loop, x0), profile, WINDOW, ("none", "model", "basis"))
            row[name] = reductions(res)
        out[f"{x0:g}"] = row
    return out


def main(out_dir: str | Path = "out/scan_production", quiet: bool = False) -> dict:
    """Run the example and write its figure and summary to `out_dir`.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing).
    quiet : bool
        Print nothing.

    Returns
    -------
    dict
        :meth:`ScanResult.to_dict` plus ``reductions`` (on the scan), ``half_speed``
        and ``double_speed`` (the carry-over's reductions), ``along_stroke``,
        ``figure`` and ``runtime_s``; also written to ``summary.json``.
    """
    from motionhyst.io.outputs import OutputFile

    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    loop = Scenario.from_file(SCENARIO).loop()
    profile = scan(LENGTH, SPEED, start=0.01, **LIMITS)
    runs = {}
    for name, factor in (("half_speed", 0.5), ("double_speed", 2.0)):
        other = scan(LENGTH, factor * SPEED, start=0.01, **LIMITS)
        runs[name] = run_scan(loop, profile, WINDOW, COMPENSATIONS, other_profile=other)
    res = runs["half_speed"]
    figure = out / "scan.png"
    fig = res.plot(log=True)
    with OutputFile(figure, force=True).open("wb") as fh:
        fig.savefig(fh, format="png", dpi=130)
    result = {**res.to_dict(), "reductions": reductions(res),
              **{k: reductions(r.carry_over) for k, r in runs.items()},
              "along_stroke": along_stroke(), "figure": str(figure),
              "runtime_s": time.perf_counter() - start}
    with OutputFile(out / "summary.json", force=True).open() as fh:
        fh.write(dumps(result) + "\n")
    if not quiet:
        print(res)
        for what in ("reductions", "half_speed", "double_speed"):
            print(f"{what}: " + "; ".join(f"{c} cuts max MA {r['ma']:.3g}x, max MSD "
                                          f"{r['msd']:.3g}x" for c, r in result[what].items()))
        for x0, row in result["along_stroke"].items():
            print(f"along the stroke from {x0} m: " + "; ".join(
                f"{m} model {r['model']['ma']:.3g}x, basis {r['basis']['ma']:.3g}x (MA)"
                for m, r in row.items()))
        print(f"figure: {figure} ({result['runtime_s']:.1f} s)")
    return result


if __name__ == "__main__":
    matplotlib.use("Agg")
    main(sys.argv[1] if len(sys.argv) > 1 else "out/scan_production")
