"""Every rule's code inputs are the modules its function reaches, within its import closure.

The module-level import closure is read from the source with ``ast`` (:mod:`netrepro.pipeline.codedeps`);
here it is recomputed independently from the compiled byte code by :mod:`modulefinder`. The
function-level closure (what a rule lists) lies within it, and an edit to a module reruns only
the rules whose function reaches it: checked on a scratch copy of the workflow, whose plan after
an edit of ``markov/stability.py`` is Snakemake's own plan for ``--forcerun markov_stability_map``.
"""

import json
import modulefinder
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.pipeline.codedeps import code_inputs, function_closure, imported_modules, module_closure

from .conftest import copy_repo, run_snakemake

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
def dry_run_steps():
    """``[(rule header, shell args)]`` of every step job of the full workflow, from a dry run."""
    proc = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "-p", "--forceall", "report"],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    steps, header = [], None
    for line in (proc.stdout + proc.stderr).splitlines():
        named = re.match(r"^(?:local)?rule (\w+):$", line.strip())
        if named:
            header = named.group(1)
        elif "-m netrepro run" in line:
            steps.append((header, shlex.split(line[line.index("-m netrepro run"):])))
    return steps


@pytest.fixture(scope="module")
def planned_jobs(dry_run_steps):
    """``{rule: (func, code inputs)}`` for every step job of the full workflow."""
    jobs = {}
    for _, args in dry_run_steps:
        io = json.loads(args[args.index("--io") + 1])
        jobs[args[args.index("--rule") + 1]] = (args[args.index("--func") + 1], set(io["inputs"]["code"]))
    return jobs


@pytest.mark.slow  # a dry run of the whole workflow
def test_every_step_passes_its_own_rule_name(dry_run_steps):
    # Each rule writes its name twice (``rule NAME:`` and ``params: rule="NAME"``: Snakemake
    # formats ``{rule}`` only in shell commands, and the lint flags it there). The name the
    # runner records in every sidecar must be the rule's own, for hand-written and generated rules.
    assert len({header for header, _ in dry_run_steps}) > 50
    wrong = [(header, args[args.index("--rule") + 1] if "--rule" in args else None)
             for header, args in dry_run_steps
             if "--rule" not in args or args[args.index("--rule") + 1] != header]
    assert not wrong, f"(rule, name its command passes): {wrong}"


def test_closure_matches_bytecode_reading_for_every_module():
    for path in sorted((SRC / "netrepro").rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        assert set(module_closure(module, SRC)) == bytecode_closure(module), module


@pytest.mark.slow  # a dry run of the whole workflow
def test_every_rule_lists_its_function_closure_within_the_import_closure(planned_jobs):
    assert len(planned_jobs) > 50
    runner = bytecode_closure("netrepro.pipeline.runner")
    narrower = 0
    for rule, (func, listed) in planned_jobs.items():
        module = func.split(":")[0]
        assert listed == set(code_inputs(func)), rule
        assert files_of(runner | {module}) <= listed, rule  # the runner and the function's own module
        assert listed <= files_of(bytecode_closure(module) | runner), f"{rule}: {sorted(listed)}"
        narrower += listed != files_of(bytecode_closure(module) | runner)
    assert narrower > 20  # most steps reach only part of what their steps.py imports


@pytest.mark.slow
def test_markov_steps_reach_stability_only_for_the_map(planned_jobs):
    """Of the markov compute rules, only the stability map runs code of ``stability.py``."""
    reaching = {rule for rule, (func, listed) in planned_jobs.items()
                if ".steps:" in func and "src/netrepro/papers/markov/stability.py" in listed}
    assert reaching == {"markov_stability_map"}


@pytest.mark.slow
def test_an_edit_to_stability_reruns_only_the_map_and_what_depends_on_it(tmp_path):
    work = copy_repo(tmp_path / "repo")
    # every output present (empty) and up to date, nothing computed: created, then ordered by --touch
    plan = run_snakemake(work, "-n", "report")
    for line in re.findall(r"^\s+output: (.*)$", plan.stdout + plan.stderr, re.MULTILINE):
        for name in line.split(", "):
            path = work / name
            if path.suffix:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.touch()
            else:  # a directory() output (report/files)
                path.mkdir(parents=True, exist_ok=True)
    run_snakemake(work, "--touch", "-j1", "report")

    def planned(*args):
        out = run_snakemake(work, "-n", *args, "report")
        return set(re.findall(r"^rule (\w+):", out.stdout + out.stderr, re.MULTILINE))

    assert planned() == set()
    with open(work / "src/netrepro/papers/markov/stability.py", "a") as handle:
        handle.write("\n# an edit\n")
    after_edit = planned()
    assert "markov_stability_map" in after_edit
    assert not any(r.startswith("markov_") and r.endswith(("_lmi_checks", "exact_moments", "sample_paths",
                                                           "critical_curves", "expectations"))
                   for r in after_edit)
    assert after_edit == planned("--forcerun", "markov_stability_map")


def test_function_closure_follows_names_not_imports(tmp_path):
    pkg = tmp_path / "netrepro"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "steps.py").write_text(
        "from . import helpers as h\nfrom .fast import quick\nfrom .slow import heavy\nimport netrepro.shared\n"
        "LIMIT = quick(2)\n"
        "def fast_step():\n    return h.scale(LIMIT)\n"
        "def slow_step():\n    return heavy()\n"
        "def lazy_step():\n    from .lazy import later\n    return later()\n"
        "def value_step():\n    return sorted(vars(h))\n"
        "def shared_step():\n    return netrepro.shared.x\n")
    (pkg / "helpers.py").write_text("from .deep import d\ndef scale(x):\n    return 2 * x\ndef other():\n    return d\n")
    for name, body in {"fast": "def quick(x):\n    return x\n", "slow": "def heavy():\n    return 1\n",
                       "lazy": "def later():\n    return 1\n", "deep": "d = 1\n", "shared": "x = 1\n"}.items():
        (pkg / f"{name}.py").write_text(body)

    def reach(func):
        return [m.removeprefix("netrepro.") for m in function_closure(f"netrepro.steps:{func}", tmp_path)]

    assert reach("fast_step") == ["netrepro", "fast", "helpers", "steps"]  # via LIMIT = quick(2) and h.scale
    assert reach("slow_step") == ["netrepro", "slow", "steps"]
    assert reach("lazy_step") == ["netrepro", "lazy", "steps"]
    assert reach("value_step") == ["netrepro", "deep", "helpers", "steps"]  # the module object as a value
    assert reach("shared_step") == ["netrepro", "shared", "steps"]
    assert set(reach("slow_step")) < set(m.removeprefix("netrepro.") for m in module_closure("netrepro.steps", tmp_path))
    # the summaries are cached beside the byte code, and an edited module is read again
    assert (pkg / "__pycache__" / "steps.codedeps.json").is_file()
    function_closure.__globals__["_summary"].cache_clear()
    (pkg / "slow.py").write_text("from .fast import quick\ndef heavy():\n    return quick(1)\n")
    assert reach("slow_step") == ["netrepro", "fast", "slow", "steps"]


@pytest.mark.slow
def test_plotting_modules_stay_out_of_compute_steps(planned_jobs):
    """An edit to a plotting module must not rerun a computation."""
    for rule, (func, listed) in planned_jobs.items():
        if ".figures:" not in func and not re.search(r"_fig(S?\d+)$", rule):
            assert "src/netrepro/figures/plotting.py" not in listed or ".steps:" not in func, rule


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
