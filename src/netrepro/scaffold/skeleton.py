"""``python -m netrepro new-paper SLUG --title ... --source FILE``: a working skeleton of a paper.

The skeleton follows the paper contract (``docs/adding-a-paper.md``, checked by
``python -m netrepro check-paper``): the package with every role and one example each (an
equation, a step, the evidence, a figure, a claim, an erratum, a reconstruction, a finding), its
step list (``steps.yaml``, from which the workflow generates its rules), configuration section and schema, caption, notebook, tests (one per role) and the
registry entry. Right after it, ``make report`` builds the new paper's figure, judges its claim
and shows its section in the report. The templates are in ``templates/`` beside this module.

Every check runs before anything is written: an existing slug, a slug that is not a valid
identifier, or a missing source file stops the command with a message and no file changed.
"""

from __future__ import annotations

import contextlib
import os

import re
from dataclasses import dataclass
from datetime import date
from pathlib import Path
from string import Template

import yaml

from ..errors import InputError
from ..pipeline.io import load_yaml
from ..judging.paperdata import LOCK_FILE, SKELETON_COMMIT, registry_lock_text
from ..pipeline.registry import load_registry, registry_entry_text, valid_slug

__all__ = ["Plan", "SOURCES_DIR", "plan_new_paper", "write_plan", "new_paper", "source_warnings"]

TEMPLATES = Path(__file__).with_name("templates")
# where the registry's ``source`` file names are found, relative to the checkout (src/netrepro/papers.yaml)
SOURCES_DIR = "../shared/papers"
PACKAGE_FILES = ("__init__.py", "model.py", "steps.py", "evidence.py", "figures.py", "checks.py", "figures.yaml",
                 "steps.yaml", "claims.yaml", "errata.yaml", "reconstructions.yaml", "findings.yaml")
TEST_FILES = ("__init__.py", "test_model.py", "test_steps.py", "test_evidence.py", "test_figures.py",
              "test_checks.py")


@dataclass
class Plan:
    """What ``new-paper`` will do: files to create (path -> text) and files to rewrite (path -> new text).

    Parameters
    ----------
    slug : str
        The new paper's slug.
    create : dict of str to str
        The files to create, paths relative to the repository's root; the notebook's text is empty
        (:func:`write_plan` writes it from the report's notebook template).
    rewrite : dict of str to str
        The existing files to rewrite (configurations, configuration schema, registry) and their
        new text.
    """

    slug: str
    create: dict
    rewrite: dict

    def paths(self) -> list[str]:
        return sorted([*self.create, *self.rewrite])


def _render(name: str, values: dict) -> str:
    return Template((TEMPLATES / name).read_text()).substitute(values)


def _add_to_papers_list(path: Path, text: str, slug: str) -> str:
    match = re.search(r"^papers:\s*\[([^\]]*)\]", text, re.M)
    if not match:
        raise InputError(f"{path}: no line 'papers: [...]' to add {slug!r} to")
    items = [s.strip() for s in match.group(1).split(",") if s.strip()]
    return text[:match.start()] + f"papers: [{', '.join([*items, slug])}]" + text[match.end():]


def _add_to_schema(path: Path, text: str, slug: str) -> str:
    match = re.search(r"(\n\s+items:\n\s+enum: \[)([^\]]*)\]", text)
    if not match:
        raise InputError(f"{path}: no 'items: enum: [...]' list of papers to add {slug!r} to")
    items = [s.strip() for s in match.group(2).split(",") if s.strip()]
    text = text[:match.start(2)] + ", ".join([*items, slug]) + text[match.end(2):]
    refs = list(re.finditer(r'^  \w+: \{\$ref: "\w+\.schema\.yaml"\}\n', text, re.M))
    if not refs:
        raise InputError(f"{path}: no paper sections ({{$ref: <slug>.schema.yaml}}) to add {slug!r} after")
    end = refs[-1].end()
    return text[:end] + f'  {slug}: {{$ref: "{slug}.schema.yaml"}}\n' + text[end:]


def _add_config_section(path: Path, text: str, values: dict) -> str:
    """config/README.md with the new paper's section, before the paper-scale section (or at the end)."""
    section = _render("config_readme.md.tmpl", values)
    marker = re.search(r"^## Paper scale", text, re.M)
    if marker is None:
        return text.rstrip("\n") + "\n\n" + section
    return text[:marker.start()] + section + "\n" + text[marker.start():]


