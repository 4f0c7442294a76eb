"""Figures regenerate: compare a run's result tables and figures with the committed references.

``python -m netrepro regression compare`` (what CI and ``make check`` run) checks every table
under ``tests/reference/`` against the same path under ``results/`` (a result table without a
reference is a difference too), and every figure under ``figures/`` against its committed
version (:mod:`netrepro.figures.check`: what it draws, with the tables' tolerances, and its
pixels); on any difference it writes ``results/regeneration/index.html``. String
columns exactly, numeric columns within ``rtol``/``atol`` (seeds are fixed, so
differences only come from floating-point details of the platform).
``python -m netrepro regression update`` refreshes the reference tables from ``results/`` and
prints what changed (the figures' references are the committed files under ``figures/``);
``--paper SLUG`` (repeatable; ``make update-references PAPER=slug``) touches only that paper's
tables: ``<slug>/...`` and the shared ``claims/<slug>.csv``, ``errata/<slug>.csv``, ... .
The comparison is this module's: the tolerances, numbers inside text (:func:`texts_agree`), the
tables; :mod:`netrepro.figures.check` calls it for what a figure draws, and the command that runs both
is :mod:`netrepro.cli.regression`.
Measured times (the columns :data:`TIMING_COLUMNS` names, e.g. ``solve_time_s``, ``seconds``)
are no part of any reference: ``update`` does not copy them and ``compare`` ignores them; the
free-text ``note`` of claims tables is copied but not compared. Numbers printed inside text are compared
with the numeric tolerance, the words exactly. The few values that legitimately
differ between CPUs (a solver point that is not unique, an unconverged iterative
solver, certificate margins at the solver's accuracy) are listed, with their reason
and the weaker check they get, in ``tests/platform_dependent.yaml``.
"""

from __future__ import annotations

import csv
import fnmatch
import re
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from ..locations import checkout_file

__all__ = ["RTOL", "ATOL", "TIMING_COLUMNS", "FIGURES", "PLATFORM_RULES", "compare_tables", "compare_trees",
           "is_timing_column", "load_platform_rules", "paper_of", "texts_agree", "update_tables"]

RTOL = 1e-6
ATOL = 1e-9
# Columns that hold measured times, or numbers derived from them alone (shell patterns, case-insensitive): they
# differ run to run, so they are no part of any reference: `update` does not copy them, `compare` ignores them.
# The one list (tests/test_regression.py checks that no committed reference has such a column). A simulated
# time (a trajectory's `t`, `time_constant_steps`) is a reproducible value and is compared.
TIMING_COLUMNS = ("*_time_s", "wall_time*", "elapsed*", "*_elapsed*", "seconds", "*_seconds",
                  "*per_second", "extrapolated_*_s", "fit_exponent")
# where the figures' references live in the repository (their committed versions: --figure-reference git:REV)
FIGURES = Path("figures")
# a file of the clone (not shipped in the wheel): outside a clone it is absent, which gives no rules
PLATFORM_RULES = checkout_file("tests", "platform_dependent.yaml")
CHECKS = ("sign", "text", "finite", "info")
# a decimal number as printed in a table or a sentence (sign, digits, optional exponent)
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def is_timing_column(column: str) -> bool:
    """Whether ``column`` holds a measured time (:data:`TIMING_COLUMNS`, case-insensitive).

    Parameters
    ----------
    column : str
        A table's column name.

    Returns
    -------
    bool
        True for a timing column (no part of any reference).
    """
    return any(fnmatch.fnmatchcase(str(column).lower(), pattern) for pattern in TIMING_COLUMNS)


def _volatile(path: Path, column: str) -> bool:
    """Compared by no check: measured times; the claims tables' notes (they may quote times)."""
    return is_timing_column(column) or (path.parent.name == "claims" and column == "note")


def _without_timings(data: bytes) -> bytes:
    """A CSV table's bytes without its timing columns (unchanged, byte for byte, when it has none)."""
    text = data.decode()
    rows = list(csv.reader(text.splitlines(keepends=True)))
    if not rows or not any(is_timing_column(c) for c in rows[0]):
        return data
    keep = [i for i, c in enumerate(rows[0]) if not is_timing_column(c)]
    out = _Lines()  # not io.StringIO: `import io` would read as netrepro.pipeline.io to the byte-code test of codedeps
    writer = csv.writer(out, lineterminator="\r\n" if "\r\n" in text else "\n")
    writer.writerows([row[i] for i in keep if i < len(row)] for row in rows)
    return "".join(out).encode()


class _Lines(list):
    """A list that csv.writer can write to."""

    write = list.append


