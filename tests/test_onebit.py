"""Tests of the `onebit` paper module: each equation against an independent computation."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import integrate, linalg, stats

from netrepro.engines.kernels import scalar_information_steps
from netrepro.claims import CLAIM_COLUMNS, ERRATA_COLUMNS, RECONSTRUCTION_COLUMNS
from netrepro.config import ConfigError
from netrepro.papers import onebit as ob

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


# ---------------------------------------------------------------- (29)-(30)
def test_fisher_1bit_matches_direct_formula_in_the_bulk():
    theta = np.linspace(-4, 4, 81)
    for se in (0.5, 1.0, 3.0):
        x = theta / se
        direct = stats.norm.pdf(x) ** 2 / (stats.norm.cdf(x) * stats.norm.sf(x)) / se**2
        np.testing.assert_allclose(ob.fisher_1bit(theta, se), direct, rtol=1e-12)
    assert ob.fisher_1bit(0.0) == pytest.approx(2 / math.pi, rel=1e-15)  # eq. (30) at theta = 0: 2/pi


def test_fisher_1bit_tails_do_not_underflow_to_nan():
    x = np.array([10.0, 20.0, 30.0, -30.0])
    f = ob.fisher_1bit(x)
    assert np.all(np.isfinite(f)) and np.all(f > 0)
    # Q(x) ~ phi(x)/x (1 - 1/x^2 + 3/x^4 - 15/x^6): F_q ~ |x| phi(x) / (1 - 1/x^2 + 3/x^4 - 15/x^6)
    ax = np.abs(x)
    asym = ax * stats.norm.pdf(ax) / (1 - ax**-2 + 3 * ax**-4 - 15 * ax**-6)
    np.testing.assert_allclose(f[1:], asym[1:], rtol=1e-6)


@pytest.mark.parametrize("mean", [0.0, 0.7, -2.5])
def test_expected_fisher_matches_adaptive_quadrature(mean):
    v = np.logspace(-3, 3, 13)
    ours = ob.expected_fisher_1bit(v, 1.0, mean)
    for vi, oi in zip(v, ours):
        s = math.sqrt(vi)
        f = lambda t: ob.fisher_1bit(t) * stats.norm.pdf(t, mean, s)  # noqa: E731
        lo, hi = max(mean - 40 * s, -60), min(mean + 40 * s, 60)
        pts = [p for p in (mean, 0.0) if lo < p < hi]
        q, err = integrate.quad(f, lo, hi, points=pts, epsabs=0, epsrel=1e-13, limit=500)
        assert err < 1e-12 * q
        assert oi == pytest.approx(q, rel=1e-10)


def test_expected_fisher_scaling_limits_and_vectorisation():
    # sigma_eta scaling: E[F_q](var, se) = E[F_q](var/se^2, 1)/se^2
    assert ob.expected_fisher_1bit(8.0, 2.0) == pytest.approx(ob.expected_fisher_1bit(2.0) / 4, rel=1e-14)
    assert ob.expected_fisher_1bit(1e-12) == pytest.approx(2 / math.pi, rel=1e-11)
    c = ob.expected_fisher_1bit(1e14) * math.sqrt(2 * math.pi * 1e14)
    c_quad = integrate.quad(lambda t: ob.fisher_1bit(t), -40, 40, epsrel=1e-13, limit=200)[0]
    assert c == pytest.approx(c_quad, rel=1e-6)
    grid = np.logspace(-2, 2, 12).reshape(3, 4)
    assert ob.expected_fisher_1bit(grid).shape == (3, 4)
    assert np.all(np.diff(ob.expected_fisher_1bit(np.logspace(-6, 6, 50))) < 0)


def test_expected_fisher_quad_helper_agrees():
    for v in (1e-2, 1.0, 1e2):
        assert ob.expected_fisher_1bit_quad(v)[0] == pytest.approx(float(ob.expected_fisher_1bit(v)), rel=1e-10)


def test_interpolator_is_accurate():
    f = ob.expected_fisher_interpolator()
    v = np.logspace(-9, 7, 333)
    np.testing.assert_allclose(f(v), ob.expected_fisher_1bit(v), rtol=1e-9)


# ---------------------------------------------------------------- (31)-(33)
def test_theta_variance_matches_recursion_and_limit():
    eps, s, sig0 = 1e-2, 0.3, 1.5
    var = [sig0**2]
    for _ in range(400):
        var.append((1 - eps) ** 2 * var[-1] + s)
    np.testing.assert_allclose(ob.theta_variance(np.arange(401), eps, sig0, s), var, rtol=1e-12)
    assert ob.theta_variance(1e7, eps, sig0, s) == pytest.approx(float(ob.stationary_variance(eps, s)), rel=1e-12)
    assert ob.theta_variance(5, 0.0, sig0, s) == pytest.approx(sig0**2 + 5 * s)  # alpha = 1: a random walk
    assert ob.theta_mean(3, 0.5, 2.0) == pytest.approx(0.25)


def test_snr_definitions():
    eps = 1e-5
    s = ob.sigma_z2_from_snr(10.0, eps, 2.0, "stationary")
    assert ob.stationary_variance(eps, s) / 4.0 == pytest.approx(10.0, rel=1e-13)
    assert ob.sigma_z2_from_snr(10.0, eps, 2.0, "innovation") == pytest.approx(40.0)
    with pytest.raises(ValueError, match="definition"):
        ob.sigma_z2_from_snr(0.0, eps, 1.0, "bogus")


# ---------------------------------------------------------------- general recursions vs Kalman / RTS
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


def test_linear_gaussian_blocks_by_monte_carlo_score():
    D11, D12, D22 = ob.linear_gaussian_blocks(A2, Q2)
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
    D11, D12, D22 = ob.linear_gaussian_blocks(A2, Q2)
    F = C2.T @ linalg.inv(R2) @ C2
    Pf, Pp, Ps = _kalman(K)
    Jf = ob.filtering_bims(linalg.inv(P02), D11, D12, D22, F, K)
    assert _rel(Jf, Pf) < 1e-12                                                   # (7)
    Jp = np.array([ob.prediction_bim_step(Jf[k], D11, D12, D22) for k in range(K)])
    assert _rel(Jp, Pp) < 1e-12                                                   # (14) corrected
    assert _rel(ob.smoothing_bims(Jf, D11, D12, D22, F), Ps) < 1e-12              # (16) corrected
    assert _rel(ob.smoothing_bims_via_gain(Jf, D11, D12, D22, F), Ps) < 1e-12     # (17)-(19) corrected
    # multi-step prediction = Kalman covariance propagation without updates
    Jpp = ob.prediction_bims(Jf[5], D11, D12, D22, 4)
    P = Pf[5]
    for j in range(1, 5):
        P = A2 @ P @ A2.T + Q2
        np.testing.assert_allclose(linalg.inv(Jpp[j]), P, rtol=1e-12)


def test_printed_transposes_fail_on_nonsymmetric_model():
    D11, D12, D22 = ob.linear_gaussian_blocks(A2, Q2)
    F = C2.T @ linalg.inv(R2) @ C2
    Pf, Pp, _ = _kalman(5)
    Jf = ob.filtering_bims(linalg.inv(P02), D11, D12, D22, F, 5)
    printed = np.array([ob._printed_prediction_step(Jf[k], D11, D12, D22) for k in range(5)])
    assert _rel(printed, Pp) > 0.05
    # for a symmetric A the printed and corrected forms coincide
    As = 0.5 * (A2 + A2.T)
    E11, E12, E22 = ob.linear_gaussian_blocks(As, np.eye(2) * 0.3)
    J = np.array([[2.0, 0.1], [0.1, 1.0]])
    np.testing.assert_allclose(ob._printed_prediction_step(J, E11, E12, E22),
                               ob.prediction_bim_step(J, E11, E12, E22), rtol=1e-12)


def test_vector_check_table(cfg):
    frame = ob.vector_check_step(cfg, {}, {})["table"]
    ok = frame[frame["form"].str.contains("corrected|\\(7\\)")]
    bad = frame[frame["form"].str.contains("as printed") & ~frame["form"].str.contains("\\(7\\)")]
    assert (ok["max_rel_err"] < 1e-12).all()
    assert (bad["max_rel_err"] > 1e-2).all()


def test_time_varying_arguments_need_matching_length():
    D11, D12, D22 = ob.linear_gaussian_blocks(A2, Q2)
    with pytest.raises(ValueError, match="needs 3"):
        ob.filtering_bims(np.eye(2), np.stack([D11] * 2), D12, D22, np.zeros((2, 2)), 3)


# ---------------------------------------------------------------- scalar random walk (22)-(27), (34)-(38)
def test_stable_forms_equal_printed_scalar_equations():
    eps, s, F = 0.05, 0.2, 0.8
    a = 1 - eps
    J = np.linspace(0.5, 20, 9)
    printed24 = 1 / s + F - (a / s) ** 2 / (J + a * a / s)
    np.testing.assert_allclose(ob.rw_filtering_step(J, F, eps, s), printed24, rtol=1e-13)
    printed25 = 1 / s - (a / s) ** 2 / (a * a / s + J)
    np.testing.assert_allclose(ob.rw_prediction_step(J, eps, s), printed25, rtol=1e-13)
    kap = np.linspace(0, 10, 9)
    printed27 = a * a / s - (a / s) ** 2 / (1 / s + F + kap)
    np.testing.assert_allclose(ob.rw_smoothing_gain_step(kap, F, eps, s), printed27, rtol=1e-12)
    # the scalar step equals the general step with the blocks (22)
    D11, D12, D22 = ob.linear_gaussian_blocks([[a]], [[s]])
    assert D11[0, 0] == pytest.approx(a * a / s) and D12[0, 0] == pytest.approx(-a / s)
    assert float(ob.filtering_bim_step([[3.0]], D11, D12, D22, [[F]])[0, 0]) == pytest.approx(
        float(ob.rw_filtering_step(3.0, F, eps, s)), rel=1e-13)


@pytest.mark.parametrize("eps,s,F", [(1e-3, 1e-4, 0.6), (1e-2, 0.5, 0.07), (0.3, 2.0, 1.0), (1e-5, 2e-8, 0.63)])
def test_fixed_points_match_dare_and_long_iteration(eps, s, F):
    a = 1 - eps
    Jstar = float(ob.rw_filtering_fixed_point(F, eps, s))
    M = linalg.solve_discrete_are(np.array([[a]]), np.array([[1.0]]), np.array([[s]]), np.array([[1 / F]]))[0, 0]
    assert 1 / M + F == pytest.approx(Jstar, rel=1e-9)  # DARE: predicted variance M
    J, kap = 1.0, 0.0
    kstar = float(ob.rw_smoothing_gain_fixed_point(F, eps, s))
    for _ in range(400_000 if eps < 1e-4 else 60_000):
        J = ob.rw_filtering_step(J, F, eps, s)
        kap = ob.rw_smoothing_gain_step(kap, F, eps, s)
    assert J == pytest.approx(Jstar, rel=1e-10)
    assert kap == pytest.approx(kstar, rel=1e-10)
    # and the smoothing variance equals the steady-state RTS variance
    Pf = 1 / Jstar
    Pp = a * a * Pf + s
    G = Pf * a / Pp
    Ps = Pf * (1 - G * G * Pp / Pf) / (1 - G * G)   # P_s = P_f + G^2 (P_s - P_p)
    assert 1 / (Jstar + kstar) == pytest.approx(Ps, rel=1e-8)


def test_lag_closed_form_equals_iteration():
    eps = 1e-3
    snr_db = np.arange(-30, 21, 2.5)
    s = ob.sigma_z2_from_snr(snr_db, eps)
    F = ob.expected_fisher_1bit(ob.stationary_variance(eps, s))
    for tol in (0.01, 0.001):
        np.testing.assert_array_equal(ob.rw_lag_needed(F, eps, s, tol), ob.rw_lag_iterated(F, eps, s, tol))
    assert np.all(ob.rw_lag_needed(F, eps, s, 0.01) > 0)


def test_ratios_tend_to_limit_and_limit_values():
    snr_db = np.array([-20.0, 0.0, 10.0])
    lim = ob.information_ratios_limit(snr_db)
    near = ob.information_ratios(snr_db, 1e-10)
    for key in ("rho_sl_db", "rho_f_db", "rho_s_db"):
        np.testing.assert_allclose(near[key], lim[key], atol=2e-3)
    low = ob.information_ratios_limit(np.array([-80.0]))
    assert low["rho_f_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert low["rho_s_db"][0] == pytest.approx(10 * math.log10(2 * math.sqrt(2 / math.pi)), abs=1e-6)
    r = ob.information_ratios(np.linspace(-30, 20, 11), 1e-3)
    assert np.all(r["rho_s_db"] > r["rho_f_db"])
    assert np.all(r["j_s_q"] <= r["j_s_inf"]) and np.all(r["j_f_q"] <= r["j_f_inf"])


def test_transient_iteration_reaches_fixed_point():
    out = ob.iterate_transient([-10.0, 10.0], 1e-2, 1.0, 0.0, 1.0, 6000, 1e-9, record=[0, 10, 100])
    np.testing.assert_allclose(out["j_f_q"], out["j_f_q_star"], rtol=1e-9)
    np.testing.assert_allclose(out["j_f_inf"], out["j_f_inf_star"], rtol=1e-12)
    assert np.all(out["k_conv_q"] < 6000)
    assert out["trace"]["j_f_q_ratio"].shape == (3, 2)
    with pytest.raises(ValueError, match="mu0"):
        ob.iterate_transient([0.0], 1e-2, 1.0, 1.0, 1.0, 10, 1e-9)


# ---------------------------------------------------------------- estimator
def test_grid_smoother_and_kalman_against_bounds(cfg):
    c = copy.deepcopy(cfg)
    c["estimator"].update(snr_db=[0.0], n_runs=200, block_size=100)
    frame = ob.run_estimator(c).set_index("kind")
    assert set(frame.index) == {"filter_1bit", "smoother_1bit", "kalman_filter", "rts_smoother"}
    assert (frame["mse_hi"] >= frame["bound"]).all()
    assert frame.loc["smoother_1bit", "mse"] < frame.loc["filter_1bit", "mse"]
    for kind in ("kalman_filter", "rts_smoother"):   # efficient estimators: the bound is met within the CI
        assert frame.loc[kind, "mse_lo"] <= frame.loc[kind, "bound"] <= frame.loc[kind, "mse_hi"] * 1.05


def test_grid_filter_without_data_information_keeps_prior_mean():
    r = np.ones((3, 5))
    filt, smooth = ob.grid_filter_smoother(r, 0.1, 0.2, 1e6)  # huge noise: 1-bit data carry ~no information
    np.testing.assert_allclose(filt, 0.0, atol=1e-5)
    np.testing.assert_allclose(smooth, 0.0, atol=1e-5)


# ---------------------------------------------------------------- tables and config
def test_errata_reconstructions_claims(cfg, tmp_path):
    err = ob.errata_step(cfg, {}, {})["table"]
    assert list(err.columns) == ERRATA_COLUMNS
    assert (err["residual_corrected"] < 1e-10).all()
    assert (err["residual_printed"] > 1e-3).all()
    rec = ob.reconstructions_step(cfg, {}, {})["table"]
    assert list(rec.columns) == RECONSTRUCTION_COLUMNS and "snr_definition" in set(rec["key"])
    paths = {}
    for name, fn in (("ratios", ob.ratios_step), ("lag", ob.lag_step), ("efq", ob.efq_step)):
        paths[name] = tmp_path / f"{name}.csv"
        fn(cfg, {}, {})["table"].to_csv(paths[name], index=False)
    c = copy.deepcopy(cfg)
    c["estimator"].update(snr_db=[0.0], n_runs=100, block_size=50)
    paths["estimator"] = tmp_path / "estimator.csv"
    ob.run_estimator(c).to_csv(paths["estimator"], index=False)
    claims = ob.claims_step(cfg, paths, {})["table"]
    assert list(claims.columns) == CLAIM_COLUMNS
    v = claims.set_index("claim_id")["verdict"]
    for cid in ("loss_no_model", "rho_f_low_snr", "rho_sl_low_snr_fig1", "rho_sl_low_snr_limit", "same_loss_limit",
                "rho_s_gt_rho_f", "rho_s_positive", "rho_s_plus_2db"):
        assert v[cid] == "reproduced", cid


def test_ratio_table_columns(cfg):
    frame = ob.ratios_step(cfg, {}, {})["table"]
    assert list(frame.columns[:6]) == ["alpha", "snr_db", "efq_db", "rho_sl_db", "rho_f_db", "rho_s_db"]
    assert set(frame["alpha"]) == {1 - 1e-3, 1 - 1e-5, 1.0}
    assert np.diff(np.sort(frame["snr_db"].unique())).max() <= 1.0
    assert frame["snr_db"].min() == -30 and frame["snr_db"].max() == 20


def test_check_config_rejects_bad_sections(cfg):
    ob.check_config(cfg)
    bad = copy.deepcopy(cfg)
    bad["estimator"]["window"] = [50, 10]
    with pytest.raises(ConfigError, match="window"):
        ob.check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["vector_check"]["Q"] = [[1.0, 2.0], [2.0, 1.0]]
    with pytest.raises(ConfigError, match="Q"):
        ob.check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["fig1_one_minus_alpha"] = 0.5
    with pytest.raises(ConfigError, match="fig1_one_minus_alpha"):
        ob.check_config(bad)


def test_estimator_shards_merge_to_identical_results(cfg, tmp_path):
    c = copy.deepcopy(cfg)
    c["estimator"].update(snr_db=[0.0], n_runs=60, block_size=20, horizon=30, window=[10, 20])
    one = ob.run_estimator(c)
    paths = []
    for shard in range(3):
        paths.append(tmp_path / f"s{shard}.npz")
        ob.estimator_shard_step(dict(c, shard=shard, n_shards=3), {}, {"sums": paths[-1]})
    three = ob.estimator_step(c, {"shards": paths}, {})["table"]
    pd.testing.assert_frame_equal(one, three)


def test_grid_filter_reproduces_kalman_on_unquantized_data():
    eps, s = 1e-2, float(ob.sigma_z2_from_snr(0.0, 1e-2))
    rng = np.random.default_rng(11)
    theta, y, r = ob.simulate_block(rng, 20, 60, eps, s, 1.0)
    filt, smooth = ob.grid_filter_smoother(y, eps, s, 1.0, 8.0, 2.0, quantized=False)
    kf, rts = ob._kalman_rts(y, eps, s, 1.0)
    sd = math.sqrt(float(ob.stationary_variance(eps, s)))
    assert np.max(np.abs(filt - kf)) < 1e-6 * sd
    assert np.max(np.abs(smooth - rts)) < 1e-6 * sd


def test_innovation_snr_definition_does_not_reproduce_the_asymptotes(cfg, tmp_path):
    """The reconstruction argument: with SNR = sigma_z^2/sigma_eta^2 the paper's -0.98 dB (Fig 1) is not reached."""
    c = copy.deepcopy(cfg)
    c["snr_definition"] = "innovation"
    paths = {}
    for name, fn in (("ratios", ob.ratios_step), ("lag", ob.lag_step), ("efq", ob.efq_step)):
        paths[name] = tmp_path / f"{name}.csv"
        fn(c, {}, {})["table"].to_csv(paths[name], index=False)
    c["estimator"].update(snr_db=[0.0], n_runs=40, block_size=20, horizon=40, window=[10, 30])
    paths["estimator"] = tmp_path / "estimator.csv"
    ob.run_estimator(c).to_csv(paths["estimator"], index=False)
    v = ob.claims_step(c, paths, {})["table"].set_index("claim_id")["verdict"]
    assert v["rho_sl_low_snr_fig1"] == "differs" and v["rho_s_positive"] == "differs"


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_config_sections_validate(name):
    import jsonschema

    from netrepro.config import load_schemas

    section = yaml.safe_load((ROOT / "config" / name).read_text())["onebit"]
    _, registry = load_schemas()
    schema = registry.get_or_retrieve("onebit.schema.yaml").value.contents
    jsonschema.Draft202012Validator(schema).validate(section)
    ob.check_config(section)


