"""Measured submissions and wall time of the small configuration on the local test Slurm.

Starts the single-node cluster of :mod:`tests.slurm.cluster` (as root), and for each mode and
repeat runs the sharded tables of ``config/test.yaml`` (:data:`TARGETS`) in a fresh scratch copy of
the repository through ``workflow/profiles/slurm``:

* ``arrays``: the profile as it is (every ``*_shard`` rule one job array per rule);
* ``individual``: the same with ``--slurm-array-jobs ''`` (one sbatch per job).

Each run appends one row to the CSV (``docs/scaling/slurm_small.csv`` by default): the mode, the
repeat, the sbatch calls counted in the plugin's own log lines (plain and array submissions), the
jobs Slurm ran (array tasks counted one by one), the wall time of the whole ``snakemake`` command
(DAG, submissions, polling, the local merge rules), the summed and longest run time Slurm gives
the run's jobs (``squeue`` ``%M``, whole seconds), the summed step time of the same jobs (their
provenance sidecars' ``wall_time_s``; the difference is the start-up in each job), the array
batches the plugin held back (its debug line "Array job collection incomplete": never submitted
when the run then hangs, upstream issue #473), the profile's ``max-jobs-per-timespan`` (or the
one given after ``--``), the plugin's version, the machine's 1-minute load average before and
after, the number of CPUs and the commit. It also times ``--sbatch-probe`` plain ``sbatch``
calls against the same controller, written to ``sbatch_rate.csv`` beside it: the submission rate
this controller sustains. Every wait is bounded (``--timeout`` per run: SIGINT, then SIGKILL).

    python -m tests.slurm.measure --repeats 2 --out docs/scaling/slurm_small.csv

Then ``python -m netrepro scaling`` regenerates ``docs/scaling.md`` from the CSVs.
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

TARGETS = [
    "results/intermittent/exact_mean.csv",
    "results/intermittent/monte_carlo.csv",
    "results/intermittent/scalar_bounds.csv",
    "results/intermittent/two_sensor_region.csv",
    "results/intermittent/two_sensor_simulation.csv",
    "results/onebit/estimator_mse.csv",
    "results/hinf/loop_variants.csv",
    "results/hinf/kalman_best.csv",
    "results/hinf/loop_swap.csv",
]
MODES = {"arrays": [], "individual": ["--slurm-array-jobs", ""]}
FIELDS = ["mode", "repeat", "submissions", "array_submissions", "single_submissions", "jobs", "array_tasks",
          "wall_s", "job_sum_s", "job_max_s", "step_sum_s", "held_back", "rate_limit", "plugin", "load_before",
          "load_after", "cpus", "targets", "shards", "status", "commit", "started_utc"]
RATE_FIELDS = ["calls", "seconds", "per_s", "load_before", "cpus", "started_utc"]

SINGLE_RE = re.compile(r"has been submitted with SLURM jobid (\d+)")
ARRAY_RE = re.compile(r"Submitted array job with Snakemake IDs ([\d,]+) and SLURM job ID (\d+)\. "
                      r"The individual task IDs are (\d+)-(\d+)\.")


def submissions(log: str) -> dict:
    """The sbatch calls in a Snakemake log of the Slurm executor plugin.

    Returns ``single`` (job ids of one-job submissions), ``arrays`` (one ``(slurm id, first task,
    last task, snakemake job ids)`` per array submission), ``calls`` (sbatch calls: one per single
    job, one per array) and ``jobs`` (Slurm jobs: single jobs plus array tasks).
    """
    single = SINGLE_RE.findall(log)
    arrays = [(slurm_id, int(first), int(last), [int(j) for j in ids.split(",")])
              for ids, slurm_id, first, last in ARRAY_RE.findall(log)]
    tasks = sum(last - first + 1 for _, first, last, _ in arrays)
    return {"single": single, "arrays": arrays, "calls": len(single) + len(arrays), "jobs": len(single) + tasks}


def slurm_seconds(clock: str) -> int:
    """Seconds of a Slurm duration as squeue prints it (``M:SS``, ``H:MM:SS``, ``D-HH:MM:SS``)."""
    parts = [int(x) for x in re.split(r"[-:]", clock.strip())]
    return sum(v * m for v, m in zip(reversed(parts), (1, 60, 3600, 86400)))


def run_bounded(cmd, cwd, env, timeout) -> tuple[int, str, float]:
    """Run ``cmd`` in its own process group; on timeout SIGINT the group, then SIGKILL it.

    Returns ``(returncode, output, seconds)``; a timeout returns code ``-1``."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            out, _ = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, _ = proc.communicate(timeout=30)
        code = -1
    return code, out, time.monotonic() - start


def _commit() -> str:
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                             timeout=10)
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def _plugin_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("snakemake-executor-plugin-slurm")
    except PackageNotFoundError:
        return ""


def _append(path: Path, fields, row):
    new = not path.exists()
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields)
        if new:
            writer.writeheader()
        writer.writerow(row)


def sbatch_rate(cluster, partition: str, calls: int) -> dict:
    """Time ``calls`` plain ``sbatch --hold`` submissions (then cancelled): this controller's rate."""
    env = cluster.client_env()
    load = os.getloadavg()[0]
    started = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    ids = []
    t0 = time.monotonic()
    for _ in range(calls):
        out = subprocess.run(["sbatch", "--parsable", "--hold", "-p", partition, "-J", "netrepro-probe",
                              "--wrap", "true"], capture_output=True, text=True, env=env, timeout=30, check=True)
        ids.append(out.stdout.strip().split(";")[0])
    seconds = time.monotonic() - t0
    subprocess.run(["scancel", *ids], env=env, timeout=30, capture_output=True)
    return {"calls": calls, "seconds": round(seconds, 3), "per_s": round(calls / seconds, 2),
            "load_before": round(load, 2), "cpus": os.cpu_count(), "started_utc": started}


