"""All `markov` steps run once on a tiny configuration; the tables are shared by the step, evidence and figure tests."""

from __future__ import annotations

from pathlib import Path

import yaml

from netrepro.papers.markov import checks, evidence, steps

__all__ = ["tiny_config", "run_all", "NAMES"]

ROOT = Path(__file__).resolve().parents[3]
PKG = ROOT / "src" / "netrepro" / "papers" / "markov"
NAMES = ("curves", "bench", "checks", "tight", "iid", "moments", "map", "sensitivity", "paths", "check", "evidence",
         "expectations", "holdout")


def tiny_config() -> dict:
    """The test configuration, shrunk further (3 q points, depth 9, 4 x 4 map, short paths)."""
    section = yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["markov"]
    section["curves"].update(q_points=3, benchmark_solves=2)
    section["exact"]["depth"] = 9
    section["map"].update(p_points=4, q_points=4)
    section["paths"].update(horizon=12, n_paths=60, rb_paths=30, rb_horizon=10)
    section["paths"]["estimator_points"] = section["paths"]["estimator_points"][:1]
    checks.check_config(section)
    return section


def _run(fn, params, inputs, outputs):
    result = fn(params, inputs, outputs) or {}
    result.pop("provenance", None)
    for name, frame in result.items():
        frame.to_csv(outputs[name], index=False)
    return result


def run_all(cfg: dict, tmp: Path) -> dict:
    """Run every compute step and the evidence step; return ``{name: path}``."""
    t = {name: tmp / f"{name}.csv" for name in NAMES}
    _run(steps.critical_curves_step, cfg, {}, {"table": t["curves"], "benchmark": t["bench"]})
    _run(steps.lmi_checks_step, cfg, {}, {"table": t["checks"]})
    _run(steps.tight_variants_step, cfg, {}, {"table": t["tight"]})
    _run(steps.iid_line_step, cfg, {}, {"table": t["iid"]})
    _run(steps.exact_moments_step, cfg, {}, {"table": t["moments"]})
    _run(steps.stability_map_step, cfg, {"moments": t["moments"]}, {"table": t["map"], "sensitivity": t["sensitivity"]})
    _run(steps.sample_paths_step, cfg, {"moments": t["moments"]}, {"table": t["paths"], "check": t["check"]})
    _run(steps.expectations_step, cfg, {"moments": t["moments"]}, {"table": t["expectations"]})
    _run(steps.asymptote_holdout_step, cfg, {"expectations": t["expectations"]}, {"table": t["holdout"]})
    _run(evidence.evidence_step, cfg, {"checks": t["checks"], "tight": t["tight"], "curves": t["curves"], "iid": t["iid"],
                                       "map": t["map"], "sensitivity": t["sensitivity"], "moments": t["moments"],
                                       "holdout": t["holdout"],
                                       "claims": PKG / "claims.yaml", "findings": PKG / "findings.yaml"},
         {"table": t["evidence"]})
    return t
