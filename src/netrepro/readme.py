"""The results table of ``README.md``, generated from the claims and errata tables of a build.

``python -m netrepro.readme README.md`` (``make readme``) rewrites the part of README.md between
the markers ``<!-- results:start -->`` and ``<!-- results:end -->`` with one row per paper: its
figures (the paper's and ours), its claims by verdict, its errata and reconstructions, read
from ``results/claims/``, ``results/errata/``, ``results/reconstructions/`` and ``figures/``.
``--check`` exits 1 when the README is not what the tables give (for CI or a test).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from .papers import PAPERS

__all__ = ["START", "END", "results_table", "rewrite", "main"]

START = "<!-- results:start (written by `make readme`: python -m netrepro.readme README.md) -->"
END = "<!-- results:end -->"
VERDICTS = ("reproduced", "differs", "erratum")


def _rows(path: Path) -> pd.DataFrame | None:
    if not path.is_file():
        return None
    try:
        return pd.read_csv(path)
    except pd.errors.EmptyDataError:
        return pd.DataFrame()


def results_table(root: str | Path = ".", papers=None) -> str:
    """The Markdown table: per paper figures, claims by verdict, errata, reconstructions."""
    root = Path(root)
    papers = list(papers or PAPERS)
    lines = ["| paper | figures (paper + ours) | claims | reproduced | differs | erratum | errata | reconstructions |",
             "|---|---|---|---|---|---|---|---|"]
    totals = dict.fromkeys(("figs", "ours", "claims", *VERDICTS, "errata", "recon"), 0)
    for slug in papers:
        claims = _rows(root / "results" / "claims" / f"{slug}.csv")
        errata = _rows(root / "results" / "errata" / f"{slug}.csv")
        recon = _rows(root / "results" / "reconstructions" / f"{slug}.csv")
        figs = sorted((root / "figures" / slug).glob("*.png"))
        ours = sum(f.stem.startswith("figS") for f in figs)
        if claims is None:
            counts, n_claims = {}, "not built"
        else:
            verdicts = claims["verdict"].astype(str).str.strip() if "verdict" in claims else pd.Series(dtype=str)
            counts, n_claims = verdicts.value_counts().to_dict(), len(claims)
        cells = [f"`{slug}` {PAPERS.get(slug, {}).get('title', '')}".strip(), f"{len(figs) - ours} + {ours}",
                 str(n_claims), *(str(int(counts.get(v, 0))) for v in VERDICTS),
                 "" if errata is None else str(len(errata)), "" if recon is None else str(len(recon))]
        lines.append("| " + " | ".join(cells) + " |")
        totals["figs"] += len(figs) - ours
        totals["ours"] += ours
        totals["claims"] += n_claims if isinstance(n_claims, int) else 0
        for v in VERDICTS:
            totals[v] += int(counts.get(v, 0))
        totals["errata"] += 0 if errata is None else len(errata)
        totals["recon"] += 0 if recon is None else len(recon)
    lines.append(f"| **total** | {totals['figs']} + {totals['ours']} | {totals['claims']} | "
                 + " | ".join(str(totals[v]) for v in VERDICTS) + f" | {totals['errata']} | {totals['recon']} |")
    return "\n".join(lines)


def rewrite(readme: str, table: str) -> str:
    """``readme`` with the text between the markers replaced by ``table``."""
    if START not in readme or END not in readme:
        raise ValueError(f"README has no results markers: add the lines\n{START}\n{END}")
    head, rest = readme.split(START, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{START}\n{table}\n{END}{tail}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m netrepro.readme", description=__doc__.split("\n")[0])
    parser.add_argument("readme", nargs="?", default="README.md")
    parser.add_argument("--root", default=".", help="checkout whose results/ and figures/ are read")
    parser.add_argument("--check", action="store_true", help="exit 1 if the README differs, write nothing")
    args = parser.parse_args(argv)
    path = Path(args.readme)
    text = path.read_text()
    new = rewrite(text, results_table(args.root))
    if args.check:
        if new != text:
            print(f"{path}: results table out of date; run `make readme`", file=sys.stderr)
            return 1
        return 0
    path.write_text(new)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
