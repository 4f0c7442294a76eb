"""A sixth paper in an afternoon (issue 30): ``new-paper``, a worked example filled in, a report.

The worked example is the scalar Kalman filter with i.i.d. packet losses (Sinopoli et al. 2004):
its critical arrival probability 1 - 1/a^2 and the fixed point of its modified Riccati equation
are known in closed form. On a scratch copy of the built repository the test scaffolds the paper,
fills in one equation, one step, one figure and two claims (one ``reproduced``, one ``differs``
against a planted wrong paper value), and runs the workflow; then it checks the report, the
scorecard and the RO-Crate, and that edits rerun only what they should.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from netrepro.judging.contract import check_paper

from .conftest import run_snakemake

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]

SLUG = "kalman_iid"
TITLE = "Kalman Filtering with Intermittent Observations (scalar, i.i.d. losses)"

MODEL = '''
"""The scalar Kalman filter with i.i.d. packet losses: critical probability and modified Riccati fixed point."""

from __future__ import annotations

import numpy as np

from ...errors import InputError

__all__ = ["critical_arrival_probability", "mare_fixed_point"]


def critical_arrival_probability(a):
    r"""Critical arrival probability of the scalar filter, Sinopoli et al. (2004), Theorem 5 for c != 0.

    .. math:: \\lambda_c = 1 - 1/a^2 \\quad (|a| > 1), \\qquad 0 \\quad (|a| \\le 1)

    Parameters
    ----------
    a : float
        The system gain.

    Returns
    -------
    float
        The arrival probability below which the expected error covariance diverges.
    """
    return max(0.0, 1.0 - 1.0 / float(a) ** 2)


def mare_fixed_point(a, c, q, r, lam):
    r"""Fixed point of the scalar modified algebraic Riccati equation, equation (MARE).

    .. math:: P = a^2 P + q - \\lambda \\frac{a^2 c^2 P^2}{c^2 P + r}

    which, times (c^2 P + r), is the quadratic alpha P^2 + beta P + gamma = 0 with
    alpha = c^2 (a^2 (1 - lambda) - 1), beta = r (a^2 - 1) + q c^2, gamma = q r.

    Parameters
    ----------
    a, c, q, r : float
        Gain, output gain, process and measurement noise variances (q, r > 0, c != 0).
    lam : array_like
        Arrival probabilities, each above the critical one.

    Returns
    -------
    numpy.ndarray
        The positive root for each lambda.

    Raises
    ------
    InputError
        If some lambda is not above the critical probability (no fixed point exists).
    """
    lam = np.asarray(lam, dtype=float)
    if np.any(lam <= critical_arrival_probability(a)):
        raise InputError("mare_fixed_point: every lambda must exceed 1 - 1/a^2")
    alpha = c**2 * (a**2 * (1.0 - lam) - 1.0)
    beta = r * (a**2 - 1.0) + q * c**2
    gamma = q * r
    return (-beta - np.sqrt(beta**2 - 4.0 * alpha * gamma)) / (2.0 * alpha)
'''

STEPS = '''
"""Pipeline steps of kalman_iid."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .model import critical_arrival_probability, mare_fixed_point

__all__ = ["fixed_point_curve_step"]


def fixed_point_curve_step(params, inputs, outputs):
    """Step of rule ``kalman_iid_fixed_point_curve``: the MARE fixed point over lambda in (lambda_c, 1]."""
    s = params["system"]
    lam_c = critical_arrival_probability(s["a"])
    lam = np.linspace(lam_c, 1.0, params["curve"]["n_points"] + 1)[1:]
    return {"table": pd.DataFrame({"lam": lam, "P": mare_fixed_point(s["a"], s["c"], s["q"], s["r"], lam)})}
'''

EVIDENCE = '''
"""Our side of the claims of kalman_iid: named quantities (assembly only)."""

from __future__ import annotations

import pandas as pd

from ...judging.paperdata import load_paper_data
from ...judging.verdicts import evidence_frame
from .model import critical_arrival_probability, mare_fixed_point

