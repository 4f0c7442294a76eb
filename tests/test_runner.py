import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from netrepro.pipeline.provenance import CorruptOutputError, read_sidecar, verify_output
from netrepro.pipeline.runner import resolve, run_step


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
        resolve("netrepro.pipeline.io:nope")


def test_failing_step_leaves_no_output(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(KeyError, match="^'x'$"):  # the step reads params["x"], which is not given
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


def _command_line(args, cwd, code=None):
    """Run ``python -m netrepro ARGS`` (or ``python -c CODE``) as the rules do, with this checkout's src/ and tests."""
    repo = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(repo / "src"), str(repo)]))
    env.pop("PYTHONUNBUFFERED", None)  # as under Snakemake's shell: the streams are buffered
    cmd = [sys.executable, "-c", code] if code else [sys.executable, "-m", "netrepro", *args]
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)


def test_command_line_exit_keeps_outputs_logs_and_exit_code(tmp_path):
    # The command line ends without the interpreter's teardown: the table, its sidecar and the
    # log file must still be complete, and a failing step must still exit with 1.
    io = json.dumps({"outputs": {"table": "t.csv"}})
    ok = _command_line(["run", "--rule", "demo", "--func", "tests.test_runner:table_step", "--params", '{"x": 1.5}',
                        "--io", io, "--log", "run.log"], tmp_path)
    assert ok.returncode == 0, ok.stderr
    assert pd.read_csv(tmp_path / "t.csv")["x"].tolist() == [1.5, 2.0]
    verify_output(tmp_path / "t.csv")
    assert "rule demo: tests.test_runner:table_step done" in (tmp_path / "run.log").read_text()
    bad = _command_line(["run", "--rule", "demo", "--func", "tests.test_runner:table_step", "--params", "{}",
                         "--io", io, "--log", "bad.log"], tmp_path)
    assert bad.returncode == 1
    assert "rule demo failed" in (tmp_path / "bad.log").read_text()


def test_exit_process_flushes_buffered_output_and_keeps_the_code(tmp_path):
    # stdout is a pipe here, hence block-buffered: without the flush the text would be lost.
    code = "import sys; from netrepro.pipeline.runner import exit_process; sys.stdout.write('unflushed'); exit_process(3)"
    proc = _command_line([], tmp_path, code=code)
    assert proc.returncode == 3 and proc.stdout == "unflushed"
