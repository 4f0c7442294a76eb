"""How the workflow scales on a cluster: per-rule work, projected wall times, ``docs/scaling.md``.

Three steps, each from data a run wrote:

1. :func:`rule_work` reads a build directory's provenance sidecars (``<output>.meta.json``, field
   ``wall_time_s``; the rule from the sidecar's ``rule`` or from the ``"rule"`` of the command's
   ``--io`` JSON) and sums the work per rule. One job writing several outputs leaves one sidecar
   per output with the same command: it is counted once.
2. :func:`parse_dry_run` reads the jobs and their dependencies from a dry run
   (``snakemake -n --forceall ...``), :func:`job_table` gives each job its measured time, and
   :func:`project` bounds and list-schedules the DAG (:func:`schedule`: longest remaining path
   first) on N nodes of C job slots.
3. :func:`write_doc` (``python -m netrepro scaling``) writes ``docs/scaling.md`` from the committed
   CSVs under ``docs/scaling/``: the measured Slurm runs (``tests/slurm/measure.py``), the
   per-rule work and the projection. Nothing in it is typed by hand but the prose.

The lower bound of the wall time on ``s`` slots is ``max(critical path, total work / s)``: no
schedule beats the longest dependency chain, nor perfect division of the summed work. A list
schedule is within a factor ``2 - 1/s`` of the optimum (Graham 1966, Bell Syst. Tech. J. 45,
Theorem 1), so ``lower bound <= list schedule <= (2 - 1/s) * optimum``.
"""

from __future__ import annotations

import argparse
import csv
import heapq
import json
import re
import shlex
import sys
from pathlib import Path

__all__ = [
    "job_times", "rule_work", "local_rules", "write_csv", "read_csv", "parse_dry_run", "job_table",
    "critical_path", "schedule", "project", "measured_overhead", "collect", "collect_partial", "render_doc",
    "write_doc", "main",
]

SIDECAR = ".meta.json"
SIDECAR_DIRS = ("results", "figures", "report")
DATA = Path("docs/scaling")
DOC = Path("docs/scaling.md")
NODES = (1, 8, 64)
CORES = 2
TOP_RULES = 20  # rules listed one by one in docs/scaling.md; the CSV has them all


# ---- 1. per-rule work ----------------------------------------------------------------------------------
def _rule_of(meta: dict) -> str | None:
    """The rule a sidecar belongs to: its ``rule`` field, else the command's ``--rule`` (or, in
    runs recorded before that flag, the ``"rule"`` of its ``--io`` JSON)."""
    if meta.get("rule"):
        return str(meta["rule"])
    try:
        words = shlex.split(meta.get("command", ""))
    except ValueError:
        return None
    for flag, value in zip(words, words[1:]):
        if flag == "--rule":
            return value
        if flag == "--io":
            try:
                return json.loads(value).get("rule")
            except (ValueError, AttributeError):
                return None
    return None


def _sidecars(build: Path, dirs=SIDECAR_DIRS):
    for sub in dirs:
        root = build / sub
        if root.is_dir():
            yield from sorted(root.rglob("*" + SIDECAR))


def job_times(build: Path, dirs=SIDECAR_DIRS) -> dict:
    """The step time of every output of a build, from its provenance sidecars.

    Parameters
    ----------
    build : path
        A build directory (the root of a checkout that ran the workflow).
    dirs : sequence of str
        Its subdirectories searched for sidecars ``<output>.meta.json``.

    Returns
    -------
    dict
        ``{output path relative to build: (rule, job key, wall_time_s)}``; the job key is the
        sidecar's command (one job, one command, whatever its number of outputs). Sidecars without
        a time or a rule are left out.
    """
    found = {}
    for path in _sidecars(Path(build), dirs):
        try:
            meta = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if not isinstance(meta, dict) or meta.get("wall_time_s") is None:
            continue
        rule = _rule_of(meta)
        if rule is None:
            continue
        output = str(path.relative_to(build))[: -len(SIDECAR)]
        key = meta.get("command") or meta.get("output") or output
        found[output] = (rule, key, float(meta["wall_time_s"]))
    return found


def rule_work(build: Path, dirs=SIDECAR_DIRS) -> list[dict]:
    """Work per rule of a build: ``rule, jobs, total_s, max_job_s`` rows, most work first.

    Parameters
    ----------
    build : path
        A build directory (the root of a checkout that ran the workflow).
    dirs : sequence of str
        Its subdirectories searched for sidecars ``<output>.meta.json``.

    Returns
    -------
    list of dict
        One row per rule: the number of distinct jobs (distinct commands), their summed
        ``wall_time_s`` and the longest one, in seconds (3 decimals, as the sidecars).
    """
    jobs = {}
    for rule, key, seconds in job_times(build, dirs).values():
        jobs[(rule, key)] = seconds
    per_rule = {}
    for (rule, _), seconds in jobs.items():
        row = per_rule.setdefault(rule, {"rule": rule, "jobs": 0, "total_s": 0.0, "max_job_s": 0.0})
        row["jobs"] += 1
        row["total_s"] += seconds
        row["max_job_s"] = max(row["max_job_s"], seconds)
    rows = sorted(per_rule.values(), key=lambda r: (-r["total_s"], r["rule"]))
    for row in rows:
        row["total_s"] = round(row["total_s"], 3)
        row["max_job_s"] = round(row["max_job_s"], 3)
    return rows


