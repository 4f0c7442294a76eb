"""Figure captions (workflow/report/<slug>/<id>.rst) are valid reStructuredText, one per listed figure."""

import io
from pathlib import Path

import docutils.core
import pytest

from netrepro.pipeline.figurespec import load_figure_specs
from netrepro.pipeline.registry import load_registry

PAPERS = load_registry()

ROOT = Path(__file__).resolve().parents[1]
CAPTIONS = sorted((ROOT / "workflow" / "report").glob("*/*.rst"))


@pytest.mark.parametrize("path", CAPTIONS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_caption_parses_without_warnings(path):
    # `snakemake --report` renders captions as RST: |x| is a substitution, *x* emphasis
    warnings = io.StringIO()
    docutils.core.publish_string(path.read_text(), writer="null",
                                 settings_overrides={"warning_stream": warnings, "report_level": 2})
    assert warnings.getvalue() == "", warnings.getvalue()


@pytest.mark.parametrize("slug", sorted(PAPERS))
def test_every_listed_figure_has_a_caption(slug):
    for spec in load_figure_specs(slug):
        assert (ROOT / "workflow" / "report" / slug / f"{spec.figure_id}.rst").is_file(), spec.rule


@pytest.mark.parametrize("slug", sorted(PAPERS))
def test_every_figure_says_which_layout_choices_are_the_papers(slug):
    """Issue 15: each figure states which layout choices come from the paper and which are ours."""
    for spec in load_figure_specs(slug):
        assert spec.layout.get("from_paper", "").strip() and spec.layout.get("ours", "").strip(), spec.rule


def test_a_malformed_layout_is_rejected(tmp_path):
    from netrepro.errors import ConfigError

    folder = tmp_path / "papers" / "x"
    folder.mkdir(parents=True)
    (folder / "figures.yaml").write_text("fig1:\n  plot: f\n  layout: {paper: axes}\n")
    with pytest.raises(ConfigError, match="figure 'fig1': field 'layout'"):
        load_figure_specs("x", src=tmp_path)


# ----------------------------------------------------------------------------- rendered inert (issue 38)
from html.parser import HTMLParser  # noqa: E402

from netrepro.report.captions import caption_html, link_allowed  # noqa: E402

# The hostile caption of issue 38: a raw-HTML script, a file inclusion and a javascript: link.
HOSTILE_CAPTION = """Figure with a hostile caption.

.. raw:: html

   <script>document.title = "PWNED"</script>

.. include:: /etc/passwd

A `link <javascript:alert(document.domain)>`_ and a `good link <https://example.org/>`_.
"""


class _Page(HTMLParser):
    """What a browser would run or follow in an HTML fragment: script texts, link addresses, handlers."""

    def __init__(self):
        super().__init__()
        self.scripts, self.hrefs, self.handlers, self._in_script = [], [], [], False

    def handle_starttag(self, tag, attrs):
        self._in_script = tag == "script"
        if tag == "script":
            self.scripts.append("")
        self.hrefs += [v for k, v in attrs if k in ("href", "src") and v is not None]
        self.handlers += [k for k, _ in attrs if k.startswith("on")]

    def handle_endtag(self, tag):
        self._in_script = False

    def handle_data(self, data):
        if self._in_script:
            self.scripts[-1] += data


def parsed(html: str) -> _Page:
    page = _Page()
    page.feed(html)
    return page


def test_the_hostile_caption_renders_as_inert_text():
    html = str(caption_html(HOSTILE_CAPTION))
    page = parsed(html)
    assert page.scripts == [] and page.handlers == []
    assert page.hrefs == ["https://example.org/"]  # the javascript: link is text now
    # the raw block and the inclusion are shown as text, escaped, and the file is not read
    assert "&lt;script&gt;document.title = &quot;PWNED&quot;&lt;/script&gt;" in html
    assert ".. include:: /etc/passwd" in html and "root:" not in html
    assert "&quot;raw&quot; directive disabled." in html and "&quot;include&quot; directive disabled." in html
    assert "link &lt;javascript:alert(document.domain)&gt;" in html


@pytest.mark.parametrize("source", [
    ".. raw:: html\n   :file: /etc/passwd",
    ".. csv-table:: t\n   :file: /etc/passwd",
    ".. role:: raw-html(raw)\n   :format: html\n\nx :raw-html:`<script>alert(1)</script>`",
    ".. image:: javascript:alert(1)\n   :target: javascript:alert(2)",
    ".. figure:: file:///etc/passwd\n\n   caption",
    "see evil_\n\n.. _evil: JavaScript:alert(1)",
    "bare javascript:alert(1) text",
    "`d <data:text/html;base64,PHNjcmlwdD5hbGVydCgxKTwvc2NyaXB0Pg==>`_",
])
def test_no_caption_markup_runs_a_script_or_reads_a_file(source):
    html = str(caption_html(source))
    page = parsed(html)
    assert page.scripts == [] and page.handlers == []
    assert all(link_allowed(h) for h in page.hrefs), page.hrefs
    assert "root:" not in html


@pytest.mark.parametrize("uri", ["https://doi.org/10.1109/x", "http://example.org", "mailto:a@b.org", "#fig1",
                                 "files/data/results/x.csv", "../x.html", "fig1.png", "HTTPS://EXAMPLE.ORG"])
def test_safe_addresses_stay_links(uri):
    assert link_allowed(uri)


@pytest.mark.parametrize("uri", ["javascript:alert(1)", "JavaScript:alert(1)", " javascript:alert(1)",
                                 "java\tscript:alert(1)", "java\nscript:alert(1)", "\x01javascript:x",
                                 "data:text/html,x", "file:///etc/passwd", "vbscript:x", "/etc/passwd",
                                 "//evil.example/x", "\\\\evil.example\\x", "ftp://example.org/x"])
def test_other_addresses_are_refused(uri):
    assert not link_allowed(uri)


def test_every_caption_of_the_papers_renders_without_a_message():
    # the settings that make a caption inert change nothing for a caption that parses cleanly
    for path in CAPTIONS:
        html = str(caption_html(path.read_text()))
        assert "system-message" not in html and "refused-link" not in html, path
