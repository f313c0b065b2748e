"""Forward sensitivities of the open-loop element simulation (openloop.simulate_elements)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from motionhyst.core.lti import expm_small
from motionhyst.hysteresis import Dahl, Jenkins, LuGre, MaxwellSlip, model_class
from motionhyst.identify._element_sensitivities import row_derivatives
from motionhyst.identify.io_elements import _LinkLayout
from motionhyst.time.openloop import (
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    fine_input,
    simulate_elements,
)

FS = 750.0
R = 10
STAGE = (2.0, 10.0, 5e4)
LINKS = {
    "jenkins": (Jenkins(k=2e4, fc=10.0), [2e4, 10.0]),
    "maxwell-slip": (MaxwellSlip(k=[2e4, 3e4], fc=[4.0, 15.0]), [2e4, 3e4, 4.0, 15.0]),
    "dahl": (Dahl(k=2e4, fc=10.0), [2e4, 10.0, 1.0]),
    "dahl-1.7": (Dahl(k=2e4, fc=10.0, alpha=1.7), [2e4, 10.0, 1.7]),
    "lugre": (LuGre(sigma0=2e4, sigma1=30.0, sigma2=0.0, fc=5.0, fs=8.0, vs=0.02),
              [2e4, 30.0, 5.0, 8.0, 0.02]),
}


def _force(n: int) -> np.ndarray:
    rng = np.random.default_rng(1)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(int(5 / (FS / n)), int(150 / (FS / n)) + 1)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return 50.0 * u / np.std(u)


def _simulate(values: np.ndarray, layout: _LinkLayout, u: np.ndarray, periodic: bool,
              fine: np.ndarray) -> np.ndarray:
    system = OpenLoop(MassSpringDamper(*values[:3]), layout.build(values[3:]))
    return system._simulate_elements(u, FS, R, periodic, fine)


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("name", list(LINKS))
def test_sensitivities_agree_with_central_differences(name, periodic):
    link, values = LINKS[name]
    layout = _LinkLayout.of(model_class(name.split("-1")[0]), 2)
    v = np.array(values)
    u = _force(256)
    fine = fine_input(u, R, periodic)
    dparams = row_derivatives(layout.build, v)
    y, dy = simulate_elements(MassSpringDamper(*STAGE).mechanics(), link.time_stepping(), u,
                              FS, R, periodic=periodic, k_link=link.initial_stiffness,
                              upsampled=fine, dparams=dparams)
    # the output is the simulation's, to rounding: bit for bit (one compiled run, the
    # sensitivities beside it)
    t = np.arange(u.size) / FS
    ref = OpenLoop(MassSpringDamper(*STAGE), link).simulate(t, u, periodic=periodic,
                                                             substeps=R).displacement
    assert np.max(np.abs(y - ref)) < 1e-12 * np.max(np.abs(ref))
    assert np.array_equal(y, ref)
    full = np.concatenate([STAGE, v])
    for b in range(full.size):
        step = 1e-6 * abs(full[b])
        hi, lo = full.copy(), full.copy()
        hi[b] += step
        lo[b] -= step
        fd = (_simulate(hi, layout, u, periodic, fine)
              - _simulate(lo, layout, u, periodic, fine)) / (2 * step)
        # central differences err by ~1e-7 of the largest value (truncation, rounding)
        assert np.max(np.abs(dy[:, b] - fd)) < 2e-6 * np.max(np.abs(fd)), (name, b)


TWO_MASS = (2.0, 3.0, 20.0, 2e5)  # internal mode at 65 Hz, in the band
TWO_MASS_LINKS = {
    "jenkins": (Jenkins(k=5e4, fc=60.0), [5e4, 60.0]),
    "dahl": (Dahl(k=5e4, fc=20.0, alpha=1.5), [5e4, 20.0, 1.5]),
    "lugre": (LuGre(sigma0=5e4, sigma1=30.0, sigma2=0.0, fc=40.0, fs=60.0, vs=0.02),
              [5e4, 30.0, 40.0, 60.0, 0.02]),
}


@pytest.mark.parametrize("output", ["y2", "y1"])
@pytest.mark.parametrize("name", list(TWO_MASS_LINKS))
def test_two_mass_sensitivities_agree_with_central_differences(name, output):
    """The same compiled run on the floating two-mass stage (eqs. 1-2), from rest: the link
    on m1, the output y2 or y1; derivatives in m1, m2, b, k and the link's parameters."""
    link, values = TWO_MASS_LINKS[name]
    layout = _LinkLayout.of(model_class(name), 2)
    plant = TwoMass(*TWO_MASS, output=output)
    v = np.array(values)
    u = _force(256)
    fine = fine_input(u, R, False)
    y, dy = simulate_elements(plant.mechanics(), link.time_stepping(), u, FS, R,
                              periodic=False, k_link=link.initial_stiffness, upsampled=fine,
                              dparams=row_derivatives(layout.build, v))
    t = np.arange(u.size) / FS
    assert np.array_equal(y, OpenLoop(plant, link).simulate(t, u, substeps=R).displacement)
    full = np.concatenate([TWO_MASS, v])
    assert dy.shape == (u.size, full.size)
    for b in range(full.size):
        step = 1e-6 * abs(full[b])
        hi, lo = full.copy(), full.copy()
        hi[b] += step
        lo[b] -= step
        fd = [OpenLoop(plant.with_parameters(p[:4]), layout.build(p[4:]))._simulate_elements(
            u, FS, R, False, fine) for p in (hi, lo)]
        fd = (fd[0] - fd[1]) / (2 * step)
        assert np.max(np.abs(dy[:, b] - fd)) < 2e-6 * np.max(np.abs(fd)), (name, b)


