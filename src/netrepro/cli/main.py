"""``python -m netrepro new-paper | check-paper | register-findings | diff | scale-record | scaling``: the commands for people.

Kept apart from :mod:`netrepro.pipeline.runner`, which every pipeline job runs: a rule's code inputs are the
modules its job can reach, so the scaffold, the contract and the diff tool stay out of them (an
edit to a template reruns nothing).
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["COMMANDS", "main"]

COMMANDS = ("new-paper", "check-paper", "register-findings", "diff", "scale-record", "scaling")


def _new_paper(args) -> int:
    from ..errors import NetreproError
    from ..scaffold import new_paper, source_warnings

    try:
        written = new_paper(args.slug, args.title, args.source, args.root, args.authors)
    except NetreproError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print("\n".join(f"wrote {path}" for path in written))
    for warning in source_warnings(args.source, args.root):
        print(warning, file=sys.stderr)
    print(f"next: `make report` builds {args.slug}'s figure, claim and report section; "
          f"`python -m netrepro check-paper {args.slug}` checks the contract; "
          "docs/adding-a-paper.md walks through the rest")
    return 0


def _git_head(root) -> str:
    """The short commit of ``root``'s checkout ("" outside git), with ``+dirty`` when it has uncommitted changes."""
    import subprocess

    def git(*args):
        out = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, check=False)
        return out.stdout.strip() if out.returncode == 0 else ""

    head = git("rev-parse", "--short", "HEAD")
    return head + ("+dirty" if head and git("status", "--porcelain", "--untracked-files=no") else "")


def _register_findings(args) -> int:
    import datetime
    from pathlib import Path

    from ..errors import NetreproError
    from ..judging.paperdata import paper_dir, register_findings
    from ..pipeline.registry import paper_slugs

    slugs = args.slugs or list(paper_slugs())
    commit = _git_head(args.root)
    today = datetime.date.today().isoformat()
    status = 0
    for slug in slugs:
        root = Path(args.root) / "src" / "netrepro" / "papers" / slug if args.root != "." else paper_dir(slug)
        try:
            new = register_findings(slug, root, commit=commit, date=today)
        except NetreproError as exc:
            print(f"error: {slug}: {exc}", file=sys.stderr)
            status = 2
            continue
        print(f"{slug}: registered {', '.join(new)} at {commit or 'no commit'}; commit findings.lock before the runs"
              if new else f"{slug}: every finding is registered")
    return status


def main(argv=None) -> int:
    """Run one of :data:`COMMANDS` (``argv`` without the program name); return its exit code.

    ``diff``, ``scale-record`` and ``scaling`` are handed to :func:`netrepro.judging.diff.main`,
    :func:`netrepro.scale.record.main` and :func:`netrepro.scale.projection.main` (their own parsers); ``new-paper`` writes a
    paper's skeleton; ``check-paper`` runs :func:`netrepro.judging.contract.main`; ``register-findings`` registers
    the rules of new findings (:func:`netrepro.judging.paperdata.register_findings`).

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name, e.g. ``["check-paper", "markov"]``;
        ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        The command's exit code (0 on success).
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["diff"]:
        from ..judging.diff import main as diff_main  # its own parser: python -m netrepro diff RUN_A RUN_B

        return diff_main(argv[1:])
    if argv[:1] == ["scale-record"]:
        from ..scale.record import main as scale_main  # its own parser: python -m netrepro scale-record RUN

        return scale_main(argv[1:])
    if argv[:1] == ["scaling"]:
        from ..scale.projection import main as scaling_main  # its own parser: python -m netrepro scaling [--collect BUILD]

        return scaling_main(argv[1:])
    parser = argparse.ArgumentParser(prog="python -m netrepro")
    sub = parser.add_subparsers(dest="command", required=True)
    new = sub.add_parser("new-paper", help="create the working skeleton of a new paper (docs/adding-a-paper.md)")
    new.add_argument("slug", help="the paper's slug: a lower-case Python identifier")
    new.add_argument("--title", required=True, help="the paper's title")
    new.add_argument("--source", required=True, help="the paper's source text (must exist)")
    new.add_argument("--authors", default="", help="the authors, one line")
    new.add_argument("--root", default=".", help="the repository's root (default: here)")
    chk = sub.add_parser("check-paper", help="check that papers follow the paper contract (file:line per violation)")
    chk.add_argument("slugs", nargs="*", help="papers to check (default: every registered paper)")
    chk.add_argument("--root", default=".", help="the repository's root (default: here)")
    reg = sub.add_parser("register-findings",
                         help="register the rules of new findings in findings.lock, before the runs that test them")
    reg.add_argument("slugs", nargs="*", help="papers (default: every registered paper)")
    reg.add_argument("--root", default=".", help="the repository's root (default: here)")
    args = parser.parse_args(argv)
    if args.command == "new-paper":
        return _new_paper(args)
    if args.command == "register-findings":
        return _register_findings(args)
    from ..judging.contract import main as check_main

    return check_main(args.slugs, args.root)
