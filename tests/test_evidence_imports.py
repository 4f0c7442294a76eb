"""Evidence is assembly only (issue 29, part 3): no paper's ``evidence.py`` reaches into another module's
private names (an underscore import, or ``module._name``)."""

import ast
from pathlib import Path

import pytest

import netrepro

PAPERS = Path(netrepro.__file__).resolve().parent / "papers"
EVIDENCE = sorted(PAPERS.glob("*/evidence.py"))


def private_uses(source: str) -> list[str]:
    """Private names of other modules that ``source`` imports or reads as attributes."""
    tree = ast.parse(source)
    found = [f"from {'.' * n.level}{n.module or ''} import {a.name}" for n in ast.walk(tree)
             if isinstance(n, ast.ImportFrom) for a in n.names if a.name.startswith("_")]
    found += [f"import {a.name}" for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names
              if any(part.startswith("_") for part in a.name.split("."))]
    found += [f"{ast.unparse(n.value)}.{n.attr}" for n in ast.walk(tree) if isinstance(n, ast.Attribute)
              and n.attr.startswith("_") and not n.attr.startswith("__")]
    return found


def test_the_check_finds_private_uses():
    src = "from .steps import _merged_runs, ok\nimport a._b\nx = steps._cases(1)\ny = obj.__class__\n"
    assert private_uses(src) == ["from .steps import _merged_runs", "import a._b", "steps._cases"]


def test_there_is_an_evidence_module_per_paper():
    assert {p.parent.name for p in EVIDENCE} >= {"intermittent", "gainsched", "onebit", "hinf", "markov"}


@pytest.mark.parametrize("path", EVIDENCE, ids=lambda p: p.parent.name)
def test_evidence_uses_no_private_name_of_another_module(path):
    assert private_uses(path.read_text()) == []
