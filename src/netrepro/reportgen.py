"""The report: per-paper papermill notebooks and the combined ``report/index.html``.

* ``make-notebook`` writes a thin parameterised notebook for a paper (load
  tables, show figures and their captions, print the claim, erratum and
  reconstruction tables). Papers may add cells.
* ``notebook`` executes a paper's notebook with papermill and exports it to
  static HTML with no external scripts (works offline).
* :func:`build_index` (a pipeline step) writes the combined index: a scorecard
  over papers, the run's identity, and per figure a provenance panel traced
  through the provenance sidecars of the figure and of every table upstream.
"""

from __future__ import annotations

import argparse
import base64
import datetime as _dt
import html
import json
import os
import platform
import re
import shlex
import sys
from pathlib import Path

import pandas as pd

from .errors import ConfigError
from .io import atomic_path
from .registry import load_registry
from .provenance import git_state, package_versions, params_hash, sidecar_path
from .crate import iso, write_crate
from .references import references_html
from .figurespec import load_figure_specs
from .summary import replication_summary, scorecard, summary_sentences
from .verdicts import TESTABLE_VERDICTS, VERDICTS

__all__ = ["make_notebook", "execute_notebook", "strip_external_scripts", "build_index", "provenance_chain",
           "scorecard", "rule_for", "workflow_producers", "config_keys", "main"]

SCORE_VERDICTS = VERDICTS


