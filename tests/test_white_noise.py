"""One estimate of a signal's white noise (third differences) for every part that needs it:
the input-output standard errors, predict's error, the closed-loop passivity check and
predict --init-from's same-run check (motionhyst.identify.io_uncertainty)."""

import numpy as np
import pytest

from motionhyst.identify.residual_noise import white_noise_variance


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("robust", [True, False])
def test_white_noise_under_a_smooth_signal_is_found(seed, robust):
    rng = np.random.default_rng(seed)
    t = np.arange(20000) / 1000.0
    smooth = 0.05 * np.sin(2 * np.pi * 1.3 * t) + 0.01 * np.sin(2 * np.pi * 17.0 * t)
    x = smooth + 1e-5 * rng.standard_normal(t.size)
    # one array or its parts, each differenced on its own: the same noise within 3 %
    for arg in (x, [x[:7000], x[7000:]]):
        assert np.sqrt(white_noise_variance(arg, robust=robust)) == pytest.approx(1e-5, rel=0.03)


def test_the_mean_square_counts_fast_moves_the_robust_one_does_not():
    rng = np.random.default_rng(1)
    x = 1e-6 * rng.standard_normal(10000)
    x[::500] += 1e-4  # 20 spikes: a controller's fast action, a sample stuck
    assert np.sqrt(white_noise_variance(x)) == pytest.approx(1e-6, rel=0.05)
    assert np.sqrt(white_noise_variance(x, robust=False)) > 3e-6  # measured: 4.5e-6


def test_the_closed_loop_check_and_predict_use_it():
    import motionhyst.cli.predict as predict
    import motionhyst.identify.closed_loop as closed_loop

    assert not hasattr(predict, "_white_noise_variance")
    assert not hasattr(closed_loop, "_white_noise_variance")
    assert closed_loop.white_noise_variance is white_noise_variance


def test_short_records_have_no_noise_estimate():
    assert white_noise_variance(np.ones(3)) == 0.0
    assert white_noise_variance([np.ones(2), np.ones(3)], robust=False) == 0.0
