"""Unit tests of the `markov` paper: every equation against an independent computation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import minimize

from netrepro.config import ConfigError
from netrepro.papers import markov as M
from netrepro.papers import markov_math as mm

A1 = np.array([[1.3, 0.3], [0.0, 1.2]])
C1 = np.array([[1.0, 1.0]])
A2 = np.diag([1.2, 1.2, -1.2])
C2 = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0]])
EX1 = mm.LinearSystem(A1, C1, np.eye(2), np.eye(1))
EX2 = mm.LinearSystem(A2, C2, np.eye(3), np.eye(2))
# a system with observability index 3 (for the general-l_o code paths)
A3 = np.array([[1.1, 1.0, 0.0], [0.0, 1.1, 1.0], [0.0, 0.0, 1.05]])
C3 = np.array([[1.0, 0.0, 0.0]])


def test_observability_index():
    assert mm.observability_index(A1, C1) == 2
    assert mm.observability_index(A2, C2) == 2
    assert mm.observability_index(A3, C3) == 3
    assert mm.stacked_output(A3, C3, 2).shape == (2, 3)
    with pytest.raises(ValueError):
        mm.observability_index(np.eye(2) * 1.2, np.array([[1.0, 0.0]]))


def test_prop1_closed_form_and_K0():
    # Section 5.1: p < (1 - |l|^2 (1-q)) / (|l|^4 q) = 0.22 at q = 0.65
    p = mm.prop1_bound(1.3, np.array([0.65]), 2)[0]
    assert p == pytest.approx((1 - 1.69 * 0.35) / (1.69 ** 2 * 0.65), rel=1e-12)
    assert round(p, 2) == 0.22
    # eq (8) is rho(H(0)) < 1 (K = 0 in eq 7): the radius is exactly 1 at the bound
    assert mm.h_radius(A1, C1, [np.zeros((2, 1))], p, 0.65) == pytest.approx(1.0, abs=1e-10)
    # general l_o = 3: bisection in prop1_bound agrees with rho(H(0)) = 1
    lam = mm.spectral_abs(A3)
    p3 = mm.prop1_bound(lam, np.array([0.6]), 3)[0]
    K0 = [np.zeros((3, 1)), np.zeros((3, 2))]
    assert mm.h_radius(A3, C3, K0, p3, 0.6) == pytest.approx(1.0, abs=1e-8)


def test_phi_lyapunov_is_series():
    rng = np.random.default_rng(0)
    G = rng.standard_normal((2, 2))
    X = G @ G.T
    q = 0.7
    series = sum(q * (1 - q) ** (j - 1) * np.linalg.matrix_power(A1.T, j) @ X @ np.linalg.matrix_power(A1, j)
                 for j in range(1, 400))
    assert np.allclose(mm.phi_lyapunov(A1, X, q), series, rtol=1e-9)


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
    l_o = mm.observability_index(A, C)
    K = [rng.standard_normal((n, m * i)) * 0.5 for i in range(1, l_o)]
    p, q = 0.4, 0.7
    H = mm.H_matrix(A, C, K, p, q).real
    Lmat = _operator_matrix(lambda X: mm.L_operator(A, C, K, p, q, X), n)
    assert np.allclose(Lmat, H.T, atol=1e-9 * np.abs(H).max())
    assert np.max(np.abs(np.linalg.eigvals(Lmat))) == pytest.approx(mm.h_radius(A, C, K, p, q), rel=1e-9)


def test_lmi_block_form_is_schur_of_L():
    """Schur complement of Psi (11) is X - sum_i w_i M_i' Y M_i with K^{(i)} = Y^{-1} F_i' (for l_o = 2 and 3)."""
    rng = np.random.default_rng(2)
    assert M._schur_residual(A1, C1, 0.5, 0.65, rng) < 1e-9
    assert M._schur_residual(A3, C3, 0.5, 0.65, rng) < 1e-8


def test_lmi_feasible_is_certified_and_matches_rebuild():
    lmi = mm.GilbertElliottLMI(A1, C1)
    res = lmi.solve(1 - 1e-6, 0.65)  # Section 5.1: feasible at p = 1
    assert res.certified and res.rho_H < 1 and res.lyap_margin > 0
    # Theorem 2 (iii) with the recovered gain: L_K(X) < X for the solver's X
    again = mm.rebuild_solve(A1, C1, 1 - 1e-6, 0.65)
    assert again.margin == pytest.approx(res.margin, rel=1e-4)
    bad = mm.GilbertElliottLMI(A2, C2).solve(1.0, 0.5)  # Section 5.2: infeasible at p = 1, q = 0.5
    assert not bad.certified


def test_thm5_equals_direct_minimisation_of_rho():
    """For l_o = 2, p_underline(q) = 1 / min_K rho(H(K)/p): LMI bisection vs Nelder-Mead on K."""
    q = 0.5
    lmi = mm.GilbertElliottLMI(A1, C1)
    res = mm.thm5_lower_bound(lmi, q, 5.0, 1e-5)

    def rho(k):
        return mm.h_radius(A1, C1, [k.reshape(2, 1)], 1.0, q)

    best = min((minimize(rho, x0, method="Nelder-Mead", options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 4000})
                for x0 in ([-1.0, -0.5], [0.0, 0.0], [-2.0, 1.0])), key=lambda r: r.fun)
    assert res["p_lower"] == pytest.approx(1.0 / best.fun, abs=2e-4)
    assert res["n_uncertified"] == 0


def test_thm5_example2_closed_form():
    lmi = mm.GilbertElliottLMI(A2, C2)
    res = mm.thm5_lower_bound(lmi, 0.5, 1.0, 1e-6)
    closed = mm.parity_bound_example2(1.2, 0.5)
    assert closed == pytest.approx(0.464506, abs=1e-6)
    assert res["p_lower"] <= closed + 1e-6 and res["p_upper"] >= closed - 2e-6
    assert res["p_lower"] < 0.465  # the paper's "p <= 0.465" is not certified


def _brute_force_mean(system, S0, p, q, k, which="norm"):
    """E||P_k|| by explicit enumeration of gamma_1 = 1, gamma_2..gamma_{k-1} (independent of the tree code)."""
    total = 0.0
    trans = {(1, 1): 1 - p, (1, 0): p, (0, 1): q, (0, 0): 1 - q}
    for tail in itertools.product([0, 1], repeat=k - 2):
        gam = (1,) + tail
        prob = np.prod([trans[(a, b)] for a, b in zip(gam[:-1], gam[1:])])
        P = np.array(S0, dtype=float)
        for g in gam:
            P = mm.riccati_g(P, system.A, system.C, system.Q, system.R) if g else mm.riccati_h(P, system.A, system.Q)
        val = np.linalg.norm(P, 2) if which == "norm" else np.trace(P)
        total += prob * val
    return total


@pytest.mark.parametrize("system", [EX1, EX2])
def test_exact_moments_against_enumeration(system):
    em = mm.exact_moments(system, np.eye(system.n), 8)
    for p, q in ((0.3, 0.6), (0.95, 0.2)):
        means = em.mean(p, q, "norm")
        traces = em.mean(p, q, "trace")
        for k in (2, 5, 9):
            assert means[k - 1] == pytest.approx(_brute_force_mean(system, np.eye(system.n), p, q, k), rel=1e-10)
        assert traces[8] == pytest.approx(_brute_force_mean(system, np.eye(system.n), p, q, 9, "trace"), rel=1e-10)
    # vectorised over a grid
    grid = em.mean(np.array([0.3, 0.95]), np.array([0.6, 0.2]))
    assert grid.shape == (2, 9)


def _all_paths(T):
    """All gamma sequences of length T with gamma_1 = 1."""
    return np.array([(1,) + t for t in itertools.product([0, 1], repeat=T - 1)], dtype=bool)


def _path_probs(arr, p, q):
    a, b = arr[:, :-1], arr[:, 1:]
    P = np.where(a & b, 1 - p, np.where(a & ~b, p, np.where(~a & b, q, 1 - q)))
    return P.prod(axis=1)


@pytest.mark.parametrize("system", [EX1, EX2])
def test_conditional_estimator_is_unbiased(system):
    """The trailing-loss-run estimator, averaged over ALL channel paths with their probabilities, equals E||P_k||."""
    T = 9
    arr = _all_paths(T)
    p, q = 0.7, 0.3
    w = _path_probs(arr, p, q)
    est = mm.rb_mean_norm(system, np.eye(system.n), p, q, arr)
    exact = mm.exact_moments(system, np.eye(system.n), T).mean(p, q)
    assert np.allclose(w @ est, exact, rtol=1e-10)
    # and the plain estimator over all paths too (sanity of the weights)
    P = mm.covariance_paths_ge(system, np.eye(system.n), arr)
    assert np.allclose(w @ mm.sym_norm(P), exact, rtol=1e-10)


def test_covariance_paths_matches_eqs_4_5_step_by_step():
    """The engine-backed path recursion against g (eq. 5) and h (eq. 4) applied one path at a time."""
    rng = np.random.default_rng(3)
    arr = rng.random((50, 15)) < 0.6
    ours = mm.covariance_paths_ge(EX2, np.eye(3), arr)
    theirs = np.empty_like(ours)
    for i, path in enumerate(arr):
        P = np.eye(3)
        theirs[i, 0] = P
        for k, received in enumerate(path):
            P = mm.riccati_g(P, A2, C2, np.eye(3), np.eye(2)) if received else mm.riccati_h(P, A2, np.eye(3))
            theirs[i, k + 1] = P
    assert np.allclose(ours, theirs, rtol=1e-9)


def test_sym_norm():
    rng = np.random.default_rng(4)
    G = rng.standard_normal((20, 3, 3))
    P = G @ np.swapaxes(G, 1, 2)
    assert np.allclose(mm.sym_norm(P), np.linalg.norm(P, 2, axis=(1, 2)))
    P2 = P[:, :2, :2]
    assert np.allclose(mm.sym_norm(P2), np.linalg.norm(P2, 2, axis=(1, 2)))
    P[0, 0, 0] = np.inf
    assert mm.sym_norm(P)[0] == np.inf


def test_classify_growth():
    k = np.arange(1, 30)
    settle = 50 - 40 * 0.7 ** k
    grow = 3.0 * 1.3 ** k
    rate, last, verdict = M.classify_growth(np.stack([settle, grow]), 0.01, 0.08)
    assert list(verdict) == ["bounded", "unbounded"]
    assert rate[1] == pytest.approx(np.log(1.3), rel=1e-6)


def test_plain_mean_understates_beyond_boundary():
    """Beyond |lambda|^2 (1-q) = 1 the plain mean misses the loss-run tail that the conditional estimator integrates."""
    rng = np.random.default_rng(5)
    norms, arr = mm.plain_mc(EX1, np.eye(2), 0.5, 0.3, 300, 40, rng)
    rb = mm.rb_mean_norm(EX1, np.eye(2), 0.5, 0.3, arr)
    assert norms[:, -1].mean() < 0.5 * rb[:, -1].mean()
    # while the conditional estimator is tight: relative standard error below 10%
    assert rb[:, -1].std() / np.sqrt(len(rb)) < 0.1 * rb[:, -1].mean()


def test_stationary_loss_rates():
    assert mm.gilbert_elliott_stationary_loss(0.04, 0.65) == pytest.approx(0.0580, abs=5e-5)
    assert mm.gilbert_elliott_stationary_loss(0.22004, 0.65) == pytest.approx(0.2529, abs=5e-5)


def test_check_config_rejects_bad_shapes():
    good = {"A": A1.tolist(), "C": C1.tolist(), "Q": np.eye(2).tolist(), "R": [[1.0]], "Sigma0": np.eye(2).tolist()}
    M.check_config({"examples": {"I": good}})
    with pytest.raises(ConfigError, match="C"):
        M.check_config({"examples": {"I": dict(good, C=[[1.0, 1.0, 1.0]])}})
    with pytest.raises(ConfigError, match="R"):
        M.check_config({"examples": {"I": dict(good, R=[[-1.0]])}})
    with pytest.raises(ConfigError, match="observable"):
        M.check_config({"examples": {"I": dict(good, A=[[1.2, 0.0], [0.0, 1.2]], C=[[1.0, 0.0]])}})


def test_long_horizon_refinement_trusts_only_narrow_intervals():
    """Example I near its boundary is resolved; Example II's parity tail is flagged as untrusted."""
    opts = dict(M.REFINE_DEFAULTS, n_paths=200, horizon=160)
    rng = np.random.default_rng(6)
    rate, rel, verdict = M.refine_long_horizon(EX1, np.eye(2), np.array([0.5, 0.5]), np.array([0.36, 0.5]), opts, rng)
    assert list(verdict) == ["unbounded", "bounded"]
    assert rate[0] == pytest.approx(np.log(1.69 * 0.64), abs=0.01)  # trailing loss-run growth |lambda|^2 (1-q)
    _, _, verdict2 = M.refine_long_horizon(EX2, np.eye(3), np.array([0.99]), np.array([0.5]), opts, rng)
    assert verdict2[0] == "undecided"


