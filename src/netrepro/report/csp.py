"""The content security policy of every page the report writes (issue 38).

A page's policy, set by a ``<meta http-equiv="Content-Security-Policy">`` at the top of its head,
is what the browser lets the page load and run whatever text ends up in it:

* our pages (``report/index.html``, the source pages, the notebook pages) run no script at all,
  load images from their own folder or ``data:`` only and nothing from the network
  (:data:`PAGE_POLICY`); a page that ships a script of its own (``report/index.html``'s claims
  explorer, ``templates/explorer.js``) allows that script alone, by its hash
  (:func:`page_policy`, :func:`script_hash`), never ``'unsafe-inline'``;
* Snakemake's report (``report/snakemake_report.html``, sealed by ``python -m netrepro report
  relocate``) is a JavaScript application: its policy (:func:`snakemake_report_policy`) allows
  exactly the scripts that Snakemake's installed template and libraries put there, and the data
  scripts that only assign JSON (``var results = {...};``); a script that came with a caption
  or any other text is not among them and does not run, and nothing is loaded from the network.
"""

from __future__ import annotations

import base64
import functools
import hashlib
import importlib.util
import json
import re
from pathlib import Path

from markupsafe import Markup

__all__ = ["PAGE_POLICY", "page_policy", "policy_text", "policy_attribute", "script_hash", "csp_meta", "with_csp", "inline_scripts",
           "is_data_script", "snakemake_known_scripts", "snakemake_report_policy"]

# Our pages: no script, no network, images and styles of the page itself.
PAGE_POLICY: dict[str, tuple[str, ...]] = {
    "default-src": ("'none'",),
    "script-src": ("'none'",),
    "img-src": ("'self'", "data:"),
    "style-src": ("'self'", "'unsafe-inline'"),
    "base-uri": ("'none'",),
    "form-action": ("'none'",),
}

_CSP_META = re.compile(r"""<meta\s+http-equiv=["']?content-security-policy["']?[^>]*>""", re.I)
_HEAD = re.compile(r"<head\b[^>]*>", re.I)
_CHARSET = re.compile(r"<meta\s+charset=[^>]*>", re.I)
# an inline script: its attributes and its text (a script with src= has no text to hash)
_SCRIPT = re.compile(r"<script\b([^>]*)>(.*?)</script\s*>", re.I | re.S)
# ``var name = <JSON>;``: a script that only assigns data (Snakemake's report keeps its data so)
_DATA_SCRIPT = re.compile(r"\s*var\s+[A-Za-z_$][\w$]*\s*=\s*(.*?);\s*", re.S)
# the same, read without a lazy group over the whole text (Snakemake's data scripts are megabytes)
_DATA_HEAD = re.compile(r"\s*var\s+[A-Za-z_$][\w$]*\s*=\s*")
_SCRIPT_OPEN = re.compile(r"<script\b([^>]*)>", re.I)
_SCRIPT_CLOSE = re.compile(r"</script\s*>", re.I)


def policy_text(policy: dict) -> str:
    """A policy as the header's text: ``directive source source; ...``.

    Parameters
    ----------
    policy : dict
        Directive -> its sources (in order).

    Returns
    -------
    str
        The policy (``"default-src 'none'; script-src 'none'; ..."``).
    """
    return "; ".join(" ".join([directive, *sources]) for directive, sources in policy.items())


def script_hash(text: str) -> str:
    """The ``script-src`` source that allows one inline script: ``'sha256-<base64>'``.

    Parameters
    ----------
    text : str
        The script's text, as between ``<script>`` and ``</script>`` in the page (the browser hashes
        the text after the HTML parser has turned CR LF and CR into LF; so does this function).

    Returns
    -------
    str
        The source expression, quotes included.
    """
    normalised = text.replace("\r\n", "\n").replace("\r", "\n")
    return "'sha256-" + base64.b64encode(hashlib.sha256(normalised.encode()).digest()).decode() + "'"


def page_policy(*scripts: str) -> dict[str, tuple[str, ...]]:
    """:data:`PAGE_POLICY` allowing exactly the inline ``scripts`` (by their hashes).

    Parameters
    ----------
    *scripts : str
        The texts of the page's own inline scripts, as between ``<script>`` and ``</script>``.

    Returns
    -------
    dict
        Directive -> sources: ``script-src`` lists the scripts' hashes (``'none'`` without a script);
        everything else is :data:`PAGE_POLICY`'s. An event handler attribute, a ``javascript:`` link
        or any other inline script stays blocked (no ``'unsafe-inline'``, no ``'unsafe-hashes'``).
    """
    hashes = tuple(dict.fromkeys(script_hash(text) for text in scripts))
    return {**PAGE_POLICY, "script-src": hashes or ("'none'",)}


def csp_meta(policy: dict = PAGE_POLICY) -> Markup:
    """The ``<meta>`` element that sets ``policy`` on a page.

    Parameters
    ----------
    policy : dict, default :data:`PAGE_POLICY`
        Directive -> sources.

    Returns
    -------
    markupsafe.Markup
        The element.
    """
    return Markup(f'<meta http-equiv="Content-Security-Policy" content="{policy_attribute(policy)}">')


def policy_attribute(policy: dict = PAGE_POLICY) -> Markup:
    """A policy as the value of a double-quoted HTML attribute (its quotes ``'`` kept as they are).

    Parameters
    ----------
    policy : dict, default :data:`PAGE_POLICY`
        Directive -> sources.

    Returns
    -------
    markupsafe.Markup
        The text, with ``&``, ``"``, ``<`` and ``>`` escaped.
    """
    text = policy_text(policy)
    return Markup(text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace(">", "&gt;"))


