"""A stage known only by its measured frequency response: fit, check, analyse.

The paper's Table I stage "measured" as a frequency-response analyser exports it:
60 log-spaced lines from 1 to 3000 Hz of the collocated ``P1 = y1 / u`` and the
non-collocated ``P2 = y2 / u``, magnitude and phase, with 0.5 % complex noise (the
resonance at 694 Hz falls between two lines).  The example

1. writes the measurement, ``frf.csv`` (``frequency_hz, p1_abs, p1_phase_deg,
   p2_abs, p2_phase_deg``), and a scenario that uses it, ``measured.toml``
   (``[plant] file = "frf.csv"`` in place of Table I's ``[stage]``);
2. reads the scenario as ``motionhyst analyze measured.toml`` does: the data are
   fitted to a rigid body plus flexible modes (:func:`motionhyst.fit_frf`) and
   printed with the uncertainty of each parameter and the error per decade;
3. draws the data and the fit (``plant_fit.png``);
4. analyses the Table I loop on the fitted plant and on the exact stage: the
   mismatch ``|E|`` of eq. (18) at 1, 5 and 10 Hz, and the margins of ``C P2``.

Two measurements that go wrong in practice can be made instead:

- ``--delay-us 50``: the chain delays both transfers by 50 us (``e^{-s tau}``, a
  sample-and-hold and a computation step); the fit estimates the delay, divides it out
  and finds the same stage;
- ``--k-ground 20``: the link sticks during the measurement and holds ``m1`` to the
  ground with its stiffness ``k_J = 20 N/m`` (eq. 13); no rigid body plus modes
  describes that, and the fit says so in a warning.

Run ``python examples/measured_plant.py [OUT_DIR] [--delay-us US] [--k-ground K]``
(default ``out/measured_plant``); then ``motionhyst analyze OUT_DIR/measured.toml`` gives
the same fit and analysis from the command line.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import numpy as np

from motionhyst import ModalPlant, TwoMassStage, analyze, load_scenario
from motionhyst.io.outputs import OutputFile
from motionhyst.scenario import default_scenario_path

LINES_HZ = np.geomspace(1.0, 3000.0, 60)
"""The measured frequencies [Hz]."""
NOISE = 0.005
"""RMS of the complex measurement noise, relative to the response."""
FREQUENCIES_HZ = (1.0, 5.0, 10.0)
"""Where the mismatch is compared [Hz]."""
TABLE_I = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)


def held_response(k_ground: float) -> tuple[np.ndarray, np.ndarray]:
    """``P1``, ``P2`` of Table I at :data:`LINES_HZ` with ``m1`` held to the ground by a
    spring `k_ground` [N/m] (a link that sticks)."""
    s = 2j * np.pi * LINES_HZ
    st = TABLE_I
    z11 = st.m1 * s**2 + st.b * s + st.k + k_ground
    z22, z12 = st.m2 * s**2 + st.b * s + st.k, -(st.b * s + st.k)
    det = z11 * z22 - z12**2
    return z22 / det, -z12 / det


def measure(seed: int = 0, delay_s: float = 0.0,
            k_ground: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``P1``, ``P2`` of Table I at :data:`LINES_HZ` with relative complex noise.

    `delay_s` [s] delays both (``e^{-s tau}``); `k_ground` [N/m] holds ``m1`` to the
    ground (:func:`held_response`).
    """
    if k_ground:
        p1, p2 = held_response(k_ground)
    else:
        p1, p2 = ModalPlant.from_two_mass(TABLE_I).response(2 * np.pi * LINES_HZ)
    if delay_s:
        lag = np.exp(-2j * np.pi * LINES_HZ * delay_s)
        p1, p2 = p1 * lag, p2 * lag
    rng = np.random.default_rng(seed)

    def noisy(p: np.ndarray) -> np.ndarray:
        n = rng.standard_normal(p.shape) + 1j * rng.standard_normal(p.shape)
        return p * (1.0 + NOISE * n / np.sqrt(2.0))

    return noisy(p1), noisy(p2)


