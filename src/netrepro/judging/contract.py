"""The paper contract as a command: ``python -m netrepro check-paper SLUG`` (issue 30).

``docs/adding-a-paper.md`` describes the shape every paper has. :func:`check_paper` checks it by
reading the files (nothing is imported or run), and names the file and line of each violation:

* ``roles``: the package roles, data files, step list (steps.yaml), captions, schema section, registry entry,
  tests and committed reference tables are present;
* ``figures-imports``: ``figures.py`` imports neither the model nor the steps;
* ``analysis-role``: ``analysis.py`` (optional: the mathematics only the evidence quotes, see
  :data:`ANALYSIS`) is imported by ``evidence.py`` and by no step or figure module;
* ``math-io``: math modules do no file IO and import no pandas;
* ``public-api``: every public top-level function is in ``__all__``, and every function of a math
  module in ``__all__`` has numpydoc sections (``Parameters`` when it takes arguments, ``Returns``
  or ``Yields`` when it returns a value);
* ``claim-quantity``: every claim and finding names an evidence quantity that the evidence step
  produces (the built ``results/evidence/<slug>.csv`` when it is no older than the paper's code and
  data files, else a string in ``evidence.py``);
* ``findings-gate``: the data files load as the workflow loads them (schemas, cross-checks, every
  finding's rule registered in ``findings.lock`` or amended); with a current evidence table, no
  statement types a number that is one of its evidence values, and no numeric rule that agrees
  with our value lacks an independent source of its threshold (issue 37);
* ``figure-spec``: every figure of ``figures.yaml`` has its plotting function and a caption;
* ``steps``: the step list ``steps.yaml`` loads as the workflow loads it (schema, every input naming a
  step declared above and an output of it, no output path twice, every function defined in its module);
* ``rule-name``: every rule of a hand-written ``workflow/rules/<slug>.smk`` (optional) starts with the slug;
* ``config-key``: every configuration key a step of ``steps.yaml`` reads (and every key a hand-written
  rule picks) is in the paper's schema;
* ``config-reference``: every configuration key that the paper's data files name in their text, as
  ``(config <key>`` (e.g. ``range: "... (config evidence.low_snr_db)"``), is in the paper's section of
  ``config/config.yaml`` and ``config/test.yaml``: a dotted key as a path from the section (or, when it
  starts with the slug, from the configuration's root), a bare key at any depth of the section. Reconstruction keys, ``at`` settings and variant labels are not configuration
  paths by definition (``steady_state``, ``Z22``, ``p``, ``steer_on_truth``), so they are not checked;
* ``whole-section``: no step of ``steps.yaml`` reads the paper's configuration section whole (a
  ``config`` mapping with neither ``from`` nor ``keys``), and no hand-written rule's params pass the
  section (or the whole configuration) whole: a step gets only the keys it reads (issue 39).
"""

from __future__ import annotations

import ast
import csv
import re
from dataclasses import dataclass
from pathlib import Path

import yaml

from ..pipeline.registry import load_registry, schema_mismatches

__all__ = ["Violation", "ROLES", "OPTIONAL_ROLES", "ANALYSIS", "DATA_FILES", "NOT_MATH", "check_paper", "math_modules",
           "main"]

ROLES = ("__init__.py", "model.py", "steps.py", "evidence.py", "figures.py", "checks.py")
# the one role name of the papers' evidence mathematics: independent computations that only the evidence
# step quotes (errata residuals, readings of the report's curves, brute-force checks), a math module
ANALYSIS = "analysis.py"
# roles a paper has when it needs them: the evidence mathematics, and the bookkeeping of sharded steps
OPTIONAL_ROLES = (ANALYSIS, "shards.py")
DATA_FILES = ("claims.yaml", "errata.yaml", "reconstructions.yaml", "findings.yaml", "figures.yaml")
# shards.py (optional): which cases a sharded step runs and how its shard files merge back (IO, no mathematics)
NOT_MATH = {"__init__", "steps", "evidence", "figures", "checks", "shards"}
# method names that only file IO uses; `load`/`save` only on numpy (an LLVM builder's load is no IO)
_IO_METHODS = {"read_csv", "to_csv", "read_text", "write_text", "read_bytes", "write_bytes", "savez",
               "savez_compressed", "loadtxt", "savetxt", "genfromtxt", "read_parquet", "to_parquet", "safe_load",
               "safe_dump", "tofile", "fromfile"}
