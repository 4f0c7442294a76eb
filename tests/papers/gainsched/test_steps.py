"""Steps of the `gainsched` paper on tiny inputs."""

from __future__ import annotations

import numpy as np
import pytest

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
    params = dict(cfg, simulation=dict(cfg["simulation"], flipped=[]))
    out = exact_moments_step(params, {"gains": tmp_path / "g.csv", "designs": tmp_path / "d.csv"}, {})
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


def test_exact_moments_step_adds_flipped_rows(cfg, sys, paper, tmp_path):
    """simulation.flipped repeats a design with H -> -H in exact_moments.csv only (not in performance.csv)."""
    import pandas as pd

    from netrepro.papers.gainsched.model import realisation, zero_gains
    from netrepro.papers.gainsched.steps import exact_moments_step
    from netrepro.papers.gainsched.tuning import exact_cost

    pd.concat([gains_table("paper", paper), gains_table("zero", zero_gains(sys))]).to_csv(tmp_path / "g.csv", index=False)
    pd.DataFrame([{"design": "paper", "method": "printed", "certified_cost": np.nan},
                  {"design": "zero", "method": "x_f = 0", "certified_cost": np.nan}]).to_csv(tmp_path / "d.csv", index=False)
    params = dict(cfg, simulation=dict(cfg["simulation"], flipped=["paper"]))
    out = exact_moments_step(params, {"gains": tmp_path / "g.csv", "designs": tmp_path / "d.csv"}, {})
    table = out["table"].set_index(["design", "nonlinearity", "initial_state"])["sum_mse"]
    assert set(out["table"]["design"]) == {"paper", "zero", "paper_flipped"}
    assert set(out["performance"]["design"]) == {"paper", "zero"}
    from netrepro.papers.gainsched.model import augmented_initial_moment
    from netrepro.papers.gainsched.steps import p_sequence

    want = exact_cost(sys, realisation(paper, -np.eye(sys.n)), p_sequence(params, sys), 0.5 * (sys.F1 + sys.F2),
                      augmented_initial_moment(np.eye(sys.n), sys.n))
    assert table[("paper_flipped", "mid", "gaussian")] == pytest.approx(want, rel=1e-12)
