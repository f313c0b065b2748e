"""A damped link's rates over fine steps of unequal length (issue 26, review B16 H1 and M1).

A sampled loop's run splits each controller period where the computation delay falls: at
10 kHz, 1.05 samples late, 3 fine steps of 4.75e-5, 4.75e-5 and 5e-6 s (1.95 samples: the
short step first).  LuGre's force takes its rates ``sigma1 z' + sigma2 v`` by the
second-order backward difference, whose weights assumed steps of one length: at each change
of length it misread the velocity (a short step after a long one: -3.25 times it), and the
first harmonic of the error of the paper's loop came out 90 % off a run of 60 fine steps a
sample, exit 0, no warning (3.1 % at 1.5 samples, 0.2 % at 1.37).  The weights are now those
of the two steps' actual lengths (``backward_weights``), at every delay, for every link whose
step has LuGre's rows (a LuGre link along the stroke too); numbers of equal steps and of links
without backward differences are unchanged to the bit.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_probe import probe

from motionhyst.hysteresis import LuGre

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SAMPLED = (EXAMPLES / "paper_10khz.toml").read_text()
JENKINS = 'model = "jenkins"\nk = 20.0\nfc = 0.05'


def _scenario(sigma2: float, delay: float, jenkins: bool = False) -> str:
    """The paper's loop at 10 kHz, `delay` samples late, with a LuGre link of `sigma2`."""
    assert JENKINS in SAMPLED and "delay_samples = 1.5" in SAMPLED
    link = JENKINS if jenkins else (f'model = "lugre"\nsigma0 = 20.0\nsigma1 = 0.0\n'
                                    f'sigma2 = {sigma2!r}\nfc = 0.05\nfs = 0.07\nvs = 0.1')
    return SAMPLED.replace(JENKINS, link).replace("delay_samples = 1.5",
                                                  f"delay_samples = {delay!r}")


def _loop(link: str, sigma2: float, delay: float):
    from motionhyst import Loop
    from motionhyst.hysteresis.along_stroke import AlongStroke
    from motionhyst.scenario import Scenario

    sc = Scenario.from_dict(tomllib.loads(_scenario(sigma2, delay, link == "jenkins")), "s")
    model = sc.hysteresis()
    if link == "along":  # the same physics (scales of 1) through the link along the stroke
        model = AlongStroke(model, [-1.0, 1.0], {"sigma2": [1.0, 1.0]})
    return Loop(sc.plant(), sc.controller(), model)


def _e1(loop, substeps: int | None = None) -> complex:
    """The error's first harmonic over the last period (0.8-1 s) of a 5 Hz, 10 mm sine."""
    from motionhyst import SineReference
    from motionhyst.time.sampled import simulate_sampled

    run = simulate_sampled(loop, SineReference(0.01, 5.0), 1.0, linear=False,
                           substeps=substeps)
    t, e = np.asarray(run.t), np.asarray(run.e)
    last = (t >= 0.8 - 1e-9) & (t < 1.0 - 1e-9)
    return complex(2j * np.mean(e[last] * np.exp(-2j * np.pi * 5.0 * t[last])))


@pytest.mark.parametrize("delay", [1.05, 1.37, 1.5, 1.95])
@pytest.mark.parametrize("sigma2", [1e3, 1e4])
@pytest.mark.parametrize("link", ["lugre", "along"])
def test_a_damped_link_s_sampled_run_at_its_default_steps_agrees_with_fine_steps(
        link, sigma2, delay):
    """e1 of the default run (3 fine steps a sample, of two lengths) against a run of 60 a
    sample: was 90 % off at 1.05 and 1.95 samples, 3.0-3.1 % at 1.5, 0.2 % at 1.37 (bare
    LuGre and along the stroke alike); now within 1.1e-5 (measured: 2.4e-7 to 1.2e-6 for
    sigma2 = 1e3, 6e-7 to 1.1e-5 for 1e4, the error growing with the steps' ratio, 9.5 at
    1.05 and 1.95), the accuracy of the continuous loop's default step."""
    loop = _loop(link, sigma2, delay)
    fine = _e1(loop, 60)
    assert abs(_e1(loop) - fine) < 2e-5 * abs(fine)


