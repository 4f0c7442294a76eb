"""Shards of the Monte Carlo runs of the `onebit` estimators (beyond the paper, issues 17 and 27).

Which (alpha, SNR) cases are simulated, with which seed and how many runs, and how the per-run
values written by the shards are merged back in block order. Used by the pipeline steps
(:mod:`.steps`) and the evidence (:mod:`.evidence`); no mathematics here.

Two sets of cases:

``grid``
    ``estimator.one_minus_alpha`` x ``estimator.snr_db`` with ``estimator.n_runs`` runs each;
    alpha ``i``, SNR ``j`` has key ``a{i}s{j}`` and seed ``estimator.seed + 1000 i + j``.
``crossing``
    ``estimator.crossing.one_minus_alpha`` x ``estimator.crossing.snr_db`` (the SNRs around the
    achievable rho_S = 0 dB crossing) with ``estimator.crossing.n_runs`` runs each; key
    ``c{i}s{j}``, seed ``estimator.crossing.seed + 1000 i + j``. Absent section: no such cases.
``edge``
    ``estimator.edge.one_minus_alpha`` x ``estimator.edge.snr_db`` with ``estimator.edge.n_runs``
    runs each (issue 37: the bias of the record edges): each run is one long record, and the four
    estimators run on it and on the standard record inside it (:data:`EDGE_KINDS`); key ``e{i}s{j}``,
    seed ``estimator.edge.seed + 1000 i + j``. Absent section: no such cases.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["ESTIMATOR_KINDS", "EDGE_KINDS", "RATIO_DEFS", "EstimatorCase", "estimator_cases", "merged_runs"]

ESTIMATOR_KINDS = ("filter_1bit", "smoother_1bit", "kalman_filter", "rts_smoother")
# edge cases: each estimator on the standard record and on the long record around it (same runs)
EDGE_KINDS = ESTIMATOR_KINDS + tuple(f"{k}_long" for k in ESTIMATOR_KINDS)
# rho = MSE of the reference / MSE of the 1-bit estimator (information ratio), (47)-(49)
RATIO_DEFS = {"rho_F": ("kalman_filter", "filter_1bit", "rho_f_db"),
              "rho_S": ("kalman_filter", "smoother_1bit", "rho_s_db"),
              "rho_SL": ("rts_smoother", "smoother_1bit", "rho_sl_db")}


class EstimatorCase(NamedTuple):
    """One simulated (alpha, SNR) case.

    Attributes
    ----------
    key : str
        Name of the case in the shard files.
    eps : float
        ``1 - alpha``.
    snr_db : float
        SNR in dB.
    seed : int
        Root seed of the case (block ``b`` uses ``block_rng(seed, b)``).
    n_runs : int
        Number of independent runs.
    case_set : str
        ``'grid'``, ``'crossing'`` or ``'edge'``.
    """

    key: str
    eps: float
    snr_db: float
    seed: int
    n_runs: int
    case_set: str


def estimator_cases(params) -> list:
    """Every simulated case of the configuration, grid cases first (see the module docstring).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration (reads ``estimator``).

    Returns
    -------
    list of EstimatorCase
        In a fixed order: grid by alpha then SNR, then crossing, then edge cases, each by alpha then SNR.
    """
    est = params["estimator"]
    cases = [EstimatorCase(f"a{i}s{j}", float(eps), float(snr), int(est["seed"]) + 1000 * i + j,
                           int(est["n_runs"]), "grid")
             for i, eps in enumerate(est["one_minus_alpha"]) for j, snr in enumerate(est["snr_db"])]
    cr = est.get("crossing")
    if cr:
        cases += [EstimatorCase(f"c{i}s{j}", float(eps), float(snr), int(cr["seed"]) + 1000 * i + j,
                                int(cr["n_runs"]), "crossing")
                  for i, eps in enumerate(cr["one_minus_alpha"]) for j, snr in enumerate(cr["snr_db"])]
    ed = est.get("edge")
    if ed:
        cases += [EstimatorCase(f"e{i}s{j}", float(eps), float(snr), int(ed["seed"]) + 1000 * i + j,
                                int(ed["n_runs"]), "edge")
                  for i, eps in enumerate(ed["one_minus_alpha"]) for j, snr in enumerate(ed["snr_db"])]
    return cases


def merged_runs(paths, key: str, with_blocks: bool = False, kinds=ESTIMATOR_KINDS) -> dict:
    """Per-run values of case ``key`` from all shard files, in block order (identical for any sharding).

    Parameters
    ----------
    paths : sequence of path
        The shard files (``.npz``) written by :func:`.steps.estimator_shard_step`.
    key : str
        The case.
    with_blocks : bool
        Also return ``'block'``: the seed block of each run (for replicate checks).
    kinds : tuple of str
        The per-run arrays of the case (:data:`EDGE_KINDS` for an edge case).

    Returns
    -------
    dict of ndarray
        ``{kind: per-run values}`` for every kind of ``kinds`` (and ``'block'``).

    Raises
    ------
    ValueError
        If a block of the case appears in two shard files.
    """
    parts = []
    for path in paths:
        with np.load(path) as data:
            blocks, counts = data[f"{key}|blocks"], data[f"{key}|counts"]
            offsets = np.concatenate([[0], np.cumsum(counts)])
            for i, b in enumerate(blocks):
                vals = {k: data[f"{key}|{k}"][offsets[i]:offsets[i + 1]] for k in kinds}
                vals["block"] = np.full(int(counts[i]), int(b), dtype=np.int64)
                parts.append((int(b), vals))
    parts.sort(key=lambda p: p[0])
    if len({b for b, _ in parts}) != len(parts):
        raise ValueError(f"estimator shards: a block of {key} appears twice")
    kinds = tuple(kinds) + (("block",) if with_blocks else ())
    return {k: np.concatenate([v[k] for _, v in parts]) for k in kinds}
