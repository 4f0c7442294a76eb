"""RO-Crate of a report build: ``report/ro-crate-metadata.json``, a Workflow Run Crate.

The research-object standard for "this run produced these files from these inputs with this
software" (https://w3id.org/ro/crate/1.1 with the Workflow Run Crate and Process Run Crate
profiles 0.5, https://w3id.org/ro/wfrun/workflow/0.5). The crate's root is ``report/``, which
holds copies of everything it describes (the report is self-contained, see ``netrepro.report``):

* the workflow (``files/workflow/``: the Snakefiles and the configuration files), the crate's
  ``mainEntity``, a ``ComputationalWorkflow`` in Snakemake with the package versions as
  ``softwareRequirements`` and the commit as ``version``;
* one ``CreateAction`` for the whole run (instrument: the workflow; start, end, configuration
  hash and commit; result: every table, figure and page);
* one ``CreateAction`` per job, from the provenance sidecars (instrument: its Snakemake rule;
  object: the tables it read; result: what it wrote; start and end time);
* every result table and figure (``files/data/``) with its SHA-256 and size;
* a ``README.md`` about the crate (Workflow RO-Crate).

It also claims the Provenance Run Crate profile: the workflow lists the rules it orchestrates
(``hasPart``), each the ``instrument`` of its jobs' actions. ``tests/test_crate_validator.py``
runs the community's validator (``rocrate-validator``, offline, with the JSON-LD contexts kept in
``tests/data/rocrate/``): every REQUIRED check of workflow-run-crate-0.5 and
provenance-run-crate-0.5 passes, and every RECOMMENDED one but a short allow-list with reasons.

Written as JSON-LD directly (no library needed to write it); ``tests/test_release_crate.py``
reads it back, checks it against the sidecars and, where the ``rocrate`` library is installed
(the test environment), loads it with it.
"""

from __future__ import annotations

import datetime as _dt
import json
import mimetypes
import os
import re
from pathlib import Path

from ..pipeline.io import atomic_path, sha256_file

__all__ = ["PROFILES", "CONTEXT", "iso", "write_crate", "data_id", "action_id"]

CONTEXT = ["https://w3id.org/ro/crate/1.1/context", "https://w3id.org/ro/terms/workflow-run/context"]
PROFILES = {
    "https://w3id.org/ro/wfrun/process/0.5": ("Process Run Crate", "0.5"),
    "https://w3id.org/ro/wfrun/workflow/0.5": ("Workflow Run Crate", "0.5"),
    "https://w3id.org/ro/wfrun/provenance/0.5": ("Provenance Run Crate", "0.5"),
    "https://w3id.org/workflowhub/workflow-ro-crate/1.0": ("Workflow RO-Crate", "1.0"),
}
SNAKEMAKE_LANGUAGE = "https://w3id.org/workflowhub/workflow-ro-crate#snakemake"
LICENSE = "https://spdx.org/licenses/BSD-3-Clause"
BIOSCHEMAS_WORKFLOW = "https://bioschemas.org/profiles/ComputationalWorkflow/1.0-RELEASE"
COMPLETED = "http://schema.org/CompletedActionStatus"  # a string, as Process Run Crate 0.5 lists it
# the crate's author and publisher: the project's maintainers (CITATION.cff `authors`)
MAINTAINERS = {"@id": "#netrepro-maintainers", "@type": "Organization", "name": "The netrepro maintainers"}
README = """# RO-Crate of a netrepro report

This folder is a Workflow Run Crate (and a Provenance Run Crate): `ro-crate-metadata.json`
describes how one run of the netrepro Snakemake workflow made the report (`index.html`: the
scorecard and the claims explorer; `paper-<slug>.html`: one page per paper; `<slug>.html`: the
papers' executed notebooks) and every result table and figure copied under `files/data/`, job by job: the rule
each job ran, the tables it read, what it wrote, when, and the package versions. The workflow's
sources and configuration are under `files/workflow/`. Open `index.html` to read the report.
"""


def _software_id(name: str, version: str) -> str:
    """An absolute, resolvable identifier of a package release (PyPI; python.org for Python)."""
    if name.lower() == "python":
        return f"https://www.python.org/downloads/release/python-{version.replace('.', '')}/"
    return f"https://pypi.org/project/{name}/{version}/"


