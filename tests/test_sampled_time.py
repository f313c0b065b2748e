"""The sampled loop in time: against its exact steady state, closed-loop identification with
the known discrete controller, the EMPS benchmark's loop (issue 22)."""

from pathlib import Path

import numpy as np
import pytest

from motionhyst import Jenkins, LeadLagLowpass, Loop, MaxwellSlip, SineReference, TwoMassStage
from motionhyst.analysis.steady import periodic_steady_state
from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.sampled import SampledController
from motionhyst.controllers.two_dof import position_velocity_cascade
from motionhyst.identify import identify_closed_loop, infer_link_force
from motionhyst.plants.mass_damper import MassDamper
from motionhyst.time.sampled import simulate_sampled

C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)


def table_i_stage():
    return TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)

EMPS = Path(__file__).resolve().parents[2] / "shared" / "benchmarks" / "emps" / "DATA_EMPS.mat"


@pytest.mark.parametrize(("d", "ff", "hff"), [
    (1.5, Feedforward(advance_samples=2.0), None),
    (1.0, Feedforward(), None),
    (1.5, Feedforward(viscous=2.0, coulomb=0.03, advance_samples=2.0),
     MaxwellSlip([19.0], [0.048])),
])
def test_hybrid_steady_state_is_the_fine_step_run(d, ff, hff):
    """The exact steady state (harmonic balance with the samples' aliasing) against a run
    from rest of the hybrid loop, 80 fine steps per sample, the Jenkins link slipping; with
    the feedforward's friction terms and a hysteresis model too."""
    stage = table_i_stage()
    loop = Loop(stage, SampledController.discretize(C, 10e3, delay_samples=d),
                Jenkins(k=20.0, fc=0.05), feedforward=ff, hysteresis_feedforward=hff)
    f, N = 10.0, 1000
    ss = periodic_steady_state(loop, 0.01, f)
    sim = simulate_sampled(loop, SineReference(0.01, f), 1.0, substeps=80, linear=False)
    th = 2 * np.pi * f * sim.t[-N:]
    n = np.arange(1, ss.e.size)
    e_ss = ss.e[0].real + np.imag(ss.e[None, 1:] * np.exp(1j * n[None, :] * th[:, None])).sum(1)
    assert np.abs(sim.w[-N:]).max() == pytest.approx(0.05, rel=1e-9)   # the link slips
    assert np.abs(sim.e[-N:] - e_ss).max() < 1e-6 * np.abs(e_ss).max()


def test_u_max_is_honoured():
    loop = Loop(table_i_stage(), SampledController.discretize(C, 10e3, u_max=5.0),
                Jenkins(k=20.0, fc=0.05))
    sim = simulate_sampled(loop, SineReference(0.01, 5.0), 0.2)
    assert np.abs(sim.u).max() == pytest.approx(5.0, rel=1e-12)
    free = simulate_sampled(Loop(table_i_stage(), SampledController.discretize(C, 10e3),
                                 Jenkins(k=20.0, fc=0.05)), SineReference(0.01, 5.0), 0.2)
    assert np.abs(free.u).max() > 20.0


def test_closed_loop_identification_with_the_known_discrete_controller():
    stage = table_i_stage()
    cd = SampledController.discretize(C, 5e3, delay_samples=1.5)
    loop = Loop(stage, cd, MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]),
                feedforward=Feedforward(advance_samples=2.0))
    sim = simulate_sampled(loop, SineReference(0.01, 2.0), 1.5, substeps=20, linear=False)
    lf = infer_link_force(sim.t, sim.y1, sim.u, stage, controller=cd)
    i = lf.settle_index
    assert np.abs(lf.w[i:] - lf.lowpass(sim.w)[i:]).max() < 2e-3 * np.abs(sim.w).max()
    ident = identify_closed_loop(sim.t, sim.y1, sim.u, stage, controller=cd)
    assert np.allclose(ident.model.k, [10.0, 6.0], rtol=2e-3)
    assert np.allclose(ident.model.fc, [0.01, 0.03], rtol=2e-3)
    # taken as a continuous force (linear between samples) the delayed hold is missed
    blind = infer_link_force(sim.t, sim.y1, sim.u, stage)
    assert np.abs(blind.w[i:] - blind.lowpass(sim.w)[i:]).max() > np.abs(sim.w).max()


