"""The report rule's step: ``report/index.html`` (summary, scorecard, claims explorer), one page per
paper (``report/paper-<slug>.html``), the copies under ``report/files/`` and the Workflow Run Crate
``report/ro-crate-metadata.json`` (written by :mod:`netrepro.release.crate`)."""

from __future__ import annotations

import datetime as _dt
import os
import platform
from pathlib import Path

import pandas as pd
from markupsafe import Markup

from ..release.crate import iso, write_crate
from ..errors import ConfigError
from ..pipeline.figurespec import load_figure_specs
from ..pipeline.io import atomic_path
from ..pipeline.provenance import git_state, package_versions
from ..release.citations import crate_citations, references_html
from ..pipeline.registry import load_registry
from ..judging.summary import scorecard
from .csp import page_policy, policy_attribute
from .markup import read_csv, relocate_json, render, script, stylesheet
from .sections import table_view
from .panel import provenance_chain, rule_name
from .sections import (explorer_html, explorer_rows, paper_brief, paper_page_name, paper_section, scale_html,
                       scorecard_html)
from .site import Site

__all__ = ["build_index"]


def build_index(params: dict, inputs: dict, outputs: dict) -> dict:
    """Pipeline step: write ``report/index.html`` and the papers' pages from claims, errata, figures and sidecars.

    Parameters
    ----------
    params : dict
        ``papers`` maps each slug to the outputs it registered in the Snakefile
        (``PAPER_OUTPUTS``); ``config_hash`` identifies the run's configuration; optional
        ``config`` (the papers' configuration sections, to name the configuration key of each
        parameter), ``order`` (the papers in the order of the configuration; the JSON of
        ``papers`` has its keys sorted), ``configfiles`` (given with ``--configfile``),
        ``machine``, ``benchmarks`` (path of an optional benchmark table), ``scale`` (the paths of
        the verdicts-by-scale tables and of the recorded paper-scale run, when one is recorded).
    inputs : dict
        The rule's inputs (read through ``params``; listed so that Snakemake orders the jobs), and
        ``source_pages``, the folder ``report/files/source`` of pages highlighted ahead by ``report_sources``
        (optional: without it, the linked source files are highlighted here).
    outputs : dict
        ``html``, ``page_<slug>`` (each paper's page; default ``paper-<slug>.html`` beside ``html``), and optionally ``files_data`` and ``files_workflow`` (``report/files/data`` and
        ``report/files/workflow``: the copies of the tables and of the workflow files, so that the report is
        self-contained), and ``crate``.

    Returns
    -------
    dict
        The scorecard, recorded in the report's provenance.
    """
    root = Path(".").resolve()
    order = [s for s in params.get("order", []) if s in params["papers"]]
    papers = {s: params["papers"][s] for s in order + sorted(set(params["papers"]) - set(order))}
    # report/files/: the copies of tables and workflow files (files_data, files_workflow); report_sources
    # writes the source pages beside them (files/source/, the input source_pages)
    files_dir = Path(outputs["files_data"]).parent if outputs.get("files_data") else None
    # the rule's threads (exported by its shell command as OMP_NUM_THREADS) highlight the source pages
    site = Site(root, files_dir, workers=int(os.environ.get("OMP_NUM_THREADS") or 1),
                pages_made=bool(inputs.get("source_pages")))
    claims = {slug: read_csv(spec["claims"]) for slug, spec in papers.items()}
    score = scorecard({s: (f if f is not None else pd.DataFrame({"verdict": []})) for s, f in claims.items()},
                      errata={s: read_csv(spec["errata"]) for s, spec in papers.items() if spec.get("errata")},
                      findings={s: read_csv(spec["findings"]) for s, spec in papers.items() if spec.get("findings")})
    git = git_state()
    versions = package_versions()
    configfiles = params.get("configfiles", [])
    ctx = {"root": root, "site": site, "config": params.get("config", {}), "configfiles": configfiles,
           "commit": git["commit"], "layouts": _layouts(papers)}
    run = {"commit": git["commit"], "dirty": git["dirty"], "config_hash": params["config_hash"],
           "configfiles": configfiles, "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
           "machine": params.get("machine", "") or f"{platform.system()} {platform.machine()}",
           "platform": platform.platform()}
    bench_path = Path(params.get("benchmarks") or "results/benchmarks.csv")
    bench_frame = read_csv(bench_path)
    bench = None if bench_frame is None else {
        "path": bench_path, "html": Markup(render("table.html", table=table_view(bench_frame),
                                                  table_id="benchmarks-table"))}
    explorer = script("explorer.js")
    css = stylesheet()
    page = render("index.html", css=css, papers=list(papers), run=run, versions=versions, bench=bench, pages=True,
                  scorecard=Markup(scorecard_html(score, papers, explore=True, pages=True)),
                  scale=Markup(scale_html(params.get("scale") or {})),
                  explorer=Markup(explorer_html(papers, explorer_rows(papers, claims))),
                  briefs=[Markup(paper_brief(slug, spec, claims[slug])) for slug, spec in papers.items()],
                  references=Markup(references_html(papers)), script=explorer,
                  csp=policy_attribute(page_policy(explorer)))
    paper_pages = {}
    for slug, spec in papers.items():
        path = Path(outputs.get(f"page_{slug}") or Path(outputs["html"]).parent / paper_page_name(slug))
        paper_pages[path] = render("paper_page.html", css=css, slug=slug, papers=list(papers),
                                   title=load_registry().get(slug, {}).get("title", slug),
                                   section=Markup(paper_section(slug, spec, claims[slug], ctx)))
    sidecars = _run_sidecars(papers, extra=[p for k, p in (params.get("scale") or {}).items() if k != "reference"])
    workflow_files = _workflow_sources(root)
    configs = list(dict.fromkeys(["config/config.yaml", *configfiles]))
    if outputs.get("crate") and files_dir is not None:
        site.tables.update(sidecars)  # the crate describes copies inside report/ (self-contained)
        for rel in [*workflow_files, *configs]:
            if (root / rel).is_file() and not Path(rel).is_absolute() and not rel.startswith(".."):
                site.raw[f"workflow/{rel}"] = rel
    site.write()
    with atomic_path(outputs["html"]) as tmp:
        tmp.write_text(page)
    for path, text in paper_pages.items():
        with atomic_path(path) as tmp:
            tmp.write_text(text)
    if outputs.get("crate") and files_dir is not None:
        crate_root = Path(outputs["crate"]).parent
        prefix = files_dir.relative_to(crate_root).as_posix() if files_dir.is_relative_to(crate_root) else "files"
        pages = [Path(outputs["html"]).name] + [p.name for p in paper_pages] + [Path(spec["notebook"]).name for spec in papers.values()
                                                if spec.get("notebook") and Path(spec["notebook"]).is_file()]
        write_crate(crate_root, sidecars={p: relocate_json(m, root) for p, m in sidecars.items()},
                    rule_of=rule_name,
                    run={"end": iso(_dt.datetime.now(_dt.timezone.utc).timestamp()), "config_hash": params["config_hash"],
                         "commit": git["commit"], "dirty": git["dirty"]},
                    workflow_files=[f"{prefix}/workflow/{rel}" for rel in workflow_files if f"workflow/{rel}" in site.raw],
                    config_files=[f"{prefix}/workflow/{rel}" for rel in configs if f"workflow/{rel}" in site.raw],
                    pages=pages, versions=versions, out=outputs["crate"], citations=crate_citations(papers))
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


def _run_sidecars(papers: dict, extra=()) -> dict[str, dict]:
    """Every result table and figure of the run with its sidecar: the registered outputs of each
    paper, the ``extra`` tables (the comparison by scale), and everything upstream of them
    (path -> sidecar, in the order found)."""
    seen: set[str] = set()
    found: dict[str, dict] = {}
    for spec in [*papers.values(), {"tables": list(extra)}]:
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
