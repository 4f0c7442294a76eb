import pandas as pd

from netrepro.regression import compare_tables, compare_trees


def test_identical_tables_agree_and_changes_are_caught(tmp_path):
    ref = tmp_path / "ref" / "p" / "t.csv"
    got = tmp_path / "res" / "p" / "t.csv"
    for path in (ref, got):
        path.parent.mkdir(parents=True)
    frame = pd.DataFrame({"x": [1.0, 2.0, float("inf")], "s": ["a", "b", "c"]})
    frame.to_csv(ref, index=False)
    frame.to_csv(got, index=False)
    assert compare_trees(tmp_path / "ref", tmp_path / "res") == (1, [])
    frame.assign(x=[1.0, 2.001, float("inf")]).to_csv(got, index=False)
    assert "column 'x' differs" in compare_tables(ref, got)[0]
    frame.assign(s=["a", "B", "c"]).to_csv(got, index=False)
    assert "column 's' differs" in compare_tables(ref, got)[0]
    got.unlink()
    assert "missing" in compare_trees(tmp_path / "ref", tmp_path / "res")[1][0]


def test_timing_columns_and_claim_notes_are_not_compared(tmp_path):
    ref, got = tmp_path / "ref" / "claims" / "t.csv", tmp_path / "res" / "claims" / "t.csv"
    for path in (ref, got):
        path.parent.mkdir(parents=True)
    pd.DataFrame({"x": [1.0], "solve_time_s": [0.5], "note": ["took 3 s"]}).to_csv(ref, index=False)
    pd.DataFrame({"x": [1.0], "solve_time_s": [0.9], "note": ["took 4 s"]}).to_csv(got, index=False)
    assert compare_tables(ref, got) == []
    pd.DataFrame({"x": [1.5], "solve_time_s": [0.9], "note": ["took 4 s"]}).to_csv(got, index=False)
    assert compare_tables(ref, got)
