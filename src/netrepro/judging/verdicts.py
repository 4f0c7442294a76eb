"""The one verdict function every paper uses, and the claims, errata, reconstructions and findings tables.

The paper's side (claims, errata, reconstructions, findings) is loaded and validated by
:mod:`netrepro.judging.paperdata` (issue 15, split out in issue 29). Our side is computed by the paper's
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

Loading and validating the data files is :mod:`netrepro.judging.paperdata`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ConfigError, InputError
from .paperdata import ClaimEntry, FindingEntry, PaperData, load_paper_data, render_statement, template_fields

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
    "AGREES",
    "DISAGREES",
    "UNDECIDED",
    "Cell",
    "compare",
    "agrees",
    "judge",
    "claims_table",
    "errata_table",
    "reconstructions_table",
    "findings_table",
    "compare_observed",
    "undecided_summary",
    "verdicts_step",
]

VERDICTS = ("reproduced", "conditional", "differs", "erratum", "undecided", "not_checkable", "not_identifiable",
            "context")
# the verdicts that score a reproduction (undecided counts against it: a claim we could not decide is not
# reproduced); the other three are kept for transparency only
TESTABLE_VERDICTS = ("reproduced", "conditional", "differs", "erratum", "undecided")
# the verdicts on our own findings: a failing finding stays, shown and counted (issue 37); a retracted one
# stays with its reason; an observation is measured, not judged
FINDING_VERDICTS = ("holds", "conditional", "fails", "undecided", "retracted", "observed")
# the three outcomes of one comparison (a value against an expected value and its tolerance)
AGREES, DISAGREES, UNDECIDED = "agrees", "disagrees", "undecided"
# only errors of substance count as errata in the scorecard; notation and typesetting are listed
SCORED_ERRATUM_KINDS = ("equation", "prose")
CLAIM_COLUMNS = ["paper", "claim_id", "statement", "paper_value", "reproduced_value", "tolerance", "verdict",
                 "note", "tolerance_reason", "location", "condition", "depends_on", "robust", "erratum_id",
                 "group", "test", "uncertainty"]
ERRATA_COLUMNS = ["paper", "erratum_id", "location", "printed", "corrected", "demonstration", "residual_printed",
                  "residual_corrected", "kind", "impact"]
RECONSTRUCTION_COLUMNS = ["paper", "key", "value", "reason", "sensitivity", "range"]
FINDING_COLUMNS = ["paper", "finding_id", "statement", "evidence", "table", "figure", "verdict", "robust", "condition",
                   "rule", "evidence_quantities", "depends_on", "prior_work", "known", "cause_variant", "kind", "control",
                   "amended_rule", "amended_verdict", "amendments", "uncertainty"]
EVIDENCE_COLUMNS = ["quantity", "variant", "value", "note", "uncertainty", "decided"]
# the columns an evidence table must have (uncertainty and decided default to exact and decided)
_REQUIRED_EVIDENCE_COLUMNS = ["quantity", "variant", "value", "note"]
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

    Every row says whether it was decided and how uncertain it is (issue 37): ``uncertainty`` is
    the half-width of an interval that holds the true value (a Monte Carlo confidence half-width
    at the level its test uses, the width of a certified bisection bracket; 0 for an exact
    computation), ``decided`` is False where a certificate is missing (an LMI point the
    certificate leaves undecided, a bracket without both ends certified). :func:`judge` reads
    an undecided row, or one whose interval straddles the tolerance's edge, as ``undecided``.

    Parameters
    ----------
    rows : iterable of dict
        One dict per row with keys ``quantity`` and ``value``, optional ``variant`` (default
        ``"nominal"``), ``note`` (default ``""``), ``uncertainty`` (default 0.0: exact) and
        ``decided`` (default True).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`EVIDENCE_COLUMNS`, rows in the given order.

    Raises
    ------
    ValueError
        For a repeated (quantity, variant) pair, a negative or NaN uncertainty, or a
        ``decided`` that is not a boolean.
    """
    records = []
    for r in rows:
        uncertainty, decided = r.get("uncertainty", 0.0), r.get("decided", True)
        if not isinstance(decided, (bool, np.bool_)):
            raise ValueError(f"evidence {r['quantity']!r}: decided must be True or False, got {decided!r}")
        u = float(uncertainty)
        if math.isnan(u) or u < 0:
            raise ValueError(f"evidence {r['quantity']!r}: uncertainty must be >= 0 (inf: unbounded), got {u!r}")
        records.append({"quantity": r["quantity"], "variant": r.get("variant", NOMINAL), "value": r["value"],
                        "note": r.get("note", ""), "uncertainty": u, "decided": bool(decided)})
    frame = pd.DataFrame(records, columns=EVIDENCE_COLUMNS)
    dup = frame.duplicated(["quantity", "variant"])
    if dup.any():
        raise ValueError(f"repeated evidence rows: {frame.loc[dup, ['quantity', 'variant']].values.tolist()}")
    return frame


