"""Hostile content in a built workflow (issue 38): the report shows it as text and copies nothing
from outside the checkout.

In a scratch copy of the session's built repository: a figure caption with a raw-HTML script, an
``include`` of ``/etc/passwd`` and a ``javascript:`` link, and a provenance sidecar whose input is
``../../../etc/hostname``. The report rule refuses the sidecar naming it, and writes nothing outside
``report/``; with the sidecar repaired, the paper's page ``report/paper-<slug>.html`` and its
notebook page show the caption as inert text, under a content security policy that runs no script,
and ``report/index.html`` runs its claims explorer alone (allowed by its hash).
Snakemake's own report, sealed by ``relocate``, is checked on a small workflow of its own.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from netrepro.report.captions import link_allowed
from netrepro.report.csp import inline_scripts, script_hash

from .conftest import run_snakemake
from .test_captions import HOSTILE_CAPTION

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]

CONFIG = os.environ.get("NETREPRO_REPORT_CONFIG", "config/test.yaml")
PAPER, FIGURE = "intermittent", "fig1"
NOT_COPIED = {".venv", ".git", ".pytest_cache", ".hypothesis", "__pycache__"}


class LivePage(HTMLParser):
    """What a browser would run or follow on a page, and the text a reader sees."""

    def __init__(self, page: str):
        super().__init__()
        self.scripts, self.hrefs, self.handlers, self.policies, self.text = [], [], [], [], []
        self.feed(page)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "script" and attrs.get("type", "text/javascript") in ("text/javascript", "module"):
            self.scripts.append(attrs)
        if tag == "a" and attrs.get("href") is not None:
            self.hrefs.append(attrs["href"])
        if tag == "meta" and (attrs.get("http-equiv") or "").lower() == "content-security-policy":
            self.policies.append(attrs["content"])
        self.handlers += [k for k in attrs if k.startswith("on")]

    def handle_data(self, data):
        self.text.append(data)


def assert_inert(page: str, name: str) -> None:
    live = LivePage(page)
    assert live.scripts == [] and live.handlers == [], name
    assert [h for h in live.hrefs if not link_allowed(h)] == [], name
    assert len(live.policies) == 1 and "script-src 'none'" in live.policies[0], name
    assert_shown(live, page, name)


def assert_index_runs_only_its_explorer(page: str) -> None:
    """``report/index.html`` runs one script, its claims explorer, allowed by its hash alone."""
    from netrepro.report.markup import script

    live = LivePage(page)
    assert live.handlers == [] and [h for h in live.hrefs if not link_allowed(h)] == []
    assert [text for _, text in inline_scripts(page)] == [str(script("explorer.js"))]
    assert len(live.policies) == 1
    sources = dict((d.split()[0], d.split()[1:]) for d in live.policies[0].split("; "))
    assert sources["script-src"] == [script_hash(str(script("explorer.js")))]
    assert "PWNED" not in "".join(a for _, a in inline_scripts(page))


def assert_shown(live: LivePage, page: str, name: str) -> None:
    text = "".join(live.text)
    assert 'document.title = "PWNED"' in text, name  # shown, as text
    assert ".. include:: /etc/passwd" in text and "root:x:0:0" not in page, name
    assert "link <javascript:alert(document.domain)>" in text, name


def files_outside(tmp_root: Path, work: Path) -> set[str]:
    """Every file under ``tmp_root`` that is not in the checkout ``work``."""
    return {str(p) for p in tmp_root.rglob("*") if p.is_file() and not p.is_relative_to(work)}


@pytest.fixture(scope="module")
def hostile(built_repo, tmp_path_factory):
    """A copy of the built repository with the hostile caption and a sidecar pointing at /etc/hostname."""
    base = tmp_path_factory.mktemp("hostile")
    work = base / "repo"
    shutil.copytree(built_repo, work, symlinks=True, ignore=lambda d, names: [n for n in names if n in NOT_COPIED])
    (work / "workflow" / "report" / PAPER / f"{FIGURE}.rst").write_text(HOSTILE_CAPTION)
    side = next(p for p in sorted((work / "results" / PAPER).glob("*.csv.meta.json"))
                if json.loads(p.read_text()).get("inputs"))
    return base, work, side


def test_a_sidecar_pointing_outside_the_checkout_stops_the_report_and_nothing_is_copied(hostile):
    base, work, side = hostile
    original = side.read_text()
    meta = json.loads(original)
    name = next(iter(meta["inputs"]))
    escape = "../" * (len(work.parts) - 1) + "etc/hostname"  # /etc/hostname, from the checkout
    meta["inputs"][name]["path"] = escape
    side.write_text(json.dumps(meta))
    before = files_outside(base, work)
    try:
        proc = run_snakemake(work, "-j2", "report/index.html", config=CONFIG, check=False)
        console = proc.stdout + proc.stderr + (work / "logs" / "report.log").read_text(errors="replace")
        assert proc.returncode != 0
        assert "outside the checkout" in console and escape in console
        assert side.relative_to(work).as_posix() in console and f"inputs.{name}.path" in console
        assert files_outside(base, work) == before  # nothing written next to the checkout
        assert not [p for p in (work / "report").rglob("hostname*")]
    finally:
        side.write_text(original)


def test_the_hostile_caption_is_inert_text_in_the_report_and_the_notebook(hostile):
    base, work, _ = hostile
    run_snakemake(work, "-j2", "report/index.html", config=CONFIG)
    assert_index_runs_only_its_explorer((work / "report" / "index.html").read_text())
    assert_inert((work / "report" / f"paper-{PAPER}.html").read_text(), f"paper-{PAPER}.html")  # its figures' page
    assert_inert((work / "report" / f"{PAPER}.html").read_text(), f"{PAPER}.html")
    assert not [p for p in (work / "report").rglob("*") if p.is_file() and "root:x:0:0" in p.read_text(errors="ignore")]


# ----------------------------------------------------------------------------- Snakemake's own report
TOY = """
report: "report/workflow.rst"

