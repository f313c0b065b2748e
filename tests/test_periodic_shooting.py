"""Periodic steady states by Newton's method on the period map (time/periodic_runs.py).

The shooting route (:func:`~motionhyst.time.periodic_runs.newton_periodic`, the default of
:func:`~motionhyst.time.openloop.simulate_elements`) must give what repeating the period
until it settles gives: the output to 1e-12 of its amplitude and the sensitivities to 1e-8
of theirs (the two routes' own tolerances), in far fewer periods on a lightly damped plant.
"""

from __future__ import annotations

import numpy as np
import pytest

from motionhyst.hysteresis import Dahl, Jenkins, LuGre, MaxwellSlip
from motionhyst.identify._element_sensitivities import row_derivatives
from motionhyst.time import periodic_runs
from motionhyst.time.openloop import MassSpringDamper, TwoMass, simulate_elements

FS = 750.0


def _odd_multisine(n: int, seed: int, rms: float) -> np.ndarray:
    rng = np.random.default_rng(seed)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    lines = np.arange(1, int(150 / (FS / n)) + 1, 2)
    spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spec, n)
    return u * rms / np.std(u)


def _counting(monkeypatch) -> list[int]:
    """Count the periods the open loop's compiled runs take (one run a period)."""
    import motionhyst.time.openloop as openloop

    calls = [0]
    real = openloop.run_steps

    def counted(*args, **kwargs):
        calls[0] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(openloop, "run_steps", counted)
    return calls


CASES = {
    # a floating two-mass stage on a link that holds it (the lightly damped in-phase mode)
    "two-mass, holding Jenkins": (TwoMass(2.0, 3.0, 20.0, 2e5),
                                  lambda v: Jenkins(k=v[0], fc=v[1]), [5e4, 20.0], 1.0),
    "two-mass, slipping Jenkins": (TwoMass(2.0, 3.0, 20.0, 2e5),
                                   lambda v: Jenkins(k=v[0], fc=v[1]), [5e4, 0.3], 1.0),
    "two-mass, Maxwell-slip": (TwoMass(2.0, 3.0, 20.0, 2e5),
                               lambda v: MaxwellSlip(k=list(v[:2]), fc=list(v[2:])),
                               [3e4, 2e4, 0.2, 1.0], 3.0),
    # a link that never slips keeps its preload: the state from rest has none
    "mass-spring-damper, holding Jenkins": (MassSpringDamper(1.0, 2.0, 4e4),
                                            lambda v: Jenkins(k=v[0], fc=v[1]), [1e4, 100.0],
                                            3.0),
    "mass-spring-damper, Dahl": (MassSpringDamper(2.0, 10.0, 5e4),
                                 lambda v: Dahl(k=v[0], fc=v[1]), [3e4, 0.5], 3.0),
    "mass-spring-damper, LuGre": (MassSpringDamper(2.0, 10.0, 5e4),
                                  lambda v: LuGre(sigma0=v[0], sigma1=v[1], sigma2=0.0,
                                                  fc=v[2], fs=v[3], vs=v[4]),
                                  [3e4, 30.0, 0.5, 0.8, 0.01], 3.0),
}


@pytest.mark.parametrize("name", list(CASES))
def test_shooting_gives_the_steady_state_of_repeated_periods(name):
    plant, build, values, rms = CASES[name]
    v = np.array(values, dtype=float)
    link, mech = build(v), plant.mechanics()
    dp = row_derivatives(build, v)
    u = _odd_multisine(390, 3, rms)
    args = (mech, link.time_stepping(), u, FS, 20)
    kw = {"periodic": True, "k_link": link.initial_stiffness, "dparams": dp}
    y_rep, s_rep = simulate_elements(*args, shooting=False, **kw)
    y_new, s_new = simulate_elements(*args, **kw)
    amp = np.ptp(y_rep)
    assert amp > 0
    assert np.max(np.abs(y_new - y_rep)) < 1e-11 * amp
    scale = np.max(np.abs(s_rep), axis=0)
    assert np.all(np.max(np.abs(s_new - s_rep), axis=0) <= 1e-7 * scale)
    # without sensitivities: the same output
    y_plain, _ = simulate_elements(*args, periodic=True, k_link=link.initial_stiffness)
    assert np.max(np.abs(y_plain - y_rep)) < 1e-11 * amp
    if mech.floating:
        assert abs(np.mean(y_new)) < 1e-12 * amp


