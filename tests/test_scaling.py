"""docs/scaling.md and its arithmetic (netrepro.scale.projection).

The projection is checked against a DAG small enough to schedule by hand; the per-rule table
against sidecars written here; the committed page against a regeneration from the committed CSVs.
"""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.scale import projection as scaling

ROOT = Path(__file__).resolve().parents[1]

# jobs 1 (4 s), 2 (2 s), 3 (3 s) have no parents; 4 (1 s) needs 1 and 2; 5 (2 s) needs 3.
SMALL = [
    {"jobid": 1, "rule": "a", "wildcards": "", "seconds": 4, "measured": 1, "parents": ""},
    {"jobid": 2, "rule": "b", "wildcards": "", "seconds": 2, "measured": 1, "parents": ""},
    {"jobid": 3, "rule": "c", "wildcards": "", "seconds": 3, "measured": 1, "parents": ""},
    {"jobid": 4, "rule": "d", "wildcards": "", "seconds": 1, "measured": 1, "parents": "1 2"},
    {"jobid": 5, "rule": "e", "wildcards": "", "seconds": 2, "measured": 0, "parents": "3"},
]


def test_projection_of_a_hand_scheduled_dag():
    # by hand: total work 12 s; longest chain max(4+1, 2+1, 3+2) = 5 s.
    # 1 slot: 12 s. 2 slots (longest remaining path first, ties by job id): t=0 jobs 1 and 3;
    # t=3 job 3 ends, 2 starts (remaining 3 > job 5's 2); t=4 job 1 ends, 5 starts; t=5 job 2 ends,
    # 4 starts; t=6 all done. 3 slots: 1, 2, 3 at t=0; 5 at t=3; 4 at t=4; done at t=5.
    rows = scaling.project(SMALL, nodes=(1, 2, 3), cores=1)
    assert [r["slots"] for r in rows] == [1, 2, 3]
    assert {r["total_work_s"] for r in rows} == {12.0}
    assert {r["critical_path_s"] for r in rows} == {5.0}
    assert [r["lower_bound_s"] for r in rows] == [12.0, 6.0, 5.0]
    assert [r["list_schedule_s"] for r in rows] == [12.0, 6.0, 5.0]


def test_projection_counts_cores_per_node_and_overhead():
    # 2 nodes of 2 cores are 4 slots: the critical path; 1 s start-up per job adds 5 s of work and
    # 2 s to the chain 3 -> 5 (now 7 s, the longest)
    rows = scaling.project(SMALL, nodes=(2,), cores=2, overhead=1.0)
    assert rows == [{"nodes": 2, "slots": 4, "total_work_s": 17.0, "critical_path_s": 7.0,
                     "lower_bound_s": 7.0, "list_schedule_s": 7.0}]


def test_list_schedule_can_exceed_the_bound():
    # three 2 s jobs on 2 slots: no split of a job, so 4 s, while work / slots = 3 s
    durations = {1: 2.0, 2: 2.0, 3: 2.0}
    assert scaling.schedule(durations, {}, 2) == 4.0
    assert scaling.critical_path(durations, {}) == 2.0
    with pytest.raises(ValueError, match="slots"):
        scaling.schedule(durations, {}, 0)


def test_long_chain_needs_no_recursion():
    n = 5000  # deeper than Python's default recursion limit
    durations = {i: 1.0 for i in range(n)}
    parents = {i: [i - 1] for i in range(1, n)}
    assert scaling.critical_path(durations, parents) == n
    assert scaling.schedule(durations, parents, 4) == n


DRY = """\
Building DAG of jobs...
[Fri Nov 27 05:24:48 2026]
rule shard:
    input: src/x.py
    output: results/shards/s_0.csv
    jobid: 2
    wildcards: shard=0
[Fri Nov 27 05:24:48 2026]
rule shard:
    input: src/x.py
    output: results/shards/s_1.csv
    jobid: 3
    wildcards: shard=1
[Fri Nov 27 05:24:48 2026]
localrule merge:
    input: src/x.py, results/shards/s_0.csv, results/shards/s_1.csv
    output: results/merged.csv, results/merged_runs.csv
    jobid: 1
"""


def _sidecar(root: Path, output: str, seconds: float, rule: str | None, command: str):
    path = root / (output + ".meta.json")
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = {"command": command, "output": output, "wall_time_s": seconds}
    if rule:
        meta["rule"] = rule
    path.write_text(json.dumps(meta))


def _command(rule, n, old=False):
    io = shlex.quote(json.dumps({"rule": rule} if old else {}))
    return f"python -m netrepro run {'' if old else '--rule ' + rule + ' '}--func f --params '{{\"n\": {n}}}' --io {io}"


