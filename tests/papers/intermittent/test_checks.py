import pytest

from netrepro.errors import ConfigError
from netrepro.papers.intermittent.checks import check_config


def test_check_config_names_key():
    with pytest.raises(ConfigError, match="exact_horizon"):
        check_config({"scalar": dict(a=1.5, exact_horizon=30, horizon=10, lambda_offsets=[0.1])})
    with pytest.raises(ConfigError, match="lambda_offsets"):
        check_config({"scalar": dict(a=1.5, exact_horizon=3, horizon=10, lambda_offsets=[0.6])})


def test_check_config_names_the_new_keys():
    scalar = dict(a=1.5, exact_horizon=3, horizon=10, lambda_offsets=[0.1])
    with pytest.raises(ConfigError, match="sample_path_horizons"):
        check_config({"scalar": scalar, "evidence": {"sample_path_horizons": [1e9, 1e6]}})
    with pytest.raises(ConfigError, match="sample_path_horizons"):
        check_config({"scalar": scalar, "evidence": {"sample_path_horizons": [1.5]}})


def test_check_config_accepts_the_paper_setting():
    check_config({"scalar": dict(a=1.5, exact_horizon=18, horizon=60, lambda_offsets=[0.1, -0.1])})
