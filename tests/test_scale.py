"""Verdicts by scale (issue 31): the comparison, the code fingerprint, staleness, recording, the panel."""

import json
from pathlib import Path

import pandas as pd
import pytest

from netrepro.scale import record as scale

ROOT = Path(__file__).resolve().parents[1]
CLAIM_COLS = ["paper", "claim_id", "reproduced_value", "verdict", "robust", "condition", "note"]


def _claims(folder: Path, paper: str, rows):
    (folder / "claims").mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows, columns=CLAIM_COLS).to_csv(folder / "claims" / f"{paper}.csv", index=False)


def _findings(folder: Path, paper: str, rows):
    (folder / "findings").mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows, columns=["paper", "finding_id", "evidence", "verdict", "robust", "condition"]).to_csv(
        folder / "findings" / f"{paper}.csv", index=False)


@pytest.fixture
def two_runs(tmp_path):
    a, b = tmp_path / "default", tmp_path / "scale"
    _claims(a, "p", [["p", "same", "1.0", "reproduced", "yes", "", ""],
                     ["p", "flips", "0.2", "conditional", "no", "holds for x", ""],
                     ["p", "robustness", "3", "reproduced", "no", "", ""],
                     ["p", "moves", "0.50", "reproduced", "yes", "", ""],
                     ["p", "gone", "1", "reproduced", "yes", "", ""]])
    _claims(b, "p", [["p", "same", "1.0", "reproduced", "yes", "", ""],
                     ["p", "flips", "0.3", "reproduced", "yes", "", "alpha = 1 - 1e-5 simulated"],
                     ["p", "robustness", "3", "reproduced", "yes", "", ""],
                     ["p", "moves", "0.51", "reproduced", "yes", "", ""],
                     ["p", "new", "2", "differs", "no", "", ""]])
    _findings(a, "p", [["p", "F1", "e", "holds", "yes", ""]])
    _findings(b, "p", [["p", "F1", "e2", "conditional", "no", "only at large N"]])
    return a, b


def test_compare_by_scale_names_every_difference(two_runs):
    table = scale.compare_by_scale(*two_runs).set_index("claim_id")
    assert list(scale.SCALE_COLUMNS[:7]) == ["paper", "claim_id", "verdict_default", "verdict_paper_scale",
                                            "value_default", "value_paper_scale", "changed"]
    # written by hand from the two tables above
    assert table.loc["same", "changed"] == False and table.loc["same", "what_changed"] == ""  # noqa: E712
    assert table.loc["flips", "what_changed"] == "verdict+robust+value" and table.loc["flips", "changed"]
    assert table.loc["flips", "verdict_paper_scale"] == "reproduced" and table.loc["flips", "value_default"] == "0.2"
    assert table.loc["robustness", "what_changed"] == "robust" and table.loc["robustness", "changed"]
    # more paths move an estimate: listed, but not a change of verdict
    assert table.loc["moves", "what_changed"] == "value" and not table.loc["moves", "changed"]
    assert table.loc["gone", "what_changed"] == "removed" and table.loc["new", "what_changed"] == "added"
    assert table.loc["flips", "note_paper_scale"] == "alpha = 1 - 1e-5 simulated"
    findings = scale.compare_by_scale(*two_runs, kind="findings").set_index("finding_id")
    assert findings.loc["F1", "what_changed"] == "verdict+robust+value"
    assert findings.loc["F1", "condition_paper_scale"] == "only at large N"


def _sidecar(path: Path, inputs: dict):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("x")
    meta = {"inputs": {k: {"path": p, "sha256": h} for k, (p, h) in inputs.items()}, "wall_time_s": 2.5,
            "command": str(path), "git": {"commit": "abc", "dirty": False}}
    Path(str(path) + ".meta.json").write_text(json.dumps(meta))


