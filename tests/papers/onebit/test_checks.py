"""Tests of netrepro.papers.onebit.checks: each equation against an independent computation."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from netrepro.pipeline.config import ConfigError
from netrepro.papers.onebit import checks

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cfg():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["onebit"]


def test_check_config_rejects_bad_sections(cfg):
    checks.check_config(cfg)
    bad = copy.deepcopy(cfg)
    bad["estimator"]["snr_db"] = [0.0, -10.0]
    with pytest.raises(ConfigError, match="estimator.snr_db"):
        checks.check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["vector_check"]["Q"] = [[1.0, 2.0], [2.0, 1.0]]
    with pytest.raises(ConfigError, match="Q"):
        checks.check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["fig1_one_minus_alpha"] = 0.5
    with pytest.raises(ConfigError, match="fig1_one_minus_alpha"):
        checks.check_config(bad)


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_config_sections_validate(name):
    import jsonschema

    from netrepro.pipeline.config import load_schemas

    section = yaml.safe_load((ROOT / "config" / name).read_text())["onebit"]
    _, registry = load_schemas()
    schema = registry.get_or_retrieve("onebit.schema.yaml").value.contents
    jsonschema.Draft202012Validator(schema).validate(section)
    checks.check_config(section)


def test_schema_requires_five_time_constants_before_the_window(cfg):
    import jsonschema

    from netrepro.pipeline.config import load_schemas

    _, registry = load_schemas()
    schema = registry.get_or_retrieve("onebit.schema.yaml").value.contents
    bad = copy.deepcopy(cfg)
    bad["estimator"]["burn_in_taus"] = 4.0
    with pytest.raises(jsonschema.ValidationError, match="burn_in_taus|4.0"):
        jsonschema.Draft202012Validator(schema).validate(bad)


def test_crossing_snrs_must_allow_a_local_fit():
    check_config = checks.check_config
    root = Path(__file__).resolve().parents[3]
    cfg = yaml.safe_load((root / "config" / "config.yaml").read_text())["onebit"]
    check_config(cfg)
    bad = copy.deepcopy(cfg)
    bad["estimator"]["crossing"]["snr_db"] = [1.0, 2.0]
    with pytest.raises(ConfigError, match="more than degree"):
        check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["estimator"]["crossing"]["one_minus_alpha"] = [0.5]
    with pytest.raises(ConfigError, match="not in onebit.estimator.one_minus_alpha"):
        check_config(bad)
