"""A Monte-Carlo study of the paper's loop from Python: estimate, run, resume, read, summarize.

The study is ``examples/study.toml``: a fleet of machines built to Table I whose dynamic link
differs from machine to machine by 10 % (one standard deviation of the logarithm) in its
stiffness ``k_J`` and its slip force ``f_c``, at two amplitudes and 50 frequencies from 1 to
100 Hz, outputs ``e1``, ``mismatch``, ``error_rms`` and the quasi-linear ``E`` (eq. 18).  The
script states what the study costs, runs it on every local core into a zarr store, runs it
again (nothing is missing: nothing is computed), reads the results back as an xarray
Dataset, prints the closing summary and draws ``|E|`` over frequency with the band of the
machines from 5 to 95 %.  The command line does the same with ``motionhyst study
examples/study.toml --estimate``, ``motionhyst study examples/study.toml --out fleet.zarr``
and ``motionhyst study --summary fleet.zarr --figure fleet.png``.

Run ``python examples/fleet_study.py [OUT_DIR]`` (default ``out/fleet_study``); it writes
``OUT_DIR/fleet.zarr`` (replaced if it holds another study) and ``OUT_DIR/fleet.png``.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import numpy as np

from motionhyst.study import Study, open_results, summarize
from motionhyst.study.summary import plot_band

EXAMPLES = Path(__file__).resolve().parent


def fleet(samples: int | None = None) -> Study:
    """The study of ``examples/study.toml``, with `samples` machines instead of its 100.

    Parameters
    ----------
    samples : int, optional
        Monte-Carlo samples (machines); default: the file's.

    Examples
    --------
    >>> fleet().n_points, fleet(4).n_points          # 2 amplitudes x 50 frequencies x machines
    (10000, 400)
    """
    path = EXAMPLES / "study.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    if samples is not None:
        data["samples"]["n"] = samples
    return Study.from_dict(data, source=str(path), base_dir=EXAMPLES)


def main(out_dir: str | Path = "out/fleet_study", samples: int | None = None,
         workers: int | None = None) -> dict:
    """Estimate, run and summarize the fleet study into `out_dir`; its key numbers.

    Parameters
    ----------
    out_dir : str or Path
        Folder of the store ``fleet.zarr`` and the figure ``fleet.png``.
    samples : int, optional
        Machines (default: the study file's 100).
    workers : int, optional
        Local worker processes (default: every core; 0: this process).

    Returns
    -------
    dict
        ``points``, ``computed`` by the first run and by the second, ``failed``, the median
        and 5-95 % band of ``|E|`` at 1 Hz and 10 mm over the machines, and the figure.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    study = fleet(samples)
    print(f"Study {study.n_points} points: estimate")
    print(study.estimate(workers=workers or 1))

    store = out / "fleet.zarr"
    first = study.run(store, workers=workers, force=True)
    again = study.run(store, workers=workers)   # the same store: only what is missing
    print(first)
    print(f"again: {again.computed} points computed")

    ds = open_results(store)                    # an xarray Dataset, complex outputs complex
    e = abs(ds["E"].sel(amplitude=0.01, frequency_hz=1.0))
    lo, mid, hi = np.percentile(e.values, [5, 50, 95])
    print(f"|E| at 1 Hz and 10 mm over the machines: median {mid:.0f}, 5-95 % {lo:.0f} to "
          f"{hi:.0f}")
    print(summarize(ds))

    fig = plot_band(ds)                          # |E| over frequency, a band per amplitude
    figure = out / "fleet.png"
    fig.savefig(figure, dpi=120)
    return {"points": study.n_points, "computed": first.computed, "again": again.computed,
            "failed": first.failed, "E_1Hz_10mm": (lo, mid, hi), "figure": figure,
            "dataset": ds}


if __name__ == "__main__":
    main(*sys.argv[1:2])
