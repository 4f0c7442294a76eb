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
