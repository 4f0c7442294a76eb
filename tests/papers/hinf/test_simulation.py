"""Tests of the named phases of the `hinf` simulation (netrepro.papers.hinf.simulation), each against an
independent computation: eq (1) by numpy's own multivariate normal, eqs (2)-(4) and (5), (6), (12)-(16)
written out by hand in loops over runs and agents."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yaml

from netrepro.errors import InputError
from netrepro.papers.hinf import simulation as S
from netrepro.papers.hinf.model import resolve_scenario, simulate
from netrepro.papers.hinf.noise import NoiseModel

ROOT = Path(__file__).resolve().parents[3]
MODEL = NoiseModel(0.3528, 15.625, 0.0008, 5.0)
I2 = np.eye(2)


def _cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["hinf"]


def _scenario(**kw):
    ang = np.deg2rad(-90.0 + 30.0 * np.arange(5))
    sc = {
        "agents0": np.stack([30.0 * np.cos(ang), 30.0 * np.sin(ang)], -1), "target0": np.zeros(2), "target": "random",
        "W_true": 0.01 * I2, "W_filter": 0.02 * I2, "A": np.array([[1.0, 0.1], [0.0, 1.0]]), "gamma": 3.0,
        "Lbar": I2, "P0": 4.0, "model": MODEL, "radius": 20.0,
        "consensus": {"gamma_c": 0.5, "h": 0.5, "K_p": 0.4, "K_i": 0.2, "iters": 2},
        "control": {"Gamma": 2000.0, "v_max": 0.5, "recursion": False},
        "evader": {"n_headings": 8, "n_iter": 20, "step": 0.14}, "mobile": False, "driver": "local",
        "filters": ["local", "decentralized", "centralized", "kalman_centralized"], "horizon": 5, "runs": 3,
        "seed": 11,
    }
    sc.update(kw)
    return S.Scenario.from_mapping(sc)


def _hand_covariance(r, th, m=MODEL):
    """Eq (3)-(4) written out: M = T diag(f_r, alpha f_r) T^T."""
    fr = m.a2 * (r - m.a1) ** 2 + m.a0
    T = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    return T @ np.diag([fr, m.alpha * fr]) @ T.T


def _setup(sc):
    plan = S.plan_filters(sc)
    rng0, rng_t, rng_m = (np.random.default_rng(s) for s in np.random.SeedSequence(sc.seed).spawn(3))
    return plan, S.initial_state(sc, plan, rng0, rng_t), rng_t, rng_m


# ------------------------------------------------------------------------------------------------ the scenario
def test_scenario_is_frozen_typed_and_read_only():
    cfg = _cfg()
    sc = S.Scenario.from_mapping(resolve_scenario(cfg, "fig2", runs=3))
    assert sc.runs == 3 and isinstance(sc.gamma, float) and isinstance(sc.filters, tuple)
    assert sc.agents0.shape == (cfg["layouts"][cfg["scenarios"]["fig2"]["layout"]]["n"], 2)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.runs = 4
    with pytest.raises(TypeError):
        sc.consensus["iters"] = 9
    assert S.Scenario.from_mapping(sc) is sc
    with pytest.raises(InputError, match="lacks"):
        S.Scenario.from_mapping({"target": "random"})
    with pytest.raises(InputError, match="unknown target mode"):
        simulate({**resolve_scenario(cfg, "fig2", runs=2, horizon=2), "target": "teleport"})


def test_plan_groups_filters_that_share_measurements():
    sc = _scenario(filters=["local", "copy", "decentralized", "centralized"], filter_base={"copy": "kalman_local"},
                   filter_gamma={"local": 5.0}, consensus_variants={"fast": {"iters": 7}})
    plan = S.plan_filters(sc)
    assert plan.groups == {"local": ["local", "copy"], "decentralized": ["decentralized"],
                           "centralized": ["centralized"], "fast": ["fast"]}
    assert plan.gi_of == {"local": 5.0 ** -2, "copy": 0.0, "decentralized": 3.0 ** -2, "centralized": 3.0 ** -2,
                          "fast": 3.0 ** -2}
    assert plan.cvars["fast"]["iters"] == 7 and plan.cons_ids == (None, "fast")
    with pytest.raises(InputError, match="driver"):
        S.plan_filters(_scenario(mobile=True, driver="centralized", filters=["local"]))


# ------------------------------------------------------------------------------------------ move the target
def test_move_target_random_walk_is_eq1_with_numpys_multivariate_normal():
    sc = _scenario()
    x = np.array([[1.0, 2.0], [0.0, -1.0], [3.0, 0.5]])
    got, fz = S.move_target(sc, 1, x, None, np.random.default_rng(5), S.gaussian_factor(sc.W_true))
    want = x @ sc.A.T + np.random.default_rng(5).multivariate_normal(np.zeros(2), sc.W_true, size=3)
    assert fz is None
    np.testing.assert_array_equal(got, want)


def test_move_target_without_noise_draws_nothing_and_other_modes():
    rng = np.random.default_rng(1)
    x = np.ones((3, 2))
    got, _ = S.move_target(_scenario(W_true=0 * I2), 1, x, None, rng, np.zeros((2, 2)))
    np.testing.assert_array_equal(got, x @ np.array([[1.0, 0.1], [0.0, 1.0]]).T)
    assert rng.standard_normal() == np.random.default_rng(1).standard_normal()  # the stream did not advance
    assert S.move_target(_scenario(target="stationary"), 1, x, None, rng, None)[0] is x
    np.testing.assert_array_equal(S.move_target(_scenario(target="drift"), 1, x, None, rng, None, drift=x)[0], 2 * x)
    path = np.arange(3 * 6 * 2, dtype=float).reshape(3, 6, 2)
    np.testing.assert_array_equal(S.move_target(_scenario(target="replay", target_path=path), 4, x, None, rng,
                                                None)[0], path[:, 4])


# ------------------------------------------------------------------------------------------------ measure
def test_measure_is_eqs_2_to_4_by_hand():
    sc = _scenario()
    x = np.array([[1.0, 2.0], [0.0, -1.0], [3.0, 0.5]])
    P = np.broadcast_to(sc.agents0, (3,) + sc.agents0.shape)
    Minv, yinfo = S.measure(x, P, MODEL, np.random.default_rng(8))
    eps = np.random.default_rng(8).standard_normal((3, 5, 2))  # the draws of eq (3), in numpy's order
    for r in range(3):
        for i in range(5):
            d = x[r] - P[r, i]
            rng_, th = np.hypot(*d), np.arctan2(d[1], d[0])
            M = _hand_covariance(rng_, th)
            np.testing.assert_allclose(Minv[r, i], np.linalg.inv(M), rtol=1e-12)
            fr = MODEL.a2 * (rng_ - MODEL.a1) ** 2 + MODEL.a0
            T = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
            y = x[r] + T @ (np.sqrt([fr, MODEL.alpha * fr]) * eps[r, i])
            np.testing.assert_allclose(yinfo[r, i], np.linalg.inv(M) @ y, rtol=1e-10)


# --------------------------------------------------------------------------------------- consensus round
def _inputs(sc, seed=2):
    plan, st, _, rng_m = _setup(sc)
    Minv, yinfo = S.measure(st.x, st.P, sc.model, np.random.default_rng(seed))
    return plan, st, Minv, yinfo


def test_consensus_round_is_eq5_by_hand_on_neighbour_sums():
    sc = _scenario(radius=25.0)
    plan, st, Minv, yinfo = _inputs(sc)
    S.consensus_round(plan, st, Minv, yinfo, 1e-9)
    c = sc.consensus
    R, N = Minv.shape[:2]
    u = np.concatenate([Minv.reshape(R, N, 4), yinfo], -1)
    for r in range(R):
        v, w = u[r].copy(), np.zeros_like(u[r])
        nb = [[j for j in range(N) if j != i and np.hypot(*(st.P[r, i] - st.P[r, j])) <= sc.radius] for i in range(N)]
        for _ in range(c["iters"]):
            dv = np.array([sum((v[i] - v[j] for j in nb[i]), np.zeros(6)) for i in range(N)])
            dw = np.array([sum((w[i] - w[j] for j in nb[i]), np.zeros(6)) for i in range(N)])
            v, w = ((1 - c["gamma_c"] * c["h"]) * v - c["h"] * c["K_p"] * dv + c["h"] * c["K_i"] * dw
                    + c["gamma_c"] * c["h"] * u[r]), w - c["h"] * c["K_i"] * dv
        np.testing.assert_allclose(st.yt[None][r], v[:, 4:], rtol=1e-12, atol=1e-14)
        C = v[:, :4].reshape(N, 2, 2)
        if np.linalg.eigvalsh((C + np.swapaxes(C, -1, -2)) / 2).min() > 1e-9:
            np.testing.assert_allclose(st.Ct[None][r], (C + np.swapaxes(C, -1, -2)) / 2, rtol=1e-12, atol=1e-14)


def test_consensus_round_exact_sums_on_a_connected_graph_are_the_network_mean():
    sc = _scenario(radius=1e3, consensus={"design": "exact_component", "iters": 1})
    plan, st, Minv, yinfo = _inputs(sc)
    S.consensus_round(plan, st, Minv, yinfo, 1e-9)
    np.testing.assert_allclose(st.Ct[None], np.broadcast_to(Minv.mean(1)[:, None], Minv.shape), rtol=1e-12)
    np.testing.assert_allclose(st.yt[None], np.broadcast_to(yinfo.mean(1)[:, None], yinfo.shape), rtol=1e-12)
    assert st.n_psd_fix == 0


# ------------------------------------------------------------------------------------------ update the filters
def _eq6(xhat, Sig, y_info, Sm, A, BWB, g2, Lbar):
    """Eq (6) written out with 2x2 inverses: Delta, the gain, the estimate, Sigma."""
    Delta = A @ Sig @ A.T + BWB
    K_y = Delta @ np.linalg.inv(I2 + Sm @ Delta) @ (y_info - Sm @ A @ xhat)
    return A @ xhat + K_y, Delta @ np.linalg.inv(I2 - g2 * Lbar @ Delta + Sm @ Delta)


def test_update_filters_is_eq6_and_eq9_by_hand():
    sc = _scenario(radius=25.0)
    plan, st, Minv, yinfo = _inputs(sc)
    x0 = {k: v.copy() for k, v in st.est.items()}
    S.consensus_round(plan, st, Minv, yinfo, 1e-9)
    S.update_filters(sc, plan, st, Minv, yinfo)
    R, N = Minv.shape[:2]
    Sig0 = sc.P0 * I2
    for r in range(R):
        for i in range(N):
            xl, Sl = _eq6(x0["local"][0, r, i], Sig0, yinfo[r, i], Minv[r, i], sc.A, sc.W_filter, 1 / 9, sc.Lbar)
            np.testing.assert_allclose(st.est["local"][0, r, i], xl, rtol=1e-10)
            np.testing.assert_allclose(st.cov["local"][0, r, i], Sl, rtol=1e-10)
            xd, Sd = _eq6(x0["decentralized"][0, r, i], Sig0, N * st.yt[None][r, i], N * st.Ct[None][r, i], sc.A,
                          sc.W_filter, 1 / 9, sc.Lbar)
            np.testing.assert_allclose(st.est["decentralized"][0, r, i], xd, rtol=1e-10)
            np.testing.assert_allclose(st.cov["decentralized"][0, r, i], Sd, rtol=1e-10)
        for f, g2 in enumerate((1 / 9, 0.0)):  # centralized H-infinity, then its Kalman limit
            xc, Sc = _eq6(x0["centralized"][f, r], Sig0, yinfo[r].sum(0), Minv[r].sum(0), sc.A, sc.W_filter, g2,
                          sc.Lbar)
            np.testing.assert_allclose(st.est["centralized"][f, r], xc, rtol=1e-10)
            np.testing.assert_allclose(st.cov["centralized"][f, r], Sc, rtol=1e-10)


# ------------------------------------------------------------------------------------------ move the agents
def test_move_agents_is_the_gradient_law_12_by_hand():
    """Without the recursion (14), dSigma/dz = -Sigma dS/dz Sigma: eq (12) by hand, dS by finite differences."""
    sc = _scenario(mobile=True, driver="local")
    plan, st, Minv, yinfo = _inputs(sc)
    S.consensus_round(plan, st, Minv, yinfo, 1e-9)
    S.update_filters(sc, plan, st, Minv, yinfo)
    P0 = st.P.copy()
    S.move_agents(sc, plan, st, Minv)
    g2, eps = 1 / 9, 1e-6
    R, N = Minv.shape[:2]
    for r in range(R):
        for i in range(N):
            d = st.est["local"][0, r, i] - P0[r, i]
            rh, th = np.hypot(*d), np.arctan2(d[1], d[0])
            Delta = sc.A @ (sc.P0 * I2) @ sc.A.T + sc.W_filter
            Sig = np.linalg.inv(np.linalg.inv(Delta) + Minv[r, i] - g2 * sc.Lbar)
            info = lambda r_, t_: np.linalg.inv(_hand_covariance(r_, t_))  # noqa: E731
            dS_r = (info(rh + eps, th) - info(rh - eps, th)) / (2 * eps)
            dS_t = (info(rh, th + eps) - info(rh, th - eps)) / (2 * eps)
            gr, gt = -np.trace(Sig @ dS_r @ Sig), -np.trace(Sig @ dS_t @ Sig)
            T = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
            u = sc.control["Gamma"] * T @ np.array([gr, gt / rh])
            u = u * min(1.0, sc.control["v_max"] / np.hypot(*u))
            np.testing.assert_allclose(st.P[r, i] - P0[r, i], u, rtol=1e-5, atol=1e-9)
    moved = np.hypot(*(st.P - P0).transpose(2, 0, 1))
    assert moved.max() <= sc.control["v_max"] + 1e-12


def test_move_agents_with_no_gain_stays_and_keeps_the_graph():
    sc = _scenario(mobile=True, driver="decentralized", control={"Gamma": 0.0, "v_max": 1.0})
    plan, st, Minv, yinfo = _inputs(sc)
    S.consensus_round(plan, st, Minv, yinfo, 1e-9)
    S.update_filters(sc, plan, st, Minv, yinfo)
    P0, adj0 = st.P.copy(), st.adj.copy()
    S.move_agents(sc, plan, st, Minv)
    np.testing.assert_array_equal(st.P, P0)
    np.testing.assert_array_equal(st.adj, adj0)
    assert not st.reset.any() and not st.changes.any()


# ------------------------------------------------------------------------------------- record, whole loop
def test_record_starts_from_the_initial_estimate_and_the_loop_is_the_phases_in_order():
    sc = _scenario()
    plan, st, _, _ = _setup(sc)
    rec = S.new_record(sc, plan, st)
    x0hat = sc.target0 + np.sqrt(sc.P0) * np.random.default_rng(np.random.SeedSequence(sc.seed).spawn(3)[0]
                                                                 ).standard_normal((sc.runs, 2))
    np.testing.assert_allclose(rec.err_g["local"][0, :, :, 0], np.hypot(*x0hat.T)[:, None] * np.ones(5))
    assert (rec.tr_g["centralized"][..., 0] == 2 * sc.P0).all()
    out = simulate(dict(agents0=sc.agents0, target0=sc.target0, target="random", W_true=sc.W_true,
                        W_filter=sc.W_filter, A=sc.A, gamma=3.0, Lbar=sc.Lbar, P0=sc.P0, model=MODEL, radius=20.0,
                        consensus=dict(sc.consensus), filters=["local"], horizon=3, runs=3, seed=11))
    fields = {f.name: getattr(sc, f.name) for f in dataclasses.fields(sc)}
    plan, st, rng_t, rng_m = _setup(S.Scenario.from_mapping({**fields, "filters": ["local"]}))
    for k in range(1, 4):  # a hand loop over runs of the random walk, the measurements and eq (6)
        st.x, _ = S.move_target(sc, k, st.x, st.P, rng_t, S.gaussian_factor(sc.W_true))
        Minv, yinfo = S.measure(st.x, st.P, MODEL, rng_m)
        for r in range(3):
            for i in range(5):
                st.est["local"][0, r, i], st.cov["local"][0, r, i] = _eq6(
                    st.est["local"][0, r, i], st.cov["local"][0, r, i], yinfo[r, i], Minv[r, i], sc.A, sc.W_filter,
                    1 / 9, sc.Lbar)
        np.testing.assert_allclose(out["errors"]["local"][..., k], np.hypot(*(st.est["local"][0] - st.x[:, None]).T).T,
                                   rtol=1e-9)
    np.testing.assert_array_equal(out["target"][:, 3], st.x)
