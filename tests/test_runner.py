
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
