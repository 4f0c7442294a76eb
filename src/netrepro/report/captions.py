"""Figure captions (``workflow/report/<paper>/<figure>.rst``) as HTML that cannot run or read anything.

A caption is text an author wrote, shown in ``report/index.html`` and in the paper's notebook page.
Rendered as it was, a ``.. raw:: html`` block put a live ``<script>`` into the page, an
``.. include:: /etc/passwd`` put the file into it, and a ``javascript:`` link ran on a click
(issue 38). :func:`caption_html` renders reStructuredText with

* raw HTML off (``raw_enabled``): the block is shown as text inside a note saying it was not run;
* file insertion off (``file_insertion_enabled``): ``include``, ``raw :file:``, ``csv-table :file:``
  are shown the same way, and no file is read;
* links and images only to the addresses :func:`link_allowed` accepts (http(s), mailto, ``#``
  fragments, relative paths); any other becomes its text followed by the refused address, as text.
"""

from __future__ import annotations

import re

from markupsafe import Markup

__all__ = ["ALLOWED_SCHEMES", "link_allowed", "caption_html"]

ALLOWED_SCHEMES = frozenset({"http", "https", "mailto"})
# what a browser drops from a URL before reading its scheme: leading and trailing C0 controls and
# spaces, and every tab and line break inside it ("java\tscript:" is "javascript:")
_URL_STRIP = re.compile(r"^[\x00-\x20]+|[\x00-\x20]+$")
_URL_TAB_NEWLINE = re.compile(r"[\t\n\r]")
_SCHEME = re.compile(r"^([a-zA-Z][a-zA-Z0-9+.\-]*):")


def link_allowed(uri: str) -> bool:
    """Whether a caption may link to (or show an image from) ``uri``.

    Allowed: ``http:``, ``https:`` and ``mailto:`` addresses, ``#`` fragments and relative paths.
    Refused: every other scheme (``javascript:``, ``data:``, ``file:``, ``vbscript:``, ...), also
    when hidden by case, spaces, tabs or line breaks as a browser reads them, and addresses that
    leave the report's folder by their form: absolute paths (``/etc/passwd``) and scheme-relative
    addresses (``//host/x``, ``\\\\host\\x``).

    Parameters
    ----------
    uri : str
        The address as written in the caption.

    Returns
    -------
    bool
        True if the address may stay a live link.
    """
    cleaned = _URL_TAB_NEWLINE.sub("", _URL_STRIP.sub("", str(uri))).replace("\\", "/")
    scheme = _SCHEME.match(cleaned)
    if scheme:
        return scheme.group(1).lower() in ALLOWED_SCHEMES
    return not cleaned.startswith("/")


def _settings() -> dict:
    """docutils settings of a caption: no raw HTML, no file read, messages as text in the page."""
    return {
        "raw_enabled": False,
        "file_insertion_enabled": False,
        # a disabled directive is a warning (level 2): shown where it stands, with its text as a
        # literal block; captions that parse cleanly (tests/test_captions.py) show no message
        "report_level": 2,
        "halt_level": 5,
        "warning_stream": False,  # the messages are in the page; none is printed
        "syntax_highlight": "none",
        "embed_stylesheet": False,
        "math_output": "HTML",
        "_disable_config": True,  # no docutils.conf of the machine or the user changes the settings
    }


def _inert_links(doctree) -> None:
    """Replace, in place, every link and image whose address :func:`link_allowed` refuses by text."""
    from docutils import nodes

    for ref in list(doctree.findall(nodes.reference)):
        uri = ref.get("refuri")
        if uri is not None and not link_allowed(uri):
            text = nodes.inline("", "", *ref.children, classes=["refused-link"])
            text += nodes.Text(f" <{uri}>")
            ref.replace_self(text)
    for image in list(doctree.findall(nodes.image)):
        uri = image.get("uri", "")
        if not link_allowed(uri):
            image.replace_self(nodes.inline("", f"[image not shown: {uri}]", classes=["refused-link"]))
    for target in doctree.findall(nodes.target):
        if target.get("refuri") is not None and not link_allowed(target["refuri"]):
            del target["refuri"]


def _caption_reader():
    """A docutils reader whose last transform is :func:`_inert_links` (after links are resolved)."""
    from docutils.readers import standalone
    from docutils.transforms import Transform

    class InertLinks(Transform):
        default_priority = 990  # after the targets of references are resolved (640-680)

        def apply(self):
            _inert_links(self.document)

    class CaptionReader(standalone.Reader):
        def get_transforms(self):
            return [*super().get_transforms(), InertLinks]

    return CaptionReader()


def _render(text: str) -> str:
    """The HTML body of ``text`` (reStructuredText) with the settings and link rule of a caption."""
    from docutils.core import publish_parts

    return publish_parts(text, reader=_caption_reader(), writer="html5", settings_overrides=_settings())["body"]


def caption_html(text: str) -> Markup:
    """A caption written in reStructuredText, as HTML that runs nothing and reads no file.

    Parameters
    ----------
    text : str
        The caption.

    Returns
    -------
    markupsafe.Markup
        Its HTML body (``""`` for an empty caption); if docutils fails, the text as escaped paragraphs.
    """
    text = text.strip()
    if not text:
        return Markup("")
    try:
        return Markup(_render(text))
    except Exception:  # noqa: BLE001 - any docutils failure falls back to plain text
        return Markup("").join(Markup("<p>{}</p>").format(p) for p in re.split(r"\n\s*\n", text))