_NUMPY_IO = {"load", "save"}
_IO_MODULES = {"pandas", "json", "yaml", "pickle", "csv", "shutil"}


@dataclass(frozen=True)
class Violation:
    """One breach of the contract: where it is and what is wrong.

    Printed as ``path:line: [check] message``.

    Parameters
    ----------
    path : str
        The file (or folder) in breach, relative to the repository's root where possible.
    line : int
        The line of the breach in ``path``; 0 when it concerns the whole file.
    check : str
        The name of the check that found it (e.g. ``"roles"``).
    message : str
        What is wrong, in one line.
    """

    path: str
    line: int
    check: str
    message: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: [{self.check}] {self.message}"


def _rel(path: Path, root: Path) -> str:
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)


def math_modules(package: Path) -> list[Path]:
    """The paper's math modules: every module of its package but the non-math roles.

    Parameters
    ----------
    package : pathlib.Path
        The paper's package folder (``src/netrepro/papers/<slug>``).

    Returns
    -------
    list of pathlib.Path
        The package's ``*.py`` files whose stem is not in ``NOT_MATH``, sorted.
    """
    return sorted(p for p in package.glob("*.py") if p.stem not in NOT_MATH)


def _check_analysis_role(pkg: Path, root: Path) -> list[Violation]:
    """``analysis.py``, when present, is the evidence's: ``evidence.py`` imports it, no step or figure module does."""
    analysis = pkg / ANALYSIS
    if not analysis.is_file():
        return []
    stem = Path(ANALYSIS).stem

    def imports_analysis(path: Path) -> int:
        """The first line of ``path`` that imports the paper's analysis module (0: none)."""
        if not path.is_file():
            return 0
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.ImportFrom) and node.level == 1 and (
                    node.module == stem or node.module is None and any(a.name == stem for a in node.names)):
                return node.lineno
            if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").endswith(
                    f"papers.{pkg.name}.{stem}"):
                return node.lineno
        return 0

    out = []
    if not imports_analysis(pkg / "evidence.py"):
        out.append(Violation(_rel(analysis, root), 0, "analysis-role",
                             f"{ANALYSIS} holds the mathematics the evidence quotes, but evidence.py does not import it"))
    for name in ("steps.py", "figures.py"):
        line = imports_analysis(pkg / name)
        if line:
            out.append(Violation(_rel(pkg / name, root), line, "analysis-role",
                                 f"{name} imports {ANALYSIS} (the evidence's mathematics): move what it needs to "
                                 "model.py or a concept-named math module"))
    return out


def _check_roles(slug: str, root: Path) -> list[Violation]:
    pkg = root / "src/netrepro/papers" / slug
    out = [Violation(_rel(pkg / name, root), 0, "roles", f"missing: the paper's {name}")
           for name in (*ROLES, *DATA_FILES) if not (pkg / name).is_file()]
    required = {
        pkg / "steps.yaml": "the paper's step list (its compute rules are generated from it)",
        root / "workflow/schemas" / f"{slug}.schema.yaml": "the paper's configuration schema",
        root / "workflow/notebooks" / f"{slug}.ipynb": "the paper's notebook (python -m netrepro report make-notebook)",
        root / "tests/papers" / slug: "the paper's tests (tests/papers/<slug>/)",
        root / "tests/reference" / slug: f"the committed reference tables (tests/reference/<slug>/): after a "
                                          f"checked build (`make report`), `make update-references PAPER={slug}` "
                                          "writes them; then commit them",
    }
    out += [Violation(_rel(path, root), 0, "roles", f"missing: {what}") for path, what in required.items()
            if not path.exists()]
    registry = root / "src/netrepro/papers.yaml"
    entries = load_registry(registry)
    if slug not in entries:
        out.append(Violation(_rel(registry, root), 0, "roles", f"paper {slug!r} is not registered"))
    else:
        # the check of tests/test_release_files.py: the citation's authors are the registry's authors
        entry = entries[slug]
        family = [a.get("family-names", "") for a in entry.get("citation", {}).get("authors", [])]
        if family and not any(name and name in str(entry.get("authors", "")) for name in family):
            out.append(Violation(_rel(registry, root), _line_of(registry.read_text(), f"{slug}:"), "citation",
                                 f"{slug}: the citation's authors ({', '.join(family)}) do not appear in its "
                                 f"authors line ({entry.get('authors')!r}): fill in citation.authors too, then "
                                 "`python -m netrepro citations CITATION.cff`"))
    schema_file = root / "workflow/schemas/config.schema.yaml"
    schema = yaml.safe_load(schema_file.read_text())
    out += [Violation(_rel(schema_file, root), 0, "roles", msg)
            for msg in schema_mismatches(schema, load_registry(registry)) if repr(slug) in msg]
    for section in ("config/config.yaml", "config/test.yaml"):
        cfg = yaml.safe_load((root / section).read_text()) or {}
        if slug not in cfg:
            out.append(Violation(section, 0, "roles", f"no configuration section {slug!r}"))
    return out


