"""Generated records of machines without visible inertia: a piezo stack and a friction damper.

Each record is simulated from known parameters, with the offsets and the noise of a
measurement, so that a test can check what identification recovers and how well the model
predicts a part of the record it did not see.

* A piezo actuator (force from its voltage in, displacement out): rate-dependent hysteresis
  without inertia, a Bouc-Wen link with a spring and a damper in parallel
  (``QuasiStatic(k, c)``); its first resonance (kHz) far above the records' content.
* A friction damper (displacement imposed by a test machine, force measured): a
  Maxwell-slip link with a parallel spring, under sines and earthquake-like histories
  (band-limited noise under a rise-plateau-decay envelope); or a link of another model
  (:data:`DAMPER_LINKS`: Dahl, whose loops have no elastic range; LuGre with viscous
  friction), as a test machine logs it (:meth:`Record.write_as_logged`: its own column
  names and units, a drifting load cell, a displacement sensor's zero, jittered time
  stamps).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import signal

from motionhyst.hysteresis import BoucWen, Dahl, Hysteresis, LuGre, MaxwellSlip
from motionhyst.plants import QuasiStatic
from motionhyst.time.quasi_static import displacement_from_force, force_from_displacement

#: The piezo stack: stiffness 40 N/um, a Bouc-Wen link saturating at 150 N (a quarter of the
#: peak force), a damper whose force is 5 % of the spring's at 100 Hz (the rate dependence)
PIEZO_PLANT = QuasiStatic(k=4.0e7, c=3.0e3, force_offset=-12.0)
PIEZO_LINK = BoucWen(k=1.5e7, fc=150.0, n=1.0, beta=0.6, gamma=0.4)
PIEZO_OUTPUT_OFFSET = 3.0e-6  # the capacitive sensor's zero [m]
PIEZO_NOISE = 2.0e-9  # [m]
#: The friction damper: a spring of 50 kN/m and three Jenkins elements (slip 2-8 mm)
DAMPER_PLANT = QuasiStatic(k=5.0e4)
DAMPER_LINK = MaxwellSlip(k=[1.5e6, 6.0e5, 2.5e5], fc=[3.0e3, 2.4e3, 2.0e3])
DAMPER_FORCE_OFFSET = 85.0  # the load cell's zero [N]
DAMPER_NOISE = 15.0  # [N]
#: Dampers whose link Maxwell-slip elements alone do not describe: Dahl's (smooth loops, no
#: elastic range) and LuGre's (with viscous friction: 2e4 N s/m, the force rises with the rate)
DAMPER_LINKS = {"dahl": Dahl(k=1.0e6, fc=3.0e3),
                "lugre": LuGre(sigma0=1.0e6, sigma1=2.0e3, sigma2=2.0e4, fc=2.5e3, fs=3.5e3,
                               vs=0.01)}


@dataclass
class Record:
    """A generated record: time, force, displacement as measured."""

    t: np.ndarray
    force: np.ndarray
    displacement: np.ndarray

    def split(self, share: float) -> tuple[Record, Record]:
        """The first `share` of the samples, and the rest (its time from 0)."""
        n = int(share * self.t.size)
        rest = Record(self.t[n:] - self.t[n], self.force[n:], self.displacement[n:])
        return Record(self.t[:n], self.force[:n], self.displacement[:n]), rest

    def write(self, path: Path, columns: tuple[str, ...] = ("time", "force", "displacement")
              ) -> Path:
        """A CSV with these columns (of ``time``, ``force``, ``displacement``)."""
        data = {"time": self.t, "force": self.force, "displacement": self.displacement}
        with open(path, "w", newline="") as f:
            out = csv.writer(f)
            out.writerow(columns)
            out.writerows(zip(*(data[c] for c in columns), strict=True))
        return path


    def write_in_units(self, path: Path, columns: tuple[str, str, str] = ("t_s", "F_mN", "x_um"),
                       gains: tuple[float, float, float] = (1.0, 1e3, 1e6)) -> Path:
        """A CSV of time, force and displacement under the lab's own `columns` names, each
        multiplied by its gain (default: mN and um, a piezo stack's logger)."""
        data = (self.t, self.force, self.displacement)
        with open(path, "w", newline="") as f:
            out = csv.writer(f)
            out.writerow(columns)
            out.writerows(zip(*(g * d for g, d in zip(gains, data, strict=True)), strict=True))
        return path

    def write_as_logged(self, path: Path, seed: int = 0, force: bool = True) -> Path:
        """A CSV as a test machine logs it: ``Time (s)`` jittered by 0.2 % of a step,
        ``LVDT_mm`` (its zero 0.1 mm off, 2 um noise) and ``Load_kN`` (when `force`; its
        zero drifting by 2 N over the record)."""
        rng = np.random.default_rng(seed)
        h = self.t[1] - self.t[0]
        t = self.t + 2e-3 * h * rng.uniform(-1.0, 1.0, self.t.size)
        x = self.displacement + 1e-4 + 2e-6 * rng.standard_normal(self.t.size)
        f = self.force + 2.0 * self.t / self.t[-1]
        header = ["Time (s)", "LVDT_mm"] + (["Load_kN"] if force else [])
        columns = [t, 1e3 * x] + ([1e-3 * f] if force else [])
        with open(path, "w", newline="") as file:
            out = csv.writer(file)
            out.writerow(header)
            out.writerows(zip(*columns, strict=True))
        return path


#: How a user maps the logged columns (:meth:`Record.write_as_logged`) to SI
LOGGED = ["--columns", "time=Time (s),displacement=LVDT_mm,force=Load_kN",
          "--scale", "displacement=1e-3,force=1e3"]


def fit_percent(y: np.ndarray, y_hat: np.ndarray) -> float:
    """``100 (1 - |y - y_hat| / |y - mean y|)``, the benchmarks' fit."""
    return float(100.0 * (1.0 - np.linalg.norm(y - y_hat) / np.linalg.norm(y - np.mean(y))))


def stepped_sines(t: np.ndarray, pieces: list[tuple[float, float]]) -> np.ndarray:
    """Sines of (frequency [Hz], amplitude) one after another, each over an equal share of
    `t`, each a whole number of periods faded in and out (a Hann taper)."""
    out = np.zeros_like(t)
    edges = np.linspace(0, t.size, len(pieces) + 1).astype(int)
    for (f, a), i0, i1 in zip(pieces, edges[:-1], edges[1:], strict=True):
        tau = t[i0:i1] - t[i0]
        n = tau.size
        out[i0:i1] = a * np.sin(2 * np.pi * f * tau) * np.sin(np.pi * np.arange(n) / n) ** 0.5
    return out


def earthquake_like(t: np.ndarray, rng: np.random.Generator, peak: float,
                    band_hz: tuple[float, float] = (0.3, 6.0)) -> np.ndarray:
    """Band-limited noise under a rise, strong phase and decay envelope, scaled to `peak`."""
    fs = 1.0 / (t[1] - t[0])
    sos = signal.butter(4, band_hz, btype="bandpass", fs=fs, output="sos")
    x = signal.sosfiltfilt(sos, rng.standard_normal(t.size))
    d = t[-1] - t[0]
    rise = np.clip((t - t[0]) / (0.15 * d), 0.0, 1.0) ** 2
    decay = np.exp(-np.clip(t - t[0] - 0.45 * d, 0.0, None) / (0.15 * d))
    x *= rise * decay * np.sin(np.pi * (t - t[0]) / d) ** 0.25  # ends at rest
    return peak * x / np.max(np.abs(x))


def piezo_record(history: str = "sines", seed: int = 0, fs: float = 5000.0,
                 seconds: float = 2.0, creep: float = 0.0, exponent: float = 1.0) -> Record:
    """A piezo stack's record: force (from its voltage) in, displacement out, measured.

    `history`: ``"sines"`` (1 to 100 Hz, 0.3 to 1 of the full force) or ``"earthquake"``;
    `creep`: the stack's creep, a share of the spring's displacement added over time
    constants of 0.02, 0.2 and 2 s (three Kelvin-Voigt elements in series, a third each),
    which the quasi-static plant does not describe; `exponent`: its Bouc-Wen link's ``n``
    (the quasi-static plant's fit keeps 1).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    if history == "sines":
        u = stepped_sines(t, [(2.0, 600.0), (10.0, 350.0), (40.0, 500.0), (100.0, 250.0)])
    else:
        u = earthquake_like(t, rng, 600.0, (1.0, 60.0))
    u_measured = u - PIEZO_PLANT.force_offset  # the drive's offset: the stack gets u + f0
    link = PIEZO_LINK if exponent == 1.0 else BoucWen(k=PIEZO_LINK.k, fc=PIEZO_LINK.fc,
                                                       n=exponent, beta=PIEZO_LINK.beta,
                                                       gamma=PIEZO_LINK.gamma)
    x = displacement_from_force(PIEZO_PLANT, link, t, u_measured)
    for tau in (0.02, 0.2, 2.0) if creep else ():
        b, a = signal.bilinear([1.0], [tau, 1.0], fs)
        x = x + creep / 3 * signal.lfilter(b, a, u / PIEZO_PLANT.k)
    y = x + PIEZO_OUTPUT_OFFSET + PIEZO_NOISE * rng.standard_normal(t.size)
    return Record(t, u_measured, y)


def damper_record(history: str = "sines", seed: int = 0, fs: float = 200.0,
                  seconds: float = 40.0, link: str | Hysteresis | None = None,
                  stiffening: float = 0.0, drift: float = 0.0,
                  plant: QuasiStatic | None = None) -> Record:
    """A friction damper's record: displacement imposed, force measured (with offset, noise).

    `history`: ``"sines"`` (0.2 to 2 Hz, 3 to 20 mm) or ``"earthquake"`` (20 mm peak);
    `link`: a name of :data:`DAMPER_LINKS` or a link (default :data:`DAMPER_LINK`); `plant`:
    its spring (a neighbour of :data:`DAMPER_PLANT`); `stiffening`: the
    share by which its spring stiffens over the record (a rubber part warming up), which no
    model of motionhyst describes; `drift`: the displacement at the end of a linear drift
    over the record [m] (the test machine's actuator creeping, a residual displacement).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    if history == "sines":
        x = stepped_sines(t, [(0.2, 0.02), (0.5, 0.008), (1.0, 0.014), (2.0, 0.003)])
    else:
        x = earthquake_like(t, rng, 0.02)
    x = x + drift * t / t[-1]
    link = DAMPER_LINK if link is None else DAMPER_LINKS[link] if isinstance(link, str) else link
    plant = DAMPER_PLANT if plant is None else plant
    w = force_from_displacement(plant, link, t, x)
    w = w + stiffening * plant.k * (t / t[-1]) * x
    f = w + DAMPER_FORCE_OFFSET + DAMPER_NOISE * rng.standard_normal(t.size)
    return Record(t, f, x)
