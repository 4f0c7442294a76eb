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


def _sym_norm_2x2_masked(P):
    """The masked form the 2 x 2 path of sym_norm replaced (reference path): zero the matrices with a
    non-finite entry, evaluate, then put inf there."""
    P = np.asarray(P, dtype=float)
    bad = ~np.isfinite(P).all(axis=(-1, -2))
    Pf = np.where(bad[..., None, None], 0.0, P)
    with np.errstate(over="ignore", invalid="ignore"):
        a, b, d = Pf[..., 0, 0], 0.5 * (Pf[..., 0, 1] + Pf[..., 1, 0]), Pf[..., 1, 1]
        val = 0.5 * (a + d) + np.sqrt(0.25 * (a - d) ** 2 + b * b)
    return np.where(bad, np.inf, val)


def _hard_2x2_cases():
    rng = np.random.default_rng(12)
    G = rng.standard_normal((3000, 2, 2)) * 10.0 ** rng.uniform(-150, 150, size=(3000, 1, 1))
    P = [G @ np.swapaxes(G, 1, 2), rng.standard_normal((500, 2, 2))]  # PSD over 300 decades; non-symmetric
    ties = np.array([[[1.0, 0.0], [0.0, 1.0]], [[2.5, 1e-300], [0.0, 2.5]], [[0.0, 0.0], [0.0, 0.0]],
                     [[1.0, 1e-17], [1e-17, 1.0 + 2e-16]], [[5e-324, 0.0], [0.0, 5e-324]]])
    big = np.array([[[1e308, 0.0], [0.0, 1e308]], [[1.7e308, 1e300], [1e300, 1.7e308]],  # a + d overflows
                    [[1e308, 0.0], [0.0, -1e308]],                                      # a - d overflows
                    [[-1.7e308, 1e308], [1e308, -1.7e308]],                             # -inf + inf: nan
                    [[1.0, 1e200], [1e200, 1.0]]])                                      # b^2 overflows
    nonfinite = []
    for i in range(2):
        for j in range(2):
            for x in (np.inf, -np.inf, np.nan):
                M = np.array([[3.0, 0.5], [0.5, 2.0]])
                M[i, j] = x
                nonfinite.append(M)
    nonfinite += [np.array([[1.0, np.inf], [-np.inf, 1.0]]), np.full((2, 2), np.inf), np.full((2, 2), -np.inf),
                  np.array([[np.inf, 0.0], [0.0, -np.inf]]), np.array([[1e308, np.inf], [np.inf, 1e308]])]
    return np.concatenate(P + [ties, big, np.array(nonfinite)])


def test_sym_norm_2x2_is_the_masked_form_bit_for_bit():
    P = _hard_2x2_cases()
    want = _sym_norm_2x2_masked(P)
    with np.errstate(over="ignore"):
        got = model.sym_norm(P)
        assert got.tobytes() == want.tobytes()  # nan, inf and -0.0 included
        # batch shapes: a leading grid, one matrix (0-d result), an empty batch, integer entries
        m = len(P) // 5 * 5
        assert model.sym_norm(P[:m].reshape(-1, 5, 2, 2)).tobytes() == want[:m].tobytes()
        one = model.sym_norm(P[-1])
        assert isinstance(one, np.ndarray) and one.shape == () and one.tobytes() == want[-1].tobytes()
        assert model.sym_norm(P[:0]).shape == (0,)
    assert model.sym_norm(np.array([[[2, 1], [1, 2]]])).tobytes() == np.array([3.0]).tobytes()
    assert np.isnan(want).any() and np.isinf(want).any()  # the cases reach both non-finite outcomes
    # and against LAPACK where the entries are finite and moderate (independent of both forms; the closed form
    # loses b^2 to underflow below ~1e-154 and overflows above ~1e154, in both forms alike)
    mag = np.abs(P).max(axis=(1, 2))
    ok = np.isfinite(P).all(axis=(1, 2)) & (mag < 1e100) & (mag > 1e-100)
    S = 0.5 * (P[ok] + np.swapaxes(P[ok], 1, 2))
    assert np.allclose(got[ok], np.linalg.eigvalsh(S)[:, -1], rtol=1e-12, atol=1e-300)


def test_sym_norm_2x2_only_masks_rows_with_a_non_finite_entry():
    # the masking branch (a non-finite value) taken with and without a non-finite entry in the same batch
    P = np.array([[[np.nan, 0.0], [0.0, 1.0]], [[1e308, 0.0], [0.0, 1e308]], [[2.0, 0.0], [0.0, 1.0]]])
    with np.errstate(over="ignore"):
        got = model.sym_norm(P)
    assert got[0] == np.inf and got[1] == np.inf and got[2] == 2.0
    assert np.isnan(model.sym_norm(np.array([[[-1.7e308, 1e308], [1e308, -1.7e308]]]))[0])  # finite entries: kept


def test_batched_trace_is_np_trace_bit_for_bit():
    rng = np.random.default_rng(13)
    for n in (1, 2, 3):
        P = rng.standard_normal((4000, n, n)) * 10.0 ** rng.uniform(-300, 300, size=(4000, 1, 1))
        P[::7] = -0.0  # np.trace sums from 0.0: a diagonal of -0.0 gives 0.0
        P[::11, 0, 0] = np.inf
        P[::13, -1, -1] = -np.inf  # with ::11: inf - inf
        P[::17, 0, 0] = np.nan
        P[::19, 0, 0], P[::19, -1, -1] = 1e308, 1e308  # overflow
        with np.errstate(over="ignore", invalid="ignore"):
            want = np.trace(P, axis1=-2, axis2=-1)
            got = model.batched_trace(P)
            assert got.dtype == want.dtype and got.tobytes() == want.tobytes()
            grid = P[:3990].reshape(10, 399, n, n)
            assert model.batched_trace(grid).tobytes() == np.trace(grid, axis1=-2, axis2=-1).tobytes()
        assert float(model.batched_trace(P[1])) == float(sum(P[1][i, i] for i in range(n)))  # one matrix
    ints = np.arange(8).reshape(2, 2, 2)  # another dtype: np.trace itself (an integer result)
    assert model.batched_trace(ints).dtype == ints.dtype and list(model.batched_trace(ints)) == [3, 11]


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


def test_defective_unit_circle_eigenvalues_on_jordan_blocks():
    """Definition 4 on matrices whose Jordan structure is known by construction (similarity by a random T)."""
    rng = np.random.default_rng(5)
    T = rng.standard_normal((3, 3)) + 3 * np.eye(3)
    Ti = np.linalg.inv(T)
    jordan_on = np.array([[1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]])  # defective eigenvalue 1
    semisimple = np.diag([1.0, 1.0, 0.5])  # eigenvalue 1 twice, two eigenvectors
    jordan_off = np.array([[1.2, 1.0, 0.0], [0.0, 1.2, 0.0], [0.0, 0.0, -1.0]])  # defective, but off the circle
    rotation = np.array([[0.0, -1.0], [1.0, 0.0]])  # eigenvalues +-i, simple
    assert model.defective_unit_circle_eigenvalues(T @ jordan_on @ Ti) == 1
    assert model.defective_unit_circle_eigenvalues(T @ semisimple @ Ti) == 0
    assert model.defective_unit_circle_eigenvalues(T @ jordan_off @ Ti) == 0
    assert model.defective_unit_circle_eigenvalues(rotation) == 0
    # the paper's examples have no eigenvalue on the unit circle
    assert model.defective_unit_circle_eigenvalues(A1) == model.defective_unit_circle_eigenvalues(A2) == 0
