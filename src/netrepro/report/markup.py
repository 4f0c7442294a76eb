"""HTML text of the report: sanitising pages for offline use, relocating paths, escaping values.

* :func:`strip_external_scripts` drops everything a page would fetch from the network.
* :func:`relocate` / :func:`relocate_json` rewrite absolute paths of the build machine.
* :func:`render` fills a Jinja2 template of ``netrepro/report/templates/``; every page template
  sets the report's content security policy (``{{ csp }}``, :data:`netrepro.report.csp.PAGE_POLICY`).
"""

from __future__ import annotations

import base64
import functools
import json
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

from jinja2 import Environment, FileSystemBytecodeCache, PackageLoader
from jinja2.ext import Extension
from markupsafe import Markup, escape

from .captions import caption_html
from .csp import policy_attribute

if TYPE_CHECKING:  # pandas is imported where a table is read: the notebook driver and relocate never need it
    import pandas as pd

__all__ = ["NO_FAVICON", "strip_external_scripts", "with_empty_favicon", "relocate", "relocate_json", "render", "read_csv",
           "rst_html", "img", "num", "fmt_value", "short", "blank", "stylesheet", "script"]

_EXTERNAL = re.compile(r"<script[^>]*\bsrc=\"https?://[^\"]*\"[^>]*>\s*</script>|<link[^>]*\bhref=\"https?://[^\"]*\"[^>]*>",
                       re.I)
NO_FAVICON = '<link rel="icon" href="data:,">'
_INLINE_SCRIPT = re.compile(r"<script\b[^>]*>(.*?)</script>", re.I | re.S)
_REMOTE_IMPORT = re.compile(r"""import\s*\(?\s*["']https?://|\bfrom\s*["']https?://|=\s*["']https?://[^"']*\.m?js["']""")


def strip_external_scripts(text: str) -> str:
    """Remove scripts and style sheets fetched from the network (offline report).

    Drops ``<script src=http...>``, ``<link href=http...>`` and inline scripts that
    import modules from a URL (nbconvert's mermaid loader), so the page makes no
    network request and logs no console error when opened offline.

    Parameters
    ----------
    text : str
        An HTML page.

    Returns
    -------
    str
        The page without network requests, with an empty favicon.
    """
    text = with_empty_favicon(_EXTERNAL.sub("", text))
    return _INLINE_SCRIPT.sub(lambda m: "" if _REMOTE_IMPORT.search(m.group(1)) else m.group(0), text)


def with_empty_favicon(text: str) -> str:
    """A page that asks for no favicon (``<link rel="icon" href="data:,">``), unless it names one.

    A browser asks a page's server for ``/favicon.ico`` otherwise: a static page makes no request it
    cannot satisfy (over HTTP the request fails, and the console shows the error).

    Parameters
    ----------
    text : str
        An HTML page.

    Returns
    -------
    str
        The page, with :data:`NO_FAVICON` right after ``<head>`` if it had no icon.
    """
    if 'rel="icon"' in text:
        return text
    return re.sub(r"<head>", "<head>" + NO_FAVICON, text, count=1, flags=re.I)


_PYTHON_PATH = re.compile(r"(?<![\w.~-])/[^\s'\"<>]*/bin/(python[0-9.]*)")
# the bounds of a word (a run without whitespace, quotes or angle brackets) around a match
_WORD_END = re.compile(r"[\s'\"<>]|\Z")
_LAST_BREAK = re.compile(r".*[\s'\"<>]", re.S)


def relocate(text: str, root: str | Path) -> str:
    """``text`` with no absolute path of the build machine.

    Parameters
    ----------
    text : str
        Any text (a page, a command line).
    root : str or Path
        The checkout: paths under it become relative to it (``root`` itself ``.``).

    Returns
    -------
    str
        The text; interpreter paths (``/.../bin/python3``) are shortened to their last part.
    """
    return _relocate_under(text, str(Path(root).resolve()))