def measure_once(cluster, mode: str, repeat: int, timeout: float, shards: dict | None, extra=()) -> tuple[dict, str]:
    """One cold run of :data:`TARGETS` through the Slurm profile in a fresh scratch copy."""
    import yaml

    from netrepro.scale.projection import job_times
    from tests.conftest import copy_repo
    from tests.slurm.cluster import PARTITION

    work = copy_repo(Path(tempfile.mkdtemp(prefix=f"netrepro-measure-{mode}-")) / "repo")
    cfg = yaml.safe_load((work / "config/test.yaml").read_text())
    if shards:
        cfg["shards"] = dict(shards)
    (work / "config/measure.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    env = cluster.client_env()
    env["PYTHONPATH"] = str(work / "src")
    env["MPLBACKEND"] = "Agg"
    env["NETREPRO_SLURM_PARTITION"] = PARTITION
    env.pop("NETREPRO_SLURM_ACCOUNT", None)
    # --verbose: the plugin's debug lines say when it holds an array batch back (upstream issue #473)
    cmd = [sys.executable, "-m", "snakemake", *TARGETS, "--configfile", "config/measure.yaml", "--profile",
           "workflow/profiles/slurm", "--verbose", "--slurm-init-seconds-before-status-checks", "3",
           *MODES[mode], *extra]
    profile = yaml.safe_load((work / "workflow/profiles/slurm/config.yaml").read_text())
    rate = next((b for a, b in zip(extra, list(extra)[1:]) if a == "--max-jobs-per-timespan"),
                profile.get("max-jobs-per-timespan"))
    known_before = {row[0] for row in cluster.jobs(fields="%i")}
    load_before = os.getloadavg()[0]
    started = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    code, log, wall = run_bounded(cmd, work, env, timeout)
    load_after = os.getloadavg()[0]
    subs = submissions(log)
    times = [slurm_seconds(t) for job_id, state, t in cluster.jobs(fields="%i|%T|%M")
             if job_id not in known_before and state == "COMPLETED"]
    # the steps' own time (sidecars) of the jobs that ran on Slurm: the rest of job_sum_s is start-up
    local = set(re.findall(r"^localrule (\w+):", log, re.MULTILINE))
    steps = {key: seconds for rule, key, seconds in job_times(work).values() if rule not in local}
    status = "ok" if code == 0 else ("timeout" if code == -1 else f"failed({code})")
    row = {"mode": mode, "repeat": repeat, "submissions": subs["calls"], "array_submissions": len(subs["arrays"]),
           "single_submissions": len(subs["single"]), "jobs": subs["jobs"],
           "array_tasks": subs["jobs"] - len(subs["single"]), "wall_s": round(wall, 1),
           "job_sum_s": sum(times), "job_max_s": max(times, default=0),
           "step_sum_s": round(sum(steps.values()), 1),
           "held_back": len(re.findall(r"Array job collection incomplete", log)), "rate_limit": rate,
           "plugin": _plugin_version(), "load_before": round(load_before, 2),
           "load_after": round(load_after, 2), "cpus": os.cpu_count(), "targets": len(TARGETS),
           "shards": " ".join(f"{k}={v}" for k, v in cfg.get("shards", {}).items()), "status": status,
           "commit": _commit(), "started_utc": started}
    return row, log


def main(argv=None) -> int:
    from tests.slurm.cluster import PARTITION, LocalSlurm, SlurmUnavailable

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modes", nargs="+", default=list(MODES), choices=list(MODES))
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--first-repeat", type=int, default=1, help="number of the first repeat (to add runs)")
    parser.add_argument("--timeout", type=float, default=1500, help="seconds per run before SIGINT")
    parser.add_argument("--out", type=Path, default=ROOT / "docs/scaling/slurm_small.csv")
    parser.add_argument("--sbatch-probe", type=int, default=20, help="plain sbatch calls timed (0: none)")
    parser.add_argument("--shards", default="", help="e.g. 'onebit_estimator=3,hinf_kalman_best=3'")
    parser.add_argument("--logs", type=Path, help="directory for the Snakemake logs of the runs")
    parser.add_argument("extra", nargs="*", help="more snakemake options (after --)")
    args = parser.parse_args(argv)
    shards = {k: int(v) for k, v in (p.split("=") for p in args.shards.split(",") if p)} or None

    cluster = LocalSlurm(default_partition=False)
    try:
        cluster.start()
    except SlurmUnavailable as exc:
        print(f"no local Slurm cluster: {exc}", file=sys.stderr)
        return 1
    try:
        if args.sbatch_probe:
            rate = sbatch_rate(cluster, PARTITION, args.sbatch_probe)
            _append(args.out.with_name("sbatch_rate.csv"), RATE_FIELDS, rate)
            print(f"sbatch: {rate}", flush=True)
        for repeat in range(args.first_repeat, args.first_repeat + args.repeats):
            for mode in args.modes:
                row, log = measure_once(cluster, mode, repeat, args.timeout, shards, args.extra)
                _append(args.out, FIELDS, row)
                if args.logs:
                    args.logs.mkdir(parents=True, exist_ok=True)
                    (args.logs / f"{mode}-{repeat}.log").write_text(log)
                print(row, flush=True)
                if row["status"] != "ok":
                    print(log[-3000:], file=sys.stderr, flush=True)
    finally:
        cluster.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
