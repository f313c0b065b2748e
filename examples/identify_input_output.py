"""A stage and its link identified from force and position records, then predicted.

The system is the Bouc-Wen benchmark's (Noel and Schoukens 2016): a mass
``m = 2 kg`` on a spring ``k = 5e4 N/m`` and damper ``c = 10 N s/m`` with a
Bouc-Wen link (``alpha = 5e4 N/m``, ``beta = 1e3``, ``gamma = 0.8``,
``delta = -1.1``, ``nu = 1``), force in, position out, sampled at 750 Hz.  The
records are made by the benchmark's own procedure (:mod:`motionhyst.identify.benchmark`:
random-phase multisines of 50 N RMS from 5 to 150 Hz, its Newmark integration and
decimation), shorter than the benchmark's so that the example runs in seconds.
The example

1. writes two training experiments from rest, ``train1.csv`` and ``train2.csv``
   (``time, force, displacement``; three periods of 2048 samples with the
   benchmark's 8e-6 m output noise), and a held-out experiment with another
   multisine: its force ``test_force.csv`` (``time, force``) and, noise-free, its
   displacement ``test_displacement.csv``;
2. identifies the mass, damper, spring and link from the training records alone,
   as ``motionhyst identify train1.csv train2.csv --record input-output`` does
   (:func:`motionhyst.identify.input_output.identify_io`), and writes the identified system as
   a scenario, ``model.toml``;
3. predicts the held-out displacement from its force, as ``motionhyst predict
   model.toml test_force.csv`` does, and scores it by the RMS error;
4. draws the held-out displacement and the prediction's error
   (``prediction.png``).

Run ``python examples/identify_input_output.py [OUT_DIR]`` (default
``out/identify_input_output``); the commands above, run in ``OUT_DIR``, give the
same model and prediction.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib
import numpy as np

from motionhyst.identify.benchmark import NOISE_RMS, TRUE_PARAMETERS, Record, training_record
from motionhyst.identify.input_output import identify_io, load_io_csv
from motionhyst.io.outputs import OutputFile
from motionhyst.scenario import Scenario

PERIOD = 2048
"""Samples per multisine period (the benchmark's are 8192)."""
TRAIN_PERIODS = 3
"""Periods of each training experiment."""
TEST_PERIODS = 2
"""Periods of the held-out experiment."""


def _csv(columns: dict[str, np.ndarray]) -> str:
    rows = [",".join(columns)]
    rows += [",".join(repr(float(v)) for v in row) for row in zip(*columns.values(), strict=True)]
    return "\n".join(rows) + "\n"


def write_records(out: Path, seed: int = 0) -> tuple[list[Path], Record]:
    """Write the training records and the held-out force; return their paths and the test."""
    rng = np.random.default_rng(seed)
    train = []
    for i in (1, 2):
        rec = training_record(rng, TRAIN_PERIODS, period=PERIOD)
        path = out / f"train{i}.csv"
        OutputFile(path, force=True).write_text(_csv(rec.columns()))
        train.append(path)
    test = training_record(rng, TEST_PERIODS, period=PERIOD, noise_rms=0.0)
    OutputFile(out / "test_force.csv", force=True).write_text(
        _csv({"time": test.t, "force": test.u}))
    OutputFile(out / "test_displacement.csv", force=True).write_text(
        _csv({"time": test.t, "displacement": test.y}))
    return train, test


def main(out_dir: str | Path = "out/identify_input_output", seed: int = 0,
         quiet: bool = False) -> dict:
    """Write the records, identify, save the model, predict the held-out record.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing); its files of the same names are replaced.
    seed : int
        Seed of the multisines and the noise.
    quiet : bool
        Print nothing.

    Returns
    -------
    dict
        ``identified`` (:meth:`motionhyst.identify.io_results.IOIdentification.to_dict`),
        ``true`` (the benchmark's parameters), ``fit_rms`` [m], ``test_rmse`` and
        ``test_output_rms`` [m] of the held-out prediction, and the paths written.
    """
    out = Path(out_dir)
    train, test = write_records(out, seed)
    fit = identify_io([load_io_csv(p) for p in train], "bouc-wen")
    OutputFile(out / "model.toml", force=True).write_text(fit.scenario_text())

    # the saved scenario, read back as motionhyst predict reads it
    system = Scenario.from_file(out / "model.toml").open_loop()
    pred = system.simulate(test.t, test.u)
    err = pred.displacement - test.y
    rmse = float(np.sqrt(np.mean(err**2)))

    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 5.0))
    ax1.plot(test.t, test.y * 1e3, color="0.2", lw=0.6)
    ax1.set_ylabel("displacement [mm]")
    ax1.set_title(f"Held-out multisine: prediction from the force alone, RMS error "
                  f"{rmse:.2g} m")
    ax2.plot(test.t, err * 1e6, color="tab:red", lw=0.6)
    ax2.set_ylabel("prediction error [um]")
    ax2.set_xlabel("time [s]")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    figure = out / "prediction.png"
    with OutputFile(figure, force=True).open("wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)

    result = {
        "identified": fit.to_dict(),
        "true": dict(TRUE_PARAMETERS),
        "fit_rms": fit.fit_rms,
        "test_rmse": rmse,
        "test_output_rms": float(np.sqrt(np.mean(test.y**2))),
        "files": [str(p) for p in (*train, out / "test_force.csv",
                                   out / "test_displacement.csv", out / "model.toml", figure)],
    }
    if not quiet:
        p = TRUE_PARAMETERS
        true = {"m": p["m"], "c": p["c"], "k": p["k"], "alpha": p["alpha"],
                "beta*gamma": p["beta"] * p["gamma"], "beta*delta": p["beta"] * p["delta"]}
        print(f"{'parameter':12s}{'true':>12s}{'estimate':>14s}{'std':>10s}")
        for name, value in fit.estimates.items():
            std = fit.std.get(name)
            print(f"{name:12s}{true.get(name, float('nan')):12.6g}{value:14.8g}"
                  f"{'-' if std is None else f'{std:.2g}':>10s}")
        print(f"\nfit RMS over the training records {fit.fit_rms:.4g} m "
              f"(output noise {NOISE_RMS:g} m)")
        print(f"held-out prediction: RMS error {rmse:.3g} m of an output of RMS "
              f"{result['test_output_rms']:.3g} m")
        print(f"\nwrote {', '.join(Path(p).name for p in result['files'])}")
    return result


if __name__ == "__main__":
    matplotlib.use("Agg")
    main(sys.argv[1] if len(sys.argv) > 1 else "out/identify_input_output")
