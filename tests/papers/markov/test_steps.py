"""Steps of `markov` on a tiny configuration: tables written with their columns and invariants."""

from __future__ import annotations

import pandas as pd


def test_steps_tables(markov_tables):
    t = markov_tables
    curves = pd.read_csv(t["curves"])
    for col in ("example", "q", "p_prop1", "p_thm5", "q_necessary", "p_thm5_uncapped"):
        assert col in curves
    assert (curves.p_thm5 <= 1).all() and (curves.thm5_n_uncertified == 0).all()
    smap = pd.read_csv(t["map"], keep_default_na=False)
    assert {"example", "p", "q", "bounded", "growth_rate", "method"} <= set(smap.columns)
    iid = pd.read_csv(t["iid"])
    assert {"example", "lambda_lower", "lambda_lmi_upper", "q_thm5_on_iid_line"} <= set(iid.columns)


def test_map_decided_by_certificates_and_sensitivity(markov_tables, markov_cfg):
    smap = pd.read_csv(markov_tables["map"], keep_default_na=False)
    far = smap.dist_critical.astype(float) >= markov_cfg["map"]["far"]
    assert not ((smap.verdict == "undecided") & far).any()
    sens = pd.read_csv(markov_tables["sensitivity"])
    assert {"example", "threshold", "value", "n_changed", "n_contradict_certified", "n_undecided_far"} <= set(sens.columns)
    default = sens[sens.is_default]
    assert (default.n_changed == 0).all()
    assert set(sens.threshold) >= {"certify.rho_margin", "certify.growth_margin", "certify.n_gaps", "bounded_tol",
                                   "unbounded_tol", "refine.rel_tol"}
