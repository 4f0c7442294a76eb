"""The one verdict function every paper uses, and the claims, errata, reconstructions and findings tables.

The paper's side (claims, errata, reconstructions, findings) is loaded and validated by
:mod:`netrepro.paperdata` (issue 15, split out in issue 29). Our side is computed by the paper's
evidence step into ``results/evidence/<slug>.csv`` (columns ``quantity, variant, value, note``;
built with :func:`evidence_frame`): one ``nominal`` row per quantity at the configured settings,
and one row per variant across the declared range of the reconstructions a claim or finding
depends on. By convention, quantity ``<erratum id>.residual_printed`` / ``.residual_corrected``
give an erratum's residuals (the note of the first is its demonstration), and
``reconstruction.<key>`` gives a reconstruction's value (its note is the sensitivity). Nothing in
Python holds a paper value, a statement or a tolerance.

Only declared ranges decide a verdict (issue 27): a variant row decides a verdict and ``robust``
only if its label reads ``<key>=<value>`` or ``<key>: <anything>`` with ``<key>`` one of the
entry's ``depends_on`` (:func:`split_variants`). Any other label is a re-reading: the note lists
it with its outcome; it decides nothing.

:func:`judge` decides a verdict from an entry (a claim or a finding), our nominal value and our
values across the declared variants: a verdict that changes inside that range is
``conditional``, with the condition stated, and ``robust`` is ``no``. :func:`verdicts_step`
writes the four tables of one paper.

Loading and validating the data files is :mod:`netrepro.paperdata`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .errors import ConfigError, InputError
from .paperdata import ClaimEntry, FindingEntry, PaperData, load_paper_data

__all__ = [
    "VERDICTS",
    "TESTABLE_VERDICTS",
    "FINDING_VERDICTS",
    "SCORED_ERRATUM_KINDS",
    "CLAIM_COLUMNS",
    "ERRATA_COLUMNS",
    "RECONSTRUCTION_COLUMNS",
    "FINDING_COLUMNS",
    "EVIDENCE_COLUMNS",
    "NOMINAL",
    "Judgement",
    "read_evidence",
    "evidence_frame",
    "erratum_evidence",
    "lookup",
    "variant_key",
    "split_variants",
    "agrees",
    "judge",
    "claims_table",
    "errata_table",
    "reconstructions_table",
    "findings_table",
    "verdicts_step",
]

VERDICTS = ("reproduced", "conditional", "differs", "erratum", "not_checkable", "not_identifiable", "context")
# the verdicts that score a reproduction; the other three are kept for transparency only
TESTABLE_VERDICTS = ("reproduced", "conditional", "differs", "erratum")
# the verdicts on our own findings (a failing finding must be rewritten)
FINDING_VERDICTS = ("holds", "conditional", "fails")
# only errors of substance count as errata in the scorecard; notation and typesetting are listed
SCORED_ERRATUM_KINDS = ("equation", "prose")
CLAIM_COLUMNS = ["paper", "claim_id", "statement", "paper_value", "reproduced_value", "tolerance", "verdict",
                 "note", "tolerance_reason", "location", "condition", "depends_on", "robust", "erratum_id",
                 "group", "test"]
ERRATA_COLUMNS = ["paper", "erratum_id", "location", "printed", "corrected", "demonstration", "residual_printed",
                  "residual_corrected", "kind", "impact"]
RECONSTRUCTION_COLUMNS = ["paper", "key", "value", "reason", "sensitivity", "range"]
FINDING_COLUMNS = ["paper", "finding_id", "statement", "evidence", "table", "figure", "verdict", "robust", "condition",
                   "rule", "evidence_quantities", "depends_on", "prior_work", "known", "cause_variant"]
EVIDENCE_COLUMNS = ["quantity", "variant", "value", "note"]
NOMINAL = "nominal"
_UNTESTABLE_KIND_VERDICT = {"not_checkable": "not_checkable", "not_identifiable": "not_identifiable",
                            "context": "context"}
_EPS = 2.0 ** -52
# a declared-range variant label: "<key>=<value>" or "<key>: <anything>" (spaces around '=' allowed)
_VARIANT_LABEL = re.compile(r"^\s*([A-Za-z0-9_.-]+)\s*(?:=|:)")


@dataclass(frozen=True)
class Judgement:
    """The verdict on one claim or finding.

    Attributes
    ----------
    verdict : str
        One of :data:`VERDICTS` (claims) or :data:`FINDING_VERDICTS` (findings).
    robust : str
        ``yes`` when the verdict holds across every declared variant, ``no`` when it changes,
        ``""`` when the entry has no declared variant.
    condition : str
        For ``conditional``: where it holds and where it does not.
    readings : tuple of str
        Labels of the variants that are re-readings (outside every declared range): listed, not judged.
    """

    verdict: str
    robust: str
    condition: str
    readings: tuple = ()


def evidence_frame(rows) -> pd.DataFrame:
    """The evidence table of a paper from ``dict(quantity, value, note='', variant='nominal')`` rows.

    Parameters
    ----------
    rows : iterable of dict
        One dict per row with keys ``quantity`` and ``value``, optional ``variant`` (default
        ``"nominal"``) and ``note`` (default ``""``).

    Returns
    -------
    pandas.DataFrame
        Columns ``quantity, variant, value, note``, rows in the given order.

    Raises
    ------
    ValueError
        For a repeated (quantity, variant) pair.
    """
    frame = pd.DataFrame([{"quantity": r["quantity"], "variant": r.get("variant", NOMINAL),
                           "value": r["value"], "note": r.get("note", "")} for r in rows], columns=EVIDENCE_COLUMNS)
    dup = frame.duplicated(["quantity", "variant"])
    if dup.any():
        raise ValueError(f"repeated evidence rows: {frame.loc[dup, ['quantity', 'variant']].values.tolist()}")
    return frame


def erratum_evidence(erratum_id: str, printed, corrected=None, note: str = "") -> list[dict]:
    """Evidence rows of an erratum's residuals, named as :func:`errata_table` reads them.

    Parameters
    ----------
    erratum_id : str
        The erratum's id in ``errata.yaml``.
    printed, corrected
        Residual of the printed form and of the corrected one (``corrected`` omitted: no row).
    note : str
        The computed part of the demonstration.

    Returns
    -------
    list of dict
        Rows for :func:`evidence_frame`.
    """
    rows = [{"quantity": f"{erratum_id}.residual_printed", "value": printed, "note": note}]
    if corrected is not None:
        rows.append({"quantity": f"{erratum_id}.residual_corrected", "value": corrected})
    return rows


def _parse(value):
    """A cell of the evidence table: booleans and numbers back from their text.

    An integer stays an integer (a seed or a horizon is shown as ``20150101``, not ``20150101.0``).
    """
    if isinstance(value, (bool, int, float)) and not isinstance(value, str):
        return value
    text = str(value).strip()
    if text in ("True", "False"):
        return text == "True"
    if re.fullmatch(r"[+-]?\d+", text):
        return int(text)
    try:
        return float(text)
    except ValueError:
        return text


def read_evidence(path: str | Path) -> dict:
    """``{quantity: {variant: (value, note)}}`` from an evidence table.

    Parameters
    ----------
    path : str or Path
        An evidence CSV (``results/evidence/<slug>.csv``); every cell is read as text.

    Returns
    -------
    dict
        Quantity -> variant -> ``(value, note)``, the value parsed from its text (number,
        boolean or text); a repeated (quantity, variant) keeps the last row.

    Raises
    ------
    InputError
        If a column of ``quantity, variant, value, note`` is missing.
    """
    frame = pd.read_csv(path, dtype=str, keep_default_na=False)
    missing = set(EVIDENCE_COLUMNS) - set(frame.columns)
    if missing:
        raise InputError(f"{path}: evidence table lacks columns {sorted(missing)}")
    out: dict = {}
    for row in frame.itertuples(index=False):
        out.setdefault(row.quantity, {})[row.variant] = (_parse(row.value), row.note)
    return out


def lookup(ours: dict, tables: dict):
    """Our value for a claim, from already loaded result tables.

    Parameters
    ----------
    ours : dict
        ``{"table": path, "column": name, "where": {column: value, ...}}``; ``where`` must select one row.
    tables : dict
        ``{path: pandas.DataFrame}``.

    Returns
    -------
    object
        The selected cell (a number or a boolean).

    Raises
    ------
    ConfigError
        If the table or column is unknown or the selection is not exactly one row.
    """
    table = ours.get("table")
    if table not in tables:
        raise ConfigError(f"claim quantity names table {table!r}, which no step produced")
    frame = tables[table]
    column = ours.get("column")
    if column not in frame.columns:
        raise ConfigError(f"claim quantity names column {column!r}, which {table} does not have")
    mask = None
    for key, value in (ours.get("where") or {}).items():
        if key not in frame.columns:
            raise ConfigError(f"claim quantity selects on column {key!r}, which {table} does not have")
        hit = frame[key] == value
        mask = hit if mask is None else (mask & hit)
    rows = frame if mask is None else frame[mask]
    if len(rows) != 1:
        raise ConfigError(f"claim quantity {ours} selects {len(rows)} rows of {table}, expected exactly one")
    return rows.iloc[0][column]


def variant_key(label: str) -> str | None:
    """The key of a declared-range variant label, or None for a label of another form.

    Parameters
    ----------
    label : str
        A variant label of the evidence table (or of a claim's ``ours.variants``).

    Returns
    -------
    str or None
        ``<key>`` of ``<key>=<value>`` or ``<key>: <anything>``; None if the label has neither form
        (e.g. ``"last k only (k=60)"``, ``"agent 0, H=200"``).
    """
    match = _VARIANT_LABEL.match(str(label))
    return match.group(1) if match else None


def split_variants(depends_on, variants: dict | None) -> tuple[dict, dict]:
    """Split variant values into those that decide a verdict and the re-readings.

    Parameters
    ----------
    depends_on : sequence of str
        The entry's reconstruction keys (whose declared ranges re-judge it).
    variants : dict or None
        ``{label: value}``.

    Returns
    -------
    declared : dict
        ``{label: value}`` whose label's key (:func:`variant_key`) is in ``depends_on``: they decide.
    readings : dict
        The others: re-readings, listed in the note, deciding nothing.
    """
    keys = set(depends_on)
    declared, readings = {}, {}
    for label, value in (variants or {}).items():
        (declared if variant_key(label) in keys else readings)[label] = value
    return declared, readings


def agrees(entry, value) -> bool:
    """Whether ``value`` agrees with the entry's expected value within its pre-set tolerance.

    Parameters
    ----------
    entry : ClaimEntry or FindingEntry
        A ``numeric`` or ``boolean`` claim (held against the paper's value) or finding (held
        against what it asserts).
    value : float or bool
        Our value.

    Returns
    -------
    bool
        For booleans, equality; for numbers, ``|ours - expected| <= tolerance`` (times
        ``|expected|`` if relative), with NaN or infinite values never agreeing.
    """
    if entry.kind == "boolean":
        return bool(value) == bool(entry.expected)
    ours, expected = float(value), float(entry.expected)
    scale = abs(expected) if entry.relative else 1.0
    # expected values and tolerances are decimals that binary floats hold only to an ulp: the edge
    # |ours - expected| == tolerance must not depend on which way the subtraction rounds
    slack = 8 * _EPS * max(abs(ours), abs(expected), entry.tolerance * scale)
    return math.isfinite(ours) and abs(ours - expected) <= entry.tolerance * scale + slack


def judge(entry, value=None, variants: dict | None = None) -> Judgement:
    """The verdict on a claim or a finding: one function for every paper.

    Parameters
    ----------
    entry : ClaimEntry or FindingEntry
        The paper's side of a claim, or our finding.
    value : float or bool, optional
        Our value at the configured (nominal) settings; unused for untestable kinds.
    variants : dict, optional
        ``{label: value}``: our value across variants. Only the labels ``<key>=...`` or
        ``<key>: ...`` with ``<key>`` in ``entry.depends_on`` decide (:func:`split_variants`,
        e.g. ``{"horizon=200": 0.8, "horizon=800": 1.2}``); the others are re-readings, returned
        in ``readings`` and judged nowhere.

    Returns
    -------
    Judgement
        Claims: ``not_checkable`` / ``not_identifiable`` / ``context`` for those kinds; otherwise
        ``reproduced`` when ours agrees at the nominal settings and at every declared variant;
        ``conditional`` when it agrees at some but not all (the condition lists where it holds);
        ``erratum`` when it disagrees everywhere and the entry names an erratum; else ``differs``.
        Findings: ``holds``, ``conditional`` (with its condition) or ``fails``, likewise.
    """
    finding = isinstance(entry, FindingEntry)
    if not finding and entry.kind in _UNTESTABLE_KIND_VERDICT:
        return Judgement(_UNTESTABLE_KIND_VERDICT[entry.kind], "", "")
    declared, readings = split_variants(entry.depends_on, variants)
    nominal = agrees(entry, value)
    outcomes = {label: agrees(entry, v) for label, v in declared.items()}
    robust = "" if not outcomes else ("yes" if all(o == nominal for o in outcomes.values()) else "no")
    if nominal and robust != "no":
        return Judgement("holds" if finding else "reproduced", robust, "", tuple(readings))
    nominal_label = entry.nominal or "nominal settings"
    holds = ([nominal_label] if nominal else []) + [label for label, ok in outcomes.items() if ok]
    fails = ([] if nominal else [nominal_label]) + [label for label, ok in outcomes.items() if not ok]
    if holds:
        return Judgement("conditional", robust, _condition_text(holds, fails), tuple(readings))
    if finding:
        return Judgement("fails", robust, "", tuple(readings))
    if entry.erratum_id:
        return Judgement("erratum", robust, "", tuple(readings))
    return Judgement("differs", robust, "", tuple(readings))


_LISTED = 6  # settings named in a condition on each side; the note lists every setting with its value


def _condition_text(holds: list, fails: list) -> str:
    """Where a conditional claim holds and where not; long lists are counted, not spelled out."""
    def side(labels):
        if len(labels) <= _LISTED:
            return "; ".join(labels)
        return "; ".join(labels[:_LISTED]) + f"; and {len(labels) - _LISTED} more (the note lists them)"

    total = len(holds) + len(fails)
    head = f"holds at {len(holds)} of {total} settings: " if total > 2 * _LISTED else "holds for "
    return f"{head}{side(holds)}; not for {side(fails)}"


def _fmt_tolerance(entry: ClaimEntry) -> str:
    if entry.kind == "boolean":
        return "exact"
    if entry.kind != "numeric":
        return ""
    return f"{entry.tolerance:g} (relative)" if entry.relative else f"{entry.tolerance:g}"


def _evidence_rows(kind: str, slug: str, ident: str, evidence: dict, name: str) -> dict:
    if name not in evidence:
        raise InputError(f"{kind} {slug}/{ident}: quantity {name!r} is not in results/evidence/{slug}.csv "
                         "(the paper's evidence step must produce it)")
    rows = evidence[name]
    if NOMINAL not in rows:
        raise InputError(f"{kind} {slug}/{ident}: quantity {name!r} has no {NOMINAL!r} row")
    return rows


def _our_value(entry: ClaimEntry, tables: dict, evidence: dict, slug: str):
    """(nominal value, note, {variant label: value}) of a testable claim."""
    ours = entry.ours
    if ours.get("quantity"):
        rows = _evidence_rows("claim", slug, entry.claim_id, evidence, ours["quantity"])
        value, note = rows[NOMINAL]
        return value, note, {label: v for label, (v, _) in rows.items() if label != NOMINAL}
    value = lookup(ours, tables)
    variants = {label: lookup(dict(ours, where={**(ours.get("where") or {}), **override}), tables)
                for label, override in (ours.get("variants") or {}).items()}
    return value, "", variants


def _undeclared(kind: str, slug: str, ident: str, depends_on: tuple, variants: dict) -> str:
    """The problem of an entry that depends on declared ranges but is re-judged across none ("" if none)."""
    declared, readings = split_variants(depends_on, variants)
    if not depends_on or declared:
        return ""
    also = f" (its variants {list(readings)} are re-readings: no label '<key>=...' with a key of depends_on)" \
        if readings else ""
    return f"{kind} {slug}/{ident} depends on {list(depends_on)} but has no variants across their declared range{also}"


def _raise_undeclared(problems: list) -> None:
    """One error naming every entry that is not re-judged across its declared range."""
    problems = [p for p in problems if p]
    if problems:
        raise InputError("\n  ".join(problems) + "\n  Re-judge each across the declared range of its depends_on: "
                         "variant rows labelled '<key>=<value>' or '<key>: ...' (evidence rows or ours.variants)")


def _variants_note(entry, variants: dict, outcome_words: tuple) -> str:
    """The note's account of the variants: the declared range, then the re-readings with their outcome."""
    declared, readings = split_variants(entry.depends_on, variants)
    parts = []
    if declared:
        parts.append("across the range: " + "; ".join(f"{label}: {_fmt_cell(v)}" for label, v in declared.items()))
    if readings:
        yes, no = outcome_words
        parts.append("re-readings (outside any declared range; they decide nothing): " + "; ".join(
            f"{label}: {_fmt_cell(v)} ({yes if agrees(entry, v) else no})" for label, v in readings.items()))
    return "; ".join(parts)


def _plain(value):
    """A numpy scalar as a plain Python value, for the table."""
    return value.item() if hasattr(value, "item") else value


def claims_table(data: PaperData, tables: dict, evidence: dict) -> pd.DataFrame:
    """Table ``results/claims/<slug>.csv``: every claim of ``data`` judged by :func:`judge`.

    Parameters
    ----------
    data : PaperData
        The paper's data files.
    tables : dict
        ``{path: DataFrame}`` of the result tables the claims read.
    evidence : dict
        From :func:`read_evidence`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`CLAIM_COLUMNS`, one row per claim in file order.

    Raises
    ------
    InputError
        When a claim that depends on a reconstruction has no variant across its declared range, or
        names a quantity the evidence step did not produce.
    """
    rows, problems = [], []
    for entry in data.claims:
        value, ev_note, variants = (None, "", {})
        if entry.kind in ("numeric", "boolean"):
            value, ev_note, variants = _our_value(entry, tables, evidence, data.slug)
            problems.append(_undeclared("claim", data.slug, entry.claim_id, entry.depends_on, variants))
        elif entry.ours.get("quantity") in evidence:
            ev_note = evidence[entry.ours["quantity"]].get(NOMINAL, (None, ""))[1]
        result = judge(entry, value, variants)
        if variants:
            ev_note = "; ".join(x for x in (ev_note, _variants_note(entry, variants, ("agrees", "disagrees"))) if x)
        rows.append({
            "paper": data.slug, "claim_id": entry.claim_id, "statement": entry.statement,
            "paper_value": entry.paper_value if entry.paper_value is not None else "",
            "reproduced_value": _plain(value) if value is not None else "", "tolerance": _fmt_tolerance(entry),
            "verdict": result.verdict, "note": "; ".join(x for x in (entry.note, ev_note) if x),
            "tolerance_reason": entry.tolerance_reason, "location": entry.location_text,
            "condition": result.condition, "depends_on": ", ".join(entry.depends_on), "robust": result.robust,
            "erratum_id": entry.erratum_id if result.verdict == "erratum" else "", "group": entry.group,
            "test": entry.test,
        })
    _raise_undeclared(problems)
    frame = pd.DataFrame(rows, columns=CLAIM_COLUMNS)
    assert set(frame["verdict"]) <= set(VERDICTS)
    return frame


def _fmt_cell(value) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return f"{value:.6g}"


def errata_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/errata/<slug>.csv``; residuals from the evidence quantities ``<id>.residual_*``.

    Parameters
    ----------
    data : PaperData
        The paper's data files.
    evidence : dict
        From :func:`read_evidence`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`ERRATA_COLUMNS`.
    """
    rows = []
    for e in data.errata:
        printed = evidence.get(f"{e['id']}.residual_printed", {}).get(NOMINAL, ("", ""))
        corrected = evidence.get(f"{e['id']}.residual_corrected", {}).get(NOMINAL, ("", ""))
        demonstration = "; ".join(x for x in (str(e.get("demonstration", "")).strip(), printed[1]) if x)
        rows.append({"paper": data.slug, "erratum_id": e["id"], "location": e["location"],
                     "printed": e["printed"].strip(), "corrected": e["corrected"].strip(),
                     "demonstration": demonstration, "residual_printed": printed[0],
                     "residual_corrected": corrected[0], "kind": e["kind"], "impact": e["impact"].strip()})
    return pd.DataFrame(rows, columns=ERRATA_COLUMNS)


def reconstructions_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/reconstructions/<slug>.csv``; value and sensitivity from ``reconstruction.<key>``.

    Parameters
    ----------
    data : PaperData
        The paper's data files.
    evidence : dict
        From :func:`read_evidence`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`RECONSTRUCTION_COLUMNS`.
    """
    rows = []
    for r in data.reconstructions:
        value, sensitivity = evidence.get(f"reconstruction.{r['key']}", {}).get(NOMINAL, (None, ""))
        if value is None or value == "":
            value = r.get("value", "")
        sensitivity = "; ".join(x for x in (str(r.get("sensitivity", "")).strip(), sensitivity) if x)
        rows.append({"paper": data.slug, "key": r["key"], "value": value, "reason": r["reason"].strip(),
                     "sensitivity": sensitivity, "range": str(r.get("range", "")).strip()})
    return pd.DataFrame(rows, columns=RECONSTRUCTION_COLUMNS)


def _fmt_rule(entry: FindingEntry) -> str:
    if entry.kind == "boolean":
        return f"{str(entry.asserted).lower()}, exact: {entry.rule_reason}"
    within = f"{entry.tolerance:.15g}" + (" (relative)" if entry.relative else "")
    return f"{entry.asserted:.15g} within {within}: {entry.rule_reason}"


def _names_evidence(cause: str, evidence: dict, rows_q: dict) -> bool:
    """Whether ``cause`` names an evidence quantity, a variant of the judged quantity, or ``<quantity>: <variant>``."""
    if cause in evidence or cause in rows_q:
        return True
    quantity, sep, variant = cause.partition(": ")
    return bool(sep) and variant in evidence.get(quantity, {})


def findings_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/findings/<slug>.csv``: our findings, judged by :func:`judge` like claims.

    Parameters
    ----------
    data : PaperData
        The paper's data files.
    evidence : dict
        From :func:`read_evidence`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`FINDING_COLUMNS`: the verdict (``holds``, ``conditional``, ``fails``),
        ``robust`` and the condition; the evidence text holds the judged quantity's value and note,
        the declared variants, the re-readings and the other evidence quantities' values.

    Raises
    ------
    InputError
        Naming the finding and the quantity, when a quantity it rests on (``quantity``,
        ``evidence_quantities``) or its cause variant is not in the evidence table, or when it
        depends on a reconstruction and has no variant across its declared range.
    """
    rows, problems = [], []
    for f in data.findings:
        rows_q = _evidence_rows("finding", data.slug, f.finding_id, evidence, f.quantity)
        for name in f.evidence_quantities:
            if name not in evidence:
                raise InputError(f"finding {data.slug}/{f.finding_id}: evidence quantity {name!r} is not in "
                                 f"results/evidence/{data.slug}.csv (the paper's evidence step must produce it)")
        cause = f.cause.get("variant", "")
        if cause and not _names_evidence(cause, evidence, rows_q):
            raise InputError(f"finding {data.slug}/{f.finding_id}: cause variant {cause!r} is neither an evidence "
                             f"quantity nor a variant of {f.quantity!r} (nor '<quantity>: <variant>' of the evidence "
                             "table)")
        value, note = rows_q[NOMINAL]
        variants = {label: v for label, (v, _) in rows_q.items() if label != NOMINAL}
        problems.append(_undeclared("finding", data.slug, f.finding_id, f.depends_on, variants))
        result = judge(f, value, variants)
        others = "; ".join(f"{q}: {_fmt_cell(evidence[q].get(NOMINAL, ('', ''))[0])}"
                           for q in f.evidence_quantities[1:])
        text = "; ".join(x for x in (f.evidence, _fmt_cell(value) if value != "" else "", note,
                                     _variants_note(f, variants, ("holds", "fails")),
                                     f"also rests on {others}" if others else "") if x)
        rows.append({"paper": data.slug, "finding_id": f.finding_id, "statement": f.statement, "evidence": text,
                     "table": f.table, "figure": f.figure, "verdict": result.verdict, "robust": result.robust,
                     "condition": result.condition, "rule": _fmt_rule(f),
                     "evidence_quantities": ", ".join(f.evidence_quantities), "depends_on": ", ".join(f.depends_on),
                     "prior_work": f.prior_work, "known": "yes" if f.known else "no", "cause_variant": cause})
    _raise_undeclared(problems)
    frame = pd.DataFrame(rows, columns=FINDING_COLUMNS)
    assert set(frame["verdict"]) <= set(FINDING_VERDICTS)
    return frame


def verdicts_step(params, inputs, outputs):
    """Step of rule ``<slug>_claims``: the claims, errata, reconstructions and findings tables.

    Parameters
    ----------
    params : dict
        ``{"slug": ...}``.
    inputs : dict
        ``evidence`` (the paper's evidence table), ``tables`` (the result tables its claims read)
        and the data files (``claims_file``, ...).
    outputs : dict
        ``table`` (claims), ``errata``, ``reconstructions``, ``findings``.

    Returns
    -------
    dict
        ``{output name: DataFrame}``.
    """
    slug = params["slug"]
    data = load_paper_data(slug, Path(inputs["claims_file"]).parent)
    evidence = read_evidence(inputs["evidence"])
    paths = inputs.get("tables", [])
    paths = [paths] if isinstance(paths, (str, Path)) else list(paths)
    tables = {str(p): pd.read_csv(p) for p in paths}
    missing = set(data.tables_read()) - set(tables)
    if missing:
        raise InputError(f"claims of {slug} read tables that are not inputs of the rule: {sorted(missing)}")
    return {"table": claims_table(data, tables, evidence), "errata": errata_table(data, evidence),
            "reconstructions": reconstructions_table(data, evidence), "findings": findings_table(data, evidence)}
