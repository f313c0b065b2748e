"""Identify a cable slab's hysteresis from noisy data and compensate it in feedforward.

End-to-end example of issue 6, in four steps:

1. Measurements: noisy force-displacement records of a three-element
   Maxwell-slip link (parallel Jenkins elements, paper eq. 3 each; total
   stiffness 20 N/m as the link of Table I, slip forces of 10-30 mN): a
   training record (a sine whose amplitude decays from 12 mm to 0.3 mm and
   grows back, so every slip threshold is crossed on many scales) and a
   held-out record of another kind (a multi-sine of three other frequencies
   and amplitudes).  Both are written to ``out_dir`` as CSV
   (``time,displacement,force``), so ``motionhyst identify OUT/train.csv``
   gives the same result on the command line.
2. Identification: :func:`motionhyst.identify.identify_maxwell_slip` on the
   training record, the number of elements chosen by its RMS criterion.
3. Validation: normalised RMS error of the identified model's force on the
   held-out record (against the measured, noisy force and against the true
   force).
4. Compensation: the Table I loop (``examples/paper.toml``) with the true
   three-element link, without and with the identified model as hysteresis
   feedforward ``u_ff = M r'' + phi_hat(r)``; the hysteresis-induced error
   ``e - e_linear`` of the exact periodic steady state at 5 Hz, 10 mm
   (:func:`motionhyst.analysis.steady.periodic_steady_state`), its RMS before and after,
   and a figure of it over one period.

Run ``python examples/identify_and_compensate.py [OUT_DIR]`` (default
``out/identify``); it takes a few seconds and prints a summary.
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
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from motionhyst.analysis.steady import SteadyState, periodic_steady_state
from motionhyst.core.jsonio import dumps
from motionhyst.hysteresis import MaxwellSlip
from motionhyst.identify import Identification, identify_maxwell_slip
from motionhyst.scenario import Scenario, default_scenario

K_TRUE = (10.0, 6.0, 4.0)
"""Stiffnesses of the simulated cable slab's elements [N/m] (sum: Table I's k_J = 20 N/m)."""
FC_TRUE = (0.01, 0.02, 0.03)
"""Slip forces of its elements [N]; slip displacements 1, 3.3 and 7.5 mm."""
FORCE_NOISE = 0.01
"""Force-sensor noise, relative to the RMS of the force [-]."""
POSITION_NOISE = 2e-7
"""Displacement-sensor noise [m] (0.2 um RMS)."""
FREQUENCY_HZ = 5.0
"""Frequency of the compensated sine reference [Hz]."""


# --------------------------------------------------------------------------- data


def training_displacement(n: int, cycles: int = 20, a_max: float = 0.012,
                          a_min: float = 3e-4) -> NDArray[np.float64]:
    """A sine whose amplitude decays from `a_max` to `a_min` [m] and grows back."""
    theta = np.linspace(0.0, 2.0 * np.pi * cycles, n)
    half = n // 2
    env = np.concatenate([np.geomspace(a_max, a_min, half),
                          np.geomspace(a_min, a_max, n - half)])
    return env * np.sin(theta)


def heldout_displacement(n: int) -> NDArray[np.float64]:
    """Held-out excitation: three sines of other frequencies and amplitudes over 1 s [m]."""
    t = np.linspace(0.0, 1.0, n)
    return (0.009 * np.sin(2 * np.pi * 2 * t) + 0.003 * np.sin(2 * np.pi * 7 * t + 1.0)
            + 0.001 * np.sin(2 * np.pi * 23 * t + 2.0))


def measure(link: MaxwellSlip, x: NDArray[np.float64], rng: np.random.Generator
            ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Noisy readings of displacement and force, and the true force [m, N, N]."""
    w = link.response(x)
    x_meas = x + POSITION_NOISE * rng.standard_normal(x.size)
    w_meas = w + FORCE_NOISE * float(np.sqrt(np.mean(w**2))) * rng.standard_normal(x.size)
    return x_meas, w_meas, w


