"""A crippled solver yields `undecided`, never `differs` or `fails` (issue 37), through the whole workflow.

The fault is injected as a test would: ``NETREPRO_SOLVER_MAX_ITER`` caps Clarabel's iterations in every
solve (netrepro.engines.cvx). Every markov and gainsched job is rerun in a copy of the built scratch
repository; each claim and finding must read as before or ``undecided``, and the console must say so.
"""

import shutil

import pandas as pd
import pytest

from .conftest import run_snakemake

PAPERS = ("markov", "gainsched")
CAP = "3"


def verdicts(root, slug):
    out = {}
    for kind, ident, columns in (("claims", "claim_id", ("verdict",)),
                                 ("findings", "finding_id", ("verdict", "amended_verdict"))):
        frame = pd.read_csv(root / "results" / kind / f"{slug}.csv", dtype=str, keep_default_na=False)
        for column in columns:
            if column in frame:
                out |= {(kind, i, column): v for i, v in zip(frame[ident], frame[column]) if v}
    return out


@pytest.mark.slow
@pytest.mark.xdist_group("workflow")
def test_a_capped_solver_leaves_verdicts_as_before_or_undecided(built_repo, tmp_path):
    work = tmp_path / "repo"
    shutil.copytree(built_repo, work, symlinks=True)
    before = {slug: verdicts(work, slug) for slug in PAPERS}
    targets = [f"results/claims/{slug}.csv" for slug in PAPERS]
    proc = run_snakemake(work, "-j2", "--forceall", *targets, env={"NETREPRO_SOLVER_MAX_ITER": CAP})
    changed, wrong = [], []
    for slug in PAPERS:
        after = verdicts(work, slug)
        assert after.keys() == before[slug].keys(), slug
        for key, verdict in after.items():
            if verdict != before[slug][key]:
                changed.append((slug, *key, before[slug][key], verdict))
                if verdict != "undecided":
                    wrong.append(changed[-1])
    assert not wrong, f"verdicts that changed to something other than undecided: {wrong}"
    # the cap bites (else this test tests nothing), and the console names the undecided verdicts
    assert changed, "no verdict changed under a 3-iteration solver: the fault was not injected"
    console = proc.stdout + proc.stderr
    assert "verdicts undecided" in console
    for slug, kind, ident, *_ in changed:
        assert f"{slug}/{ident}" in console
    # the LMI steps record the solver's statuses in their provenance
    sidecars = [p.read_text() for p in (work / "results" / "markov").glob("*.meta.json")]
    assert any('"solver_statuses"' in text and '"user_limit"' in text for text in sidecars)
