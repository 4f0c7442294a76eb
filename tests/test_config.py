import copy
from pathlib import Path

import pytest
import yaml

from netrepro.pipeline.config import ConfigError, require_pd, validate_config

ROOT = Path(__file__).resolve().parents[1]


def load(name):
    return yaml.safe_load((ROOT / "config" / name).read_text())


def test_require_pd():
    require_pd("Q", [[2, 0], [0, 1]])
    with pytest.raises(ConfigError, match="positive definite"):
        require_pd("Q", [[1, 2], [2, 1]])
    with pytest.raises(ConfigError, match="symmetric"):
        require_pd("Q", [[1, 2], [0, 1]])


def test_load_yaml_gives_what_the_pure_python_parser_gives():
    """The fast loader (libyaml when present) against PyYAML's pure-Python safe loader with the same float
    resolver, on every data file; and against plain safe_load wherever no YAML 1.2 float is written."""
    from pathlib import Path

    import yaml

    from netrepro.pipeline.io import load_yaml, yaml_loader_class

    root = Path(__file__).resolve().parents[1]
    files = [*root.glob("src/**/*.yaml"), *root.glob("workflow/**/*.yaml"), *root.glob("config/*.yaml")]
    assert len(files) > 20
    pure = yaml_loader_class(yaml.SafeLoader)
    for path in files:
        text = path.read_text()
        assert repr(load_yaml(text)) == repr(yaml.load(text, Loader=pure)), path  # noqa: S506 (a safe loader)
    assert load_yaml("a: 1.0e12\nb: 5e-05\nc: 1.0e+12\nd: '1e5'\ne: 1e5x\nf: 12") == \
        {"a": 1e12, "b": 5e-05, "c": 1e12, "d": "1e5", "e": "1e5x", "f": 12}
    assert yaml.safe_load("a: 1.0e12")["a"] == "1.0e12"  # what YAML 1.1 alone would give


def test_shard_counts_are_validated_and_named():
    cfg = load("test.yaml")
    cfg["shards"]["hinf_loop_variants"] = 0
    with pytest.raises(ConfigError, match=r"shards\.hinf_loop_variants.*minimum of 1"):
        validate_config(cfg)
    cfg = load("test.yaml")
    cfg["shards"]["hinf_loop_variant"] = 3
    with pytest.raises(ConfigError, match=r"shards\.hinf_loop_variant' = 3 is not a known key"):
        validate_config(cfg)


def test_shard_count_in_a_paper_section_points_to_the_shards_section():
    cfg = load("test.yaml")
    cfg["intermittent"]["scalar"]["n_shards"] = 4
    with pytest.raises(ConfigError, match=r"intermittent\.scalar\.n_shards.*moved to the top-level section 'shards:'"):
        validate_config(cfg)


def test_command_line_shard_counts_become_integers():
    from netrepro.pipeline.config import coerce_shard_counts, shard_count

    # what `--config 'shards={a: 8, b: x}'` gives: YAML's base loader keeps scalars as strings
    cfg = coerce_shard_counts({"shards": {"onebit_estimator": "8", "hinf_kalman_best": "x"}})
    assert cfg["shards"] == {"onebit_estimator": 8, "hinf_kalman_best": "x"}
    assert shard_count(cfg, "onebit_estimator") == 8
    assert shard_count(cfg, "intermittent_monte_carlo") == 1  # not listed: one job
    with pytest.raises(ConfigError, match=r"shards\.hinf_kalman_best' = 'x'"):
        validate_config({**load("test.yaml"), "shards": cfg["shards"]})


def test_paper_scale_overlay_validates_and_changes_only_known_keys():
    from snakemake.utils import update_config

    base, overlay = load("config.yaml"), load("paper-scale.yaml")
    merged = copy.deepcopy(base)
    update_config(merged, overlay)  # what `--configfile config/config.yaml config/paper-scale.yaml` does
    validate_config(merged)
    assert "shards" not in overlay  # shard counts belong to profiles and the command line
    assert merged["onebit"]["estimator"]["one_minus_alpha"][0] == 1e-5  # Fig 1's alpha, the nominal case
    # every count the overlay raises is at least 10x the default's
    assert merged["hinf"]["paired"]["runs"] >= 10 * base["hinf"]["paired"]["runs"]
    assert merged["intermittent"]["scalar"]["n_paths"] >= 10 * base["intermittent"]["scalar"]["n_paths"]
    assert merged["markov"]["expectations"]["n_paths"] >= 10 * base["markov"]["expectations"]["n_paths"]
    assert merged["gainsched"]["simulation"]["n_runs"] >= 10 * base["gainsched"]["simulation"]["n_runs"]


def test_overlay_with_an_unknown_key_is_named():
    from snakemake.utils import update_config

    merged = load("config.yaml")
    update_config(merged, {"hinf": {"paired": {"runz": 2000}}})
    with pytest.raises(ConfigError, match=r"hinf\.paired\.runz' = 2000 is not a known key"):
        validate_config(merged)


def test_a_number_yaml_reads_as_text_is_named_with_its_fix():
    """`1.0e12` in a YAML 1.1 file is text (issue 38): the message says to write `1.0e+12`."""
    import copy as _copy
    from pathlib import Path

    import yaml

    from netrepro.pipeline.config import validate_config
    from netrepro.errors import ConfigError

    root = Path(__file__).resolve().parents[1]
    config = yaml.safe_load((root / "config" / "config.yaml").read_text())
    bad = _copy.deepcopy(config)
    bad["markov"]["checks"]["tight_tol"] = yaml.safe_load("x: 1.0e12")["x"]
    assert bad["markov"]["checks"]["tight_tol"] == "1.0e12"  # what YAML 1.1 gives (no sign in the exponent)
    with pytest.raises(ConfigError) as info:
        validate_config(bad, root / "workflow" / "schemas")
    assert "config key 'markov.checks.tight_tol' = '1.0e12'" in str(info.value)
    assert "write it as 1.0e+12, with a dot and a signed exponent" in str(info.value)
