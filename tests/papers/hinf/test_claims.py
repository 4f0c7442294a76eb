"""Claims, errata and reconstructions of `hinf` on a tiny run: computed verdicts, corrected forms fit better."""

from __future__ import annotations

import pandas as pd

from netrepro.claims import CLAIM_COLUMNS, VERDICTS
from netrepro.papers.hinf import claims


def test_errata_corrected_forms_beat_printed(hinf_run):
    cfg, _ = hinf_run
    e = claims.errata_step(cfg, {}, {})["table"]
    assert list(e["erratum_id"]) == ["E1", "E2", "E3", "E4", "E5"]
    assert (e["residual_corrected"] < 0.05).all()
    assert (e["residual_printed"] > 10 * e["residual_corrected"]).all()


def test_reconstructions_cover_sweeps(hinf_run):
    cfg, files = hinf_run
    r = claims.reconstructions_step(cfg, {"sensitivity": files["sensitivity"],
                                          "sensitivity_evasive": files["sensitivity_evasive"],
                                          "evader": files["evader"]}, {})["table"]
    assert r.loc[r["key"] == "hinf.evader.n_iter", "sensitivity"].str.contains("certified").all()
    assert r["key"].is_unique
    assert r.loc[r["key"] == "hinf.filter.gamma", "sensitivity"].str.contains("sweep").all()


def test_claims_table(hinf_run):
    cfg, files = hinf_run
    inputs = {k: files[k] for k in ("noise_fit", "consensus", "attenuation", "checks", "summary", "paired",
                                    "paired_evasive", "per_agent", "modes", "evader_paired")}
    c = claims.claims_step(cfg, inputs, {})["table"]
    assert list(c.columns) == CLAIM_COLUMNS
    assert set(c["verdict"]) <= set(VERDICTS)
    v = c.set_index("claim_id")["verdict"]
    for key in ("hinf_to_kalman", "decentralized_exact_equals_centralized", "below_gamma0_no_filter"):
        assert v[key] == "reproduced", key
    assert isinstance(c, pd.DataFrame)
    assert "pairwise" in c.set_index("claim_id").loc["future_hinf_beats_kalman_evasive", "note"]
