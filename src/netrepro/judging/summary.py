"""Scorecard and replication summaries, computed from the claims, errata and findings tables.

Everything a reader sees in the report's scorecard and in the replication summary that opens
each paper's section is counted here from the tables of a build, never typed (issue 15):

* :func:`scorecard`: per paper, every verdict category; only the testable verdicts
  (:data:`netrepro.judging.verdicts.TESTABLE_VERDICTS`) are scored, and only errata of kind ``equation``
  or ``prose`` count as errata (notation and typesetting slips are listed, not counted).
* :func:`replication_summary`: per figure of the paper and per claim group, ``replicated``,
  ``partially``, ``not replicated`` or ``not testable``, and why.
* :func:`summary_sentences`: the one-minute prose of a paper, with its numbers from the tables.
"""

from __future__ import annotations

import re

import pandas as pd

from .verdicts import FINDING_VERDICTS, SCORED_ERRATUM_KINDS, TESTABLE_VERDICTS, VERDICTS

__all__ = ["SCORECARD_COLUMNS", "FINDING_COUNT_COLUMNS", "scorecard", "replication_summary", "summary_sentences",
           "STATUSES"]

# our findings by verdict (issue 37): a failing or retracted finding is counted, never dropped
FINDING_COUNT_COLUMNS = [f"findings_{v}" for v in FINDING_VERDICTS]
SCORECARD_COLUMNS = ["paper", "claims", *VERDICTS, "other", "testable", "scored_reproduced_pct", "errata",
                     "minor_errata", "findings", *FINDING_COUNT_COLUMNS]
STATUSES = ("replicated", "partially", "not replicated", "not testable", "no claim")
# a group is replicated when every testable claim of it is reproduced; partially when some hold (reproduced
# or conditional); not replicated when none does
_HOLDS = ("reproduced", "conditional")


def _verdicts(frame: pd.DataFrame | None) -> pd.Series:
    if frame is None or "verdict" not in frame:
        return pd.Series(dtype=str)
    return frame["verdict"].astype(str).str.strip()


def _errata_split(frame: pd.DataFrame | None) -> tuple[int, int]:
    """(errata of substance, notation/typesetting slips); without a kind column every row counts."""
    if frame is None or not len(frame):
        return 0, 0
    if "kind" not in frame:
        return len(frame), 0
    scored = frame["kind"].astype(str).isin(SCORED_ERRATUM_KINDS)
    return int(scored.sum()), int((~scored).sum())


def scorecard(claims: dict, errata: dict | None = None, findings: dict | None = None) -> pd.DataFrame:
    """Counts of every verdict per paper, the testable share reproduced, errata and findings (and a total row).

    Parameters
    ----------
    claims : dict
        ``{slug: claims DataFrame}``.
    errata, findings : dict, optional
        ``{slug: DataFrame}``; missing papers count zero.

    Returns
    -------
    DataFrame
        Columns :data:`SCORECARD_COLUMNS`. Verdicts outside the vocabulary are counted in ``other``
        so that the verdict columns add up to ``claims``; ``testable`` counts reproduced, conditional,
        differs, erratum and undecided; ``scored_reproduced_pct`` is reproduced / testable in percent;
        ``findings_<verdict>`` counts our findings by verdict (the registered rule's verdict).
    """
    errata, findings = errata or {}, findings or {}
    rows = []
    for slug, frame in claims.items():
        counts = _verdicts(frame).value_counts()
        row = {"paper": slug, "claims": 0 if frame is None else len(frame),
               **{v: int(counts.get(v, 0)) for v in VERDICTS}}
        row["other"] = row["claims"] - sum(row[v] for v in VERDICTS)
        row["errata"], row["minor_errata"] = _errata_split(errata.get(slug))
        found = findings.get(slug)
        row["findings"] = 0 if found is None else len(found)
        found_counts = _verdicts(found).value_counts()
        row.update({f"findings_{v}": int(found_counts.get(v, 0)) for v in FINDING_VERDICTS})
        rows.append(row)
    table = pd.DataFrame(rows, columns=[c for c in SCORECARD_COLUMNS if c not in ("testable", "scored_reproduced_pct")])
    total = {"paper": "total", **{c: int(table[c].sum()) for c in table.columns[1:]}}
    table = pd.concat([table, pd.DataFrame([total])], ignore_index=True)
    table["testable"] = table[list(TESTABLE_VERDICTS)].sum(axis=1).astype(int)
    share = 100.0 * table["reproduced"] / table["testable"].where(table["testable"] > 0)
    table["scored_reproduced_pct"] = share.round(1)
    return table[SCORECARD_COLUMNS]


def _figure_number(figure_id: str) -> str:
    return figure_id[3:] if figure_id.startswith("fig") else figure_id


def _about_figure(frame: pd.DataFrame, number: str) -> pd.Series:
    """Claims stated on figure ``number``: their group is 'Fig <n>' or their location names the figure."""
    pattern = re.compile(rf"\bfig(?:ure|\.)?\s*{re.escape(number)}\b", re.IGNORECASE)
    text = frame.get("group", pd.Series("", index=frame.index)).astype(str) + " | " + \
        frame.get("location", pd.Series("", index=frame.index)).astype(str)
    return text.map(lambda t: bool(pattern.search(t)))


