"""The paper registry: ``papers.yaml`` beside this module, the one list of the papers (issue 30).

Every list of papers is read from it: the Snakefile's includes, the configuration schema's
``papers`` (checked against it by :func:`schema_mismatches`), the report's and the README's
titles, ``CITATION.cff`` and the report's "Cite the originals" (:mod:`netrepro.references`), and
the tests' slug lists. No module that a pipeline step imports reads it, so a title fix reruns the
report only, and adding a paper reruns nothing of the others.
"""

from __future__ import annotations

import keyword
from functools import lru_cache
from pathlib import Path

import yaml

from .errors import ConfigError

__all__ = ["REGISTRY_FILE", "REQUIRED_FIELDS", "load_registry", "paper_slugs", "valid_slug", "registry_entry_text",
           "schema_mismatches"]

REGISTRY_FILE = Path(__file__).with_name("papers.yaml")
REQUIRED_FIELDS = ("source", "title", "authors", "citation")
_CITATION_FIELDS = ("type", "title", "authors")


def valid_slug(slug: str) -> bool:
    """Whether ``slug`` can name a paper: a lower-case Python identifier that is not a keyword.

    Parameters
    ----------
    slug : str
        The candidate slug.

    Returns
    -------
    bool
        True for a lower-case identifier that is not a keyword and does not start with ``_``.
    """
    return slug.isidentifier() and not keyword.iskeyword(slug) and slug == slug.lower() and not slug.startswith("_")


def _validate(path: Path, data) -> dict:
    if not isinstance(data, dict) or not data:
        raise ConfigError(f"{path}: the registry must map each paper's slug to its entry")
    for slug, entry in data.items():
        if not valid_slug(str(slug)):
            raise ConfigError(f"{path}: paper {slug!r}: a slug must be a lower-case Python identifier")
        if not isinstance(entry, dict):
            raise ConfigError(f"{path}: paper {slug!r}: the entry must be a mapping of {list(REQUIRED_FIELDS)}")
        missing = [k for k in REQUIRED_FIELDS if not entry.get(k)]
        if missing:
            raise ConfigError(f"{path}: paper {slug!r} lacks {missing}")
        cite = entry["citation"]
        missing = [k for k in _CITATION_FIELDS if not (isinstance(cite, dict) and cite.get(k))]
        if missing:
            raise ConfigError(f"{path}: paper {slug!r}: citation lacks {missing}")
    return data


@lru_cache(maxsize=16)
def _load(path: str, stamp: tuple) -> dict:
    file = Path(path)
    return _validate(file, yaml.safe_load(file.read_text()))


def load_registry(path: str | Path = REGISTRY_FILE) -> dict:
    """Slug -> entry (``source``, ``title``, ``authors``, ``citation``), in the registry's order.

    The file is read again when it changed (its modification time or size).

    Parameters
    ----------
    path : str or pathlib.Path, default REGISTRY_FILE
        The registry file (``src/netrepro/papers.yaml``).

    Returns
    -------
    dict of str to dict
        Each paper's entry, keyed by its slug (a shallow copy of the cached mapping).

    Raises
    ------
    ConfigError
        When the file is missing, a slug is not a valid identifier, or an entry lacks a field.
    """
    file = Path(path).resolve()
    if not file.is_file():
        raise ConfigError(f"paper registry {file} not found")
    stat = file.stat()  # an edited file is read again
    return dict(_load(str(file), (stat.st_mtime_ns, stat.st_size)))


def paper_slugs(path: str | Path = REGISTRY_FILE) -> list[str]:
    """The registered slugs, in the registry's order.

    Parameters
    ----------
    path : str or pathlib.Path, default REGISTRY_FILE
        The registry file.

    Returns
    -------
    list of str
        The slugs.

    Raises
    ------
    ConfigError
        When the registry cannot be read (see :func:`load_registry`).
    """
    return list(load_registry(path))


def registry_entry_text(slug: str, title: str, source: str, authors: str = "") -> str:
    """The YAML text of a new registry entry (appended by ``new-paper``), every field commented.

    The citation's authors are placeholders (``TODO``) and ``venue_checked`` is false; a comment
    line above the entry says what to fill in.

    Parameters
    ----------
    slug : str
        The paper's slug.
    title : str
        The paper's title (the entry's and the citation's).
    source : str
        The paper's source text.
    authors : str, default ""
        The authors, one line; ``"TODO: the authors"`` when empty.

    Returns
    -------
    str
        The entry's YAML text, starting with its comment line.
    """
    entry = {slug: {"source": source, "title": title, "authors": authors or "TODO: the authors",
                    "citation": {"type": "article", "title": title,
                                 "authors": [{"family-names": "TODO", "given-names": "TODO"}],
                                 "venue_checked": False}}}
    return ("# added by `python -m netrepro new-paper`: fill in authors and citation (CFF persons, year, venue)\n"
            + yaml.safe_dump(entry, sort_keys=False, allow_unicode=True, width=110))


def schema_mismatches(schema: dict, slugs) -> list[str]:
    """Where the configuration schema's paper list differs from the registry.

    Parameters
    ----------
    schema : dict
        The parsed ``workflow/schemas/config.schema.yaml``.
    slugs : iterable of str
        The registered slugs.

    Returns
    -------
    list of str
        One message per difference (empty when the schema lists exactly the registered papers,
        each with its ``$ref`` section).
    """
    slugs = list(slugs)
    props = schema.get("properties", {})
    enum = list(props.get("papers", {}).get("items", {}).get("enum", []))
    problems = []
    for slug in slugs:
        if slug not in enum:
            problems.append(f"paper {slug!r} is registered but not in the schema's papers enum")
        if props.get(slug, {}).get("$ref") != f"{slug}.schema.yaml":
            problems.append(f"paper {slug!r} has no section {{$ref: {slug}.schema.yaml}} in the schema")
    problems += [f"schema lists paper {slug!r}, which is not registered" for slug in enum if slug not in slugs]
    return problems
