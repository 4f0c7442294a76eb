"""The original papers, for citing: the report's "Cite the originals" section and CITATION.cff.

The data are the ``citation`` entries of the paper registry (``papers.yaml``,
:mod:`netrepro.pipeline.registry`; titles and authors from the source texts). :func:`citation_cff` builds the whole ``CITATION.cff`` (this software, with the papers
as ``references``); ``python -m netrepro citations CITATION.cff`` rewrites it, and
``tests/test_release_files.py`` checks that the committed file is this output and that it
validates against the Citation File Format 1.2.0 schema.
"""

from __future__ import annotations

import argparse
import html
import sys
from pathlib import Path

import yaml

from ..pipeline.registry import REGISTRY_FILE, identifier_url, load_registry

__all__ = ["load_references", "load_identifiers", "format_reference", "references_html", "cff_reference",
           "citation_cff", "crate_citations", "SOFTWARE", "main"]

# This software as CITATION.cff describes it (title, licence, version: keep in step with pyproject.toml).
SOFTWARE = {
    "title": "netrepro: reproducing five papers on networked estimation and control",
    "version": "0.1.0",
    "license": "BSD-3-Clause",
    "authors": [{"name": "The netrepro maintainers"}],
    "abstract": ("One Snakemake workflow recomputes every figure and every stated number of five papers on "
                 "Kalman filtering over lossy networks, gain-scheduled filtering, 1-bit Bayesian bounds and "
                 "decentralized H-infinity filtering, checks each number the papers state, and lists every "
                 "equation they print wrong."),
    "keywords": ["reproducibility", "Kalman filtering", "networked control", "Snakemake", "RO-Crate"],
    # the release date of `version` (CFF date-released): change both together
    "date-released": "2026-12-02",
}


def load_references(path: str | Path = REGISTRY_FILE) -> dict:
    """Slug -> reference (``type``, ``title``, ``authors``, optional ``year``, ``venue``, ``underlying``).

    The ``citation`` of every paper of the registry ``path``.

    Parameters
    ----------
    path : str or Path, default REGISTRY_FILE
        The paper registry (``src/netrepro/papers.yaml``).

    Returns
    -------
    dict
        Paper slug -> its ``citation`` entry.
    """
    return {slug: entry["citation"] for slug, entry in load_registry(path).items()}


def load_identifiers(path: str | Path = REGISTRY_FILE) -> dict:
    """Slug -> the paper's verified identifiers (``type``, ``value``, ``source``, ``checked``; maybe empty).

    Parameters
    ----------
    path : str or Path, default REGISTRY_FILE
        The paper registry (``src/netrepro/papers.yaml``).

    Returns
    -------
    dict
        Paper slug -> list of identifier mappings.
    """
    return {slug: list(entry.get("identifiers") or []) for slug, entry in load_registry(path).items()}


def _author(person: dict) -> str:
    given = " ".join(f"{part[0]}." for part in str(person.get("given-names", "")).replace(".", " ").split())
    return f"{person['family-names']}, {given}".rstrip(", ") if given else str(person.get("family-names", person))


def format_reference(ref: dict) -> str:
    """One reference as plain text: ``Wei, G.; Wang, Z. (2011). Title. Venue.``

    Parameters
    ----------
    ref : dict
        A reference with ``title`` and optional ``authors``, ``year``, ``venue``.

    Returns
    -------
    str
        Authors separated by ``"; "``, the year in parentheses (``(n.d.)`` when the registry gives
        none), title and venue; one full stop after each part, never two.
    """
    authors = "; ".join(_author(a) for a in ref.get("authors", []))
    year = f" ({ref['year']})" if ref.get("year") else " (n.d.)"
    venue = f" {ref['venue'].rstrip('.')}." if ref.get("venue") else ""
    return f"{authors}{year}. {ref['title'].rstrip('.')}.{venue}"


def references_html(slugs) -> str:
    """The report's "Cite the originals" section for the papers ``slugs``.

    Parameters
    ----------
    slugs : iterable of str
        Paper slugs, in list order; a slug without a citation in the registry is skipped.

    Returns
    -------
    str
        An HTML ``<section id="cite">`` with one escaped list item per paper (and the works it
        reproduces), linking each verified identifier (``doi:`` to https://doi.org/, ``arXiv:`` to
        https://arxiv.org/abs/); an unchecked venue is flagged.
    """
    refs = load_references()
    idents = load_identifiers()
    items = []
    for slug in slugs:
        ref = refs.get(slug)
        if not ref:
            continue
        note = "" if ref.get("venue_checked", True) or not ref.get("venue") else \
            ' <small class="sha">(venue not in the source text: check before citing)</small>'
        links = "".join(f' <a class="ident" href="{html.escape(identifier_url(i))}">'
                        f"{html.escape(_ident_label(i))}</a>" for i in idents.get(slug, []))
        under = "".join(f"<li>{html.escape(format_reference(u))}</li>" for u in ref.get("underlying", []))
        items.append(f'<li id="cite-{html.escape(slug)}"><code>{html.escape(slug)}</code> '
                     f"{html.escape(format_reference(ref))}{links}{note}"
                     + (f"<br><small>which reproduces</small><ul>{under}</ul>" if under else "") + "</li>")
    return ('<section id="cite"><h2>Cite the originals</h2><p class="sub">The results above are ours; the '
            "questions, models and stated numbers are the authors'. Cite the original papers, and this "
            "workflow (<code>CITATION.cff</code>) for the reproduction.</p>"
            f"<ol class=\"refs\">{''.join(items)}</ol></section>")