def _imports(tree: ast.AST):
    """(module name, line) of every import, relative imports resolved to their last part."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level and not base:
                for alias in node.names:
                    yield alias.name, node.lineno
            else:
                yield base, node.lineno


def _check_figures_imports(slug: str, pkg: Path, root: Path) -> list[Violation]:
    path = pkg / "figures.py"
    if not path.is_file():
        return []
    forbidden = {"model", "steps"}
    out = []
    for name, line in _imports(ast.parse(path.read_text())):
        last = name.split(".")[-1]
        if last in forbidden and (name in forbidden or name.startswith(f"netrepro.papers.{slug}.")):
            out.append(Violation(_rel(path, root), line, "figures-imports",
                                 f"figures.py imports {name!r}: figures read tables, never the model or the steps"))
    return out


def _check_math_io(pkg: Path, root: Path) -> list[Violation]:
    out = []
    for path in math_modules(pkg):
        tree = ast.parse(path.read_text())
        for name, line in _imports(tree):
            if name.split(".")[0] in _IO_MODULES:
                out.append(Violation(_rel(path, root), line, "math-io",
                                     f"math module imports {name!r}: no pandas and no file IO in the equations"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                func = node.func
                owner = getattr(func.value, "id", "") if isinstance(func, ast.Attribute) else ""
                name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
                if (name == "open" and not owner) or name in _IO_METHODS or (
                        name in _NUMPY_IO and owner in ("np", "numpy")):
                    out.append(Violation(_rel(path, root), node.lineno, "math-io",
                                         f"math module calls {name}(): file IO belongs in steps.py"))
    return out


def _module_all(tree: ast.Module) -> list[str] | None:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets) and node.value is not None:
            try:
                return list(ast.literal_eval(node.value))
            except ValueError:
                return None
    return None


def _sections(doc: str) -> set[str]:
    lines = [line.strip() for line in (doc or "").splitlines()]
    return {line for line, nxt in zip(lines, lines[1:]) if line and nxt and set(nxt) == {"-"} and len(nxt) == len(line)}


def _returns_value(func: ast.FunctionDef) -> bool:
    for node in ast.walk(func):
        if isinstance(node, (ast.Yield, ast.YieldFrom)):
            return True
        if isinstance(node, ast.Return) and node.value is not None and not (
                isinstance(node.value, ast.Constant) and node.value.value is None):
            return True
    return False


def _check_public_api(pkg: Path, root: Path) -> list[Violation]:
    out = []
    math = {p.stem for p in math_modules(pkg)}
    for path in sorted(pkg.glob("*.py")):
        tree = ast.parse(path.read_text())
        names = _module_all(tree)
        if names is None:
            if path.stem != "__init__":
                out.append(Violation(_rel(path, root), 1, "public-api", "module has no literal __all__"))
            continue
        for node in tree.body:
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) or node.name.startswith("_"):
                continue
            if node.name not in names:
                out.append(Violation(_rel(path, root), node.lineno, "public-api",
                                     f"public function {node.name!r} is not in __all__ (add it, or prefix it with _)"))
                continue
            if path.stem not in math:
                continue
            doc = ast.get_docstring(node) or ""
            sections = _sections(doc)
            args = [a.arg for a in (*node.args.posonlyargs, *node.args.args, *node.args.kwonlyargs)
                    if a.arg not in ("self", "cls")] + [a.arg for a in (node.args.vararg, node.args.kwarg) if a]
            if args and "Parameters" not in sections:
                out.append(Violation(_rel(path, root), node.lineno, "public-api",
                                     f"{node.name}() has no numpydoc 'Parameters' section"))
            if _returns_value(node) and not sections & {"Returns", "Yields"}:
                out.append(Violation(_rel(path, root), node.lineno, "public-api",
                                     f"{node.name}() has no numpydoc 'Returns' section"))
    return out


def _line_of(text: str, needle: str) -> int:
    pos = text.find(needle)
    return text.count("\n", 0, pos) + 1 if pos >= 0 else 0


def _current(built: Path, pkg: Path) -> bool:
    """Whether a built table exists and is no older than the paper's code and data files (else it is stale)."""
    if not built.is_file():
        return False
    sources = [p for p in pkg.iterdir() if p.suffix in (".py", ".yaml", ".lock")]
    return all(built.stat().st_mtime >= p.stat().st_mtime for p in sources)


