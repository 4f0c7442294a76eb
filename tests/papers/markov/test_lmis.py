"""Tests of `markov`: the LMI (10)-(11), Theorem 5's bisection and the Schur identity, each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from netrepro.papers.markov import lmis, model
from .systems import A1, C1, A2, C2, A3, C3


def _own_blocks(A, C, p, q, rng):
    """The two matrix blocks of the compiled LMI (10) and (11), evaluated at random X, Y > 0 and F_i (t = 0)."""
    lmi = lmis.GilbertElliottLMI(A, C)
    n, m = A.shape[0], C.shape[0]
    G = rng.standard_normal((n, n))
    X, Y = 50.0 * np.eye(n), G @ G.T + np.eye(n)
    F = [rng.standard_normal((m * i, n)) for i in range(1, lmi.l_o)]
    lmi.X.value, lmi.Y.value, lmi.t.value = X, Y, 0.0
    for var, val in zip(lmi.F, F):
        var.value = val
    lmi._set(p, q)
    (_, c10), (_, c11) = lmi.blocks
    return lmi.l_o, X, Y, F, np.asarray(c10.args[0].value), np.asarray(c11.args[0].value)


@pytest.mark.parametrize("A, C", [(A1, C1), (A3, C3)], ids=["l_o=2", "l_o=3"])
def test_lmi_own_blocks_are_the_schur_forms_of_theorem2(A, C):
    """The LMI as compiled (its constraint expressions, evaluated): the Schur complement of Psi (11) over its Y blocks
    is X - sum_i w_i M_i' Y M_i with M_i = A^i + K^{(i)} C^{(i)}, K^{(i)} = Y^{-1} F_i', C^{(i)} = [C; CA; ...; CA^{i-1}]
    (built here, not by the module), and the Schur complement of (10) over diag(Y, X) is Y - (1-q) A'YA - q A'XA."""
    p, q = 0.5, 0.65
    l_o, X, Y, F, b10, psi = _own_blocks(A, C, p, q, np.random.default_rng(2))
    n = A.shape[0]
    r = l_o - 1
    assert psi.shape == (n * (r + 1), n * (r + 1)) and b10.shape == (3 * n, 3 * n)
    B, D = psi[n:, :n], psi[n:, n:]
    assert np.allclose(D, np.kron(np.eye(r), Y), atol=1e-12)  # the Y blocks on the diagonal, zeros elsewhere
    schur = psi[:n, :n] - B.T @ np.linalg.solve(D, B)
    direct = X.copy()
    for i in range(1, l_o):
        Ci = np.vstack([C @ np.linalg.matrix_power(A, j) for j in range(i)])
        M = np.linalg.matrix_power(A, i) + np.linalg.solve(Y, F[i - 1].T) @ Ci
        direct -= p * (1 - p) ** (i - 1) * M.T @ Y @ M
    assert np.max(np.abs(schur - direct)) < 1e-8 * np.max(np.abs(direct))
    lower = np.zeros((2 * n, 2 * n))
    lower[:n, :n], lower[n:, n:] = Y, X
    s10 = b10[:n, :n] - b10[:n, n:] @ np.linalg.solve(lower, b10[n:, :n])
    assert np.allclose(s10, Y - (1 - q) * A.T @ Y @ A - q * A.T @ X @ A, atol=1e-9)
    # the module's helper (erratum E1's residual) agrees with the blocks
    assert lmis.schur_residual(A, C, p, q, np.random.default_rng(2)) < 1e-8


def test_lmi_feasible_is_certified_and_matches_rebuild():
    lmi = lmis.GilbertElliottLMI(A1, C1)
    res = lmi.solve(1 - 1e-6, 0.65)  # Section 5.1: feasible at p = 1
    assert res.certified and res.rho_H < 1 and res.lyap_margin > 0
    # Theorem 2 (iii) with the recovered gain: L_K(X) < X for the solver's X
    again = lmis.rebuild_solve(A1, C1, 1 - 1e-6, 0.65)
    assert again.margin == pytest.approx(res.margin, rel=1e-4)
    bad = lmis.GilbertElliottLMI(A2, C2).solve(1.0, 0.5)  # Section 5.2: infeasible at p = 1, q = 0.5
    assert not bad.certified and bad.verdict == "infeasible"


def test_thm5_equals_direct_minimisation_of_rho():
    """For l_o = 2, p_underline(q) = 1 / min_K rho(H(K)/p): LMI bisection vs Nelder-Mead on K."""
    q = 0.5
    lmi = lmis.GilbertElliottLMI(A1, C1)
    res = lmis.thm5_lower_bound(lmi, q, 5.0, 1e-5)

    def rho(k):
        return model.h_radius(A1, C1, [k.reshape(2, 1)], 1.0, q)

    best = min((minimize(rho, x0, method="Nelder-Mead", options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 4000})
                for x0 in ([-1.0, -0.5], [0.0, 0.0], [-2.0, 1.0])), key=lambda r: r.fun)
    assert res["p_lower"] == pytest.approx(1.0 / best.fun, abs=2e-4)
    assert res["n_uncertified"] == 0


def test_thm5_example2_closed_form():
    lmi = lmis.GilbertElliottLMI(A2, C2)
    res = lmis.thm5_lower_bound(lmi, 0.5, 1.0, 1e-6)
    closed = model.parity_bound_example2(1.2, 0.5)
    assert closed == pytest.approx(0.464506, abs=1e-6)
    # issue 16: both ends certified, and the true boundary (closed form) lies inside the bracket
    assert res["certified"] and res["p_lower"] <= closed <= res["p_upper"]
    assert res["p_upper"] - res["p_lower"] < 2e-6 and res["n_uncertified"] == 0
    assert res["p_lower"] < 0.465  # the paper's "p <= 0.465" is not certified


def test_necessary_condition_is_the_closed_form_and_the_direct_minimum():
    """The kernel (Collatz-Wielandt) bound: Example II = the parity closed form; Example I = 1 / min_K rho(H_1(K))
    found by Nelder-Mead (certificates.thm1_radius, a different algorithm); both tight to 1e-7."""
    from netrepro.papers.markov.certificates import thm1_radius

    for q in (0.4, 0.5, 0.8):
        closed = model.parity_bound_example2(1.2, q)
        assert lmis.lmi_necessary_condition(A2, C2, closed * (1 + 1e-7), q)[0]
        assert not lmis.lmi_necessary_condition(A2, C2, closed * (1 - 1e-7), q)[0]
    rho1, _ = thm1_radius(A1, C1, [0.5, 0.7])
    for q, r in zip((0.5, 0.7), rho1):
        assert lmis.lmi_necessary_condition(A1, C1, (1 + 1e-6) / r, q)[0]
        assert not lmis.lmi_necessary_condition(A1, C1, (1 - 1e-6) / r, q)[0]
    assert lmis.lmi_necessary_condition(A1, C1, 0.1, 0.3)[0]  # |lambda|^2 (1-q) >= 1

