"""The shared verdict function and the claims-file validation (issue 15)."""

import pandas as pd
import pytest

from netrepro.errors import ConfigError
from netrepro.verdicts import VERDICTS, ClaimEntry, judge, load_claims, lookup


def numeric(tol=0.05, relative=False, paper=0.4, erratum=""):
    return ClaimEntry("C1", {"figure": "1"}, "s_k converges to about 0.4", "numeric", paper_value=paper,
                      tolerance=tol, relative=relative, tolerance_reason="half a unit of the last digit",
                      ours={"table": "t.csv", "column": "x"}, erratum_id=erratum)


@pytest.mark.parametrize("value, verdict", [(0.45, "reproduced"), (0.35, "reproduced"), (0.4500001, "differs"),
                                            (float("nan"), "differs"), (float("inf"), "differs")])
def test_tolerance_edges_are_inclusive_and_nonfinite_never_agrees(value, verdict):
    assert judge(numeric(), value).verdict == verdict


def test_relative_tolerance_scales_with_the_paper_value():
    entry = numeric(tol=0.1, relative=True, paper=-20.0)
    assert judge(entry, -22.0).verdict == "reproduced"
    assert judge(entry, -22.1).verdict == "differs"


def test_a_verdict_that_flips_inside_the_range_is_conditional_and_not_robust():
    result = judge(numeric(), 0.42, {"horizon=200": 0.43, "horizon=800": 0.6})
    assert (result.verdict, result.robust) == ("conditional", "no")
    assert "nominal settings" in result.condition and "horizon=200" in result.condition
    holds, fails = result.condition.split("; not for ")
    assert "horizon=800" not in holds and "horizon=800" in fails
    # holds nowhere at the nominal setting but at one variant: still conditional
    assert judge(numeric(), 0.6, {"a": 0.41}).verdict == "conditional"
    stable = judge(numeric(), 0.42, {"a": 0.41, "b": 0.44})
    assert (stable.verdict, stable.robust) == ("reproduced", "yes")


def test_erratum_only_when_the_disagreement_is_explained():
    assert judge(numeric(erratum="E3"), 0.9).verdict == "erratum"
    assert judge(numeric(erratum="E3"), 0.41).verdict == "reproduced"
    assert judge(numeric(), 0.9).verdict == "differs"


def test_untestable_kinds_and_booleans():
    for kind in ("not_checkable", "not_identifiable", "context"):
        assert judge(ClaimEntry("X", {"section": "1"}, "s", kind), None).verdict == kind
    flag = ClaimEntry("B", {"section": "2"}, "bounded", "boolean", paper_value=True, ours={"table": "t"})
    assert judge(flag, True).verdict == "reproduced"
    assert judge(flag, False).verdict == "differs"
    assert set(VERDICTS) == {"reproduced", "conditional", "differs", "erratum", "not_checkable",
                             "not_identifiable", "context"}


def test_lookup_selects_exactly_one_row():
    tables = {"t.csv": pd.DataFrame({"k": [1, 2, 2], "case": ["a", "a", "b"], "x": [0.1, 0.2, 0.3]})}
    assert lookup({"table": "t.csv", "column": "x", "where": {"k": 2, "case": "b"}}, tables) == 0.3
    with pytest.raises(ConfigError, match="selects 2 rows"):
        lookup({"table": "t.csv", "column": "x", "where": {"k": 2}}, tables)
    with pytest.raises(ConfigError, match="no step produced"):
        lookup({"table": "u.csv", "column": "x"}, tables)
    with pytest.raises(ConfigError, match="column 'y'"):
        lookup({"table": "t.csv", "column": "y"}, tables)


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
import math  # noqa: E402
from pathlib import Path  # noqa: E402

from netrepro.errors import InputError  # noqa: E402
from netrepro.verdicts import (  # noqa: E402
    CLAIM_COLUMNS, claims_table, errata_table, evidence_frame, findings_table, load_paper_data,
    reconstructions_table)

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
  statement: "the printed gain is worse than no filter"
  quantity: gain_vs_none
  table: results/p/gains.csv
  figure: fig1
