"""The whole workflow on the small test configuration, in a scratch copy of the repository.

Checks what a user does: a full `report` build, a no-op rerun, a rerun of
exactly the steps a parameter change touches, one figure rebuilt by rule
name and by file path, `--lint`, and that a bad configuration stops before
any job runs.
"""

import os
import re
import subprocess
import sys

import pandas as pd
import pytest
import yaml

from netrepro.judging.verdicts import VERDICTS
from netrepro.pipeline.registry import paper_slugs

from .conftest import run_snakemake

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]


def snakemake(workdir, *args, check=True):
    return run_snakemake(workdir, *args, check=check)


def jobs_planned(workdir, *targets):
    """Rule names a dry run would execute."""
    out = snakemake(workdir, "-n", *targets).stdout
    rules = set()
    for line in out.splitlines():
        match = re.match(r"^(\w+)\s+\d+$", line.strip())
        if match and match.group(1) not in ("total", "job"):
            rules.add(match.group(1))
    return rules


@pytest.fixture(scope="module")
def built(built_repo):
    return built_repo


def test_report_and_interface_tables(built):
    assert (built / "report" / "index.html").stat().st_size > 10_000
    bounds = pd.read_csv(built / "results/intermittent/scalar_bounds.csv")
    assert list(bounds.columns[:9]) == ["lam", "k", "s", "r", "report_estimate", "mean", "mean_lo", "mean_hi",
                                        "mean_method"]
    region = pd.read_csv(built / "results/intermittent/two_sensor_region.csv")
    assert list(region.columns[:3]) == ["lambda1", "lambda2c_lower", "lambda2c_upper"]
    for claims in (built / "results/claims").glob("*.csv"):
        frame = pd.read_csv(claims)
        assert list(frame.columns[:8]) == ["paper", "claim_id", "statement", "paper_value", "reproduced_value",
                                           "tolerance", "verdict", "note"]
        assert set(frame["verdict"]) <= set(VERDICTS)
        assert {"location", "condition", "depends_on", "robust"} <= set(frame.columns), claims.name
    for slug in paper_slugs():
        if (built / "results/claims" / f"{slug}.csv").is_file():
            assert (built / "results/findings" / f"{slug}.csv").is_file(), slug
    for table in (built / "results").rglob("*.csv"):
        assert table.with_name(table.name + ".meta.json").is_file(), f"no provenance sidecar for {table}"


def test_every_output_has_the_mode_of_a_new_file(built):
    """Issue 41: every table, figure, sidecar and page is readable as the umask allows (0644 under
    umask 022), not 0600 as mkstemp creates it."""
    from netrepro.pipeline.io import current_umask, new_file_mode

    expected = new_file_mode(current_umask())  # the build ran in this process's umask
    outputs = [p for folder in ("results", "figures", "report") for p in (built / folder).rglob("*") if p.is_file()]
    assert len(outputs) > 100
    wrong = {str(p.relative_to(built)): oct(p.stat().st_mode & 0o777) for p in outputs
             if p.stat().st_mode & 0o777 != expected}
    assert wrong == {}, f"expected {oct(expected)}"


def test_second_run_does_nothing(built):
    assert jobs_planned(built, "report") == set()


def test_parameter_change_reruns_exactly_dependents(built):
    cfg_path = built / "config/test.yaml"
    original = cfg_path.read_text()
    cfg = yaml.safe_load(original)
    cfg["intermittent"]["two_sensor"]["lambda1_grid"] += 1
    cfg_path.write_text(yaml.safe_dump(cfg))
    try:
        planned = jobs_planned(built, "report")
    finally:
        cfg_path.write_text(original)
    assert {"intermittent_two_sensor_region", "intermittent_fig4", "intermittent_fig5", "report"} <= planned
    untouched = {"intermittent_monte_carlo", "intermittent_exact_mean", "intermittent_scalar_bounds",
                 "intermittent_fig1", "intermittent_fig2", "intermittent_two_sensor_simulation"}
    assert not planned & untouched