class Cell(tuple):
    """One evidence row as ``(value, note)``, with its ``uncertainty`` and whether it was ``decided``.

    A tuple of two, so code that unpacks ``value, note = cell`` keeps working; the verdict reads
    the two attributes.

    Parameters
    ----------
    value : object
        The value (number, boolean or text).
    note : str
        The row's note.
    uncertainty : float
        Half-width of the interval that holds the true value (0: exact).
    decided : bool
        False where a certificate is missing.
    """

    def __new__(cls, value, note="", uncertainty: float = 0.0, decided: bool = True):
        cell = super().__new__(cls, (value, note))
        cell.uncertainty, cell.decided = float(uncertainty), bool(decided)
        return cell

    def __repr__(self) -> str:
        return f"Cell({self[0]!r}, {self[1]!r}, uncertainty={self.uncertainty!r}, decided={self.decided!r})"


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
    """``{quantity: {variant: Cell(value, note)}}`` from an evidence table.

    Parameters
    ----------
    path : str or Path
        An evidence CSV (``results/evidence/<slug>.csv``); every cell is read as text.

    Returns
    -------
    dict
        Quantity -> variant -> :class:`Cell` ``(value, note)`` with its ``uncertainty`` and
        ``decided`` (exact and decided for a table without those columns), the value parsed from
        its text (number, boolean or text); a repeated (quantity, variant) keeps the last row.

    Raises
    ------
    InputError
        If a column of ``quantity, variant, value, note`` is missing, or an uncertainty or
        decided cell cannot be read.
    """
    frame = pd.read_csv(path, dtype=str, keep_default_na=False)
    missing = set(_REQUIRED_EVIDENCE_COLUMNS) - set(frame.columns)
    if missing:
        raise InputError(f"{path}: evidence table lacks columns {sorted(missing)}")
    if "uncertainty" not in frame:
        frame["uncertainty"] = "0"
    if "decided" not in frame:
        frame["decided"] = "True"
    out: dict = {}
    for row in frame.itertuples(index=False):
        decided = _parse(row.decided)
        try:
            uncertainty = float(row.uncertainty or 0.0)
        except ValueError:
            uncertainty = math.nan
        if not isinstance(decided, bool) or math.isnan(uncertainty) or uncertainty < 0:
            raise InputError(f"{path}: evidence row {row.quantity!r} / {row.variant!r}: decided {row.decided!r} "
                             f"must be True or False and uncertainty {row.uncertainty!r} a number >= 0")
        out.setdefault(row.quantity, {})[row.variant] = Cell(_parse(row.value), row.note, uncertainty, decided)
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


def _as_cell(row) -> Cell:
    """An evidence row as a :class:`Cell` (a plain ``(value, note)`` pair is exact and decided)."""
    return row if isinstance(row, Cell) else Cell(row[0], row[1])


