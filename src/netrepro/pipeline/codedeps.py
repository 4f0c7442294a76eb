"""Code inputs of pipeline rules, derived from the package's source.

A rule that calls ``netrepro.<module>:<function>`` depends on the source files whose code
the function can reach (:func:`function_closure`): the function itself, every function,
class and module-level name of the package it refers to, transitively (through
``from .x import f``, ``from . import x`` then ``x.f``, imports inside functions, re-exports
of a package's ``__init__``), the packages (``__init__.py``) Python executes to import
them, and the runner that calls the step with its own import closure.
:func:`code_inputs` returns those files, so that a change to any of them reruns the rule,
and a change to a module the function imports but never reaches (a sibling step's
helpers in the same ``steps.py``) does not. Where a name cannot be followed (a star
import, a module object passed around as a value), the whole module and its import
closure count. A module's top-level statements that bind no name (a bare call) are
taken to have no effect on the results.

:func:`module_closure` is the module-level import closure (what importing a module
executes); the function-level closure is always a subset of it.

The import graph is read statically, without importing anything: the import statements
are picked out of each source file by a pattern and only they are parsed with ``ast``
(parsing whole files cost a quarter of a second at every workflow start-up). The test
suite checks the result against an independent reading of the compiled byte code
(:mod:`modulefinder`).
"""

from __future__ import annotations

import ast
import functools
import json
import os
import re
import textwrap
from pathlib import Path

from ..locations import package_root

__all__ = ["PACKAGE", "RUNNER_MODULE", "module_file", "imported_modules", "module_closure", "function_closure",
           "code_inputs", "top_level_names"]

PACKAGE = "netrepro"
# the module every step runs in (it also imports io and provenance): part of every rule's code
RUNNER_MODULE = "netrepro.pipeline.runner"
# the folder that holds the package (src/ of a checkout)
_SRC = package_root().resolve().parent
# an import statement at any indentation; a parenthesised name list may span lines
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+[.\w]+[ \t]+import[ \t]+(?:\([^)]*\)|[^\n]*)|import[ \t]+[^\n]*)",
                     re.MULTILINE)


@functools.lru_cache(maxsize=None)
def module_file(module: str, src: Path = _SRC) -> Path | None:
    """The source file of a package module (``pkg/__init__.py`` for a package), or None if absent.

    Parameters
    ----------
    module : str
        A dotted module name.
    src : Path
        The directory that holds the package.

    Returns
    -------
    Path or None
        The file.
    """
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
    """Package modules that ``module`` imports directly (anywhere in its source).

    Parameters
    ----------
    module : str
        A dotted module name.
    src : Path
        The directory that holds the package.

    Returns
    -------
    list of str
        The imported package modules, sorted.
    """
    return list(_imports_cached(module, Path(src)))


def _with_parents(module: str) -> list[str]:
    """``a.b.c`` -> ``[a, a.b, a.b.c]``: importing a module executes its parent packages."""
    parts = module.split(".")
    return [".".join(parts[: i + 1]) for i in range(len(parts))]


def module_closure(module: str, src: Path = _SRC) -> list[str]:
    """Every package module executed when ``module`` is imported and its functions run, sorted.

    Parameters
    ----------
    module : str
        A dotted module name.
    src : Path
        The directory that holds the package.

    Returns
    -------
    list of str
        The module, what it imports (transitively) and their parent packages.
    """
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


def _own(module: str) -> bool:
    return module == PACKAGE or module.startswith(PACKAGE + ".")


def _bindings(node, module: str, src: Path):
    """``(name, (target module, attribute or None))`` bound by an import statement in ``module``."""
    if isinstance(node, ast.Import):
        for alias in node.names:
            if alias.asname:
                yield alias.asname, (alias.name, None)
            else:  # `import a.b` binds `a`; the attribute chain a.b.x is followed from `a`
                yield alias.name.split(".")[0], (alias.name.split(".")[0], None)
    elif isinstance(node, ast.ImportFrom):
        target = _absolute(module, node.level, node.module, src)
        for alias in node.names:
            if alias.name != "*":
                yield alias.asname or alias.name, (target, alias.name)


def _module_of(target: str, attr: str | None, src: Path) -> tuple[str, str | None]:
    """``from target import attr``: the submodule ``target.attr`` when there is one."""
    if attr is not None and module_file(f"{target}.{attr}", src) is not None:
        return f"{target}.{attr}", None
    return target, attr


def _summarise(module: str, src: Path) -> dict:
    """One module's top-level names: what each definition refers to, the imports, the star imports."""
    path = module_file(module, src)
    tree = ast.parse(path.read_text()) if path is not None else ast.Module(body=[], type_ignores=[])
    nodes: dict[str, list] = {}
    imports: dict[str, tuple] = {}
    star = []
    for node in tree.body:
        statements = [node]
        if isinstance(node, (ast.If, ast.Try)):  # `if TYPE_CHECKING:` / `try: import x except ImportError:`
            statements = [n for n in ast.walk(node) if isinstance(n, ast.stmt)]
        for stmt in statements:
            if isinstance(stmt, (ast.Import, ast.ImportFrom)):
                if isinstance(stmt, ast.ImportFrom) and any(a.name == "*" for a in stmt.names):
                    star.append(_absolute(module, stmt.level, stmt.module, src))
                imports.update(_bindings(stmt, module, src))
            elif isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                nodes.setdefault(stmt.name, []).append(stmt)
            elif isinstance(stmt, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                targets = stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target]
                for target in targets:
                    for name in ast.walk(target):
                        if isinstance(name, ast.Name):
                            nodes.setdefault(name.id, []).append(stmt)
    defs = {name: sorted({ref for node in found for ref in _references(node, module, nodes, imports, src)},
                         key=lambda r: (r[0], r[1] or ""))
            for name, found in nodes.items()}
    return {"defs": {k: [list(r) for r in v] for k, v in defs.items()},
            "imports": {k: list(v) for k, v in imports.items()}, "star": star}


