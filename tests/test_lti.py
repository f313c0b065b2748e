"""The small-matrix exponential of :mod:`motionhyst.core.lti` against :func:`scipy.linalg.expm`."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from motionhyst.core.lti import expm_small
from motionhyst.hysteresis import Jenkins
from motionhyst.time.openloop import MassSpringDamper, OpenLoop, TwoMass

FS = 750.0
PLANTS = {
    "benchmark stage": MassSpringDamper(2.0, 10.0, 5e4),
    "two-mass, Table I": TwoMass(5.0, 17.5, 90.0, 7.4e7),
    "two-mass, soft": TwoMass(2.0, 3.0, 20.0, 2e5),
}


def _foh_matrix(plant) -> tuple[np.ndarray, int]:
    """The matrix whose exponential is the stage's first-order hold over one fine step (as
    OpenLoop discretises it, with the step of its default substeps)."""
    A, B = plant.mechanics().state_space()
    h = 1.0 / (FS * OpenLoop(plant, Jenkins(k=5e4, fc=20.0)).default_substeps(FS))
    ns = A.shape[0]
    M = np.zeros((ns + 2, ns + 2))
    M[:ns, :ns] = A * h
    M[:ns, ns] = B * h
    M[ns, ns + 1] = 1.0
    return M, ns


@pytest.mark.parametrize("name", list(PLANTS))
def test_the_stage_matrices_agree_with_scipy_entry_by_entry(name):
    M, ns = _foh_matrix(PLANTS[name])
    E, ref = expm_small(M), expm(M)
    # Ad, and the hold's weights of the step's two end forces, each entry to a few roundings
    # (the entries of k h / m and of h lie ten decades apart in the Table I stage's matrix)
    for got, want in ((E[:ns, :ns], ref[:ns, :ns]),
                      (E[:ns, ns] - E[:ns, ns + 1], ref[:ns, ns] - ref[:ns, ns + 1]),
                      (E[:ns, ns + 1], ref[:ns, ns + 1])):
        np.testing.assert_allclose(got, want, rtol=5e-15, atol=0.0)
    # the block matrix whose corner is a Frechet derivative (the identification's Jacobian)
    n = ns + 2
    big = np.zeros((2 * n, 2 * n))
    big[:n, :n] = big[n:, n:] = M
    big[:n, n:] = 1e-3 * np.random.default_rng(0).standard_normal((n, n))
    ref = expm(big)
    assert np.max(np.abs(expm_small(big) - ref)) <= 5e-15 * np.max(np.abs(ref))


@pytest.mark.parametrize("scale", [0.1, 1.0, 10.0, 100.0])
def test_general_matrices_agree_with_scipy_to_their_conditioning(scale):
    M = np.random.default_rng(0).standard_normal((6, 6)) * scale / 6
    ref = expm(M)
    # either method errs by about the unit roundoff times the norm of M
    tol = 2e-15 * max(1.0, np.max(np.sum(np.abs(M), axis=0)))
    assert np.max(np.abs(expm_small(M) - ref)) <= tol * np.max(np.abs(ref))


def test_a_large_norm_and_a_nilpotent_matrix():
    big = 300.0 * np.eye(3) + np.diag([1.0, 2.0], 1)  # scaled and squared many times
    np.testing.assert_allclose(expm_small(big), expm(big), rtol=1e-13)
    # exp(N) = I + N for N^2 = 0, however large N: no squaring, the series exact
    assert expm_small([[0.0, 1e6], [0.0, 0.0]]).tolist() == [[1.0, 1e6], [0.0, 1.0]]


def test_a_matrix_that_is_not_square_is_refused():
    with pytest.raises(ValueError, match="square matrix"):
        expm_small(np.zeros((2, 3)))