def _measured(value) -> tuple:
    """``(value, uncertainty, decided)`` of a plain value or a :class:`Cell`."""
    if isinstance(value, Cell):
        return value[0], value.uncertainty, value.decided
    return value, 0.0, True


def _is_bool(value) -> bool:
    return isinstance(value, (bool, np.bool_))


def compare(entry, value) -> str:
    """One comparison, three outcomes: whether ``value`` agrees with the entry within its tolerance.

    The value's interval ``[value - u, value + u]`` (``u`` its uncertainty, 0 for a plain value)
    is held against the band ``expected +- tolerance``: inside it, ``agrees``; disjoint from it,
    ``disagrees``; straddling its edge, ``undecided`` (so an uncertainty wider than the tolerance
    can never read ``agrees``, and reads ``disagrees`` only when even the nearest end of its
    interval is outside the band).

    Parameters
    ----------
    entry : ClaimEntry or FindingEntry
        A ``numeric`` or ``boolean`` claim (held against the paper's value) or finding (held
        against what it asserts).
    value : float, bool or Cell
        Our value (a :class:`Cell` carries its uncertainty and whether it was decided).

    Returns
    -------
    str
        :data:`AGREES`, :data:`DISAGREES` or :data:`UNDECIDED`: undecided where the row is not
        decided (a missing certificate), a boolean entry's value is not a real boolean (NaN,
        ``"undecided"``, a number), a numeric value is NaN or not a number, or the interval
        straddles the band's edge.
    """
    value, uncertainty, decided = _measured(value)
    if not decided:
        return UNDECIDED
    if entry.kind == "boolean":
        if not _is_bool(value):
            return UNDECIDED
        return AGREES if bool(value) == bool(entry.expected) else DISAGREES
    if _is_bool(value) or not isinstance(value, (int, float, np.integer, np.floating)):
        return UNDECIDED
    ours, expected = float(value), float(entry.expected)
    if math.isnan(ours) or math.isnan(uncertainty):
        return UNDECIDED
    scale = abs(expected) if entry.relative else 1.0
    band = entry.tolerance * scale
    if math.isinf(ours):
        return UNDECIDED if math.isinf(uncertainty) else DISAGREES
    # expected values and tolerances are decimals that binary floats hold only to an ulp: the edge
    # |ours - expected| == tolerance must not depend on which way the subtraction rounds
    band += 8 * _EPS * max(abs(ours), abs(expected), band)
    distance = abs(ours - expected)
    if distance + uncertainty <= band:
        return AGREES
    if distance - uncertainty > band:
        return DISAGREES
    return UNDECIDED


def agrees(entry, value) -> bool:
    """Whether ``value`` surely agrees with the entry: :func:`compare` reads ``agrees``.

    Parameters
    ----------
    entry : ClaimEntry or FindingEntry
        A ``numeric`` or ``boolean`` claim or finding.
    value : float, bool or Cell
        Our value.

    Returns
    -------
    bool
        True only for a decided agreement (undecided and disagreeing values give False).
    """
    return compare(entry, value) == AGREES


