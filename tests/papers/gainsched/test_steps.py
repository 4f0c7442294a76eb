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


def test_sensitivity_step_brackets_both_classes(cfg, sys):
    """The plant rows: scalar multiplier (class (3)) below the worst-gain necessary end, below componentwise."""
    from netrepro.papers.gainsched.feasibility import worst_sector_gain
    from netrepro.papers.gainsched.steps import sensitivity_step

    params = dict(cfg, sensitivity=dict(cfg["sensitivity"], sigma2_grid=[1.0, 4.5], sigma2_zoom=[], tol=0.05))
    out = sensitivity_step(params, {}, {})
    lim = out["limits"].set_index("design")
    assert set(lim.index) == {"plant", "plant_componentwise", "scheduled", "fixed_gain", "zero", "printed_gains",
                              "plant_necessary", "plant_componentwise_necessary",
                              "plant Z22=0.62", "plant_necessary Z22=0.62", "scheduled Z22=0.62"}
    assert lim["certified"].all()
    # the other reading of Z22 (reconstruction range): a sound bracket there too, the necessary end from the
    # closed-form limit of that system's worst gain
    import dataclasses

    Zz = sys.Z.copy()
    Zz[1, 1] = 0.62
    assert (lim["Z22"] == 0.62).sum() == 3
    assert lim.loc["plant Z22=0.62", "sigma2_lo"] <= lim.loc["plant_necessary Z22=0.62", "sigma2_hi"]
    assert lim.loc["plant_necessary Z22=0.62", "sigma2_hi"] == pytest.approx(
        worst_sector_gain(dataclasses.replace(sys, Z=Zz))["value"], abs=2e-6)
    assert lim.loc["plant", "sigma2_lo"] <= lim.loc["plant_necessary", "sigma2_hi"]
    assert lim.loc["plant_necessary", "sigma2_hi"] < lim.loc["plant_componentwise_necessary", "sigma2_lo"]
    assert lim.loc["plant_componentwise", "sigma2_lo"] <= lim.loc["plant_componentwise_necessary", "sigma2_hi"]
    assert lim.loc["plant_necessary", "sigma2_hi"] == pytest.approx(worst_sector_gain(sys)["value"], abs=2e-6)
    assert set(lim["role"]) == {"sufficient", "necessary"}
    grid = out["table"]
    beyond = grid[grid["sigma2"] == 4.5]  # above every necessary end: decided without a solve
    assert (beyond["verdict"] == "infeasible").all() and (beyond["status"] == "not solved").all()
    assert set(grid.loc[grid["sigma2"] == 1.0, "verdict"]) == {"feasible"}


def test_scheduling_step_nests_the_families(cfg, sys, paper, tmp_path):
    import pandas as pd

    from netrepro.papers.gainsched.model import zero_gains
    from netrepro.papers.gainsched.steps import scheduling_step

    pd.concat([gains_table("paper", paper), gains_table("performance", zero_gains(sys))]).to_csv(tmp_path / "g.csv",
                                                                                               index=False)
    out = scheduling_step(cfg, {"gains": tmp_path / "g.csv"}, {})["table"]
    gc_all = out[out["comparison"] == "guaranteed_cost"]
    assert set(gc_all["verdict"]) == {"feasible"}
    assert set(gc_all["multiplier"]) == {"free", "fixed"}
    for mult, gc in gc_all.groupby("multiplier"):
        gc = gc.set_index("family")
        # nested families: x_f = 0 within fixed gains within scheduled gains, so the guaranteed costs are ordered
        assert gc.loc["scheduled", "value"] <= gc.loc["fixed_gain", "value"] * (1 + 1e-6) <= gc.loc["zero", "value"] * (
            1 + 1e-6), mult
    free = gc_all[gc_all["multiplier"] == "free"].set_index("family")["value"]
    fixed = gc_all[gc_all["multiplier"] == "fixed"].set_index("family")["value"]
    assert (free <= fixed * (1 + 1e-6)).all()  # the fixed multiplier is one value of the free one
    # the certified bracket of the scheduled family's least cost holds its certified point's cost
    for family in ("scheduled", "zero"):
        rows = out[out["family"] == family].set_index("comparison")["value"]
        assert rows["guaranteed_cost_lower"] <= free[family] <= rows["guaranteed_cost_upper"] + 1e-12, family
    et = out[out["comparison"] == "exact_tuned"].set_index("family")["value"]
    assert et["scheduled"] <= et["fixed_gain"]
    assert set(out.loc[out["comparison"] == "schedule_size", "family"]) == {"performance"}


def test_a_step_with_every_decision_undecided_stops_naming_step_and_status():
    from netrepro.papers.gainsched.model import GainschedError
    from netrepro.papers.gainsched.steps import _no_decision

    rows = [{"verdict": "undecided", "status": "user_limit"}, {"verdict": "undecided", "status": "optimal_inaccurate"}]
    with pytest.raises(GainschedError, match=r"gainsched_scheduling: every decision .* user_limit"):
        _no_decision(rows, "gainsched_scheduling", "the performance LMI")
    _no_decision(rows + [{"verdict": "feasible", "status": "user_limit"}], "gainsched_scheduling", "x")  # one decided
    _no_decision([], "gainsched_scheduling", "x")  # nothing to decide


def test_design_step_without_a_certified_design_names_the_step_and_the_solver_status(cfg, monkeypatch):
    """A one-iteration solver (the fault injection of the shared engine) leaves Theorem 3 undecided: the design
    step stops at once, naming itself and the solver's status, instead of a later step missing the design."""
    from netrepro.papers.gainsched.model import GainschedError
    from netrepro.papers.gainsched.steps import design_step

    monkeypatch.setenv("NETREPRO_SOLVER_MAX_ITER", "1")
    with pytest.raises(GainschedError, match=r"gainsched_design: the theorem3 design .* undecided .*solver status user_limit"):
        design_step(cfg, {}, {})
