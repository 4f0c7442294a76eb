"""Projected wall time of the workflow on N cluster nodes, from measured per-job times.

Reads the jobs and their dependencies from a dry run (``snakemake -n ... report`` output:
each job's rule, wildcards, inputs and outputs), takes each job's time from one of

* ``--squeue FILE``: ``squeue -h -t all -o '%i|%k|%T|%M'`` of a run under Slurm
  (the comment ``%k`` names rule and wildcards; ``%M`` is the job's run time, so it includes
  the per-job start-up: Snakemake in the job, ``srun``, Python imports), or
* ``--results DIR``: the provenance sidecars (``<output>.meta.json``, ``wall_time_s``) of a
  run, plus ``--overhead`` seconds per job for the start-up a sidecar does not see,

and list-schedules the DAG (longest remaining path first; :func:`netrepro.scale.projection.schedule`) on
N nodes with ``--cores`` job slots each. ``python -m netrepro scaling`` does the same from committed
tables for ``docs/scaling.md``. Prints the job count, the summed job time, the critical path and the makespan
per N. Jobs without a measured time get ``--default`` seconds (plus the overhead).

    python tests/slurm/project.py --dry-run dry.log --results results --overhead 20 --nodes 1 2 4 8 16
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from netrepro.scale.projection import parse_dry_run, schedule  # the one implementation (tested in tests/test_scaling.py)

__all__ = ["parse_dry_run", "schedule", "main"]


def _slurm_key(rule, wildcards):
    key = f"rule_{rule}"
    if wildcards:
        key += "_wildcards_" + "_".join(str(v) for v in wildcards.values())
    return key


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dry-run", required=True, type=Path, help="output of `snakemake -n ... report`")
    parser.add_argument("--squeue", type=Path, help="squeue -h -t all -o '%%i|%%k|%%T|%%M' of a Slurm run")
    parser.add_argument("--results", type=Path, help="root of a run's outputs (sidecars <output>.meta.json)")
    parser.add_argument("--overhead", type=float, default=0.0, help="seconds added to each sidecar time")
    parser.add_argument("--default", type=float, default=10.0, help="seconds for a job without a measured time")
    parser.add_argument("--nodes", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    parser.add_argument("--cores", type=int, default=1, help="jobs at once per node")
    args = parser.parse_args(argv)

    jobs = parse_dry_run(args.dry_run.read_text())
    measured = {}
    if args.squeue:
        for line in args.squeue.read_text().splitlines():
            parts = line.split("|")
            if len(parts) >= 4 and parts[2] == "COMPLETED":
                clock = [int(x) for x in re.split(r"[-:]", parts[3])]
                seconds = sum(v * m for v, m in zip(reversed(clock), (1, 60, 3600, 86400)))
                measured[parts[1]] = seconds
    durations, parents, unmeasured = {}, {}, []
    producer = {out: j["jobid"] for j in jobs for out in j["output"]}
    for j in jobs:
        jid = j["jobid"]
        t = measured.get(_slurm_key(j["rule"], j["wildcards"]))
        if t is None and args.results:
            for out in j["output"]:
                sidecar = args.results / (out + ".meta.json")
                if sidecar.is_file():
                    t = json.loads(sidecar.read_text()).get("wall_time_s")
                    if t is not None:
                        t += args.overhead
                        break
        if t is None:
            unmeasured.append(j["rule"])
            t = args.default + args.overhead
        durations[jid] = float(t)
        parents[jid] = sorted({producer[i] for i in j["input"] if i in producer and producer[i] != jid})
    total = sum(durations.values())
    critical = schedule(durations, parents, slots=len(durations))
    print(f"jobs: {len(jobs)}  summed job time: {total:.0f} s  critical path: {critical:.0f} s")
    if unmeasured:
        print(f"no measured time ({args.default:.0f} s assumed): {', '.join(sorted(set(unmeasured)))}")
    print("nodes  slots  projected wall time")
    for n in args.nodes:
        print(f"{n:5d}  {n * args.cores:5d}  {schedule(durations, parents, n * args.cores):8.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
