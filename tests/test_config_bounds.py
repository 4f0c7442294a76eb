"""Bounds on every value that decides (issue 38 item 3).

Every number of a paper schema whose name marks it as a tolerance, threshold, margin, significance
level or band (the patterns below) has a lower and an upper bound and a description giving the range
and its reason: ``gainsched.sensitivity.tol: 1000`` had no maximum, exited 0 and flipped a finding.
"""

import copy
import re
from pathlib import Path

import pytest
import yaml

from netrepro.pipeline.config import ConfigError, validate_config

ROOT = Path(__file__).resolve().parents[1]
SCHEMAS = ROOT / "workflow" / "schemas"
PAPERS = ("intermittent", "markov", "onebit", "gainsched", "hinf")

# Decision keys, matched against the dotted key path inside a paper's section (last part: the key's name).
DECISION_PATTERNS = (
    r"(^|\.)[a-z0-9_]*tol[a-z0-9_]*$",      # tol, rtol, atol, bisection_tol, tight_tol_variants, lag_tol_db, ...
    r"(^|\.)[a-z0-9_]*threshold[a-z0-9_]*$",  # settle_threshold
    r"(^|\.)[a-z0-9_]*margin[a-z0-9_]*$",   # q_margin, rho_margin, growth_margin, margin_cap
    r"(^|\.)eps$",                          # strictness margin of LMIs, p = 1 - eps
    r"(^|\.)tests\.alpha$",                 # significance level (hinf.noise.alpha is a variance ratio, not a level)
    r"(^|\.)[a-z0-9_]*level$",              # sample_path_level
    r"(^|\.)[a-z0-9_]*signific[a-z0-9_]*$",  # z_significant
    r"(^|\.)(z_[a-z0-9_]*|interval_z)$",   # z_max, z_significant, interval_z (not points_per_sigma_z)
    r"(^|\.)band[a-z0-9_]*$",               # band, band_sigmas
    r"(^|\.)settle_[a-z0-9_]*$",            # settle_readings, settle_variants
    r"(^|\.)far$",                          # markov.map.far
    r"(^|\.)cost_(span|resolution)$",       # gainsched.scheduling
    r"(^|\.)pilot_factor$",                 # markov.map.refine
)
LOWER = ("minimum", "exclusiveMinimum")
UPPER = ("maximum", "exclusiveMaximum")


def _resolve(schema, root):
    while isinstance(schema, dict) and str(schema.get("$ref", "")).startswith("#/$defs/"):
        extra = {k: v for k, v in schema.items() if k != "$ref"}
        schema = {**root["$defs"][schema["$ref"].split("/")[-1]], **extra}
    return schema if isinstance(schema, dict) else {}


def number_keys(schema, root=None, prefix=""):
    """``(dotted key, key schema, number schema)`` of every number (or list of numbers) of ``schema``."""
    root = schema if root is None else root
    schema = _resolve(schema, root)
    children = dict(schema.get("properties") or {})
    if isinstance(schema.get("additionalProperties"), dict):
        children["*"] = schema["additionalProperties"]
    for name, sub in children.items():
        key = f"{prefix}.{name}" if prefix else name
        sub = _resolve(sub, root)
        if sub.get("type") in ("number", "integer"):
            yield key, sub, sub
        elif sub.get("type") == "array":
            items = _resolve(sub.get("items", {}), root)
            if items.get("type") in ("number", "integer"):
                yield key, sub, items
            elif items.get("type") == "object" or "properties" in items:
                yield from number_keys(items, root, f"{key}[]")
        if sub.get("type") == "object" or "properties" in sub or isinstance(sub.get("additionalProperties"), dict):
            yield from number_keys(sub, root, key)


def is_decision_key(key: str) -> bool:
    return any(re.search(p, key) for p in DECISION_PATTERNS)


def unbounded_decision_keys(schema) -> list[str]:
    """Decision keys of ``schema`` lacking a lower bound, an upper bound or a description."""
    problems = []
    for key, outer, number in number_keys(schema):
        if not is_decision_key(key):
            continue
        if not any(b in number for b in LOWER):
            problems.append(f"{key}: no lower bound")
        if not any(b in number for b in UPPER):
            problems.append(f"{key}: no upper bound")
        if not str(outer.get("description") or number.get("description") or "").strip():
            problems.append(f"{key}: no description (the range and its reason)")
    return problems


def schema(slug):
    return yaml.safe_load((SCHEMAS / f"{slug}.schema.yaml").read_text())


def load(name):
    return yaml.safe_load((ROOT / "config" / name).read_text())


# ----------------------------------------------------------------------------- 1. every decision key is bounded
@pytest.mark.parametrize("slug", PAPERS)
def test_every_decision_key_has_both_bounds_and_a_reason(slug):
    doc = schema(slug)
    found = [key for key, _, _ in number_keys(doc) if is_decision_key(key)]
    assert found, f"no decision key found in {slug}.schema.yaml: the patterns no longer match anything"
    assert unbounded_decision_keys(doc) == []


