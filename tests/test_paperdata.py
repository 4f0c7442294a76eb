"""Loading and validating the four data files of a paper (netrepro.judging.paperdata; issues 15, 27, 29)."""

from dataclasses import replace
from pathlib import Path

import pytest

from netrepro.errors import ConfigError
from netrepro.judging.paperdata import CAUSAL_WORDING, FindingEntry, load_claims, load_errata, load_findings, load_paper_data

GOOD = """
- id: C1
  location: {figure: "1"}
  group: Fig 1
  statement: "s_k converges to about 0.4"
  kind: numeric
  paper_value: 0.4
  tolerance: {value: 0.05, reason: "one significant digit"}
  ours: {table: results/x.csv, column: lower}
- id: C2
  location: {section: "5"}
  group: Section 5
  statement: "as shown in [16]"
  kind: not_checkable
"""


def test_a_valid_claims_file_loads(tmp_path):
    path = tmp_path / "claims.yaml"
    path.write_text(GOOD)
    entries = load_claims(path)
    assert [e.claim_id for e in entries] == ["C1", "C2"]
    assert entries[0].tolerance == 0.05 and entries[0].location_text == "figure 1"
    assert entries[0].expected == 0.4


@pytest.mark.parametrize("edit, field", [
    (("tolerance: {value: 0.05, reason: \"one significant digit\"}", "tolerance: {value: 0.05}"), "tolerance.reason"),
    (("kind: numeric", "kind: numerical"), "kind"),
    (("  ours: {table: results/x.csv, column: lower}\n", ""), "ours"),
    (("paper_value: 0.4", "paper_value: about"), "paper_value"),
    (("  location: {figure: \"1\"}\n", ""), "location"),
])
def test_a_malformed_claims_file_is_rejected_naming_file_entry_and_field(tmp_path, edit, field):
    path = tmp_path / "claims.yaml"
    path.write_text(GOOD.replace(*edit, 1))
    with pytest.raises(ConfigError) as info:
        load_claims(path)
    message = str(info.value)
    assert str(path) in message and "'C1'" in message and repr(field) in message


def test_duplicate_ids_are_rejected(tmp_path):
    path = tmp_path / "claims.yaml"
    path.write_text(GOOD.replace("id: C2", "id: C1"))
    with pytest.raises(ConfigError, match="duplicate id 'C1'"):
        load_claims(path)


# ----------------------------------------------------------------------------- the four data files together
PAPER = {
    "claims.yaml": """
- id: C1
  location: {figure: "1"}
  group: Fig 1
  statement: "s_k converges to about 0.4"
  kind: numeric
  paper_value: 0.4
  tolerance: {value: 0.05, reason: "one significant digit"}
  ours: {quantity: s_limit}
  depends_on: [horizon]
  nominal: "horizon 200"
- id: C2
  location: {section: "4"}
  group: Section 4
  statement: "the filter is stable"
  kind: boolean
  paper_value: true
  tolerance: {reason: "certified eigenvalue bound below 1"}
  ours: {table: results/p/stab.csv, column: stable, where: {case: a}}
- id: C3
  location: {equation: "12"}
  group: Section 4
  statement: "the gain is 2.5"
  kind: numeric
  paper_value: 2.5
  tolerance: {value: 0.01, reason: "two printed decimals"}
  ours: {quantity: gain}
  erratum_id: E1
- id: C4
  location: {section: "5"}
  group: Section 5
  statement: "as in [16]"
  kind: not_checkable
""",
    "errata.yaml": """
- id: E1
  location: eq (12)
  kind: equation
  printed: "K = 2.5"
  corrected: "K = 1.5"
  impact: "the gain and every MSE that uses it"
- id: E2
  location: Sec. 2
  kind: notation
  printed: "P_k"
  corrected: "Sigma_k"
  impact: "none (a name)"
""",
    "reconstructions.yaml": """
- key: horizon
  reason: "the paper does not say how long it ran"
  range: "100 to 400 steps"
""",
    "findings.yaml": """
- id: F1
  statement: "the printed gain is worse than no filter, by a factor of about 3"
  kind: numeric
  asserted: 3.0
  rule: {value: 0.5, reason: "'about 3': half a unit of the one digit stated", source: {kind: effect_size, ref: "a factor of 3 set before the runs"}}
  quantity: gain_vs_none
  evidence_quantities: [gain]
  depends_on: [horizon]
  prior_work: "none found (searched: Google Scholar 'gain scheduled filter printed gains', the paper's citations)"
  table: results/p/gains.csv
  figure: fig1
- id: F2
  statement: "the MSE is finite because the gain is below 2"
  kind: boolean
  asserted: true
  rule: {reason: "a certified bound, exact"}
  quantity: mse_finite
  evidence_quantities: [mse_finite, gain]
  depends_on: []
  asserts_cause: true
  cause: {variant: "gain=2.5", reason: "with the printed gain 2.5 > 2 the MSE diverges", control: {holds_fixed: "the plant and the noise", changes: "only the gain"}}
  prior_work: "Sinopoli et al. 2004 (IEEE TAC 49(9)), Theorem 2"
  known: true
  table: results/p/mse.csv
""",
}


