"""Does scale change a verdict? The claims of a paper-scale run, recorded, against this run's.

The default configuration runs some steps cheaper than the papers state (config/README.md, "Paper
scale"). ``python -m netrepro scale-record RUN`` copies the claims and findings tables of a
paper-scale build (``make report CONFIG=paper-scale``) into ``tests/reference/paper-scale/``, with a
``provenance.json``: the commit, the configuration and its hash, the wall time, and the fingerprint
of the code each paper's tables came from (every source file any of its steps read, with its
SHA-256, from the steps' provenance sidecars: the import closure that decides reruns). The workflow
step :func:`scale_step` then compares them with the run's own claims
(``results/scale/verdicts_by_scale.csv``) and says which papers' recorded tables are stale: a
source file of their closure changed since they were recorded, so a rerun would recompute them.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import hashlib
import json
import shutil
import sys
from pathlib import Path

from ..judging.diff import paired_entries, same_value, tables_of

__all__ = ["SCALE_COLUMNS", "FINDING_COLUMNS", "STALE_COLUMNS", "NOT_RECORDED", "NOT_RUN", "compare_by_scale", "code_fingerprint",
           "stale_sources", "record", "scale_step", "main"]

# results/scale/verdicts_by_scale.csv: the interface of issue 31 first, then what explains a change
SCALE_COLUMNS = ["paper", "claim_id", "verdict_default", "verdict_paper_scale", "value_default",
                 "value_paper_scale", "changed", "what_changed", "robust_default", "robust_paper_scale",
                 "condition_paper_scale", "note_paper_scale"]
FINDING_COLUMNS = ["paper", "finding_id", "verdict_default", "verdict_paper_scale", "robust_default",
                   "robust_paper_scale", "changed", "what_changed", "condition_paper_scale", "evidence_default",
                   "evidence_paper_scale"]
STALE_COLUMNS = ["paper", "path", "recorded_sha256", "current_sha256"]
# ``what_changed`` of the entries of a paper that the recording does not hold (a paper added since): not a change
NOT_RECORDED = "no paper-scale recording yet"
# ``what_changed`` of the entries of a recorded paper that this run did not build (a run of fewer papers)
NOT_RUN = "not in this run"
# result folders that hold one table per paper (file stem = slug); the others are results/<slug>/
_PER_PAPER = ("claims", "findings", "errata", "reconstructions", "evidence")


def _cell(row, col) -> str:
    return "" if row is None or col not in row.index else str(row[col])


def compare_by_scale(default_run, scale_run, kind: str = "claims", rel: float = 1e-9):
    """Every claim (or finding) of two runs side by side, and what differs.

    Parameters
    ----------
    default_run, scale_run : str or pathlib.Path
        The two runs: a build folder (its ``results/<kind>/``) or a folder holding ``<kind>/``
        directly, such as ``tests/reference/paper-scale``.
    kind : {"claims", "findings"}
        Which tables to compare.
    rel : float
        Relative tolerance under which two numeric values count as equal.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`SCALE_COLUMNS` (claims) or :data:`FINDING_COLUMNS` (findings), one row per
        entry of either run; ``changed`` is True when the verdict or the robust flag differs, or
        the entry is in one run only; ``what_changed`` names every difference (``verdict``,
        ``robust``, ``value``, ``added``, ``removed``, joined by ``+``). A value-only change is
        listed but leaves ``changed`` False: more paths move every estimate a little. The entries
        of a paper that the recording does not hold at all (neither claims nor findings: a paper
        added since it was recorded) read :data:`NOT_RECORDED`, and those of a recorded paper
        this run did not build read :data:`NOT_RUN`; neither counts as a change.
    """
    import pandas as pd

    ident = {"claims": "claim_id", "findings": "finding_id"}[kind]
    value_col = {"claims": "reproduced_value", "findings": "evidence"}[kind]
    recorded, built = _papers(scale_run), _papers(default_run)
    rows = []
    for paper, entry, ra, rb in paired_entries(default_run, scale_run, kind):
        what = []
        if paper not in recorded or paper not in built:
            what.append(NOT_RECORDED if paper not in recorded else NOT_RUN)
        elif ra is None or rb is None:
            what.append("added" if ra is None else "removed")
        else:
            what += [c for c in ("verdict", "robust") if _cell(ra, c) != _cell(rb, c)]
            if not same_value(_cell(ra, value_col), _cell(rb, value_col), rel):
                what.append("value")
        row = {"paper": paper, ident: entry, "verdict_default": _cell(ra, "verdict"),
               "verdict_paper_scale": _cell(rb, "verdict"), "robust_default": _cell(ra, "robust"),
               "robust_paper_scale": _cell(rb, "robust"),
               "changed": bool(set(what) - {"value", NOT_RECORDED, NOT_RUN}), "what_changed": "+".join(what),
               "condition_paper_scale": _cell(rb, "condition")}
        if kind == "claims":
            row.update(value_default=_cell(ra, value_col), value_paper_scale=_cell(rb, value_col),
                       note_paper_scale=_cell(rb, "note"))
        else:
            row.update(evidence_default=_cell(ra, value_col), evidence_paper_scale=_cell(rb, value_col))
        rows.append(row)
    return pd.DataFrame(rows, columns=SCALE_COLUMNS if kind == "claims" else FINDING_COLUMNS)


def _papers(run) -> set:
    """The papers of which a run holds a claims or a findings table."""
    out = set()
    for kind in ("claims", "findings"):
        try:
            out |= set(tables_of(run, kind))
        except FileNotFoundError:
            pass
    return out


def _paper_of(sidecar: Path, results: Path, slugs) -> str | None:
    """The paper a result belongs to: ``results/<slug>/...`` or ``results/<folder>/<slug>.csv``."""
    parts = sidecar.relative_to(results).parts
    if parts[0] in slugs:
        return parts[0]
    stem = parts[-1].split(".")[0]
    return stem if parts[0] in _PER_PAPER and stem in slugs else None


def code_fingerprint(run, slugs) -> dict:
    """The source files each paper's results were computed from, with the SHA-256 each job read.

    Parameters
    ----------
    run : str or pathlib.Path
        A build folder (``results/**/*.meta.json`` are read).
    slugs : iterable of str
        The papers.

    Returns
    -------
    dict of str to dict of str to str
        ``{slug: {path: sha256}}`` over every input under ``src/`` of every sidecar of the paper
        (code closures and the claims layer's data files).

    Raises
    ------
    ValueError
        When two jobs of one paper read different versions of the same file (a run mixing code
        versions cannot be fingerprinted).
    """
    run, slugs = Path(run), set(slugs)
    results = run / "results"
    out: dict[str, dict[str, str]] = {s: {} for s in sorted(slugs)}
    for meta_path in sorted(results.rglob("*.meta.json")):
        slug = _paper_of(meta_path, results, slugs)
        if slug is None:
            continue
        meta = json.loads(meta_path.read_text())
        for item in (meta.get("inputs") or {}).values():
            path, digest = str(item.get("path", "")), item.get("sha256")
            if not path.startswith("src/") or not digest:
                continue
            seen = out[slug].setdefault(path, digest)
            if seen != digest:
                raise ValueError(f"{run}: paper {slug!r} was computed from two versions of {path} "
                                 f"({seen[:12]} and {digest[:12]}); rebuild it with one version of the code")
    return out


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def stale_sources(provenance: dict, root=".") -> list[dict]:
    """The recorded source files that differ now: a rerun would recompute those papers' tables.

    Parameters
    ----------
    provenance : dict
        A recorded ``provenance.json`` (its ``code``: ``{slug: {path: sha256}}``).
    root : str or pathlib.Path
        The checkout the files are looked up in.

    Returns
    -------
    list of dict
        One row per changed or missing file (columns :data:`STALE_COLUMNS`; ``current_sha256`` is
        ``"missing"`` for a file that no longer exists).
    """
    root = Path(root)
    rows = []
    for slug, files in sorted((provenance.get("code") or {}).items()):
        for path, digest in sorted(files.items()):
            current = _sha256(root / path) if (root / path).is_file() else "missing"
            if current != digest:
                rows.append({"paper": slug, "path": path, "recorded_sha256": digest, "current_sha256": current})
    return rows


def _merged_config(configfiles, shards=None) -> dict:
    """The configuration Snakemake builds from ``--configfile A B ...`` (later files win, key by key)."""
    import yaml
    from snakemake.utils import update_config

    merged: dict = {}
    for f in configfiles:
        update_config(merged, yaml.safe_load(Path(f).read_text()) or {})
    if shards:
        update_config(merged, {"shards": shards})
    return merged


def record(run, dest, configfiles, shards=None, wall_time_s=None, command: str = "") -> dict:
    """Copy a paper-scale run's claims and findings into ``dest`` with their provenance.

    Parameters
    ----------
    run : str or pathlib.Path
        The build folder of the paper-scale run (a checkout with ``results/``).
    dest : str or pathlib.Path
        Where to write ``claims/``, ``findings/`` and ``provenance.json`` (replaced).
    configfiles : list of str
        The ``--configfile`` files of the run, in order (paths relative to ``run``).
    shards : dict, optional
        The shard counts given on the command line (recorded; they do not change a table).
    wall_time_s : float, optional
        The measured wall time of the whole run.
    command : str
        The command that built the run, as a user would retype it.

    Returns
    -------
    dict
        The provenance written to ``dest/provenance.json``.

    Raises
    ------
    FileNotFoundError
        When the run has no claims tables.
    """
    from ..pipeline.provenance import git_state, params_hash

    run, dest = Path(run), Path(dest)
    claims = tables_of(run, "claims")  # raises FileNotFoundError, naming the run
    slugs = sorted(claims)
    merged = _merged_config([run / f for f in configfiles], shards)
    science = {k: v for k, v in merged.items() if k != "shards"}
    sidecars = [json.loads(p.read_text()) for p in (run / "results").rglob("*.meta.json")]
    commits = sorted({(m.get("git") or {}).get("commit") for m in sidecars} - {None})
    dirty = any((m.get("git") or {}).get("dirty") for m in sidecars)
    provenance = {
        "recorded": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
        "commit": commits[0] if len(commits) == 1 else commits,
        "dirty": dirty,
        "configfiles": list(configfiles),
        "config_hash": params_hash(science),
        "shards": shards or {},
        "command": command,
        "wall_time_s": wall_time_s,
        "job_seconds": round(sum(float(m.get("wall_time_s") or 0.0) for m in sidecars), 1),
        "jobs": len({m.get("command") for m in sidecars}),
        "papers": slugs,
        "code": code_fingerprint(run, slugs),
        "run_state": git_state(run) if run.is_dir() else {},
    }
    for kind in ("claims", "findings"):
        folder = dest / kind
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        for src in sorted((run / "results" / kind).glob("*.csv")):
            shutil.copy2(src, folder / src.name)
    (dest / "provenance.json").write_text(json.dumps(provenance, indent=1, sort_keys=True) + "\n")
    return provenance


def scale_step(params, inputs, outputs) -> dict:
    """Pipeline step: ``results/scale/verdicts_by_scale.csv`` and its companions.

    Parameters
    ----------
    params : dict
        ``reference``: the folder of the recorded paper-scale run (``tests/reference/paper-scale``).
    inputs : dict
        ``claims`` and ``findings`` (this run's tables, one per paper), ``provenance`` (the recorded
        ``provenance.json``) and ``sources`` (the recorded source files that still exist: listed so
        that an edit reruns this step).
    outputs : dict
        ``table`` (verdicts_by_scale.csv), ``findings`` (findings_by_scale.csv), ``stale``
        (stale_sources.csv).

    Returns
    -------
    dict
        The three tables under their output names, and counts for the sidecar (changed claims and
        findings, stale papers, the recorded commit).
    """
    import pandas as pd

    reference = Path(params["reference"])
    this_run = Path(inputs["claims"][0]).parents[1] if inputs.get("claims") else Path("results")
    claims = compare_by_scale(this_run, reference, "claims")
    findings = compare_by_scale(this_run, reference, "findings")
    provenance = json.loads(Path(inputs["provenance"]).read_text())
    stale = pd.DataFrame(stale_sources(provenance), columns=STALE_COLUMNS)
    return {"table": claims, "findings": findings, "stale": stale, "provenance": {"claims_changed": int(claims["changed"].sum()),
                           "findings_changed": int(findings["changed"].sum()),
                           "stale_papers": sorted(set(stale["paper"])),
                           "recorded_commit": provenance.get("commit")}}


def main(argv=None) -> int:
    """``python -m netrepro scale-record RUN``: record a paper-scale run (see the module docstring).

    Parameters
    ----------
    argv : list of str, optional
        ``RUN [--dest DIR] [--configfile A B ...] [--shards YAML] [--wall-time-s S] [--command TEXT]``;
        ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        0 on success, 2 when the run holds no claims tables.
    """
    import yaml

    parser = argparse.ArgumentParser(prog="python -m netrepro scale-record",
                                     description="Record a paper-scale run's claims with their provenance.")
    parser.add_argument("run", help="the paper-scale build folder")
    parser.add_argument("--dest", default="tests/reference/paper-scale")
    parser.add_argument("--configfile", nargs="+", default=["config/config.yaml", "config/paper-scale.yaml"])
    parser.add_argument("--shards", default="", help="the shard counts the run was given (YAML mapping)")
    parser.add_argument("--wall-time-s", type=float, default=None)
    parser.add_argument("--command", default="")
    args = parser.parse_args(argv)
    shards = yaml.safe_load(args.shards) if args.shards else None
    try:
        prov = record(args.run, args.dest, args.configfile, shards, args.wall_time_s, args.command)
    except FileNotFoundError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"recorded {len(prov['papers'])} papers of {args.run} (commit {prov['commit']}, configuration "
          f"{prov['config_hash'][:12]}) into {args.dest}")
    return 0
