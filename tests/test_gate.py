"""The verdict gate of issue 37: undecided evidence, registered rules, findings that may fail, observations,
statements filled from the evidence, bounded tolerances."""

import math

import numpy as np
import pandas as pd
import pytest

from netrepro.errors import ConfigError, InputError
from netrepro.judging.paperdata import (ClaimEntry, FindingEntry, check_tolerance, load_paper_data, register_findings,
                                registered_fields, render_statement, rule_hash, template_fields, typed_numbers)
from netrepro.judging.summary import scorecard
from netrepro.judging.verdicts import (AGREES, DISAGREES, UNDECIDED, Cell, compare, evidence_frame, findings_table, judge,
                               read_evidence)

from .test_paperdata import PAPER, write_paper


def claim(tol=0.05, paper=0.4, kind="numeric", depends_on=("horizon",), erratum=""):
    return ClaimEntry("C1", {"figure": "1"}, "about 0.4", kind, paper_value=paper, tolerance=tol,
                      tolerance_reason="half a unit", ours={"quantity": "q"}, depends_on=depends_on,
                      erratum_id=erratum)


# ----------------------------------------------------------------------------- one comparison, three outcomes
@pytest.mark.parametrize("value, u, decided, outcome", [
    (0.42, 0.0, True, AGREES),
    (0.42, 0.03, True, AGREES),        # [0.39, 0.45] inside [0.35, 0.45]
    (0.42, 0.031, True, UNDECIDED),    # reaches past the band's edge
    (0.48, 0.04, True, UNDECIDED),     # [0.44, 0.52] straddles the edge 0.45
    (0.50, 0.04, True, DISAGREES),     # [0.46, 0.54] entirely outside
    (0.60, 0.10, True, DISAGREES),     # [0.50, 0.70] entirely outside
    (0.4167, 0.5, True, UNDECIDED),    # the capped-solver bracket of exII_thm5_q05: 100x the tolerance
    (0.42, 0.0, False, UNDECIDED),     # a missing certificate
    (float("nan"), 0.0, True, UNDECIDED),
    (0.42, float("inf"), True, UNDECIDED),
])
def test_an_interval_against_the_band(value, u, decided, outcome):
    """Interval arithmetic by hand: [value - u, value + u] against [0.35, 0.45]."""
    lo, hi = value - u, value + u
    if decided and not math.isnan(value):
        by_hand = AGREES if (lo >= 0.35 - 1e-12 and hi <= 0.45 + 1e-12) else (
            DISAGREES if (hi < 0.35 or lo > 0.45) else UNDECIDED)
        assert by_hand == outcome
    assert compare(claim(), Cell(value, "", u, decided)) == outcome


@pytest.mark.parametrize("value, outcome", [
    (True, AGREES), (False, DISAGREES), (np.bool_(True), AGREES), (np.bool_(False), DISAGREES),
    (float("nan"), UNDECIDED), ("undecided", UNDECIDED), ("", UNDECIDED), (1, UNDECIDED), (0.0, UNDECIDED),
    (None, UNDECIDED),
])
def test_booleans_are_compared_only_as_booleans(value, outcome):
    """`bool(value)` read NaN and "undecided" as True (issue 37): only a real boolean decides."""
    flag = claim(kind="boolean", paper=True)
    assert compare(flag, value) == outcome


def test_an_undecided_setting_makes_the_verdict_undecided_unless_the_others_already_decide_it():
    variants = {"horizon=100": Cell(0.41, "", 0.0, False)}
    # agrees at nominal, undecided across the range: reproduced or conditional, we cannot say which
    result = judge(claim(), 0.42, variants)
    assert (result.verdict, result.robust) == ("undecided", "undecided")
    assert "horizon=100" in result.condition
    # agrees somewhere and disagrees somewhere: conditional whatever the undecided one reads
    result = judge(claim(), 0.42, {**variants, "horizon=400": 0.9})
    assert (result.verdict, result.robust) == ("conditional", "no")
    assert "undecided at horizon=100" in result.condition
    # an undecided nominal with every variant agreeing: still undecided (never reproduced on the range alone)
    assert judge(claim(), Cell(0.42, "", 0.0, False), {"horizon=100": 0.41}).verdict == "undecided"
    # an erratum or a differs needs a decided disagreement
    assert judge(claim(erratum="E1"), Cell(0.9, "", 0.5)).verdict == "undecided"
    assert judge(claim(erratum="E1"), Cell(0.9, "", 0.1)).verdict == "erratum"


