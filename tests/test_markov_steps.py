"""Smoke test of the `markov` pipeline steps on a tiny configuration (tables written, claims well formed)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml

from netrepro.claims import CLAIM_COLUMNS, ERRATA_COLUMNS, RECONSTRUCTION_COLUMNS
from netrepro.papers import markov as M

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def cfg():
    section = yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["markov"]
    section["curves"].update(q_points=3, benchmark_solves=2)
    section["exact"]["depth"] = 9
    section["map"].update(p_points=4, q_points=4)
    section["paths"].update(horizon=12, n_paths=60, rb_paths=30, rb_horizon=10)
    section["paths"]["estimator_points"] = section["paths"]["estimator_points"][:1]
    M.check_config(section)
    return section


def _run(fn, params, inputs, outputs):
    result = fn(params, inputs, outputs) or {}
    result.pop("provenance", None)
    for name, frame in result.items():
        frame.to_csv(outputs[name], index=False)
    return result


def test_steps_end_to_end(cfg, tmp_path):
    t = {name: tmp_path / f"{name}.csv" for name in
         ("curves", "bench", "checks", "iid", "moments", "map", "paths", "check", "claims", "errata", "recon")}
    _run(M.critical_curves_step, cfg, {}, {"table": t["curves"], "benchmark": t["bench"]})
    _run(M.lmi_checks_step, cfg, {}, {"table": t["checks"]})
    _run(M.iid_line_step, cfg, {}, {"table": t["iid"]})
    _run(M.exact_moments_step, cfg, {}, {"table": t["moments"]})
    _run(M.stability_map_step, cfg, {"moments": t["moments"]}, {"table": t["map"]})
    _run(M.sample_paths_step, cfg, {"moments": t["moments"]}, {"table": t["paths"], "check": t["check"]})
    _run(M.claims_step, cfg, {"checks": t["checks"], "curves": t["curves"], "iid": t["iid"], "map": t["map"],
                              "moments": t["moments"]}, {"table": t["claims"]})
    _run(M.errata_step, cfg, {"checks": t["checks"]}, {"table": t["errata"]})
    _run(M.reconstructions_step, cfg, {}, {"table": t["recon"]})

    curves = pd.read_csv(t["curves"])
    for col in ("example", "q", "p_prop1", "p_thm5", "q_necessary", "p_thm5_uncapped"):
        assert col in curves
    assert (curves.p_thm5 <= 1).all() and (curves.thm5_n_uncertified == 0).all()
    smap = pd.read_csv(t["map"], keep_default_na=False)
    assert {"example", "p", "q", "bounded", "growth_rate", "method"} <= set(smap.columns)
    iid = pd.read_csv(t["iid"])
    assert {"example", "lambda_lower", "lambda_lmi_upper", "q_thm5_on_iid_line"} <= set(iid.columns)
    claims = pd.read_csv(t["claims"])
    assert list(claims.columns) == CLAIM_COLUMNS
    row = claims.set_index("claim_id").loc["exII_thm5_q05"]
    assert abs(float(row.reproduced_value) - 0.4645062) < 1e-5
    assert claims.set_index("claim_id").loc["exII_p0465_certified", "verdict"] == "erratum"
    assert list(pd.read_csv(t["errata"]).columns) == ERRATA_COLUMNS
    assert list(pd.read_csv(t["recon"]).columns) == RECONSTRUCTION_COLUMNS

    for fn, params, inputs, name in (
        (M.figure_plane, cfg, {"curves": t["curves"], "map": t["map"], "iid": t["iid"]}, "fig2"),
        (M.figure_path, {"figure": "fig3"}, {"paths": t["paths"]}, "fig3"),
        (M.figure_mean, {"figure": "fig6"}, {"paths": t["paths"]}, "fig6"),
        (M.figure_estimators, {}, {"check": t["check"]}, "figS1"),
        (M.figure_curves, cfg, {"curves": t["curves"]}, "figS2"),
    ):
        out = tmp_path / f"{name}.png"
        fn(params, inputs, {"figure": out})
        assert out.stat().st_size > 1000
