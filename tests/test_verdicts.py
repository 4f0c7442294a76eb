"""The shared verdict function and the tables it builds (issues 15, 27); the loader is tested in test_paperdata."""

import pandas as pd
import pytest

from netrepro.errors import ConfigError
from netrepro.judging.paperdata import ClaimEntry, FindingEntry
from netrepro.judging.verdicts import FINDING_VERDICTS, VERDICTS, judge, lookup, split_variants, variant_key


def numeric(tol=0.05, relative=False, paper=0.4, erratum="", depends_on=("horizon",)):
    return ClaimEntry("C1", {"figure": "1"}, "s_k converges to about 0.4", "numeric", paper_value=paper,
                      tolerance=tol, relative=relative, tolerance_reason="half a unit of the last digit",
                      ours={"table": "t.csv", "column": "x"}, erratum_id=erratum, depends_on=depends_on)


@pytest.mark.parametrize("value, verdict", [(0.45, "reproduced"), (0.35, "reproduced"), (0.4500001, "differs"),
                                            (float("nan"), "undecided"), (float("inf"), "differs")])
def test_tolerance_edges_are_inclusive_and_nonfinite_never_agrees(value, verdict):
    """NaN is no measurement (undecided, issue 37); an infinite value is a decided disagreement."""
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
    assert judge(numeric(), 0.6, {"horizon=100": 0.41}).verdict == "conditional"
    stable = judge(numeric(), 0.42, {"horizon=100": 0.41, "horizon: to the end": 0.44})
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
    assert set(VERDICTS) == {"reproduced", "conditional", "differs", "erratum", "undecided", "not_checkable",
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


# ----------------------------------------------------------------------------- only declared ranges decide
@pytest.mark.parametrize("label, key", [
    ("horizon=200", "horizon"), ("scalar.horizon=200", "scalar.horizon"), ("sigma2 = 0.25", "sigma2"),
    ("reading: exact E(p_k) on the right-hand side", "reading"), ("realisation=S21=I", "realisation"),
    ("gamma3=[0;HC], sigma2=1", "gamma3"), ("last k only (k=60)", None), ("agent 0, H=200", None),
    ("alpha -> 1, SNR = -40 dB", None), ("limit k->inf", None), ("scenario fig2", None), ("", None),
])
def test_variant_labels_parse_to_their_key(label, key):
    assert variant_key(label) == key


def test_only_variants_of_the_declared_ranges_decide_the_verdict():
    """Issue 27: a re-reading (a label outside every declared range) is listed, it never decides."""
    readings = {"last k only (k=60)": 0.9, "reading: exact E(p_k)": 0.9, "sigma2=3": 0.9}
    result = judge(numeric(), 0.42, {"horizon=100": 0.43, **readings})
    assert (result.verdict, result.robust, result.condition) == ("reproduced", "yes", "")
    assert result.readings == tuple(readings)
    # the same value under a declared key decides
    flipped = judge(numeric(), 0.42, {"horizon=100": 0.43, "horizon: to the end": 0.9, **readings})
    assert (flipped.verdict, flipped.robust) == ("conditional", "no")
    assert "horizon: to the end" in flipped.condition and "last k only" not in flipped.condition
    # a claim that disagrees at the nominal settings and agrees only under re-readings differs, robustly
    differs = judge(numeric(), 0.9, {"horizon=100": 0.8, "last k only (k=60)": 0.41})
    assert (differs.verdict, differs.robust) == ("differs", "yes")
    # with no declared variant at all, robust is unknown ("")
    assert judge(numeric(depends_on=()), 0.42, {"horizon=100": 0.9}).robust == ""
    declared, other = split_variants(("horizon",), {"horizon=1": 1, "horizonx=2": 2, "h: 3": 3})
    assert list(declared) == ["horizon=1"] and list(other) == ["horizonx=2", "h: 3"]


def finding(kind="numeric", asserted=3.0, tol=0.5, depends_on=("horizon",)):
    return FindingEntry("F1", "the printed gain is about 3 times worse", kind, asserted, "gain_vs_none",
                        "half a unit of the digit", "none found (searched: x)", "results/p/g.csv", tolerance=tol,
                        evidence_quantities=("gain_vs_none",), depends_on=depends_on)


def test_findings_are_judged_by_the_same_function():
    # the same decision as for a claim with that value and tolerance, in the findings' vocabulary
    claim, variants = numeric(tol=0.5, paper=3.0), {"horizon=100": 3.6, "horizon=400": 2.9}
    assert (judge(claim, 3.4, variants).condition, judge(claim, 3.4, variants).verdict) == (
        judge(finding(), 3.4, variants).condition, "conditional")
    holds = judge(finding(), 3.4, {"horizon=100": 2.6, "another reading": 9.0})
    assert (holds.verdict, holds.robust, holds.readings) == ("holds", "yes", ("another reading",))
    cond = judge(finding(), 3.4, {"horizon=100": 3.6})
    assert (cond.verdict, cond.robust) == ("conditional", "no")
    assert cond.condition == "holds for nominal settings; not for horizon=100"
    assert judge(finding(), 3.6, {"horizon=100": 4.0}).verdict == "fails"
    assert judge(finding(), float("nan")).verdict == "undecided"
    flag = finding("boolean", True, 0.0)
    assert judge(flag, True).verdict == "holds" and judge(flag, False).verdict == "fails"
    assert set(FINDING_VERDICTS) == {"holds", "conditional", "fails", "undecided", "retracted", "observed"}


# ----------------------------------------------------------------------------- the four data files together
import math  # noqa: E402
from pathlib import Path  # noqa: E402

from netrepro.errors import InputError  # noqa: E402
from netrepro.judging.paperdata import load_paper_data  # noqa: E402
from netrepro.judging.verdicts import (  # noqa: E402
    CLAIM_COLUMNS, FINDING_COLUMNS, claims_table, errata_table, evidence_frame, findings_table, reconstructions_table)

from .test_paperdata import write_paper  # noqa: E402  (the synthetic paper's four data files)


def evidence(rows):
    frame = evidence_frame(rows)
    return {q: {v: (val, note) for v, val, note in zip(g["variant"], g["value"], g["note"])}
            for q, g in frame.groupby("quantity")}


EVIDENCE = [
    dict(quantity="s_limit", value=0.44, note="closed form"),
    dict(quantity="s_limit", variant="horizon=100", value=0.445),
    dict(quantity="s_limit", variant="horizon=400", value=0.43),
    dict(quantity="s_limit", variant="limit k->inf", value=0.47),
    dict(quantity="gain", value=1.5),
    dict(quantity="gain_vs_none", value=3.2, note="MSE ratio at k = 50"),
    dict(quantity="gain_vs_none", variant="horizon=100", value=2.9),
    dict(quantity="gain_vs_none", variant="horizon=400", value=3.4),
    dict(quantity="gain_vs_none", variant="last k only", value=9.0),
    dict(quantity="mse_finite", value=True, note="certified bound 0.93 < 1"),
    dict(quantity="mse_finite", variant="gain=2.5", value=False),
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
    assert table.loc["C1", "note"] == ("closed form; across the range: horizon=100: 0.445; horizon=400: 0.43; "
                                       "re-readings (outside any declared range; they decide nothing): "
                                       "limit k->inf: 0.47 (disagrees)")
    assert table.loc["C1", "depends_on"] == "horizon"
    assert table.loc["C2", ["verdict", "robust", "tolerance"]].tolist() == ["reproduced", "", "exact"]
    assert table.loc["C3", ["verdict", "erratum_id"]].tolist() == ["erratum", "E1"]
    assert table.loc["C4", "verdict"] == "not_checkable" and table.loc["C1", "location"] == "figure 1"
    errata = errata_table(data, ev).set_index("erratum_id")
    assert errata.loc["E1", "residual_printed"] == 0.7 and math.isclose(errata.loc["E1", "residual_corrected"], 1e-16)
    assert errata.loc["E1", "demonstration"] == "max |K P - ...|" and errata.loc["E2", "kind"] == "notation"
    recon = reconstructions_table(data, ev).iloc[0]
    assert (recon["value"], recon["range"]) == (200, "100 to 400 steps") and "settles" in recon["sensitivity"]


def test_the_findings_table_judges_every_finding(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    frame = findings_table(data, evidence(EVIDENCE))
    assert list(frame.columns) == FINDING_COLUMNS
    f1, f2 = frame.set_index("finding_id").loc["F1"], frame.set_index("finding_id").loc["F2"]
    # F1 asserts 3 +- 0.5: 3.2 nominal, 2.9 and 3.4 across the horizon range; 'last k only' (9.0) is a re-reading
    assert (f1["verdict"], f1["robust"], f1["condition"]) == ("holds", "yes", "")
    assert f1["evidence"] == ("3.2; MSE ratio at k = 50; across the range: horizon=100: 2.9; horizon=400: 3.4; "
                              "re-readings (outside any declared range; they decide nothing): last k only: 9 (fails); "
                              "also rests on gain: 1.5")
    assert f1["rule"] == ("3 within 0.5: 'about 3': half a unit of the one digit stated [threshold from effect size: "
                          "a factor of 3 set before the runs]")
    assert (f1["evidence_quantities"], f1["depends_on"], f1["known"], f1["cause_variant"]) == (
        "gain_vs_none, gain", "horizon", "no", "")
    assert f1["prior_work"].startswith("none found (searched:") and f1["figure"] == "fig1"
    # F2: a boolean, known, causal finding; its cause variant (a variant of its quantity) is a re-reading
    assert (f2["verdict"], f2["robust"], f2["known"], f2["cause_variant"]) == ("holds", "", "yes", "gain=2.5")
    assert f2["rule"] == "true, exact: a certified bound, exact" and f2["depends_on"] == ""


def test_a_finding_that_changes_inside_a_declared_range_gets_its_condition(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    rows = [dict(r, value=3.6) if (r["quantity"], r.get("variant")) == ("gain_vs_none", "horizon=400") else r
            for r in EVIDENCE]
    f1 = findings_table(data, evidence(rows)).iloc[0]
    assert (f1["verdict"], f1["robust"]) == ("conditional", "no")
    assert f1["condition"] == "holds for nominal settings; horizon=100; not for horizon=400"
    rows = [dict(r, value=5.0) if r["quantity"] == "gain_vs_none" and r.get("variant") != "last k only" else r
            for r in EVIDENCE]
    assert findings_table(data, evidence(rows)).iloc[0]["verdict"] == "fails"


@pytest.mark.parametrize("drop, message", [
    (("gain", None), "finding p/F1: evidence quantity 'gain' is not in results/evidence/p.csv"),
    (("gain_vs_none", None), "finding p/F1: quantity 'gain_vs_none' has no 'nominal' row"),
    (("mse_finite", "gain=2.5"), "finding p/F2: cause variant 'gain=2.5' is neither an evidence quantity nor a variant"),
    (("gain_vs_none", "horizon"), "finding p/F1 depends on ['horizon'] but has no variants across their declared range"),
])
def test_a_finding_whose_evidence_is_missing_is_rejected_naming_finding_and_quantity(tmp_path, drop, message):
    data = load_paper_data("p", write_paper(tmp_path))
    quantity, variant = drop
    rows = [r for r in EVIDENCE if not (r["quantity"] == quantity and (variant is None and r.get("variant") is None
                                                                       or variant and variant in r.get("variant", "")))]
    assert len(rows) < len(EVIDENCE)
    with pytest.raises(InputError) as info:
        findings_table(data, evidence(rows))
    assert message in str(info.value)


def test_a_flip_across_the_reconstruction_range_is_conditional(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path))
    rows = [r if r.get("variant") != "horizon=100" or r["quantity"] != "s_limit" else dict(r, value=0.52)
            for r in EVIDENCE]
    row = claims_table(data, TABLES, evidence(rows)).set_index("claim_id").loc["C1"]
    assert (row["verdict"], row["robust"]) == ("conditional", "no")
    assert row["condition"] == "holds for horizon 200; horizon=400; not for horizon=100"


def test_a_claim_that_depends_on_a_reconstruction_needs_variants_of_its_range(tmp_path):
    data = load_paper_data("p", write_paper(tmp_path, claims=[("erratum_id: E1", "erratum_id: E1\n  depends_on: [horizon]")]))
    rows = [r for r in EVIDENCE if r.get("variant") in (None, "limit k->inf")]
    with pytest.raises(InputError) as info:
        claims_table(data, TABLES, evidence(rows))
    lines = str(info.value).splitlines()  # every such claim in one error
    assert lines[0] == ("claim p/C1 depends on ['horizon'] but has no variants across their declared range "
                        "(its variants ['limit k->inf'] are re-readings: no label '<key>=...' with a key of depends_on)")
    assert lines[1].strip() == "claim p/C3 depends on ['horizon'] but has no variants across their declared range"
    with pytest.raises(InputError, match="quantity 'gain' is not in"):
        claims_table(data, TABLES, evidence([r for r in EVIDENCE if r["quantity"] != "gain"]))


def test_the_step_writes_the_four_tables(tmp_path, monkeypatch):
    from netrepro.judging.verdicts import verdicts_step

    root = write_paper(tmp_path)
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "evidence.csv"
    evidence_frame(EVIDENCE).to_csv(path, index=False)
    (tmp_path / "results" / "p").mkdir(parents=True)
    TABLES["results/p/stab.csv"].to_csv("results/p/stab.csv", index=False)
    with pytest.raises(InputError, match="read tables that are not inputs of the rule"):
        verdicts_step({"slug": "p"}, {"claims_file": root / "claims.yaml", "evidence": path, "tables": []}, {})
    out = verdicts_step({"slug": "p"}, {"claims_file": root / "claims.yaml", "evidence": path,
                                        "tables": "results/p/stab.csv"}, {})
    assert set(out) == {"table", "errata", "reconstructions", "findings"}
    assert out["findings"]["verdict"].tolist() == ["holds", "holds"]


# ----------------------------------------------------------------------------- the papers' own files
REFERENCE = Path(__file__).resolve().parent / "reference"
SLUGS = sorted(p.parent.name for p in Path(__file__).resolve().parents[1].glob("src/netrepro/papers/*/claims.yaml"))


@pytest.mark.parametrize("slug", SLUGS)
def test_every_claim_of_a_paper_points_to_a_quantity_a_step_produces(slug):
    """Each claim has a tolerance reason and resolves against the committed reference tables."""
    from netrepro.judging.paperdata import referenced_tables
    from netrepro.judging.verdicts import read_evidence

    data = load_paper_data(slug)
    for entry in data.claims:
        if entry.kind in ("numeric", "boolean"):
            assert entry.tolerance_reason, entry.claim_id
    ev = read_evidence(REFERENCE / "evidence" / f"{slug}.csv")
    tables = {t: pd.read_csv(REFERENCE / Path(t).relative_to("results")) for t in referenced_tables(slug)}
    table = claims_table(data, tables, ev)  # raises for a quantity no step produces
    reference = pd.read_csv(REFERENCE / "claims" / f"{slug}.csv", dtype=str, keep_default_na=False)
    assert table["verdict"].tolist() == reference["verdict"].tolist()
    assert table["robust"].tolist() == reference["robust"].tolist()
    findings = findings_table(data, ev)  # raises for an evidence quantity no step produces
    # every finding stays in the table with the verdict of the committed build, a failing one too (issue 37)
    expected = pd.read_csv(REFERENCE / "findings" / f"{slug}.csv", dtype=str, keep_default_na=False)
    assert findings["finding_id"].tolist() == [f.finding_id for f in data.findings]
    assert dict(zip(findings["finding_id"], findings["verdict"])) == dict(zip(expected["finding_id"],
                                                                             expected["verdict"]))
    for f in data.findings:
        assert (REFERENCE / Path(f.table).relative_to("results")).is_file(), f.finding_id


def test_a_long_condition_is_counted_not_spelled_out():
    variants = {f"agent={i}": (0.41 if i % 3 else 0.9) for i in range(30)}
    result = judge(numeric(depends_on=("agent",)), 0.42, variants)
    assert result.verdict == "conditional"
    assert result.condition.startswith("holds at 21 of 31 settings: nominal settings; agent=1; agent=2;")
    assert "and 15 more (the note lists them)" in result.condition
    assert "not for agent=0; agent=3;" in result.condition and "and 4 more" in result.condition


@pytest.mark.parametrize("slug", SLUGS)
def test_no_statement_or_printed_form_is_typed_in_python(slug):
    """The paper's side lives only in the data files: no statement or printed form is repeated in the code."""
    from netrepro.pipeline.io import load_yaml
    from netrepro.judging.paperdata import paper_dir

    def entries(name):
        path = paper_dir(slug) / f"{name}.yaml"
        return (load_yaml(path.read_text()) or []) if path.is_file() else []

    claims = entries("claims")
    texts = [e["statement"] for e in claims + entries("findings")] + [e["printed"] for e in entries("errata")] + \
            [e["tolerance"]["reason"] for e in claims if "tolerance" in e]
    texts = [" ".join(str(t).split()) if "\n" in str(t) else str(t).strip() for t in texts]
    sources = "\n".join(p.read_text() for p in Path(__file__).resolve().parents[1].glob("src/netrepro/**/*.py"))
    typed = [t for t in texts if len(t) >= 25 and t in sources]
    assert not typed, typed


def test_integers_of_the_evidence_table_stay_integers(tmp_path):
    path = tmp_path / "evidence.csv"
    path.write_text("quantity,variant,value,note\nseed,nominal,20150101,\nx,nominal,2.5,\nflag,nominal,True,\n")
    from netrepro.judging.verdicts import read_evidence

    evidence = read_evidence(path)
    assert evidence["seed"]["nominal"][0] == 20150101 and isinstance(evidence["seed"]["nominal"][0], int)
    assert evidence["x"]["nominal"][0] == 2.5 and evidence["flag"]["nominal"][0] is True