__all__ = ["evidence_step"]


def evidence_step(params, inputs, outputs):
    """Step of rule ``kalman_iid_evidence``: ``results/evidence/kalman_iid.csv``."""
    at = {c.claim_id: c.at for c in load_paper_data("kalman_iid", inputs["claims_file"].parent).claims}
    s = params["system"]
    curve = pd.read_csv(inputs["curve"])
    fp = at["fixed_point"]
    rows = [
        {"quantity": "lambda_c", "variant": "nominal", "value": critical_arrival_probability(at["lambda_c"]["a"])},
        {"quantity": "fixed_point", "variant": "nominal",
         "value": float(mare_fixed_point(fp["a"], s["c"], s["q"], s["r"], fp["lam"]))},
        {"quantity": "diverges_at_lambda_c", "variant": "nominal",
         "value": bool(curve["P"].iloc[0] > 100 * curve["P"].iloc[-1]),
         "note": f"P just above lambda_c over P at lambda = 1: {curve['P'].iloc[0] / curve['P'].iloc[-1]:.4g}"},
    ]
    return {"table": evidence_frame(rows)}
'''

FIGURES = '''
"""Figures of kalman_iid (plotting only)."""

from __future__ import annotations

import pandas as pd

from ...figures.plotting import new_figure, save_figure

__all__ = ["figure_fixed_point"]


def figure_fixed_point(params, inputs, outputs):
    """Fig. 1: the MARE fixed point against the arrival probability."""
    curve = pd.read_csv(inputs["curve"])
    fig, ax = new_figure(1, 1, figsize=(5.0, 3.6))
    ax.semilogy(curve["lam"], curve["P"], color="tab:blue", lw=2, label="MARE fixed point")
    ax.set_xlabel("arrival probability lambda")
    ax.set_ylabel("P")
    ax.legend()
    save_figure(fig, outputs["figure"])
    return {}
'''

FIGURES_YAML = '''
fig1:
  plot: figure_fixed_point
  inputs: {curve: fixed_point_curve}
  layout:
    from_paper: "the fixed point of the modified Riccati equation against lambda"
    ours: "log y axis; lambda from just above lambda_c to 1"
'''

CLAIMS = '''
- id: lambda_c
  location: {theorem: 5}
  group: Critical probability
  statement: "for a = 1.5 the critical arrival probability is 0.5556"
  kind: numeric
  paper_value: 0.5556
  tolerance: {value: 5.0e-5, reason: "four printed decimals: half a unit in the last place"}
  ours: {quantity: lambda_c}
  at: {a: 1.5}
- id: fixed_point
  location: {section: 5}
  group: Fixed point
  statement: "at lambda = 0.8 the expected error covariance settles at 3.9 (PLANTED wrong value)"
  kind: numeric
  paper_value: 3.9
  tolerance: {value: 0.05, reason: "two printed digits: half a unit in the last place"}
  ours: {quantity: fixed_point}
  at: {a: 1.5, lam: 0.8}
'''

FINDINGS = '''
- id: F1_divergence_at_lambda_c
  statement: "the fixed point grows without bound as lambda decreases to lambda_c"
  kind: boolean
  asserted: true
  rule: {reason: "true when P just above lambda_c exceeds 100 times P at lambda = 1 (two orders of magnitude)"}
  quantity: diverges_at_lambda_c
  evidence_quantities: [diverges_at_lambda_c]
  depends_on: []
  prior_work: "Sinopoli et al. 2004, IEEE TAC 49(9), Theorem 2"
  known: true
  table: results/kalman_iid/fixed_point_curve.csv
  figure: fig1
'''

STEP_LIST = '''
tables: [fixed_point_curve, evidence]
steps:
  fixed_point_curve:
    func: steps:fixed_point_curve_step
    outputs:
      table: results/kalman_iid/fixed_point_curve.csv
    config: [system, curve]
    local: true
  evidence:
    func: evidence:evidence_step
    inputs:
      curve: fixed_point_curve
      claims_file: src/netrepro/papers/kalman_iid/claims.yaml
    outputs:
      table: results/evidence/kalman_iid.csv
    config: [system]
    local: true
