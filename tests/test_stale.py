"""Stale outputs (issue 40 B): files in results/ and figures/ that no rule of the workflow produces."""

import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.pipeline.stale import prune, stale_outputs

ROOT = Path(__file__).resolve().parents[1]

DECLARED = ["results/a/t.csv", "results/a/sim", "results/claims/a.csv", "figures/a/fig1.png",
            "figures/a/fig1.data.json", "report/files/source", "report/index.html"]
KEPT = ["results/a/t.csv", "results/a/t.csv.meta.json", "results/a/sim/run0.csv", "results/a/sim/deep/run1.csv",
        "results/a/sim/run0.csv.meta.json", "results/claims/a.csv", "results/claims/a.csv.meta.json",
        "figures/a/fig1.png", "figures/a/fig1.png.meta.json", "figures/a/fig1.data.json",
        "figures/a/fig1.data.json.meta.json", "results/regeneration/index.html", "results/benchmarks.csv",
        "results/benchmarks.csv.meta.json", "report/files/source/x.py", "report/old.html"]
STALE = ["figures/a/fig2.png", "figures/a/fig2.png.meta.json", "figures/gone/fig1.png", "results/a/old.csv",
         "results/a/old.csv.meta.json", "results/a/t.csv.bak", "results/claims/b.csv", "results/sim/run0.csv",
         "results/a/simulation.csv", "results/a/orphan.csv.meta.json"]


@pytest.fixture
def tree(tmp_path):
    for rel in KEPT + STALE:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("x")
    return tmp_path


def test_files_no_declared_output_accounts_for_are_stale(tree):
    """Declared files, files under a declared directory, their sidecars and the non-workflow files are kept."""
    assert stale_outputs(DECLARED, tree) == sorted(Path(p) for p in STALE)
    assert stale_outputs(DECLARED + STALE, tree) == []
    assert stale_outputs(DECLARED, tree / "nothing-here") == []


def test_prune_removes_the_stale_files_and_their_emptied_folders_only(tree):
    removed = prune(stale_outputs(DECLARED, tree), tree)
    assert sorted(removed) == sorted(Path(p) for p in STALE)
    assert all((tree / p).is_file() for p in KEPT)
    assert not any((tree / p).exists() for p in STALE)
    assert not (tree / "figures" / "gone").exists() and not (tree / "results" / "sim").exists()
    assert (tree / "results").is_dir() and (tree / "figures").is_dir()
    assert stale_outputs(DECLARED, tree) == []


def _fake_snakemake(tmp_path, declared):
    """A stand-in for `snakemake report --summary` that prints the given outputs."""
    script = tmp_path / "fake_snakemake.py"
    rows = "".join(f"{p}\\tdate\\trule\\t-\\tok\\tno update\\n" for p in declared)
    script.write_text("import sys\nassert sys.argv[1:3] == ['report', '--summary'], sys.argv\n"
                      "assert '--report' not in sys.argv\n"
                      f"sys.stdout.write('output_file\\tdate\\trule\\tlog-file(s)\\tstatus\\tplan\\n{rows}')\n")
    return f"{sys.executable} {script}"


def test_prune_command_lists_checks_and_removes(tree):
    fake = _fake_snakemake(tree, DECLARED)
    env = {"PYTHONPATH": str(ROOT / "src")}

    def run(*args):
        return subprocess.run([sys.executable, "-m", "netrepro", "prune", *args, "--snakemake", fake, "--",
                               "--report", "report/x.html", "--report-after-run"],
                              cwd=tree, capture_output=True, text=True, env=env)

    dry = run("--dry-run")
    assert dry.returncode == 0, dry.stderr
    assert "stale: results/a/old.csv" in dry.stdout and "`make prune` removes them" in dry.stdout
    assert (tree / "results/a/old.csv").exists()
    check = run("--check")
    assert check.returncode == 1 and "make prune" in check.stdout and "figures/gone/fig1.png" in check.stdout
    done = run()
    assert done.returncode == 0 and "removed results/a/old.csv" in done.stdout
    assert not (tree / "results/a/old.csv").exists() and (tree / "results/a/t.csv").exists()
    again = run("--check")
    assert again.returncode == 0 and "0 stale files" in again.stdout


def test_make_check_reports_stale_outputs_and_make_prune_exists():
    out = subprocess.run(["make", "-n", "check", "prune", "BIN=bin", "STAMP="], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    assert "-m netrepro prune --check -- --profile workflow/profiles/default" in out
    assert "-m netrepro regression compare" in out and "-m netrepro verify" in out
    assert "-m netrepro prune  -- --profile" in out or "-m netrepro prune -- --profile" in out
