import pandas as pd

from netrepro.judging.regression import compare_tables, compare_trees


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


def _pair(tmp_path, ref_frame, got_frame, name="p/t.csv"):
    ref, got = tmp_path / "ref" / name, tmp_path / "res" / name
    for path, frame in ((ref, ref_frame), (got, got_frame)):
        path.parent.mkdir(parents=True, exist_ok=True)
        frame.to_csv(path, index=False)
    return ref, got


def test_numbers_inside_text_are_compared_with_the_numeric_tolerance(tmp_path):
    ref, got = _pair(tmp_path, pd.DataFrame({"s": ["slack 0.8027613281380114 > 0"]}),
                     pd.DataFrame({"s": ["slack 0.8027613281380112 > 0"]}))
    assert compare_tables(ref, got) == []
    pd.DataFrame({"s": ["slack 0.81 > 0"]}).to_csv(got, index=False)
    assert "column 's' differs" in compare_tables(ref, got)[0]
    pd.DataFrame({"s": ["slack 0.8027613281380114 < 0"]}).to_csv(got, index=False)
    assert "column 's' differs" in compare_tables(ref, got)[0]


def test_platform_rules_weaken_only_the_rows_and_columns_they_name(tmp_path):
    reference = pd.DataFrame({"design": ["a", "b"], "x": [1.0, 2.0], "slack": [1e-9, 2e-9],
                              "ev": ["min slack 1e-9 > 0", "min slack 2e-9 > 0"], "status": ["optimal", "optimal"]})
    rules = [{"table": "p/t.csv", "rows": {"design": ["a"]}, "columns": ["x"], "check": "finite", "reason": "r"},
             {"table": "p/t.csv", "columns": ["slack"], "check": "sign", "reason": "r"},
             {"table": "p/t.csv", "columns": ["ev"], "check": "text", "reason": "r"},
             {"table": "p/t.csv", "columns": ["status"], "check": "info", "reason": "r"}]
    changed = reference.assign(x=[1.5, 2.0], slack=[3e-9, 5e-10], ev=["min slack 4e-9 > 0", "min slack 7e-9 > 0"],
                               status=["optimal_inaccurate", "optimal"])
    ref, got = _pair(tmp_path, reference, changed)
    assert compare_tables(ref, got, rules=rules) == []
    assert len(compare_tables(ref, got)) == 4  # without the rules every change is caught
    for broken, column in ((changed.assign(x=[1.5, 2.5]), "x"),            # row b is not covered
                           (changed.assign(x=[float("nan"), 2.0]), "x"),   # finite: NaN pattern kept
                           (changed.assign(slack=[-1e-9, 5e-10]), "slack"),  # sign flip = other decision
                           (changed.assign(ev=["min slack 4e-9 < 0", "min slack 7e-9 > 0"]), "ev")):
        broken.to_csv(got, index=False)
        assert f"column '{column}' differs" in compare_tables(ref, got, rules=rules)[0]


def test_malformed_platform_rules_are_named(tmp_path):
    import pytest

    from netrepro.judging.regression import load_platform_rules

    path = tmp_path / "rules.yaml"
    path.write_text("- {table: p/t.csv, columns: [x], check: loose, reason: r}\n")
    with pytest.raises(ValueError, match="entry 0 .p/t.csv.*check"):
        load_platform_rules(path)
    ref, got = _pair(tmp_path, pd.DataFrame({"x": [1.0]}), pd.DataFrame({"x": [1.0]}))
    with pytest.raises(ValueError, match="column 'y'"):
        compare_tables(ref, got, rules=[{"table": "p/t.csv", "columns": ["y"], "check": "sign", "reason": "r"}])
    path.write_text("- {table: p/other.csv, columns: [x], check: sign, reason: r}\n")
    with pytest.raises(ValueError, match="p/other.csv"):
        compare_trees(tmp_path / "ref", tmp_path / "res", platform_rules=path)


def test_committed_platform_rules_name_existing_reference_columns_with_a_reason():
    from pathlib import Path

    from netrepro.judging.regression import PLATFORM_RULES, load_platform_rules

    reference = Path(__file__).parent / "reference"
    rules = load_platform_rules(PLATFORM_RULES)
    assert rules, "tests/platform_dependent.yaml is missing or empty"
    for table, entries in rules.items():
        columns = set(pd.read_csv(reference / table, nrows=0).columns)
        for rule in entries:
            assert set(rule["columns"]) <= columns, (table, rule["columns"])
            assert len(rule["reason"].split()) >= 5, (table, rule["reason"])


