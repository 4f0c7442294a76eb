"""The user's CI (.github/workflows/regenerate.yml) runs what .ci/run runs (issue 26)."""

import re
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
WORKFLOW = ROOT / ".github" / "workflows" / "regenerate.yml"
MAKE = re.compile(r"^\s*make\s+([\w-]+)\s*$", re.M)


def _workflow():
    return yaml.safe_load(WORKFLOW.read_text())


def _steps():
    (job,) = _workflow()["jobs"].values()
    return job, job["steps"]


def test_the_workflow_runs_the_make_targets_of_ci_run_in_the_same_order():
    ci = MAKE.findall((ROOT / ".ci" / "run").read_text())
    _, steps = _steps()
    workflow = [t for step in steps for t in MAKE.findall(step.get("run", ""))]
    assert ci == workflow, f".ci/run runs make {ci}, the workflow make {workflow}"
    assert ci[-1] == "check" and {"test", "lint", "clean", "report"} <= set(ci)


def test_the_workflow_sets_up_like_ci_and_uploads_the_comparison_on_every_run():
    job, steps = _steps()
    runs = "\n".join(step.get("run", "") for step in steps)
    assert "for setup in .ci/setup.d/*.sh" in runs and "for setup in .ci/setup.d/*.sh" in (ROOT / ".ci/run").read_text()
    # `on:` is read by YAML 1.1 as True
    triggers = _workflow().get("on", _workflow().get(True))
    assert {"push", "pull_request", "schedule"} <= set(triggers)
    assert "3.11" in job["container"]
    cache = [s for s in steps if str(s.get("uses", "")).startswith("actions/cache")]
    assert cache and cache[0]["with"]["path"] == ".venv" and "hashFiles('requirements/*.txt'" in cache[0]["with"]["key"]
    upload = [s for s in steps if str(s.get("uses", "")).startswith("actions/upload-artifact")]
    # the comparison's evidence is uploaded on every run, passing or not, with a job summary (issue 41 item 5)
    assert upload and upload[0]["if"] == "always()"
    assert "results/regeneration/" in upload[0]["with"]["path"] and "report/" in upload[0]["with"]["path"]
    summary = [s for s in steps if "GITHUB_STEP_SUMMARY" in s.get("run", "")]
    assert summary and summary[0]["if"] == "always()" and "results/regeneration/summary.md" in summary[0]["run"]


def test_the_pages_workflow_publishes_the_report_from_main_and_passes_actionlint():
    pages = ROOT / ".github" / "workflows" / "pages.yml"
    doc = yaml.safe_load(pages.read_text())
    triggers = doc.get("on", doc.get(True))
    assert triggers["push"]["branches"] == ["main"]
    steps = doc["jobs"]["build"]["steps"]
    assert any("make report" in s.get("run", "") for s in steps)
    assert any(str(s.get("uses", "")).startswith("actions/upload-pages-artifact") and s["with"]["path"] == "report/"
               for s in steps)
    assert any(str(s.get("uses", "")).startswith("actions/deploy-pages") for s in doc["jobs"]["deploy"]["steps"])
    actionlint = Path(sys.executable).parent / "actionlint"
    proc = subprocess.run([sys.executable, str(actionlint), str(pages)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_workflow_passes_actionlint_and_make_lint_runs_it():
    actionlint = Path(sys.executable).parent / "actionlint"
    proc = subprocess.run([str(actionlint), str(WORKFLOW)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lint = re.search(r"^lint:.*?(?=^\S)", (ROOT / "Makefile").read_text(), re.M | re.S).group(0)
    assert "actionlint .github/workflows/regenerate.yml" in lint


def test_make_report_takes_an_overlay_a_profile_and_shard_counts():
    root = Path(__file__).resolve().parents[1]

    def dry(*args):
        out = subprocess.run(["make", "-n", "report", *args], cwd=root, capture_output=True, text=True, check=True)
        return [line for line in out.stdout.splitlines() if "netrepro build -- " in line]

    default = dry()
    assert default and all("--configfile" not in line and "--config " not in line and "-j2" in line for line in default)
    scaled = dry("CONFIG=paper-scale", "PROFILE=slurm", "SHARDS={onebit_estimator: 8}")
    assert scaled and all("--configfile config/config.yaml config/paper-scale.yaml" in line for line in scaled)
    assert all("--profile workflow/profiles/slurm" in line and " -j" not in line for line in scaled)  # the profile's job limit
    assert all("--config 'shards={onebit_estimator: 8}'" in line for line in scaled)
    assert (root / "config" / "paper-scale.yaml").is_file()
