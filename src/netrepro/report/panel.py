"""Provenance of a figure: the sidecars of the figure and of every table upstream of it, and the
panel the report shows under the figure (rule, rebuild command, source functions, configuration
keys, data tables with checksums, seeds, compute time).

The rule of each step is the one its sidecar records (the runner's ``--rule``, given by each
rule's shell command as Snakemake's ``{rule}``): the report reads no rule table of the workflow.
"""

from __future__ import annotations

import functools
import json
import shlex
from pathlib import Path

from ..pipeline.provenance import sidecar_path
from .confine import confine_sidecar
from .markup import fmt_value, render

__all__ = ["provenance_chain", "rule_name", "config_keys", "provenance_panel", "repo_relative"]


def provenance_chain(path: str | Path, seen=None) -> list[dict]:
    """Sidecars of ``path`` and of every upstream input that has one (depth first, no repeats).

    Parameters
    ----------
    path : str or Path
        A figure or table of the run.
    seen : set of str, optional
        Paths already visited (shared across calls to list each sidecar once).

    Returns
    -------
    list of dict
        The sidecars, ``path``'s own first.

    Raises
    ------
    OutsideCheckoutError
        A sidecar of the chain names a path (its output, an input, its source file) outside the
        checkout; the message names the sidecar, the field and the path. No file outside is read.
    """
    seen = set() if seen is None else seen
    path = Path(path)
    if str(path) in seen:
        return []
    meta = _sidecar(str(path))
    if meta is None:
        return []
    seen.add(str(path))
    chain = [meta]
    for item in meta.get("inputs", {}).values():
        chain.extend(provenance_chain(item["path"], seen))
    return chain


@functools.lru_cache(maxsize=None)
def _sidecar(path: str) -> dict | None:
    """The sidecar of ``path`` (``None`` if it has none), read once per report: the chains of the
    figures share their upstream tables. A sidecar naming a path outside the checkout (the report
    runs in the checkout) raises :class:`~netrepro.report.confine.OutsideCheckoutError`."""
    side = sidecar_path(path)
    if not side.is_file():
        return None
    meta = json.loads(side.read_text())
    confine_sidecar(meta, side, Path.cwd(), source_form=repo_relative)
    return meta


def rule_name(meta: dict) -> str:
    """The rule that made a sidecar's output, as the sidecar records it.

    Parameters
    ----------
    meta : dict
        A provenance sidecar.

    Returns
    -------
    str
        The rule's name, ``"?"`` if the sidecar names none.
    """
    return str(meta.get("rule") or "") or "?"


def repo_relative(source_file: str) -> str:
    """``src/netrepro/...`` form of a source path recorded as absolute (editable installs).

    Parameters
    ----------
    source_file : str
        A path recorded by a sidecar.

    Returns
    -------
    str
        The path relative to the checkout when it lies under ``src/netrepro/``.
    """
    source_file = str(source_file)
    marker = "src/netrepro/"
    if marker in source_file and not source_file.startswith(marker):
        return source_file[source_file.index(marker):]
    return source_file


def _flatten(obj, prefix="") -> dict:
    """Nested dict -> ``{"a.b.c": leaf}`` (lists are leaves)."""
    if isinstance(obj, dict) and obj:
        flat = {}
        for key, value in obj.items():
            flat.update(_flatten(value, f"{prefix}.{key}" if prefix else str(key)))
        return flat
    return {prefix: obj} if prefix else {}


@functools.lru_cache(maxsize=None)
def _by_leaf(config_json: str) -> dict[str, list]:
    """Configuration keys by their last part (a key equal to a param's, or ending in it, has its
    last part), for one configuration section (given as JSON: the steps of a paper share it)."""
    by_leaf: dict[str, list] = {}
    for k, v in _flatten(json.loads(config_json)).items():
        by_leaf.setdefault(k.split(".")[-1], []).append((k, v))
    return by_leaf