def judge(entry, value=None, variants: dict | None = None) -> Judgement:
    """The verdict on a claim or a finding: one function for every paper.

    Parameters
    ----------
    entry : ClaimEntry or FindingEntry
        The paper's side of a claim, or our finding.
    value : float, bool or Cell, optional
        Our value at the configured (nominal) settings; unused for untestable kinds.
    variants : dict, optional
        ``{label: value}``: our value across variants. Only the labels ``<key>=...`` or
        ``<key>: ...`` with ``<key>`` in ``entry.depends_on`` decide (:func:`split_variants`,
        e.g. ``{"horizon=200": 0.8, "horizon=800": 1.2}``); the others are re-readings, returned
        in ``readings`` and judged nowhere.

    Returns
    -------
    Judgement
        Claims: ``not_checkable`` / ``not_identifiable`` / ``context`` for those kinds; otherwise,
        each setting (nominal and every declared variant) compared by :func:`compare`:
        ``conditional`` when ours agrees at some settings and disagrees at others (the condition
        lists where it holds); else ``undecided`` when any setting is undecided (the verdict
        would depend on it); else ``reproduced`` when it agrees everywhere, ``erratum`` when it
        disagrees everywhere and the entry names an erratum, ``differs`` otherwise. Findings:
        ``holds``, ``conditional``, ``undecided`` or ``fails``, likewise. ``robust`` is ``yes``
        when every decided variant reads as the nominal and none is undecided, ``no`` when one
        reads otherwise, ``undecided`` when one is undecided and none reads otherwise.
    """
    finding = isinstance(entry, FindingEntry)
    if not finding and entry.kind in _UNTESTABLE_KIND_VERDICT:
        return Judgement(_UNTESTABLE_KIND_VERDICT[entry.kind], "", "")
    declared, readings = split_variants(entry.depends_on, variants)
    nominal = compare(entry, value)
    outcomes = {label: compare(entry, v) for label, v in declared.items()}
    robust = _robust(nominal, outcomes)
    nominal_label = entry.nominal or "nominal settings"
    settings = [(nominal_label, nominal), *outcomes.items()]
    holds = [label for label, o in settings if o == AGREES]
    fails = [label for label, o in settings if o == DISAGREES]
    unknown = [label for label, o in settings if o == UNDECIDED]
    if holds and fails:
        condition = _condition_text(holds, fails)
        if unknown:
            condition += f"; undecided at {_side(unknown)}"
        return Judgement("conditional", robust, condition, tuple(readings))
    if unknown:
        return Judgement(UNDECIDED, robust, f"undecided at {_side(unknown)}", tuple(readings))
    if holds:
        return Judgement("holds" if finding else "reproduced", robust, "", tuple(readings))
    if finding:
        return Judgement("fails", robust, "", tuple(readings))
    if entry.erratum_id:
        return Judgement("erratum", robust, "", tuple(readings))
    return Judgement("differs", robust, "", tuple(readings))


def _robust(nominal: str, outcomes: dict) -> str:
    """``yes`` / ``no`` / ``undecided`` / ``""`` (no declared variant) for the robust column."""
    if not outcomes:
        return ""
    decided = [o for o in outcomes.values() if o != UNDECIDED]
    if nominal != UNDECIDED and any(o != nominal for o in decided):
        return "no"
    if nominal == UNDECIDED and AGREES in decided and DISAGREES in decided:
        return "no"
    return UNDECIDED if (nominal == UNDECIDED or len(decided) < len(outcomes)) else "yes"


_LISTED = 6  # settings named in a condition on each side; the note lists every setting with its value


def _side(labels: list) -> str:
    """Settings named in a condition; long lists are counted, not spelled out."""
    if len(labels) <= _LISTED:
        return "; ".join(labels)
    return "; ".join(labels[:_LISTED]) + f"; and {len(labels) - _LISTED} more (the note lists them)"


def _condition_text(holds: list, fails: list) -> str:
    """Where a conditional claim holds and where not."""
    total = len(holds) + len(fails)
    head = f"holds at {len(holds)} of {total} settings: " if total > 2 * _LISTED else "holds for "
    return f"{head}{_side(holds)}; not for {_side(fails)}"


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
        return _as_cell(rows[NOMINAL]), rows[NOMINAL][1], {label: _as_cell(v) for label, v in rows.items()
                                                           if label != NOMINAL}
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
            f"{label}: {_fmt_cell(v)} ({_outcome_word(entry, v, outcome_words)})" for label, v in readings.items()))
    return "; ".join(parts)


def _outcome_word(entry, value, outcome_words: tuple) -> str:
    if getattr(entry, "observation", False):
        return "measured" if compare_observed(value) else UNDECIDED
    yes, no = outcome_words
    return {AGREES: yes, DISAGREES: no, UNDECIDED: UNDECIDED}[compare(entry, value)]


def _bare(value):
    """The value of a :class:`Cell`, or the value itself."""
    return value[0] if isinstance(value, Cell) else value