def plan_new_paper(slug: str, title: str, source: str | Path, root: str | Path = ".", authors: str = "") -> Plan:
    """Check the request and compute every file ``new-paper`` writes, writing nothing.

    Parameters
    ----------
    slug : str
        The new paper's slug: a lower-case Python identifier not yet registered.
    title : str
        The paper's title.
    source : str or Path
        The paper's source text; it must exist.
    root : str or Path
        The repository's root.
    authors : str
        The authors, one line (the registry says TODO when empty).

    Returns
    -------
    Plan
        The files to create and to rewrite.

    Raises
    ------
    InputError
        When the slug is invalid or taken, the title empty, the source file missing, or a file
        the skeleton would create already exists.
    """
    root = Path(root)
    if not valid_slug(slug):
        raise InputError(f"new-paper: slug {slug!r} is not a valid lower-case Python identifier "
                         "(letters, digits and underscores, not starting with a digit or underscore, not a keyword)")
    registry_path = root / "src/netrepro/papers.yaml"
    if slug in load_registry(registry_path):
        raise InputError(f"new-paper: paper {slug!r} already exists in {registry_path}")
    if not str(title).strip():
        raise InputError("new-paper: --title must not be empty")
    source = Path(source)
    if not source.is_file():
        raise InputError(f"new-paper: source file {source} does not exist")
    values = {"slug": slug, "title": title.strip(), "source": source.name,
              "authors": authors.strip() or "authors to be named (TODO in the registry)"}
    create = {f"src/netrepro/papers/{slug}/{name}": _render(f"package/{name}.tmpl", values) for name in PACKAGE_FILES}
    create |= {f"tests/papers/{slug}/{name}": _render(f"tests/{name}.tmpl", values) for name in TEST_FILES}
    create[f"workflow/schemas/{slug}.schema.yaml"] = _render("schema.yaml.tmpl", values)
    create[f"workflow/report/{slug}/fig1.rst"] = _render("caption.rst.tmpl", values)
    create[f"workflow/notebooks/{slug}.ipynb"] = ""  # written by the report's notebook template
    # the example finding's rule, registered with the skeleton (issue 37): a new finding is registered
    # with `python -m netrepro register-findings` before the runs that test it
    create[f"src/netrepro/papers/{slug}/{LOCK_FILE}"] = registry_lock_text(
        load_yaml(create[f"src/netrepro/papers/{slug}/findings.yaml"]) or [], SKELETON_COMMIT, date.today().isoformat())
    taken = [p for p in create if (root / p).exists()]
    if taken:
        raise InputError(f"new-paper: {taken[0]} already exists (paper {slug!r} is partly there); nothing written")
    section = _render("config.yaml.tmpl", values)
    rewrite = {}
    for cfg in ("config/config.yaml", "config/test.yaml"):
        text = (root / cfg).read_text()
        if slug in (yaml.safe_load(text) or {}):
            raise InputError(f"new-paper: {cfg} already has a section {slug!r}; nothing written")
        rewrite[cfg] = _add_to_papers_list(root / cfg, text, slug).rstrip("\n") + "\n" + section
    schema = "workflow/schemas/config.schema.yaml"
    rewrite[schema] = _add_to_schema(root / schema, (root / schema).read_text(), slug)
    readme = "config/README.md"
    if (root / readme).is_file():
        rewrite[readme] = _add_config_section(root / readme, (root / readme).read_text(), values)
    registry_text = registry_path.read_text()
    rewrite["src/netrepro/papers.yaml"] = (registry_text.rstrip("\n") + "\n"
                                           + registry_entry_text(slug, title.strip(), source.name, authors))
    return Plan(slug, create, rewrite)


def write_plan(plan: Plan, root: str | Path = ".") -> list[str]:
    """Write the files of ``plan`` under ``root``; return their paths.

    Parent folders are created; the notebook is written by :func:`netrepro.report.notebooks.make_notebook`.

    Parameters
    ----------
    plan : Plan
        The files to create and to rewrite (:func:`plan_new_paper`).
    root : str or pathlib.Path, default "."
        The repository's root.

    Returns
    -------
    list of str
        The paths written, relative to ``root``, sorted.
    """
    from ..report.notebooks import make_notebook  # the report's notebook template, imported only when writing

    root = Path(root)
    for rel, text in plan.create.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        if rel.endswith(".ipynb"):
            make_notebook(plan.slug, path)
        else:
            path.write_text(text)
    for rel, text in plan.rewrite.items():
        (root / rel).write_text(text)
    return plan.paths()


def new_paper(slug: str, title: str, source: str | Path, root: str | Path = ".", authors: str = "") -> list[str]:
    """Create the skeleton of paper ``slug`` (see :func:`plan_new_paper`); return the paths written.

    Every check is made before anything is written.

    Parameters
    ----------
    slug : str
        The new paper's slug: a lower-case Python identifier not yet registered.
    title : str
        The paper's title.
    source : str or pathlib.Path
        The paper's source text; it must exist.
    root : str or pathlib.Path, default "."
        The repository's root.
    authors : str, default ""
        The authors, one line (the registry says TODO when empty).

    Returns
    -------
    list of str
        The paths written, relative to ``root``, sorted.

    Raises
    ------
    InputError
        When the request is refused (see :func:`plan_new_paper`).
    """
    written = write_plan(plan_new_paper(slug, title, source, root, authors), root)
    # CITATION.cff lists every paper of the registry; it is written from the registry the package reads
    from ..release.citations import REGISTRY_FILE, main as write_citation

    citation = Path(root) / "CITATION.cff"
    if citation.is_file() and Path(REGISTRY_FILE).resolve() == (Path(root) / "src/netrepro/papers.yaml").resolve():
        with open(os.devnull, "w") as quiet, contextlib.redirect_stdout(quiet):  # new-paper lists what it wrote
            write_citation([str(citation)])
        written = sorted({*written, "CITATION.cff"})
    return written


def source_warnings(source: str | Path, root: str | Path = ".") -> list[str]:
    """Why the registry's ``source`` of a new paper would name no file, if it would.

    The registry records only the source text's file name, looked up in :data:`SOURCES_DIR`
    (``../shared/papers/`` beside the checkout); a source elsewhere leaves that name dangling.

    Parameters
    ----------
    source : str or pathlib.Path
        The ``--source`` file given to ``new-paper``.
    root : str or pathlib.Path, default "."
        The repository's root.

    Returns
    -------
    list of str
        One warning when ``source`` is not in :data:`SOURCES_DIR`, else empty.
    """
    source, expected = Path(source), (Path(root) / SOURCES_DIR).resolve()
    if source.resolve().parent == expected:
        return []
    return [f"warning: {source} is not in {SOURCES_DIR}/ ({expected}), where the registry's source names are "
            f"looked up: the registry records only {source.name!r}, which names no file there; copy the source "
            f"text to {SOURCES_DIR}/{source.name}"]