@pytest.mark.parametrize("delay", [0.01, 1.00001, 1.99999])
@pytest.mark.parametrize("sigma2", [1e3, 1e4])
def test_a_split_of_any_ratio_is_stepped_right(sigma2, delay):
    """A delay just past or short of a whole sample splits a period into steps of very
    different lengths (1e-5 of a sample beside steps of 5e-5 s at 1.00001 and 1.99999
    samples, 1e-6 s beside 4.95e-5 s at 0.01; none of them a whole number as
    time.steps.run_delay judges it): the run stopped ("did not converge in 50 iterations") or
    ended with e1 4e101 times too large (0.01 samples, exit 0); now within 2e-5 of 60 fine
    steps a sample."""
    from motionhyst.time.steps import run_delay

    assert run_delay(delay) == delay  # split, not run as a whole number of samples
    loop = _loop("lugre", sigma2, delay)
    fine = _e1(loop, 60)
    assert abs(_e1(loop) - fine) < 2e-5 * abs(fine)


@pytest.mark.parametrize("delay", [0.01, 1.05, 1.37, 1.5, 1.95, 1.99999])
def test_a_damped_link_s_sampled_run_agrees_with_the_hybrid_steady_state(delay):
    """An independent answer: the exact periodic steady state of the hybrid loop (the
    scenario's loop, its feedforward included; LuGre sigma2 = 1e3 N s/m) against the run's
    last period at its default steps: within 7.2e-7 at every delay (main: 3.1 % at 1.5
    samples, 90 % at 1.05 and 1.95, no answer at 1.99999)."""
    from motionhyst import periodic_steady_state
    from motionhyst.scenario import Scenario

    loop = Scenario.from_dict(tomllib.loads(_scenario(1e3, delay)), "s").loop()
    steady = complex(periodic_steady_state(loop, 0.01, 5.0).e[1])
    assert abs(_e1(loop) - steady) < 2e-6 * abs(steady)


@pytest.mark.parametrize("delay", [1.0000000000000002, 2.9999999999999996, 3 * 0.1 / 0.1,
                                   3.0 + 5e-7])
def test_a_delay_a_hair_off_a_whole_number_runs_as_that_number(delay):
    """3 * 0.1 / 0.1 = 3.0000000000000004 samples split each period at a fine step of 4e-20 s,
    whose change of the motion is rounding: main stopped ("did not converge in 50
    iterations"), and with the rates over the steps' lengths e1 came out 24 % off (exit 0).
    Within 1e-6 samples of a whole number the run takes that number: the same run to the
    bit."""
    from motionhyst.time.steps import sampled_substeps

    assert sampled_substeps(1e-4, delay, natural_frequency_hz=694.3)[:2] == (3, 0)
    assert _e1(_loop("lugre", 1e3, delay)) == _e1(_loop("lugre", 1e3, float(round(delay))))


def test_a_link_along_the_stroke_runs_as_its_base():
    """AlongStroke(LuGre) of scales 1 gives the bare LuGre's run to the bit."""
    assert _e1(_loop("along", 1e4, 1.05)) == _e1(_loop("lugre", 1e4, 1.05))


