"""Tests of netrepro.papers.onebit.claims: each equation against an independent computation."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from netrepro.claims import CLAIM_COLUMNS, ERRATA_COLUMNS, RECONSTRUCTION_COLUMNS
from netrepro.papers.onebit import claims
from netrepro.papers.onebit import steps

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


def _claim_inputs(c, tmp_path):
    """Every table the claims step reads, from the steps on configuration ``c``."""
    paths = {}
    for name, fn in (("ratios", steps.ratios_step), ("lag", steps.lag_step), ("efq", steps.efq_step)):
        paths[name] = tmp_path / f"{name}.csv"
        fn(c, {}, {})["table"].to_csv(paths[name], index=False)
    est = steps.run_estimator(c)
    for name, key in (("estimator", "table"), ("estimator_ratios", "ratios"), ("crossing", "crossing")):
        paths[name] = tmp_path / f"{name}.csv"
        est[key].to_csv(paths[name], index=False)
    paths["alpha_threshold"] = tmp_path / "alpha_threshold.csv"
    steps.alpha_scan_step(c, {}, {})["threshold"].to_csv(paths["alpha_threshold"], index=False)
    return paths


def test_errata_reconstructions_claims(cfg, tmp_path):
    err = claims.errata_step(cfg, {}, {})["table"]
    assert list(err.columns) == ERRATA_COLUMNS
    assert (err["residual_corrected"] < 1e-10).all()
    assert (err["residual_printed"] > 1e-3).all()
    rec = claims.reconstructions_step(cfg, {}, {})["table"]
    assert list(rec.columns) == RECONSTRUCTION_COLUMNS and "snr_definition" in set(rec["key"])
    c = copy.deepcopy(cfg)
    c["estimator"].update(snr_db=[-10.0, 0.0], n_runs=100, block_size=50)
    table = claims.claims_step(c, _claim_inputs(c, tmp_path), {})["table"]
    assert list(table.columns) == CLAIM_COLUMNS
    v = table.set_index("claim_id")["verdict"]
    for cid in ("loss_no_model", "rho_f_low_snr", "rho_sl_low_snr_fig1", "rho_sl_low_snr_limit", "same_loss_limit",
                "rho_s_gt_rho_f", "rho_s_positive", "rho_s_plus_2db", "break_even_lag", "rho_s_alpha_close_to_one",
                "bound_below_mse"):
        assert v[cid] == "reproduced", cid


def test_innovation_snr_definition_does_not_reproduce_the_asymptotes(cfg, tmp_path):
    """The reconstruction argument: with SNR = sigma_z^2/sigma_eta^2 the paper's -0.98 dB (Fig 1) is not reached."""
    c = copy.deepcopy(cfg)
    c["snr_definition"] = "innovation"
    c["estimator"].update(snr_db=[0.0], n_runs=40, block_size=20)
    v = claims.claims_step(c, _claim_inputs(c, tmp_path), {})["table"].set_index("claim_id")["verdict"]
    assert v["rho_sl_low_snr_fig1"] == "differs" and v["rho_s_positive"] == "differs"
