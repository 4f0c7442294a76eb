"""Evidence of `hinf`: helpers against closed forms and other algorithms, the evidence table on a tiny run,
and the paper's data files (claims, errata, reconstructions, findings) judged against it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from netrepro.papers.hinf import evidence
from netrepro.judging.paperdata import load_paper_data
from netrepro.judging.verdicts import read_evidence, verdicts_step

INPUTS = ("consensus", "attenuation", "checks", "summary", "paired", "errors", "trajectories", "per_run_static_fixed",
          "per_run_static_mobile", "connectivity", "sensitivity", "sensitivity_evasive", "paired_evasive", "per_agent",
          "modes", "evader", "evader_paired", "fig5_control", "evasive_network", "loop_variants", "loop_swap", "kalman_best", "evader_fused",
          "fig6_paths")


@pytest.fixture(scope="module")
def evidence_table(hinf_run, tmp_path_factory):
    cfg, files = hinf_run
    claims, findings = (Path(evidence.__file__).with_name(f"{name}.yaml") for name in ("claims", "findings"))
    table = evidence.evidence_step(cfg, {"claims": claims, "findings": findings, **{k: files[k] for k in INPUTS}},
                                   {})["table"]
    path = tmp_path_factory.mktemp("evidence") / "hinf.csv"
    table.to_csv(path, index=False)
    return cfg, files, table, path


def test_evidence_matches_independent_reads_of_the_tables(evidence_table):
    cfg, files, table, path = evidence_table
    ev = read_evidence(path)
    # the sweet spot is the vertex a1 of (4)
    assert ev["noise.sweet_spot"]["nominal"][0] == pytest.approx(cfg["noise"]["a1"], abs=1e-3)
    # settling step at the configured threshold: same as steps.scenario_tables' settle_k (another implementation)
    summ = pd.read_csv(files["summary"]).set_index(["scenario", "filter"])
    md, sl = summ.loc[("static_mobile", "decentralized"), "settle_k"], summ.loc[("static_fixed", "local"), "settle_k"]
    assert ev["fig4.mobile_settles_quicker"]["nominal"][0] == bool(md >= 0 and (sl < 0 or md < sl))
    assert f"mobile decentralized {md}, stationary local {sl}" in ev["fig4.mobile_settles_quicker"]["nominal"][1]
    # the Fig-2 per-agent variants are the per-agent table's z-scores against the configured threshold
    pa = pd.read_csv(files["per_agent"])
    z_sig = cfg["claims"]["z_significant"]
    for r in pa[pa["scenario"] == "fig2"].itertuples():
        who = "mean over agents" if r.agent < 0 else f"agent {r.agent}"
        suffix = "" if r.tag == "holds" else f" ({r.tag})"
        assert ev["fig2.decentralized_beats_local"][f"fig2_horizon: {who}, H={r.horizon}{suffix}"][0] == bool(r.z < -z_sig)
        assert r.tag == ("holds" if r.z < -z_sig else "reversed" if r.z > z_sig else "not significant")
    # the loop comparison's z (PI design, evasive target, same paths) is scipy's paired t on the per-run table
    runs = pd.read_csv(files["loop_variants_runs"])
    pi = runs[(runs["target"] == "evasive") & (runs["loop"] == "pi")].sort_values("run")
    t = stats.ttest_rel(pi["decentralized"], pi["local"]).statistic
    assert ev["loop.dec_vs_local_same_paths"]["nominal"][0] == pytest.approx(t, rel=1e-9)
    # one connectivity variant per scenario, true exactly where every step is connected
    conn = summ.groupby(level="scenario")["connected_fraction"].first()
    for s, v in conn.items():
        assert ev["r20.connected"][f"scenario {s}"][0] == bool(v == 1.0)
    # the fig4 attribution's paired z equals scipy's paired t statistic on the per-run tables
    sf = pd.read_csv(files["per_run_static_fixed"])
    t = stats.ttest_rel(sf["decentralized"], sf["local"]).statistic
    assert f"(SD - SL): late-error diff {np.mean(sf['decentralized'] - sf['local']):+.3f} (z = {t:.1f}" in \
        ev["fig4.attribution"]["nominal"][1]


def test_errata_corrected_forms_beat_printed(evidence_table):
    _, _, table, path = evidence_table
    ev = read_evidence(path)
    for eid in ("E1", "E2", "E3", "E4", "E5", "E6", "E9"):
        printed, corrected = ev[f"{eid}.residual_printed"]["nominal"][0], ev[f"{eid}.residual_corrected"]["nominal"][0]
        assert corrected < 0.05 and printed > 10 * corrected, eid


def test_paper_data_load_and_every_claim_is_judged(evidence_table, tmp_path):
    _, _, _, path = evidence_table
    data = load_paper_data("hinf")
    ids = [c.claim_id for c in data.claims]
    assert not any(i.startswith("noise_") for i in ids)  # self-checks removed (issue 15)
    assert {"abstract_multiagent_vs_local_evasive", "sweet_spot", "limit_filter_gains"} <= set(ids)
    assert {e["id"] for e in data.errata} >= {"E6", "E7", "E8", "E9", "E10", "E_speed"}
    pkg = Path(evidence.__file__).parent
    outs = verdicts_step({"slug": "hinf"}, {"claims_file": pkg / "claims.yaml", "evidence": path, "tables": []}, {})
    claims = outs["table"]
    assert list(claims["claim_id"]) == ids
    assert set(claims["verdict"]) <= {"reproduced", "conditional", "differs", "erratum", "context"}
    assert (outs["reconstructions"]["value"].astype(str) != "").all()
    assert outs["findings"]["evidence"].str.len().gt(0).all()