def test_the_keys_bounded_for_issue_38_are_all_matched():
    keys = {slug: {k for k, _, _ in number_keys(schema(slug)) if is_decision_key(k)} for slug in PAPERS}
    expected = {
        "intermittent": {"two_sensor.bisection_tol", "evidence.settle_readings", "evidence.sample_path_level",
                         "evidence.growth_ratio_rtol"},
        "markov": {"curves.q_margin", "curves.bisection_tol", "checks.eps", "checks.tight_tol",
                   "checks.tight_tol_variants", "iid.tol", "estimator.interval_z", "estimator.deterministic_rtol",
                   "prop2.rtol", "expectations.z_max", "expectations.rel_tol", "map.bounded_tol",
                   "map.unbounded_tol", "map.far", "map.certify.rho_margin", "map.certify.growth_margin",
                   "map.sensitivity.rho_margin", "map.sensitivity.growth_margin", "map.sensitivity.bounded_tol",
                   "map.sensitivity.unbounded_tol", "map.sensitivity.rel_tol", "map.sensitivity.refine_bounded_tol",
                   "map.sensitivity.refine_unbounded_tol", "map.refine.rel_tol", "map.refine.bounded_tol",
                   "map.refine.unbounded_tol", "map.refine.pilot_factor"},
        "onebit": {"lag_tol_db", "convergence.rtol", "estimator.band_sigmas", "evidence.lag_tol_db",
                   "evidence.flat_tol_db"},
        "gainsched": {"lmi.eps", "lmi.margin_cap", "simulation.band", "sensitivity.tol", "scheduling.cost_span",
                      "scheduling.cost_resolution"},
        "hinf": {"output.band", "claims.settle_threshold", "claims.settle_variants", "claims.z_significant",
                 "tests.alpha"},
    }
    for slug in PAPERS:
        assert expected[slug] <= keys[slug], (slug, sorted(expected[slug] - keys[slug]))
    assert "noise.alpha" not in keys["hinf"]  # a variance ratio of the noise model, not a level


def test_the_check_reports_a_missing_bound():
    """The check can fail: a synthetic schema with unbounded decision keys is reported, key by key."""
    synthetic = {
        "type": "object",
        "$defs": {"pos": {"type": "number", "exclusiveMinimum": 0}},
        "properties": {
            "sensitivity": {"type": "object", "properties": {
                "tol": {"type": "number", "exclusiveMinimum": 0, "description": "bisection tolerance"},
                "n_runs": {"type": "integer", "minimum": 1},  # not a decision key: not reported
            }},
            "claims": {"type": "object", "properties": {
                "settle_variants": {"type": "array", "items": {"type": "number", "maximum": 1},
                                    "description": "levels"},
                "z_significant": {"$ref": "#/$defs/pos"},
                "rho_margin": {"type": "number", "minimum": 0, "maximum": 0.5, "description": "ok"},
            }},
        },
    }
    assert unbounded_decision_keys(synthetic) == [
        "sensitivity.tol: no upper bound",
        "claims.settle_variants: no lower bound",
        "claims.z_significant: no upper bound",
        "claims.z_significant: no description (the range and its reason)",
    ]
    synthetic["properties"]["sensitivity"]["properties"]["tol"]["maximum"] = 1
    assert "sensitivity.tol: no upper bound" not in unbounded_decision_keys(synthetic)


# ----------------------------------------------------------------------------- 2. offending values are refused
# (path in config/config.yaml, out-of-range value): at least one per paper
OFFENDING = [
    (("gainsched", "sensitivity", "tol"), 1000),
    (("gainsched", "lmi", "margin_cap"), 5.0),
    (("intermittent", "evidence", "sample_path_level"), 1.0e12),
    (("intermittent", "evidence", "growth_ratio_rtol"), 0.3),
    (("markov", "map", "sensitivity", "rho_margin"), [0.0, 0.9]),
    (("markov", "checks", "tight_tol"), 1.0e-3),
    (("onebit", "lag_tol_db"), 3.0),
    (("onebit", "convergence", "rtol"), 0.5),
    (("hinf", "claims", "z_significant"), 20.0),
    (("hinf", "tests", "alpha"), 0.9),
    (("hinf", "claims", "settle_threshold"), 0.0),
]


@pytest.mark.parametrize("path,value", OFFENDING, ids=[".".join(p) for p, _ in OFFENDING])
def test_out_of_range_decision_value_is_refused_and_named(path, value):
    cfg = load("config.yaml")
    node = cfg
    for key in path[:-1]:
        node = node[key]
    assert node[path[-1]] != value  # the configured value is valid (test below); this one is not
    node[path[-1]] = copy.deepcopy(value)
    with pytest.raises(ConfigError) as info:
        validate_config(cfg)
    msg = str(info.value)
    key = ".".join(path)
    lines = [line for line in msg.splitlines() if f"config key '{key}" in line]
    assert lines, f"{key} not named in:\n{msg}"
    assert "Expected:" in lines[0] and ("in (" in lines[0] or "in [" in lines[0]), lines[0]


def test_gainsched_sensitivity_tol_1000_names_its_range():
    cfg = load("config.yaml")
    cfg["gainsched"]["sensitivity"]["tol"] = 1000
    with pytest.raises(ConfigError, match=r"config key 'gainsched\.sensitivity\.tol' = 1000 is invalid: .*"
                                          r"maximum of 1.*in \(0, 1\]"):
        validate_config(cfg)


# ----------------------------------------------------------------------------- 3. the shipped configurations
def test_shipped_configurations_still_validate():
    from snakemake.utils import update_config

    validate_config(load("config.yaml"))
    validate_config(load("test.yaml"))
    merged = load("config.yaml")
    update_config(merged, load("paper-scale.yaml"))  # `--configfile config/config.yaml config/paper-scale.yaml`
    validate_config(merged)
