"""The workflow on a real Slurm cluster, through ``workflow/profiles/slurm``, shards as job arrays.

Starts a single-node Slurm cluster on this machine (``tests/slurm/cluster.py``:
munged as the ``munge`` user, slurmctld and slurmd as root, no slurmdbd), runs the sharded
tables of the small test configuration (intermittent's tables, the onebit estimator, hinf's loop
variants, Kalman-best and the fixed-path swap: :data:`tests.slurm.measure.TARGETS`) in a scratch copy of the
repository with ``snakemake --profile workflow/profiles/slurm`` (job states from squeue), and
checks that

* the shard rules went to Slurm as job arrays (the plugin's ``slurm-array-jobs``): the plugin
  logged array submissions, at least one for every shard rule, none for another rule, and Slurm
  knows each array task as ``<jobid>_<task>``, completed;
* every planned job went through Slurm exactly once, as a plain job or an array task, in the
  partition the profile takes from ``NETREPRO_SLURM_PARTITION`` (the cluster has no default
  partition, so a job without it would be refused); the sbatch calls are one per array plus one
  per plain job, fewer than the jobs; the run ends with no job left in the queue;
* the tables equal those of a local run of ``config/test.yaml`` in another scratch copy
  (``netrepro.judging.regression.compare_tables``), although the Slurm run splits every sharded step into
  one shard more (each count of ``shards:`` + 1): results do not depend on the split.

Needs root and the Debian packages munge, slurmctld, slurmd and slurm-client (CI installs
them with ``.ci/setup.d/20-slurm.sh``) and ``snakemake-executor-plugin-slurm`` (the ``test``
and ``slurm`` extras); skips with the reason otherwise. ``NETREPRO_SKIP_SLURM=1`` skips it.
Every wait is bounded: a run that outlives its timeout is interrupted (SIGINT: Snakemake cancels
its jobs), then killed (SIGKILL to its process group), and the test fails naming the timeout (and
the plugin's held-back array batches, the signature of its array deadlock, upstream issue #473);
the fixture then cancels what is left and stops the daemons by PID.
"""

from __future__ import annotations

import importlib.util
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from netrepro.pipeline.registry import paper_slugs
from netrepro.judging.regression import compare_tables
from netrepro.pipeline.stepspec import load_step_specs
from tests.conftest import copy_repo
from tests.slurm.cluster import PARTITION, LocalSlurm, SlurmUnavailable, unavailable_reason
from tests.slurm.measure import TARGETS, submissions

# every table the targets write (the merges write several)
TABLES = TARGETS + [
    "results/onebit/estimator_ratios.csv",
    "results/onebit/estimator_crossing.csv",
    "results/hinf/loop_variants_runs.csv",
    "results/hinf/loop_swap_runs.csv",
]
LOCAL_TIMEOUT = 900  # s, the local reference run
SLURM_TIMEOUT = 900  # s, the whole run under Slurm (the whole test: 92 s on a loaded 2-core machine)
STATUS_INTERVAL = 3  # s, first status check after a submission (the profile's 20 s is for real clusters)

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("slurm")]


def _env(workdir: Path, cluster: LocalSlurm) -> dict:
    env = cluster.client_env()
    env["PYTHONPATH"] = os.pathsep.join([str(workdir / "src"), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["MPLBACKEND"] = "Agg"
    env["NETREPRO_SLURM_PARTITION"] = PARTITION  # the profile's partition setting, exercised
    env.pop("NETREPRO_SLURM_ACCOUNT", None)  # no slurmdbd here, so no account can be validated
    return env


def _start(cmd, cwd, env):
    return subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            stdin=subprocess.DEVNULL, start_new_session=True)


def _run(cmd, cwd, env, timeout, proc=None):
    """Run a command (or finish the started ``proc``) in its own process group; on timeout SIGINT
    the group (Snakemake then scancels its jobs; SIGTERM would wait for them), then SIGKILL it."""
    proc = proc or _start(cmd, cwd, env)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            out, _ = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, _ = proc.communicate(timeout=30)
        held = len(re.findall(r"Array job collection incomplete", out))
        raise AssertionError(f"{' '.join(map(str, cmd))} timed out after {timeout} s; the Slurm plugin held back "
                             f"{held} array batches (its deadlock of upstream issue #473 when > 0):\n"
                             f"{out[-6000:]}") from None
    if proc.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} failed ({proc.returncode}):\n{out[-6000:]}")
    return out


