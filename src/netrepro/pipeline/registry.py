"""The paper registry: ``papers.yaml`` beside this module, the one list of the papers (issue 30).

Every list of papers is read from it: the Snakefile's includes, the configuration schema's
``papers`` (checked against it by :func:`schema_mismatches`), the report's and the README's
titles, ``CITATION.cff`` and the report's "Cite the originals" (:mod:`netrepro.release.citations`), and
the tests' slug lists. No module that a pipeline step imports reads it, so a title fix reruns the
report only, and adding a paper reruns nothing of the others.
"""

from __future__ import annotations

import datetime as _dt
import keyword
import re
from functools import lru_cache
from pathlib import Path

import yaml

from ..errors import ConfigError

__all__ = ["REGISTRY_FILE", "REQUIRED_FIELDS", "IDENTIFIER_TYPES", "load_registry", "paper_slugs", "valid_slug",
           "registry_entry_text", "schema_mismatches", "identifier_problems", "identifier_url"]

REGISTRY_FILE = Path(__file__).parents[1] / "papers.yaml"
REQUIRED_FIELDS = ("source", "title", "authors", "citation")
_CITATION_FIELDS = ("type", "title", "authors")
# A persistent identifier of a paper: its type, the pattern its value must match, and the URL it resolves at.
IDENTIFIER_TYPES = {
    "doi": (re.compile(r"10\.\d{4,9}/\S+"), "https://doi.org/{}"),
    "arxiv": (re.compile(r"\d{4}\.\d{4,5}(v\d+)?"), "https://arxiv.org/abs/{}"),
}


def identifier_url(ident: dict) -> str:
    """The URL an identifier resolves at: ``https://doi.org/<doi>`` or ``https://arxiv.org/abs/<id>``.

    Parameters
    ----------
    ident : dict
        A registry identifier (``type``, ``value``).

    Returns
    -------
    str
        The resolver URL.
    """
    return IDENTIFIER_TYPES[ident["type"]][1].format(ident["value"])


def identifier_problems(entry: dict) -> list[str]:
    """What is wrong with a registry entry's ``identifiers`` and ``identifier_note``.

    Each paper lists the identifiers verified for it (``identifiers``: type ``doi`` or ``arxiv``,
    ``value``, ``source``: the http(s) URL where it was found, ``checked``: the ISO date of the
    check); a paper without any (an empty list) says why in ``identifier_note``.

    Parameters
    ----------
    entry : dict
        One paper's registry entry.

    Returns
    -------
    list of str
        One message per problem (empty when the entry is well formed).
    """
    if "identifiers" not in entry:
        return ["lacks 'identifiers' (a list; [] with an identifier_note when none was verified)"]
    idents = entry["identifiers"]
    if not isinstance(idents, list):
        return ["'identifiers' must be a list"]
    problems = []
    if not idents and not str(entry.get("identifier_note") or "").strip():
        problems.append("has no identifiers and no identifier_note saying why")
    for i, ident in enumerate(idents):
        where = f"identifiers[{i}]"
        if not isinstance(ident, dict):
            problems.append(f"{where} must be a mapping of type, value, source, checked")
            continue
        kind, value = ident.get("type"), str(ident.get("value") or "")
        if kind not in IDENTIFIER_TYPES:
            problems.append(f"{where}: type {kind!r} is not one of {sorted(IDENTIFIER_TYPES)}")
        elif not IDENTIFIER_TYPES[kind][0].fullmatch(value):
            problems.append(f"{where}: {value!r} is not a {kind} identifier")
        if not re.match(r"https?://\S+$", str(ident.get("source") or "")):
            problems.append(f"{where}: 'source' must be the http(s) URL where the identifier was verified")
        checked = ident.get("checked")
        if isinstance(checked, str):
            try:
                checked = _dt.date.fromisoformat(checked)
            except ValueError:
                checked = None
        if not isinstance(checked, _dt.date):
            problems.append(f"{where}: 'checked' must be the ISO date (YYYY-MM-DD) of the check")
    return problems


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
        if not cite.get("year") and not str(cite.get("year_note") or "").strip():
            raise ConfigError(f"{path}: paper {slug!r}: citation has no year and no year_note saying why")
        problems = identifier_problems(entry)
        if problems:
            raise ConfigError(f"{path}: paper {slug!r}: " + "; ".join(problems))
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
                                 "year_note": "TODO: the year of publication", "venue_checked": False},
                    "identifiers": [],
                    "identifier_note": "TODO: a DOI or arXiv id verified at a named source (with source URL and "
                                       "checked date), or why there is none"}}
    return ("# added by `python -m netrepro new-paper`: fill in authors, citation (CFF persons, year, venue) "
            "and identifiers\n"
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