def test_code_fingerprint_collects_each_papers_sources_and_refuses_mixed_versions(tmp_path):
    res = tmp_path / "results"
    _sidecar(res / "p" / "t.csv", {"code[0]": ("src/a.py", "h1"), "code[1]": ("src/b.py", "h2"),
                                   "table": ("results/q/u.csv", "h9")})
    _sidecar(res / "evidence" / "p.csv", {"code[0]": ("src/a.py", "h1"), "f": ("src/p/claims.yaml", "h3")})
    _sidecar(res / "q" / "u.csv", {"code[0]": ("src/c.py", "h4")})
    fp = scale.code_fingerprint(tmp_path, ["p", "q"])
    assert fp == {"p": {"src/a.py": "h1", "src/b.py": "h2", "src/p/claims.yaml": "h3"}, "q": {"src/c.py": "h4"}}
    _sidecar(res / "claims" / "p.csv", {"code[0]": ("src/a.py", "other")})
    with pytest.raises(ValueError, match=r"paper 'p' was computed from two versions of src/a\.py"):
        scale.code_fingerprint(tmp_path, ["p", "q"])


def test_stale_sources_lists_changed_and_missing_files(tmp_path):
    import hashlib

    (tmp_path / "src").mkdir()
    (tmp_path / "src/a.py").write_text("same\n")
    (tmp_path / "src/b.py").write_text("edited\n")
    same = hashlib.sha256(b"same\n").hexdigest()
    prov = {"code": {"p": {"src/a.py": same, "src/b.py": hashlib.sha256(b"before\n").hexdigest(),
                           "src/gone.py": "h"}}}
    rows = scale.stale_sources(prov, tmp_path)
    assert [(r["path"], r["current_sha256"] == "missing") for r in rows] == [("src/b.py", False), ("src/gone.py", True)]
    prov["code"]["p"] = {"src/a.py": same}
    assert scale.stale_sources(prov, tmp_path) == []


def test_record_writes_tables_and_provenance(tmp_path, two_runs):
    run = tmp_path / "run"
    _claims(run / "results", "p", [["p", "c", "1", "reproduced", "yes", "", ""]])
    _findings(run / "results", "p", [["p", "F1", "e", "holds", "yes", ""]])
    _sidecar(run / "results" / "p" / "t.csv", {"code[0]": ("src/a.py", "h1")})
    (run / "config").mkdir()
    (run / "config/base.yaml").write_text("papers: [p]\nshards: {x: 2}\np: {n: 1, m: {k: 1}}\n")
    (run / "config/over.yaml").write_text("p: {m: {k: 10}}\n")
    dest = tmp_path / "ref"
    prov = scale.record(run, dest, ["config/base.yaml", "config/over.yaml"], shards={"x": 5}, wall_time_s=12.0)
    assert (dest / "claims/p.csv").read_text() == (run / "results/claims/p.csv").read_text()
    assert (dest / "findings/p.csv").is_file()
    written = json.loads((dest / "provenance.json").read_text())
    assert written["code"] == {"p": {"src/a.py": "h1"}} and written["commit"] == "abc"
    assert written["wall_time_s"] == 12.0 and written["shards"] == {"x": 5} and written == prov
    # the hash is of the merged science (the overlay applied key by key), not of the shard counts
    from netrepro.pipeline.provenance import params_hash

    assert written["config_hash"] == params_hash({"papers": ["p"], "p": {"n": 1, "m": {"k": 10}}})
    with pytest.raises(FileNotFoundError, match="no claims tables"):
        scale.record(tmp_path / "empty", dest, [])


