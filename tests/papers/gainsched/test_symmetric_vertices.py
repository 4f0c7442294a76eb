"""The LMI vertex matrices are structurally symmetric, so stating them without 0.5 (M + M^T) leaves the
solver data unchanged, bit for bit (LMI solutions are non-unique: the tables record the solver's point)."""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from netrepro.papers.gainsched.design import FixedGainsVertexLMI, Theorem3
from netrepro.papers.gainsched.model import theorem1_matrix


def _clarabel_data(M, t, variables, bound=100.0):
    prob = cp.Problem(cp.Maximize(t), [M << -t * np.eye(M.shape[0]), t <= 0.1]
                      + [cp.abs(v) <= bound for v in variables])
    data, _, _ = prob.get_problem_data(cp.CLARABEL)
    A = data["A"].tocsc()
    return A.data, A.indices, A.indptr, data["b"], data["c"]


def _assert_same_data(M, t, variables):
    for x, y in zip(_clarabel_data(M, t, variables), _clarabel_data(0.5 * (M + M.T), t, variables)):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("opts", [dict(), dict(gamma3_top="zero"), dict(scheduled=False), dict(noise_row=False)])
def test_theorem3_vertex_needs_no_symmetrisation(sys, opts):
    prob = Theorem3(sys, bound=100.0, **opts)
    M = prob.vertex(sys.p1, sys.p2, sys.p2, sys.p1)
    _assert_same_data(M, prob.t, list(prob.vars.values()))


def test_fixed_gains_vertex_needs_no_symmetrisation(sys, paper):
    prob = FixedGainsVertexLMI(sys, paper, bound=100.0)
    _assert_same_data(prob.vertex(sys.p2, sys.p1, sys.p2, sys.p1), prob.t, [prob.Q0, prob.Qp, prob.S])


def test_theorem1_matrix_needs_no_symmetrisation(sys, paper):
    nn = 2 * sys.n
    Q0 = cp.Variable((nn, nn), symmetric=True)
    Qp = cp.Variable((nn, nn), symmetric=True)
    S = cp.Variable((nn, nn))
    t = cp.Variable()
    p, pn = 0.5 * (sys.p1 + sys.p2), sys.p2
    M = theorem1_matrix(sys, paper, Q0 + p * Qp, Q0 + pn * Qp, S, p)
    _assert_same_data(M, t, [Q0, Qp, S])
