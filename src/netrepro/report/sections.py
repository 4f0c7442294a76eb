"""The sections of ``report/index.html``: the scorecard over papers, and per paper its replication
summary, figures, claims, errata, findings, reconstructions and result tables. Each function
gathers the values; the markup is in ``templates/``."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
from markupsafe import Markup

from ..pipeline.registry import load_registry
from ..scale.record import NOT_RECORDED, NOT_RUN
from ..pipeline.provenance import sidecar_path
from ..judging.summary import FINDING_COUNT_COLUMNS, replication_summary, summary_sentences
from ..judging.verdicts import FINDING_VERDICTS, TESTABLE_VERDICTS, VERDICTS
from .markup import img, read_csv, render, rst_html
from .notebooks import figure_captions, figure_sort_key
from .panel import provenance_panel, rule_name

__all__ = ["table_view", "claims_html", "summary_html", "figure_html", "paper_section", "paper_brief", "paper_page_name",
           "explorer_rows", "explorer_html", "scorecard_html", "scale_html"]

# Text tables shown cell by cell (besides the claims, which have their own layout)
_TEXT_TABLES = (
    ("Errata", "errata", "Errors of the text: printed form, corrected form, numerical demonstration, kind "
                         "(only equation and prose errors count as errata; notation and typesetting slips are "
                         "listed) and which of our results the printed form would change."),
    ("Findings", "findings", "Our own discoveries beyond the paper's claims, with the evidence and the table "
                             "(and figure) that shows it. They are not errata of the text."),
    ("Reconstructions", "reconstructions",
     "Parameters the paper does not state or garbles: the value we chose, why, and where conclusions depend on it."),
)


def _truthy(value) -> bool:
    return str(value).strip().lower() in ("true", "1", "yes")


def _setting(config: dict, key: str):
    """The configuration value at the dotted ``key`` (``None`` if there is none)."""
    value = config
    for part in str(key).split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


def _as_configured(cell, setting):
    """A reconstruction's value as the configuration writes it: an integer setting stored in the
    table as a float (``20150101.0``, a float column of the evidence table) shows as the integer."""
    if not isinstance(setting, int) or isinstance(setting, bool):
        return cell
    try:
        return str(setting) if float(cell) == setting else cell
    except (TypeError, ValueError):
        return cell


def table_view(frame: pd.DataFrame, key: str = "", config: dict | None = None) -> dict:
    """A table as the ``data_table`` macro shows it: every column, cell by cell.

    Parameters
    ----------
    frame : pandas.DataFrame
        The table (its ``paper`` column is dropped).
    key : str, default ""
        Which table: ``findings`` labels a finding with ``known`` true a "known result";
        ``reconstructions`` shows the value of an integer setting as an integer.
    config : dict, optional
        The paper's configuration section (the types of the reconstructed settings).

    Returns
    -------
    dict
        ``columns``, ``rows`` (lists of cells) and ``known`` (one flag per row, or empty).
    """
    frame = frame.drop(columns=["paper"], errors="ignore")
    if key == "reconstructions" and {"key", "value"} <= set(frame.columns):
        frame = frame.assign(value=[_as_configured(v, _setting(config or {}, k))
                                    for k, v in zip(frame["key"], frame["value"])])
    known = [_truthy(v) for v in frame["known"]] if key == "findings" and "known" in frame else []
    return {"columns": list(frame.columns), "rows": [list(row) for row in frame.itertuples(index=False)],
            "known": known}


def _cell(row: pd.Series, name: str):
    value = row.get(name, "")
    return "" if value is None or (isinstance(value, float) and pd.isna(value)) else value


def claims_html(frame: pd.DataFrame, slug: str) -> str:
    """Claims table: where, statement, paper's value, ours, tolerance and why, verdict (robust, condition), note.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``results/claims/<slug>.csv``.
    slug : str
        The paper.

    Returns
    -------
    str
        The table's HTML.
    """
    names = ("claim_id", "location", "statement", "paper_value", "reproduced_value", "uncertainty", "tolerance",
             "tolerance_reason", "test", "verdict", "robust", "condition", "erratum_id", "note")
    rows = []
    for _, row in frame.iterrows():
        claim = {n: _cell(row, n) for n in names}
        claim["verdict"] = str(claim["verdict"]).strip()
        claim["robust"] = str(claim["robust"])
        rows.append(claim)
    return render("claims.html", slug=slug, rows=rows)


def summary_html(slug: str, spec: dict, frame: pd.DataFrame | None) -> str:
    """The replication summary that opens a paper's section (counted by :mod:`netrepro.judging.summary`).

    Parameters
    ----------
    slug : str
        The paper.
    spec : dict
        Its registered outputs (``errata``, ``findings``, ``figures``).
    frame : pandas.DataFrame or None
        Its claims table.

    Returns
    -------
    str
        The summary's HTML (``""`` without a claims table).
    """
    if frame is None:
        return ""
    errata = read_csv(spec["errata"]) if spec.get("errata") else None
    findings = read_csv(spec["findings"]) if spec.get("findings") else None
    table = replication_summary(frame, [Path(f).stem for f in spec.get("figures", [])])
    rows = [{**r, "testable": int(r["testable"])} for r in table.to_dict(orient="records")]
    return render("summary.html", slug=slug, sentences=summary_sentences(frame, errata, findings, table), rows=rows)


def figure_html(fig: Path, slug: str, captions: dict, ctx: dict) -> str:
    """One figure with its caption, layout notes, image and provenance panel.

    Parameters
    ----------
    fig : Path
        The figure.
    slug : str
        Its paper.
    captions : dict
        Figure stem -> caption (reStructuredText).
    ctx : dict
        The report's context (see :func:`netrepro.report.panel.provenance_panel`; ``layouts``).

    Returns
    -------
    str
        The ``<figure>``.
    """
    return render("figure.html", slug=slug, stem=fig.stem, fig=fig, ours=fig.stem.startswith("figS"),
                  label=("Figure " + fig.stem[3:]) if fig.stem.startswith("fig") else fig.stem,
                  caption=rst_html(captions.get(fig.stem, "")),
                  layout=ctx.get("layouts", {}).get(slug, {}).get(fig.stem) or {},
                  image=img(fig) if fig.is_file() else None, panel=Markup(provenance_panel(fig, slug, ctx)))


def _table_row(path: str, ctx: dict) -> dict:
    frame = read_csv(path)
    side = sidecar_path(Path(path))
    meta = json.loads(side.read_text()) if side.is_file() else {}
    return {"path": path, "href": ctx["site"].table_link(str(path)), "rows": "" if frame is None else len(frame),
            "rule": rule_name(meta) if meta else "", "sha": meta.get("output_sha256")}


def paper_section(slug: str, spec: dict, frame: pd.DataFrame | None, ctx: dict) -> str:
    """A paper's section of the report.

    Parameters
    ----------
    slug : str
        The paper.
    spec : dict
        Its registered outputs (``PAPER_OUTPUTS`` of the workflow).
    frame : pandas.DataFrame or None
        Its claims table.
    ctx : dict
        The report's context.

    Returns
    -------
    str
        The ``<section>``.
    """
    meta = load_registry().get(slug, {})
    captions = figure_captions(ctx["root"], slug)
    figures = sorted((Path(f) for f in spec.get("figures", [])), key=figure_sort_key)
    claims = None
    counts = ""
    if frame is not None:
        found = frame["verdict"].value_counts() if "verdict" in frame else {}
        counts = ", ".join(f"{int(found.get(v, 0))} {v}" for v in VERDICTS)
        claims = {"n": len(frame), "href": ctx["site"].table_link(spec["claims"]),
                  "html": Markup(claims_html(frame, slug))}
    parts = []
    for title, key, intro in _TEXT_TABLES:
        table = read_csv(spec[key]) if spec.get(key) else None
        parts.append({"key": key, "title": title, "intro": Markup(intro), "path": spec.get(key),
                      "table": None if table is None else table_view(table, key, ctx["config"].get(slug, {}))})
    notebook = spec.get("notebook")
    return render(
        "paper.html", slug=slug, title=meta.get("title", slug), authors=meta.get("authors", ""),
        source_text=meta.get("file"), notebook=Path(notebook).name if notebook else None,
        summary=Markup(summary_html(slug, spec, frame)),
        paper_figures=[Markup(figure_html(f, slug, captions, ctx)) for f in figures if not f.stem.startswith("figS")],
        our_figures=[Markup(figure_html(f, slug, captions, ctx)) for f in figures if f.stem.startswith("figS")],
        claims=claims, claims_path=spec.get("claims"), counts=counts, parts=parts,
        tables=[_table_row(p, ctx) for p in dict.fromkeys(spec.get("tables", []))])


def paper_page_name(slug: str) -> str:
    """The file name of a paper's page in ``report/``: ``paper-<slug>.html``.

    Parameters
    ----------
    slug : str
        The paper.

    Returns
    -------
    str
        The name (the notebook page is ``<slug>.html``).
    """
    return f"paper-{slug}.html"


def paper_brief(slug: str, spec: dict, frame: pd.DataFrame | None) -> str:
    """A paper's summary on ``report/index.html`` (``<section id=slug>``): its title, authors, the
    replication summary's sentences and links to its page, its notebook and its rows in the explorer.

    Parameters
    ----------
    slug : str
        The paper.
    spec : dict
        Its registered outputs.
    frame : pandas.DataFrame or None
        Its claims table.

    Returns
    -------
    str
        The ``<section>``.
    """
    meta = load_registry().get(slug, {})
    sentences = []
    if frame is not None:
        errata = read_csv(spec["errata"]) if spec.get("errata") else None
        findings = read_csv(spec["findings"]) if spec.get("findings") else None
        table = replication_summary(frame, [Path(f).stem for f in spec.get("figures", [])])
        sentences = summary_sentences(frame, errata, findings, table)
    notebook = spec.get("notebook")
    return render("brief.html", slug=slug, title=meta.get("title", slug), authors=meta.get("authors", ""),
                  page=paper_page_name(slug), notebook=Path(notebook).name if notebook else None, sentences=sentences)


def explorer_rows(papers: dict, claims: dict) -> list[dict]:
    """Every claim, finding and erratum of every paper, as rows of the claims explorer.

    Parameters
    ----------
    papers : dict
        Slug -> registered outputs (``findings``, ``errata``).
    claims : dict
        Slug -> claims table (or None).

    Returns
    -------
    list of dict
        ``paper``, ``kind`` (``claim``, ``finding``, ``erratum``), ``id``, ``statement``, ``verdict``
        (``""`` for an erratum), ``detail`` and ``href`` (the row or table on the paper's page).
    """
    rows = []
    for slug, spec in papers.items():
        page = paper_page_name(slug)
        frame = claims.get(slug)
        for _, row in (frame.iterrows() if frame is not None else ()):
            ident = _cell(row, "claim_id")
            rows.append({"paper": slug, "kind": "claim", "id": ident, "statement": _cell(row, "statement"),
                         "verdict": str(_cell(row, "verdict")).strip(), "detail": _cell(row, "location"),
                         "href": f"{page}#{slug}-claim-{ident}"})
        findings = read_csv(spec["findings"]) if spec.get("findings") else None
        for _, row in (findings.iterrows() if findings is not None else ()):
            rows.append({"paper": slug, "kind": "finding", "id": _cell(row, "finding_id"),
                         "statement": _cell(row, "statement"), "verdict": str(_cell(row, "verdict")).strip(),
                         "detail": "", "href": f"{page}#{slug}-findings"})
        errata = read_csv(spec["errata"]) if spec.get("errata") else None
        for _, row in (errata.iterrows() if errata is not None else ()):
            printed, corrected = _cell(row, "printed"), _cell(row, "corrected")
            rows.append({"paper": slug, "kind": "erratum", "id": _cell(row, "erratum_id"),
                         "statement": f"{_cell(row, 'location')}: printed {printed}; corrected {corrected}",
                         "verdict": "", "detail": _cell(row, "kind"), "href": f"{page}#{slug}-errata"})
    return rows


def explorer_html(papers: dict, rows: list[dict]) -> str:
    """The claims explorer (``<section id="explore">``): one table of ``rows`` with its filters.

    Parameters
    ----------
    papers : dict
        Slug -> registered outputs (the paper filter's choices, in order).
    rows : list of dict
        :func:`explorer_rows`.

    Returns
    -------
    str
        The section; its script is ``templates/explorer.js``.
    """
    found = {r["verdict"] for r in rows if r["verdict"]}
    order = list(dict.fromkeys([*VERDICTS, *FINDING_VERDICTS]))
    verdicts = [v for v in order if v in found] + sorted(found - set(order))
    kinds = [k for k in ("claim", "finding", "erratum") if any(r["kind"] == k for r in rows)]
    return render("explorer.html", papers=list(papers), rows=rows, verdicts=verdicts, kinds=kinds)


def scorecard_html(score: pd.DataFrame, papers: dict, explore: bool = False, pages: bool = False) -> str:
    """The scorecard: verdict counts per paper and in total, with the share reproduced.

    Parameters
    ----------
    score : pandas.DataFrame
        :func:`netrepro.judging.summary.scorecard` (its last row is the total).
    papers : dict
        Slug -> registered outputs.
    explore : bool, default False
        The page has the claims explorer: each count links to its rows there.
    pages : bool, default False
        Each paper has its own page (:func:`paper_page_name`): the claims links go there.

    Returns
    -------
    str
        The cards, the table and its legend.
    """
    total = score.iloc[-1]
    shown = list(VERDICTS)
    counted = [*shown, "claims", "testable", "other", "errata", "minor_errata", "findings",
               *(c for c in FINDING_COUNT_COLUMNS if c in score.columns)]
    rows = []
    for _, row in score.iterrows():
        slug = row["paper"]
        spec = papers.get(slug)
        n = max(int(row["testable"]), 1)
        item = {"paper": slug, "title": None, "n": {k: int(row[k]) for k in counted},
                "share": "" if pd.isna(row["scored_reproduced_pct"]) else f'{row["scored_reproduced_pct"]:.1f} %',
                "bar": [(v, int(row[v]), f"{120 * int(row[v]) / n:.1f}") for v in TESTABLE_VERDICTS if int(row[v])]}
        if spec is not None:
            recon = read_csv(spec["reconstructions"]) if spec.get("reconstructions") else None
            figs = spec.get("figures", [])
            item.update(title=load_registry().get(slug, {}).get("title", slug), reconstructions="" if recon is None else len(recon),
                        paper_figures=sum(not Path(f).stem.startswith("figS") for f in figs),
                        our_figures=sum(Path(f).stem.startswith("figS") for f in figs))
        rows.append(item)
    pct = total["scored_reproduced_pct"]
    finding_verdicts = [c.removeprefix("findings_") for c in FINDING_COUNT_COLUMNS if c in score.columns]
    return render("scorecard.html", total={k: int(total[k]) for k in counted}, shown=shown,
                  finding_verdicts=finding_verdicts,
                  untestable=[v for v in shown if v not in TESTABLE_VERDICTS], show_other=int(total["other"]) > 0,
                  rows=rows, pct="" if pd.isna(pct) else f"{pct:.1f} %", explore=explore, pages=pages)


def scale_html(scale: dict) -> str:
    """The panel "Does scale change a verdict?" (issue 31), or ``""`` without a recorded run.

    Parameters
    ----------
    scale : dict
        Paths from the report rule: ``table`` (``verdicts_by_scale.csv``), ``findings``,
        ``stale`` (:func:`netrepro.scale.record.scale_step`) and ``reference`` (the recorded run's folder,
        holding ``provenance.json``).

    Returns
    -------
    str
        The panel: the recorded run's identity, whether its tables are stale, and every claim and
        finding whose verdict or robust flag differs between this run and the paper-scale run.
    """
    def text_table(path):
        return pd.read_csv(path, dtype=str, keep_default_na=False) if path and Path(path).is_file() else None

    if not scale or text_table(scale.get("table")) is None:
        return ""
    claims, findings, stale = (text_table(scale.get(k)) for k in ("table", "findings", "stale"))
    prov_path = Path(scale["reference"]) / "provenance.json"
    prov = json.loads(prov_path.read_text()) if prov_path.is_file() else {}

    def changed(frame):
        return frame[frame["changed"].str.lower() == "true"]

    def absent(frame, what):
        return frame["what_changed"] == what

    # a paper the recording does not hold (added since) is not compared: no change, no removal
    unrecorded = sorted(set(claims[absent(claims, NOT_RECORDED)]["paper"])
                        | (set(findings[absent(findings, NOT_RECORDED)]["paper"]) if findings is not None else set()))
    compared_claims = claims[~absent(claims, NOT_RECORDED) & ~absent(claims, NOT_RUN)]
    compared_findings = None if findings is None else findings[~absent(findings, NOT_RECORDED)
                                                               & ~absent(findings, NOT_RUN)]
    wall = prov.get("wall_time_s")
    return render("scale.html", prov=prov, prov_path=prov_path.as_posix(),
                  wall=f"{float(wall) / 60:.1f} min" if wall else "not recorded",
                  unrecorded=[{"paper": p, "claims": int((claims["paper"] == p).sum()),
                               "findings": 0 if findings is None else int((findings["paper"] == p).sum())}
                              for p in unrecorded],
                  n_claims=len(compared_claims), n_findings=0 if findings is None else len(compared_findings),
                  claims=changed(claims).to_dict(orient="records"),
                  findings=[] if findings is None else changed(findings).to_dict(orient="records"),
                  values_only=int(((claims["changed"].str.lower() != "true")
                                   & claims["what_changed"].str.contains("value")).sum()),
                  value_rows=_value_only_rows(claims, findings),
                  stale=[] if stale is None else stale.to_dict(orient="records"),
                  stale_papers=[] if stale is None else sorted(set(stale["paper"])),
                  table=scale["table"])


def _value_only_rows(claims: pd.DataFrame, findings: pd.DataFrame | None) -> list[dict]:
    """Claims and findings whose verdict and robust flag stay but whose value or evidence moves with scale."""
    rows = []
    for kind, frame, ident in (("claim", claims, "claim_id"), ("finding", findings, "finding_id")):
        if frame is None:
            continue
        moved = frame[(frame["changed"].str.lower() != "true") & frame["what_changed"].str.contains("value")]
        for _, r in moved.iterrows():
            rows.append({"kind": kind, "paper": r["paper"], "id": r[ident], "verdict": r["verdict_paper_scale"]})
    return rows
