"""The content security policy of the report's pages (netrepro.report.csp, issue 38)."""

import base64
import hashlib
import re

import pytest

from netrepro.report.cli import relocate_page
from netrepro.report.csp import (PAGE_POLICY, csp_meta, inline_scripts, is_data_script, policy_text, script_hash,
                                 snakemake_known_scripts, snakemake_report_policy, with_csp)
from netrepro.report.markup import render
from netrepro.report.site import source_page

META = re.compile(r'<meta http-equiv="Content-Security-Policy" content="([^"]*)">')


def policy_of(page: str) -> dict:
    """The policy a page sets (directive -> sources); fails unless exactly one is set."""
    found = META.findall(page)
    assert len(found) == 1, found
    return {d.split()[0]: d.split()[1:] for d in found[0].split("; ")}


def test_our_pages_run_no_script_and_load_nothing_remote():
    policy = {k: list(v) for k, v in PAGE_POLICY.items()}
    assert policy["default-src"] == ["'none'"] and policy["script-src"] == ["'none'"]
    assert policy["base-uri"] == ["'none'"] and policy["form-action"] == ["'none'"]
    sources = [s for v in policy.values() for s in v]
    assert not [s for s in sources if s.startswith(("http", "*")) or s in ("'unsafe-eval'", "https:")]
    assert policy["style-src"] == ["'self'", "'unsafe-inline'"] and policy["img-src"] == ["'self'", "data:"]


def test_the_source_page_template_sets_the_policy_first_in_its_head():
    page = source_page("src/netrepro/x.py", "print('</script>')\n")
    assert policy_of(page) == {k: list(v) for k, v in PAGE_POLICY.items()}
    assert page.index("Content-Security-Policy") < page.index("<title>") < page.index("<style>")


def test_the_index_template_sets_the_policy_before_any_content():
    page = render("index.html", css="", papers=[], run={"commit": "", "dirty": None, "config_hash": "x",
                                                         "configfiles": [], "date": "", "machine": "", "platform": ""},
                  versions={}, bench=None, scorecard="", scale="", sections=[], references="")
    assert policy_of(page)["script-src"] == ["'none'"]
    assert page.index("Content-Security-Policy") < page.index("<style>") < page.index("<body>")


def test_script_hash_is_the_browsers_sha256_of_the_text():
    text = "var a = 1;\n"
    assert script_hash(text) == "'sha256-" + base64.b64encode(hashlib.sha256(text.encode()).digest()).decode() + "'"
    assert script_hash("a\r\nb\rc") == script_hash("a\nb\nc")  # the parser's newlines


def test_with_csp_goes_after_the_charset_and_replaces_an_older_policy():
    page = '<!DOCTYPE html><html><head><meta charset="utf-8"><title>t</title></head><body>x</body></html>'
    once = with_csp(page)
    assert once.startswith('<!DOCTYPE html><html><head><meta charset="utf-8">' + str(csp_meta()) + "<title>")
    assert with_csp(once) == once
    other = with_csp(once, {"default-src": ("'none'",)})
    assert policy_of(other) == {"default-src": ["'none'"]}


def test_with_csp_needs_a_head():
    with pytest.raises(ValueError, match="no <head>"):
        with_csp("<p>fragment</p>")


@pytest.mark.parametrize(("text", "data"), [
    ('\n    var results = {"a": "<b>x</b>", "b": [1, 2.5, null]};\n    ', True),
    ('var logo_uri = "data:image/svg+xml;base64,AAAA";', True),
    ("var x = {};alert(1);", False),
    ('var x = {"a": 1}; fetch("https://evil.example")', False),
    ("var x = window.y;", False),
    ("alert(1)", False),
    ('var results = {"caption": "', False),  # a data script cut by a caption's "</script>"
])
def test_only_pure_json_assignments_count_as_data(text, data):
    assert is_data_script(text) is data


SNAKEMAKE_LIKE = """<!doctype html><html lang="en"><head><meta charset="utf-8"><title>Snakemake Report</title>
<script>LIBRARY</script></head><body><div id="app"></div>
<script id="results">
    var results = {"x": {"caption": "<p>fine</p>"}};
    </script>
<script id="rules">
    var rules = {"a": 1};</script><script>alert("injected by a caption")</script><script>"}};
    </script>
<script>APP</script>
<img src=x onerror="alert(2)"><a href="javascript:alert(3)">x</a>
</body></html>"""


def test_the_snakemake_report_policy_allows_its_own_scripts_and_data_only():
    page = relocate_page(SNAKEMAKE_LIKE, "/nonexistent-root")
    # the libraries and components are known by their text (here two stand-ins)
    policy = snakemake_report_policy(page, known=frozenset({"LIBRARY", "APP"}))
    allowed = set(policy["script-src"])
    scripts = [text for _, text in inline_scripts(page)]
    assert script_hash("LIBRARY") in allowed and script_hash("APP") in allowed
    assert script_hash(scripts[1]) in allowed  # var results = {...};
    for text in scripts:
        if "alert" in text or text.startswith('"}}'):
            assert script_hash(text) not in allowed, text
    assert "'unsafe-inline'" not in allowed and "'unsafe-hashes'" not in allowed  # no handler, no javascript:
    assert policy["default-src"] == ("'none'",)
    assert not [s for v in policy.values() for s in v if s.startswith(("http", "*"))]


def test_relocate_page_seals_the_page_it_relocates():
    page = relocate_page(SNAKEMAKE_LIKE.replace("APP", "run('/root/x/.venv/bin/python3')"), "/root/x")
    assert "/root/x" not in page and "python3" in page
    policy = policy_of(page)
    assert policy["default-src"] == ["'none'"] and "'unsafe-inline'" not in policy["script-src"]
    assert relocate_page(page, "/root/x") == page  # sealing twice changes nothing


def test_snakemakes_own_scripts_are_known_from_its_installed_template():
    known = snakemake_known_scripts()
    if not known:
        pytest.skip("Snakemake's report assets are not installed")
    assert any("document.querySelector('#loading-screen').style.display" in t for t in known)
    assert any("React" in t for t in known) and all("{{" not in t for t in known)
    assert not [t for t in known if is_data_script(t)]  # data is never taken for a known script


def test_policy_text_keeps_the_order():
    assert policy_text({"a": ("x", "y"), "b": ("z",)}) == "a x y; b z"


def test_a_page_with_its_own_script_allows_that_script_alone():
    from netrepro.report.csp import page_policy
    from netrepro.report.markup import script

    explorer = str(script("explorer.js"))
    policy = page_policy(explorer)
    assert policy["script-src"] == (script_hash(explorer),) and page_policy()["script-src"] == ("'none'",)
    assert {k: v for k, v in policy.items() if k != "script-src"} == {k: v for k, v in PAGE_POLICY.items()
                                                                         if k != "script-src"}
    page = render("index.html", css="", papers=[], run={"commit": "", "dirty": None, "config_hash": "x",
                                                         "configfiles": [], "date": "", "machine": "", "platform": ""},
                  versions={}, bench=None, scorecard="", scale="", references="", explorer="<section></section>",
                  script=script("explorer.js"), csp=csp_meta(policy).split('content="')[1][:-2])
    assert policy_of(page)["script-src"] == [script_hash(explorer)]
    assert [text for _, text in inline_scripts(page)] == [explorer]  # the text hashed is the text the page holds
    assert "'unsafe-inline'" not in policy_of(page)["script-src"]
