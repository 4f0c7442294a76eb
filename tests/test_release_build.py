"""The built report as a research object: RO-Crate, no build-machine path, citations, clean rebuild.

Uses the session's built scratch repository (small configuration, see conftest.built_repo).
"""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from netrepro.release.crate import PROFILES, data_id
from netrepro.pipeline.io import sha256_file
from netrepro.pipeline.registry import load_registry

PAPERS = load_registry()
from netrepro.release.readme import END, START
from netrepro.judging.verdicts import TESTABLE_VERDICTS, VERDICTS

from .conftest import run_snakemake

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]


@pytest.fixture(scope="module")
def crate(built_repo):
    path = built_repo / "report" / "ro-crate-metadata.json"
    assert path.is_file(), "the report rule wrote no RO-Crate"
    doc = json.loads(path.read_text())
    return {e["@id"]: e for e in doc["@graph"]}, doc


def _ids(value):
    if isinstance(value, dict):
        value = [value]
    return [v["@id"] for v in value or []]


def test_crate_is_a_workflow_run_crate(crate):
    graph, doc = crate
    assert "https://w3id.org/ro/crate/1.1/context" in doc["@context"]
    meta = graph["ro-crate-metadata.json"]
    assert _ids(meta["about"]) == ["./"]
    root = graph["./"]
    assert set(_ids(root["conformsTo"])) == set(PROFILES)
    workflow = graph[_ids(root["mainEntity"])[0]]
    assert set(workflow["@type"]) >= {"File", "SoftwareSourceCode", "ComputationalWorkflow"}
    assert graph[_ids(workflow["programmingLanguage"])[0]]["name"] == "Snakemake"
    software = {graph[i]["name"]: graph[i]["version"] for i in _ids(workflow["softwareRequirements"])}
    assert {"numpy", "scipy", "cvxpy", "snakemake", "python"} <= set(software)
    # every reference resolves inside the graph (or is a URL)
    for entity in graph.values():
        for key, value in entity.items():
            if key != "@id" and isinstance(value, (dict, list)):
                for ref in (v for v in (value if isinstance(value, list) else [value]) if isinstance(v, dict)):
                    if set(ref) == {"@id"} and not ref["@id"].startswith("http"):
                        assert ref["@id"] in graph, f"{entity['@id']}.{key} -> {ref['@id']} missing"


def test_crate_run_has_times_config_hash_and_commit(crate, built_repo):
    graph, _ = crate
    run = next(e for e in graph.values() if e["@type"] == "CreateAction" and
               _ids(e["instrument"]) == _ids(graph["./"]["mainEntity"]))
    assert run["startTime"] <= run["endTime"]
    values = {graph[i]["name"]: graph[i]["value"] for i in _ids(run["object"]) if graph[i]["@type"] == "PropertyValue"}
    index_meta = json.loads((built_repo / "report/index.html.meta.json").read_text())
    assert values["config_hash"] == index_meta["params"]["config_hash"]
    assert values["git_commit"] == str(index_meta["git"]["commit"])


def test_crate_describes_every_table_and_figure_as_its_sidecar_says(crate, built_repo):
    graph, _ = crate
    report = built_repo / "report"
    made_by = {}
    for action in (e for e in graph.values() if e["@type"] == "CreateAction"):
        rule = graph[_ids(action["instrument"])[0]]["name"] if _ids(action["instrument"])[0].startswith("#rule-") else None
        for result in _ids(action.get("result")):
            if rule:
                made_by[result] = rule
    expected = [p for p in (built_repo / "results").rglob("*") if p.is_file() and not p.name.endswith(".meta.json")]
    expected += list((built_repo / "figures").rglob("*.png"))
    assert len(expected) > 50
    for path in expected:
        rel = path.relative_to(built_repo).as_posix()
        sidecar = json.loads(path.with_name(path.name + ".meta.json").read_text())
        entity = graph.get(data_id(rel))
        assert entity is not None, f"{rel} is not in the crate"
        assert entity["sha256"] == sidecar["output_sha256"] == sha256_file(report / entity["@id"])
        assert int(entity["contentSize"]) == path.stat().st_size
        assert made_by[entity["@id"]] == sidecar["rule"], rel


