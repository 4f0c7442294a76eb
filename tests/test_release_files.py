"""Release files: lock files, licence, citation, catalog files (no workflow run)."""

import json
import re
import tomllib
from pathlib import Path

import jsonschema
import pytest
import yaml
from packaging.requirements import Requirement

from netrepro.release.lockfile import normalize, read_lock
from netrepro.release.readme import END, START
from netrepro.release.citations import citation_cff, load_references

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


@pytest.fixture(scope="module")
def locks():
    return {name: read_lock(ROOT / "requirements" / f"{name}.txt") for name in ("bootstrap", "default", "test")}


# ----------------------------------------------------------------------------- lock files
def test_every_pin_is_exact_and_hashed(locks):
    for name, pins in locks.items():
        assert pins, f"requirements/{name}.txt has no pins"
        for pin in pins.values():
            assert pin.hashes, f"requirements/{name}.txt: {pin.name} has no hash"
            assert re.fullmatch(r"[0-9A-Za-z.+!]+", pin.version), pin


def _satisfied(requirement: str, pins) -> None:
    req = Requirement(requirement)
    pin = pins.get(normalize(req.name))
    assert pin is not None, f"{req.name} is not in the lock file"
    assert req.specifier.contains(pin.version, prereleases=True), f"{pin.name}=={pin.version} violates {req}"


def test_locks_satisfy_the_bounds_of_pyproject(locks):
    for dep in PYPROJECT["project"]["dependencies"]:
        _satisfied(dep, locks["default"])
        _satisfied(dep, locks["test"])
    for dep in PYPROJECT["project"]["optional-dependencies"]["test"]:
        _satisfied(dep, locks["test"])
    assert "pip" in locks["bootstrap"]
    # the build backend is locked too: `make` installs the package with --no-build-isolation
    build = Requirement(PYPROJECT["build-system"]["requires"][0])
    assert build.specifier.contains(locks["default"]["setuptools"].version)


def test_test_environment_is_the_default_one_plus_the_test_extra(locks):
    default, test = locks["default"], locks["test"]
    for key, pin in default.items():
        assert key in test, f"{pin.name} is in default.txt but not in test.txt"
        assert test[key].version == pin.version, f"{pin.name}: {pin.version} (default) != {test[key].version} (test)"
    for dep in ("pytest", "snakefmt"):
        assert dep in test and dep not in default


def test_conda_environment_pins_the_lock_versions(locks):
    env = yaml.safe_load((ROOT / "workflow/envs/netrepro.yaml").read_text())
    pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    pinned = {}
    for line in pip:
        if line.startswith("-"):
            continue
        req = Requirement(line)
        pinned[normalize(req.name)] = str(req.specifier).removeprefix("==")
    assert pinned == {k: p.version for k, p in locks["default"].items()}


def test_make_installs_from_the_locks():
    makefile = (ROOT / "Makefile").read_text()
    for name in ("bootstrap", "default", "test"):
        assert re.search(rf"pip install .*--require-hashes -r \$\(LOCK\)/{name}\.txt", makefile), name
    assert re.search(r"^lock:", makefile, re.M) and "uv pip compile" in makefile
    ci = (ROOT / ".ci/run").read_text()
    assert "make test" in ci and "make lint" in ci and "make clean" in ci


# ----------------------------------------------------------------------------- licence and citation
def test_licence_is_bsd_3_clause():
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("BSD 3-Clause License")
    assert "Neither the name of the copyright holder" in text
    assert PYPROJECT["project"]["license"] == "BSD-3-Clause"


def test_citation_cff_validates_against_the_cff_1_2_0_schema():
    schema = json.loads((ROOT / "tests/data/cff-1.2.0.schema.json").read_text())
    doc = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    jsonschema.Draft7Validator(schema, format_checker=jsonschema.FormatChecker()).validate(doc)
    assert doc["cff-version"] == "1.2.0"
    assert doc["license"] == "BSD-3-Clause"
    assert doc["version"] == PYPROJECT["project"]["version"]


