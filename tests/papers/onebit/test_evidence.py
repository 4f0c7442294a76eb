"""Tests of netrepro.papers.onebit.evidence against independent computations, and of the paper's data files."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from netrepro.papers.onebit import evidence, steps
from netrepro.judging.paperdata import load_paper_data
from netrepro.judging.verdicts import NOMINAL, read_evidence, verdicts_step

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


def test_low_snr_cases():
    cases = evidence.low_snr_cases(1e-5, -30.0, [-40.0, -30.0], [0.0, 1e-3, 1e-5])
    assert cases[0] == (1e-5, -30.0)
    assert len(cases) == len(set(cases))
    assert set(cases) == {(1e-5, -30.0), (1e-5, -40.0), (0.0, -30.0), (0.0, -40.0), (1e-3, -30.0)}
    assert evidence.alpha_label(0.0) == "alpha -> 1" and evidence.alpha_label(1e-5) == "alpha = 1 - 1e-05"


def test_errata_residuals(cfg):
    rows = {r["quantity"]: r["value"] for r in evidence.errata_rows(dict(cfg, _at=load_paper_data("onebit").settings()))}
    for e in ("E1", "E2", "E3", "E4", "E5", "E6"):
        assert rows[f"{e}.residual_corrected"] < 1e-10, e
        assert rows[f"{e}.residual_printed"] > 1e-3, e


def test_errata_settings_come_from_errata_yaml(cfg):
    """E4 and E5 are demonstrated at the 'at' settings of errata.yaml: other settings give other residuals and notes.

    E4 against an independent recursion: the printed (32) misses exactly the newest innovation, so its relative
    error at step k is sigma_z^2 / Var_k with Var_k = alpha^2 Var_{k-1} + sigma_z^2, Var_0 = sigma_0^2."""
    at = load_paper_data("onebit").settings()
    assert at["E4"] == {"one_minus_alpha": 1.0e-3, "sigma_z2": 0.01, "K": 200}
    assert at["E5"] == {"one_minus_alpha": 1.0e-2, "snr_db": 0.0, "sigma_eta": 1.0, "K": 300}
    eps, s, K = 0.2, 0.5, 40
    other = dict(at, E4={"one_minus_alpha": eps, "sigma_z2": s, "K": K},
                 E5={"one_minus_alpha": 0.05, "snr_db": -3.0, "sigma_eta": 2.0, "K": 50})
    rows = {(r["quantity"]): r for r in evidence.errata_rows(dict(cfg, _at=other))}
    var, worst = cfg["sigma_theta0"] ** 2, 0.0
    for _ in range(K):
        var = (1 - eps) ** 2 * var + s
        worst = max(worst, s / var)
    assert rows["E4.residual_printed"]["value"] == pytest.approx(worst, rel=1e-9)
    assert "k = 1..40" in rows["E4.residual_printed"]["note"] and "alpha = 1 - 0.2, sigma_z^2 = 0.5" in \
        rows["E4.residual_printed"]["note"]
    assert "(alpha = 0.95, stationary SNR = -3 dB, sigma_eta = 2, K = 50)" in rows["E5.residual_printed"]["note"]
    assert rows["E5.residual_corrected"]["value"] < 1e-10 and rows["E5.residual_printed"]["value"] > 1e-3
    nominal = {r["quantity"]: r for r in evidence.errata_rows(dict(cfg, _at=at))}
    assert "(alpha = 1 - 1e-3, sigma_z^2 = 0.01, sigma_0 = 1)" in nominal["E4.residual_printed"]["note"]


def test_paper_data_loads():
    data = load_paper_data("onebit")
    ids = {c.claim_id for c in data.claims}
    assert {"same_loss", "rho_sl_fig1", "rho_s_alpha_threshold", "outperform_achievable"} <= ids
    assert "bound_below_mse" not in ids and "bound_below_mse" in {f.finding_id for f in data.findings}
    kinds = {e["id"]: e["kind"] for e in data.errata}
    assert kinds["E5"] == "typesetting" and kinds["E6"] == "notation"


@pytest.fixture(scope="module")
def tables(cfg, tmp_path_factory):
    """The evidence table and the four verdict tables of the test configuration."""
    tmp = tmp_path_factory.mktemp("onebit")
    c = copy.deepcopy(cfg)
    c["estimator"].update(one_minus_alpha=[1e-2, 1e-1], snr_db=[-10.0, 0.0], n_runs=40, block_size=10)
    paths = {}
    for name, fn, key in (("ratios", steps.ratios_step, "table"), ("lag", steps.lag_step, "table"),
                          ("efq", steps.efq_step, "table"), ("alpha_threshold", steps.alpha_scan_step, "threshold")):
        paths[name] = tmp / f"{name}.csv"
        fn(c, {}, {})[key].to_csv(paths[name], index=False)
    shards = []
    for i in range(2):
        shards.append(tmp / f"shard{i}.npz")
        steps.estimator_shard_step(dict(c, shard=i, n_shards=2), {}, {"runs": shards[-1]})
    est = steps.estimator_step(c, {"shards": shards}, {})
    for name, key in (("estimator", "table"), ("estimator_ratios", "ratios"), ("crossing", "crossing"),
                      ("coverage", "coverage"), ("edge", "edge")):
        paths[name] = tmp / f"{name}.csv"
        est[key].to_csv(paths[name], index=False)
    root = ROOT / "src" / "netrepro" / "papers" / "onebit"
    table = evidence.evidence_step(c, {**{k: str(v) for k, v in paths.items()}, "shards": [str(s) for s in shards],
                                       "findings_file": str(root / "findings.yaml")}, {})["table"]
    ev_path = tmp / "evidence.csv"
    table.to_csv(ev_path, index=False)
    root = ROOT / "src" / "netrepro" / "papers" / "onebit"
    out = verdicts_step({"slug": "onebit"}, {"claims_file": str(root / "claims.yaml"), "evidence": str(ev_path),
                                             "tables": []}, {})
    return read_evidence(ev_path), out


def test_every_claim_quantity_has_evidence(tables):
    ev, out = tables
    data = load_paper_data("onebit")
    for c in data.claims:
        q = c.ours.get("quantity")
        if c.kind in ("numeric", "boolean"):
            assert NOMINAL in ev[q], c.claim_id
            if c.depends_on:
                assert len(ev[q]) > 1, c.claim_id
    # every claim but the Monte Carlo one (40 runs here: too few to be significant) holds at least somewhere
    bounds_only = out["table"][out["table"]["claim_id"] != "outperform_achievable"]
    assert set(bounds_only["verdict"]) <= {"reproduced", "conditional", "context", "not_checkable"}


def test_evidence_values(tables):
    ev, out = tables
    # same loss: exactly zero in the limit, not at alpha = 1 - 1e-5 (prior information at low SNR)
    assert ev["same_loss_db"]["alpha_to_1: alpha -> 1, SNR = -30 dB"][0] == 0.0
    assert ev["same_loss_db"][NOMINAL][0] > 0.01
    # the innovation reading moves rho_S > 0 out of the low-medium SNR range
    assert ev["rho_s_positive"][NOMINAL][0] is True
    assert ev["rho_s_positive"]["snr_definition: SNR = sigma_z^2/sigma_eta^2, alpha = 1 - 1e-05"][0] is False
    assert ev["rho_s_alpha_threshold"]["snr_definition: SNR = sigma_z^2/sigma_eta^2"][0] is False
    # the medium regime's declared ends are variants named by their key (issue 27, convention 2)
    assert {"medium_snr_regime=2.5 dB", "medium_snr_regime=5 dB"} <= set(ev["rho_s_positive"])
    assert "low_snr_regime=-5 dB" in ev["rho_s_low_snr_max_db"]
    keys = {"snr_grid_db", "alpha_to_1", "snr_definition", "low_snr_regime", "medium_snr_regime", "estimator"}
    for q, variants in ev.items():
        for label in variants:
            if label != NOMINAL and not q.startswith("reconstruction."):
                # a declared range (<key>: / <key>=) or the counterfactual a finding's cause names
                assert label.split(":")[0].split("=")[0] in keys | {"cause"}, (q, label)
    causes = [(f.quantity, f.cause["variant"]) for f in load_paper_data("onebit").findings if f.cause]
    for q, label in causes:  # the cause variant is a variant of the judged quantity
        assert label in ev[q], (q, label)
    # the counterfactual of finite_alpha_low_snr (an observation since issue 37) stays in the evidence: without the
    # mean reversion rho_SL stays near the -0.98 dB asymptote at -60 dB
    cf = ev["finite_alpha_low_snr"]["cause: alpha = 1 in (24)/(27), same sigma_z^2, E[F_q]"][0]
    assert cf == pytest.approx(-0.98, abs=0.01) and ev["finite_alpha_low_snr"][NOMINAL][0] > -0.5
    # the break-even lag exists exactly where rho_S > 0 (why it is no separate claim)
    assert ev["break_even_lag"][NOMINAL][0] is True
    # run halves: n = 20 of 40 runs each
    assert any("n = 20" in label for label in ev["achievable_rho_s_positive"])
    claims = out["table"].set_index("claim_id")
    assert claims.loc["same_loss", "verdict"] == "conditional"
    assert "alpha -> 1" in claims.loc["same_loss", "condition"].split("; not for")[0]
    assert claims.loc["rho_s_gt_rho_f", "verdict"] == "reproduced"
    assert isinstance(out["findings"], pd.DataFrame) and len(out["findings"]) == 8
    # the crossing: a local fit on the crossing SNRs, the former straight line and the bound beside it
    assert "local fit, crossing SNRs" in ev["rho_s_crossing"][NOMINAL][1]


def test_findings_are_judged_like_claims():
    """Every judged finding has a rule (an observation none), every finding evidence quantities, depends_on naming
    reconstructions, and prior work (issues 27 and 37)."""
    data = load_paper_data("onebit")
    keys = {r["key"] for r in data.reconstructions}
    for f in data.findings:
        assert bool(f.rule_reason) == (f.kind != "observation"), f.finding_id
        assert f.evidence_quantities and f.quantity in f.evidence_quantities, f.finding_id
        assert set(f.depends_on) <= keys, f.finding_id
        assert f.prior_work, f.finding_id


def _crossing_table(est, lo, hi, bound, alpha=0.999):
    rows = [dict(alpha=alpha, curve=c, snr_db_crossing=v, method="local fit, crossing SNRs", fit_snr_lo=1.0,
                 fit_snr_hi=2.5, n_points=7, n_runs=4000, n_boot=4000, fit_residual_rms=0.05,
                 slope_db_per_db=-0.5 if c == "estimate" else np.nan)
            for c, v in (("estimate", est), ("lo", lo), ("hi", hi))]
    rows += [dict(alpha=alpha, curve="grid_linear", snr_db_crossing=est), dict(alpha=alpha, curve="bound",
                                                                               snr_db_crossing=bound)]
    return pd.DataFrame(rows)


@pytest.mark.parametrize("est,lo,hi,bound,value,decided", [
    (2.0, 1.8, 2.3, 7.0, True, True),      # gap [4.7, 5.2] > 3 dB: holds
    (2.0, 1.8, 2.3, 5.0, False, False),    # gap [2.7, 3.2] straddles 3 dB: undecided
    (2.0, 1.8, 2.3, 4.0, False, True),     # gap [1.7, 2.2] < 3 dB: fails, decided
])
def test_crossing_test_is_undecided_while_the_interval_straddles_the_effect_size(cfg, est, lo, hi, bound, value,
                                                                                decided):
    at = {"rho_s_crossing": {"one_minus_alpha": 1e-3, "effect_size_db": 3.0}}
    edge = pd.DataFrame([dict(alpha=0.999, snr_db=2.0, quantity="edge_bias_db.rho_S", estimate=-0.1, lo=-0.2, hi=0.0,
                              extra_taus=20.0, n_runs=100)])
    rows = evidence._crossing_evidence(dict(cfg, _at=at), _crossing_table(est, lo, hi, bound), edge)
    test = next(r for r in rows if r["quantity"] == "rho_s_crossing_far_below_bound")
    assert (test["value"], test["decided"]) == (value, decided)
    q = {r["quantity"]: r for r in rows}
    assert q["rho_s_crossing"]["uncertainty"] == pytest.approx(0.3)       # the larger side of the interval
    # the edge bias -0.1 dB on a slope of -0.5 dB/dB moves the crossing by -0.2 dB (+- 0.1 / 0.5)
    assert q["rho_s_crossing_edge_shift_db"]["value"] == pytest.approx(-0.2)
    assert q["rho_s_crossing_edge_shift_db"]["uncertainty"] == pytest.approx(0.2)
