"""Tests of netrepro.papers.onebit.evidence against independent computations, and of the paper's data files."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import integrate, stats

from netrepro.papers.onebit import evidence, steps
from netrepro.papers.onebit.model import axis_shift_db
from netrepro.papers.onebit.randomwalk import ratios_at, snr_shift_deviation
from netrepro.verdicts import NOMINAL, load_paper_data, read_evidence, verdicts_step

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


def _efq_by_quad(var):
    """(29) with (30), sigma_eta = 1, by adaptive quadrature of the plain formula (no product-Gaussian trick)."""
    def f(t):
        q = stats.norm.sf(t) * stats.norm.cdf(t)
        return math.exp(-t * t) / (2 * math.pi * q) * stats.norm.pdf(t, scale=math.sqrt(var))
    sd = math.sqrt(var)
    return integrate.quad(f, -12 * sd, 12 * sd, points=[0.0], limit=400, epsabs=0, epsrel=1e-12)[0]


def _ratios_by_iteration(eps, sigma_z2, F_q, n=200_000):
    """(24)/(34) and (27)/(37)-(38) iterated to their fixed points (plain loops), then (47)-(49) in dB."""
    a = 1.0 - eps

    def fixed(F):
        J = 1.0
        for _ in range(n):
            J_new = 1 / sigma_z2 + F - (a / sigma_z2) ** 2 / (J + a * a / sigma_z2)
            if abs(J_new - J) <= 1e-15 * J_new:
                break
            J = J_new
        k = 0.0
        for _ in range(n):
            k_new = a * a / sigma_z2 - (a / sigma_z2) ** 2 / (1 / sigma_z2 + F + k)
            if abs(k_new - k) <= 1e-15 * abs(k_new):
                break
            k = k_new
        return J, J + k

    jf_i, js_i = fixed(1.0)
    jf_q, js_q = fixed(F_q)
    db = lambda x: 10 * math.log10(x)  # noqa: E731
    return dict(rho_sl_db=db(js_q / js_i), rho_f_db=db(jf_q / jf_i), rho_s_db=db(js_q / jf_i))


@pytest.mark.parametrize("eps,snr_db,definition", [(1e-2, 0.0, "stationary"), (1e-1, -10.0, "stationary"),
                                                   (1e-2, -20.0, "innovation")])
def test_ratios_at_against_plain_iteration(eps, snr_db, definition):
    snr = 10 ** (snr_db / 10)
    s = snr * eps * (2 - eps) if definition == "stationary" else snr
    var = s / (eps * (2 - eps))
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(var))
    ours = ratios_at([snr_db], eps, 1.0, definition)
    for k, v in ref.items():
        assert ours[k][0] == pytest.approx(v, abs=1e-6), k


def test_limit_low_snr_closed_form():
    """alpha -> 1 and SNR -> 0: rho_F = rho_SL = sqrt(2/pi), rho_S = 2 sqrt(2/pi) (Sec. 1, Sec. 5)."""
    r = ratios_at([-80.0], 0.0)
    assert r["rho_f_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert r["rho_sl_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert r["rho_s_db"][0] == pytest.approx(10 * math.log10(2 * math.sqrt(2 / math.pi)), abs=1e-6)
    assert np.isnan(ratios_at([-10.0], 0.0, definition="innovation")["rho_s_db"][0])


def test_limit_is_approached_by_finite_alpha():
    """The closed-form limit against the plain iteration at a tiny 1 - alpha (fixed stationary SNR 0 dB)."""
    eps = 1e-7
    s = eps * (2 - eps)
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(1.0), n=2_000_000)
    lim = ratios_at([0.0], 0.0)
    for k, v in ref.items():
        assert lim[k][0] == pytest.approx(v, abs=2e-3), k


@pytest.mark.parametrize("eps", [1e-3, 1e-5, 0.3])
def test_axis_shift(eps):
    """The innovation SNR is the stationary SNR times 1 - alpha^2, (33); the curves coincide after the shift."""
    a = 1 - eps
    assert axis_shift_db(eps) == pytest.approx(10 * math.log10(1 - a * a), rel=1e-12)
    snr_stat = -12.0
    s = 10 ** (snr_stat / 10) * (1 - a * a)          # the same sigma_z^2 ...
    snr_inno = 10 * math.log10(s)                     # ... labelled by the innovation reading
    ours = ratios_at([snr_inno], eps, 1.0, "innovation")
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(10 ** (snr_stat / 10)))
    for k, v in ref.items():
        assert ours[k][0] == pytest.approx(v, abs=1e-6), k
    assert snr_shift_deviation(np.array([-30.0, 0.0, 10.0]), eps) < 1e-9


def test_low_snr_cases():
    cases = evidence.low_snr_cases(1e-5, -30.0, [-40.0, -30.0], [0.0, 1e-3, 1e-5])
    assert cases[0] == (1e-5, -30.0)
    assert len(cases) == len(set(cases))
    assert set(cases) == {(1e-5, -30.0), (1e-5, -40.0), (0.0, -30.0), (0.0, -40.0), (1e-3, -30.0)}
    assert evidence.alpha_label(0.0) == "alpha -> 1" and evidence.alpha_label(1e-5) == "alpha = 1 - 1e-05"


def test_errata_residuals(cfg):
    rows = {r["quantity"]: r["value"] for r in evidence.errata_rows(cfg)}
    for e in ("E1", "E2", "E3", "E4", "E5", "E6"):
        assert rows[f"{e}.residual_corrected"] < 1e-10, e
        assert rows[f"{e}.residual_printed"] > 1e-3, e


def test_paper_data_loads():
    data = load_paper_data("onebit")
    ids = {c.claim_id for c in data.claims}
    assert {"same_loss", "rho_sl_fig1", "rho_s_alpha_threshold", "outperform_achievable"} <= ids
    assert "bound_below_mse" not in ids and "bound_below_mse" in {f["id"] for f in data.findings}
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
    for name, key in (("estimator", "table"), ("estimator_ratios", "ratios"), ("crossing", "crossing")):
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
                assert label.split(":")[0].split("=")[0] in keys, (q, label)
    # the break-even lag exists exactly where rho_S > 0 (why it is no separate claim)
    assert ev["break_even_lag"][NOMINAL][0] is True
    # run halves: n = 20 of 40 runs each
    assert any("n = 20" in label for label in ev["achievable_rho_s_positive"])
    claims = out["table"].set_index("claim_id")
    assert claims.loc["same_loss", "verdict"] == "conditional"
    assert "alpha -> 1" in claims.loc["same_loss", "condition"].split("; not for")[0]
    assert claims.loc["rho_s_gt_rho_f", "verdict"] == "reproduced"
    assert isinstance(out["findings"], pd.DataFrame) and len(out["findings"]) == 7
    # the crossing: a local fit on the crossing SNRs, the former straight line and the bound beside it
    assert "local fit, crossing SNRs" in ev["rho_s_crossing"][NOMINAL][1]


def test_findings_are_judged_like_claims():
    """Every finding has a rule, evidence quantities, depends_on naming reconstructions, and prior work (issue 27)."""
    data = load_paper_data("onebit")
    keys = {r["key"] for r in data.reconstructions}
    for f in data.findings:
        assert f.get("rule", {}).get("reason"), f["id"]
        assert f.get("evidence_quantities") and f["quantity"] in f["evidence_quantities"], f["id"]
        assert set(f.get("depends_on", [])) <= keys, f["id"]
        assert f.get("prior_work"), f["id"]
