"""The `hinf` pipeline steps on a tiny configuration: columns and invariants of every table."""

from __future__ import annotations

import numpy as np
import pandas as pd

from netrepro.papers.hinf import steps
from netrepro.papers.hinf.model import SCENARIOS


def test_noise_tables(hinf_run):
    cfg, files = hinf_run
    t = pd.read_csv(files["noise_model"])
    assert list(t.columns) == ["sensor", "x", "y", "r", "theta", "f_r", "f_b", "sigma_major", "sigma_minor", "angle"]
    np.testing.assert_allclose(np.hypot(t["x"], t["y"]), t["r"])
    fit = pd.read_csv(files["noise_fit"])
    # sample variances within 5 standard errors (relative sd sqrt(2/n)) of the model
    tol = 5 * np.sqrt(2 / fit["n_samples"])
    assert np.all(np.abs(fit["var_range"] / fit["f_r_model"] - 1) < tol)
    assert np.all(np.abs(fit["var_bearing"] / fit["f_b_model"] - 1) < tol)


def test_consensus_table(hinf_run):
    _, files = hinf_run
    c = pd.read_csv(files["consensus"])
    assert list(c.columns) == ["h", "steady_state_error", "stable", "spectral_radius", "h_max"]
    assert (c["stable"] == (c["spectral_radius"] < 1)).all()
    assert (c.loc[c["stable"], "steady_state_error"] < 1e-6).all()


def test_attenuation_tables(hinf_run):
    _, files = hinf_run
    a = pd.read_csv(files["attenuation"])
    assert set(a["filter"]) == {"local", "centralized"}
    # pooling information can only lower gamma_0
    g = a.set_index("filter")["gamma0"]
    assert g["centralized"] <= g["local"]
    assert (a["status_below"] == "does_not_exist").all()
    chk = pd.read_csv(files["checks"]).set_index("check")["value"]
    assert chk.max() < 1e-6


def test_simulation_tables(hinf_run):
    cfg, files = hinf_run
    err = pd.read_csv(files["errors"])
    assert set(err["scenario"]) == set(SCENARIOS)
    assert (err["error_lo"] <= err["error_hi"]).all()
    summ = pd.read_csv(files["summary"])
    assert (summ["n_runs"] > 0).all() and np.isfinite(summ["late_mean"]).all()
    paired = pd.read_csv(files["paired"])
    assert list(paired.columns) == ["comparison", "scenario_a", "filter_a", "scenario_b", "filter_b", "mean_diff",
                                    "se_diff", "z"]
    assert set(paired["comparison"]) == set(steps.PAIRED)
    np.testing.assert_allclose(paired["z"], paired["mean_diff"] / paired["se_diff"])
    traj = pd.read_csv(files["trajectories"], dtype={"who": str})
    assert {"target", "0"} <= set(traj["who"])


def test_sensitivity_tables(hinf_run):
    _, files = hinf_run
    s = pd.read_csv(files["sensitivity"])
    # gamma = 1.5 is below gamma_0 of the local filters: reported as not existing
    assert not s.loc[(s["parameter"] == "gamma") & (s["value"] == 1.5), "exists"].any()
    ev = pd.read_csv(files["sensitivity_evasive"])
    assert (ev["parameter"] == "gamma_evasive").all() and np.isinf(ev["value"]).any()


def test_issue17_steps_columns(hinf_run):
    cfg, files = hinf_run
    pe = steps.paired_evasive_step(cfg, {}, {})["table"]
    assert list(pe.columns[:8]) == ["target", "filter_a", "filter_b", "gamma", "runs", "mean_diff", "se", "z"]
    assert set(pe["target"]) == {"evasive", "random"}
    names = {"local", "decentralized", "centralized", "kalman_local", "kalman_decentralized", "kalman_centralized"}
    assert set(pe["filter_a"]) | set(pe["filter_b"]) <= names
    assert (pe["runs"] == cfg["paired"]["runs"]).all()
    np.testing.assert_allclose(pe["z"], pe["mean_diff"] / pe["se"])
    hk = pe[np.isfinite(pe["gamma_ratio"]) & (pe["filter_b"] == "kalman_" + pe["filter_a"])]
    assert (hk["gamma_ratio"] > 1).all()
    fh = steps.fig2_horizon_step(cfg, {}, {})
    pa = fh["table"]
    assert list(pa.columns[:7]) == ["scenario", "agent", "horizon", "local", "decentralized", "ratio", "z"]
    assert set(pa["scenario"]) == {t for s in cfg["fig2_horizon"]["scenarios"] for t in (s, f"{s}_ki0")}
    np.testing.assert_allclose(pa["ratio"], pa["decentralized"] / pa["local"])
    # the local filter does not use the consensus: identical with and without the integral gain
    a = pa[pa["scenario"] == "fig2"].reset_index()
    b = pa[pa["scenario"] == "fig2_ki0"].reset_index()
    np.testing.assert_allclose(a["local"], b["local"])
    modes = fh["modes"]
    assert (modes["modulus"] < 1).all()