def _rule_source(crate_root: Path, rule: str, workflow_files: list[str]) -> str:
    """The crate path of the workflow file that defines ``rule`` (generated rules: the file that generates them)."""
    texts = {f: (crate_root / f).read_text(errors="replace") if (crate_root / f).is_file() else ""
             for f in workflow_files}
    for f, text in texts.items():
        if f"rule {rule}:" in text:
            return f
    generated = [f for f, text in texts.items() if "name:" in text and "_spec.rule" in text]
    if generated and re.search(r"_(fig\w+|notebook)$", rule):
        return generated[0]
    return workflow_files[0]


def _single(value):
    """RO-Crate 1.1 (JSON-LD appendix): a property with one value is that value, not a one-element list."""
    if isinstance(value, list) and len(value) == 1:
        return value[0]
    return value


def iso(timestamp: float) -> str:
    """A POSIX time as ISO 8601 in UTC (``2026-11-23T04:15:17+00:00``).

    Parameters
    ----------
    timestamp : float
        Seconds since the epoch; truncated to whole seconds.

    Returns
    -------
    str
        The time in ISO 8601 with the ``+00:00`` offset.
    """
    return _dt.datetime.fromtimestamp(timestamp, _dt.timezone.utc).isoformat(timespec="seconds")


def data_id(path: str) -> str:
    """The crate identifier of a pipeline file (its copy under ``files/data/``).

    Parameters
    ----------
    path : str
        Repository-relative path of the file.

    Returns
    -------
    str
        ``files/data/<path>`` (POSIX separators).
    """
    return f"files/data/{Path(path).as_posix()}"


def action_id(rule: str, index: int) -> str:
    """The crate identifier of the ``CreateAction`` of one job.

    Parameters
    ----------
    rule : str
        Name of the Snakemake rule of the job.
    index : int
        Position of the job in the crate's sorted job list.

    Returns
    -------
    str
        ``#job-<index, 3 digits>-<rule>``.
    """
    return f"#job-{index:03d}-{rule}"


def _ref(ids):
    return [{"@id": i} for i in ids]


def _file_entity(crate_root: Path, rel_id: str, name: str, **extra) -> dict:
    path = crate_root / rel_id
    kind = mimetypes.guess_type(path.name)[0] or ("application/json" if path.suffix == ".json" else
                                                   "application/octet-stream")
    entity = {"@id": rel_id, "@type": "File", "name": name, "encodingFormat": kind}
    if path.is_file():
        entity.update(contentSize=str(path.stat().st_size), sha256=sha256_file(path),
                      dateModified=iso(path.stat().st_mtime))
    entity.update(extra)
    return entity


def _job_key(meta: dict) -> str:
    """Sidecars written by one job share its command (several outputs of one job, one action)."""
    if meta.get("command"):
        return str(meta["command"])
    inputs = sorted(str(v.get("path")) for v in (meta.get("inputs") or {}).values())
    return json.dumps([meta.get("rule"), meta.get("params_hash"), inputs])


