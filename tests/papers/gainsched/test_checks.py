"""Configuration checks of the `gainsched` paper."""

from __future__ import annotations

import copy

import pytest

from netrepro.pipeline.config import ConfigError
from netrepro.papers.gainsched.checks import check_config


def test_check_config_accepts_and_rejects(cfg):
    check_config(cfg)
    bad = copy.deepcopy(cfg)
    bad["simulation"]["x0"] = [1.0, 2.0, 3.0]
    with pytest.raises(ConfigError, match="x0"):
        check_config(bad)
    bad = copy.deepcopy(cfg)
    bad["system"]["F2_diag"] = [0.1, 0.1]
    with pytest.raises(ConfigError, match="F2 - F1"):
        check_config(bad)
