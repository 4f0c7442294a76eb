"""Issue 17 mathematics: paired design, gamma_0 levels, consensus time constants, evader certificate.

Each result is checked against an independent computation (a separate simulation, scipy's optimiser,
the full iteration matrix, scipy's paired t-test).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from scipy.optimize import minimize

from netrepro.papers.hinf.consensus import adjacency, laplacian, pi_consensus_step, pi_consensus_time_constants
from netrepro.papers.hinf.evader import evader_decisions, fused_trace_bounds, min_fused_trace, min_fused_trace_pairwise
from netrepro.papers.hinf.filters import FilterDoesNotExist
from netrepro.papers.hinf.model import layout_positions, paired_z, run_paired, simulate, window_means
from netrepro.papers.hinf.noise import NoiseModel, geometry, noise_information

MODEL = NoiseModel(0.3528, 15.625, 0.0008, 5.0)
I2 = np.eye(2)


def _scenario(target="evasive", **kw):
    sc = {
        "agents0": layout_positions({"n": 4, "radius": 30.0, "spacing_deg": 30.0, "start_deg": -135.0}),
        "target0": np.zeros(2), "target": target, "W_true": 0.01 * I2, "W_filter": 0.01 * I2, "A": I2, "gamma": 3.0,
        "Lbar": I2, "P0": 4.0, "psd_floor": 1e-9, "model": MODEL, "radius": 20.0,
        "consensus": {"gamma_c": 0.5, "h": 0.5, "K_p": 0.4, "K_i": 0.2, "iters": 1},
        "control": {"Gamma": 20000.0, "v_max": 0.5, "recursion": True},
        "evader": {"n_headings": 8, "n_iter": 10, "step": 0.14}, "mobile": True, "driver": "decentralized",
        "filters": ["decentralized"], "horizon": 25, "runs": 5, "seed": 11,
    }
    sc.update(kw)
    return sc


@pytest.mark.parametrize("target", ["evasive", "random"])
def test_all_filters_see_identical_trajectories_and_measurements(target):
    sc = _scenario(target)
    res = run_paired(sc, [1.1, 2.0])
    out = res["out"]
    # an independent run with a different filter set (driver + one Kalman filter), the target simulated, not replayed
    other = simulate({**sc, "filters": ["decentralized", "kalman_local"]})
    np.testing.assert_array_equal(other["target"], out["target"])
    np.testing.assert_array_equal(other["agents"], out["agents"])
    # same measurements: a filter's errors do not depend on which other filters run beside it
    np.testing.assert_array_equal(other["errors"]["kalman_local"], out["errors"]["kalman_local"])
    np.testing.assert_array_equal(other["errors"]["decentralized"], out["errors"]["decentralized"])
    alone = simulate({**sc, "filters": ["decentralized", "centralized"], "filter_gamma": {"centralized": 5.0}})
    np.testing.assert_array_equal(alone["agents"], out["agents"])


def test_gamma0_levels_are_existence_thresholds():
    sc = _scenario("random")
    res = run_paired(sc, [1.1])
    path = res["out"]["target"]
    for kind, g0 in res["gamma0"].items():
        base = {**sc, "target": "replay", "target_path": path}
        copy = {"filters": ["decentralized", "copy"], "filter_base": {"copy": kind}}  # the driver keeps its gamma
        out = simulate({**base, **copy, "filter_gamma": {"copy": 1.01 * g0}})
        np.testing.assert_array_equal(out["agents"], res["out"]["agents"])
        with pytest.raises(FilterDoesNotExist, match="gamma below gamma_0"):
            simulate({**base, **copy, "filter_gamma": {"copy": 0.97 * g0}})


def test_paired_z_is_the_paired_t_statistic():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=50), rng.normal(size=50) + 0.3
    mean, se, z = paired_z(a, b)
    t = stats.ttest_rel(a, b).statistic
    assert z == pytest.approx(t, rel=1e-12)
    assert mean == pytest.approx(np.mean(a - b))


def test_window_means_against_loops():
    rng = np.random.default_rng(1)
    e = rng.random((3, 4, 11))
    got = window_means(e, 5, 8)
    want = [np.mean([e[r, i, k] for i in range(4) for k in range(5, 9)]) for r in range(3)]
    np.testing.assert_allclose(got, want)


def _slsqp_min(M):
    n = M.shape[0]

    def f(lam):
        return np.trace(np.linalg.inv(np.tensordot(lam, M, 1)))

    res = minimize(f, np.full(n, 1.0 / n), method="SLSQP", bounds=[(0, 1)] * n,
                   constraints=[{"type": "eq", "fun": lambda l: l.sum() - 1}], options={"ftol": 1e-14, "maxiter": 500})
    return res.fun


def test_fused_trace_bounds_bracket_the_minimum():
    rng = np.random.default_rng(2)
    agents = rng.normal(scale=20, size=(30, 4, 2))
    x = rng.normal(scale=3, size=(30, 2))
    r, th = geometry(x, agents)
    M = noise_information(r, th, MODEL)
    for solver in (min_fused_trace, min_fused_trace_pairwise):
        up, lam = solver(M, 40)
        val, low = fused_trace_bounds(M, lam)
        for i in range(len(M)):
            true = _slsqp_min(M[i])
            assert low[i] <= true + 1e-9 and true <= up[i] + 1e-9
            assert low[i] <= val[i] + 1e-15


def test_certified_evader_choice_is_the_true_argmax():
    rng = np.random.default_rng(3)
    agents = rng.normal(scale=20, size=(6, 4, 2))
    x = rng.normal(scale=3, size=(6, 2))
    d = evader_decisions(x, agents, MODEL, 0.5, 6, 200, "pairwise")
    phi = 2 * np.pi * np.arange(6) / 6
    offs = np.concatenate([np.zeros((1, 2)), 0.5 * np.stack([np.cos(phi), np.sin(phi)], -1)])
    for i in np.nonzero(d["certified"])[0]:
        vals = []
        for o in offs:
            r, th = geometry(x[i] + o, agents[i])
            vals.append(_slsqp_min(noise_information(r, th, MODEL)))
        assert int(np.argmax(vals)) == d["choice"][i]
    assert d["certified"].any()
    from netrepro.papers.hinf.evader import evader_move
    moved, _ = evader_move(x, agents, MODEL, 0.5, 6, 200, "pairwise")
    np.testing.assert_allclose(moved, x + offs[d["choice"]])


def test_consensus_time_constants_against_full_matrix_and_simulation():
    ag = layout_positions({"n": 10, "radius": 40.0, "spacing_deg": 20.0, "start_deg": -90.0})
    L = laplacian(adjacency(ag, 20.0))
    gc, h, kp, ki = 0.5, 0.5, 0.4, 0.2
    lam = np.linalg.eigvalsh(L)
    rho, tau = pi_consensus_time_constants(lam, gc, h, kp, ki)
    n = len(lam)
    F = np.block([[(1 - gc * h) * np.eye(n) - h * kp * L, h * ki * L], [-h * ki * L, np.eye(n)]])
    mod = np.abs(np.linalg.eigvals(F))
    nontrivial = np.sort(mod[np.abs(mod - 1) > 1e-9])
    assert rho[1:].max() == pytest.approx(nontrivial[-1], rel=1e-9)
    # the consensus error of a simulation decays at the slow rate
    rng = np.random.default_rng(4)
    u = rng.normal(size=(n, 1))
    v, w = u.copy(), np.zeros_like(u)
    errs = []
    for k in range(12001):
        if k in (8000, 12000):
            errs.append(np.abs(v - u.mean()).max())
        v, w = pi_consensus_step(v, w, u, L, gc, h, kp, ki)
    assert errs[1] / errs[0] == pytest.approx(rho[1:].max() ** 4000, rel=0.05)
    assert tau[1:].max() == pytest.approx(-1 / np.log(rho[1:].max()))
    # K_i = 0: only the proportional mode acts on v
    rho0, _ = pi_consensus_time_constants(lam, gc, h, kp, 0.0)
    np.testing.assert_allclose(rho0, np.abs(1 - gc * h - h * kp * lam))
