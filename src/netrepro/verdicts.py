"""Claims as data, and the one verdict function every paper uses (issue 15).

Per paper, four data files beside its code hold the paper's side of the reproduction, each
validated against a JSON schema in ``workflow/schemas/paper/`` before any job starts:

``claims.yaml``
    id, location in the paper, group (of the replication summary), the quoted statement, kind
    (``numeric | boolean | not_checkable | not_identifiable | context``), the paper's value,
    the tolerance and its reason (fixed before and independently of our value), the quantity of
    ours it is compared with, what it depends on (reconstruction keys) and, for a statement
    the text gets wrong, the erratum that explains it::

        - id: C2
          location: {section: "3.1", figure: "1"}
          group: Fig 1
          statement: "s_k converges to approximately 0.4"
          kind: numeric
          paper_value: 0.4
          tolerance: {value: 0.05, reason: "'approximately', one significant digit: half a unit of it"}
          ours: {quantity: s_limit}           # or {table: results/..., column: x, where: {k: 60}}
          depends_on: [horizon]

``errata.yaml``
    id, location, kind (``equation | prose | notation | typesetting``), printed, corrected, impact.
``reconstructions.yaml``
    key, reason, range (over which dependent claims are re-judged), optional value/sensitivity.
``findings.yaml``
    id, statement, the table (and figure) that shows it, the evidence quantity.

Our side is computed by the paper's evidence step into ``results/evidence/<slug>.csv``
(columns ``quantity, variant, value, note``): one ``nominal`` row per quantity at the
configured settings, and one row per variant across the range of the reconstructions the
claim depends on. By convention, quantity ``<erratum id>.residual_printed`` /
``.residual_corrected`` give an erratum's residuals (the note of the first is its
demonstration), and ``reconstruction.<key>`` gives a reconstruction's value (its note is the
sensitivity). Nothing in Python holds a paper value, a statement or a tolerance.

:func:`judge` decides a verdict from an entry, our nominal value and our values across the
variants: a verdict that changes inside that range is ``conditional``, with the condition
stated, and ``robust`` is ``no``. :func:`verdicts_step` writes the claims, errata,
reconstructions and findings tables of one paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import yaml

from .errors import ConfigError, InputError
from .io import load_yaml

__all__ = [
    "VERDICTS",
    "TESTABLE_VERDICTS",
    "KINDS",
    "ERRATUM_KINDS",
    "SCORED_ERRATUM_KINDS",
    "CLAIM_COLUMNS",
    "ERRATA_COLUMNS",
    "RECONSTRUCTION_COLUMNS",
    "FINDING_COLUMNS",
    "EVIDENCE_COLUMNS",
    "ClaimEntry",
    "Judgement",
    "PaperData",
    "load_claims",
    "load_paper_data",
    "paper_dir",
    "referenced_tables",
    "read_evidence",
    "evidence_frame",
    "erratum_evidence",
    "lookup",
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
KINDS = ("numeric", "boolean", "not_checkable", "not_identifiable", "context")
ERRATUM_KINDS = ("equation", "prose", "notation", "typesetting")
# only errors of substance count as errata in the scorecard; notation and typesetting are listed
SCORED_ERRATUM_KINDS = ("equation", "prose")
CLAIM_COLUMNS = ["paper", "claim_id", "statement", "paper_value", "reproduced_value", "tolerance", "verdict",
                 "note", "tolerance_reason", "location", "condition", "depends_on", "robust", "erratum_id",
                 "group", "test"]
ERRATA_COLUMNS = ["paper", "erratum_id", "location", "printed", "corrected", "demonstration", "residual_printed",
                  "residual_corrected", "kind", "impact"]
RECONSTRUCTION_COLUMNS = ["paper", "key", "value", "reason", "sensitivity", "range"]
FINDING_COLUMNS = ["paper", "finding_id", "statement", "evidence", "table", "figure"]
EVIDENCE_COLUMNS = ["quantity", "variant", "value", "note"]
NOMINAL = "nominal"
_UNTESTABLE_KIND_VERDICT = {"not_checkable": "not_checkable", "not_identifiable": "not_identifiable",
                            "context": "context"}
_EPS = 2.0 ** -52
_SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas" / "paper"
_PAPERS_DIR = Path(__file__).resolve().parent / "papers"
DATA_FILES = ("claims", "errata", "reconstructions", "findings")


@dataclass(frozen=True)
class ClaimEntry:
    """One claim of a paper, as its data file states it.

    Attributes
    ----------
    claim_id : str
        Identifier, unique within the paper.
    location : dict
        Where the paper states it (``section``, ``equation``, ``figure``, ``page``, ...).
    statement : str
        The paper's statement, quoted.
    kind : str
        One of :data:`KINDS`.
    paper_value : float, bool or None
        The paper's value (None for untestable kinds).
    tolerance : float
        Absolute, or relative to ``|paper_value|`` when ``relative``.
    relative : bool
        Whether ``tolerance`` is relative.
    tolerance_reason : str
        Why this tolerance (or decision rule), fixed before and independently of our value.
    ours : dict
        Where our value comes from: ``{quantity}`` (the evidence table) or ``{table, column, where}``.
    depends_on : tuple of str
        Reconstruction keys the value depends on.
    erratum_id : str
        The erratum that explains a disagreement, if any.
    group : str
        The claim group of the replication summary.
    test : str
        For statistical verdicts: the test, its sample size and significance level.
    nominal : str
        The setting of the nominal value, as named in a condition.
    at : dict
        The paper's settings of the claim (e.g. ``{"p": 0.04, "q": 0.65}``), read by the evidence step.
    """

    claim_id: str
    location: dict
    statement: str
    kind: str
    paper_value: object = None
    tolerance: float = 0.0
    relative: bool = False
    tolerance_reason: str = ""
    ours: dict = field(default_factory=dict)
    depends_on: tuple = ()
    erratum_id: str = ""
    note: str = ""
    group: str = ""
    test: str = ""
    nominal: str = ""
    at: dict = field(default_factory=dict)

    @property
    def location_text(self) -> str:
        return ", ".join(f"{k} {v}" for k, v in self.location.items())


@dataclass(frozen=True)
class Judgement:
    """The verdict on one claim.

    Attributes
    ----------
    verdict : str
        One of :data:`VERDICTS`.
    robust : str
        ``yes`` when the verdict holds across every variant, ``no`` when it changes, ``""`` when
        the claim depends on nothing that could be varied.
    condition : str
        For ``conditional``: where the claim holds and where it does not.
    """

    verdict: str
    robust: str
    condition: str


@dataclass(frozen=True)
class PaperData:
    """The four data files of one paper, validated and cross-checked."""

    slug: str
    claims: list
    errata: list
    reconstructions: list
    findings: list


def paper_dir(slug: str) -> Path:
    return _PAPERS_DIR / slug


def _read_yaml_list(path: Path) -> list:
    try:
        data = load_yaml(path.read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML: {exc}") from None
    return [] if data is None else data


def _schema_errors(path: Path, kind: str, data) -> None:
    """Raise a ConfigError naming file, entry and field for the first schema violations."""
    import jsonschema

    schema = load_yaml((_SCHEMA_DIR / f"{kind}.schema.yaml").read_text())
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if not errors:
        return
    lines = []
    for err in errors[:5]:
        parts = list(err.absolute_path)
        if not parts:
            lines.append(f"{path}: {err.message} (expected a list of entries)")
            continue
        index, fields = parts[0], [str(p) for p in parts[1:]]
        entry = data[index] if isinstance(data, list) and isinstance(index, int) else None
        ident = entry.get("id", entry.get("key", "?")) if isinstance(entry, dict) else "?"
        if err.validator == "required":
            missing = err.message.split("'")[1] if err.message.count("'") >= 2 else "?"
            fields, message = fields + [missing], "is required"
        elif err.validator == "additionalProperties":
            extra = sorted(set(err.instance) - set(err.schema.get("properties", {})))
            fields, message = fields + [",".join(extra)], "is not a known field (a typo?)"
        else:
            message = err.message
        lines.append(f"{path}: entry {index} (id {ident!r}): field {'.'.join(fields) or '<entry>'!r} {message}")
    raise ConfigError("\n  ".join(lines))


def _problem(path: Path, where: str, field_name: str, what: str) -> ConfigError:
    return ConfigError(f"{path}: {where}: field {field_name!r} {what}")


def _entry(path: Path, index: int, raw) -> ClaimEntry:
    where = f"entry {index} (id {raw.get('id', '?')!r})"
    kind = raw["kind"]
    tol = raw.get("tolerance")
    if kind in ("numeric", "boolean"):
        if "paper_value" not in raw:
            raise _problem(path, where, "paper_value", f"is required for kind {kind!r}")
        ours = raw.get("ours")
        if not isinstance(ours, dict) or not (ours.get("quantity") or (ours.get("table") and ours.get("column"))):
            raise _problem(path, where, "ours", "must name an evidence quantity, or a table and column")
        if not isinstance(tol, dict) or not str(tol.get("reason", "")).strip():
            raise _problem(path, where, "tolerance.reason", "is required: why this tolerance, fixed in advance")
    if kind == "numeric":
        if not isinstance(tol.get("value"), (int, float)):
            raise _problem(path, where, "tolerance.value", "is required for kind 'numeric'")
        if not isinstance(raw["paper_value"], (int, float)) or isinstance(raw["paper_value"], bool):
            raise _problem(path, where, "paper_value", "must be a number for kind 'numeric'")
    if kind == "boolean" and not isinstance(raw["paper_value"], bool):
        raise _problem(path, where, "paper_value", "must be true or false for kind 'boolean'")
    tol = tol if isinstance(tol, dict) else {}
    return ClaimEntry(
        claim_id=str(raw["id"]), location=dict(raw["location"]), statement=str(raw["statement"]).strip(), kind=kind,
        paper_value=raw.get("paper_value"), tolerance=float(tol.get("value", 0.0)),
        relative=bool(tol.get("relative", False)), tolerance_reason=str(tol.get("reason", "")).strip(),
        ours=dict(raw.get("ours", {})), depends_on=tuple(raw.get("depends_on", ())),
        erratum_id=str(raw.get("erratum_id", "")), note=str(raw.get("note", "")).strip(),
        group=str(raw.get("group", "")), test=str(raw.get("test", "")).strip(), nominal=str(raw.get("nominal", "")),
        at=dict(raw.get("at") or {}))


def _unique(path: Path, ids) -> None:
    seen = set()
    for ident in ids:
        if ident in seen:
            raise ConfigError(f"{path}: duplicate id {ident!r}")
        seen.add(ident)


def load_claims(path: str | Path) -> list[ClaimEntry]:
    """Read and validate a paper's ``claims.yaml``.

    Parameters
    ----------
    path : str or Path
        The data file.

    Returns
    -------
    list of ClaimEntry
        In file order.

    Raises
    ------
    ConfigError
        Naming the file, the entry (index and id) and the field, for a malformed file.
    """
    path = Path(path)
    data = _read_yaml_list(path)
    _schema_errors(path, "claims", data)
    entries = [_entry(path, i, raw) for i, raw in enumerate(data)]
    _unique(path, [e.claim_id for e in entries])
    return entries


def _load_list(path: Path, kind: str) -> list[dict]:
    if not path.is_file():
        return []
    data = _read_yaml_list(path)
    _schema_errors(path, kind, data)
    _unique(path, [d.get("id", d.get("key")) for d in data])
    return data


def load_paper_data(slug: str, root: str | Path | None = None) -> PaperData:
    """Read, validate and cross-check the data files of one paper.

    Parameters
    ----------
    slug : str
        The paper.
    root : str or Path, optional
        The directory holding the files (default: the paper's package).

    Raises
    ------
    ConfigError
        For a malformed file, a ``depends_on`` that names no reconstruction, or an
        ``erratum_id`` that names no erratum.
    """
    root = Path(root) if root is not None else paper_dir(slug)
    claims_path = root / "claims.yaml"
    claims = load_claims(claims_path)
    errata = _load_list(root / "errata.yaml", "errata")
    reconstructions = _load_list(root / "reconstructions.yaml", "reconstructions")
    findings = _load_list(root / "findings.yaml", "findings")
    keys = {r["key"] for r in reconstructions}
    errata_ids = {e["id"] for e in errata}
    for i, entry in enumerate(claims):
        where = f"entry {i} (id {entry.claim_id!r})"
        for dep in entry.depends_on:
            if dep not in keys:
                raise _problem(claims_path, where, "depends_on",
                               f"names {dep!r}, which is not a key of {root / 'reconstructions.yaml'}")
        if entry.erratum_id and entry.erratum_id not in errata_ids:
            raise _problem(claims_path, where, "erratum_id", f"names {entry.erratum_id!r}, which is not in errata.yaml")
    return PaperData(slug, claims, errata, reconstructions, findings)


def referenced_tables(slug: str, root: str | Path | None = None) -> list[str]:
    """The result tables (other than the evidence table) that the paper's claims read."""
    return _tables_read(load_paper_data(slug, root))


def _tables_read(data: PaperData) -> list[str]:
    return sorted({e.ours["table"] for e in data.claims if e.ours.get("table")})


def evidence_frame(rows) -> pd.DataFrame:
    """The evidence table of a paper from ``dict(quantity, value, note='', variant='nominal')`` rows.

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
    """A cell of the evidence table: booleans and numbers back from their text."""
    if isinstance(value, (bool, int, float)) and not isinstance(value, str):
        return value
    text = str(value).strip()
    if text in ("True", "False"):
        return text == "True"
    try:
        return float(text)
    except ValueError:
        return text


def read_evidence(path: str | Path) -> dict:
    """``{quantity: {variant: (value, note)}}`` from an evidence table."""
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


def agrees(entry: ClaimEntry, value) -> bool:
    """Whether ``value`` agrees with the paper's value within the entry's pre-set tolerance.

    Parameters
    ----------
    entry : ClaimEntry
        A ``numeric`` or ``boolean`` claim.
    value : float or bool
        Our value.

    Returns
    -------
    bool
        For booleans, equality; for numbers, ``|ours - paper| <= tolerance`` (times ``|paper|`` if
        relative), with NaN or infinite values never agreeing.
    """
    if entry.kind == "boolean":
        return bool(value) == bool(entry.paper_value)
    ours, paper = float(value), float(entry.paper_value)
    scale = abs(paper) if entry.relative else 1.0
    # paper values and tolerances are decimals that binary floats hold only to an ulp: the edge
    # |ours - paper| == tolerance must not depend on which way the subtraction rounds
    slack = 8 * _EPS * max(abs(ours), abs(paper), entry.tolerance * scale)
    return math.isfinite(ours) and abs(ours - paper) <= entry.tolerance * scale + slack


def judge(entry: ClaimEntry, value=None, variants: dict | None = None) -> Judgement:
    """The verdict on a claim: one function for every paper.

    Parameters
    ----------
    entry : ClaimEntry
        The paper's side of the claim.
    value : float or bool, optional
        Our value at the configured (nominal) settings; unused for untestable kinds.
    variants : dict, optional
        ``{label: value}``: our value across the range of the reconstructions and settings the
        claim depends on (e.g. ``{"horizon=200": 0.8, "horizon=800": 1.2}``).

    Returns
    -------
    Judgement
        ``not_checkable`` / ``not_identifiable`` / ``context`` for those kinds; otherwise
        ``reproduced`` when ours agrees at the nominal settings and at every variant;
        ``conditional`` when it agrees at some but not all (the condition lists where it holds);
        ``erratum`` when it disagrees everywhere and the entry names an erratum; else ``differs``.
    """
    if entry.kind in _UNTESTABLE_KIND_VERDICT:
        return Judgement(_UNTESTABLE_KIND_VERDICT[entry.kind], "", "")
    nominal = agrees(entry, value)
    outcomes = {label: agrees(entry, v) for label, v in (variants or {}).items()}
    robust = "" if not outcomes else ("yes" if all(o == nominal for o in outcomes.values()) else "no")
    if nominal and robust != "no":
        return Judgement("reproduced", robust, "")
    nominal_label = entry.nominal or "nominal settings"
    holds = ([nominal_label] if nominal else []) + [label for label, ok in outcomes.items() if ok]
    fails = ([] if nominal else [nominal_label]) + [label for label, ok in outcomes.items() if not ok]
    if holds:
        return Judgement("conditional", robust, _condition_text(holds, fails))
    if entry.erratum_id:
        return Judgement("erratum", robust, "")
    return Judgement("differs", robust, "")


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


def _our_value(entry: ClaimEntry, tables: dict, evidence: dict, slug: str):
    """(nominal value, note, {variant label: value}) of a testable claim."""
    ours = entry.ours
    if ours.get("quantity"):
        name = ours["quantity"]
        if name not in evidence:
            raise InputError(f"claim {slug}/{entry.claim_id}: quantity {name!r} is not in results/evidence/{slug}.csv "
                             "(the paper's evidence step must produce it)")
        rows = evidence[name]
        if NOMINAL not in rows:
            raise InputError(f"claim {slug}/{entry.claim_id}: quantity {name!r} has no {NOMINAL!r} row")
        value, note = rows[NOMINAL]
        return value, note, {label: v for label, (v, _) in rows.items() if label != NOMINAL}
    value = lookup(ours, tables)
    variants = {label: lookup(dict(ours, where={**(ours.get("where") or {}), **override}), tables)
                for label, override in (ours.get("variants") or {}).items()}
    return value, "", variants


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

    Raises
    ------
    InputError
        When a claim that depends on a reconstruction has no variants to be re-judged on, or
        names a quantity the evidence step did not produce.
    """
    rows = []
    for entry in data.claims:
        value, ev_note, variants = (None, "", {})
        if entry.kind in ("numeric", "boolean"):
            value, ev_note, variants = _our_value(entry, tables, evidence, data.slug)
            if entry.depends_on and not variants:
                raise InputError(f"claim {data.slug}/{entry.claim_id} depends on {list(entry.depends_on)} but has no "
                                 "variants: re-judge it across their range (evidence rows or ours.variants)")
        elif entry.ours.get("quantity") in evidence:
            ev_note = evidence[entry.ours["quantity"]].get(NOMINAL, (None, ""))[1]
        result = judge(entry, value, variants)
        if variants:
            shown = "; ".join(f"{label}: {_fmt_cell(v)}" for label, v in variants.items())
            ev_note = "; ".join(x for x in (ev_note, f"across the range: {shown}") if x)
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
    frame = pd.DataFrame(rows, columns=CLAIM_COLUMNS)
    assert set(frame["verdict"]) <= set(VERDICTS)
    return frame


def _fmt_cell(value) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return f"{value:.6g}"


def errata_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/errata/<slug>.csv``; residuals from the evidence quantities ``<id>.residual_*``."""
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
    """Table ``results/reconstructions/<slug>.csv``; value and sensitivity from ``reconstruction.<key>``."""
    rows = []
    for r in data.reconstructions:
        value, sensitivity = evidence.get(f"reconstruction.{r['key']}", {}).get(NOMINAL, (None, ""))
        if value is None or value == "":
            value = r.get("value", "")
        sensitivity = "; ".join(x for x in (str(r.get("sensitivity", "")).strip(), sensitivity) if x)
        rows.append({"paper": data.slug, "key": r["key"], "value": value, "reason": r["reason"].strip(),
                     "sensitivity": sensitivity, "range": str(r.get("range", "")).strip()})
    return pd.DataFrame(rows, columns=RECONSTRUCTION_COLUMNS)


def findings_table(data: PaperData, evidence: dict) -> pd.DataFrame:
    """Table ``results/findings/<slug>.csv``: our discoveries, with their evidence."""
    rows = []
    for f in data.findings:
        text = str(f.get("evidence", "")).strip()
        if f.get("quantity"):
            if f["quantity"] not in evidence:
                raise InputError(f"finding {data.slug}/{f['id']}: quantity {f['quantity']!r} is not in the evidence table")
            value, note = evidence[f["quantity"]][NOMINAL]
            text = "; ".join(x for x in (text, f"{_fmt_cell(value)}" if value != "" else "", note) if x)
        rows.append({"paper": data.slug, "finding_id": f["id"], "statement": f["statement"].strip(), "evidence": text,
                     "table": f["table"], "figure": f.get("figure", "")})
    return pd.DataFrame(rows, columns=FINDING_COLUMNS)


def verdicts_step(params, inputs, outputs):
    """Step of rule ``<slug>_claims``: the claims, errata, reconstructions and findings tables.

    ``params``: ``{"slug": ...}``; ``inputs``: ``evidence`` (the paper's evidence table),
    ``tables`` (the result tables its claims read) and the data files; outputs ``table``
    (claims), ``errata``, ``reconstructions``, ``findings``.
    """
    slug = params["slug"]
    data = load_paper_data(slug, Path(inputs["claims_file"]).parent)
    evidence = read_evidence(inputs["evidence"])
    paths = inputs.get("tables", [])
    paths = [paths] if isinstance(paths, (str, Path)) else list(paths)
    tables = {str(p): pd.read_csv(p) for p in paths}
    missing = set(_tables_read(data)) - set(tables)
    if missing:
        raise InputError(f"claims of {slug} read tables that are not inputs of the rule: {sorted(missing)}")
    return {"table": claims_table(data, tables, evidence), "errata": errata_table(data, evidence),
            "reconstructions": reconstructions_table(data, evidence), "findings": findings_table(data, evidence)}
