"""The report's RO-Crate passes the community's validator, offline (issue 26).

``rocrate-validator`` (PyPI ``roc-validator``) fetches the crate's JSON-LD contexts through its
HTTP cache. Offline, the cache is filled from the copies kept in ``tests/data/rocrate/``
(the RO-Crate 1.1 context, ResearchObject/ro-crate ``docs/_specification/1.1/context.jsonld``;
the Workflow Run terms, ResearchObject/ro-terms ``workflow-run/context.json``), served to the
validator's own cache format by a local transport: no network is used.

Two levels: workflow-run-crate-0.5, every REQUIRED check and every RECOMMENDED check but
:data:`ALLOWED` (each with its reason); provenance-run-crate-0.5, every REQUIRED check.
"""

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]

DATA = Path(__file__).parent / "data" / "rocrate"
CONTEXTS = {
    "https://w3id.org/ro/crate/1.1/context": DATA / "ro-crate-1.1-context.jsonld",
    "https://w3id.org/ro/terms/workflow-run/context": DATA / "workflow-run-context.json",
}
# RECOMMENDED checks allowed to fail, with the entities they may fail on and why.
ALLOWED = {
    "process-run-crate-0.5_5.1": (
        ("#rule-", "Snakefile"),
        "a Snakemake rule is a part of this workflow with no web identity of its own: its id is local to "
        "the crate and its url names the workflow file that defines it; the workflow itself is a file in the "
        "crate, whose id RO-Crate 1.1 requires to be relative (the packages have PyPI URLs)"),
    "process-run-crate-0.5_8.6": (
        ("#job-", "#run"),
        "who ran a build is not recorded: any user or CI builds the same crate, naming the maintainers "
        "as the agent of someone else's run would be false, and a user's name is personal data"),
    "ro-crate-1.1_31.2": (
        ("#netrepro-maintainers",),
        "the crate's author and publisher, the project's maintainers (CITATION.cff), have no public web "
        "address yet: CITATION.cff names none, and an invented one would be worse than none"),
}


def warm_cache(path: Path) -> Path:
    """A ``requests-cache`` SQLite cache (the validator's) holding the local copies of the contexts."""
    from requests.adapters import HTTPAdapter
    from requests_cache import CachedSession
    from urllib3 import HTTPResponse

    class Local(HTTPAdapter):
        def send(self, request, **kwargs):
            data = CONTEXTS[request.url].read_bytes()
            raw = HTTPResponse(body=io.BytesIO(data), status=200, preload_content=False, request_url=request.url,
                               headers={"Content-Type": "application/ld+json", "Content-Length": str(len(data))})
            return self.build_response(request, raw)

    session = CachedSession(cache_name=str(path), backend="sqlite", expire_after=-1, allowable_methods=("GET",),
                            allowable_codes=(200, 302, 404))
    session.mount("https://", Local())
    session.mount("http://", Local())
    for url in CONTEXTS:  # the request the validator's JSON-LD loader makes
        response = session.get(url, headers={"Accept": "application/ld+json, application/json, */*;q=0.1"})
        assert response.status_code == 200
    session.close()
    return path


def validate(crate: Path, profile: str, severity: str, cache: Path) -> dict:
    """Run ``rocrate-validator validate`` offline; its JSON report."""
    out = cache.parent / f"{profile}-{severity}.json"
    exe = Path(sys.executable).parent / "rocrate-validator"
    cmd = [str(exe), "validate", "-p", profile, "-l", severity, "--offline", "--cache-path", str(cache),
           "--no-paging", "-f", "json", "-o", str(out), str(crate)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert out.is_file(), f"{' '.join(cmd)} wrote no report:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return json.loads(out.read_text())


def failures(report: dict) -> dict[str, set[str]]:
    """Failed check -> the entities it failed on."""
    out: dict[str, set[str]] = {}
    for issue in report["issues"]:
        out.setdefault(issue["check"]["identifier"], set()).add(
            str(issue.get("violatingPropertyValue") or issue.get("violatingEntity")))
    return out


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return warm_cache(tmp_path_factory.mktemp("rocrate-cache") / "cache")


def test_workflow_run_crate_required_and_recommended_pass_but_the_allow_list(built_repo, cache):
    report = validate(built_repo / "report", "workflow-run-crate-0.5", "recommended", cache)
    stats = report["statistics"]
    assert stats["total_checks_by_severity"]["REQUIRED"] > 40 and stats["total_checks_by_severity"]["RECOMMENDED"] > 60
    failed = failures(report)
    required = {i["check"]["identifier"] for i in report["issues"] if i["severity"] == "REQUIRED"}
    assert not required, f"REQUIRED checks fail: {sorted(required)}"
    unexpected = {check: entities for check, entities in failed.items() if check not in ALLOWED}
    assert not unexpected, f"RECOMMENDED checks fail outside the allow-list: {unexpected}"
    for check, entities in failed.items():
        prefixes = ALLOWED[check][0]
        outside = sorted(e for e in entities if not e.split("/")[-1].startswith(prefixes))
        assert not outside, f"{check} fails on entities the allow-list does not cover: {outside[:5]}"


def test_provenance_run_crate_required_checks_pass(built_repo, cache):
    report = validate(built_repo / "report", "provenance-run-crate-0.5", "required", cache)
    assert report["statistics"]["total_checks_by_severity"]["REQUIRED"] > 40
    assert report["issues"] == [], sorted(failures(report))
    assert report["passed"] is True


def test_the_allow_list_is_short_and_reasoned():
    assert len(ALLOWED) <= 3
    assert all(len(reason.split()) >= 10 for _, reason in ALLOWED.values())
