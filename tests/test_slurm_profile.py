"""The Slurm profile submits every shard rule as a job array, and no other rule.

The list ``slurm-array-jobs`` in ``workflow/profiles/slurm/config.yaml`` names rules one by one; a
shard rule added to the workflow but not to the list would silently go back to one sbatch per
shard. The workflow's own rule list (``snakemake --list-rules``) decides which rules exist.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from yte import process_yaml

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "workflow/profiles/slurm/config.yaml"


def _profile() -> dict:
    with open(PROFILE) as f:
        return process_yaml(f)  # the way Snakemake reads a profile with __use_yte__


def _array_rules(profile: dict) -> list[str]:
    value = profile.get("slurm-array-jobs")
    assert isinstance(value, str) and value.strip(), f"no slurm-array-jobs list in {PROFILE}: {value!r}"
    # the plugin splits on ',' (and ';'), stripping blanks
    return [name.strip() for name in value.replace(";", ",").split(",") if name.strip()]


def _workflow_rules() -> set[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    out = subprocess.run([sys.executable, "-m", "snakemake", "--list-rules", "--configfile", "config/test.yaml"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    return {line.strip() for line in out.stdout.splitlines() if line.strip() and " " not in line.strip()}


@pytest.mark.slow  # the workflow's rule list comes from Snakemake
def test_array_list_names_exactly_the_shard_rules():
    rules = _workflow_rules()
    shard_rules = {name for name in rules if name.endswith("_shard")}
    assert len(shard_rules) >= 5, sorted(rules)  # the five sharded steps of issue 31 at least
    listed = _array_rules(_profile())
    assert len(listed) == len(set(listed)), f"a rule listed twice: {listed}"
    assert "all" not in listed, "the profile lists the shard rules by name (see its comment), not 'all'"
    assert set(listed) == shard_rules, (
        f"missing from slurm-array-jobs: {sorted(shard_rules - set(listed))}; "
        f"not shard rules of the workflow: {sorted(set(listed) - shard_rules)}")


def test_array_list_parse_checks_itself():
    # the parser above reads what the plugin reads: comma or semicolon separated, blanks ignored
    assert _array_rules({"slurm-array-jobs": " a_shard, b_shard;c_shard ,"}) == ["a_shard", "b_shard", "c_shard"]
    assert yaml.safe_load(PROFILE.read_text())["executor"] == "slurm"


@pytest.mark.slow  # the workflow's rule list comes from Snakemake
def test_every_sharded_step_has_a_shard_count_key_and_shards_in_the_test_configuration():
    # a shard rule whose step is missing from the schema's `shards` runs as one job whatever the
    # profile asks (the key is refused), and one the test configuration leaves at 1 shard is never
    # sent to Slurm as an array by tests/test_slurm.py
    steps = {name.removesuffix("_shard") for name in _workflow_rules() if name.endswith("_shard")}
    schema = yaml.safe_load((ROOT / "workflow/schemas/config.schema.yaml").read_text())
    keys = set(schema["properties"]["shards"]["properties"])
    assert keys == steps, f"steps without a shard key: {sorted(steps - keys)}; keys without a step: {sorted(keys - steps)}"
    test_shards = yaml.safe_load((ROOT / "config/test.yaml").read_text())["shards"]
    assert {step for step, count in test_shards.items() if count >= 2} == steps, test_shards
