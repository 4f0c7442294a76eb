"""The paper's side of a reproduction: its four data files, loaded, validated and cross-checked.

Per paper, four data files beside its code hold what the paper says and what we add, each
validated against a JSON schema in ``workflow/schemas/paper/`` before any job starts (the
workflow loads them when it starts); :mod:`netrepro.judging.verdicts` judges them against our evidence.

``claims.yaml``
    id, location in the paper, group (of the replication summary), the quoted statement, kind
    (``numeric | boolean | not_checkable | not_identifiable | context``), the paper's value,
    the tolerance and its reason (fixed before and independently of our value), the quantity of
    ours it is compared with, what it depends on (reconstruction keys), the paper's settings of
    the claim (``at``) and, for a statement the text gets wrong, the erratum that explains it::

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
    id, location, kind (``equation | prose | notation | typesetting``), printed, corrected, impact,
    and (optional) the settings at which the erratum is demonstrated (``at``, as for claims).
``reconstructions.yaml``
    key, reason, range (over which dependent claims and findings are re-judged), optional
    value/sensitivity.
``findings.yaml``
    our own findings, judged like claims (issue 27): the statement, how it is checked (``kind``,
    ``asserted``, the decision ``rule`` with its reason), the evidence quantity judged
    (``quantity``) and every one it rests on (``evidence_quantities``), ``depends_on``, the
    prior work, whether it is a known result, the tested cause of a causal statement, and the
    table (and figure) that shows it.

``findings.lock``
    the registry of the findings' rules (issue 37): per finding, the SHA-256 of the fields that
    decide it (:data:`REGISTERED_FIELDS`), the date and the commit it was registered at. It is
    written by ``python -m netrepro register-findings <slug>`` before the runs that test a new
    finding, and never rewritten: a registered rule that changes needs an ``amendments:`` entry
    (:func:`check_registry`), and the report shows the registered verdict first.

Cross-checks across files: every ``depends_on`` names a reconstruction key, every claim's
``erratum_id`` an erratum; ids are unique across the four files, ignoring case; an empty claims
file, a non-finite value and a tolerance without a finite bound are refused
(:func:`check_tolerance`).
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import yaml

from ..errors import ConfigError
from ..pipeline.io import load_yaml
from ..locations import PAPER_SCHEMA_DIR, PAPERS_DIR

__all__ = [
    "KINDS",
    "FINDING_KINDS",
    "REGISTERED_FIELDS",
    "LOCK_FILE",
    "SKELETON_COMMIT",
    "SOURCE_KINDS",
    "Amendment",
    "check_tolerance",
    "registered_fields",
    "rule_hash",
    "read_registry",
    "check_registry",
    "register_findings",
    "registry_lock_text",
    "template_fields",
    "render_statement",
    "typed_numbers",
    "ERRATUM_KINDS",
    "DATA_FILES",
    "CAUSAL_WORDING",
    "ClaimEntry",
    "FindingEntry",
    "PaperData",
    "paper_dir",
    "load_claims",
    "load_findings",
    "load_errata",
    "load_paper_data",
    "referenced_tables",
]

KINDS = ("numeric", "boolean", "not_checkable", "not_identifiable", "context")
FINDING_KINDS = ("numeric", "boolean", "observation")
# the fields of a finding that decide its verdict: registered in findings.lock before its runs (issue 37)
REGISTERED_FIELDS = ("kind", "asserted", "rule", "quantity", "evidence_quantities", "test")
LOCK_FILE = "findings.lock"
# the commit recorded for the example finding of a new paper's skeleton: a placeholder, not a finding of
# ours, so replacing it is not a deletion (register-findings drops its entry once it is gone)
SKELETON_COMMIT = "new-paper"
# independent sources of a numeric rule's threshold (issue 37): never our own value
SOURCE_KINDS = ("paper", "limit", "control", "effect_size")
# a relative tolerance of 1 already accepts 0 and twice the expected value: nothing wider is a test
_MAX_RELATIVE_TOLERANCE = 1.0
# against an expected 0, an absolute tolerance is the largest |value| accepted; the quantities judged
# against 0 are residuals, differences and counts on their natural unit scale
_MAX_TOLERANCE_AT_ZERO = 1.0
# a template field of a finding's statement: {quantity}, {quantity:fmt}, {quantity#u:fmt}, #lo, #hi
_FIELD = re.compile(r"\{([A-Za-z_][\w.\-]*)(?:#(u|lo|hi))?(?::([^{}:]*))?\}")
# a number typed in a statement: decimals, or integers of two digits or more (a single digit is a count
# or a setting such as "gamma = 3", and equation numbers come in parentheses)
_NUMBER = re.compile(r"(?<![\w.])(\(?)([-+]?(?:\d+\.\d+|\d+)(?:[eE][-+]?\d+)?)(\)?)(?![\w.]\w)")
ERRATUM_KINDS = ("equation", "prose", "notation", "typesetting")
DATA_FILES = ("claims", "errata", "reconstructions", "findings")
# Words with which a statement asserts a cause. A finding whose statement uses one must say whether it
# asserts a cause (``asserts_cause: true`` with the ``cause`` that tests it, or ``asserts_cause: false``).
CAUSAL_WORDING = re.compile(
    r"\b(because|due to|caused by|causes?|causing|owing to|explains?|explained by|comes? from|is why|"
    r"the reason|attributed to|responsible for)\b", re.IGNORECASE)
_SCHEMA_DIR = PAPER_SCHEMA_DIR
_PAPERS_DIR = PAPERS_DIR


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
        Reconstruction keys whose declared ranges the claim is re-judged across.
    erratum_id : str
        The erratum that explains a disagreement, if any.
    note : str
        A remark on the claim, carried into the ``note`` column of the claims table.
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

    @property
    def expected(self):
        """The value ours is held against: the paper's."""
        return self.paper_value


