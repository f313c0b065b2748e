"""Standard errors of closed-loop fits that a user can trust (issue 21, "honest results").

The link force inferred from a closed-loop record is ``L u - (L / P1) y1``: white noise on
the force ``u`` comes out of the prefilter ``L`` coloured, correlated over tens of the fit's
samples, and standard errors computed as for white residuals put the true slip force up to
19 of them away (the paper's loop with a Jenkins link, 1 N of noise on ``u``: on main,
``|fc - 0.05| <= 3 std`` in 11 of 20 seeds).  With the residuals' autocorrelation in the
covariance (Newey-West, :class:`~motionhyst.identify.residual_noise.ResidualCorrelation`)
19 of 20 are (the 20th a fit whose element became a Coulomb slider, k not determined), and
noise on the position alone keeps its coverage without widening much."""

import math
import warnings

import numpy as np
import pytest

from motionhyst import Jenkins, Loop, SineReference, default_scenario, simulate
from motionhyst.identify import identify_closed_loop

K, FC = 20.0, 0.05


@pytest.fixture(scope="module")
def run():
    sc = default_scenario()
    sim = simulate(Loop(sc.plant(), sc.controller(), Jenkins(k=K, fc=FC)),
                   SineReference(0.01, 2.0), 2.0, dt=1e-4)
    return sc, sim


