"""Tests of `markov`: exact E||P_k|| against brute-force enumeration of channel paths, each against an independent computation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from netrepro.errors import InputError
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



@pytest.mark.parametrize("Sigma0", [np.eye(3), np.diag([2.0, 2.0, 0.5])])
def test_block_split_against_full_recursion(Sigma0):
    """Example II on its decoupled blocks (2-D + scalar) equals the full 3-D tree recursion."""
    split = exact.example2_split()
    full = exact.exact_moments(EX2, Sigma0, 12)
    blk = exact.exact_moments_split(EX2, Sigma0, 12, split)
    assert exact.find_split(EX2, Sigma0) is not None
    for p, q in ((0.45, 0.5), (0.99, 0.5), (0.2, 0.9)):
        for which in ("norm", "trace"):
            assert np.allclose(blk.mean(p, q, which), full.mean(p, q, which), rtol=1e-12)
    # and against brute-force enumeration of the paths
    assert blk.mean(0.45, 0.5)[8] == pytest.approx(_brute_force_mean(EX2, Sigma0, 0.45, 0.5, 9), rel=1e-10)


def test_block_split_rejected_when_coupled():
    Qc = np.eye(3)
    Qc[0, 2] = Qc[2, 0] = 0.3  # couples w = (e1 - e2)/sqrt 2 with e3
    coupled = model.LinearSystem(EX2.A, EX2.C, Qc, EX2.R)
    # a uniform correlation keeps the split (u, e3 | w)
    uniform = model.LinearSystem(EX2.A, EX2.C, np.eye(3) + 0.3 * (np.ones((3, 3)) - np.eye(3)), EX2.R)
    assert exact.find_split(uniform, np.eye(3)) is not None
    assert exact.find_split(coupled, np.eye(3)) is None
    assert exact.find_split(EX2, np.array([[1.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 1.0]])) is not None
    assert exact.find_split(EX2, np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.0], [0.5, 0.0, 1.0]])) is None
    assert exact.find_split(EX1, np.eye(2)) is None
    with pytest.raises(InputError, match="does not split Q"):
        exact.example2_split().blocks(coupled, np.eye(3))


def test_transition_groups_equal_np_unique():
    """_transition_groups: the groups, order and assignment np.unique(key) gives, without the sort."""
    from netrepro.papers.markov.exact import _branch_channel, _transition_groups, _transition_key

    state, counts = np.ones(1, dtype=bool), np.zeros((1, 4), dtype=np.int16)
    for d in range(1, 13):
        if d > 1:
            state, counts = _branch_channel(state, counts)
        uniq, first, inv = np.unique(_transition_key(counts, d), return_index=True, return_inverse=True)
        group_counts, got_inv = _transition_groups(counts, d)
        assert np.array_equal(group_counts, counts[first]) and np.array_equal(got_inv, inv.ravel())


def test_branch_channel_counts_every_paths_transitions():
    """_branch_channel against the paths themselves: after d - 1 branchings (reception half first), path j's
    channel states are gamma_1 = 1 and the bits of j from the least significant (the latest branching is the most
    significant bit; 1 = lost), and its counts
    are the transitions 11, 10, 01, 00 along them, counted here one path at a time."""
    from netrepro.papers.markov.exact import _branch_channel

    state, counts = np.ones(1, dtype=bool), np.zeros((1, 4), dtype=np.int16)
    for d in range(2, 11):
        state, counts = _branch_channel(state, counts)
        assert counts.dtype == np.int16 and state.dtype == bool
        for j in range(len(state)):
            gammas = [1] + [1 - int(b) for b in reversed(format(j, f"0{d - 1}b"))]
            want = np.zeros(4, dtype=int)
            for a, b in zip(gammas[:-1], gammas[1:]):
                want[{(1, 1): 0, (1, 0): 1, (0, 1): 2, (0, 0): 3}[(a, b)]] += 1
            assert np.array_equal(counts[j], want) and state[j] == bool(gammas[-1])
