"""One deposit of a release: ``make archive`` (``python -m netrepro archive --out DIR``), issue 41 item 4.

The deposit is a BagIt bag (RFC 8493, written with the ``bagit`` library) named after the commit,
``DIR/netrepro-<commit12>/``, holding under ``data/``:

- ``netrepro-<commit>.tar.gz``: ``git archive`` of the commit (HEAD), the sources exactly as committed;
- ``report/``: the built report (``make report``), with its RO-Crate ``ro-crate-metadata.json``;
- ``requirements/``: the lock files (``requirements/*.txt``) the report was built with;
- ``CITATION.cff`` and, generated from it, ``.zenodo.json`` (Zenodo's legacy deposit metadata) and
  ``codemeta.json`` (CodeMeta 2.0).

``--zip`` also writes ``DIR/netrepro-<commit12>.zip`` of the bag. Without a built report the command
stops and names ``make report``. The bag's ``bag-info.txt`` records the commit, whether the working tree
was dirty (uncommitted changes are not in the source archive) and the commit the report was built from.

``.zenodo.json`` and ``codemeta.json`` are written here rather than by ``cffconvert``: its Zenodo
output gives ``license`` as an object, which Zenodo's legacy deposit schema refuses, it drops the
references, and it pins ``jsonschema<4``, which the test environment cannot share.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

import yaml

from ..errors import ConfigError

__all__ = ["zenodo_json", "codemeta_json", "write_archive", "main"]

CODEMETA_CONTEXT = "https://doi.org/10.5063/schema/codemeta-2.0"
_SPDX = "https://spdx.org/licenses/{}"


def _person_name(person: dict) -> str:
    """``Family, Given`` (Zenodo's personal name format), or an entity's ``name``."""
    if person.get("family-names"):
        return ", ".join(filter(None, (person["family-names"], person.get("given-names"))))
    return str(person.get("name", ""))


def _ref_text(ref: dict) -> str:
    from .citations import format_reference

    venue = ref.get("journal") or (ref.get("conference") or {}).get("name") or ""
    return format_reference({"authors": ref.get("authors", []), "year": ref.get("year"), "title": ref["title"],
                             "venue": venue})


def _ref_identifiers(ref: dict) -> list[tuple[str, str]]:
    """(scheme, identifier) of a CFF reference: its DOI and its identifiers (arXiv URLs as arxiv ids)."""
    out = []
    if ref.get("doi"):
        out.append(("doi", ref["doi"]))
    for ident in ref.get("identifiers", []):
        value = str(ident["value"])
        if ident["type"] == "doi":
            out.append(("doi", value))
        elif value.startswith("https://arxiv.org/abs/"):
            out.append(("arxiv", "arXiv:" + value.removeprefix("https://arxiv.org/abs/")))
        elif ident["type"] == "url":
            out.append(("url", value))
    return list(dict.fromkeys(out))


def zenodo_json(cff: dict) -> dict:
    """Zenodo deposit metadata (the legacy ``.zenodo.json``) from a CITATION.cff document.

    Parameters
    ----------
    cff : dict
        The parsed ``CITATION.cff``.

    Returns
    -------
    dict
        ``upload_type`` software, ``title``, ``creators`` (``Family, Given`` or the entity's name),
        ``description``, ``notes`` (the version: the legacy schema has no ``version``), ``license`` (SPDX id), ``keywords``, ``publication_date``
        (``date-released``), ``access_right`` open, ``references`` (each reference as text) and
        ``related_identifiers`` (``references`` relation) for every reference with a DOI or arXiv id.
    """
    out = {
        "upload_type": "software",
        "title": cff["title"],
        "creators": [{"name": _person_name(a), **({"orcid": a["orcid"].rsplit("/", 1)[-1]} if a.get("orcid") else {}),
                      **({"affiliation": a["affiliation"]} if a.get("affiliation") else {})} for a in cff["authors"]],
        "description": cff.get("abstract") or cff.get("message", ""),
        "access_right": "open",
    }
    for key, zkey in (("license", "license"), ("keywords", "keywords"), ("date-released", "publication_date")):
        if cff.get(key):
            out[zkey] = str(cff[key]) if key != "keywords" else list(cff[key])
    if cff.get("version"):  # the legacy deposit schema has no `version` property: said in the notes
        out["notes"] = f"Version {cff['version']}."
    refs = cff.get("references", [])
    if refs:
        out["references"] = [_ref_text(r) for r in refs]
        related = [{"identifier": value, "relation": "references", "scheme": scheme}
                   for r in refs for scheme, value in _ref_identifiers(r)]
        if related:
            out["related_identifiers"] = related
    if cff.get("doi"):
        out["doi"] = cff["doi"]
    return out


def _schema_work(ref: dict) -> dict:
    work = {"@type": "ScholarlyArticle" if ref["type"] in ("article", "conference-paper") else "CreativeWork",
            "name": ref["title"],
            "author": [{"@type": "Person", "givenName": a["given-names"], "familyName": a["family-names"]}
                       if a.get("family-names") else {"@type": "Organization", "name": a.get("name", "")}
                       for a in ref.get("authors", [])]}
    ids = _ref_identifiers(ref)
    if ids:
        urls = [f"https://doi.org/{v}" if s == "doi" else
                f"https://arxiv.org/abs/{v.removeprefix('arXiv:')}" if s == "arxiv" else v for s, v in ids]
        work["@id"] = urls[0]
        work["identifier"] = urls[0] if len(urls) == 1 else urls
    if ref.get("year"):
        work["datePublished"] = str(ref["year"])
    return work


def codemeta_json(cff: dict) -> dict:
    """CodeMeta 2.0 metadata (``codemeta.json``) from a CITATION.cff document.

    Parameters
    ----------
    cff : dict
        The parsed ``CITATION.cff``.

    Returns
    -------
    dict
        A ``SoftwareSourceCode`` with ``name``, ``description``, ``version``, ``license`` (SPDX URL),
        ``keywords``, ``datePublished``, ``author`` (a ``Person`` for CFF persons, an
        ``Organization`` for CFF entities), ``programmingLanguage`` and, as ``citation``, the
        references (``ScholarlyArticle``, ``@id`` the DOI or arXiv URL when one is known).
    """
    out = {
        "@context": CODEMETA_CONTEXT,
        "@type": "SoftwareSourceCode",
        "name": cff["title"],
        "description": cff.get("abstract", ""),
        "author": [{"@type": "Person", "givenName": a.get("given-names", ""), "familyName": a["family-names"]}
                   if a.get("family-names") else {"@type": "Organization", "name": a["name"]} for a in cff["authors"]],
        "programmingLanguage": ["Python", "Snakemake"],
    }
    if cff.get("version"):
        out["version"] = str(cff["version"])
    if cff.get("license"):
        out["license"] = _SPDX.format(cff["license"])
    if cff.get("keywords"):
        out["keywords"] = list(cff["keywords"])
    if cff.get("date-released"):
        out["datePublished"] = str(cff["date-released"])
    if cff.get("repository-code"):
        out["codeRepository"] = cff["repository-code"]
    if cff.get("doi"):
        out["identifier"] = f"https://doi.org/{cff['doi']}"
    if cff.get("references"):
        out["citation"] = [_schema_work(r) for r in cff["references"]]
    return out


def _git(root: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=root, check=True, capture_output=True, text=True).stdout.strip()


def _report_commit(report: Path) -> str | None:
    crate = report / "ro-crate-metadata.json"
    if not crate.is_file():
        return None
    graph = json.loads(crate.read_text()).get("@graph", [])
    return next((str(e.get("value")) for e in graph if e.get("@id") == "#commit"), None)


def write_archive(root: str | Path, out: str | Path, *, zip_bag: bool = False) -> Path:
    """Write the deposit of the checkout ``root`` as a BagIt bag under ``out``; return the bag's folder.

    Parameters
    ----------
    root : str or Path
        The checkout (a git work tree with a built ``report/``).
    out : str or Path
        Where the bag ``netrepro-<commit12>/`` (and with ``zip_bag`` its ``.zip``) is written; an
        existing bag of the same commit is replaced.
    zip_bag : bool, default False
        Also write ``netrepro-<commit12>.zip`` of the bag.

    Returns
    -------
    Path
        The bag's folder (validated before it is returned).

    Raises
    ------
    ConfigError
        When ``root`` is not a git checkout, the report is not built (``make report``), or
        ``CITATION.cff`` or the lock files are missing.
    """
    import bagit

    root = Path(root).resolve()
    out = Path(out).resolve()
    try:
        commit = _git(root, "rev-parse", "HEAD")
    except (subprocess.CalledProcessError, FileNotFoundError) as exc:
        raise ConfigError(f"archive: {root} is not a git checkout with a commit ({exc})") from None
    report = root / "report"
    if not (report / "index.html").is_file():
        raise ConfigError(f"archive: no built report in {report} (no index.html): run `make report` first")
    cff_path = root / "CITATION.cff"
    if not cff_path.is_file():
        raise ConfigError(f"archive: {cff_path} not found")
    locks = sorted((root / "requirements").glob("*.txt"))
    if not locks:
        raise ConfigError(f"archive: no lock files in {root / 'requirements'} (make lock)")
    dirty = bool(_git(root, "status", "--porcelain", "--untracked-files=no"))
    name = f"netrepro-{commit[:12]}"
    bag_dir = out / name
    if bag_dir.exists():
        shutil.rmtree(bag_dir)
    bag_dir.mkdir(parents=True)
    subprocess.run(["git", "archive", "--format=tar.gz", f"--prefix=netrepro-{commit}/",
                    "-o", str(bag_dir / f"netrepro-{commit}.tar.gz"), commit], cwd=root, check=True)
    shutil.copytree(report, bag_dir / "report", ignore=shutil.ignore_patterns(".gitkeep"))
    (bag_dir / "requirements").mkdir()
    for lock in locks:
        shutil.copy2(lock, bag_dir / "requirements" / lock.name)
    shutil.copy2(cff_path, bag_dir / "CITATION.cff")
    cff = yaml.safe_load(cff_path.read_text())
    (bag_dir / ".zenodo.json").write_text(json.dumps(zenodo_json(cff), indent=2, ensure_ascii=False) + "\n")
    (bag_dir / "codemeta.json").write_text(json.dumps(codemeta_json(cff), indent=2, ensure_ascii=False) + "\n")
    report_commit = _report_commit(report)
    info = {
        "Source-Organization": str(cff["authors"][0].get("name") or _person_name(cff["authors"][0])),
        "External-Description": f"{cff['title']} {cff.get('version', '')}: sources (git archive of {commit}), "
                                "built report with its RO-Crate, lock files, CITATION.cff, .zenodo.json, codemeta.json",
        "External-Identifier": f"git:{commit}",
        "Netrepro-Commit": commit,
        "Netrepro-Working-Tree": "dirty (uncommitted changes are not in the source archive)" if dirty else "clean",
        "Netrepro-Report-Commit": report_commit or "unknown (no ro-crate-metadata.json)",
    }
    bag = bagit.make_bag(str(bag_dir), info, checksums=["sha256", "sha512"])
    bag.validate()
    if zip_bag:
        shutil.make_archive(str(out / name), "zip", root_dir=out, base_dir=name)
    warnings = []
    if dirty:
        warnings.append("the working tree has uncommitted changes: the source archive holds HEAD only")
    if report_commit and report_commit != commit:
        warnings.append(f"the report was built from commit {report_commit[:12]}, not HEAD {commit[:12]}")
    for warning in warnings:
        print(f"archive: warning: {warning}", file=sys.stderr)
    return bag_dir


def main(argv=None) -> int:
    """``python -m netrepro archive --out DIR [--root DIR] [--zip]``: write the deposit bag.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        0 on success, 2 when the archive cannot be made (the message names why).
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro archive",
                                     description="one deposit: git archive of HEAD, report/, lock files, "
                                                 ".zenodo.json and codemeta.json, as a BagIt bag")
    parser.add_argument("--out", default="archive", help="output folder (default: archive)")
    parser.add_argument("--root", default=".", help="the checkout (default: .)")
    parser.add_argument("--zip", action="store_true", help="also write a zip of the bag")
    args = parser.parse_args(argv)
    try:
        bag = write_archive(args.root, args.out, zip_bag=args.zip)
    except ConfigError as exc:
        print(exc, file=sys.stderr)
        return 2
    print(bag)
    return 0


if __name__ == "__main__":
    sys.exit(main())
