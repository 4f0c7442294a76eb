"""Tests of netrepro.papers.onebit.steps: each equation against an independent computation."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from netrepro.papers.onebit import steps

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


def test_vector_check_table(cfg):
    frame = steps.vector_check_step(cfg, {}, {})["table"]
    ok = frame[frame["form"].str.contains("corrected|\\(7\\)")]
    bad = frame[frame["form"].str.contains("as printed") & ~frame["form"].str.contains("\\(7\\)")]
    assert (ok["max_rel_err"] < 1e-12).all()
    assert (bad["max_rel_err"] > 1e-2).all()


def test_grid_smoother_and_kalman_against_bounds(cfg):
    c = copy.deepcopy(cfg)
    c["estimator"].update(one_minus_alpha=[1e-2], snr_db=[0.0], n_runs=200, block_size=100)
    c["estimator"].pop("crossing")   # one case only
    frame = steps.run_estimator(c)["table"].set_index("kind")
    assert set(frame.index) == {"filter_1bit", "smoother_1bit", "kalman_filter", "rts_smoother"}
    se = (frame["mse_hi"] - frame["mse"]) / 1.959964
    assert ((frame["bound"] - frame["mse"]) <= 3.5 * se).all()   # no MSE below its bound beyond 3.5 standard errors
    assert frame.loc["smoother_1bit", "mse"] < frame.loc["filter_1bit", "mse"]
    for kind in ("kalman_filter", "rts_smoother"):   # efficient estimators: the bound is met within the CI
        assert frame.loc[kind, "mse_lo"] <= frame.loc[kind, "bound"] <= frame.loc[kind, "mse_hi"] * 1.05


def test_ratio_table_columns(cfg):
    frame = steps.ratios_step(cfg, {}, {})["table"]
    assert list(frame.columns[:6]) == ["alpha", "snr_db", "efq_db", "rho_sl_db", "rho_f_db", "rho_s_db"]
    assert set(frame["alpha"]) == {1 - 1e-3, 1 - 1e-5, 1.0}
    assert np.diff(np.sort(frame["snr_db"].unique())).max() <= 1.0
    assert frame["snr_db"].min() == -30 and frame["snr_db"].max() == 20


def test_estimator_shards_merge_to_identical_results(cfg, tmp_path):
    c = copy.deepcopy(cfg)
    c["estimator"].update(snr_db=[0.0, 10.0], n_runs=60, block_size=20)
    one = steps.run_estimator(c)
    paths = []
    for shard in range(3):
        paths.append(tmp_path / f"s{shard}.npz")
        steps.estimator_shard_step(dict(c, shard=shard, n_shards=3), {}, {"runs": paths[-1]})
    three = steps.estimator_step(c, {"shards": paths}, {})
    for name in ("table", "ratios", "crossing"):
        pd.testing.assert_frame_equal(one[name], three[name])


def test_estimator_tables_have_the_issue_columns_and_a_steady_window(cfg):
    out = steps.run_estimator(cfg)
    ratios = out["ratios"]
    assert list(ratios.columns[:8]) == ["alpha", "snr_db", "quantity", "estimate_db", "lo_db", "hi_db", "bound_db",
                                        "n_runs"]
    assert set(ratios["quantity"]) == {"rho_F", "rho_S", "rho_SL"}
    assert (ratios["lo_db"] <= ratios["estimate_db"]).all() and (ratios["estimate_db"] <= ratios["hi_db"]).all()
    assert (ratios["start_over_tau"] >= 5.0).all()                       # window after >= 5 time constants
    assert ((ratios["horizon"] - ratios["window_stop"]) >= 5.0 * ratios["tau"]).all()
    assert (ratios["steady_dev"] < 1e-3).all()                            # bound over the window = steady state
    assert set(ratios["case_set"]) == {"grid", "crossing"}
    mse = out["table"].set_index(["case_set", "alpha", "snr_db", "kind"])["mse"]
    r = ratios.set_index(["case_set", "alpha", "snr_db", "quantity"])["estimate_db"]
    for eps in cfg["estimator"]["one_minus_alpha"]:
        for snr in cfg["estimator"]["snr_db"]:  # the ratios are the MSE ratios of the same runs
            k = ("grid", 1 - eps, snr)
            assert r[k + ("rho_S",)] == pytest.approx(
                10 * np.log10(mse[k + ("kalman_filter",)] / mse[k + ("smoother_1bit",)]), abs=1e-12)
            assert r[k + ("rho_SL",)] == pytest.approx(
                10 * np.log10(mse[k + ("rts_smoother",)] / mse[k + ("smoother_1bit",)]), abs=1e-12)
    assert {"estimate", "lo", "hi", "grid_linear", "bound"} <= set(out["crossing"]["curve"])
    assert {"kurtosis", "max_over_mean", "se_ratio"} <= set(out["table"].columns)
    assert (out["table"]["kurtosis"] >= 1.0).all()    # Pearson kurtosis is at least 1 for any law


def test_estimator_runs_are_paired_same_paths_and_noise(cfg):
    """Every estimator of one run sees the same theta path and the same noise: recompute each from one draw."""
    from netrepro.engines.montecarlo import block_rng
    from netrepro.papers.onebit import estimators

    eps, snr = cfg["estimator"]["one_minus_alpha"][0], 0.0
    fn = steps._estimator_simulator(cfg, eps, snr)
    got = fn(block_rng(7, 3), 12)
    s, _, d = steps._estimator_design(cfg, eps, snr)
    theta, y, r = estimators.simulate_block(block_rng(7, 3), 12, d["horizon"], eps, s, cfg["sigma_eta"])
    assert np.array_equal(r, np.where(y >= 0, 1.0, -1.0))               # the 1-bit data are the signs of the same y
    ev = d["eval_idx"]
    # an independent scalar Kalman filter on the same y
    a, P, m = 1 - eps, float(s / (eps * (2 - eps))), np.zeros(12)
    kf = np.zeros((12, d["horizon"] + 1))
    for k in range(1, d["horizon"] + 1):
        Pp = a * a * P + s
        G = Pp / (Pp + 1.0)
        m = a * m + G * (y[:, k - 1] - a * m)
        P = (1 - G) * Pp
        kf[:, k] = m
    np.testing.assert_allclose(got["kalman_filter"], np.mean((kf[:, ev] - theta[:, ev]) ** 2, axis=1), rtol=1e-10)
    filt, smooth = estimators.grid_filter_smoother(r, eps, s, 1.0, 6.0, 1.0)    # dense transition, all steps
    np.testing.assert_allclose(got["smoother_1bit"], np.mean((smooth[:, ev] - theta[:, ev]) ** 2, axis=1), rtol=1e-8)
    np.testing.assert_allclose(got["filter_1bit"], np.mean((filt[:, ev] - theta[:, ev]) ** 2, axis=1), rtol=1e-8)


def test_lag_table_break_even_column(cfg):
    lag = steps.lag_step(cfg, {}, {})["table"]
    ratios = steps.ratios_step(cfg, {}, {})["table"]
    m = lag.merge(ratios, on=["alpha", "snr_db"])
    assert (m["delta_break_even"].isna() == (m["rho_s_db"] <= 0)).all()   # exists iff rho_S > 0 dB
    assert (m["delta_break_even"].dropna() >= 1).all()


def test_alpha_scan_threshold_is_where_rho_s_changes_sign(cfg):
    out = steps.alpha_scan_step(cfg, {}, {})
    scan, thr = out["table"], out["threshold"]
    for _, row in thr.iterrows():
        sub = scan[scan["snr_db"] == row["snr_db"]]
        assert (sub.loc[sub["one_minus_alpha"] < row["one_minus_alpha_max"], "rho_s_db"] > 0).all()
        assert (sub.loc[sub["one_minus_alpha"] > row["one_minus_alpha_max"], "rho_s_db"] <= 0).all()
    assert thr["single_sign_change"].all()


def test_edge_simulator_runs_the_standard_record_inside_the_long_one(cfg):
    """The edge case's short estimates are those of the standard record cut out of the long one (steps extra..extra+K,
    started from the stationary prior), its long estimates those of the whole record at the same states; checked
    with the numpy Kalman/RTS reference on the cut records and with the grid smoother called directly."""
    from netrepro.papers.onebit.estimators import _kalman_rts_numpy, grid_smoother_at, simulate_block, window_mse

    c = copy.deepcopy(cfg)
    eps, snr = 1e-2, 2.0
    fn = steps._edge_simulator(c, eps, snr)
    got = fn(np.random.default_rng(7), 6)
    s, _, d = steps._estimator_design(c, eps, snr)
    ev, K = d["eval_idx"], d["horizon"]
    extra = int(np.ceil(c["estimator"]["edge"]["extra_taus"] * d["tau"]))
    theta, y, r = simulate_block(np.random.default_rng(7), 6, K + 2 * extra, eps, s, c["sigma_eta"])
    th = theta[:, ev + extra]
    kf_s, rts_s = _kalman_rts_numpy(y[:, extra:extra + K], eps, s, c["sigma_eta"])
    kf_l, rts_l = _kalman_rts_numpy(y, eps, s, c["sigma_eta"])
    np.testing.assert_allclose(got["kalman_filter"], window_mse(kf_s[:, ev], th), rtol=1e-10)
    np.testing.assert_allclose(got["rts_smoother_long"], window_mse(rts_l[:, ev + extra], th), rtol=1e-10)
    e = c["estimator"]
    _, sm_s = grid_smoother_at(r[:, extra:extra + K], eps, s, c["sigma_eta"], ev, e["grid_half_width"],
                               e["points_per_sigma_z"], None)   # dense transition: another code path
    np.testing.assert_allclose(got["smoother_1bit"], window_mse(sm_s, th), rtol=1e-6)
    assert not np.allclose(got["smoother_1bit"], got["smoother_1bit_long"])


def test_estimator_step_writes_coverage_and_edge_tables(cfg):
    out = steps.run_estimator(copy.deepcopy(cfg))
    cov, edge = out["coverage"], out["edge"]
    n_rep = cfg["estimator"]["n_replicates"]
    assert set(cov["replicate"]) == set(range(-1, n_rep)) and cov["covered"].dtype == bool
    # the ratio band against its exact value: the Kalman filter's MSE over the RTS smoother's, per case
    rat = cov[cov["kind"] == "ratio_db:kalman_filter/rts_smoother"]
    mse_all = out["table"].set_index(["alpha", "snr_db", "kind", "case_set"])["bound"]
    for r in rat.itertuples():
        exact_db = 10 * np.log10(mse_all[(r.alpha, r.snr_db, "kalman_filter", r.case_set)]
                                 / mse_all[(r.alpha, r.snr_db, "rts_smoother", r.case_set)])
        assert r.reference == pytest.approx(exact_db, rel=1e-12) and r.replicate == -1
    assert len(rat) == len(out["table"]) // 4
    assert (out["ratios"]["se_rep_db"] > 0).all() and (out["ratios"]["se_boot_db"] > 0).all()
    cov = cov[cov["replicate"] >= 0]
    exact = cov[cov["kind"].isin(["kalman_filter", "rts_smoother"])]
    assert (exact["reference_se"] == 0).all() and (cov[cov["kind"] == "smoother_1bit"]["reference_se"] > 0).all()
    # the Kalman reference is the finite-record bound of the MSE table
    mse = out["table"].set_index(["alpha", "snr_db", "kind", "case_set"])["bound"]
    for r in exact.itertuples():
        assert r.reference == pytest.approx(mse[(r.alpha, r.snr_db, r.kind, r.case_set)], rel=1e-12)
    assert {"edge_bias_db.rho_S", "mse_edge_bias_db.smoother_1bit"} <= set(edge["quantity"])
    assert (edge["lo"] <= edge["estimate"]).all() and (edge["estimate"] <= edge["hi"]).all()
    cr = out["crossing"].set_index("curve")
    assert {"replicate_se", "bootstrap_se"} <= set(cr.index)
