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
