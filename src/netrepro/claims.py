"""Claim checks: each number a paper states becomes one row of a claims table.

Columns (an interface other tools read): ``paper, claim_id, statement,
paper_value, reproduced_value, tolerance, verdict, note``; we add
``tolerance_reason``. Verdicts: ``reproduced``, ``differs``, ``erratum``.
"""

from __future__ import annotations

import math

import pandas as pd

__all__ = ["CLAIM_COLUMNS", "VERDICTS", "claim_row", "claims_frame", "ERRATA_COLUMNS", "errata_frame",
           "RECONSTRUCTION_COLUMNS", "reconstructions_frame"]

CLAIM_COLUMNS = ["paper", "claim_id", "statement", "paper_value", "reproduced_value", "tolerance", "verdict",
                 "note", "tolerance_reason"]
VERDICTS = ("reproduced", "differs", "erratum")
ERRATA_COLUMNS = ["paper", "erratum_id", "location", "printed", "corrected", "demonstration", "residual_printed",
                  "residual_corrected"]
RECONSTRUCTION_COLUMNS = ["paper", "key", "value", "reason", "sensitivity"]


def claim_row(paper, claim_id, statement, paper_value, reproduced_value, tolerance, tolerance_reason,
              note="", relative=False, erratum=False) -> dict:
    """One claim; the verdict is computed, never passed in.

    ``tolerance`` is absolute unless ``relative``. A numeric paper value is
    reproduced when ``|ours - paper| <= tolerance`` (times ``|paper|`` if
    relative). Booleans (qualitative claims) are reproduced when equal.
    ``erratum=True`` marks a claim whose printed value we show to be wrong
    *and* explain as a misprint; it is only honoured when the values differ.
    """
    if isinstance(paper_value, bool) or isinstance(reproduced_value, bool):
        agree = bool(paper_value) == bool(reproduced_value)
    else:
        p, r = float(paper_value), float(reproduced_value)
        scale = abs(p) if relative else 1.0
        agree = math.isfinite(r) and abs(r - p) <= tolerance * scale
    verdict = "reproduced" if agree else ("erratum" if erratum else "differs")
    tol_text = f"{tolerance:g} (relative)" if relative else f"{tolerance:g}"
    return {
        "paper": paper, "claim_id": claim_id, "statement": statement, "paper_value": paper_value,
        "reproduced_value": reproduced_value, "tolerance": tol_text, "verdict": verdict, "note": note,
        "tolerance_reason": tolerance_reason,
    }


def claims_frame(rows) -> pd.DataFrame:
    frame = pd.DataFrame(list(rows), columns=CLAIM_COLUMNS)
    bad = set(frame["verdict"]) - set(VERDICTS)
    if bad:
        raise ValueError(f"unknown verdicts {bad}")
    if frame["claim_id"].duplicated().any():
        raise ValueError(f"duplicate claim ids: {list(frame.loc[frame['claim_id'].duplicated(), 'claim_id'])}")
    return frame


def errata_frame(rows) -> pd.DataFrame:
    return pd.DataFrame(list(rows), columns=ERRATA_COLUMNS)


def reconstructions_frame(rows) -> pd.DataFrame:
    return pd.DataFrame(list(rows), columns=RECONSTRUCTION_COLUMNS)
