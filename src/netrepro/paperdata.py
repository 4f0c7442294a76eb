"""The paper's side of a reproduction: its four data files, loaded, validated and cross-checked.

Per paper, four data files beside its code hold what the paper says and what we add, each
validated against a JSON schema in ``workflow/schemas/paper/`` before any job starts (the
workflow loads them when it starts); :mod:`netrepro.verdicts` judges them against our evidence.

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

Cross-checks across files: every ``depends_on`` names a reconstruction key, every claim's
``erratum_id`` an erratum; ids are unique per file, and an id whose entry has settings (``at``)
is not used by an entry of another file that has settings too (:meth:`PaperData.settings`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .errors import ConfigError
from .io import load_yaml

__all__ = [
    "KINDS",
    "FINDING_KINDS",
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
FINDING_KINDS = ("numeric", "boolean")
ERRATUM_KINDS = ("equation", "prose", "notation", "typesetting")
DATA_FILES = ("claims", "errata", "reconstructions", "findings")
# Words with which a statement asserts a cause. A finding whose statement uses one must say whether it
# asserts a cause (``asserts_cause: true`` with the ``cause`` that tests it, or ``asserts_cause: false``).
CAUSAL_WORDING = re.compile(
    r"\b(because|due to|caused by|causes?|causing|owing to|explains?|explained by|comes? from|is why|"
    r"the reason|attributed to|responsible for)\b", re.IGNORECASE)
_SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas" / "paper"
_PAPERS_DIR = Path(__file__).resolve().parent / "papers"


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
        ``numeric`` or ``boolean``: how the assertion is checked.
    asserted : float or bool
        What the finding asserts (the value ours is held against).
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

    @property
    def expected(self):
        """The value ours is held against: what the finding asserts."""
        return self.asserted


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


def _finding(path: Path, index: int, raw) -> FindingEntry:
    """A schema-valid entry of ``findings.yaml`` checked for what the schema cannot say."""
    where = f"entry {index} (id {raw.get('id', '?')!r})"
    kind, asserted, rule = raw["kind"], raw["asserted"], raw["rule"]
    statement = " ".join(str(raw["statement"]).split())
    if not str(rule["reason"]).strip():
        raise _problem(path, where, "rule.reason", "is empty: give the decision rule's reason, fixed in advance")
    if kind == "numeric":
        if not isinstance(rule.get("value"), (int, float)):
            raise _problem(path, where, "rule.value", "is required for kind 'numeric' (the tolerance of the rule)")
        if not isinstance(asserted, (int, float)) or isinstance(asserted, bool):
            raise _problem(path, where, "asserted", "must be a number for kind 'numeric'")
    elif not isinstance(asserted, bool):
        raise _problem(path, where, "asserted", "must be true or false for kind 'boolean'")
    quantities = [str(raw["quantity"])] + [str(q) for q in raw["evidence_quantities"] if q != raw["quantity"]]
    if len(set(quantities)) != len(quantities):
        raise _problem(path, where, "evidence_quantities", "names a quantity twice")
    prior = str(raw["prior_work"]).strip()
    if re.match(r"none\b", prior, re.IGNORECASE) and "search" not in prior.lower():
        raise _problem(path, where, "prior_work", "says none was found but not what was searched: "
                       "write 'none found (searched: ...)'")
    if raw.get("known") and re.match(r"none\b", prior, re.IGNORECASE):
        raise _problem(path, where, "prior_work", "must cite the known result (known: true)")
    cause = dict(raw.get("cause") or {})
    asserts_cause = raw.get("asserts_cause")
    if asserts_cause is None:
        words = CAUSAL_WORDING.search(statement)
        if words and not cause:
            raise _problem(path, where, "asserts_cause",
                           f"is required: the statement says {words.group(0)!r}. A finding that asserts a cause "
                           "names the variant that tests it (asserts_cause: true, cause: {variant, reason}); "
                           "otherwise say asserts_cause: false")
        asserts_cause = bool(cause)
    if asserts_cause and not cause:
        raise _problem(path, where, "cause", "is required when the finding asserts a cause: "
                       "{variant: <the evidence quantity or variant that tests it>, reason: ...}")
    if cause and not asserts_cause:
        raise _problem(path, where, "cause", "is given but asserts_cause is false")
    return FindingEntry(
        finding_id=str(raw["id"]), statement=str(raw["statement"]).strip(), kind=kind, asserted=asserted,
        quantity=str(raw["quantity"]), rule_reason=str(rule["reason"]).strip(), prior_work=prior,
        table=str(raw["table"]), tolerance=float(rule.get("value", 0.0)), relative=bool(rule.get("relative", False)),
        evidence_quantities=tuple(quantities), depends_on=tuple(raw["depends_on"]),
        figure=str(raw.get("figure", "")), evidence=str(raw.get("evidence", "")).strip(),
        nominal=str(raw.get("nominal", "")), asserts_cause=bool(asserts_cause), cause=cause,
        known=bool(raw.get("known", False)), at=dict(raw.get("at") or {}))


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


def load_paper_data(slug: str, root: str | Path | None = None) -> PaperData:
    """Read, validate and cross-check the data files of one paper.

    Parameters
    ----------
    slug : str
        The paper.
    root : str or Path, optional
        The directory holding the files (default: the paper's package).

    Returns
    -------
    PaperData
        The claims, errata, reconstructions and findings.

    Raises
    ------
    ConfigError
        For a malformed file, a ``depends_on`` (of a claim or a finding) that names no
        reconstruction, or an ``erratum_id`` that names no erratum.
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
    return PaperData(slug, claims, errata, reconstructions, findings)


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