'''

SCHEMA = '''
$schema: "https://json-schema.org/draft/2020-12/schema"
description: Configuration of the kalman_iid worked example.
type: object
required: [system, curve]
additionalProperties: false
properties:
  system:
    type: object
    additionalProperties: false
    required: [a, c, q, r]
    properties:
      a: {type: number}
      c: {type: number}
      q: {type: number, exclusiveMinimum: 0}
      r: {type: number, exclusiveMinimum: 0}
  curve:
    type: object
    additionalProperties: false
    required: [n_points]
    properties:
      n_points: {type: integer, minimum: 2}
'''

SECTION = "kalman_iid:\n  system: {a: 1.5, c: 1.0, q: 1.0, r: 1.0}\n  curve: {n_points: 40}\n"

TEST_MODEL = '''
import numpy as np

from netrepro.papers.kalman_iid.model import critical_arrival_probability, mare_fixed_point


def test_fixed_point_is_where_the_recursion_settles():
    a, c, q, r, lam = 1.5, 1.0, 1.0, 1.0, 0.8
    p = 1.0
    for _ in range(5000):
        p = a**2 * p + q - lam * a**2 * c**2 * p**2 / (c**2 * p + r)
    np.testing.assert_allclose(mare_fixed_point(a, c, q, r, lam), p, rtol=1e-10)


def test_critical_probability_of_a_stable_system_is_zero():
    assert critical_arrival_probability(0.5) == 0.0