@pytest.mark.skipif(not EMPS.is_file(), reason="the EMPS benchmark's data are not beside the "
                    "repository (../shared)")
def test_emps_closed_loop_reproduces_the_measured_position():
    """The benchmark's cascade at 1 kHz around its reference model (mass, viscous and Coulomb
    friction, force offset; Janot, Gautier, Brunot 2019), driven by the recorded reference qg,
    reproduces the measured position better than the benchmark's own simulation (0.0138 %)."""
    from scipy.io import loadmat

    from motionhyst.hysteresis.coulomb import Coulomb
    from motionhyst.time.references import SampledReference

    data = loadmat(EMPS)
    qm, qg = data["qm"].ravel(), data["qg"].ravel()
    gtau, kp, kv = (float(data[k].ravel()[0]) for k in ("gtau", "kp", "kv"))
    M, Fv, Fc, OF = 95.1089, 203.5034, 20.3935, -3.1648
    c = position_velocity_cascade(kp=kp, kv=kv, gain=gtau, sample_rate_hz=1e3)
    loop = Loop(MassDamper(M, Fv), c, Coulomb(fc=Fc), feedforward=None)
    t = np.arange(qg.size) * 1e-3

    def offset(tt):   # -OF on the load, beside the drive's force (no delay in this loop)
        return np.full(np.shape(tt), -OF)

    sim = simulate_sampled(loop, SampledReference(t, qg), t[-1], force=offset,
                           x0=[qm[0], 0.0], linear=False)
    error = 100 * np.linalg.norm(qm - sim.y2) / np.linalg.norm(qm)
    assert error < 0.0138
    # the drive's output: the recorded vir against the controller's force / gtau
    vir = data["vir"].ravel()
    assert np.linalg.norm(vir - (sim.u + OF) / gtau) < 0.1 * np.linalg.norm(vir)


def test_ilc_learns_at_the_controllers_rate():
    from motionhyst.scan.ilc import learn
    from motionhyst.scan.profiles import point_to_point

    cd = SampledController.discretize(C, 10e3, delay_samples=1.5)
    loop = Loop(table_i_stage(), cd, Jenkins(20.0, 0.05),
                feedforward=Feedforward(advance_samples=2.0))
    p = point_to_point(0.005, 0.2, 20.0, 2000.0, 1e6, start=0.005)
    res = learn(loop, p, p.end + 0.02, trials=3)
    assert np.allclose(np.diff(res.t), cd.period)      # trials and force at the samples
    assert res.rms_errors[-1] < res.rms_errors[0] / 10
    with pytest.raises(ValueError, match="learns at its controller's period"):
        learn(loop, p, p.end + 0.02, trials=2, dt=1e-5)


def test_scan_of_a_sampled_loop():
    from motionhyst.scan.profiles import scan
    from motionhyst.scan.scanning import run_scan

    cd = SampledController.discretize(C, 10e3, delay_samples=1.5)
    loop = Loop(table_i_stage(), cd, Jenkins(20.0, 0.05),
                feedforward=Feedforward(advance_samples=2.0))
    p = scan(0.015, 0.05, 2.0, 50.0, 1000.0, rate_hz=10e3)
    res = run_scan(loop, p, 0.05, compensations=("none",))
    # the link slips in the acceleration and leaves fc / C(0) through the scan (8.06 nm), as
    # in the continuous loop; the digital loop's own error stays far below it
    assert res.runs[0].ma_max == pytest.approx(0.05 / 6.2e6, rel=0.01)
    assert res.without_link.ma_max < 0.01 * res.runs[0].ma_max
