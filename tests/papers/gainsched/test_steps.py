"""Steps of the `gainsched` paper on tiny inputs."""

from __future__ import annotations

import numpy as np

from netrepro.papers.gainsched.steps import MATRICES, gains_from_table, gains_table


def test_gains_table_round_trip(sys, paper):
    tab = gains_table("paper", paper)
    assert list(tab.columns) == ["design", "matrix", "row", "col", "value"]
    back = gains_from_table(tab, "paper", sys)
    for k in MATRICES:
        np.testing.assert_array_equal(getattr(back, k), getattr(paper, k))


def test_exact_moments_step_columns_and_zero_design(cfg, sys, paper, tmp_path):
    import pandas as pd

    from netrepro.papers.gainsched.model import zero_gains
    from netrepro.papers.gainsched.steps import exact_moments_step

    pd.concat([gains_table("paper", paper), gains_table("zero", zero_gains(sys))]).to_csv(tmp_path / "g.csv", index=False)
    pd.DataFrame([{"design": "paper", "method": "printed", "certified_cost": np.nan},
                  {"design": "zero", "method": "x_f = 0", "certified_cost": np.nan}]).to_csv(tmp_path / "d.csv", index=False)
    out = exact_moments_step(cfg, {"gains": tmp_path / "g.csv", "designs": tmp_path / "d.csv"}, {})
    table, per_k = out["table"], out["per_k"]
    assert list(table.columns) == ["design", "nonlinearity", "initial_state", "sum_mse", "final_mse"]
    assert len(table) == 2 * 3 * 2
    assert set(table["nonlinearity"]) == {"F1", "F2", "mid"} and set(table["initial_state"]) == {"gaussian", "x0"}
    K = int(cfg["simulation"]["horizon"])
    assert per_k["k"].max() == K
    # sum_mse is the sum of the per-k values; e(0) = x(0) - x_f(0): E||e(0)||^2 = n for the Gaussian start
    for (d, f, s), sub in per_k.groupby(["design", "nonlinearity", "initial_state"]):
        row = table[(table["design"] == d) & (table["nonlinearity"] == f) & (table["initial_state"] == s)].iloc[0]
        assert np.isclose(row["sum_mse"], sub["mse"].sum(), rtol=1e-12)
        if s == "gaussian":
            assert np.isclose(sub.sort_values("k")["mse"].iloc[0], sys.n)
    perf = out["performance"].set_index("design")
    assert perf.loc["zero", "sum_mse_gaussian_worst"] == table[(table["design"] == "zero")
                                                              & (table["initial_state"] == "gaussian")]["sum_mse"].max()