def test_crate_loads_with_the_rocrate_library(built_repo):
    rocrate = pytest.importorskip("rocrate.rocrate")
    crate = rocrate.ROCrate(built_repo / "report")
    assert crate.mainEntity is not None and "ComputationalWorkflow" in crate.mainEntity.type
    actions = [e for e in crate.get_entities() if e.type == "CreateAction"]
    assert len(actions) > 20


def test_report_carries_no_path_of_the_build_machine(built_repo):
    """report/ can be copied elsewhere or published: no file in it names the checkout."""
    needles = {str(built_repo).encode(), str(built_repo.resolve()).encode()}
    offenders = []
    for path in (built_repo / "report").rglob("*"):
        if path.is_file():
            data = path.read_bytes()
            offenders += [f"{path.relative_to(built_repo)}: {n.decode()}" for n in needles if n in data]
    assert not offenders, "absolute paths in the report:\n" + "\n".join(offenders[:20])
    notebook = re.sub(r"<[^>]+>", "", (built_repo / "report" / "intermittent.html").read_text())
    assert 'root = "."' in notebook  # the injected parameter cell: the kernel ran in the checkout


def test_report_cites_the_originals(built_repo):
    index = (built_repo / "report" / "index.html").read_text()
    assert 'id="cite"' in index and "Cite the originals" in index
    for meta in PAPERS.values():
        assert meta["title"].split(" ")[0] in index


def test_readme_results_table_from_the_claims(built_repo, tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{START}\nold\n{END}\nrest\n")
    subprocess.run([sys.executable, "-m", "netrepro", "readme", str(readme), "--root", str(built_repo)], check=True,
                   capture_output=True, text=True)
    text = readme.read_text()
    assert text.startswith("intro\n") and text.endswith(f"{END}\nrest\n") and "old" not in text
    for claims in (built_repo / "results/claims").glob("*.csv"):
        frame = pd.read_csv(claims)
        counts = frame["verdict"].value_counts()
        testable = sum(int(counts.get(v, 0)) for v in TESTABLE_VERDICTS)
        row = next(line for line in text.splitlines() if line.startswith(f"| `{claims.stem}`"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[2:4 + len(VERDICTS)] == [str(len(frame)), str(testable),
                                              *(str(int(counts.get(v, 0))) for v in VERDICTS)]
    check = subprocess.run([sys.executable, "-m", "netrepro", "readme", str(readme), "--root", str(built_repo),
                            "--check"], capture_output=True, text=True)
    assert check.returncode == 0


def _planned_total(workdir, *args):
    out = run_snakemake(workdir, "-n", *args, "report").stdout
    totals = [line.split()[-1] for line in out.splitlines() if line.strip().startswith("total")]
    return int(totals[-1]) if totals else 0


def test_make_clean_then_report_runs_every_job(built_repo, tmp_path):
    work = tmp_path / "repo"
    shutil.copytree(built_repo, work, symlinks=True)
    assert _planned_total(work) == 0  # built: nothing to do
    subprocess.run(["make", "clean"], cwd=work, check=True, capture_output=True, text=True)
    for gone in ("results", "logs", "report/index.html", "report/files", "report/ro-crate-metadata.json",
                 ".snakemake/metadata", ".snakemake/incomplete"):
        assert not (work / gone).exists(), f"make clean left {gone}"
    assert not list((work / "figures").rglob("*.png")) and not list((work / "report").glob("*.html"))
    every = _planned_total(work, "--forceall")
    assert every > 50
    assert _planned_total(work) == every  # `make report` after `make clean` runs every job