@pytest.mark.parametrize(("link", "sigma2", "delay", "e1"), [
    ("jenkins", 0.0, 1.05, -4.570490277133086e-10 - 1.6693989400670733e-07j),
    ("jenkins", 0.0, 1.5, -2.9137302503843157e-09 - 2.175198937414174e-07j),
    ("lugre", 1e3, 1.0, 2.7465398379427615e-06 + 5.042572750418284e-05j),
    ("lugre", 1e4, 1.0, 5.0215390151810205e-05 + 0.000502181638121476j),
])
def test_runs_without_a_change_of_step_length_or_backward_differences_are_unchanged(
        link, sigma2, delay, e1):
    """A link without backward differences (Jenkins) at split delays, and LuGre on fine
    steps of one length (a whole sample late): the numbers of the run before the rates over
    the steps' lengths, to 1e-8. Computed on one machine, they are reproduced to 8.6e-10 on
    another (numpy 2.4.6, scipy 1.17.1, numba 0.68.1: its linear algebra rounds otherwise, and
    the fixed point settles within its own tolerance); a change of the steps' weights moves
    them by 1e-5 and more (see the comparison with fine steps above)."""
    assert _e1(_loop(link, sigma2, delay)) == pytest.approx(e1, rel=1e-8, abs=0.0)


def test_the_simulate_command_s_time_series_of_a_lugre_link_1_05_samples_late(tmp_path):
    """simulate --time-series: the last period's error printed and written 10x too small
    (peak 5.008e-06 m of 5.07e-05 m), exit 0; now the fine run's."""
    (tmp_path / "s.toml").write_text(_scenario(1e3, 1.05))
    out = probe(["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5",
                 "--duration", "1"], tmp_path)
    assert out["rc"] == 0, out["err"]
    data = np.genfromtxt(tmp_path / "ts.csv", delimiter=",", names=True)
    t, e = data["time"], data["error"]
    last = (t >= 0.8 - 1e-9) & (t < 1.0 - 1e-9)
    e1 = 2j * np.mean(e[last] * np.exp(-2j * np.pi * 5.0 * t[last]))
    from motionhyst.scenario import Scenario

    fine = _e1(Scenario.from_dict(tomllib.loads(_scenario(1e3, 1.05)), "s").loop(), 60)
    assert abs(e1 - fine) < 2e-5 * abs(fine)


def test_backward_weights_give_a_parabola_s_slope_on_unequal_steps():
    """The weights reproduce the end slope of a quadratic for any two step lengths (the
    equal steps' 1.5 and 0.5 to the bit); without a step before, the first-order ones."""
    from motionhyst.hysteresis.stepping import backward_weights

    assert backward_weights(3.3e-5, 3.3e-5) == (1.5, 0.5)
    assert backward_weights(1e-4, 0.0) == (1.0, 0.0)
    for h, h_prev in [(4.75e-5, 5e-6), (5e-6, 4.75e-5), (3.15e-5, 3.7e-5)]:
        a, b = backward_weights(h, h_prev)
        t = np.array([0.0, h_prev, h_prev + h])
        x = 2.0 * t - 7e3 * t ** 2
        assert (a * (x[2] - x[1]) - b * (x[1] - x[0])) / h == pytest.approx(
            2.0 - 1.4e4 * t[2], rel=1e-12)


def test_lugre_s_partials_follow_its_step_over_unequal_lengths():
    """advance_partials' derivatives in the state and the displacement one step earlier
    (the identification's sensitivities) match finite differences of advance with the
    weights of a long step after a short one."""
    from motionhyst.hysteresis.stepping import GL_T, GL_W, LUGRE, advance, advance_partials

    p = np.array([2e4, 300.0, 1e3, 0.05, 0.07, 0.1])
    s, s_prev, dx, dx_prev, h, h_prev = 1.2e-6, 0.9e-6, 3e-6, 2e-7, 4.75e-5, 5e-6
    ds, df = np.zeros(10), np.zeros(10)
    sn, f = advance_partials(LUGRE, p, s, s_prev, dx, dx_prev, h, h_prev, False, ds, df)
    assert (sn, f) == advance(LUGRE, p, s, s_prev, dx, dx_prev, h, h_prev, False, GL_T, GL_W)
    args = [s, s_prev, dx, dx_prev]
    for i in range(4):
        step = 1e-6 * abs(args[i])
        up, down = list(args), list(args)
        up[i] += step
        down[i] -= step
        fd = (advance(LUGRE, p, *up, h, h_prev, False, GL_T, GL_W)[1]
              - advance(LUGRE, p, *down, h, h_prev, False, GL_T, GL_W)[1]) / (2 * step)
        assert df[i] == pytest.approx(fd, rel=1e-6), i


