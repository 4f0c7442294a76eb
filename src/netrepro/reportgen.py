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
import re
import sys
from pathlib import Path

import pandas as pd

from .io import atomic_path
from .papers import PAPERS
from .provenance import git_state, package_versions, params_hash, sidecar_path

__all__ = ["make_notebook", "execute_notebook", "strip_external_scripts", "build_index", "provenance_chain",
           "scorecard", "main"]

SCORE_VERDICTS = ("reproduced", "differs", "erratum")


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
                              "erratum and reconstruction tables. Every value below is read from `results/`."),
        nbf.new_code_cell("show_figures(root, slug)"),
        nbf.new_markdown_cell("## Claims"),
        nbf.new_code_cell('show_table(root / "results" / "claims" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Errata"),
        nbf.new_code_cell('show_table(root / "results" / "errata" / f"{slug}.csv")'),
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


def strip_external_scripts(text: str) -> str:
    """Remove ``<script src=http...>`` and ``<link href=http...>`` tags (offline report)."""
    return _EXTERNAL.sub("", text)


def execute_notebook(slug: str, notebook: str | Path, html_out: str | Path, root: str | Path = ".") -> Path:
    """Run ``notebook`` with papermill (parameters ``slug``, ``root``) and export static HTML."""
    import nbformat
    import papermill
    from nbconvert import HTMLExporter

    root = Path(root).resolve()
    html_out = Path(html_out)
    executed = html_out.with_suffix(".ipynb")
    papermill.execute_notebook(str(notebook), str(executed), parameters={"slug": slug, "root": str(root)},
                               kernel_name="python3", cwd=str(root), progress_bar=False)
    exporter = HTMLExporter()
    body, _ = exporter.from_notebook_node(nbformat.read(str(executed), as_version=4))
    with atomic_path(html_out) as tmp:
        tmp.write_text(strip_external_scripts(body))
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


def scorecard(claims: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Counts of verdicts per paper (and a total row)."""
    rows = []
    for slug, frame in claims.items():
        counts = frame["verdict"].value_counts()
        rows.append({"paper": slug, "claims": len(frame), **{v: int(counts.get(v, 0)) for v in SCORE_VERDICTS}})
    table = pd.DataFrame(rows, columns=["paper", "claims", *SCORE_VERDICTS])
    total = {"paper": "total", **{c: int(table[c].sum()) for c in table.columns[1:]}}
    return pd.concat([table, pd.DataFrame([total])], ignore_index=True)


def _img(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(path.stem)}">'


def _table_html(frame: pd.DataFrame, css="data") -> str:
    return frame.to_html(index=False, escape=True, na_rep="", classes=css, border=0)


def _provenance_panel(fig: Path, root: Path) -> str:
    chain = provenance_chain(fig)
    if not chain:
        return '<div class="prov missing">no provenance sidecar</div>'
    head = chain[0]
    rule = head["rule"]
    src = head["source_file"]
    line = head["source_line"]
    rows = []
    for meta in chain:
        seeds = ", ".join(f"{k}={v}" for k, v in meta.get("seeds", {}).items()) or "none"
        rows.append(
            f"<tr><td><code>{html.escape(meta['rule'])}</code></td>"
            f"<td><a class=\"src\" href=\"../{html.escape(meta['source_file'])}\">{html.escape(meta['source_file'])}:{meta['source_line']}</a>"
            f"<br><code>{html.escape(meta['function'])}</code></td>"
            f"<td><code>{html.escape(meta['output'])}</code><br><span class=\"sha\">sha256 {meta['output_sha256'][:16]}</span></td>"
            f"<td><details><summary>params {meta['params_hash']}</summary><pre>{html.escape(json.dumps(meta['params'], indent=1, sort_keys=True))}</pre></details></td>"
            f"<td>{html.escape(seeds)}</td><td>{meta['wall_time_s']:.2f} s</td></tr>"
        )
    git = head.get("git", {})
    return (
        f'<div class="prov" data-rule="{html.escape(rule)}" data-source="{html.escape(src)}" '
        f'data-function="{html.escape(head["function"])}">'
        f"<p><b>Rule</b> <code>{html.escape(rule)}</code> &middot; <b>rebuild</b> "
        f"<code>snakemake -j2 --forcerun {html.escape(rule)} {html.escape(rule)}</code> &middot; <b>source</b> "
        f"<a href=\"../{html.escape(src)}\">{html.escape(src)}:{line}</a> &middot; <b>commit</b> "
        f"<code>{html.escape(str(git.get('commit'))[:12])}</code>{' (dirty)' if git.get('dirty') else ''}</p>"
        "<table class=\"chain\"><tr><th>rule</th><th>function</th><th>output</th><th>configuration</th>"
        f"<th>seeds</th><th>time</th></tr>{''.join(rows)}</table></div>"
    )


CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
h1{margin-bottom:.2em} h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:2em}
table.data,table.chain,table.score{border-collapse:collapse;font-size:.85em;margin:.5em 0}
table.data td,table.data th,table.chain td,table.chain th,table.score td,table.score th{border:1px solid #ddd;padding:3px 6px;vertical-align:top}
tr.reproduced td.verdict{background:#e6f4ea} tr.differs td.verdict{background:#fde7e9} tr.erratum td.verdict{background:#fff4d6}
.prov{background:#f7f7f9;border:1px solid #e2e2e8;padding:.5em;font-size:.85em}
figure{margin:1.5em 0} figure img{max-width:100%;border:1px solid #eee} figcaption{font-style:italic;margin:.3em 0}
pre{white-space:pre-wrap;max-width:420px;font-size:.8em} .sha{color:#777;font-size:.85em} nav a{margin-right:1em}
"""


def _claims_html(frame: pd.DataFrame) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in frame.columns)
    body = []
    for _, row in frame.iterrows():
        cells = "".join(
            f'<td class="{"verdict" if c == "verdict" else ""}">{html.escape("" if pd.isna(v) else str(v))}</td>'
            for c, v in row.items()
        )
        body.append(f'<tr class="{html.escape(str(row["verdict"]))}">{cells}</tr>')
    return f'<table class="data claims"><tr>{head}</tr>{"".join(body)}</table>'


def build_index(params: dict, inputs: dict, outputs: dict) -> dict:
    """Pipeline step: write ``report/index.html`` from claims, errata, figures and sidecars.

    ``params["papers"]`` maps each slug to the outputs it registered in the
    Snakefile (``PAPER_OUTPUTS``); ``params["config_hash"]`` identifies the run's configuration.
    """
    root = Path(".").resolve()
    papers = params["papers"]
    claims = {slug: pd.read_csv(spec["claims"]) for slug, spec in papers.items()}
    score = scorecard(claims)
    git = git_state()
    versions = package_versions()
    identity = {
        "commit": git["commit"], "dirty": git["dirty"], "configuration hash": params["config_hash"],
        "date (UTC)": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
        "machine": params.get("machine", ""), **{f"{k}": v for k, v in versions.items()},
    }
    parts = [f"<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>Reproduction report</title>"
             f"<style>{CSS}</style></head><body>",
             "<h1>Reproduction report: networked estimation and control</h1>",
             "<nav>" + "".join(f'<a href="#{s}">{s}</a>' for s in papers) + "</nav>",
             "<h2 id=\"scorecard\">Scorecard</h2>"]
    score_html = ['<table class="score" id="scorecard-table"><tr><th>paper</th><th>claims</th>'
                  + "".join(f"<th>{v}</th>" for v in SCORE_VERDICTS) + "<th>claims table</th></tr>"]
    for _, row in score.iterrows():
        slug = row["paper"]
        link = (f'<a href="../{html.escape(papers[slug]["claims"])}">{html.escape(papers[slug]["claims"])}</a>'
                if slug in papers else "")
        score_html.append(
            f'<tr data-paper="{html.escape(slug)}"><td>{html.escape(slug)}</td><td class="n-claims">{row["claims"]}</td>'
            + "".join(f'<td class="n-{v}">{row[v]}</td>' for v in SCORE_VERDICTS) + f"<td>{link}</td></tr>")
    parts.append("".join(score_html) + "</table>")
    parts.append("<h3>Run identity</h3><table class=\"data\" id=\"identity\">"
                 + "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in identity.items())
                 + "</table>")
    for slug, spec in papers.items():
        meta = PAPERS.get(slug, {})
        parts.append(f'<h2 id="{slug}">{html.escape(meta.get("title", slug))}</h2>'
                     f"<p>{html.escape(meta.get('authors', ''))} &middot; source text <code>{html.escape(meta.get('file', ''))}</code>"
                     f' &middot; <a href="{html.escape(Path(spec["notebook"]).name)}">executed notebook</a></p>')
        captions = figure_captions(root, slug)
        for fig in sorted((Path(f) for f in spec["figures"]), key=_figure_sort_key):
            ours = " <b>[beyond the paper]</b>" if fig.stem.startswith("figS") else ""
            parts.append(f'<figure id="{slug}-{fig.stem}"><figcaption>{slug} {fig.stem}{ours}: '
                         f"{html.escape(captions.get(fig.stem, ''))}</figcaption>{_img(fig)}"
                         f"{_provenance_panel(fig, root)}</figure>")
        parts.append(f"<h3>Claims</h3>{_claims_html(claims[slug])}")
        for title, key in (("Errata", "errata"), ("Reconstructions", "reconstructions")):
            path = Path(spec[key])
            frame = pd.read_csv(path) if path.is_file() else pd.DataFrame()
            parts.append(f"<h3>{title}</h3>" + (_table_html(frame) if len(frame) else "<p>none</p>"))
    parts.append("</body></html>")
    with atomic_path(outputs["html"]) as tmp:
        tmp.write_text("\n".join(parts))
    return {"provenance": {"scorecard": score.to_dict(orient="records")}}


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
    args = parser.parse_args(argv)
    if args.command == "make-notebook":
        out = args.out or f"workflow/notebooks/{args.slug}.ipynb"
        print(make_notebook(args.slug, out))
    else:
        execute_notebook(args.slug, args.notebook, args.html)
    return 0


if __name__ == "__main__":
    sys.exit(main())
