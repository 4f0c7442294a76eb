"""Steps of `markov` on a tiny configuration: tables written with their columns and invariants."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from netrepro.errors import ModelError
from netrepro.papers.markov import analysis as enumeration, lmis, steps

from .systems import EX2


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


def test_lmi_checks_mark_certified_infeasibility_and_map_labels_p_thm1(markov_tables):
    """`certified` says a certificate decided the row, feasible or infeasible (issue 37); p_thm1 above 1 is
    labelled (it is 1 / rho(H_1(K)), not a failure rate)."""
    checks = pd.read_csv(markov_tables["checks"])
    assert (checks.certified == (checks.verdict != "undecided")).all()
    assert checks.loc[checks.verdict == "infeasible", "certified"].all()
    assert (checks.verdict == "infeasible").any()
    smap = pd.read_csv(markov_tables["map"], keep_default_na=False)
    p_thm1 = pd.to_numeric(smap.p_thm1, errors="coerce")
    assert (smap.p_thm1_above_cap.astype(str).eq("True") == (p_thm1 > 1)).all()


def test_holdout_exact_values_against_brute_force_enumeration(markov_tables, markov_cfg):
    """The held-out E||P_k|| (deeper exact tree on the split blocks) equals the mean over all 2^(k-1) channel paths
    enumerated one by one (enumeration.py, no tree and no block split); the bracket is the expectations table's."""
    hold = pd.read_csv(markov_tables["holdout"])
    assert len(hold) and set(hold.example) == {"II"}
    expect = pd.read_csv(markov_tables["expectations"])
    paths = enumeration.enumerate_norms(EX2, np.eye(3), int(hold.k.max()))
    for r in hold.itertuples():
        brute = enumeration.mean_norm_enumerated(paths, r.p, r.q, "gamma1")[r.k - 1]
        assert r.exact_mean == pytest.approx(brute, rel=1e-10)
        row = expect[(expect.example == r.example) & (expect.p == r.p) & (expect.k == r.k)].iloc[0]
        assert row.method == "asymptote" and (row.lo, row.hi) == (r.asym_lo, r.asym_hi)
        assert r.inside == (r.asym_lo <= brute <= r.asym_hi)
    # the held-out steps lie beyond the exact range the asymptote saw
    exact_k = expect[(expect.example == "II") & (expect.method == "exact")].k.max()
    assert hold.k.min() == exact_k + 1


class _Undecided:
    """An LMI whose every answer is undecided, as from a solver stopped after a few iterations."""

    def __init__(self, A, C, l_o=None, margin_tol=1e-7):
        self.A, self.C, self.n_solves = np.asarray(A, float), np.asarray(C, float), 0

    def solve(self, p, q):
        self.n_solves += 1
        return lmis.LMIResult(p, q, "user_limit", np.nan, False, False, np.nan, np.nan, [], "undecided",
                              "no certificate: solver stopped")


def test_a_step_with_every_decision_undecided_fails_naming_the_solver_status(markov_cfg, monkeypatch):
    monkeypatch.setattr(steps, "GilbertElliottLMI", _Undecided)
    cfg = dict(markov_cfg, checks=dict(markov_cfg["checks"], points=[p for p in markov_cfg["checks"]["points"]
                                                                      if p["name"] != "exII_thm2_p1"]))
    with pytest.raises(ModelError, match=r"markov step lmi_checks: all \d+ LMI decisions are undecided \(solver "
                                         r"statuses: user_limit\)"):
        steps.lmi_checks_step(cfg, {}, {})
    with pytest.raises(ModelError, match="markov step tight_variants: .* undecided"):
        steps.tight_variants_step(markov_cfg, {}, {})
