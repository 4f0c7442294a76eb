"""``netrepro regression {compare,update}``: a run's tables and figures against the committed references.

The verb over two comparisons that do not know each other's commands: the tables
(:mod:`netrepro.judging.regression`, which owns the tolerances and the comparison of numbers and text)
and the figures (:mod:`netrepro.figures.check`, which calls it for what a figure draws). ``compare``
writes the difference page and ``summary.json``/``summary.md`` beside it; ``update`` refreshes the
reference tables. What is compared, and how, is described in :mod:`netrepro.judging.regression`.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..judging.regression import FIGURES, PLATFORM_RULES, compare_trees, update_tables

__all__ = ["main", "write_check_summary"]


def main(argv=None) -> int:
    """``python -m netrepro regression {compare,update}``: compare the build with the references, or refresh them.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0, or (``compare``) 1 when a table or figure differs or nothing was compared.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro regression", description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=["compare", "update"])
    parser.add_argument("--reference", default="tests/reference")
    parser.add_argument("--results", default="results")
    parser.add_argument("--platform-rules", default=str(PLATFORM_RULES),
                        help="values that differ between CPUs and their weaker checks ('' for none)")
    parser.add_argument("--figures", default="figures", help="the built figures ('' to compare tables only)")
    parser.add_argument("--figure-reference", default="git:HEAD",
                        help="the figures' references: git:REV (committed files under figures/) or a folder")
    parser.add_argument("--html", default="results/regeneration/index.html",
                        help="the difference page, written when anything differs")
    parser.add_argument("--paper", action="append", default=None, metavar="SLUG",
                        help="update: only this paper's tables (repeatable; default every paper)")
    args = parser.parse_args(argv)
    if args.command == "update":
        try:
            changes = update_tables(Path(args.reference), Path(args.results), papers=args.paper)
        except ValueError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        if args.figures:
            from ..figures.check import compare_figures, open_baseline

            _, diffs = compare_figures(open_baseline(args.figure_reference, FIGURES), args.figures)
            for d in diffs:
                if args.paper and d.name.split("/")[0] not in args.paper:
                    continue
                changes.append(f"figure changed: figures/{d.name}.png (and its .data.json): " + "; ".join(
                    (d.problems + d.notes)[:2]))
            if args.figure_reference.startswith("git:"):
                changes.append("figure references are the files under figures/: commit them with the tables")
        for line in changes or ["nothing changed"]:
            print(line)
        print(f"reference tables written to {args.reference}"
              + (f" (papers {', '.join(args.paper)} only)" if args.paper else ""))
        return 0
    start = time.perf_counter()
    if args.html:  # a page from an earlier run would describe differences that may be gone
        from ..figures.check import clear_difference_page

        clear_difference_page(Path(args.html).parent)
    details: list[dict] = []
    count, problems = compare_trees(Path(args.reference), Path(args.results),
                                    platform_rules=args.platform_rules or None, details=details)
    for line in problems:
        print("DIFF", line)
    print(f"regression: {count} reference tables compared, {len(problems)} differences")
    figure_diffs, failing, n_fig = [], [], 0
    if args.figures:
        from ..figures.check import compare_figures, load_figure_rules, open_baseline

        n_fig, figure_diffs = compare_figures(open_baseline(args.figure_reference, FIGURES), args.figures,
                                              rules=load_figure_rules(args.platform_rules or None))
        failing = [d for d in figure_diffs if d.problems]
        for d in figure_diffs:
            for line in d.problems:
                print("DIFF", line)
            for line in d.notes:
                print("NOTE", line)
        print(f"regression: {n_fig} figures compared, {len(failing)} differ "
              f"({time.perf_counter() - start:.1f} s with the tables)")
    failed = bool(problems or failing or count == 0 or (args.figures and n_fig == 0))
    if args.html:
        # written on every run, passing or not: the evidence of what was compared (issue 41 item 5)
        from ..figures.check import write_difference_page

        page = write_difference_page(Path(args.html).parent, failing, details, compared=figure_diffs,
                                     tables_compared=count)
        summary = write_check_summary(Path(args.html).parent, failed, count, details, figure_diffs)
        print(f"regression: the comparison, figure by figure: {page} (summary: {summary})")
    return 1 if failed else 0


def write_check_summary(out_dir: Path, failed: bool, tables_compared: int, tables: list[dict], figures: list) -> Path:
    """Write ``summary.json`` and ``summary.md`` of a comparison beside its page; return the JSON's path.

    Parameters
    ----------
    out_dir : Path
        The comparison page's folder.
    failed : bool
        Whether the check fails.
    tables_compared : int
        How many reference tables were compared.
    tables : list of dict
        The differing tables (``{"table", "problems", "cells"}``).
    figures : list of FigureDifference
        Every figure compared (those with problems differ).

    Returns
    -------
    Path
        ``out_dir/summary.json``.
    """
    import json

    from ..pipeline.io import atomic_path

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rms = [d.rms for d in figures if d.rms is not None]
    doc = {
        "status": "fail" if failed else "pass",
        "tables": {"compared": tables_compared, "differing": len(tables),
                   "differences": [{"table": str(t["table"]), "problems": list(t["problems"])} for t in tables]},
        "figures": {"compared": len(figures), "differing": sum(1 for d in figures if d.problems),
                    "largest_pixel_rms": max(rms) if rms else None,
                    "each": [{"figure": d.name, "status": "differs" if d.problems else "same", "pixel_rms": d.rms,
                              "problems": list(d.problems), "notes": list(d.notes)} for d in figures]},
    }
    path = out_dir / "summary.json"
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
    largest = f"{doc['figures']['largest_pixel_rms']:.3g}" if rms else "n/a"
    lines = [f"## make check: {doc['status']}", "",
             f"* tables: {tables_compared} compared, {len(tables)} differ",
             f"* figures: {len(figures)} compared, {doc['figures']['differing']} differ "
             f"(largest pixel RMS {largest})", ""]
    lines += [f"* table `{t['table']}`: {'; '.join(t['problems'])[:300]}" for t in tables]
    lines += [f"* figure `{d.name}`: {'; '.join(d.problems)[:300]}" for d in figures if d.problems]
    with atomic_path(out_dir / "summary.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return path