def test_shooting_settles_a_lightly_damped_stage_in_two_periods(monkeypatch):
    """A link that holds: the period map is affine, Newton's first step lands on its fixed
    point, the second period confirms it; repeating the period takes many more."""
    plant, build, values, rms = CASES["two-mass, holding Jenkins"]
    v = np.array(values)
    link = build(v)
    u = _odd_multisine(390, 3, rms)
    args = (plant.mechanics(), link.time_stepping(), u, FS, 20)
    calls = _counting(monkeypatch)
    simulate_elements(*args, periodic=True, k_link=v[0], dparams=row_derivatives(build, v))
    assert calls[0] == 2
    calls[0] = 0
    simulate_elements(*args, periodic=True, k_link=v[0], dparams=row_derivatives(build, v),
                      shooting=False)
    assert calls[0] > 5


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("shooting", [True, False])
def test_a_zero_force_has_rest_as_its_steady_state_at_once(monkeypatch, name, shooting):
    """Rest repeats exactly: an output that stays zero has not changed (its change relative
    to an amplitude of zero was infinite, so the run went on to its last period and was
    reported as not reaching its steady state)."""
    plant, build, values, _ = CASES[name]
    v = np.array(values, dtype=float)
    link = build(v)
    calls = _counting(monkeypatch)
    y, sy = simulate_elements(plant.mechanics(), link.time_stepping(), np.zeros(390), FS, 20,
                              periodic=True, k_link=link.initial_stiffness,
                              dparams=row_derivatives(build, v), shooting=shooting)
    assert y.shape == (390,) and not np.any(y) and not np.any(sy)
    assert calls[0] <= 3


def test_newton_on_an_affine_map_with_a_gauge_finds_its_drift():
    """A floating state whose period map moves it on by 0.5 along the gauge: refused with the
    step; without the step, the fixed point (defined up to the gauge) is found."""
    A = np.array([[1.0, 0.3], [0.0, 0.5]])  # the first state is the gauge (eigenvalue 1)

    def affine(b):
        def run_period(z, S):
            t = np.linspace(0.0, 1.0, 9)
            y = z[0] + z[1] * np.sin(2 * np.pi * t)
            sy = np.column_stack([np.ones(9), np.sin(2 * np.pi * t)])
            return y, sy, A @ z + b, A.copy()
        return run_period

    with pytest.raises(ValueError, match=r"drifts 0\.5 m per period"):
        periodic_runs.newton_periodic(affine(np.array([0.5 - 0.3 * 2.0, 1.0])), np.zeros(2),
                                      0, 5, True)
    y, _ = periodic_runs.newton_periodic(affine(np.array([-0.6, 1.0])), np.zeros(2), 0, 5,
                                         True)
    t = np.linspace(0.0, 1.0, 9)[:-1]
    ref = 2.0 * np.sin(2 * np.pi * t)  # z[1] = 1 / (1 - 0.5)
    np.testing.assert_allclose(y, ref - np.mean(ref), rtol=0, atol=1e-12)


def test_a_floating_stage_without_a_link_closes_its_period_by_its_momentum(monkeypatch):
    """No link: the position is free and the momentum conserved (a rigid body); the steady
    state is the one whose mean velocity closes the period: that of the record's spectrum
    line by line (to the integration's accuracy; repeating the period from rest keeps the
    start's mean velocity and never settles)."""
    from motionhyst.hysteresis.stepping import Stepping
    from motionhyst.time.periodic_runs import floating_linear_periodic

    mech = TwoMass(2.0, 3.0, 20.0, 2e5).mechanics()
    u = _odd_multisine(390, 5, 1.0)
    calls = _counting(monkeypatch)
    y_new, _ = simulate_elements(mech, Stepping.empty(), u, FS, 20, periodic=True)
    assert calls[0] <= 3
    y_spec = floating_linear_periodic(mech, u, FS)
    amp = np.ptp(y_spec)
    assert np.max(np.abs(y_new - y_spec)) < 1e-5 * amp  # 9.5e-7 at 20 steps a sample
    # a force with a mean moves it on: no steady state
    with pytest.raises(ValueError, match="steady state"):
        simulate_elements(mech, Stepping.empty(), u + 0.1, FS, 20, periodic=True)


def test_the_noise_a_periodic_record_leaves_from_its_periods_spread():
    """identify's starts end at a fit to the records' own noise (io_elements): its variance
    from the spread of the periods about their mean, here within 5 % of the noise drawn."""
    from motionhyst.identify.io_checks import NOISE_COST_FACTOR, noise_cost
    from motionhyst.identify.io_records import IORecord

    n, periods, sigma = 390, 8, 2e-3
    u = np.tile(_odd_multisine(n, 3, 1.0), periods)
    shape = np.tile(np.sin(2 * np.pi * np.arange(n) / n), periods)
    y = shape + sigma * np.random.default_rng(1).standard_normal(u.size)
    rec = IORecord(np.arange(u.size) / FS, u, y, "r")
    cost = noise_cost([rec], 0.5)
    expected = 0.5 * NOISE_COST_FACTOR * u.size * sigma ** 2 / 0.5 ** 2
    assert abs(cost / expected - 1) < 0.05
    # a record of one period (or not periodic) says nothing about its noise
    one = IORecord(rec.t[:n], u[:n], y[:n], "one")
    assert noise_cost([one], 0.5) is None
