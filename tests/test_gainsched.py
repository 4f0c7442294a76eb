"""Tests of the `gainsched` paper: each equation against an independent computation."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from netrepro.config import ConfigError
from netrepro.papers import gainsched as gs
from netrepro.papers.gainsched_design import Theorem3, certificate_from_solution, congruence_residual, recover_gains
from netrepro.papers.gainsched_model import (
    Gains,
    GainschedError,
    augmented,
    frozen_radius,
    gains_from_dict,
    p_schedule,
    scheduled_growth_rate,
    sector_cases,
    sector_nonlinearity,
    sector_split,
    simulate,
    system_from_config,
    theorem1_grid_check,
    theorem1_lmi,
    theorem1_matrix,
)


@pytest.fixture(scope="module")
def cfg():
    with open("config/test.yaml") as fh:
        return yaml.safe_load(fh)["gainsched"]


@pytest.fixture(scope="module")
def sys(cfg):
    return system_from_config(cfg["system"])


@pytest.fixture(scope="module")
def paper(cfg, sys):
    return gains_from_dict(cfg["paper_gains"], sys)


@pytest.fixture(scope="module")
def t3(sys):
    sol = Theorem3(sys, bound=100.0).solve()
    assert sol.values, sol.status
    return sol


def _random_gains(rng, sys, scale=0.3):
    n, m = sys.n, sys.m
    return Gains(scale * rng.standard_normal((n, n)), scale * rng.standard_normal((n, n)),
                 rng.standard_normal((n, m)), rng.standard_normal((n, m)))


def test_check_config_accepts_and_rejects(cfg):
    gs.check_config(cfg)
    bad = copy.deepcopy(cfg)
    bad["simulation"]["x0"] = [1.0, 2.0, 3.0]
    with pytest.raises(ConfigError, match="x0"):
        gs.check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["system"]["F2_diag"] = [0.1, 0.1]
    with pytest.raises(ConfigError, match="F2 - F1"):
        gs.check_config(bad)


def test_augmented_system_matches_plant_and_filter(sys):
    """(10)-(11) against one step of (1), (6), (8) computed directly, for both values of xi."""
    rng = np.random.default_rng(0)
    g = _random_gains(rng, sys)
    x, xf, w = rng.standard_normal(2), rng.standard_normal(2), 0.7
    p = 0.55
    f = sector_nonlinearity((sys.Z @ x)[None], sys.F1, sys.F2)[0]
    for xi in (0.0, 1.0):
        x_next = sys.A @ x + sys.B @ f + sys.D @ x * w
        xf_next = g.G(p) @ xf + g.H(p) @ (xi * sys.C @ x)
        aug = augmented(sys, g, p)
        zb = np.concatenate([x, xf])
        z_next = aug["A"] @ zb + aug["B"] @ f + (xi - p) * aug["C"] @ aug["N"] @ zb + aug["D"] @ aug["N"] @ zb * w
        np.testing.assert_allclose(z_next, np.concatenate([x_next, xf_next]), atol=1e-12)


def test_sector_decomposition(sys):
    """(3)-(5): the named nonlinearity and the linear extremes satisfy the sector condition."""
    z = np.random.default_rng(1).standard_normal((500, 2)) * 5
    for kind in ("sine_mid", "lower", "upper"):
        f = sector_nonlinearity(z, sys.F1, sys.F2, kind)
        fs, s = sector_split(f, z, sys.F1, sys.F2)
        np.testing.assert_allclose(f, z @ sys.F1.T + fs)  # (4)
        assert np.all(s <= 1e-12)  # (5)
        # (3) directly
        assert np.all(np.einsum("ri,ri->r", f - z @ sys.F1.T, f - z @ sys.F2.T) <= 1e-12)
    with pytest.raises(GainschedError, match="kind"):
        sector_nonlinearity(z, sys.F1, sys.F2, "cubic")


def test_p_schedule_in_bounds():
    p = p_schedule(np.arange(200), 0.4, 0.8, 1.0)
    assert p.min() >= 0.4 and p.max() <= 0.8 and p[0] == 0.4
    assert p.max() > 0.79


def test_theorem1_schur_complement_gives_pi(sys):
    """With S = Q(p(k+1)), Λ = Q(p(k+1)) and the Schur complement of (12) is Π of (17)-(18)."""
    rng = np.random.default_rng(2)
    g = _random_gains(rng, sys)
    p, pn = 0.47, 0.71
    M0 = rng.standard_normal((4, 4))
    Qn = M0 @ M0.T + np.eye(4)
    Qc = np.eye(4) * 2.0
    M = theorem1_matrix(sys, g, Qc, Qn, Qn, p)
    nz, nn = sys.nz, 4
    a = nn + nz
    Mab, Mbb = M[a:, :a], M[a:, a:]
    schur = M[:a, :a] - Mab.T @ np.linalg.solve(Mbb, Mab)
    aug = augmented(sys, g, p)
    N = aug["N"]
    AF = aug["A"] + aug["B"] @ sys.F1 @ sys.Z @ N
    CN, DN = aug["C"] @ N, aug["D"] @ N
    pi1 = AF.T @ Qn @ AF + sys.sigma2 * DN.T @ Qn @ DN + p * (1 - p) * CN.T @ Qn @ CN - Qc
    pi2 = aug["B"].T @ Qn @ AF + sys.F @ sys.Z @ N
    pi3 = -2 * np.eye(nz) + aug["B"].T @ Qn @ aug["B"]
    Pi = np.block([[pi1, pi2.T], [pi2, pi3]])
    np.testing.assert_allclose(schur, Pi, atol=1e-10)


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


def test_theorem1_rejects_unstable_filter(sys, paper):
    """A filter matrix with spectral radius > 1 cannot pass Theorem 1; the printed gains do."""
    ok = theorem1_lmi(sys, paper, n_grid=2)
    assert ok.solver_feasible
    bad = Gains(1.2 * np.eye(2), np.zeros((2, 2)), paper.H0, np.zeros_like(paper.Hf))
    res = theorem1_lmi(sys, bad, n_grid=2)
    assert not res.solver_feasible
    assert frozen_radius(sys, bad, 0.6, sector_cases(sys)["F11"]) > 1


def test_second_moment_operator_matches_simulation(sys, paper):
    """E||e(k)||^2 from the second-moment recursion vs Monte Carlo (linear f = F1 z, constant p)."""
    p, K, R = 0.6, 6, 40000
    x0 = np.array([1.0, -0.5])
    e = simulate(sys, paper, np.full(K, p), np.tile(x0, (R, 1)), np.random.default_rng(4), "lower")
    mc = (e[:, -1] ** 2).sum(-1)
    from netrepro.papers.gainsched_model import second_moment_operator
    loops, w = second_moment_operator(sys, paper, p, sys.F1)
    X = np.outer(np.r_[x0, 0, 0], np.r_[x0, 0, 0])
    for _ in range(K):
        X = sum(wi * L @ X @ L.T for L, wi in zip(loops, w))
    L = np.hstack([np.eye(2), -np.eye(2)])
    exact = np.trace(L @ X @ L.T)
    assert abs(mc.mean() - exact) < 4 * mc.std() / np.sqrt(R)


def test_growth_rate_tends_to_frozen_radius(sys, paper):
    F = sector_cases(sys)["F22"]
    rho = frozen_radius(sys, paper, 0.6, F)
    assert scheduled_growth_rate(sys, paper, np.full(300, 0.6), F) == pytest.approx(rho, rel=2e-2)


def test_gains_table_round_trip(sys, paper):
    tab = gs.gains_table("paper", paper)
    assert list(tab.columns) == ["design", "matrix", "row", "col", "value"]
    back = gs.gains_from_table(tab, "paper", sys)
    for k in gs.MATRICES:
        np.testing.assert_array_equal(getattr(back, k), getattr(paper, k))


def test_eq15_corrected_sign_is_an_upper_bound(sys, paper):
    """E{ΔV} (14) <= right side of (15) with '-' for sector nonlinearities; the printed '+' is not a bound."""
    rng = np.random.default_rng(5)
    zb = rng.standard_normal((2000, 4))
    f = sector_nonlinearity(zb[:, :2] @ sys.Z.T, sys.F1, sys.F2, "upper")
    dv, corr, prin = gs._exact_dV_and_bounds(sys, paper, np.eye(4), 0.1 * np.eye(4), 0.5, 0.6, zb, f)
    assert np.all(dv <= corr + 1e-10)
    assert np.any(dv > prin + 1e-6)


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
    from netrepro.papers.gainsched_model import System

    s0 = System(sys.A, sys.B, sys.C, sys.D, sys.Z, sys.F1, sys.F2, 0.0, sys.p1, sys.p2)
    assert not Theorem3(s0, bound=100.0).solve().solver_feasible
    assert Theorem3(s0, bound=100.0, noise_row=False).solve().solver_feasible
