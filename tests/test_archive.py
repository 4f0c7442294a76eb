"""The deposit (`make archive`, issue 41 item 4): .zenodo.json and codemeta.json from CITATION.cff, the bag."""

import copy
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import jsonschema
import pytest
import yaml

from netrepro.release.archive import codemeta_json, main, write_archive, zenodo_json
from netrepro.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
CFF = yaml.safe_load((ROOT / "CITATION.cff").read_text())


def _zenodo_schema() -> dict:
    """Zenodo's legacy deposit schema, with the enums it nests inside ``type`` lifted one level up."""
    schema = json.loads((ROOT / "tests/data/zenodo/legacyrecord.json").read_text())
    for prop in schema["properties"].values():
        if isinstance(prop.get("type"), dict):
            inner = prop.pop("type")
            prop["type"], prop["enum"] = inner["type"], inner["enum"]
    jsonschema.Draft4Validator.check_schema(schema)
    return schema


def test_zenodo_json_validates_against_zenodos_legacy_deposit_schema():
    doc = zenodo_json(CFF)
    jsonschema.Draft4Validator(_zenodo_schema()).validate(doc)
    assert doc["upload_type"] == "software" and doc["access_right"] == "open"
    assert doc["title"] == CFF["title"] and doc["notes"] == f"Version {CFF['version']}."
    assert doc["license"] == "BSD-3-Clause"
    assert doc["publication_date"] == str(CFF["date-released"])
    assert doc["creators"] == [{"name": "The netrepro maintainers"}]
    assert len(doc["references"]) == len(CFF["references"])


def test_zenodo_schema_refuses_what_zenodo_refuses():
    schema = _zenodo_schema()
    for broken in ({"upload_type": "code"}, {"license": {"id": "BSD-3-Clause"}}, {"unknown_key": 1},
                   {"related_identifiers": [{"identifier": "x", "relation": "mentions", "scheme": "doi"}]}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.Draft4Validator(schema).validate({**zenodo_json(CFF), **broken})


def test_identifiers_of_the_references_become_related_identifiers():
    cff = copy.deepcopy(CFF)
    cff["references"] = [
        {"type": "article", "title": "A", "authors": [{"family-names": "X", "given-names": "Y"}], "year": 2001,
         "doi": "10.1109/TAC.2004.834121", "identifiers": [{"type": "doi", "value": "10.1109/TAC.2004.834121"}]},
        {"type": "article", "title": "B", "authors": [{"family-names": "Z", "given-names": "W"}],
         "identifiers": [{"type": "url", "value": "https://arxiv.org/abs/1511.05318"}]},
        {"type": "report", "title": "C", "authors": [{"family-names": "V", "given-names": "U"}], "year": 2014},
    ]
    doc = zenodo_json(cff)
    jsonschema.Draft4Validator(_zenodo_schema()).validate(doc)
    assert doc["related_identifiers"] == [
        {"identifier": "10.1109/TAC.2004.834121", "relation": "references", "scheme": "doi"},
        {"identifier": "arXiv:1511.05318", "relation": "references", "scheme": "arxiv"}]
    assert doc["references"] == ["X, Y. (2001). A.", "Z, W. (n.d.). B.", "V, U. (2014). C."]
    meta = codemeta_json(cff)
    assert [c.get("@id") for c in meta["citation"]] == [
        "https://doi.org/10.1109/TAC.2004.834121", "https://arxiv.org/abs/1511.05318", None]
    assert meta["citation"][0]["author"] == [{"@type": "Person", "givenName": "Y", "familyName": "X"}]


def test_the_registry_identifiers_reach_the_deposit_metadata():
    from netrepro.release.citations import load_identifiers

    related = {r["identifier"] for r in zenodo_json(CFF).get("related_identifiers", [])}
    for slug, idents in load_identifiers().items():
        for ident in idents:
            assert (ident["value"] if ident["type"] == "doi" else f"arXiv:{ident['value']}") in related, slug


def test_codemeta_json_is_codemeta_2():
    doc = codemeta_json(CFF)
    assert doc["@context"] == "https://doi.org/10.5063/schema/codemeta-2.0"
    assert doc["@type"] == "SoftwareSourceCode"
    assert doc["name"] == CFF["title"] and doc["version"] == CFF["version"]
    assert doc["license"] == "https://spdx.org/licenses/BSD-3-Clause"
    assert doc["datePublished"] == str(CFF["date-released"])
    assert doc["author"] == [{"@type": "Organization", "name": "The netrepro maintainers"}]
    assert doc["keywords"] == CFF["keywords"]
    assert len(doc["citation"]) == len(CFF["references"])
    json.dumps(doc)  # plain JSON


def test_a_person_author_becomes_a_zenodo_family_given_name_and_a_codemeta_person():
    cff = {**CFF, "authors": [{"family-names": "Doe", "given-names": "Jane", "orcid": "https://orcid.org/0000-0000-0000-0000",
                               "affiliation": "Somewhere"}]}
    assert zenodo_json(cff)["creators"] == [{"name": "Doe, Jane", "orcid": "0000-0000-0000-0000",
                                             "affiliation": "Somewhere"}]
    assert codemeta_json(cff)["author"] == [{"@type": "Person", "givenName": "Jane", "familyName": "Doe"}]


def test_the_makefile_has_an_archive_target_that_installs_bagit_from_a_lock():
    makefile = (ROOT / "Makefile").read_text()
    assert "\narchive:" in makefile
    assert "--require-hashes -r $(LOCK)/archive.txt" in makefile
    assert "-m netrepro archive " in makefile
    assert "bagit" in (ROOT / "requirements/archive.txt").read_text()


# ----------------------------------------------------------------------------- the bag
def _git(cwd, *args):
    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True)


