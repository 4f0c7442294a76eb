"""Configuration checks of the `hinf` section: bad configurations rejected with a message naming the key."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from netrepro.errors import ConfigError
from netrepro.papers.hinf.checks import check_config

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def section():
    return yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["hinf"]


def test_test_config_passes(section):
    check_config(section)


def test_bad_layout_named(section):
    bad = copy.deepcopy(section)
    bad["scenarios"]["fig2"]["layout"] = "nowhere"
    with pytest.raises(ConfigError, match="hinf.scenarios.fig2.layout"):
        check_config(bad)


def test_indefinite_Q_named(section):
    bad = copy.deepcopy(section)
    bad["filter"]["Q"] = [[1.0, 0.0], [0.0, -1.0]]
    with pytest.raises(ConfigError, match="hinf.filter.Q"):
        check_config(bad)


def test_driver_must_be_a_decentralized_filter(section):
    bad = copy.deepcopy(section)
    bad["scenarios"]["static_mobile"]["driver"] = "local"
    with pytest.raises(ConfigError, match="hinf.scenarios.static_mobile.driver"):
        check_config(bad)


def test_consensus_check_layout_named(section):
    bad = copy.deepcopy(section)
    bad["consensus_check"]["layout"] = "nowhere"
    with pytest.raises(ConfigError, match="hinf.consensus_check.layout"):
        check_config(bad)