def _references(node, module: str, defs: dict, imports: dict, src: Path):
    """``(module, name or None)`` pairs that the definition ``node`` of ``module`` refers to."""
    attributes: dict[str, set] = {}
    bare: set[str] = set()
    for sub in ast.walk(node):
        if isinstance(sub, (ast.Import, ast.ImportFrom)):  # an import inside the function
            for _, (target, attr) in _bindings(sub, module, src):
                if _own(target):
                    yield _module_of(target, attr, src)
        elif isinstance(sub, ast.Attribute) and isinstance(sub.value, ast.Name):
            attributes.setdefault(sub.value.id, set()).add(sub.attr)
            sub.value.netrepro_attribute_of = True  # not a use of the name as a value
        elif isinstance(sub, ast.Name) and not getattr(sub, "netrepro_attribute_of", False):
            bare.add(sub.id)
    for name in bare | set(attributes):
        if name in defs:
            yield module, name
        elif name in imports:
            target, attr = _module_of(*imports[name], src)
            if not _own(target):
                continue
            if attr is not None:
                yield target, attr
            elif name in bare or not attributes.get(name):  # a module object used as a value: all of it
                yield target, None
            else:  # `est.run`: the attributes used
                yield from (_module_of(target, a, src) for a in sorted(attributes[name]))


def _cache_file(path: Path) -> Path:
    return path.parent / "__pycache__" / f"{path.stem}.codedeps.json"


@functools.lru_cache(maxsize=None)
def _summary(module: str, src: Path) -> dict:
    """:func:`_summarise`, kept beside the module's byte code (``__pycache__/<name>.codedeps.json``)
    and reused while the file's size and modification time are unchanged: parsing every module
    whole at each workflow start-up would cost about a second."""
    path = module_file(module, src)
    if path is None:
        return {"defs": {}, "imports": {}, "star": []}
    stat = path.stat()
    key = [stat.st_mtime_ns, stat.st_size, 1]
    cache = _cache_file(path)
    try:
        cached = json.loads(cache.read_text())
        if cached.get("key") == key:
            return cached["summary"]
    except (OSError, ValueError):
        pass
    summary = _summarise(module, src)
    try:
        cache.parent.mkdir(exist_ok=True)
        tmp = cache.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"key": key, "summary": summary}))
        os.replace(tmp, cache)
    except OSError:  # a read-only checkout: no cache
        pass
    return summary


def top_level_names(module: str, src: Path = _SRC) -> set[str]:
    """The names a module defines at its top level (functions, classes, assignments; not its imports).

    Read from the summary cached beside the module's byte code, so that checking a step list's
    functions at every workflow start-up parses no module that has not changed.

    Parameters
    ----------
    module : str
        A dotted module name.
    src : Path
        The directory that holds the package.

    Returns
    -------
    set of str
        The names (empty for a module that does not exist).
    """
    return set(_summary(module, Path(src))["defs"])


def function_closure(func_spec: str, src: Path = _SRC) -> list[str]:
    """Package modules whose code ``func_spec`` can reach, sorted (parent packages included).

    Parameters
    ----------
    func_spec : str
        ``"netrepro.module:function"`` (a module alone: its module-level import closure).
    src : Path
        The directory that holds the package.

    Returns
    -------
    list of str
        The modules defining a name the function reaches, transitively, and their parent packages.
    """
    src = Path(src)
    module, _, name = func_spec.partition(":")
    if not name:
        return module_closure(module, src)
    modules: set[str] = set()
    seen: set[tuple] = set()
    stack: list[tuple[str, str | None]] = [(module, name)]
    while stack:
        mod, attr = stack.pop()
        if (mod, attr) in seen or not _own(mod):
            continue
        seen.add((mod, attr))
        if module_file(mod, src) is None:
            continue
        modules.add(mod)
        summary = _summary(mod, src)
        if attr is None:  # the module object itself is used as a value: everything it imports counts
            modules.update(module_closure(mod, src))
        elif attr in summary["defs"]:
            stack.extend((m, a) for m, a in summary["defs"][attr])
        elif attr in summary["imports"]:  # a re-export (`from .x import f` in this module)
            stack.append(_module_of(*summary["imports"][attr], src))
        else:
            stack.extend((m, None) for m in summary["star"])  # perhaps bound by a star import
    return sorted({parent for mod in modules for parent in _with_parents(mod) if module_file(parent, src)})


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
        Paths ``<root>/netrepro/...py`` of the function's closure (:func:`function_closure`) and of
        the runner's import closure.

    Raises
    ------
    ValueError
        If the module does not exist in the package.
    """
    module = func_spec.split(":", 1)[0]
    if module_file(module, Path(src)) is None:
        raise ValueError(f"{func_spec!r}: no module {module!r} under {src}")
    modules = sorted(set(function_closure(func_spec, src)) | set(module_closure(RUNNER_MODULE, src)))
    return [str(Path(root) / module_file(m, Path(src)).relative_to(Path(src))) for m in modules]