def test_rule_work_and_job_table_from_sidecars(tmp_path):
    _sidecar(tmp_path, "results/shards/s_0.csv", 2.5, "shard", _command("shard", 0))
    _sidecar(tmp_path, "results/shards/s_1.csv", 3.5, None, _command("shard", 1))  # rule from --rule
    # one merge job, two outputs, the report's copy of one: one job of 1.25 s
    for out in ("results/merged.csv", "results/merged_runs.csv", "report/files/data/results/merged.csv"):
        _sidecar(tmp_path, out, 1.25, "merge", _command("merge", 9))
    assert scaling.rule_work(tmp_path) == [
        {"rule": "shard", "jobs": 2, "total_s": 6.0, "max_job_s": 3.5},
        {"rule": "merge", "jobs": 1, "total_s": 1.25, "max_job_s": 1.25},
    ]
    jobs = scaling.parse_dry_run(DRY)
    assert [(j["jobid"], j["rule"], j["wildcards"], j["local"]) for j in jobs] == [
        (2, "shard", {"shard": "0"}, False), (3, "shard", {"shard": "1"}, False), (1, "merge", {}, True)]
    table = scaling.job_table(jobs, scaling.job_times(tmp_path), default=10.0)
    assert [(r["jobid"], r["seconds"], r["measured"], r["parents"]) for r in table] == [
        (1, 1.25, 1, "2 3"), (2, 2.5, 1, ""), (3, 3.5, 1, "")]
    table = scaling.job_table(jobs, {}, default=10.0)
    assert {r["seconds"] for r in table} == {10.0} and {r["measured"] for r in table} == {0}
    # merge after the longer shard: 3.5 + 1.25 on 2 slots; 2.5 + 3.5 + 1.25 on one
    assert [p["list_schedule_s"] for p in scaling.project(table_with(tmp_path, jobs), (1, 2), 1)] == [7.2, 4.8]
    # 1 s of start-up for each Slurm job, none for the local merge: 3.5 + 1 + 1.25 on 2 slots
    assert [p["list_schedule_s"] for p in scaling.project(table_with(tmp_path, jobs), (2,), 1, 1.0)] == [5.8]


def table_with(root, jobs):
    return scaling.job_table(jobs, scaling.job_times(root), default=10.0)


def test_measured_overhead_is_the_median_start_up_per_job():
    runs = [{"status": "ok", "job_sum_s": "100", "step_sum_s": "40", "jobs": "10"},   # 6 s
            {"status": "ok", "job_sum_s": "90", "step_sum_s": "50", "jobs": "10"},    # 4 s
            {"status": "timeout", "job_sum_s": "900", "step_sum_s": "0", "jobs": "1"}]  # left out
    assert scaling.measured_overhead(runs) == 5.0
    assert scaling.measured_overhead([]) == 0.0


def test_committed_page_is_generated_from_the_committed_tables(tmp_path):
    data = ROOT / "docs/scaling"
    assert (data / "slurm_small.csv").is_file(), "no measured Slurm runs committed (python -m tests.slurm.measure)"
    assert (data / "paper_scale_rules.csv").is_file() and (data / "paper_scale_jobs.csv").is_file()
    out = tmp_path / "scaling.md"
    proc = subprocess.run([sys.executable, "-m", "netrepro", "scaling", "--data", str(data), "--out", str(out)],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert out.read_text() == (ROOT / "docs/scaling.md").read_text(), (
        "docs/scaling.md is not what its CSVs give: run `python -m netrepro scaling` and commit it")


def test_local_rules_are_snakemakes_own():
    # the merges and the generated figure rules say `localrule: True`; the shards run on the cluster
    local = scaling.local_rules(ROOT, ["config/test.yaml"])
    assert {"onebit_estimator", "hinf_loop_variants", "intermittent_monte_carlo", "onebit_notebook"} <= local
    assert "report" not in local and "hinf_simulate" not in local
    assert not {name for name in local if name.endswith("_shard")}
    assert "intermittent_fig1" in local  # a rule the figures.smk loop generates


def test_partial_build_table_and_its_section(tmp_path):
    build = tmp_path / "build"
    _sidecar(build, "results/shards/s_0.csv", 7.5, "shard", _command("shard", 0))
    _sidecar(build, "results/x.csv", 2.0, "x", _command("x", 1))
    path = scaling.collect_partial(build, tmp_path / "data", "3 of 9 jobs done")
    rows = scaling.read_csv(path)
    assert rows[0]["rule"] == "(as of)" and rows[0]["note"].endswith(": 3 of 9 jobs done")
    assert [(r["rule"], r["jobs"], r["total_s"]) for r in rows[1:]] == [("shard", "1", "7.5"), ("x", "1", "2.0")]
    page = scaling.render_doc(tmp_path / "data")
    assert "## The paper-scale build, as far as it had run" in page
    assert "the longest job so far: shard, 8 s" in page  # 7.5 s, printed to the second


def test_job_table_sources_in_order():
    # build times shard 0 only; the other shard takes its rule's median; the merge the fallback's time
    jobs = scaling.parse_dry_run(DRY)
    times = {"results/shards/s_0.csv": ("shard", "k0", 4.0)}
    fallback = {"results/merged.csv": ("merge", "k9", 0.5), "results/shards/s_1.csv": ("shard", "k1", 99.0)}
    table = scaling.job_table(jobs, times, default=10.0, local={"merge"}, fallback=fallback)
    assert [(r["jobid"], r["seconds"], r["source"], r["measured"], r["local"]) for r in table] == [
        (1, 0.5, "fallback", 0, 1), (2, 4.0, "build", 1, 0), (3, 4.0, "rule", 0, 0)]
    assert [(r["seconds"], r["source"]) for r in scaling.job_table(jobs, {}, 10.0)] == [(10.0, "default")] * 3


def test_rule_of_a_sidecar_from_its_field_its_command_or_an_older_command():
    assert scaling._rule_of({"rule": "a", "command": _command("b", 0)}) == "a"
    assert scaling._rule_of({"command": _command("b", 0)}) == "b"
    assert scaling._rule_of({"command": _command("c", 0, old=True)}) == "c"  # before --rule existed
    assert scaling._rule_of({"command": "python -m netrepro run --func f"}) is None