def finding(**kw):
    base = dict(finding_id="F1", statement="s", kind="numeric", asserted=3.0, quantity="q", rule_reason="r",
                prior_work="none found (searched: x)", table="results/p/t.csv", tolerance=0.5,
                evidence_quantities=("q",), source={"kind": "effect_size", "ref": "set before"})
    base.update(kw)
    return FindingEntry(**base)


def test_findings_fail_and_are_undecided_like_claims():
    assert judge(finding(), 3.2).verdict == "holds"
    assert judge(finding(), 4.0).verdict == "fails"
    assert judge(finding(), Cell(3.2, "", 0.4)).verdict == "undecided"
    assert judge(finding(kind="boolean", asserted=True), "undecided").verdict == "undecided"


# ----------------------------------------------------------------------------- tolerances and values at the door
@pytest.mark.parametrize("value, relative, expected, problem", [
    (0.05, False, 0.4, ""), (0.1, True, -20.0, ""), (1e-12, False, 0.0, ""), (0.0, False, 0.0, ""),
    (float("nan"), False, 0.4, "finite"), (float("inf"), False, 0.4, "finite"), (-0.1, False, 0.4, "finite"),
    (1e300, False, 0.4, "as wide as"), (0.4, False, 0.4, "as wide as"), (1.5, True, 0.4, "tests nothing"),
    (2.0, False, 0.0, "at most 1"), ("0.1", False, 0.4, "a number"), (True, False, 0.4, "a number"),
])
def test_a_tolerance_is_finite_and_bounded(value, relative, expected, problem):
    found = check_tolerance(value, relative, expected)
    assert (problem in found) if problem else found == ""


@pytest.mark.parametrize("file, edit, message", [
    ("claims", ("tolerance: {value: 0.05, reason", "tolerance: {value: .nan, reason"), "finite number >= 0"),
    ("claims", ("tolerance: {value: 0.05, reason", "tolerance: {value: 1.0e300, reason"), "as wide as"),
    ("claims", ("tolerance: {value: 0.05, reason", "tolerance: {value: 1e300, reason"), "as wide as"),
    ("claims", ("paper_value: 0.4\n", "paper_value: .nan\n"), "finite number"),
    ("claims", ("- id: C3", "- id: f1"), "clashes with"),
    ("claims", ("- id: C3", "- id: horizon"), "clashes with"),
    ("findings", ("- id: F2", "- id: C2"), "clashes with"),
])
def test_bad_values_and_clashing_ids_are_refused_before_any_job(tmp_path, file, edit, message):
    root = write_paper(tmp_path, **{file: [edit]})
    with pytest.raises(ConfigError, match=message):
        load_paper_data("p", root)


def test_an_empty_claims_file_is_refused(tmp_path):
    root = write_paper(tmp_path)
    (root / "claims.yaml").write_text("# nothing yet\n")
    with pytest.raises(ConfigError, match="claims file is empty"):
        load_paper_data("p", root)


# ----------------------------------------------------------------------------- registered rules
def test_the_registry_hash_covers_exactly_the_registered_fields():
    raw = {"id": "F1", "kind": "numeric", "asserted": 3.0, "statement": "a", "quantity": "q",
           "evidence_quantities": ["x"], "rule": {"value": 0.5, "reason": "r", "source": {"kind": "paper", "ref": "1"}}}
    base = rule_hash(registered_fields(raw))
    # the statement and the threshold's source do not decide the verdict: same registration
    assert rule_hash(registered_fields(dict(raw, statement="b"))) == base
    assert rule_hash(registered_fields(dict(raw, rule={"value": 0.5, "reason": "r"}))) == base
    for changed in (dict(raw, asserted=3.1), dict(raw, rule={"value": 0.6, "reason": "r"}),
                    dict(raw, rule={"value": 0.5, "reason": "r2"}), dict(raw, quantity="q2"),
                    dict(raw, evidence_quantities=["x", "y"]), dict(raw, test={"family": 88}),
                    dict(raw, kind="observation")):
        assert rule_hash(registered_fields(changed)) != base
    assert base.startswith("sha256:") and len(base) == 7 + 64


