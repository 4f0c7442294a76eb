"""Tests of netrepro.papers.onebit.model: each equation against an independent computation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import linalg

from netrepro.papers.onebit import model

ROOT = Path(__file__).resolve().parents[3]


A2 = np.array([[0.95, 0.7], [-0.25, 0.6]])  # non-symmetric

Q2 = np.array([[0.4, 0.15], [0.15, 0.2]])

C2 = np.array([[1.0, -0.4]])

R2 = np.array([[0.6]])

P02 = np.array([[1.5, -0.2], [-0.2, 0.8]])

def _kalman(K):
    """Textbook covariance-form Kalman filter and RTS smoother (independent of the module)."""
    Pf, Pp = [P02], []
    for _ in range(K):
        M = A2 @ Pf[-1] @ A2.T + Q2
        G = M @ C2.T @ linalg.inv(C2 @ M @ C2.T + R2)
        Pf.append(M - G @ C2 @ M)
        Pp.append(M)
    Ps = [None] * (K + 1)
    Ps[K] = Pf[K]
    for k in range(K - 1, -1, -1):
        Gs = Pf[k] @ A2.T @ linalg.inv(Pp[k])
        Ps[k] = Pf[k] + Gs @ (Ps[k + 1] - Pp[k]) @ Gs.T
    return np.array(Pf), np.array(Pp), np.array(Ps)

def _rel(J, P):
    return max(np.linalg.norm(np.linalg.inv(j) - p) / np.linalg.norm(p) for j, p in zip(J, P))


def test_theta_variance_matches_recursion_and_limit():
    eps, s, sig0 = 1e-2, 0.3, 1.5
    var = [sig0**2]
    for _ in range(400):
        var.append((1 - eps) ** 2 * var[-1] + s)
    np.testing.assert_allclose(model.theta_variance(np.arange(401), eps, sig0, s), var, rtol=1e-12)
    assert model.theta_variance(1e7, eps, sig0, s) == pytest.approx(float(model.stationary_variance(eps, s)), rel=1e-12)
    assert model.theta_variance(5, 0.0, sig0, s) == pytest.approx(sig0**2 + 5 * s)  # alpha = 1: a random walk
    assert model.theta_mean(3, 0.5, 2.0) == pytest.approx(0.25)


def test_snr_definitions():
    eps = 1e-5
    s = model.sigma_z2_from_snr(10.0, eps, 2.0, "stationary")
    assert model.stationary_variance(eps, s) / 4.0 == pytest.approx(10.0, rel=1e-13)
    assert model.sigma_z2_from_snr(10.0, eps, 2.0, "innovation") == pytest.approx(40.0)
    with pytest.raises(ValueError, match="definition"):
        model.sigma_z2_from_snr(0.0, eps, 1.0, "bogus")


def test_linear_gaussian_blocks_by_monte_carlo_score():
    D11, D12, D22 = model.linear_gaussian_blocks(A2, Q2)
    rng = np.random.default_rng(3)
    th0 = rng.standard_normal((400_000, 2))
    th1 = th0 @ A2.T + rng.multivariate_normal([0, 0], Q2, size=len(th0))
    Qi = linalg.inv(Q2)
    r = (th1 - th0 @ A2.T) @ Qi  # Q^-1 (theta_k - A theta_{k-1}), row-wise
    g_prev, g_cur = r @ A2, -r    # d ln p / d theta_{k-1}, d ln p / d theta_k
    n = len(th0)
    np.testing.assert_allclose(g_prev.T @ g_prev / n, D11, atol=0.03 * np.abs(D11).max())
    np.testing.assert_allclose(g_prev.T @ g_cur / n, D12, atol=0.03 * np.abs(D12).max())  # (9): rows theta_{k-1}
    np.testing.assert_allclose(g_cur.T @ g_cur / n, D22, atol=0.03 * np.abs(D22).max())


def test_filtering_prediction_smoothing_equal_kalman_rts():
    K = 30
    D11, D12, D22 = model.linear_gaussian_blocks(A2, Q2)
    F = C2.T @ linalg.inv(R2) @ C2
    Pf, Pp, Ps = _kalman(K)
    Jf = model.filtering_bims(linalg.inv(P02), D11, D12, D22, F, K)
    assert _rel(Jf, Pf) < 1e-12                                                   # (7)
    Jp = np.array([model.prediction_bim_step(Jf[k], D11, D12, D22) for k in range(K)])
    assert _rel(Jp, Pp) < 1e-12                                                   # (14) corrected
    assert _rel(model.smoothing_bims(Jf, D11, D12, D22, F), Ps) < 1e-12              # (16) corrected
    assert _rel(model.smoothing_bims_via_gain(Jf, D11, D12, D22, F), Ps) < 1e-12     # (17)-(19) corrected
    # multi-step prediction = Kalman covariance propagation without updates
    Jpp = model.prediction_bims(Jf[5], D11, D12, D22, 4)
    P = Pf[5]
    for j in range(1, 5):
        P = A2 @ P @ A2.T + Q2
        np.testing.assert_allclose(linalg.inv(Jpp[j]), P, rtol=1e-12)


def test_printed_transposes_fail_on_nonsymmetric_model():
    D11, D12, D22 = model.linear_gaussian_blocks(A2, Q2)
    F = C2.T @ linalg.inv(R2) @ C2
    Pf, Pp, _ = _kalman(5)
    Jf = model.filtering_bims(linalg.inv(P02), D11, D12, D22, F, 5)
    printed = np.array([model.printed_prediction_step(Jf[k], D11, D12, D22) for k in range(5)])
    assert _rel(printed, Pp) > 0.05
    # for a symmetric A the printed and corrected forms coincide
    As = 0.5 * (A2 + A2.T)
    E11, E12, E22 = model.linear_gaussian_blocks(As, np.eye(2) * 0.3)
    J = np.array([[2.0, 0.1], [0.1, 1.0]])
    np.testing.assert_allclose(model.printed_prediction_step(J, E11, E12, E22),
                               model.prediction_bim_step(J, E11, E12, E22), rtol=1e-12)


def test_time_varying_arguments_need_matching_length():
    D11, D12, D22 = model.linear_gaussian_blocks(A2, Q2)
    with pytest.raises(ValueError, match="needs 3"):
        model.filtering_bims(np.eye(2), np.stack([D11] * 2), D12, D22, np.zeros((2, 2)), 3)
