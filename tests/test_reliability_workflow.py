"""Reliability (issue 8) of the whole workflow, in scratch copies of the repository.

* bad configurations and a missing package stop snakemake before any job runs, and nothing under
  results/ changes (parts 1 and 7);
* a run killed in the middle of the Monte Carlo step (SIGTERM to snakemake, SIGTERM to its
  process group, SIGKILL to its process group) leaves no table that looks complete, and the rerun
  gives tables identical to an uninterrupted run (part 2);
* truncated or edited tables are detected, reported, and rebuilt identically (part 3);
* -j1, -j2, another chunking/sharding of the Monte Carlo work and a --forceall rerun give identical
  tables (part 4);
* the tables the figures read hold no NaN and the logs hold no flood of warnings (part 6).

Every snakemake run uses the scratch copy's own src/ (a snapshot of the package taken once), so that
edits made meanwhile in the live checkout cannot mix into a comparison. Only the `intermittent` paper
is built (its own section of config/test.yaml, with more Monte Carlo
paths so that the step lasts long enough to be interrupted).
"""

import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
BUILD_PRODUCTS = {"results", "logs", ".snakemake", "report", "figures"}


def top_level_ignore(root, names_at_root, anywhere=("__pycache__",)):
    """An ignore function for copytree: ``names_at_root`` only at ``root`` (src/netrepro/report and
    workflow/report are sources), ``anywhere`` at every level."""
    root = Path(root).resolve()

    def ignore(directory, names):
        here = names_at_root if Path(directory).resolve() == root else set()
        return [n for n in names if n in here or n in anywhere or n.endswith(".egg-info")]

    return ignore


IGNORE_AT_ROOT = {".venv", ".git", ".pytest_cache", ".hypothesis", *BUILD_PRODUCTS}
TARGETS = [
    "results/intermittent/exact_mean.csv",
    "results/intermittent/monte_carlo.csv",
    "results/intermittent/scalar_bounds.csv",
    "results/intermittent/two_sensor_region.csv",
    "results/intermittent/two_sensor_simulation.csv",
    "results/claims/intermittent.csv",
    "results/errata/intermittent.csv",
    "results/reconstructions/intermittent.csv",
]
MC_TARGETS = ["results/intermittent/scalar_bounds.csv"]  # needs exact_mean and the Monte Carlo
MC_TABLES = ["results/intermittent/exact_mean.csv", "results/intermittent/monte_carlo.csv",
             "results/intermittent/scalar_bounds.csv"]
TIMEOUT = 900

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("reliability")]


def isolated_env(workdir, env=None):
    """Run the scratch copy's own package code (a snapshot), not the live checkout's editable install."""
    env = dict(env or os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(Path(workdir) / "src"), env.get("PYTHONPATH")) if p)
    return env


def snakemake(workdir, *args, config="config/rel.yaml", check=True, env=None, timeout=TIMEOUT):
    cmd = [sys.executable, "-m", "snakemake", "--configfile", *config.split(), *args]
    proc = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=timeout,
                          env=isolated_env(workdir, env))
    if check and proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
    return proc


def write_config(workdir, name, shards=None, **scalar):
    """config/<name>: the intermittent section of config/test.yaml, with ``scalar`` overrides and the
    Monte Carlo's shard count ``shards`` (config/test.yaml's when None)."""
    cfg = yaml.safe_load((workdir / "config/test.yaml").read_text())
    section = cfg["intermittent"]
    schema = yaml.safe_load((workdir / "workflow/schemas/intermittent.schema.yaml").read_text())
    known = schema["properties"]["scalar"]["properties"]
    unknown = set(scalar) - set(known)
    assert not unknown, f"not keys of intermittent.scalar: {unknown}"
    section["scalar"].update(scalar)
    counts = dict(cfg.get("shards", {}))
    if shards is not None:
        counts["intermittent_monte_carlo"] = shards
    (workdir / "config" / name).write_text(
        yaml.safe_dump({"papers": ["intermittent"], "shards": counts, "intermittent": section}))


def fresh_copy(tmp_path_factory, name):
    work = tmp_path_factory.mktemp(name) / "repo"
    shutil.copytree(ROOT, work, ignore=top_level_ignore(ROOT, IGNORE_AT_ROOT))
    write_config(work, "rel.yaml", n_paths=2_000_000, block_size=10_000, n_chunks=1, shards=1)
    return work


def clone(src, tmp_path_factory, name, results=True):
    """A copy of a built scratch repository (same code), with or without its results and metadata."""
    work = tmp_path_factory.mktemp(name) / "repo"
    ignore = None if results else top_level_ignore(src, BUILD_PRODUCTS, anywhere=())
    shutil.copytree(src, work, symlinks=True, ignore=ignore)
    return work