def test_a_result_table_without_a_reference_fails_naming_it(tmp_path):
    """Issue 30: a new table is never silently skipped (timings and shards have no reference)."""
    from netrepro.cli.regression import main

    ref, got = _pair(tmp_path, pd.DataFrame({"x": [1.0]}), pd.DataFrame({"x": [1.0]}))
    for extra in ("p/new.csv", "benchmarks.csv", "p/shards/s0.csv"):
        (tmp_path / "res" / extra).parent.mkdir(parents=True, exist_ok=True)
        pd.DataFrame({"x": [2.0]}).to_csv(tmp_path / "res" / extra, index=False)
    count, problems = compare_trees(tmp_path / "ref", tmp_path / "res")
    assert count == 1 and len(problems) == 1
    assert "p/new.csv: no reference" in problems[0]
    assert main(["compare", "--reference", str(tmp_path / "ref"), "--results", str(tmp_path / "res"),
                 "--figures", "", "--html", "", "--platform-rules", ""]) == 1


def test_update_writes_the_references_and_prints_what_changed(tmp_path, capsys):
    from netrepro.cli.regression import main

    _pair(tmp_path, pd.DataFrame({"x": [1.0]}), pd.DataFrame({"x": [1.5]}))
    _pair(tmp_path, pd.DataFrame({"x": [1.0]}), pd.DataFrame({"x": [1.0]}), name="p/same.csv")
    (tmp_path / "ref" / "p" / "gone.csv").write_text("x\n1\n")
    pd.DataFrame({"y": [3]}).to_csv(tmp_path / "res" / "p" / "new.csv", index=False)
    args = ["--reference", str(tmp_path / "ref"), "--results", str(tmp_path / "res"), "--figures", "", "--platform-rules", ""]
    assert main(["update", *args]) == 0
    out = capsys.readouterr().out
    assert "table changed: " in out and "p/t.csv" in out and "table added: " in out and "p/new.csv" in out
    assert "table removed: " in out and "p/gone.csv" in out and "same.csv" not in out
    assert main(["compare", *args, "--html", ""]) == 0



def test_recorded_paper_scale_run_is_neither_compared_nor_removed_by_update(tmp_path, capsys):
    from netrepro.cli.regression import main

    _pair(tmp_path, pd.DataFrame({"x": [1.0]}), pd.DataFrame({"x": [1.0]}))
    recorded = tmp_path / "ref" / "paper-scale" / "claims" / "p.csv"
    recorded.parent.mkdir(parents=True)
    recorded.write_text("claim_id,verdict\nc,reproduced\n")
    scale_table = tmp_path / "res" / "scale" / "verdicts_by_scale.csv"  # derived from committed data: unchecked
    scale_table.parent.mkdir(parents=True)
    scale_table.write_text("paper,claim_id\np,c\n")
    args = ["--reference", str(tmp_path / "ref"), "--results", str(tmp_path / "res"), "--figures", "", "--platform-rules", ""]
    assert main(["compare", *args, "--html", ""]) == 0
    assert main(["update", *args]) == 0
    assert recorded.read_text() == "claim_id,verdict\nc,reproduced\n"
    assert not (tmp_path / "ref" / "scale").exists()
    count, problems = compare_trees(tmp_path / "ref", tmp_path / "res")
    assert (count, problems) == (1, [])

def test_clearing_an_old_difference_page_touches_nothing_else(tmp_path):
    from netrepro.figures.check import clear_difference_page

    keep = [tmp_path / "README.md", tmp_path / "figure.png", tmp_path / "sub" / "x_result.png"]
    gone = [tmp_path / "index.html", tmp_path / "markov_fig2_reference.png", tmp_path / "markov_fig2_result.png",
            tmp_path / "markov_fig2_difference.png"]
    for path in keep + gone:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("x")
    clear_difference_page(tmp_path)
    assert all(p.exists() for p in keep) and not any(p.exists() for p in gone)


def test_compare_with_no_page_deletes_nothing_in_the_working_directory(tmp_path, monkeypatch):
    # `--html ''` once made compare remove Path('').parent, the working directory, with everything in it
    from netrepro.cli.regression import main

    (tmp_path / "ref").mkdir()
    (tmp_path / "res").mkdir()
    (tmp_path / "precious.txt").write_text("keep me")
    monkeypatch.chdir(tmp_path)
    main(["compare", "--reference", "ref", "--results", "res", "--figures", "", "--html", "", "--platform-rules", ""])
    assert (tmp_path / "precious.txt").read_text() == "keep me"