def _evidence_quantities(slug: str, pkg: Path, root: Path):
    """(set of quantities, how they were found, a matcher for quantities built by f-strings)."""
    built = root / "results/evidence" / f"{slug}.csv"
    if _current(built, pkg):
        with built.open(newline="") as handle:
            return {row["quantity"] for row in csv.DictReader(handle)}, [], "results/evidence"
    path = pkg / "evidence.py"
    if not path.is_file():
        return set(), [], "evidence.py"
    tree = ast.parse(path.read_text())
    literals = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    # netrepro.judging.verdicts.erratum_evidence("<id>", ...) names <id>.residual_printed and <id>.residual_corrected
    for node in ast.walk(tree):
        if (isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) == "erratum_evidence"
                and node.args and isinstance(node.args[0], ast.Constant)):
            literals |= {f"{node.args[0].value}.residual_printed", f"{node.args[0].value}.residual_corrected"}
    prefixes = []
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            fixed = "".join(v.value for v in node.values if isinstance(v, ast.Constant))
            if len(fixed) < 3:  # f"{name}" could be anything: it proves no quantity
                continue
            parts = [re.escape(v.value) if isinstance(v, ast.Constant) else ".+" for v in node.values]
            prefixes.append(re.compile("^" + "".join(parts) + "$"))
    return literals, prefixes, "evidence.py"


def _check_quantities(slug: str, pkg: Path, root: Path) -> list[Violation]:
    known, patterns, where = _evidence_quantities(slug, pkg, root)
    out = []
    for data in ("claims.yaml", "findings.yaml"):
        path = pkg / data
        if not path.is_file():
            continue
        text = path.read_text()
        for entry in yaml.safe_load(text) or []:
            names = []
            ours = entry.get("ours") or {}
            if ours.get("quantity"):
                names.append(ours["quantity"])
            if data == "findings.yaml":
                names += [entry["quantity"]] if entry.get("quantity") else []
                names += list(entry.get("evidence_quantities") or [])
            for name in names:
                if name in known or any(p.match(name) for p in patterns):
                    continue
                out.append(Violation(_rel(path, root), _line_of(text, f"id: {entry.get('id')}"), "claim-quantity",
                                     f"{entry.get('id')}: quantity {name!r} is not produced by the evidence step "
                                     f"(looked in {where})"))
    return out