# ----------------------------------------------------------------------------- notebooks
def _cells(slug: str):
    import nbformat.v4 as nbf

    params = nbf.new_code_cell(f'slug = "{slug}"\nroot = "."')
    params.metadata["tags"] = ["parameters"]
    return [
        params,
        nbf.new_code_cell(
            "from pathlib import Path\nimport pandas as pd\n"
            "from netrepro.reportgen import figure_captions, show_figures, show_table\n"
            "root = Path(root)"
        ),
        nbf.new_markdown_cell(f"# Paper `{slug}`\nFigures (rendered by the pipeline's figure rules), then the claim, "
                              "erratum, finding and reconstruction tables. Every value below is read from `results/`."),
        nbf.new_code_cell("show_figures(root, slug)"),
        nbf.new_markdown_cell("## Claims"),
        nbf.new_code_cell('show_table(root / "results" / "claims" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Errata"),
        nbf.new_code_cell('show_table(root / "results" / "errata" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Findings (ours, beyond the paper)"),
        nbf.new_code_cell('show_table(root / "results" / "findings" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Reconstructions"),
        nbf.new_code_cell('show_table(root / "results" / "reconstructions" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Result tables (first rows)"),
        nbf.new_code_cell(
            'for table in sorted((root / "results" / slug).glob("*.csv")):\n'
            '    print(table.relative_to(root))\n'
            '    show_table(table, max_rows=8)'
        ),
    ]


def make_notebook(slug: str, path: str | Path) -> Path:
    """Write the default thin notebook of paper ``slug``."""
    import nbformat
    import nbformat.v4 as nbf

    nb = nbf.new_notebook(cells=_cells(slug))
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, str(path))
    return path


def figure_captions(root: Path, slug: str) -> dict:
    """Figure stem -> caption text from ``workflow/report/<slug>/<stem>.rst``."""
    folder = Path(root) / "workflow" / "report" / slug
    return {p.stem: p.read_text().strip() for p in sorted(folder.glob("*.rst"))}


def _figure_sort_key(path: Path):
    match = re.match(r"fig(S?)(\d+)", path.stem)
    return (bool(match and match.group(1)), int(match.group(2)) if match else 0, path.stem)


def show_figures(root, slug):
    """Display the paper's figures with captions (used inside notebooks)."""
    from IPython.display import Image, Markdown, display

    captions = figure_captions(root, slug)
    for fig in sorted((Path(root) / "figures" / slug).glob("*.png"), key=_figure_sort_key):
        display(Markdown(f"### {fig.stem}\n{captions.get(fig.stem, '')}"))
        display(Image(filename=str(fig)))


def show_table(path, max_rows=None):
    """Display a CSV table as HTML (used inside notebooks)."""
    from IPython.display import HTML, display

    path = Path(path)
    if not path.is_file():
        display(HTML(f"<p><em>{html.escape(str(path))} not built</em></p>"))
        return
    frame = pd.read_csv(path)
    if max_rows is not None:
        frame = frame.head(max_rows)
    display(HTML(frame.to_html(index=False, escape=True, na_rep="")))


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
    """
    text = _EXTERNAL.sub("", text)
    if 'rel="icon"' not in text:  # no favicon request: a static page makes no request it cannot satisfy
        text = re.sub(r"<head>", "<head>" + NO_FAVICON, text, count=1, flags=re.I)
    return _INLINE_SCRIPT.sub(lambda m: "" if _REMOTE_IMPORT.search(m.group(1)) else m.group(0), text)


_PYTHON_PATH = re.compile(r"(?<![\w.~-])/[^\s'\"<>]*/bin/(python[0-9.]*)")
_WORD = re.compile(r"[^\s'\"<>]+")


def _short_interpreter(word: re.Match) -> str:
    text = word.group(0)
    return _PYTHON_PATH.sub(r"\1", text) if "/bin/python" in text else text


def relocate(text: str, root: str | Path) -> str:
    """``text`` with no absolute path of the build machine: paths under ``root`` become relative
    to it (``root`` itself ``.``), and interpreter paths (``/.../bin/python3``) their last part."""
    return _relocate_under(text, str(Path(root).resolve()))


def _relocate_under(text: str, root: str) -> str:
    """:func:`relocate` with ``root`` already resolved."""
    text = text.replace(root + "/", "").replace(root, ".")
    if "/bin/python" not in text:
        return text
    # word by word: on a long word without spaces (a base64 image) the path pattern backtracks
    # from every '/', quadratic in the word's length (seconds per notebook page)
    return _WORD.sub(_short_interpreter, text)


def relocate_json(obj, root: str | Path):
    """:func:`relocate` applied to every string of a JSON value (sidecars copied into the report)."""
    return _relocate_json_under(obj, str(Path(root).resolve()))


def _relocate_json_under(obj, root: str):
    if isinstance(obj, str):
        return _relocate_under(obj, root)
    if isinstance(obj, list):
        return [_relocate_json_under(v, root) for v in obj]
    if isinstance(obj, dict):
        return {k: _relocate_json_under(v, root) for k, v in obj.items()}
    return obj


def execute_notebook(slug: str, notebook: str | Path, html_out: str | Path, root: str | Path = ".") -> Path:
    """Run ``notebook`` with papermill (parameters ``slug``, ``root``) and export static HTML."""
    import nbformat
    import papermill
    from nbconvert import HTMLExporter

    # The kernel runs in ``root``, so the parameter cell says ``root = "."``: the page shows no
    # path of the machine that built it (and any path a warning prints is made relative too).
    print("command:", shlex.join(getattr(sys, "orig_argv", sys.argv)), flush=True)
    root = Path(root).resolve()
    html_out = Path(html_out)
    executed = html_out.with_suffix(".ipynb")
    papermill.execute_notebook(str(notebook), str(executed), parameters={"slug": slug, "root": "."},
                               kernel_name="python3", cwd=str(root), progress_bar=False,
                               request_save_on_cell_execute=False)
    exporter = HTMLExporter()
    body, _ = exporter.from_notebook_node(nbformat.read(str(executed), as_version=4))
    with atomic_path(html_out) as tmp:
        tmp.write_text(relocate(strip_external_scripts(body), root))
    os.chmod(html_out, 0o644)
    return html_out


# ----------------------------------------------------------------------------- index
def provenance_chain(path: str | Path, seen=None) -> list[dict]:
    """Sidecars of ``path`` and of every upstream input that has one (depth first, no repeats)."""
    seen = set() if seen is None else seen
    path = Path(path)
    side = sidecar_path(path)
    if str(path) in seen or not side.is_file():
        return []
    seen.add(str(path))
    meta = json.loads(side.read_text())
    chain = [meta]
    for item in meta.get("inputs", {}).values():
        chain.extend(provenance_chain(item["path"], seen))
    return chain


def workflow_producers(rules) -> dict:
    """Output file -> name of the rule producing it, from Snakemake's ``workflow.rules``.

    Outputs with wildcards are given as regular expressions. The result is the
    ``producers`` parameter of :func:`build_index` (see :func:`rule_for`).
    """
    files, patterns = {}, []
    for each in rules:
        for out in each.output:
            if out.contains_wildcard():
                patterns.append([out.regex().pattern, each.name])
            else:
                files[str(out)] = each.name
    return {"files": files, "patterns": patterns}


def rule_for(path: str | Path, producers: dict | None) -> str | None:
    """Name of the Snakemake rule producing ``path``, from the workflow's own rule table.

    ``producers`` is ``{"files": {path: rule}, "patterns": [[regex, rule], ...]}``
    as built by ``workflow/rules/report.smk`` from ``workflow.rules``.
    """
    if not producers:
        return None
    path = str(path)
    if path in producers.get("files", {}):
        return producers["files"][path]
    for pattern, name in producers.get("patterns", []):
        if re.fullmatch(pattern, path):
            return name
    return None


def _rule_name(meta: dict, producers: dict | None) -> str:
    """The rule that made a sidecar's output: the workflow's rule table first, then the sidecar."""
    name = rule_for(meta.get("output", ""), producers)
    recorded = str(meta.get("rule", ""))
    if name:
        return name
    return recorded if recorded and "@" not in recorded else "?"


def _repo_relative(source_file: str) -> str:
    """``src/netrepro/...`` form of a source path recorded as absolute (editable installs)."""
    source_file = str(source_file)
    marker = "src/netrepro/"
    if marker in source_file and not source_file.startswith(marker):
        return source_file[source_file.index(marker):]
    return source_file


def _flatten(obj, prefix="") -> dict:
    """Nested dict -> ``{"a.b.c": leaf}`` (lists are leaves)."""
    if isinstance(obj, dict) and obj:
        flat = {}
        for key, value in obj.items():
            flat.update(_flatten(value, f"{prefix}.{key}" if prefix else str(key)))
        return flat
    return {prefix: obj} if prefix else {}


def config_keys(params: dict, config_section: dict, slug: str) -> list[tuple[str, object, bool]]:
    """Each leaf of a step's params with the configuration key it came from.

    Returns ``(key, value, from_config)``: ``key`` is the dotted configuration path
    (``slug.section.name``) when exactly one configuration entry ends with the
    param's name and holds the same value, otherwise the param's own name
    (a constant fixed in the rule, ``from_config`` False).
    """
    # configuration keys by their last part (a key equal to the param's, or ending in it, has its last part)
    by_leaf: dict[str, list] = {}
    for k, v in _flatten(config_section or {}).items():
        by_leaf.setdefault(k.split(".")[-1], []).append((k, v))
    matches = {}
    for key, value in _flatten(params or {}).items():
        hits = [k for k, v in by_leaf.get(key.split(".")[-1], ()) if v == value]
        exact = [k for k in hits if k == key or k.endswith("." + key)]
        matches[key] = (value, exact or hits)
    # A step reads one or a few sections: an ambiguous key comes from the section its unambiguous keys come from.
    sections: dict[str, int] = {}
    for _, hits in matches.values():
        if len(hits) == 1:
            parent = hits[0].rpartition(".")[0]
            sections[parent] = sections.get(parent, 0) + 1
    out = []
    for key, (value, hits) in matches.items():
        if len(hits) > 1 and sections:
            best = max(sections.get(h.rpartition(".")[0], 0) for h in hits)
            preferred = [h for h in hits if sections.get(h.rpartition(".")[0], 0) == best]
            hits = preferred if best > 0 else hits
        if len(hits) == 1:
            out.append((f"{slug}.{hits[0]}", value, True))
        elif hits:
            out.append((" | ".join(f"{slug}.{h}" for h in hits), value, True))
        else:
            out.append((key, value, False))
    return out


def _img(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(path.stem)}" loading="eager">'


def _esc(value) -> str:
    if value is None or (isinstance(value, float) and pd.isna(value)):
        return ""
    return html.escape(str(value))


def _fmt_value(value) -> str:
    if isinstance(value, (list, dict)):
        text = json.dumps(value)
        return text if len(text) <= 120 else text[:117] + "..."
    return str(value)


def _rst_html(text: str) -> str:
    """Render a caption written in reStructuredText (fallback: escaped paragraphs)."""
    text = text.strip()
    if not text:
        return ""
    try:
        from docutils.core import publish_parts

        body = publish_parts(text, writer_name="html5",
                             settings_overrides={"report_level": 5, "halt_level": 5, "syntax_highlight": "none",
                                                 "embed_stylesheet": False, "math_output": "HTML"})["body"]
        return body
    except Exception:  # noqa: BLE001 - any docutils failure falls back to plain text
        return "".join(f"<p>{html.escape(p)}</p>" for p in re.split(r"\n\s*\n", text))


def _table_html(frame: pd.DataFrame, css="data", table_id=None) -> str:
    head = "".join(f"<th>{_esc(c)}</th>" for c in frame.columns)
    body = "".join("<tr>" + "".join(f"<td>{_esc(v)}</td>" for v in row) + "</tr>"
                   for row in frame.itertuples(index=False))
    tid = f' id="{table_id}"' if table_id else ""
    return f'<div class="scroll"><table class="{css}"{tid}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>'


def _read_csv(path) -> pd.DataFrame | None:
    path = Path(path)
    if not path.is_file():
        return None
    try:
        return pd.read_csv(path)
    except pd.errors.EmptyDataError:
        return pd.DataFrame()


class _Site:
    """Files the index links to, copied under ``report/files/`` so the report is self-contained."""

    def __init__(self, root: Path, out_dir: Path | None, workers: int = 1):
        self.root = root
        self.workers = workers  # processes that highlight the source pages
        self.out_dir = out_dir
        self.sources: set[str] = set()
        self.tables: set[str] = set()
        self.raw: dict[str, str] = {}  # copy target under files/ -> source file (workflow, config)

    def source_link(self, source_file: str, line=None) -> str:
        rel = _repo_relative(source_file)
        if self.out_dir is None or not (self.root / rel).is_file():
            return f"../{rel}"
        self.sources.add(rel)
        return f"files/source/{rel}.html" + (f"#L-{int(line)}" if line else "")

    def table_link(self, path: str) -> str:
        if self.out_dir is None or not (self.root / path).is_file():
            return f"../{path}"
        self.tables.add(str(path))
        return f"files/data/{path}"

    def write(self) -> None:
        if self.out_dir is None:
            return
        import shutil

        self.out_dir.mkdir(parents=True, exist_ok=True)
        for rel in sorted(self.tables):
            target = self.out_dir / "data" / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(self.root / rel, target)
            side = sidecar_path(self.root / rel)
            if side.is_file():  # relocated: no absolute path of the build machine in the report
                meta = relocate_json(json.loads(side.read_text()), self.root)
                sidecar_path(target).write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
        for rel, source in sorted(self.raw.items()):
            target = self.out_dir / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(self.root / source, target)
        rels = sorted(self.sources)
        for rel, page in zip(rels, _source_pages(self.root, rels, self.workers)):
            target = self.out_dir / "source" / f"{rel}.html"
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(page)


def _source_pages_of(root: Path, rels: list[str]) -> list[str]:
    """:func:`_source_page` of each file ``rels`` (relative to ``root``), in order."""
    return [_source_page(rel, (root / rel).read_text()) for rel in rels]


def _source_pages(root: Path, rels: list[str], workers: int = 1) -> list[str]:
    """The source pages of ``rels``, in order, highlighted by up to ``workers`` processes.

    Highlighting (pygments' Python lexer) is most of the report rule's time, and the rule runs
    last, alone: with ``threads: 2`` the second core takes half of the files (interleaved by
    size, so both halves take about as long). The pages do not depend on the split.
    """
    workers = max(1, min(int(workers), len(rels)))
    if workers == 1:
        return _source_pages_of(root, rels)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    by_size = sorted(range(len(rels)), key=lambda i: -(root / rels[i]).stat().st_size)
    shares = [by_size[w::workers] for w in range(workers)]
    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        done = pool.map(_source_pages_of, [root] * workers, [[rels[i] for i in share] for share in shares])
        pages = [""] * len(rels)
        for share, share_pages in zip(shares, done):
            for i, page in zip(share, share_pages):
                pages[i] = page
    return pages


def _source_page(rel: str, code: str) -> str:
    """A static, offline page of one source file; line N has the anchor ``#L-N``."""
    try:
        from pygments import highlight
        from pygments.formatters import HtmlFormatter
        from pygments.lexers import PythonLexer

        formatter = HtmlFormatter(linenos="inline", linespans="L", anchorlinenos=True, lineanchors="N",
                                  cssclass="code")
        body = highlight(code, PythonLexer(), formatter)
        style = formatter.get_style_defs(".code")
        body = re.sub(r'<span id="L-(\d+)">', r'<span id="L-\1" class="line">', body)
    except ImportError:
        style = ""
        body = "<pre class=\"code\">" + "".join(
            f'<span id="L-{n}" class="line">{n:5d}  {html.escape(line)}\n</span>'
            for n, line in enumerate(code.splitlines(), 1)) + "</pre>"
    return (f"<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">{NO_FAVICON}<title>{html.escape(rel)}</title>"
            f"<style>{style}\nbody{{font-family:system-ui,sans-serif;margin:1em}} pre{{font-size:13px;line-height:1.35}}"
            f" .line:target{{background:#fff3a8;display:inline-block;width:100%}}</style></head><body>"
            f"<p><a href=\"{'../' * (rel.count('/') + 2)}index.html\">&larr; report</a> &middot; <code>{html.escape(rel)}</code>"
            f" (as built)</p>{body}</body></html>")


def _short(sha) -> str:
    return str(sha or "")[:12]


def _provenance_panel(fig: Path, slug: str, ctx: dict) -> str:
    """Provenance of one figure: its rule, rebuild command, source functions, configuration keys,
    upstream data tables with checksums, seeds, compute time."""
    site: _Site = ctx["site"]
    chain = provenance_chain(fig)
    if not chain:
        return '<div class="prov missing">no provenance sidecar: rebuild the figure with snakemake</div>'
    producers = ctx["producers"]
    head = chain[0]
    rule = _rule_name(head, producers)
    func = head.get("function", "?")
    src = _repo_relative(head.get("source_file", "?"))
    line = head.get("source_line")
    configfile = "".join(f" --configfile {shlex.quote(c)}" for c in ctx.get("configfiles", []))
    rebuild = f"snakemake -j2{configfile} --forcerun {rule} {rule}"
    total = sum(float(m.get("wall_time_s", 0) or 0) for m in chain)
    seeds = {}
    for meta in chain:
        for key, value in (meta.get("seeds") or {}).items():
            seeds[f"{_rule_name(meta, producers)}: {key}"] = value
    git = head.get("git") or {}
    stale = ""
    run_commit = ctx.get("commit")
    if git.get("commit") and run_commit and git.get("commit") != run_commit:
        stale = f' <span class="warn">built at an earlier commit than this report ({_short(git.get("commit"))})</span>'

    steps, tables, code = [], {}, {}
    for meta in chain:
        name = _rule_name(meta, producers)
        msrc = _repo_relative(meta.get("source_file", "?"))
        keys = config_keys(meta.get("params", {}), ctx["config"].get(slug, {}), slug)
        cfg = "".join(
            f'<li class="{"cfg" if from_cfg else "const"}"><code>{_esc(k)}</code> = <code>{_esc(_fmt_value(v))}</code>'
            f'{"" if from_cfg else " <small>(fixed in the rule)</small>"}</li>' for k, v, from_cfg in keys)
        steps.append(
            f'<tr><td><code class="rule">{_esc(name)}</code></td>'
            f'<td><a class="src" href="{_esc(site.source_link(msrc, meta.get("source_line")))}">{_esc(msrc)}:{_esc(meta.get("source_line"))}</a>'
            f'<br><code class="func">{_esc(meta.get("function"))}</code></td>'
            f'<td>{"<ul>" + cfg + "</ul>" if cfg else "<small>none</small>"}'
            f'<small class="sha">params hash {_esc(meta.get("params_hash"))}</small></td>'
            f'<td class="num">{float(meta.get("wall_time_s", 0) or 0):.2f}&nbsp;s</td></tr>')
        for item_name, item in (meta.get("inputs") or {}).items():
            target = code if item_name.startswith("code") or item["path"].endswith(".py") else tables
            target.setdefault(item["path"], item.get("sha256"))
    table_rows = "".join(
        f'<tr><td><a class="data" href="{_esc(site.table_link(p))}">{_esc(p)}</a></td>'
        f'<td><code class="sha" title="{_esc(s)}">sha256 {_esc(_short(s))}</code></td></tr>' for p, s in sorted(tables.items()))
    code_list = ", ".join(
        f'<a href="{_esc(site.source_link(p))}">{_esc(_repo_relative(p))}</a> <code class="sha" title="{_esc(s)}">{_esc(_short(s))}</code>'
        for p, s in sorted(code.items()))
    seed_text = ", ".join(f"<code>{_esc(k)} = {_esc(v)}</code>" for k, v in seeds.items()) or "none (deterministic)"
    return (
        f'<div class="prov" data-rule="{_esc(rule)}" data-source="{_esc(src)}" data-function="{_esc(func)}" '
        f'data-line="{_esc(line)}">'
        f'<div class="prov-head"><span><b>rule</b> <code class="rule">{_esc(rule)}</code></span>'
        f'<span><b>source</b> <a class="src" href="{_esc(site.source_link(src, line))}">{_esc(src)}:{_esc(line)}</a> '
        f'<code class="func">{_esc(func.split(":")[-1])}</code></span>'
        f'<span><b>compute</b> {float(head.get("wall_time_s", 0) or 0):.2f}&nbsp;s (with upstream steps {total:.1f}&nbsp;s)</span>'
        f'<span><b>commit</b> <code>{_esc(_short(git.get("commit")) or "n/a")}</code>{" (dirty)" if git.get("dirty") else ""}{stale}</span></div>'
        f'<div class="rebuild"><b>rebuild just this figure</b> <code class="cmd">{_esc(rebuild)}</code></div>'
        f'<div><b>seeds</b> {seed_text} &middot; <b>figure</b> <code>{_esc(fig)}</code> '
        f'<code class="sha" title="{_esc(head.get("output_sha256"))}">sha256 {_esc(_short(head.get("output_sha256")))}</code></div>'
        f'<details><summary>steps ({len(chain)}), configuration, data tables ({len(tables)}) and code</summary>'
        '<table class="chain"><thead><tr><th>rule</th><th>source function</th><th>configuration used</th><th>time</th></tr></thead>'
        f'<tbody>{"".join(steps)}</tbody></table>'
        + (f'<table class="chain tables"><thead><tr><th>data table read</th><th>checksum</th></tr></thead><tbody>{table_rows}</tbody></table>'
           if table_rows else "<p>data tables: none</p>")
        + f'<p class="code-inputs"><b>code</b> {code_list}</p></details></div>'
    )


CSS = """
:root{--ok:#1e7b34;--ok-bg:#e6f4ea;--bad:#b3261e;--bad-bg:#fde7e9;--err:#8a5a00;--err-bg:#fff1cc;--line:#dcdce3;--muted:#666}
*{box-sizing:border-box}
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;max-width:1180px;margin:0 auto;padding:0 1.2em 4em;color:#1d1d22;line-height:1.45}
header.top{padding:1.2em 0 .4em;border-bottom:3px solid #2b4c7e;margin-bottom:.8em}
h1{margin:0;font-size:1.7em} .sub{color:var(--muted);margin:.2em 0 0}
h2{border-bottom:2px solid var(--line);padding-bottom:.2em;margin-top:2.2em} h3{margin-top:1.6em} h4{margin:1.2em 0 .3em}
nav.toc{position:sticky;top:0;background:#fff;border-bottom:1px solid var(--line);padding:.4em 0;z-index:5;font-size:.92em}
nav.toc a{margin-right:1.1em;text-decoration:none}
.cards{display:flex;gap:1em;flex-wrap:wrap;margin:.6em 0}
.card{border:1px solid var(--line);border-radius:6px;padding:.5em .9em;min-width:8.5em}
.card .n{font-size:1.8em;font-weight:650;display:block} .card.reproduced .n{color:var(--ok)} .card.differs .n{color:var(--bad)} .card.erratum .n{color:var(--err)} .card.conditional .n{color:#2f6fb0}
.card.untestable{color:var(--muted)}
table{border-collapse:collapse;font-size:.86em;margin:.5em 0}
td,th{border:1px solid var(--line);padding:3px 7px;vertical-align:top;text-align:left} thead th{background:#f3f4f7}
td.num,th.num{text-align:right;font-variant-numeric:tabular-nums}
table.score td.bar{min-width:180px} .bar span{display:inline-block;height:.9em;vertical-align:middle}
.bar .reproduced{background:var(--ok)} .bar .conditional{background:#6fa8dc} .bar .differs{background:var(--bad)} .bar .erratum{background:#e0a800} .bar .other{background:#999}
.verdict{font-weight:600;white-space:nowrap;border-radius:3px;padding:0 .35em}
tr.v-reproduced td.verdict-cell{background:var(--ok-bg)} tr.v-differs td.verdict-cell{background:var(--bad-bg)} tr.v-erratum td.verdict-cell{background:var(--err-bg)} tr.v-conditional td.verdict-cell{background:#e3eefa}
tr.v-not_checkable td.verdict-cell,tr.v-not_identifiable td.verdict-cell,tr.v-context td.verdict-cell{background:#f0f0f0;color:var(--muted)}
.summary{border-left:4px solid #2b4c7e;background:#f5f8fc;padding:.4em 1em .6em;margin:1em 0}
.st-replicated{color:var(--ok);font-weight:600} .st-partially{color:#2f6fb0;font-weight:600} .st-not-replicated{color:var(--bad);font-weight:600}
.st-not-testable,.st-no-claim{color:var(--muted)} .layout{font-size:.85em;color:#333;margin:.2em 0} .layout b{font-weight:600}
.scroll{overflow-x:auto}
figure{margin:1.4em 0 2em;border-top:1px solid var(--line);padding-top:.8em} figure img{max-width:100%;height:auto;border:1px solid #eee;display:block;margin:.3em 0}
figcaption .fig-id{font-weight:650} figcaption p{margin:.25em 0}
.prov{background:#f6f7fa;border:1px solid #e0e2ea;border-radius:5px;padding:.5em .7em;font-size:.84em}
.prov-head{display:flex;flex-wrap:wrap;gap:.4em 1.4em} .prov .rebuild{margin:.35em 0} code.cmd{background:#fff;border:1px solid var(--line);padding:1px 5px;user-select:all}
.prov details{margin-top:.4em} .prov ul{margin:0;padding-left:1.1em} .prov li.const{color:var(--muted)}
.sha{color:var(--muted);font-size:.9em} .warn{color:var(--bad)} .missing{color:var(--bad)}
.beyond{border:2px dashed #7b5ea7;border-radius:8px;padding:.2em 1em 1em;margin-top:2em;background:#fbf9fe}
.beyond>h3:first-child{color:#5b3f8a} .badge{display:inline-block;font-size:.75em;font-weight:700;padding:1px 6px;border-radius:3px;background:#7b5ea7;color:#fff;vertical-align:middle}
dl.identity{display:grid;grid-template-columns:max-content 1fr;gap:.15em 1em;font-size:.9em} dl.identity dt{font-weight:600} dl.identity dd{margin:0}
footer{margin-top:3em;color:var(--muted);font-size:.85em}
"""


def _num(value) -> str:
    """A number as a reader wants it (7 significant digits; the exact value on hover)."""
    text = _esc(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        return text
    if isinstance(value, bool) or not pd.notna(number) or number == int(number) and abs(number) < 1e15:
        return text
    short = f"{number:.7g}"
    return text if short == str(value) else f'<span title="{text}">{short}</span>'


def _claims_html(frame: pd.DataFrame, slug: str) -> str:
    """Claims table: where, statement, paper's value, ours, tolerance and why, verdict (robust, condition), note."""
    def col(row, *names):
        for n in names:
            if n in row and not (isinstance(row[n], float) and pd.isna(row[n])):
                return row[n]
        return ""

    rows = []
    for _, row in frame.iterrows():
        verdict = str(col(row, "verdict")).strip()
        why = col(row, "tolerance_reason", "tolerance_why")
        test = col(row, "test")
        where = col(row, "location")
        robust = str(col(row, "robust"))
        condition = col(row, "condition")
        extra = ""
        if robust:
            extra += f"<br><small>robust: {_esc(robust)}</small>"
        if condition != "":
            extra += f"<br><small>{_esc(condition)}</small>"
        if col(row, "erratum_id") != "":
            extra += f'<br><small>see <a href="#{slug}-errata">{_esc(col(row, "erratum_id"))}</a></small>'
        rows.append(
            f'<tr class="claim v-{_esc(verdict)}" data-verdict="{_esc(verdict)}">'
            f'<td><code>{_esc(col(row, "claim_id"))}</code>{("<br><small>" + _esc(where) + "</small>") if where != "" else ""}</td>'
            f'<td>{_esc(col(row, "statement"))}</td>'
            f'<td class="num">{_num(col(row, "paper_value"))}</td><td class="num">{_num(col(row, "reproduced_value"))}</td>'
            f'<td><span class="num">{_esc(col(row, "tolerance"))}</span>{("<br><small>" + _esc(why) + "</small>") if why != "" else ""}'
            f'{("<br><small>test: " + _esc(test) + "</small>") if test != "" else ""}</td>'
            f'<td class="verdict-cell"><span class="verdict">{_esc(verdict)}</span>{extra}</td><td>{_esc(col(row, "note"))}</td></tr>')
    return (f'<div class="scroll"><table class="data claims" id="{slug}-claims-table" data-paper="{slug}">'
            "<thead><tr><th>id, where</th><th>statement</th><th>paper</th><th>ours</th><th>tolerance and why</th>"
            f"<th>verdict</th><th>note</th></tr></thead><tbody>{''.join(rows)}</tbody></table></div>")


def _summary_html(slug: str, spec: dict, frame: pd.DataFrame | None, ctx: dict) -> str:
    """The replication summary that opens a paper's section (counted from its tables, see netrepro.summary)."""
    if frame is None:
        return ""
    errata = _read_csv(spec["errata"]) if spec.get("errata") else None
    findings = _read_csv(spec["findings"]) if spec.get("findings") else None
    figure_ids = [Path(f).stem for f in spec.get("figures", [])]
    table = replication_summary(frame, figure_ids)
    sentences = summary_sentences(frame, errata, findings, table)
    rows = "".join(
        f'<tr data-item="{_esc(r["item"])}"><td>{_esc(r["item"])}</td><td>{_esc(r["kind"])}</td>'
        f'<td class="st-{_esc(r["status"].replace(" ", "-"))}">{_esc(r["status"])}</td>'
        f'<td class="num">{int(r["testable"])}</td><td>{_esc(r["why"])}</td></tr>' for _, r in table.iterrows())
    return (f'<div class="summary" id="{slug}-summary"><h3>Replication summary</h3>'
            + "".join(f"<p>{_esc(t)}</p>" for t in sentences)
            + '<details open><summary>per figure and per claim group</summary><div class="scroll"><table class="data">'
              "<thead><tr><th>figure / group</th><th>kind</th><th>status</th><th class=\"num\">testable claims</th>"
              f"<th>why not fully</th></tr></thead><tbody>{rows}</tbody></table></div></details>"
              f'<p class="sub">Status: <b>replicated</b> every testable claim reproduced; <b>partially</b> some hold '
              "(reproduced, or only under a stated condition); <b>not replicated</b> none holds; <b>not testable</b> "
              "only untestable rows; <b>no claim</b> the paper states nothing testable about the figure (it is "
              "redrawn).</p></div>")


def _layout_html(layout: dict) -> str:
    if not layout:
        return ""
    parts = []
    if layout.get("from_paper"):
        parts.append(f"<b>from the paper:</b> {_esc(layout['from_paper'])}")
    if layout.get("ours"):
        parts.append(f"<b>our choice:</b> {_esc(layout['ours'])}")
    return f'<p class="layout">Layout &mdash; {" &middot; ".join(parts)}</p>'


def _figure_html(fig: Path, slug: str, captions: dict, ctx: dict) -> str:
    ours = fig.stem.startswith("figS")
    label = ("Figure " + fig.stem[3:]) if fig.stem.startswith("fig") else fig.stem
    badge = ' <span class="badge">beyond the paper</span>' if ours else ""
    caption = _rst_html(captions.get(fig.stem, "")) or "<p><em>no caption file</em></p>"
    layout = _layout_html(ctx.get("layouts", {}).get(slug, {}).get(fig.stem, {}))
    image = _img(fig) if fig.is_file() else f'<p class="missing">{_esc(fig)} not built</p>'
    return (f'<figure id="{slug}-{fig.stem}" data-figure="{_esc(fig)}"><figcaption><span class="fig-id">{_esc(slug)} '
            f"{_esc(label)}</span>{badge}{caption}{layout}</figcaption>{image}{_provenance_panel(fig, slug, ctx)}</figure>")


def _tables_list(paths, ctx) -> str:
    site: _Site = ctx["site"]
    rows = []
    for p in paths:
        path = Path(p)
        frame = _read_csv(path)
        side = sidecar_path(path)
        meta = json.loads(side.read_text()) if side.is_file() else {}
        rows.append(
            f'<tr><td><a class="data" href="{_esc(site.table_link(str(p)))}">{_esc(p)}</a></td>'
            f'<td class="num">{"" if frame is None else len(frame)}</td>'
            f'<td><code>{_esc(_rule_name(meta, ctx["producers"])) if meta else ""}</code></td>'
            f'<td><code class="sha" title="{_esc(meta.get("output_sha256"))}">{_esc(_short(meta.get("output_sha256")))}</code></td></tr>')
    return ("<table class=\"data\"><thead><tr><th>table</th><th>rows</th><th>rule</th><th>sha256</th></tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table>")


def _paper_section(slug: str, spec: dict, frame: pd.DataFrame | None, ctx: dict) -> str:
    meta = load_registry().get(slug, {})
    root = ctx["root"]
    captions = figure_captions(root, slug)
    figures = sorted((Path(f) for f in spec.get("figures", [])), key=_figure_sort_key)
    paper_figs = [f for f in figures if not f.stem.startswith("figS")]
    our_figs = [f for f in figures if f.stem.startswith("figS")]
    notebook = spec.get("notebook")
    out = [f'<section class="paper" id="{slug}"><h2>{_esc(meta.get("title", slug))} <small>(<code>{slug}</code>)</small></h2>',
           f'<p class="sub">{_esc(meta.get("authors", ""))}'
           + (f' &middot; source text <code>{_esc(meta["file"])}</code>' if meta.get("file") else "")
           + (f' &middot; <a href="{_esc(Path(notebook).name)}">executed notebook</a>' if notebook else "")
           + f' &middot; <a href="#{slug}-claims">claims</a> &middot; <a href="#{slug}-errata">errata</a>'
           f' &middot; <a href="#{slug}-findings">findings</a>'
           f' &middot; <a href="#{slug}-reconstructions">reconstructions</a> &middot; <a href="#{slug}-beyond">beyond the paper</a></p>']
    out.append(_summary_html(slug, spec, frame, ctx))
    out.append(f'<h3 id="{slug}-figures">Figures of the paper</h3>')
    out.extend(_figure_html(f, slug, captions, ctx) for f in paper_figs)
    if not paper_figs:
        out.append("<p>The paper has no figure that we redraw.</p>")
    out.append(f'<h3 id="{slug}-claims">Claims</h3>')
    if frame is None:
        out.append(f'<p class="missing">{_esc(spec.get("claims"))} not built</p>')
    else:
        counts = frame["verdict"].value_counts() if "verdict" in frame else {}
        out.append("<p>" + ", ".join(f"{int(counts.get(v, 0))} {v}" for v in SCORE_VERDICTS)
                   + f" of {len(frame)} claims. Table: "
                   f'<a class="data" href="{_esc(ctx["site"].table_link(spec["claims"]))}">{_esc(spec["claims"])}</a>.</p>')
        out.append(_claims_html(frame, slug))
    for title, key, intro in (
            ("Errata", "errata", "Errors of the text: printed form, corrected form, numerical demonstration, kind "
                                 "(only equation and prose errors count as errata; notation and typesetting slips are "
                                 "listed) and which of our results the printed form would change."),
            ("Findings", "findings", "Our own discoveries beyond the paper's claims, with the evidence and the table "
                                     "(and figure) that shows it. They are not errata of the text."),
            ("Reconstructions", "reconstructions",
             "Parameters the paper does not state or garbles: the value we chose, why, and where conclusions depend on it.")):
        out.append(f'<h3 id="{slug}-{key}">{title}</h3><p class="sub">{intro}</p>')
        table = _read_csv(spec[key]) if spec.get(key) else None
        if table is None:
            out.append(f'<p class="missing">{_esc(spec.get(key))} not built</p>')
        elif not len(table):
            out.append("<p>none</p>")
        else:
            out.append(_table_html(table.drop(columns=["paper"], errors="ignore"), table_id=f"{slug}-{key}-table"))
    out.append(f'<div class="beyond" id="{slug}-beyond"><h3>Beyond the paper <span class="badge">ours</span></h3>'
               "<p>Ground truths, comparisons and checks we add. Nothing here is claimed by the paper.</p>")
    out.extend(_figure_html(f, slug, captions, ctx) for f in our_figs)
    extra = spec.get("beyond_tables") or spec.get("extra_tables") or []
    for table in extra:
        frame_x = _read_csv(table)
        if frame_x is not None:
            out.append(f"<h4><code>{_esc(table)}</code></h4>" + _table_html(frame_x.head(50)))
    tables = list(dict.fromkeys(spec.get("tables", [])))
    if tables:
        out.append("<h4>Result tables of this paper</h4>" + _tables_list(tables, ctx))
    out.append("</div></section>")
    return "\n".join(out)


def _scorecard_html(score: pd.DataFrame, papers: dict, ctx: dict) -> str:
    total = score.iloc[-1]
    shown = list(SCORE_VERDICTS)
    untestable = [v for v in shown if v not in TESTABLE_VERDICTS]
    pct = total["scored_reproduced_pct"]
    cards = (f'<div class="card"><span class="n" id="total-claims">{int(total["claims"])}</span>claims listed</div>'
             f'<div class="card"><span class="n" id="total-testable">{int(total["testable"])}</span>testable</div>'
             + "".join(f'<div class="card {v}{" untestable" if v in untestable else ""}"><span class="n" id="total-{v}">'
                       f'{int(total[v])}</span>{v.replace("_", " ")}</div>' for v in shown)
             + f'<div class="card"><span class="n" id="total-errata">{int(total["errata"])}</span>errata</div>'
             + f'<div class="card"><span class="n" id="total-findings">{int(total["findings"])}</span>findings</div>')
    show_other = int(total["other"]) > 0
    head = ("<tr><th>paper</th><th class=\"num\">claims</th><th class=\"num\">testable</th>"
            + "".join(f'<th class="num">{v.replace("_", " ")}</th>' for v in shown)
            + ('<th class="num">other</th>' if show_other else "")
            + "<th class=\"num\">reproduced of testable</th><th></th><th class=\"num\">errata</th>"
              "<th class=\"num\">findings</th><th class=\"num\">reconstructions</th><th class=\"num\">figures</th>"
              "<th>claims table</th></tr>")
    rows = []
    for _, row in score.iterrows():
        slug = row["paper"]
        spec = papers.get(slug)
        n = max(int(row["testable"]), 1)
        bar = "".join(f'<span class="{v}" style="width:{160 * int(row[v]) / n:.1f}px" title="{int(row[v])} {v}"></span>'
                      for v in TESTABLE_VERDICTS if int(row[v]))
        if spec is not None:
            name = f'<a href="#{slug}">{_esc(load_registry().get(slug, {}).get("title", slug))}</a> <code>{_esc(slug)}</code>'
            recon = _read_csv(spec.get("reconstructions", "")) if spec.get("reconstructions") else None
            figs = spec.get("figures", [])
            extra = (f'<td class="num">{"" if recon is None else len(recon)}</td>'
                     f'<td class="num">{sum(not Path(f).stem.startswith("figS") for f in figs)}'
                     f' + {sum(Path(f).stem.startswith("figS") for f in figs)} ours</td>'
                     f'<td><a class="claims-link" href="#{slug}-claims">claims of {_esc(slug)}</a></td>')
        else:
            name, extra = "<b>total</b>", "<td></td>" * 3
        share = "" if pd.isna(row["scored_reproduced_pct"]) else f'{row["scored_reproduced_pct"]:.1f} %'
        rows.append(f'<tr data-paper="{_esc(slug)}"><td>{name}</td><td class="num n-claims">{int(row["claims"])}</td>'
                    f'<td class="num n-testable">{int(row["testable"])}</td>'
                    + "".join(f'<td class="num n-{v}">{int(row[v])}</td>' for v in shown)
                    + (f'<td class="num n-other">{int(row["other"])}</td>' if show_other else "")
                    + f'<td class="num">{share}</td><td class="bar">{bar}</td>'
                    f'<td class="num n-errata" title="{int(row["minor_errata"])} notation or typesetting slips not counted">'
                    f'{int(row["errata"])}</td><td class="num n-findings">{int(row["findings"])}</td>{extra}</tr>')
    return (f'<div class="cards">{cards}</div><div class="scroll"><table class="score" id="scorecard-table"><thead>{head}</thead>'
            f"<tbody>{''.join(rows)}</tbody></table></div>"
            '<p class="sub">Testable verdicts (scored): <b>reproduced</b> our value is within the tolerance fixed in '
            "advance, at every setting in the range of the reconstructions it depends on; <b>conditional</b> it holds "
            "only under a condition the paper does not state (named in the claims table); <b>differs</b> a genuine "
            "disagreement, explained in the note; <b>erratum</b> the paper's statement is wrong because of an error of "
            "its text. Kept for transparency, not scored: <b>not checkable</b> (rests on a source the paper does not "
            "contain), <b>not identifiable</b> (one of many valid answers, e.g. LMI gains; the defining property is "
            "checked in its own row), <b>context</b> (not a testable result). Errata count equation and prose errors "
            f"only; {int(total['minor_errata'])} notation or typesetting slips are listed per paper. Overall "
            f"{'' if pd.isna(pct) else f'{pct:.1f} %'} of the testable claims are reproduced.</p>")


def _identity_html(identity: dict, versions: dict) -> str:
    items = "".join(f"<dt>{_esc(k)}</dt><dd id=\"id-{re.sub(r'[^a-z]+', '-', k.lower()).strip('-')}\">{v}</dd>"
                    for k, v in identity.items())
    pkgs = ", ".join(f"{_esc(k)} {_esc(v)}" for k, v in versions.items())
    return f'<dl class="identity">{items}<dt>packages</dt><dd id="id-packages">{pkgs}</dd></dl>'


def build_index(params: dict, inputs: dict, outputs: dict) -> dict:
    """Pipeline step: write ``report/index.html`` from claims, errata, figures and sidecars.

    ``params``: ``papers`` maps each slug to the outputs it registered in the
    Snakefile (``PAPER_OUTPUTS``); ``config_hash`` identifies the run's
    configuration; optional ``config`` (the papers' configuration sections, to
    name the configuration key of each parameter), ``order`` (the papers in the order
    of the configuration; the JSON of ``papers`` has its keys sorted), ``producers`` (output file ->
    rule, from the workflow), ``configfiles`` (given with ``--configfile``),
    ``machine``, ``benchmarks`` (path of an optional benchmark table).
    ``outputs``: ``html``, and optionally ``files``, a folder receiving the
    linked source pages and tables so that the report is self-contained.
    """
    root = Path(".").resolve()
    order = [s for s in params.get("order", []) if s in params["papers"]]
    papers = {s: params["papers"][s] for s in order + sorted(set(params["papers"]) - set(order))}
    files_dir = Path(outputs["files"]) if outputs.get("files") else None
    # the rule's threads (exported by its shell command as OMP_NUM_THREADS) highlight the source pages
    site = _Site(root, files_dir, workers=int(os.environ.get("OMP_NUM_THREADS") or 1))
    claims = {slug: _read_csv(spec["claims"]) for slug, spec in papers.items()}
    score = scorecard({s: (f if f is not None else pd.DataFrame({"verdict": []})) for s, f in claims.items()},
                      errata={s: _read_csv(spec["errata"]) for s, spec in papers.items() if spec.get("errata")},
                      findings={s: _read_csv(spec["findings"]) for s, spec in papers.items() if spec.get("findings")})
    git = git_state()
    versions = package_versions()
    ctx = {"root": root, "site": site, "producers": params.get("producers"), "config": params.get("config", {}),
           "configfiles": params.get("configfiles", []), "commit": git["commit"], "layouts": _layouts(papers)}
    commit = git["commit"]
    identity = {
        "commit": f"<code>{_esc(commit)}</code>" if commit else "not a git checkout",
        "working tree": ("<span class=\"warn\">dirty (uncommitted changes)</span>" if git["dirty"] else "clean")
        if git["dirty"] is not None else "unknown",
        "configuration hash": f"<code>{_esc(params['config_hash'])}</code>"
        + (f" &middot; {' '.join('<code>' + _esc(c) + '</code>' for c in ctx['configfiles'])}" if ctx["configfiles"] else ""),
        "date (UTC)": _esc(_dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S")),
        "machine": _esc(params.get("machine", "") or f"{platform.system()} {platform.machine()}")
        + f" &middot; {_esc(platform.platform())}",
        "papers": _esc(", ".join(papers)),
    }
    nav = "".join(f'<a href="#{s}">{_esc(s)}</a>' for s in papers)
    bench_path = Path(params.get("benchmarks") or "results/benchmarks.csv")
    bench = _read_csv(bench_path)
    parts = [
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">" + NO_FAVICON +
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
        f"<title>Reproduction report: networked estimation and control</title><style>{CSS}</style></head><body>",
        '<header class="top"><h1>Reproduction report: networked estimation and control</h1>'
        f'<p class="sub">{len(papers)} papers recomputed from their equations by one Snakemake workflow. Every figure '
        "carries its provenance; every number the papers state is checked.</p></header>",
        f'<nav class="toc"><a href="#scorecard">Scorecard</a><a href="#identity">Run</a>{nav}'
        + ('<a href="#benchmarks">Benchmarks</a>' if bench is not None else "") + '<a href="#cite">Cite</a></nav>',
        '<h2 id="scorecard">Scorecard</h2>', _scorecard_html(score, papers, ctx),
        '<h3 id="identity">Run identity</h3>', _identity_html(identity, versions),
    ]
    for slug, spec in papers.items():
        parts.append(_paper_section(slug, spec, claims[slug], ctx))
    if bench is not None:
        parts.append(f'<section id="benchmarks"><h2>Benchmarks</h2><p class="sub">From <code>{_esc(bench_path)}</code> '
                     "(written by <code>make bench</code>; not a pipeline output, shown as found when the report was "
                     f"built).</p>{_table_html(bench, table_id='benchmarks-table')}</section>")
    parts.append(references_html(papers))
    parts.append("<footer>Built by the <code>report</code> rule (<code>netrepro.reportgen:build_index</code>). "
                 "Figures are embedded; linked tables and source files are copies under <code>files/</code>, so the "
                 "report works offline. Snakemake's own report: <code>snakemake --report report/snakemake_report.html</code>."
                 "</footer></body></html>")
    sidecars = _run_sidecars(papers)
    if outputs.get("crate") and files_dir is not None:
        site.tables.update(sidecars)  # the crate describes copies inside report/ (self-contained)
        workflow_files = _workflow_sources(root)
        configs = list(dict.fromkeys(["config/config.yaml", *ctx["configfiles"]]))
        for rel in [*workflow_files, *configs]:
            if (root / rel).is_file() and not Path(rel).is_absolute() and not rel.startswith(".."):
                site.raw[f"workflow/{rel}"] = rel
    site.write()
    with atomic_path(outputs["html"]) as tmp:
        tmp.write_text("\n".join(parts))
    os.chmod(outputs["html"], 0o644)
    if outputs.get("crate") and files_dir is not None:
        crate_root = Path(outputs["crate"]).parent
        prefix = files_dir.relative_to(crate_root).as_posix() if files_dir.is_relative_to(crate_root) else "files"
        pages = [Path(outputs["html"]).name] + [Path(spec["notebook"]).name for spec in papers.values()
                                                if spec.get("notebook") and Path(spec["notebook"]).is_file()]
        write_crate(crate_root, sidecars={p: relocate_json(m, root) for p, m in sidecars.items()},
                    rule_of=lambda meta: _rule_name(meta, ctx["producers"]),
                    run={"end": iso(_dt.datetime.now(_dt.timezone.utc).timestamp()), "config_hash": params["config_hash"],
                         "commit": commit, "dirty": git["dirty"]},
                    workflow_files=[f"{prefix}/workflow/{rel}" for rel in workflow_files if f"workflow/{rel}" in site.raw],
                    config_files=[f"{prefix}/workflow/{rel}" for rel in configs if f"workflow/{rel}" in site.raw],
                    pages=pages, versions=versions, out=outputs["crate"])
    return {"provenance": {"scorecard": score.to_dict(orient="records")}}


def _layouts(papers: dict) -> dict:
    """``{slug: {figure id: layout}}`` from the figure lists (which layout choices are the paper's)."""
    out = {}
    for slug in papers:
        try:
            out[slug] = {spec.figure_id: spec.layout for spec in load_figure_specs(slug)}
        except ConfigError:  # a paper without a figure list shows no layout notes
            out[slug] = {}
    return out


def _run_sidecars(papers: dict) -> dict[str, dict]:
    """Every result table and figure of the run with its sidecar: the registered outputs of each
    paper and everything upstream of them (path -> sidecar, in the order found)."""
    seen: set[str] = set()
    found: dict[str, dict] = {}
    for spec in papers.values():
        paths = [*spec.get("figures", []), *spec.get("tables", []),
                 *(spec.get(k) for k in ("claims", "errata", "reconstructions", "findings"))]
        for path in paths:
            if not path:
                continue
            for meta in provenance_chain(path, seen):
                out = str(meta.get("output", ""))
                if out and Path(out).is_file():
                    found.setdefault(out, meta)
    return found


def _workflow_sources(root: Path) -> list[str]:
    """The Snakefiles of the workflow, the root entry point first (repository-relative)."""
    files = ["Snakefile", "workflow/Snakefile", *sorted(p.relative_to(root).as_posix()
                                                         for p in (root / "workflow" / "rules").glob("*.smk"))]
    return [f for f in files if (root / f).is_file()]


def config_hash(config: dict) -> str:
    return params_hash(config)


# ----------------------------------------------------------------------------- CLI
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m netrepro.reportgen")
    sub = parser.add_subparsers(dest="command", required=True)
    mk = sub.add_parser("make-notebook", help="write the default thin notebook of a paper")
    mk.add_argument("--slug", required=True)
    mk.add_argument("--out", default=None)
    ex = sub.add_parser("notebook", help="execute a paper notebook and export HTML")
    ex.add_argument("--slug", required=True)
    ex.add_argument("--notebook", required=True)
    ex.add_argument("--html", required=True)
    rel = sub.add_parser("relocate", help="rewrite files so they name no path of this checkout "
                                          "(e.g. Snakemake's own report, which shows the rules' commands)")
    rel.add_argument("files", nargs="+")
    args = parser.parse_args(argv)
    if args.command == "relocate":
        for name in args.files:
            path = Path(name)
            text = path.read_text()
            new = relocate(text, Path.cwd())
            if new != text:
                path.write_text(new)
        return 0
    if args.command == "make-notebook":
        out = args.out or f"workflow/notebooks/{args.slug}.ipynb"
        print(make_notebook(args.slug, out))
    else:
        execute_notebook(args.slug, args.notebook, args.html)
    return 0


if __name__ == "__main__":
    from .runner import exit_process

    exit_process(main())
