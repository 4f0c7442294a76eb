import numpy as np
import pandas as pd
import pytest

from netrepro.errors import InputError
from netrepro.pipeline.io import write_table
from netrepro.papers.intermittent import steps

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
SCALAR = dict(a=A, R1=R1, R2=R2, Ep0=P0, lambda_offsets=[0.1, -0.1], horizon=12, exact_horizon=6,
              n_paths=400, block_size=100, seed=1)


def test_region_shards_give_identical_tables_whatever_the_split():
    base = {"a": A, "lambda1_grid": 9, "bisection_tol": 1e-4}
    tables = []
    for n_shards in (1, 2, 4):
        parts = [steps.two_sensor_region_shard_step({**base, "n_shards": n_shards, "shard": s}, {}, {})["table"]
                 for s in range(n_shards)]
        tables.append(pd.concat(parts).sort_values("lambda1", kind="stable").reset_index(drop=True))
    for other in tables[1:]:
        pd.testing.assert_frame_equal(tables[0], other)


def test_scalar_pipeline_on_a_tiny_config(tmp_path):
    exact = steps.exact_mean_step(SCALAR, {}, {})["table"]
    assert list(exact.columns) == ["lam", "k", "mean_exact", "rel_error_bound", "mean_enumeration",
                                   "enumeration_rel_diff"] and len(exact) == 2 * 13
    assert exact["mean_enumeration"].notna().sum() == 2 * 7 and exact["enumeration_rel_diff"].max() < 1e-12
    shard = tmp_path / "s0.npz"
    steps.monte_carlo_shard_step({**SCALAR, "n_shards": 1, "shard": 0}, {}, {"sums": str(shard)})
    write_table(exact, tmp_path / "exact.csv")
    mc = steps.monte_carlo_merge_step(SCALAR, {"shards": [str(shard)], "exact": str(tmp_path / "exact.csv")},
                                      {})["table"]
    assert {"exact_mean", "cond_z", "plain_z", "cond_se"} <= set(mc.columns)
    assert np.isfinite(mc["cond_z"]).all()
    write_table(mc, tmp_path / "mc.csv")
    bounds = steps.scalar_bounds_step(SCALAR, {"exact": str(tmp_path / "exact.csv"), "mc": str(tmp_path / "mc.csv")},
                                      {})["table"]
    for col in ("lam", "k", "s", "r", "report_estimate", "mean", "mean_lo", "mean_hi", "mean_method"):
        assert col in bounds.columns
    assert len(bounds) == 2 * 13
    assert (bounds["s"] <= bounds["r"] + 1e-12).all()
    assert (bounds["mean_lo"] == bounds["mean"]).all() and (bounds["mean_hi"] == bounds["mean"]).all()
    assert set(bounds["mean_method"]) == {"exact"}
    # the exact mean lies between the bounds (eq. 7)
    assert (bounds["s"] <= bounds["mean"] * (1 + 1e-12)).all() and (bounds["mean"] <= bounds["r"] * (1 + 1e-12)).all()


def test_stationary_table():
    table = steps.stationary_mean_step(SCALAR, {}, {})["table"]
    stable, unstable = table.iloc[0], table.iloc[1]
    assert stable["s_limit"] < stable["stationary_lo"] <= stable["stationary_hi"] < stable["r_limit"]
    assert np.isinf(unstable["stationary_mean"]) and unstable["loss_growth"] > 1


def test_simulation_step_columns():
    params = dict(a=A, R1=0.1, sigma2=[0.2, 0.5], check_lambda1=0.3, check_offset=0.1, check_horizon=10,
                  check_paths=200, block_size=100, seed=2)
    table = steps.two_sensor_simulation_step(params, {}, {})["table"]
    assert set(table["side"]) == {"stable", "unstable"} and len(table) == 22
    assert np.isfinite(table["mean"]).all()
    assert np.isfinite(table[table["side"] == "stable"]["stationary_mean"]).all()
    assert np.isinf(table[table["side"] == "unstable"]["stationary_mean"]).all()