def test_the_damping_check_weighs_a_long_step_after_a_short_one(tmp_path):
    """1.05 samples late the long fine step (4.75e-5 s) follows a short one (5e-6 s): its
    velocity weighs its own change 1.905 times, not 1.5, so the implicit step's factor is
    1.27 times that of equal steps; sigma2 = 3.5e5 N s/m (factor 0.83 by equal steps, 1.06
    so) ran into 50 passes that did not converge, after the loop was built; now refused
    first, by the command and by the library."""
    from motionhyst.scenario import Scenario
    from motionhyst.time.steps import check_link_damping, damping_factor, sampled_steps

    (tmp_path / "s.toml").write_text(_scenario(3.5e5, 1.05))
    out = probe(["simulate", "s.toml", "--time-series", "ts.csv", "--frequency", "5",
                 "--duration", "0.2"], tmp_path)
    assert out["rc"] == 2 and out["err"].count("\n") == 1, out["err"]
    assert ("too strong for the time step of 4.75e-05 s: it would amplify each pass of the "
            "step's implicit iteration 1.06 times") in out["err"], out["err"]
    assert "numba" not in out["packages"] and not (tmp_path / "ts.csv").exists()
    sc = Scenario.from_dict(tomllib.loads(_scenario(3.5e5, 1.05)), "s")
    long, short = sampled_steps(sc.plant(), sc.hysteresis(), 1e4, 1.05)
    assert (long, short) == pytest.approx((4.75e-5, 5e-6), rel=1e-12)
    equal = damping_factor(sc.hysteresis(), sc.plant(), long)
    assert damping_factor(sc.hysteresis(), sc.plant(), long, short) == pytest.approx(
        equal * (1.0 + 4.75 / 5.25) / 1.5, rel=1e-12)
    with pytest.raises(ValueError, match=r"time step of 4\.75e-05 s: it would amplify each "
                                         r"pass of the step's implicit iteration 1\.06 times"):
        check_link_damping(sc.hysteresis(), sc.plant(), long, shorter=short)
    with pytest.raises(ValueError, match=r"4\.75e-05 s: .* 1\.06 times"):
        _e1(_loop("lugre", 3.5e5, 1.05))


def test_a_step_that_does_not_converge_names_the_longest_fine_step(monkeypatch):
    """The run's own refusal named the period over the substeps, 3.33e-5 s, for steps of
    4.75e-5 and 5e-6 s (1.05 samples late); now the longest, the one the check judges."""
    from motionhyst.time import engine
    from motionhyst.time.kernel import StepNotConverged

    monkeypatch.setattr(engine, "check_link_damping", lambda *args, **kwargs: None)
    with pytest.raises(StepNotConverged, match=r"for the time step of 4\.75e-05 s; use more "
                                               r"substeps"):
        _e1(_loop("lugre", 3.5e5, 1.05))


def test_lugre_link_with_damping_sigma1_also_agrees():
    """The rate of the bristles' state (sigma1 z') takes the same weights: sigma1 = 1e3 N s/m,
    1.05 samples late, was 90 % off as well."""
    from motionhyst import Loop
    from motionhyst.scenario import Scenario

    sc = Scenario.from_dict(tomllib.loads(_scenario(0.0, 1.05)), "s")
    loop = Loop(sc.plant(), sc.controller(),
                LuGre(sigma0=20.0, sigma1=1e3, sigma2=0.0, fc=0.05, fs=0.07, vs=0.1))
    fine = _e1(loop, 60)
    assert abs(_e1(loop) - fine) < 2e-5 * abs(fine)
