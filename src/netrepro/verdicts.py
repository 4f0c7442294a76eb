"""Claims as data, and the one verdict function every paper uses (issue 15).

A paper's side of every claim lives in ``src/netrepro/papers/<slug>/claims.yaml``, a
list of entries validated against ``workflow/schemas/claims.schema.yaml``::

    - id: C2
      location: {section: "3.1", figure: "1"}
      statement: "s_k converges to approximately 0.4"
      paper_value: 0.4
      kind: numeric                 # numeric | boolean | not_checkable | not_identifiable | context
      tolerance: {value: 0.05, relative: false,
                  reason: "'approximately' with one significant digit: half a unit of the last digit"}
      ours: {table: results/intermittent/scalar_bounds.csv, column: lower, where: {k: 60}}
      depends_on: [horizon]
      erratum_id: E3                # only when the paper's statement is wrong because of an error of its text

Ours is looked up in a result table (:func:`lookup`); the verdict is computed by
:func:`judge` from the entry, our value and our values across the range of every
reconstruction or setting the claim depends on (``variants``): a verdict that changes
inside that range is ``conditional``, with the condition stated, and ``robust`` is
``no``. Nothing here holds a paper value or a tolerance: they come from the data files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .errors import ConfigError

__all__ = [
    "VERDICTS",
    "TESTABLE_VERDICTS",
    "KINDS",
    "ClaimEntry",
    "Judgement",
    "load_claims",
    "lookup",
    "agrees",
    "judge",
]

VERDICTS = ("reproduced", "conditional", "differs", "erratum", "not_checkable", "not_identifiable", "context")
# the verdicts that score a reproduction; the other three are kept for transparency only
TESTABLE_VERDICTS = ("reproduced", "conditional", "differs", "erratum")
KINDS = ("numeric", "boolean", "not_checkable", "not_identifiable", "context")
_UNTESTABLE_KIND_VERDICT = {"not_checkable": "not_checkable", "not_identifiable": "not_identifiable",
                            "context": "context"}
_REQUIRED = ("id", "location", "statement", "kind")
_EPS = 2.0 ** -52


@dataclass(frozen=True)
class ClaimEntry:
    """One claim of a paper, as its data file states it.

    Attributes
    ----------
    claim_id : str
        Identifier, unique within the paper.
    location : dict
        Where the paper states it (``section``, ``equation``, ``figure``, ``page``).
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
        Why this tolerance, fixed before and independently of our value.
    ours : dict
        Where our value comes from (``table``, ``column``, ``where``).
    depends_on : tuple of str
        Reconstruction ids and numerical settings the value depends on.
    erratum_id : str
        The erratum that explains a disagreement, if any.
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
        ``yes`` when the verdict holds across every variant, ``no`` when it changes, ``""`` when untested.
    condition : str
        For ``conditional``: the variants under which the claim holds.
    """

    verdict: str
    robust: str
    condition: str


def _problem(path: Path, where: str, field_name: str, what: str) -> ConfigError:
    return ConfigError(f"{path}: {where}: field {field_name!r} {what}")


def _entry(path: Path, index: int, raw) -> ClaimEntry:
    where = f"entry {index}"
    if not isinstance(raw, dict):
        raise ConfigError(f"{path}: {where}: expected a mapping, got {type(raw).__name__}")
    where = f"entry {index} (id {raw.get('id', '?')!r})"
    for name in _REQUIRED:
        if name not in raw:
            raise _problem(path, where, name, "is required")
    kind = raw["kind"]
    if kind not in KINDS:
        raise _problem(path, where, "kind", f"must be one of {list(KINDS)}, got {kind!r}")
    if not isinstance(raw["location"], dict) or not raw["location"]:
        raise _problem(path, where, "location", "must map section/equation/figure/page to where the paper says it")
    tol = raw.get("tolerance")
    if kind in ("numeric", "boolean"):
        if "paper_value" not in raw:
            raise _problem(path, where, "paper_value", f"is required for kind {kind!r}")
        if "ours" not in raw or not isinstance(raw["ours"], dict) or not raw["ours"].get("table"):
            raise _problem(path, where, "ours", "must name the table (and column) our value is read from")
    if kind == "numeric":
        if not isinstance(tol, dict) or not isinstance(tol.get("value"), (int, float)) or tol["value"] < 0:
            raise _problem(path, where, "tolerance", "must be a mapping with a non-negative 'value'")
        if not str(tol.get("reason", "")).strip():
            raise _problem(path, where, "tolerance.reason", "is required: why this tolerance, fixed in advance")
        if not isinstance(raw["paper_value"], (int, float)) or isinstance(raw["paper_value"], bool):
            raise _problem(path, where, "paper_value", "must be a number for kind 'numeric'")
    tol = tol if isinstance(tol, dict) else {}
    return ClaimEntry(
        claim_id=str(raw["id"]), location=dict(raw["location"]), statement=str(raw["statement"]), kind=kind,
        paper_value=raw.get("paper_value"), tolerance=float(tol.get("value", 0.0)),
        relative=bool(tol.get("relative", False)), tolerance_reason=str(tol.get("reason", "")),
        ours=dict(raw.get("ours", {})), depends_on=tuple(raw.get("depends_on", ())),
        erratum_id=str(raw.get("erratum_id", "")), note=str(raw.get("note", "")))


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
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML: {exc}") from None
    if not isinstance(data, list):
        raise ConfigError(f"{path}: expected a list of claim entries, got {type(data).__name__}")
    entries = [_entry(path, i, raw) for i, raw in enumerate(data)]
    seen = set()
    for e in entries:
        if e.claim_id in seen:
            raise ConfigError(f"{path}: duplicate claim id {e.claim_id!r}")
        seen.add(e.claim_id)
    return entries


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
    holds = [label for label, ok in outcomes.items() if ok]
    if nominal and robust != "no":
        return Judgement("reproduced", robust, "")
    if holds or nominal:
        where = (["nominal settings"] if nominal else []) + holds
        return Judgement("conditional", robust, "holds for " + "; ".join(where))
    if entry.erratum_id:
        return Judgement("erratum", robust, "")
    return Judgement("differs", robust, "")