def test_a_rule_changed_after_registration_stops_the_build_until_amended(tmp_path):
    changed = ("rule: {value: 0.5, reason:", "rule: {value: 0.8, reason:")
    root = write_paper(tmp_path, findings=[changed])
    with pytest.raises(ConfigError, match=r"p/F1: its rule .* changed since it was registered 2026-12-02 at commit "
                                          r"fixture.*amendments"):
        load_paper_data("p", root)
    # register-findings refuses to paper over it
    with pytest.raises(ConfigError, match="refusing to register over a changed rule"):
        register_findings("p", root, commit="x", date="2026-12-03")
    # an amendment that starts from the registered rule is accepted, and both verdicts are shown
    import yaml

    old = {k: v for k, v in yaml.safe_load(PAPER["findings.yaml"])[0].items()
           if k in ("kind", "asserted", "rule", "quantity", "evidence_quantities")}
    amendment = ("  figure: fig1\n", "  figure: fig1\n  amendments:\n    - registered: " + yaml.safe_dump(
        old, default_flow_style=True, width=10_000).strip() + "\n      why: \"a wider band\"\n      when: \"today\"\n")
    root = write_paper(tmp_path / "amended", findings=[changed, amendment]) if (tmp_path / "amended").mkdir() is None \
        else None
    data = load_paper_data("p", root)
    f1 = data.findings[0]
    assert f1.registered_rule.tolerance == 0.5 and f1.tolerance == 0.8
    ev = {"gain_vs_none": {"nominal": Cell(3.7, "")}, "gain": {"nominal": Cell(1.5, "")},
          "mse_finite": {"nominal": Cell(True, ""), "gain=2.5": Cell(False, "")}}
    row = findings_table(data, {**ev, "gain_vs_none": {"nominal": Cell(3.7, ""), "horizon=100": Cell(3.6, "")}}) \
        .set_index("finding_id").loc["F1"]
    # 3.7 fails the registered 3 +- 0.5 and holds under the amended 3 +- 0.8: the registered verdict comes first
    assert (row["verdict"], row["amended_verdict"]) == ("fails", "holds")
    assert row["rule"].startswith("3 within 0.5") and row["amended_rule"].startswith("3 within 0.8")
    assert row["amendments"] == "today: a wider band"


def test_a_deleted_or_unregistered_finding_stops_the_build(tmp_path):
    root = write_paper(tmp_path)
    text = (root / "findings.yaml").read_text()
    (root / "findings.yaml").write_text(text[:text.index("- id: F2")])
    with pytest.raises(ConfigError, match="p/F2 is registered .* but missing from findings.yaml: .* retract it"):
        load_paper_data("p", root)
    (root / "findings.yaml").write_text(text.replace("- id: F2", "- id: F3"))
    with pytest.raises(ConfigError, match="p/F3 is not registered"):
        load_paper_data("p", root)


def test_register_findings_adds_new_rules_and_never_rewrites(tmp_path):
    root = write_paper(tmp_path)
    before = (root / "findings.lock").read_text()
    text = (root / "findings.yaml").read_text()
    new = text[text.index("- id: F2"):].replace("- id: F2", "- id: F3")
    (root / "findings.yaml").write_text(text + new)
    assert register_findings("p", root, commit="abc1234", date="2026-12-03") == ["F3"]
    after = (root / "findings.lock").read_text()
    assert before in after and 'F3: {rule: "sha256:' in after and 'commit: "abc1234"' in after
    assert register_findings("p", root, commit="def", date="2026-12-04") == []
    assert (root / "findings.lock").read_text() == after
    load_paper_data("p", root)