def _ident_label(ident: dict) -> str:
    return f"doi:{ident['value']}" if ident["type"] == "doi" else f"arXiv:{ident['value']}"


def cff_reference(ref: dict, identifiers=()) -> dict:
    """A reference in the Citation File Format (``references`` entry).

    Parameters
    ----------
    ref : dict
        A registry reference (``type``, ``title``, ``authors``, optional ``year``, ``venue``, ``affiliation``).
    identifiers : iterable of dict, default ()
        The paper's verified identifiers (registry ``identifiers``).

    Returns
    -------
    dict
        The CFF entry: the venue as ``journal`` (article), ``conference.name`` (conference paper)
        or ``notes`` (otherwise); the affiliation appended to ``notes``; the first DOI as ``doi``,
        and every identifier under ``identifiers`` (a DOI as ``type: doi``, an arXiv id as its
        ``type: url``), each described with where and when it was verified.
    """
    out = {"type": ref["type"], "title": ref["title"], "authors": [dict(a) for a in ref["authors"]]}
    if ref.get("year"):
        out["year"] = int(ref["year"])
    venue = ref.get("venue")
    if venue and ref["type"] == "article":
        out["journal"] = venue
    elif venue and ref["type"] == "conference-paper":
        out["conference"] = {"name": venue}
    elif venue:
        out["notes"] = venue
    if ref.get("affiliation"):
        out["notes"] = (out.get("notes", "") + " " if out.get("notes") else "") + f"Authors' affiliation: {ref['affiliation']}"
    identifiers = list(identifiers)
    dois = [i["value"] for i in identifiers if i["type"] == "doi"]
    if dois:
        out["doi"] = dois[0]
    if identifiers:
        out["identifiers"] = [
            {"type": "doi", "value": i["value"]} if i["type"] == "doi" else {"type": "url", "value": identifier_url(i)}
            for i in identifiers]
        for cff, i in zip(out["identifiers"], identifiers):
            cff["description"] = f"{_ident_label(i)}, verified at {i['source']} on {i['checked']}"
    return out


def citation_cff() -> dict:
    """The content of ``CITATION.cff``: this software, with the reproduced papers as references.

    Returns
    -------
    dict
        The CFF document: this software's metadata and, as ``references``, each paper of the
        registry followed by the works it reproduces.
    """
    refs = load_references()
    idents = load_identifiers()
    references = []
    for slug, ref in refs.items():
        for entry in [cff_reference(ref, idents.get(slug, [])), *(cff_reference(u) for u in ref.get("underlying", []))]:
            # a work two papers share (one reproduced, one underlying another) is listed once: the CFF
            # schema wants unique references
            if entry not in references:
                references.append(entry)
    return {
        "cff-version": "1.2.0",
        "message": ("If you use this reproduction, please cite it as below, and cite the original papers "
                    "listed under references."),
        "type": "software",
        **SOFTWARE,
        "references": references,
    }


_SCHEMA_TYPES = {"article": "ScholarlyArticle", "conference-paper": "ScholarlyArticle", "report": "Report"}


def crate_citations(slugs) -> list[dict]:
    """The papers ``slugs`` as RO-Crate contextual entities, for the root dataset's ``citation``.

    RO-Crate 1.1 ("Publications via citation property") asks for a URL, for example a DOI URL,
    as the ``@id`` of each publication, described as a ``ScholarlyArticle`` or ``CreativeWork``.
    A paper with a verified identifier is named by its resolver URL (``https://doi.org/...``,
    ``https://arxiv.org/abs/...``); one without is named ``#paper-<slug>`` and says so in
    ``description`` (no identifier is made up).

    Parameters
    ----------
    slugs : iterable of str
        Paper slugs, in list order; a slug without a citation in the registry is skipped.

    Returns
    -------
    list of dict
        One entity per paper: ``@id``, ``@type``, ``name``, ``author`` (names), ``datePublished``
        (when the registry gives a year), ``identifier`` (resolver URLs), ``description``.
    """
    refs, idents = load_references(), load_identifiers()
    out = []
    for slug in slugs:
        ref = refs.get(slug)
        if not ref:
            continue
        urls = [identifier_url(i) for i in idents.get(slug, [])]
        entity = {"@id": urls[0] if urls else f"#paper-{slug}",
                  "@type": _SCHEMA_TYPES.get(ref["type"], "CreativeWork"), "name": ref["title"],
                  "author": [" ".join(filter(None, (a.get("given-names"), a.get("family-names")))) or a.get("name", "")
                             for a in ref["authors"]]}
        if ref.get("year"):
            entity["datePublished"] = str(ref["year"])
        if urls:
            entity["identifier"] = urls
        entity["description"] = (f"The original paper reproduced by the workflow's `{slug}` part: "
                                 + format_reference(ref)
                                 + ("" if urls else " No DOI or arXiv id was verified for it."))
        out.append(entity)
    return out


def main(argv=None) -> int:
    """``python -m netrepro citations [OUT]``: write ``CITATION.cff`` from the paper registry.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status 0.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro citations",
                                     description="write CITATION.cff from the paper registry (papers.yaml)")
    parser.add_argument("out", nargs="?", default="CITATION.cff")
    args = parser.parse_args(argv)
    text = ("# Written by `python -m netrepro citations` from src/netrepro/papers.yaml: edit that, not this.\n"
            + yaml.safe_dump(citation_cff(), sort_keys=False, allow_unicode=True, width=100))
    Path(args.out).write_text(text)
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