def test_compiled_bim_steps_equal_numpy_loop_and_general_recursion_7():
    """(24)/(34) as compiled: bit-identical to the numpy loop it replaced, and equal to the general (7)
    with the random walk's D11 = a^2/s, D12 = -a/s, D22 = 1/s (an independent form)."""
    rng = np.random.default_rng(3)
    a2, s2 = 0.98**2, rng.uniform(0.01, 2.0, 6)
    F = rng.uniform(0.0, 3.0, (50, 6))
    j0 = rng.uniform(0.1, 5.0, 6)
    j, J = j0.copy(), np.empty_like(F)
    scalar_information_steps(j, a2, s2, F, J)
    ref, tmp, out = j0.copy(), np.empty(6), []
    for i in range(len(F)):  # the numpy form
        np.divide(a2, ref, out=tmp)
        tmp += s2
        np.divide(1.0, tmp, out=ref)
        ref += F[i]
        out.append(ref.copy())
    assert np.array_equal(J, np.array(out)) and np.array_equal(j, J[-1])
    a = np.sqrt(a2)
    for lane in range(6):
        s = s2[lane]
        general = ob.filtering_bims(j0[lane], a2 / s, -a / s, 1.0 / s, F[:, lane].reshape(-1, 1, 1), len(F))
        assert np.allclose(general[1:, 0, 0], J[:, lane], rtol=1e-12)