def load_platform_rules(path: Path | str | None = PLATFORM_RULES) -> dict[str, list[dict]]:
    """``table -> [rule, ...]`` from ``tests/platform_dependent.yaml`` (empty if there is none).

    Every rule names its table, columns, check and reason; a malformed rule stops the
    comparison with a message naming it. Figure entries (a ``figure`` and no ``table``) are
    skipped: :func:`netrepro.figures.check.load_figure_rules` reads them.

    Parameters
    ----------
    path : Path or str or None, default PLATFORM_RULES
        The rules file; ``None`` or a missing file gives no rules.

    Returns
    -------
    dict of str to list of dict
        Table path (relative to the results folder) -> its rules, in file order.

    Raises
    ------
    ValueError
        For an entry lacking ``table``, ``columns``, ``check`` or ``reason``, or with an unknown check.
    """
    if path is None or not Path(path).is_file():
        return {}
    rules = {}
    for i, rule in enumerate(yaml.safe_load(Path(path).read_text()) or []):
        if "figure" in rule and "table" not in rule:  # figure entries: netrepro.figures.check.load_figure_rules
            continue
        missing = {"table", "columns", "check", "reason"} - set(rule)
        if missing or rule["check"] not in CHECKS:
            raise ValueError(f"{path}: entry {i} ({rule.get('table')}): needs table, columns, "
                             f"check (one of {', '.join(CHECKS)}) and reason; got {sorted(rule)}")
        rules.setdefault(rule["table"], []).append(rule)
    return rules


def _split_numbers(text: str) -> tuple[list[str], np.ndarray]:
    """The words of ``text`` (numbers masked) and its numbers."""
    return NUMBER.split(text), np.array([float(x) for x in NUMBER.findall(text)])


def texts_agree(a: str, b: str, rtol: float, atol: float, numbers: bool = True) -> bool:
    """Same words, and (with ``numbers``) the same numbers within the tolerance.

    The comparison of text that every check of a regenerated output uses: table cells here, the
    text a figure draws in :mod:`netrepro.figures.check`.

    Parameters
    ----------
    a, b : str
        The reference text and the regenerated one.
    rtol, atol : float
        Relative and absolute tolerance of the numbers printed in the text.
    numbers : bool
        Compare the numbers too (False: the words alone).

    Returns
    -------
    bool
        Whether the two texts agree.
    """
    if a == b:
        return True
    words_a, nums_a = _split_numbers(a)
    words_b, nums_b = _split_numbers(b)
    if words_a != words_b:
        return False
    return not numbers or bool(np.allclose(nums_a, nums_b, rtol=rtol, atol=atol, equal_nan=True))


def _weak_agree(check: str, a: pd.Series, b: pd.Series, rtol: float, atol: float) -> np.ndarray:
    """Row-wise agreement under a platform rule's weaker check."""
    if check == "info":
        return np.ones(len(a), dtype=bool)
    if not (pd.api.types.is_numeric_dtype(a) and pd.api.types.is_numeric_dtype(b)) or check == "text":
        sa, sb = a.fillna("").astype(str).to_numpy(), b.fillna("").astype(str).to_numpy()
        return np.array([texts_agree(x, y, rtol, atol, numbers=False) for x, y in zip(sa, sb)], dtype=bool)
    x, y = a.to_numpy(dtype=float), b.to_numpy(dtype=float)
    same_pattern = (np.isnan(x) == np.isnan(y)) & (np.isinf(x) == np.isinf(y))
    if check == "sign":
        return same_pattern & ((np.sign(x) == np.sign(y)) | np.isnan(x))
    return same_pattern


def _covered_rows(rule: dict, ref: pd.DataFrame, where: str) -> np.ndarray:
    """Rows of the reference table a platform rule covers (all, or those its ``rows`` select)."""
    covered = np.ones(len(ref), dtype=bool)
    for column, values in (rule.get("rows") or {}).items():
        if column not in ref.columns:
            raise ValueError(f"{where}: platform rule selects rows by {column!r}, not a column")
        covered &= ref[column].astype(str).isin([str(v) for v in values]).to_numpy()
    return covered


def _plain(value):
    """A numpy scalar as the Python value (printed without its numpy type)."""
    return value.item() if hasattr(value, "item") else value