def test_citation_cff_is_written_from_the_references():
    doc = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert doc == citation_cff(), "CITATION.cff is stale: run `python -m netrepro citations CITATION.cff`"
    titles = {ref["title"] for ref in doc["references"]}
    for slug, ref in load_references().items():
        assert ref["title"] in titles, slug


def test_every_paper_has_a_reference():
    from netrepro.pipeline.registry import load_registry

    refs = load_references()
    for slug, meta in load_registry().items():
        assert slug in refs, f"the registry entry of {slug} has no citation"
        family = {a["family-names"] for a in refs[slug]["authors"]}
        assert any(name in meta["authors"] for name in family), slug


def test_a_broken_citation_is_rejected_by_the_schema():
    schema = json.loads((ROOT / "tests/data/cff-1.2.0.schema.json").read_text())
    doc = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    del doc["authors"]
    with pytest.raises(jsonschema.ValidationError, match="'authors' is a required property"):
        jsonschema.Draft7Validator(schema).validate(doc)


# ----------------------------------------------------------------------------- catalog files
def test_catalog_files():
    catalog = yaml.safe_load((ROOT / ".snakemake-workflow-catalog.yml").read_text())
    usage = catalog["usage"]
    assert usage["software-stack-deployment"] and usage["report"] is True
    assert "--profile" in usage["mandatory-flags"]["flags"]
    assert re.search(r'^min_version\("9', (ROOT / "workflow/Snakefile").read_text(), re.M)


def test_config_readme_names_every_section():
    text = (ROOT / "config/README.md").read_text()
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    for key, section in config.items():
        assert f"`{key}`" in text, f"config/README.md does not describe `{key}`"
        if isinstance(section, dict):
            for sub in section:
                assert f"`{sub}`" in text, f"config/README.md does not describe `{key}.{sub}`"


def test_readme_has_the_generated_results_table():
    text = (ROOT / "README.md").read_text()
    assert START in text and END in text
    table = text.split(START, 1)[1].split(END, 1)[0]
    assert "| **total** |" in table


# ----------------------------------------------------------------------------- notebooks
@pytest.mark.parametrize("notebook", sorted((ROOT / "workflow" / "notebooks").glob("*.ipynb")), ids=lambda p: p.stem)
def test_notebook_cells_have_unique_ids(notebook):
    """nbformat >= 4.5 needs one unique id per cell; a duplicate is 'corrected' with a warning in every build."""
    import nbformat

    raw = json.loads(notebook.read_text())  # nbformat.read would 'correct' duplicates silently
    ids = [cell.get("id") for cell in raw["cells"]]
    assert None not in ids, f"{notebook.name}: a cell has no id"
    assert len(set(ids)) == len(ids), f"{notebook.name}: duplicate cell ids"
    nbformat.validate(nbformat.from_dict(raw))


def test_references_print_one_full_stop_and_a_year_or_nd():
    from netrepro.release.citations import format_reference

    for slug, ref in load_references().items():
        text = format_reference(ref)
        assert ".." not in text, text
        assert re.search(r"\((\d{4}|n\.d\.)\)", text), text


def test_identifiers_flow_into_citation_cff_the_report_and_the_crate():
    from netrepro.release.citations import crate_citations, load_identifiers, references_html
    from netrepro.pipeline.registry import identifier_url

    doc = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert doc["date-released"]
    by_title = {ref["title"]: ref for ref in doc["references"]}
    html = references_html(list(load_references()))
    crate = {c["name"]: c for c in crate_citations(list(load_references()))}
    assert len(crate) == len(load_references())
    for slug, idents in load_identifiers().items():
        title = load_references()[slug]["title"]
        for ident in idents:
            url = identifier_url(ident)
            assert f'href="{url}"' in html, slug
            values = [i["value"] for i in by_title[title]["identifiers"]]
            assert (ident["value"] if ident["type"] == "doi" else url) in values, slug
            assert crate[title]["@id"] == identifier_url(idents[0]), slug
        if not idents:
            assert crate[title]["@id"] == f"#paper-{slug}" and "identifiers" not in by_title[title], slug