""",
}


def write_paper(tmp_path, **edits):
    for name, text in PAPER.items():
        for old, new in edits.get(name.split(".")[0], []):
            assert old in text, old
            text = text.replace(old, new)
        (tmp_path / name).write_text(text)
    return tmp_path


def evidence(rows):
    frame = evidence_frame(rows)
    return {q: {v: (val, note) for v, val, note in zip(g["variant"], g["value"], g["note"])}
            for q, g in frame.groupby("quantity")}


EVIDENCE = [
    dict(quantity="s_limit", value=0.44, note="closed form"),
    dict(quantity="s_limit", variant="horizon 100", value=0.445),
    dict(quantity="s_limit", variant="horizon 400", value=0.43),
    dict(quantity="gain", value=1.5),
    dict(quantity="gain_vs_none", value=3.2, note="MSE ratio at k = 50"),
    dict(quantity="E1.residual_printed", value=0.7, note="max |K P - ...|"),
    dict(quantity="E1.residual_corrected", value=1e-16),
    dict(quantity="reconstruction.horizon", value=200, note="s_k settles within 1e-6 by k = 60"),
]
TABLES = {"results/p/stab.csv": pd.DataFrame({"case": ["a", "b"], "stable": [True, False]})}


def test_one_paper_from_data_files_to_tables(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    ev = evidence(EVIDENCE)
    table = claims_table(data, TABLES, ev).set_index("claim_id")
    assert list(claims_table(data, TABLES, ev).columns) == CLAIM_COLUMNS
    assert table.loc["C1", ["verdict", "robust"]].tolist() == ["reproduced", "yes"]
    assert "horizon 100: 0.445" in table.loc["C1", "note"] and table.loc["C1", "depends_on"] == "horizon"
    assert table.loc["C2", ["verdict", "robust", "tolerance"]].tolist() == ["reproduced", "", "exact"]
    assert table.loc["C3", ["verdict", "erratum_id"]].tolist() == ["erratum", "E1"]
    assert table.loc["C4", "verdict"] == "not_checkable" and table.loc["C1", "location"] == "figure 1"
    errata = errata_table(data, ev).set_index("erratum_id")
    assert errata.loc["E1", "residual_printed"] == 0.7 and math.isclose(errata.loc["E1", "residual_corrected"], 1e-16)
    assert errata.loc["E1", "demonstration"] == "max |K P - ...|" and errata.loc["E2", "kind"] == "notation"
    recon = reconstructions_table(data, ev).iloc[0]
    assert (recon["value"], recon["range"]) == (200, "100 to 400 steps") and "settles" in recon["sensitivity"]
    finding = findings_table(data, ev).iloc[0]
    assert finding["evidence"] == "3.2; MSE ratio at k = 50" and finding["figure"] == "fig1"


def test_a_flip_across_the_reconstruction_range_is_conditional(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    rows = [r if r.get("variant") != "horizon 100" else dict(r, value=0.52) for r in EVIDENCE]
    row = claims_table(data, TABLES, evidence(rows)).set_index("claim_id").loc["C1"]
    assert (row["verdict"], row["robust"]) == ("conditional", "no")
    assert row["condition"] == "holds for horizon 200; horizon 400; not for horizon 100"


def test_a_claim_that_depends_on_a_reconstruction_needs_variants(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    rows = [r for r in EVIDENCE if r.get("variant") is None]
    with pytest.raises(InputError, match="C1 depends on .'horizon'. but has no variants"):
        claims_table(data, TABLES, evidence(rows))
    with pytest.raises(InputError, match="quantity 'gain' is not in"):
        claims_table(data, TABLES, evidence([r for r in EVIDENCE if r["quantity"] != "gain"]))


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
])
def test_malformed_data_files_are_rejected_naming_file_entry_and_field(tmp_path, file, edit, message):
    root = write_paper(tmp_path, **{file: [edit]})
    with pytest.raises(ConfigError) as info:
        load_paper_data("p", root)
    assert str(root / f"{file}.yaml") in str(info.value) and message in str(info.value)


# ----------------------------------------------------------------------------- the papers' own files
REFERENCE = Path(__file__).resolve().parent / "reference"
SLUGS = sorted(p.parent.name for p in Path(__file__).resolve().parents[1].glob("src/netrepro/papers/*/claims.yaml"))


@pytest.mark.parametrize("slug", SLUGS)
def test_every_claim_of_a_paper_points_to_a_quantity_a_step_produces(slug):
    """Each claim has a tolerance reason and resolves against the committed reference tables."""
    from netrepro.verdicts import read_evidence, referenced_tables

    data = load_paper_data(slug)
    for entry in data.claims:
        if entry.kind in ("numeric", "boolean"):
            assert entry.tolerance_reason, entry.claim_id
    ev = read_evidence(REFERENCE / "evidence" / f"{slug}.csv")
    tables = {t: pd.read_csv(REFERENCE / Path(t).relative_to("results")) for t in referenced_tables(slug)}
    table = claims_table(data, tables, ev)  # raises for a quantity no step produces
    reference = pd.read_csv(REFERENCE / "claims" / f"{slug}.csv")
    assert table["verdict"].tolist() == reference["verdict"].tolist()
    for f in data.findings:
        assert (REFERENCE / Path(f["table"]).relative_to("results")).is_file(), f["id"]


def test_a_long_condition_is_counted_not_spelled_out():
    variants = {f"agent {i}": (0.41 if i % 3 else 0.9) for i in range(30)}
    result = judge(numeric(), 0.42, variants)
    assert result.verdict == "conditional"
    assert result.condition.startswith("holds at 21 of 31 settings: nominal settings; agent 1; agent 2;")
    assert "and 15 more (the note lists them)" in result.condition
    assert "not for agent 0; agent 3;" in result.condition and "and 4 more" in result.condition


@pytest.mark.parametrize("slug", SLUGS)
def test_no_statement_or_printed_form_is_typed_in_python(slug):
    """The paper's side lives only in the data files: no statement or printed form is repeated in the code."""
    data = load_paper_data(slug)
    texts = [e.statement for e in data.claims] + [e["printed"] for e in data.errata] + \
            [e.tolerance_reason for e in data.claims]
    sources = "\n".join(p.read_text() for p in Path(__file__).resolve().parents[1].glob("src/netrepro/**/*.py"))
    typed = [t for t in texts if len(t) >= 25 and t in sources]
    assert not typed, typed