def _job_actions(root: Path, sidecars: dict, rule_of, run: dict, workflow_files: list, main: str):
    """One ``CreateAction`` per Snakemake job (the sidecars grouped by job), its rule and its files.

    Returns ``(actions, rules, files, starts, ends)``: the actions in the order of their sorted outputs,
    rule name -> its ``SoftwareApplication``, pipeline path -> its file entity, and the actions' start and end
    times (ISO 8601).
    """
    jobs: dict[str, list[tuple[str, dict]]] = {}
    for path, meta in sidecars.items():
        jobs.setdefault(_job_key(meta), []).append((path, meta))
    actions, rules, files = [], {}, {}
    starts, ends = [], []
    for index, (_, members) in enumerate(sorted(jobs.items(), key=lambda kv: sorted(p for p, _ in kv[1]))):
        meta = members[0][1]
        rule = rule_of(meta)
        rules.setdefault(rule, {"@id": f"#rule-{rule}", "@type": "SoftwareApplication", "name": rule,
                                "description": f"Snakemake rule {rule}: calls {meta.get('function', '?')}",
                                "url": _rule_source(root, rule, workflow_files),
                                "version": str(run.get("commit")), "isPartOf": {"@id": main}})
        results = [data_id(p) for p, _ in sorted(members)]
        objects = sorted({data_id(item["path"]) for _, m in members for item in (m.get("inputs") or {}).values()
                          if item.get("path") in sidecars})
        action = {"@id": action_id(rule, index), "@type": "CreateAction", "name": f"rule {rule}",
                  "instrument": {"@id": f"#rule-{rule}"}, "object": _ref(objects), "result": _ref(results),
                  "actionStatus": COMPLETED}
        end = meta.get("finished")  # sidecars before "finished" was recorded: the file's time
        first = Path(sorted(members)[0][0])
        if not end and first.is_file():
            end = iso(first.stat().st_mtime)
        if end:
            action["endTime"] = end
            wall = float(meta.get("wall_time_s") or 0)
            start = iso(_dt.datetime.fromisoformat(end).timestamp() - wall)
            action["startTime"] = start
            starts.append(start)
            ends.append(end)
        if meta.get("params_hash"):
            action["description"] = f"{meta.get('function', '?')}, parameters hash {meta['params_hash']}"
        actions.append(action)
        for path, m in members:
            files[path] = _file_entity(root, data_id(path), path, description=f"written by rule {rule}")
    return actions, rules, files, starts, ends