@dataclass(frozen=True)
class FindingEntry:
    """One finding of ours, as ``findings.yaml`` states it (judged like a claim, issue 27).

    Attributes
    ----------
    finding_id : str
        Identifier, unique within the paper.
    statement : str
        The conclusion (with its condition when it holds only under one).
    kind : str
        ``numeric`` or ``boolean``: how the assertion is checked; ``observation``: measured, not judged.
    asserted : float, bool or None
        What the finding asserts (the value ours is held against); None for an observation.
    tolerance : float
        For ``numeric``: the rule's tolerance, absolute or relative to ``|asserted|``.
    relative : bool
        Whether ``tolerance`` is relative.
    rule_reason : str
        The decision rule's reason, fixed in advance.
    quantity : str
        The evidence quantity judged: its ``nominal`` row and its variant rows.
    evidence_quantities : tuple of str
        Every evidence quantity the finding rests on (``quantity`` included, first).
    depends_on : tuple of str
        Reconstruction keys whose declared ranges the finding is re-judged across.
    table : str
        The result table that shows it.
    figure : str
        The figure that shows it, if any.
    evidence : str
        Text of the evidence beyond the quantities' values and notes.
    nominal : str
        The setting of the nominal value, as named in a condition.
    asserts_cause : bool
        Whether the statement asserts a cause (then ``cause`` names the variant that tests it).
    cause : dict
        ``{"variant": ..., "reason": ...}`` for a causal statement, else empty.
    prior_work : str
        A citation where the result is known, or "none found (searched: ...)".
    known : bool
        A known result that we re-derive.
    at : dict
        The settings of the finding, read by the evidence step.
    source : dict
        ``{"kind", "ref"}``: where a numeric rule's threshold comes from, independently of our
        value (``paper``, ``limit``, ``control``, ``effect_size``); empty for other kinds.
    test : dict
        The statistical test's registered sizes (``runs``, ``family``, ``alpha``, ``correction``).
    amendments : tuple of Amendment
        The history of a registered rule changed after registration, oldest first.
    retracted : dict
        ``{"reason", "when"}`` of a finding we no longer stand by (kept and shown), else empty.
    registered : dict
        The fields its registration covers (:func:`registered_fields`), as written now.
    """

    finding_id: str
    statement: str
    kind: str
    asserted: object
    quantity: str
    rule_reason: str
    prior_work: str
    table: str
    tolerance: float = 0.0
    relative: bool = False
    evidence_quantities: tuple = ()
    depends_on: tuple = ()
    figure: str = ""
    evidence: str = ""
    nominal: str = ""
    asserts_cause: bool = False
    cause: dict = field(default_factory=dict)
    known: bool = False
    at: dict = field(default_factory=dict)
    source: dict = field(default_factory=dict)
    test: dict = field(default_factory=dict)
    amendments: tuple = ()
    retracted: dict = field(default_factory=dict)
    registered: dict = field(default_factory=dict)

    @property
    def expected(self):
        """The value ours is held against: what the finding asserts."""
        return self.asserted

    @property
    def observation(self) -> bool:
        """A descriptive measurement: measured, not judged."""
        return self.kind == "observation"

    @property
    def registered_rule(self) -> "FindingEntry":
        """The finding as its rule was registered: the first amendment's rule, or itself if never amended."""
        return self.amendments[0].rule if self.amendments else self


@dataclass(frozen=True)
class Amendment:
    """A registered rule that was changed: the rule as it stood before, why it changed and when.

    Attributes
    ----------
    rule : FindingEntry
        The finding with its fields of :data:`REGISTERED_FIELDS` as they stood before the change.
    why : str
        The reason for the change.
    when : str
        Date and commit of the change.
    fields : dict
        The registered fields as written (their hash is compared with ``findings.lock``).
    """

    rule: FindingEntry
    why: str
    when: str
    fields: dict