def test_a_template_edit_reruns_only_the_report(built):
    # the report's markup is data (Jinja2 templates, one style sheet), not code: an edit must still show
    template = built / "src/netrepro/report/templates/scale.html"
    original, stat = template.read_text(), template.stat()
    template.write_text(original + "\n")
    try:
        assert jobs_planned(built, "report") == {"report"}
    finally:  # content and time restored: the later tests see the built repository as it was
        template.write_text(original)
        os.utime(template, ns=(stat.st_atime_ns, stat.st_mtime_ns))


def test_source_pages_are_made_ahead_of_the_report(built):
    # the report's source pages come from report_sources (it highlights once per change of the code or of
    # the source-page template, in parallel with the other jobs), not from the report itself
    assert (built / "report/files/source/src/netrepro/pipeline/runner.py.html").is_file()
    template = built / "src/netrepro/report/templates/source.html"
    original, stat = template.read_text(), template.stat()
    template.write_text(original + "\n")
    try:
        assert jobs_planned(built, "report") == {"report_sources", "report"}
    finally:
        template.write_text(original)
        os.utime(template, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    forced = jobs_planned(built, "report", "--forcerun", "intermittent_fig1")
    assert "report_sources" not in forced and {"intermittent_fig1", "report"} <= forced


def test_n_chunks_does_not_trigger_rerun(built):
    cfg_path = built / "config/test.yaml"
    original = cfg_path.read_text()
    cfg = yaml.safe_load(original)
    cfg["intermittent"]["scalar"]["n_chunks"] = 5
    cfg_path.write_text(yaml.safe_dump(cfg))
    try:
        assert "intermittent_monte_carlo" not in jobs_planned(built, "report")
    finally:
        cfg_path.write_text(original)


def test_single_figure_by_rule_name_and_by_path(built):
    fig = built / "figures/intermittent/fig4.png"
    fig.unlink()
    assert jobs_planned(built, "intermittent_fig4") == {"intermittent_fig4"}
    snakemake(built, "-j2", "intermittent_fig4")
    assert fig.is_file()
    fig.unlink()
    assert jobs_planned(built, "figures/intermittent/fig4.png") == {"intermittent_fig4"}
    snakemake(built, "-j2", "figures/intermittent/fig4.png")
    assert fig.is_file()


def test_lint_clean(built):
    out = snakemake(built, "--lint")
    assert "good condition" in out.stdout + out.stderr


def test_bad_config_stops_before_any_job(built):
    bad = built / "config/bad.yaml"
    cfg = yaml.safe_load((built / "config/test.yaml").read_text())
    cfg["intermittent"]["scalar"]["R2"] = -1
    bad.write_text(yaml.safe_dump(cfg))
    before = {p: p.stat().st_mtime_ns for p in (built / "results").rglob("*")}
    proc = subprocess.run([sys.executable, "-m", "snakemake", "--configfile", "config/bad.yaml", "-j2", "--forceall",
                           "report"], cwd=built, capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, PYTHONPATH=str(built / "src")))
    assert proc.returncode != 0
    assert "intermittent.scalar.R2" in proc.stdout + proc.stderr
    after = {p: p.stat().st_mtime_ns for p in (built / "results").rglob("*")}
    assert before == after


def test_malformed_claims_file_stops_before_any_job(built):
    """Issue 15: a claims file that breaks its schema stops the run at start-up, naming file, entry and field."""
    claims = built / "src/netrepro/papers/onebit/claims.yaml"
    original = claims.read_text()
    entries = yaml.safe_load(original)
    del entries[1]["tolerance"]
    before = {p: p.stat().st_mtime_ns for p in (built / "results").rglob("*")}
    try:
        claims.write_text(yaml.safe_dump(entries, sort_keys=False))
        proc = subprocess.run([sys.executable, "-m", "snakemake", "--configfile", "config/test.yaml", "-j2",
                               "--forceall", "report"], cwd=built, capture_output=True, text=True, timeout=300,
                              env=dict(os.environ, PYTHONPATH=str(built / "src")))
    finally:
        claims.write_text(original)
    message = proc.stdout + proc.stderr
    assert proc.returncode != 0
    assert "onebit/claims.yaml" in message and f"entry 1 (id '{entries[1]['id']}')" in message
    assert "'tolerance.reason'" in message or "'tolerance'" in message
    assert before == {p: p.stat().st_mtime_ns for p in (built / "results").rglob("*")}
