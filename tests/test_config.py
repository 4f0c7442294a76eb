import copy
from pathlib import Path

import pytest
import yaml

from netrepro.config import ConfigError, require_pd, validate_config

ROOT = Path(__file__).resolve().parents[1]


def load(name):
    return yaml.safe_load((ROOT / "config" / name).read_text())


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_shipped_configs_are_valid(name):
    validate_config(load(name))


@pytest.mark.parametrize(
    "path,value,fragment",
    [
        (("intermittent", "scalar", "R2"), -0.5, "intermittent.scalar.R2"),
        (("intermittent", "scalar", "a"), 0.5, "intermittent.scalar.a"),
        (("intermittent", "scalar", "horizon"), "sixty", "intermittent.scalar.horizon"),
        (("intermittent", "scalar", "seed"), -1, "intermittent.scalar.seed"),
        (("intermittent", "scalar", "exact_horizon"), 40, "intermittent.scalar.exact_horizon"),
        (("intermittent", "two_sensor", "sigma2"), [0.2], "intermittent.two_sensor.sigma2"),
        (("intermittent", "two_sensor", "check_lambda1"), 1.2, "intermittent.two_sensor.check_lambda1"),
        (("papers",), ["nonsense"], "papers"),
    ],
)
def test_bad_values_are_named(path, value, fragment):
    cfg = copy.deepcopy(load("test.yaml"))
    node = cfg
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ConfigError, match=fragment.replace(".", r"\.")):
        validate_config(cfg)


def test_unknown_key_rejected():
    cfg = load("test.yaml")
    cfg["intermittent"]["scalar"]["typo_key"] = 1
    with pytest.raises(ConfigError, match="typo_key"):
        validate_config(cfg)


def test_semantic_check_runs_after_schema():
    cfg = load("test.yaml")
    cfg["intermittent"]["scalar"]["exact_horizon"] = 20
    cfg["intermittent"]["scalar"]["horizon"] = 10
    with pytest.raises(ConfigError, match="must not exceed"):
        validate_config(cfg)


def test_require_pd():
    require_pd("Q", [[2, 0], [0, 1]])
    with pytest.raises(ConfigError, match="positive definite"):
        require_pd("Q", [[1, 2], [2, 1]])
    with pytest.raises(ConfigError, match="symmetric"):
        require_pd("Q", [[1, 2], [0, 1]])


def test_load_yaml_gives_what_the_pure_python_parser_gives():
    """The fast loader (libyaml when present) against PyYAML's own safe_load, on every data file."""
    from pathlib import Path

    import yaml

    from netrepro.io import load_yaml

    root = Path(__file__).resolve().parents[1]
    files = [*root.glob("src/**/*.yaml"), *root.glob("workflow/**/*.yaml"), *root.glob("config/*.yaml")]
    assert len(files) > 20
    for path in files:
        text = path.read_text()
        assert repr(load_yaml(text)) == repr(yaml.safe_load(text)), path
