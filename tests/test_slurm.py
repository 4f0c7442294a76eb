"""The workflow on a real Slurm cluster, through ``workflow/profiles/slurm``.

Starts a single-node Slurm cluster on this machine (``tests/slurm/cluster.py``:
munged as the ``munge`` user, slurmctld and slurmd as root, no slurmdbd), runs the
``intermittent`` tables of the small test configuration in a scratch copy of the
repository with ``snakemake --profile workflow/profiles/slurm`` (every job an sbatch
job, job states from squeue), and checks that

* every planned job went through Slurm, in the partition the profile takes from
  ``NETREPRO_SLURM_PARTITION`` (the cluster has no default partition, so a job without it
  would be refused), and the run ends with no job left in the queue;
* the tables equal those of a local run of ``config/test.yaml`` in another scratch copy
  (``netrepro.regression.compare_tables``), although the Slurm run splits the Monte Carlo
  and the LMI sweep into a different number of shards (each count of ``shards:`` + 1) when the
  configuration has that key: results do not depend on the split.

Needs root and the Debian packages munge, slurmctld, slurmd and slurm-client (CI installs
them with ``.ci/setup.d/20-slurm.sh``) and ``snakemake-executor-plugin-slurm`` (the ``test``
and ``slurm`` extras); skips with the reason otherwise. ``NETREPRO_SKIP_SLURM=1`` skips it.
Every wait is bounded: a run that outlives its timeout is interrupted (SIGINT: Snakemake cancels
its jobs), then killed (SIGKILL to its process group); the fixture then cancels what is left and
stops the daemons by PID.
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

from netrepro.regression import compare_tables
from tests.conftest import copy_repo
from tests.slurm.cluster import PARTITION, LocalSlurm, SlurmUnavailable, unavailable_reason

TABLES = [
    "results/intermittent/exact_mean.csv",
    "results/intermittent/monte_carlo.csv",
    "results/intermittent/scalar_bounds.csv",
    "results/intermittent/two_sensor_region.csv",
    "results/intermittent/two_sensor_simulation.csv",
]
LOCAL_TIMEOUT = 900  # s, the local reference run
SLURM_TIMEOUT = 1500  # s, the whole run under Slurm
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
        raise AssertionError(f"{' '.join(map(str, cmd))} timed out after {timeout} s:\n{out[-6000:]}") from None
    if proc.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} failed ({proc.returncode}):\n{out[-6000:]}")
    return out


def _snakemake(workdir, configfile, *options, targets=TABLES):
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


def test_intermittent_tables_through_slurm(cluster, tmp_path_factory):
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
        log = _run(_snakemake(on_slurm, "config/slurm_test.yaml", *profile,
                              "--slurm-init-seconds-before-status-checks", str(STATUS_INTERVAL)),
                   on_slurm, _env(on_slurm, cluster), SLURM_TIMEOUT)
    except BaseException:
        os.killpg(local_run.pid, signal.SIGKILL)
        local_run.communicate(timeout=30)
        raise
    _run(local_cmd, reference, None, LOCAL_TIMEOUT, proc=local_run)

    # every planned job was an sbatch job in the profile's partition, and none is left
    submitted = re.findall(r"has been submitted with SLURM jobid (\d+)", log)
    assert planned >= 3  # the shards and the simulation, at least
    assert len(submitted) == planned, f"{len(submitted)} Slurm jobs for {planned} planned:\n{log[-4000:]}"
    known = {job_id: (partition, state) for job_id, partition, state in cluster.jobs(fields="%i|%P|%T")}
    assert {known.get(job_id) for job_id in submitted} == {(PARTITION, "COMPLETED")}, known
    assert not cluster.jobs("PENDING,RUNNING,COMPLETING,CONFIGURING,SUSPENDED")
    # without slurmdbd, sacct cannot answer; the profile makes the plugin ask squeue
    assert "Falling back to 'sacct'" not in log

    # the same tables as the local run, whatever the shard count
    problems = []
    for table in TABLES:
        problems += compare_tables(reference / table, on_slurm / table)
    assert not problems, "\n".join(problems) + f"\n(Slurm run resharded: {resharded or 'no'})"
