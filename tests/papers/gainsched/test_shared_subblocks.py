"""The vertex LMIs build each shared sub-block (Q̄^i, Λ^l, Γ1^{ij}, S^T, ...) once and reuse it: the expression trees
are the same as building every block afresh per vertex, so the solver data must be the same, bit for bit (the tables
record the solver's point of a non-unique LMI solution)."""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

from netrepro.papers.gainsched import model
from netrepro.papers.gainsched.design import FixedGainsVertexLMI, Theorem3
from netrepro.papers.gainsched.feasibility import with_sigma2
from netrepro.papers.gainsched.model import augmented_initial_moment, theorem1_matrix


def _data(problem):
    data, _, _ = problem.get_problem_data(cp.CLARABEL)
    A = data["A"].tocsc()
    return [A.data, A.indices, A.indptr, data["b"], data["c"], np.array(repr(data["dims"]))]


def _assert_same(p, q):
    x, y = _data(p), _data(q)
    assert len(x) == len(y)
    for a, b in zip(x, y):
        assert a.shape == b.shape and np.array_equal(a, b)


class _FreshTheorem3(Theorem3):
    """Every sub-block built afresh at each use (the construction before the sharing)."""

    def _part(self, key, build, *args):
        return build(*args)


class _FreshFixedGains(FixedGainsVertexLMI):
    def _part(self, key, build):
        return build()


@pytest.mark.parametrize("opts", [dict(), dict(scheduled=False), dict(gamma3_top="zero"), dict(noise_row=False),
                                  dict(zero_filter=True), dict(qp_positive=False), "fixed_gains", "performance",
                                  "output_slack"])
@pytest.mark.parametrize("sigma2", [3.5])
def test_theorem3_shared_blocks_same_solver_data(sys, paper, opts, sigma2):
    X0 = augmented_initial_moment(np.eye(sys.n), sys.n)
    opts = {"fixed_gains": dict(fixed_gains=paper), "performance": dict(performance=True, X0=X0),
            "output_slack": dict(performance=True, output_slack=True, X0=X0)}.get(opts) if isinstance(opts, str) else opts
    shared, fresh = (cls(sys, bound=100.0, **opts) for cls in (Theorem3, _FreshTheorem3))
    assert shared._parts  # the sharing is in use
    shared.sigma2.value = fresh.sigma2.value = sigma2
    _assert_same(shared.problem, fresh.problem)
    for (_, a), (_, b) in zip(shared._blocks, fresh._blocks):  # the certifier's blocks too
        assert np.array_equal(_data(cp.Problem(cp.Minimize(0), [a >> 0]))[0],
                              _data(cp.Problem(cp.Minimize(0), [b >> 0]))[0])


def test_theorem3_noise_free_shared_blocks_same_solver_data(sys):
    sys0 = with_sigma2(sys, 0.0)
    for keep in (True, False):
        _assert_same(Theorem3(sys0, bound=100.0, noise_row=keep).problem,
                     _FreshTheorem3(sys0, bound=100.0, noise_row=keep).problem)


@pytest.mark.parametrize("sigma2", [1.0, 4.0])
def test_fixed_gains_shared_blocks_same_solver_data(sys, paper, sigma2):
    shared, fresh = FixedGainsVertexLMI(sys, paper, bound=100.0), _FreshFixedGains(sys, paper, bound=100.0)
    assert shared._parts
    shared.sigma2.value = fresh.sigma2.value = sigma2
    _assert_same(shared.problem, fresh.problem)


def _fresh_theorem1_problem(sys, gains, n_grid, bound, margin_cap):
    """theorem1_lmi's problem with Q(p) and S^T built afresh at each use."""
    nn = 2 * sys.n
    Q0 = cp.Variable((nn, nn), symmetric=True, name="Q0")
    Qp = cp.Variable((nn, nn), symmetric=True, name="Qp")
    S = cp.Variable((nn, nn), name="S")
    t = cp.Variable(name="t")
    grid = np.linspace(sys.p1, sys.p2, max(2, n_grid))
    cons = [cp.abs(S) <= bound, cp.abs(Q0) <= bound, cp.abs(Qp) <= bound, t <= margin_cap]

    for p in grid:
        cons.append(Q0 + p * Qp >> t * np.eye(nn))
        for pn in grid:
            aug = model.augmented(sys, gains, p)
            N = aug["N"]
            theta, s2 = p * (1.0 - p), sys.sigma2
            Lam = -(Q0 + pn * Qp) + S + S.T
            Om1 = S.T @ (aug["A"] + aug["B"] @ sys.F1 @ sys.Z @ N)
            Om2 = theta * (S.T @ aug["C"] @ N)
            SB = S.T @ aug["B"]
            SD = s2 * (S.T @ aug["D"] @ N)
            FZN = sys.F @ sys.Z @ N
            nz, O = sys.nz, np.zeros
            M = cp.bmat([
                [-(Q0 + p * Qp), FZN.T, Om1.T, Om2.T, SD.T],
                [FZN, -2 * np.eye(nz), SB.T, O((nz, nn)), O((nz, nn))],
                [Om1, SB, -Lam, O((nn, nn)), O((nn, nn))],
                [Om2, O((nn, nz)), O((nn, nn)), -theta * Lam, O((nn, nn))],
                [SD, O((nn, nz)), O((nn, nn)), O((nn, nn)), -s2 * Lam],
            ])
            cons.append(M << -t * np.eye(M.shape[0]))
    return cp.Problem(cp.Maximize(t), cons)


@pytest.mark.parametrize("n_grid", [2, 3])
def test_theorem1_lmi_shared_blocks_same_solver_data(sys, paper, monkeypatch, n_grid):
    captured = []

    def capture(self, *args, **kwargs):
        captured.append(self)
        raise cp.error.SolverError("captured")

    monkeypatch.setattr(cp.Problem, "solve", capture)
    res = model.theorem1_lmi(sys, paper, n_grid=n_grid, bound=100.0, margin_cap=0.1)
    monkeypatch.undo()
    assert res.status.startswith("solver_error") and len(captured) == 1
    _assert_same(captured[0], _fresh_theorem1_problem(sys, paper, n_grid, 100.0, 0.1))

