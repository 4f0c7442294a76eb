"""Code inputs of pipeline rules, derived from the package's import graph.

A rule that calls ``netrepro.<module>:<function>`` depends on that module, on every
module of the package it imports (directly or through other package modules, at
module level or inside a function), on the packages (``__init__.py``) Python executes
to import them, and on the runner that calls the step. :func:`code_inputs` returns
those source files, so a change to any of them reruns the rule, and a change
elsewhere does not.

The import graph is read statically, without importing anything: the import statements
are picked out of each source file by a pattern and only they are parsed with ``ast``
(parsing whole files cost a quarter of a second at every workflow start-up). The test
suite checks the result against an independent reading of the compiled byte code
(:mod:`modulefinder`).
"""

from __future__ import annotations

import ast
import functools
import re
import textwrap
from pathlib import Path

__all__ = ["PACKAGE", "RUNNER_MODULE", "module_file", "imported_modules", "module_closure", "code_inputs"]

PACKAGE = "netrepro"
# the module every step runs in (it also imports io and provenance): part of every rule's code
RUNNER_MODULE = "netrepro.runner"
_SRC = Path(__file__).resolve().parent.parent
# an import statement at any indentation; a parenthesised name list may span lines
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+[.\w]+[ \t]+import[ \t]+(?:\([^)]*\)|[^\n]*)|import[ \t]+[^\n]*)",
                     re.MULTILINE)


@functools.lru_cache(maxsize=None)
def module_file(module: str, src: Path = _SRC) -> Path | None:
    """The source file of a package module (``pkg/__init__.py`` for a package), or None if absent."""
    base = src.joinpath(*module.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _is_package(module: str, src: Path) -> bool:
    return (src.joinpath(*module.split(".")) / "__init__.py").is_file()


def _absolute(module: str, level: int, name: str | None, src: Path) -> str:
    """The absolute name of ``from <level dots><name> import ...`` written inside ``module``."""
    if level == 0:
        return name or ""
    parts = module.split(".")
    base = parts if _is_package(module, src) else parts[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


@functools.lru_cache(maxsize=None)
def _imports_cached(module: str, src: Path) -> tuple[str, ...]:
    path = module_file(module, src)
    if path is None:
        return ()
    statements = []
    for match in _IMPORT.finditer(path.read_text()):
        # a line continued with a backslash, or text that only looks like an import (in a
        # docstring), is skipped here; the byte-code test would show a module missed that way
        try:
            statements.extend(ast.parse(textwrap.dedent(match.group(0).strip("\n"))).body)
        except SyntaxError:
            continue
    found = set()
    for node in (n for statement in statements for n in ast.walk(statement)):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            target = _absolute(module, node.level, node.module, src)
            found.add(target)
            # `from pkg import sub` may name a submodule, not an attribute
            found.update(f"{target}.{alias.name}" for alias in node.names if alias.name != "*")
    own = (m for m in found if m == PACKAGE or m.startswith(PACKAGE + "."))
    return tuple(sorted(m for m in own if module_file(m, src) is not None))


def imported_modules(module: str, src: Path = _SRC) -> list[str]:
    """Package modules that ``module`` imports directly (anywhere in its source)."""
    return list(_imports_cached(module, Path(src)))


def _with_parents(module: str) -> list[str]:
    """``a.b.c`` -> ``[a, a.b, a.b.c]``: importing a module executes its parent packages."""
    parts = module.split(".")
    return [".".join(parts[: i + 1]) for i in range(len(parts))]


def module_closure(module: str, src: Path = _SRC) -> list[str]:
    """Every package module executed when ``module`` is imported and its functions run, sorted."""
    return list(_closure_cached(module, Path(src)))


@functools.lru_cache(maxsize=None)
def _closure_cached(module: str, src: Path) -> tuple[str, ...]:
    seen: set[str] = set()
    stack = [module]
    while stack:
        current = stack.pop()
        for each in _with_parents(current):
            if each in seen or module_file(each, src) is None:
                continue
            seen.add(each)
            stack.extend(_imports_cached(each, src))
    return tuple(sorted(seen))


def code_inputs(func_spec: str, root: str | Path = "src", src: Path = _SRC) -> list[str]:
    """Source files a rule calling ``func_spec`` (``netrepro.module:function`` or a module) depends on.

    Parameters
    ----------
    func_spec : str
        ``"netrepro.papers.intermittent.steps:exact_mean_step"``, or a module name.
    root : str or Path
        Prefix of the returned paths (the ``src`` directory as the workflow sees it).
    src : Path
        The directory that holds the package, read for the import graph.

    Returns
    -------
    list of str
        Paths ``<root>/netrepro/...py`` of the closure of the function's module and of the runner.

    Raises
    ------
    ValueError
        If the module does not exist in the package.
    """
    module = func_spec.split(":", 1)[0]
    if module_file(module, Path(src)) is None:
        raise ValueError(f"{func_spec!r}: no module {module!r} under {src}")
    modules = sorted(set(module_closure(module, src)) | set(module_closure(RUNNER_MODULE, src)))
    return [str(Path(root) / module_file(m, Path(src)).relative_to(Path(src))) for m in modules]
