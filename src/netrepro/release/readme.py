"""The results table of ``README.md``, generated from the claims and errata tables of a build.

``python -m netrepro readme README.md`` (``make readme``) rewrites the part of README.md between
the markers ``<!-- results:start -->`` and ``<!-- results:end -->`` with one row per paper: its
figures (the paper's and ours), its claims by verdict (every category; testable ones counted
apart), its errata of substance, findings and reconstructions, read from ``results/claims/``,
``results/errata/``, ``results/findings/``, ``results/reconstructions/`` and ``figures/``.
``--check`` exits 1 when the README is not what the tables give (for CI or a test).

The figure-targets table between ``<!-- figures:start -->`` and ``<!-- figures:end -->`` is written
from the paper registry and each paper's ``figures.yaml`` (:func:`figure_table`): it needs no build.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from ..pipeline.figurespec import load_figure_specs
from ..pipeline.registry import load_registry
from ..judging.summary import scorecard
from ..judging.verdicts import VERDICTS

__all__ = ["START", "END", "FIG_START", "FIG_END", "results_table", "figure_table", "rewrite", "rewrite_figures",
           "main"]

START = "<!-- results:start (written by `make readme`: python -m netrepro readme README.md) -->"
END = "<!-- results:end -->"
FIG_START = "<!-- figures:start (written by `make readme` from src/netrepro/papers.yaml and each figures.yaml) -->"
FIG_END = "<!-- figures:end -->"


def _rows(path: Path) -> pd.DataFrame | None:
    if not path.is_file():
        return None
    try:
        return pd.read_csv(path)
    except pd.errors.EmptyDataError:
        return pd.DataFrame()


def results_table(root: str | Path = ".", papers=None) -> str:
    """The Markdown table: per paper figures, claims by verdict (testable and not), errata, findings, reconstructions.

    The counts are :func:`netrepro.judging.summary.scorecard`'s, so README and report agree.

    Parameters
    ----------
    root : str or Path, default "."
        The checkout whose ``results/`` and ``figures/`` are read.
    papers : iterable of str, optional
        Paper slugs, in row order; default every paper of the registry. A paper without a claims
        table gets a "not built" row.

    Returns
    -------
    str
        The Markdown table (header, one row per paper, a total row), without a final newline.
    """
    root = Path(root)
    registry = load_registry()
    papers = list(papers or registry)
    table = {kind: {slug: _rows(root / "results" / kind / f"{slug}.csv") for slug in papers}
             for kind in ("claims", "errata", "findings", "reconstructions")}
    built = {slug: frame for slug, frame in table["claims"].items() if frame is not None}
    score = scorecard(built, table["errata"], table["findings"]).set_index("paper")
    head = ["paper", "figures (paper + ours)", "claims", "testable", *(v.replace("_", " ") for v in VERDICTS),
            "errata", "findings", "reconstructions"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    n_figs = n_ours = n_recon = 0
    for slug in papers:
        figs = sorted((root / "figures" / slug).glob("*.png"))
        ours = sum(f.stem.startswith("figS") for f in figs)
        recon = table["reconstructions"][slug]
        n_figs, n_ours, n_recon = n_figs + len(figs) - ours, n_ours + ours, n_recon + (0 if recon is None else len(recon))
        name = f"`{slug}` {registry.get(slug, {}).get('title', '')}".strip()
        if slug not in score.index:
            cells = [name, f"{len(figs) - ours} + {ours}", "not built", *[""] * (len(head) - 3)]
        else:
            row = score.loc[slug]
            cells = [name, f"{len(figs) - ours} + {ours}", str(int(row["claims"])), str(int(row["testable"])),
                     *(str(int(row[v])) for v in VERDICTS), str(int(row["errata"])), str(int(row["findings"])),
                     "" if recon is None else str(len(recon))]
        lines.append("| " + " | ".join(cells) + " |")
    total = score.loc["total"] if "total" in score.index else None
    if total is not None:
        lines.append(f"| **total** | {n_figs} + {n_ours} | {int(total['claims'])} | {int(total['testable'])} | "
                     + " | ".join(str(int(total[v])) for v in VERDICTS)
                     + f" | {int(total['errata'])} | {int(total['findings'])} | {n_recon} |")
    return "\n".join(lines)


def rewrite(readme: str, table: str) -> str:
    """``readme`` with the text between the results markers replaced by ``table``.

    Parameters
    ----------
    readme : str
        The README text, holding the lines :data:`START` and :data:`END`.
    table : str
        The new content (from :func:`results_table`).

    Returns
    -------
    str
        The README with ``START``, ``table`` and ``END`` on their own lines.

    Raises
    ------
    ValueError
        If either marker is missing.
    """
    if START not in readme or END not in readme:
        raise ValueError(f"README has no results markers: add the lines\n{START}\n{END}")
    head, rest = readme.split(START, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{START}\n{table}\n{END}{tail}"


def figure_table(papers=None) -> str:
    """The Markdown table of figure targets: per registered paper its figure rules and folder.

    Parameters
    ----------
    papers : iterable of str, optional
        The papers' slugs, in this order; every registered paper when None (or empty).

    Returns
    -------
    str
        The table's lines (``| paper | figure rules | files |``), without a final newline.
    """
    registry = load_registry()
    lines = ["| paper | figure rules | files |", "|---|---|---|"]
    for slug in papers or registry:
        number = str(registry[slug]["source"]).split("_", 1)[0]
        rules = ", ".join(f"`{spec.rule}`" for spec in load_figure_specs(slug))
        lines.append(f"| `{slug}` ({number}) | {rules} | `figures/{slug}/` |")
    return "\n".join(lines)


def rewrite_figures(readme: str, table: str) -> str:
    """``readme`` with the figure-targets table replaced by ``table`` (unchanged without its markers).

    Parameters
    ----------
    readme : str
        The README's text.
    table : str
        The new table (:func:`figure_table`), put between the ``FIG_START`` and ``FIG_END`` lines.

    Returns
    -------
    str
        The README's new text; ``readme`` itself when it lacks either marker.
    """
    if FIG_START not in readme or FIG_END not in readme:
        return readme
    head, rest = readme.split(FIG_START, 1)
    _, tail = rest.split(FIG_END, 1)
    return f"{head}{FIG_START}\n{table}\n{FIG_END}{tail}"


def main(argv=None) -> int:
    """``python -m netrepro readme [README] [--root DIR] [--check]``: rewrite the results and figure tables.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0, or 1 with ``--check`` when the README is out of date.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro readme", description=__doc__.split("\n")[0])
    parser.add_argument("readme", nargs="?", default="README.md")
    parser.add_argument("--root", default=".", help="checkout whose results/ and figures/ are read")
    parser.add_argument("--check", action="store_true", help="exit 1 if the README differs, write nothing")
    args = parser.parse_args(argv)
    path = Path(args.readme)
    text = path.read_text()
    new = rewrite_figures(rewrite(text, results_table(args.root)), figure_table())
    if args.check:
        if new != text:
            print(f"{path}: results or figure table out of date; run `make readme`", file=sys.stderr)
            return 1
        return 0
    path.write_text(new)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
