"""Exact second moments (issue 16 section 2) against independent computations."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from netrepro.papers.gainsched.model import GainschedError, System, p_schedule, simulate, zero_gains
from netrepro.papers.gainsched.moments import (
    error_mse,
    initial_moment,
    linear_gains,
    mode_matrices,
    second_moments,
)

from .conftest import random_gains


def _enumerated_mse(sys, gains, p_seq, F, x0, xf0):
    """E||e(K)||^2 by enumerating every arrival sequence and a 3-point Gauss-Hermite rule for each w(k).

    e(K) is linear in each w(k), so ||e(K)||^2 has degree 2 in each w(k) and the 3-point rule is exact.
    The plant and filter are stepped directly from (1), (6), (8), not through the recursion's matrices.
    """
    nodes, weights = np.polynomial.hermite_e.hermegauss(3)  # probabilists' Hermite: N(0, 1)
    weights = weights / weights.sum()
    sd = np.sqrt(sys.sigma2)
    K = len(p_seq)
    total = 0.0
    for xis in itertools.product((0, 1), repeat=K):
        pxi = np.prod([p if xi else 1 - p for xi, p in zip(xis, p_seq)])
        for idx in itertools.product(range(3), repeat=K):
            x, xf = np.array(x0, float), np.array(xf0, float)
            wgt = pxi
            for k in range(K):
                w = sd * nodes[idx[k]]
                wgt *= weights[idx[k]]
                p = p_seq[k]
                y = xis[k] * (sys.C @ x)
                xf = gains.G(p) @ xf + gains.H(p) @ y
                x = sys.A @ x + sys.B @ (F @ (sys.Z @ x)) + sys.D @ x * w
            total += wgt * float(np.sum((x - xf) ** 2))
    return total


@pytest.mark.parametrize("fname", ["F1", "F2", "mid"])
def test_recursion_matches_enumeration(sys, fname):
    rng = np.random.default_rng(11)
    g = random_gains(rng, sys)
    p_seq = np.array([0.45, 0.8, 0.6, 0.7])
    F = linear_gains(sys)[fname]
    x0, xf0 = np.array([1.0, -0.7]), np.array([0.3, 0.2])
    M1, M0, W = mode_matrices(sys, g, p_seq, F)
    X = second_moments(M1, M0, W, p_seq, sys.sigma2, initial_moment(x0, np.zeros((2, 2)), xf0))
    exact = _enumerated_mse(sys, g, p_seq, F, x0, xf0)
    assert error_mse(X)[-1] == pytest.approx(exact, rel=1e-11)
    assert error_mse(X)[0] == pytest.approx(np.sum((x0 - xf0) ** 2), rel=1e-14)


def test_gaussian_start_is_the_average_over_initial_states(sys, paper):
    """Linearity in X(0): N(0, I) start = the average of the moments from x0 = e1 and x0 = e2 (times 2)."""
    p_seq = p_schedule(np.arange(12), sys.p1, sys.p2, 1.0)
    M1, M0, W = mode_matrices(sys, paper, p_seq, sys.F2)
    g = error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, initial_moment(np.zeros(2), np.eye(2), np.zeros(2))))
    parts = [error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, initial_moment(e, np.zeros((2, 2)), np.zeros(2))))
             for e in np.eye(2)]
    np.testing.assert_allclose(g, parts[0] + parts[1], rtol=1e-12)


def test_recursion_matches_monte_carlo_where_the_tail_is_light(sys, paper):
    """Small sigma^2 (light tail): Monte Carlo mean within 4 standard errors at every k."""
    s = System(sys.A, sys.B, sys.C, sys.D, sys.Z, sys.F1, sys.F2, 0.05, sys.p1, sys.p2)
    p_seq = p_schedule(np.arange(8), s.p1, s.p2, 1.0)
    R = 100_000
    x0 = np.random.default_rng(12).standard_normal((R, 2))
    e = simulate(s, paper, p_seq, x0, np.random.default_rng(13), "lower")
    sq = (e ** 2).sum(-1)
    M1, M0, W = mode_matrices(s, paper, p_seq, s.F1)
    exact = error_mse(second_moments(M1, M0, W, p_seq, s.sigma2, initial_moment(np.zeros(2), np.eye(2), np.zeros(2))))
    z = (sq.mean(0) - exact) / (sq.std(0, ddof=1) / np.sqrt(R))
    assert np.all(np.abs(z) < 4), z


def test_zero_design_is_the_plant_moment(sys):
    """x_f = 0: E||e||^2 = tr P(k), P(k+1) = (A+BFZ) P (A+BFZ)^T + sigma^2 D P D^T (the plant alone)."""
    p_seq = np.full(20, 0.6)
    F = linear_gains(sys)["mid"]
    M1, M0, W = mode_matrices(sys, zero_gains(sys), p_seq, F)
    mse = error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, initial_moment(np.zeros(2), np.eye(2), np.zeros(2))))
    AF = sys.A + sys.B @ F @ sys.Z
    P = np.eye(2)
    for k in range(21):
        assert mse[k] == pytest.approx(np.trace(P), rel=1e-12)
        P = AF @ P @ AF.T + sys.sigma2 * sys.D @ P @ sys.D.T


def test_batch_equals_single(sys, paper):
    p_seq = p_schedule(np.arange(6), sys.p1, sys.p2, 1.0)
    Ms = [mode_matrices(sys, g, p_seq, sys.F1) for g in (paper, zero_gains(sys))]
    X0 = initial_moment([1.0, 2.0], np.eye(2), [0.0, 0.0])
    batch = second_moments(np.array([m[0] for m in Ms]), np.array([m[1] for m in Ms]), Ms[0][2], p_seq, 1.0,
                           np.array([X0, X0]))
    for i, m in enumerate(Ms):
        np.testing.assert_allclose(batch[i], second_moments(m[0], m[1], m[2], p_seq, 1.0, X0), rtol=1e-14)


def test_initial_moment_rejects_bad_shapes():
    with pytest.raises(GainschedError, match="xf0"):
        initial_moment([0.0, 0.0], np.eye(2), [0.0])