def tables(workdir, paths=TARGETS):
    return {p: (workdir / p).read_bytes() for p in paths}


def snapshot(workdir):
    """Every file under results/ (and figures/): modification time and content hash."""
    out = {}
    for top in ("results", "figures"):
        for path in sorted((workdir / top).rglob("*")) if (workdir / top).is_dir() else []:
            if path.is_file():
                out[str(path.relative_to(workdir))] = (path.stat().st_mtime_ns,
                                                       hashlib.sha256(path.read_bytes()).hexdigest())
    return out


def verify(workdir, *args):
    return subprocess.run([sys.executable, "-m", "netrepro", "verify", "-q", *args], cwd=workdir,
                          capture_output=True, text=True, timeout=300, env=isolated_env(workdir))


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    work = fresh_copy(tmp_path_factory, "rel_built")
    snakemake(work, "-j1", *TARGETS)
    return work


@pytest.fixture(scope="module")
def reference(built):
    return tables(built)


# ----------------------------------------------------------------------------- part 4: determinism
def test_j2_other_chunking_and_forceall_give_identical_tables(built, reference, tmp_path_factory):
    work = clone(built, tmp_path_factory, "rel_det")
    write_config(work, "rel2.yaml", n_paths=2_000_000, block_size=10_000, n_chunks=7, shards=3)
    snakemake(work, "-j2", "--forceall", *TARGETS, config="config/rel2.yaml")
    again = tables(work)
    for path, data in reference.items():
        assert again[path] == data, f"{path} differs between -j1 and -j2 --forceall with another chunking"
    assert verify(work).returncode == 0


# ----------------------------------------------------------------------------- parts 1 and 7: refused before any job
BAD_OVERRIDES = [
    ("intermittent.scalar.R2", {"R2": -1.0}),
    ("intermittent.scalar.seed", {"seed": -3}),
    ("intermittent.scalar.R1", {"R1": float("nan")}),
    ("intermittent.scalar.exact_horizon", {"horizon": 5}),
    ("intermittent.scalar.n_paths", {"n_paths": 7}),
]