def compare_tables(reference: Path, result: Path, rtol=RTOL, atol=ATOL, rules=(), cells=None) -> list[str]:
    """Differences between two CSV tables, as readable strings (empty when they agree).

    Numeric columns agree where ``numpy.isclose(result, reference, rtol, atol)`` (NaN equals
    NaN, equal infinities agree); text cells where their words are the same and their numbers
    agree by the same rule. Measured-time columns (:data:`TIMING_COLUMNS`) are left out of both
    tables (a reference has none); the claims tables' ``note`` is skipped.

    Parameters
    ----------
    reference : Path
        The committed reference table.
    result : Path
        The table of this build.
    rtol, atol : float
        Relative and absolute tolerances (default ``RTOL``, ``ATOL``).
    rules : sequence of dict, default ()
        This table's entries of ``tests/platform_dependent.yaml``: in the rows and columns they
        cover, their weaker check replaces the comparison of values.
    cells : list, optional
        Receives ``(row, column, result, reference)`` of the differing cells (at most 50 per column).

    Returns
    -------
    list of str
        One line per differing column; a single line if the columns or the row counts differ.

    Raises
    ------
    ValueError
        If a rule names a column the table lacks.
    """
    ref, got = pd.read_csv(reference), pd.read_csv(result)
    ref = ref[[c for c in ref.columns if not is_timing_column(c)]]  # no part of a reference (older ones had them)
    got = got[[c for c in got.columns if not is_timing_column(c)]]
    problems = []
    if list(ref.columns) != list(got.columns):
        return [f"{result}: columns {list(got.columns)} differ from reference {list(ref.columns)}"]
    if len(ref) != len(got):
        return [f"{result}: {len(got)} rows, reference has {len(ref)}"]
    weak = {}
    for rule in rules:
        rows = _covered_rows(rule, ref, str(result))
        for col in rule["columns"]:
            if col not in ref.columns:
                raise ValueError(f"{result}: platform rule names column {col!r}, which the table lacks")
            weak.setdefault(col, []).append((rows, rule["check"]))
    for col in ref.columns:
        if _volatile(Path(result), col):
            continue
        a, b = ref[col], got[col]
        if pd.api.types.is_numeric_dtype(a) and pd.api.types.is_numeric_dtype(b):
            x, y = a.to_numpy(dtype=float), b.to_numpy(dtype=float)
            ok = np.isclose(x, y, rtol=rtol, atol=atol, equal_nan=True) | (np.isinf(x) & (x == y))
        else:
            sa, sb = a.fillna("").astype(str).to_numpy(), b.fillna("").astype(str).to_numpy()
            ok = np.array([texts_agree(u, v, rtol, atol) for u, v in zip(sa, sb)], dtype=bool)
        for rows, check in weak.get(col, []):
            ok = np.where(rows, _weak_agree(check, a, b, rtol, atol), ok)
        if not ok.all():
            if cells is not None:
                cells.extend((int(r), col, _plain(b.iloc[r]), _plain(a.iloc[r])) for r in np.flatnonzero(~ok)[:50])
            i = int(np.argmin(ok))
            problems.append(f"{result}: column {col!r} differs in {int((~ok).sum())} rows "
                            f"(first at row {i}: {b.iloc[i]!r} vs reference {a.iloc[i]!r})")
    return problems


# results/scale/: the comparison with the recorded paper-scale run (its staleness follows every code
# edit, and its verdicts are the claims tables, which have references of their own)
_UNCHECKED_RESULT_DIRS = ("shards", "scale", "regeneration")
# the folders of tables with one file per paper (results/claims/<slug>.csv, ...)
SHARED_TABLE_DIRS = ("claims", "errata", "evidence", "findings", "reconstructions")


# tests/reference/paper-scale/: a recorded run at another configuration (netrepro.scale.record), not a reference
_RECORDED_RUNS = ("paper-scale",)


def _result_tables(results_dir: Path) -> list[Path]:
    """The result tables that have references: all CSVs but timings, shards (merged tables are checked)
    and the scale comparison."""
    return [t for t in sorted(Path(results_dir).rglob("*.csv"))
            if t.name != "benchmarks.csv" and not set(_UNCHECKED_RESULT_DIRS) & set(t.relative_to(results_dir).parts)]


def _reference_tables(reference_dir: Path) -> list[Path]:
    """The reference tables (every CSV under the folder but the recorded runs of other configurations)."""
    return [p for p in sorted(Path(reference_dir).rglob("*.csv"))
            if p.relative_to(reference_dir).parts[0] not in _RECORDED_RUNS]