def test_stationary_curve_lies_between_its_bounds_and_flags_the_variance():
    table = steps.stationary_curve_step(dict(a=A, R1=R1, R2=R2, n_lambda=12, first_fraction=1e-3,
                                             lambda_offsets=[0.1, -0.1]), {}, {})["table"]
    lam_c = 1 - 1 / A**2
    assert table["lam"].min() == pytest.approx(lam_c + 1e-3 / A**2) and table["lam"].max() == 1.0
    assert len(table) == 14 and table["report_setting"].sum() == 1
    assert table.loc[table["report_setting"], "lam"].iloc[0] == pytest.approx(lam_c + 0.1)
    assert (table["s_limit"] <= table["stationary_lo"]).all()
    assert (table["stationary_lo"] <= table["r_limit"] * (1 + 1e-12)).all()
    inner = table[table["lam"] < 1.0]
    assert (inner["stationary_hi"] < inner["r_limit"]).all()  # E(p_inf) < r* strictly when arrivals are random
    assert (table["variance_finite"] == (table["lam"] > 1 - 1 / A**4)).all()
    # lambda = 1: the standard Kalman filter, E(p_inf) = r* = the positive root of p = a^2 p R2/(p + R2) + R1
    last = table.iloc[-1]
    p = last["stationary_mean"]
    assert p == pytest.approx(A * A * p * R2 / (p + R2) + R1, rel=1e-12)
    assert p == pytest.approx(last["r_limit"], rel=1e-12)
    with pytest.raises(InputError, match="first_fraction"):
        steps.stationary_curve_step(dict(a=A, R1=R1, R2=R2, n_lambda=5, first_fraction=1.0), {}, {})


def test_heavy_tail_table_against_a_monte_carlo_of_p_k():
    params = dict(a=A, R1=R1, R2=R2, Ep0=P0, horizon=12, lambda_offsets=[0.1], lambdas=[0.9], quantiles=[0.5, 0.9])
    table = steps.heavy_tail_step(params, {}, {})["table"]
    assert table["lam_label"].tolist() == ["lambda_c+0.1", "lambda=0.9"]
    assert table["variance_finite"].tolist() == [False, True]
    row = table.iloc[0]
    assert row["mean"] == pytest.approx(row["mean_exact"], rel=1e-12)
    # independent: simulate eq. (6) and compare the empirical quantiles (200k paths; the law is discrete, so
    # compare through the CDF: P(p_12 <= q) >= level and P(p_12 < q) <= level, up to 4 binomial s.e.)
    rng = np.random.default_rng(11)
    lam = 1 - 1 / A**2 + 0.1
    p = np.full(200_000, P0)
    for _ in range(12):
        g = rng.random(p.size) < lam
        p = A * A * p + R1 - g * A * A * p * p / (p + R2)
    se = 4 * np.sqrt(0.25 / p.size)
    for level in (0.5, 0.9):
        lo, hi = row[f"q{level:g}_lo"], row[f"q{level:g}_hi"]
        assert np.mean(p <= lo * (1 + 1e-12)) >= level - se
        assert np.mean(p < hi * (1 - 1e-12)) <= level + se
    assert np.mean(p > row["mean_exact"]) == pytest.approx(row["p_above_mean"], abs=se)
    assert not row["variance_finite"] and row["mean_finite"]
    # lambda = 0.9: the final arrival (probability 0.9) puts p_k below every value after a final loss, so the
    # distribution function is flat at 0.9 and the 0.9-quantile is an interval
    tail = table.iloc[1]
    assert tail["flat_levels"] == "0.9" and tail["q0.9_lo"] < tail["q0.9_hi"]
    assert tail["q0.5_lo"] == tail["q0.5_hi"]


def test_region_closed_form_has_the_kink_exactly():
    table = steps.region_closed_form_step(dict(a=A, n_dense=11), {}, {})["table"]
    kink = 1 - 1 / A**2
    assert kink in set(table["lambda1"]) and len(table) == 12
    assert table.loc[table["lambda1"] == kink, "lambda2c_lower"].iloc[0] == pytest.approx(0.0, abs=1e-15)
    below = table[table["lambda1"] < kink]
    assert (below["lambda2c_lower"] > 0).all()
    assert (table[table["lambda1"] > kink]["lambda2c_lower"] == 0).all()


def test_monte_carlo_table_is_identical_for_any_shard_count_even_above_the_block_count(tmp_path):
    from netrepro.engines.montecarlo import n_blocks

    exact = steps.exact_mean_step(SCALAR, {}, {})["table"]
    write_table(exact, tmp_path / "exact.csv")
    blocks = n_blocks(SCALAR["n_paths"], SCALAR["block_size"])
    tables = []
    for n_shards in (1, 2, blocks + 2):  # more shards than blocks: some shards hold no block
        paths = []
        for s in range(n_shards):
            paths.append(str(tmp_path / f"s{n_shards}_{s}.npz"))
            steps.monte_carlo_shard_step({**SCALAR, "n_shards": n_shards, "shard": s}, {}, {"sums": paths[-1]})
        tables.append(steps.monte_carlo_merge_step(SCALAR, {"shards": paths, "exact": str(tmp_path / "exact.csv")},
                                                   {})["table"])
    for other in tables[1:]:
        pd.testing.assert_frame_equal(tables[0], other, check_exact=True)
