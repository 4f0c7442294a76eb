"""Tests of `markov`: exact E||P_k|| against brute-force enumeration of channel paths, each against an independent computation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from netrepro.papers.markov import exact, model
from .systems import EX1, EX2


def _brute_force_mean(system, S0, p, q, k, which="norm"):
    """E||P_k|| by explicit enumeration of gamma_1 = 1, gamma_2..gamma_{k-1} (independent of the tree code)."""
    total = 0.0
    trans = {(1, 1): 1 - p, (1, 0): p, (0, 1): q, (0, 0): 1 - q}
    for tail in itertools.product([0, 1], repeat=k - 2):
        gam = (1,) + tail
        prob = np.prod([trans[(a, b)] for a, b in zip(gam[:-1], gam[1:])])
        P = np.array(S0, dtype=float)
        for g in gam:
            P = model.riccati_g(P, system.A, system.C, system.Q, system.R) if g else model.riccati_h(P, system.A, system.Q)
        val = np.linalg.norm(P, 2) if which == "norm" else np.trace(P)
        total += prob * val
    return total


@pytest.mark.parametrize("system", [EX1, EX2])
def test_exact_moments_against_enumeration(system):
    em = exact.exact_moments(system, np.eye(system.n), 8)
    for p, q in ((0.3, 0.6), (0.95, 0.2)):
        means = em.mean(p, q, "norm")
        traces = em.mean(p, q, "trace")
        for k in (2, 5, 9):
            assert means[k - 1] == pytest.approx(_brute_force_mean(system, np.eye(system.n), p, q, k), rel=1e-10)
        assert traces[8] == pytest.approx(_brute_force_mean(system, np.eye(system.n), p, q, 9, "trace"), rel=1e-10)
    # vectorised over a grid
    grid = em.mean(np.array([0.3, 0.95]), np.array([0.6, 0.2]))
    assert grid.shape == (2, 9)