# ----------------------------------------------------------------------------- fails, retracted, observations
def test_failing_retracted_and_observed_findings_stay_visible_and_counted(tmp_path):
    retract = ("  known: true\n", "  known: true\n  retracted: {reason: \"the bound was misread\", when: \"today\"}\n")
    root = write_paper(tmp_path, findings=[retract])
    data = load_paper_data("p", root)
    ev = {"gain_vs_none": {"nominal": Cell(9.0, ""), "horizon=100": Cell(9.0, "")}, "gain": {"nominal": Cell(1.5, "")},
          "mse_finite": {"nominal": Cell(True, ""), "gain=2.5": Cell(False, "")}}
    table = findings_table(data, ev).set_index("finding_id")
    assert table.loc["F1", "verdict"] == "fails"
    assert table.loc["F2", "verdict"] == "retracted"
    assert table.loc["F2", "condition"].startswith("retracted today: the bound was misread; its rule reads holds")
    score = scorecard({"p": pd.DataFrame({"verdict": ["reproduced"]})}, findings={"p": table.reset_index()})
    row = score.set_index("paper").loc["p"]
    assert (row["findings"], row["findings_fails"], row["findings_retracted"], row["findings_holds"]) == (2, 1, 1, 0)


def test_an_observation_is_measured_not_judged(tmp_path):
    observe = ('  kind: numeric\n  asserted: 3.0\n  rule: {value: 0.5, reason: "\'about 3\': half a unit of the one '
               'digit stated", source: {kind: effect_size, ref: "a factor of 3 set before the runs"}}\n',
               "  kind: observation\n")
    with pytest.raises(ConfigError, match="registered"):  # a registered rule changed: needs an amendment
        load_paper_data("p", write_paper(tmp_path, findings=[observe]))
    from netrepro.judging.paperdata import load_findings

    f1 = load_findings(write_paper(tmp_path, findings=[observe]) / "findings.yaml")[0]
    assert f1.observation and f1.asserted is None
    ev = {"gain_vs_none": {"nominal": Cell(3.2, "", 0.1), "horizon=100": Cell(3.1, "")}, "gain": {"nominal": Cell(1.5, "")}}
    from netrepro.judging.paperdata import PaperData

    table = findings_table(PaperData("p", [], [], [], [f1]), ev)
    assert table.loc[0, ["verdict", "kind", "uncertainty"]].tolist() == ["observed", "observation", "0.1"]
    ev["gain_vs_none"]["nominal"] = Cell(float("nan"), "")
    assert findings_table(PaperData("p", [], [], [], [f1]), ev).loc[0, "verdict"] == "undecided"


def test_a_causal_finding_names_its_isolating_control(tmp_path):
    no_control = (', control: {holds_fixed: "the plant and the noise", changes: "only the gain"}', "")
    from netrepro.judging.paperdata import load_findings

    with pytest.raises(ConfigError, match=r"entry 1 \(id 'F2'\): field 'cause.control' is required"):
        load_findings(write_paper(tmp_path, findings=[no_control]) / "findings.yaml")


def test_a_numeric_rule_names_the_source_of_its_threshold(tmp_path):
    from netrepro.judging.paperdata import load_findings

    unsourced = (', source: {kind: effect_size, ref: "a factor of 3 set before the runs"}', "")
    with pytest.raises(ConfigError, match="rule.source.*independently of our value"):
        load_findings(write_paper(tmp_path, findings=[unsourced]) / "findings.yaml")


# ----------------------------------------------------------------------------- statements from the evidence
def test_statements_are_filled_from_the_evidence():
    template = "crosses 0 dB at {cross:.2f} dB [{cross#lo:.2f}, {cross#hi:.2f}] (+- {cross#u:.1f}); F in {F1, F2}"
    assert template_fields(template) == [("cross", "", ".2f"), ("cross", "lo", ".2f"), ("cross", "hi", ".2f"),
                                         ("cross", "u", ".1f")]
    assert render_statement(template, {"cross": Cell(2.0862, "", 0.2)}) == \
        "crosses 0 dB at 2.09 dB [1.89, 2.29] (+- 0.2); F in {F1, F2}"
    # at another scale the same statement follows its evidence
    assert render_statement("at {x:.1f} dB", {"x": Cell(1.94, "")}) == "at 1.9 dB"


