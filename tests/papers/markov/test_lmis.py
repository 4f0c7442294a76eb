"""Tests of `markov`: the LMI (10)-(11), Theorem 5's bisection and the Schur identity, each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from netrepro.papers.markov import lmis, model
from .systems import A1, C1, A2, C2, A3, C3


def test_lmi_block_form_is_schur_of_L():
    """Schur complement of Psi (11) is X - sum_i w_i M_i' Y M_i with K^{(i)} = Y^{-1} F_i' (for l_o = 2 and 3)."""
    rng = np.random.default_rng(2)
    assert lmis.schur_residual(A1, C1, 0.5, 0.65, rng) < 1e-9
    assert lmis.schur_residual(A3, C3, 0.5, 0.65, rng) < 1e-8


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