def _check_findings_gate(slug: str, pkg: Path, root: Path) -> list[Violation]:
    """The verdict gate of issue 37 on the paper's data: files valid, rules registered, statements from evidence.

    The data files are loaded as the workflow loads them (schema, cross-checks, ``findings.lock``);
    with a built evidence table no older than ``findings.yaml``, every finding's statement is
    checked for a typed number that is one of its evidence values (a self-referential statement)
    and every numeric rule whose asserted value equals our value within its tolerance must name
    an independent source of its threshold.
    """
    from ..errors import NetreproError
    from .paperdata import load_paper_data, typed_numbers
    from .verdicts import NOMINAL, agrees, read_evidence

    findings_path = pkg / "findings.yaml"
    try:
        data = load_paper_data(slug, pkg)
    except NetreproError as exc:
        return [Violation(_rel(findings_path, root), 0, "findings-gate", str(exc).replace("\n", " "))]
    built = root / "results/evidence" / f"{slug}.csv"
    if not findings_path.is_file() or not _current(built, pkg):
        return []
    evidence = read_evidence(built)
    text = findings_path.read_text()
    out = []
    for f in data.findings:
        line = _line_of(text, f"id: {f.finding_id}")
        values = {q: evidence[q][NOMINAL][0] for q in f.evidence_quantities if NOMINAL in evidence.get(q, {})}
        typed = typed_numbers(f.statement, values)
        if typed:
            out.append(Violation(_rel(findings_path, root), line, "findings-gate",
                                 f"{f.finding_id}: the statement types {', '.join(typed)}; write a template field "
                                 "({quantity:.2f}) so it is filled from the evidence"))
        rules = [f.registered_rule, f] if f.amendments else [f]
        for rule in rules[-1:]:
            ours = evidence.get(rule.quantity, {}).get(NOMINAL)
            if rule.kind == "numeric" and ours is not None and agrees(rule, ours) and not rule.source:
                out.append(Violation(_rel(findings_path, root), line, "findings-gate",
                                     f"{f.finding_id}: the rule's threshold {rule.asserted:g} equals our value within "
                                     "its tolerance and names no independent source (rule.source: paper, limit, "
                                     "control or effect_size): it only checks our own rounding; make it an "
                                     "observation or give the source"))
    return out


def _check_figures(slug: str, pkg: Path, root: Path) -> list[Violation]:
    spec_path, fig_path = pkg / "figures.yaml", pkg / "figures.py"
    if not spec_path.is_file():
        return []
    text = spec_path.read_text()
    specs = yaml.safe_load(text) or {}
    functions = set()
    if fig_path.is_file():
        functions = {n.name for n in ast.parse(fig_path.read_text()).body if isinstance(n, ast.FunctionDef)}
    out = []
    for figure_id, spec in specs.items():
        line = _line_of(text, f"{figure_id}:")
        plot = (spec or {}).get("plot")
        if plot not in functions:
            out.append(Violation(_rel(spec_path, root), line, "figure-spec",
                                 f"{figure_id}: plotting function {plot!r} is not defined in figures.py"))
        caption = root / "workflow/report" / slug / f"{figure_id}.rst"
        if not caption.is_file():
            out.append(Violation(_rel(spec_path, root), line, "figure-spec",
                                 f"{figure_id}: no caption {_rel(caption, root)}"))
    return out


_RULE = re.compile(r"^rule\s+(\w+)\s*:", re.M)


def _check_rule_names(slug: str, root: Path) -> list[Violation]:
    path = root / "workflow/rules" / f"{slug}.smk"
    if not path.is_file():
        return []
    text = path.read_text()
    return [Violation(_rel(path, root), text.count("\n", 0, m.start()) + 1, "rule-name",
                      f"rule {m.group(1)!r} does not start with '{slug}_'")
            for m in _RULE.finditer(text) if not m.group(1).startswith(f"{slug}_")]


def _calls(text: str, name: str):
    """(offset, source) of every call ``name(...)`` in ``text``, by balanced parentheses."""
    for m in re.finditer(rf"\b{name}\(", text):
        depth, i = 0, m.end() - 1
        while i < len(text):
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            if depth == 0:
                yield m.start(), text[m.start():i + 1]
                break
            i += 1


def _tuple_constants(text: str) -> dict:
    out = {}
    for m in re.finditer(r"^([A-Z_][A-Z0-9_]*)\s*=\s*(\([^()]*\)|\[[^\[\]]*\])", text, re.M):
        try:
            value = ast.literal_eval(m.group(2))
        except (ValueError, SyntaxError):
            continue
        if isinstance(value, (tuple, list)) and all(isinstance(v, str) for v in value):
            out[m.group(1)] = list(value)
    return out


