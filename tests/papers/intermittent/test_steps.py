import numpy as np
import pandas as pd

from netrepro.io import write_table
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
    assert list(exact.columns) == ["lam", "k", "mean_exact"] and len(exact) == 2 * 7
    shard = tmp_path / "s0.npz"
    steps.monte_carlo_shard_step({**SCALAR, "n_shards": 1, "shard": 0}, {}, {"sums": str(shard)})
    mc = steps.monte_carlo_merge_step(SCALAR, {"shards": [str(shard)]}, {})["table"]
    write_table(exact, tmp_path / "exact.csv")
    write_table(mc, tmp_path / "mc.csv")
    bounds = steps.scalar_bounds_step(SCALAR, {"exact": str(tmp_path / "exact.csv"), "mc": str(tmp_path / "mc.csv")},
                                      {})["table"]
    for col in ("lam", "k", "s", "r", "report_estimate", "mean", "mean_lo", "mean_hi", "mean_method"):
        assert col in bounds.columns
    assert len(bounds) == 2 * 13
    assert (bounds["s"] <= bounds["r"] + 1e-12).all()
    assert (bounds["mean_lo"] <= bounds["mean_hi"]).all()


def test_simulation_step_columns():
    params = dict(a=A, R1=0.1, sigma2=[0.2, 0.5], check_lambda1=0.3, check_offset=0.1, check_horizon=10,
                  check_paths=200, block_size=100, seed=2)
    table = steps.two_sensor_simulation_step(params, {}, {})["table"]
    assert set(table["side"]) == {"stable", "unstable"} and len(table) == 22
    assert np.isfinite(table["mean"]).all()