def nrms(predicted: NDArray[np.float64], reference: NDArray[np.float64]) -> float:
    """RMS of ``predicted - reference`` over the RMS of `reference` about its mean [-]."""
    return float(np.sqrt(np.mean((predicted - reference) ** 2)) / np.std(reference))


# --------------------------------------------------------------------------- output


def _write_atomic(path: Path, write: Callable[[IO], None], mode: str = "w") -> None:
    """Write `path` through a temporary file in the same folder and rename it."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, mode) as fh:
            write(fh)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_record(path: Path, t: NDArray, x: NDArray, w: NDArray) -> None:
    """A force-displacement record as CSV: ``time,displacement,force`` [s, m, N]."""
    def write(fh: IO) -> None:
        fh.write("time,displacement,force\n")
        np.savetxt(fh, np.column_stack([t, x, w]), delimiter=",", fmt="%.12e")
    _write_atomic(path, write)


def error_figure(before: SteadyState, after: SteadyState, x_held: NDArray[np.float64],
                 w_held: NDArray[np.float64], w_pred: NDArray[np.float64],
                 heldout_nrms: float) -> Figure:
    """Held-out force prediction and the hysteresis-induced error before and after."""
    style = {"font.size": 9, "legend.fontsize": 8, "legend.frameon": False,
             "axes.spines.top": False, "axes.spines.right": False, "lines.linewidth": 1.4}
    with matplotlib.rc_context(style):
        fig = Figure(figsize=(7.0, 8.0), layout="constrained")
        ax_w, ax_b, ax_a = fig.subplots(3, 1)
    ax_w.plot(1e3 * x_held, 1e3 * w_held, ".", ms=1.5, color="0.6",
              label="held-out measurement (noisy)")
    ax_w.plot(1e3 * x_held, 1e3 * w_pred, color="tab:red", lw=1.0,
              label=f"identified model (NRMS error {100 * heldout_nrms:.2f} %)")
    ax_w.set(xlabel="link displacement x [mm]", ylabel="link force w [mN]",
             title="Held-out record: identified Maxwell-slip model against measured force")
    ax_w.set_ylim(top=1.6e3 * float(np.max(w_held)))  # room for the legend
    ax_w.legend(loc="upper left")
    for ax, ss, label, color in ((ax_b, before, "rigid-body feedforward only", "0.15"),
                                 (ax_a, after, "with identified hysteresis feedforward",
                                  "tab:red")):
        ts = ss.time_series()
        ax.plot(1e3 * ts["t"], 1e9 * (ts["e"] - ts["e_linear"]), color=color,
                label=f"{label}: RMS {1e9 * ss.error_hysteresis_rms:.3g} nm")
        ax.axhline(0.0, color="0.7", lw=0.6)
        ax.set(xlabel="time [ms]", ylabel="error due to hysteresis\ne - e_linear [nm]")
        ax.legend(loc="upper right")
        ax.grid(True, alpha=0.3)
    ratio = before.error_hysteresis_rms / after.error_hysteresis_rms
    ax_b.set_title(f"Tracking error due to hysteresis, Table I loop, "
                   f"r = {1e3 * before.amplitude:g} mm at {before.frequency_hz:g} Hz: before")
    ax_a.set_title(f"After: identified model as feedforward ({ratio:.0f}x smaller; own scale)")
    ax_w.grid(True, alpha=0.3)
    return fig


# --------------------------------------------------------------------------- main


def _compensated_loops(true_link: MaxwellSlip, ident: Identification
                       ) -> tuple[Scenario, Scenario]:
    """Table I with the true link, without and with the identified hysteresis feedforward."""
    data = default_scenario().to_dict()
    data["hysteresis"] = {"model": "maxwell-slip", "k": list(map(float, true_link.k)),
                          "fc": list(map(float, true_link.fc))}
    data["feedforward"].pop("hysteresis", None)
    before = Scenario.from_dict(data, "Table I, three-element link")
    data["feedforward"]["hysteresis"] = {
        "model": "maxwell-slip", "k": [e["k"] for e in ident.elements],
        "fc": [e["fc"] for e in ident.elements]}
    after = Scenario.from_dict(data, "Table I, three-element link, hysteresis feedforward")
    return before, after


def main(out_dir: str | Path = "out/identify", n_train: int = 4000, n_heldout: int = 3000,
         seed: int = 6, quiet: bool = False) -> dict:
    """Run the example and write its records, figure and summary to `out_dir`.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing).
    n_train, n_heldout : int
        Samples of the training and held-out records.
    seed : int
        Seed of the measurement noise.
    quiet : bool
        Print nothing.

    Returns
    -------
    dict
        ``identified`` (:meth:`Identification.to_dict`), ``heldout_nrms``
        (against the measured force), ``heldout_nrms_true`` (against the true
        force), ``error_hysteresis_rms_before`` / ``_after`` [m],
        ``reduction`` [-], ``figure`` and ``runtime_s``; also written to
        ``summary.json``.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    link = MaxwellSlip(K_TRUE, FC_TRUE)

    x_train = training_displacement(n_train)
    t_train = np.arange(n_train) * (20.0 / n_train)  # 20 cycles in 20 s: quasi-static
    xm_train, wm_train, _ = measure(link, x_train, rng)
    write_record(out / "train.csv", t_train, xm_train, wm_train)

    x_held = heldout_displacement(n_heldout)
    t_held = np.linspace(0.0, 1.0, n_heldout)
    xm_held, wm_held, w_held = measure(link, x_held, rng)
    write_record(out / "heldout.csv", t_held, xm_held, wm_held)

    ident = identify_maxwell_slip(xm_train, wm_train, t=t_train)
    w_pred = ident.predict(xm_held)  # from relaxed, like the held-out record
    heldout = nrms(w_pred, wm_held)
    heldout_true = nrms(w_pred, w_held)

    sc_before, sc_after = _compensated_loops(link, ident)
    amplitude = sc_before.amplitude
    before = periodic_steady_state(sc_before.loop(), amplitude, FREQUENCY_HZ)
    after = periodic_steady_state(sc_after.loop(), amplitude, FREQUENCY_HZ)
    reduction = before.error_hysteresis_rms / after.error_hysteresis_rms

    fig = error_figure(before, after, xm_held, wm_held, w_pred, heldout)
    figure = out / "identify_and_compensate.png"
    _write_atomic(figure, lambda fh: fig.savefig(fh, format="png", dpi=130), mode="wb")

    result = {
        "true": {"k": list(K_TRUE), "fc": list(FC_TRUE)},
        "identified": ident.to_dict(),
        "heldout_nrms": heldout,
        "heldout_nrms_true": heldout_true,
        "frequency_hz": FREQUENCY_HZ,
        "amplitude": amplitude,
        "error_hysteresis_rms_before": before.error_hysteresis_rms,
        "error_hysteresis_rms_after": after.error_hysteresis_rms,
        "reduction": reduction,
        "figure": str(figure),
        "records": [str(out / "train.csv"), str(out / "heldout.csv")],
        "runtime_s": time.perf_counter() - start,
    }
    _write_atomic(out / "summary.json", lambda fh: fh.write(dumps(result) + "\n"))
    if not quiet:
        ks = ", ".join(f"{e['k']:.4g}" for e in ident.elements)
        fcs = ", ".join(f"{e['fc']:.4g}" for e in ident.elements)
        print(f"identified {ident.n_elements} elements from {n_train} noisy samples: "
              f"k = [{ks}] N/m, fc = [{fcs}] N (true {list(K_TRUE)}, {list(FC_TRUE)})")
        print(f"held-out NRMS force error {100 * heldout:.3g} % against the measured force, "
              f"{100 * heldout_true:.3g} % against the true force")
        print(f"hysteresis-induced error at {FREQUENCY_HZ:g} Hz (RMS): "
              f"{1e9 * before.error_hysteresis_rms:.4g} nm -> "
              f"{1e9 * after.error_hysteresis_rms:.4g} nm ({reduction:.0f}x smaller)")
        print(f"wrote {figure}, summary.json, train.csv, heldout.csv in {out} "
              f"({result['runtime_s']:.2g} s)")
    return result


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/identify")