@dataclass(frozen=True)
class PaperData:
    """The four data files of one paper, validated and cross-checked.

    Attributes
    ----------
    slug : str
        The paper.
    claims : list of ClaimEntry
        The claims of ``claims.yaml``, in the file's order.
    errata : list of dict
        The entries of ``errata.yaml`` (``id``, ``location``, ``kind``, ``printed``, ``corrected``,
        ``impact``, ``at``: a dict, empty when the file gives no settings).
    reconstructions : list of dict
        The entries of ``reconstructions.yaml`` (``key``, ``reason``, ``range``, ...), whose keys
        the claims' and findings' ``depends_on`` name.
    findings : list of FindingEntry
        Our own findings of ``findings.yaml``, in the file's order.
    """

    slug: str
    claims: list
    errata: list
    reconstructions: list
    findings: list

    def tables_read(self) -> list[str]:
        """The result tables (other than the evidence table) that the claims read."""
        return sorted({e.ours["table"] for e in self.claims if e.ours.get("table")})

    def settings(self) -> dict:
        """The ``at`` settings of every claim, finding and erratum that has some, by id.

        Returns
        -------
        dict
            ``{id: {setting: value}}`` over claims, findings and errata (entries without ``at`` left out).

        Raises
        ------
        ConfigError
            If two entries with settings share an id (the evidence step would not know whose they are).
        """
        out, owner = {}, {}
        entries = [("claims.yaml", c.claim_id, c.at) for c in self.claims]
        entries += [("findings.yaml", f.finding_id, f.at) for f in self.findings]
        entries += [("errata.yaml", e["id"], e["at"]) for e in self.errata]
        for file, ident, at in entries:
            if not at:
                continue
            if ident in out:
                raise ConfigError(f"paper {self.slug!r}: id {ident!r} has settings ('at') in both {owner[ident]} and "
                                  f"{file}; the evidence step reads settings by id, so give one of them another id")
            out[ident], owner[ident] = dict(at), file
        return out


def paper_dir(slug: str) -> Path:
    """The package directory of a paper, which holds its data files.

    Parameters
    ----------
    slug : str
        The paper.

    Returns
    -------
    pathlib.Path
        ``src/netrepro/papers/<slug>`` (whether or not it exists).
    """
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


def _claim(path: Path, index: int, raw) -> ClaimEntry:
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
        _finite_number(path, where, "paper_value", raw["paper_value"])
        problem = check_tolerance(tol["value"], bool(tol.get("relative", False)), raw["paper_value"])
        if problem:
            raise _problem(path, where, "tolerance.value", problem)
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