def write_csv(rows: list[dict], path: Path, fields=None) -> Path:
    """Write ``rows`` as a CSV.

    Parameters
    ----------
    rows : list of dict
        The rows.
    path : path
        The file written (its directory is created).
    fields : list of str, optional
        The columns, in order; the first row's keys when None.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fields = fields or (list(rows[0]) if rows else [])
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    return path


def read_csv(path: Path) -> list[dict]:
    """The rows of a CSV.

    Parameters
    ----------
    path : path
        The file.

    Returns
    -------
    list of dict
        One dict of strings per row; ``[]`` when the file does not exist.
    """
    path = Path(path)
    if not path.is_file():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# ---- 2. the DAG and its schedule ---------------------------------------------------------------------------
def parse_dry_run(text: str) -> list[dict]:
    """The jobs of a dry run (``snakemake -n``, with ``--forceall`` for every job).

    Parameters
    ----------
    text : str
        The dry run's output.

    Returns
    -------
    list of dict
        One per job: ``rule``, ``local`` (a local rule: it runs in the main Snakemake process, not
        on the cluster), ``jobid``, ``wildcards`` (dict), ``input`` and ``output`` (lists).
    """
    jobs, job = [], None
    for line in text.splitlines():
        head = re.match(r"^(local)?rule (\w+):\s*$", line)
        if head:
            job = {"rule": head.group(2), "local": bool(head.group(1)), "input": [], "output": [], "wildcards": {}}
            jobs.append(job)
            continue
        field = re.match(r"^\s+(input|output|jobid|wildcards): (.*)$", line)
        if job is None or not field:
            continue
        key, value = field.groups()
        if key == "jobid":
            job["jobid"] = int(value)
        elif key == "wildcards":
            job["wildcards"] = dict(part.split("=", 1) for part in value.split(", ") if "=" in part)
        else:
            job[key] = [v.strip() for v in value.split(", ") if v.strip()]
    return [j for j in jobs if "jobid" in j]


def local_rules(workflow: Path = Path("."), configfiles=()) -> set[str]:
    """The rules Snakemake runs in its main process (``localrule: True`` or ``localrules:``).

    A dry run does not tell them apart, so the workflow is loaded with Snakemake's API.

    Parameters
    ----------
    workflow : path
        A checkout of the workflow (its ``Snakefile`` at the root); nothing is run or written.
    configfiles : sequence of path
        The configuration files, as for ``--configfile``.

    Returns
    -------
    set of str
        The names of the local rules.
    """
    import os

    from snakemake.api import SnakemakeApi
    from snakemake.settings.types import ConfigSettings, OutputSettings, ResourceSettings

    workflow = Path(workflow).resolve()
    here = Path.cwd()
    os.chdir(workflow)  # the workflow reads its config and rule files relative to its root
    try:
        with SnakemakeApi(OutputSettings()) as api:
            api_wf = api.workflow(resource_settings=ResourceSettings(),
                                  config_settings=ConfigSettings(configfiles=[Path(c) for c in configfiles]),
                                  snakefile=Path("Snakefile"), workdir=workflow)
            wf = api_wf._workflow
            # Workflow.is_local without its "everything is local" switch (no cluster executor here)
            return {rule.name for rule in wf.rules if rule.group is None
                    and (rule.name in wf._localrules or rule.norun or rule.is_template_engine)}
    finally:
        os.chdir(here)


def job_table(jobs: list[dict], times: dict, default: float, local=frozenset(), fallback=None) -> list[dict]:
    """One row per dry-run job, with its time and the jobs it waits for.

    Parameters
    ----------
    jobs : list of dict
        The jobs of :func:`parse_dry_run`.
    times : dict
        ``{output path: (rule, key, seconds)}`` (:func:`job_times`); a job takes the time of its
        first output that has one.
    default : float
        Seconds of a job none of whose outputs has a time.
    local : set of str
        Names of local rules (:func:`local_rules`); a job is local when its rule is one of them or
        the dry run marked it ``localrule``.
    fallback : dict, optional
        Times of another build, like ``times``, for the jobs ``times`` lacks (before ``default``).
        Before it, a job ``times`` lacks takes the median time of the other jobs of its rule that
        ``times`` has (source ``rule``).

    Returns
    -------
    list of dict
        ``jobid, rule, wildcards, seconds, measured`` (1 when timed by ``times``, 0 otherwise),
        ``source`` (``build``, ``rule``, ``fallback`` or ``default``), ``local``
        (1 for a local rule) and ``parents`` (the jobids whose outputs it reads, space separated), by jobid.
    """
    producer = {out: j["jobid"] for j in jobs for out in j["output"]}
    timed = {}
    for j in jobs:
        seconds = next((times[out][2] for out in j["output"] if out in times), None)
        if seconds is not None:
            timed.setdefault(j["rule"], []).append(seconds)
    rows = []
    for j in sorted(jobs, key=lambda j: j["jobid"]):
        seconds = next((times[out][2] for out in j["output"] if out in times), None)
        source = "build"
        if seconds is None and j["rule"] in timed:
            # another job of the same rule in the same build, e.g. a shard still running: the shards
            # of a step split the same work evenly
            seconds, source = _median(timed[j["rule"]]), "rule"
        if seconds is None and fallback:
            seconds = next((fallback[out][2] for out in j["output"] if out in fallback), None)
            source = "fallback"
        if seconds is None:
            source = "default"
        parents = sorted({producer[i] for i in j["input"] if i in producer and producer[i] != j["jobid"]})
        rows.append({"jobid": j["jobid"], "rule": j["rule"],
                     "wildcards": " ".join(f"{k}={v}" for k, v in j["wildcards"].items()),
                     "seconds": round(default if seconds is None else seconds, 3),
                     "measured": int(source == "build"), "source": source,
                     "local": int(bool(j.get("local")) or j["rule"] in local),
                     "parents": " ".join(map(str, parents))})
    return rows


def _graph(rows: list[dict], overhead: float = 0.0):
    # a local rule runs in the main process: no Slurm job, no start-up
    durations = {int(r["jobid"]): float(r["seconds"]) + (0.0 if str(r.get("local", 0)) == "1" else overhead)
                 for r in rows}
    parents = {int(r["jobid"]): [int(p) for p in str(r.get("parents") or "").split()] for r in rows}
    return durations, parents


def _children(durations: dict, parents: dict) -> dict:
    children = {j: [] for j in durations}
    for j, ps in parents.items():
        for p in ps:
            children[p].append(j)
    return children


def _remaining(durations: dict, children: dict) -> dict:
    """Longest path from the start of each job to the end of the workflow (iterative, any depth)."""
    rank, order, seen = {}, [], set()
    for root in durations:
        stack = [(root, False)]
        while stack:
            j, done = stack.pop()
            if done:
                order.append(j)
                continue
            if j in seen:
                continue
            seen.add(j)
            stack.append((j, True))
            stack.extend((c, False) for c in children[j] if c not in seen)
    for j in order:  # children before parents
        rank[j] = durations[j] + max((rank[c] for c in children[j]), default=0.0)
    return rank


def critical_path(durations: dict, parents: dict) -> float:
    """The length of the longest dependency chain: the wall time on unboundedly many slots.

    Parameters
    ----------
    durations : dict
        ``{job: seconds}``.
    parents : dict
        ``{job: [jobs it waits for]}``.

    Returns
    -------
    float
        The largest sum of durations along a chain of dependencies (0 for no job).
    """
    rank = _remaining(durations, _children(durations, parents))
    return max(rank.values(), default=0.0)


def schedule(durations: dict, parents: dict, slots: int) -> float:
    """The makespan of a list schedule on ``slots`` job slots.

    A job starts when its parents are done and a slot is free; among ready jobs the one with the
    longest remaining path goes first (ties: the lower job id).

    Parameters
    ----------
    durations : dict
        ``{job: seconds}``.
    parents : dict
        ``{job: [jobs it waits for]}``.
    slots : int
        Jobs that run at once (at least 1).

    Returns
    -------
    float
        The time the last job ends.

    Raises
    ------
    ValueError
        If ``slots`` is below 1.
    """
    if slots < 1:
        raise ValueError(f"slots must be at least 1, got {slots}")
    children = _children(durations, parents)
    rank = _remaining(durations, children)
    waiting = {j: len(parents.get(j, ())) for j in durations}
    ready = [(-rank[j], j) for j, n in waiting.items() if n == 0]
    heapq.heapify(ready)
    running, now, free = [], 0.0, slots
    while ready or running:
        while ready and free:
            _, j = heapq.heappop(ready)
            heapq.heappush(running, (now + durations[j], j))
            free -= 1
        now, done = heapq.heappop(running)
        free += 1
        for c in children[done]:
            waiting[c] -= 1
            if waiting[c] == 0:
                heapq.heappush(ready, (-rank[c], c))
    return now


def project(rows: list[dict], nodes=NODES, cores: int = CORES, overhead: float = 0.0) -> list[dict]:
    """The projected wall time of a job table on each node count.

    Parameters
    ----------
    rows : list of dict
        Jobs with ``jobid``, ``seconds`` and ``parents`` (:func:`job_table`, or its CSV).
    nodes : sequence of int
        Node counts.
    cores : int
        Job slots per node.
    overhead : float
        Seconds added first to every job but those of local rules (the start-up of a Slurm job).

    Returns
    -------
    list of dict
        Per node count: ``nodes, slots, total_work_s, critical_path_s``, ``lower_bound_s``
        (max of the critical path and the work per slot) and ``list_schedule_s``
        (:func:`schedule`), seconds rounded to 0.1.
    """
    durations, parents = _graph(rows, overhead)
    total = sum(durations.values())
    critical = critical_path(durations, parents)
    out = []
    for n in nodes:
        slots = n * cores
        out.append({"nodes": n, "slots": slots, "total_work_s": round(total, 1),
                    "critical_path_s": round(critical, 1), "lower_bound_s": round(max(critical, total / slots), 1),
                    "list_schedule_s": round(schedule(durations, parents, slots), 1)})
    return out


# ---- 3. docs/scaling.md ------------------------------------------------------------------------------------
def _table(rows: list[dict], columns: list[str]) -> str:
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(str(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def _f(x, digits=1) -> str:
    return f"{float(x):.{digits}f}"


def _reshard_note(jobs: list[dict], longest: dict) -> str:
    """What more shards would make of the longest job, when it is a shard (its step's work split evenly)."""
    if not longest["rule"].endswith("_shard"):
        return ""
    same = [float(r["seconds"]) for r in jobs if r["rule"] == longest["rule"]]
    work = sum(same)
    splits = ", ".join(f"{k} shards {work / k:.0f} s" for k in (16, 64) if k > len(same))
    return (f" Its step's {len(same)} shards hold {work:.0f} s of work; split evenly that is "
            f"{splits} per shard (shard counts are set per run: `--config 'shards={{...}}'`)." if splits else "")


def _counts(shards: str) -> str:
    """``"a=2 b=3"`` -> ``"2/3"``: the shard counts of a measured run, in their order."""
    return "/".join(part.split("=", 1)[1] for part in str(shards).split() if "=" in part)


def _total(shards: str) -> int:
    return sum(int(c) for c in _counts(shards).split("/") if c.isdigit())


def _median(values):
    v = sorted(values)
    return (v[len(v) // 2] + v[(len(v) - 1) // 2]) / 2 if v else float("nan")


def _measured_section(data, rates, runs) -> list:
    """The measured runs on the local Slurm (arrays against single jobs), the array deadlock, the sbatch rate."""
    parts = []
    parts += ["", "## Measured: the small configuration on the local Slurm, with and without job arrays", ""]
    if runs:
        parts.append(
            "Each row is one cold run of the sharded tables of `config/test.yaml` (intermittent, the onebit "
            "estimator, hinf's loop variants and Kalman-best; every shard count as in the row) through "
            "`workflow/profiles/slurm`, in a fresh copy of the repository. `arrays`: the profile as it is "
            "(each `*_shard` rule one job array); `individual`: `--slurm-array-jobs ''` (one sbatch per job). "
            "`submissions` counts sbatch calls in the plugin's log, `jobs` the Slurm jobs (array tasks one by "
            "one); `wall_s` is the whole `snakemake` command; `job_sum_s`/`job_max_s` are Slurm's run times "
            "(squeue, whole seconds) of the run's jobs and `step_sum_s` the steps' own time in them "
            "(sidecars). `shards` are the shard counts of intermittent_monte_carlo / "
            "intermittent_two_sensor_region / onebit_estimator / hinf_loop_variants / hinf_kalman_best. "
            "The load is the machine's 1-minute load average before and after (other work shared the "
            "machine's 2 cores; the test node offers 4 job slots).")
        parts += ["", _table([{**r, "shards": _counts(r["shards"])} for r in runs],
                             ["mode", "repeat", "status", "shards", "submissions", "array_submissions",
                              "single_submissions", "jobs", "wall_s", "job_sum_s", "job_max_s", "step_sum_s",
                              "load_before", "load_after", "cpus"]), ""]
        summary = []
        for shards, mode in sorted({(r["shards"], r["mode"]) for r in runs}, key=lambda k: (_total(k[0]), k[1])):
            ok = [r for r in runs if r["mode"] == mode and r["shards"] == shards and r["status"] == "ok"]
            if ok:
                summary.append({"shards": _counts(shards), "mode": mode, "runs": len(ok),
                                "submissions (median)": _f(_median([float(r["submissions"]) for r in ok]), 0),
                                "jobs (median)": _f(_median([float(r["jobs"]) for r in ok]), 0),
                                "wall_s (median)": _f(_median([float(r["wall_s"]) for r in ok])),
                                "wall_s (min-max)": f"{min(float(r['wall_s']) for r in ok):.1f}-"
                                                    f"{max(float(r['wall_s']) for r in ok):.1f}"})
        if summary:
            parts += ["Summary of the successful runs:", "",
                      _table(summary, list(summary[0])), ""]
            text = ("With arrays a step costs one sbatch call whatever its shard count, so the saving grows "
                    "with the shards per step. ")
            largest = max((r["shards"] for r in runs if r["status"] == "ok"), key=_total)
            by_mode = {row["mode"]: row for row in summary if row["shards"] == _counts(largest)}
            if {"arrays", "individual"} <= set(by_mode):
                a, i = by_mode["arrays"], by_mode["individual"]
                text += (f"At the largest shard counts measured ({_counts(largest)}) the calls went from "
                         f"{i['submissions (median)']} to {a['submissions (median)']} and the wall time "
                         f"from {i['wall_s (median)']} s to {a['wall_s (median)']} s (medians). ")
                faster = float(a["wall_s (median)"]) < float(i["wall_s (median)"])
            else:
                faster = None
            text += ("The wall time on this one node is set by its job slots, the machine's load and the "
                     "per-job start-up (`job_sum_s` against the steps' own `step_sum_s`), not by the "
                     "submissions: arrays save sbatch calls, the scheduler's and the administrators' concern"
                     + {True: ", and were also faster here.", False: ", and did not make runs faster here.",
                        None: "."}[faster]
                     + " Per job, an array task starts more Snakemake processes than a plain job: from the "
                     "second task on, snakemake-executor-plugin-slurm-jobstep (0.6.1, read in its code) runs "
                     "the task's own submission command, itself a Snakemake that then starts the step's, "
                     "inside the Snakemake of the array's first job; one workflow parse more per task, "
                     "which shows in `job_sum_s` against `step_sum_s`.")
            parts += [text, ""]
    else:
        parts += ["No measured run yet (`python -m tests.slurm.measure`).", ""]
    deadlock = read_csv(data / "array_deadlock.csv")
    if deadlock:
        parts += ["### Job arrays and the scheduler's rate limit (plugin issue #473)", "",
                  "The plugin submits a rule's jobs as an array only once it holds every ready job of "
                  "that rule; a smaller batch is set aside (its debug line \"Array job collection "
                  "incomplete\") and, Snakemake having already counted it as running, never offered again. "
                  "Snakemake hands jobs over in batches of at most `max-jobs-per-timespan` per second, so "
                  "a limit below the number of ready shards cuts them and the run waits forever (upstream "
                  "issue #473, reported for 2.7.1). These runs (more shards per step than the test, "
                  "`held_back`: batches set aside; `timeout`: the run was stopped at its time limit) are "
                  "why the profile hands over up to 100 jobs per second:", "",
                  _table([{**r, "shards": _counts(r["shards"])} for r in deadlock],
                         ["plugin", "rate_limit", "shards", "status", "held_back", "submissions", "jobs",
                          "wall_s", "load_before", "started_utc"]), ""]
    if rates:
        parts.append("Plain `sbatch --hold` calls timed against the same controller (the submission rate it "
                     "sustains, one caller):")
        parts += ["", _table(rates, ["calls", "seconds", "per_s", "load_before", "started_utc"]), ""]

    return parts


def _work_per_rule_section(data, rules, src) -> list:
    """The work per rule of a complete build, and of the unfinished paper-scale build."""
    parts = []
    parts += ["## Work per rule", ""]
    if rules:
        parts.append(
            f"From the provenance sidecars (`wall_time_s`: the step itself, without the start of Snakemake "
            f"and Python in the job) of the build in `{src.get('rules_build') or src.get('build', '?')}` "
            f"({src.get('rules_what') or src.get('what', 'configuration not recorded')}). One row per rule, "
            "most work first.")
        total = sum(float(r["total_s"]) for r in rules)
        shown = rules[:TOP_RULES]
        rest = rules[TOP_RULES:]
        if rest:
            shown = shown + [{"rule": f"({len(rest)} more rules)", "jobs": sum(int(r["jobs"]) for r in rest),
                              "total_s": f"{sum(float(r['total_s']) for r in rest):.3f}",
                              "max_job_s": f"{max(float(r['max_job_s']) for r in rest):.3f}"}]
        parts += ["", _table(shown, ["rule", "jobs", "total_s", "max_job_s"]), "",
                  f"Total: {total:.1f} s of step time in {sum(int(r['jobs']) for r in rules)} jobs "
                  f"(every rule: `docs/scaling/paper_scale_rules.csv`).", ""]
    else:
        parts += ["No per-rule table yet.", ""]

    partial = read_csv(data / "paper_scale_partial_rules.csv")
    if partial:
        head, rows = partial[0], partial[1:]
        parts += ["## The paper-scale build, as far as it had run", "",
                  f"Sidecars of an unfinished paper-scale build ({head['note']}): the rules that had "
                  "finished, most work first. The projection below takes these times for the jobs they cover.", "",
                  _table(rows[:TOP_RULES], ["rule", "jobs", "total_s", "max_job_s"]), ""]
        if rows:
            top = max(rows, key=lambda r: float(r["max_job_s"]))
            parts += [f"{len(rows)} rules, {sum(int(r['jobs']) for r in rows)} jobs, "
                      f"{sum(float(r['total_s']) for r in rows):.0f} s of step time; the longest job so far: "
                      f"{top['rule']}, {float(top['max_job_s']):.0f} s.", ""]
    return parts


def _projection_section(jobs, rates, runs, src) -> list:
    """The projected wall time on N nodes, and where the projection stops holding."""
    parts = []
    parts += ["## Projected wall time on N nodes of 2 cores", ""]
    if jobs:
        overhead = float(src.get("overhead_s", 0.0) or 0.0)
        unmeasured = sorted({r["rule"] for r in jobs if r.get("source", "build" if r["measured"] == "1" else
                                                               "default") == "default"})
        from_fallback = [r for r in jobs if r.get("source") == "fallback"]
        text = (f"The DAG is the dry run's ({len(jobs)} jobs) for the configuration and shard counts of "
                f"`{src.get('build', '?')}`. Each job takes its sidecar time there")
        from_rule = [r for r in jobs if r.get("source") == "rule"]
        if from_rule:
            text += (f"; {len(from_rule)} jobs without one take the median time of their rule's other jobs "
                     f"there ({', '.join(sorted({r['rule'] for r in from_rule}))}: shards of one step split "
                     "the same work evenly)")
        if from_fallback:
            text += (f"; the {len(from_fallback)} other jobs without one (the build had not finished) take the time "
                     f"of the same output in `{src.get('fallback')}` (the default configuration: a low "
                     f"estimate for them)")
        parts.append(
            text + f"; jobs without any ({', '.join(unmeasured) or 'none'}) take "
            f"{src.get('default_s', '?')} s. `+overhead` rows add {overhead:.1f} s to every job that runs "
            "on Slurm (not to the local rules): "
            f"{src.get('overhead_note', 'the per-job start-up')}. The lower bound is "
            "max(critical path, total work / slots); the list schedule runs the ready job with the "
            "longest remaining path first on 2 slots per node (no schedule is shorter than the bound, and "
            "a list schedule is at most 2 - 1/slots times the best one). Local rules' jobs (merges, "
            "figures, notebooks, the report) run on the login node; the model puts them on the nodes' "
            "slots too, which errs long by their step time.")
        rows = []
        for label, extra in (("step time", 0.0), ("+overhead", overhead)):
            for p in project(jobs, NODES, CORES, extra):
                rows.append({"job time": label, **p})
        parts += ["", _table(rows, ["job time", "nodes", "slots", "total_work_s", "critical_path_s",
                                     "lower_bound_s", "list_schedule_s"]), ""]
        rate = next((r["rate_limit"] for r in reversed(runs) if r.get("rate_limit")), "100/1s")
        longest = max((r for r in jobs if r["measured"] == "1") or jobs, key=lambda r: float(r["seconds"]))
        merges = [r for r in jobs if r["rule"] + "_shard" in {x["rule"] for x in jobs}]
        parts.append("## Where the projection stops holding")
        parts += ["",
                  f"* **The longest single job** ({longest['rule']} {longest['wildcards']}".rstrip()
                  + f", {float(longest['seconds']):.1f} s) bounds the wall time from below whatever the node "
                  "count; only more shards of its step (a larger `shards:` count) shorten it, and only for "
                  "shard rules." + _reshard_note(jobs, longest),
                  f"* **The merge steps run serially**: {len(merges)} merge jobs "
                  f"({', '.join(sorted({r['rule'] for r in merges})) or 'none'}) each wait for all of their "
                  f"step's shards and run as one job on the login node (local rules), "
                  f"{sum(float(r['seconds']) for r in merges):.1f} s in total here; each starts only after its "
                  "step's last shard, and the figures, notebooks and the report queue behind them: "
                  "the end of the critical path, which no node count shortens.",
                  "* **The scheduler's submission rate**: the profile lets Snakemake hand jobs to the "
                  f"plugin at most as fast as `max-jobs-per-timespan: {rate}`, and the plugin "
                  "calls sbatch from two threads. "
                  + (f"Plain sbatch calls here ran at {_f(rates[-1]['per_s'])} per second on this "
                     f"controller, so the {len(jobs)} jobs would take "
                     f"{len(jobs) / float(rates[-1]['per_s']):.1f} s of submission one by one; "
                     if rates else "")
                  + "a real cluster's controller is shared and slower, and administrators cap submissions "
                  "per user, which arrays (one sbatch call per step) keep low. The queue wait of each job "
                  "on a shared cluster comes on top and is not modelled.",
                  "* **Snakemake's own start-up**: the main process parses the workflow and builds the DAG "
                  "before the first submission, and every Slurm job starts Snakemake and Python again "
                  "(the `+overhead` rows; measured on a machine loaded by other work, so an upper estimate). "
                  "Where steps take seconds this start-up dominates; it matters less where single steps "
                  "take minutes.",
                  "* **Status polling**: the plugin asks squeue at intervals (first after "
                  "`slurm-init-seconds-before-status-checks`, 20 s in the profile, then up to 180 s), so "
                  "each level of the DAG can add up to one polling interval after its jobs finish.",
                  ""]
    else:
        parts += ["No job table yet.", ""]
    return parts


def render_doc(data: Path = DATA) -> str:
    """The text of ``docs/scaling.md``.

    Parameters
    ----------
    data : path
        The directory of the CSVs (``slurm_small.csv``, ``sbatch_rate.csv``, ``array_deadlock.csv``,
        ``paper_scale_rules.csv``, ``paper_scale_jobs.csv``, ``paper_scale_source.csv``); a missing
        one leaves its section saying so.

    Returns
    -------
    str
        The page, Markdown.
    """
    data = Path(data)
    runs = read_csv(data / "slurm_small.csv")
    rates = read_csv(data / "sbatch_rate.csv")
    rules = read_csv(data / "paper_scale_rules.csv")
    jobs = read_csv(data / "paper_scale_jobs.csv")
    source = read_csv(data / "paper_scale_source.csv")
    src = {r["key"]: r["value"] for r in source}

    parts = ["<!-- generated by `python -m netrepro scaling` from docs/scaling/*.csv: do not edit by hand -->",
             "# Scaling on a cluster", ""]
    parts.append(
        "Measured on this repository's own test cluster (one Slurm node on the development machine, "
        "`tests/slurm/cluster.py`), then projected to larger clusters from the per-job times of a "
        "complete build (which one: below). Regenerate the measurements with "
        "`python -m tests.slurm.measure` (as root, with the Slurm packages), the per-rule and per-job "
        "tables with `python -m netrepro scaling --collect BUILD --dry-run DRY.log` (DRY.log: "
        "`snakemake -n --forceall report` with the build's configuration and shard counts), and this page "
        "with `python -m netrepro scaling`.")
    parts += _measured_section(data, rates, runs)
    parts += _work_per_rule_section(data, rules, src)
    parts += _projection_section(jobs, rates, runs, src)
    return "\n".join(parts).rstrip() + "\n"


def write_doc(out: Path = DOC, data: Path = DATA) -> Path:
    """Write ``docs/scaling.md`` from the CSVs (:func:`render_doc`).

    Parameters
    ----------
    out : path
        The page written.
    data : path
        The directory of the CSVs.

    Returns
    -------
    Path
        ``out``.
    """
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render_doc(data))
    return out


def collect(build: Path, dry_run: Path, data: Path = DATA, default: float = 10.0, what: str = "",
            overhead: float | None = None, overhead_note: str = "", local=frozenset(),
            fallback: Path | None = None, rules_from: Path | None = None, rules_what: str = "") -> list[Path]:
    """Write the per-rule and per-job tables of a build, and where they came from.

    Parameters
    ----------
    build : path
        The build directory (read only).
    dry_run : path
        The output of ``snakemake -n --forceall`` for the build's configuration and shard counts.
    data : path
        The directory written: ``paper_scale_rules.csv`` (:func:`rule_work`),
        ``paper_scale_jobs.csv`` (:func:`job_table`) and ``paper_scale_source.csv``.
    default : float
        Seconds of a job without a sidecar.
    what : str
        The build's configuration, in words, for the page.
    overhead : float, optional
        Start-up seconds per job; from the measured runs in ``data`` when None
        (:func:`measured_overhead`).
    overhead_note : str
        How ``overhead`` was obtained, for the page.
    local : set of str
        Names of local rules (:func:`local_rules`): no Slurm start-up for their jobs.
    fallback : path, optional
        Another build whose sidecars time the jobs ``build`` has none for (e.g. the default
        configuration's, for an unfinished paper-scale build: a low estimate for those jobs).
    rules_from : path, optional
        The build whose sidecars give the per-rule table instead of ``build`` (a complete one,
        when ``build`` has not finished).
    rules_what : str
        That build's configuration, in words.

    Returns
    -------
    list of Path
        The three files written.
    """
    build, data = Path(build), Path(data)
    times = job_times(build)
    rules = rule_work(Path(rules_from) if rules_from else build)
    jobs = job_table(parse_dry_run(Path(dry_run).read_text()), times, default, local,
                     job_times(Path(fallback)) if fallback else None)
    if overhead is None:
        overhead = measured_overhead(read_csv(data / "slurm_small.csv"))
        overhead_note = overhead_note or ("the median over the measured Slurm runs of (Slurm run time - step "
                                          "time) per job: Snakemake, srun and Python starting in the job")
    source = [{"key": "build", "value": str(build)}, {"key": "what", "value": what},
              {"key": "fallback", "value": str(fallback or "")},
              {"key": "rules_build", "value": str(rules_from or "")}, {"key": "rules_what", "value": rules_what},
              {"key": "default_s", "value": default}, {"key": "overhead_s", "value": round(overhead, 1)},
              {"key": "overhead_note", "value": overhead_note}]
    return [write_csv(rules, data / "paper_scale_rules.csv", ["rule", "jobs", "total_s", "max_job_s"]),
            write_csv(jobs, data / "paper_scale_jobs.csv",
                      ["jobid", "rule", "wildcards", "seconds", "measured", "source", "local", "parents"]),
            write_csv(source, data / "paper_scale_source.csv", ["key", "value"])]


def collect_partial(build: Path, data: Path = DATA, what: str = "") -> Path:
    """Write the per-rule table of a build that has not finished (``paper_scale_partial_rules.csv``).

    Parameters
    ----------
    build : path
        The build directory (read only).
    data : path
        The directory written.
    what : str
        The build's configuration and state, in words, for the page.

    Returns
    -------
    Path
        The file written; its first data row ``(as of)`` holds ``what`` and the time of collection.
    """
    from datetime import datetime, timezone

    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    rows = [{"rule": "(as of)", "jobs": "", "total_s": "", "max_job_s": "", "note": f"{stamp}: {what}"}]
    rows += [{**r, "note": ""} for r in rule_work(build)]
    return write_csv(rows, Path(data) / "paper_scale_partial_rules.csv",
                     ["rule", "jobs", "total_s", "max_job_s", "note"])


def measured_overhead(runs: list[dict]) -> float:
    """The start-up of a Slurm job, from measured runs.

    Parameters
    ----------
    runs : list of dict
        Rows of ``slurm_small.csv`` (``status, job_sum_s, step_sum_s, jobs``).

    Returns
    -------
    float
        The median over the successful runs of ``(job_sum_s - step_sum_s) / jobs``: Slurm's run
        time of a job less the step's own time (0 when no run qualifies, never negative).
    """
    values = [(float(r["job_sum_s"]) - float(r["step_sum_s"])) / int(r["jobs"]) for r in runs
              if r.get("status") == "ok" and r.get("step_sum_s") not in (None, "") and int(r.get("jobs") or 0)]
    return max(_median(values), 0.0) if values else 0.0


def main(argv=None) -> int:
    """``python -m netrepro scaling``: regenerate docs/scaling.md (and, with --collect, its tables).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``scaling``; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        0.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro scaling", description=main.__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="directory of the CSVs (docs/scaling)")
    parser.add_argument("--out", type=Path, default=DOC, help="the page written (docs/scaling.md)")
    parser.add_argument("--collect", type=Path, metavar="BUILD",
                        help="first write the per-rule and per-job tables from this build's sidecars")
    parser.add_argument("--dry-run", type=Path, help="with --collect: `snakemake -n --forceall ...` output")
    parser.add_argument("--what", default="", help="with --collect: the build's configuration, in words")
    parser.add_argument("--default", type=float, default=10.0, help="seconds of a job without a sidecar")
    parser.add_argument("--workflow", type=Path, default=Path("."),
                        help="with --collect: a checkout of the build's workflow, to find its local rules")
    parser.add_argument("--configfile", nargs="*", default=["config/config.yaml"],
                        help="with --collect: the build's configuration files (for the local rules)")
    parser.add_argument("--fallback", type=Path, metavar="BUILD",
                        help="with --collect: time the jobs BUILD has no sidecar for from this build")
    parser.add_argument("--rules-from", type=Path, metavar="BUILD",
                        help="with --collect: the per-rule table from this (complete) build instead")
    parser.add_argument("--rules-what", default="", help="with --rules-from: that build's configuration")
    parser.add_argument("--partial", type=Path, metavar="BUILD",
                        help="write the per-rule table of an unfinished build (paper_scale_partial_rules.csv)")
    args = parser.parse_args(argv)
    if args.partial:
        print(f"wrote {collect_partial(args.partial, args.data, args.what)}")
    if args.collect:
        if not args.dry_run:
            parser.error("--collect needs --dry-run")
        local = local_rules(args.workflow, args.configfile)
        for path in collect(args.collect, args.dry_run, args.data, args.default, args.what, local=local,
                            fallback=args.fallback, rules_from=args.rules_from, rules_what=args.rules_what):
            print(f"wrote {path}")
    print(f"wrote {write_doc(args.out, args.data)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