def _snakemake(workdir, configfile, *options, targets=TARGETS):
    # targets first: --configfile takes several values and would swallow them
    return [sys.executable, "-m", "snakemake", *targets, "--configfile", configfile, *options]


def _local_rules(workdir: Path) -> set[str]:
    """Rules marked `localrule: True` (or listed in `localrules:`): they run in the main process, not on Slurm."""
    names = set()
    for smk in sorted((Path(workdir) / "workflow" / "rules").glob("*.smk")):
        text = smk.read_text()
        for block in re.findall(r"^localrules:\n((?:[ \t]+\w+,?[ \t]*\n?)+)", text, re.MULTILINE):
            names.update(re.findall(r"\w+", block))
        for name, body in re.findall(r"^rule (\w+):\n(.*?)(?=^\S|\Z)", text, re.MULTILINE | re.DOTALL):
            if re.search(r"^\s+localrule:\s*True", body, re.MULTILINE):
                names.add(name)
    # the generated compute rules: a step declared `local: true` in its paper's steps.yaml
    for slug in paper_slugs():
        names.update(spec.rule for spec in load_step_specs(slug).steps if spec.local)
    return names


def _planned_jobs(dry_run_output: str, workdir: Path) -> int:
    """Jobs the dry run sends to the executor (its job table, less the local rules)."""
    table = dict(re.findall(r"^(\w+)\s+(\d+)\s*$", dry_run_output, re.MULTILINE))
    assert "total" in table, f"no job count in the dry run:\n{dry_run_output[-3000:]}"
    local = _local_rules(workdir)
    return sum(int(n) for name, n in table.items() if name not in ("total", "job") and name not in local)


@pytest.fixture(scope="module")
def cluster():
    reason = unavailable_reason()
    if reason:
        pytest.skip(f"no local Slurm cluster: {reason}")
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        pytest.skip("snakemake-executor-plugin-slurm is not installed (pip install -e '.[slurm]')")
    local = LocalSlurm(default_partition=False)
    try:
        local.start()
    except SlurmUnavailable as exc:
        if os.environ.get("CI"):
            pytest.fail(f"CI has root and the Slurm packages, but the cluster did not start: {exc}")
        pytest.skip(f"could not start a local Slurm cluster: {exc}")
    try:
        yield local
    finally:
        local.stop()


def _shard_rules(workdir: Path) -> set[str]:
    hand_written = {name for smk in (Path(workdir) / "workflow" / "rules").glob("*.smk")
                    for name in re.findall(r"^rule (\w+_shard):", smk.read_text(), re.MULTILINE)}
    return hand_written | {spec.shard_rule for slug in paper_slugs() for spec in load_step_specs(slug).steps
                           if spec.shard}


