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
