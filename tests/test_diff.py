"""``python -m netrepro diff``: verdict, robust and value changes between two runs."""

import subprocess
import sys
from pathlib import Path

import pandas as pd

from netrepro.judging.diff import DIFF_COLUMNS, diff_runs

ROOT = Path(__file__).resolve().parents[1]
CLAIMS = ["paper", "claim_id", "reproduced_value", "verdict", "robust"]
FINDINGS = ["paper", "finding_id", "evidence", "verdict", "robust"]


def _run(root: Path, claims, findings) -> Path:
    (root / "results/claims").mkdir(parents=True)
    (root / "results/findings").mkdir(parents=True)
    pd.DataFrame(claims, columns=CLAIMS).to_csv(root / "results/claims/p.csv", index=False)
    pd.DataFrame(findings, columns=FINDINGS).to_csv(root / "results/findings/p.csv", index=False)
    return root


def test_each_kind_of_change_is_named(tmp_path):
    a = _run(tmp_path / "a", [["p", "same", 1.0, "reproduced", "yes"], ["p", "flip", 1.0, "reproduced", "yes"],
                              ["p", "rob", 2.0, "conditional", "yes"], ["p", "val", 3.0, "reproduced", ""],
                              ["p", "gone", 4.0, "differs", ""], ["p", "tiny", 1.0, "reproduced", ""]],
             [["p", "F1", "x", "holds", ""]])
    b = _run(tmp_path / "b", [["p", "same", 1.0, "reproduced", "yes"], ["p", "flip", 1.5, "differs", "yes"],
                              ["p", "rob", 2.0, "conditional", "no"], ["p", "val", 3.5, "reproduced", ""],
                              ["p", "new", 5.0, "reproduced", ""], ["p", "tiny", 1.0 + 1e-13, "reproduced", ""]],
             [["p", "F1", "y", "conditional", ""]])
    table = diff_runs(a, b).set_index("id")
    assert list(diff_runs(a, b).columns) == DIFF_COLUMNS
    assert table.loc["flip", "changed"] == "verdict+value"
    assert table.loc["rob", "changed"] == "robust"
    assert table.loc["val", "changed"] == "value"
    assert table.loc["gone", "changed"] == "removed" and table.loc["new", "changed"] == "added"
    assert table.loc["F1", "changed"] == "verdict+value" and table.loc["F1", "kind"] == "finding"
    assert "same" not in table.index and "tiny" not in table.index


def test_identical_runs_have_no_difference():
    assert diff_runs(ROOT / "tests/reference", ROOT / "tests/reference").empty


def test_the_command_reads_reference_folders_and_fails_on_change_when_asked(tmp_path):
    a = _run(tmp_path / "a", [["p", "c", 1.0, "reproduced", ""]], [])
    b = _run(tmp_path / "b", [["p", "c", 1.0, "differs", ""]], [])
    out = tmp_path / "diff.csv"
    proc = subprocess.run([sys.executable, "-m", "netrepro", "diff", str(a), str(b), "--csv", str(out),
                           "--fail-on-change"], capture_output=True, text=True, check=False)
    assert proc.returncode == 1, proc.stderr
    assert "p claim c: verdict: reproduced -> differs" in proc.stdout
    assert pd.read_csv(out)["changed"].tolist() == ["verdict"]
    missing = subprocess.run([sys.executable, "-m", "netrepro", "diff", str(a), str(tmp_path / "nowhere")],
                             capture_output=True, text=True, check=False)
    assert missing.returncode == 2 and "no claims tables" in missing.stderr
