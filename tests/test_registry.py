"""The paper registry (issue 30): one file feeds every list of papers."""

from pathlib import Path

import pytest
import yaml

from netrepro.errors import ConfigError
from netrepro.pipeline.registry import load_registry, paper_slugs, schema_mismatches, valid_slug

ROOT = Path(__file__).resolve().parents[1]


def test_the_schema_lists_exactly_the_registered_papers():
    schema = yaml.safe_load((ROOT / "workflow/schemas/config.schema.yaml").read_text())
    assert schema_mismatches(schema, paper_slugs()) == []


def test_schema_mismatches_names_each_difference():
    schema = {"properties": {"papers": {"items": {"enum": ["a", "stale"]}}, "a": {"$ref": "a.schema.yaml"}}}
    problems = schema_mismatches(schema, ["a", "b"])
    assert any("'b' is registered but not in the schema's papers enum" in p for p in problems)
    assert any("'b' has no section" in p for p in problems)
    assert any("'stale', which is not registered" in p for p in problems)
    assert not any("'a'" in p for p in problems)


def test_every_registered_paper_has_its_package_rules_and_source():
    shared = ROOT.parent / "shared" / "papers"
    for slug, entry in load_registry().items():
        assert (ROOT / "src/netrepro/papers" / slug / "__init__.py").is_file(), slug
        # the paper's compute rules are generated from its step list (workflow/rules/steps.smk)
        assert (ROOT / "src/netrepro/papers" / slug / "steps.yaml").is_file(), slug
        if shared.is_dir():  # the texts are beside the checkout here, not in a clone
            assert (shared / entry["source"]).is_file(), entry["source"]


def test_the_package_init_files_hold_no_data():
    """``netrepro/papers/__init__.py`` holds a docstring and at most an empty ``__all__``: no data."""
    import ast

    tree = ast.parse((ROOT / "src/netrepro/papers/__init__.py").read_text())
    body = tree.body[1:] if ast.get_docstring(tree) else tree.body
    for node in body:
        target = node.target if isinstance(node, ast.AnnAssign) else (node.targets[0] if isinstance(node, ast.Assign) else None)
        assert isinstance(target, ast.Name) and target.id == "__all__", ast.dump(node)[:80]
        assert ast.literal_eval(node.value) == [], "the papers package exports nothing"


@pytest.mark.parametrize("slug,ok", [("markov", True), ("kalman_iid", True), ("1paper", False), ("Paper", False),
                                     ("class", False), ("_x", False), ("a-b", False)])
def test_valid_slug(slug, ok):
    assert valid_slug(slug) is ok


@pytest.mark.parametrize("text,message", [
    ("[]", "must map each paper"),
    ("Bad-Slug: {source: a, title: b, authors: c, citation: {type: article, title: b, authors: [x]}}", "Python identifier"),
    ("p: {source: a, title: b, citation: {type: article, title: b, authors: [x]}}", "lacks ['authors']"),
    ("p: {source: a, title: b, authors: c, citation: {type: article}}", "citation lacks ['title', 'authors']"),
])
def test_a_broken_registry_is_refused_naming_the_problem(tmp_path, text, message):
    path = tmp_path / "papers.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_registry(path)


# ----------------------------------------------------------------------------- identifiers (issue 41 item 4)
def test_every_identifier_names_its_source_and_check_date_and_papers_without_say_why():
    import datetime as dt

    from netrepro.pipeline.registry import IDENTIFIER_TYPES, identifier_problems

    for slug, entry in load_registry().items():
        assert identifier_problems(entry) == [], slug
        for ident in entry["identifiers"]:
            assert ident["type"] in IDENTIFIER_TYPES, slug
            assert ident["source"].startswith(("https://", "http://")), slug
            assert isinstance(ident["checked"], dt.date), slug
        if not entry["identifiers"]:
            assert "verified" in entry["identifier_note"] or "no DOI" in entry["identifier_note"], slug


def test_every_citation_has_a_year_or_says_why_not():
    for slug, entry in load_registry().items():
        cite = entry["citation"]
        assert cite.get("year") or cite.get("year_note"), slug


@pytest.mark.parametrize("identifiers,message", [
    ("", "lacks 'identifiers'"),
    ("identifiers: []", "no identifier_note"),
    ("identifiers: [{type: isbn, value: '1', source: 'https://x.org', checked: 2026-12-02}]", "not one of"),
    ("identifiers: [{type: doi, value: 'abc', source: 'https://x.org', checked: 2026-12-02}]", "not a doi"),
    ("identifiers: [{type: doi, value: '10.1109/x.1', checked: 2026-12-02}]", "'source' must be"),
    ("identifiers: [{type: arxiv, value: '1511.05318', source: 'https://x.org'}]", "'checked' must be"),
])
def test_a_malformed_identifier_is_refused(tmp_path, identifiers, message):
    path = tmp_path / "papers.yaml"
    path.write_text("p:\n  source: a\n  title: b\n  authors: c\n"
                    "  citation: {type: article, title: b, authors: [x], year: 2000}\n"
                    + (f"  {identifiers}\n" if identifiers else ""))
    with pytest.raises(ConfigError, match=message):
        load_registry(path)


def test_a_well_formed_identifier_is_accepted(tmp_path):
    path = tmp_path / "papers.yaml"
    path.write_text("p:\n  source: a\n  title: b\n  authors: c\n"
                    "  citation: {type: article, title: b, authors: [x], year_note: unknown}\n"
                    "  identifiers: [{type: doi, value: '10.1109/x.1', source: 'https://doi.org/x', checked: 2026-12-02}]\n")
    assert load_registry(path)["p"]["identifiers"][0]["value"] == "10.1109/x.1"


def test_a_citation_without_year_or_year_note_is_refused(tmp_path):
    path = tmp_path / "papers.yaml"
    path.write_text("p:\n  source: a\n  title: b\n  authors: c\n"
                    "  citation: {type: article, title: b, authors: [x]}\n  identifiers: []\n  identifier_note: none\n")
    with pytest.raises(ConfigError, match="no year and no year_note"):
        load_registry(path)
