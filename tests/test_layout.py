"""The top level of ``src/netrepro/`` reads as a list of concepts (issue 39 item 4).

Subpackages only, plus ``__init__``/``__main__`` and two leaves every subpackage uses (``errors``: the
package's exceptions; ``locations``: where the package finds its files); every subpackage's
``__init__.py`` imports nothing, so that importing one module of a subpackage executes nothing else
(a rule's code inputs, :mod:`netrepro.pipeline.codedeps`, include the ``__init__`` files on the way).
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "netrepro"
# the top-level modules allowed beside the subpackages, and why
TOP_LEVEL_MODULES = {
    "__init__.py": "the package: its version",
    "__main__.py": "python -m netrepro: the console script",
    "errors.py": "the package's exceptions, imported by every subpackage (the bottom of the import order)",
    "locations.py": "where the package finds its data and the checkout, imported by several subpackages",
}
SUBPACKAGES = {"cli", "engines", "figures", "judging", "papers", "pipeline", "release", "report", "scaffold", "scale"}


def test_the_top_level_holds_subpackages_and_a_few_named_modules():
    modules = {p.name for p in PACKAGE.glob("*.py")}
    assert modules == set(TOP_LEVEL_MODULES), f"a module at the top level of src/netrepro/: {modules - set(TOP_LEVEL_MODULES)}"
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    assert packages == SUBPACKAGES


def test_every_subpackage_init_imports_nothing():
    offenders = []
    for init in sorted(PACKAGE.rglob("__init__.py")):
        if "templates" in init.relative_to(PACKAGE).parts:
            continue
        tree = ast.parse(init.read_text())
        offenders += [f"{init.relative_to(PACKAGE.parent)}:{node.lineno}" for node in ast.walk(tree)
                      if isinstance(node, (ast.Import, ast.ImportFrom))]
    assert not offenders, f"an __init__.py imports (keep them docstrings, at most __all__): {offenders}"


def test_nothing_in_the_package_imports_the_benchmarks():
    # the benchmarks reach into every paper's internals: they stand at the top of the import order
    offenders = [str(p.relative_to(PACKAGE.parent)) for p in PACKAGE.rglob("*.py")
                 if p.name != "bench.py" and p.relative_to(PACKAGE).parts[0] != "cli" and
                 any(isinstance(n, ast.ImportFrom) and (n.module or "").endswith("bench")
                     for n in ast.walk(ast.parse(p.read_text())))]
    assert not offenders, offenders
