"""The ``netrepro`` console script (also ``python -m netrepro``): one command, a subcommand per verb.

Every verb imports its module only when it runs (:data:`VERBS` names each as ``module:function``), so
starting one costs nothing of the others: ``run`` and ``verify`` (what every pipeline job runs) import
:mod:`netrepro.pipeline.runner` alone, and a rule's code inputs (:mod:`netrepro.pipeline.codedeps`, the
runner's import closure) stay as they were. ``new-paper``, ``check-paper`` and ``register-findings`` are
parsed here; every other verb has its own parser (``netrepro VERB --help``).
"""

from __future__ import annotations

import sys

__all__ = ["VERBS", "COMMANDS", "main"]

# verb -> (module:function, what the function is given, one line of help)
#   "argv": the arguments after the verb; "verb": the arguments with the verb first (its parser takes it);
#   "here": parsed by this module (new-paper, check-paper, register-findings)
VERBS = {
    "run": ("netrepro.pipeline.runner:main", "verb", "run one pipeline step (what every Snakemake job runs)"),
    "verify": ("netrepro.pipeline.runner:main", "verb", "check results against their provenance sidecars"),
    "build": ("netrepro.pipeline.build:main", "verb", "run `snakemake report` (make report)"),
    "repair": ("netrepro.pipeline.build:main", "verb", "rebuild what verify finds corrupt or missing (make repair)"),
    "unlock": ("netrepro.pipeline.build:main", "verb", "remove the lock a killed build left (make unlock)"),
    "prune": ("netrepro.pipeline.stale:main", "verb", "remove outputs no rule produces any more (make prune)"),
    "new-paper": ("netrepro.cli.main:_new_paper", "here", "create the working skeleton of a new paper"),
    "check-paper": ("netrepro.judging.contract:main", "here", "check that papers follow the paper contract"),
    "register-findings": ("netrepro.cli.main:_register_findings", "here",
                          "register the rules of new findings in findings.lock, before the runs"),
    "diff": ("netrepro.judging.diff:main", "argv", "what changed in the verdicts between two runs"),
    "regression": ("netrepro.cli.regression:main", "argv",
                   "compare a run with the committed references, or update them (compare | update)"),
    "scale-record": ("netrepro.scale.record:main", "argv", "record a paper-scale run's claims"),
    "scaling": ("netrepro.scale.projection:main", "argv", "per-rule work and projected cluster wall times"),
    "bench": ("netrepro.scale.bench:main", "argv", "benchmarks of the hot paths (make bench)"),
    "report": ("netrepro.report.cli:main", "argv", "the report's tools (notebook, make-notebook, relocate, ...)"),
    "readme": ("netrepro.release.readme:main", "argv", "the results table of README.md (make readme)"),
    "citations": ("netrepro.release.citations:main", "argv", "the original papers: CITATION.cff and the report's list"),
    "lockfile": ("netrepro.release.lockfile:main", "argv", "the conda environment written from the lock files"),
    "archive": ("netrepro.release.archive:main", "argv", "one deposit of a release as a BagIt bag (make archive)"),
}
COMMANDS = tuple(VERBS)
# the verbs whose process ends without the interpreter's teardown (netrepro.pipeline.runner.exit_process)
_FAST_EXIT = ("run", "verify", "report")


def _new_paper(args) -> int:
    from ..errors import NetreproError
    from ..scaffold.skeleton import new_paper, source_warnings

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


def _own_parser(argv: list[str]):
    """The parser of the verbs parsed here (new-paper, check-paper, register-findings)."""
    import argparse

    parser = argparse.ArgumentParser(prog="netrepro")
    sub = parser.add_subparsers(dest="command", required=True)
    new = sub.add_parser("new-paper", help=VERBS["new-paper"][2])
    new.add_argument("slug", help="the paper's slug: a lower-case Python identifier")
    new.add_argument("--title", required=True, help="the paper's title")
    new.add_argument("--source", required=True, help="the paper's source text (must exist)")
    new.add_argument("--authors", default="", help="the authors, one line")
    new.add_argument("--root", default=".", help="the repository's root (default: here)")
    chk = sub.add_parser("check-paper", help=VERBS["check-paper"][2] + " (file:line per violation)")
    chk.add_argument("slugs", nargs="*", help="papers to check (default: every registered paper)")
    chk.add_argument("--root", default=".", help="the repository's root (default: here)")
    reg = sub.add_parser("register-findings", help=VERBS["register-findings"][2])
    reg.add_argument("slugs", nargs="*", help="papers (default: every registered paper)")
    reg.add_argument("--root", default=".", help="the repository's root (default: here)")
    return parser.parse_args(argv)


def usage() -> str:
    """The command's usage: the list of verbs, one line each with its help.

    Returns
    -------
    str
        The text ``netrepro --help`` prints.
    """
    width = max(map(len, VERBS))
    return "usage: netrepro VERB [ARGS...]   (or python -m netrepro VERB ...; netrepro VERB --help)\n\nverbs:\n" + \
        "\n".join(f"  {verb:<{width}}  {help_}" for verb, (_, _, help_) in VERBS.items())


def main(argv=None) -> int:
    """Run one verb of :data:`VERBS` (``argv`` without the program name); return its exit code.

    The verb's module is imported here, not before: ``netrepro run`` imports the runner alone.

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name, e.g. ``["check-paper", "markov"]``;
        ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        The command's exit code (0 on success, 2 for an unknown verb).
    """
    import importlib

    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(usage(), file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    verb = argv[0]
    if verb not in VERBS:
        print(f"netrepro: unknown verb {verb!r}\n{usage()}", file=sys.stderr)
        return 2
    spec, given, _ = VERBS[verb]
    module, function = spec.split(":")
    if given == "here":
        args = _own_parser(argv)
        if verb == "check-paper":
            return importlib.import_module(module).main(args.slugs, args.root)
        return getattr(sys.modules[__name__], function)(args)
    fn = getattr(importlib.import_module(module), function)
    return fn(argv if given == "verb" else argv[1:])


def console() -> None:
    """The console script ``netrepro`` and ``python -m netrepro``: :func:`main`, then exit with its code.

    ``run``, ``verify`` and ``report`` end through :func:`netrepro.pipeline.runner.exit_process` (no
    interpreter teardown: 0.1-0.4 s of CPU per pipeline job), as their ``python -m`` entry points did.
    """
    verb = sys.argv[1] if len(sys.argv) > 1 else ""
    code = main()
    if verb in _FAST_EXIT:
        from ..pipeline.runner import exit_process

        exit_process(code)
    sys.exit(code)