def test_expm_small_and_the_stage_derivatives():
    M = np.array([[0.0, 1e-4, 0.0, 0.0], [-2.5, -5e-4, 5e-5, 0.0], [0.0, 0.0, 0.0, 1.0],
                  [0.0, 0.0, 0.0, 0.0]])
    np.testing.assert_allclose(expm_small(M), expm(M), rtol=1e-14, atol=1e-15)
    big = 300.0 * np.eye(3) + np.diag([1.0, 2.0], 1)  # scaled and squared many times
    np.testing.assert_allclose(expm_small(big), expm(big), rtol=1e-13)
    h = 1.0 / (FS * R)
    Ad, B0, B1, dAd, dB0, dB1 = MassSpringDamper(*STAGE).mechanics().foh(h, derivatives=True)
    m, c, k = STAGE
    M = np.zeros((4, 4))
    M[:2, :2] = np.array([[0.0, 1.0], [-k / m, -c / m]]) * h
    M[:2, 2] = np.array([0.0, 1.0 / m]) * h
    M[2, 3] = 1.0
    E = expm(M)  # the stage's first-order hold by scipy's exponential
    for got, ref in ((Ad, E[:2, :2]), (B0, E[:2, 2] - E[:2, 3]), (B1, E[:2, 3])):
        np.testing.assert_allclose(got, ref, rtol=1e-14, atol=1e-15 * np.max(np.abs(ref)))
    for a in range(3):
        p_hi, p_lo = list(STAGE), list(STAGE)
        p_hi[a] *= 1 + 1e-6
        p_lo[a] *= 1 - 1e-6
        hi = MassSpringDamper(*p_hi).mechanics().foh(h)
        lo = MassSpringDamper(*p_lo).mechanics().foh(h)
        span = 2e-6 * STAGE[a]
        for got, k in ((dAd[a], 0), (dB0[a], 1), (dB1[a], 2)):
            fd = (hi[k] - lo[k]) / span
            np.testing.assert_allclose(got, fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(fd)))


def test_an_element_kind_without_sensitivities_falls_back():
    from motionhyst.hysteresis import BoucWen

    def build(v):
        return BoucWen(k=v[0], fc=v[1])

    assert row_derivatives(build, np.array([2e4, 10.0])) is None
