"""Theorem 3 of the `gainsched` paper: vertex LMIs (24)-(25), gain recovery (26), certificates."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.gainsched.design import Theorem3, certificate_from_solution, congruence_residual, recover_gains
from netrepro.papers.gainsched.model import (
    System,
    frozen_radius,
    p_schedule,
    sector_cases,
    simulate,
    theorem1_grid_check,
    theorem1_matrix,
)


@pytest.mark.parametrize("realisation", ["identity_T", "S21_identity"])
def test_theorem3_vertices_are_congruent_to_theorem1(sys, realisation):
    """Σ α_iα_jα_rβ_l M^{ijrl} (24), (29)-(33) equals diag(T,I,T,T,T)^T (12) diag(T,I,T,T,T)
    with the gains (26), S from (23) and Q = T^{-T} Q̄ T^{-1}: checks every block and transpose."""
    rng = np.random.default_rng(3)
    prob = Theorem3(sys)
    vals = {}
    for name, var in prob.vars.items():
        val = rng.standard_normal(var.shape)
        if name in ("Q0", "Qp"):
            val = val @ val.T + np.eye(var.shape[0])
        var.value = val
        vals[name] = val
    g, extra = recover_gains(vals, realisation)
    cert = certificate_from_solution(vals, realisation)
    T = extra["T"]
    ps = (sys.p1, sys.p2)
    for p, pn in ((0.5, 0.7), (0.43, 0.8), (0.79, 0.41)):
        a = ((sys.p2 - p) / (sys.p2 - sys.p1), (p - sys.p1) / (sys.p2 - sys.p1))  # (28)
        b = ((sys.p2 - pn) / (sys.p2 - sys.p1), (pn - sys.p1) / (sys.p2 - sys.p1))  # (30)
        combo = sum(a[i] * a[j] * a[r] * b[l] * prob.vertex(ps[i], ps[j], ps[r], ps[l]).value
                    for i in range(2) for j in range(2) for r in range(2) for l in range(2))
        M = theorem1_matrix(sys, g, cert["Q0"] + p * cert["Qp"], cert["Q0"] + pn * cert["Qp"], cert["S"], p)
        nz = sys.nz
        big = np.zeros((4 * 4 + nz, 4 * 4 + nz))
        big[:4, :4] = T
        big[4:4 + nz, 4:4 + nz] = np.eye(nz)
        for k in range(3):
            o = 4 + nz + 4 * k
            big[o:o + 4, o:o + 4] = T
        np.testing.assert_allclose(big.T @ M @ big, combo, atol=1e-9)


def test_congruence_residual_flags_gamma3_misreading(sys, t3):
    assert congruence_residual(sys, t3.values, [(0.5, 0.7), (0.8, 0.4)]) < 1e-9
    assert congruence_residual(sys, t3.values, [(0.5, 0.7)], gamma3_top="zero") > 1e-4


def test_realisations_have_same_stability(sys, t3):
    g1, _ = recover_gains(t3.values, "identity_T")
    g2, _ = recover_gains(t3.values, "S21_identity")
    for F in sector_cases(sys).values():
        for p in (sys.p1, 0.6, sys.p2):
            assert frozen_radius(sys, g1, p, F) == pytest.approx(frozen_radius(sys, g2, p, F), rel=1e-8)
    assert not np.allclose(g1.H0, g2.H0)


def test_theorem3_feasible_and_certified(sys, t3):
    assert t3.solver_feasible and t3.status == "optimal"
    for real in ("identity_T", "S21_identity"):
        g, _ = recover_gains(t3.values, real)
        c = certificate_from_solution(t3.values, real)
        worst, qmin, wv = theorem1_grid_check(sys, g, c["Q0"], c["Qp"], c["S"], n_fine=7)
        assert worst < 0 and qmin > 0 and wv <= worst + 1e-12


def test_performance_design_bound_holds(sys, cfg):
    """The performance design: sum_k E||e||^2 (Monte Carlo) below the certified gamma."""
    X0 = np.zeros((4, 4))
    X0[:2, :2] = np.eye(2)
    sol = Theorem3(sys, performance=True, X0=X0, bound=100.0).solve()
    assert sol.values
    g, _ = recover_gains(sol.values, "identity_T")
    x0 = np.random.default_rng(6).standard_normal((4000, 2))
    e = simulate(sys, g, p_schedule(np.arange(40), sys.p1, sys.p2, 1.0), x0, np.random.default_rng(7))
    assert (e ** 2).sum(-1).mean(0).sum() <= sol.objective


def test_noise_free_case_needs_the_last_row_removed(sys):
    """At σ² = 0 the printed (24) has a zero diagonal block: strictly infeasible; without it, feasible."""
    s0 = System(sys.A, sys.B, sys.C, sys.D, sys.Z, sys.F1, sys.F2, 0.0, sys.p1, sys.p2)
    assert not Theorem3(s0, bound=100.0).solve().solver_feasible
    assert Theorem3(s0, bound=100.0, noise_row=False).solve().solver_feasible



def test_full_slack_performance_design_cost_is_certified_and_respected(sys):
    """The full-slack design: its checked point certifies gamma; the exact error sums (any linear f at the sector
    edges, worst p(k) of a few fixed sequences) stay below it, and it beats x_f = 0 (independent: exact recursion)."""
    from netrepro.papers.gainsched.design import certified_cost, output_certificate, recover_output_gains
    from netrepro.papers.gainsched.model import augmented_initial_moment, zero_gains
    from netrepro.papers.gainsched.moments import error_mse, linear_gains, mode_matrices, second_moments

    X0 = augmented_initial_moment(np.eye(2), 2)
    prob = Theorem3(sys, performance=True, output_slack=True, X0=X0, bound=100.0)
    sol = prob.solve()
    ok, slack = prob.check_point(sol.values, sys.sigma2)
    assert ok and slack > 0
    gamma = certified_cost(sol.values, X0, sys.p1, sys.p2)
    g = recover_output_gains(sol.values)
    # Theorem 1 with the performance term, rebuilt from the final gains and the transformed certificate
    c = output_certificate(sol.values)
    worst, qmin, _ = theorem1_grid_check(sys, g, c["Q0"], c["Qp"], c["S"], n_fine=9, performance=True,
                                         multiplier=c["multiplier"])
    assert worst < 0 and qmin > 0
    sums = {}
    for name, gains in (("perf", g), ("zero", zero_gains(sys))):
        vals = []
        for F in linear_gains(sys).values():
            for p_seq in (np.full(60, sys.p1), np.full(60, sys.p2), p_schedule(np.arange(60), sys.p1, sys.p2, 1.0),
                          np.where(np.arange(60) % 2, sys.p1, sys.p2)):
                M1, M0, W = mode_matrices(sys, gains, p_seq, F)
                vals.append(error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, X0)).sum())
        sums[name] = np.array(vals)
    assert np.all(sums["perf"] <= gamma)
    assert np.all(sums["perf"] < sums["zero"])