def check_tolerance(value, relative: bool, expected) -> str:
    """What is wrong with a tolerance (``""`` if nothing): it must be finite, >= 0 and bounded.

    Bounds, each with its reason: a relative tolerance above 1 accepts 0 and more than twice the
    expected value, so it tests nothing; an absolute tolerance must be narrower than
    ``|expected|`` (a band that reaches 0 cannot tell the value from nothing), and against an
    expected 0 at most 1 (the quantities judged against 0 are residuals, differences and counts
    on their natural scale).

    Parameters
    ----------
    value : float
        The tolerance.
    relative : bool
        Whether it is relative to ``|expected|``.
    expected : float or bool
        The expected value (booleans have no tolerance to check).

    Returns
    -------
    str
        The problem, or ``""``.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"must be a number, got {value!r}"
    if not math.isfinite(value) or value < 0:
        return f"must be a finite number >= 0, got {value!r}"
    if isinstance(expected, bool) or not isinstance(expected, (int, float)):
        return ""
    if relative:
        if value > _MAX_RELATIVE_TOLERANCE:
            return (f"is {value:g} (relative): above {_MAX_RELATIVE_TOLERANCE:g} it accepts 0 and more than twice "
                    "the expected value, so it tests nothing")
        return ""
    if expected != 0 and value >= abs(expected):
        return (f"is {value:g}, as wide as the expected value {expected:g}: a band that reaches 0 cannot tell the "
                "value from nothing (use a relative tolerance below 1, or a narrower one)")
    if expected == 0 and value > _MAX_TOLERANCE_AT_ZERO:
        return f"is {value:g} against an expected 0: at most {_MAX_TOLERANCE_AT_ZERO:g} (a residual or difference)"
    return ""


def _finite_number(path: Path, where: str, name: str, value) -> None:
    if isinstance(value, float) and not math.isfinite(value):
        raise _problem(path, where, name, f"must be a finite number, got {value!r}")


def registered_fields(raw: dict) -> dict:
    """The fields of a finding (or of an amendment's ``registered``) that its registration covers.

    ``rule.source`` is left out: it documents where a threshold comes from and changes no
    verdict; the threshold (``rule.value``, ``relative``), the rule's text and the asserted value do.

    Parameters
    ----------
    raw : dict
        A finding as written in ``findings.yaml``.

    Returns
    -------
    dict
        ``{field: value}`` over :data:`REGISTERED_FIELDS` (absent fields as None), the judged
        quantity first in ``evidence_quantities`` (as the loader reads it).
    """
    out = {name: raw.get(name) for name in REGISTERED_FIELDS}
    if isinstance(out["rule"], dict):
        out["rule"] = {k: v for k, v in out["rule"].items() if k != "source"}
    quantity = str(raw.get("quantity", ""))
    out["evidence_quantities"] = [quantity] + [str(q) for q in (raw.get("evidence_quantities") or []) if q != quantity]
    return out


def rule_hash(fields: dict) -> str:
    """SHA-256 of registered fields, over their canonical JSON (sorted keys, no spaces).

    Parameters
    ----------
    fields : dict
        From :func:`registered_fields`.

    Returns
    -------
    str
        ``"sha256:<hex>"``.
    """
    text = json.dumps(fields, sort_keys=True, separators=(",", ":"), ensure_ascii=True, default=str)
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def template_fields(statement: str) -> list[tuple[str, str, str]]:
    """The template fields of a statement: ``(quantity, part, format spec)`` in order.

    A field is ``{quantity}``, ``{quantity:spec}`` or ``{quantity#part:spec}`` with ``quantity`` an
    evidence quantity's name (letters, digits, ``_ . -``) and ``part`` one of ``u`` (its
    uncertainty), ``lo``, ``hi`` (value minus / plus uncertainty). Other braces are text (a set
    such as ``{F1, (F1+F2)/2, F2}`` stays as written).

    Parameters
    ----------
    statement : str
        A finding's statement.

    Returns
    -------
    list of tuple
        One ``(quantity, part, spec)`` per field.
    """
    return [(m.group(1), m.group(2) or "", m.group(3) or "") for m in _FIELD.finditer(statement)]


def render_statement(statement: str, cells: dict) -> str:
    """A statement with its template fields filled from the evidence (issue 37).

    Parameters
    ----------
    statement : str
        The template (:func:`template_fields`).
    cells : dict
        ``{quantity: (value, note)}`` nominal evidence rows; a row with attributes
        ``uncertainty`` (:class:`netrepro.judging.verdicts.Cell`) fills ``#u``, ``#lo`` and ``#hi``.

    Returns
    -------
    str
        The statement as the table shows it.
    """
    def fill(match):
        quantity, part, spec = match.group(1), match.group(2) or "", match.group(3) or ""
        cell = cells[quantity]
        uncertainty = float(getattr(cell, "uncertainty", 0.0))
        value = {"": cell[0], "u": uncertainty}.get(part)
        if part in ("lo", "hi"):
            value = cell[0] - uncertainty if part == "lo" else cell[0] + uncertainty
        return format(value, spec)

    return _FIELD.sub(fill, statement)


def _literal_text(statement: str) -> str:
    """The statement without its template fields."""
    return _FIELD.sub(" ", statement)


def typed_numbers(statement: str, values: dict) -> list[str]:
    """Numbers typed in a statement's text that equal one of our values at their printed precision.

    Such a number belongs in a template field: typed, it can disagree with its own evidence at
    another scale (issue 37). Integers in parentheses (equation numbers) and numbers of one
    significant digit (settings such as "gamma = 3", "lambda_c + 0.1", counts) are not read as results.

    Parameters
    ----------
    statement : str
        The template.
    values : dict
        ``{quantity: number}``: the nominal values of the finding's evidence quantities.

    Returns
    -------
    list of str
        ``"<number> (= <quantity> <value>)"`` for each typed number that matches.
    """
    literal = _literal_text(statement)
    found = []
    for match in _NUMBER.finditer(literal):
        opened, number, closed = match.groups()
        integer = re.fullmatch(r"[-+]?\d+", number) is not None
        significant = len(re.sub(r"^[-+]?0*\.?0*", "", number.split("e")[0].split("E")[0]).replace(".", ""))
        if (integer and opened and closed) or significant < 2:
            continue
        typed = float(number)
        decimals = len(number.split(".")[1].split("e")[0].split("E")[0]) if "." in number else 0
        for quantity, value in values.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                continue
            if value != 0 and abs(typed) > 0 and round(abs(value), decimals) == abs(typed) and \
                    (decimals > 0 or abs(abs(value) - abs(typed)) < 0.5):
                found.append(f"{number} (= {quantity} {value:.6g})")
                break
    return found


def _finding_rule(path: Path, where: str, raw: dict, historical: bool = False) -> dict:
    """The checked decision fields of a finding (or, ``historical``, of an amendment's registered rule).

    A registered rule is history: it is judged as it was, so today's requirement of a stated
    threshold source does not apply to it (the amendment says why it changed).
    """
    kind = raw["kind"]
    rule = raw.get("rule") or {}
    asserted = raw.get("asserted")
    if kind == "observation":
        if "asserted" in raw or raw.get("rule"):
            raise _problem(path, where, "rule", "is given for an observation: an observation is measured, not "
                           "judged (give kind numeric or boolean to judge it)")
        return {"kind": kind, "asserted": None, "tolerance": 0.0, "relative": False, "rule_reason": "",
                "source": {}}
    if "asserted" not in raw:
        raise _problem(path, where, "asserted", f"is required for kind {kind!r}")
    if "rule" not in raw:
        raise _problem(path, where, "rule", f"is required for kind {kind!r}: the decision rule, fixed in advance")
    if not isinstance(rule, dict) or not str(rule.get("reason", "")).strip():
        raise _problem(path, where, "rule.reason", "is empty: give the decision rule's reason, fixed in advance")
    if kind == "numeric":
        if not isinstance(rule.get("value"), (int, float)):
            raise _problem(path, where, "rule.value", "is required for kind 'numeric' (the tolerance of the rule)")
        if not isinstance(asserted, (int, float)) or isinstance(asserted, bool):
            raise _problem(path, where, "asserted", "must be a number for kind 'numeric'")
        _finite_number(path, where, "asserted", asserted)
        problem = check_tolerance(rule["value"], bool(rule.get("relative", False)), asserted)
        if problem:
            raise _problem(path, where, "rule.value", problem)
        if not rule.get("source") and not historical:
            raise _problem(path, where, "rule.source",
                           "is required for kind 'numeric': where the threshold comes from, independently of our "
                           "value ({kind: paper|limit|control|effect_size, ref: ...}). A rule that only checks that "
                           "our number rounds to what the statement says is bookkeeping: make it an observation")
    elif not isinstance(asserted, bool):
        raise _problem(path, where, "asserted", "must be true or false for kind 'boolean'")
    return {"kind": kind, "asserted": asserted, "tolerance": float(rule.get("value", 0.0)),
            "relative": bool(rule.get("relative", False)), "rule_reason": str(rule.get("reason", "")).strip(),
            "source": dict(rule.get("source") or {})}


def _finding(path: Path, index: int, raw) -> FindingEntry:
    """A schema-valid entry of ``findings.yaml`` checked for what the schema cannot say."""
    where = f"entry {index} (id {raw.get('id', '?')!r})"
    statement = " ".join(str(raw["statement"]).split())
    decision = _finding_rule(path, where, raw)
    quantities = [str(raw["quantity"])] + [str(q) for q in raw["evidence_quantities"] if q != raw["quantity"]]
    if len(set(quantities)) != len(quantities):
        raise _problem(path, where, "evidence_quantities", "names a quantity twice")
    prior = str(raw["prior_work"]).strip()
    if re.match(r"none\b", prior, re.IGNORECASE) and "search" not in prior.lower():
        raise _problem(path, where, "prior_work", "says none was found but not what was searched: "
                       "write 'none found (searched: ...)'")
    if raw.get("known") and re.match(r"none\b", prior, re.IGNORECASE):
        raise _problem(path, where, "prior_work", "must cite the known result (known: true)")
    if re.search(r"\bnot verified\b", prior, re.IGNORECASE):
        raise _problem(path, where, "prior_work", "says 'not verified': verify the citation from a source you can "
                       "name, or drop it")
    cause = dict(raw.get("cause") or {})
    asserts_cause = raw.get("asserts_cause")
    if asserts_cause is None:
        words = CAUSAL_WORDING.search(statement)
        if words and not cause:
            raise _problem(path, where, "asserts_cause",
                           f"is required: the statement says {words.group(0)!r}. A finding that asserts a cause "
                           "names the control that isolates it (asserts_cause: true, cause: {variant, reason, "
                           "control: {holds_fixed, changes}}); without one it is an observation, or say "
                           "asserts_cause: false")
        asserts_cause = bool(cause)
    if asserts_cause and not cause:
        raise _problem(path, where, "cause", "is required when the finding asserts a cause: {variant: <the evidence "
                       "quantity or variant that tests it>, reason: ..., control: {holds_fixed: ..., changes: ...}}; "
                       "a finding without an isolating control is an observation")
    if cause and not asserts_cause:
        raise _problem(path, where, "cause", "is given but asserts_cause is false")
    if cause and decision["kind"] == "observation":
        raise _problem(path, where, "cause", "is given for an observation: a causal finding is judged (kind numeric "
                       "or boolean) against its control")
    amendments = tuple(_amendment(path, where, i, a, raw) for i, a in enumerate(raw.get("amendments") or ()))
    return FindingEntry(
        finding_id=str(raw["id"]), statement=str(raw["statement"]).strip(), kind=decision["kind"],
        asserted=decision["asserted"], quantity=str(raw["quantity"]), rule_reason=decision["rule_reason"],
        prior_work=prior, table=str(raw["table"]), tolerance=decision["tolerance"], relative=decision["relative"],
        evidence_quantities=tuple(quantities), depends_on=tuple(raw["depends_on"]),
        figure=str(raw.get("figure", "")), evidence=str(raw.get("evidence", "")).strip(),
        nominal=str(raw.get("nominal", "")), asserts_cause=bool(asserts_cause), cause=cause,
        known=bool(raw.get("known", False)), at=dict(raw.get("at") or {}), source=decision["source"],
        test=dict(raw.get("test") or {}), amendments=amendments, retracted=dict(raw.get("retracted") or {}),
        registered=registered_fields(raw))


def _amendment(path: Path, where: str, index: int, raw_amendment: dict, finding: dict) -> Amendment:
    """One entry of a finding's ``amendments``: the rule before the change, judged like a finding."""
    old = dict(raw_amendment["registered"])
    here = f"{where}, amendments[{index}].registered"
    decision = _finding_rule(path, here, old, historical=True)
    quantities = registered_fields(old)["evidence_quantities"]
    rule = FindingEntry(
        finding_id=str(finding["id"]), statement=str(finding["statement"]).strip(), kind=decision["kind"],
        asserted=decision["asserted"], quantity=str(old["quantity"]), rule_reason=decision["rule_reason"],
        prior_work=str(finding["prior_work"]).strip(), table=str(finding["table"]), tolerance=decision["tolerance"],
        relative=decision["relative"], evidence_quantities=tuple(quantities),
        depends_on=tuple(finding["depends_on"]), nominal=str(finding.get("nominal", "")),
        source=decision["source"], test=dict(old.get("test") or {}), registered=registered_fields(old))
    return Amendment(rule, str(raw_amendment["why"]).strip(), str(raw_amendment["when"]).strip(),
                     registered_fields(old))


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
    if not data:
        raise ConfigError(f"{path}: the claims file is empty: a paper has at least one claim (a statement of the "
                          "paper, even one we cannot check: kind not_checkable)")
    _schema_errors(path, "claims", data)
    entries = [_claim(path, i, raw) for i, raw in enumerate(data)]
    _unique(path, [e.claim_id for e in entries])
    return entries


def load_findings(path: str | Path) -> list[FindingEntry]:
    """Read and validate a paper's ``findings.yaml`` (no file: no findings).

    Parameters
    ----------
    path : str or Path
        The data file.

    Returns
    -------
    list of FindingEntry
        In file order.

    Raises
    ------
    ConfigError
        Naming the file, the entry (index and id) and the field: a finding without a decision rule,
        evidence quantities, ``depends_on`` or ``prior_work``; "none found" without what was
        searched; a causal statement without the variant that tests the cause.
    """
    path = Path(path)
    if not path.is_file():
        return []
    data = _read_yaml_list(path)
    _schema_errors(path, "findings", data)
    entries = [_finding(path, i, raw) for i, raw in enumerate(data)]
    _unique(path, [e.finding_id for e in entries])
    return entries


def load_errata(path: str | Path) -> list[dict]:
    """Read and validate a paper's ``errata.yaml`` (no file: no errata).

    Parameters
    ----------
    path : str or Path
        The data file.

    Returns
    -------
    list of dict
        The entries in file order; each has ``at`` (the settings at which the erratum is demonstrated,
        read by the evidence step; ``{}`` when the entry gives none).

    Raises
    ------
    ConfigError
        Naming the file, the entry (index and id) and the field, for a malformed file; a duplicate id.
    """
    entries = _load_list(Path(path), "errata")
    return [dict(e, at=dict(e.get("at") or {})) for e in entries]


def _load_list(path: Path, kind: str) -> list[dict]:
    if not path.is_file():
        return []
    data = _read_yaml_list(path)
    _schema_errors(path, kind, data)
    _unique(path, [d.get("id", d.get("key")) for d in data])
    return data


_LOCK_HEADER = """\
# findings.lock: the registry of the findings' rules (issue 37). One entry per finding: the SHA-256 of
# its registered fields (kind, asserted, rule without its source, quantity, evidence_quantities, test;
# netrepro.judging.paperdata.REGISTERED_FIELDS), the date and the commit on which it was registered.
# Written by `python -m netrepro register-findings <slug>` before the runs that test a new finding; never
# edited by hand and never rewritten. A registered rule that changes keeps its registration: the finding
# gets an `amendments:` entry (the registered fields, why, when) and the report shows both verdicts.
"""


def read_registry(root: str | Path) -> dict:
    """The registry ``findings.lock`` of a paper's data directory (``{}`` when there is none).

    Parameters
    ----------
    root : str or Path
        The directory holding ``findings.yaml``.

    Returns
    -------
    dict
        ``{finding id: {"rule": "sha256:...", "registered": date, "commit": sha}}``.

    Raises
    ------
    ConfigError
        If the file is not a mapping of such entries.
    """
    path = Path(root) / LOCK_FILE
    if not path.is_file():
        return {}
    try:
        data = load_yaml(path.read_text()) or {}
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML: {exc}") from None
    bad = [k for k, v in data.items() if not (isinstance(v, dict) and str(v.get("rule", "")).startswith("sha256:"))] \
        if isinstance(data, dict) else ["<file>"]
    if bad:
        raise ConfigError(f"{path}: entries {bad} are not {{rule: sha256:..., registered: ..., commit: ...}}; the "
                          "file is written by `python -m netrepro register-findings`, never by hand")
    return {str(k): dict(v) for k, v in data.items()}


def check_registry(slug: str, root: str | Path, findings: list) -> list[str]:
    """What breaks the registration of a paper's findings (issue 37); ``[]`` when every rule is registered.

    A finding is in order when ``findings.lock`` registers it and the registered hash is that of
    its fields (:func:`registered_fields`), or, for an amended finding, that of its first
    amendment's ``registered`` fields. A registered id that is no longer in ``findings.yaml`` is a
    problem too: findings are retracted, never deleted.

    Parameters
    ----------
    slug : str
        The paper (for the messages).
    root : str or Path
        Its data directory.
    findings : list of FindingEntry
        The loaded findings.

    Returns
    -------
    list of str
        One message per problem, naming the finding, what changed and the fix.
    """
    root = Path(root)
    registry = read_registry(root)
    lock = root / LOCK_FILE
    problems = []
    for f in findings:
        entry = registry.get(f.finding_id)
        if entry is None:
            problems.append(f"{slug}/{f.finding_id} is not registered in {lock}: register its rule before the runs "
                            f"that test it (`python -m netrepro register-findings {slug}`, then commit {LOCK_FILE})")
            continue
        registered = f.amendments[0].fields if f.amendments else f.registered
        if rule_hash(registered) == entry["rule"]:
            continue
        at = f"registered {entry.get('registered', '?')} at commit {entry.get('commit', '?')}"
        if f.amendments:
            problems.append(f"{slug}/{f.finding_id}: the `registered` fields of its first amendment are not the rule "
                            f"{at} (see `git show {entry.get('commit', 'HEAD')}:{lock.as_posix()}` and that commit's "
                            "findings.yaml): the amendment must start from the registered rule")
        else:
            problems.append(f"{slug}/{f.finding_id}: its rule ({', '.join(REGISTERED_FIELDS)}) changed since it was "
                            f"{at}. A registered rule is not rewritten: add an `amendments:` entry to the finding "
                            "with the rule as registered (`registered: {...}`), why it changed and when; the "
                            "report then shows the registered verdict first and the amended one beside it")
    known = {f.finding_id for f in findings}
    for ident, entry in registry.items():
        if ident not in known and entry.get("commit") != SKELETON_COMMIT:
            problems.append(f"{slug}/{ident} is registered in {lock} but missing from findings.yaml: findings are "
                            "never deleted; retract it instead (retracted: {reason, when})")
    return problems


def registry_lock_text(findings: list, commit: str, date: str) -> str:
    """The text of a ``findings.lock`` that registers every finding of ``findings`` as written.

    Parameters
    ----------
    findings : list of dict
        The entries of a ``findings.yaml``, as parsed.
    commit, date : str
        Recorded with each registration.

    Returns
    -------
    str
        The file's text (the header, then one line per finding).
    """
    lines = [_LOCK_HEADER]
    for raw in findings:
        fields = raw["amendments"][0]["registered"] if raw.get("amendments") else raw
        lines.append(_lock_line(str(raw["id"]), rule_hash(registered_fields(fields)), date, commit))
    return "".join(lines)


def _lock_line(ident: str, rule: str, date: str, commit: str) -> str:
    """One entry of ``findings.lock``, as every writer of the file writes it."""
    return f'{ident}: {{rule: "{rule}", registered: "{date}", commit: "{commit}"}}\n'



def register_findings(slug: str, root: str | Path | None = None, commit: str = "", date: str = "") -> list[str]:
    """Register the rules of a paper's unregistered findings in ``findings.lock``.

    Registered entries are never rewritten: a changed rule is refused here and needs an
    ``amendments:`` entry in ``findings.yaml``.

    Parameters
    ----------
    slug : str
        The paper.
    root : str or Path, optional
        Its data directory (default: the paper's package).
    commit : str
        The commit the registration is made on (the caller's ``git rev-parse HEAD``).
    date : str
        The date of the registration (ISO).

    Returns
    -------
    list of str
        The ids registered now (in file order).

    Raises
    ------
    ConfigError
        If a registered finding's rule changed without an amendment, or the data files are invalid.
    """
    root = Path(root) if root is not None else paper_dir(slug)
    findings = load_findings(root / "findings.yaml")
    registry = read_registry(root)
    changed = [p for p in check_registry(slug, root, findings) if " is not registered " not in p]
    if changed:
        raise ConfigError("refusing to register over a changed rule:\n  " + "\n  ".join(changed))
    known = {f.finding_id for f in findings}
    dropped = [k for k, e in registry.items() if k not in known and e.get("commit") == SKELETON_COMMIT]
    for ident in dropped:
        del registry[ident]
    new = [f for f in findings if f.finding_id not in registry]
    for f in new:
        fields = f.amendments[0].fields if f.amendments else f.registered
        registry[f.finding_id] = {"rule": rule_hash(fields), "registered": date, "commit": commit}
    if new or dropped or not (root / LOCK_FILE).is_file():
        order = [f.finding_id for f in findings] + [k for k in registry if k not in {f.finding_id for f in findings}]
        lock = root / LOCK_FILE
        kept = [line for line in lock.read_text().splitlines(keepends=True) if line.startswith("#")] \
            if lock.is_file() else []
        lines = kept or [_LOCK_HEADER]
        for ident in order:
            e = registry[ident]
            lines.append(_lock_line(ident, e["rule"], e.get("registered", ""), e.get("commit", "")))
        (root / LOCK_FILE).write_text("".join(lines))
    return [f.finding_id for f in new]


def load_paper_data(slug: str, root: str | Path | None = None, registry: bool = True) -> PaperData:
    """Read, validate and cross-check the data files of one paper.

    Parameters
    ----------
    slug : str
        The paper.
    root : str or Path, optional
        The directory holding the files (default: the paper's package).
    registry : bool
        Check the findings against their registry ``findings.lock`` (:func:`check_registry`).

    Returns
    -------
    PaperData
        The claims, errata, reconstructions and findings.

    Raises
    ------
    ConfigError
        For a malformed file, a ``depends_on`` (of a claim or a finding) that names no
        reconstruction, an ``erratum_id`` that names no erratum, an id used twice across the
        files (ignoring case), or a finding whose rule is not registered or changed without an
        amendment.
    """
    root = Path(root) if root is not None else paper_dir(slug)
    claims_path, findings_path = root / "claims.yaml", root / "findings.yaml"
    claims = load_claims(claims_path)
    errata = load_errata(root / "errata.yaml")
    reconstructions = _load_list(root / "reconstructions.yaml", "reconstructions")
    findings = load_findings(findings_path)
    keys = {r["key"] for r in reconstructions}
    errata_ids = {e["id"] for e in errata}
    entries = [(claims_path, i, e.claim_id, e.depends_on) for i, e in enumerate(claims)]
    entries += [(findings_path, i, f.finding_id, f.depends_on) for i, f in enumerate(findings)]
    for path, i, ident, depends_on in entries:
        for dep in depends_on:
            if dep not in keys:
                raise _problem(path, f"entry {i} (id {ident!r})", "depends_on",
                               f"names {dep!r}, which is not a key of {root / 'reconstructions.yaml'} "
                               "(a declared range is a reconstruction's range)")
    for i, entry in enumerate(claims):
        if entry.erratum_id and entry.erratum_id not in errata_ids:
            raise _problem(claims_path, f"entry {i} (id {entry.claim_id!r})", "erratum_id",
                           f"names {entry.erratum_id!r}, which is not in errata.yaml")
    _unique_across(root, claims, findings, errata, reconstructions)
    if registry:
        problems = check_registry(slug, root, findings)
        if problems:
            raise ConfigError("\n  ".join(problems))
    return PaperData(slug, claims, errata, reconstructions, findings)


def _unique_across(root: Path, claims, findings, errata, reconstructions) -> None:
    """Refuse an id used twice across the four files, ignoring case (tables and links are read by id)."""
    owners: dict = {}
    named = [("claims.yaml", c.claim_id) for c in claims] + [("findings.yaml", f.finding_id) for f in findings]
    named += [("errata.yaml", str(e["id"])) for e in errata]
    named += [("reconstructions.yaml", str(r["key"])) for r in reconstructions]
    for file, ident in named:
        key = ident.casefold()
        if key in owners:
            other_file, other = owners[key]
            raise ConfigError(f"{root}: id {ident!r} of {file} clashes with {other!r} of {other_file} (ids are unique "
                              "across claims, findings, errata and reconstructions, ignoring case): rename one")
        owners[key] = (file, ident)


def referenced_tables(slug: str, root: str | Path | None = None) -> list[str]:
    """The result tables (other than the evidence table) that a paper's claims read.

    Parameters
    ----------
    slug : str
        The paper.
    root : str or Path, optional
        The directory holding its data files (default: the paper's package).

    Returns
    -------
    list of str
        Sorted paths, as the claims name them.
    """
    return load_paper_data(slug, root).tables_read()
