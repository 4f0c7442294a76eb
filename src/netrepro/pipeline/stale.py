"""Stale outputs (issue 40 B): files under ``results/`` and ``figures/`` that no rule of the current workflow produces.

A step renamed or removed leaves its old tables and figures behind; nothing rebuilds them, ``verify``
still finds them consistent with their sidecars, and ``make update-references`` would freeze a stale
table into the references. The declared outputs come from Snakemake (``snakemake report --summary``,
with the build's options: configuration, profile), so the answer is the workflow's own. A file is
*not* stale when it is a declared output, lies under a declared directory output, or is the
provenance sidecar (``X.meta.json``) of such a file. Files that tools outside the workflow write
(:data:`NOT_WORKFLOW_OUTPUTS`: the difference page of ``make check``, ``make bench``'s table) are
never stale.

``python -m netrepro prune [--dry-run | --check] -- SNAKEMAKE OPTIONS`` (``make prune``) removes them
with their sidecars (and the folders that become empty); ``--dry-run`` lists them; ``--check``
(``make check``) lists them with the command that removes them and exits 1 when there are any.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path, PurePosixPath

__all__ = ["NOT_WORKFLOW_OUTPUTS", "OUTPUT_ROOTS", "main", "prune", "stale_outputs"]

# the folders whose files the workflow writes
OUTPUT_ROOTS = ("results", "figures")
# written by tools outside the workflow, so never declared: the difference page of `make check`
# (netrepro.judging.regression) and `make bench`'s table with its sidecar (netrepro.scale.bench)
NOT_WORKFLOW_OUTPUTS = ("results/regeneration/", "results/benchmarks.csv", "results/benchmarks.csv.meta.json")
SIDECAR = ".meta.json"


def _declared_by(path: str, files: set[str], dirs: list[str]) -> bool:
    return path in files or any(path.startswith(d) for d in dirs)


def stale_outputs(declared, root: Path | str = ".", roots=OUTPUT_ROOTS) -> list[Path]:
    """The files under ``roots`` that no declared output accounts for.

    Parameters
    ----------
    declared : iterable of str or Path
        The workflow's declared outputs, relative to ``root`` (files and directory outputs alike:
        the first column of ``snakemake --summary``).
    root : Path or str, default "."
        The checkout.
    roots : sequence of str, default OUTPUT_ROOTS
        The folders (relative to ``root``) to look in; missing ones are skipped.

    Returns
    -------
    list of Path
        The stale files, relative to ``root``, sorted; a stale file's sidecar is listed too.
    """
    root = Path(root)
    declared = {PurePosixPath(Path(d).as_posix()).as_posix() for d in declared}
    # a declared path that is a directory on disk (or declared as one) covers everything under it
    dirs = [d.rstrip("/") + "/" for d in declared if (root / d).is_dir()]
    stale = []
    for top in roots:
        if not (root / top).is_dir():
            continue
        for path in sorted((root / top).rglob("*")):
            if not path.is_file() and not path.is_symlink():
                continue
            rel = path.relative_to(root).as_posix()
            if any(rel == x or (x.endswith("/") and rel.startswith(x)) for x in NOT_WORKFLOW_OUTPUTS):
                continue
            owner = rel[: -len(SIDECAR)] if rel.endswith(SIDECAR) else rel
            if _declared_by(rel, declared, dirs) or _declared_by(owner, declared, dirs):
                continue
            stale.append(Path(rel))
    return sorted(stale)


def prune(stale, root: Path | str = ".", roots=OUTPUT_ROOTS) -> list[Path]:
    """Remove the ``stale`` files (relative to ``root``), then the folders under ``roots`` left empty.

    Parameters
    ----------
    stale : iterable of Path
        What :func:`stale_outputs` returned.
    root : Path or str, default "."
        The checkout.
    roots : sequence of str, default OUTPUT_ROOTS
        The output folders: empty folders below them are removed, the folders themselves stay.

    Returns
    -------
    list of Path
        The files removed.
    """
    root = Path(root)
    removed = []
    for rel in stale:
        path = root / rel
        if path.is_file() or path.is_symlink():
            path.unlink()
            removed.append(Path(rel))
    for top in roots:
        base = root / top
        if not base.is_dir():
            continue
        for folder in sorted((p for p in base.rglob("*") if p.is_dir()), key=lambda p: len(p.parts), reverse=True):
            if not any(folder.iterdir()):
                folder.rmdir()
    return removed


def main(argv=None) -> int:
    """``python -m netrepro prune [--dry-run | --check] [-- SNAKEMAKE OPTIONS]``.

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name, starting with ``prune`` (default ``sys.argv[1:]``).

    Returns
    -------
    int
        0; 1 with ``--check`` when there are stale files; 2 when Snakemake cannot list the outputs.
    """
    from .build import split_options

    argv, options = split_options(argv)
    parser = argparse.ArgumentParser(prog="python -m netrepro prune", description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=["prune"])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--dry-run", "-n", action="store_true", help="list the stale files, remove nothing")
    mode.add_argument("--check", action="store_true",
                      help="list the stale files and the command that removes them; exit 1 if there are any")
    parser.add_argument("--make-target", default="make prune", help="the command named by --check")
    parser.add_argument("--snakemake", default=None,
                        help="the Snakemake command (default: this interpreter's `-m snakemake`)")
    args = parser.parse_args(argv)
    from .build import summary_rows

    snakemake = args.snakemake.split() if args.snakemake else [sys.executable, "-m", "snakemake"]
    try:
        declared = [fields[0] for fields in summary_rows(snakemake, options)]
    except RuntimeError as exc:
        print(f"prune: {exc}", file=sys.stderr)
        return 2
    stale = stale_outputs(declared)
    if args.check or args.dry_run:
        for path in stale:
            print(f"stale: {path} (no rule of the workflow produces it)")
        if args.check and stale:
            print(f"prune: {len(stale)} stale files in {', '.join(OUTPUT_ROOTS)}; `{args.make_target}` removes "
                  "them (a stale table could otherwise be frozen into the references)")
            return 1
        print(f"prune: {len(stale)} stale files" + (f"; `{args.make_target}` removes them" if stale else ""))
        return 0
    for path in prune(stale):
        print(f"prune: removed {path}")
    print(f"prune: {len(stale)} stale files removed")
    return 0
