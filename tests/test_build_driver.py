"""The build driver (netrepro.pipeline.build, issue 38 items 2 and 5): builds of this checkout found by their
processes, the lock and the interrupt told truly, `unlock` refused while a build runs, and a job that
notices its Snakemake is gone. Fake Snakemake processes (a script named ``snakemake``) stand in for real
builds; the workflow-level repair and kill tests are in tests/test_reliability_workflow.py."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from netrepro.pipeline import build, processes

ROOT = Path(__file__).resolve().parents[1]
SLEEPER = "import time, sys\nprint('started', flush=True)\ntime.sleep(float(sys.argv[1]) if len(sys.argv) > 1 else 60)\n"


def fake_snakemake(directory: Path, body: str = SLEEPER) -> Path:
    """A script called ``snakemake``, run as ``python .../snakemake`` (as the console script runs)."""
    script = directory / "bin" / "snakemake"
    script.parent.mkdir(parents=True, exist_ok=True)
    script.write_text(body)
    return script


def start(argv, cwd, **kwargs):
    proc = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, **kwargs)
    assert proc.stdout.readline().strip() == "started"
    return proc


def stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=30)


def driver(cwd, *args, snakemake=None, **kwargs):
    cmd = [sys.executable, "-m", "netrepro", *args]
    if snakemake:
        cmd[4:4] = ["--snakemake", snakemake]
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=120, env=env, **kwargs)


@pytest.mark.parametrize("argv, expected", [
    (["/x/.venv/bin/python", "/x/.venv/bin/snakemake", "report"], True),
    (["snakemake", "-n"], True),
    (["python3", "-m", "snakemake", "--unlock"], True),
    (["python3", "-m", "netrepro", "run", "--rule", "snakemake_like"], False),
    (["python3", "workflow/Snakefile"], False),
    ([], False),
])
def test_snakemake_processes_are_told_from_jobs(argv, expected):
    assert processes.is_snakemake(argv) is expected


def test_a_build_is_found_by_its_working_directory_only(tmp_path):
    here, elsewhere = tmp_path / "checkout", tmp_path / "other"
    here.mkdir(), elsewhere.mkdir()
    proc = start([sys.executable, str(fake_snakemake(tmp_path))], cwd=here)
    try:
        found = processes.running_builds(here)
        assert [b.pid for b in found] == [proc.pid] and "snakemake" in found[0].command
        assert processes.running_builds(elsewhere) == []
    finally:
        stop(proc)
    assert processes.running_builds(here) == []


def test_unlock_refuses_while_a_build_runs_and_unlocks_after(tmp_path):
    proc = start([sys.executable, str(fake_snakemake(tmp_path))], cwd=tmp_path)
    try:
        refused = driver(tmp_path, "unlock", snakemake="true")
        assert refused.returncode == 1
        assert f"a build of this checkout is running (pid {proc.pid}" in refused.stderr and "Nothing was changed" in refused.stderr
        refused = driver(tmp_path, "build", snakemake="true")  # a second build is refused the same way
        assert refused.returncode == 1 and f"pid {proc.pid}" in refused.stderr
    finally:
        stop(proc)
    assert driver(tmp_path, "unlock", snakemake="true").returncode == 0


def test_a_stale_lock_is_named_as_a_killed_builds_with_the_command_that_removes_it(tmp_path):
    (tmp_path / ".snakemake" / "locks").mkdir(parents=True)
    (tmp_path / ".snakemake" / "locks" / "0.output.lock").write_text("report/index.html\n")
    failed = driver(tmp_path, "build", snakemake="false")
    assert failed.returncode == 1
    assert "no build of this checkout is running, so the lock was left by a killed build: `make unlock`" in failed.stderr
    # without a lock left, a failure is Snakemake's own to explain
    (tmp_path / ".snakemake" / "locks" / "0.output.lock").unlink()
    assert "lock" not in driver(tmp_path, "build", snakemake="false").stderr


def test_ctrl_c_says_interrupted_and_rerun_not_that_a_job_failed(tmp_path):
    fake = fake_snakemake(tmp_path)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "netrepro", "build", "--snakemake", f"{sys.executable} {fake}"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, env=env)
    try:
        assert proc.stdout.readline().strip() == "started"
        os.killpg(proc.pid, signal.SIGINT)  # what the terminal does on Ctrl-C: the whole foreground group
        _, err = proc.communicate(timeout=60)
    finally:
        stop(proc)
    assert proc.returncode == build.INTERRUPTED
    assert "make report: interrupted (SIGINT); rerun `make report` to resume" in err
    assert "failed" not in err.lower()


def test_sigterm_to_the_driver_alone_reaches_snakemake_and_reads_interrupted(tmp_path):
    fake = fake_snakemake(tmp_path, SLEEPER.replace("print(", "import signal\nprint("))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "netrepro", "build", "--snakemake", f"{sys.executable} {fake}"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, env=env)
    try:
        assert proc.stdout.readline().strip() == "started"
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        stop(proc)
    assert proc.returncode == build.INTERRUPTED and "interrupted (SIGTERM)" in err
    assert processes.running_builds(tmp_path) == []  # the fake Snakemake got the SIGINT and ended


CHILD = """
import sys
sys.path.insert(0, {src!r})
from netrepro.pipeline.processes import snakemake_ancestor
import os
print(os.getppid(), snakemake_ancestor(), flush=True)
"""


def test_a_job_finds_the_snakemake_that_started_it_and_sees_it_die(tmp_path):
    # a fake Snakemake that starts a job through a shell, as Snakemake's shell commands do
    body = ("import subprocess, sys, time\n"
            f"out = subprocess.run(['/bin/sh', '-c', {sys.executable!r} + ' -c \"' + sys.argv[1] + '\"'], "
            "capture_output=True, text=True).stdout\n"
            "print('started', flush=True)\nprint(out, flush=True)\ntime.sleep(60)\n")
    fake = fake_snakemake(tmp_path, body)
    child = CHILD.format(src=str(ROOT / "src")).replace('"', "'")
    proc = start([sys.executable, str(fake), child], cwd=tmp_path)
    try:
        line = proc.stdout.readline().split(maxsplit=1)
        ancestor = eval(line[1])  # (pid, start time) printed by the job
        assert ancestor[0] == proc.pid
        assert processes.process_alive(ancestor)
        assert not processes.process_alive((ancestor[0], str(int(ancestor[1]) + 1)))  # a reused pid is another process
    finally:
        stop(proc)
    deadline = time.monotonic() + 10
    while processes.process_alive(ancestor) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not processes.process_alive(ancestor)
    assert processes.snakemake_ancestor() is None or processes.is_snakemake(processes._cmdline(processes.snakemake_ancestor()[0]))


def test_an_orphaned_step_writes_nothing(tmp_path, monkeypatch):
    # the runner's check before writing: the Snakemake that started the job is gone
    from netrepro.pipeline import runner
    from netrepro.errors import OrphanedJobError

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(runner, "snakemake_ancestor", lambda: (999_999_999, "1"))  # no such process
    out = tmp_path / "results" / "t.csv"
    with pytest.raises(OrphanedJobError, match="is gone, so the job stops without writing"):
        runner.run_step("demo", "tests.test_build_driver:_table_step", {}, {}, {"table": str(out)})
    assert not out.exists() and not list(out.parent.glob("t.csv*"))


def _table_step(params, inputs, outputs):
    import pandas as pd

    return {"table": pd.DataFrame({"x": [1.0]})}


def test_the_starter_is_read_from_the_environment_on_this_host_only():
    import socket

    mark = processes.starter_mark()
    host, pid, start = mark.rsplit(":", 2)
    assert host == socket.gethostname() and int(pid) == os.getpid()
    assert processes.starter_from_environment({processes.STARTER_VARIABLE: mark}) == (os.getpid(), start)
    assert processes.process_alive((os.getpid(), start))
    assert processes.starter_from_environment({processes.STARTER_VARIABLE: f"other-host:{pid}:{start}"}) is None
    for bad in ("", "garbage", f"{host}:x:1"):
        assert processes.starter_from_environment({processes.STARTER_VARIABLE: bad}) is None


def test_a_job_started_after_its_snakemake_died_does_no_work(tmp_path, monkeypatch):
    # Snakemake killed between starting the job's shell and the job's interpreter: no ancestor is left to
    # find, but the environment names it, and the job stops before it reads or computes anything
    from netrepro.pipeline import runner
    from netrepro.errors import OrphanedJobError

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(processes.STARTER_VARIABLE, processes.starter_mark(os.getpid()).rsplit(":", 2)[0]
                       + f":{dead.pid}:1")
    calls = []
    monkeypatch.setattr(runner, "_run_and_record", lambda *args: calls.append(args))
    with pytest.raises(OrphanedJobError):
        runner.run_step("demo", "tests.test_build_driver:_table_step", {}, {}, {"table": "results/t.csv"})
    assert calls == [] and not (tmp_path / "results").exists()
