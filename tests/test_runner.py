
import pandas as pd
import pytest

from netrepro.provenance import CorruptOutputError, read_sidecar, verify_output
from netrepro.runner import resolve, run_step


def table_step(params, inputs, outputs):
    return {"table": pd.DataFrame({"x": [params["x"], 2.0]}), "provenance": {"note": "hi"}}


def test_run_step_writes_table_and_sidecar(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run_step("demo", "tests.test_runner:table_step", {"x": 1.5, "seed": 7}, {}, {"table": "out/t.csv"})
    assert pd.read_csv("out/t.csv")["x"].tolist() == [1.5, 2.0]
    meta = read_sidecar("out/t.csv")
    assert meta["rule"] == "demo" and meta["seeds"] == {"seed": 7} and meta["extra"] == {"note": "hi"}
    assert meta["function"] == "tests.test_runner:table_step" and meta["source_line"] > 0
    verify_output("out/t.csv")


def test_corrupted_input_is_detected_before_work(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run_step("demo", "tests.test_runner:table_step", {"x": 1.0}, {}, {"table": "a.csv"})
    with open("a.csv", "a") as fh:
        fh.write("999\n")
    with pytest.raises(CorruptOutputError, match="checksum"):
        run_step("demo2", "tests.test_runner:table_step", {"x": 1.0}, {"a": "a.csv"}, {"table": "b.csv"})
    assert not (tmp_path / "b.csv").exists()


def test_resolve_errors_name_the_problem():
    with pytest.raises(ValueError, match="module:function"):
        resolve("no_colon")
    with pytest.raises(ValueError, match="no function"):
        resolve("netrepro.io:nope")


def test_failing_step_leaves_no_output(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(KeyError):
        run_step("demo", "tests.test_runner:table_step", {}, {}, {"table": "c.csv"})
    assert not (tmp_path / "c.csv").exists()


def two_tables_step(params, inputs, outputs):
    return {"a": pd.DataFrame({"x": [1.0]}), "b": pd.DataFrame({"y": [2.0]})}


def test_every_sidecar_of_a_step_records_its_inputs_checksums(tmp_path, monkeypatch):
    """The inputs' checksums are computed once per step and written into the sidecar of every output."""
    import hashlib

    monkeypatch.chdir(tmp_path)
    (tmp_path / "in.txt").write_text("some input\n")
    run_step("demo", "tests.test_runner:two_tables_step", {}, {"data": "in.txt", "none": "missing.txt"},
             {"a": "a.csv", "b": "b.csv"})
    expected = {"data": {"path": "in.txt", "sha256": hashlib.sha256(b"some input\n").hexdigest()}}
    metas = [read_sidecar(name) for name in ("a.csv", "b.csv")]
    assert [m["inputs"] for m in metas] == [expected, expected]
    assert metas[0]["packages"] == metas[1]["packages"] and "numpy" in metas[0]["packages"]
