"""A configuration key read by one step reruns that step and its dependents only (issue 39, item 2).

Each rule's params carry only the configuration keys its step reads (``pick(SECTION, ...)``; check-paper's
``whole-section`` check), so an edit of a key that one step reads plans exactly that step and what depends
on it. For each paper, on the built test workflow (the session fixture ``built_repo``): the dry-run job set
after editing such a key equals the job set of ``--forcerun <rule>`` on the unchanged configuration.
Dry runs only: nothing is rebuilt.
"""

import re

import pytest
import yaml

from netrepro.pipeline.registry import paper_slugs

from .conftest import run_snakemake

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]

# paper -> (a key of its section in config/test.yaml read by one step only, that step's rule)
ONE_STEP_KEYS = {
    "intermittent": (("heavy_tail", "horizon"), "intermittent_heavy_tail"),
    "onebit": (("efq_grid_db", "stop"), "onebit_efq"),
    "gainsched": (("timing", "seed"), "gainsched_timing"),
    "hinf": (("noise_check", "seed"), "hinf_noise_model"),
    "markov": (("errata_seed",), "markov_evidence"),
}


def jobs_planned(workdir, *args):
    """Rule names a dry run of ``report`` would execute (the job table's rows)."""
    out = run_snakemake(workdir, "-n", "report", *args).stdout
    return {m.group(1) for line in out.splitlines() if (m := re.match(r"^(\w+)\s+\d+$", line.strip()))
            and m.group(1) not in ("total", "job")}


@pytest.fixture(scope="module")
def built(built_repo):
    assert jobs_planned(built_repo) == set(), "the built test workflow is not up to date"
    return built_repo


def test_every_paper_has_a_one_step_key():
    assert set(ONE_STEP_KEYS) == set(paper_slugs())


@pytest.mark.parametrize("slug", sorted(ONE_STEP_KEYS))
def test_a_key_read_by_one_step_reruns_that_step_and_its_dependents_only(built, slug):
    path, rule = ONE_STEP_KEYS[slug]
    expected = jobs_planned(built, "--forcerun", rule)  # the step and everything downstream of it
    assert rule in expected and "report" in expected, expected
    cfg_path = built / "config/test.yaml"
    original = cfg_path.read_text()
    cfg = yaml.safe_load(original)
    node = cfg[slug]
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] += 1
    cfg_path.write_text(yaml.safe_dump(cfg))
    try:
        planned = jobs_planned(built)
    finally:  # the later tests see the built repository as it was
        cfg_path.write_text(original)
    assert planned == expected, (f"{slug}.{'.'.join(path)}: planned beyond {rule} and its dependents: "
                                 f"{sorted(planned - expected)}; not planned: {sorted(expected - planned)}")
