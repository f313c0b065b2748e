"""Benchmark: motionhyst against a python-control simulation of the paper's Table I loop.

One run measures, for the reference ``r = 0.01 sin(2 pi 10 t)``:

1. the peer: the loop built as a python-control user would build it (the Jenkins
   element as the ODE of eq. (3) in a ``control.nlsys`` driven by ``y1'``, the
   two-mass stage and the eq. (23) controller as state-space systems, rigid-body
   feedforward ``M r''`` as an input signal, all joined by ``control.interconnect``)
   simulated for 0.5 s from rest with ``control.input_output_response``, once with
   the default solver settings and once with ``rtol=1e-6``; the inputs are given
   every 2e-7 s (python-control interpolates them linearly, which biases the
   error's first harmonic by ``(omega dt)^2/12 * A``, 4e-6 relative here) and
   ``t_eval`` is a uniform 1e-5 s grid;
2. motionhyst: ``periodic_steady_state`` per point, a 200-point
   ``steady_state_sweep`` over 1-100 Hz, and ``simulate`` of 1 s;
3. wall times (``time.perf_counter``), the relative error in the first harmonic of
   the tracking error ``e = r - y2``, and the ratios peer / motionhyst.

The reference value is motionhyst's converged ``periodic_steady_state(loop, 0.01,
10.0).e[1]``; the steady state's own error is taken against a run with
``tol=1e-16`` and twice the harmonics.

Run with ``make bench`` or ``python benchmarks/run.py [--json] [--peer-cap S]``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import textwrap
import time
import warnings

import control as ct
import numpy as np
import scipy

import motionhyst
from motionhyst import (
    Jenkins,
    LeadLagLowpass,
    Loop,
    TwoMassStage,
    periodic_steady_state,
    steady_state_sweep,
)
from motionhyst.analysis.steady import default_harmonics
from motionhyst.time.references import SineReference
from motionhyst.time.simulation import default_step, simulate

# Table I
M1, M2, B, K = 5.0, 17.5, 90.0, 7.4e7
KJ, FC = 20.0, 0.05
CONTROLLER = (6.2e6, 60.0, 240.0, 700.0, 0.6)
AMPLITUDE, FREQUENCY = 0.01, 10.0

PEER_DURATION = 0.5      # s, from rest
PEER_INPUT_DT = 2e-7     # s, grid of the input signals (python-control interpolates linearly)
PEER_EVAL_EVERY = 50     # t_eval = every 50th input sample (1e-5 s)
SIM_DURATION = 1.0       # s
SWEEP = np.geomspace(1.0, 100.0, 200)
N_HARMONICS_FIT = 9
STEADY_REPEATS = 50      # >= 20
SIM_REPEATS = 3
SWEEP_REPEATS = 3


class PeerCapped(Exception):
    """The peer simulation ran past its wall-time cap."""


class JenkinsODE:
    """Eq. (3) as a python-control user writes it, with call counters for the report.

    ``dw/dt = kJ/2 xdot {1 - sign(w^2 - fc^2) - sign(xdot w) (1 + sign(w^2 - fc^2))}``
    """

    def __init__(self, k: float, fc: float, deadline: float) -> None:
        self.k, self.fc, self.deadline = k, fc, deadline
        self.calls = 0
        self.regime_flips = 0   # changes of sign(w^2 - fc^2) between successive calls
        self._last = 0.0
        self.t_reached = 0.0

    @staticmethod
    def _sign(v: float) -> float:
        return float(v > 0.0) - float(v < 0.0)

    def updfcn(self, t, x, u, params):
        self.calls += 1
        if self.calls % 256 == 0 and time.perf_counter() > self.deadline:
            raise PeerCapped
        self.t_reached = max(self.t_reached, float(t))
        w, xdot = float(x[0]), float(u[0])
        s = self._sign(w * w - self.fc * self.fc)
        if s != self._last:
            self.regime_flips += 1
            self._last = s
        return np.array([0.5 * self.k * xdot * (1.0 - s - self._sign(xdot * w) * (1.0 + s))])

    def outfcn(self, t, x, u, params):
        if time.perf_counter() > self.deadline:
            raise PeerCapped
        return x[:1]


def build_peer(element: JenkinsODE) -> ct.InterconnectedSystem:
    """The Table I loop as python-control objects joined by ``control.interconnect``."""
    P = TwoMassStage(M1, M2, B, K).ss()  # state (y1, y2, y1', y2'), input u - w
    plant = ct.ss(P.A, P.B, np.vstack([P.C, [[0.0, 0.0, 1.0, 0.0]]]), np.zeros((3, 1)),
                  inputs="f", outputs=["y1", "y2", "y1dot"], name="plant")
    controller = ct.ss(LeadLagLowpass(*CONTROLLER), inputs="e", outputs="u_fb", name="C")
    jenkins = ct.nlsys(element.updfcn, element.outfcn, inputs="y1dot", outputs="w",
                       states="w", name="jenkins")
    error = ct.summing_junction(["r", "-y2"], "e", name="error")
    force = ct.summing_junction(["u_fb", "u_ff", "-w"], "f", name="force")
    return ct.interconnect([plant, controller, jenkins, error, force],
                           inputs=["r", "u_ff"], outputs=["e", "y1", "y2", "w"])


def first_harmonic(t, x, f: float, t_end: float, periods: int = 1) -> complex:
    """First harmonic of `x` over ``[t_end - periods/f, t_end)`` (complex, relative to sin).

    Least-squares fit of a mean and harmonics 1..9 of `f`.
    """
    t = np.asarray(t)
    dt = float(np.median(np.diff(t)))
    t0 = t_end - periods / f
    m = (t >= t0 - dt / 2) & (t < t_end - dt / 2)
    tt = t[m]
    th = 2.0 * np.pi * f * tt
    cols = [np.ones_like(tt)]
    for n in range(1, N_HARMONICS_FIT + 1):
        cols += [np.sin(n * th), np.cos(n * th)]
    c, *_ = np.linalg.lstsq(np.column_stack(cols), np.asarray(x)[m], rcond=None)
    return complex(c[1], c[2])  # a sin + b cos = Im((a + jb) e^{j theta})


def run_peer(label: str, solve_ivp_kwargs: dict | None, cap_s: float, ref: complex) -> dict:
    """One python-control simulation of 0.5 s from rest; its e1 against `ref`."""
    start = time.perf_counter()
    element = JenkinsODE(KJ, FC, start + cap_s)
    T = np.linspace(0.0, PEER_DURATION, round(PEER_DURATION / PEER_INPUT_DT) + 1)
    t_eval = T[::PEER_EVAL_EVERY]
    omega = 2.0 * np.pi * FREQUENCY
    r = AMPLITUDE * np.sin(omega * T)
    U = np.vstack([r, -(M1 + M2) * omega**2 * r])  # (r, M r'')
    out = {"label": label, "solve_ivp_kwargs": solve_ivp_kwargs or {}, "capped": False}
    kwargs = {} if solve_ivp_kwargs is None else {"solve_ivp_kwargs": solve_ivp_kwargs}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            sys_ = build_peer(element)
            res = ct.input_output_response(sys_, T, U, X0=0.0, t_eval=t_eval, **kwargs)
        except PeerCapped:
            res = None
    out["wall_s"] = time.perf_counter() - start
    out["warnings"] = sorted({f"{w.category.__name__}: {w.message}" for w in caught})
    out["rhs_calls"] = element.calls
    out["regime_flips"] = element.regime_flips
    if res is None:
        out.update(capped=True, t_reached_s=element.t_reached, e1=None, rel_error=None)
        return out
    e, w = res.outputs[0], res.outputs[3]
    e1 = first_harmonic(t_eval, e, FREQUENCY, PEER_DURATION)
    e1_prev = first_harmonic(t_eval, e, FREQUENCY, PEER_DURATION - 1.0 / FREQUENCY)
    out.update(
        e1=e1,
        rel_error=abs(e1 - ref) / abs(ref),
        period_change=abs(e1 - e1_prev) / abs(ref),
        w_overshoot=float(np.max(np.abs(w)) - FC),
        success=bool(getattr(res, "success", True)),
    )
    return out


def time_median(fn, repeats: int) -> tuple[float, object]:
    """Median wall time of `repeats` calls and the last result."""
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def truth(loop: Loop, f: float):
    """Steady state with tol=1e-16 and doubled harmonics (the accuracy reference)."""
    return periodic_steady_state(loop, AMPLITUDE, f, tol=1e-16,
                                 n_harmonics=2 * default_harmonics(loop, f))


def run_motionhyst(loop: Loop, ref: complex) -> dict:
    out = {}
    exact = truth(loop, FREQUENCY).e[1]
    # steady state per point (warm-up: the reference computation)
    t_ss, ss = time_median(lambda: periodic_steady_state(loop, AMPLITUDE, FREQUENCY),
                           STEADY_REPEATS)
    out["steady"] = {"wall_s": t_ss, "repeats": STEADY_REPEATS,
                     "n_harmonics": ss.n_harmonics, "iterations": ss.iterations,
                     "e1": complex(ss.e[1]), "rel_error": abs(ss.e[1] - exact) / abs(exact)}
    # sweep
    t_sw, sweep = time_median(lambda: steady_state_sweep(loop, AMPLITUDE, SWEEP), SWEEP_REPEATS)
    exact_sweep = [truth(loop, float(f)).e[1] for f in SWEEP]
    errs = np.array([abs(s.e[1] - x) / abs(x) for s, x in zip(sweep, exact_sweep, strict=True)])
    out["sweep"] = {"wall_s": t_sw, "points": len(SWEEP), "per_point_s": t_sw / len(SWEEP),
                    "repeats": SWEEP_REPEATS, "rel_error_max": float(errs.max()),
                    "rel_error_median": float(np.median(errs)),
                    "worst_frequency_hz": float(SWEEP[int(np.argmax(errs))])}
    # time simulation (numba compile excluded)
    reference = SineReference(AMPLITUDE, FREQUENCY)
    t0 = time.perf_counter()
    simulate(loop, reference, 0.05)
    compile_s = time.perf_counter() - t0
    t_sim, sim = time_median(lambda: simulate(loop, reference, SIM_DURATION), SIM_REPEATS)
    t_end = float(sim.t[-1])
    e1 = first_harmonic(sim.t, sim.e, FREQUENCY, t_end)
    e1_prev = first_harmonic(sim.t, sim.e, FREQUENCY, t_end - 1.0 / FREQUENCY)
    out["simulate"] = {"wall_s": t_sim, "repeats": SIM_REPEATS, "duration_s": SIM_DURATION,
                       "steps": len(sim.t), "dt_s": default_step(loop, FREQUENCY),
                       "first_call_s": compile_s, "e1": e1,
                       "rel_error": abs(e1 - ref) / abs(ref),
                       "period_change": abs(e1 - e1_prev) / abs(ref)}
    return out


def interp_bias(dt: float) -> float:
    """Relative loss of the first harmonic of a linearly interpolated sine sampled every `dt`."""
    return (2.0 * np.pi * FREQUENCY * dt) ** 2 / 12.0


def machine() -> dict:
    return {"platform": platform.platform(), "processor": platform.processor() or "?",
            "cpu_count": os.cpu_count(), "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__, "control": ct.__version__,
            "motionhyst": motionhyst.__version__}


def fmt_t(s: float) -> str:
    if s >= 1.0:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.2f} ms"
    return f"{s * 1e6:.0f} us"


def fmt_e(x: float | None) -> str:
    return "-" if x is None else f"{x:.1e}"


def ratio(a: float | None, b: float | None, lower_bound: bool = False) -> str:
    if a is None or b is None:
        return "-"
    if b == 0.0:
        return "inf"
    r = a / b
    text = f"{r:.1e}x" if r >= 1e5 else (f"{r:,.0f}x" if r >= 100 else f"{r:.1f}x")
    return ">" + text if lower_bound else text


def print_note(text: str) -> None:
    print(textwrap.fill(text, 100, initial_indent="- ", subsequent_indent="  "))


def print_table(res: dict) -> None:
    m, ref, mh = res["machine"], res["reference"], res["motionhyst"]
    peers = res["peer"]
    print("motionhyst benchmark: paper Table I loop, r = 0.01 sin(2 pi 10 t) m")
    print(f"machine: {m['platform']}, os.cpu_count() = {m['cpu_count']}, "
          f"processor {m['processor']}")
    print(f"software: Python {m['python']}, numpy {m['numpy']}, scipy {m['scipy']}, "
          f"python-control {m['control']}, motionhyst {m['motionhyst']}")
    e1 = ref["e1"]
    print(f"reference e1 = periodic_steady_state(loop, 0.01, 10.0).e[1] = "
          f"{e1.real:.6e}{e1.imag:+.6e}j m (|e1| = {abs(e1):.4e} m); "
          f"vs tol=1e-16, 2x harmonics: {ref['rel_error']:.1e}")
    print("error column: |e1 - e1_ref| / |e1_ref|, e1 = first harmonic of e = r - y2")
    print()
    rows = []
    for p in peers:
        note = (f"1 run, {PEER_DURATION:g} s from rest, {p['rhs_calls']} RHS calls, "
                f"{p['regime_flips']} slip-boundary flips")
        if p["capped"]:
            note += f"; CAPPED at {p['wall_s']:.0f} s (reached t = {p['t_reached_s']:.3f} s)"
        rows.append((f"peer: python-control, {p['label']}", fmt_t(p["wall_s"]),
                     fmt_e(p["rel_error"]), note))
    s, sw, si = mh["steady"], mh["sweep"], mh["simulate"]
    rows.append(("motionhyst periodic_steady_state, 1 point", fmt_t(s["wall_s"]),
                 fmt_e(s["rel_error"]),
                 f"median of {s['repeats']}; {s['n_harmonics']} harmonics, "
                 f"{s['iterations']} iterations"))
    rows.append(("motionhyst steady_state_sweep, per point", fmt_t(sw["per_point_s"]),
                 fmt_e(sw["rel_error_max"]),
                 f"{sw['points']} pts 1-100 Hz in {fmt_t(sw['wall_s'])} (median of "
                 f"{sw['repeats']}); error max (median {sw['rel_error_median']:.1e})"))
    rows.append((f"motionhyst simulate, {si['duration_s']:g} s", fmt_t(si["wall_s"]),
                 fmt_e(si["rel_error"]),
                 f"median of {si['repeats']}, {si['steps']} steps; first call "
                 f"{fmt_t(si['first_call_s'])} (excluded)"))
    w0 = max(len(r[0]) for r in rows)
    print(f"{'':<{w0}}  {'wall time':>10}  {'rel. error':>10}  notes")
    for name, t, e, note in rows:
        print(f"{name:<{w0}}  {t:>10}  {e:>10}  {note}")
    print()
    print("ratios peer / motionhyst (time per point; error)")
    heads = [p["label"] for p in peers]
    wr = max(len("simulate (1 s vs 0.5 s peer)"), 34)
    print(f"{'':<{wr}}" + "".join(f"  {'time, ' + h:>22}" for h in heads)
          + "".join(f"  {'error, ' + h:>22}" for h in heads))
    for name, t_m, e_m in (("periodic_steady_state (1 point)", s["wall_s"], s["rel_error"]),
                           ("steady_state_sweep (per point)", sw["per_point_s"],
                            sw["rel_error_max"]),
                           ("simulate (1 s vs 0.5 s peer)", si["wall_s"], si["rel_error"])):
        line = f"{name:<{wr}}"
        line += "".join(f"  {ratio(p['wall_s'], t_m, p['capped']):>22}" for p in peers)
        line += "".join(f"  {ratio(p['rel_error'], e_m):>22}" for p in peers)
        print(line)
    print()
    print("targets (issue 3)")
    default = next((p for p in peers if p["label"] == "RK45 default"), None)
    checks = [("one periodic steady-state point <= 5 ms", s["wall_s"] <= 5e-3, fmt_t(s["wall_s"])),
              ("sweep of 200 frequencies <= 1 s", sw["wall_s"] <= 1.0, fmt_t(sw["wall_s"])),
              (f"{si['duration_s']:g} s of transient simulation <= 0.2 s", si["wall_s"] <= 0.2,
               fmt_t(si["wall_s"]))]
    if default is not None and default["rel_error"] is not None:
        tr = default["wall_s"] / s["wall_s"]
        er = default["rel_error"] / s["rel_error"] if s["rel_error"] > 0 else np.inf
        checks.append(("per point >= 1000x faster than python-control (defaults)",
                       tr >= 1000, f"{tr:.3g}x"))
        checks.append(("per point >= 1000x more accurate than python-control (defaults)",
                       er >= 1000, f"{er:.3g}x"))
    for what, ok, value in checks:
        print(f"  [{'met' if ok else 'MISSED'}] {what}: {value}")
    print()
    print("notes:")
    tau = res["slowest_tau_s"]
    settle = ", ".join(f"{p['label']}: {fmt_e(p.get('period_change'))}" for p in peers)
    print_note(
        f"the peer runs {PEER_DURATION:g} s ({PEER_DURATION * FREQUENCY:g} periods) from rest "
        "(stage at rest while r starts with velocity 2 pi f A); its e1 is fitted over the last "
        "whole period, so it may not be fully settled. Change of e1 between the last two "
        f"periods (relative to |e1_ref|): {settle}. Slowest closed-loop pole: time constant "
        f"{tau * 1e3:.1f} ms, so a transient decays by "
        f"exp(-{(PEER_DURATION - 1.0 / FREQUENCY) / tau:.0f}) before that period.")
    A_e1 = AMPLITUDE / abs(e1)
    print_note(
        f"peer inputs r and M r'' are sampled every {PEER_INPUT_DT:g} s (python-control "
        f"interpolates them linearly); t_eval is every {PEER_EVAL_EVERY}th sample. At t_eval r "
        "is exact while y2 answers the interpolated inputs, whose first harmonic is "
        "(omega dt)^2/12 smaller: this biases e1 by (omega dt)^2/12 * A, "
        f"{interp_bias(PEER_INPUT_DT) * A_e1:.1e} relative here "
        f"({interp_bias(1e-5) * A_e1:.1e} with the inputs on a 1e-05 s grid).")
    print_note("peer times are single runs and include building the interconnection and "
               "python-control's output evaluation at t_eval.")
    for p in peers:
        if p.get("w_overshoot") is not None:
            print_note(f"peer {p['label']}: max |w| - fc = {p['w_overshoot']:.1e} N on the "
                       f"output grid; solve_ivp success = {p['success']}")
        for w in p["warnings"]:
            print_note(f"peer {p['label']} warning: {w}")
    print_note(f"simulate: e1 over the last period of {si['duration_s']:g} s; change between "
               f"the last two periods {si['period_change']:.1e}; dt = {si['dt_s']:.3g} s.")
    print_note("steady-state errors are against periodic_steady_state(tol=1e-16, 2x harmonics); "
               "peer and simulate errors against the reference e1 above.")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of the table")
    parser.add_argument("--peer-cap", type=float, default=300.0,
                        help="wall-time cap per peer simulation [s] (default 300)")
    parser.add_argument("--skip-peer", action="store_true", help="motionhyst only")
    args = parser.parse_args(argv)

    loop = Loop(TwoMassStage(M1, M2, B, K), LeadLagLowpass(*CONTROLLER), Jenkins(KJ, FC))
    ss_ref = periodic_steady_state(loop, AMPLITUDE, FREQUENCY)
    ref = complex(ss_ref.e[1])
    exact = complex(truth(loop, FREQUENCY).e[1])
    res = {
        "machine": machine(),
        "reference": {"e1": ref, "rel_error": abs(ref - exact) / abs(exact),
                      "frequency_hz": FREQUENCY, "amplitude": AMPLITUDE},
        "slowest_tau_s": float(1.0 / np.min(np.abs(loop.closed_loop_poles().real))),
    }
    peers = []
    if not args.skip_peer:
        for label, kw in (("RK45 default", None), ("RK45 rtol=1e-6", {"rtol": 1e-6})):
            if not args.json:
                print(f"running peer ({label}) ...", file=sys.stderr, flush=True)
            peers.append(run_peer(label, kw, args.peer_cap, ref))
    res["peer"] = peers
    if not args.json:
        print("running motionhyst ...", file=sys.stderr, flush=True)
    res["motionhyst"] = run_motionhyst(loop, ref)

    if args.json:
        def enc(o):
            if isinstance(o, complex):
                return {"re": o.real, "im": o.imag}
            if isinstance(o, np.generic):
                return o.item()
            raise TypeError(type(o).__name__)
        print(json.dumps(res, indent=2, default=enc))
    else:
        print_table(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