def _relocate_under(text: str, root: str) -> str:
    """:func:`relocate` with ``root`` already resolved."""
    text = text.replace(root + "/", "").replace(root, ".")
    # word by word: on a long word without spaces (a base64 image) the path pattern backtracks
    # from every '/', quadratic in the word's length (seconds per notebook page). Only the words
    # around an occurrence of "/bin/python" are visited (the whole 8 MB Snakemake report has
    # ~400,000 words and a few hundred such occurrences).
    parts, done = [], 0
    hit = text.find("/bin/python")
    while hit >= 0:
        start, end = _word_start(text, hit), _WORD_END.search(text, hit).start()
        parts += [text[done:start], _PYTHON_PATH.sub(r"\1", text[start:end])]
        done = end
        hit = text.find("/bin/python", end)
    return "".join(parts) + text[done:] if parts else text


def _word_start(text: str, pos: int, step: int = 256) -> int:
    """Where the word (a run without whitespace, quotes or angle brackets) holding ``text[pos]`` begins."""
    lo = pos
    while lo > 0:
        lo = max(0, lo - step)
        last = _LAST_BREAK.match(text, lo, pos)
        if last:
            return last.end()
    return 0


def relocate_json(obj, root: str | Path):
    """:func:`relocate` applied to every string of a JSON value.

    Parameters
    ----------
    obj : object
        A JSON value (a sidecar copied into the report).
    root : str or Path
        The checkout.

    Returns
    -------
    object
        The same structure with every string relocated.
    """
    return _relocate_json_under(obj, str(Path(root).resolve()))


def _relocate_json_under(obj, root: str):
    if isinstance(obj, str):
        return _relocate_under(obj, root)
    if isinstance(obj, list):
        return [_relocate_json_under(v, root) for v in obj]
    if isinstance(obj, dict):
        return {k: _relocate_json_under(v, root) for k, v in obj.items()}
    return obj