def config_keys(params: dict, config_section: dict, slug: str) -> list[tuple[str, object, bool]]:
    """Each leaf of a step's params with the configuration key it came from.

    Parameters
    ----------
    params : dict
        The step's params (from its sidecar).
    config_section : dict
        The paper's configuration section.
    slug : str
        The paper.

    Returns
    -------
    list of tuple
        ``(key, value, from_config)``: ``key`` is the dotted configuration path
        (``slug.section.name``) when exactly one configuration entry ends with the
        param's name and holds the same value, otherwise the param's own name
        (a constant fixed in the rule, ``from_config`` False).
    """
    by_leaf = _by_leaf(json.dumps(config_section or {}, sort_keys=True))
    matches = {}
    for key, value in _flatten(params or {}).items():
        hits = [k for k, v in by_leaf.get(key.split(".")[-1], ()) if v == value]
        exact = [k for k in hits if k == key or k.endswith("." + key)]
        matches[key] = (value, exact or hits)
    # A step reads one or a few sections: an ambiguous key comes from the section its unambiguous keys come from.
    sections: dict[str, int] = {}
    for _, hits in matches.values():
        if len(hits) == 1:
            parent = hits[0].rpartition(".")[0]
            sections[parent] = sections.get(parent, 0) + 1
    out = []
    for key, (value, hits) in matches.items():
        if len(hits) > 1 and sections:
            best = max(sections.get(h.rpartition(".")[0], 0) for h in hits)
            preferred = [h for h in hits if sections.get(h.rpartition(".")[0], 0) == best]
            hits = preferred if best > 0 else hits
        if len(hits) == 1:
            out.append((f"{slug}.{hits[0]}", value, True))
        elif hits:
            out.append((" | ".join(f"{slug}.{h}" for h in hits), value, True))
        else:
            out.append((key, value, False))
    return out


def _seconds(meta: dict) -> float:
    return float(meta.get("wall_time_s", 0) or 0)


def provenance_panel(fig: Path, slug: str, ctx: dict) -> str:
    """The provenance panel of one figure.

    Parameters
    ----------
    fig : Path
        The figure.
    slug : str
        Its paper.
    ctx : dict
        The report's context: ``site`` (:class:`netrepro.report.site.Site`), ``config`` (the papers'
        configuration sections), ``configfiles``, ``commit`` (of the run).

    Returns
    -------
    str
        The panel's HTML.
    """
    site = ctx["site"]
    chain = provenance_chain(fig)
    if not chain:
        return render("panel_missing.html")
    head = chain[0]
    rule = rule_name(head)
    configfile = "".join(f" --configfile {shlex.quote(c)}" for c in ctx.get("configfiles", []))
    seeds = {}
    for meta in chain:
        for key, value in (meta.get("seeds") or {}).items():
            seeds[f"{rule_name(meta)}: {key}"] = value
    git = head.get("git") or {}
    run_commit = ctx.get("commit")
    steps, tables, code = [], {}, {}
    for meta in chain:
        src = repo_relative(meta.get("source_file", "?"))
        steps.append({
            "rule": rule_name(meta), "source": src, "line": meta.get("source_line"),
            "href": site.source_link(src, meta.get("source_line")), "function": meta.get("function"),
            "keys": [(k, fmt_value(v), from_cfg)
                     for k, v, from_cfg in config_keys(meta.get("params", {}), ctx["config"].get(slug, {}), slug)],
            "params_hash": meta.get("params_hash"), "seconds": _seconds(meta)})
        for item_name, item in (meta.get("inputs") or {}).items():
            target = code if item_name.startswith("code") or item["path"].endswith(".py") else tables
            target.setdefault(item["path"], item.get("sha256"))
    src = repo_relative(head.get("source_file", "?"))
    func = head.get("function", "?")
    return render(
        "panel.html", rule=rule, source=src, line=head.get("source_line"), function=func,
        source_href=site.source_link(src, head.get("source_line")), seconds=_seconds(head),
        total=sum(_seconds(m) for m in chain), git=git,
        stale=bool(git.get("commit") and run_commit and git.get("commit") != run_commit),
        rebuild=f"snakemake -j2{configfile} --forcerun {rule} {rule}", seeds=seeds, fig=fig,
        sha=head.get("output_sha256"), steps=steps,
        tables=[(p, site.table_link(p), s) for p, s in sorted(tables.items())],
        code=[(site.source_link(p), repo_relative(p), s) for p, s in sorted(code.items())])