def _uncertainty_text(value) -> str:
    """The uncertainty column: ``""`` for an exact decided value, else its half-width or ``undecided``."""
    if not isinstance(value, Cell) or (value.decided and value.uncertainty == 0):
        return ""
    return f"{value.uncertainty:.3g}" if value.decided else UNDECIDED


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
            "reproduced_value": _plain(_bare(value)) if value is not None else "",
            "tolerance": _fmt_tolerance(entry),
            "verdict": result.verdict, "note": "; ".join(x for x in (entry.note, ev_note) if x),
            "tolerance_reason": entry.tolerance_reason, "location": entry.location_text,
            "condition": result.condition, "depends_on": ", ".join(entry.depends_on), "robust": result.robust,
            "erratum_id": entry.erratum_id if result.verdict == "erratum" else "", "group": entry.group,
            "test": entry.test, "uncertainty": _uncertainty_text(value),
        })
    _raise_undeclared(problems)
    frame = pd.DataFrame(rows, columns=CLAIM_COLUMNS)
    assert set(frame["verdict"]) <= set(VERDICTS)
    return frame


def _fmt_cell(value) -> str:
    """A value for a note; a :class:`Cell` with its uncertainty, or marked undecided."""
    if isinstance(value, Cell):
        text = _fmt_cell(value[0])
        if value.uncertainty > 0:
            text += f" +- {value.uncertainty:.3g}"
        return text if value.decided else f"{text} (undecided)"
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
    if entry.observation:
        return "observation: measured, not judged"
    if entry.kind == "boolean":
        text = f"{str(entry.asserted).lower()}, exact: {entry.rule_reason}"
    else:
        within = f"{entry.tolerance:.15g}" + (" (relative)" if entry.relative else "")
        text = f"{entry.asserted:.15g} within {within}: {entry.rule_reason}"
    if entry.source:
        text += f" [threshold from {entry.source['kind'].replace('_', ' ')}: {entry.source['ref']}]"
    if entry.test:
        text += " [test: " + ", ".join(f"{k} {v}" for k, v in entry.test.items()) + "]"
    return text


def _names_evidence(cause: str, evidence: dict, rows_q: dict) -> bool:
    """Whether ``cause`` names an evidence quantity, a variant of the judged quantity, or ``<quantity>: <variant>``."""
    if cause in evidence or cause in rows_q:
        return True
    quantity, sep, variant = cause.partition(": ")
    return bool(sep) and variant in evidence.get(quantity, {})


def _judge_finding(f: FindingEntry, evidence: dict, slug: str) -> tuple:
    """(Judgement, nominal Cell, note, variants) of one finding's rule on its evidence quantity."""
    rows_q = _evidence_rows("finding", slug, f.finding_id, evidence, f.quantity)
    value = _as_cell(rows_q[NOMINAL])
    variants = {label: _as_cell(v) for label, v in rows_q.items() if label != NOMINAL}
    if f.observation:
        decided = compare_observed(value)
        return Judgement("observed" if decided else UNDECIDED, "", "" if decided else "its evidence is not decided"), \
            value, value[1], variants
    return judge(f, value, variants), value, value[1], variants


def _noted(f: FindingEntry) -> FindingEntry:
    """The rule whose outcomes the note gives for the variants: the registered one of an amended observation."""
    return f.registered_rule if (f.observation and f.amendments) else f


def compare_observed(value) -> bool:
    """Whether an observation's value is decided: a decided row with a real value (not NaN or empty).

    Parameters
    ----------
    value : Cell or object
        The observation's nominal evidence row.

    Returns
    -------
    bool
        True when the measurement stands.
    """
    bare, _, decided = _measured(value)
    if not decided or bare is None or (isinstance(bare, str) and bare.strip().lower() in ("", "nan", UNDECIDED)):
        return False
    return not (isinstance(bare, float) and math.isnan(bare))