def test_evader_and_network_steps(hinf_run):
    cfg, files = hinf_run
    both = steps.evader_check_step(cfg, {}, {})
    ev = both["table"]
    ep = both["paired"]
    conf = cfg["evader"].get("solver", "mirror")
    assert set(ep["solver"]) == {conf, "mirror", "pairwise"} and len(ep) == 3 * len({conf, "mirror", "pairwise"})
    assert ev["configured"].sum() == 1 and ev.loc[ev["configured"], "solver"].iloc[0] == conf
    ref = ev[ev["solver"] == "exact"].iloc[0]  # the certified reference
    assert ref["same_as_reference"] == 1.0 and ref["max_loss"] == 0.0
    assert ref["max_gap"] <= 1e-12 * ref["median_value"] * 10 and ref["certified_fraction"] > 0.95
    # a choice certified by an iterative solver is the exact solver's choice: it never loses more than the tolerance
    assert (ev["loss_above_tolerance_fraction"] <= 1 - ev["certified_fraction"] + 1e-12).all()
    assert ((ev["certified_fraction"] >= 0) & (ev["certified_fraction"] <= 1)).all()
    net = steps.network_step(cfg, {"trajectories": files["trajectories"]}, {})
    conn = net["connectivity"]
    # the ten-agent arc is a connected path: connected at every step, lambda_2 = 2 (1 - cos(pi / 10))
    fixed = conn[conn["scenario"] == "fig2"]
    assert (fixed["connected_fraction"] == 1.0).all()
    np.testing.assert_allclose(fixed["min_lambda2"], 2 * (1 - np.cos(np.pi / 10)), rtol=1e-9)
    links = net["table"]
    k0 = links[(links["scenario"] == "fig2") & (links["run"] == 0) & (links["k"] == 0)]
    assert len(k0) == 9


def test_fig5_control_table(hinf_run):
    cfg, files = hinf_run
    t = pd.read_csv(files["fig5_control"])
    assert list(t.columns) == ["parameter", "value", "runs", "horizon", "start", "stationary", "mobile", "mean_diff",
                               "se", "z"]
    sv = cfg["sensitivity"]
    assert len(t) == len(sv["Gamma"]) + len(sv["v_max"])
    assert t["stationary"].nunique() == 1  # one stationary reference, paired with every mobile run
    np.testing.assert_allclose(t["mobile"] - t["stationary"], t["mean_diff"], atol=1e-12)
    np.testing.assert_allclose(t["z"], t["mean_diff"] / t["se"])


def test_evasive_network_table(hinf_run):
    cfg, files = hinf_run
    t = pd.read_csv(files["evasive_network"])
    assert list(t.columns) == ["target", "run", "connected_fraction", "local", "decentralized"]
    assert set(t["target"]) == set(cfg["paired"]["targets"])
    assert (t.groupby("target").size() == cfg["paired"]["network_runs"]).all()
    assert t["connected_fraction"].between(0, 1).all()


def _sensitivity_consensus_rows_one_by_one(cfg, scen):
    """Reference: the consensus rows of the sensitivity table, one simulation per value (the former loop)."""
    from netrepro.papers.hinf.model import FilterDoesNotExist, resolve_scenario, simulate

    sv = cfg["sensitivity"]
    start = min(int(cfg["claims"]["late_start"]), int(sv["horizon"]) // 2)
    rows = []
    for key in ("gamma_c", "K_p", "K_i", "h", "iters"):
        for val in sv[key]:
            sc = resolve_scenario(cfg, scen, runs=int(sv["runs"]), horizon=int(sv["horizon"]), seed=int(sv["seed"]),
                                  consensus={key: val})
            sc["filters"] = ["local", "decentralized", "centralized"]
            try:
                with np.errstate(all="ignore"):
                    err = simulate(sc)["errors"]
            except FilterDoesNotExist:
                rows.append((key, val, False, np.nan, np.nan, np.nan))
                continue
            rows.append((key, val, True) + tuple(
                float(err[f][..., start:].mean()) if np.all(np.isfinite(err[f])) else np.inf
                for f in ("local", "decentralized", "centralized")))
    return rows


def test_sensitivity_consensus_rows_equal_one_simulation_each():
    """The consensus sweeps share one simulation per scenario; the rows equal those of one run per value, also
    when a value makes the filter fail (then every value is simulated on its own)."""
    from tests.papers.hinf.conftest import tiny_section

    cfg = tiny_section()
    cfg["sensitivity"].update(gamma_c=[0.25, 2.0], K_p=[0.1], K_i=[0.0, 0.4], h=[0.25], iters=[2])
    for h in ([0.25], [0.25, 40.0]):  # h = 40: the consensus diverges and the filter fails
        cfg["sensitivity"]["h"] = h
        got = steps.sensitivity_step(cfg, {}, {})["table"]
        for scen in cfg["sensitivity"]["random_scenarios"]:
            ref = _sensitivity_consensus_rows_one_by_one(cfg, scen)
            g = got[(got["scenario"] == scen) & got["parameter"].isin(["gamma_c", "K_p", "K_i", "h", "iters"])]
            assert len(g) == len(ref)
            for (_, row), (key, val, exists, loc, dec, cen) in zip(g.iterrows(), ref):
                assert (row["parameter"], row["value"], row["exists"]) == (key, val, exists)
                assert np.array_equal(row[["local_error", "decentralized_error", "centralized_error"]].to_numpy(float),
                                      np.array([loc, dec, cen]), equal_nan=True)
            assert any(not r[2] for r in ref) == (40.0 in h)  # the fallback is exercised
