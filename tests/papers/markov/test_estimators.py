"""Tests of `markov`: Monte Carlo estimators against exact enumeration, each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.markov import estimators, model
from netrepro.papers.markov.exact import exact_moments
from .systems import A2, C2, EX1, EX2, all_paths, path_probs


@pytest.mark.parametrize("system", [EX1, EX2])
def test_conditional_estimator_is_unbiased(system):
    """The trailing-loss-run estimator, averaged over ALL channel paths with their probabilities, equals E||P_k||."""
    T = 9
    arr = all_paths(T)
    p, q = 0.7, 0.3
    w = path_probs(arr, p, q)
    est = estimators.rb_mean_norm(system, np.eye(system.n), p, q, arr)
    exact = exact_moments(system, np.eye(system.n), T).mean(p, q)
    assert np.allclose(w @ est, exact, rtol=1e-10)
    # and the plain estimator over all paths too (sanity of the weights)
    P = estimators.covariance_paths_ge(system, np.eye(system.n), arr)
    assert np.allclose(w @ model.sym_norm(P), exact, rtol=1e-10)


def test_covariance_paths_matches_eqs_4_5_step_by_step():
    """The engine-backed path recursion against g (eq. 5) and h (eq. 4) applied one path at a time."""
    rng = np.random.default_rng(3)
    arr = rng.random((50, 15)) < 0.6
    ours = estimators.covariance_paths_ge(EX2, np.eye(3), arr)
    theirs = np.empty_like(ours)
    for i, path in enumerate(arr):
        P = np.eye(3)
        theirs[i, 0] = P
        for k, received in enumerate(path):
            P = model.riccati_g(P, A2, C2, np.eye(3), np.eye(2)) if received else model.riccati_h(P, A2, np.eye(3))
            theirs[i, k + 1] = P
    assert np.allclose(ours, theirs, rtol=1e-9)


def test_plain_mean_understates_beyond_boundary():
    """Beyond |lambda|^2 (1-q) = 1 the plain mean misses the loss-run tail that the conditional estimator integrates."""
    rng = np.random.default_rng(5)
    norms, arr = estimators.plain_mc(EX1, np.eye(2), 0.5, 0.3, 300, 40, rng)
    rb = estimators.rb_mean_norm(EX1, np.eye(2), 0.5, 0.3, arr)
    assert norms[:, -1].mean() < 0.5 * rb[:, -1].mean()
    # while the conditional estimator is tight: relative standard error below 10%
    assert rb[:, -1].std() / np.sqrt(len(rb)) < 0.1 * rb[:, -1].mean()


def test_rb_trace_grid_matches_single_point_estimator():
    rng = np.random.default_rng(8)
    m, h = estimators.rb_trace_grid(EX1, np.eye(2), [0.5], [0.5], 400, 40, rng, n_batches=10, z=1.96)
    arr = estimators.gilbert_elliott_arrivals(np.random.default_rng(9), 4000, 40, 0.5, 0.5, initial=1)
    m2, lo, hi = estimators.rb_mean_trace(EX1, np.eye(2), 0.5, 0.5, arr, n_batches=20, z=1.96)
    assert abs(m[0, -1] - m2[-1]) < 3 * (h[0, -1] + (hi[-1] - lo[-1]) / 2)


@pytest.mark.parametrize("system", [EX1, EX2])
def test_linear_trace_estimator_is_unbiased(system):
    """rb_mean_trace (linear form) equals the per-path trace estimator, which is unbiased by enumeration."""
    T = 9
    arr = all_paths(T)
    p, q = 0.6, 0.35
    w = path_probs(arr, p, q)
    per_path = estimators.rb_mean_norm(system, np.eye(system.n), p, q, arr, which="trace")
    exact = exact_moments(system, np.eye(system.n), T).mean(p, q, "trace")
    assert np.allclose(w @ per_path, exact, rtol=1e-10)
    mean, _, _ = estimators.rb_mean_trace(system, np.eye(system.n), p, q, arr, n_batches=len(arr), z=1.96)
    assert np.allclose(mean, per_path.mean(axis=0), rtol=1e-10)



def test_riccati_step_equals_where_of_both_maps():
    """rb_trace_grid's per-path step: g on received, h on lost paths, bit for bit the np.where form."""
    from netrepro.papers.markov.estimators import _riccati_step
    from netrepro.papers.markov.model import LinearSystem, riccati_g, riccati_h

    rng = np.random.default_rng(5)
    for A, C in (([[1.3, 0.3], [0.0, 1.2]], [[1.0, 1.0]]),
                 ([[1.2, 0, 0], [0, 1.2, 0], [0, 0, -1.2]], [[1.0, 0, 1], [0, 1, 1]])):
        n, m = len(A), len(C)
        s = LinearSystem.from_config(dict(A=A, C=C, Q=np.eye(n).tolist(), R=np.eye(m).tolist()))
        X = rng.normal(size=(500, n, n))
        P = X @ np.swapaxes(X, -1, -2) * 10.0 ** rng.uniform(-2, 6, size=(500, 1, 1))
        P[:3] = np.inf
        for received in (rng.random(500) < 0.4, np.ones(500, bool), np.zeros(500, bool)):
            with np.errstate(over="ignore", invalid="ignore"):
                ref = np.where(received[:, None, None], riccati_g(P, s.A, s.C, s.Q, s.R), riccati_h(P, s.A, s.Q))
                got = _riccati_step(P, received, s.A, s.C, s.Q, s.R)
            assert np.array_equal(got, ref, equal_nan=True)