# ----------------------------------------------------------------------------- values
def blank(value):
    """``value`` as a template shows it: ``None`` and NaN as nothing.

    Parameters
    ----------
    value : object
        A cell of a table or a field of a sidecar.

    Returns
    -------
    object
        ``""`` for a missing value, else ``value``.
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return value


def num(value) -> Markup:
    """A number as a reader wants it (7 significant digits; the exact value on hover).

    Parameters
    ----------
    value : object
        A cell of a claims table.

    Returns
    -------
    markupsafe.Markup
        Escaped text, or a ``<span title=exact>`` holding the rounded number.
    """
    text = escape(blank(value))
    try:
        number = float(value)
    except (TypeError, ValueError):
        return text
    if isinstance(value, bool) or not math.isfinite(number) or number == int(number) and abs(number) < 1e15:
        return text
    shown = f"{number:.7g}"
    return text if shown == str(value) else Markup('<span title="{}">{}</span>').format(text, shown)


def fmt_value(value) -> str:
    """A parameter's value in one line (lists and dicts as JSON, cut at 120 characters).

    Parameters
    ----------
    value : object
        A leaf of a step's params.

    Returns
    -------
    str
        The text shown.
    """
    if isinstance(value, (list, dict)):
        text = json.dumps(value)
        return text if len(text) <= 120 else text[:117] + "..."
    return str(value)


def short(sha) -> str:
    """The first 12 characters of a checksum or commit (``""`` if none).

    Parameters
    ----------
    sha : str or None
        A checksum.

    Returns
    -------
    str
        Its prefix.
    """
    return str(sha or "")[:12]


def rst_html(text: str) -> Markup:
    """Render a caption written in reStructuredText, inert (:func:`netrepro.report.captions.caption_html`).

    Raw HTML and file insertion are off and links go only to http(s), mailto, ``#`` and relative
    addresses: a caption can show text, never run a script or read a file.

    Parameters
    ----------
    text : str
        The caption.

    Returns
    -------
    markupsafe.Markup
        Its HTML body (``""`` for an empty caption).
    """
    return caption_html(text)


def img(path: Path) -> Markup:
    """An ``<img>`` with the PNG embedded (the report works offline).

    Parameters
    ----------
    path : Path
        A PNG file.

    Returns
    -------
    markupsafe.Markup
        The tag.
    """
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return Markup('<img src="data:image/png;base64,{}" alt="{}" loading="eager">').format(data, Path(path).stem)


def read_csv(path) -> pd.DataFrame | None:
    """A table, ``None`` if it is not built, an empty frame if it is empty.

    The report reads a paper's claims, errata and findings tables in several sections: each
    version of a file (size, modification time) is parsed once. The frame is shared: callers
    must not modify it.

    Parameters
    ----------
    path : str or Path
        A CSV file.

    Returns
    -------
    pandas.DataFrame or None
        The table.
    """
    path = Path(path)
    if not path.is_file():
        return None
    stat = path.stat()
    return _read_csv(str(path), stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=256)
def _read_csv(path: str, mtime_ns: int, size: int) -> pd.DataFrame:
    import pandas as pd

    try:
        return pd.read_csv(path)
    except pd.errors.EmptyDataError:
        return pd.DataFrame()


# ----------------------------------------------------------------------------- templates
class _JoinLines(Extension):
    """Templates are written over lines for reading: a line break and the indentation after it
    are not part of the page (write ``{{ "\\n" }}`` for a line break that is)."""

    def preprocess(self, source, name, filename=None):
        return re.sub(r"\n[ \t]*", "", source)


def _finalize(value):
    return blank(value)


class _Bytecode(FileSystemBytecodeCache):
    """Compiled templates kept in Jinja2's per-user cache directory (keyed by the template's
    source checksum), so that the report job does not compile them again; a cache it cannot
    write is skipped."""

    def dump_bytecode(self, bucket):
        try:
            super().dump_bytecode(bucket)
        except OSError:
            pass


def _bytecode_cache():
    try:
        return _Bytecode()
    except OSError:  # no usable cache directory
        return None


_ENV = Environment(loader=PackageLoader("netrepro.report", "templates"), autoescape=True,
                   extensions=[_JoinLines], finalize=_finalize, keep_trailing_newline=False,
                   bytecode_cache=_bytecode_cache())
_ENV.globals["csp"] = policy_attribute()  # <meta http-equiv="Content-Security-Policy" content="{{ csp }}">
_ENV.filters.update(num=num, value=fmt_value, short=short, rst=rst_html,
                    css=lambda text: re.sub(r"[^a-z]+", "-", str(text).lower()).strip("-"))


def render(name: str, **context) -> str:
    """Fill the template ``name`` of ``netrepro/report/templates/``.

    Parameters
    ----------
    name : str
        The template's file name.
    **context
        Its variables.

    Returns
    -------
    str
        The HTML.
    """
    return _ENV.get_template(name).render(**context)


def stylesheet() -> Markup:
    """The report's one style sheet (``templates/report.css``), inlined into the page.

    Returns
    -------
    markupsafe.Markup
        The CSS.
    """
    return Markup(_ENV.loader.get_source(_ENV, "report.css")[0])


def script(name: str) -> Markup:
    """A script of ``templates/`` (``explorer.js``), its text exactly as the page will hold it.

    The page allows it by the hash of this text (:func:`netrepro.report.csp.page_policy`), so it is
    inserted as it is: not through a template (whose line joining would change it). A script that
    holds ``</script`` would end its element early and is refused.

    Parameters
    ----------
    name : str
        The file's name in ``templates/``.

    Returns
    -------
    markupsafe.Markup
        The script's text.

    Raises
    ------
    ValueError
        The text holds ``</script``.
    """
    text = _ENV.loader.get_source(_ENV, name)[0]
    if "</script" in text.lower():
        raise ValueError(f"{name}: a script holding '</script' cannot be inlined")
    return Markup(text)
