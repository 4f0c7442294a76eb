"""The paper contract as a command (issue 30): it passes on every paper and names each planted violation."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.contract import check_paper
from netrepro.registry import paper_slugs

ROOT = Path(__file__).resolve().parents[1]
SLUG = "intermittent"
# what check_paper reads of a checkout
PARTS = ("src/netrepro/papers.yaml", f"src/netrepro/papers/{SLUG}", f"workflow/rules/{SLUG}.smk",
         f"workflow/schemas/{SLUG}.schema.yaml", "workflow/schemas/config.schema.yaml",
         f"workflow/notebooks/{SLUG}.ipynb", f"workflow/report/{SLUG}", f"tests/papers/{SLUG}",
         f"tests/reference/{SLUG}", "config/config.yaml", "config/test.yaml")


@pytest.mark.parametrize("slug", paper_slugs())
def test_every_registered_paper_follows_the_contract(slug):
    violations = check_paper(slug, ROOT)
    assert not violations, "\n".join(map(str, violations))


def test_the_command_passes_on_all_papers_and_exits_zero():
    proc = subprocess.run([sys.executable, "-m", "netrepro", "check-paper", "--root", str(ROOT)],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert all(f"check-paper {slug}: ok" in proc.stdout for slug in paper_slugs())


@pytest.fixture
def scratch(tmp_path):
    """The files of one paper that the contract reads, in a scratch checkout."""
    for part in PARTS:
        src, dst = ROOT / part, tmp_path / part
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
    assert not check_paper(SLUG, tmp_path)
    return tmp_path


def _append(path: Path, text: str) -> int:
    """Append ``text`` to ``path``; return the line number of its first line."""
    old = path.read_text()
    path.write_text(old.rstrip("\n") + "\n" + text)
    return len(old.rstrip("\n").splitlines()) + 1


def _named(violations, check, path, line=None):
    return [v for v in violations if v.check == check and v.path == path and (line is None or v.line == line)]


def test_each_planted_violation_is_named_with_file_and_line(scratch):
    pkg = f"src/netrepro/papers/{SLUG}"
    (scratch / pkg / "checks.py").unlink()
    fig_line = _append(scratch / pkg / "figures.py", "from .model import lambda_c\n")
    io_line = _append(scratch / pkg / "model.py", "import pandas as pd\n")
    api_line = _append(scratch / pkg / "exact.py", "def forgotten(x):\n    return x\n")
    two = scratch / pkg / "two_sensor.py"
    doc_line = _append(two, "def undocumented(x):\n    \"\"\"No sections.\"\"\"\n    return x\n")
    two.write_text(two.read_text().replace("__all__ = [", "__all__ = [\"undocumented\", ", 1))
    claims = scratch / pkg / "claims.yaml"
    text = claims.read_text()
    first_quantity = text.split("quantity: ", 1)[1].split("}", 1)[0].split("\n", 1)[0].strip()
    claims.write_text(text.replace(f"quantity: {first_quantity}", "quantity: no_such_quantity", 1))
    spec_line = _append(scratch / pkg / "figures.yaml", "figS9:\n  plot: figure_nowhere\n")
    smk = scratch / f"workflow/rules/{SLUG}.smk"
    rule_line = _append(smk, "\n\nrule wrong_prefix:\n    output:\n        'x'\n    shell:\n        'touch {output}'\n")
    key_line = _append(smk, "\nEXTRA = pick(ICFG.get('scalar', {}), 'a', 'no_such_key')\n")

    found = check_paper(SLUG, scratch)
    text = "\n".join(map(str, found))
    assert _named(found, "roles", f"{pkg}/checks.py"), text
    assert _named(found, "figures-imports", f"{pkg}/figures.py", fig_line), text
    assert _named(found, "math-io", f"{pkg}/model.py", io_line), text
    assert _named(found, "public-api", f"{pkg}/exact.py", api_line), text
    assert [v for v in _named(found, "public-api", f"{pkg}/two_sensor.py", doc_line) if "Parameters" in v.message], text
    assert [v for v in _named(found, "claim-quantity", f"{pkg}/claims.yaml") if "no_such_quantity" in v.message], text
    assert [v for v in _named(found, "figure-spec", f"{pkg}/figures.yaml", spec_line) if "figure_nowhere" in v.message]
    assert [v for v in _named(found, "figure-spec", f"{pkg}/figures.yaml", spec_line) if "caption" in v.message]
    assert [v for v in _named(found, "rule-name", f"workflow/rules/{SLUG}.smk") if "wrong_prefix" in v.message], text
    assert _named(found, "rule-name", f"workflow/rules/{SLUG}.smk", rule_line + 2), text
    assert [v for v in _named(found, "config-key", f"workflow/rules/{SLUG}.smk", key_line + 1)
            if "intermittent.scalar.no_such_key" in v.message], text
    # and nothing else: every violation is one of those planted
    assert len(found) == 11, text


def test_a_missing_reference_folder_is_a_violation(scratch):
    shutil.rmtree(scratch / f"tests/reference/{SLUG}")
    found = check_paper(SLUG, scratch)
    assert [v for v in found if v.check == "roles" and v.path == f"tests/reference/{SLUG}"], found


def test_an_unregistered_paper_is_a_violation(scratch):
    registry = scratch / "src/netrepro/papers.yaml"
    text = registry.read_text()
    start = text.index(f"\n{SLUG}:")
    end = text.index("\ngainsched:")
    registry.write_text(text[:start] + text[end:])
    found = check_paper(SLUG, scratch)
    assert [v for v in found if v.check == "roles" and "not registered" in v.message], found
