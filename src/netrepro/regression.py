"""Figures regenerate: compare a run's result tables with committed reference values.

``python -m netrepro.regression compare`` checks every table under
``tests/reference/`` against the same path under ``results/``: string
columns exactly, numeric columns within ``rtol``/``atol`` (seeds are fixed, so
differences only come from floating-point details of the platform).
``python -m netrepro.regression update`` refreshes the references from ``results/``.
Measured times (columns named like ``*time*``, ``seconds``, ...) and the free-text
``note`` of claims tables are not compared.
"""

from __future__ import annotations

import argparse
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["compare_tables", "compare_trees", "main"]

RTOL = 1e-6
ATOL = 1e-9
# measured times are not reproducible values; claim notes may quote them
VOLATILE_COLUMNS = re.compile(r"time|seconds|per_second|extrapolated|fit_exponent", re.I)


def _volatile(path: Path, column: str) -> bool:
    return bool(VOLATILE_COLUMNS.search(column)) or (path.parent.name == "claims" and column == "note")


def compare_tables(reference: Path, result: Path, rtol=RTOL, atol=ATOL) -> list[str]:
    """Differences between two CSV tables, as readable strings (empty when they agree)."""
    ref, got = pd.read_csv(reference), pd.read_csv(result)
    problems = []
    if list(ref.columns) != list(got.columns):
        return [f"{result}: columns {list(got.columns)} differ from reference {list(ref.columns)}"]
    if len(ref) != len(got):
        return [f"{result}: {len(got)} rows, reference has {len(ref)}"]
    for col in ref.columns:
        if _volatile(Path(result), col):
            continue
        a, b = ref[col], got[col]
        if pd.api.types.is_numeric_dtype(a) and pd.api.types.is_numeric_dtype(b):
            x, y = a.to_numpy(dtype=float), b.to_numpy(dtype=float)
            ok = np.isclose(x, y, rtol=rtol, atol=atol, equal_nan=True) | (np.isinf(x) & (x == y))
            if not ok.all():
                i = int(np.argmin(ok))
                problems.append(f"{result}: column {col!r} differs in {int((~ok).sum())} rows "
                                f"(first at row {i}: {y[i]!r} vs reference {x[i]!r})")
        elif not a.fillna("").astype(str).equals(b.fillna("").astype(str)):
            i = int(np.argmax(a.fillna("").astype(str).to_numpy() != b.fillna("").astype(str).to_numpy()))
            problems.append(f"{result}: column {col!r} differs (first at row {i}: {b.iloc[i]!r} vs {a.iloc[i]!r})")
    return problems


def compare_trees(reference_dir: Path, results_dir: Path, **tol) -> tuple[int, list[str]]:
    """Compare every reference table with its result; returns (number compared, problems)."""
    problems, count = [], 0
    for ref in sorted(Path(reference_dir).rglob("*.csv")):
        rel = ref.relative_to(reference_dir)
        got = Path(results_dir) / rel
        count += 1
        if not got.is_file():
            problems.append(f"{got}: missing (reference {ref})")
            continue
        problems.extend(compare_tables(ref, got, **tol))
    return count, problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m netrepro.regression", description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=["compare", "update"])
    parser.add_argument("--reference", default="tests/reference")
    parser.add_argument("--results", default="results")
    args = parser.parse_args(argv)
    if args.command == "update":
        ref = Path(args.reference)
        shutil.rmtree(ref, ignore_errors=True)
        for table in sorted(Path(args.results).rglob("*.csv")):
            # timings are not reproducible values; shards are checked through their merged tables
            if table.name == "benchmarks.csv" or "shards" in table.parts:
                continue
            target = ref / table.relative_to(args.results)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(table, target)
        print(f"reference tables written to {ref}")
        return 0
    count, problems = compare_trees(Path(args.reference), Path(args.results))
    for line in problems:
        print("DIFF", line)
    print(f"regression: {count} reference tables compared, {len(problems)} differences")
    return 1 if problems or count == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