def write_crate(crate_root: str | Path, *, sidecars: dict[str, dict], rule_of, run: dict,
                workflow_files: list[str], config_files: list[str], pages: list[str],
                versions: dict, out: str | Path | None = None, citations: list[dict] | None = None) -> Path:
    """Write ``ro-crate-metadata.json`` into ``crate_root`` (the report folder).

    Parameters
    ----------
    crate_root : str or Path
        The report folder; file entities' sizes and checksums are read below it.
    sidecars : dict
        Pipeline file (repository-relative path, copied to ``files/data/<path>``) -> its
        provenance sidecar.
    rule_of : callable
        Sidecar -> name of the Snakemake rule that wrote it.
    run : dict
        ``start``, ``end`` (ISO 8601), ``config_hash``, ``commit``, ``dirty``, ``name``.
    workflow_files, config_files : list of str
        Crate-relative copies of the Snakefiles (the first is the main one) and configuration files.
    pages : list of str
        Crate-relative report pages (``index.html``, the papers' pages ``paper-<slug>.html``, the notebooks).
    versions : dict
        Package -> version of the software that computed the results (``None`` versions are left out).
    out : str or Path, optional
        Where to write the metadata; default ``<crate_root>/ro-crate-metadata.json``.
    citations : list of dict, optional
        The reproduced papers as contextual entities (:func:`netrepro.release.citations.crate_citations`),
        listed by the root dataset's ``citation`` (RO-Crate 1.1, "Publications via citation property").

    Returns
    -------
    Path
        The metadata file written (mode 0644).
    """
    root = Path(crate_root)
    graph: list[dict] = []
    main = workflow_files[0]
    packages = []
    for name, version in versions.items():
        if version is None:
            continue
        packages.append({"@id": _software_id(name, str(version)), "@type": "SoftwareApplication", "name": name,
                         "version": str(version), "url": _software_id(name, str(version))})

    # one action per job, from the sidecars
    actions, rules, files, starts, ends = _job_actions(root, sidecars, rule_of, run, workflow_files, main)
    run_id = "#run"
    run_action = {
        "@id": run_id, "@type": "CreateAction", "name": run.get("name", "netrepro workflow run"),
        "instrument": {"@id": main},
        "startTime": min([run["start"], *starts]) if run.get("start") else (min(starts) if starts else run["end"]),
        "endTime": run["end"],
        "object": _ref([*config_files, "#config-hash", "#commit"]),
        "result": _ref([*pages, *sorted(data_id(p) for p in sidecars)]),
        "actionStatus": COMPLETED,
        "description": "One run of the netrepro Snakemake workflow (`make report`): every job below, then the "
                       "report pages; object: the configuration files, its hash and the commit.",
    }
    values = [
        {"@id": "#config-hash", "@type": "PropertyValue", "name": "config_hash", "value": str(run.get("config_hash")),
         "description": "SHA-256 (16 hex digits) of the run's configuration (netrepro.pipeline.provenance.params_hash)"},
        {"@id": "#commit", "@type": "PropertyValue", "name": "git_commit", "value": str(run.get("commit")),
         "description": "git commit of the workflow" + (" (working tree dirty)" if run.get("dirty") else "")},
    ]
    workflow = {
        **_file_entity(root, main, "netrepro: reproducing five papers on networked estimation and control",
                       encodingFormat="text/x-snakemake"),
        "@type": ["File", "SoftwareSourceCode", "ComputationalWorkflow"],
        "programmingLanguage": {"@id": SNAKEMAKE_LANGUAGE},
        "version": str(run.get("commit")), "license": {"@id": LICENSE}, "url": main,
        # Provenance Run Crate: the workflow lists the tools it orchestrates (its rules)
        "hasPart": _ref(r["@id"] for _, r in sorted(rules.items())),
        "softwareRequirements": _ref(p["@id"] for p in packages),
        "conformsTo": {"@id": BIOSCHEMAS_WORKFLOW},
    }
    (root / "README.md").write_text(README)
    os.chmod(root / "README.md", 0o644)
    has_part = ["README.md", *workflow_files, *config_files, *pages, *sorted(files)]
    graph.append({"@id": "ro-crate-metadata.json", "@type": "CreativeWork", "about": {"@id": "./"},
                  "conformsTo": _ref(["https://w3id.org/ro/crate/1.1",
                                      "https://w3id.org/workflowhub/workflow-ro-crate/1.0"])})
    graph.append({"@id": "./", "@type": "Dataset", "name": "Reproduction report: networked estimation and control",
                  "description": "The report, its tables and figures, and how one run of the netrepro workflow made them.",
                  "datePublished": run["end"], "license": {"@id": LICENSE},
                  "author": {"@id": MAINTAINERS["@id"]}, "publisher": {"@id": MAINTAINERS["@id"]},
                  "conformsTo": _ref(PROFILES), "mainEntity": {"@id": main},
                  "hasPart": _ref(data_id(p) if p in sidecars else p for p in has_part),
                  "mentions": _ref([run_id, *(a["@id"] for a in actions)]),
                  **({"citation": _ref(c["@id"] for c in citations)} if citations else {})})
    graph.extend({"@id": url, "@type": "CreativeWork", "name": name, "version": version}
                 for url, (name, version) in PROFILES.items())
    graph.extend(dict(c) for c in citations or [])
    graph.append({"@id": LICENSE, "@type": "CreativeWork", "name": "BSD 3-Clause License"})
    graph.append(dict(MAINTAINERS))
    graph.append({"@id": BIOSCHEMAS_WORKFLOW, "@type": "CreativeWork", "name": "Bioschemas ComputationalWorkflow profile",
                  "version": "1.0-RELEASE"})
    graph.append(_file_entity(root, "README.md", "README.md", encodingFormat="text/markdown", about={"@id": "./"}))
    graph.append({"@id": SNAKEMAKE_LANGUAGE, "@type": "ComputerLanguage", "name": "Snakemake",
                  "identifier": {"@id": "https://doi.org/10.12688/f1000research.29032.2"},
                  "url": {"@id": "https://snakemake.readthedocs.io"},
                  **({"version": versions["snakemake"]} if versions.get("snakemake") else {})})
    graph.append(workflow)
    graph.extend(_file_entity(root, f, Path(f).name, encodingFormat="text/x-snakemake" if not f.endswith(".yaml")
                              else "application/yaml") for f in workflow_files[1:])
    graph.extend(_file_entity(root, f, Path(f).name, description="configuration file of the run") for f in config_files)
    graph.extend(_file_entity(root, p, Path(p).name, description="report page") for p in pages)
    graph.extend(files[p] for p in sorted(files))
    graph.append(run_action)
    graph.extend(values)
    graph.extend(actions)
    graph.extend(rules[r] for r in sorted(rules))
    graph.extend(packages)
    graph = [{key: value if key == "@id" else _single(value) for key, value in entity.items()} for entity in graph]
    out = Path(out) if out else root / "ro-crate-metadata.json"
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps({"@context": CONTEXT, "@graph": graph}, indent=1) + "\n")
    os.chmod(out, 0o644)
    return out