def test_scale_step_and_panel(tmp_path, two_runs, monkeypatch):
    from netrepro.report.sections import scale_html

    default, reference = two_runs
    (reference / "provenance.json").write_text(json.dumps(
        {"commit": "abc", "config_hash": "h", "configfiles": ["config/paper-scale.yaml"], "recorded": "2026",
         "wall_time_s": 1800, "jobs": 3, "job_seconds": 3000, "code": {"p": {"src/nothing_here.py": "h"}}}))
    monkeypatch.chdir(tmp_path)
    out = scale.scale_step({"reference": str(reference)},
                           {"claims": [str(default / "claims" / "p.csv")], "provenance": str(reference / "provenance.json")},
                           {})
    assert set(out) == {"table", "findings", "stale", "provenance"}
    assert out["provenance"]["claims_changed"] == 4 and out["provenance"]["stale_papers"] == ["p"]
    paths = {}
    for name in ("table", "findings", "stale"):
        paths[name] = str(tmp_path / f"{name}.csv")
        out[name].to_csv(paths[name], index=False)
    html = scale_html({**paths, "reference": str(reference)})
    assert "Does scale change a verdict?" in html and "stale for p" in html
    assert "4 of 6 claims and 1 of 1 findings change their verdict or robust flag" in html
    assert 'data-claim="flips"' in html and 'data-claim="same"' not in html and 'data-claim="moves"' not in html
    assert "30.0 min" in html
    assert scale_html({}) == ""
    # a recording whose jobs ran at two commits lists both, not a Python list
    prov = json.loads((reference / "provenance.json").read_text())
    (reference / "provenance.json").write_text(json.dumps({**prov, "commit": ["abc", "def"]}))
    html = scale_html({**paths, "reference": str(reference)})
    assert "commits <code>abc</code>, <code>def</code>" in html and "[&#39;abc&#39;" not in html


def test_findings_comparison_keeps_both_evidence_texts(two_runs):
    findings = scale.compare_by_scale(*two_runs, kind="findings").set_index("finding_id")
    assert findings.loc["F1", "evidence_default"] == "e" and findings.loc["F1", "evidence_paper_scale"] == "e2"


def test_a_paper_without_a_recording_reads_no_recording_yet(tmp_path, two_runs, monkeypatch):
    """A paper the recording does not hold (a sixth paper, added since) is neither a change nor a removal."""
    from netrepro.report.sections import scale_html

    default, reference = two_runs
    _claims(default, "sixth", [["sixth", "C1", "1.0", "reproduced", "yes", "", ""],
                               ["sixth", "C2", "2.0", "differs", "no", "", ""]])
    _findings(default, "sixth", [["sixth", "F9", "e", "holds", "yes", ""]])
    # and a recorded paper this run did not build (a run of fewer papers): not compared either
    _claims(reference, "old", [["old", "K1", "1.0", "reproduced", "yes", "", ""]])
    table = scale.compare_by_scale(default, reference)
    sixth = table[table["paper"] == "sixth"]
    assert list(sixth["what_changed"]) == [scale.NOT_RECORDED] * 2 and not sixth["changed"].any()
    old = table[table["paper"] == "old"]
    assert list(old["what_changed"]) == [scale.NOT_RUN] and not old["changed"].any()
    # the recorded paper is compared as before: "gone" is still removed, "new" still added
    p = table[table["paper"] == "p"].set_index("claim_id")
    assert p.loc["gone", "what_changed"] == "removed" and p.loc["new", "what_changed"] == "added"
    findings = scale.compare_by_scale(default, reference, kind="findings")
    assert findings.set_index("finding_id").loc["F9", "what_changed"] == scale.NOT_RECORDED
    # the panel counts only the compared claims and names the paper without a recording
    (reference / "provenance.json").write_text(json.dumps(
        {"commit": "abc", "config_hash": "h", "configfiles": [], "recorded": "2026", "code": {}}))
    monkeypatch.chdir(tmp_path)
    out = scale.scale_step({"reference": str(reference)},
                           {"claims": [str(default / "claims" / "p.csv")], "provenance": str(reference / "provenance.json")},
                           {})
    assert out["provenance"]["claims_changed"] == 4 and out["provenance"]["findings_changed"] == 1
    paths = {}
    for name in ("table", "findings", "stale"):
        paths[name] = str(tmp_path / f"{name}.csv")
        out[name].to_csv(paths[name], index=False)
    html = scale_html({**paths, "reference": str(reference)})
    assert "4 of 6 claims and 1 of 1 findings change their verdict or robust flag" in html
    assert "No paper-scale recording yet for sixth (2 claims, 1 findings)" in html
    assert 'data-claim="C1"' not in html and 'data-finding="F9"' not in html and 'data-claim="K1"' not in html