def test_sharded_tables_through_slurm_as_job_arrays(cluster, tmp_path_factory):
    # one test, so that no distribution of tests over workers builds the cluster twice
    base = tmp_path_factory.mktemp("slurm")
    reference = copy_repo(base / "local")
    on_slurm = copy_repo(base / "slurm")

    # the Slurm run uses one shard more than the local one for every sharded step
    cfg = yaml.safe_load((on_slurm / "config/test.yaml").read_text())
    cfg["shards"] = {step: int(count) + 1 for step, count in cfg.get("shards", {}).items()}
    resharded = [f"shards.{step}={count}" for step, count in cfg["shards"].items()]
    (on_slurm / "config/slurm_test.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))

    # the local reference run goes on while the Slurm run waits for its jobs
    local_cmd = _snakemake(reference, "config/test.yaml", "-j2", "--profile", "workflow/profiles/default")
    local_run = _start(local_cmd, reference, _env(reference, cluster))
    try:
        profile = ["--profile", "workflow/profiles/slurm"]
        planned = _planned_jobs(_run(_snakemake(on_slurm, "config/slurm_test.yaml", *profile, "-n"), on_slurm,
                                     _env(on_slurm, cluster), 300), on_slurm)
        # --verbose: the plugin's debug lines name held-back array batches if the run hangs
        log = _run(_snakemake(on_slurm, "config/slurm_test.yaml", *profile, "--verbose",
                              "--slurm-init-seconds-before-status-checks", str(STATUS_INTERVAL)),
                   on_slurm, _env(on_slurm, cluster), SLURM_TIMEOUT)
    except BaseException:
        os.killpg(local_run.pid, signal.SIGKILL)
        local_run.communicate(timeout=30)
        raise
    _run(local_cmd, reference, None, LOCAL_TIMEOUT, proc=local_run)

    # the shard rules went as job arrays: the plugin's array submissions, and Slurm's array task ids
    subs = submissions(log)
    assert planned >= 10  # 6 sharded steps x (2 + 1) shards and the plain jobs, at least
    assert subs["arrays"], f"no array submission in the log:\n{log[-4000:]}"
    known = {job_id: (partition, state, comment) for job_id, partition, state, comment
             in cluster.jobs(fields="%i|%P|%T|%k")}
    shard_rules = _shard_rules(on_slurm)
    arrays_of = {}
    for slurm_id, first, last, snakemake_ids in subs["arrays"]:
        tasks = [f"{slurm_id}_{t}" for t in range(first, last + 1)]
        assert len(tasks) == len(snakemake_ids) >= 2
        assert {known.get(t, (None, None, None))[:2] for t in tasks} == {(PARTITION, "COMPLETED")}, (tasks, known)
        rule = re.match(r"rule_(\w+?)(?:_wildcards_.*)?$", known[tasks[0]][2]).group(1)
        assert rule in shard_rules, f"array job {slurm_id} is of {rule}, not a shard rule"
        arrays_of.setdefault(rule, []).append(slurm_id)
    assert set(arrays_of) == shard_rules, f"shard rules without an array job: {shard_rules - set(arrays_of)}"

    # every planned job went through Slurm once, as a plain job or an array task, and none is left;
    # sbatch calls: one per array plus one per plain job (a shard the scheduler handed over alone
    # goes as a plain job)
    assert subs["jobs"] == planned, f"{subs['jobs']} Slurm jobs for {planned} planned:\n{log[-4000:]}"
    # Slurm's side of the count: one job id per sbatch call (an array's tasks share their parent's id);
    # the cluster is this test's own, so every job it knows is this run's
    sbatch_ids = {job_id.split("_")[0] for job_id in known}
    assert len(sbatch_ids) == subs["calls"] == len(subs["arrays"]) + len(subs["single"]) < planned, (
        sorted(sbatch_ids), subs)
    assert {known.get(job_id, (None, None, None))[:2] for job_id in subs["single"]} == {(PARTITION, "COMPLETED")}
    assert not cluster.jobs("PENDING,RUNNING,COMPLETING,CONFIGURING,SUSPENDED")
    # without slurmdbd, sacct cannot answer; the profile makes the plugin ask squeue
    assert "Falling back to 'sacct'" not in log

    # the same tables as the local run, whatever the shard count
    problems = []
    for table in TABLES:
        problems += compare_tables(reference / table, on_slurm / table)
    assert not problems, "\n".join(problems) + f"\n(Slurm run resharded: {resharded or 'no'})"