@pytest.fixture
def scratch(tmp_path):
    """A minimal checkout: CITATION.cff, a lock file, a source file, committed; no report yet."""
    repo = tmp_path / "repo"
    (repo / "requirements").mkdir(parents=True)
    (repo / "src").mkdir()
    shutil.copy2(ROOT / "CITATION.cff", repo / "CITATION.cff")
    (repo / "requirements/default.txt").write_text("numpy==2.0.0 \\\n    --hash=sha256:00\n")
    (repo / "src/x.py").write_text("print('x')\n")
    _git(repo, "init", "-q")
    _git(repo, "add", ".")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "init")
    return repo


def test_without_a_built_report_the_archive_names_make_report(scratch, tmp_path, capsys):
    with pytest.raises(ConfigError, match="make report"):
        write_archive(scratch, tmp_path / "out")
    assert main(["--root", str(scratch), "--out", str(tmp_path / "out")]) == 2
    assert "make report" in capsys.readouterr().err


def _fake_report(repo: Path, commit: str) -> None:
    report = repo / "report"
    report.mkdir(exist_ok=True)
    (report / "index.html").write_text("<html><body>report</body></html>\n")
    (report / "ro-crate-metadata.json").write_text(json.dumps(
        {"@context": "https://w3id.org/ro/crate/1.1/context",
         "@graph": [{"@id": "#commit", "@type": "PropertyValue", "name": "git_commit", "value": commit}]}))


@pytest.mark.slow
def test_the_archive_is_a_valid_bag_with_every_part(scratch, tmp_path):
    bagit = pytest.importorskip("bagit")
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=scratch, check=True, capture_output=True,
                            text=True).stdout.strip()
    _fake_report(scratch, commit)
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "netrepro", "archive", "--root", str(scratch), "--out", str(out),
                           "--zip"], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert proc.returncode == 0, proc.stderr
    bag_dir = Path(proc.stdout.strip())
    assert bag_dir == out / f"netrepro-{commit[:12]}"
    # unpack the zip and validate the unpacked bag (what a depositor would receive)
    unpacked = tmp_path / "unpacked"
    with zipfile.ZipFile(out / f"netrepro-{commit[:12]}.zip") as zf:
        zf.extractall(unpacked)
    bag = bagit.Bag(str(unpacked / bag_dir.name))
    bag.validate()
    assert bag.info["Netrepro-Commit"] == commit
    assert bag.info["Netrepro-Report-Commit"] == commit
    assert bag.info["Netrepro-Working-Tree"] == "clean"
    data = unpacked / bag_dir.name / "data"
    assert sorted(p.name for p in data.iterdir()) == sorted(
        [".zenodo.json", "CITATION.cff", "codemeta.json", f"netrepro-{commit}.tar.gz", "report", "requirements"])
    assert (data / "report/index.html").is_file() and (data / "requirements/default.txt").is_file()
    listing = subprocess.run(["tar", "-tzf", str(data / f"netrepro-{commit}.tar.gz")], check=True,
                             capture_output=True, text=True).stdout.split()
    assert f"netrepro-{commit}/src/x.py" in listing and f"netrepro-{commit}/CITATION.cff" in listing
    jsonschema.Draft4Validator(_zenodo_schema()).validate(json.loads((data / ".zenodo.json").read_text()))
    assert json.loads((data / "codemeta.json").read_text())["@type"] == "SoftwareSourceCode"
    # a changed payload file is caught by the bag's checksums
    (unpacked / bag_dir.name / "data/report/index.html").write_text("tampered\n")
    with pytest.raises(bagit.BagValidationError):
        bagit.Bag(str(unpacked / bag_dir.name)).validate()


@pytest.mark.slow
def test_the_archive_warns_about_a_dirty_tree_and_a_report_of_another_commit(scratch, tmp_path, capsys):
    pytest.importorskip("bagit")
    _fake_report(scratch, "0" * 40)
    (scratch / "src/x.py").write_text("print('changed')\n")
    bag_dir = write_archive(scratch, tmp_path / "out")
    err = capsys.readouterr().err
    assert "uncommitted changes" in err and "not HEAD" in err
    assert "dirty" in (bag_dir / "bag-info.txt").read_text()


@pytest.mark.slow
@pytest.mark.xdist_group("workflow")
def test_the_archive_of_a_built_report_holds_a_valid_crate(built_repo, tmp_path):
    """The built report of the test configuration, in a git checkout of its own: archive it, validate bag and crate."""
    bagit = pytest.importorskip("bagit")
    from tests.test_crate_validator import failures, validate, warm_cache

    work = tmp_path / "repo"
    top = Path(built_repo).resolve()

    def build_products(directory, names):  # at the top only: report/files/data/results/ is the report's payload
        return [n for n in names if n in (".snakemake", "results", "logs")] if Path(directory).resolve() == top else []

    shutil.copytree(built_repo, work, symlinks=True, ignore=build_products)
    git = ["git", "-c", "user.name=test", "-c", "user.email=test@example.org"]
    subprocess.run(["git", "init", "-q"], cwd=work, check=True)
    subprocess.run(["git", "add", "-A", "--", ".", ":!report"], cwd=work, check=True)
    subprocess.run([*git, "commit", "-q", "-m", "built"], cwd=work, check=True)
    bag_dir = write_archive(work, tmp_path / "out")
    bagit.Bag(str(bag_dir)).validate()
    (tmp_path / "rocrate-cache").mkdir()
    cache = warm_cache(tmp_path / "rocrate-cache" / "cache")
    report = validate(bag_dir / "data/report", "provenance-run-crate-0.5", "REQUIRED", cache)
    assert report["passed"], failures(report)
