"""``python -m netrepro report``: write a paper's default notebook, execute a notebook into
``report/<slug>.html``, or relocate pages (no path of this checkout; an HTML page is also sealed
by a content security policy, :mod:`netrepro.report.csp`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .csp import snakemake_report_policy, with_csp
from .markup import relocate, with_empty_favicon
from .notebooks import EXECUTION_TIMEOUT_S, NotebookError, execute_notebook, make_notebook

__all__ = ["main", "relocate_page"]


def relocate_page(page: str, root: str | Path) -> str:
    """Snakemake's report (or another page) relocated and sealed by a content security policy.

    Parameters
    ----------
    page : str
        The page (``report/snakemake_report.html``).
    root : str or Path
        The checkout (:func:`netrepro.report.markup.relocate`).

    Returns
    -------
    str
        The page without paths of this checkout, asking for no favicon, with a policy that allows
        the scripts Snakemake wrote and nothing else (:func:`netrepro.report.csp.snakemake_report_policy`;
        hashed after relocating, which may change a script's text).
    """
    page = with_empty_favicon(relocate(page, root))
    return with_csp(page, snakemake_report_policy(page))


def main(argv=None) -> int:
    """Run the command line; returns the exit status (1 when a notebook fails or times out)."""
    parser = argparse.ArgumentParser(prog="python -m netrepro report")
    sub = parser.add_subparsers(dest="command", required=True)
    mk = sub.add_parser("make-notebook", help="write the default thin notebook of a paper")
    mk.add_argument("--slug", required=True)
    mk.add_argument("--out", default=None)
    ex = sub.add_parser("notebook", help="execute a paper notebook and export HTML")
    ex.add_argument("--slug", required=True)
    ex.add_argument("--notebook", required=True)
    ex.add_argument("--html", required=True)
    ex.add_argument("--timeout", type=float, default=EXECUTION_TIMEOUT_S,
                    help=f"seconds one cell may run (default {EXECUTION_TIMEOUT_S})")
    rel = sub.add_parser("relocate", help="rewrite files so they name no path of this checkout "
                                          "(e.g. Snakemake's own report, which shows the rules' commands); "
                                          "an HTML page also gets a content security policy that lets only "
                                          "Snakemake's own scripts run")
    rel.add_argument("files", nargs="+")
    args = parser.parse_args(argv)
    if args.command == "relocate":
        for name in args.files:
            path = Path(name)
            text = path.read_text()
            is_page = path.suffix.lower() in (".html", ".htm")
            new = relocate_page(text, Path.cwd()) if is_page else relocate(text, Path.cwd())
            if new != text:
                path.write_text(new)
        return 0
    if args.command == "make-notebook":
        print(make_notebook(args.slug, args.out or f"workflow/notebooks/{args.slug}.ipynb"))
        return 0
    try:
        execute_notebook(args.slug, args.notebook, args.html, timeout=args.timeout)
    except NotebookError as exc:
        print(f"error: {exc}", file=sys.stderr, flush=True)
        return 1
    return 0
