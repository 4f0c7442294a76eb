"""The per-paper step lists (issue 39): loader, schema and the rules the workflow generates from them."""

import json
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from netrepro.errors import ConfigError
from netrepro.pipeline.registry import paper_slugs
from netrepro.pipeline.stepspec import compose_config, config_keys, load_step_specs, step_list_path

ROOT = Path(__file__).resolve().parents[1]

GOOD = """
key_groups:
  system: [a, b]
wildcards:
  case: [one, two]
tables: [first, second.extra, merged]
steps:
  first:
    func: steps:first_step
    outputs: {table: results/demo/first.csv}
    config: [$system, c]
    threads: 1
    resources: {mem_mb: 500, runtime: 1}
  per_case:
    func: steps:first_step
    over: case
    narrow: cases
    wrap: cfg
    outputs: {table: "results/demo/{case}.csv"}
    config: [$system]
  second:
    func: steps:second_step
    inputs:
      first: first
      one: {step: per_case, output: table, value: one}
      all: {each: per_case}
      claims: data/claims.yaml
    outputs: {table: results/demo/second.csv, extra: results/demo/extra.csv}
    config: {from: sub, keys: [$system], merge: [whole, {from: other, keys: [x]}]}
    local: true
  merged:
    func: steps:second_step
    outputs: {table: results/demo/merged.csv}
    config: {fields: {sub: {from: sub, keys: [a]}, evidence: {from: evidence}}}
    shard:
      func: steps:first_step
      outputs: {sums: "results/demo/shards/merged_{shard}.npz"}
      config: [a]
  evidence:
    func: evidence:evidence_step
    inputs: {shards: {shards: merged}}
    outputs: {table: results/evidence/demo.csv}
"""


@pytest.fixture
def demo(tmp_path):
    """A package folder with one paper, ``demo``, its step functions and the steps schema."""
    src = tmp_path / "src/netrepro"
    pkg = src / "papers/demo"
    pkg.mkdir(parents=True)
    (pkg / "steps.py").write_text("def first_step(params, inputs, outputs):\n    pass\n\n\n"
                                  "def second_step(params, inputs, outputs):\n    pass\n")
    (pkg / "evidence.py").write_text("def evidence_step(params, inputs, outputs):\n    pass\n")
    (tmp_path / "data").mkdir()
    (tmp_path / "data/claims.yaml").write_text("[]\n")
    (src / "schemas").mkdir()
    shutil.copy(ROOT / "workflow/schemas/steps.schema.yaml", src / "schemas")
    return tmp_path, src


def _write(src: Path, text: str) -> Path:
    path = step_list_path("demo", src)
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def test_a_good_step_list_loads_in_order_with_groups_expanded(demo):
    root, src = demo
    _write(src, GOOD)
    paper = load_step_specs("demo", src, root=root)
    assert [s.name for s in paper.steps] == ["first", "per_case", "second", "merged", "evidence"]
    first = paper.step("first")
    assert first.rule == "demo_first" and first.log == "logs/demo/first.log"
    assert first.func == "netrepro.papers.demo.steps:first_step"
    assert first.config == ["a", "b", "c"] and first.threads == 1 and first.resources == {"mem_mb": 500, "runtime": 1}
    per_case = paper.step("per_case")
    assert per_case.log == "logs/demo/per_case_{case}.log" and paper.wildcards["case"] == ["one", "two"]
    merged = paper.step("merged")
    assert merged.shard_rule == "demo_merged_shard" and merged.shard_log == "logs/demo/merged_{shard}.log"
    assert merged.shard.func == "netrepro.papers.demo.steps:first_step"
    assert paper.step("second").local and paper.tables == ["first", "second.extra", "merged"]


def test_compose_config_picks_only_the_declared_keys(demo):
    root, src = demo
    _write(src, GOOD)
    paper = load_step_specs("demo", src, root=root)
    section = {"a": 1, "b": 2, "c": 3, "d": 4, "sub": {"a": 5, "b": 6, "z": 7}, "whole": {"w": 8},
               "other": {"x": 9, "y": 10}, "evidence": {"e": 11}}
    assert compose_config(section, paper.step("first").config) == {"a": 1, "b": 2, "c": 3}
    assert compose_config(section, paper.step("second").config) == {"a": 5, "b": 6, "w": 8, "x": 9}
    assert compose_config(section, paper.step("merged").config) == {"sub": {"a": 5}, "evidence": {"e": 11}}
    # an entry read whole is there even when the section lacks it (as SECTION.get("evidence", {}))
    assert compose_config({}, paper.step("merged").config) == {"sub": {}, "evidence": {}}
    assert ((), "sub") in config_keys(paper.step("second").config)
    assert (("other",), "x") in config_keys(paper.step("second").config)