def with_csp(page: str, policy: dict = PAGE_POLICY) -> str:
    """``page`` with ``policy`` as its content security policy.

    The ``<meta>`` goes right after the page's ``<meta charset>`` (or its ``<head>``): a policy set
    by a meta element governs only what follows it. A policy the page already had is replaced,
    so sealing a page twice gives the same page.

    Parameters
    ----------
    page : str
        An HTML page with a ``<head>``.
    policy : dict, default :data:`PAGE_POLICY`
        Directive -> sources.

    Returns
    -------
    str
        The page with the policy.

    Raises
    ------
    ValueError
        The page has no ``<head>`` (where the policy must go).
    """
    page = _CSP_META.sub("", page)
    anchor = _CHARSET.search(page) or _HEAD.search(page)
    if anchor is None:
        raise ValueError("the page has no <head>: its content security policy has no place to go")
    return page[:anchor.end()] + str(csp_meta(policy)) + page[anchor.end():]


def inline_scripts(page: str) -> list[tuple[str, str]]:
    """The inline scripts of a page, in order.

    The elements ``<script ...>...</script>`` that ``_SCRIPT`` finds, found by locating each opening
    tag and the next closing tag (a lazy regex group over a page of megabytes was most of
    ``relocate``'s time).

    Parameters
    ----------
    page : str
        An HTML page.

    Returns
    -------
    list of tuple
        ``(attributes, text)`` of each ``<script>`` element without ``src``.
    """
    out, pos, lowered = [], 0, page.lower()
    while True:
        start = lowered.find("<script", pos)
        if start < 0:
            break
        opening = _SCRIPT_OPEN.match(page, start)
        if opening is None:
            pos = start + 7
            continue
        closing = _SCRIPT_CLOSE.search(page, opening.end())
        if closing is None:
            break
        attrs = opening.group(1)
        if not re.search(r"\bsrc\s*=", attrs, re.I):
            out.append((attrs, page[opening.end():closing.start()]))
        pos = closing.end()
    return out


def is_data_script(text: str) -> bool:
    """Whether a script only assigns one JSON value to a variable (``var x = {...};``).

    Parameters
    ----------
    text : str
        A script's text.

    Returns
    -------
    bool
        True if the text is ``var <name> = <JSON>;`` and nothing else: running it computes
        nothing and calls nothing.
    """
    head = _DATA_HEAD.match(text)
    if head is None:
        return False
    body = text[head.end():].rstrip()
    if not body.endswith(";"):
        return False
    try:
        json.loads(body[:-1])
    except ValueError:
        return False
    return True


@functools.lru_cache(maxsize=1)
def snakemake_known_scripts() -> frozenset[str]:
    """The texts of the scripts that the installed Snakemake's report template puts into its page.

    The template's fixed inline scripts, its components (``template/components/*.js``) and the
    libraries it embeds (React, Vega, ..., the ``.js`` and ``.css`` files of Snakemake's assets: the
    template puts Tailwind's ``tailwind.css`` into a script). Read from Snakemake's installed files
    without importing it (``relocate`` is the last, serial step of ``make report``).

    Returns
    -------
    frozenset of str
        The scripts' texts (empty if Snakemake or its report assets are not installed).
    """
    spec = importlib.util.find_spec("snakemake")
    if spec is None or not spec.submodule_search_locations:
        return frozenset()
    package = Path(next(iter(spec.submodule_search_locations)))
    template = package / "report" / "html_reporter" / "template"
    try:
        page = (template / "index.html.jinja2").read_text(encoding="utf-8")
    except OSError:
        return frozenset()
    texts = {text for _, text in inline_scripts(page) if "{{" not in text and "{%" not in text}
    files = [*(template / "components").glob("*.js"), *(package / "assets" / "data").rglob("*.js"),
             *(package / "assets" / "data").rglob("*.css")]
    texts |= {path.read_text(encoding="utf-8") for path in files}
    return frozenset(texts)


def snakemake_report_policy(page: str, known: frozenset[str] | None = None) -> dict:
    """The content security policy of Snakemake's report ``page``.

    Allows, by hash, each inline script of the page that Snakemake's template or libraries wrote
    (``known``) or that only assigns JSON data (:func:`is_data_script`), and nothing else: a
    script that a caption or another text brought into the page stays inert, and so do inline
    event handlers and ``javascript:`` links. Vega (the rule graph, the run-time plots) compiles
    its expressions with ``Function``, hence ``'unsafe-eval'``: it lets the allowed scripts build
    functions from strings and does not let any other script run.

    Parameters
    ----------
    page : str
        ``report/snakemake_report.html``.
    known : frozenset of str, optional
        The texts of Snakemake's own scripts (default: :func:`snakemake_known_scripts`).

    Returns
    -------
    dict
        Directive -> sources.
    """
    known = snakemake_known_scripts() if known is None else known
    hashes = dict.fromkeys(script_hash(text) for attrs, text in inline_scripts(page)
                           if text in known or is_data_script(text))
    return {
        "default-src": ("'none'",),
        "script-src": (*hashes, "'unsafe-eval'") if hashes else ("'none'",),
        "img-src": ("'self'", "data:", "blob:"),
        "style-src": ("'self'", "'unsafe-inline'"),
        "font-src": ("'self'", "data:"),
        "frame-src": ("'self'", "data:", "blob:"),
        "base-uri": ("'none'",),
        "form-action": ("'none'",),
    }