'''


def _fill_in(work: Path) -> None:
    """What the author writes after ``new-paper``: one equation, one step, one figure, two claims."""
    pkg = work / "src/netrepro/papers" / SLUG
    for name, text in {"model.py": MODEL, "steps.py": STEPS, "evidence.py": EVIDENCE, "figures.py": FIGURES,
                       "figures.yaml": FIGURES_YAML, "claims.yaml": CLAIMS, "findings.yaml": FINDINGS,
                       "errata.yaml": "[]\n", "reconstructions.yaml": "[]\n", "steps.yaml": STEP_LIST}.items():
        (pkg / name).write_text(textwrap.dedent(text).lstrip())
    (work / "workflow/schemas" / f"{SLUG}.schema.yaml").write_text(textwrap.dedent(SCHEMA).lstrip())
    tests = work / "tests/papers" / SLUG
    for old in tests.glob("test_*.py"):
        old.unlink()
    (tests / "test_model.py").write_text(textwrap.dedent(TEST_MODEL).lstrip())
    for cfg in ("config/config.yaml", "config/test.yaml"):
        path = work / cfg
        text = path.read_text()
        path.write_text(text[:text.index(f"\n{SLUG}:")] + "\n" + SECTION)


def _planned(work: Path) -> dict:
    """``{rule: jobs}`` of a dry run of the report on the test configuration."""
    out = run_snakemake(work, "-n", "report").stdout
    table = dict(re.findall(r"^(\w+)\s+(\d+)\s*$", out, re.MULTILINE))
    table.pop("total", None)
    table.pop("job", None)
    return {rule: int(n) for rule, n in table.items()}


@pytest.fixture(scope="module")
def sixth(built_repo, tmp_path_factory):
    """The built repository with the worked example added and built."""
    work = tmp_path_factory.mktemp("sixth") / "repo"
    shutil.copytree(built_repo, work, symlinks=True)
    source = work / "kalman_iid.txt"
    source.write_text("Kalman filtering with intermittent observations: the scalar case.\n")
    env_src = {"PYTHONPATH": str(work / "src")}
    new = subprocess.run([sys.executable, "-m", "netrepro", "new-paper", SLUG, "--title", TITLE,
                          "--source", str(source)], cwd=work, capture_output=True, text=True,
                         env={**os.environ, **env_src}, check=False)
    assert new.returncode == 0, new.stdout + new.stderr
    _fill_in(work)
    # the finding's rule is registered before its first run, as docs/adding-a-paper.md says
    reg = subprocess.run([sys.executable, "-m", "netrepro", "register-findings", SLUG], cwd=work, capture_output=True,
                         text=True, env={**os.environ, **env_src}, check=False)
    assert reg.returncode == 0 and f"{SLUG}: registered F1_divergence_at_lambda_c" in reg.stdout, reg.stdout + reg.stderr
    assert "F1_example_variance_grows" not in (work / "src/netrepro/papers" / SLUG / "findings.lock").read_text()
    planned_before_build = _planned(work)
    run_snakemake(work, "-j2", "report")
    return work, planned_before_build


def test_adding_a_paper_reruns_nothing_of_the_others(sixth):
    _, planned = sixth
    assert planned, "the new paper planned no jobs"
    # the report and the comparison with the recorded paper-scale run read every paper's claims
    cross_paper = {"report", "scale_verdicts", "report_sources"}  # report_sources: the new code's pages
    others = {rule for rule in planned if rule not in cross_paper and not rule.startswith(f"{SLUG}_")}
    assert not others, f"adding {SLUG} reruns rules of other papers: {sorted(others)}"
    assert {f"{SLUG}_fixed_point_curve", f"{SLUG}_evidence", f"{SLUG}_claims", f"{SLUG}_fig1",
            f"{SLUG}_notebook", "report"} <= set(planned)


def test_the_new_paper_has_both_verdicts_in_its_tables_and_report(sixth):
    work, _ = sixth
    claims = pd.read_csv(work / "results/claims" / f"{SLUG}.csv").set_index("claim_id")
    assert claims.loc["lambda_c", "verdict"] == "reproduced"
    assert claims.loc["fixed_point", "verdict"] == "differs"
    assert abs(claims.loc["fixed_point", "reproduced_value"] - 4.49544) < 1e-4
    index = (work / "report/index.html").read_text()
    assert f'id="{SLUG}"' in index and TITLE.split(" (")[0] in index
    assert f'href="paper-{SLUG}.html"' in index  # the index summarises; the paper's section is its own page
    section = (work / "report" / f"paper-{SLUG}.html").read_text()
    section = section[section.index(f'id="{SLUG}"'):]
    assert "lambda_c" in section and "fixed_point" in section
    assert "reproduced" in section and "differs" in section
    explored = index[index.index('id="explore"'):]  # and its rows are in the index's claims explorer
    assert f'data-paper="{SLUG}" data-kind="claim" data-verdict="differs"' in explored and "fixed_point" in explored
    assert (work / "report" / f"{SLUG}.html").is_file()
    assert (work / "figures" / SLUG / "fig1.png").is_file()


def test_the_scorecard_counts_it(sixth):
    work, _ = sixth
    index = (work / "report/index.html").read_text()
    card = index[index.index('id="total-claims"'):]
    total = int(re.search(r">(\d+)<", card).group(1))
    counted = sum(len(pd.read_csv(p)) for p in (work / "results/claims").glob("*.csv"))
    assert total == counted
    assert f"<code>{SLUG}</code>" in index


def test_the_crate_lists_its_tables(sixth):
    work, _ = sixth
    crate = json.loads((work / "report/ro-crate-metadata.json").read_text())
    ids = {str(entity.get("@id")) for entity in crate["@graph"]}
    for table in (f"results/{SLUG}/fixed_point_curve.csv", f"results/claims/{SLUG}.csv",
                  f"results/evidence/{SLUG}.csv"):
        assert any(i.endswith(table) for i in ids), table


def test_the_new_paper_follows_the_contract(sixth):
    work, _ = sixth
    ref = work / "tests/reference" / SLUG
    ref.mkdir(parents=True)
    shutil.copy2(work / "results" / SLUG / "fixed_point_curve.csv", ref)
    assert not check_paper(SLUG, work)
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"tests/papers/{SLUG}"],
                          cwd=work, capture_output=True, text=True, check=False,
                          env={**os.environ, "PYTHONPATH": str(work / "src")})
    assert proc.returncode == 0, proc.stdout[-3000:]


def test_a_figure_edit_reruns_only_its_figure_notebook_and_report(sixth):
    work, _ = sixth
    path = work / "src/netrepro/papers" / SLUG / "figures.py"
    path.write_text(path.read_text().replace('lw=2', 'lw=2.5'))
    # report_sources: the edited code's page in the report
    assert set(_planned(work)) == {f"{SLUG}_fig1", f"{SLUG}_notebook", "report_sources", "report"}


def test_a_title_fix_reruns_only_the_report(sixth):
    work, _ = sixth
    run_snakemake(work, "-j2", "report")  # settle the figure edit of the test before
    registry = work / "src/netrepro/papers.yaml"
    registry.write_text(registry.read_text().replace("title: Stability Conditions", "title: Stability conditions", 1))
    assert set(_planned(work)) == {"report"}


# ----------------------------------------------------------------------------- the untouched skeleton (issue 40 item 2)
@pytest.fixture(scope="module")
def untouched(built_repo, tmp_path_factory):
    """The built repository with a new paper's skeleton, untouched, built, and its references written by the command."""
    work = tmp_path_factory.mktemp("untouched") / "repo"
    shutil.copytree(built_repo, work, symlinks=True)
    source = work / "paper.txt"
    source.write_text("A paper.\n")
    env = {**os.environ, "PYTHONPATH": str(work / "src")}

    def run(*args):
        proc = subprocess.run([sys.executable, "-m", *args], cwd=work, capture_output=True, text=True, env=env,
                              check=False, timeout=900)
        assert proc.returncode == 0, f"{args}:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
        return proc

    written = run("netrepro", "new-paper", "skeleton_only", "--title", "An untouched skeleton",
                  "--source", str(source)).stdout
    # whatever must change outside the paper's package is written by the command itself
    assert "wrote CITATION.cff" in written and "wrote config/README.md" in written
    run_snakemake(work, "-j2", "report")
    # the copy is no git checkout, so the figures' committed references cannot be read here: tables only
    run("netrepro", "regression", "update", "--reference", "tests/reference", "--results", "results",
        "--paper", "skeleton_only", "--figures", "")
    return work, env


def test_the_untouched_skeleton_passes_check_paper_and_the_project_tests(untouched):
    work, env = untouched
    assert not check_paper("skeleton_only", work)
    # the project's own tests that a new paper's files meet: docstrings, citation, configuration docs,
    # the contract, and the paper's own tests (fast lane options)
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not slow",
                           "--hypothesis-profile", "fast", "tests/test_docstrings.py", "tests/test_release_files.py",
                           "tests/test_contract.py", "tests/test_paperdata.py", "tests/papers/skeleton_only"],
                          cwd=work, capture_output=True, text=True, env=env, check=False, timeout=900)
    assert proc.returncode == 0, proc.stdout[-4000:]


def test_the_untouched_skeleton_passes_make_check(untouched):
    work, env = untouched
    verify = subprocess.run([sys.executable, "-m", "netrepro", "verify", "-q"], cwd=work, capture_output=True,
                            text=True, env=env, check=False, timeout=300)
    assert verify.returncode == 0, verify.stdout[-3000:]
    # the test configuration's tables are not the committed references of the other papers: compare the new
    # paper's own folder, as `make check` does for every paper
    compare = subprocess.run([sys.executable, "-m", "netrepro", "regression", "compare", "--reference",
                              "tests/reference/skeleton_only", "--results", "results/skeleton_only",
                              "--figures", "", "--html", "", "--platform-rules", ""],
                             cwd=work, capture_output=True, text=True, env=env, check=False, timeout=300)
    assert compare.returncode == 0, compare.stdout[-3000:] + compare.stderr[-3000:]