def _two_papers(root):
    """A results tree and a reference tree of papers a and b: own tables and shared per-paper tables."""
    for side, value in (("ref", 1.0), ("res", 2.0)):
        for paper in ("a", "b"):
            for rel in (f"{paper}/t.csv", f"{paper}/sim/u.csv", f"claims/{paper}.csv", f"errata/{paper}.csv",
                        f"findings/{paper}.csv", f"evidence/{paper}.csv", f"reconstructions/{paper}.csv"):
                path = root / side / rel
                path.parent.mkdir(parents=True, exist_ok=True)
                pd.DataFrame({"x": [value], "wall_time_s": [value * 7]}).to_csv(path, index=False)
    return root / "ref", root / "res"


def test_update_of_one_paper_leaves_every_other_reference_byte_identical(tmp_path, capsys):
    """Issue 40 A: `make update-references PAPER=a` touches a's tables (own and shared) only."""
    from netrepro.cli.regression import main
    from netrepro.judging.regression import paper_of

    ref, res = _two_papers(tmp_path)
    (res / "a" / "new.csv").write_text("x\n3\n")
    (res / "b" / "new.csv").write_text("x\n3\n")
    (ref / "a" / "gone.csv").write_text("x\n1\n")
    (ref / "b" / "gone.csv").write_text("x\n1\n")
    before = {p: p.read_bytes() for p in ref.rglob("*") if p.is_file()}
    args = ["--reference", str(ref), "--results", str(res), "--figures", "", "--platform-rules", ""]
    assert main(["update", *args, "--paper", "a"]) == 0
    out = capsys.readouterr().out
    assert "/a/" in out and "claims/a.csv" in out and "/b/" not in out and "b.csv" not in out
    for path, data in before.items():
        if paper_of(path.relative_to(ref)) == "b":
            assert path.read_bytes() == data, path
    assert not (ref / "b" / "new.csv").exists() and (ref / "b" / "gone.csv").exists()
    assert (ref / "a" / "new.csv").exists() and not (ref / "a" / "gone.csv").exists()
    for rel in ("a/t.csv", "a/sim/u.csv", "claims/a.csv", "errata/a.csv", "findings/a.csv", "evidence/a.csv",
                "reconstructions/a.csv"):
        assert (ref / rel).read_text() == "x\n2.0\n", rel  # copied, without the timing column
    assert main(["update", *args, "--paper", "a", "--paper", "b"]) == 0
    assert main(["compare", *args, "--html", ""]) == 0
    assert main(["update", *args, "--paper", "nosuch"]) == 2
    assert "nosuch" in capsys.readouterr().err


def test_a_timing_column_difference_is_not_reported_and_not_copied(tmp_path):
    """Issue 40 A: measured times are no part of a reference (TIMING_COLUMNS, one list)."""
    from netrepro.judging.regression import is_timing_column, update_tables

    timings = ["wall_time_s", "solve_time_s", "total_time_s", "seconds", "solves_per_second", "elapsed",
               "elapsed_s", "build_seconds", "extrapolated_1000_s", "fit_exponent"]
    assert all(is_timing_column(c) for c in timings)
    assert not any(is_timing_column(c) for c in ("t", "time_constant_steps", "n_steps", "x", "note"))
    columns = {"x": [1.0, 2.0], "s": ["a", "b,c"], **{c: [0.1, 0.2] for c in timings}}
    ref, got = _pair(tmp_path, pd.DataFrame(columns), pd.DataFrame({**columns, **{c: [9.0, 8.0] for c in timings}}))
    assert compare_tables(ref, got) == []
    assert compare_trees(tmp_path / "ref", tmp_path / "res") == (1, [])
    assert update_tables(tmp_path / "ref", tmp_path / "res") == [f"table changed: {ref}"]
    assert ref.read_text() == 'x,s\n1.0,a\n2.0,"b,c"\n'
    assert compare_trees(tmp_path / "ref", tmp_path / "res") == (1, [])  # result with timings vs reference without
    assert update_tables(tmp_path / "ref", tmp_path / "res") == []  # a rerun with other times changes nothing
    pd.DataFrame({**columns, "x": [1.0, 2.5]}).to_csv(got, index=False)
    assert "column 'x' differs" in compare_tables(ref, got)[0]


def test_no_committed_reference_has_a_timing_column():
    from pathlib import Path

    from netrepro.judging.regression import _reference_tables, is_timing_column

    reference = Path(__file__).parent / "reference"
    found = [(t.relative_to(reference).as_posix(), c) for t in _reference_tables(reference)
             for c in pd.read_csv(t, nrows=0).columns if is_timing_column(c)]
    assert found == [], found