def compare_trees(reference_dir: Path, results_dir: Path, platform_rules=None, details=None,
                  **tol) -> tuple[int, list[str]]:
    """Compare every reference table with its result; returns (number compared, problems).

    A result table without a reference is a problem (a new table needs ``update``, else it
    would never be checked); so is a reference table whose result is missing.

    Parameters
    ----------
    reference_dir : Path
        The reference tables (``tests/reference``).
    results_dir : Path
        The build's tables (``results``), same layout.
    platform_rules : Path or str, optional
        The file of platform-dependent values (``None``: compare all strictly; the command line
        passes ``tests/platform_dependent.yaml``).
    details : list, optional
        Receives ``{"table", "problems", "cells"}`` per differing table.
    **tol
        ``rtol``, ``atol`` passed to :func:`compare_tables`.

    Returns
    -------
    count : int
        Number of reference tables compared.
    problems : list of str
        Every difference found.

    Raises
    ------
    ValueError
        If the platform rules name a table that has no reference.
    """
    rules = load_platform_rules(platform_rules)
    unknown = sorted(set(rules) - {p.relative_to(reference_dir).as_posix() for p in _reference_tables(reference_dir)})
    if unknown:
        raise ValueError(f"platform rules name tables without a reference: {', '.join(unknown)}")
    problems, count = [], 0
    details = [] if details is None else details
    for ref in _reference_tables(reference_dir):
        rel = ref.relative_to(reference_dir)
        got = Path(results_dir) / rel
        count += 1
        if not got.is_file():
            found = [f"{got}: missing (reference {ref})"]
            cells = []
        else:
            cells = []
            found = compare_tables(ref, got, rules=rules.get(rel.as_posix(), ()), cells=cells, **tol)
        if found:
            problems.extend(found)
            details.append({"table": got, "problems": found, "cells": cells})
    for got in _result_tables(results_dir):
        if not (Path(reference_dir) / got.relative_to(results_dir)).is_file():
            found = [f"{got}: no reference in {reference_dir} (a new table: `make update-references`, then commit)"]
            problems.extend(found)
            details.append({"table": got, "problems": found, "cells": []})
    return count, problems


def paper_of(rel) -> str | None:
    """The paper a table belongs to, from its path relative to the results (or reference) folder.

    ``<slug>/...`` is the paper's own table; ``claims/<slug>.csv`` (and ``errata/``, ``findings/``,
    ``evidence/``, ``reconstructions/``) a shared table's part for that paper.

    Parameters
    ----------
    rel : str or PurePath
        The table's relative path.

    Returns
    -------
    str or None
        The slug; None for a table at the top of the folder.
    """
    parts = Path(rel).parts
    if len(parts) < 2:
        return None
    return Path(parts[1]).stem if len(parts) == 2 and parts[0] in SHARED_TABLE_DIRS else parts[0]


def update_tables(reference: Path, results: Path, papers=None) -> list[str]:
    """Replace the reference tables by the result tables; returns what changed (added, removed, changed).

    Timing columns (:data:`TIMING_COLUMNS`) are not copied. The recorded runs of other configurations
    (``tests/reference/paper-scale/``) stay.

    Parameters
    ----------
    reference : Path
        The reference folder (``tests/reference``).
    results : Path
        The build's tables (``results``).
    papers : sequence of str, optional
        Only these papers' tables (:func:`paper_of`) are written or removed; every other file stays
        byte-identical. None: every table.

    Returns
    -------
    list of str
        One line per table added, removed or changed.

    Raises
    ------
    ValueError
        If a paper has no table in either folder (a misspelt slug).
    """
    reference, results = Path(reference), Path(results)
    old_tables = _reference_tables(reference) if reference.is_dir() else []
    new_tables = _result_tables(results) if results.is_dir() else []
    if papers is not None:
        known = {paper_of(p.relative_to(reference)) for p in old_tables} | \
                {paper_of(t.relative_to(results)) for t in new_tables}
        unknown = sorted(set(papers) - known)
        if unknown:
            raise ValueError(f"no tables of paper {', '.join(unknown)} in {results} or {reference}; "
                             f"papers: {', '.join(sorted(p for p in known if p))}")
        old_tables = [p for p in old_tables if paper_of(p.relative_to(reference)) in papers]
        new_tables = [t for t in new_tables if paper_of(t.relative_to(results)) in papers]
    old = {p.relative_to(reference).as_posix(): p.read_bytes() for p in old_tables}
    new = {t.relative_to(results).as_posix(): _without_timings(t.read_bytes()) for t in new_tables}
    for rel in set(old) - set(new):
        (reference / rel).unlink()
    for rel, data in new.items():
        if old.get(rel) == data:
            continue
        target = reference / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    return ([f"table added: {reference / r}" for r in sorted(set(new) - set(old))]
            + [f"table removed: {reference / r}" for r in sorted(set(old) - set(new))]
            + [f"table changed: {reference / r}" for r in sorted(set(old) & set(new)) if old[r] != new[r]])
