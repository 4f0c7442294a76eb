"""Every rule's code inputs equal the import closure of the function it calls.

The closure used by the workflow is read from the source with ``ast``
(:mod:`netrepro.codedeps`); here it is recomputed independently from the compiled
byte code by :mod:`modulefinder`, and compared with what each rule of the real
workflow lists (read from a dry run's printed commands).
"""

import json
import modulefinder
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.codedeps import code_inputs, imported_modules, module_closure

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def bytecode_closure(module: str) -> set[str]:
    """Package modules reached from ``module`` by modulefinder (byte code, nested functions included)."""
    finder = modulefinder.ModuleFinder(path=[str(SRC)])
    finder.import_hook(module)
    return {name for name in finder.modules if name == "netrepro" or name.startswith("netrepro.")}


def files_of(modules) -> set[str]:
    out = set()
    for name in modules:
        base = Path("src", *name.split("."))
        out.add(str(base / "__init__.py") if (ROOT / base).is_dir() else str(base.with_suffix(".py")))
    return out


@pytest.fixture(scope="module")
def planned_jobs():
    """``{rule: (func, code inputs)}`` for every step job of the full workflow, from a dry run."""
    proc = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "-p", "--forceall", "report"],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    jobs = {}
    for line in (proc.stdout + proc.stderr).splitlines():
        if "-m netrepro run" not in line:
            continue
        args = shlex.split(line[line.index("-m netrepro run"):])
        func = args[args.index("--func") + 1]
        io = json.loads(args[args.index("--io") + 1])
        rule = io["rule"]
        jobs[rule] = (func, set(io["inputs"]["code"]))
    return jobs


def test_closure_matches_bytecode_reading_for_every_module():
    for path in sorted((SRC / "netrepro").rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        assert set(module_closure(module, SRC)) == bytecode_closure(module), module


def test_every_rule_lists_exactly_the_closure_of_its_function(planned_jobs):
    assert len(planned_jobs) > 50
    runner = bytecode_closure("netrepro.runner")
    for rule, (func, listed) in planned_jobs.items():
        expected = files_of(bytecode_closure(func.split(":")[0]) | runner)
        assert listed == expected, f"{rule}: missing {sorted(expected - listed)}, extra {sorted(listed - expected)}"


def test_plotting_modules_stay_out_of_compute_steps(planned_jobs):
    """An edit to a plotting module must not rerun a computation."""
    for rule, (func, listed) in planned_jobs.items():
        if ".figures:" not in func and not re.search(r"_fig(S?\d+)$", rule):
            assert "src/netrepro/plotting.py" not in listed or ".steps:" not in func, rule


def test_relative_and_nested_imports_are_found(tmp_path):
    pkg = tmp_path / "netrepro"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from .sub import b\n")
    (pkg / "sub" / "b.py").write_text("from ..c import x\nimport numpy\n")
    (pkg / "c.py").write_text("x = 1\n")
    (pkg / "unused.py").write_text("")
    assert imported_modules("netrepro.a", tmp_path) == ["netrepro.sub", "netrepro.sub.b"]
    assert module_closure("netrepro.a", tmp_path) == [
        "netrepro", "netrepro.a", "netrepro.c", "netrepro.sub", "netrepro.sub.b"]
    with pytest.raises(ValueError, match="no module"):
        code_inputs("netrepro.missing:f", src=tmp_path)