def registry_text(findings_yaml: str) -> str:
    """A findings.lock registering the rules of ``findings_yaml`` as written."""
    import yaml

    from netrepro.judging.paperdata import registered_fields, rule_hash

    return "".join(f'{e["id"]}: {{rule: "{rule_hash(registered_fields(e))}", registered: "2026-12-02", '
                   f'commit: "fixture"}}\n' for e in yaml.safe_load(findings_yaml))


def write_paper(tmp_path, **edits):
    """The synthetic paper's four data files (with ``edits``) and the registry of its unedited findings."""
    for name, text in PAPER.items():
        for old, new in edits.get(name.split(".")[0], []):
            assert old in text, old
            text = text.replace(old, new, 1)
        (tmp_path / name).write_text(text)
    (tmp_path / "findings.lock").write_text(registry_text(PAPER["findings.yaml"]))
    return tmp_path


def test_a_valid_paper_loads_with_its_findings(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    assert [c.claim_id for c in data.claims] == ["C1", "C2", "C3", "C4"]
    f1, f2 = data.findings
    assert isinstance(f1, FindingEntry) and (f1.kind, f1.expected, f1.tolerance) == ("numeric", 3.0, 0.5)
    # the judged quantity is one of the evidence quantities, first, and never twice
    assert f1.evidence_quantities == ("gain_vs_none", "gain") and f2.evidence_quantities == ("mse_finite", "gain")
    assert f1.depends_on == ("horizon",) and not f1.asserts_cause and not f1.known and f1.cause == {}
    assert f2.asserts_cause and f2.cause["variant"] == "gain=2.5" and f2.known
    assert data.tables_read() == ["results/p/stab.csv"]


@pytest.mark.parametrize("file, edit, message", [
    ("claims", ("depends_on: [horizon]", "depends_on: [horizn]"), "'depends_on' names 'horizn'"),
    ("claims", ("erratum_id: E1", "erratum_id: E9"), "'erratum_id' names 'E9'"),
    ("claims", ("  group: Section 5\n", ""), "entry 3 (id 'C4'): field 'group' is required"),
    ("claims", ("  nominal: \"horizon 200\"", "  nominal: \"horizon 200\"\n  tolerence: 3"), "field 'tolerence' is not a known"),
    ("claims", ("kind: boolean\n  paper_value: true", "kind: boolean\n  paper_value: 1"), "'paper_value' must be true or false"),
    ("claims", ("tolerance: {reason: \"certified eigenvalue bound below 1\"}", "tolerance: {reason: \"\"}"), "C2"),
    ("errata", ("kind: notation", "kind: spelling"), "entry 1 (id 'E2'): field 'kind' 'spelling' is not one of"),
    ("errata", ("  impact: \"none (a name)\"\n", ""), "entry 1 (id 'E2'): field 'impact' is required"),
    ("reconstructions", ("  reason: \"the paper does not say how long it ran\"\n", ""), "field 'reason' is required"),
    ("findings", ("  table: results/p/gains.csv\n", ""), "entry 0 (id 'F1'): field 'table' is required"),
    ("findings", ("depends_on: [horizon]", "depends_on: [horizn]"), "entry 0 (id 'F1'): field 'depends_on' names 'horizn'"),
])
def test_malformed_data_files_are_rejected_naming_file_entry_and_field(tmp_path, file, edit, message):
    root = write_paper(tmp_path, **{file: [edit]})
    with pytest.raises(ConfigError) as info:
        load_paper_data("p", root)
    assert str(root / f"{file}.yaml") in str(info.value) and message in str(info.value)


# ----------------------------------------------------------------------------- the findings gate (issue 27)
F1_RULE = ("  rule: {value: 0.5, reason: \"'about 3': half a unit of the one digit stated\", source: {kind: effect_size, "
           "ref: \"a factor of 3 set before the runs\"}}\n")
F1_PRIOR = ("  prior_work: \"none found (searched: Google Scholar 'gain scheduled filter printed gains', "
            "the paper's citations)\"\n")


@pytest.mark.parametrize("edit, field", [
    ((F1_RULE, ""), "rule"),
    (("  evidence_quantities: [gain]\n", ""), "evidence_quantities"),
    (("  evidence_quantities: [gain]\n", "  evidence_quantities: []\n"), "evidence_quantities"),
    ((F1_PRIOR, ""), "prior_work"),
    ((F1_PRIOR, "  prior_work: \"\"\n"), "prior_work"),
    (("  depends_on: [horizon]\n", ""), "depends_on"),
    (("  kind: numeric\n", ""), "kind"),
    (("  asserted: 3.0\n", ""), "asserted"),
    (("  quantity: gain_vs_none\n", ""), "quantity"),
    ((F1_RULE, "  rule: {value: 0.5}\n"), "rule.reason"),
    ((F1_RULE, "  rule: {value: 0.5, reason: \"  \"}\n"), "rule.reason"),
    ((F1_RULE, "  rule: {reason: \"a digit\"}\n"), "rule.value"),
    (("  asserted: 3.0\n", "  asserted: true\n"), "asserted"),
    ((F1_PRIOR, "  prior_work: \"none found\"\n"), "prior_work"),
    ((F1_PRIOR, "  prior_work: \"none found (searched: Scholar)\"\n  known: true\n"), "prior_work"),
    (("  statement: \"the printed gain is worse", "  statement: \"because of its sign, the printed gain is worse"),
     "asserts_cause"),
    (("  figure: fig1\n", "  figure: fig1\n  asserts_cause: true\n"), "cause"),
])
def test_a_finding_without_its_gate_fields_is_rejected(tmp_path, edit, field):
    """A finding lacking a rule, evidence, prior work, or the variant that tests a stated cause fails to load."""
    root = write_paper(tmp_path, findings=[edit])
    with pytest.raises(ConfigError) as info:
        load_findings(root / "findings.yaml")
    message = str(info.value)
    assert str(root / "findings.yaml") in message and "entry 0 (id 'F1')" in message and repr(field) in message


def test_cause_and_its_declaration_must_agree(tmp_path):
    root = write_paper(tmp_path, findings=[("  asserts_cause: true\n", "  asserts_cause: false\n")])
    with pytest.raises(ConfigError, match="entry 1 .id 'F2'.: field 'cause' is given but asserts_cause is false"):
        load_findings(root / "findings.yaml")
    # a statement with causal wording that explicitly asserts no cause loads
    root = write_paper(tmp_path, findings=[
        ("  statement: \"the printed gain is worse", "  statement: \"not because of its sign, the printed gain is worse"),
        ("  figure: fig1\n", "  figure: fig1\n  asserts_cause: false\n")])
    assert not load_findings(root / "findings.yaml")[0].asserts_cause


@pytest.mark.parametrize("text, causal", [
    ("the loss comes from decentralization", True), ("worse due to the sign", True), ("H < 0 causes it", True),
    ("this explains D2", True), ("the designs coincide", False), ("the sequence drives to zero because", True),
    ("a becauseway", False),
])
def test_causal_wording(text, causal):
    assert bool(CAUSAL_WORDING.search(text)) is causal


# ----------------------------------------------------------------------------- the papers' own files
SLUGS = sorted(p.parent.name for p in Path(__file__).resolve().parents[1].glob("src/netrepro/papers/*/claims.yaml"))


@pytest.mark.parametrize("slug", SLUGS)
def test_every_finding_of_a_paper_has_a_rule_evidence_and_prior_work(slug):
    """Every real findings.yaml passes the gate (issues 27, 37): a judged finding has a decision rule with its
    reason (a numeric one, the source of its threshold), an observation has none; every finding has at least one
    evidence quantity, depends_on, prior work (a citation, or 'none found' with what was searched), and a causal
    one its isolating control."""
    data = load_paper_data(slug)
    for f in data.findings:
        assert f.evidence_quantities and f.prior_work, f.finding_id
        assert bool(f.rule_reason) != f.observation, f.finding_id
        assert f.kind != "numeric" or f.source, f.finding_id
        assert not f.asserts_cause or {"holds_fixed", "changes"} <= set(f.cause.get("control", {})), f.finding_id


# ----------------------------------------------------------------------------- settings ('at') of errata (issue 29)
E1_AT = "  impact: \"the gain and every MSE that uses it\"\n"


def test_errata_settings_load_as_a_dict_and_every_entry_has_one(tmp_path):
    root = write_paper(tmp_path, errata=[(E1_AT, E1_AT + "  at: {p: 0.5, K: 200}\n")])
    data = load_paper_data("p", root)
    assert [e["at"] for e in data.errata] == [{"p": 0.5, "K": 200}, {}]
    assert load_errata(root / "errata.yaml")[0]["at"] == {"p": 0.5, "K": 200}
    assert load_errata(tmp_path / "missing.yaml") == []


def test_errata_settings_that_are_not_a_mapping_are_rejected_naming_the_field(tmp_path):
    root = write_paper(tmp_path, errata=[(E1_AT, E1_AT + "  at: 200\n")])
    with pytest.raises(ConfigError, match=r"entry 0 \(id 'E1'\): field 'at' 200 is not of type 'object'"):
        load_paper_data("p", root)


def test_settings_gather_claims_findings_and_errata_by_id(tmp_path):
    root = write_paper(tmp_path, errata=[(E1_AT, E1_AT + "  at: {K: 200}\n")],
                       claims=[("  nominal: \"horizon 200\"", "  nominal: \"horizon 200\"\n  at: {a: 1.5}")],
                       findings=[("  figure: fig1\n", "  figure: fig1\n  at: {snr_db: [0, 5]}\n")])
    assert load_paper_data("p", root).settings() == {"C1": {"a": 1.5}, "F1": {"snr_db": [0, 5]}, "E1": {"K": 200}}


def test_an_id_with_settings_in_two_files_is_refused(tmp_path):
    """Ids are unique across the four files (issue 38), so the evidence step's settings by id are unambiguous."""
    root = write_paper(tmp_path, errata=[(E1_AT, E1_AT + "  at: {K: 200}\n")],
                       claims=[("- id: C3", "- id: E1"), ("  erratum_id: E1\n", "  at: {a: 1}\n")])
    with pytest.raises(ConfigError, match="id 'E1' of errata.yaml clashes with 'E1' of claims.yaml"):
        load_paper_data("p", root)
    (tmp_path / "ok").mkdir()
    data = load_paper_data("p", write_paper(tmp_path / "ok"))
    clash = type(data)("p", [replace(data.claims[0], claim_id="E1", at={"a": 1})], [dict(data.errata[0], at={"K": 2})],
                       data.reconstructions, data.findings)
    with pytest.raises(ConfigError, match="id 'E1' has settings .* in both claims.yaml and errata.yaml"):
        clash.settings()
