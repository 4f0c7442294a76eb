"""``python -m netrepro diff RUN_A RUN_B``: what changed in the verdicts between two runs.

A run is a checkout or build directory (its ``results/claims/*.csv`` and ``results/findings/*.csv``
are read) or a directory holding ``claims/`` and ``findings/`` directly, such as
``tests/reference``. Claims are compared on their verdict, robust flag and value; findings on
their verdict (when judged), robust flag and evidence. The same command answers "what did this
change do to the verdicts?" for a pull request (a run of main against a run of the branch) and
"does scale change a verdict?" (the default configuration against the paper-scale one).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

__all__ = ["DIFF_COLUMNS", "tables_of", "paired_entries", "same_value", "diff_runs", "main"]

DIFF_COLUMNS = ["paper", "kind", "id", "verdict_a", "verdict_b", "value_a", "value_b", "robust_a", "robust_b",
                "changed"]
_ID = {"claims": "claim_id", "findings": "finding_id"}
_VALUE = {"claims": "reproduced_value", "findings": "evidence"}
_KIND = {"claims": "claim", "findings": "finding"}


def tables_of(run: str | Path, kind: str) -> dict:
    """``{paper: DataFrame}`` of a run's ``claims`` or ``findings`` tables.

    Looks in ``<run>/results/<kind>/`` then ``<run>/<kind>/``; every cell is read as a string.

    Parameters
    ----------
    run : str or pathlib.Path
        The run's folder (a checkout or a copy of its ``results``).
    kind : {"claims", "findings"}
        Which tables to read.

    Returns
    -------
    dict of str to pandas.DataFrame
        Each paper's table, keyed by the CSV file's stem.

    Raises
    ------
    FileNotFoundError
        When the run holds no such tables.
    """
    import pandas as pd

    run = Path(run)
    for folder in (run / "results" / kind, run / kind):
        if folder.is_dir() and any(folder.glob("*.csv")):
            return {p.stem: pd.read_csv(p, dtype=str, keep_default_na=False) for p in sorted(folder.glob("*.csv"))}
    raise FileNotFoundError(f"{run}: no {kind} tables (looked in results/{kind}/ and {kind}/)")


def same_value(a: str, b: str, rel: float) -> bool:
    """Whether two table cells hold the same value: equal text, or numbers within ``rel`` (NaN equals NaN).

    Parameters
    ----------
    a, b : str
        The cells, as read (strings).
    rel : float
        Relative tolerance of two numbers.

    Returns
    -------
    bool
        True when equal as text, or both numbers within ``rel`` of the larger magnitude.
    """
    if a == b:
        return True
    try:
        x, y = float(a), float(b)
    except ValueError:
        return False
    if math.isnan(x) and math.isnan(y):
        return True
    return abs(x - y) <= rel * max(abs(x), abs(y))


def paired_entries(run_a, run_b, kind: str):
    """Every entry of two runs' ``claims`` or ``findings`` tables, side by side.

    Parameters
    ----------
    run_a, run_b : str or pathlib.Path
        The two runs (see the module docstring).
    kind : {"claims", "findings"}
        Which tables.

    Yields
    ------
    tuple
        ``(paper, id, row_a, row_b)`` per entry, in run A's order and then the entries only run B
        has; a row is a pandas Series of strings, or None where that run lacks the entry.
    """
    import pandas as pd

    a, b = tables_of(run_a, kind), tables_of(run_b, kind)
    for paper in sorted(set(a) | set(b)):
        ta = a.get(paper, pd.DataFrame(columns=[_ID[kind]])).set_index(_ID[kind])
        tb = b.get(paper, pd.DataFrame(columns=[_ID[kind]])).set_index(_ID[kind])
        for entry in [*ta.index, *[i for i in tb.index if i not in ta.index]]:
            yield (paper, entry, ta.loc[entry] if entry in ta.index else None,
                   tb.loc[entry] if entry in tb.index else None)


def diff_runs(run_a: str | Path, run_b: str | Path, rel: float = 1e-9):
    """Every claim and finding whose verdict, robust flag or value differs between two runs.

    Parameters
    ----------
    run_a, run_b : str or Path
        The two runs (see the module docstring).
    rel : float
        Relative tolerance under which two numeric values count as equal.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`DIFF_COLUMNS`; ``changed`` names what differs (``verdict``, ``robust``,
        ``value``, ``added``, ``removed``, joined by ``+``). Entries equal in both runs are left out.
    """
    import pandas as pd

    def cell(row, col):
        return "" if row is None or col not in row.index else str(row[col])

    rows = []
    for kind in ("claims", "findings"):
        for paper, entry, ra, rb in paired_entries(run_a, run_b, kind):
            changed = []
            if ra is None:
                changed.append("added")
            elif rb is None:
                changed.append("removed")
            else:
                if cell(ra, "verdict") != cell(rb, "verdict"):
                    changed.append("verdict")
                if cell(ra, "robust") != cell(rb, "robust"):
                    changed.append("robust")
                if not same_value(cell(ra, _VALUE[kind]), cell(rb, _VALUE[kind]), rel):
                    changed.append("value")
            if changed:
                rows.append({"paper": paper, "kind": _KIND[kind], "id": entry,
                             "verdict_a": cell(ra, "verdict"), "verdict_b": cell(rb, "verdict"),
                             "value_a": cell(ra, _VALUE[kind]), "value_b": cell(rb, _VALUE[kind]),
                             "robust_a": cell(ra, "robust"), "robust_b": cell(rb, "robust"),
                             "changed": "+".join(changed)})
    return pd.DataFrame(rows, columns=DIFF_COLUMNS)


def main(argv=None) -> int:
    """Compare two runs' claims and findings tables from the command line (``python -m netrepro diff``).

    Prints one line per changed entry (verdict, robust flag, value, added or removed) and a
    summary line; the table of :func:`diff_runs` is also written to ``--csv`` when given.

    Parameters
    ----------
    argv : list of str, optional
        The arguments ``RUN_A RUN_B [--csv FILE] [--rel TOL] [--fail-on-change]``; ``sys.argv[1:]``
        when None.

    Returns
    -------
    int
        The exit code: 2 when a run holds no tables, 1 with ``--fail-on-change`` when any verdict,
        robust flag or membership changed, else 0.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro diff", description=__doc__.splitlines()[0])
    parser.add_argument("run_a")
    parser.add_argument("run_b")
    parser.add_argument("--csv", help="also write the table to this file")
    parser.add_argument("--rel", type=float, default=1e-9, help="relative tolerance of equal values (default 1e-9)")
    parser.add_argument("--fail-on-change", action="store_true", help="exit 1 when any verdict or robust flag changed")
    args = parser.parse_args(argv)
    try:
        table = diff_runs(args.run_a, args.run_b, args.rel)
    except FileNotFoundError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.csv:
        Path(args.csv).parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(args.csv, index=False)
    verdicts = table[table["changed"].str.contains("verdict|robust|added|removed")]
    for row in table.itertuples(index=False):
        what = f"{row.verdict_a or '-'} -> {row.verdict_b or '-'}"
        if "robust" in row.changed:
            what += f" (robust {row.robust_a or '-'} -> {row.robust_b or '-'})"
        if "value" in row.changed:
            what += f"; value {row.value_a[:60]} -> {row.value_b[:60]}"
        print(f"{row.paper} {row.kind} {row.id}: {row.changed}: {what}")
    print(f"diff: {len(verdicts)} verdict/robust/membership change(s), {len(table) - len(verdicts)} value-only "
          f"change(s) between {args.run_a} and {args.run_b}")
    return 1 if args.fail_on_change and len(verdicts) else 0
