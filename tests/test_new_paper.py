"""``new-paper`` refuses a bad request with a message naming the problem, and writes nothing."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.errors import InputError
from netrepro.scaffold.skeleton import plan_new_paper

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("slug,title,missing,message", [
    ("markov", "T", False, "paper 'markov' already exists"),
    ("2nd_paper", "T", False, "'2nd_paper' is not a valid lower-case Python identifier"),
    ("Kalman", "T", False, "'Kalman' is not a valid"),
    ("new_one", "T", True, "source file .*missing.txt does not exist"),
    ("new_one", " ", False, "--title must not be empty"),
])
def test_a_bad_request_is_refused_naming_the_problem(tmp_path, slug, title, missing, message):
    source = tmp_path / ("missing.txt" if missing else "paper.txt")
    if not missing:
        source.write_text("text")
    with pytest.raises(InputError, match=message):
        plan_new_paper(slug, title, source, ROOT)


def test_the_command_refuses_and_writes_nothing(tmp_path):
    source = tmp_path / "paper.txt"
    source.write_text("text")
    watched = [ROOT / "src/netrepro/papers.yaml", ROOT / "config/config.yaml", ROOT / "config/test.yaml",
               ROOT / "workflow/schemas/config.schema.yaml"]
    before = {p: p.read_bytes() for p in watched}
    proc = subprocess.run([sys.executable, "-m", "netrepro", "new-paper", "hinf", "--title", "T", "--source",
                           str(source), "--root", str(ROOT)], capture_output=True, text=True, check=False)
    assert proc.returncode == 2
    assert "paper 'hinf' already exists" in proc.stderr
    assert {p: p.read_bytes() for p in watched} == before


def test_the_plan_creates_every_role_and_registers_the_paper(tmp_path):
    source = tmp_path / "paper.txt"
    source.write_text("text")
    plan = plan_new_paper("plan_probe", "A title", source, ROOT)
    pkg = "src/netrepro/papers/plan_probe/"
    for name in ("__init__.py", "model.py", "steps.py", "evidence.py", "figures.py", "checks.py", "figures.yaml",
                 "steps.yaml", "claims.yaml", "errata.yaml", "reconstructions.yaml", "findings.yaml"):
        assert pkg + name in plan.create, name
    for role in ("model", "steps", "evidence", "figures", "checks"):
        assert f"tests/papers/plan_probe/test_{role}.py" in plan.create, role
    # no rules file: the workflow generates the paper's rules from its steps.yaml
    assert not [p for p in plan.create if p.startswith("workflow/rules/")]
    assert "plan_probe:" in plan.rewrite["src/netrepro/papers.yaml"]
    assert 'plan_probe: {$ref: "plan_probe.schema.yaml"}' in plan.rewrite["workflow/schemas/config.schema.yaml"]
    assert re.search(r"^papers: \[intermittent, markov, onebit, gainsched, hinf(, \w+)*, plan_probe\]$", plan.rewrite["config/test.yaml"], re.M)


def test_a_source_outside_the_shared_papers_folder_is_warned_about(tmp_path, monkeypatch, capsys):
    """The registry records only the source's file name, looked up in ../shared/papers/: elsewhere it dangles."""
    from netrepro.cli import main as commands
    from netrepro.scaffold import skeleton as scaffold

    root = tmp_path / "checkout"
    shared = tmp_path / "shared/papers"
    root.mkdir()
    shared.mkdir(parents=True)
    inside, outside = shared / "007_paper.txt", tmp_path / "paper.txt"
    inside.write_text("text")
    outside.write_text("text")
    assert scaffold.source_warnings(inside, root) == []
    assert scaffold.source_warnings(root / ".." / "shared/papers/007_paper.txt", root) == []  # the same folder
    (warning,) = scaffold.source_warnings(outside, root)
    assert "../shared/papers/" in warning and "'paper.txt'" in warning and "copy the source" in warning
    # the command prints it after writing the skeleton (new_paper itself is not run here)
    monkeypatch.setattr(scaffold, "new_paper", lambda *args: ["src/netrepro/papers.yaml"])
    assert commands.main(["new-paper", "sixth", "--title", "T", "--source", str(outside), "--root", str(root)]) == 0
    err = capsys.readouterr().err
    assert "warning:" in err and "paper.txt" in err
    assert commands.main(["new-paper", "sixth", "--title", "T", "--source", str(inside), "--root", str(root)]) == 0
    assert "warning" not in capsys.readouterr().err
