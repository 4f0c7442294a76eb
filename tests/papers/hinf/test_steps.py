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