def _statement(f: FindingEntry, evidence: dict, slug: str) -> str:
    """The finding's statement with its template fields filled from the evidence.

    Typed numbers that equal one of its evidence values are refused by ``check-paper`` (lint), on the configured
    scale's evidence, not here: at another scale a typed setting ("lambda_c + 0.1") may round to a result by
    coincidence, and a heuristic must not stop a build.

    A template may name any quantity of the evidence table (the statement's numbers are text, not the rule:
    the registered ``evidence_quantities`` are what the verdict rests on).
    """
    named = list(dict.fromkeys([*f.evidence_quantities, *(q for q, _, _ in template_fields(f.statement))]))
    missing = [q for q in named[len(f.evidence_quantities):] if NOMINAL not in evidence.get(q, {})]
    if missing:
        raise InputError(f"finding {slug}/{f.finding_id}: the statement fills {missing} from the evidence, which has "
                         f"no nominal row of them (results/evidence/{slug}.csv)")
    cells = {q: _as_cell(evidence[q][NOMINAL]) for q in named if q in evidence and NOMINAL in evidence[q]}
    return " ".join(render_statement(f.statement, cells).split())


def findings_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/findings/<slug>.csv``: our findings, judged by :func:`judge` like claims.

    A finding whose registered rule was amended (``amendments``) is judged twice: ``verdict`` and
    ``rule`` are the registered rule's, ``amended_verdict`` and ``amended_rule`` the current one's
    (issue 37). A retracted finding keeps its row, with verdict ``retracted`` and the verdict its
    rule gives in ``condition``; an observation reads ``observed`` (or ``undecided``).

    Parameters
    ----------
    data : PaperData
        The paper's data files.
    evidence : dict
        From :func:`read_evidence`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`FINDING_COLUMNS`: the verdict (:data:`FINDING_VERDICTS`), ``robust`` and the
        condition; the statement with its numbers filled from the evidence; the evidence text holds
        the judged quantity's value and note, the declared variants, the re-readings and the other
        evidence quantities' values.

    Raises
    ------
    InputError
        Naming the finding and the quantity, when a quantity it rests on (``quantity``,
        ``evidence_quantities``) or its cause variant is not in the evidence table, when it
        depends on a reconstruction and has no variant across its declared range, or when its
        statement prints a quantity the evidence table lacks.
    """
    rows, problems = [], []
    for f in data.findings:
        for name in f.evidence_quantities + tuple(q for a in f.amendments for q in a.rule.evidence_quantities):
            if name not in evidence:
                raise InputError(f"finding {data.slug}/{f.finding_id}: evidence quantity {name!r} is not in "
                                 f"results/evidence/{data.slug}.csv (the paper's evidence step must produce it)")
        rows_q = _evidence_rows("finding", data.slug, f.finding_id, evidence, f.quantity)
        cause = f.cause.get("variant", "")
        if cause and not _names_evidence(cause, evidence, rows_q):
            raise InputError(f"finding {data.slug}/{f.finding_id}: cause variant {cause!r} is neither an evidence "
                             f"quantity nor a variant of {f.quantity!r} (nor '<quantity>: <variant>' of the evidence "
                             "table)")
        result, value, note, variants = _judge_finding(f, evidence, data.slug)
        problems.append(_undeclared("finding", data.slug, f.finding_id, f.depends_on, variants))
        amended_rule = amended_verdict = history = ""
        rule_text = _fmt_rule(f)
        if f.amendments:
            registered, _, _, _ = _judge_finding(f.registered_rule, evidence, data.slug)
            amended_rule, amended_verdict = rule_text, result.verdict
            rule_text = _fmt_rule(f.registered_rule)
            history = " | ".join(f"{a.when}: {a.why}" for a in f.amendments)
            result = registered
        condition = result.condition
        verdict = result.verdict
        if f.retracted:
            condition = "; ".join(x for x in (f"retracted {f.retracted['when']}: {f.retracted['reason']}",
                                              f"its rule reads {verdict}", condition) if x)
            verdict = "retracted"
        others = "; ".join(f"{q}: {_fmt_cell(_as_cell(evidence[q].get(NOMINAL, ('', ''))))}"
                           for q in f.evidence_quantities[1:])
        shown = _fmt_cell(value) if _bare(value) != "" else ""
        text = "; ".join(x for x in (f.evidence, shown, note, _variants_note(_noted(f), variants, ("holds", "fails")),
                                     f"also rests on {others}" if others else "") if x)
        control = f.cause.get("control", {})
        rows.append({"paper": data.slug, "finding_id": f.finding_id, "statement": _statement(f, evidence, data.slug),
                     "evidence": text, "table": f.table, "figure": f.figure, "verdict": verdict,
                     "robust": result.robust, "condition": condition, "rule": rule_text,
                     "evidence_quantities": ", ".join(f.evidence_quantities), "depends_on": ", ".join(f.depends_on),
                     "prior_work": f.prior_work, "known": "yes" if f.known else "no", "cause_variant": cause,
                     "kind": "observation" if f.observation else ("causal" if f.asserts_cause else "finding"),
                     "control": (f"holds fixed {control['holds_fixed']}; changes {control['changes']}"
                                 if control else ""),
                     "amended_rule": amended_rule, "amended_verdict": amended_verdict, "amendments": history,
                     "uncertainty": _uncertainty_text(value)})
    _raise_undeclared(problems)
    frame = pd.DataFrame(rows, columns=FINDING_COLUMNS)
    assert set(frame["verdict"]) <= set(FINDING_VERDICTS)
    return frame


def undecided_summary(results: str | Path = "results") -> str:
    """One line naming every claim and finding of the built tables whose verdict is undecided ("" if none).

    The workflow prints it when a run ends (``onsuccess``), so a build whose solver or sampling
    could not decide a verdict says so on the console, not only in the tables (issue 37).

    Parameters
    ----------
    results : str or Path
        The results folder (``results/claims/*.csv``, ``results/findings/*.csv``).

    Returns
    -------
    str
        ``"N verdicts undecided: slug/id, ..."``, or ``""``.
    """
    results = Path(results)
    names = []
    for kind, ident in (("claims", "claim_id"), ("findings", "finding_id")):
        for path in sorted((results / kind).glob("*.csv")):
            frame = pd.read_csv(path, dtype=str, keep_default_na=False)
            columns = [c for c in ("verdict", "amended_verdict") if c in frame]
            hit = frame[columns].eq(UNDECIDED).any(axis=1) if columns else pd.Series(False, index=frame.index)
            names += [f"{path.stem}/{i}" for i in frame.loc[hit, ident]] if ident in frame else []
    if not names:
        return ""
    return (f"{len(names)} verdicts undecided (a certificate is missing or an uncertainty exceeds its tolerance; "
            f"the claims and findings tables say where): {', '.join(names)}")


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
    claims, findings = claims_table(data, tables, evidence), findings_table(data, evidence)
    _warn_undecided(slug, claims, findings)
    return {"table": claims, "errata": errata_table(data, evidence),
            "reconstructions": reconstructions_table(data, evidence), "findings": findings}


def _warn_undecided(slug: str, claims: pd.DataFrame, findings: pd.DataFrame) -> None:
    """One warning (shown on the console) naming every claim and finding the evidence left undecided."""
    import warnings

    names = [f"claim {c}" for c in claims.loc[claims["verdict"] == UNDECIDED, "claim_id"]]
    names += [f"finding {f}" for f in findings.loc[(findings["verdict"] == UNDECIDED)
                                                   | (findings["amended_verdict"] == UNDECIDED), "finding_id"]]
    if names:
        warnings.warn(f"{slug}: {len(names)} verdicts undecided (a certificate is missing or an uncertainty exceeds "
                      f"its tolerance; the tables say where): {', '.join(names)}", UserWarning, stacklevel=2)