@pytest.mark.parametrize("text, values, typed", [
    ("crosses at 2.1 dB", {"x": 2.0862}, ["2.1 (= x 2.0862)"]),
    ("crosses at {x:.1f} dB", {"x": 2.0862}, []),
    ("within 32 steps", {"n": 32}, ["32 (= n 32)"]),
    ("equation (14) with gamma = 3", {"n": 14, "g": 3}, []),
    ("at 2.5 dB", {"x": 2.0862}, []),
    ("0.8025 and 1.31", {"v": 0.802469, "t": 1.31432}, ["0.8025 (= v 0.802469)", "1.31 (= t 1.31432)"]),
])
def test_a_typed_number_that_is_one_of_its_values_is_found(text, values, typed):
    assert typed_numbers(text, values) == typed


def test_check_paper_refuses_a_typed_statement_and_the_build_does_not(tmp_path):
    """A typed number equal to one of its evidence values fails check-paper (lint, on the configured scale's
    evidence); the build only renders (at another scale a typed setting may round to a result by chance)."""
    import os
    import shutil
    from pathlib import Path

    from netrepro.judging.contract import _check_findings_gate

    root = Path(__file__).resolve().parents[1]
    pkg = tmp_path / "src/netrepro/papers/intermittent"
    shutil.copytree(root / "src/netrepro/papers/intermittent", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    text = (pkg / "findings.yaml").read_text()
    assert "tail index {tail_index_fig1:.2f}" in text
    (pkg / "findings.yaml").write_text(text.replace("tail index {tail_index_fig1:.2f}", "tail index 1.31"))
    built = tmp_path / "results/evidence/intermittent.csv"
    built.parent.mkdir(parents=True)
    shutil.copy(root / "tests/reference/evidence/intermittent.csv", built)
    newest = max(p.stat().st_mtime for p in pkg.iterdir())
    os.utime(built, (newest + 1, newest + 1))
    found = _check_findings_gate("intermittent", pkg, tmp_path)
    assert [v.check for v in found] == ["findings-gate"]
    assert "F6: the statement types 1.31 (= tail_index_fig1 1.31432)" in found[0].message
    # the build renders the statement as written
    data = load_paper_data("intermittent", pkg)
    table = findings_table(data, read_evidence(built)).set_index("finding_id")
    assert "tail index 1.31:" in table.loc["F6", "statement"]
    (pkg / "findings.yaml").write_text(text)
    os.utime(built, (newest + 2, newest + 2))
    assert _check_findings_gate("intermittent", pkg, tmp_path) == []


# ----------------------------------------------------------------------------- the evidence table's new columns
def test_evidence_rows_carry_uncertainty_and_decided(tmp_path):
    frame = evidence_frame([dict(quantity="a", value=1.0), dict(quantity="b", value=0.46, uncertainty=0.02),
                            dict(quantity="c", value="", decided=False)])
    assert frame.columns.tolist() == ["quantity", "variant", "value", "note", "uncertainty", "decided"]
    path = tmp_path / "e.csv"
    frame.to_csv(path, index=False)
    ev = read_evidence(path)
    assert (ev["a"]["nominal"].uncertainty, ev["a"]["nominal"].decided) == (0.0, True)
    assert ev["b"]["nominal"].uncertainty == 0.02 and ev["c"]["nominal"].decided is False
    value, note = ev["b"]["nominal"]  # still a (value, note) pair
    assert (value, note) == (0.46, "")
    with pytest.raises(ValueError, match="uncertainty must be >= 0"):
        evidence_frame([dict(quantity="a", value=1.0, uncertainty=-1)])
    with pytest.raises(ValueError, match="decided must be True or False"):
        evidence_frame([dict(quantity="a", value=1.0, decided="yes")])
    # an old table without the columns reads as exact and decided
    path.write_text("quantity,variant,value,note\nx,nominal,2.5,\n")
    cell = read_evidence(path)["x"]["nominal"]
    assert (cell[0], cell.uncertainty, cell.decided) == (2.5, 0.0, True)


# ----------------------------------------------------------------------------- the solver's faults, counted
def test_solves_are_counted_capped_and_a_step_that_decides_nothing_stops(monkeypatch):
    from netrepro.engines import cvx
    from netrepro.engines.certify import CertifiedLMI
    from netrepro.errors import LMIError
    from netrepro.pipeline.runner import _refuse_undecided_step

    cp = cvx.cp
    monkeypatch.setattr(cvx, "_STATUSES", __import__("collections").Counter())
    monkeypatch.setattr(cvx, "_DECISIONS", __import__("collections").Counter())
    # X > I, X < 3 I: feasible; a solver capped at one iteration cannot certify it
    X = cp.Variable((2, 2), symmetric=True)
    lmi = CertifiedLMI([("X - I", X - np.eye(2)), ("3I - X", 3 * np.eye(2) - X)],
                       problem=cp.Problem(cp.Minimize(0), [X >> 1.5 * np.eye(2), X << 2.5 * np.eye(2)]))
    assert cvx.solver_options() == {"solver": "CLARABEL"}
    assert lmi.solve().verdict == "feasible"
    monkeypatch.setenv(cvx.FAULT_MAX_ITER, "1")
    assert cvx.solver_options()["max_iter"] == 1
    capped = lmi.solve()
    assert capped.verdict in ("feasible", "undecided")  # never a wrong "infeasible"
    assert sum(cvx.solver_statuses().values()) == 2 and cvx.solver_statuses().get("optimal") == 1
    _refuse_undecided_step("demo", cvx.certified_decisions(), cvx.solver_statuses())  # one decided: it stands
    with pytest.raises(LMIError, match=r"rule demo: every one of its 3 certified decisions is undecided "
                                       r"\(solver CLARABEL, statuses user_limit: 3\)"):
        _refuse_undecided_step("demo", {"undecided": 3}, {"user_limit": 3})
    monkeypatch.setenv(cvx.FAULT_MAX_ITER, "zero")
    with pytest.raises(ValueError, match="must be a positive integer"):
        cvx.solver_options()


def test_a_statement_may_print_any_evidence_quantity_but_only_an_existing_one(tmp_path):
    from netrepro.judging.paperdata import PaperData, load_findings

    f1 = load_findings(write_paper(tmp_path, findings=[("by a factor of about 3", "by a factor of {gain:.1f}")])
                       / "findings.yaml")[0]
    f1 = type(f1)(**{**f1.__dict__, "statement": "worse by {extra.ratio:.2f} (gain {gain:.1f})"})
    ev = {"gain_vs_none": {"nominal": Cell(3.2, ""), "horizon=100": Cell(3.1, "")}, "gain": {"nominal": Cell(1.5, "")}}
    with pytest.raises(InputError, match=r"p/F1: the statement fills \['extra.ratio'\] from the evidence"):
        findings_table(PaperData("p", [], [], [], [f1]), ev)
    ev["extra.ratio"] = {"nominal": Cell(2.345, "", 0.01)}
    row = findings_table(PaperData("p", [], [], [], [f1]), ev).iloc[0]
    assert row["statement"] == "worse by 2.35 (gain 1.5)"


def test_the_skeletons_example_finding_may_be_replaced(tmp_path):
    """The example finding new-paper registers is a placeholder: replacing it is no deletion."""
    from netrepro.judging.paperdata import SKELETON_COMMIT

    root = write_paper(tmp_path)
    lock = (root / "findings.lock").read_text().replace('commit: "fixture"', f'commit: "{SKELETON_COMMIT}"')
    (root / "findings.lock").write_text(lock)
    text = (root / "findings.yaml").read_text()
    (root / "findings.yaml").write_text(text.replace("- id: F2", "- id: F3"))
    with pytest.raises(ConfigError, match="p/F3 is not registered") as info:
        load_paper_data("p", root)
    assert "F2 is registered" not in str(info.value)
    assert register_findings("p", root, commit="abc", date="2026-12-03") == ["F3"]
    assert "F2:" not in (root / "findings.lock").read_text()
    load_paper_data("p", root)
