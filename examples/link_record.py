"""A short, noisy force-displacement record of Table I's link, for a Monte-Carlo study.

The record is generated, not measured: a Jenkins element with the paper's ``k_J = 20 N/m``
and ``f_c = 0.05 N`` (eq. 3) driven by a 2 Hz sine whose amplitude decays from 10 mm to
0.5 mm and grows back, 500 samples at 250 Hz, its force with 20 mN RMS of white sensor noise
(seeded).  Identified with one element (``motionhyst identify link.csv --elements 1 --save
link.toml``), it gives ``k`` and ``fc`` with about 3 % standard errors, correlated (the
slip displacement ``fc / k`` is better determined than either), and a Monte-Carlo study of
the paper's loop draws them from that covariance (``motionhyst study
examples/study_identified.toml --from-identification link.toml``; README, "Studies").

Run ``python examples/link_record.py [OUT_DIR]`` (default ``out/fleet``); it writes
``OUT_DIR/link.csv`` (``time,displacement,force``) and prints the commands that follow.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from motionhyst.hysteresis import Jenkins

K_TRUE, FC_TRUE = 20.0, 0.05
"""The link of Table I: spring stiffness k_J [N/m] and slip force f_c [N]."""
NOISE = 0.02
"""RMS of the force sensor's white noise [N]."""


def record(n: int = 500, rate_hz: float = 250.0, seed: int = 0) -> np.ndarray:
    """The record's columns ``time, displacement, force`` as an (n, 3) array.

    Parameters
    ----------
    n : int
        Samples.
    rate_hz : float
        Sampling rate [Hz].
    seed : int
        Seed of the noise.

    Examples
    --------
    >>> r = record(100)
    >>> r.shape, float(r[0, 0])
    ((100, 3), 0.0)
    """
    t = np.arange(n) / rate_hz
    envelope = np.concatenate([np.geomspace(0.01, 5e-4, n // 2),
                               np.geomspace(5e-4, 0.01, n - n // 2)])
    x = envelope * np.sin(2 * np.pi * 2.0 * t)
    force = (Jenkins(k=K_TRUE, fc=FC_TRUE).response(x)
             + NOISE * np.random.default_rng(seed).standard_normal(n))
    return np.column_stack([t, x, force])


def main(out_dir: str | Path = "out/fleet") -> Path:
    """Write ``out_dir/link.csv`` and return its path.

    Parameters
    ----------
    out_dir : str or Path
        The folder (made if missing).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "link.csv"
    np.savetxt(path, record(), delimiter=",", header="time,displacement,force", comments="",
               fmt="%.17g")
    return path


if __name__ == "__main__":
    written = main(*sys.argv[1:2])
    folder = written.parent
    print(f"wrote {written} (a generated record of Table I's link, 20 mN of force noise); then\n"
          f"  motionhyst identify {written} --elements 1 --save {folder / 'link.toml'}\n"
          f"  motionhyst study examples/study_identified.toml --from-identification "
          f"{folder / 'link.toml'} --out {folder / 'fleet.zarr'}\n"
          f"  motionhyst study --summary {folder / 'fleet.zarr'} --figure "
          f"{folder / 'fleet.png'}")
