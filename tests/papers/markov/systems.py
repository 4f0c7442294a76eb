"""Shared systems of the `markov` tests: Examples I and II of the paper and an l_o = 3 system."""

from __future__ import annotations

import itertools

import numpy as np

from netrepro.papers.markov.model import LinearSystem

__all__ = ["A1", "C1", "A2", "C2", "A3", "C3", "EX1", "EX2", "all_paths", "path_probs"]

A1 = np.array([[1.3, 0.3], [0.0, 1.2]])
C1 = np.array([[1.0, 1.0]])
A2 = np.diag([1.2, 1.2, -1.2])
C2 = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0]])
EX1 = LinearSystem(A1, C1, np.eye(2), np.eye(1))
EX2 = LinearSystem(A2, C2, np.eye(3), np.eye(2))
# a system with observability index 3 (for the general-l_o code paths)
A3 = np.array([[1.1, 1.0, 0.0], [0.0, 1.1, 1.0], [0.0, 0.0, 1.05]])
C3 = np.array([[1.0, 0.0, 0.0]])


def all_paths(T):
    """All gamma sequences of length T with gamma_1 = 1."""
    return np.array([(1,) + t for t in itertools.product([0, 1], repeat=T - 1)], dtype=bool)


def path_probs(arr, p, q):
    """Probability of each path under the Gilbert-Elliott chain (eq. 3), gamma_1 = 1 given."""
    a, b = arr[:, :-1], arr[:, 1:]
    P = np.where(a & b, 1 - p, np.where(a & ~b, p, np.where(~a & b, q, 1 - q)))
    return P.prod(axis=1)