rule all:
    input: "out/t.csv"

rule table:
    output: report("out/t.csv", caption="report/cap.rst", category="Tables")
    shell: "printf 'a,b\\\\n1,2\\\\n' > {output}"
"""
BREAKOUT = ".. raw:: html\n\n   </script><script>document.title=String.fromCharCode(80,87,78,69,68)</script>\n"


def test_snakemakes_report_sealed_by_relocate_runs_only_snakemakes_scripts(tmp_path):
    (tmp_path / "report").mkdir()
    (tmp_path / "Snakefile").write_text(TOY)
    (tmp_path / "report" / "workflow.rst").write_text("A workflow.\n")
    (tmp_path / "report" / "cap.rst").write_text(BREAKOUT)
    for args in (["-j1", "all"], ["--report", "report.html"]):
        subprocess.run([sys.executable, "-m", "snakemake", *args], cwd=tmp_path, check=True, capture_output=True)
    subprocess.run([sys.executable, "-m", "netrepro", "report", "relocate", "report.html"], cwd=tmp_path, check=True)
    page = (tmp_path / "report.html").read_text()
    policies = LivePage(page).policies
    assert len(policies) == 1
    sources = dict((d.split()[0], d.split()[1:]) for d in policies[0].split("; "))
    scripts = [text for _, text in inline_scripts(page)]
    injected = [t for t in scripts if "fromCharCode(80,87" in t]
    assert injected, "the caption's script did not reach the page: the test does not test"
    assert all(script_hash(t) not in sources["script-src"] for t in injected)
    allowed = [t for t in scripts if script_hash(t) in sources["script-src"]]
    assert len(allowed) >= 30 and any("React" in t for t in allowed)  # Snakemake's application still runs
    assert sources["default-src"] == ["'none'"] and "'unsafe-inline'" not in sources["script-src"]
    assert not [s for v in sources.values() for s in v if s.startswith(("http", "*"))]
