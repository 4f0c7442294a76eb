"""Tests of `markov`: growth-rate verdicts of the stability map, each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.markov import stability
from .systems import EX1, EX2


def test_classify_growth():
    k = np.arange(1, 30)
    settle = 50 - 40 * 0.7 ** k
    grow = 3.0 * 1.3 ** k
    rate, last, verdict = stability.classify_growth(np.stack([settle, grow]), 0.01, 0.08)
    assert list(verdict) == ["bounded", "unbounded"]
    assert rate[1] == pytest.approx(np.log(1.3), rel=1e-6)


def test_long_horizon_refinement_trusts_only_narrow_intervals():
    """Example I near its boundary is resolved; Example II's parity tail is flagged as untrusted."""
    opts = {"enabled": True, "n_paths": 200, "horizon": 160, "n_batches": 10, "rel_tol": 0.1, "bounded_tol": 0.003,
            "unbounded_tol": 0.01, "chunk": 64, "seed": 4242, "pilot_paths": 100, "pilot_horizon": 60, "pilot_factor": 2.0}
    rng = np.random.default_rng(6)
    rate, rel, verdict = stability.refine_long_horizon(EX1, np.eye(2), np.array([0.5, 0.5]), np.array([0.36, 0.5]), opts, rng, 1.96)
    assert list(verdict) == ["unbounded", "bounded"]
    assert rate[0] == pytest.approx(np.log(1.69 * 0.64), abs=0.01)  # trailing loss-run growth |lambda|^2 (1-q)
    _, _, verdict2 = stability.refine_long_horizon(EX2, np.eye(3), np.array([0.99]), np.array([0.5]), opts, rng, 1.96)
    assert verdict2[0] == "undecided"

