"""The mathematical helpers the evidence step uses (issue 29: moved out of evidence.py), against
independent computations (closed forms, scipy's DARE solver, hand-made series)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import linalg, stats

from netrepro.errors import InputError
from netrepro.papers.hinf.algebra import central_difference
from netrepro.papers.hinf.consensus import component_membership, component_sums, topology_changed
from netrepro.papers.hinf.filters import gain_norms, steady_state_prior
from netrepro.papers.hinf.model import advantage, bonferroni_z, gaussian_draws, gaussian_factor, settle_step, tag_z


def test_central_difference_is_exact_on_quadratics():
    assert central_difference(lambda z: 3 * z**2 - 2 * z + 1, 0.7, eps=1e-3) == pytest.approx(6 * 0.7 - 2)


def test_steady_state_prior_kalman_limit_matches_scipy_dare():
    # gamma^-2 = 0: the prior covariance solves the DARE X = X - X (X + R)^-1 X + W (A = C = I, R = M)
    M = np.array([[0.8, 0.3], [0.3, 2.5]])
    W = 0.01
    X = linalg.solve_discrete_are(np.eye(2), np.eye(2), W * np.eye(2), M)
    D = steady_state_prior(np.linalg.inv(M), W, 0.0, np.eye(2))
    np.testing.assert_allclose(D, X, rtol=1e-9)


def test_steady_state_prior_scalar_closed_form_with_gamma():
    # diagonal case, one axis: Sigma^-1 = Delta^-1 + s - g, Delta = Sigma + w  ->  Delta^2 (s - g) - w (s - g) Delta - w = 0
    s, g, w = 2.0, 0.25, 0.05
    a = s - g
    delta = (w * a + math.sqrt((w * a) ** 2 + 4 * a * w)) / (2 * a)
    D = steady_state_prior(np.diag([s, s]), w, g, np.eye(2))
    np.testing.assert_allclose(np.diag(D), [delta, delta], rtol=1e-10)


def test_gain_norms_closed_form():
    d, s = 0.3, 4.0
    K, Kt = gain_norms(d * np.eye(2), s * np.eye(2), s * np.eye(2))
    assert K == pytest.approx(d * s / (1 + s * d))
    assert Kt == pytest.approx(d / (1 + s * d))


@pytest.mark.parametrize("series, thr, expected", [
    ([1.0, 0.5, 0.2, 0.1], 0.3, 2), ([0.1, 0.2], 0.3, 0), ([0.5, 0.1, 0.4, 0.1], 0.3, 3), ([0.5, 0.1, 0.4], 0.3, -1)])
def test_settle_step_by_hand(series, thr, expected):
    assert settle_step(series, thr) == expected


def test_advantage_is_the_ratio():
    np.testing.assert_allclose(advantage([1.0, 2.0], [0.5, 4.0]), [2.0, 0.5])


def test_bonferroni_z_against_scipy_and_the_union_bound():
    # m two-sided tests at alpha/m each: P(|Z| > z) = alpha/m exactly for a standard normal Z
    for m in (1, 4, 48):
        z = bonferroni_z(0.05, m)
        assert 2 * stats.norm.sf(z) == pytest.approx(0.05 / m, rel=1e-12)
        assert z == float(stats.norm.ppf(1.0 - 0.05 / (2 * m)))  # scipy.special.ndtri: scipy.stats's numbers exactly
    assert bonferroni_z(0.05, 1) == pytest.approx(1.959963984540054, rel=1e-12)
    with pytest.raises(InputError, match="alpha"):
        bonferroni_z(1.5, 3)


@pytest.mark.parametrize("z, tag", [(-4.0, "holds"), (4.0, "reversed"), (0.5, "not significant"),
                                    (float("nan"), "not significant")])
def test_tag_z(z, tag):
    assert tag_z(z, 3.0) == tag


def test_components_of_two_pieces_and_an_isolated_agent():
    # agents 0-1-2 a path, 3-4 a link, 5 alone: membership is block diagonal
    adj = np.zeros((6, 6))
    for i, j in ((0, 1), (1, 2), (3, 4)):
        adj[i, j] = adj[j, i] = 1.0
    m = component_membership(adj)
    blocks = np.zeros((6, 6))
    blocks[:3, :3] = 1
    blocks[3:5, 3:5] = 1
    blocks[5, 5] = 1
    np.testing.assert_array_equal(m, blocks)
    u = np.arange(12.0).reshape(6, 2)
    sums = component_sums(u, adj)
    np.testing.assert_allclose(sums[0], u[:3].sum(0))
    np.testing.assert_allclose(sums[4], u[3:5].sum(0))
    np.testing.assert_allclose(sums[5], u[5])


def test_topology_changed_per_run():
    a = np.zeros((2, 3, 3))
    b = a.copy()
    b[1, 0, 2] = b[1, 2, 0] = 1.0
    np.testing.assert_array_equal(topology_changed(a, b), [False, True])


def test_range_derivative_reading_of_eq17_against_finite_differences():
    from netrepro.papers.hinf.noise import NoiseModel, dinfo_dr_reading, noise_information

    model = NoiseModel(a0=0.3528, a1=15.625, a2=0.0008, alpha=5.0)
    for r in (5.0, 27.0, 45.0):
        fd = central_difference(lambda z: noise_information(z, 0.7, model), r, eps=1e-5)
        np.testing.assert_allclose(dinfo_dr_reading(r, 0.7, model, "variances"), fd, rtol=1e-6, atol=1e-12)
        assert np.linalg.norm(dinfo_dr_reading(r, 0.7, model, "square_roots") - fd) > 0.1 * np.linalg.norm(fd)
    with pytest.raises(ValueError, match="unknown reading"):
        dinfo_dr_reading(5.0, 0.7, model, "sqrt")


@pytest.mark.parametrize("cov", [0.01 * np.eye(2), 0.001 * np.eye(2), np.zeros((2, 2)), [[0.02, 0.005], [0.005, 0.01]],
                                 np.diag([1.0, 2.0, 0.5])])
def test_gaussian_draws_are_multivariate_normal(cov):
    # the simulation's target noise: numpy's multivariate_normal with its factor computed once, the same
    # draws from the same generator state (tolerance 0), and the generator left in the same state
    cov = np.asarray(cov, dtype=float)
    F = gaussian_factor(cov)
    for size in (1, 7, 200):
        g1, g2 = np.random.default_rng(size), np.random.default_rng(size)
        for _ in range(3):
            want = g1.multivariate_normal(np.zeros(len(cov)), cov, size=size)
            assert gaussian_draws(g2, F, size).tobytes() == want.tobytes()
        assert g1.random() == g2.random()