BAD = [
    # (what to change in GOOD, the words the message must hold)
    (lambda t: t.replace("    threads: 1\n", "    threads: 1\n    colour: red\n", 1),
     ["step 'first'", "colour"]),
    (lambda t: t.replace("      first: first\n", "      first: nowhere\n"),
     ["step 'second'", "'nowhere'", "not declared above"]),
    (lambda t: t.replace("      first: first\n", "      first: first.missing\n"),
     ["step 'second'", "first.missing"]),
    (lambda t: t.replace("results/demo/merged.csv", "results/demo/first.csv"),
     ["step 'merged'", "results/demo/first.csv", "already an output of step 'first'"]),
    (lambda t: t.replace("func: steps:second_step\n    outputs: {table: results/demo/merged.csv}",
                         "func: steps:no_such_step\n    outputs: {table: results/demo/merged.csv}"),
     ["step 'merged'", "no function 'no_such_step'"]),
    (lambda t: t.replace("func: evidence:evidence_step", "func: nomodule:evidence_step"),
     ["step 'evidence'", "no module"]),
    (lambda t: t.replace("config: [$system, c]", "config: [$nogroup, c]"),
     ["step 'first'", "'$nogroup'", "key_groups"]),
    (lambda t: t.replace("over: case", "over: nowhere"),
     ["step 'per_case'", "'nowhere'", "wildcards"]),
    (lambda t: t.replace("value: one", "value: three"),
     ["step 'second'", "'three'"]),
    (lambda t: t.replace("claims: data/claims.yaml", "claims: data/none.yaml"),
     ["step 'second'", "data/none.yaml", "does not exist"]),
    (lambda t: t.replace("tables: [first, second.extra, merged]", "tables: [first, second.nothing]"),
     ["tables", "second.nothing"]),
    (lambda t: t.replace('outputs: {sums: "results/demo/shards/merged_{shard}.npz"}',
                         'outputs: {sums: "results/demo/shards/merged.npz"}'),
     ["step 'merged'", "{shard}"]),
]


@pytest.mark.parametrize("change, words", BAD)
def test_each_bad_step_list_is_refused_with_file_and_step(demo, change, words):
    root, src = demo
    path = _write(src, change(textwrap.dedent(GOOD).lstrip()))
    with pytest.raises(ConfigError) as err:
        load_step_specs("demo", src, root=root)
    message = str(err.value)
    assert str(path) in message, message
    for word in words:
        assert word in message, message


def test_a_missing_step_list_is_named(demo):
    _, src = demo
    with pytest.raises(ConfigError, match="has no step list"):
        load_step_specs("demo", src)


@pytest.mark.parametrize("slug", paper_slugs())
def test_every_paper_declares_its_steps_once(slug):
    paper = load_step_specs(slug, root=ROOT)
    rules = [s.rule for s in paper.steps] + [s.shard_rule for s in paper.steps if s.shard]
    assert len(rules) == len(set(rules))
    assert f"{slug}_evidence" in rules and paper.step("evidence").outputs["table"] == f"results/evidence/{slug}.csv"


def test_hinf_scenarios_are_declared_once_and_match_the_configuration():
    import yaml

    paper = load_step_specs("hinf", root=ROOT)
    for name in ("config/config.yaml", "config/test.yaml"):
        scenarios = yaml.safe_load((ROOT / name).read_text())["hinf"]["scenarios"]
        assert set(paper.wildcards["scenario"]) == set(scenarios), name
    assert "scenarios" in paper.key_groups["scenario"]


def _dry_run_jobs(config: str) -> dict:
    """``{rule: set of outputs}`` of every job of a forced dry run of the report in this checkout."""
    proc = subprocess.run([sys.executable, "-m", "snakemake", "--configfile", config, "-n", "-F", "--nolock",
                           "report"], cwd=ROOT, capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    jobs = {}
    for rule, outputs in re.findall(r"^(?:local)?rule (\w+):\n(?:    .*\n)*?    output: (.*)$", proc.stdout, re.M):
        jobs.setdefault(rule, set()).update(outputs.split(", "))
    return jobs


@pytest.mark.slow
def test_every_declared_step_yields_a_rule_with_its_outputs():
    jobs = _dry_run_jobs("config/config.yaml")
    for slug in paper_slugs():
        paper = load_step_specs(slug, root=ROOT)
        for spec in paper.steps:
            values = paper.wildcards.get(spec.over, [None])
            wanted = {path.format(**({spec.over: v} if v else {})) for path in spec.outputs.values() for v in values}
            assert jobs.get(spec.rule) == wanted, spec.rule
            if spec.shard:
                (path,) = spec.shard.outputs.values()
                assert jobs.get(spec.shard_rule) and all(re.fullmatch(path.replace("{shard}", r"\d+"), p)
                                                         for p in jobs[spec.shard_rule]), spec.shard_rule


@pytest.mark.slow
@pytest.mark.xdist_group("workflow")
def test_every_built_output_was_written_by_its_declared_function(built_repo):
    """The command a job ran (the output's sidecar) names the step's rule and function.

    Snakemake evaluates a rule's ``shell:`` again when the job runs, after the generating loop has
    moved on; a dry run shows the command of the definition only, so this reads what ran.
    """
    for slug in paper_slugs():
        paper = load_step_specs(slug, root=ROOT)
        for spec in paper.steps:
            pairs = [(spec.rule, spec.func, path) for path in spec.outputs.values()]
            if spec.shard:
                pairs += [(spec.shard_rule, spec.shard.func, path.replace("{shard}", "0"))
                          for path in spec.shard.outputs.values()]
            for rule, func, path in pairs:
                if spec.over:
                    path = path.format(**{spec.over: paper.wildcards[spec.over][0]})
                sidecar = built_repo / f"{path}.meta.json"
                command = json.loads(sidecar.read_text())["command"]
                assert f"--rule {rule} --func {func} " in command, (sidecar, command[:200])