def test_bad_configurations_change_nothing(built):
    before = snapshot(built)
    assert before
    for key, override in BAD_OVERRIDES:
        write_config(built, "bad.yaml", **override)
        proc = snakemake(built, "-j2", "--forceall", *TARGETS, config="config/bad.yaml", check=False)
        out = proc.stdout + proc.stderr
        assert proc.returncode != 0 and "invalid configuration" in out and key in out, out[-3000:]
        assert "localrule" not in out and "Finished jobid" not in out
    # a bad top-level value given on the command line
    proc = snakemake(built, "-j2", "--forceall", *TARGETS, "--config", "papers=[nonsense]", check=False)
    assert proc.returncode != 0 and "'nonsense'" in proc.stdout + proc.stderr
    # a shard count below 1 on the command line, and an overlay (a second --configfile) with a key
    # the schema does not know: both stop the run before any job, naming the key
    proc = snakemake(built, "-j2", "--forceall", *TARGETS, "--config", "shards={intermittent_monte_carlo: 0}",
                     check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "shards.intermittent_monte_carlo" in out and "minimum of 1" in out, out[-3000:]
    assert "localrule" not in out and "Finished jobid" not in out
    (built / "config/overlay.yaml").write_text(yaml.safe_dump({"intermittent": {"scalar": {"n_pathz": 10}}}))
    proc = snakemake(built, "-j2", "--forceall", *TARGETS, config="config/rel.yaml config/overlay.yaml", check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "intermittent.scalar.n_pathz" in out and "not a known key" in out, out[-3000:]
    assert "localrule" not in out and "Finished jobid" not in out
    assert snapshot(built) == before


BLOCKER = """
import sys
class _Block:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "cvxpy":
            raise ModuleNotFoundError("No module named 'cvxpy' (blocked by the test)", name=name)
        return None
sys.meta_path.insert(0, _Block())
"""


def test_missing_package_stops_snakemake_with_a_clear_message(built, tmp_path):
    (tmp_path / "sitecustomize.py").write_text(BLOCKER)
    env = dict(os.environ, PYTHONPATH=str(tmp_path))  # the scratch copy's src/ is prepended by snakemake()
    before = snapshot(built)
    proc = snakemake(built, "-j2", "--forceall", *TARGETS, check=False, env=env)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0
    assert "required package 'cvxpy' is missing" in out and "needed for LMI feasibility problems" in out
    assert "Fix: run `make`" in out and "localrule" not in out
    assert snapshot(built) == before


# ----------------------------------------------------------------------------- part 2: interruptions
def interrupt(work, how):
    """Start the Monte Carlo targets, kill as ``how`` while the Monte Carlo step runs; return the log."""
    out = open(work / "interrupted.txt", "w")
    cmd = [sys.executable, "-m", "snakemake", "--configfile", "config/rel.yaml", "-j2", *MC_TARGETS]
    proc = subprocess.Popen(cmd, cwd=work, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                            env=isolated_env(work))
    try:
        deadline = time.monotonic() + 600
        while not list((work / "logs/intermittent").glob("monte_carlo*.log")):
            assert proc.poll() is None, (work / "interrupted.txt").read_text()[-3000:]
            if time.monotonic() > deadline:  # a hang guard, not a speed requirement
                pytest.fail("the Monte Carlo step never started")
            time.sleep(0.1)
        # signal while a Monte Carlo job process runs: with a warm compile cache the shard takes well
        # under a second, so a fixed wait could miss it (the signal then came after the step)
        settle = time.monotonic() + 1.0
        while time.monotonic() < settle and not any("monte_carlo" in line for line in job_processes(work)):
            time.sleep(0.01)
        running = not (work / "results/intermittent/monte_carlo.csv").exists()
        if how == "TERM":
            proc.send_signal(signal.SIGTERM)
        elif how == "KILL-snakemake":  # Snakemake alone, as `kill -9 PID`: its jobs run on
            proc.send_signal(signal.SIGKILL)
        else:
            os.killpg(proc.pid, signal.SIGTERM if how == "TERM-group" else signal.SIGKILL)
        proc.wait(timeout=300)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        out.close()
    assert running, "the Monte Carlo step had already finished when the signal was sent"
    assert proc.returncode != 0
    return (work / "interrupted.txt").read_text()


def job_processes(work):
    """The pipeline job processes running in ``work`` (their command lines name relative paths only,
    so the process's working directory tells whose they are)."""
    ps = subprocess.run(["ps", "-eo", "pid,args"], capture_output=True, text=True).stdout
    mine = []
    for line in ps.splitlines():
        pid, _, args = line.strip().partition(" ")
        if "netrepro run" not in args:
            continue
        try:
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except OSError:  # ended meanwhile
            continue
        if Path(cwd).resolve() == Path(work).resolve():
            mine.append(line)
    return mine


@pytest.mark.parametrize("how", ["TERM", "TERM-group", "KILL-group"])
def test_interrupted_monte_carlo_reruns_to_identical_tables(how, built, reference, tmp_path_factory):
    work = clone(built, tmp_path_factory, f"rel_{how.lower()}", results=False)
    interrupt(work, how)
    time.sleep(0.5)
    # nothing that looks complete unless it is: a graceful stop (SIGTERM to snakemake) lets the
    # running job finish; a killed job leaves no Monte Carlo table; whatever exists verifies
    if how != "TERM":
        assert not (work / "results/intermittent/monte_carlo.csv").exists()
    assert not (work / "results/intermittent/scalar_bounds.csv").exists()
    check = verify(work)
    assert check.returncode == 0 and "CORRUPT" not in check.stdout, check.stdout
    if how != "TERM":  # the jobs died with their group; none is left running
        assert not job_processes(work)
    proc = snakemake(work, "-j2", *MC_TARGETS, check=how != "KILL-group")
    if proc.returncode != 0:
        # SIGKILL leaves Snakemake's directory lock behind, and a job that finished writing (atomically)
        # just before the kill is still marked incomplete in Snakemake's metadata (which one depends on
        # timing): the rerun refuses with a message saying what to do, and after the documented
        # recovery (`--unlock`, then `--rerun-incomplete`, which the default profile sets) it proceeds
        out = proc.stdout + proc.stderr
        locked = "LockException" in out and "--unlock" in out
        incomplete = "IncompleteFilesException" in out and "--rerun-incomplete" in out
        assert locked or incomplete, out[-3000:]
        assert not (work / "results/intermittent/monte_carlo.csv").exists()
        snakemake(work, "--unlock", *MC_TARGETS)
        proc = snakemake(work, "-j2", "--rerun-incomplete", *MC_TARGETS)
    assert "Nothing to be done" not in proc.stdout + proc.stderr
    for path in MC_TABLES:
        assert (work / path).read_bytes() == reference[path], f"{path} differs after the {how} interruption"
    assert verify(work).returncode == 0
    assert not list((work / "results").rglob(".*.part*")), "a temporary file of an interrupted write was left"


def test_a_job_whose_snakemake_is_killed_stops_without_writing(built, reference, tmp_path_factory):
    # issue 38 item 5: after `kill -9` of Snakemake alone, its running job used to finish and write
    # its outputs later, unwarned; now it notices before writing and leaves nothing
    work = clone(built, tmp_path_factory, "rel_orphan", results=False)
    interrupt(work, "KILL-snakemake")
    deadline = time.monotonic() + 300
    while job_processes(work):
        if time.monotonic() > deadline:
            pytest.fail("the orphaned job never ended")
        time.sleep(0.1)
    shard = work / "results/intermittent/shards/monte_carlo_0.npz"
    assert not shard.exists() and not (shard.parent / (shard.name + ".meta.json")).exists()
    log = (work / "logs/intermittent/monte_carlo_0.log").read_text()
    assert "the Snakemake process that started this job" in log and "stops without writing" in log, log[-2000:]
    assert verify(work).returncode == 0
    # the lock it left is a killed build's: `unlock` (the driver) proceeds, as no build of this checkout runs
    unlock = subprocess.run([sys.executable, "-m", "netrepro", "unlock", "--", "--configfile", "config/rel.yaml"],
                            cwd=work, capture_output=True, text=True, timeout=300, env=isolated_env(work))
    assert unlock.returncode == 0, unlock.stdout + unlock.stderr
    snakemake(work, "-j2", "--rerun-incomplete", *MC_TARGETS)
    for path in MC_TABLES:
        assert (work / path).read_bytes() == reference[path], f"{path} differs after the orphaned job"


# ----------------------------------------------------------------------------- part 3: corrupted caches
def test_corrupted_tables_are_detected_reported_and_rebuilt(built, reference, tmp_path_factory):
    work = clone(built, tmp_path_factory, "rel_corrupt")
    mc = work / "results/intermittent/monte_carlo.csv"
    exact = work / "results/intermittent/exact_mean.csv"
    region = work / "results/intermittent/two_sensor_region.csv"
    # 1. truncated: snakemake reruns the consumers (newer input), whose runner refuses it
    data = mc.read_bytes()
    mc.write_bytes(data[: len(data) // 3])
    proc = snakemake(work, "-j1", *TARGETS, check=False)
    logs = proc.stdout + proc.stderr + "".join(p.read_text() for p in (work / "logs").rglob("*.log"))
    assert proc.returncode != 0
    assert re.search(r"monte_carlo\.csv: checksum \w+… differs from the sidecar's", logs), logs[-3000:]
    assert not (work / "results/intermittent/scalar_bounds.csv").exists() or \
        (work / "results/intermittent/scalar_bounds.csv").read_bytes() == reference[MC_TABLES[2]]
    # 2. edited in place with its old modification time: invisible to snakemake, caught by verify
    stat = exact.stat()
    text = exact.read_text()
    exact.write_text(text.replace("10,", "11,", 1))
    os.utime(exact, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    # 3. a sidecar replaced by garbage
    (region.parent / (region.name + ".meta.json")).write_text("{")
    report = verify(work)
    assert report.returncode == 1
    for path in (mc, exact, region):
        assert f"CORRUPT: {path.relative_to(work)}" in report.stdout, report.stdout
    # rebuild: remove what is corrupt, rerun, get the very same tables
    assert verify(work, "--remove-corrupt").returncode == 0
    snakemake(work, "-j2", *TARGETS)
    assert tables(work) == reference
    assert verify(work).returncode == 0


# ----------------------------------------------------------------------------- part 6: what the figures read
def test_figure_tables_hold_no_nan_and_logs_no_warning_flood(built):
    plotted = {
        "results/intermittent/scalar_bounds.csv": ["s", "r", "report_estimate", "mean", "mean_lo", "mean_hi"],
        "results/intermittent/monte_carlo.csv": ["cond_mean", "cond_lo", "cond_hi", "plain_mean", "plain_lo",
                                                 "plain_hi"],
        "results/intermittent/exact_mean.csv": ["mean_exact"],
        "results/intermittent/two_sensor_region.csv": ["lambda1", "lambda2c_lower", "lambda2c_upper"],
        "results/intermittent/two_sensor_simulation.csv": ["mean", "mean_lo", "mean_hi"],
    }
    for path, columns in plotted.items():
        frame = pd.read_csv(built / path)
        values = frame[columns].to_numpy(dtype=float)
        assert not np.isnan(values).any(), f"NaN in {path}"
    bounds = pd.read_csv(built / "results/intermittent/scalar_bounds.csv")
    diverging = bounds[bounds["lam"] == bounds["lam"].min()].sort_values("k")
    assert (diverging[["s", "r", "mean"]] > 0).all().all()  # drawable on log axes
    lines = [line for p in (built / "logs").rglob("*.log") for line in p.read_text().splitlines()]
    warns = [line for line in lines if "Warning" in line]
    assert len(warns) <= 5, "\n".join(warns[:20])
    assert verify(built).returncode == 0