def frf_csv(p1: np.ndarray, p2: np.ndarray) -> str:
    """The measurement as CSV text, magnitude [m/N] and phase [deg] as analysers export it."""
    rows = ["frequency_hz,p1_abs,p1_phase_deg,p2_abs,p2_phase_deg"]
    rows += [f"{f:.6g},{abs(a):.6e},{np.degrees(np.angle(a)):.4f},"
             f"{abs(b):.6e},{np.degrees(np.angle(b)):.4f}"
             for f, a, b in zip(LINES_HZ, p1, p2, strict=True)]
    return "\n".join(rows) + "\n"


def scenario_text() -> str:
    """Table I with ``[plant] file = "frf.csv"`` in place of its ``[stage]``."""
    text = default_scenario_path().read_text(encoding="utf-8")
    start, end = text.index("[stage]"), text.index("[hysteresis]")
    plant = ('[plant]               # measured P1, P2, fitted to a rigid body plus modes\n'
             'file = "frf.csv"      # relative to this file\n\n')
    return text[:start] + plant + text[end:]


def main(out_dir: str | Path = "out/measured_plant", seed: int = 0, quiet: bool = False,
         delay_s: float = 0.0, k_ground: float = 0.0) -> dict:
    """Write the measurement and scenario, fit, draw and analyse; return the numbers.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created if missing); its files of the same names are replaced.
    seed : int
        Seed of the measurement noise.
    quiet : bool
        Print nothing.
    delay_s : float
        Delay of the measurement chain [s] (:func:`measure`).
    k_ground : float
        Stiffness holding ``m1`` to the ground during the measurement [N/m].

    Returns
    -------
    dict
        ``fit`` (:meth:`motionhyst.FrfFit.to_dict`), ``mismatch_fit`` and
        ``mismatch_exact`` (``|E|`` at :data:`FREQUENCIES_HZ`), ``margins_fit``,
        ``margins_exact``, ``warnings`` (:attr:`motionhyst.FrfFit.warnings`) and the
        paths written.
    """
    out = Path(out_dir)
    p1, p2 = measure(seed, delay_s, k_ground)
    OutputFile(out / "frf.csv", force=True).write_text(frf_csv(p1, p2))
    OutputFile(out / "measured.toml", force=True).write_text(scenario_text())

    sc = load_scenario(out / "measured.toml")
    fit = sc.plant_fit()
    loop = sc.loop()                                   # on the fitted ModalPlant
    exact_loop = load_scenario(None).loop()            # Table I's stage itself
    amplitude = sc.amplitude
    on_fit = analyze(loop, amplitude, FREQUENCIES_HZ)
    on_exact = analyze(exact_loop, amplitude, FREQUENCIES_HZ)

    figure = out / "plant_fit.png"
    fig = fit.plot()
    with OutputFile(figure, force=True).open("wb") as fh:
        fig.savefig(fh, format="png", dpi=110)

    margin_keys = ("gain_margin_db", "phase_margin_deg", "modulus_margin", "bandwidth_hz")
    result = {
        "fit": fit.to_dict(),
        "mismatch_fit": [abs(p.value) for p in on_fit.points],
        "mismatch_exact": [abs(p.value) for p in on_exact.points],
        "margins_fit": {k: on_fit.to_dict()[k] for k in margin_keys},
        "margins_exact": {k: on_exact.to_dict()[k] for k in margin_keys},
        "warnings": list(fit.warnings),
        "files": [str(out / "frf.csv"), str(out / "measured.toml"), str(figure)],
    }
    if not quiet:
        print(fit)
        print()
        print(f"{'':22s}{'fitted plant':>14s}{'exact stage':>14s}")
        for f, a, b in zip(FREQUENCIES_HZ, result["mismatch_fit"], result["mismatch_exact"],
                           strict=True):
            print(f"{f'|E| at {f:g} Hz':22s}{a:14.4g}{b:14.4g}")
        for k in margin_keys:
            print(f"{k:22s}{result['margins_fit'][k]:14.4g}{result['margins_exact'][k]:14.4g}")
        print(f"\nwrote {', '.join(result['files'])}")
    return result


if __name__ == "__main__":
    matplotlib.use("Agg")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir", nargs="?", default="out/measured_plant")
    parser.add_argument("--delay-us", type=float, default=0.0,
                        help="delay of the measurement chain [us]")
    parser.add_argument("--k-ground", type=float, default=0.0,
                        help="stiffness holding m1 to the ground (a stuck link) [N/m]")
    args = parser.parse_args()
    main(args.out_dir, delay_s=args.delay_us * 1e-6, k_ground=args.k_ground)