def _fits(run, sigma_y, sigma_u, seeds):
    sc, sim = run
    out = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        y1 = sim.y1 + sigma_y * rng.standard_normal(sim.y1.size)
        u = sim.u + sigma_u * rng.standard_normal(sim.u.size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out.append(identify_closed_loop(sim.t, y1, u, sc.plant(), n_elements=1))
    return out


def test_force_noise_through_the_prefilter_is_covered(run):
    """1 N of white noise on u (seeds 1-8): main had the true fc within 3 standard errors in 4
    of 8 (z = 1.3, -4.2, -6.6, 2.5, -0.5, -1.9, -3.8, 8.8), k in 5; now in every seed (|z| at
    most 2.2 for fc, 2.5 for k), the standard errors 3-5 times wider."""
    fits = _fits(run, 0.0, 1.0, range(1, 9))
    z_fc = [(f.elements[0]["fc"] - FC) / f.elements[0]["fc_std"] for f in fits]
    z_k = [(f.elements[0]["k"] - K) / f.elements[0]["k_std"] for f in fits]
    assert sum(abs(z) <= 3 for z in z_fc) >= 7, z_fc
    assert sum(abs(z) <= 3 for z in z_k) >= 7, z_k
    assert max(map(abs, z_fc)) < 4.5 and max(map(abs, z_k)) < 4.5
    # not made true by being vague: the slip force still to 20 % (its std about 14 %)
    assert all(f.elements[0]["fc_std"] < 0.2 * FC for f in fits)
    # the covariance carries the same standard errors
    for f in fits:
        cov = f.covariance
        i = cov["parameters"].index("fc")
        assert math.sqrt(cov["matrix"][i][i]) == pytest.approx(f.elements[0]["fc_std"],
                                                               rel=1e-9)
        assert f.std_lower_bound is None  # the residuals are the records' noise


def test_position_noise_keeps_its_coverage(run):
    """0.5 um of white noise on y1 (seeds 0-5): covered (|z| <= 1.6 on main, 1.1 now).  The
    noise through L / P1 alternates from sample to sample, and Andrews' lags alone (main) made
    fc's standard error 0.7-0.8 of white residuals' (0.57-0.69e-3 against 0.74-0.88e-3);
    no standard error is narrower than white residuals' or the fixed rule's now
    (residual_noise.newey_west_lags), which is wider here: k 1.15-1.37 (white 0.61-0.72, main
    0.79-0.94), fc 1.17-1.38e-3 (scratch-nw17/cl_position.py)."""
    fits = _fits(run, 5e-7, 0.0, range(6))
    for f in fits:
        e = f.elements[0]
        assert abs(e["fc"] - FC) <= 3 * e["fc_std"]
        assert abs(e["k"] - K) <= 3 * e["k_std"]
        assert e["k_std"] >= f.judged_std["k[0]"] and e["fc_std"] >= f.judged_std["fc[0]"]
        assert e["k_std"] < 2.0  # measured 1.15-1.37: not widened beyond the fixed rule's
        assert e["fc_std"] < 2e-3


def test_a_link_the_fit_cannot_describe_says_its_standard_errors_are_lower_bounds():
    """A three-element Maxwell-slip link fitted with one element (13.8 % of the prefiltered
    force left, 1 nm of noise on y1): the fit leaves 130 times what the records' white noise
    leaves in that force (9.2e-5 N; the median absolute deviation of the third differences:
    their mean square takes the controller's fast action on u for noise, 0.35 N, and did not
    flag it; 0.0038 N, 3.1 times, on main, which took the filters' response to an impulse on
    the first sample, where they start in steady state, for the noise's).  The standard errors
    are marked lower bounds by a line of the printed result, not by a warning, and the saved
    scenario says so; the element's k and fc stay determined."""
    from motionhyst import MaxwellSlip

    sc = default_scenario()
    sim = simulate(Loop(sc.plant(), sc.controller(),
                        MaxwellSlip(k=[20.0, 10.0, 5.0], fc=[0.02, 0.05, 0.1])),
                   SineReference(0.01, 2.0), 2.0, dt=1e-4)
    y1 = sim.y1 + 1e-9 * np.random.default_rng(0).standard_normal(sim.y1.size)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning
        ident = identify_closed_loop(sim.t, y1, sim.u, sc.plant(), n_elements=1)
    note = ident.std_lower_bound
    assert note is not None and note.startswith("standard errors are lower bounds: the fit ")
    times = float(note.split("leaves ")[1].split(" times")[0])
    assert 80.0 < times < 200.0  # measured 130
    text = str(ident)
    assert f"  {note}" in text.splitlines() and ">= " in text
    assert ident.to_dict()["std_lower_bound"] is True
    assert "# standard errors are lower bounds" in ident.scenario_text()
    e = ident.elements[0]
    assert math.isfinite(e["k_std"]) and math.isfinite(e["fc_std"])
    assert e["fc_std"] > ident.judged_std["fc[0]"]  # widened; judged on the white one


@pytest.mark.parametrize("link", ["dahl", "bouc-wen"])
def test_a_smooth_link_fitted_with_one_element_says_its_standard_errors_are_lower_bounds(link):
    """A Dahl (or Bouc-Wen) link of Table I's loop fitted with one Jenkins element (1 nm of
    noise on y1): the model is not the record's, yet main did not mark its standard errors
    (std16's notes): it compared the fit's 0.0048 N (0.0035 N for Bouc-Wen) with 0.0038 N,
    the response of L / P1 to an impulse on the first sample, where the filters start in
    steady state (a step that was on before the record: 40 times the noise's response).  The
    noise that the prefiltered force of pure white noise on y1 shows after the start-up
    (8.5-9.5e-5 N, three draws) is what the line now compares the fit with: 52 times (38)."""
    from motionhyst import BoucWen, Dahl
    from motionhyst.identify import closed_loop

    sc = default_scenario()
    model = Dahl(k=20.0, fc=0.05) if link == "dahl" else BoucWen(k=20.0, fc=0.05, n=1.0)
    sim = simulate(Loop(sc.plant(), sc.controller(), model), SineReference(0.01, 2.0), 2.0,
                   dt=1e-4)
    y1 = sim.y1 + 1e-9 * np.random.default_rng(0).standard_normal(sim.y1.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the widened std's warning on the offset
        ident = identify_closed_loop(sim.t, y1, sim.u, sc.plant(), n_elements=1)
    note = ident.std_lower_bound
    assert note is not None and note.startswith("standard errors are lower bounds: the fit ")
    times = float(note.split("leaves ")[1].split(" times")[0])
    assert 20.0 < times < 100.0  # measured 52 (Dahl), 38 (Bouc-Wen)
    noise = float(note.split("white noise (")[1].split(" N")[0])
    lf, L_over_P1 = closed_loop._infer(sim.t, y1, sim.u, sc.plant(), None, None)
    pure = L_over_P1(1e-9 * np.random.default_rng(1).standard_normal(sim.y1.size))
    measured = float(np.sqrt(np.mean(pure[lf.settle_index:] ** 2)))
    assert noise == pytest.approx(measured, rel=0.2)  # main: 0.0038 N, 40 times