def _judge_group(sub: pd.DataFrame) -> tuple[str, dict, str]:
    verdicts = _verdicts(sub)
    counts = verdicts.value_counts()
    testable = int(verdicts.isin(TESTABLE_VERDICTS).sum())
    if testable == 0:
        status = "not testable" if len(sub) else "no claim"
    elif int(counts.get("reproduced", 0)) == testable:
        status = "replicated"
    elif int(verdicts.isin(_HOLDS).sum()) == 0:
        status = "not replicated"
    else:
        status = "partially"
    reasons = []
    for _, row in sub[verdicts.isin(("conditional", "differs", "erratum"))].iterrows():
        why = {"conditional": str(row.get("condition", "") or ""),
               "erratum": f"erratum {row.get('erratum_id', '')}".strip(),
               "differs": _first_sentence(row.get("note", ""))}[row["verdict"]]
        reasons.append(f"{row['claim_id']} {row['verdict']}" + (f" ({why})" if why else ""))
    counts_out = {v: int(counts.get(v, 0)) for v in VERDICTS}
    return status, {"testable": testable, **counts_out}, "; ".join(reasons)


def _first_sentence(text) -> str:
    text = "" if text is None or (isinstance(text, float) and pd.isna(text)) else str(text)
    head = re.split(r"(?<=[.;])\s", text, maxsplit=1)[0]
    return head if len(head) <= 160 else head[:157] + "..."


def replication_summary(claims: pd.DataFrame, figure_ids=()) -> pd.DataFrame:
    """Per figure of the paper and per claim group: replicated / partially / not, and why.

    Parameters
    ----------
    claims : DataFrame
        A paper's claims table (columns ``claim_id, verdict, group, location, condition,
        erratum_id, note``).
    figure_ids : iterable of str
        The paper's own figures (``fig1``, ...; our ``figS*`` figures are not the paper's).

    Returns
    -------
    DataFrame
        Columns ``item, kind, status, testable, <every verdict>, why``: first one row per
        figure (kind ``figure``; status ``no claim`` when the paper states nothing testable
        about it), then one per claim group (kind ``group``) not named after a figure, in order of
        first appearance.
    """
    rows = []
    for fig in figure_ids:
        if fig.startswith("figS"):
            continue
        sub = claims[_about_figure(claims, _figure_number(fig))] if len(claims) else claims
        status, counts, why = _judge_group(sub)
        rows.append({"item": f"Fig {_figure_number(fig)}", "kind": "figure", "status": status, **counts, "why": why})
    groups = claims["group"].astype(str) if "group" in claims else pd.Series(dtype=str)
    figure_items = {r["item"] for r in rows}
    for name in dict.fromkeys(groups):
        if name in figure_items:  # a group named after a figure is that figure's row
            continue
        status, counts, why = _judge_group(claims[groups == name])
        rows.append({"item": name, "kind": "group", "status": status, **counts, "why": why})
    return pd.DataFrame(rows, columns=["item", "kind", "status", "testable", *VERDICTS, "why"])


def _verb(count: int, one: str, many: str) -> str:
    return one if count == 1 else many


def summary_sentences(claims: pd.DataFrame, errata: pd.DataFrame | None, findings: pd.DataFrame | None,
                      summary: pd.DataFrame) -> list[str]:
    """The replication summary of a paper in three sentences, every number counted from the tables.

    Parameters
    ----------
    claims : pandas.DataFrame
        The paper's claims table.
    errata : pandas.DataFrame or None
        Its errata table.
    findings : pandas.DataFrame or None
        Its findings table.
    summary : pandas.DataFrame
        :func:`replication_summary` of the claims.

    Returns
    -------
    list of str
        The sentences.
    """
    verdicts = _verdicts(claims)
    counts = verdicts.value_counts()
    testable = int(verdicts.isin(TESTABLE_VERDICTS).sum())
    untestable = len(verdicts) - testable
    scored, minor = _errata_split(errata)
    figs = summary[summary["kind"] == "figure"]
    groups = summary[summary["kind"] == "group"]
    fig_counts = figs["status"].value_counts()
    group_counts = groups["status"].value_counts()
    n = {v: int(counts.get(v, 0)) for v in VERDICTS}
    sentences = [
        f"Of {testable} testable claims, {n['reproduced']} {_verb(n['reproduced'], 'is', 'are')} reproduced, "
        f"{n['conditional']} {_verb(n['conditional'], 'holds', 'hold')} only under a condition the paper does not "
        f"state, {n['differs']} {_verb(n['differs'], 'differs', 'differ')} and {n['erratum']} "
        f"{_verb(n['erratum'], 'is', 'are')} wrong because of an error of the text; {untestable} further "
        f"{_verb(untestable, 'row is', 'rows are')} kept for transparency ({n['not_checkable']} not checkable, "
        f"{n['not_identifiable']} not identifiable, {n['context']} context).",
    ]
    parts = []
    for label, rows, tally in (("figures", figs, fig_counts), ("claim groups", groups, group_counts)):
        if len(rows):
            parts.append(f"of its {len(rows)} {label}, " + ", ".join(
                f"{int(tally.get(s, 0))} {s}" for s in STATUSES if int(tally.get(s, 0))))
    if parts:
        sentences.append("; ".join(parts).capitalize() + ".")
    sentences.append(f"The text has {scored} errata of substance (equation or prose) and {minor} notation or "
                     f"typesetting slips; we add {0 if findings is None else len(findings)} findings of our own.")
    return sentences