def _check_config_keys(slug: str, root: Path) -> list[Violation]:
    path = root / "workflow/rules" / f"{slug}.smk"
    schema_path = root / "workflow/schemas" / f"{slug}.schema.yaml"
    if not (path.is_file() and schema_path.is_file()):
        return []
    text = path.read_text()
    schema = yaml.safe_load(schema_path.read_text())
    constants = _tuple_constants(text)
    out = []
    for offset, source in _calls(text, "pick"):
        try:
            call = ast.parse(source, mode="eval").body
        except SyntaxError:
            continue
        section = [n.value for n in ast.walk(call.args[0]) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
        node = schema
        for key in section:
            node = (node.get("properties") or {}).get(key, {})
        props = node.get("properties") or {}
        keys = []
        for arg in call.args[1:]:
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                keys.append(arg.value)
            elif isinstance(arg, ast.Starred) and isinstance(arg.value, ast.Name):
                keys += constants.get(arg.value.id, [])
        where = ".".join([slug, *section])
        for key in keys:
            if key not in props:
                out.append(Violation(_rel(path, root), text.count("\n", 0, offset) + 1, "config-key",
                                     f"the rule passes {where}.{key} to its step, but "
                                     f"{_rel(schema_path, root)} does not define it"))
    return out


def _params_blocks(text: str):
    """(start, end) offsets of the body of every ``params:`` block of a rules file (by indentation)."""
    lines = text.splitlines(keepends=True)
    starts = [0]
    for line in lines:
        starts.append(starts[-1] + len(line))
    for i, line in enumerate(lines):
        m = re.match(r"^(\s*)params:\s*(#.*)?$", line)
        if not m:
            continue
        indent, j = len(m.group(1)), i + 1
        while j < len(lines) and (not lines[j].strip() or len(lines[j]) - len(lines[j].lstrip()) > indent):
            j += 1
        yield starts[i + 1], starts[j]


def _first_argument(source: str) -> tuple[int, int]:
    """(start, end) offsets in ``source`` (a call ``name(...)``) of its first argument."""
    start = source.index("(") + 1
    depth = 0
    for i in range(start, len(source)):
        ch = source[i]
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            if depth == 0:
                return start, i
            depth -= 1
        elif ch == "," and depth == 0:
            return start, i
    return start, len(source)


# one key taken of a mapping, at the start of the text: ["key"] / [expr] or .get("key", ...) / .get(expr, ...)
_ACCESSOR = re.compile(r"""\s*(?:\[\s*["']?([^\[\]"']*)["']?\s*\]|\.get\(\s*["']?([^,()"']*)["']?[^()]*\))""")


def _check_whole_section(slug: str, root: Path) -> list[Violation]:
    """Rules whose params pass a whole configuration section (or the whole configuration) to their step.

    A step's params carry only the keys it reads (``pick(SECTION, "key", ...)``): a section passed whole
    reruns the step on an edit of any key of it (issue 39). In a ``params:`` block, the paper's section (a
    name bound to ``config.get("<slug>", ...)`` or ``config["<slug>"]``, or that expression itself) and
    ``config`` are mentioned only as the first argument of a ``pick`` call or to take one key of them
    (``SECTION["key"]``, ``SECTION.get("key", ...)``: an entry of the section, for a step that reads it all).
    """
    path = root / "workflow/rules" / f"{slug}.smk"
    if not path.is_file():
        return []
    text = path.read_text()
    names = set(re.findall(rf"^(\w+)\s*=\s*config(?:\.get\(\s*|\[\s*)[\"']{re.escape(slug)}[\"']", text, re.M))
    names.add("config")
    pattern = re.compile(r"(?<![\w.])(" + "|".join(sorted(map(re.escape, names))) + r")\b")
    out = []
    for start, end in _params_blocks(text):
        block = text[start:end]
        allowed = []
        for offset, source in _calls(block, "pick"):
            a, b = _first_argument(source)
            allowed.append((offset + a, offset + b))
        for m in pattern.finditer(block):
            line_text = block[block.rfind("\n", 0, m.start()) + 1:m.start()]
            if "#" in line_text or any(a <= m.start() < b for a, b in allowed):
                continue
            keys, pos = [], m.end()
            while len(keys) < 2 and (a := _ACCESSOR.match(block, pos)):
                keys.append((a.group(1) or a.group(2) or "").strip())
                pos = a.end()
            if m.group(1) == "config" and keys[:1] == [slug]:
                keys = keys[1:]  # config["<slug>"] is the section itself
            if keys:
                continue
            expr = re.sub(r"\s+", "", block[m.start():pos])
            out.append(Violation(_rel(path, root), text.count("\n", 0, start + m.start()) + 1, "whole-section",
                                 f"the params pass {expr} whole: pass only the keys the step reads, "
                                 f"pick({expr}, \"key\", ...)"))
    return out


def _step_configs(entry: dict):
    """(where, declaration) of the configuration a step of steps.yaml reads, and of its shard's."""
    yield "", entry.get("config", [])
    if isinstance(entry.get("shard"), dict):
        yield "shard ", entry["shard"].get("config", [])


def _picks(config):
    """Every pick of a ``config`` declaration: ``(from, keys)``; ``keys`` None for a whole entry."""
    if isinstance(config, list):
        yield None, config
    elif isinstance(config, dict) and "fields" in config:
        for part in (config["fields"] or {}).values():
            yield from _picks(part)
    elif isinstance(config, dict):
        yield config.get("from"), config.get("keys")
        for part in config.get("merge") or []:
            yield from ([(None, [part])] if isinstance(part, str) else _picks(part))


def _check_steps(slug: str, pkg: Path, root: Path) -> list[Violation]:
    """The step list: it loads (``steps``), reads no whole section (``whole-section``) and only the schema's keys."""
    from ..errors import NetreproError
    from ..pipeline.stepspec import load_step_specs

    path = pkg / "steps.yaml"
    if not path.is_file():
        return []
    rel, text = _rel(path, root), path.read_text()
    out = []
    try:
        load_step_specs(slug, pkg.parents[1], root=root)
    except NetreproError as exc:
        out.append(Violation(rel, 0, "steps", str(exc).replace(str(path), rel)))
    data = yaml.safe_load(text) or {}
    steps = data.get("steps") if isinstance(data.get("steps"), dict) else {}
    groups = data.get("key_groups") if isinstance(data.get("key_groups"), dict) else {}
    schema_path = root / "workflow/schemas" / f"{slug}.schema.yaml"
    schema = yaml.safe_load(schema_path.read_text()) if schema_path.is_file() else None
    for name, entry in steps.items():
        if not isinstance(entry, dict):
            continue
        line = _line_of(text, f"\n  {name}:") + 1
        for label, config in _step_configs(entry):
            for source, keys in _picks(config):
                if source is None and keys is None:
                    out.append(Violation(rel, line, "whole-section",
                                         f"step {name!r}: the {label}config reads the section {slug!r} whole: "
                                         "list only the keys the step reads (config: [key, ...])"))
                    continue
                if schema is None:
                    continue
                expanded = []
                for key in keys or []:
                    expanded += groups.get(key[1:], []) if str(key).startswith("$") else [key]
                props = schema.get("properties") or {}
                checks = [((), source)] if source is not None else []
                node = props.get(source, {}) if source is not None else None
                inner = (node.get("properties") or {}) if node is not None else props
                checks += [((source,) if source is not None else (), k) for k in expanded]
                for where, key in checks:
                    if key not in (inner if where else props):
                        dotted = ".".join([slug, *where, key])
                        out.append(Violation(rel, line, "config-key",
                                             f"step {name!r}: the {label}config reads {dotted}, but "
                                             f"{_rel(schema_path, root)} does not define it"))
    return out


# a configuration key named in the text of a data file: "(config evidence.low_snr_db", "(config growth_ratio_rtol"
_CONFIG_REFERENCE = re.compile(r"\(config\s+([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)")
_CONFIG_FILES = ("config/config.yaml", "config/test.yaml")


def _strings(value):
    """Every string in a loaded entry (a dataclass, dict, list or scalar), depth first."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for item in value.values():
            yield from _strings(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            yield from _strings(item)
    elif hasattr(value, "__dataclass_fields__"):
        for name in value.__dataclass_fields__:
            yield from _strings(getattr(value, name))


def _resolves(section, key: str) -> bool:
    """Whether ``key`` names an entry of ``section``: a dotted key as a path, a bare key at any depth."""
    if "." not in key:
        stack = [section]
        while stack:
            node = stack.pop()
            if isinstance(node, dict):
                if key in node:
                    return True
                stack.extend(node.values())
        return False
    node = section
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True


def _check_config_references(slug: str, pkg: Path, root: Path) -> list[Violation]:
    """Configuration keys named in the data files' text, ``(config <key>``, that the configurations lack.

    The entries are read as :func:`netrepro.judging.paperdata.load_paper_data` loads them (YAML comments
    are not read); data files that do not load are the ``findings-gate`` check's to report.
    """
    from ..errors import NetreproError
    from .paperdata import load_paper_data

    try:
        data = load_paper_data(slug, pkg)
    except NetreproError:
        return []
    configs = {}
    for name in _CONFIG_FILES:
        path = root / name
        if path.is_file():
            configs[name] = (yaml.safe_load(path.read_text()) or {}).get(slug) or {}
    entries = [("claims.yaml", c.claim_id, "id", c) for c in data.claims]
    entries += [("errata.yaml", e["id"], "id", e) for e in data.errata]
    entries += [("reconstructions.yaml", r["key"], "key", r) for r in data.reconstructions]
    entries += [("findings.yaml", f.finding_id, "id", f) for f in data.findings]
    texts, out = {}, []
    for file, ident, field_name, entry in entries:
        path = pkg / file
        text = texts.setdefault(file, path.read_text() if path.is_file() else "")
        keys = dict.fromkeys(m.group(1) for s in _strings(entry) for m in _CONFIG_REFERENCE.finditer(s))
        for key in keys:
            # "(config <slug>.evidence.x": a path from the configuration's root, i.e. from the section
            inner = key.split(".", 1)[1] if key.startswith(f"{slug}.") else key
            missing = [name for name, section in configs.items() if not _resolves(section, inner)]
            if not missing:
                continue
            how = "a path from" if "." in key else "a key at any depth of"
            start = max(text.find(f"{field_name}: {ident}"), 0)
            found = re.compile(r"\(config\s+" + re.escape(key) + r"\b").search(text, start)
            line = text.count("\n", 0, found.start()) + 1 if found else _line_of(text, f"{field_name}: {ident}")
            out.append(Violation(_rel(path, root), line, "config-reference",
                                 f"{ident}: names the configuration key {key!r} ('(config {key}'), which is not "
                                 f"{how} the {slug!r} section of {' and '.join(missing)}: add the key to the "
                                 "configuration (and its schema) or correct the name"))
    return out


def check_paper(slug: str, root: str | Path = ".") -> list[Violation]:
    """Every breach of the paper contract by paper ``slug`` in the checkout ``root``.

    Parameters
    ----------
    slug : str
        The paper's slug.
    root : str or Path
        The repository's root.

    Returns
    -------
    list of Violation
        Empty when the paper follows the contract.
    """
    root = Path(root).resolve()
    pkg = root / "src/netrepro/papers" / slug
    if not pkg.is_dir():
        return [Violation(_rel(pkg, root), 0, "roles", f"paper {slug!r} has no package")]
    return [*_check_roles(slug, root), *_check_figures_imports(slug, pkg, root), *_check_analysis_role(pkg, root),
            *_check_math_io(pkg, root),
            *_check_public_api(pkg, root), *_check_quantities(slug, pkg, root), *_check_findings_gate(slug, pkg, root),
            *_check_figures(slug, pkg, root), *_check_config_references(slug, pkg, root),
            *_check_steps(slug, pkg, root), *_check_rule_names(slug, root), *_check_config_keys(slug, root),
            *_check_whole_section(slug, root)]


def main(slugs, root: str | Path = ".") -> int:
    """Print every violation of the papers ``slugs`` (all registered ones when empty); 1 if any.

    Each violation is printed on its own line, then one ``check-paper <slug>: ok`` (or
    ``N violation(s)``) line per paper.

    Parameters
    ----------
    slugs : iterable of str
        The papers to check; every paper of the registry (``src/netrepro/papers.yaml``) when empty.
    root : str or pathlib.Path, default "."
        The repository's root.

    Returns
    -------
    int
        The exit code: 1 when any paper has a violation, else 0.
    """
    root = Path(root)
    slugs = list(slugs) or list(load_registry(root / "src/netrepro/papers.yaml"))
    found = 0
    for slug in slugs:
        violations = check_paper(slug, root)
        found += len(violations)
        for v in violations:
            print(v)
        print(f"check-paper {slug}: {'ok' if not violations else f'{len(violations)} violation(s)'}")
    return 1 if found else 0
