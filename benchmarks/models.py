"""Benchmark: numerical describing functions of Bouc-Wen and LuGre links against scipy.

A Bode-style analysis needs ``D`` at many points: over 200 amplitudes for a
rate-independent element, over 200 frequencies for the rate-dependent LuGre.
One run measures, per model:

1. the peer: the element's ODE integrated with ``scipy.integrate.solve_ivp``
   (RK45, as a user would write it) for ``x = A sin(omega t)`` from rest over
   ``PEER_PERIODS`` periods, ``D = (b1 + j a1) / A`` projected from the last
   period on a 4096-point ``t_eval`` grid, with ``rtol`` 1e-6 and 1e-9; timed on
   ``PEER_POINTS`` of the 200 points and reported per point;
2. motionhyst: ``describing_function`` over all 200 points on a fresh instance
   (no cache), per point;
3. both errors against a reference on the same ``PEER_POINTS`` points: the
   ODE with DOP853 at ``rtol`` 1e-12 over one period from the initial state that
   makes it periodic (shooting).  The peer's error includes what is left of
   its start from rest: part of what a user of the peer gets.

Run with ``make bench`` or ``python benchmarks/models.py``.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from motionhyst.hysteresis import BoucWen, LuGre

TWO_PI = 2.0 * np.pi
N_POINTS = 200
PEER_POINTS = 8
PEER_PERIODS = 6
N_EVAL = 4096

BOUC_WEN = {"k": 20.0, "fc": 0.05, "n": 2.0, "beta": 0.7, "gamma": 0.3}
BOUC_WEN_AMPLITUDES = np.geomspace(1e-4, 1e-1, N_POINTS)   # m
BOUC_WEN_FREQUENCY = 5.0                                    # Hz (irrelevant to D)
LUGRE = {"sigma0": 20.0, "sigma1": 0.01, "sigma2": 0.001, "fc": 0.05, "fs": 0.06, "vs": 0.01}
LUGRE_AMPLITUDE = 0.01                                      # m
LUGRE_FREQUENCIES = np.geomspace(1.0, 1000.0, N_POINTS)     # Hz


def bouc_wen_rhs(p: dict, A: float, omega: float):
    """Bouc-Wen as in ``BoucWen``: ``w = fc z``,
    ``dz/dt = (k / fc) v [1 - (beta sign(v z) + gamma) |z|^n]``."""
    k, fc, n, beta, gamma = p["k"], p["fc"], p["n"], p["beta"], p["gamma"]

    def rhs(t, s):
        v = A * omega * np.cos(omega * t)
        z = s[0]
        return [(k / fc) * v * (1.0 - (beta * np.sign(v * z) + gamma) * abs(z) ** n)]

    def force(t, s):
        return fc * s[0]

    return rhs, force


def lugre_rhs(p: dict, A: float, omega: float):
    """LuGre: ``dz/dt = v - sigma0 |v| z / g(v)``, ``w = sigma0 z + sigma1 dz/dt + sigma2 v``."""
    s0, s1, s2, fc, fs, vs = (p[k] for k in ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs"))

    def zdot(t, z):
        v = A * omega * np.cos(omega * t)
        g = fc + (fs - fc) * np.exp(-(v / vs) ** 2)
        return v - s0 * np.abs(v) * z / g

    def rhs(t, s):
        return [zdot(t, s[0])]

    def force(t, s):
        v = A * omega * np.cos(omega * t)
        return s0 * s[0] + s1 * zdot(t, s[0]) + s2 * v

    return rhs, force


def peer_df(make, p: dict, A: float, omega: float, method: str, rtol: float,
            periods: int) -> complex:
    """``D`` from ``solve_ivp`` over `periods` periods from rest, last period projected."""
    rhs, force = make(p, A, omega)
    T = TWO_PI / omega
    t = (periods - 1) * T + np.arange(N_EVAL) * (T / N_EVAL)
    sol = solve_ivp(rhs, (0.0, periods * T), [0.0], method=method, rtol=rtol,
                    atol=rtol * 1e-3, t_eval=t)
    w = force(sol.t, sol.y)
    theta = omega * t
    b1 = 2.0 * np.mean(w * np.sin(theta))
    a1 = 2.0 * np.mean(w * np.cos(theta))
    return complex(b1, a1) / A


def reference_df(make, p: dict, A: float, omega: float, z_bound: float) -> complex:
    """``D`` of the exactly periodic state: DOP853, rtol 1e-12, shooting for ``z(T) = z(0)``.

    Running periods from rest is not enough for a reference: at small amplitudes
    a Bouc-Wen loop forgets its start only over hundreds of periods.
    """
    rhs, force = make(p, A, omega)
    T = TWO_PI / omega
    kw = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-15 * z_bound}

    def period_map(z0: float) -> float:
        return solve_ivp(rhs, (0.0, T), [z0], **kw).y[0, -1] - z0

    # the state decays towards the bound from beyond it, so the period map changes sign over
    # +-1.5 bound; at the bound itself it is zero up to the integrator's round-off (1e-13 at
    # large amplitudes), of either sign
    z0 = brentq(period_map, -1.5 * z_bound, 1.5 * z_bound, xtol=1e-15 * z_bound)

    def with_projection(t, s):  # the Fourier integrals as two more states, no sampling error
        w = force(t, s)
        return [rhs(t, s)[0], w * np.sin(omega * t), w * np.cos(omega * t)]

    kw["atol"] = [kw["atol"], 1e-15 * z_bound * T, 1e-15 * z_bound * T]
    b1, a1 = solve_ivp(with_projection, (0.0, T), [z0, 0.0, 0.0], **kw).y[1:, -1]
    return complex(b1, a1) * (2.0 / (T * A))


def run(label: str, make, p: dict, points: list[tuple[float, float]], motionhyst_df,
        z_bound: float) -> dict:
    idx = np.linspace(0, len(points) - 1, PEER_POINTS).round().astype(int)
    sub = [points[i] for i in idx]
    ref = np.array([reference_df(make, p, A, om, z_bound) for A, om in sub])
    out = {"label": label, "points": len(points)}
    for rtol in (1e-6, 1e-9):
        t0 = time.perf_counter()
        D = np.array([peer_df(make, p, A, om, "RK45", rtol, PEER_PERIODS) for A, om in sub])
        dt = (time.perf_counter() - t0) / len(sub)
        out[f"peer rtol={rtol:g}"] = (dt, float(np.max(np.abs(D - ref) / np.abs(ref))))
    motionhyst_df(points[:2])  # compile and warm up on other inputs than the timed ones
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        D_all = motionhyst_df(points)
        times.append((time.perf_counter() - t0) / len(points))
    err = float(np.max(np.abs(D_all[idx] - ref) / np.abs(ref)))
    out["motionhyst"] = (statistics.median(times), err)
    return out


def bouc_wen_points() -> list[tuple[float, float]]:
    return [(float(A), TWO_PI * BOUC_WEN_FREQUENCY) for A in BOUC_WEN_AMPLITUDES]


def lugre_points() -> list[tuple[float, float]]:
    return [(LUGRE_AMPLITUDE, TWO_PI * float(f)) for f in LUGRE_FREQUENCIES]


def motionhyst_bouc_wen(points):
    return np.asarray(BoucWen(**BOUC_WEN).describing_function(np.array([a for a, _ in points])))


def motionhyst_lugre(points):
    el = LuGre(**LUGRE)
    return np.asarray(el.describing_function(np.array([a for a, _ in points]),
                                             np.array([om for _, om in points])))


def fmt(s: float) -> str:
    return f"{s * 1e3:.3g} ms" if s < 1 else f"{s:.3g} s"


def main() -> int:
    rows = []
    bw_bound = (BOUC_WEN["beta"] + BOUC_WEN["gamma"]) ** (-1.0 / BOUC_WEN["n"])
    lugre_bound = max(LUGRE["fc"], LUGRE["fs"]) / LUGRE["sigma0"]
    for label, make, p, pts, mh, bound in (
            (f"Bouc-Wen {BOUC_WEN}, 200 amplitudes 0.1-100 mm", bouc_wen_rhs, BOUC_WEN,
             bouc_wen_points(), motionhyst_bouc_wen, bw_bound),
            (f"LuGre {LUGRE}, A = 10 mm, 200 frequencies 1-1000 Hz", lugre_rhs, LUGRE,
             lugre_points(), motionhyst_lugre, lugre_bound)):
        print(f"running {label.split()[0]} ...", file=sys.stderr, flush=True)
        with np.errstate(over="ignore", invalid="ignore"):  # trial steps of the peers
            rows.append(run(label, make, p, pts, mh, bound))
    print("motionhyst benchmark: numerical describing functions, per point "
          "(error: max |D - D_ref| / |D_ref| over "
          f"{PEER_POINTS} points, D_ref periodic by shooting, DOP853 rtol=1e-12)")
    for r in rows:
        print()
        print(r["label"])
        mt, me = r["motionhyst"]
        print(f"  {'':<32} {'time/point':>10}  {'error':>8}  peer/motionhyst: time, error")
        for key in ("peer rtol=1e-06", "peer rtol=1e-09", "motionhyst"):
            t, e = r[key]
            name = key.replace("peer", "scipy solve_ivp RK45")
            ratios = "" if key == "motionhyst" else f"  {t / mt:6.0f}x, {e / me:8.1e}x"
            print(f"  {name:<32} {fmt(t):>10}  {e:8.1e}{ratios}")
        print(f"  200 points with motionhyst: {fmt(200 * mt)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