def test_rb_trace_grid_matches_single_point_estimator():
    rng = np.random.default_rng(8)
    m, h = mm.rb_trace_grid(EX1, np.eye(2), [0.5], [0.5], 400, 40, rng, n_batches=10)
    arr = mm.gilbert_elliott_arrivals(np.random.default_rng(9), 4000, 40, 0.5, 0.5, initial=1)
    m2, lo, hi = mm.rb_mean_trace(EX1, np.eye(2), 0.5, 0.5, arr)
    assert abs(m[0, -1] - m2[-1]) < 3 * (h[0, -1] + (hi[-1] - lo[-1]) / 2)


@pytest.mark.parametrize("system", [EX1, EX2])
def test_linear_trace_estimator_is_unbiased(system):
    """rb_mean_trace (linear form) equals the per-path trace estimator, which is unbiased by enumeration."""
    T = 9
    arr = _all_paths(T)
    p, q = 0.6, 0.35
    w = _path_probs(arr, p, q)
    per_path = mm.rb_mean_norm(system, np.eye(system.n), p, q, arr, which="trace")
    exact = mm.exact_moments(system, np.eye(system.n), T).mean(p, q, "trace")
    assert np.allclose(w @ per_path, exact, rtol=1e-10)
    mean, _, _ = mm.rb_mean_trace(system, np.eye(system.n), p, q, arr, n_batches=len(arr))
    assert np.allclose(mean, per_path.mean(axis=0), rtol=1e-10)


def test_sym_norm_3x3_closed_form_matches_lapack():
    rng = np.random.default_rng(11)
    X = rng.normal(size=(4000, 3, 3))
    scales = 10.0 ** rng.uniform(-3, 8, size=(4000, 3))  # condition numbers up to ~1e11
    Qm = np.linalg.qr(X)[0]
    P = Qm @ (scales[:, :, None] * np.swapaxes(Qm, 1, 2))
    P = np.concatenate([P, np.eye(3)[None] * 2.5, np.diag([4.0, 4.0, 1.0])[None], np.zeros((1, 3, 3))])
    want = np.linalg.eigvalsh(0.5 * (P + np.swapaxes(P, 1, 2)))[:, -1]
    assert np.allclose(mm.sym_norm(P), want, rtol=1e-10, atol=1e-300)
    assert np.isinf(mm.sym_norm(np.full((1, 3, 3), np.inf))).all()
