"""Tests of `markov`: the equations of model.py (eqs. 4-9, Definition 2, Proposition 1), each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.markov import model
from .systems import A1, C1, A2, C2, A3, C3


def test_observability_index():
    assert model.observability_index(A1, C1) == 2
    assert model.observability_index(A2, C2) == 2
    assert model.observability_index(A3, C3) == 3
    assert model.stacked_output(A3, C3, 2).shape == (2, 3)
    with pytest.raises(ValueError, match="not observable"):
        model.observability_index(np.eye(2) * 1.2, np.array([[1.0, 0.0]]))


def test_prop1_closed_form_and_K0():
    # Section 5.1: p < (1 - |l|^2 (1-q)) / (|l|^4 q) = 0.22 at q = 0.65
    p = model.prop1_bound(1.3, np.array([0.65]), 2)[0]
    assert p == pytest.approx((1 - 1.69 * 0.35) / (1.69 ** 2 * 0.65), rel=1e-12)
    assert round(p, 2) == 0.22
    # eq (8) is rho(H(0)) < 1 (K = 0 in eq 7): the radius is exactly 1 at the bound
    assert model.h_radius(A1, C1, [np.zeros((2, 1))], p, 0.65) == pytest.approx(1.0, abs=1e-10)
    # general l_o = 3: bisection in prop1_bound agrees with rho(H(0)) = 1
    lam = model.spectral_abs(A3)
    p3 = model.prop1_bound(lam, np.array([0.6]), 3)[0]
    K0 = [np.zeros((3, 1)), np.zeros((3, 2))]
    assert model.h_radius(A3, C3, K0, p3, 0.6) == pytest.approx(1.0, abs=1e-8)


def test_phi_lyapunov_is_series():
    rng = np.random.default_rng(0)
    G = rng.standard_normal((2, 2))
    X = G @ G.T
    q = 0.7
    series = sum(q * (1 - q) ** (j - 1) * np.linalg.matrix_power(A1.T, j) @ X @ np.linalg.matrix_power(A1, j)
                 for j in range(1, 400))
    assert np.allclose(model.phi_lyapunov(A1, X, q), series, rtol=1e-9)


def _operator_matrix(fn, n):
    """Matrix of a linear map on n x n matrices in the column-major vec basis."""
    cols = []
    for j in range(n * n):
        E = np.zeros(n * n)
        E[j] = 1.0
        cols.append(fn(E.reshape(n, n, order="F")).reshape(-1, order="F"))
    return np.array(cols).T


@pytest.mark.parametrize("A,C,K", [(A1, C1, None), (A3, C3, None)])
def test_L_is_adjoint_of_H(A, C, K):
    """Theorem 2 (i) <=> (ii): L_K (eq 9) is the adjoint of H(K) (eq 7) and shares its spectral radius."""
    rng = np.random.default_rng(1)
    n, m = A.shape[0], C.shape[0]
    l_o = model.observability_index(A, C)
    K = [rng.standard_normal((n, m * i)) * 0.5 for i in range(1, l_o)]
    p, q = 0.4, 0.7
    H = model.H_matrix(A, C, K, p, q).real
    Lmat = _operator_matrix(lambda X: model.L_operator(A, C, K, p, q, X), n)
    assert np.allclose(Lmat, H.T, atol=1e-9 * np.abs(H).max())
    assert np.max(np.abs(np.linalg.eigvals(Lmat))) == pytest.approx(model.h_radius(A, C, K, p, q), rel=1e-9)


def test_sym_norm():
    rng = np.random.default_rng(4)
    G = rng.standard_normal((20, 3, 3))
    P = G @ np.swapaxes(G, 1, 2)
    assert np.allclose(model.sym_norm(P), np.linalg.norm(P, 2, axis=(1, 2)))
    P2 = P[:, :2, :2]
    assert np.allclose(model.sym_norm(P2), np.linalg.norm(P2, 2, axis=(1, 2)))
    P[0, 0, 0] = np.inf
    assert model.sym_norm(P)[0] == np.inf


def test_sym_norm_3x3_closed_form_matches_lapack():
    rng = np.random.default_rng(11)
    X = rng.normal(size=(4000, 3, 3))
    scales = 10.0 ** rng.uniform(-3, 8, size=(4000, 3))  # condition numbers up to ~1e11
    Qm = np.linalg.qr(X)[0]
    P = Qm @ (scales[:, :, None] * np.swapaxes(Qm, 1, 2))
    P = np.concatenate([P, np.eye(3)[None] * 2.5, np.diag([4.0, 4.0, 1.0])[None], np.zeros((1, 3, 3))])
    want = np.linalg.eigvalsh(0.5 * (P + np.swapaxes(P, 1, 2)))[:, -1]
    assert np.allclose(model.sym_norm(P), want, rtol=1e-10, atol=1e-300)
    assert np.isinf(model.sym_norm(np.full((1, 3, 3), np.inf))).all()


def test_stationary_loss_rates():
    assert model.gilbert_elliott_stationary_loss(0.04, 0.65) == pytest.approx(0.0580, abs=5e-5)
    assert model.gilbert_elliott_stationary_loss(0.22004, 0.65) == pytest.approx(0.2529, abs=5e-5)



def test_parity_ceiling_against_a_numerical_maximisation():
    """max_q p_c(q) of Example II: the closed form against the spectral-radius condition solved numerically.

    Independent route: at each q, the critical p is the root of rho(|lambda|^4 [[pq, p(1-q)], [q(1-q), (1-q)^2]]) = 1
    (eigenvalues by LAPACK, root by brentq), maximised over q by a bounded scalar search; no closed form is used."""
    from scipy.optimize import brentq, minimize_scalar

    lam = 1.2
    L = lam ** 4

    def rho(p, q):
        return np.max(np.abs(np.linalg.eigvals(L * np.array([[p * q, p * (1 - q)], [q * (1 - q), (1 - q) ** 2]]))))

    def p_crit(q):
        return brentq(lambda p: rho(p, q) - 1.0, 0.0, 1.0, xtol=1e-14)

    q_zero = brentq(lambda q: rho(0.0, q) - 1.0, 0.01, 0.99, xtol=1e-14)  # p_c = 0 where (1-q)^2 L = 1
    best = minimize_scalar(lambda q: -p_crit(q), bounds=(q_zero + 1e-6, 1.0 - 1e-9), method="bounded",
                           options={"xatol": 1e-10})
    got = model.parity_ceiling(lam)
    assert got["p_max"] == pytest.approx(-best.fun, abs=1e-9)
    assert got["q_star"] == pytest.approx(best.x, abs=1e-4)  # flat maximum: the argmax is resolved less finely
    assert got["p_at_q1"] == pytest.approx(p_crit(1.0 - 1e-12), abs=1e-9)
    assert got["q_zero"] == pytest.approx(q_zero, abs=1e-9)
    # and it is the maximum of the closed-form curve the LMI tests use
    qs = np.linspace(got["q_zero"], 1.0, 200001)
    assert np.max(model.parity_bound_example2(lam, qs)) == pytest.approx(got["p_max"], abs=1e-9)
    assert got["p_max"] == pytest.approx(0.5609, abs=5e-5) and got["p_at_q1"] == pytest.approx(0.4823, abs=5e-5)
    with pytest.raises(ValueError, match=r"needs \|lambda\| > 1"):
        model.parity_ceiling(0.9)
